"""Detector of the open world (issue 33, item 3) on the final model's residual: every line of every channel departing
from the model alike as the speed changes (a ``line_property`` of property ``gain_trend``: a gain that changes with
speed, common to all channels).

The model's lines follow C·Ω² (or a law, or the suspension modes' transfer), one C per line fitted to the data, so a
gain common to the whole measurement chain that is the same at every speed goes into the C's unseen.  A gain that
changes with speed does not: a load cell or its amplifier warming as the wheel runs faster (trial16 ``tempgain``,
1 − 0.08·rpm/5000 on every channel) leaves each line's measured-over-predicted power ratio (dB) with one slope
against the speed, the same for every line (every h, every direction, forces and torques alike), and nothing was
said (or one line of the sixteen got an amplitude law).  Read per direction (a radial pair's powers summed: x + y
hold a line's whole power whatever its ellipse) on the model's lines standing :data:`LINE_SNR_DB` over the noise in
:data:`MIN_RUNS` runs or more spanning :data:`MIN_SPAN` of the test's speed range whose slope (below) is read to a
standard error (from its own scatter) that resolves the change tested (:data:`MAX_LINE_SE_DB`): a noisy test (family
wheel 2, noise 0.03: few lines 20 dB over it in 6 runs) reads its lines at 10-20 dB over the noise, over more runs.
A line the model gives its own amplitude law a·(Ω/Ω_ref)^p is read with the law put back (its departure from Ω²,
20·(p − 2)·log10(Ω/Ω_ref) dB, added to its ratios): a law the search fitted to the trend on one line (the 1x lines of
the radial and axial forces at Ω^1.93-1.94 on family wheel 2) is that line's trend, read like the others'.  Each
line's least-squares slope of 10·log10(P/P̂) against the speed (its own offset out: the C's take the mean gain), is
described when the median slope over the lines

- changes the lines' power by :data:`MIN_CHANGE_DB` or more across the speed range,
- stands :data:`MIN_Z` standard errors from 0 (the median's, from the lines' scatter, its MAD),
- leaves the runs no common offset from it scattering by more than :data:`MAX_RUN_SCATTER` of its change (runs
  changed in steps, a ``run_change``, are not a trend),
- is held by :data:`MIN_LINES` lines or more, a share :data:`MIN_AGREE` of those read (a slope of the same sign
  within a factor 2 of the median), in :data:`MIN_DIRECTIONS` directions or more (one line's own amplitude law, or a
  resonance misfit near one mode, moves one line or the lines of one band: the ``amplitude_law`` class, not this),
- and is not explained clearly better (:data:`FILTER_RSS_RATIO`) as a function of the lines' frequency h·Ω/2π (a
  filter, an anti-alias filter or a transfer, acts on the frequency: lines of different h see different slopes
  against the speed).  Both are fitted with one common slope and each line's own offset; the record gives both fits'
  residuals and says whether they told the two apart.

The trend's size (``slope_dB_per_krpm``, ``change_dB``) is the lines that hold it weighted by their slopes'
precision (an unbiased estimate from each line's own scatter, (ν − 2)/ν · sxx/v: :func:`_weighted_slope`; 1/se²
overstates it by ν/(ν − 2), twice with 6 runs); the median, robust, decides: lines whose trend a fit absorbed in part
(a 1x line through a suspension mode whose fit bent to it) pull it toward 0 (family wheel 2: −0.216 against −0.248 dB per 1000 rpm
weighted, the truth −0.654 dB over 300-3000 rpm, −0.242 per 1000 rpm).
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .describe_gain import _powers
from .unexplained import Unexplained

#: A line's predicted power over the noise in its window at least (dB; the noise's power a tenth of the line's): in the
#: runs that pass, the ratios of family wheel 2's lines at 10-20 dB scatter 0.1-0.2 dB (the window's several
#: Welch segments; the model's noise taken out of the measurement).  Whether the line's slope is read well enough is
#: told by that scatter (:data:`MAX_LINE_SE_DB`), not by this threshold (20 dB before: 2 lines read on wheel 2).
LINE_SNR_DB = 10.0
#: A line's slope's standard error (from its ratios' scatter about the fitted slope) times the test's speed range at
#: most (dB): the line resolves a change of the size tested (:data:`MIN_CHANGE_DB`) to 1.5 standard errors.
MAX_LINE_SE_DB = 0.2
#: Runs (with the line read) a line's slope needs at least ...
MIN_RUNS = 6
#: ... spanning at least this fraction of the test's speed range.
MIN_SPAN = 0.4
#: The median slope's change of power across the speed range at least (dB): 0.3 dB is 3.5 % of amplitude, about
#: twice the worst line C error of the clean fits (1.3-2.6 % on trial16's clean cells, 3 seeds); a smaller drift is
#: within what the fit of a clean test leaves (the clean cells' median slopes change the lines by ≤ 0.02 dB).
MIN_CHANGE_DB = 0.3
#: ... and this many standard errors of the median (the lines' slopes scatter 0.005-0.01 dB per 1000 rpm, MAD).
MIN_Z = 5.0
#: Lines that must each show it, at least ...
MIN_LINES = 4
#: ... and this share of the lines read (most lines: a common factor acts on all) ...
MIN_AGREE = 0.6
#: ... in this many directions (radial force, radial torque, axial force, axial torque) or more.
MIN_DIRECTIONS = 2
#: ... or one direction of one channel (the axial force on Fz, the axial torque on Tz): every one of its lines read,
#: this many at least, its 1x among them, while the other directions' lines keep their law (their median slope under
#: this fraction of the trend's): a gain of that channel alone (an independent trial's Fz × 1.0-1.2 over a test
#: recorded in speed order: three amplitude laws Ω^2.11-2.14 on the axial force, its 1x among them).
ONE_CHANNEL_DIRECTIONS = ("axial_force", "axial_torque")
ONE_CHANNEL_LINES = 3
ONE_CHANNEL_OTHERS = 0.25
#: ... its lines' slopes read to this standard error over the speed range (dB; the E-like wheel's axial lines, 2 of 5
#: within MAX_LINE_SE_DB, its Fz drifting 1.0-1.2: 1.6 dB over the range)
ONE_CHANNEL_SE_DB = 0.5
#: The runs' common offset from the trend (the median over the lines read in a run of what the common slope leaves of
#: each line, its offset out) scatters (1.4826 × MAD over the runs) by at most this fraction of the trend's change:
#: a gain that changes smoothly with speed leaves the runs only the lines' noise in common (0.004-0.015 dB on
#: trial16 tempgain and family wheels 0, 4, 5, 6 with 1 − 0.08·Ω/Ω_max, for changes of 0.55-0.65 dB), runs changed in
#: steps by a common factor (a re-mounting: the ``run_change`` signature) leave their steps, of which a slope is only
#: the projection on the speed (the open world's every third run 3.5 dB up on family wheel 3: 0.47 dB over the range,
#: the runs scattering 0.32 dB).
MAX_RUN_SCATTER = 0.25
#: A gain of the line's frequency (a filter) rather than of the speed when one slope against the frequency leaves less
#: than this fraction of the residual one slope against the speed leaves.  Between it and 1 the two are not told apart
#: (lines of a narrow span of h, or lines whose misfit near a suspension mode outweighs the difference: family wheel 4
#: with the gain below, h 2-9.24 after the 1x lines took laws, left 2.92 dB² against 2.97) and the record says so.
FILTER_RSS_RATIO = 0.5
#: A line read (resolved or not) is in the record's cells when its slope is within this many of its own standard
#: errors of the trend's (or within a factor 2 of it): the trend explains it.
CONSISTENT_SE = 3.0


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope of y on x."""
    xc = x - x.mean()
    return float(np.dot(xc, y - y.mean()) / np.dot(xc, xc))


