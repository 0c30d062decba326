"""Lines at one fixed frequency in every run (electrical pickup, a pump or fan on the stand, a clock): found in the
data before the search, described, and taken out of the records the fits read (issue 33, item 3).

A wheel's line moves with the speed (f = h·|Ω|/2π); a line that stays at one frequency while the speed changes is
no harmonic, and no effect class describes it.  Left in the data it is forced into a class: a 50 Hz pickup line was
fitted as a 54.5 Hz test-stand resonance of gain 8, which spoilt the wheel's suspension modes, and the search then
named a line the empirical fit had lost (issue 33: "forced into a wrong class").  So the lines are found first, on
the Welch PSDs against each run's block floor (:func:`find_fixed_lines`), and subtracted from every record the
search reads (each run's own whole-record phasor at the line's frequency, :func:`remove_fixed_lines`); the
diagnosis measures its error on the data as given, where they stay unexplained, and describes them
(:func:`describe_fixed_lines`).

A bin is lit in a run when its PSD stands over the run's block floor beyond a 1e-4 false-alarm level (the Welch
estimate's χ² with the spectra's degrees of freedom), the bin or one of its neighbours (a line between bins); a
fixed line is a bin lit in at least :data:`MIN_LIT_FRACTION` of the runs of some channel, over the whole speed range
(the lowest and the highest third of the speeds both), steady (10 dB over the floor in the median run, 7 dB in three
quarters of them: the wheel's lines crossing a low frequency light it in many runs too, but leave it at the noise in
others) and narrow, at a frequency where a line at a constant ratio of the speed would move by at least
:data:`MIN_MOVE_BINS` Welch bins over the speed range (otherwise the two cannot be told apart).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..units import RAD_S_TO_RPM

if TYPE_CHECKING:
    from ..data import SteadyTest

#: Fraction of the runs in which a fixed line's bin (or a neighbour) is lit, in some channel.
MIN_LIT_FRACTION = 0.75
#: Fewest runs a fixed line can be found on.
MIN_RUNS = 6
#: Welch bins a line at a constant ratio of the speed would move over the speed range, at least.
MIN_MOVE_BINS = 4.0
#: False-alarm probability of one lit bin (a χ² tail of the Welch estimate over the block floor).
LIT_FALSE_ALARM = 1e-4
#: A channel carries the line when its bin is lit in at least this fraction of the runs.
CHANNEL_LIT_FRACTION = 0.5
#: Half width of the frequency refinement, Welch bins, and its step, record bins.
REFINE_HALF_BINS = 1.5
REFINE_STEP_RECORD_BINS = 0.125
#: Runs the refinement sums over (evenly spread), at most.
REFINE_RUNS = 12
#: Half width and step (record bins) of the phasors a fixed line's amplitude is read from in each run.
TONE_GRID_BINS = 4.0
TONE_GRID_STEP = 0.5
#: A fixed line's amplitude is within STEADY_RATIO of its median over the runs in STEADY_FRACTION of them at least.
STEADY_RATIO = 1.5
STEADY_FRACTION = 0.6
#: A second tone (a wheel line passing the fixed one) is fitted from this offset (record bins: beyond the main lobe's
#: half width, where the two are told apart), when it fits the phasors this many times better.
SECOND_TONE_MIN_BINS = 1.5
SECOND_TONE_GAIN = 4.0
#: A run's phasors around a fixed line fitted by its tone (and a second one) leave at most this fraction of their power:
#: more, and a wheel line inside its main lobe mixes in (the run is not corrected there).  Lenient: a run left
#: uncorrected keeps its fixed line, which the search may then fit (2 % left 8-12 % of the runs uncorrected on the
#: test cases, and a counter-rotation was fitted to them; at 20 % one run in 120)
TONE_MISFIT = 0.2
#: A run's amplitude of a fixed line within this factor of the median over the runs is the line's own (a steady
#: source); beyond, a wheel line at the same frequency is mixed in and the run is not corrected.
SAME_AMPLITUDE = 2.0
#: A fixed line's median PSD over the block floor (over the runs, its peak bin or a neighbour), at least: 10 dB (lines
#: of the wheel crossing a frequency light it in many runs at low frequencies, but in few of them each)
MIN_LEVEL = 10.0
#: ... and at least this much in three quarters of the runs (7 dB).
MIN_STEADY_LEVEL = 5.0
#: Welch bins between two fixed lines, at least, and from a line's peak to the bins its narrowness is read against.
PEAK_SEPARATION_BINS = 4
#: A line's median PSD over that of the bins PEAK_SEPARATION_BINS away, at least.
PEAKINESS = 4.0
#: Mains frequencies (Hz) whose families are named as electrical pickup.
MAINS_HZ = (50.0, 60.0, 400.0)


@dataclass(frozen=True)
class FixedLine:
    """A line at one frequency in every run: f_Hz (refined on the whole records), the channels that carry it, the
    runs where it is lit (indices of the spectra), its median power over the block floor in its bin (dB) and its
    median mean square per channel (unit²)."""

    f_Hz: float
    channels: tuple
    runs: tuple
    level_dB: float
    mean_square: dict
    #: complex amplitude (every run of the test, the channels) of the line (:func:`run_amplitudes`)
    amplitudes: np.ndarray | None = field(default=None, repr=False, compare=False)


def _lit(psd: np.ndarray, floor: np.ndarray, dof: float) -> np.ndarray:
    """Bins (runs, n_f) lit: over the block floor beyond the χ² level of :data:`LIT_FALSE_ALARM`, the bin or a
    neighbour."""
    from scipy import stats

    thr = stats.chi2.isf(LIT_FALSE_ALARM, dof) / dof
    lit = psd > thr * np.maximum(floor, 1e-300)
    out = lit.copy()
    out[:, 1:] |= lit[:, :-1]
    out[:, :-1] |= lit[:, 1:]
    return out


def find_fixed_lines(ctx) -> list:
    """The :class:`FixedLine` of the context's spectra (:class:`rwadist.diagnose.engine.Context`: its Welch PSDs
    and block floors, every run with a speed), strongest first; [] when the speeds do not move a line enough to
    tell one apart, or without the time series (their frequency is refined on the records)."""
    runs = ctx.runs
    om = ctx.omega[runs]
    if runs.size < MIN_RUNS or ctx.test is None or om.max() <= 0:
        return []
    # a line at constant h through frequency f moves by f·(1 − Ω_min/Ω_max) over the speeds
    f_min = MIN_MOVE_BINS * ctx.df / max(1.0 - om.min() / om.max(), 1e-12)
    k_lo = max(ctx.k_lo, int(np.ceil(f_min / ctx.df)))
    if k_lo >= ctx.k_hi:
        return []
    order = np.argsort(om)
    thirds = (order[: max(runs.size // 3, 1)], order[-max(runs.size // 3, 1):])
    frac, peak = {}, {}
    for c in ctx.channels:
        ok = np.isfinite(ctx.sp.psd[c][runs, 0])
        if ok.sum() < MIN_RUNS:
            continue
        lit = _lit(ctx.sp.psd[c][runs[ok]], ctx.floor[c][runs[ok]], ctx.dof)
        f = lit.mean(0)
        # the whole speed range: lit in most of the lowest and of the highest third of the speeds too
        for third in thirds:
            sel = np.isin(np.flatnonzero(ok), third)
            f = np.minimum(f, lit[sel].mean(0) if sel.any() else 0.0)
        frac[c] = f
        peak[c] = np.median(ctx.sp.psd[c][runs[ok]] / np.maximum(ctx.floor[c][runs[ok]], 1e-300), axis=0)
    if not frac:
        return []
    best = np.max(np.stack(list(frac.values())), axis=0)
    score = np.sum(np.stack(list(peak.values())), axis=0)
    hit = best >= MIN_LIT_FRACTION
    hit[:k_lo] = False
    hit[ctx.k_hi + 1:] = False
    # one line per peak of the summed level: the strongest lit bin within PEAK_SEPARATION_BINS (a strong line lights
    # its whole main lobe and first side lobes), narrow as a line (not a hump of noise: PEAKINESS)
    out: list[FixedLine] = []
    for k0 in np.flatnonzero(hit)[np.argsort(-score[hit])]:
        k0 = int(k0)
        if any(abs(k0 - int(round(x.f_Hz / ctx.df))) <= PEAK_SEPARATION_BINS for x in out):
            continue
        if not _narrow(ctx, k0, list(peak)) or not _steady(ctx, k0, list(peak)):
            continue
        chans = tuple(c for c in ctx.channels if c in frac and frac[c][max(k0 - 1, 0):k0 + 2].max()
                      >= CHANNEL_LIT_FRACTION)
        got = _measure(ctx, k0, chans)
        if got is not None:
            out.append(got)
    return sorted(out, key=lambda x: -x.level_dB)


def _steady(ctx, k0: int, chans) -> bool:
    """True when bin ``k0`` (or a neighbour) stands over the block floor by :data:`MIN_LEVEL` in the median over the
    runs and by :data:`MIN_STEADY_LEVEL` in three quarters of them, in some channel: a steady source, where the lines
    of a wheel crossing a low frequency light it in many runs, some of them by 80 dB, and leave it at the noise in a
    quarter of them or more."""
    runs = ctx.runs
    lo, hi = max(k0 - 1, 0), k0 + 2
    for c in chans:
        ratio = np.max(ctx.sp.psd[c][runs, lo:hi] / np.maximum(ctx.floor[c][runs, lo:hi], 1e-300), axis=1)
        ratio = ratio[np.isfinite(ratio)]
        if ratio.size and np.median(ratio) >= MIN_LEVEL and np.percentile(ratio, 25) >= MIN_STEADY_LEVEL:
            return True
    return False


def _narrow(ctx, k0: int, chans) -> bool:
    """True when bin ``k0`` holds a line, not a hump of noise: its median PSD over the runs stands at least
    :data:`PEAKINESS` times over that of the bins :data:`PEAK_SEPARATION_BINS` on either side (a Hann line's kernel
    there is 50 dB down; a hump of noise is nearly as high), in some channel."""
    runs = ctx.runs
    k = np.array([k0 - PEAK_SEPARATION_BINS, k0, k0 + PEAK_SEPARATION_BINS])
    if k[0] < 0 or k[-1] >= ctx.f.size:
        return False
    for c in chans:
        p = np.nanmedian(ctx.sp.psd[c][runs][:, k], axis=0)
        if p[1] >= PEAKINESS * max(p[0], p[2]):
            return True
    return False


def _measure(ctx, k0: int, chans) -> FixedLine | None:
    """The fixed line near Welch bin ``k0`` on ``chans``: its frequency refined on the whole records (the maximum of
    the median over up to :data:`REFINE_RUNS` runs of Σ|X|² over the channels, a parabola through the grid's top three
    points), its amplitude in every run and channel (:func:`run_amplitudes`), the runs where it is lit, its level and
    mean square; None without a channel or when its amplitude is not steady from run to run (:data:`STEADY_FRACTION`
    of the runs within :data:`STEADY_RATIO` of the median, in some channel: a source at one frequency is steady,
    where wheel lines passing a frequency in many runs give it amplitudes of every size)."""
    if not chans:
        return None
    runs = ctx.runs
    f0 = _refine(ctx, k0, chans)
    if f0 is None:
        return None
    A = run_amplitudes(ctx, f0, chans)                                                   # (all runs, chans)
    mag = np.abs(A[runs])
    # a channel no run reads the tone in (every fit past its misfit limit: trial 33's fixture at 100 Hz) has no median,
    # and numpy's all-NaN warning would reach the console
    read = np.isfinite(mag).any(axis=0)
    med = np.full(mag.shape[1], np.nan)
    med[read] = np.nanmedian(mag[:, read], axis=0)
    # over the runs that have the channel (one absent from some runs is not unsteady for it; a run whose tone fit
    # failed is: the wheel's axial mode rung by a broadband floor, a peak at 139 Hz of a random amplitude, passed)
    near = (mag <= STEADY_RATIO * med) & (mag >= med / STEADY_RATIO)
    have = np.stack([np.isfinite(ctx.sp.psd[c][runs, 0]) for c in chans], axis=1)
    within = np.sum(near, axis=0) / np.maximum(np.sum(have, axis=0), 1)
    steady = within >= STEADY_FRACTION
    if not np.any(steady):
        return None
    # the channels that carry it are those it is steady in: a new user's 50 Hz pickup on Fz and Tz was also listed on
    # Fx, Fy, Tx and Ty, lit near 50 Hz in 88-93 % of the runs by the wheel's lines crossing it (amplitudes of every
    # size: interquartile range 2-5x the median, where the pickup's is 0)
    chans = tuple(c for c, keep in zip(chans, steady) if keep)
    A, mag, med = A[:, steady], mag[:, steady], med[steady]
    lit_runs = set()
    ms, levels = {}, []
    for j, c in enumerate(chans):
        ok = np.isfinite(ctx.sp.psd[c][runs, 0])
        r_ok = runs[ok]
        lit = _lit(ctx.sp.psd[c][r_ok], ctx.floor[c][r_ok], ctx.dof)[:, k0]
        lit_runs |= set(int(r) for r in r_ok[lit])
        ratio = ctx.sp.psd[c][r_ok, k0] / np.maximum(ctx.floor[c][r_ok, k0], 1e-300)
        levels.append(float(np.median(10 * np.log10(np.maximum(ratio, 1e-30)))))
        ms[c] = float(med[j] ** 2 / 2.0)
    return FixedLine(f0, tuple(chans), tuple(sorted(lit_runs)), float(np.max(levels)), ms, A)


def _refine(ctx, k0: int, chans) -> float | None:
    """The frequency (Hz) of the fixed line near Welch bin ``k0``: the maximum, within ±:data:`REFINE_HALF_BINS` Welch
    bins, of the median over up to :data:`REFINE_RUNS` runs (a wheel line crossing it in a run would pull a sum) of
    Σ|X|² over ``chans`` on each run's whole-record transform zero-padded to a grid of
    :data:`REFINE_STEP_RECORD_BINS` record bins (one FFT per run), a parabola through the top three points of its
    logarithm; None when the runs are of several lengths."""
    from scipy import fft as sp_fft

    from ..dft import demeaned_windowed, run_window

    runs = ctx.runs
    rows = runs[np.linspace(0, runs.size - 1, min(REFINE_RUNS, runs.size)).round().astype(int)]
    rows = [r for r in rows if all(ctx.test.runs[r].usable(c) for c in chans)]
    if not rows or len({ctx.test.runs[r].n_samples for r in rows}) != 1:
        return None
    n = ctx.test.runs[rows[0]].n_samples
    pad = int(round(1.0 / REFINE_STEP_RECORD_BINS))
    step = ctx.sp.sample_rate / (n * pad)
    k = np.arange(int((k0 - REFINE_HALF_BINS) * ctx.df / step), int((k0 + REFINE_HALF_BINS) * ctx.df / step) + 1)
    if k[0] < 1 or k[-1] >= pad * n // 2:
        return None
    w, _, _ = run_window(ctx.sp.window, n)
    p = np.array([np.sum(np.abs(sp_fft.rfft(demeaned_windowed([ctx.test.runs[r].signals[c] for c in chans], w),
                                           pad * n, axis=-1)[:, k]) ** 2, axis=0) for r in rows])
    p = np.median(p, axis=0)
    i = int(np.clip(np.argmax(p), 1, k.size - 2))
    lo, mid, hi = np.log(np.maximum(p[i - 1:i + 2], 1e-300))
    den = lo - 2 * mid + hi
    return float((k[i] + (0.5 * (lo - hi) / den if den < 0 else 0.0)) * step)


def run_amplitudes(ctx, f_hz, chans) -> np.ndarray:
    """Complex amplitude (n_runs, len(chans)) of a tone at ``f_hz`` (Hz: one frequency, or one per run of the test,
    NaN for a run not read) in every run (all of the test's, NaN where a channel is missing) and channel: from the
    run's whole-record transform (Hann, the mean taken off, zero-padded to 1/:data:`TONE_GRID_STEP` points per record
    bin: one FFT per run) at the points within ±:data:`TONE_GRID_BINS` record bins of it (:func:`_tone_amplitudes`:
    beside a wheel line passing it in that run, the two fitted together)."""
    from scipy import fft as sp_fft

    from ..dft import demeaned_windowed, run_window

    test = ctx.test
    out = np.full((len(test.runs), len(chans)), np.nan + 0j)
    pad = int(round(1.0 / TONE_GRID_STEP))
    f_runs = np.broadcast_to(np.asarray(f_hz, dtype=float), (len(test.runs),))
    for i, run in enumerate(test.runs):
        have = [j for j, c in enumerate(chans) if run.usable(c)]
        f_hz = float(f_runs[i])
        if not have or not np.isfinite(f_hz):
            continue
        n = run.n_samples
        rec_bin = run.sample_rate / n
        k = np.arange(int(np.ceil((f_hz / rec_bin - TONE_GRID_BINS) * pad)),
                      int(np.floor((f_hz / rec_bin + TONE_GRID_BINS) * pad)) + 1)
        if k[0] < 0 or k[-1] >= pad * n // 2:
            continue
        w, wsum, _ = run_window(ctx.sp.window, n)
        x = demeaned_windowed([run.signals[chans[j]] for j in have], w)
        X = 2.0 * sp_fft.rfft(x, pad * n, axis=-1)[:, k] / wsum                       # (K, G)
        offsets = k / pad - f_hz / rec_bin
        out[i, have] = _tone_amplitudes(X, offsets, n)
    return out


def _tone_amplitudes(X: np.ndarray, offsets: np.ndarray, n: int) -> np.ndarray:
    """The complex amplitude of a tone at offset 0 from whole-record phasors ``X`` (..., G) read at ``offsets`` (G,)
    record bins around it: the least squares of X on the tone's Hann response W(δ)/W(0), or, where a second tone at
    an offset of at least :data:`SECOND_TONE_MIN_BINS` (a wheel line passing the fixed one in that run) fits the
    phasors :data:`SECOND_TONE_GAIN` times better, of X on both responses (the second tone's offset the best of the
    grid's); NaN where the fit leaves more than :data:`TONE_MISFIT` of the phasors' power."""
    from .measure import hann_transform_ratio

    t0 = hann_transform_ratio(n, offsets)                                              # (G,)
    a1 = (X @ np.conj(t0)) / np.vdot(t0, t0).real
    r1 = np.sum(np.abs(X - a1[..., None] * t0) ** 2, axis=-1)
    cand = offsets[np.abs(offsets) >= SECOND_TONE_MIN_BINS]
    tw = hann_transform_ratio(n, offsets[None, :] - cand[:, None])                     # (K, G)
    # the 2x2 normal equations of (a0, aw) for every candidate offset at once
    g00 = np.vdot(t0, t0).real
    g01 = tw.conj() @ t0                                                               # (K,) = <tw, t0>
    g11 = np.sum(np.abs(tw) ** 2, axis=1)
    b0 = X @ np.conj(t0)                                                               # (...,)
    bw = X @ np.conj(tw).T                                                             # (..., K)
    det = g00 * g11 - np.abs(g01) ** 2
    a0 = (g11 * b0[..., None] - np.conj(g01) * bw) / det
    aw = (g00 * bw - g01 * b0[..., None]) / det
    r2 = np.sum(np.abs(X[..., None, :] - a0[..., None] * t0 - aw[..., None] * tw) ** 2, axis=-1)      # (..., K)
    best = np.argmin(r2, axis=-1)
    r2b = np.take_along_axis(r2, best[..., None], -1)[..., 0]
    a0b = np.take_along_axis(a0, best[..., None], -1)[..., 0]
    two = r2b * SECOND_TONE_GAIN < r1
    # a wheel line inside the fixed one's main lobe (not told apart by either fit) leaves a misfit: no amplitude then
    misfit = np.where(two, r2b, r1) / np.maximum(np.sum(np.abs(X) ** 2, axis=-1), 1e-300)
    return np.where(misfit <= TONE_MISFIT, np.where(two, a0b, a1), np.nan + 0j)


def remove_fixed_lines(ctx, lines) -> SteadyTest:
    """A copy of the context's test with every line of ``lines`` subtracted from each run's records: x − Re(A·e^{2πj f
    t}), A the line's amplitude in that run and channel (:attr:`FixedLine.amplitudes`), in every channel that carries
    it, except in a run whose amplitude is more than :data:`SAME_AMPLITUDE` times from the median over the runs (a
    wheel line at the same frequency there, not told apart).  A line's ``f_runs`` (a fixed line's sideband,
    :class:`rwadist.diagnose.describe_carrier.Sideband`), when it has one, gives its frequency in each run instead of
    ``f_Hz``.  The runs' signals are new arrays (the input is not changed)."""
    test = ctx.test
    tones = []
    for ln in lines:
        A = ln.amplitudes
        mag = np.abs(A)
        # a channel with no run read (a sideband's tone not fitted in any run of it) is not corrected
        med = np.array([np.median(m[np.isfinite(m)]) if np.isfinite(m).any() else np.nan for m in mag.T])
        A = np.where((np.abs(A) > SAME_AMPLITUDE * med) | (np.abs(A) < med / SAME_AMPLITUDE), np.nan, A)
        f_runs = np.broadcast_to(np.asarray(getattr(ln, "f_runs", ln.f_Hz), dtype=float), (len(test.runs),))
        tones += [(c, f_runs, A[:, j]) for j, c in enumerate(ln.channels)]
    return subtract_tones(test, tones)


