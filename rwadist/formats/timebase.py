"""The sampling step of a time column as instruments write it.

A data-acquisition system prints its time stamps with a fixed number of
decimals (``%.6f``: microseconds) or of significant digits (``%.10g``), so
consecutive steps jitter by the rounding of the last printed digit.  The step
is therefore estimated from the whole column (a least-squares line through
sample index and time), and a column is refused only for what rounding cannot
explain: a repeated sample, a dropped sample, a gap, or a rate that disagrees
with the declared one by more than the rounding allows.  Every reader (CSV,
HDF5, UFF, TDMS, MATLAB) uses :func:`sample_step`.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .records import DataError

#: Float64 relative precision margin (a few ulp) added to every rounding bound.
FLOAT_MARGIN = 8.0 * np.finfo(float).eps
#: Largest deviation of one step accepted as rounding, as a fraction of the step
#: (a dropped or repeated sample is a whole step off).
MAX_RESOLUTION_FRACTION = 0.25


def printed_resolution(time: np.ndarray, stored_rtol: float = 0.0) -> np.ndarray:
    """Rounding step of each printed time value, s, shape (n,).

    The column is taken to be printed either with a fixed number of decimals
    or with a fixed number of significant digits; both are inferred from the
    values themselves (the most decimals and the most significant digits any
    value needs), and each sample gets the coarser of the two resolutions.
    Values stored at full float64 precision get a resolution of a few ulp.

    Parameters
    ----------
    time : array, shape (n,), s.
    stored_rtol : relative precision of the storage (float32 time stamps: its epsilon), 0 for float64/text.

    Returns
    -------
    array, shape (n,), s: bound on twice the rounding error of each value.
    """
    t = np.asarray(time, dtype=float)
    mag = np.abs(t)
    decimals = np.full(t.shape, 17, dtype=int)
    pending = mag > 0
    for k in range(0, 17):
        if not pending.any():
            break
        scaled = t[pending] * 10.0**k
        exact = np.abs(scaled - np.rint(scaled)) <= FLOAT_MARGIN * np.abs(scaled)
        idx = np.flatnonzero(pending)[exact]
        decimals[idx] = k
        pending[idx] = False
    nonzero = mag > 0
    if not nonzero.any():
        return np.full(t.shape, np.inf)
    exponent = np.zeros(t.shape, dtype=int)
    exponent[nonzero] = np.floor(np.log10(mag[nonzero])).astype(int)
    fixed_decimals = int(decimals[nonzero].max())
    significant = int((decimals + exponent + 1)[nonzero].max())
    fixed = 10.0 ** (-fixed_decimals)
    relative = np.where(nonzero, 10.0 ** (exponent + 1 - significant).astype(float), 0.0)   # 0 prints exactly
    return np.maximum(np.maximum(fixed, relative), (FLOAT_MARGIN + stored_rtol) * mag)


def _least_squares_step(time: np.ndarray) -> tuple:
    """(step, intercept) of the line time ≈ intercept + step·i, i = 0..n-1.

    The least squares of what a line through the two ends leaves, added to that line: its sums then hold numbers
    of the size of the rounding, not of the time stamps.  Taken directly, Σ(i − ī)(t − t̄) over the 1 497 600 time
    stamps of a 390-s sweep (terms up to 1.5e8) put the step 6.5e-13 off (1.7e-16 s): 17 times the printed rounding
    of a 17-digit column, so every step of the project's own sweep file was refused as a gap."""
    t = np.asarray(time, dtype=float)
    n = len(t)
    i = np.arange(n, dtype=float)
    rough = (t[-1] - t[0]) / (n - 1)
    r = t - (t[0] + rough * i)                          # the rounding, and any real departure from uniform
    di = i - 0.5 * (n - 1)
    slope = float(np.dot(di, r - r.mean()) / np.dot(di, di))
    step = float(rough + slope)
    return step, float(t[0] + r.mean() - slope * 0.5 * (n - 1))


#: Rounding up to this fraction of the step is judged over the whole column (:func:`_on_one_grid`); from there on a
#: stamp cannot name its sample (exact stamps a whole step apart fit a grid shifted half a step as well, a lost
#: sample included)
COARSE_MAX_FRACTION = 0.95
#: Golden-section steps of :func:`_on_one_grid`'s search over the grid's step (the slopes of the lines through both end
#: stamps' bands: 0.618^80, 1e-17 of that span)
GRID_SEARCH_STEPS = 80


