"""Where a line crosses the wheel's suspension modes (a whirl branch included): the runs whose level the modes'
damping sets, and the groups of runs either side of each crossing, for :class:`~rwadist.effects.amplitude_law_diagnose.AmplitudeLaw`.

A line's amplitude is measured through the state's modes (:func:`rwadist.diagnose.measure.measure_run_powers`
divides their gain out).  Where the line crosses a mode, the gain divided out is the fitted mode's, and a misfit of
its frequency or damping (the fit bent by anything else the data hold) leaves a step between the runs below the
crossing and those above it, which an exponent fitted over every run reads as a slope: family wheel 0's axial h 2
line, its axial mode fitted 0.25 % low (bent by an axial resonance stiffening with speed above it), read 1.035 of
its C·Ω² on the 14 runs below the crossing at 140 Hz and 1.10-1.16 above it: Ω^2.07 ± 0.013 over every run, an
``amplitude_law`` added for what is flat (2.00) below the crossing.  A law of the line's source holds on either
side of every crossing."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..stand_detect import STAND_MIN_LOG_GAIN
from ..units import CHANNELS, DIRECTION_CHANNELS

#: Speeds (log spaced over the runs' range) the damping's reach is read on to place the crossings between runs.
GRID_POINTS = 512


def damping_log_gain(state, direction: str, h: float, senses, omega: np.ndarray) -> np.ndarray:
    """ln of the power ratio of the line (direction, h, ``senses`` each of unit load) pooled over its direction's
    channels with every mode's damping doubled to that with the state's modes (``state.ext``), at ``omega`` rad/s.

    Near a crossing it is about ln ¼ (the resonant peak goes as 1/ζ²); away from the modes about 0: where its
    magnitude reaches :data:`rwadist.stand_detect.STAND_MIN_LOG_GAIN` (a factor 1.5) the modes' damping, not the
    line's source, sets the line's level."""
    from .. import extended as ext

    p = state.ext
    chans = [CHANNELS.index(c) for c in DIRECTION_CHANNELS[direction]]
    lines = [ext.Line(direction, float(h), 1.0, s) for s in senses]
    power = []
    for q in (p, replace(p, c_r=2.0 * p.c_r, c_rock=2.0 * p.c_rock, c_z=2.0 * p.c_z)):
        _, A = ext.steady_lines(q, lines, np.asarray(omega, float))
        power.append(np.maximum(np.sum(np.abs(A[:, :, chans]) ** 2, axis=(1, 2)), 1e-300))
    return np.log(power[1] / power[0])


def crossing_groups(state, direction: str, h: float, senses, w: np.ndarray) -> np.ndarray:
    """Per run (speed ``w`` rad/s): -1 where the modes' damping changes the line's power by a factor 1.5 or more
    (:func:`damping_log_gain`), else the index of the stretch between the line's crossings of the modes the run
    lies in (0 below the first crossing); all 0 on the empirical base (no modes).

    The crossings are the peaks of |:func:`damping_log_gain`| that reach the factor 1.5, read on
    :data:`GRID_POINTS` speeds over the runs' range: a crossing that falls between two runs splits them as well."""
    w = np.abs(np.asarray(w, float))
    if state.ext is None or w.size == 0 or np.ptp(w) <= 0:
        return np.zeros(w.size, int)
    grid = np.geomspace(w.min(), w.max(), GRID_POINTS)
    s = np.abs(damping_log_gain(state, direction, h, senses, grid))
    peak = np.flatnonzero((s[1:-1] >= s[:-2]) & (s[1:-1] > s[2:]) & (s[1:-1] >= STAND_MIN_LOG_GAIN)) + 1
    group = np.searchsorted(grid[peak], w)
    reach = np.abs(damping_log_gain(state, direction, h, senses, w)) >= STAND_MIN_LOG_GAIN
    return np.where(reach, -1, group)
