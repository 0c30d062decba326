"""Lines whose strength scatters from run to run, read at their median law by the suspension-mode fit.

The extended fit (:func:`rwadist.extended_fit.fit_extended`) locates and fits the wheel's suspension modes on how every
measured line's amplitude departs from C·Ω² with the speed: a smooth gain |T(f)| that peaks where the line crosses a
mode.  A line whose source is not locked in strength to the speed (a bearing defect's impacts, a rub, a lubricant film
that forms and breaks) scatters about its law from run to run by several dB, and in the least squares of log
amplitudes that scatter outweighs every other line's departure from C·Ω²: a line at h 2.3 of lognormal strength (8 dB
from run to run) beside the E-like wheel's lines left its radial translation (227.6 Hz, ζ 0.17) unlocated, parked at 3x
the top line and declared unconstrained, and an amplitude law (Ω^3.2) and a partial line were invented on the lines
that cross it.

A line's own readings cannot tell: on sparse speeds a line that crosses the rocking whirl's two branches and the
translation rises and falls by 10-20 dB from run to run (family wheel 0's radial-torque h 3.08 over 12 runs), which
the modes explain.  So the fit judges its own residuals: a line scatters when the log residuals of its rows, less the
median of their :data:`MEDIAN_RUNS` − 1 neighbours by speed (a smooth misfit, a law of its own, follows; a run or two
do not count), have a robust spread (1.4826 x the median absolute deviation) of :data:`SCATTER_MIN` or more and
:data:`OUTLIER_FACTOR` times the lines' median spread, over :data:`MIN_RUNS` rows at least.  Such a line is read at its
median law in every channel (its amplitudes replaced by median(a/Ω²)·Ω²) and the modes fitted again: it carries no
evidence of a mode, and the residual keeps its scatter for the open world to describe
(:mod:`rwadist.diagnose.describe_partial`).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

#: The running median's width (speeds) a line's log amplitude over Ω² is taken against.
MEDIAN_RUNS = 5
#: Its robust spread about that (natural log of amplitude) that makes a line scatter (0.35 is 3 dB), and this many
#: times the lines' median spread (a line of lognormal strength, 8 dB from run to run: 0.57-1.4 where the others read
#: 0.006-0.008; a fit still without a fixture that lifts the lines it passes: 0.36-0.51 against 0.06-0.09, family
#: wheel 6's pair of fixtures, whose second was lost when those lines were read at their law); over this many speeds.
SCATTER_MIN = 0.35
OUTLIER_FACTOR = 10.0
MIN_RUNS = 8


def _neighbours_median(y: np.ndarray) -> np.ndarray:
    """Per point of ``y`` (1-D, at least :data:`MEDIAN_RUNS` points) the median of its :data:`MEDIAN_RUNS` − 1 nearest
    neighbours, the point itself left out (a running median that holds it would read 0 wherever it is its window's
    median: 40 % of a scattering line's runs), mirrored at the ends."""
    half = MEDIAN_RUNS // 2
    windows = np.lib.stride_tricks.sliding_window_view(np.pad(y, half, mode="reflect"), MEDIAN_RUNS)
    return np.median(np.delete(windows, half, axis=1), axis=1)


def spread(y: np.ndarray) -> float:
    """The robust spread (1.4826 x the median absolute deviation) of a series ``y`` (1-D, by speed) about the median of
    each point's neighbours (:func:`_neighbours_median`); 0 with fewer than :data:`MEDIAN_RUNS` points."""
    y = np.asarray(y, dtype=float)
    if y.size < MEDIAN_RUNS:
        return 0.0
    e = y - _neighbours_median(y)
    return 1.4826 * float(np.median(np.abs(e - np.median(e))))


def scattering(residuals: np.ndarray, row_line: np.ndarray, row_speed: np.ndarray) -> list:
    """Indices of the measured lines whose log residuals scatter (module docstring): ``residuals`` (n_rows,) of the
    least squares, ``row_line`` each row's measured line, ``row_speed`` its speed (rad/s); rows of one line at one
    speed (its channels) averaged."""
    spreads = {}
    for j in np.unique(row_line):
        m = row_line == j
        speeds, where = np.unique(np.abs(row_speed[m]), return_inverse=True)
        if speeds.size >= MIN_RUNS:
            spreads[int(j)] = spread(np.bincount(where, weights=residuals[m]) / np.bincount(where))
    if not spreads:
        return []
    typical = float(np.median(list(spreads.values())))
    return sorted(j for j, s in spreads.items() if s >= SCATTER_MIN and s >= OUTLIER_FACTOR * typical)


def at_median_law(lines: list, which) -> list:
    """``lines`` (:class:`rwadist.empirical.LineFit`) with those of ``which`` (indices) at their median law in each
    channel: amplitudes median(a/Ω²)·Ω²."""
    out = list(lines)
    for j in which:
        x = lines[j]
        amp = np.array(x.amplitude, dtype=float)
        for c in np.unique(x.channel):
            m = (x.channel == c) & (amp > 0)
            if m.any():
                amp[m] = float(np.median(amp[m] / x.speed[m] ** 2)) * x.speed[m] ** 2
        out[j] = replace(x, amplitude=amp)
    return out


def note(direction: str, h: float) -> str:
    """The extended fit's note of a line read at its median law."""
    return (f"{direction} h = {h:g}: its strength scatters from run to run about its law more than the modes explain "
            "(its residuals' robust spread over 3 dB, 10x the other lines'): read at its median strength to locate the "
            "modes (it carries no evidence of them), and the modes fitted again")
