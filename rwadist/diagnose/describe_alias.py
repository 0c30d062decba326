"""A line folded at the sample rate: the ``affine_line`` tracks f = f_s − h·f_spin of a line at h × the speed above the
Nyquist frequency (:func:`alias_tracks`), and the cause they name (:func:`alias_causes`).

A record with no anti-alias filter before the DAQ (or one set above the Nyquist frequency) holds every line at
h·f_spin between f_s/2 and f_s at f_s − h·f_spin: a straight track falling with the speed at h Hz per Hz of spin,
steeper than the slopes the ``affine_line`` search counts (|b| <= 4) for a motor's or a gear's high order, and over the
few top speeds where the line passes the Nyquist frequency.  Session 62's trial: a 7.5-kg wheel's motor-stator line
h 24 at 3 kHz, folded at 1455 -> 1200 Hz over its 6 runs of 3864-4500 rpm, 0.016-0.022 N: described by nothing.  Its
offset is the sample rate, known, so the track is one parameter (h) and is counted over fewer runs
(:data:`MIN_RUNS`); it is read and refused as any ``affine_line`` (:func:`rwadist.diagnose.describe_affine.affine_lines`).
"""
from __future__ import annotations

import numpy as np

from .describe_lines import RIDGE_FRACTION

#: Runs a folded track is lit in, at least (its offset is the sample rate: one parameter)
MIN_RUNS = 5
#: The h grid's step moves a folded track this many Welch bins over the runs' speed range
H_STEP_BINS = 0.5
#: Largest h searched (a motor's or gear's order)
MAX_H = 200.0
#: At most this many folded tracks are read, the most lit first
MAX_TRACKS = 40
#: A track whose offset lies within this many Welch bins of the sample rate, falling, is a folded line
FOLD_BINS = 2.0


def alias_tracks(lit: np.ndarray, seg: np.ndarray, spin: np.ndarray, df: float, fs: float, k_lo: int,
                 k_hi: int) -> list:
    """Candidate folded tracks (slope b = −h, offset bin of ``fs``, runs lit (bool per run), fraction lit, lit segment
    label per run, True) of the pooled lit map ``lit`` (runs, n_f; ``seg`` its segment labels) over runs of spin
    frequencies ``spin`` (Hz) sampled at ``fs`` (Hz): for h on a grid, the runs where h·f_spin lies between fs/2 and
    fs and its fold fs − h·f_spin in the band [``k_lo``, ``k_hi``] bins, lit in :data:`RIDGE_FRACTION` of at least
    :data:`MIN_RUNS` of them; local maxima of the lit fraction over h, the most lit first."""
    R, K = lit.shape
    span = float(spin.max() - spin.min())
    if span <= 0 or spin.min() <= 0:
        return []
    h_lo, h_hi = 0.5 * fs / spin.max(), min(fs / spin.min(), MAX_H)
    if h_hi <= h_lo:
        return []
    h = np.arange(h_lo, h_hi, H_STEP_BINS * df / span)
    n_in, n_hit = np.zeros(h.size, int), np.zeros(h.size, int)
    for lo in range(0, h.size, CHUNK):                  # (chunk, R) at a time: long records make the h grid fine
        k, inb = _folded_bins(h[lo:lo + CHUNK], spin, df, fs, k_lo, k_hi)
        n_in[lo:lo + CHUNK] = inb.sum(1)
        n_hit[lo:lo + CHUNK] = (lit[np.arange(R)[None, :], np.clip(k, 0, K - 1)] & inb).sum(1)
    frac = np.where(n_in >= MIN_RUNS, n_hit / np.maximum(n_in, 1), 0.0)
    ok = (frac >= RIDGE_FRACTION) & (n_hit >= MIN_RUNS)
    # a ridge's peak inside the grid, the first of a plateau of equal lit fractions
    inner = np.zeros(h.size, bool)
    inner[1:-1] = (frac[1:-1] > frac[:-2]) & (frac[1:-1] >= frac[2:])
    peaks = np.flatnonzero(ok & inner)
    out = []
    j_fs = int(np.rint(fs / df))
    for i in peaks[np.lexsort((-n_hit[peaks], -frac[peaks]))][:MAX_TRACKS]:
        k, inb = _folded_bins(h[i:i + 1], spin, df, fs, k_lo, k_hi)
        hit = lit[np.arange(R), np.clip(k[0], 0, K - 1)] & inb[0]
        labels = np.where(hit, seg[np.arange(R), np.clip(k[0], 0, K - 1)], 0)
        out.append((-float(h[i]), j_fs, hit, float(frac[i]), labels, True))
    return out