def _on_one_grid(t: np.ndarray, q: np.ndarray) -> bool:
    """True when one uniform grid t0 + k·s (k = 0..n-1) lies within every stamp's rounding: some t0 and s with
    |t_k − t0 − k·s| ≤ q_k/2 for all k.  For a slope s the least gap left, max(t − q/2 − k·s) − min(t + q/2 − k·s),
    is convex in s: its least over the slopes of the lines through both end stamps' bands (golden section) is ≤ 0
    exactly when such a grid exists.  Not the least-squares step: where the step is an odd multiple of half the
    rounding, ties round one way over long stretches and tilt it (4 kHz printed to 0.1 ms from t0 = 0.1 s).  A golden
    section of its own: scipy's bounded Brent search stalls on this piecewise-linear gap (4 kHz and 40 kHz columns
    with rounding ties refused)."""
    n = t.size
    i = np.arange(n, dtype=float)
    r = t - (t[0] + (t[-1] - t[0]) / (n - 1) * i)         # about the line through the ends: numbers of the rounding
    lo, hi = r - 0.5 * q, r + 0.5 * q
    margin = 4.0 * FLOAT_MARGIN * float(np.max(np.abs(t)))

    def gap(slope: float) -> float:
        u = slope * i
        return float(np.max(lo - u) - np.min(hi - u))

    a, b = (lo[-1] - hi[0]) / (n - 1), (hi[-1] - lo[0]) / (n - 1)
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = b - golden * (b - a), a + golden * (b - a)
    gc, gd = gap(c), gap(d)
    for _ in range(GRID_SEARCH_STEPS):
        if min(gc, gd) <= margin:
            return True
        if gc < gd:
            b, d, gd = d, c, gc
            c = b - golden * (b - a)
            gc = gap(c)
        else:
            a, c, gc = c, d, gd
            d = a + golden * (b - a)
            gd = gap(d)
    return bool(min(gc, gd) <= margin)


def _change_point(t: np.ndarray) -> tuple[int, float]:
    """(i, jump s): the step (sample i to i+1) after which the stamps sit off the grid of those before, and by how
    much: the least squares of a line plus one jump at each place in turn (a lost sample shifts every later stamp
    by a step and tilts the column's line, which the fitted line takes up), the place explaining most chosen.
    Closed form from suffix sums, no loop."""
    n = len(t)
    idx = np.arange(n, dtype=float)
    x = idx - idx.mean()
    u = t - (t[0] + (t[-1] - t[0]) / (n - 1) * idx)
    u = u - u.mean()
    u = u - x * (x @ u) / (x @ x)                            # the residual of the column's line
    m = np.arange(n - 1, 0, -1, dtype=float)                  # samples from k = 1..n-1 on
    su = np.cumsum(u[::-1])[::-1][1:]
    sx = np.cumsum(x[::-1])[::-1][1:]
    # a jump at k, H = (index >= k), orthogonalised against the line: |H⊥|² = m − m²/n − (Σx over H)²/Σx²
    den = np.maximum(m - m * m / n - sx * sx / (x @ x), np.finfo(float).tiny)
    k = int(np.argmax(su * su / den))
    return k, float(su[k] / den[k])


def _what_to_do(ratio: float) -> str:
    """The advice of a non-uniform time column: a run with lost or repeated samples is no steady record."""
    return ("; export the run again without the loss (or leave it out: a steady run's lines need an unbroken "
            "record)" if ratio > 0 else "; export the run again with increasing time stamps (or leave it out)")


def _kind_of_step(ratio: float, whole: float = 0.05) -> str:
    """What a step of ``ratio`` sampling steps is; within ``whole`` of a whole number of steps, lost samples."""
    if ratio < 0.5:
        return "a repeated sample (time stamp written twice)" if ratio > -0.5 else "time going backwards"
    n_missing = round(ratio) - 1
    if n_missing >= 1 and abs(ratio - round(ratio)) < whole:
        return f"{n_missing} dropped sample(s)"
    return "a gap in the sampling"


def _csv_line(i: int) -> str:
    """Where the step from sample i to i+1 ends in a CSV with a header line."""
    return f"line {i + 3}"


