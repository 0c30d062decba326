"""A line of a run cut from a sweep, as its Welch PSD shows it: a chirp in every segment (the ``spin_acceleration``
effect's prediction, :meth:`rwadist.diagnose.engine.Context.predict`).

While the wheel accelerates at |α| = |dΩ/dt| the line of harmonic h moves at h|α|/2π Hz/s.  A Welch PSD is the mean
over its segments (L samples, 50 % overlap: segment k starts at k·L/2) of each segment's windowed periodogram, and
on one segment the line is a linear chirp about the frequency it has at the segment's centre, sweeping
c = h|α|(L/f_s)²/2π bins of the segment's grid.  So the line's PSD is, exactly for a linear ramp,

    S(f) = Σ_k (1/K)·P_k·K_c(f − f_k),   f_k = f + h|α|τ_k/2π,   P_k = (a²/2)·(1 + |α|τ_k/|Ω|)⁴,

τ_k the segment's centre less the run's (s), K the run's segments, a the line's amplitude at the run's mean speed Ω
(a C·Ω² line's power goes as Ω⁴; higher in frequency is faster both ways, so a run-down reads as a run-up), and K_c
the chirp's kernel: |Σ_n w_n·e^{iπc(n/L − ½)²}·e^{−2πiδn/L}|²/(f_s·Σw²) at δ bins from the centre (its power is the
window kernel's, Parseval; for c = 0 it is the window kernel).  K_c is tabulated for each c asked by a zero-padded
FFT (every 1/:data:`OVERSAMPLE` bin) and read by a cubic.

The earlier prediction spread each line over points every half bin across the whole run (weighted by the Welch
weight of their part of the record) and split each point across ±⅓ of a segment's own sweep through the window's
steady kernel: the segments' chirp counted twice, a fitted |α| 5-8 % low on fast sweeps (trial 11's 120-s run-up,
3.48 rad/s² for 3.665 with its tach column).

Units: Hz, s, rad/s, rad/s²; offsets in bins of the Welch segment.
"""
from __future__ import annotations

import functools

import numpy as np

from .constants import KERNEL_HALF

#: points per bin of the kernel table in δ (read by the 4-point Lagrange cubic)
OVERSAMPLE = 64
#: instants per Welch segment at which a line's response through the suspension modes is read
#: (:func:`segment_transfer`)
INSTANTS = 32


@functools.lru_cache(maxsize=512)
def _kernel_row(nperseg: int, window: str, c: float) -> np.ndarray:
    """|W_c|²/Σw² (the chirp kernel without its 1/f_s) at δ = −(KERNEL_HALF + 2) … KERNEL_HALF + 2 bins every
    1/OVERSAMPLE bin, for a line sweeping ``c`` bins across the segment: bin m of the zero-padded FFT of
    w(n)·e^{iπc(n/L − ½)²}.  Read-only (shared)."""
    from scipy import signal

    L = int(nperseg)
    w = signal.get_window(window, L)
    x = np.arange(L) / L - 0.5
    steps = np.arange(-(KERNEL_HALF + 2) * OVERSAMPLE, (KERNEL_HALF + 2) * OVERSAMPLE + 1)
    W = np.fft.fft(w * np.exp(1j * np.pi * c * x**2), L * OVERSAMPLE)[steps % (L * OVERSAMPLE)]
    row = np.abs(W) ** 2 / np.sum(w**2)
    row.flags.writeable = False
    return row


def chirp_kernel(nperseg: int, fs: float, window: str, c: float):
    """The kernel K_c (1/Hz) of a line sweeping ``c`` bins across a segment of ``nperseg`` samples at ``fs`` Hz under
    ``window``, as a function of the offsets δ (bins, any shape; read within ±(KERNEL_HALF + 1)): the kernel of that
    c (:func:`_kernel_row`, kept per c: a state's spin acceleration and line set ask for the same few) read by the
    4-point Lagrange cubic through its table (within 1e-8 of the peak, as the steady kernel's reading)."""
    row = _kernel_row(int(nperseg), str(window), round(abs(float(c)), 12))
    n = row.size

    def at(dlt: np.ndarray) -> np.ndarray:
        y = np.clip((np.asarray(dlt, dtype=float) + KERNEL_HALF + 2) * OVERSAMPLE, 1.0, n - 3.0)
        i = y.astype(int)
        u = y - i
        p0, p1, p2, p3 = row[i - 1], row[i], row[i + 1], row[i + 2]
        val = (-u * (u - 1) * (u - 2) / 6 * p0 + (u + 1) * (u - 1) * (u - 2) / 2 * p1
               - (u + 1) * u * (u - 2) / 2 * p2 + (u + 1) * u * (u - 1) / 6 * p3)
        return np.maximum(val, 0.0) / fs

    return at