def pooled_slope(xs: list, ys: list) -> tuple:
    """(common slope, residual sum of squares) of y = a_l + s·x over the lines (each its own offset a_l)."""
    xc = [x - x.mean() for x in xs]
    yc = [y - y.mean() for y in ys]
    sxx = sum(float(np.dot(a, a)) for a in xc)
    s = sum(float(np.dot(a, b)) for a, b in zip(xc, yc)) / sxx if sxx > 0 else 0.0
    return s, sum(float(np.sum((b - s * a) ** 2)) for a, b in zip(xc, yc))


def _weighted_slope(xs: list, ys: list) -> tuple:
    """(slope, its standard error) of lines y_l = a_l + s_l·x_l, each its own slope and noise: their least-squares
    slopes s_l weighted by an unbiased estimate of their precision, (ν_l − 2)/ν_l · sxx_l/v_l (v_l the line's residual
    variance about its own fit, ν_l = n_l − 2 its degrees of freedom: v_l ~ σ_l²·χ²_ν/ν, whose E[1/v_l] is
    ν/(ν − 2)/σ_l²), the standard error 1/sqrt(Σ weights).

    Weights 1/se_l² = sxx_l/v_l themselves overstate each line's precision by ν/(ν − 2), twice with 6 runs: the
    standard error read ~40 % low (6 lines of 6 runs, one noise level: 0.014 for a scatter of 0.023 dB per 1000 rpm
    over Monte-Carlo draws).  A residual variance pooled over the lines reads it right when they share one noise
    level, but the lines a gain trend is read on do not (family wheel 2's 5 agreeing lines scatter 0.028-0.21 dB
    about their slopes, their signal over the noise from 10 to 40 dB): weighted by sxx alone, the slope scattered 2.4x
    the inverse-variance optimum over draws of lines like those, against 1.05x so (tests/test_describe_trend_stderr.py).
    Lines of ν ≤ 2 (4 runs or fewer: never read, :data:`MIN_RUNS`) have no finite estimate: weight 0."""
    s, w = [], []
    for x, y in zip(xs, ys):
        xc = x - x.mean()
        sxx = float(np.dot(xc, xc))
        nu = x.size - 2
        if not sxx > 0 or nu <= 2:
            continue
        sl = float(np.dot(xc, y - y.mean())) / sxx
        r = y - y.mean() - sl * xc
        v = max(float(np.dot(r, r)) / nu, 1e-18)
        s.append(sl)
        w.append((nu - 2) / nu * sxx / v)
    if not w:
        return 0.0, float("inf")
    w_arr = np.asarray(w)
    return float(np.dot(w_arr, s) / w_arr.sum()), float(1.0 / np.sqrt(w_arr.sum()))


