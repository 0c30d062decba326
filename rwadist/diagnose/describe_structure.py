"""Detectors of the open world (issue 33, item 3) on the final model's residual: a run-to-run change of the lines,
a resonance whose frequency moves with the speed (docs/diagnose.md, "Unexplained residual"; a broadband hump is
:mod:`.describe_hump`'s).  Each returns :class:`~rwadist.diagnose.unexplained.Unexplained` records; :mod:`.describe` runs them.

The lines' measured-over-predicted ratios (:func:`line_ratios`) are read per direction (the power of the direction's
channels summed: a radial line's x and y powers differ run by run by the random co/counter cross term, their sum
does not), for the lines standing :data:`LINE_SNR_DB` over the noise in their window.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .constants import LINE_HALF
from .describe_whirl import rocking_whirl, whirl_note
from .line_offsets import line_indicator, offset_free_sse
from .sweep_crossing import crossings
from .unexplained import Unexplained, _number

#: A line's predicted power over the noise in its window, at least, for its ratio to be read (dB).
LINE_SNR_DB = 20.0
#: ... and for a run to tell whether it holds the line at all (``line_ratios(absent=True)``, read by
#: :mod:`.describe_partial`): the noise alone then reads 13 dB under the model, 3 dB past ``ABSENT_DB`` (−10 dB), and
#: a present line within 0.2 dB of it.  At LINE_SNR_DB a weaker direction's share of one line went unread (session 60's
#: trial: h 5.46 absent under 3000 rpm on the radial force and torque, the torque's 14-17 dB over its window's noise
#: where present: named on Fx Fy alone)
ABSENT_SNR_DB = 13.0


@dataclass
class LineRatios:
    """Measured over predicted power of the model's lines, per direction: ``q`` dB, frequency ``f`` Hz, the run's
    position ``run`` in the context's runs, its spin frequency ``spin`` Hz, the line's index ``line`` and ratio
    ``h``, and the weight ``w`` (the line's SNR, capped at 40 dB: the ratio's own noise is then far below the
    model's misfits)."""

    direction: str
    q: np.ndarray
    f: np.ndarray
    run: np.ndarray
    spin: np.ndarray
    line: np.ndarray
    h: np.ndarray
    w: np.ndarray


def line_ratios(ctx, state, absent: bool = False) -> list:
    """The :class:`LineRatios` of every direction with lines (the context's runs).  ``absent``: the runs where the
    measured line power is 0 kept too (``q`` then held at −100 dB: a line the run lacks)."""
    runs = ctx.runs
    out = []
    for d, direction_chans in DIRECTION_CHANNELS.items():
        chans = [c for c in direction_chans if c in ctx.channels]
        if not chans:
            continue
        meas, pred, noise, hs = None, None, None, None
        for c in chans:
            cl = ctx.channel_lines(state, c, runs)
            if not cl:
                break
            h = np.array([x[0] for x in cl])
            if hs is not None and (h.size != hs.size or np.any(np.abs(h - hs) > 1e-9)):
                break
            hs = h
            f = h[:, None] * ctx.omega[runs][None, :] / (2 * np.pi)                        # (L, R)
            a = np.array([x[2] for x in cl]) * ctx.gain(state, c, f)
            m = ctx.measure_lines(state, c, runs)                                           # (L, R) amplitude
            k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)
            nz = ctx.floor_psd(state, c, runs)[np.arange(runs.size)[None, :], k] * ctx.df * (2 * LINE_HALF + 1)
            ok = np.isfinite(ctx.sp.psd[c][runs, 0])[None, :]
            mp, pp = np.where(ok, np.nan_to_num(m) ** 2 / 2, np.nan), np.where(ok, a**2 / 2, np.nan)
            meas = mp if meas is None else meas + mp
            pred = pp if pred is None else pred + pp
            noise = nz if noise is None else noise + nz
        else:
            if hs is None or meas is None or pred is None or noise is None:     # (set together, by the first channel)
                continue
            snr = pred / np.maximum(noise, 1e-300)
            good = np.isfinite(meas) & (meas > 0) & (snr >= 10 ** (LINE_SNR_DB / 10))
            if absent:
                # a line measured 0 inside the band the lines are read in (outside it, 0 means not read)
                k = np.rint(hs[:, None] * ctx.omega[runs][None, :] / (2 * np.pi) / ctx.df).astype(int)
                inband = (k - LINE_HALF >= ctx.k_lo) & (k + LINE_HALF <= ctx.k_hi)
                good = np.isfinite(meas) & (meas >= 0) & inband & (snr >= 10 ** (ABSENT_SNR_DB / 10))
            li, ri = np.nonzero(good)
            keep = ~crossings(ctx, state, hs[li], ri)      # a sweep's line passing a mode: not its steady response
            li, ri = li[keep], ri[keep]
            if li.size < 3:
                continue
            f = hs[li] * ctx.omega[runs][ri] / (2 * np.pi)
            q = 10 * np.log10(np.maximum(meas[li, ri], 1e-10 * pred[li, ri]) / pred[li, ri])
            out.append(LineRatios(d, q, f, ri, ctx.omega[runs][ri] / (2 * np.pi),
                                  li, hs[li], np.minimum(snr[li, ri], 1e4)))
    return out


# ----------------------------------------------------------------------------------------------- run-to-run change
#: The runs' common factor must scatter about a smooth trend with speed by at least this much (dB, robust std; on
#: clean data of the wheel family it scatters by 0.004 dB) ...
RUN_SCATTER_DB = 0.25
#: ... with at least this many runs (and this fraction of them) beyond it, each with RUN_MIN_LINES lines at least.
RUN_MIN_RUNS = 3
RUN_MIN_FRACTION = 0.2
RUN_MIN_LINES = 2