def segment_offsets(alpha: float, h: float, omega: np.ndarray, n_samples: np.ndarray, n_segments: np.ndarray,
                    nperseg: int, fs: float) -> tuple:
    """(offsets Hz, weights) (len(runs), max K) of the line h on each run's Welch segments (module docstring): the
    centre frequency of segment k less the run's mean h|Ω|/2π, and (1/K)·(1 + |α|τ_k/|Ω|)⁴ (0 past a run's own K).
    ``omega`` rad/s, ``n_samples`` and ``n_segments`` per run; ``alpha`` rad/s²."""
    alpha = abs(float(alpha))
    tau, used, n_seg = _segment_times(n_samples, n_segments, nperseg, fs)
    ratio = speed_ratios(alpha, omega, n_samples, n_segments, nperseg, fs)
    wt = np.where(used, ratio**4 / n_seg[:, None], 0.0)
    return np.where(used, h * alpha * tau / (2 * np.pi), 0.0), wt


def _segment_times(n_samples: np.ndarray, n_segments: np.ndarray, nperseg: int, fs: float) -> tuple:
    """(τ_k s, used, K) of each run's Welch segments: the centre of segment k less the run's, (len(runs), max K);
    True for a segment the run has; each run's own K."""
    n_seg = np.maximum(np.asarray(n_segments, dtype=int), 1)
    k = np.arange(int(n_seg.max()))
    step = nperseg - int(round(0.5 * nperseg))
    tau = (k[None, :] * step + nperseg / 2.0 - np.asarray(n_samples, dtype=float)[:, None] / 2.0) / fs
    return tau, k[None, :] < n_seg[:, None], n_seg


def speed_ratios(alpha: float, omega: np.ndarray, n_samples: np.ndarray, n_segments: np.ndarray, nperseg: int,
                 fs: float) -> np.ndarray:
    """|Ω(τ_k)|/|Ω| = max(1 + |α|τ_k/|Ω|, 0) (len(runs), max K) on each run's Welch segments (higher in frequency is
    faster both ways: a run-down reads as a run-up); 1 past a run's own K."""
    tau, used, _ = _segment_times(n_samples, n_segments, nperseg, fs)
    w = np.maximum(np.abs(np.asarray(omega, dtype=float)), 1e-12)
    return np.where(used, np.maximum(1.0 + abs(float(alpha)) * tau / w[:, None], 0.0), 1.0)


def segment_chirp(alpha: float, h: float, nperseg: int, fs: float) -> float:
    """Bins the line h sweeps across one segment at |dΩ/dt| = ``alpha``: h|α|(L/f_s)²/2π."""
    return abs(float(alpha)) * h * (nperseg / fs) ** 2 / (2 * np.pi)


def _track(ctx, runs) -> tuple | None:
    """(start times s, speeds rad/s) of the runs in start-time order (runs of one sweep, ``Run.t0`` distinct), or None
    (no time series, fewer than 3 runs, start times not known or repeated)."""
    if ctx.test is None or len(runs) < 3:
        return None
    t0 = np.array([ctx.test.runs[r].t0 for r in runs], dtype=float)
    w = np.asarray(ctx.omega, dtype=float)[runs]
    order = np.argsort(t0)
    if not np.all(np.isfinite(t0)) or np.any(np.diff(t0[order]) <= 0):
        return None
    return t0[order], w[order]


def speed_track(ctx, runs, signed: bool = False) -> float:
    """Median |dΩ/dt| (rad/s²; ``signed``: dΩ/dt, negative on a run-down) of the runs' speeds against their start
    times (runs of one sweep, ``Run.t0`` distinct), or NaN (no time series, fewer than 3 runs, start times not known or
    repeated)."""
    track = _track(ctx, runs)
    if track is None:
        return float("nan")
    t0, w = track
    rates = np.diff(w) / np.diff(t0)
    return float(np.median(rates if signed else np.abs(rates)))


#: :func:`track_span` reads dΩ/dt over windows of this share of the runs (one run at least): the difference of two
#: runs' speeds next in time holds their errors over one spacing (1e-3 of 400 rad/s over 2 s: 0.28 rad/s², a quarter
#: of a slow ramp's), over an eighth of a long sweep's runs a few per cent of it
SPAN_WINDOW = 1 / 8


def track_span(ctx, runs) -> tuple[float, float]:
    """(slowest, fastest) dΩ/dt (rad/s², signed), by |dΩ/dt|, of the runs' speeds against their start times over
    windows of :data:`SPAN_WINDOW` of the runs: how far one acceleration (the median, :func:`speed_track`) is from the
    sweep's own (a motor's exponential run-down falls from its fastest at the start to a crawl at the end); (NaN, NaN)
    when :func:`speed_track` is NaN."""
    track = _track(ctx, runs)
    if track is None:
        return float("nan"), float("nan")
    t0, w = track
    m = max(1, int(round(SPAN_WINDOW * t0.size)))
    m = min(m, t0.size - 1)
    rates = (w[m:] - w[:-m]) / (t0[m:] - t0[:-m])
    order = np.argsort(np.abs(rates), kind="stable")
    return float(rates[order[0]]), float(rates[order[-1]])


