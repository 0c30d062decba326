"""The error metric of ``rwadist diagnose`` (``waterfall_unexplained_fraction``, docs/diagnose.md).

:class:`Metric` is mixed into :class:`rwadist.diagnose.engine.Context`: it needs the context's bands,
degrees of freedom, data and predictions.
"""
from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np

from ..dft import hann_transform
from .constants import BAND_BINS, CONTRAST_NOISE_Z, KERNEL_HALF, NOISE_Z, TORQUE_CHANNELS
from .reduce import bin_sums
from .ripple import RIPPLE_OWN_GAIN_ORDERS
from .state import State

if TYPE_CHECKING:
    from ..spectra import Spectra

#: Points per bin of :func:`hann_tables`: the 4-point interpolation's error falls as its step⁴ (measured on |W|²:
#: 1/64 2.5e-8, 1/128 1.6e-9, 1/256 1e-10 of the peak; 1e-10 is a fraction of a noise level in the strongest
#: line's bins at 0.1 % noise, where a line's peak PSD stands ~L/3·1e6 over the noise).
HANN_OVERSAMPLE = 256
#: Elements (pairs × runs × kernel offsets) of one chunk of :meth:`Metric._beat_shapes`: a few MB per temporary.
BEAT_CHUNK_ELEMENTS = 1 << 18
#: Reach of :func:`hann_tables`, bins each side: the kernel's ±KERNEL_HALF, the interpolation's 2 points, margin.
HANN_TABLE_HALF = KERNEL_HALF + 3


@functools.lru_cache(maxsize=8)
def hann_tables(nperseg: int) -> tuple:
    """(V, |V|²) of the periodic Hann window of ``nperseg`` samples as interpolation tables for :func:`read_table`:
    V(δ) = W(δ)·e^{jπδ(L−1)/L}, the window's transform (:func:`rwadist.dft.hann_transform`, closed form) without
    its linear phase (complex; |V| = |W|), at δ = −HANN_TABLE_HALF + i/HANN_OVERSAMPLE bins, each interval
    stored as the coefficients of its cubic in the fraction u (the 4-point Lagrange cubic through the points
    i − 1 … i + 2), one contiguous row per power of u: (4, n_intervals), each row gathered at the intervals
    :func:`read_table` reads.  Read-only (shared)."""
    delta = np.arange(-HANN_TABLE_HALF * HANN_OVERSAMPLE, HANN_TABLE_HALF * HANN_OVERSAMPLE + 1) / HANN_OVERSAMPLE
    L = float(nperseg)
    V = hann_transform(nperseg, L, delta) * np.exp(1j * np.pi * delta * (L - 1.0) / L)    # f_s = L: δ in bins
    out = []
    for y in (V, V.real**2 + V.imag**2):
        p0, p1, p2, p3 = y[:-3], y[1:-2], y[2:-1], y[3:]
        coef = np.ascontiguousarray(np.stack([p1, -p0 / 3.0 - p1 / 2.0 + p2 - p3 / 6.0, (p0 + p2) / 2.0 - p1,
                                              (p3 - p0) / 6.0 + (p1 - p2) / 2.0], axis=0))
        coef.flags.writeable = False
        out.append(coef)
    return tuple(out)


def read_table(coef: np.ndarray, dlt: np.ndarray) -> np.ndarray:
    """A table of :func:`hann_tables` at offsets ``dlt`` (bins, any shape; clipped to the table's reach): the cubic
    of the interval holding each offset, evaluated at its fraction (Horner; each coefficient gathered from its own
    contiguous row: a gather of (..., 4) rows read through strided views cost 3x as much)."""
    x = np.clip((dlt + HANN_TABLE_HALF) * HANN_OVERSAMPLE, 1.0, coef.shape[1])
    i = x.astype(int)
    u = x - i
    i -= 1
    c0, c1, c2, c3 = (row.take(i) for row in coef)
    return ((c3 * u + c2) * u + c1) * u + c0