def _smooth_trend(x: np.ndarray, y: np.ndarray, half: int = 3, keep: np.ndarray | None = None) -> np.ndarray:
    """A smooth trend of ``y`` in the order of ``x``: a straight line (Theil-Sen: the median of the pairwise slopes)
    plus a running median of what it leaves over the ``half`` neighbours on either side; with ``keep`` (bool, like
    ``y``), both from the kept points alone, the running median over the ``half`` kept neighbours on either side (and
    the point itself when kept).  The line first: at the ends of the speed range the window is one-sided, and a
    running median alone lags a sloped trend there (0.35 dB at a 0.14 dB-per-run slope)."""
    from scipy.stats import theilslopes

    order = np.argsort(x)
    xs, ys = x[order], y[order]
    kept = np.flatnonzero(np.ones(ys.size, bool) if keep is None else np.asarray(keep)[order])
    out = np.full(ys.shape, np.nan)
    if kept.size:
        line = np.full(ys.shape, float(np.median(ys[kept])))
        if kept.size >= 3 and np.ptp(xs[kept]) > 0:
            slope, icpt = theilslopes(ys[kept], xs[kept])[:2]
            line = icpt + slope * xs
        out = line + _window_medians(ys - line, kept, half)
    back = np.empty_like(out)
    back[order] = out
    return back