def sample_step(path, field_name: str, time, declared_rate: float | None = None,
                declared_by: str = "meta.json sample_rate_hz",
                position: Callable[[int], str] | None = None, stored_rtol: float = 0.0) -> float:
    """The sampling step of a time column, s; DataError unless it is uniform up to its printed rounding.

    Parameters
    ----------
    path : file named in errors.
    field_name : column or dataset named in errors.
    time : array, shape (n,), s, as read from the file.
    declared_rate : Hz, a sample rate stated elsewhere (meta.json, an attribute), or None.
    declared_by : how errors name where ``declared_rate`` comes from.
    position : ``position(i)`` names where the step from sample i to i+1 ends in the file; None: a CSV line
        (header on line 1, sample 0 on line 2).
    stored_rtol : relative precision of the storage beyond printing (float32: its epsilon).

    Returns
    -------
    float, s: ``1/declared_rate`` when given and consistent, else the least-squares step.
    """
    t = np.asarray(time, dtype=float)
    n = len(t)
    if n < 2:
        raise DataError(path, field_name, f"only {n} sample(s); need at least 2")
    step, _ = _least_squares_step(t)
    if not step > 0:
        raise DataError(path, field_name, f"time does not increase (least-squares step {step:.9g} s)")
    q = printed_resolution(t, stored_rtol)
    q_max = float(q.max())
    # a step differs from the true step by at most the rounding of its two ends (q/2 each), and the
    # estimated step from the truth by at most 1.5·q_max/n (worst case of the least-squares slope)
    step_error = 1.5 * q_max / n + FLOAT_MARGIN * step
    dt = np.diff(t)
    # values that merely look round (exact multiples of 1 ms) must not widen the tolerance to where a
    # dropped or repeated sample (one whole step off) would pass: cap it at a fraction of the step
    tolerance = np.minimum(0.5 * (q[:-1] + q[1:]) + step_error * 1.01 + FLOAT_MARGIN * np.abs(t[1:]),
                           MAX_RESOLUTION_FRACTION * step)
    excess = np.abs(dt - step) - tolerance
    coarse = MAX_RESOLUTION_FRACTION * step < q_max < COARSE_MAX_FRACTION * step
    if coarse:
        # stamps rounded coarser than a quarter step but finer than a whole one: one step cannot tell a dropped
        # sample from rounding, the whole column can (every stamp the rounding of one uniform grid)
        bad, jump = (None, 0.0) if _on_one_grid(t, q) else _change_point(t)
        ratio = 1.0 + jump / step
    else:
        bad = int(np.argmax(excess)) if excess.max() > 0 else None
        ratio = 1.0 if bad is None else dt[bad] / step
    if bad is not None:
        where = _csv_line(bad) if position is None else position(bad)
        if coarse:
            found = (f"the time stamps from {where} on sit {ratio - 1:.3g} sampling steps off the uniform grid of "
                     f"those before ({_kind_of_step(ratio, 0.25)}); sampling step {step:.9g} s from a least-squares line "
                     f"through all {n} time stamps, printed to {q_max:.3g} s (rounding explains ±{0.5 * q_max:.2g} s)")
        else:
            found = (f"step {dt[bad]:.9g} s at {where} is {ratio:.4g} sampling steps ({_kind_of_step(ratio)}); "
                     f"sampling step {step:.9g} s from a least-squares line through all {n} time stamps, printed "
                     f"rounding explains ±{tolerance[bad]:.2g} s")
        hint = (f"; the time stamps are printed to {q_max:.3g} s, too coarse for this step: write more digits "
                "(%.10g or 17 significant digits)") if q_max >= COARSE_MAX_FRACTION * step else _what_to_do(ratio)
        raise DataError(path, field_name, f"sampling is not uniform: {found}{hint}")
    if declared_rate is not None:
        declared_step = 1.0 / float(declared_rate)
        if abs(declared_step - step) > step_error * 1.01 + FLOAT_MARGIN * step:
            raise DataError(path, field_name, f"sample rate from the time stamps {1.0 / step:.9g} Hz "
                            f"(±{step_error / step * 1.0 / step:.2g} Hz from their printed rounding) disagrees "
                            f"with {declared_by} {declared_rate!r}")
        return declared_step
    return step


def check_rate(path, field_name: str, rate: float, rate_rtol: float, declared_rate: float | None,
               declared_by: str = "meta.json sample_rate_hz") -> float:
    """A sample rate stored by the file (Hz, relative precision ``rate_rtol``) against a declared one.

    Returns the declared rate when given and consistent within the file's precision, else ``rate``.
    """
    if not (np.isfinite(rate) and rate > 0):
        raise DataError(path, field_name, f"sample rate {rate!r} Hz is not a positive number")
    if declared_rate is None:
        return float(rate)
    tol = (rate_rtol + FLOAT_MARGIN) * rate
    if abs(rate - declared_rate) > tol:
        raise DataError(path, field_name, f"sample rate {rate:.9g} Hz (stored to ±{tol:.2g} Hz) disagrees with "
                        f"{declared_by} {declared_rate!r}")
    return float(declared_rate)