class Metric:
    """Band powers, their noise standard deviations and the misplaced power (methods of a Context)."""

    # what the methods read of their Context (:class:`rwadist.diagnose.engine.Context` sets and defines these)
    sp: Spectra
    omega: np.ndarray                   # |Ω| per run of the spectra, rad/s
    runs: np.ndarray                    # the runs at a speed (|Ω| > 0), indices, sorted
    channels: tuple[str, ...]
    df: float                           # Hz per bin
    dof: float                          # Welch degrees of freedom of a bin
    k_lo: int                           # first bin of the bands
    n_bands: int
    _memo: dict
    _scale: dict[str, float]            # per channel, the mean data power of its unit group

    if TYPE_CHECKING:
        def data(self, state: State, c: str, runs: np.ndarray | None = None) -> np.ndarray: ...

        def gain(self, state: State, c: str, f_hz) -> np.ndarray: ...

        def channel_lines(self, state: State, c: str, runs: np.ndarray) -> list: ...

        def line_mixing(self, state: State, c: str, runs: np.ndarray) -> list: ...

        def sideband_gain(self, state: State, c: str, h: float, shift: float, runs: np.ndarray) -> np.ndarray: ...

        def floor_psd(self, state: State, c: str, runs: np.ndarray) -> np.ndarray: ...

        def predict(self, state: State, c: str, runs: np.ndarray, skip=None, only=None) -> np.ndarray: ...

        def ripple_powers(self, state: State, h: float, law, runs: np.ndarray, c: str | None = None): ...

        def _ripple_gains(self, state: State, c: str, h: float, shift: float, f: np.ndarray, k: np.ndarray,
                          runs: np.ndarray) -> np.ndarray: ...

    def rows_of_every_run(self, state: State, name: str, c: str, runs: np.ndarray) -> tuple | None:
        """(what ``state`` keeps under ``(name, c)`` for every run, the positions of ``runs`` in it), or None when
        nothing is kept for every run or ``runs`` is not a proper subset of the runs (sorted, as ``self.runs``).
        For terms each run has on its own: a subset's are the rows of every run's."""
        whole = state._cache.get((name, c, self.runs.tobytes()))
        pos = None if whole is None else self.run_rows(runs)
        return None if pos is None else (whole, pos)

    def run_rows(self, runs: np.ndarray) -> np.ndarray | None:
        """The positions of ``runs`` in ``self.runs``, or None when ``runs`` is not a proper subset of them (sorted,
        as ``self.runs``)."""
        if runs.size >= self.runs.size:
            return None
        pos = np.searchsorted(self.runs, runs)
        if np.all(pos < self.runs.size) and np.array_equal(self.runs[np.minimum(pos, self.runs.size - 1)], runs):
            return pos
        return None

    def band_sums(self, x: np.ndarray) -> np.ndarray:
        """Σ of each band's BAND_BINS bins of ``x`` (rows, n_f), times df: (rows, n_bands)."""
        lo = self.k_lo
        n = self.n_bands * BAND_BINS
        return bin_sums(x[:, lo:lo + n].reshape(x.shape[0], self.n_bands, BAND_BINS)) * self.df

    def band_sigma(self, state: State, c: str, runs: np.ndarray, floor=None, lines=None,
                   beat_state: State | None = None) -> np.ndarray:
        """Noise standard deviation (unit²) of the data power in every band if the model were right.

        A Welch PSD bin of noise N plus a deterministic line L has variance (N² + 2·L·N)·2/ν
        (ν = Welch degrees of freedom; the second term is the line × noise cross term); bins
        are summed as if independent and the result doubled for the Hann correlation of
        neighbouring bins (an approximation, stated); to that the variance of the model's lines beating
        with one another (:meth:`beat_variance`, exact for the Hann window), of the lines of ``beat_state``
        (default: ``state``)."""
        N = self.floor_psd(state, c, runs) if floor is None else floor
        L = (self.predict(state, c, runs) - N) if lines is None else lines
        var_bin = (N**2 + 2.0 * np.maximum(L, 0.0) * N) * 2.0 / self.dof
        beats = self.beat_variance(state if beat_state is None else beat_state, c, runs)
        return np.sqrt(2.0 * self.band_sums(var_bin) * self.df + beats)

    def beat_variance(self, state: State, c: str, runs: np.ndarray) -> np.ndarray:
        """Variance (unit⁴, (len(runs), n_bands)) of the band powers from the model's lines beating.

        Two lines i, j (mean squares P_i, P_j) within two kernel reaches of each other add to a Welch band the
        cross term 2·√(P_i·P_j)·Re(S·e^{jΔφ})·c_ij·Δf/(f_s·Σw²), S = Σ_band V(k − p_i)·V(k − p_j)* (V of
        :func:`hann_tables`, p the lines' positions in bins), whose phase difference Δφ the model does not know
        (every line's phase is free): uniform Δφ gives the variance 2·P_i·P_j·c_ij²·|S|²·(Δf/(f_s·Σw²))².
        c_ij = |sin(Mπx)/(M·sin(πx))|, x = (p_i − p_j)/2, is what is left of the term after averaging M
        segments at 50 % overlap (the phase difference turns by 2πx from one segment to the next).  A line's
        image at −f (a channel is a real signal) beats with the line itself and its neighbours near 0 Hz as a
        line of phase −φ.  The lines and their sidebands as :meth:`predict` has them (each within ±KERNEL_HALF of
        its bin), under a speed ripple with its orders near the line (:meth:`_ripple_parts`); under a spin smear as the
        steady lines' at the runs' mean speeds; zero for other windows (the term is not modelled).  Cached on the
        state; each pair's shape on the context; a subset of the runs whose variance on every run is kept reads its
        rows (a pair near only in other runs adds exact zeros)."""
        key = ("beat", c, runs.tobytes())
        if key in state._cache:
            return state._cache[key]
        kept = self.rows_of_every_run(state, "beat", c, runs)
        if kept is not None:
            whole, pos = kept
            state._cache[key] = whole[pos]
            return state._cache[key]
        out = np.zeros((runs.size, self.n_bands))
        # under a spin smear too: a co/counter pair's parts turn together (one relative phase over the whole run, every
        # segment's Fx/Fy split alike), so their beat stays, in sum (the steady kernel places it, not the smeared
        # shape; near lines' beats under a chirp are larger than the steady formula's).  Zero there, the
        # smear at any |α| > 0 counted as misplaced power what the steady lines' beats allow for (the E wheel's 8-s run-up
        # with its radial-force lines planar: 1.188 without a smear, 1.883 at α 1e-6 rad/s²), and the smear's own test
        # (SpinAcceleration.fit, its cost at α 0 against the track's) compared two states without beats
        if self.sp.window == "hann":
            comps, mixed = [], []
            for (h, law, amp, _), mix in zip(self.channel_lines(state, c, runs), self.line_mixing(state, c, runs)):
                f0 = h * self.omega[runs] / (2 * np.pi)
                for shift, rel in state.line_components(c, h):
                    a = amp * rel * self.sideband_gain(state, c, h, shift, runs)
                    if state.resonances:
                        a = a * self.gain(state, c, f0 + shift)
                    for extra, p in self._ripple_parts(state, c, h, law, shift, f0 + shift, runs):
                        comps.append(((round(h, 9), shift + extra), np.abs(f0 + shift + extra) / self.df,
                                      a**2 / 2.0 * p))
                        if shift == 0 and extra == 0 and np.any(mix > 0):
                            mixed.append((len(comps) - 1, mix))
            if comps:
                first, second, shapes = self._beat_pairs(comps, runs)
                if first.size:
                    P = np.array([x[2] for x in comps])                                    # (n, len(runs))
                    out = np.einsum("pr,prb->rb", 2.0 * P[first] * P[second], shapes)
            # a line of parts with independent phases at one frequency (a co/counter pair) beats with itself: the
            # variance mix·P² spread as the line's own kernel squared (the pair shape at one position, coherence 1)
            for i, mix in mixed:
                own, pos, p = comps[i]
                (shape,) = self._beat_shapes([(own, own, False, pos, pos)], runs)
                out = out + (mix * p**2)[:, None] * shape
        state._cache[key] = out
        return out

    def _ripple_parts(self, state: State, c: str, h: float, law, shift: float, f: np.ndarray, runs: np.ndarray):
        """[(offset Hz, power fraction (len(runs),) or 1.0)] of a line component at ``f`` for :meth:`beat_variance`: itself
        without a speed ripple; under one, its orders |k| <= RIPPLE_OWN_GAIN_ORDERS at k·f_r, each with its share of the
        power through the modes at its own frequency (as :meth:`predict` has them: a ripple's lines beat with their
        carrier and its neighbours as steady lines do, their phases unknown)."""
        rip = self.ripple_powers(state, h, law, runs, c)
        if rip is None or state.speed_modulation is None:
            return [(0.0, 1.0)]
        k, P = rip
        G = self._ripple_gains(state, c, h, shift, f, k, runs)
        f_r = float(state.speed_modulation[1])
        return [(float(k[j] * f_r), P[:, j] * G[:, j] ** 2) for j in np.flatnonzero(np.abs(k) <= RIPPLE_OWN_GAIN_ORDERS)]

    def _beat_pairs(self, comps, runs):
        """(i, j, shapes (n_pairs, len(runs), n_bands)) of the pairs of :meth:`beat_variance`'s line components
        ``comps`` [(key, position, power)] within two kernel reaches of each other in some run (a line with a line,
        i < j; a line with the image of a line, i ≤ j), their shapes (:meth:`_beat_shapes`) stacked.  The pairs and
        shapes depend on the lines' positions only: kept on the context per set of lines (every hypothesis that does
        not move a line -- a floor, a resonance, a law -- reads them again); the shapes not yet known are computed
        together."""
        key = ("beat_pairs", tuple(x[0] for x in comps), runs.tobytes())
        if key not in self._memo:
            pos = np.array([x[1] for x in comps])                                         # (n, len(runs))
            reach = 2 * KERNEL_HALF
            near = np.triu(np.any(np.abs(pos[:, None, :] - pos[None, :, :]) <= reach, axis=2), 1)
            near_image = np.triu(np.any(pos[:, None, :] + pos[None, :, :] <= reach, axis=2))
            pairs = [(i, j, image) for image, mask in ((False, near), (True, near_image))
                     for i, j in zip(*np.nonzero(mask))]
            wanted = [(comps[i][0], comps[j][0], image, pos[i], pos[j]) for i, j, image in pairs]
            shapes = np.array(self._beat_shapes(wanted, runs)) if pairs else np.zeros((0, runs.size, self.n_bands))
            self._memo[key] = (np.array([x[0] for x in pairs], dtype=int), np.array([x[1] for x in pairs], dtype=int),
                               shapes)
        return self._memo[key]

    def _beat_shape(self, ki, kj, image, pi, pj, runs):
        """c_ij²·|S|²·(Δf/(f_s·Σw²))² (len(runs), n_bands) of :meth:`beat_variance` for lines at bins ``pi``, ``pj``
        (len(runs),; ``image``: the image of j, at −pj), keyed by the lines' (h, shift) ``ki``, ``kj`` on the
        context (the positions depend on h, shift and the runs only, not on the state)."""
        return self._beat_shapes([(ki, kj, image, pi, pj)], runs)[0]

    def _beat_shapes(self, wanted, runs) -> list:
        """:meth:`_beat_shape` of every (ki, kj, image, pi, pj) of ``wanted``: those not kept on the context computed
        as one stack (each pair's numbers the same operations as alone: its own rows of every array, its own bins of
        the bincount, in the same order), and kept."""
        keys = [("beat_shape", ki, kj, image, runs.tobytes()) for ki, kj, image, _, _ in wanted]
        missing = [i for i, k in enumerate(keys) if k not in self._memo]
        # a few MB of temporaries per chunk of pairs (each pair: len(runs) × (2·KERNEL_HALF + 1) complex numbers)
        per_chunk = max(1, BEAT_CHUNK_ELEMENTS // max(runs.size * (2 * KERNEL_HALF + 1), 1))
        for c0 in range(0, len(missing), per_chunk):
            todo = missing[c0:c0 + per_chunk]
            L = self.sp.nperseg
            V = hann_tables(L)[0]
            pi = np.array([wanted[i][3] for i in todo])                                   # (P, runs)
            qj = np.array([-wanted[i][4] if wanted[i][2] else wanted[i][4] for i in todo])
            n_p = len(todo)
            # the bins both kernels reach (each ±KERNEL_HALF of its line's bin): from the later line's first bin on,
            # 2·KERNEL_HALF + 1 of them (the other products are zero; their sums add the same terms in the same order)
            bi, bj = np.rint(pi), np.rint(qj)
            k = (np.maximum(bi, bj).astype(int) - KERNEL_HALF)[:, :, None] + np.arange(2 * KERNEL_HALF + 1)
            lo, hi = self.k_lo, self.k_lo + self.n_bands * BAND_BINS
            vi = np.where(np.abs(k - bi[:, :, None]) <= KERNEL_HALF, read_table(V, k - pi[:, :, None]), 0)
            vj = np.where(np.abs(k - bj[:, :, None]) <= KERNEL_HALF, read_table(V, k - qj[:, :, None]), 0)
            near = np.abs(pi - qj) <= 2 * KERNEL_HALF
            prod = np.where(near[:, :, None] & (k >= lo) & (k < hi), vi * np.conj(vj), 0)
            band = np.clip((k - lo) // BAND_BINS, 0, self.n_bands - 1)
            flat = (np.arange(n_p * runs.size).reshape(n_p, runs.size, 1) * self.n_bands + band).ravel()
            size = n_p * runs.size * self.n_bands
            S = (np.bincount(flat, prod.real.ravel(), size) + 1j * np.bincount(flat, prod.imag.ravel(), size))
            x = 0.5 * (pi - qj)
            m = np.asarray(self.sp.n_segments, dtype=float)[runs]
            den = m * np.sin(np.pi * x)
            small = np.abs(den) < 1e-12
            coh = np.where(small, 1.0, np.abs(np.sin(m * np.pi * x)) / np.where(small, 1.0, np.abs(den)))
            norm = (self.df / (self.sp.sample_rate * 3.0 * L / 8.0)) ** 2                 # Σw² = 3L/8
            out = (coh**2)[:, :, None] * norm * np.abs(S.reshape(n_p, runs.size, -1)) ** 2
            for a, i in enumerate(todo):
                shape = out[a].copy()
                shape.flags.writeable = False
                self._memo[keys[i]] = shape
        return [self._memo[k] for k in keys]

    def run_errors(self, state: State, runs: np.ndarray, channels=None, detail: bool = False,
                   beat_state: State | None = None):
        """Per run: (E_num, D_tot) summed over channels and bands, E_num = Σ max(|D − M| − 2σ, 0)
        (the misplaced power beyond two noise standard deviations), each channel divided by the mean
        data power of its unit group so forces and torques weigh alike.  ``detail``: also the per-band
        (channel -> (D − M, σ)) arrays (the residual: an effect may change the model M or, a measurement
        correction, the data D as the state reads them).  ``beat_state``: the state whose lines' beats
        the noise allows for (:meth:`band_sigma`; default ``state``)."""
        err = np.zeros(runs.size)
        tot = np.zeros(runs.size)
        parts = {}
        for c in channels or self.channels:
            ok, e_run, t_run, resid, sig = self._channel_terms(state, c, runs, beat_state)
            err[ok] += e_run[ok]
            tot[ok] += t_run[ok]
            parts[c] = (resid, sig)
        return (err, tot, parts) if detail else (err, tot)

    def _channel_terms(self, state: State, c: str, runs: np.ndarray, beat_state: State | None) -> tuple:
        """One channel's part of :meth:`run_errors`: (ok (runs,), Σ_bands e / scale (runs,), D_tot / scale (runs,),
        (D − M)/scale and σ/scale (runs, n_bands)), e = max(|D − M| − NOISE_Z·σ, 0).  Each run's terms are its own
        (no sum across runs): with the state's own beats they are kept on the state (read-only, as its prediction), and
        a subset of the runs whose terms on every run are kept (the search's held-out runs of a state whose error on
        every run the search asked for first) reads its rows of those."""
        own = beat_state is None or beat_state is state
        key = ("channel_terms", c, runs.tobytes())
        if own:
            if key in state._cache:
                return state._cache[key]
            # not under a spin smear or a speed ripple: there the lines' spreading is set by the runs asked together
            kept = self.rows_of_every_run(state, "channel_terms", c, runs) \
                if state.smear is None and state.speed_modulation is None else None
            if kept is not None:
                whole, pos = kept
                return tuple(x[pos] for x in whole)
        ok, D = self._data_bands(state, c, runs)
        N = self.floor_psd(state, c, runs)
        Mfull = self.predict(state, c, runs)
        M = self.band_sums(Mfull)
        sig = self.band_sigma(state, c, runs, N, Mfull - N, beat_state)
        scale = self.scale(c)
        e = np.maximum(np.abs(D - M) - NOISE_Z * sig, 0.0)
        out = (ok, e.sum(1) / scale, D.sum(1) / scale, (D - M) / scale, sig / scale)
        if own:
            for x in out:
                x.flags.writeable = False
            state._cache[key] = out
        return out

    def _data_bands(self, state: State, c: str, runs: np.ndarray) -> tuple:
        """(runs with data (len(runs),), band sums of the data as the state reads it (len(runs), n_bands)) of channel
        ``c``: the data's alone (a torque corrected for the state's load-cell offset is keyed by it), kept on the
        context, read-only."""
        r = state.load_cell_offset
        offset = tuple(float(x) for x in r) if r is not None and c in TORQUE_CHANNELS \
            else None
        key = ("data_bands", c, offset, runs.tobytes())
        if key not in self._memo:
            Dfull = self.data(state, c, runs)[runs]
            out = (np.isfinite(Dfull[:, 0]), self.band_sums(Dfull))
            for x in out:
                x.flags.writeable = False
            self._memo[key] = out
        return self._memo[key]

    def scale(self, c):
        return self._scale[c]

    def error(self, state: State, runs=None) -> float:
        e, t = self.run_errors(state, self.runs if runs is None else runs)
        return float(e.sum() / t.sum())

    def contrast_error(self, state: State, runs=None) -> float:
        """The narrow-line figure of merit (``waterfall_band_contrast``, docs/diagnose.md): the mean over every band of
        every run and channel of max(|D − M| − 3σ, 0) / max(D, M), the fraction of the band's own power the model
        misplaces beyond three noise standard deviations.  Every band weighs alike, as on the residual waterfall's
        dB scale: a line standing 10 dB out of the noise in its band counts 0.9 of that band whatever its power,
        where :meth:`error` weighs it by its power (one narrow unexplained line moved that from 1.0 to 1.1 × the
        clean level).  Read from the terms :meth:`run_errors` keeps on the state."""
        runs = self.runs if runs is None else runs
        _, _, parts = self.run_errors(state, runs, detail=True)
        num, count = 0.0, 0
        for c, (resid, sig) in parts.items():
            D = self._data_bands(state, c, runs)[1] / self.scale(c)
            ok = np.isfinite(D[:, 0])
            M = D - resid
            e = np.maximum(np.abs(resid) - CONTRAST_NOISE_Z * sig, 0.0)[ok] / np.maximum(np.maximum(D, M)[ok], 1e-300)
            num += float(e.sum())
            count += e.size
        return num / count if count else float("nan")

    def rms_error(self, state: State) -> float:
        vals = []
        for c in self.channels:
            D = self.band_sums(self.data(state, c)[self.runs]).sum(1)
            M = self.band_sums(self.predict(state, c, self.runs)).sum(1)
            vals.append(np.abs(np.sqrt(M) - np.sqrt(D)) / np.sqrt(D))
        return float(np.nanmean(np.concatenate(vals)))


def rows_of_lines(whole: tuple, pos: np.ndarray) -> tuple:
    """(lines, mixing) by channel of the extended base's lines (:meth:`rwadist.diagnose.engine.Context.channel_lines`,
    :meth:`~rwadist.diagnose.engine.Context.line_mixing`) at the rows ``pos`` of every run's ``whole``: each entry's
    rows (each run's numbers are its own), an entry kept where it has power in one of those runs, as they are made."""
    lines: dict = {c: [] for c in whole[0]}
    mixing: dict = {c: [] for c in whole[1]}
    for c, entries in whole[0].items():
        for (h, law, a, gain), mix in zip(entries, whole[1][c]):
            if np.any(a[pos] > 0):
                a, gain, mix = a[pos], gain[pos], mix[pos]
                a.flags.writeable = gain.flags.writeable = mix.flags.writeable = False
                lines[c].append((h, law, a, gain))
                mixing[c].append(mix)
    return lines, mixing