def _direction_powers(ctx, state, d: str, runs: np.ndarray):
    """(h (L,), amplitude law or None (L), measured (L, R), predicted (L, R), noise (L, R) power) of the model's lines
    of direction ``d``, its channels' powers summed (a radial pair: x + y, the whole power of a line whatever the shape and
    orientation of its ellipse, which share it between x and y differently in each run); None without lines or when
    the pair's channels do not hold the same lines."""
    chans = [c for c in DIRECTION_CHANNELS[d] if c in ctx.channels]
    got = [_powers(ctx, state, c, runs) for c in chans]
    if not got or any(g is None for g in got) or any(g[0].shape != got[0][0].shape or np.any(np.abs(g[0] - got[0][0])
                                                                                         > 1e-9) for g in got):
        return None
    laws = [x[1] for x in ctx.channel_lines(state, chans[0], runs)]
    return (got[0][0], laws, sum(g[1] for g in got), sum(g[2] for g in got), sum(g[3] for g in got))


def _line_slope_se(x: np.ndarray, y: np.ndarray) -> float:
    """Standard error of the least-squares slope of y on x, from y's scatter about the fitted line (n − 2 degrees of
    freedom)."""
    xc = x - x.mean()
    sxx = float(np.dot(xc, xc))
    r = y - y.mean() - _slope(x, y) * xc
    return float(np.sqrt(np.dot(r, r) / max(x.size - 2, 1) / sxx)) if sxx > 0 else np.inf