def _window_medians(rest: np.ndarray, kept: np.ndarray, half: int) -> np.ndarray:
    """Per point i of ``rest`` (n,), the median of ``rest`` over the ``half`` points of ``kept`` (increasing indices, at
    least one) on either side of i, and i itself when kept: the numbers of :func:`numpy.median` of each window (the
    middle value, or the mean of the two middle ones; NaN when the window holds one), all windows at once."""
    n = rest.size
    p = np.searchsorted(kept, np.arange(n))
    own = (p < kept.size) & (kept[np.minimum(p, kept.size - 1)] == np.arange(n))
    lo = np.maximum(p - half, 0)
    count = np.minimum(p + half + own, kept.size) - lo
    idx = lo[:, None] + np.arange(2 * half + 1)[None, :]
    inside = np.arange(2 * half + 1)[None, :] < count[:, None]
    vals = np.where(inside, rest[kept[np.minimum(idx, kept.size - 1)]], np.inf)
    nan = np.any(np.isnan(vals), axis=1)
    srt = np.sort(np.where(np.isnan(vals), np.inf, vals), axis=1)
    rows = np.arange(n)
    upper = srt[rows, count // 2]
    med = np.where(count % 2 == 1, upper, (srt[rows, np.maximum(count // 2 - 1, 0)] + upper) / 2.0)
    return np.where(nan, np.nan, med)


def per_run_median(ratios: list, n_runs: int, min_points: int, min_lines: int, detrend) -> np.ndarray:
    """Per run (n_runs,): the median over its lines of each line's dB ratio less ``detrend(r, m)`` (that line's
    reference, (m.sum(),), for :class:`LineRatios` ``r`` and the line's mask ``m``), lines read in ``min_points``
    runs at least; NaN for a run with fewer than ``min_lines`` such lines."""
    devs, runs = [], []
    for r in ratios:
        for ln in np.unique(r.line):
            m = r.line == ln
            if m.sum() >= min_points:
                devs.append(r.q[m] - detrend(r, m))
                runs.append(r.run[m])
    per = np.full(n_runs, np.nan)
    if not devs:
        return per
    dev, run = np.concatenate(devs), np.concatenate(runs)
    for i in np.flatnonzero(np.bincount(run, minlength=n_runs) >= min_lines):
        per[i] = np.median(dev[run == i])
    return per


def _run_deviations(ctx, ratios: list, apart: np.ndarray | None = None) -> np.ndarray:
    """Per run of the context (R,): the median over its lines of each line's dB ratio less that line's own smooth
    trend with speed (:func:`_smooth_trend` over the line's runs; with ``apart``, a bool (R,), over its runs not set
    apart), NaN for a run with fewer than :data:`RUN_MIN_LINES` such lines.  Each line detrended on its own: a
    resonance crossing lifts one line in a run (a bump on that line's trend), a change of the run lifts all of them
    alike."""

    def trend(r, m):
        return _smooth_trend(r.spin[m], r.q[m], keep=None if apart is None else ~apart[r.run[m]])

    return per_run_median(ratios, ctx.runs.size, 2 * RUN_MIN_RUNS + 1, RUN_MIN_LINES, trend)


#: Rounds of :func:`_changed_runs`: the runs set apart, the lines' trends made again without them
RUN_ROUNDS = 3


def _flag_runs(per: np.ndarray) -> tuple | None:
    """(dev, off, scatter) of the per-run deviations ``per`` (R,): each finite run's offset from their median (dB), the
    runs beyond :data:`RUN_SCATTER_DB` and 3 × the robust scatter (beyond the scatter itself when that exceeds
    RUN_SCATTER_DB), the scatter; None when too few runs are finite or set apart."""
    ok = np.isfinite(per)
    if ok.sum() < 2 * RUN_MIN_RUNS + 1:
        return None
    dev = np.full(per.shape, np.nan)
    dev[ok] = per[ok] - np.median(per[ok])
    scatter = 1.4826 * float(np.median(np.abs(dev[ok])))
    off = ok & (np.abs(np.nan_to_num(dev)) > max(RUN_SCATTER_DB, (1.0 if scatter >= RUN_SCATTER_DB else 3.0) * scatter))
    if off.sum() < max(RUN_MIN_RUNS, RUN_MIN_FRACTION * ok.sum()):
        return None
    return dev, off, scatter


def _changed_runs(ctx, ratios: list) -> tuple | None:
    """(idx, dev, off, scatter, unread): the positions ``idx`` in the context's runs of the runs a change sets apart,
    the offsets ``dev`` (dB) of the runs with a deviation and the mask ``off`` of those set apart among them, the
    robust scatter, the positions of the runs with no deviation (too few lines read) (:func:`_flag_runs` on :func:`_run_deviations`); None when no change is seen.  A few runs changed (the scatter below
    RUN_SCATTER_DB): the lines' trends are made again from the other runs alone, up to :data:`RUN_ROUNDS` times, so
    that the changed runs do not pull the trend of their neighbours (every third run 3.5 dB up: the top run's window
    held two of them, it read 1.75 dB and its two neighbours −1.3 and −0.9 dB, none changed)."""
    got = _flag_runs(_run_deviations(ctx, ratios))
    if got is None:
        return None
    for _ in range(RUN_ROUNDS - 1):
        dev, off, scatter = got
        if scatter >= RUN_SCATTER_DB:
            break
        again = _flag_runs(_run_deviations(ctx, ratios, apart=off))
        if again is None or np.array_equal(again[1], off):
            got = again or got
            break
        got = again
    dev, off, scatter = got
    ok = np.isfinite(dev)
    return np.flatnonzero(off), dev[ok], off[ok], scatter, np.flatnonzero(~ok)


def run_change(ctx, ratios: list, shares, order: dict | None = None) -> list:
    """A run-to-run change: every line of a run (all directions together) off the model by a common factor (a load
    cell's gain drifting over the test, a wheel re-mounted between runs, an amplifier's range switched).  Each
    line's dB ratio less its own smooth trend with speed, the median over the run's lines (:func:`_run_deviations`);
    described when :data:`RUN_MIN_RUNS` runs (a fifth of them at least) stand beyond :data:`RUN_SCATTER_DB` and
    beyond 3 × the runs' robust scatter (a few runs switched: the others stay on the trend), or the robust scatter
    itself exceeds :data:`RUN_SCATTER_DB` (a drift in the order of recording, the speeds shuffled); first, where the
    order of recording is known, a step or a drift read in it (``order``: :func:`.run_order.read_in_recorded_order`,
    made by the caller: a step sets the runs recorded after it apart, a drift every run).  ``pattern`` "step" (a few
    runs off the others' trend: a re-mounting or a range switched named first) or "spread" (a drift named first)."""
    if not ratios:
        return []
    order = order or {"recorded_order": "unknown", "kind": None}
    got = order["runs"] if order["kind"] is not None else _changed_runs(ctx, ratios)
    if got is None:
        return []
    idx, dev, off, scatter, unread = got
    rpm = ctx.omega[ctx.runs[idx]] * RAD_S_TO_RPM

    def names_of(pos):
        return [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in ctx.runs[pos]]

    names = names_of(idx)
    share, _ = shares(ctx.runs[idx])
    # a step: a few runs set apart from others that stay on their trend (the scatter small), whatever their factors
    # (two re-mountings may go opposite ways; a drift moves every run); a spread: the runs' offsets scattered beyond
    # RUN_SCATTER_DB (a drift in the order of recording)
    step = order["kind"] == "step" if order["kind"] is not None else scatter < RUN_SCATTER_DB
    words = order.get("words", "")
    causes = (("the wheel or the fixture re-mounted or re-torqued between runs" + (words if step else ""),
               "an amplifier range or filter switched between runs"),
              ("the load cell's or its amplifier's gain drifting over the test (temperature, a bridge supply)" +
               ("" if step else words),))
    tell = ("a repeated run at one speed at the start and the end of the test" if order["recorded_order"] == "known"
            else "the runs in the order they were recorded (a drift grows with time; a re-mounting is a step) and a "
                 "repeated run at one speed at the start and the end of the test")
    return [Unexplained(
        signature="run_change", channels=tuple(c for c in ctx.channels if any(c in DIRECTION_CHANNELS[r.direction]
                                                                               for r in ratios)),
        speed_rpm=(float(rpm.min()), float(rpm.max())),
        f_Hz=(float(np.min(np.concatenate([r.f for r in ratios]))), float(np.max(np.concatenate([r.f for r in ratios])))),
        level_dB=float(np.median(np.abs(dev[off]))), share=share, n_runs=int(idx.size),
        parameters={"scatter_dB": float(scatter), "largest_dB": float(np.max(np.abs(dev))),
                    "runs": names, "run_speeds_rpm": [float(x) for x in rpm],
                    "run_offsets_dB": [float(x) for x in dev[off]], "runs_not_read": names_of(unread),
                    "pattern": "step" if step else "spread", "recorded_order": order["recorded_order"],
                    **order.get("parameters", {})},
        causes=causes[0] + causes[1] if step else causes[1] + causes[0], would_tell=tell)]


# ----------------------------------------------------------------------------------------------- moving resonance
#: A direction's lines must be lifted this much (dB) in one run at least for a resonance to be looked for (a
#: resonance of peak gain 2 lifts the lines that cross it by 6 dB), and this much (dB) in two runs at least: the
#: lifted points bound its track, and a track needs two.  Only the line nearest the resonance's peak in a run is
#: lifted by much when the runs are sparse against its width (family wheel 7: 16 runs, a line h 3.42 moving 32 Hz
#: from run to run past a softening resonance of half-power width 2ζf = 16 Hz: lifted 12 dB in one run, 2-3 dB in
#: two others); whether it moves is the F test's to say (:data:`MOVING_F`).
MOVING_PEAK_DB = 3.0
MOVING_GATE_DB = 2.0
#: The moving track must drop the misfit a fixed resonance leaves by this many times the misfit per degree of freedom
#: (an F statistic of its one more parameter: 23 and 57 on the wheel family's moving resonances, at most 10 on its
#: other cases), leave at most MOVING_RATIO of that misfit and MOVING_NULL_RATIO of the misfit without a resonance.
MOVING_F = 15.0
MOVING_RATIO = 0.8
MOVING_NULL_RATIO = 0.5
#: ... and a track beside a fixed resonance only where the fixed ones leave a misfit a reviewer would see, at least
#: this RMS over the points (dB): below it the fixed shapes' own approximation (a line's ratio is read to about
#: 0.05 dB) is all that is left, which the pair's freedom fits (the wheel family's clean data with the modes not
#: fitted: at most 0.32 dB left, 8 of 11 directions "moving" without this; a softening resonance of peak gain 5
#: leaves 0.49-2.0 dB beside a fixed mode)
MOVING_MIN_MISFIT_DB = 0.45
#: Grids: the track's slope (Hz per Hz of spin), damping ratios, peak gains.
SLOPES = np.round(np.arange(-3.0, 3.0001, 0.1), 2)
ZETAS = (0.01, 0.02, 0.04, 0.08)
GAINS = (2.0, 3.5, 6.0, 10.0)
#: ... and the gain far above it: 1 (a resonance of the stand or the rotor, H -> 1 on both sides), 0 (a wheel mode
#: seen through its suspension, the transmissibility falling above it) or :data:`MASS_SHARE` (a mode carrying a share
#: of the rotor's mass), for the moving and the fixed alike
MASS_SHARE = None
GAINS_ABOVE: tuple = (1.0, 0.0, MASS_SHARE)


def gain_above(zeta: float, gain: float, above: float | None) -> float:
    """β, the gain far above the resonance, of a shape of :data:`GAINS_ABOVE`: ``above`` itself, or for
    :data:`MASS_SHARE` 1 − μ with μ = 2ζ·sqrt(g² − 1).

    A mode of the rotor holding a share μ of its mass (modal mass over the rotor's, ζ its damping ratio) adds
    μ·r²/(1 − r² + 2jζr) to the force the rigid rotor puts through its bearings at a line of frequency ratio r = f/f_r:
    H = (1 − (1 − μ)·r² + 2jζr)/(1 − r² + 2jζr), 1 below, 1 − μ far above, an antiresonance at r = 1/sqrt(1 − μ)
    between, peak |H(1)| = sqrt(1 + (μ/2ζ)²) = g (the general gain of :mod:`rwadist.resonance` with γ = 1).  The
    antiresonance takes lines just above the mode down by 10-20 dB, which neither other shape has."""
    if above is not None:
        return float(above)
    return 1.0 - 2.0 * zeta * float(np.sqrt(max(gain * gain - 1.0, 0.0)))


def _resonance_db(f: np.ndarray, f_r: np.ndarray, zeta: float, gain: float, above: float | None = 1.0) -> np.ndarray:
    """20·log10 |H| of the resonance (:func:`rwadist.resonance.resonance_response`, gain ``above`` far above it, or
    the shape of a mode holding a share of the rotor's mass: :func:`gain_above`) at ``f`` over ``f_r``."""
    from ..resonance import resonance_response

    beta = gain_above(zeta, gain, above)
    return 20 * np.log10(np.maximum(np.abs(resonance_response(f / f_r, zeta, gain, beta)), 1e-12))


def _track_fit(r: LineRatios, f0s: np.ndarray, slopes: np.ndarray, shapes=None, per_slope: bool = False):
    """(sse, f0, slope, zeta, gain, gain above) of the best track f_r = f0 + slope·(spin − spin_mid) over the grids
    (``shapes``: the (ζ, gain, gain above) tried, default every one of :data:`ZETAS`, :data:`GAINS` and
    :data:`GAINS_ABOVE`), each line's own offset (its C's misfit) taken out: the least squares of q on the
    resonance's dB gain per line; with ``per_slope``, the list of the best of each slope."""
    mid = 0.5 * (r.spin.min() + r.spin.max())
    onehot, count = line_indicator(r.line)                                          # (L, N), (L,)
    none = (np.inf, np.nan, np.nan, np.nan, np.nan, np.nan)
    best, each = none, []
    for b in slopes:
        if per_slope:
            each.append(best)
            best = none
        fr = f0s[:, None] + b * (r.spin[None, :] - mid)                               # (F, N)
        valid = np.all(fr > 0, axis=1)
        if not valid.any():
            continue
        fr = np.where(fr > 0, fr, 1.0)
        for z, g, above in shapes or ((z, g, a) for z in ZETAS for g in GAINS for a in GAINS_ABOVE):
            if above is MASS_SHARE and gain_above(z, g, above) <= 0.0:
                continue                # a mode of more than the rotor's whole mass (μ >= 1): no physical shape
            G = _resonance_db(r.f[None, :], fr, z, g, above)                      # (F, N)
            sse = np.where(valid, offset_free_sse(r.q[None, :] - G, onehot, count), np.inf)
            i = int(np.argmin(sse))
            if sse[i] < best[0]:
                best = (float(sse[i]), float(f0s[i]), float(b), z, g, above)
    return (each + [best])[1:] if per_slope else best


def _offsets_only(r: LineRatios) -> float:
    """The misfit left with each line's own offset only (no resonance)."""
    sse = 0.0
    for ln in np.unique(r.line):
        x = r.q[r.line == ln]
        sse += float(np.sum((x - x.mean()) ** 2))
    return sse


def _track_db(r: LineRatios, f0: float, slope: float, zeta: float, gain: float, above: float | None) -> np.ndarray:
    """The dB gain at every point of ``r`` of the resonance on the track f_r = f0 + slope·(spin − spin_mid)."""
    mid = 0.5 * (r.spin.min() + r.spin.max())
    return _resonance_db(r.f, np.maximum(f0 + slope * (r.spin - mid), 1e-6), zeta, gain, above)


#: The fine step's factors on the coarse best's ζ and peak gain (its shape kept): between the coarse grid's values
#: (a factor 1.7-2 apart) the place of a rotor mode's antiresonance (:func:`gain_above`) moves by several ζ, and the
#: lines just above the track read it (an independent trial's rotor mode at 1000 − 2·f_spin Hz on Fz, ζ 0.015, peak
#: gain 10: ζ 0.02, gain 6 on the coarse grids, 0.016 and 9.6 fine, the misfit 3.7 times smaller, slope −2.05)
FINE_FACTORS = (0.6, 0.8, 1.0, 1.25, 1.6)
#: ... from the best coarse fits of this many slopes (each its own, the best f0 and shape of that slope): the coarse
#: f0 grid (3 % steps) and shapes misplace a narrow peak and a rotor mode's antiresonance, which ranks the coarse
#: slopes unevenly (with one line crossing the track, a rotor mode at 900 − f_spin Hz on family wheel 5's lines:
#: +2.0 first, misfit 9.2; −1 refined from its own coarse best leaves 0.25.  The open world's softening resonance
#: on wheel 2: −0.2, −0.4, +0.2, −0.6 first; refined from −0.6 it leaves 1.8 at −0.58, from −0.2 3.9 at −0.25)
FINE_STARTS = 5


def _best_track(r: LineRatios, coarse: np.ndarray, slopes: np.ndarray, q: np.ndarray | None = None) -> tuple:
    """:func:`_track_fit` over the ``coarse`` f0 grid and ``slopes`` (every other one), then finely around the best
    (f0 to 0.5 %, the slope to 0.05 Hz/Hz, ζ and the peak gain by :data:`FINE_FACTORS`; a fixed resonance,
    ``slopes`` = [0], stays fixed); ``q``: the dB ratios fitted instead of ``r.q`` (what another resonance leaves)."""
    from dataclasses import replace

    rr = r if q is None else replace(r, q=q)
    fixed = slopes.size == 1 and slopes[0] == 0.0
    starts = sorted(_track_fit(rr, coarse, slopes if fixed else slopes[::2], per_slope=True), key=lambda t: t[0])
    best = starts[0]
    for start in [t for t in starts if np.isfinite(t[0])][:FINE_STARTS]:
        f0s = np.exp(np.arange(np.log(start[1]) - 0.04, np.log(start[1]) + 0.0401, 0.005))
        near = slopes if fixed else np.round(np.arange(start[2] - 0.2, start[2] + 0.2001, 0.05), 3)
        shapes = [(start[3] * a, max(start[4] * b, 1.1), start[5]) for a in FINE_FACTORS for b in FINE_FACTORS]
        best = min(best, _track_fit(rr, f0s, near, shapes), key=lambda t: t[0])
    return best


#: Rounds of the fit of a track beside a fixed resonance, each fitted in turn on what the other leaves.
PAIR_ROUNDS = 2
FIXED = np.array([0.0])


def _beside_fixed(r: LineRatios, coarse: np.ndarray, slopes: np.ndarray, fixed: tuple) -> tuple:
    """(sse, track, fixed) of a track of ``slopes`` fitted together with a fixed resonance (starting from ``fixed``),
    each in turn on what the other leaves (:data:`PAIR_ROUNDS`): a wheel mode the model lacks (its suspension modes
    not fitted) lifts the lines it crosses beside the moving resonance."""
    track = fixed
    for _ in range(PAIR_ROUNDS):
        track = _best_track(r, coarse, slopes, r.q - _track_db(r, *fixed[1:]))
        fixed = _best_track(r, coarse, FIXED, r.q - _track_db(r, *track[1:]))
    return fixed[0], track, fixed


def _moving_fit(r: LineRatios) -> tuple | None:
    """(track (sse, f0, slope, ζ, gain), misfit ratio to the fixed alternative, F statistic, fixed companion or None)
    of the resonance moving with speed that the dB ratios of ``r`` hold, or None (:func:`moving_resonance`): alone
    against one fixed resonance, else beside a fixed resonance against two fixed ones."""
    lifted = r.f[r.q >= MOVING_GATE_DB]
    coarse = np.exp(np.arange(np.log(0.7 * lifted.min()), np.log(1.3 * lifted.max()), 0.03))
    sse0 = _offsets_only(r)
    span = r.spin.max() - r.spin.min()
    n_lines = np.unique(r.line).size
    fix = _best_track(r, coarse, FIXED)

    def judged(mov, null_sse, companion, n_par, floor=0.0):
        sse_m, f0, b, zeta = mov[:4]
        # the moving track's one more parameter must pay: its drop of the misfit over the misfit per degree of freedom
        dof = max(r.q.size - n_lines - n_par, 1)
        f_stat = (null_sse - sse_m) / max(sse_m / dof, 1e-300)
        if (f_stat >= MOVING_F and sse_m <= MOVING_RATIO * null_sse and sse_m <= MOVING_NULL_RATIO * sse0
                and abs(b) * span > 2 * zeta * f0 and null_sse >= r.q.size * floor**2):
            return mov, sse_m / max(null_sse, 1e-300), f_stat, companion
        return None

    got = judged(_best_track(r, coarse, SLOPES), fix[0], None, 4)
    if got is None:                     # beside a fixed resonance, against two fixed ones
        sse, mov, companion = _beside_fixed(r, coarse, SLOPES, fix)
        # against the better of one and two fixed ones (a second resonance of the grids cannot be switched off)
        got = judged((sse,) + mov[1:], min(_beside_fixed(r, coarse, FIXED, fix)[0], fix[0]), companion, 8,
                     MOVING_MIN_MISFIT_DB)
    return got


def resolved_lines(ctx, state, r: LineRatios) -> LineRatios:
    """``r`` without the points of a line in a run where it is not resolved from the direction's other lines: where
    they predict more power in its window than it does (:func:`.describe_partial.others_in_window` over
    :data:`.describe_partial.OTHERS_IN_WINDOW_MAX`, the lines the effects added included).  There its measured power
    (:meth:`Context.measure_lines`: the data less the model's other lines) is its neighbours' misfit and beat as
    much as its own: a speed sideband 0.06·Ω/2π from its carrier read the carrier's misfit, lifted by 4-6 dB in the
    top three runs (family wheel 7's speed_sidebands, 1.2-1.9 bins from the carrier; the E-like wheel's at the
    default path), and a track through them was described as a moving resonance of 0 % share, and on the E-like
    wheel the true speed_sidebands effect was taken back as fitted to it."""
    from dataclasses import replace

    from .describe_partial import OTHERS_IN_WINDOW_MAX, others_in_window

    keep = np.ones(r.q.size, bool)
    for ln in np.unique(r.line):
        m = np.flatnonzero(r.line == ln)
        others = others_in_window(ctx, state, r.direction, float(r.h[m[0]]), ctx.runs[r.run[m]])
        keep[m] = others <= OTHERS_IN_WINDOW_MAX
    if keep.all():
        return r
    return replace(r, **{k: getattr(r, k)[keep] for k in ("q", "f", "run", "spin", "line", "h", "w")})


def steady_lines(r: LineRatios, df: float) -> LineRatios:
    """``r`` without the points of a line whose strength scatters from run to run (its ratios' spread about their
    neighbours' by speed :data:`.describe_partial.SCATTER_DB` or more, a third of its runs neither absent nor present:
    :func:`.describe_partial._scatter`; a line a moving resonance lifts in a few runs is not), nor those
    of another line within a line window (2·LINE_HALF + 1 bins of ``df`` Hz) of it in their run: its strong runs are no
    resonance's lift, and its leakage lifts its neighbours beyond what the model's line at its median strength
    predicts there (a line at h 2.3 of lognormal strength, 8 dB from run to run: moving resonances 'lifting lines up
    to +18.5 dB' were fitted through its strongest runs, and through h 2.0's runs where it leaked in)."""
    from dataclasses import replace

    from .describe_partial import _scatter

    scattering = [float(r.h[r.line == ln][0]) for ln in np.unique(r.line)
                  if _scatter(r.q[r.line == ln], r.spin[r.line == ln], r.w[r.line == ln])[1]]
    keep = np.ones(r.q.size, bool)
    for h_s in scattering:
        keep &= np.abs(r.h - h_s) * r.spin > (2 * LINE_HALF + 1) * df
    if keep.all():
        return r
    return replace(r, **{k: getattr(r, k)[keep] for k in ("q", "f", "run", "spin", "line", "h", "w")})


def moving_resonance(ctx, state, ratios: list, shares) -> list:
    """A resonance lifting the lines of one direction whose frequency moves with the speed.

    Where the lines of a direction are lifted by :data:`MOVING_PEAK_DB` in one run at least and by
    :data:`MOVING_GATE_DB` in two runs at least, their dB ratios are
    fitted with a resonance on a track f_r = f0 + b·(spin − spin_mid) (spin the rotation frequency, Hz; each line's
    own offset taken out), over grids of f0, the slope b, ζ and the peak gain (coarse, then fine around the best);
    the same with b = 0 (a fixed resonance).  Described when the moving track's one more parameter pays
    (:data:`MOVING_F`), it leaves at most :data:`MOVING_RATIO` of the misfit the fixed one leaves (and
    :data:`MOVING_NULL_RATIO` of the misfit without any) and it moves by more than its own half-power width over the
    speeds.  When it does not, the same beside a fixed resonance against two fixed ones (:func:`_beside_fixed`: a
    wheel mode the model lacks lifts other lines of the direction).  The gyroscopic whirl explains a moving
    resonance only on the radial torques (the rocking mode: forward whirl slope between 0 and I_zz/I_rr, backward
    falling): on a translation direction, no whirl does."""
    modes = next((e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"), None)
    out = []
    for r in ratios:
        if r.q.size < 8 or not np.any(r.q >= MOVING_PEAK_DB) or np.unique(r.run[r.q >= MOVING_GATE_DB]).size < 2 \
                or np.unique(r.line).size < 2:
            continue
        got = _moving_fit(r)
        if got is None:
            continue
        (sse_m, f0, b, zeta, gain, above), misfit_ratio, f_stat, companion = got
        mid = 0.5 * (r.spin.min() + r.spin.max())
        f_low, f_high = f0 + b * (r.spin.min() - mid), f0 + b * (r.spin.max() - mid)
        chans = tuple(c for c in DIRECTION_CHANNELS[r.direction] if c in ctx.channels)
        beside: dict = {} if companion is None else {"beside_fixed_resonance_Hz": float(companion[1]),
                                                     "beside_fixed_resonance_peak_gain": float(companion[4])}
        whirl, explained = whirl_note(r.direction, b, modes, r.spin.min(), r.spin.max(), f_low, f_high)
        if explained:
            continue
        rocking = rocking_whirl(r, modes, (f0, b, zeta, gain, gain_above(zeta, gain, above)), sse_m)
        if rocking is not None:
            whirl, beside["rocking_whirl"] = rocking[1], rocking[0]
        share, level = shares(chans, lambda spin: f0 + b * (spin - mid), zeta)
        rpm = np.array([r.spin.min(), r.spin.max()]) * 60.0
        sign = "stiffening" if b > 0 else "softening"
        track = lambda spin: f0 + b * (spin - mid)                                              # noqa: E731
        crossed = _crossed_mode(r.direction, modes, track, r.spin.min(), r.spin.max(), (zeta, gain, above))
        if crossed:
            beside["crosses_fitted_mode"] = crossed
        out.append(Unexplained(
            signature="moving_resonance", channels=chans, speed_rpm=(float(rpm[0]), float(rpm[1])),
            f_Hz=(float(min(f_low, f_high)), float(max(f_low, f_high))), level_dB=level, share=share,
            n_runs=int(np.unique(r.run).size),
            parameters={"direction": r.direction, "f_at_lowest_speed_Hz": float(f_low),
                        "f_at_highest_speed_Hz": float(f_high), "slope_Hz_per_Hz_of_spin": float(b),
                        "largest_line_lift_dB": float(np.max(r.q)),
                        **_lifted(r),
                        "zeta": float(zeta), "peak_gain": float(gain), **_shape_words(zeta, gain, above),
                        "fixed_resonance_misfit_ratio":
                        float(misfit_ratio), "f_statistic": float(f_stat), "whirl": whirl, **beside},
            causes=(() if rocking is None or not rocking[3] else (rocking[2],)) + _moving_causes(b, sign, track(mid), mid)
            + (() if rocking is None or rocking[3] else (rocking[2],)),
            would_tell=_crossing_words(crossed) + "a slow run-up recorded with its speed tracks the resonance "
                       "continuously; a tap test of the rotor at rest gives its frequency at zero speed"))
    return out


def _lifted(r: LineRatios) -> dict:
    """The points of ``r`` lifted by :data:`MOVING_GATE_DB` at least: their speeds (rpm), frequencies (Hz) and lifts
    (dB), by speed."""
    m = np.flatnonzero(r.q >= MOVING_GATE_DB)
    m = m[np.argsort(r.spin[m], kind="stable")]
    return {"lifted_rpm": [float(x) for x in r.spin[m] * 60.0], "lifted_Hz": [float(x) for x in r.f[m]],
            "lifted_dB": [float(x) for x in r.q[m]]}


#: A line lifted within this many Welch bins of a narrow line of no model (a tone's or a straight track's Hann lobe
#: and leakage; a review's 60 Hz + 1.3·f_spin, +34 dB over the model, lifted lines 0-3.9 bins from it by 2-6.5 dB)
#: ...
LEAK_BINS = 4.0
#: ... which stands this much (dB) over the most it lifts a line, at least: a resonance's own peak over the model is
#: the gain it lifts the lines at its peak by (a hump of noise through it lifts the floor as much), a foreign line's
#: leakage lifts them far less than it stands itself.
LEAK_MARGIN_DB = 6.0
#: A moving resonance whose lifted lines are at least this fraction a narrow line's leakage is that line's.
LEAK_FRACTION = 2.0 / 3.0


def _line_at(u, rpm: np.ndarray) -> np.ndarray:
    """The frequency (Hz) of the narrow-line record ``u`` (a ``fixed_line`` or an ``affine_line``) at ``rpm``, NaN
    outside its speeds."""
    from .describe_affine import track_of

    inside = (rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6)
    if u.signature == "affine_line":
        f = track_of(u, rpm / 60.0)
    else:
        f = np.full(rpm.shape, float(u.f_Hz[0]))
    return np.where(inside, f, np.nan)


def without_line_leaks(records: list, df: float) -> list:
    """``records`` without the ``moving_resonance`` records whose lifted lines (``lifted_rpm``/``lifted_Hz``) lie, at
    least :data:`LEAK_FRACTION` of them, within :data:`LEAK_BINS` Welch bins of ``df`` (Hz) of a described narrow line
    on one of its channels (a record with ``peak_over_model_dB``, :data:`LEAK_MARGIN_DB` over the largest lift): that
    line leaking into the model's lines it passes, not a resonance (a review's tone at 215 Hz in Fz over the top
    speeds lifted one line in two runs; a 60 Hz + 1.3·f_spin line on Fx, Fy lifted six points, and a track of slope 3.1
    was fitted through them)."""
    lines = [u for u in records if u.signature in ("fixed_line", "affine_line")
             and _number((u.parameters or {}).get("peak_over_model_dB")) is not None]
    if not lines:
        return records

    def leaks(m) -> bool:
        p = m.parameters or {}
        rpm, f = np.asarray(p.get("lifted_rpm", []), float), np.asarray(p.get("lifted_Hz", []), float)
        if m.signature != "moving_resonance" or rpm.size == 0 or f.size != rpm.size:
            return False
        near = np.zeros(rpm.size, bool)
        for u in lines:
            if set(u.channels) & set(m.channels) and \
                    u.parameters["peak_over_model_dB"] >= p.get("largest_line_lift_dB", np.inf) + LEAK_MARGIN_DB:
                with np.errstate(invalid="ignore"):
                    near |= np.abs(f - _line_at(u, rpm)) <= LEAK_BINS * df
        return bool(near.mean() >= LEAK_FRACTION)

    return [u for u in records if not leaks(u)]


#: A slope within this of a whole number n (Hz per Hz of spin) reads first as a mode of n nodal diameters of the
#: rotor seen from the stationary frame (its travelling waves at f_rotor ± n·f_spin), up to n = NODAL_MAX
NODAL_TOL = 0.25
NODAL_MAX = 4


def _moving_causes(slope: float, sign: str, f_mid: float, spin_mid: float) -> tuple:
    """The causes of a moving resonance of ``slope`` (Hz per Hz of spin) at ``f_mid`` Hz at the speeds' middle
    ``spin_mid`` Hz: a rotor mode of n nodal diameters seen from the stationary frame first when the slope is within
    :data:`NODAL_TOL` of ±n (its frequency in the rotor's frame, f_mid − n_signed·spin_mid, stays put), a mode
    stiffening or softening with speed and a drive resonance after."""
    centrifugal = (f"a mode of the rotor {sign} with speed (centrifugal {sign} of the disc or rim: an umbrella or "
                   "diaphragm mode, or the bearings' preload changing with speed)")
    drive = "a resonance of the motor's drive or speed loop whose frequency follows the speed"
    n = int(round(abs(slope)))
    if 1 <= n <= NODAL_MAX and abs(abs(slope) - n) <= NODAL_TOL:
        wave, op = ("backward", "−") if slope < 0 else ("forward", "+")
        f_rot = f_mid - np.sign(slope) * n * spin_mid
        if f_rot < 0:
            # a rising track below n·f_spin: the backward wave past its critical speed, |f_rotor − n·f_spin|
            wave, op, f_rot = "backward (past its critical speed, n·f_spin = f_rotor)", "−", -f_rot
        nodal = (f"a mode of the rotor with {n} nodal diameter{'s' if n > 1 else ''} (a disc, web or rim mode) at "
                 f"≈ {f_rot:.4g} Hz in the rotor's frame, seen in the stationary frame as its {wave} travelling wave "
                 f"at f_rotor {op} {n}·f_spin (a rotating-frame mode seen from the housing; an axisymmetric rotor's modes "
                 f"of {n} nodal diameters reach the bearings through its asymmetries)")
        # the rotor-frame frequency's own slope: the track's slope less the wave's n·f_spin (sign flipped for a
        # backward wave past its critical speed, where the housing sees n·f_spin − f_rotor)
        rest = slope - np.sign(slope) * n
        if "past" in wave:
            rest = -rest
        if abs(rest) >= 0.05:
            # the track's slope is not a whole number: say what the rest would be (trial24: 1.2 read as n = 1 alone)
            nodal += (f"; the measured slope {slope:+.2f} Hz per Hz of spin leaves {rest:+.2f} to the mode's own "
                      f"frequency in the rotor's frame: {'stiffening' if rest > 0 else 'softening'} with speed")
        return (nodal, centrifugal, drive)
    return (centrifugal, drive)


def _shape_words(zeta: float, gain: float, above) -> dict:
    """The fitted shape of a moving resonance (a :data:`GAINS_ABOVE` entry) as parameters: ``gain_far_above`` and
    ``shape``; for a mode holding a share of the rotor's mass (:func:`gain_above`) also ``mass_share`` μ and
    ``antiresonance_ratio`` 1/sqrt(1 − μ) (f over f_r)."""
    beta = gain_above(zeta, gain, above)
    if above is MASS_SHARE:
        out = {"shape": "a mode holding a share of the rotor's mass (1 below, 1 − μ above)", "gain_far_above": beta,
               "mass_share": 1.0 - beta}
        if 0.0 < beta < 1.0:
            out["antiresonance_ratio"] = float(1.0 / np.sqrt(beta))
        return out
    words = "1 on both sides" if beta == 1.0 else "the transmissibility falling above it"
    return {"shape": words, "gain_far_above": beta}


#: The directions' suspension modes a moving track can reach (the rocking mode whirls: :func:`.describe_whirl.whirl_note`)
DIRECTION_MODE = {"radial_force": "radial_translation", "axial_force": "axial"}
#: The track reaches a fitted mode of its direction where its fitted resonance changes a line at the mode's frequency
#: by this much (dB) at one of the speeds at least
REACH_DB = 1.0
#: ... counted only where the mode's frequency is within this factor of the track's
REACH_RATIO = 1.5


def _crossed_mode(direction: str, modes, track, s_lo: float, s_hi: float, shape: tuple) -> dict | None:
    """{"mode", "f_Hz", "speed_rpm", "lift_dB", "located"} of the fitted suspension mode of ``direction`` (``modes``:
    the ``suspension_modes`` effect, or None) that the moving resonance (``shape``: ζ, peak gain, gain above) on the
    track f(spin) = ``track(spin)`` reaches over the speeds ``s_lo``-``s_hi`` Hz: where a line at the mode's frequency
    is changed by at least :data:`REACH_DB` by it; the speed and change (dB) where the change is largest.  None when it
    reaches none.  The modes are fitted with the lines the track lifts near them: a mode it reaches is read with it
    (trial12: a rotor mode at 900 − 2·f_spin Hz passing the 560-Hz axial mode at the top speed, the axial mode fitted
    1.9 % low with ζ 0.008 for 0.025; at 1000 − 2·f_spin Hz, 18 % above it at the top speed and lifting a line there
    by 4-5 dB, ζ 0.015)."""
    name = DIRECTION_MODE.get(direction)
    if modes is None or name is None:
        return None
    f_m = float(modes.f0_Hz.get(name, np.nan))
    if not np.isfinite(f_m) or f_m <= 0:
        return None
    spin = np.linspace(s_lo, s_hi, 201)
    f_track = np.maximum(track(spin), 1e-6)
    lift = _resonance_db(np.full(spin.shape, f_m), f_track, *shape)
    # only where the mode lies near the track (within REACH_RATIO of it): far above it a shape falling to its
    # asymptote (1/r² of a transmissibility, 1 − μ of a mass share) changes every line, which is no reach of the mode
    lift = np.where(np.abs(np.log(f_m / f_track)) < np.log(REACH_RATIO), lift, 0.0)
    i = int(np.argmax(np.abs(lift)))
    if not abs(lift[i]) >= REACH_DB:
        return None
    return {"mode": name, "f_Hz": f_m, "speed_rpm": float(60.0 * spin[i]), "lift_dB": float(lift[i]),
            "located": name not in modes.unconstrained}


def _crossing_words(crossed: dict | None) -> str:
    """The words of :func:`_crossed_mode`'s crossing (empty without one), ahead of what would tell."""
    if not crossed:
        return ""
    where = "" if crossed["located"] else ", which the data do not locate"
    return (f"it reaches the fitted {crossed['mode'].replace('_', ' ')} mode ({crossed['f_Hz']:.4g} Hz{where}), a "
            f"line there {crossed['lift_dB']:+.1f} dB by it near {crossed['speed_rpm']:.0f} rpm: that mode's "
            "frequency and damping are fitted with what it lifts and are suspect; ")