def subtract_tones(test, tones) -> SteadyTest:
    """A copy of ``test`` with each tone of ``tones`` ((channel, frequency Hz per run (R,), complex amplitude per run
    (R,))) subtracted from its channel's records: x − Re(A·e^{2πj f t}), in every run where both are finite and the
    channel is usable.  The runs' signals are new arrays (the input is not changed)."""
    from ..data import SteadyTest

    new_signals = [dict(r.signals) for r in test.runs]
    for i, run in enumerate(test.runs):
        n = np.arange(run.n_samples)
        for c, f_runs, A in tones:
            if np.isfinite(f_runs[i]) and np.isfinite(A[i]) and run.usable(c):
                e = np.exp(2j * np.pi * f_runs[i] * n / run.sample_rate)
                new_signals[i][c] = new_signals[i][c] - np.real(A[i] * e)
    return SteadyTest([replace(r, signals=s) for r, s in zip(test.runs, new_signals)], dict(test.meta))


def mains_family(freqs) -> tuple | None:
    """(mains Hz, orders) when every frequency of ``freqs`` is a whole multiple of one mains frequency of
    :data:`MAINS_HZ` within 0.5 % (at least one of them the fundamental or an order up to 9), else None: the mains
    first (50 Hz before 60 Hz: 300 Hz stays the 50 Hz mains' sixth order, a six-pulse rectifier's ripple), unless the
    400 Hz supply holds them at lower orders (a 400 Hz line is that supply's fundamental before it is the 50 Hz mains'
    eighth order: trial15's inverter)."""
    found = []
    for m in MAINS_HZ:
        orders = [f / m for f in freqs]
        if all(o >= 0.9 and abs(o - round(o)) <= 0.005 * o for o in orders) and min(orders) < 9.5:
            found.append((m, tuple(int(round(o)) for o in orders)))
    mains = [x for x in found if x[0] < 100.0]
    supply = [x for x in found if x[0] >= 100.0]
    pick = mains[0] if mains else None
    if supply and (pick is None or max(supply[0][1]) < max(pick[1])):
        pick = supply[0]
    return pick


