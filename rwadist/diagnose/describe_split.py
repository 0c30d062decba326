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
"""
from __future__ import annotations

import numpy as np

from ..units import RAD_S_TO_RPM
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


def split_mode(ctx, state, shares) -> list:
    """``line_property`` records (property ``split_mode``) of the radial forces read through two translation modes
    (``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines' cells)."""
    cx, cy = "Fx", "Fy"
    if cx not in ctx.channels or cy not in ctx.channels:
        return []
    runs = ctx.runs
    px, py = _powers(ctx, state, cx, runs), _powers(ctx, state, cy, runs)
    if px is None or py is None or px[0].size != py[0].size or np.any(np.abs(px[0] - py[0]) > 1e-9):
        return []
    h = px[0]
    snr = np.minimum(px[2] / np.maximum(px[3], 1e-300), py[2] / np.maximum(py[3], 1e-300))
    good = (snr >= 10 ** (LINE_SNR_DB / 10)) & (px[1] > 0) & (py[1] > 0) & np.isfinite(px[1] + py[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        d = 10 * np.log10(py[1] / py[2]) - 10 * np.log10(px[1] / px[2])
    lines = np.array([i for i in range(h.size) if good[i].sum() >= MIN_RUNS], dtype=int)
    if lines.size < MIN_LINES:
        return []
    cells = good & np.isin(np.arange(h.size), lines)[:, None]
    li, ri = np.nonzero(cells)
    f, dc = h[li] * ctx.omega[runs[ri]] / (2 * np.pi), d[li, ri]
    if np.abs(dc - np.median(dc)).max() < MIN_PEAK_DB:
        return []                           # x and y alike within a dB on every line read: nothing to fit
    fit = fit_split(f, dc)
    # a line of co and counter parts (an ellipse) reads x over y by its orientation, the parts' phase in the run:
    # its cells scatter about any course (family wheel 3's h 5.98 and 8.03, up to ±27 dB); a line of one sense
    # follows the course to its noise.  The lines that scatter are left out and the course fitted again
    scatter = np.array([np.median(np.abs(dc - fit["course_dB"])[li == i]) for i in lines])
    steady = lines[scatter <= MAX_LINE_SCATTER_DB]
    if steady.size < MIN_LINES:
        return []
    keep = np.isin(li, steady)
    li, ri, f, dc = li[keep], ri[keep], f[keep], dc[keep]
    fit = fit_split(f, dc)
    split = abs(np.log(fit["f_x_Hz"] / fit["f_y_Hz"]))
    reach = np.abs(fit["course_dB"]) >= MIN_PEAK_DB
    if (fit["misfit_dB"] > MAX_MISFIT_RATIO * fit["constant_misfit_dB"] or split < MIN_SPLIT
            or reach.sum() < MIN_CELLS or np.unique(li[reach]).size < MIN_LINES):
        return []
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
