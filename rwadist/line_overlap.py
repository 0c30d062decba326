"""A line measured beside weaker lines that share its bins (step 3 of :mod:`rwadist.empirical`).

A line's power is summed over 2L+1 Welch bins about its peak.  A harmonic with another harmonic's line within those
bins is *unresolved* and was dropped from the run: at low speed a carrier with speed sidebands at 0.94x and 1.06x
then loses every run below the speed where the sidebands leave its bins, and with them the speed range the
amplitude law is read on (trial 34: the sidebands of 0.2 went unfitted on two wheels).  When every neighbour in the
bins is weak (its power, as both are measured where both are resolved, at most :data:`WEAK_POWER_RATIO` of this
line's) and outside its main lobe, the line is measured there all the same, and what the neighbours put into its bins is taken out:

    P_measured = P_a (1 + Σ_b r_ab s_b),

with r_ab the median power ratio of line b to line a and s_b the share of a sinusoid at line b's frequency that the
Welch window puts into line a's bins (:func:`window_share`; Parseval: the shares over every bin sum to 1).  The
relative noise of such a measurement grows by sqrt(1 + Σ r_ab s_b) (the ratio is a median, not this run's) and
takes in half the bound of the lines' cross terms in the bins (they beat within a segment, by their phases).
A weak neighbour itself stays unresolved: its bins hold the strong line.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal

#: A neighbour is weak when its power is at most this fraction of the line's (amplitude ratio ~0.32).
WEAK_POWER_RATIO = 0.1
#: Fewest spectra in which both lines are resolved for their power ratio to be read.
MIN_COMMON = 1
#: Zero-padding factor of the window's spectrum: the share table's step is 1/this bin.
_PAD = 32
#: The share table reaches this many bins from the line (the Hann side lobes are below -90 dB there).
_REACH = 24


@lru_cache(maxsize=8)
def _share_table(window: str, nperseg: int) -> np.ndarray:
    """|W(u)|² / (N Σw²) at u = 0, 1/_PAD, ..., _REACH bins (the window's spectrum, zero-padded FFT)."""
    w = signal.get_window(window, nperseg)
    pad = max(2, min(_PAD, (1 << 23) // nperseg))
    spec = np.abs(np.fft.rfft(w, nperseg * pad)) ** 2 / (nperseg * np.sum(w ** 2))
    u = np.arange(_REACH * _PAD + 1) / _PAD
    return np.interp(u, np.arange(spec.size) / pad, spec)


def main_lobe(window: str, nperseg: int) -> float:
    """Half-width of the window's main lobe, bins (its spectrum's first null: 2 for Hann)."""
    table = _share_table(window, nperseg)
    k = int(np.argmax(np.diff(table) > 0))
    return k / _PAD


def window_share(window: str, nperseg: int, offset, half_width: int) -> np.ndarray:
    """Share of a sinusoid's power that a Welch PSD of ``window`` (``nperseg`` samples) puts into the 2L+1 bins
    k0-L..k0+L (L = ``half_width``), the sinusoid sitting ``offset`` bins (any shape, fractional) from bin k0."""
    table = _share_table(window, nperseg)
    grid = np.arange(table.size) / _PAD
    u = np.abs(np.arange(-half_width, half_width + 1) - np.asarray(offset, float)[..., None])
    return np.interp(u, grid, table, right=0.0).sum(axis=-1)


def weak_neighbours(power: np.ndarray) -> np.ndarray:
    """Power ratios r_ab = P_b / P_a (the median over the spectra where both are measured, ``power`` (n_h, n_pairs)
    with NaN where a line is not measured) of the neighbours b weak beside a; NaN where b is not weak beside a or the
    ratio cannot be read (shape (n_h, n_h))."""
    n = power.shape[0]
    ratio = np.full((n, n), np.nan)
    for a in range(n):
        both = np.isfinite(power[a])[None, :] & np.isfinite(power) & (power[a] > 0)[None, :]
        for b in np.nonzero(both.sum(axis=1) >= MIN_COMMON)[0]:
            if b != a:
                ratio[a, b] = np.median(power[b, both[b]] / power[a, both[b]])
    return np.where(ratio <= WEAK_POWER_RATIO, ratio, np.nan)


def measured_beside(valid: np.ndarray, resolved: np.ndarray, clear: np.ndarray, n_near: np.ndarray,
                    fpk: np.ndarray, predicted: np.ndarray, power: np.ndarray, df: float, half_width: int, window: str,
                    nperseg: int) -> tuple:
    """The (harmonic, pair) cells that are measured beside weak neighbours, and their neighbours' part.

    valid : (n_h, n_pairs) bool, detected and in band.  resolved : (n_h, n_pairs) bool, measured as they stand.
    clear : (n_h, n_h, n_pairs) bool, line b is clear of line a's bins in the pair.  n_near : (n_h, n_pairs) detected
    lines under line a's window.  fpk : (n_h, n_pairs) detected frequency (Hz, NaN: none).  predicted : (n_h, n_pairs)
    h times the speed, Hz: where a neighbour is (a weak line's detected peak is pulled towards the strong one).  power : (n_h, n_pairs) power of the resolved cells (NaN elsewhere).
    Returns (hi, pi, part, beat): cell indices, Σ_b r_ab s_b of each (the measured power is (1 + part) times the
    line's) and the bound of the lines' cross terms relative to the line's power (lines closer than a few bins beat
    within a Welch segment: their cross term follows the phases; ~0.08 for two sidebands of 0.2 at 2.4 bins).
    """
    n_h = fpk.shape[0]
    empty = (np.zeros(0, int), np.zeros(0, int), np.zeros(0), np.zeros(0))
    if n_h < 2:
        return empty
    ratio = weak_neighbours(power)
    weak = np.isfinite(ratio)
    near = ~clear
    near[np.arange(n_h), np.arange(n_h), :] = False
    # a neighbour inside the main lobe beats with the line within a segment (their cross term is as large as the
    # weak line's power and follows the phases): such a run is left out as before
    apart = np.abs(predicted[None, :, :] - np.where(np.isfinite(fpk), fpk, predicted)[:, None, :]) \
        >= main_lobe(window, nperseg) * df
    cand = valid & ~resolved & near.any(axis=1) & np.all(~near | (weak[:, :, None] & apart), axis=1)
    # the weak neighbours' own detections are not other lines under the window (one each: a weak line's peak on the
    # strong one's skirt is pulled towards it, out of its harmonic's tolerance)
    cand &= (n_near - near.sum(axis=1)) <= 1
    hi, pi = np.nonzero(cand)
    if hi.size == 0:
        return empty
    k0 = np.rint(fpk[hi, pi] / df)
    offset = predicted[:, pi] / df - k0[None, :]                                    # (n_h, m)
    offset[hi, np.arange(hi.size)] = fpk[hi, pi] / df - k0
    share = window_share(window, nperseg, offset, half_width)
    with_a = near[hi, :, pi].T                                                      # (n_h, m)
    with_a[hi, np.arange(hi.size)] = True
    r = np.where(with_a, ratio[hi, :].T, 0.0)
    r[hi, np.arange(hi.size)] = 1.0
    part = np.sum(np.where(with_a, r * share, 0.0), axis=0) - 1.0
    # bound of the cross terms 2 Re(X_x X_y*) of every two lines in the bins, relative to the line's power
    table = _share_table(window, nperseg)
    grid = np.arange(table.size) / _PAD
    kernel = np.sqrt(np.interp(np.abs(np.arange(-half_width, half_width + 1) - offset[..., None]), grid, table,
                               right=0.0))                                          # (n_h, m, 2L+1)
    amp = np.sqrt(r)[..., None] * kernel
    total = amp.sum(axis=0)
    beat = np.sum(total ** 2 - np.sum(amp ** 2, axis=0), axis=-1)
    return hi, pi, part, beat