def sweep_sign(ctx) -> float:
    """+1 when the context's runs rise in |Ω| with their start times (a run-up), −1 when they fall (a run-down); +1
    when their start times are not known (no time series, or runs not cut from one record)."""
    test = ctx.test
    if test is None or len(ctx.runs) < 2:
        return 1.0
    # read as _track reads them: every Run has a start time, and the first slice's 0.0 is one (``t0 or nan`` was not)
    t0 = np.array([test.runs[r].t0 for r in ctx.runs], dtype=float)
    w = np.abs(np.asarray(ctx.omega, dtype=float)[ctx.runs])
    if not np.all(np.isfinite(t0)) or np.ptp(t0) <= 0:
        return 1.0
    return 1.0 if np.sum((t0 - t0.mean()) * (w - w.mean())) >= 0 else -1.0


def instant_ratios(alpha: float, omega: np.ndarray, n_samples: np.ndarray, n_segments: np.ndarray, nperseg: int,
                   fs: float, window: str) -> tuple:
    """(|Ω(t)|/|Ω| (len(runs), max K, :data:`INSTANTS`), weights (INSTANTS,)) at :data:`INSTANTS` instants spread
    evenly over each Welch segment, and the squares of the segment's window there, summing to 1 (a segment's
    periodogram holds the window²-weighted mean square of its record, Parseval); the instants of a segment a run does
    not have carry the segment's centre's ratio (1)."""
    from scipy import signal

    tau, used, _ = _segment_times(n_samples, n_segments, nperseg, fs)
    idx = ((np.arange(INSTANTS) + 0.5) * nperseg / INSTANTS).astype(int)
    s = (idx - nperseg / 2.0) / fs                                   # s from the segment's centre
    win = signal.get_window(window, nperseg)[idx] ** 2
    w = np.maximum(np.abs(np.asarray(omega, dtype=float)), 1e-12)
    r = np.maximum(1.0 + abs(float(alpha)) * (tau[:, :, None] + s) / w[:, None, None], 0.0)
    return np.where(used[:, :, None], r, 1.0), win / win.sum()


def segment_transfer(ctx, state, c: str, h: float, runs: np.ndarray) -> np.ndarray:
    """(len(runs), K): the line h's power in channel ``c`` on each of the runs' Welch segments under the state's spin
    acceleration (the extended base's lines at :data:`INSTANTS` instants of the segment, each through the suspension
    as a linear chirp of the sweep's sign, :func:`rwadist.extended.steady_lines` ``omega_dot``: a mode crossed faster
    than it settles lags, peaks lower and rings on; their window²-weighted mean square) over its power at the run's
    mean speed, less a C·Ω² line's (Ω(τ_k)/Ω)⁴; 1 where it has no power.  ``ctx`` a
    :class:`~rwadist.diagnose.engine.Context`."""
    fs, L = ctx.sp.sample_rate, ctx.sp.nperseg
    n = np.rint(ctx.run_durations(runs) * fs)
    n_seg = np.asarray(ctx.sp.n_segments)[runs]
    alpha = abs(float(state.smear or 0.0))
    w_run = np.asarray(ctx.omega, dtype=float)[runs]
    ratio = speed_ratios(alpha, w_run, n, n_seg, L, fs)
    seg_key = ("smear_lines", runs.tobytes())            # every line at every segment's instants, once per runs
    if seg_key not in state._cache:
        lines = tuple(state.ext_lines())
        sign = sweep_sign(ctx)
        content = ("smear_lines", state.ext, lines, runs.tobytes(), alpha, sign, L, fs)
        if content not in ctx._memo:
            r, win = instant_ratios(alpha, w_run, n, n_seg, L, fs, ctx.sp.window)
            w_inst = w_run[:, None, None] * r
            w_dot = np.broadcast_to(sign * alpha * np.sign(w_run)[:, None, None], w_inst.shape)
            by_channel = ctx._ext_lines(state, w_inst.ravel(), lines, omega_dot=w_dot.ravel())[0]
            ctx._memo[content] = {ch: [(hs, (a.reshape(w_inst.shape) ** 2) @ win) for hs, _, a, _ in rows]
                                  for ch, rows in by_channel.items()}
        state._cache[seg_key] = ctx._memo[content]
    p_seg = next((p for hs, p in state._cache[seg_key].get(c, []) if abs(hs - h) < 1e-9), None)
    a0 = next((a for hm, _, a, _ in ctx.channel_lines(state, c, runs) if abs(hm - h) < 1e-9), None)
    if p_seg is None or a0 is None:
        return np.ones(ratio.shape)
    ok = (a0[:, None] > 0) & (ratio > 0)
    return np.where(ok, p_seg / np.where(ok, a0[:, None], 1.0) ** 2 / np.where(ok, ratio, 1.0) ** 4, 1.0)