def read_lines(ctx, state, runs: np.ndarray) -> list:
    """[(direction, h, runs (n,), rpm (n,), f_Hz (n,), dB (n,), has a law)] of the model's lines read
    (:data:`LINE_SNR_DB`, :data:`MIN_RUNS`, :data:`MIN_SPAN`), per direction
    (:func:`_direction_powers`): each line's runs (indices into the context's), speeds, frequencies,
    measured-over-predicted power ratios against C·Ω² and whether the model gives it its own amplitude law.  A law
    a_ref·(Ω/Ω_ref)^p is the line's departure from Ω² fitted to the line: it is put back,
    20·(p − 2)·log10(Ω/Ω_ref) dB added to the line's ratios (each line's constant is its own: the C's, and the law's
    a_ref, take the mean gain), so that a trend a law took on one line is read on that line as on the others."""
    rpm_all = np.abs(ctx.omega[runs]) * RAD_S_TO_RPM
    span = float(np.ptp(rpm_all)) if rpm_all.size else 0.0
    out = []
    for d in DIRECTION_CHANNELS:
        p = _direction_powers(ctx, state, d, runs)
        if p is None:
            continue
        h, laws, meas, pred, noise = p
        for i in range(h.size):
            with np.errstate(divide="ignore", invalid="ignore"):
                good = (pred[i] >= 10 ** (LINE_SNR_DB / 10) * noise[i]) & (meas[i] > 0) & np.isfinite(meas[i])
                if good.sum() < MIN_RUNS or np.ptp(rpm_all[good]) < MIN_SPAN * span:
                    continue
                db = 10 * np.log10(meas[i][good] / pred[i][good])
            rpm = rpm_all[good]
            if laws[i] is not None:
                _, w_ref, expo = laws[i]
                db = db + 20.0 * (expo - 2.0) * np.log10(np.abs(ctx.omega[runs[good]]) / w_ref)
            out.append((d, float(h[i]), runs[good], rpm, abs(h[i]) * rpm / 60.0, db, laws[i] is not None))
    return out


def gain_trend(ctx, state, shares) -> list:
    """A ``line_property`` record (property ``gain_trend``) when the model's lines in every direction depart from it
    with one slope against the speed (a gain common to the channels that changes with speed), else []; ``state`` read
    as recorded (:func:`rwadist.diagnose.describe_gain.as_recorded`), ``shares(chans, hs, runs)`` -> (share of the
    misplaced power, level dB) of the lines' cells.  A line with an amplitude law of its own is read with the law put
    back (:func:`read_lines`: the search gave the 1x lines of three directions Ω^1.93 on family wheel 4 with the gain
    below, their ratios against the law flat); the record's cells hold the lines read whose slopes the trend does
    not contradict, laws included (:func:`rwadist.diagnose.describe.cells_of`: a law fitted to the trend is taken
    back)."""
    runs = ctx.runs
    if runs.size < MIN_RUNS:
        return []
    rpm_all = np.abs(ctx.omega[runs]) * RAD_S_TO_RPM
    if not np.ptp(rpm_all) > 0:
        return []          # every run at one speed: no slope against the speed to read
    read = read_lines(ctx, state, runs)
    # each line's slope and its standard error; the slopes of the lines that resolve the change tested decide
    slopes_read = np.array([_slope(x[3] / 1000.0, x[5]) for x in read])
    se_read = np.array([_line_slope_se(x[3] / 1000.0, x[5]) for x in read])
    resolved = se_read * float(np.ptp(rpm_all)) / 1000.0 <= MAX_LINE_SE_DB
    got = _trend(ctx, shares, read, slopes_read, se_read, resolved, rpm_all)
    for d in ONE_CHANNEL_DIRECTIONS if not got else ():
        others = [i for i, x in enumerate(read) if x[0] != d and resolved[i]]
        mine = np.array([x[0] == d for x in read], bool)
        # one channel's lines are few: read to ONE_CHANNEL_SE_DB
        loose = se_read[mine] * float(np.ptp(rpm_all)) / 1000.0 <= ONE_CHANNEL_SE_DB
        got = _trend(ctx, shares, [x for x, m in zip(read, mine) if m], slopes_read[mine], se_read[mine],
                     loose, rpm_all, one_channel=(d, slopes_read[others]))
        if got:
            break
    return got


