"""Reductions of the diagnosis that must give numpy's own numbers faster: sums of a band's bins in numpy's pairwise
order, column medians over valid values."""
from __future__ import annotations

import numpy as np


def bin_sums(v: np.ndarray) -> np.ndarray:
    """``v.sum(-1)`` of a (..., BAND_BINS) array of each band's bins: for 8 bins numpy's own pairwise order,
    ((x0 + x1) + (x2 + x3)) + ((x4 + x5) + (x6 + x7)), as 7 adds of whole arrays -- the same sums (numpy's
    reduction over a short strided axis costs 2.4x as much)."""
    if v.shape[-1] != 8:
        return v.sum(-1)
    return ((v[..., 0] + v[..., 1]) + (v[..., 2] + v[..., 3])) + ((v[..., 4] + v[..., 5]) + (v[..., 6] + v[..., 7]))


def column_nanmedian(z: np.ndarray) -> np.ndarray:
    """Median of each column of ``z`` (rows, cols) over its non-NaN values, NaN for a column with none:
    ``np.nanmedian(z, axis=0)``'s numbers (the middle value, or the mean (a + b)/2 of the middle two, of the sorted
    values), from one sort of the columns -- numpy takes masked arrays for fewer than 600 rows, 50x slower here."""
    z = np.asarray(z, dtype=float)
    if z.shape[0] == 0:
        return np.full(z.shape[1:], np.nan)
    srt = np.sort(z, axis=0)                                                # NaN sorted after every value
    cnt = np.sum(~np.isnan(z), axis=0)
    hi = cnt // 2
    lo = np.where(cnt % 2 == 1, hi, hi - 1)
    cols = np.arange(z.shape[1])
    last = z.shape[0] - 1
    mid = (srt[np.clip(lo, 0, last), cols] + srt[np.clip(hi, 0, last), cols]) / 2.0
    return np.where(cnt > 0, mid, np.nan)
