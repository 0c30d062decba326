"""The prediction engine of ``rwadist diagnose``: the line kernel and the :class:`Context` that predicts
the expected Welch PSD of a :class:`~rwadist.diagnose.state.State` on every run and channel.

Theory: docs/diagnose.md ("Prediction").
"""
from __future__ import annotations

import copy
from collections.abc import Callable

import numpy as np

from ..empirical import block_floor
from ..model import WheelModel
from ..spectra import Spectra, welch_dof
from ..units import CHANNEL_DIRECTION, CHANNEL_UNIT, CHANNELS
from . import smear
from .constants import BAND_BINS, F_MIN_BINS, KERNEL_HALF, LINE_HALF, NOISE_Z, TORQUE_CHANNELS
from .metric import Metric, hann_tables, read_table, rows_of_lines
from .reduce import bin_sums, column_nanmedian
from .ripple import RIPPLE_IMBALANCE_DIRECTIONS, RIPPLE_OWN_GAIN_ORDERS, ripple_sideband_powers
from .state import State

#: Samples (runs × record length × channels) :meth:`Context.phasors` transforms together: a few tens of MB.
PHASOR_CHUNK_SAMPLES = 1 << 21

# --------------------------------------------------------------------------- line kernel

def line_kernel(nperseg: int, fs: float, window: str = "hann", half: int = KERNEL_HALF, oversample: int = 64):
    """Tabulated PSD shape of a unit-variance sinusoid in a Welch estimate, 1/Hz.

    Returns (delta, K): K(δ) = |W(δ)|²/(f_s Σw²) at offsets δ (bins) from −half−1
    to half+1 in steps of 1/oversample; Σ_k K(δ+k)·df = 1 over all integer k (Parseval).
    """
    from scipy import signal

    w = signal.get_window(window, nperseg)
    steps = np.arange(-(half + 1) * oversample, (half + 1) * oversample + 1)
    delta = steps / oversample
    # W(δ) = Σ w_n e^{−2πj δ n/nperseg} at δ = m/oversample is bin m of the window's FFT zero-padded to
    # nperseg·oversample (the direct sum over the (δ, n) matrix cost seconds for long segments)
    W = np.fft.fft(w, nperseg * oversample)[steps % (nperseg * oversample)]
    return delta, np.abs(W) ** 2 / (fs * np.sum(w**2))