def _trend(ctx, shares, read, slopes_read, se_read, resolved, rpm_all, one_channel=None) -> list:
    """:func:`gain_trend` on the lines ``read`` (their slopes, standard errors and whether they resolve the change):
    every direction, or (``one_channel``: (direction, the other directions' resolved slopes)) one direction of one
    channel, :data:`ONE_CHANNEL_LINES` lines of it agreeing, its 1x among them, while the other directions' lines
    (two at least) keep their law (their median slope under :data:`ONE_CHANNEL_OTHERS` of the trend's)."""
    lines = [x for x, ok in zip(read, resolved) if ok]
    if len(lines) < (MIN_LINES if one_channel is None else ONE_CHANNEL_LINES):
        return []
    lo, hi = float(rpm_all.min()), float(rpm_all.max())
    # slopes in dB of power per 1000 rpm, each line's own offset out
    slopes = slopes_read[resolved]
    med = float(np.median(slopes))
    se = 1.2533 * 1.4826 * float(np.median(np.abs(slopes - med))) / np.sqrt(slopes.size)
    change = med * (hi - lo) / 1000.0
    agree = (np.sign(slopes) == np.sign(med)) & (np.abs(slopes) >= 0.5 * abs(med)) & (np.abs(slopes) <= 2 * abs(med))
    held = [lines[i] for i in np.flatnonzero(agree)]
    directions = sorted({x[0] for x in held})
    if abs(change) < MIN_CHANGE_DB or abs(med) < MIN_Z * se:
        return []
    if one_channel is None:
        if agree.sum() < max(MIN_LINES, MIN_AGREE * len(lines)) or len(directions) < MIN_DIRECTIONS:
            return []
    elif (not agree.all() or not any(abs(x[1] - 1.0) < 1e-3 for x in held) or one_channel[1].size < 2
          or abs(float(np.median(one_channel[1]))) >= ONE_CHANNEL_OTHERS * abs(med)):
        return []
    # a smooth trend, not runs changed in steps: what the common slope leaves of each line, per run, its median
    left: dict = {}
    for x in lines:
        r = x[5] - x[5].mean() - med * (x[3] - x[3].mean()) / 1000.0
        for k, v in zip(x[2], r):
            left.setdefault(int(k), []).append(v)
    per_run = np.array([np.median(v) for v in left.values()])
    run_scatter = 1.4826 * float(np.median(np.abs(per_run - np.median(per_run))))
    if run_scatter > MAX_RUN_SCATTER * abs(change):
        return []
    # the speed against the line's frequency: one common slope each, every line its own offset
    d_all = [x[5] for x in lines]
    s_speed, rss_speed = pooled_slope([x[3] / 1000.0 for x in lines], d_all)
    s_freq, rss_freq = pooled_slope([x[4] / 1000.0 for x in lines], d_all)
    if rss_freq < FILTER_RSS_RATIO * rss_speed:
        return []          # a gain that depends on the line's frequency (a filter): not a gain trend with speed
    apart = rss_speed <= rss_freq
    # the trend's size: the common slope of the lines that hold it, each weighted by its precision
    slope, slope_se = _weighted_slope([x[3] / 1000.0 for x in held], [x[5] for x in held])
    change = slope * (hi - lo) / 1000.0
    used = np.unique(np.concatenate([x[2] for x in held]))
    # the record's cells: every line read that the trend does not contradict (a slope within a factor 2 of the
    # trend's, or within CONSISTENT_SE of its own standard errors from it, resolved or not): a law the search fitted
    # to the trend on such a line is taken back, a line's own law that departs from it (a true amplitude law, Ω³)
    # is not
    near = ((np.sign(slopes_read) == np.sign(slope)) & (np.abs(slopes_read) >= 0.5 * abs(slope))
            & (np.abs(slopes_read) <= 2 * abs(slope))) | (np.abs(slopes_read - slope) <= CONSISTENT_SE * se_read)
    cell_lines = [x for x, ok in zip(read, near) if ok]
    read_dirs = {x[0] for x in cell_lines}
    chans = tuple(c for c in ctx.channels if any(c in DIRECTION_CHANNELS[d] for d in read_dirs))
    read_h = sorted({x[1] for x in cell_lines})
    share, _ = shares(chans, read_h, used)
    f = np.concatenate([x[4] for x in held])
    ratio = 10 ** (change / 20)
    pct = 100.0 * (ratio - 1.0)
    falls = "falls" if change < 0 else "rises"
    law = f"amplitude ∝ Ω^{2 + change / 20 / np.log10(hi / lo):.3f} over the range" if lo > 0 else "one law for all"
    return [Unexplained(
        signature="line_property", channels=chans, speed_rpm=(lo, hi), f_Hz=(float(f.min()), float(f.max())),
        level_dB=change, share=share, n_runs=int(used.size),
        parameters={"property": "gain_trend", "slope_dB_per_krpm": slope,
                    "slope_stderr_dB_per_krpm": slope_se, "median_slope_dB_per_krpm": med,
                    "stderr_dB_per_krpm": float(se),
                    "change_dB": change, "gain_change_percent": pct, "amplitude_ratio": float(ratio),
                    "lines_agreeing": int(agree.sum()), "lines_read": len(lines),
                    "lines_unresolved": int(len(read) - len(lines)), "directions": directions,
                    "lines_h": sorted({x[1] for x in held}), "read_h": read_h,
                    "lines_with_a_law": [[x[0], x[1]] for x in read if x[6]], "run_scatter_dB": run_scatter,
                    "pooled_slope_dB_per_krpm": s_speed, "rss_speed_dB2": rss_speed,
                    "frequency_slope_dB_per_kHz": s_freq, "rss_frequency_dB2": rss_freq,
                    "depends_on": "speed" if apart else "speed or frequency, not told apart",
                    **({} if one_channel is None else {"one_channel": True})},
        causes=((f"a gain of the whole measurement chain that {falls} with speed: {pct:+.1f} % in amplitude from "
                 f"{lo:.0f} to {hi:.0f} rpm on {int(agree.sum())} of the {len(lines)} lines read, every direction "
                 f"alike ({', '.join(directions)}): a load cell or amplifier whose gain drifts with temperature (the "
                 "cell warming as the wheel runs faster)" if one_channel is None else
                 f"a gain of {' and '.join(chans)}'s chain alone that {falls} with speed (or with time, the runs "
                 f"recorded in speed order): {pct:+.1f} % in amplitude from {lo:.0f} to {hi:.0f} rpm on every one of its "
                 f"{len(lines)} lines read, its 1x included (an imbalance grows as Ω² exactly), while the other "
                 "channels' lines keep their law: that channel's amplifier or bridge drifting, a loose connector")
                + ("" if apart else "; a filter of the chain (a gain of the line's frequency) explains the lines about "
                   "as well: not told apart on these lines"),
                f"every line departing from Ω² alike ({law}): a change of the wheel common to all its lines (the "
                "rotor's balance or the bearings' preload changing with speed or temperature)"),
        would_tell="a calibration of the load cell with one known load, warm (right after the top speed) and cold; a "
                   "run-down right after a run-up at the same speeds (a temperature drift follows the time, not the "
                   "speed); an accelerometer beside the cell")]
