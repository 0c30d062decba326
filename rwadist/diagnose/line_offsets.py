"""Misfits with each line's own offset taken out: the least squares of a curve through the points of several lines
whose coefficients C are free (a line's dB offset is its C's misfit, never the curve's)."""
from __future__ import annotations

import numpy as np


def line_indicator(line: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(onehot (L, N), count (L,)): per distinct line of ``line`` (N,) its points as 1.0 (lines in sorted order), and
    the number of its points."""
    lines = np.unique(line)
    onehot = (line[None, :] == lines[:, None]).astype(float)
    return onehot, onehot.sum(1)


def offset_free_sse(res: np.ndarray, onehot: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Σ of the squared residuals ``res`` (K, N) dB of K curves at N points, each line's mean residual taken out
    (``onehot``, ``count``: :func:`line_indicator`), shape (K,)."""
    e = res - ((res @ onehot.T) / count) @ onehot
    return np.sum(e * e, axis=1)


def per_line_sse(res: np.ndarray, onehot: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Per line, Σ of the squared residuals ``res`` (N,) dB about the line's own mean (``onehot``, ``count``:
    :func:`line_indicator`), shape (L,)."""
    e = res - ((onehot @ res) / count) @ onehot
    return onehot @ (e * e)