class Context(Metric):
    """Spectra, kernel, bands and run split shared by every step of a diagnosis.

    test : the SteadyTest the spectra were computed from (same runs, same order), or None; the time
    series are needed by the ``cross_coupling`` effect only (complex line amplitudes, corrected PSDs)."""

    def __init__(self, spectra: Spectra, channels=None, test=None):
        self.sp = spectra
        if test is not None and (len(test.runs) != len(spectra.speed) or not np.allclose(
                [r.speed for r in test.runs], spectra.speed)):
            raise ValueError("diagnose: the test's runs are not those of the spectra (count or speeds differ)")
        self.test = test
        self._memo: dict = {}        # computed values of several kinds, each under what it is made of
        #: the search step under way (:func:`rwadist.diagnose.search.diagnose`): (state, its held-out errors on a set of
        #: channels, min_gain), read by :meth:`can_pass`; None outside a search
        self.step: tuple[State, Callable[[list | None], tuple], float] | None = None
        #: the search may move the 'auto' base to the wheel's suspension modes fitted from the data (set by
        #: :func:`rwadist.diagnose.search.diagnose`, read by the ``suspension_modes`` family)
        self.base_switch = False
        #: the wheel's modes may be judged with the load-cell offset they were located beside (set by
        #: :func:`rwadist.diagnose.search._search_once`, read by :func:`rwadist.diagnose.search._judge`)
        self.offset_pair = True
        #: (direction, h) of the harmonics the data show that the starting empirical fit left out of the model, its
        #: lines modally amplified at nearly every speed (:attr:`rwadist.empirical.EmpiricalFit.modally_left_out`; set
        #: by :func:`rwadist.diagnose.search._search_once` when no model is given)
        self.left_out: tuple = ()
        self._corrected: dict = {}
        self.f = spectra.f
        self.df = spectra.df
        self.omega = np.abs(np.asarray(spectra.speed, dtype=float))
        self.runs = np.nonzero(self.omega > 0)[0]
        order = self.runs[np.argsort(self.omega[self.runs], kind="stable")]
        self.fit_runs, self.held_runs = np.sort(order[0::2]), np.sort(order[1::2])
        self.channels = tuple(c for c in (channels or spectra.channels) if c in spectra.psd
                              and c in CHANNEL_DIRECTION)
        self.dof = welch_dof(int(np.min(spectra.n_segments)))
        self.k_lo = F_MIN_BINS
        self.k_hi = int(np.floor(spectra.band_limit / self.df))
        self.n_bands = max((self.k_hi - self.k_lo + 1) // BAND_BINS, 1)
        self.delta, self.kernel = line_kernel(spectra.nperseg, spectra.sample_rate, spectra.window)
        self.osmp = int(round(1 / (self.delta[1] - self.delta[0])))
        # the periodic Hann window's kernel is read in closed form (:meth:`kernel_at`); other windows from the table
        self._hann = spectra.window == "hann"
        self.floor = {c: self._floor(c) for c in self.channels}
        power = {c: float(np.nanmean(self.band_sums(self.sp.psd[c][self.runs]).sum(1))) for c in self.channels}
        # forces are weighed against forces, torques against torques (mean data power of the unit group)
        self._scale = {c: float(np.mean([power[k] for k in self.channels if CHANNEL_UNIT[k] == CHANNEL_UNIT[c]]))
                       for c in self.channels}

    def data(self, state: State, c: str, runs: np.ndarray | None = None) -> np.ndarray:
        """Measured PSD (n_runs, n_f) of channel ``c`` as the state reads it: a torque channel corrected for
        the state's load-cell offset, T − r × F, its Welch PSD recomputed with the spectra's settings.  ``runs``:
        the rows the caller reads; a corrected torque is computed for the runs asked for so far only (a run's
        Welch PSD is its own: the held-out judge of a ``cross_coupling`` hypothesis reads half of them), the other
        rows NaN until asked for; None: every run."""
        if state.load_cell_offset is None or c not in TORQUE_CHANNELS:
            return self.sp.psd[c]
        key = tuple(float(x) for x in state.load_cell_offset)
        chans = [k for k in TORQUE_CHANNELS if k in self.sp.psd]
        if key not in self._corrected:
            self._corrected[key] = ({k: np.full_like(self.sp.psd[k], np.nan) for k in chans},
                                    np.zeros(len(self.test.runs), bool))
        psd, done = self._corrected[key]
        want = np.ones(done.size, bool)
        if runs is not None:
            want = np.zeros(done.size, bool)
            want[np.asarray(runs, dtype=int)] = True
        todo = np.flatnonzero(want & ~done)
        if todo.size:
            from dataclasses import replace

            from ..data import SteadyTest
            from ..spectra import compute_spectra

            r = np.asarray(key)
            sub = []
            for i in todo:          # the corrected torques only (a copy of every signal is not needed)
                run = self.test.runs[i]
                F = np.column_stack([run.signals[k] for k in ("Fx", "Fy", "Fz")])
                T = np.cross(r[None, :], F)
                sub.append(replace(run, signals={k: run.signals[k] - T[:, j] for j, k in enumerate(TORQUE_CHANNELS)
                                                 if k in run.signals}))
            sp = compute_spectra(SteadyTest(sub, dict(self.test.meta)), nperseg=self.sp.nperseg,
                                 window=self.sp.window, f_lim=self.sp.f_lim, channels=chans)
            if not np.array_equal(sp.n_segments, np.asarray(self.sp.n_segments)[todo]):
                raise ValueError("diagnose: the spectra were not computed with 50 % overlap; cannot correct them")
            for k in chans:
                psd[k][todo] = sp.psd[k]
            done[todo] = True
        return psd[c]

    def phasors(self, runs: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
        """Complex amplitudes (len(runs), L, 6) of every channel at frequencies ``f_hz`` (len(runs), L), Hz:
        X = 2·Σ w x e^{−2πj f t}/Σ w over the whole run (the spectra's window), so x(t) ≈ Re(X e^{2πj f t});
        NaN for a channel the run lacks.  Kept on the context per column (a line's frequency at every run): the
        columns not yet known, each once, are computed in one pass over the records -- the runs of one record length
        and channel set transformed together (:func:`rwadist.dft.windowed_dfts`, whose sums at a frequency do not
        depend on the others asked with it; chunks of :data:`PHASOR_CHUNK_SAMPLES` samples; the windowed signals are
        not kept: a long test's would double its memory)."""
        f_hz = np.asarray(f_hz, dtype=float).reshape(runs.size, -1)
        cols = [np.ascontiguousarray(f_hz[:, j:j + 1]) for j in range(f_hz.shape[1])]
        keys = [("phasors", runs.tobytes(), col.tobytes()) for col in cols]
        todo = list(dict.fromkeys(k for k in keys if k not in self._memo))        # each missing column once
        if todo:
            first = {k: keys.index(k) for k in todo}
            out = self.transforms(runs, np.column_stack([cols[first[k]] for k in todo]))
            for i, k in enumerate(todo):
                col = out[:, i:i + 1].copy()
                col.flags.writeable = False
                self._memo[k] = col
        return np.concatenate([self._memo[k] for k in keys], axis=1) if keys else \
            np.full((runs.size, 0, len(CHANNELS)), np.nan + 0j)

    def transforms(self, runs: np.ndarray, f_hz: np.ndarray, channels: tuple = CHANNELS) -> np.ndarray:
        """The numbers of :meth:`phasors` (len(runs), L, len(channels)) of ``channels`` only, not kept: the runs of
        one record length and channel set transformed together (:func:`rwadist.dft.windowed_dfts`), in chunks of
        :data:`PHASOR_CHUNK_SAMPLES` samples.  A scan over a grid of frequencies read once (a line's drift) asks it for
        the channels it reads: a third of the work of every channel's phasors for a radial pair."""
        from ..dft import blocked_records, run_window, windowed_dfts

        f_hz = np.asarray(f_hz, dtype=float).reshape(runs.size, -1)
        out = np.full((runs.size, f_hz.shape[1], len(channels)), np.nan + 0j)
        groups: dict[tuple, list[int]] = {}
        for i, r in enumerate(runs):
            run = self.test.runs[r]
            if have := tuple(j for j, c in enumerate(channels) if run.usable(c)):    # none (frozen there): NaN
                groups.setdefault((run.n_samples, run.sample_rate, have), []).append(i)
        for (n, fs, have), rows_all in groups.items():
            w, wsum, _ = run_window(self.sp.window, n)
            step = max(1, PHASOR_CHUNK_SAMPLES // (n * max(len(have), 1)))
            for s in range(0, len(rows_all), step):
                rows = np.asarray(rows_all[s:s + step])
                x = blocked_records([[self.test.runs[runs[i]].signals[channels[j]] for j in have] for i in rows], w)
                out[rows[:, None], :, np.asarray(have, dtype=int)[None, :]] = \
                    (2.0 * windowed_dfts(x, fs, f_hz[rows]) / wsum).transpose(0, 2, 1)
        return out

    def prefetch_phasors(self, runs: np.ndarray, f_hz: np.ndarray) -> None:
        """:meth:`phasors` of every column of ``f_hz`` (len(runs), L) Hz computed in one pass over the records and kept:
        a family that measures its lines one at a time reads them without transforming every record again per line."""
        self.phasors(runs, f_hz)

    def data_floor(self, state: State, c: str) -> np.ndarray:
        """Block floor (n_runs, n_f) of channel ``c`` as the state reads its data (:meth:`data`): a torque
        channel corrected for the state's load-cell offset has its own (the correction moves noise)."""
        if state.load_cell_offset is None or c not in TORQUE_CHANNELS:
            return self.floor[c]
        key = ("data_floor", tuple(float(x) for x in state.load_cell_offset), c)
        if key not in self._memo:
            psd = self.data(state, c)
            fl = np.full_like(psd, np.nan)
            ok = np.isfinite(psd[:, 0])
            fl[ok] = block_floor(psd[ok], dof=self.dof)
            self._memo[key] = fl
        return self._memo[key]

    def _floor(self, c):
        psd = self.sp.psd[c]
        fl = np.full_like(psd, np.nan)
        ok = np.isfinite(psd[:, 0])
        fl[ok] = block_floor(psd[ok], dof=self.dof)
        return fl

    def omega_ref(self) -> float:
        """Reference speed of the amplitude and floor laws, rad/s: the median of the runs' |Ω| (computed once)."""
        if "omega_ref" not in self._memo:
            self._memo["omega_ref"] = float(np.median(self.omega[self.runs]))
        return self._memo["omega_ref"]

    # ---- predictions
    def line_psd(self, h: float, amp: np.ndarray, runs: np.ndarray) -> np.ndarray:
        """PSD (len(runs), n_f) of one line h at amplitudes ``amp`` (per run)."""
        return self.psd_at(h * self.omega[runs] / (2 * np.pi), amp**2 / 2.0)

    def kernel_at(self, dlt: np.ndarray) -> np.ndarray:
        """The line kernel K(δ) = |W(δ)|²/(f_s·Σw²) (1/Hz) at offsets ``dlt`` (bins from the line, any shape).

        Periodic Hann window: |W|² of its closed-form transform (:func:`rwadist.dft.hann_transform`) tabulated
        every 1/:data:`~rwadist.diagnose.metric.HANN_OVERSAMPLE` bin (:func:`~rwadist.diagnose.metric.hann_tables`)
        and read by 4-point Lagrange interpolation: within 2e-10 of the peak (the closed form at every point costs ten times as much, and psd_at is the
        search's inner loop).  Other windows: the table of :func:`line_kernel`, linearly interpolated.  Read at
        the table's nearest 1/64-bin point (as before), a line's power was misplaced by up to 1/128 bin: a line
        just beside a band edge sent ~0.4 % of its peak bin's power to the wrong band, 50-100 noise standard
        deviations for a line 80 dB over 1 % noise (most of the true model's error on modes-on data, issue 14)."""
        if self._hann:
            L = self.sp.nperseg
            return read_table(hann_tables(L)[1], dlt) / (self.sp.sample_rate * 3.0 * L / 8.0)   # Σw² = 3L/8
        x = np.clip((dlt - self.delta[0]) * self.osmp, 0.0, self.delta.size - 1.0)
        i0 = np.minimum(x.astype(int), self.delta.size - 2)
        frac = x - i0
        return self.kernel[i0] * (1.0 - frac) + self.kernel[i0 + 1] * frac

    def psd_at(self, f_hz: np.ndarray, power: np.ndarray, bins: np.ndarray | None = None, kernel=None) -> np.ndarray:
        """PSD (n_runs, n_f) of lines at frequencies ``f_hz`` (n_runs,) or (n_runs, n) Hz with mean squares
        ``power`` (same shape, unit²) through the line kernel; a line at negative frequency (a lower
        sideband below 0 Hz) folds to |f|.  ``bins``: (n_runs, n_b) bin indices (in range): the PSD at those
        bins only, (n_runs, n_b) -- the same kernel values, without the whole grid.  ``kernel``: another kernel than
        :meth:`kernel_at` (offsets in bins -> 1/Hz, within ±KERNEL_HALF), e.g. a chirp's."""
        kernel_at = self.kernel_at if kernel is None else kernel
        f_hz = np.asarray(f_hz, dtype=float)
        power = np.broadcast_to(np.asarray(power, dtype=float), f_hz.shape)
        if f_hz.ndim == 1:
            f_hz, power = f_hz[:, None], power[:, None]
        n_runs, n_l = f_hz.shape
        if bins is not None:
            pos = np.abs(f_hz) / self.df                                           # (n_runs, n_l)
            dlt = bins[:, None, :] - pos[:, :, None]                               # (n_runs, n_l, n_b)
            near = np.abs(bins[:, None, :] - np.rint(pos).astype(int)[:, :, None]) <= KERNEL_HALF
            return np.sum(np.where(near, power[:, :, None] * kernel_at(dlt), 0.0), axis=1)
        out = np.zeros((n_runs, self.f.size))
        pos = (np.abs(f_hz) / self.df).ravel()                           # fractional bin
        k0 = np.rint(pos).astype(int)
        offs = np.arange(-KERNEL_HALF, KERNEL_HALF + 1)
        k = k0[:, None] + offs
        dlt = k - pos[:, None]                                         # bin minus line, bins
        val = power.ravel()[:, None] * kernel_at(dlt)
        ok = (k >= 0) & (k < self.f.size)
        rows = np.broadcast_to(np.repeat(np.arange(n_runs), n_l)[:, None], k.shape)
        # a flat bincount adds in the same order as np.add.at, several times faster
        out += np.bincount(rows[ok] * self.f.size + k[ok], weights=val[ok],
                           minlength=n_runs * self.f.size).reshape(n_runs, self.f.size)
        return out

    def ripple_powers(self, state: State, h: float, law, runs: np.ndarray, c: str | None = None):
        """(k, P) of the state's speed ripple for a line h: sideband orders k (2K+1,) and their power
        fractions P (len(runs), 2K+1) (:func:`ripple_sideband_powers`), or None without a ripple.  ``c``: the channel,
        whose line h = 1 of a radial direction (C·Ω², no law) is an imbalance, also pushed along the rim by the
        ripple's Ω̇ (τ = ΔΩ·2πf_r/Ω0², :func:`rwadist.extended_ripple.ripple_coefficients`)."""
        if state.speed_modulation is None:
            return None
        d_ref, f_r, w_ref, q = state.speed_modulation
        w = self.omega[runs]
        dw = d_ref * (w / w_ref) ** q
        p_amp = 2.0 if law is None else law[2]
        imbalance = c is not None and CHANNEL_DIRECTION.get(c) in RIPPLE_IMBALANCE_DIRECTIONS and abs(h - 1.0) < 1e-6 \
            and law is None
        tau = dw * 2 * np.pi * f_r / np.maximum(w, 1e-12) ** 2 if imbalance else 0.0
        return ripple_sideband_powers(h * dw / (2 * np.pi * f_r), dw / np.maximum(w, 1e-12), p_amp, tau=tau)

    def _ripple_gains(self, state: State, c: str, h: float, shift: float, f: np.ndarray, k: np.ndarray,
                      runs: np.ndarray) -> np.ndarray:
        """(len(runs), len(k)) amplitude of the ripple's order k of the component ``shift`` (at ``f`` Hz) of line h
        in channel ``c`` relative to the component itself: its orders up to RIPPLE_OWN_GAIN_ORDERS go through the
        suspension modes (:meth:`sideband_gain`) and the fixed resonances at their own frequency f + k·f_r (5-Hz
        sidebands beside a rocking whirl of ζ 0.02 at 95 Hz differ from the carrier's gain by factors); the higher
        orders, which carry (β/2)^{2|k|}/(|k|!)² of the line's power, take the component's."""
        f_r = float(state.speed_modulation[1]) if state.speed_modulation is not None else 0.0
        out = np.ones((runs.size, k.size))
        g0 = self.sideband_gain(state, c, h, shift, runs)
        r0 = self.gain(state, c, f) if state.resonances else 1.0
        for j in np.flatnonzero((np.abs(k) <= RIPPLE_OWN_GAIN_ORDERS) & (k != 0)):
            g = self.sideband_gain(state, c, h, shift + k[j] * f_r, runs) / np.where(g0 > 0, g0, 1.0)
            if state.resonances:
                g = g * self.gain(state, c, f + k[j] * f_r) / np.where(r0 > 0, r0, 1.0)
            out[:, j] = g
        return out

    def gain(self, state: State, c: str, f_hz) -> np.ndarray:
        """|H| of the state's fixed resonances acting on channel ``c`` at line frequencies ``f_hz`` (Hz)."""
        return np.abs(state.channel_gain(c, f_hz))

    def channel_lines(self, state: State, c: str, runs: np.ndarray) -> list:
        """[(h, law, a, g)] of every line acting on channel ``c``: harmonic number, amplitude law or None, the
        line's amplitude a (unit, one per run of ``runs``, before the fixed resonances) and its modal gain g = a / the
        free load amplitude of the channel's direction at h.

        Empirical base: the state's harmonics, a = C·Ω² (or the law), g = 1.  Extended base (``state.ext`` set):
        the lines of :meth:`State.ext_lines` through :func:`rwadist.extended.steady_lines` (suspension modes,
        gyroscopic whirl, rotation sense, lever arm), lines of one h acting on the channel merged into one entry
        of power Σ|A|²/2 (independent phases: the expected power; a co/counter pair of one h has a cross term
        of zero mean that cancels between x and y).  Cached on the state per set of runs, and on the context per
        content (the extended parameters, the lines and the runs: every hypothesis that leaves them alone -- a
        floor, a resonance, a sideband -- reads them again; read-only arrays)."""
        if state.ext is None:
            return [(h, law, self.amplitude(C, law, runs), np.ones(runs.size)) for h, C, law in state.lines(c)]
        return self._ext_lines_of(state, runs)[0].get(c, [])

    def line_mixing(self, state: State, c: str, runs: np.ndarray) -> list:
        """Per entry of :meth:`channel_lines` of channel ``c``: the share of its power squared that the cross terms of
        its parts carry in variance, Σ_{i<j} 2·P_i·P_j / (Σ P)² per run (parts of one h acting on the channel with
        independent phases: a co/counter pair of one radial line, whose cross term 2·√(P₊P₋)·cos Δφ is constant over a
        run's Welch segments, of zero mean and variance 2·P₊·P₋ over the runs' phases); on the empirical base
        :meth:`State.mixing_shares` (0 for a line of one part)."""
        if state.ext is None:
            return [np.full(runs.size, share) for share in state.mixing_shares(c)]
        return self._ext_lines_of(state, runs)[1].get(c, [])

    def _ext_lines_of(self, state: State, runs: np.ndarray) -> tuple:
        """(lines, mixing) by channel of :meth:`channel_lines` and :meth:`line_mixing` on the extended base, cached."""
        key = ("lines", runs.tobytes())
        if key not in state._cache:
            lines = tuple(state.ext_lines())
            content = ("ext_lines", state.ext, lines, runs.tobytes())
            every = ("ext_lines", state.ext, lines, self.runs.tobytes())
            if content not in self._memo and every in self._memo and (pos := self.run_rows(runs)) is not None:
                self._memo[content] = rows_of_lines(self._memo[every], pos)     # each run's lines are its own
            if content not in self._memo:
                self._memo[content] = self._ext_lines(state, self.omega[runs], lines)
            state._cache[key] = self._memo[content]
        return state._cache[key]

    def _ext_lines(self, state: State, w: np.ndarray, lines, omega_dot=None) -> tuple:
        """(:meth:`channel_lines`, :meth:`line_mixing`) of every channel on the extended base at the speeds ``w``
        (rad/s, 1-D), computed (``lines``: ``state.ext_lines()``); at instants of a sweep whose dΩ/dt is ``omega_dot``
        (rad/s², as ``w``) when given (:func:`rwadist.extended.steady_lines`)."""
        from .. import extended as ext

        if state.ext is None:
            raise ValueError("extended lines asked of a state on the empirical base (ext is None)")
        out: dict[str, list[tuple]]         # channel -> (h, law, amplitude, modal gain) per line
        out = {c: [] for c in self.channels}
        mixing: dict[str, list[np.ndarray]] = {c: [] for c in self.channels}
        if not lines:
            return out, mixing
        _, A = ext.steady_lines(state.ext, lines, w, omega_dot=omega_dot)    # (S, L, 6)
        P = np.abs(A) ** 2                                             # 2 × mean square
        hs = np.array([ln.h for ln in lines])
        free = np.array([ln.amplitude(w) for ln in lines]).T           # (S, L) load amplitudes
        groups: list[list[int]] = []
        for j in np.argsort(hs, kind="stable"):
            if groups and abs(hs[j] - hs[groups[-1][0]]) < ext.LAW_H_TOL:
                groups[-1].append(j)
            else:
                groups.append([j])
        for c in self.channels:
            k = CHANNELS.index(c)
            d = CHANNEL_DIRECTION[c]
            for g in groups:
                p = P[:, g, k].sum(1)
                if not np.any(p > 0):
                    continue
                own = [j for j in g if lines[j].direction == d]
                a_free = np.sqrt(np.sum(free[:, own] ** 2, axis=1)) if own else np.zeros(w.size)
                a = np.sqrt(p)
                gain = np.where(a_free > 0, a / np.where(a_free > 0, a_free, 1.0), 1.0)
                a.flags.writeable = gain.flags.writeable = False          # shared by the states of one content
                j0 = own[0] if own else g[0]
                out[c].append((float(lines[j0].h), lines[j0].law, a, gain))
                mix = np.where(p > 0, 1.0 - np.sum(P[:, g, k] ** 2, axis=1) / np.where(p > 0, p, 1.0) ** 2, 0.0)
                mix.flags.writeable = False
                mixing[c].append(mix)
        return out, mixing

    def unit_gain(self, state: State, c: str, direction: str, h: float, sense: str, runs: np.ndarray) -> np.ndarray:
        """|amplitude in channel ``c``| per unit load amplitude of a line (direction, h, sense) through the state's
        suspension modes (:func:`rwadist.extended.steady_lines`), per run; ones on the empirical base."""
        if state.ext is None:
            return np.ones(runs.size)
        from .. import extended as ext

        w = self.omega[runs]
        _, A = ext.steady_lines(state.ext, [ext.Line(direction, float(h), 1.0, sense)], w)
        return np.abs(A[:, 0, CHANNELS.index(c)]) / np.maximum(w**2, 1e-300)

    def sideband_gain(self, state: State, c: str, h: float, shift: float, runs: np.ndarray) -> np.ndarray:
        """Amplitude in channel ``c`` of a sideband ``shift`` Hz from the line h, relative to the carrier's (the
        depth's m/2 apart), per run: on the extended base the carrier's lines of the channel's direction sent
        through the suspension modes at the sideband's own frequency and whirl rate
        (:class:`rwadist.extended.Line` ``f_offset``), against the carrier's own; ones on the empirical base.
        Near a mode the two differ (corner-high, h = 2 at 200 Hz beside radial translation at 227 Hz: 7-Hz
        sidebands 0.93 and 1.07 of the carrier's transfer).  Cached on the state."""
        if state.ext is None or shift == 0.0:
            return np.ones(runs.size)
        key = ("sideband_gain", c, round(h, 9), float(shift), runs.tobytes())
        if key not in state._cache:
            from dataclasses import replace

            from .. import extended as ext

            d = CHANNEL_DIRECTION[c]
            own = [ln for ln in state.ext_lines() if ln.direction == d and abs(ln.h - h) < ext.LAW_H_TOL]
            out = np.ones(runs.size)
            if own:
                w, k = self.omega[runs], CHANNELS.index(c)
                _, A0 = ext.steady_lines(state.ext, own, w)
                _, A1 = ext.steady_lines(state.ext, [replace(ln, f_offset=ln.f_offset + shift) for ln in own], w)
                p0, p1 = (np.sum(np.abs(A[:, :, k]) ** 2, axis=1) for A in (A0, A1))
                out = np.where(p0 > 0, np.sqrt(p1 / np.where(p0 > 0, p0, 1.0)), 1.0)
            state._cache[key] = out
        return state._cache[key]

    def modal_gain(self, state: State, c: str, h: float, runs: np.ndarray) -> np.ndarray:
        """Modal gain g of the line h of channel ``c`` (:meth:`channel_lines`); for a line the state lacks, that
        of a co-rotating line of the channel's direction (a wheel disturbance goes through the modes)."""
        if state.ext is None:
            return np.ones(runs.size)
        from .. import extended as ext

        for hh, _, _, g in self.channel_lines(state, c, runs):
            if abs(hh - h) < ext.LAW_H_TOL:
                return g
        return self.unit_gain(state, c, CHANNEL_DIRECTION[c], h, "co", runs)

    def amplitude(self, C, law, runs):
        w = self.omega[runs]
        if law is None:
            return C * w**2
        a_ref, w_ref, p = law
        return a_ref * (w / w_ref) ** p

    def floor_psd(self, state: State, c: str, runs: np.ndarray) -> np.ndarray:
        key = ("floor", c, runs.tobytes())          # kept read-only on the state, as its prediction
        if key not in state._cache:
            out = np.broadcast_to(state.noise[c], (runs.size, self.f.size)).copy()
            if c in state.floors:
                ref, w_ref, p = state.floors[c]
                out += ref[None, :] * (self.omega[runs][:, None] / w_ref) ** p
            out.flags.writeable = False
            state._cache[key] = out
        return state._cache[key]

    def predict(self, state: State, c: str, runs: np.ndarray, skip=None, only=None) -> np.ndarray:
        """Expected PSD of channel ``c`` on ``runs``; ``skip`` = h of a line to leave out (with its
        sidebands); ``only`` = h of the one line to predict (with its sidebands; no noise floor).  A line's
        components (carrier and amplitude-modulation sidebands, :meth:`State.line_components`) are each multiplied by
        the resonance gain at their own frequency and, under a speed modulation, spread over f + k·f_ripple with
        the power fractions of :meth:`ripple_powers`.

        The whole prediction (no ``skip``, no ``only``) is computed once per (channel, runs) and kept on the
        state, read-only (a state is not changed once made: an effect's ``apply`` returns a new one, and every
        family asks for the same state's prediction)."""
        if skip is None and only is None:
            key = ("predict", c, runs.tobytes())
            if key not in state._cache:
                # under a spin smear or a speed ripple the lines' spreading is set by the runs asked together
                kept = self.rows_of_every_run(state, "predict", c, runs) \
                    if state.smear is None and state.speed_modulation is None else None
                if kept is not None:
                    whole, pos = kept
                    full = whole[pos]           # each run's prediction is its own: the rows of every run's
                else:
                    full = self._predict(state, c, runs, None, None)
                full.flags.writeable = False
                state._cache[key] = full
            return state._cache[key]
        return self._predict(state, c, runs, skip, only)

    def _predict(self, state: State, c: str, runs: np.ndarray, skip, only, bins=None) -> np.ndarray:
        """:meth:`predict` computed; ``bins`` (with ``only``): at those bins only (:meth:`psd_at`)."""
        if only is None:
            out = self.floor_psd(state, c, runs).copy()
        else:
            out = np.zeros((runs.size, self.f.size) if bins is None else bins.shape)
        plain_f, plain_p = [], []           # lines without smear or ripple: one kernel pass for all of them
        for h, law, amp, _ in self.channel_lines(state, c, runs):
            if skip is not None and abs(h - skip) < 1e-9:
                continue
            if only is not None and abs(h - only) >= 1e-9:
                continue
            f0 = h * self.omega[runs] / (2 * np.pi)
            rip = self.ripple_powers(state, h, law, runs, c)
            for shift, rel in state.line_components(c, h):
                f = f0 + shift
                a = amp * rel * self.sideband_gain(state, c, h, shift, runs)
                if state.resonances:
                    a = a * self.gain(state, c, f)
                if state.smear is not None:
                    du, wt, kern = self.smear_offsets(state, h, runs)
                    if state.ext is not None:
                        wt = wt * self.smear_transfer(state, c, h, runs)
                    out += self.psd_at(f[:, None] + du, (a**2 / 2.0)[:, None] * wt, bins, kernel=kern)
                elif rip is None or state.speed_modulation is None:       # a ripple's powers come with one
                    plain_f.append(f)
                    plain_p.append(a**2 / 2.0)
                else:
                    k, P = rip
                    f_r = state.speed_modulation[1]
                    P = P * self._ripple_gains(state, c, h, shift, f, k, runs) ** 2
                    out += self.psd_at(f[:, None] + k[None, :] * f_r, (a**2 / 2.0)[:, None] * P, bins)
        if plain_f:
            out += self.psd_at(np.column_stack(plain_f), np.column_stack(plain_p), bins)
        return out

    def can_pass(self, state: State, chans, bands: np.ndarray | None = None) -> bool:
        """False when no effect that changes the prediction of ``chans`` only (and there only in ``bands``, (len(held
        runs), n_bands) bool: the bands its lines can reach) and is judged by the error metric can pass the search
        step's ``min_gain`` rule: its held-out gain is the drop of misplaced power there, at most the state's own
        misplaced power there (the new state's is ≥ 0), and that is below ``min_gain`` of the held-out misplaced power
        on every channel.  A family skips such a fit (nothing it could propose there would be taken).  True outside a
        search step, for another state than the step's, and for an effect that brings its own held-out evidence (it
        must not ask)."""
        if self.step is None or self.step[0] is not state:
            return True
        _, errors, min_gain = self.step
        chans = [c for c in chans if c in self.channels]
        e_all = float(errors(None)[0].sum())
        if not chans or not (min_gain > 0 and e_all > 0):
            return True
        e0, _, parts = errors(chans)
        if bands is None:
            here = float(e0.sum())
        else:
            # a run without the channel's data (a NaN row) adds nothing, as in the judge
            here = sum(float(np.sum(np.nan_to_num(np.maximum(np.abs(parts[c][0]) - NOISE_Z * parts[c][1], 0.0),
                                                  nan=0.0)[bands])) for c in chans)
        # a hair over the bound: the band sums and the run sums round differently
        return here * (1.0 + 1e-9) >= min_gain * e_all

    def reach_bands(self, f_lo: np.ndarray, f_hi: np.ndarray) -> np.ndarray:
        """(len(f_lo), n_bands) bool: the metric's bands a line between ``f_lo`` and ``f_hi`` Hz (per held-out run) can
        change -- its kernel reaches ±KERNEL_HALF bins, its band one more (a band is BAND_BINS bins from k_lo)."""
        lo = np.floor(np.asarray(f_lo) / self.df) - KERNEL_HALF - 1
        hi = np.ceil(np.asarray(f_hi) / self.df) + KERNEL_HALF + 1
        first = self.k_lo + np.arange(self.n_bands) * BAND_BINS
        last = first + BAND_BINS - 1
        return (last[None, :] >= lo[:, None]) & (first[None, :] <= hi[:, None])

    def reuse(self, family: str, state: State, chans, runs: np.ndarray, compute, part: str = "") -> list:
        """The effects ``compute()`` proposes (a list) from channels ``chans`` of ``runs`` alone, kept on the context
        under the state's :meth:`content_key` of those channels and the family's own effects already in the state
        (``family`` is their ``kind``: one that leaves the prediction as it was, a counter-rotating part of a line no
        mode tells apart, still changes what the family proposes): a later search step whose accepted effect touched
        other channels only gets them again, as copies, instead of fitting anew.  ``part``: which of the family's
        searches (one family may propose from several)."""
        from dataclasses import replace

        own = tuple(repr(e.params()) for e in state.effects if getattr(e, "kind", None) == family)
        # and what a fit reads besides the prediction: the extended parameters (a line's modal gain, also where the
        # channel has no line yet), the directions' harmonics (a counter-rotating split leaves a radial force's
        # prediction as it was) and the spans of lines the model's fit could not measure apart
        dirs = sorted({CHANNEL_DIRECTION[c] for c in chans})
        harmonics = tuple((d, x.h, x.C, getattr(x, "sense", None)) for d in dirs for x in state.model.harmonics(d))
        spans = repr(((getattr(state.model, "analytical", None) or {}).get("fit") or {}).get("unresolved_lines"))
        key = ("reuse", family, part, tuple(chans), np.asarray(runs).tobytes(), own, state.ext, harmonics, spans,
               self.content_key(state, chans, runs))
        if key not in self._memo:
            self._memo[key] = compute()
        return [replace(e) for e in self._memo[key]]

    def content_key(self, state: State, chans, runs: np.ndarray) -> bytes:
        """A digest of everything ``state`` predicts and reads on channels ``chans`` and ``runs``: per channel the
        data it reads (the load-cell offset of a corrected torque), the whole prediction, the noise floor, every
        line (h, law, amplitude, modal gain) with its sidebands, and the fixed resonances acting on it; with the
        state's speed ripple and spin smear.  Two states with the same digest measure and predict every line of
        those channels alike, so a fit made from them alone (e.g. ``fixed_resonance``) can be reused by a later
        search step whose accepted effect touched other channels only."""
        import hashlib

        runs = np.asarray(runs)
        hsh = hashlib.blake2b(digest_size=20)
        hsh.update(repr((runs.tobytes(), state.speed_modulation, state.smear)).encode())
        for c in chans:
            hsh.update(self._channel_digest(state, c, runs))
        return hsh.digest()

    def _channel_digest(self, state: State, c: str, runs: np.ndarray) -> bytes:
        """The part of :meth:`content_key` of one channel, kept on the state (read-only, as its prediction): the same
        state is keyed for each direction's channels and for all of them."""
        import hashlib

        key = ("content_digest", c, runs.tobytes())
        if key not in state._cache:
            hsh = hashlib.blake2b(digest_size=20)
            coupling = tuple(float(x) for x in state.load_cell_offset) if state.load_cell_offset is not None \
                and c in TORQUE_CHANNELS else None
            res = [r[:3] + tuple(r[4:]) for r in state.resonances if c in r[3]]
            hsh.update(repr((c, coupling, res)).encode())
            hsh.update(np.ascontiguousarray(self.predict(state, c, runs)).tobytes())
            hsh.update(np.ascontiguousarray(self.floor_psd(state, c, runs)).tobytes())
            for h, law, amp, g in self.channel_lines(state, c, runs):
                hsh.update(repr((h, law, state.line_components(c, h))).encode())
                hsh.update(np.ascontiguousarray(amp, dtype=float).tobytes())
                hsh.update(np.ascontiguousarray(g, dtype=float).tobytes())
            state._cache[key] = hsh.digest()
        return state._cache[key]

    def run_durations(self, runs: np.ndarray) -> np.ndarray:
        """Length of each run's record, s: from the time series when known, else from the Welch
        segments (50 % overlap: (n_segments + 1)·nperseg/2 samples)."""
        if self.test is not None:
            return np.array([self.test.runs[r].n_samples / self.test.runs[r].sample_rate for r in runs])
        n = np.asarray(self.sp.n_segments, dtype=float)[runs]
        return (n + 1.0) * self.sp.nperseg / 2.0 / self.sp.sample_rate

    def smear_offsets(self, state: State, h: float, runs: np.ndarray) -> tuple:
        """(offsets Hz, weights) (len(runs), K) of a line h on each run's K Welch segments under the state's spin
        acceleration, and its kernel on one segment (a function of offsets in bins, 1/Hz): a chirp across every segment
        (:mod:`rwadist.diagnose.smear`)."""
        if state.smear is None:
            raise ValueError("smear_offsets: the state has no spin acceleration (smear)")
        fs, L = self.sp.sample_rate, self.sp.nperseg
        n = np.rint(self.run_durations(runs) * fs)
        du, wt = smear.segment_offsets(state.smear, h, self.omega[runs], n, np.asarray(self.sp.n_segments)[runs], L, fs)
        return du, wt, smear.chirp_kernel(L, fs, self.sp.window, smear.segment_chirp(state.smear, h, L, fs))

    def smear_transfer(self, state: State, c: str, h: float, runs: np.ndarray) -> np.ndarray:
        """(len(runs), K) on the extended base: the line h's power in channel ``c`` on each Welch segment under the
        state's spin acceleration over its power at the run's mean speed, less a C·Ω² line's (Ω(τ_k)/Ω)⁴: the
        modes' response to the line sweeping through them over the segment (:func:`rwadist.diagnose.smear.
        segment_transfer`; docs/diagnose.md, ``spin_acceleration``); 1 where it has no power.  Cached."""
        key = ("smear_transfer", c, round(float(h), 9), runs.tobytes())
        if key not in state._cache:
            out = smear.segment_transfer(self, state, c, h, runs)
            out.flags.writeable = False
            state._cache[key] = out
        return state._cache[key]

    def band_centres(self) -> np.ndarray:
        return self.f[self.k_lo + BAND_BINS * np.arange(self.n_bands) + BAND_BINS // 2] - 0.5 * self.df

    def offline_bands(self, state: State, c: str, runs: np.ndarray):
        """Mean PSD of the data less the model's lines (their kernel skirts) per band, over the bins away
        from every line (model lines ±LINE_HALF bins and residual peaks above a 1e-4 false-alarm
        threshold ±2 bins): (value unit²/Hz, bins used) per run and band; kept on the state, read-only."""
        from scipy import stats

        key = ("offline_bands", c, runs.tobytes())
        if key in state._cache:
            return state._cache[key]
        P = self.predict(state, c, runs)
        D = self.data(state, c)[runs] - (P - self.floor_psd(state, c, runs))     # data less the model's lines
        mask = np.zeros(D.shape, bool)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        rows = np.arange(runs.size)[:, None]
        for h, _, _, _ in self.channel_lines(state, c, runs):
            k = np.clip(np.rint(h * self.omega[runs] / (2 * np.pi) / self.df).astype(int)[:, None] + offs,
                        0, self.f.size - 1)
            mask[rows, k] = True
            if state.smear is not None:     # the whole range a smeared line sweeps, ±LINE_HALF bins
                half = h * state.smear * self.run_durations(runs) / (4 * np.pi) / self.df + LINE_HALF
                kc = h * self.omega[runs] / (2 * np.pi) / self.df
                kk = np.arange(self.f.size)[None, :]
                mask |= (kk >= (kc - half)[:, None]) & (kk <= (kc + half)[:, None])
        if state.modulations or state.speed_modulation is not None:
            # the model's sideband and ripple lines too, where their power is above a tenth of the noise
            # power in their window
            noise = self.floor_psd(state, c, runs)
            for h, law, amp, _ in self.channel_lines(state, c, runs):
                f0 = h * self.omega[runs] / (2 * np.pi)
                rip = self.ripple_powers(state, h, law, runs) or (np.zeros(1), np.ones((runs.size, 1)))
                for shift, rel in state.line_components(c, h):
                    for j, kk in enumerate(rip[0]):
                        if shift == 0.0 and kk == 0:
                            continue
                        f = np.abs(f0 + shift + kk * (state.speed_modulation[1] if state.speed_modulation else 0.0))
                        k = np.clip(np.rint(f / self.df).astype(int)[:, None] + offs, 0, self.f.size - 1)
                        pw = (amp * rel) ** 2 / 2 * rip[1][:, j]
                        big = pw > 0.1 * noise[rows, k].sum(1) * self.df
                        mask[rows, k] |= big[:, None]
        z = D / np.maximum(self.data_floor(state, c)[runs], 1e-300) - 1.0     # against the run's own block floor
        thr = stats.chi2.isf(1e-4, self.dof) / self.dof - 1.0
        peak = z > thr
        for j in (-2, -1, 1, 2):
            peak |= np.roll(z > thr, j, axis=1)
        mask |= peak
        lo, n = self.k_lo, self.n_bands * BAND_BINS
        keep = ~mask[:, lo:lo + n].reshape(runs.size, self.n_bands, BAND_BINS)
        vals = D[:, lo:lo + n].reshape(runs.size, self.n_bands, BAND_BINS)
        cnt = keep.sum(-1)
        out = (np.where(cnt > 0, bin_sums(vals * keep) / np.maximum(cnt, 1), 0.0), cnt.astype(float))
        for a in out:
            a.flags.writeable = False
        state._cache[key] = out
        return out

    def measure_line(self, state: State, c: str, h: float, runs: np.ndarray, skip=None):
        """Amplitude (unit) of a line h in the data of ``runs`` less everything else the state
        predicts (other lines, floors); NaN where the line is out of band or not above noise."""
        pos = h * self.omega[runs] / (2 * np.pi) / self.df
        k0 = np.rint(pos).astype(int)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        inband = (k0 - LINE_HALF >= self.k_lo) & (k0 + LINE_HALF <= self.k_hi)
        k = np.clip(k0[:, None] + offs, 0, self.f.size - 1)
        rows = np.arange(runs.size)[:, None]
        # the residual in the line's window only: the data less the state's whole prediction (computed once) plus
        # the skipped line alone at those bins -- a line measured against every other costs a few bins of one line
        R = self.data(state, c, runs)[runs[:, None], k] - self.predict(state, c, runs)[rows, k]
        if skip is not None:
            R = R + self._predict(state, c, runs, None, skip, bins=k)
        p = R.sum(1) * self.df
        noise = self.floor_psd(state, c, runs)[rows, k].sum(1) * self.df
        # 3 standard deviations of the window's noise power: std of a bin mean·sqrt(2/ν), summed
        # over the window's bins with a factor 2 for the Hann correlation of neighbouring bins
        sig = 3.0 * 2.0 * noise * np.sqrt(2.0 / self.dof) / np.sqrt(2 * LINE_HALF + 1)
        return np.where(inband & (p > sig), np.sqrt(2 * np.maximum(p, 0)), np.nan)

    def measure_lines(self, state: State, c: str, runs: np.ndarray) -> np.ndarray:
        """:meth:`measure_line` of every line h of :meth:`channel_lines` against all the others (``skip=h``), one row
        per line (L, len(runs)): the same numbers, the windows of all lines gathered at once and each line's own PSD
        at its window (:meth:`_predict` with ``only``) computed in one kernel pass.  Under a speed ripple or a spin
        smear, line by line."""
        cl = self.channel_lines(state, c, runs)
        if state.smear is not None or state.speed_modulation is not None or not cl:
            return np.array([self.measure_line(state, c, h, runs, skip=h)
                             for h, _, _, _ in cl]).reshape(len(cl), runs.size)
        hs = np.array([x[0] for x in cl])
        pos = hs[:, None] * self.omega[runs][None, :] / (2 * np.pi) / self.df                  # (L, R)
        k0 = np.rint(pos).astype(int)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        inband = (k0 - LINE_HALF >= self.k_lo) & (k0 + LINE_HALF <= self.k_hi)
        k = np.clip(k0[:, :, None] + offs, 0, self.f.size - 1)                               # (L, R, W)
        rows = np.arange(runs.size)[None, :, None]
        R = self.data(state, c, runs)[runs[None, :, None], k] - self.predict(state, c, runs)[rows, k]
        # each line's own PSD at its window: the components of the lines of its h (as _predict(only=h) collects
        # them, in the same order), padded with powerless ones to a common count
        comps = []
        for h in hs:
            fs, ps = [], []
            for hh, _law, amp, _g in cl:
                if abs(hh - h) >= 1e-9:
                    continue
                f0 = hh * self.omega[runs] / (2 * np.pi)
                for shift, rel in state.line_components(c, hh):
                    f = f0 + shift
                    a = amp * rel
                    if state.resonances:
                        a = a * self.gain(state, c, f)
                    fs.append(f)
                    ps.append(a**2 / 2.0)
            comps.append((fs, ps))
        n = max(len(fs) for fs, _ in comps)
        f_all = np.stack([np.column_stack(fs + [fs[0]] * (n - len(fs))) for fs, _ in comps])        # (L, R, n)
        p_all = np.stack([np.column_stack(ps + [np.zeros(runs.size)] * (n - len(ps))) for _, ps in comps])
        own = self.psd_at(f_all.reshape(-1, n), p_all.reshape(-1, n), bins=k.reshape(-1, k.shape[-1]))
        R = R + (np.zeros(k.shape) + own.reshape(k.shape))
        p = R.sum(-1) * self.df
        noise = self.floor_psd(state, c, runs)[rows, k].sum(-1) * self.df
        sig = 3.0 * 2.0 * noise * np.sqrt(2.0 / self.dof) / np.sqrt(2 * LINE_HALF + 1)
        return np.where(inband & (p > sig), np.sqrt(2 * np.maximum(p, 0)), np.nan)


def initial_state(ctx: Context, model: WheelModel, ext_params=None) -> State:
    """The model with a speed-independent instrument noise per channel: the off-line band means
    (:meth:`Context.offline_bands`) averaged over every run, interpolated between the centres of the
    bands with a positive mean (the median block floor of the data outside them).  ``ext_params``:
    the :class:`rwadist.extended.ExtendedParams` of the extended base, or None (empirical base)."""
    rough = {c: column_nanmedian(ctx.floor[c][ctx.runs]) for c in ctx.channels}
    state = State(copy.deepcopy(model), rough, ext=ext_params)
    return State(state.model, noise_estimate(ctx, state), ext=ext_params)


def noise_estimate(ctx: Context, state: State) -> dict:
    """Instrument noise per channel (unit²/Hz on the grid) as :func:`initial_state` estimates it, the
    model's lines (as ``state`` predicts them, smear included) masked out; ``state.noise`` is the
    fallback outside the bands."""
    noise = {}
    fc = ctx.band_centres()
    for c in ctx.channels:
        ok = ctx.runs[np.isfinite(ctx.sp.psd[c][ctx.runs, 0])]
        y, cnt = ctx.offline_bands(state, c, ok)
        mean = np.sum(y * cnt, 0) / np.maximum(cnt.sum(0), 1)
        # a band whose mean is not positive (the model's line skirts exceed the data there: coherent lines
        # closer than the kernel beat in the Welch estimate) says nothing about the noise: interpolated over
        good = (cnt.sum(0) > 0) & (mean > 0)
        n = np.array(state.noise[c], dtype=float)
        band = (ctx.f >= fc[0]) & (ctx.f <= fc[-1])
        if good.sum() >= 2:
            n[band] = np.interp(ctx.f[band], fc[good], mean[good])
        noise[c] = n
    return noise
