"""``broadband_floor``: a noise-like floor of one channel growing with speed."""
from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ..diagnose.constants import BAND_BINS, FLOOR_EXPONENTS, NOISE_Z
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.state import State
from ..units import CHANNEL_UNIT

#: Standard errors of held-out evidence the floor's growth needs (:meth:`BroadbandFloor.significant`): the
#: search's default k_sigma (:func:`rwadist.diagnose.search.diagnose`).
GROWTH_T = 4.0


def _band_levels(y: np.ndarray, wt: np.ndarray) -> np.ndarray:
    """Each band's mean level over the runs (bands,), unit²/Hz: the off-line band means ``y`` weighted by their bins
    ``wt`` ((runs, bands) each)."""
    return np.sum(wt * y, 0) / np.maximum(wt.sum(0), 1e-300)


def _floor_law(wt: np.ndarray, y: np.ndarray, x0: np.ndarray) -> tuple:
    """(p, n (bands,), g (bands,)) of the floor law y = n + g·x0^p per band (``y`` (runs, bands) off-line band
    means, unit²/Hz; ``wt`` (runs, bands) bins used; ``x0`` (runs,) Ω/Ω_ref): for each exponent of
    :data:`FLOOR_EXPONENTS`, n and g its weighted 2-parameter least squares per band in three passes of iteratively
    reweighted least squares, each pass weighted by that exponent's own previous expected values; p the exponent whose
    law is the likeliest, the smallest Whittle deviance Σ wt·(y/E + ln E) (a band mean of chi² bins of expected value
    E), over the bands of positive mean level.  The exponents are solved a chunk at once (arrays (P, runs, bands),
    :func:`_floor_laws`): the same numbers as one exponent at a time (tests/test_fast_paths_floor.py).

    Why each exponent its own weights and the likelihood: with the weights of the previous pass's best exponent shared
    by all, that exponent was a fixed point -- weights 1/E² of a steep law forgive the top speeds' scatter, so the
    steep law fitted best under them (family wheel 4, Fz, a floor ∝ Ω³ through the 70-Hz axial mode: p 8 on the fit
    runs and on every run; each exponent by its own weights, p 3 and 3.25; the error of the floor of p 8 on the
    held-out runs 8 % of the misplaced power worse than none).  The weighted SSEs of different weights are not
    comparable; the likelihood is."""
    level = np.maximum(_band_levels(y, wt), 1e-300)
    # x = (Ω/Ω_ref)^p of every exponent at once (P, runs, 1), each power as ``x0[:, None] ** p`` computes it
    xs = np.stack([x0[:, None] ** p for p in FLOOR_EXPONENTS])
    use = np.sum(wt * y, 0) > 0
    n, g, dev = (np.empty((len(FLOOR_EXPONENTS), y.shape[1])), np.empty((len(FLOOR_EXPONENTS), y.shape[1])),
                 np.empty(len(FLOOR_EXPONENTS)))
    # the exponents in chunks of about FLOOR_CHUNK_ELEMENTS (runs x bands) elements, each chunk's arrays in four buffers
    # written in place (each exponent's numbers its own: the same operations in the same order as all at once, kept in
    # cache)
    step = max(1, FLOOR_CHUNK_ELEMENTS // max(y.size, 1))
    bufs = [np.empty((min(step, len(FLOOR_EXPONENTS)),) + y.shape) for _ in range(4)]
    for s in range(0, len(FLOOR_EXPONENTS), step):
        k = min(step, len(FLOOR_EXPONENTS) - s)
        n[s:s + k], g[s:s + k], dev[s:s + k] = _floor_laws(wt, y, xs[s:s + k], level, use, [b[:k] for b in bufs])
    i = int(np.argmin(dev))                 # the first smallest
    return FLOOR_EXPONENTS[i], n[i], g[i]


#: Elements (runs x bands x exponents) of each of :func:`_floor_law`'s four working arrays: its exponents taken in
#: chunks of this size (four arrays of 256 kB stay in a core's cache; all 31 exponents at once of 60 runs x 381 bands,
#: 5.7 MB each, ran from memory at about twice the time)
FLOOR_CHUNK_ELEMENTS = 32768


def _floor_laws(wt, y, xs, level, use, bufs) -> tuple:
    """(n (P, bands), g (P, bands), deviance (P,)) of :func:`_floor_law` for the exponents whose powers are ``xs``
    (P, runs, 1) (``level`` (bands,) the bands' mean levels, ``use`` the bands of positive level; ``bufs`` four arrays
    (P, runs, bands) to work in)."""
    expected, wts, wx, tmp = bufs
    expected[...] = level
    for _ in range(3):
        # weights: bins used / expected value² (a band mean of chi² bins has variance ∝ mean²/bins), each exponent's
        # re-estimated from its own previous pass (iteratively reweighted least squares)
        # (relative to the band's own level, a per-band factor that leaves each band's fit as it is, and held at 1e-3
        # of it as in the deviance below: the likelihood the passes maximise is then the one that judges the exponents.
        # Unheld, a steep law's fit with its noise at 0 weighed its slowest runs up to 1e24 times its fastest and the
        # passes did not reach its likeliest law: a floor ∝ Ω⁸ read as p 3 (12 speeds 0.18-1.75 Ω_ref))
        # (a band of no positive mean level, held at 1e-300, can expect ~1e-150 or more after a pass: its ratio
        # squared overflows to inf and the band weighs 0 -- it holds no floor, and the deviance leaves it out too)
        with np.errstate(over="ignore"):
            np.square(np.maximum(np.divide(expected, level, out=tmp), 1e-3, out=tmp), out=tmp)
        np.divide(wt, tmp, out=wts)
        # weighted 2-parameter least squares per band and exponent: y = n + g·x (sums over the runs, axis 1)
        np.multiply(wts, xs, out=wx)
        s0, s1 = wts.sum(1), wx.sum(1)
        s2 = np.multiply(wx, xs, out=tmp).sum(1)
        t0 = np.multiply(wts, y, out=tmp).sum(1)
        t1 = np.multiply(wx, y, out=tmp).sum(1)
        det = s0 * s2 - s1 * s1
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.maximum(np.where(det > 0, (s0 * t1 - s1 * t0) / det, 0.0), 0.0)
        n = np.where(s0 > 0, np.maximum((t0 - g * s1) / np.maximum(s0, 1e-300), 0.0), 0.0)
        # expected = max(n + g·x, 1e-300)
        np.maximum(np.add(n[:, None, :], np.multiply(g[:, None, :], xs, out=expected), out=expected), 1e-300,
                   out=expected)
    # the Whittle deviance of each exponent's law, over the bands whose mean level is positive (a band at or below the
    # model's line skirts holds no estimate of the floor), its expected value held at 1e-3 of the band's level or more
    # (a law of zero noise where the data are not zero is that unlikely, not infinitely so):
    # Σ wt·(y/E + ln(E/level)), in place in the buffers when every band is used
    lu = level[use]
    if use.all():
        e_use, w_use, y_use, term = np.maximum(expected, 1e-3 * lu, out=expected), wt, y, tmp
    else:
        e_use, w_use, y_use = np.maximum(expected[:, :, use], 1e-3 * lu), wt[:, use], y[:, use]
        term = np.empty(e_use.shape)
    np.divide(y_use, e_use, out=term)
    np.add(term, np.log(np.divide(e_use, lu, out=e_use), out=e_use), out=term)
    return n, g, np.multiply(w_use, term, out=term).sum(axis=(1, 2))


#: False-alarm probability of a residual peak on the whole-run spectrum (a line the state lacks): its bin and
#: RECORD_PEAK_BINS either side are not floor (as :meth:`Context.offline_bands` on the Welch PSD).
RECORD_PEAK_FA = 1e-4
RECORD_PEAK_BINS = 2


def _record_spectra(ctx: Context, c: str, rows) -> list:
    """X = 2·rfft((x − x̄)·w)/Σw of channel ``c`` of each run of ``rows`` (the spectra's window): the runs of one record
    length in one call (scipy.fft: the numbers of numpy.fft's, run by run, in about half the time)."""
    from scipy import fft as sp_fft

    from ..dft import demeaned_windowed, run_window

    out: list = [None] * len(rows)
    groups: dict = {}
    for a, r in enumerate(rows):
        groups.setdefault(ctx.test.runs[r].n_samples, []).append(a)
    for n, idx in groups.items():
        w, wsum, _ = run_window(ctx.sp.window, n)
        xs = demeaned_windowed([ctx.test.runs[rows[a]].signals[c] for a in idx], w)
        X = 2.0 * sp_fft.rfft(xs, axis=-1) / wsum
        for k, a in enumerate(idx):
            out[a] = X[k]
    return out


def record_offline_bands(ctx: Context, state: State, c: str, runs: np.ndarray, need: np.ndarray) -> tuple:
    """(mean PSD unit²/Hz, bins used) per run and band (each (len(runs), n_bands)), and each run's bin width df_rec
    (Hz, (len(runs),)), of channel ``c`` off the lines, on the whole-run spectrum, in the bands ``need``
    ((len(runs), n_bands) bool; 0 bins elsewhere): where a short record's Welch bins are too coarse to leave any bin
    between the lines (2048 samples at 3840 Hz: 7.5-Hz bins, ±LINE_HALF = ±22.5 Hz around each line, every bin of
    26-266 Hz taken at 3000 rpm), the whole run's bins are 4× finer and leave room between them.

    Per run: the Hann-windowed record's DFT X = 2·Σ w x e^{−2πj f t}/Σw (the mean taken off) less the leakage of every
    line the state predicts on the channel (each line's own whole-run phasor times the window's transform, its
    negative-frequency image too: the lines' sidelobes sit far above a floor), at the record bins RECORD_SEP_BINS or
    more from each line and from RECORD_MIN_BINS up; bins of a residual peak (above RECORD_PEAK_FA false alarms on the
    band's median level) and RECORD_PEAK_BINS either side dropped; the PSD |X|²·(Σw)²/(2·fs·Σw²) averaged per band of
    the error metric.  No bin where the time series are unknown or lack the channel.  A whole-run bin has 2
    degrees of freedom (a Welch bin ctx.dof).  Each run's numbers are kept on the context (the data's and the
    lines', the same at every search step)."""
    from ..diagnose.measure import record_dfts, state_line_freqs

    y = np.zeros((runs.size, ctx.n_bands))
    cnt_all = np.zeros((runs.size, ctx.n_bands))
    df_all = np.ones(runs.size)
    if ctx.test is None or not need.any():
        return y, cnt_all, df_all
    j = ctx.channels.index(c)
    lines = state_line_freqs(ctx, state, c, runs)
    keys = [("broadband_floor_record", int(r), j, lines[i].tobytes(), need[i].tobytes()) for i, r in enumerate(runs)]
    todo = [i for i, r in enumerate(runs)
            if need[i].any() and keys[i] not in ctx._memo and ctx.test.runs[int(r)].usable(c)]
    A = (record_dfts(ctx, [int(runs[i]) for i in todo], c, lines[todo]) if lines.shape[1] and todo
         else np.zeros((len(todo), 0), complex))
    spectra = _record_spectra(ctx, c, [int(runs[i]) for i in todo])
    groups: dict = {}                   # the runs to do by (record length, sample rate): one bin grid each
    for a, i in enumerate(todo):
        run = ctx.test.runs[int(runs[i])]
        groups.setdefault((run.n_samples, run.sample_rate), []).append(a)
    for (n, fs), idx in groups.items():
        rows = [todo[a] for a in idx]
        got = _record_bands(ctx, n, fs, np.stack([spectra[a] for a in idx]), need[rows], lines[rows], A[idx])
        for k, i in enumerate(rows):
            ctx._memo[keys[i]] = (got[0][k], got[1][k], fs / n)
    for i in range(runs.size):
        if keys[i] in ctx._memo:
            y[i], cnt_all[i], df_all[i] = ctx._memo[keys[i]]
    return y, cnt_all, df_all


#: Largest (record bins x lines) of the leakage of the lines :func:`_record_bands` evaluates at once (complex; the runs
#: of one bin grid taken in chunks under it)
RECORD_CHUNK_ELEMENTS = 1_000_000


def _record_bands(ctx: Context, n: int, fs: float, X: np.ndarray, need: np.ndarray, lines: np.ndarray,
                  A: np.ndarray) -> tuple:
    """(mean PSD unit²/Hz, bins used), each (runs, n_bands), of :func:`record_offline_bands` for runs of one record
    length ``n`` and sample rate ``fs``: ``X`` (runs, n//2 + 1) their whole-run spectra, ``need`` (runs, n_bands) the
    bands wanted, ``lines`` (runs, L) Hz and ``A`` (runs, L) the lines' whole-run phasors.

    Every run's bins at once (the bins kept of all the runs in one array, run by run, each run's in increasing
    frequency; the runs in chunks of at most :data:`RECORD_CHUNK_ELEMENTS` bins x lines): each bin's numbers are those
    of the run alone -- the same elementwise operations, each bin's leakage summed over its own lines, each band's
    median and sums over its own bins in the same order (tests/test_fast_paths_floor.py)."""
    from ..dft import run_window
    from ..diagnose.measure import hann_transform_ratio
    from ..diagnose.record_residual import RECORD_MIN_BINS, RECORD_SEP_BINS

    nb = ctx.n_bands
    df_rec = fs / n
    _, wsum, w2sum = run_window(ctx.sp.window, n)
    lo_edge = float(ctx.f[ctx.k_lo] - 0.5 * ctx.df)
    band_w = BAND_BINS * ctx.df
    thr = -np.log(RECORD_PEAK_FA)                # |X|² of complex Gaussian noise is exponential: P(> t·mean) = e^{-t}
    f = np.arange(X.shape[1]) * df_rec
    band = np.floor((f - lo_edge) / band_w).astype(int)
    inside = (f >= RECORD_MIN_BINS * df_rec) & (band >= 0) & (band < nb)
    sel = inside[None, :] & need[:, np.where(inside, band, 0)]          # (runs, bins) each run's bins in its bands
    mean, used = np.zeros((X.shape[0], nb)), np.zeros((X.shape[0], nb))
    per_run = sel.sum(1) * max(lines.shape[1], 1)
    start = 0
    while start < X.shape[0]:
        stop = start + max(1, int(np.searchsorted(np.cumsum(per_run[start:]), RECORD_CHUNK_ELEMENTS, side="right")))
        ri, ki = np.nonzero(sel[start:stop])
        ri_abs = ri + start
        fk, Xk, bk = f[ki], X[ri_abs, ki], band[ki]
        keep = np.ones(fk.size, bool)
        if lines.shape[1]:
            fl, Ak = lines[ri_abs], A[ri_abs]
            Xk = Xk - (hann_transform_ratio(n, (fk[:, None] - fl) / df_rec) * Ak
                       + hann_transform_ratio(n, (fk[:, None] + fl) / df_rec) * np.conj(Ak)).sum(1)
            keep = np.all(np.abs(fk[:, None] - fl) >= RECORD_SEP_BINS * df_rec, axis=1)
        P = np.abs(Xk) ** 2 * wsum**2 / (2.0 * fs * w2sum)
        # a residual peak: above thr times the band's level (median of its bins clear of lines / ln 2); a peak's
        # neighbours are neighbours on the run's record grid (the bins kept are contiguous within a band)
        key = ri * nb + bk                       # (run, band) of each bin, nondecreasing
        level = np.zeros((stop - start) * nb)
        kk, pk = key[keep], P[keep]
        if kk.size:
            # each band's median (np.median's: the middle value, or the mean of the middle two) from one sort by run,
            # band and value
            srt = pk[np.lexsort((pk, kk))]
            k_u, first, cnt_b = np.unique(kk, return_index=True, return_counts=True)
            hi = first + cnt_b // 2
            lo = np.where(cnt_b % 2 == 1, hi, hi - 1)
            level[k_u] = (srt[lo] + srt[hi]) / 2.0 / np.log(2.0)
        peak = P > thr * level[key]
        wide = peak.copy()
        for s_ in range(1, RECORD_PEAK_BINS + 1):
            same = ri[s_:] == ri[:-s_]
            wide[s_:] |= peak[:-s_] & same
            wide[:-s_] |= peak[s_:] & same
        use = keep & ~wide
        cnt = np.bincount(key[use], minlength=level.size).astype(float)
        tot = np.bincount(key[use], P[use], minlength=level.size)
        mean[start:stop] = np.where(cnt > 0, tot / np.maximum(cnt, 1.0), 0.0).reshape(-1, nb)
        used[start:stop] = cnt.reshape(-1, nb)
        start = stop
    return mean, used


@register(order=30)
@dataclass
class BroadbandFloor:
    """A broadband floor of one channel: S(f, Ω) = psd_ref(f)·(|Ω|/Ω_ref)^p, unit²/Hz."""

    channel: str
    exponent: float
    omega_ref: float
    f_hz: np.ndarray
    psd_ref: np.ndarray
    noise: np.ndarray
    kind: str = "broadband_floor"
    #: the knots written to the model file (band centres with flat ends over the analysed band): psd_ref is
    #: exactly their linear interpolation (0 outside), so the file reproduces the fitted floor
    knots_f: np.ndarray | None = None
    knots_psd: np.ndarray | None = None
    #: the null hypothesis of :meth:`heldout_evidence` (not written to the model file): per band, the channel's
    #: off-line level without growth refitted on the same runs (unit²/Hz, (n_bands,); 0 where no run was seen)
    flat_noise: np.ndarray | None = None
    #: t-value of the growth on the held-out runs, set by :meth:`refit` (None: not tested)
    growth_t: float | None = None

    @property
    def channels(self):
        return (self.channel,)

    def apply(self, state: State) -> State:
        s = state.plus(self)
        s.noise = dict(s.noise)
        s.noise[self.channel] = self.noise
        return s

    def contribute(self, parts) -> None:
        parts.floors[self.channel] = (self.psd_ref, self.omega_ref, self.exponent)

    def refit(self, ctx: Context, state: State) -> "BroadbandFloor":
        """Refitted on every run (``ctx.runs``); itself when that fit fails.  ``self`` is the hypothesis the search
        judged (fitted on ``ctx.fit_runs``): its growth is tested on the held-out runs (:meth:`growth_evidence`) and
        the t-value is kept on the refit, for :meth:`significant`."""
        out = BroadbandFloor.fit(ctx, state, self.channel, ctx.runs) or self
        drop, se = self.growth_evidence(ctx, state, ctx.held_runs)
        out.growth_t = drop / se if se > 0 else (np.inf if drop > 0 else 0.0)
        return out

    def significant(self) -> bool:
        """True when the floor's growth, fitted on the fit runs, predicts the held-out runs' off-line power beyond
        GROWTH_T standard errors (:meth:`growth_evidence`; checked by the search after the refit on every run, as an
        amplitude law's exponent).  The search's judge weighs the floor on whole bands, where raising the noise
        also widens the allowance of every band a line holds: a floor fitted to the lines' own leakage passed it
        on that allowance alone (see :meth:`growth_evidence`)."""
        return self.growth_t is None or self.growth_t > GROWTH_T

    def to_schema(self) -> dict:
        return schema_entry(self)

    def growth_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of the floor's growth where the floor makes its claim, between the lines: (drop, se),
        in the error metric's units (:meth:`Context.run_errors`), of the misplaced power
        Σ max(|y − N|·n·df − zσ, 0) over the bands of ``runs``: y the off-line band mean of the data less the
        model's lines (:meth:`Context.offline_bands`, n bins), N the band's level under the null and with this
        floor, σ the null's noise allowance of those bins (sqrt(2n·N₀²·2/ν)·df, the metric's band σ without
        lines) for both, z = NOISE_Z; se as the search's judge (Σ min(|ΔN|·n·df, σ)²·P(change)).  The null is
        the channel's noise refitted without growth on the fit runs (``flat_noise``): a floor also re-estimates
        the noise, and a noise level corrected (e.g. after a speed ripple took its lines' power) is no floor
        growing with speed.

        Why the search's judge is not enough: it weighs the floor on whole bands, where raising the noise N
        widens the allowance of every band a line holds (σ² ∋ 2·L·N·2/ν: a line 80 dB over the noise is
        forgiven sqrt(L/N) times more than the noise alone).  Where the model misses a line by more than that
        allowance -- a line predicted a fraction of a per cent off near a mode, two coherent lines beating in
        the Welch estimate -- any floor "explains" 2·Δσ of it: on clean 0.1 %-noise data 99.9 % of a false
        floor's held-out gain was that allowance (corner-low of benchmarks/diagnose_matrix.py, Fz, p 0.5, fitted
        to the lines' leakage beside them).  Here the allowance is held at the null's and only off-line power
        counts: leakage whose sign changes from run to run (random line phases) gains nothing on held-out runs,
        a real floor's growth does."""
        c = self.channel
        ok = runs[np.isfinite(ctx.sp.psd[c][runs, 0])]
        if ok.size == 0:
            return 0.0, 0.0
        y, cnt = ctx.offline_bands(state, c, ok)                     # (n_runs, n_bands) unit²/Hz, bins
        lo, n = ctx.k_lo, ctx.n_bands * BAND_BINS

        def band_noise(st):
            return ctx.floor_psd(st, c, ok)[:, lo:lo + n].reshape(ok.size, ctx.n_bands, BAND_BINS).mean(-1)

        # the null: the same channel's noise refitted without growth (a floor also re-estimates the noise, and a
        # noise level corrected is not a floor growing with speed: it must not earn the floor its place)
        n0 = band_noise(state)
        if self.flat_noise is not None and self.flat_noise.shape == (ctx.n_bands,) and (self.flat_noise > 0).any():
            # a band of no positive flat level (no run seen, or the model's line skirts over the data: a mode's lines
            # on a sweep) holds no estimate of the noise: the null there is interpolated from the bands either side,
            # as the floor's own noise is (:func:`_floor_of_law`), not the state's noise, which the floor re-estimates
            # (family wheel 4 sweep, Fy: the state's noise of the empirical start 9.0e-6 and 4.5e-6 N²/Hz at the
            # 176- and 236-Hz bands, 440x and 220x the data's 2.1e-8; a floor of no growth there, its noise corrected,
            # held 100 % of a held-out growth of 11.3 standard errors)
            good = self.flat_noise > 0
            fc = ctx.band_centres()
            n0 = np.broadcast_to(np.interp(fc, fc[good], self.flat_noise[good]), n0.shape)
        n1 = band_noise(self.apply(state))
        to_power = cnt * ctx.df                                       # unit²/Hz -> unit² of the band's off-line bins
        sig = np.sqrt(2.0 * cnt * n0**2 * 2.0 / ctx.dof) * ctx.df         # the null's noise allowance
        # a band whose Welch bins are all taken by the lines in a run: that run's whole-run bins between them (as the
        # fit), each of its own width and 2 degrees of freedom
        yr, cr, dfr = record_offline_bands(ctx, state, c, ok, cnt == 0)
        fill = (cnt == 0) & (cr > 0)
        y = np.where(fill, yr, y)
        to_power = np.where(fill, cr * dfr[:, None], to_power)
        sig = np.where(fill, np.sqrt(2.0 * cr * n0**2) * dfr[:, None], sig)
        r0, r1 = (y - n0) * to_power, (y - n1) * to_power
        drop = np.maximum(np.abs(r0) - NOISE_Z * sig, 0.0) - np.maximum(np.abs(r1) - NOISE_Z * sig, 0.0)
        dm = np.abs(r1 - r0)
        p_change = np.minimum(2.0 * stats.norm.sf(np.maximum(NOISE_Z - dm / np.maximum(sig, 1e-300), 0.0)), 1.0)
        se = np.sqrt(np.sum(np.minimum(dm, sig) ** 2 * p_change))
        scale = ctx.scale(c)
        return float(drop.sum()) / scale, float(se) / scale

    def params(self) -> dict:
        kf = self.f_hz[::BAND_BINS] if self.knots_f is None else self.knots_f
        kp = self.psd_ref[::BAND_BINS] if self.knots_psd is None else self.knots_psd
        return {"channel": self.channel, "exponent": self.exponent, **_exponent_bound(self.exponent),
                "omega_ref_rad_s": self.omega_ref,
                "psd_law": "psd_ref(f) * (|omega|/omega_ref)^exponent, linear between knots, 0 outside",
                "unit": f"{CHANNEL_UNIT[self.channel]}^2/Hz",
                "f_Hz": [float(x) for x in kf],
                "psd_ref": [float(x) for x in kp]}

    @staticmethod
    def fit(ctx: Context, state: State, c: str, runs) -> "BroadbandFloor | None":
        got = _floor_bands(ctx, state, c, runs)
        if got is None:
            return None
        y, wt = got
        x0 = ctx.omega[runs] / ctx.omega_ref()
        p, n, g = _floor_law(wt, y, x0)
        return _floor_of_law(ctx, state, c, y, wt, x0, p, n, g)

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """A floor law per channel without one; each channel's from that channel alone (:meth:`Context.reuse`), and
        only where it could pass (:meth:`Context.can_pass`).  And one law of the channels of each unit group
        (:data:`FLOOR_GROUPS`) without a floor, two or more (:class:`FloorGroup`), judged on its own held-out evidence."""
        def one(c):
            e = BroadbandFloor.fit(ctx, state, c, runs)
            return [e] if e is not None and e.psd_ref.max() > 0 else []

        singles = [e for c in ctx.channels if c not in state.floors and ctx.can_pass(state, [c])
                   for e in ctx.reuse("broadband_floor", state, [c], runs, lambda c=c: one(c))]
        groups = []
        for group in FLOOR_GROUPS:
            chans = [c for c in group if c in ctx.channels and c not in state.floors]
            if len(chans) >= 2:
                groups += ctx.reuse("broadband_floor", state, chans, runs,
                                    lambda chans=chans: FloorGroup.fit_list(ctx, state, chans, runs), part="group")
        return singles + groups


def _exponent_bound(p: float) -> dict:
    """``{"exponent_bound": "at_least"}`` for an exponent at the top of :data:`FLOOR_EXPONENTS` (``"at_most"`` at its
    bottom), else ``{}``: :func:`_floor_law` chooses the likeliest exponent of that grid, and one at its edge says only
    that the likeliest law lies there or beyond (a floor read p 8 may grow as Ω^10), a bound, not a value."""
    if p >= FLOOR_EXPONENTS[-1]:
        return {"exponent_bound": "at_least"}
    if p <= FLOOR_EXPONENTS[0]:
        return {"exponent_bound": "at_most"}
    return {}


def _floor_bands(ctx: Context, state: State, c: str, runs) -> tuple | None:
    """(y, wt) of :meth:`BroadbandFloor.fit`: channel ``c``'s off-line band means (unit²/Hz) and bins used per run and
    band ((len(runs), n_bands) each), a band whose Welch bins are all taken by the lines in a run filled from that
    run's whole-run bins between them; None where a run lacks the channel."""
    y, wt = ctx.offline_bands(state, c, runs)                       # (n_runs, n_bands) unit²/Hz
    if not np.isfinite(ctx.sp.psd[c][runs, 0]).all() or wt.sum(0).min() < 0:
        return None
    # a band whose Welch bins are all taken by the lines in a run: that run's whole-run bins between them
    # (their bins weighed in Welch-bin equivalents, 2/ctx.dof each: a band mean's variance is mean²·2/(dof·bins))
    yr, cr, _ = record_offline_bands(ctx, state, c, runs, wt == 0)
    fill = (wt == 0) & (cr > 0)
    return np.where(fill, yr, y), np.where(fill, cr * 2.0 / ctx.dof, wt)


def _floor_of_law(ctx: Context, state: State, c: str, y, wt, x0, p, n, g) -> BroadbandFloor | None:
    """The floor of channel ``c`` whose law y = n + g·x0^p per band (:func:`_floor_law`) was fitted to its off-line band
    means ``y`` with bins ``wt`` ((runs, bands) each; ``x0`` (runs,) Ω/Ω_ref), or None where it holds no floor."""
    w_ref = ctx.omega_ref()
    # growth is measured only in a band whose usable runs reach the upper half of the speeds (Ω >= Ω_max/2):
    # from lower speeds alone the law Ω^p is extrapolated to the top speed by 2^p or more (1.4 to 256 over the
    # exponent grid) times its error -- e.g. a band near a mode whose high-speed runs are skirt dominated.
    # Elsewhere the band's noise is its plain weighted mean and its growth is interpolated from its neighbours
    grows = ((wt > 0) & (x0 >= 0.5 * x0.max())[:, None]).any(0)
    flat = _band_levels(y, wt)
    n = np.where(grows, n, np.maximum(flat, 0.0))
    g = np.where(grows, g, 0.0)
    # a band with no usable bin in any run (every bin taken by lines) constrains nothing, and a band whose
    # fitted noise and growth are both 0 (its off-line data at or below the model's line skirts, as in
    # noise_estimate) holds no estimate of the floor: a zero floor would divide every later noise-relative
    # measure by zero.  The noise knots skip both, the growth knots the first; the floor there is
    # interpolated from the bands either side
    seen = wt.sum(0) > 0
    has_noise = seen & ((n > 0) | (g > 0))
    if not has_noise.any() or not grows.any():
        return None
    seen = grows
    f = ctx.f
    lo, hi = f[ctx.k_lo], f[ctx.k_lo + ctx.n_bands * BAND_BINS - 1]
    centres = ctx.band_centres()
    # knots: the band centres, held flat out to the analysed band's first and last bins (a floor below
    # the first centre -- energy below 1x -- is there in the data too)
    kf = np.concatenate([[lo], centres[seen], [hi]])
    kg = np.concatenate([[g[seen][0]], g[seen], [g[seen][-1]]])
    kf_n = np.concatenate([[lo], centres[has_noise], [hi]])
    kn = np.concatenate([[n[has_noise][0]], n[has_noise], [n[has_noise][-1]]])
    n0 = np.array(state.noise[c], dtype=float)
    band = (f >= lo) & (f <= hi)
    n0[band] = np.interp(f[band], kf_n, kn)
    ref = np.interp(f, kf, kg, left=0.0, right=0.0)
    return BroadbandFloor(c, float(p), w_ref, f.copy(), ref, n0, knots_f=kf, knots_psd=kg,
                          flat_noise=np.maximum(flat, 0.0))


#: Held-out growth t-value (:meth:`BroadbandFloor.growth_evidence`) each channel's part of a :class:`FloorGroup` must
#: reach on its own to be kept (a channel the floor does not reach: |t| about 1 or less)
PART_GROWTH_T = 2.0


def _summed(evidence) -> tuple:
    """(drop, se) of independent parts' (drop, se) pairs: the drops summed, the standard errors in quadrature."""
    return float(sum(d for d, _ in evidence)), float(np.sqrt(sum(s * s for _, s in evidence)))


def _t_value(drop: float, se: float) -> float:
    """drop / se, the held-out growth in standard errors (inf for a drop with no noise, 0 for none)."""
    return drop / se if se > 0 else (np.inf if drop > 0 else 0.0)


#: The channels one floor law is also proposed on together (:class:`FloorGroup`): each unit group's (the class's own
#: injection puts one floor law on Fx+Fy+Fz)
FLOOR_GROUPS = (("Fx", "Fy", "Fz"), ("Tx", "Ty", "Tz"))


@dataclass
class FloorGroup:
    """One floor law of several channels of a unit group, S_c(f, Ω) = psd_ref_c(f)·(|Ω|/Ω_ref)^p: one exponent p, each
    channel its own spectrum psd_ref_c (each part a :class:`BroadbandFloor` of one channel; the search adds the parts,
    each its own entry of the model file, from one hypothesis).

    A noise-like load of the rotor (random bearing forces) reaches every force channel, each through its own path.
    Split over the channels, each channel's share of the held-out misplaced power can stay below the search's
    ``min_gain`` while their sum does not: family wheel 4 (4096 samples, 300-3000 rpm), a floor ∝ Ω³ on the rotor's
    forces: Fx 4.9 %, Fy 2.4 %, Fz 4.2 % of it, so no single-channel floor was even fitted (:meth:`Context.can_pass`),
    while each channel's growth between the lines stood 8.4, 3.8 and 6.5 standard errors out on the held-out runs.

    Judged on that evidence (:meth:`heldout_evidence`: :meth:`BroadbandFloor.growth_evidence` summed over the parts,
    their standard errors in quadrature), the test a single floor's refit passes (:meth:`BroadbandFloor.significant`):
    the error metric's whole bands weigh a floor where the lines hold most of the power and their noise allowance
    forgives it (on that wheel the injected floor itself, truth PSD and exponent, gained Fx 4.3 % t 4.9, Fy 1.9 %
    t 2.3, Fz 1.4 % t 0.6 there)."""

    parts: tuple
    kind: str = "broadband_floor"
    #: t-value of the parts' growth on the held-out runs, set by :meth:`refit` (None: not tested)
    growth_t: float | None = None
    #: (the state, the runs, each part's evidence) of :meth:`_part_evidence`'s last call
    _evidence: tuple | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def channels(self):
        return tuple(e.channel for e in self.parts)

    def apply(self, state: State) -> State:
        """Each part added in turn (one effect of the state per channel)."""
        for e in self.parts:
            state = e.apply(state)
        return state

    def _part_evidence(self, ctx: Context, state: State, runs) -> list:
        """Each part's (drop, se) of :meth:`BroadbandFloor.growth_evidence` on ``runs``: computed once for a state and
        runs (the search judges a group on the held-out runs, then :meth:`refit` reads the same parts' evidence)."""
        got = self._evidence
        if got is not None and got[0]() is state and np.array_equal(got[1], runs):
            return got[2]
        ev = [e.growth_evidence(ctx, state, runs) for e in self.parts]
        self._evidence = (weakref.ref(state), np.array(runs), ev)
        return ev

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """(drop, se) of the parts' growth on ``runs`` (:meth:`BroadbandFloor.growth_evidence`), in the error metric's
        units: the drops summed, the standard errors in quadrature (the channels' noises are independent)."""
        return _summed(self._part_evidence(ctx, state, runs))

    def refit(self, ctx: Context, state: State) -> "FloorGroup":
        """Refitted on every run, on the channels whose own part (fitted on the fit runs) grows on the held-out runs
        beyond :data:`PART_GROWTH_T` standard errors (:meth:`BroadbandFloor.growth_evidence`; the kept parts when that
        fit fails), with the t-value of the kept parts' growth there, for :meth:`significant`; not significant when
        fewer than two channels are kept (the single-channel floors remain).

        Why each part on its own: the summed evidence of a floor on one channel alone passes with the other channels'
        parts in it, their g >= 0 fitted to their noise (E wheel, a floor on Fz only, 2048 samples: the group of Fx,
        Fy, Fz at held-out t 5.75, of which Fz's part 5.74, Fx's 0.01, Fy's 0.4) -- a floor named on channels that have
        none."""
        ev = self._part_evidence(ctx, state, ctx.held_runs)
        keep = [i for i, (d, s) in enumerate(ev) if _t_value(d, s) > PART_GROWTH_T]
        if len(keep) < 2:
            return FloorGroup(self.parts, growth_t=0.0)
        kept = tuple(self.parts[i] for i in keep)
        out = FloorGroup.fit(ctx, state, [e.channel for e in kept], ctx.runs) or FloorGroup(kept)
        out.growth_t = _t_value(*_summed([ev[i] for i in keep]))
        return out

    def significant(self) -> bool:
        """As :meth:`BroadbandFloor.significant`: the growth beyond GROWTH_T standard errors on the held-out runs."""
        return self.growth_t is None or self.growth_t > GROWTH_T

    def params(self) -> dict:
        e = self.parts[0]
        return {"channel": list(self.channels), "exponent": e.exponent, **_exponent_bound(e.exponent),
                "omega_ref_rad_s": e.omega_ref,
                "psd_law": "psd_ref_c(f) * (|omega|/omega_ref)^exponent per channel c (one entry each)",
                "unit": f"{CHANNEL_UNIT[e.channel]}^2/Hz"}

    def to_schema(self) -> dict:
        return schema_entry(self)

    @staticmethod
    def fit(ctx: Context, state: State, chans, runs) -> "FloorGroup | None":
        """One law y_c = n_c + g_c·(Ω/Ω_ref)^p of the off-line band means of channels ``chans`` on ``runs``
        (:func:`_floor_law` over every channel's bands at once, each channel's relative to its own largest band level,
        so that each weighs by its relative misfit as alone), each channel's floor from its part (:func:`_floor_of_law`);
        None unless two channels or more hold a floor."""
        got = {c: b for c in chans if (b := _floor_bands(ctx, state, c, runs)) is not None}
        chans = list(got)
        if len(chans) < 2:
            return None
        x0 = ctx.omega[runs] / ctx.omega_ref()
        scale = {c: max(float(np.max(_band_levels(*got[c]))), 1e-300) for c in chans}
        p, n, g = _floor_law(np.concatenate([got[c][1] for c in chans], 1),
                             np.concatenate([got[c][0] / scale[c] for c in chans], 1), x0)
        nb = ctx.n_bands
        parts = []
        for i, c in enumerate(chans):
            sl = slice(i * nb, (i + 1) * nb)
            e = _floor_of_law(ctx, state, c, got[c][0], got[c][1], x0, p, n[sl] * scale[c], g[sl] * scale[c])
            if e is not None and e.psd_ref.max() > 0:
                parts.append(e)
        return FloorGroup(tuple(parts)) if len(parts) >= 2 else None

    @staticmethod
    def fit_list(ctx: Context, state: State, chans, runs) -> list:
        e = FloorGroup.fit(ctx, state, chans, runs)
        return [] if e is None else [e]
