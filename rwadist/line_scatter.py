"""The run-to-run spread of a line's strength about its smooth course with the speed.

A line whose source is not locked in strength to the speed (a bearing defect's impacts, a rub, a lubricant film that
forms and breaks) scatters about its law from run to run by several dB; a line that crosses a suspension mode rises
and falls smoothly, and a run or two where a sharp mode lifts it stand out alone.  :func:`spread` reads the first and
not the others: each reading less the median of its :data:`MEDIAN_RUNS` − 1 neighbours by speed (which follows a
smooth gain), the robust spread (1.4826 x the median absolute deviation) of what is left (which a run or two do not
move).  :mod:`rwadist.diagnose.describe_partial` describes a model line whose measured-over-model ratios scatter so.
"""
from __future__ import annotations

import numpy as np

#: The running median's width (speeds) a line's log amplitude over Ω² is taken against.
MEDIAN_RUNS = 5


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
