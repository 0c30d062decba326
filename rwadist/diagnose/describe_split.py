"""Detector of the open world (issue 33, item 3) on the final model's residual: a radial translation mode split into
an x and a y mode (a ``line_property`` of property ``split_mode``: a suspension or mount stiffer along one axis).

The model's suspension is axisymmetric: a radial line reaches Fx and Fy through one transmissibility
H(f) = (1 + 2jζr)/(1 − r² + 2jζr), r = f/f_t.  A support stiffer along x than along y (trial25: 8 % in stiffness, the
translation at 187.1 Hz in x and 180 Hz in y) gives each channel its own, so the lines' measured-over-predicted ratios
differ between Fx and Fy by d(f) = 20·log10|H(f; f_y, ζ)/H(f; f_x, ζ)| dB: near zero far from the modes, one sign
between them and the other beyond -- a resonant course in the line's frequency that no constant gain follows (that
is :func:`rwadist.diagnose.describe_gain.channel_gain`).  Before, the translation was declared "not located" and
report.md said "Nothing" at 5x the clean level.

Read on the model's radial-force lines standing :data:`~rwadist.diagnose.describe_gain.LINE_SNR_DB` over the noise
in both channels (``d`` per line and run, as the gain detector reads it); f_x, f_y and ζ fitted over a grid about the
cell whose |d| is largest (the L1 misfit), then again on the lines that follow it within :data:`MAX_LINE_SCATTER_DB`
(an ellipse line's orientation, the phase of its co and counter parts in the run, scatters its cells); described
when the split
fit leaves at most :data:`MAX_MISFIT_RATIO` of the misfit a constant leaves, the two modes differ by
:data:`MIN_SPLIT` or more, and the fitted course reaches :data:`MIN_PEAK_DB` on :data:`MIN_CELLS` cells or more of
:data:`~rwadist.diagnose.describe_gain.MIN_LINES` lines.

The same differences on either radial pair (Fx/Fy, Tx/Ty) may follow one resonance of ONE channel (a
``line_property`` of property ``channel_resonance``: the load cell's channel, its amplifier or cabling, or a fixture
mode along one axis): d(f) = ±20·log10|H(f; f_r, ζ, g)|, H = (1 − r² + 2jζgr)/(1 − r² + 2jζr) (peak gain g at f_r,
1 far from it), fitted over grids as the split (:func:`fit_channel_resonance`) and described under the same rules;
on Fx/Fy the better of the two fits is described (:func:`pair_asymmetries`).  A mode of the wheel lifts x and y
alike, so the search names none whose lift is one channel's
(:func:`rwadist.effects.fixed_resonance_diagnose.one_channel_of_pair`).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..units import RAD_S_TO_RPM, RADIAL_PAIRS
from .describe_gain import LINE_SNR_DB, MIN_LINES, MIN_RUNS, _powers
from .unexplained import Unexplained

#: The split course's L1 misfit over the constant's, at most
MAX_MISFIT_RATIO = 0.5
#: |ln(f_x/f_y)| at least (a split of 1 %)
MIN_SPLIT = 0.01
#: The fitted |d| at least this (dB) ...
MIN_PEAK_DB = 1.0
#: ... on this many cells
MIN_CELLS = 3
#: A line whose cells lie further than this (dB, their median) from the first fitted course is an ellipse's, left out
MAX_LINE_SCATTER_DB = 1.0
#: The grids: mode frequencies within ±:data:`SPAN` (log) of the largest |d|'s frequency, and the damping ratios
SPAN = 0.2
N_FREQ = 81
ZETAS = (0.005, 0.01, 0.02, 0.03, 0.05, 0.08)


def _transmissibility_db(f: np.ndarray, f0: np.ndarray, zeta: float) -> np.ndarray:
    """20·log10|H| (dB) of the suspension's transmissibility H = (1 + 2jζr)/(1 − r² + 2jζr), r = f/f0, for every mode
    frequency ``f0`` (n,) and cell frequency ``f`` (m,): (n, m)."""
    r = f[None, :] / f0[:, None]
    return 10 * np.log10((1 + (2 * zeta * r) ** 2) / ((1 - r**2) ** 2 + (2 * zeta * r) ** 2))


def fit_split(f: np.ndarray, d: np.ndarray) -> dict:
    """The split course d(f) = L(f; f_y) − L(f; f_x) (L: :func:`_transmissibility_db`) best fitting the cells' dB
    differences ``d`` (y over x) at frequencies ``f`` Hz in L1, over the grids; returns f_x, f_y (Hz), zeta, the
    L1 misfits of the split course, of the best constant (the median) and the fitted course at the cells."""
    centre = float(f[np.argmax(np.abs(d))])
    grid = centre * np.exp(np.linspace(-SPAN, SPAN, N_FREQ))
    best = (np.inf, 0, 0, ZETAS[0])
    for zeta in ZETAS:
        L = _transmissibility_db(f, grid, zeta)                 # (n, m)
        # misfit of every (f_y = grid[i], f_x = grid[j]): Σ_cells |d − (L_i − L_j)|, in blocks of f_y
        cost = np.abs(d[None, None, :] - (L[:, None, :] - L[None, :, :])).sum(axis=2)
        iy, ix = np.unravel_index(np.argmin(cost), cost.shape)
        if cost[iy, ix] < best[0]:
            best = (float(cost[iy, ix]), int(iy), int(ix), zeta)
    l1, i_y, i_x, zeta = best
    course = _transmissibility_db(f, grid[[i_y]], zeta)[0] - _transmissibility_db(f, grid[[i_x]], zeta)[0]
    return {"f_x_Hz": float(grid[i_x]), "f_y_Hz": float(grid[i_y]), "zeta": float(zeta), "misfit_dB": l1,
            "constant_misfit_dB": float(np.abs(d - np.median(d)).sum()), "course_dB": course}


def _pair_cells(ctx, state, cx: str, cy: str):
    """(h (L,), line index, run index, f Hz, d dB) of the cells of the model's lines read in both channels of the pair
    (cx, cy) :data:`~rwadist.diagnose.describe_gain.LINE_SNR_DB` over the noise, d = 10·log10(P_y/P̂_y) −
    10·log10(P_x/P̂_x); None when fewer than MIN_LINES lines are read or x and y agree within MIN_PEAK_DB on every cell."""
    if cx not in ctx.channels or cy not in ctx.channels:
        return None
    runs = ctx.runs
    px, py = _powers(ctx, state, cx, runs), _powers(ctx, state, cy, runs)
    if px is None or py is None or px[0].size != py[0].size or np.any(np.abs(px[0] - py[0]) > 1e-9):
        return None
    h = px[0]
    snr = np.minimum(px[2] / np.maximum(px[3], 1e-300), py[2] / np.maximum(py[3], 1e-300))
    good = (snr >= 10 ** (LINE_SNR_DB / 10)) & (px[1] > 0) & (py[1] > 0) & np.isfinite(px[1] + py[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        d = 10 * np.log10(py[1] / py[2]) - 10 * np.log10(px[1] / px[2])
    lines = np.array([i for i in range(h.size) if good[i].sum() >= MIN_RUNS], dtype=int)
    if lines.size < MIN_LINES:
        return None
    cells = good & np.isin(np.arange(h.size), lines)[:, None]
    li, ri = np.nonzero(cells)
    f, dc = h[li] * ctx.omega[runs[ri]] / (2 * np.pi), d[li, ri]
    if np.abs(dc - np.median(dc)).max() < MIN_PEAK_DB:
        return None                         # x and y alike within a dB on every line read: nothing to fit
    return h, li, ri, f, dc


def _steady_fit(fit_fn, li, ri, f, dc):
    """(fit, li, ri, f, dc) of ``fit_fn`` (:func:`fit_split` or :func:`fit_channel_resonance`) refitted on the lines
    whose cells follow its first fit within MAX_LINE_SCATTER_DB (their median), or None when fewer than MIN_LINES do:
    a line of co and counter parts (an ellipse) reads x over y by its orientation, the parts' phase in the run, and
    its cells scatter about any course (family wheel 3's h 5.98 and 8.03, up to ±27 dB); a line of one sense follows
    the course to its noise."""
    fit = fit_fn(f, dc)
    lines = np.unique(li)
    scatter = np.array([np.median(np.abs(dc - fit["course_dB"])[li == i]) for i in lines])
    steady = lines[scatter <= MAX_LINE_SCATTER_DB]
    if steady.size < MIN_LINES:
        return None
    keep = np.isin(li, steady)
    li, ri, f, dc = li[keep], ri[keep], f[keep], dc[keep]
    return fit_fn(f, dc), li, ri, f, dc


def _fitted_cells(ctx, state, pair, fit_fn):
    """(h, fit, line index, run index, f Hz, d dB) of ``fit_fn`` on the cells of the radial ``pair``
    (:func:`_pair_cells`, then :func:`_steady_fit`), or None when either has nothing."""
    cells = _pair_cells(ctx, state, *pair)
    if cells is None:
        return None
    h, li, ri, f, dc = cells
    got = _steady_fit(fit_fn, li, ri, f, dc)
    return None if got is None else (h,) + got


def _reaches(fit: dict, li, f=None) -> np.ndarray | None:
    """The cells where ``fit``'s course reaches MIN_PEAK_DB, when it leaves at most MAX_MISFIT_RATIO of a constant's
    misfit and reaches MIN_CELLS cells of MIN_LINES lines; else None.  With ``f`` (the cells' frequencies, Hz; a
    resonance's fit, its ``f_r_Hz``), one line will do when its reached cells lie on both sides of the resonance: one
    line crossing it over the speeds draws its peak (family wheel 3's h 4.02 on Tx, the only torque line past 200 Hz),
    when the course there reaches :data:`ONE_LINE_PEAK_DB` (a line whose x and y drift apart by a few dB over its speeds
    is no resonance: family wheel 0's run-up, h 3.08 on Tx, 3.5 dB)."""
    reach = np.abs(fit["course_dB"]) >= MIN_PEAK_DB
    if fit["misfit_dB"] > MAX_MISFIT_RATIO * fit["constant_misfit_dB"] or reach.sum() < MIN_CELLS:
        return None
    crossed = f is not None and np.any(f[reach] < fit["f_r_Hz"]) and np.any(f[reach] > fit["f_r_Hz"]) \
        and np.max(np.abs(fit["course_dB"])) >= ONE_LINE_PEAK_DB
    return reach if np.unique(li[reach]).size >= MIN_LINES or crossed else None


def pair_asymmetries(ctx, state, shares) -> list:
    """The records of the radial pairs whose x and y read the model's lines through different resonant courses: on
    Fx/Fy the better fitting of a split translation (:func:`split_mode`) and a resonance of one channel
    (:func:`channel_resonance`), on Tx/Ty the latter (``shares(chans, hs, runs)`` -> (share of the misplaced power,
    level dB) of the lines' cells)."""
    out = []
    for cx, cy in RADIAL_PAIRS:
        found = [u for u in ((split_mode(ctx, state, shares) if cx == "Fx" else []) +
                             channel_resonance(ctx, state, shares, (cx, cy)))]
        if found:
            out.append(min(found, key=lambda u: u.parameters["misfit_dB"]))
    return out


def radial_pairs(ctx, recorded, state, shares) -> list:
    """The records of the radial pairs' channels reading the model's lines differently: a gain of one channel
    (:func:`.describe_gain.channel_gain`, on the ``recorded`` channels: a gain acts on them, before any load-cell
    correction), two translation modes or one channel's resonance (:func:`pair_asymmetries`, on ``state``), one
    channel recorded later than the other (:func:`.describe_skew.channel_skew`).  A channel's resonance is divided
    out of its lines before a gain is read, and no skew is described on its pair: its phase below the resonance grows
    as 2ζ(g − 1)·f/f_r, a delay's (docs/diagnose.md).  ``shares(chans, hs, runs)`` -> (share of the misplaced power,
    level dB) of the lines' cells."""
    from .describe_gain import channel_gain
    from .describe_skew import channel_skew

    asymmetric = pair_asymmetries(ctx, state, shares)
    resonant = [u for u in asymmetric if u.parameters.get("property") == "channel_resonance"]
    chans = {c for u in resonant for c in (u.parameters["channel"], u.parameters["partner"])}
    # a pair read through two courses gives each line its own x/y ratio, steady over the runs above both modes: no
    # load of a fixed direction (the session-54 trial's 450/510 Hz split: its h 8.8 line at +2.8 dB beside the split)
    split = {c for u in asymmetric for c in u.channels}
    gains = [u for u in channel_gain(ctx, recorded, shares, resonant)
             if not (u.parameters.get("property") == "fixed_direction" and set(u.channels) & split)]
    return (gains + asymmetric + [u for u in channel_skew(ctx, state, shares) if not set(u.channels) & chans])


def split_mode(ctx, state, shares) -> list:
    """``line_property`` records (property ``split_mode``) of the radial forces read through two translation modes
    (``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines' cells)."""
    cx, cy = "Fx", "Fy"
    got = _fitted_cells(ctx, state, (cx, cy), fit_split)
    if got is None:
        return []
    h, fit, li, ri, f, dc = got
    split = abs(np.log(fit["f_x_Hz"] / fit["f_y_Hz"]))
    reach = _reaches(fit, li)
    if reach is None or split < MIN_SPLIT:
        return []
    runs = ctx.runs
    used = np.unique(ri[reach])
    share, _ = shares((cx, cy), h[np.unique(li[reach])], runs[used])
    rpm = ctx.omega[runs[used]] * RAD_S_TO_RPM
    k = int(np.argmax(np.abs(fit["course_dB"])))
    stiff, soft = (cx, cy) if fit["f_x_Hz"] > fit["f_y_Hz"] else (cy, cx)
    hi, lo = max(fit["f_x_Hz"], fit["f_y_Hz"]), min(fit["f_x_Hz"], fit["f_y_Hz"])
    return [Unexplained(
        signature="line_property", channels=(cx, cy), speed_rpm=(float(rpm.min()), float(rpm.max())),
        f_Hz=(float(f[reach].min()), float(f[reach].max())), level_dB=float(fit["course_dB"][k]), share=share,
        n_runs=int(used.size),
        parameters={"property": "split_mode", "f_x_Hz": fit["f_x_Hz"], "f_y_Hz": fit["f_y_Hz"], "zeta": fit["zeta"],
                    "stiffness_ratio": float((hi / lo) ** 2), "misfit_dB": fit["misfit_dB"],
                    "constant_misfit_dB": fit["constant_misfit_dB"], "cells": int(li.size),
                    "lines_h": [float(x) for x in h[np.unique(li[reach])]]},
        causes=(f"a radial translation split in two: along {stiff[-1]} at {hi:.4g} Hz, along {soft[-1]} at {lo:.4g} Hz "
                f"(stiffness {100 * ((hi / lo) ** 2 - 1):.1f} % higher along {stiff[-1]}): a suspension, bearing "
                "preload or mount stiffer along one axis; the model's one axisymmetric mode cannot follow it",),
        would_tell="the wheel turned 90 degrees on the stand (a split of the wheel's own turns with it, one of the "
                   "stand's stays), or a tap test along x and along y at rest")]


#: Peak gains of :func:`fit_channel_resonance`'s grid (a channel's resonance lifting its lines, g > 1)
RESONANCE_GAINS = np.geomspace(1.25, 40.0, 17)
#: Step (log) of its resonance frequencies over the cells' range, refined off the grid after
RESONANCE_STEP = 0.03
#: Evaluations of the refinement at most (a resonance converges in 10-30; cells of no resonance ran it to its default
#: 300, 0.14 s a fit on family wheel 3's clean torques)
REFINE_NFEV = 60
#: A channel's resonance is described with ζ at most this (the refinement may run ζ to 0.3 on a tilt)
MAX_RESONANCE_ZETA = 0.1
#: ... and, read on one line alone, with its course reaching this at least (dB; a peak gain of 2)
ONE_LINE_PEAK_DB = 6.0


def _resonance_db(f: np.ndarray, f0: np.ndarray, zeta: float, gains: np.ndarray) -> np.ndarray:
    """20·log10|H| (dB), H = (1 − r² + 2jζgr)/(1 − r² + 2jζr), r = f/f0 (peak gain g at f0, 1 far from it), for every
    (mode frequency ``f0`` (n,), gain ``gains`` (G,)) and cell frequency ``f`` (m,): (n·G, m)."""
    r = f[None, None, :] / f0[:, None, None]
    base = (1 - r * r) ** 2
    two_zr = (2 * zeta * r) ** 2
    out = 10 * np.log10((base + gains[None, :, None] ** 2 * two_zr) / (base + two_zr))
    return out.reshape(-1, f.size)


def fit_channel_resonance(f: np.ndarray, d: np.ndarray) -> dict:
    """The course d(f) = s·20·log10|H(f; f_r, ζ, g)| (:func:`_resonance_db`; s = +1: the resonance is y's, −1: x's)
    best fitting the cells' dB differences ``d`` (y over x) at frequencies ``f`` Hz in L1, over the grids (f_r over
    the cells' whole range in log steps of :data:`RESONANCE_STEP`, ζ in ZETAS, g in RESONANCE_GAINS), then refined
    off the grid; returns f_r (Hz), zeta, peak_gain, sign, the L1 misfits of the course and of the best constant (the
    median) and the fitted course at the cells.  f_r is not searched about the largest |d| alone: the lines
    a channel's resonance lifts may be few beside stronger misfits elsewhere (family wheel 3's torques: one line, h
    4.02, crosses a 300-Hz resonance on Tx; the largest |d| was at 67 Hz)."""
    lo, hi = float(f.min()), float(f.max())
    grid = np.exp(np.arange(np.log(lo), np.log(hi) + RESONANCE_STEP, RESONANCE_STEP))
    best = (np.inf, 0, ZETAS[0], 1.0)
    for zeta in ZETAS:
        R = _resonance_db(f, grid, zeta, RESONANCE_GAINS)                  # (n·G, m)
        for sign in (1.0, -1.0):
            cost = np.abs(d[None, :] - sign * R).sum(axis=1)
            i = int(np.argmin(cost))
            if cost[i] < best[0]:
                best = (float(cost[i]), i, zeta, sign)
    l1, i, zeta, sign = best
    f_r, g = float(grid[i // RESONANCE_GAINS.size]), float(RESONANCE_GAINS[i % RESONANCE_GAINS.size])
    # refined off the grid (its damping and gain trade the peak's height against its width: 0.02 / 7.1 on the grid
    # for a 0.03 / 5 resonance), kept where its L1 misfit is lower
    fine = least_squares(lambda x: d - sign * _resonance_db(f, np.exp(x[:1]), float(np.exp(x[1])),
                                                           np.exp(x[2:]))[0],
                         np.log([f_r, zeta, g]), loss="soft_l1", f_scale=0.5, max_nfev=REFINE_NFEV,
                         bounds=(np.log([grid[0], 1e-3, 1.0]), np.log([grid[-1], 0.3, 1e3])))
    f_fine, z_fine, g_fine = (float(v) for v in np.exp(fine.x))
    course = sign * _resonance_db(f, np.array([f_fine]), z_fine, np.array([g_fine]))[0]
    if np.abs(d - course).sum() < l1:
        f_r, zeta, g, l1 = f_fine, z_fine, g_fine, float(np.abs(d - course).sum())
    course = sign * _resonance_db(f, np.array([f_r]), zeta, np.array([g]))[0]
    return {"f_r_Hz": f_r, "zeta": float(zeta), "peak_gain": g, "sign": sign, "misfit_dB": l1,
            "constant_misfit_dB": float(np.abs(d - np.median(d)).sum()), "course_dB": course}


def channel_resonance(ctx, state, shares, pair=("Fx", "Fy")) -> list:
    """``line_property`` records (property ``channel_resonance``) of one channel of the radial ``pair`` reading the
    model's lines through a resonance of its own (:func:`fit_channel_resonance`) that its partner does not have
    (``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines' cells).  The new-user
    trial's sensor resonance on Fy alone (200 Hz, ζ 0.03, peak gain 5) was a 'wheel mode' of gain 3.6 on Fx and Fy."""
    cx, cy = pair
    got = _fitted_cells(ctx, state, pair, fit_channel_resonance)
    if got is None:
        return []
    h, fit, li, ri, f, dc = got
    reach = _reaches(fit, li, f)
    if reach is None or fit["zeta"] > MAX_RESONANCE_ZETA:
        return []                           # a tilt the fit can only bend by running ζ up is no resonance
    runs = ctx.runs
    used = np.unique(ri[reach])
    share, _ = shares((cx, cy), h[np.unique(li[reach])], runs[used])
    rpm = ctx.omega[runs[used]] * RAD_S_TO_RPM
    own, other = (cy, cx) if fit["sign"] > 0 else (cx, cy)
    axis = own[-1]
    f_r, zeta, g = fit["f_r_Hz"], fit["zeta"], fit["peak_gain"]
    return [Unexplained(
        signature="line_property", channels=(own,), speed_rpm=(float(rpm.min()), float(rpm.max())),
        f_Hz=(float(f[reach].min()), float(f[reach].max())), level_dB=float(np.max(np.abs(fit["course_dB"]))),
        share=share, n_runs=int(used.size),
        parameters={"property": "channel_resonance", "channel": own, "partner": other, "f_r_Hz": f_r, "zeta": zeta,
                    "peak_gain": g, "misfit_dB": fit["misfit_dB"], "constant_misfit_dB": fit["constant_misfit_dB"],
                    "cells": int(li.size), "lines_h": [float(x) for x in h[np.unique(li[reach])]]},
        causes=(f"a resonance of {own} alone at {f_r:.4g} Hz (ζ {zeta:.2g}, peak gain {g:.3g}), {other} untouched: the "
                f"load cell's {own} channel (its bridge, amplifier or cabling) or a mode of the fixture along {axis}; "
                "a mode of the wheel lifts x and y alike, so no wheel mode is named for it",),
        would_tell=f"a tap test of the load cell and the fixture along {axis} at rest; {own}'s cable and amplifier "
                   f"swapped with {other}'s (a resonance that moves with them is the chain's)")]