def fundamental_of(f_hz: float, freqs) -> float | None:
    """The lowest of ``freqs`` (Hz) of which ``f_hz`` is a whole multiple of order 2 or more within 0.5 %, or None (the
    session-54 new-user trial's lab machine at 37 Hz: its 74 and 111 Hz lines were each described alone)."""
    for f in sorted(freqs):
        k = f_hz / f if f > 0 else 0.0
        if round(k) >= 2 and abs(k - round(k)) <= 0.005 * k:
            return float(f)
    return None


def describe_fixed_lines(ctx, lines, shares: dict) -> list:
    """:class:`~rwadist.diagnose.unexplained.Unexplained` records (signature ``fixed_line``) of ``lines``, one per
    line; ``shares``: line index -> (share of the misplaced power, level over the model dB) measured on the data as
    given (:func:`rwadist.diagnose.describe.fixed_line_shares`)."""
    from .unexplained import Unexplained

    family = mains_family([ln.f_Hz for ln in lines]) if lines else None
    out = []
    for i, ln in enumerate(lines):
        speeds = ctx.omega[list(ln.runs)] * RAD_S_TO_RPM if ln.runs else np.array([np.nan])
        share, level = shares.get(i, (np.nan, ln.level_dB))
        mains = family if family is not None else mains_family([ln.f_Hz])
        causes: tuple[str, ...]
        if mains is not None:
            m, orders = mains
            k = int(round(ln.f_Hz / m))
            supply = "mains" if m < 100 else "supply (an aircraft or ground power supply, a converter's switching)"
            causes = (f"electrical pickup: order {k} of the {m:g} Hz {supply}" + (
                f" (the fixed lines found are orders {', '.join(map(str, orders))} of it)" if family and len(
                    orders) > 1 else ""),)
            tell = "a run with the wheel still and its electronics on shows pickup at the same frequency; so do " \
                   "runs with the load cell's cables rerouted or its amplifier grounded differently (pickup changes)"
        else:
            base = fundamental_of(ln.f_Hz, [x.f_Hz for x in lines])
            own = (f"order {int(round(ln.f_Hz / base))} of the fixed line at {base:.4g} Hz: the same source's harmonic "
                   "(a machine's or a clock's line is seldom a pure tone)",) if base is not None else ()
            causes = own + ("a machine of the stand or near it (a pump, a fan, a compressor) or a clock of the "
                            "electronics", "a structural resonance of the stand excited by a steady source")
            tell = "a run with the wheel still (electronics on, then off) tells the stand's sources from the wheel's " \
                   "electronics; a line the wheel makes moves with its speed"
        out.append(Unexplained(
            signature="fixed_line", channels=ln.channels,
            speed_rpm=(float(np.nanmin(speeds)), float(np.nanmax(speeds))), f_Hz=(ln.f_Hz, ln.f_Hz),
            level_dB=level, share=share, n_runs=len(ln.runs),
            parameters={"f_Hz": ln.f_Hz, "level_over_floor_dB": ln.level_dB,
                        "rms": {c: float(np.sqrt(v)) for c, v in ln.mean_square.items()},
                        "removed_before_the_search": True},
            causes=causes, would_tell=tell))
    return out