#: h values of the grid counted at once (memory: CHUNK × runs cells)
CHUNK = 4096


def _folded_bins(h: np.ndarray, spin: np.ndarray, df: float, fs: float, k_lo: int, k_hi: int) -> tuple:
    """(bins (len(h), R) of the folds fs − h·f_spin, in band (len(h), R): h·f_spin between fs/2 and fs and the fold in
    [``k_lo``, ``k_hi``])."""
    hf = h[:, None] * spin[None, :]
    k = np.rint((fs - hf) / df).astype(int)
    return k, (hf > 0.5 * fs) & (hf < fs) & (k >= k_lo) & (k <= k_hi)


def folded(f0: float, b: float, fs: float | None, df: float) -> bool:
    """Whether the track f0 + b·f_spin is a line folded at the sample rate ``fs`` (Hz; None: runs of several rates):
    falling, from an offset within :data:`FOLD_BINS` Welch bins (``df`` Hz) of it."""
    return fs is not None and b < 0 and abs(f0 - fs) <= FOLD_BINS * df


#: A fold's offset, read free, lies within this many of its standard errors of the sample rate (or FOLD_BINS bins)
FOLD_STDERRS = 4.0


def offset_holds(spin: np.ndarray, f: np.ndarray, offset: float, df: float) -> bool:
    """Whether the peaks ``f`` (Hz) over the spin frequencies ``spin`` (Hz) allow the line's offset to be ``offset``:
    their free least-squares offset within :data:`FOLD_STDERRS` of its standard error (from the residuals, n − 2
    degrees of freedom) or :data:`FOLD_BINS` Welch bins of it.  A falling line 3-10
    bins off the sample rate, read sharply, is not a fold (read through the sample rate it passed the misfit gate)."""
    n = spin.size
    b, f0 = np.polyfit(spin, f, 1)
    if n <= 2:
        return abs(f0 - offset) <= FOLD_BINS * df
    resid = f - (f0 + b * spin)
    sxx = float(np.sum((spin - spin.mean()) ** 2))
    se = float(np.sqrt(np.sum(resid**2) / (n - 2) * (1.0 / n + spin.mean() ** 2 / max(sxx, 1e-300))))
    return abs(f0 - offset) <= max(FOLD_BINS * df, FOLD_STDERRS * se)


def reads_as_counted(f0: float, b: float, h: float, spin: np.ndarray, fs: float, df: float) -> bool:
    """Whether a folded track counted at ``h`` was read as one (:func:`folded`, its slope −h within
    :data:`FOLD_BINS` Welch bins over the spin frequencies ``spin`` Hz): a candidate counted over few runs and read
    as any other straight line is not described (it passed none of the ``affine_line`` search's own gates)."""
    return folded(f0, b, fs, df) and abs(b + h) * float(np.ptp(spin)) <= FOLD_BINS * df


def alias_causes(f0: float, b: float, fs: float) -> tuple:
    """What a line folded at the sample rate ``fs`` (the track f0 + b·f_spin, f0 ≈ fs, b < 0) is, and its order."""
    return (f"a line at {-b:.4g} × the speed above the Nyquist frequency ({fs / 2:.4g} Hz), folded at the sample rate "
            f"({fs:.4g} Hz): f = {fs:.4g} − {-b:.4g}·f_spin, seen where {-b:.4g}·f_spin lies between {fs / 2:.4g} and "
            f"{fs:.4g} Hz (no anti-alias filter before the DAQ, or one set above the Nyquist frequency); a motor's "
            f"or a gear's order, or a bearing line's high multiple, at {-b:.4g}·f_spin in the wheel",)


ALIAS_TELLS = ("the runs recorded again at a higher sample rate or with the DAQ's anti-alias filter on: a folded line "
               "moves to h·f_spin (or is gone under the filter), a line of the wheel's own stays where it is")
