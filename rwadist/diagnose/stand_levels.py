"""A test-stand resonance fitted together with the levels of the lines it multiplies (the empirical base's C).

On the empirical base every line's C is fitted from the data before any effect is proposed, each line on its
own, over the speeds where no amplification shows (:func:`rwadist.empirical.modal_exclusion`).  A fixture
resonance biases those C: a line that lies above a fixture at every speed is attenuated at every speed (a
transmissibility, H → 0 above it) or lifted at every speed, and its C takes that in; a line that crosses the
fixture keeps only the speeds on one side.  Its log power gain against the base then holds an offset no resonance
explains, and a resonance fitted to those gains is bent to make up the offsets (the W7 trial wheel, a 180-Hz
fixture of ζ 0.03: the lines h 4.88, 6.24 and 9.76 fitted 3.5-13x low, a 'stand' at 180.8 Hz of ζ 0.014 and gain
54 that made the held-out misfit worse, and nothing named).  Here each line's level is a free parameter beside the
resonance: the log power gains are read with each line's weighted mean taken out (variable projection), so the
resonance is fitted on how each line's gain changes along its own speeds, and the levels follow from it.
"""
from __future__ import annotations

import numpy as np

from ..resonance import general_log_power_gain, peak_of

#: A line's level is changed with the resonance only when the resonance changes the line's power at one of its points
#: by this factor at least (1 % in amplitude): a line the fixture does not reach keeps the C the base fitted.
LEVEL_MIN_LOG_GAIN = float(np.log(1.02))
#: Evaluation limit of each least-squares start (4 parameters)
MAX_NFEV = 400
#: The smallest scatter (rms, natural-log power: 0.3 %) a line's log gains are weighted by in the second pass of
#: :func:`fit_with_levels`: the model error a line's Ω² law may carry however strong the line
LINE_SCATTER_FLOOR = 3e-3
#: A line with fewer degrees of freedom about its level than this is weighted by the larger of its own scatter and the
#: lines' median: two or three points may agree by chance
MIN_SCATTER_DOF = 3


def _projected(values: np.ndarray, inverse: np.ndarray, w: np.ndarray, w_sum: np.ndarray) -> np.ndarray:
    """``values`` (n,) or (n, k) with each line's ``w``-weighted mean taken out (lines ``inverse``)."""
    if values.ndim == 1:
        return values - (np.bincount(inverse, w * values, minlength=w_sum.size) / w_sum)[inverse]
    means = np.stack([np.bincount(inverse, w * v, minlength=w_sum.size) for v in values.T], axis=1) / w_sum[:, None]
    return values - means[inverse]


def _scatter_weights(res: np.ndarray, inverse: np.ndarray, w: np.ndarray, w_sum: np.ndarray) -> np.ndarray:
    """``w`` (n,) divided by the scatter of each point's line: the ``w``-weighted mean square of its residuals ``res``
    (n,) about its level (n/(n − 1) for the level fitted), floored at :data:`LINE_SCATTER_FLOOR`², the median's where
    the line has fewer than :data:`MIN_SCATTER_DOF` degrees of freedom; scaled so that the largest is 1."""
    count = np.bincount(inverse, minlength=w_sum.size)
    dof = np.maximum(count - 1, 0)
    var = np.bincount(inverse, w * res * res, minlength=w_sum.size) / w_sum * count / np.maximum(dof, 1)
    enough = dof >= MIN_SCATTER_DOF
    if enough.any():
        var = np.where(enough, var, np.maximum(var, np.median(var[enough])))
    out = w / np.maximum(var, LINE_SCATTER_FLOOR**2)[inverse]
    return out / max(float(out.max()), 1e-300)


def fit_with_levels(f: np.ndarray, y: np.ndarray, w: np.ndarray, lines: np.ndarray, lo: float, hi: float,
                    starts, predicted: np.ndarray | None = None) -> tuple | None:
    """The general resonance (:mod:`rwadist.resonance`) and one level per line fitted together to log power gains,
    in two passes: from ``starts`` with the points' weights ``w``, then from that fit with each line's weights divided
    by its own scatter about it (:func:`_scatter_weights`).

    Parameters
    ----------
    f, y, w : (n,) arrays
        Each point's frequency (Hz), log power gain ln(measured/predicted power) and weight (the line's SNR weight).
    lines : (n,) array of int
        The line each point belongs to (its level is common to its points).
    lo, hi : float
        Band of the resonance's frequency, Hz.
    starts : iterable of (f_r Hz, ζ, γ, β)
        Starting points of the robust least squares (:func:`rwadist.resonance.general_log_power_gain`'s parameters).
    predicted : (n,) array, optional
        Each point's predicted power: a line's level is then read on its powers, ln(Σ measured / Σ predicted·|H|²)
        over its points (its mean power, as :func:`rwadist.empirical.line_C` reads C), not as the weighted mean of
        its log gains, which reads a line whose power on a channel changes from run to run (both senses with their
        own phases) at its geometric mean: family wheel 4 hard mounted on a 90-Hz transmissibility, a planar line
        0.78x and a line of co share 0.8 0.87x its C.

    Returns
    -------
    tuple or None
        (f_r Hz, ζ, peak gain, gain above β, levels (m,) log power offset of each line id 0..m−1, soft-L1 cost of the
        second pass), or None when the points are too few.
    """
    from scipy.optimize import least_squares

    if f.size < 6:
        return None
    inverse = np.asarray(lines, dtype=int)
    lb = np.array([np.log(lo), np.log(1e-3), 0.0, -1.0])
    ub = np.array([np.log(hi), np.log(0.5), 200.0, 3.0])

    def best_of(weights: np.ndarray, x_starts) -> tuple:
        """(the lowest-cost least-squares solution from ``x_starts`` with point weights ``weights``, its line weight
        sums)."""
        w_sum = np.maximum(np.bincount(inverse, weights), 1e-300)
        sw = np.sqrt(weights)

        def res_jac(x):
            lg, d = general_log_power_gain(f, float(np.exp(x[0])), float(np.exp(x[1])), float(x[2]), float(x[3]))
            return sw * _projected(y - lg, inverse, weights, w_sum), -sw[:, None] * _projected(d, inverse, weights, w_sum)

        sols = [least_squares(lambda x: res_jac(x)[0], np.clip(x0, lb + 1e-9, ub - 1e-9), jac=lambda x: res_jac(x)[1],
                              loss="soft_l1", f_scale=0.5, bounds=(lb, ub), max_nfev=MAX_NFEV) for x0 in x_starts]
        return min(sols, key=lambda sol: sol.cost), w_sum          # the first of the lowest cost

    first, w_sum = best_of(w, [[np.log(f0), np.log(z0), gamma, beta] for f0, z0, gamma, beta in starts])
    # again from there, each line weighted by its own scatter about that fit: a line's SNR weight is ~1 for every line
    # well over the noise, but a line the fixture attenuates toward the noise scatters 10-30x more than one it lifts
    # (family wheel 5 hard mounted on a 300-Hz transmissibility: 0.002-0.055 rms), and the scattered ones had pulled
    # the frequency 1.2e-4 off, 6x the error after that the resonance's own frequency leaves
    lg1, _ = general_log_power_gain(f, float(np.exp(first.x[0])), float(np.exp(first.x[1])), float(first.x[2]),
                                    float(first.x[3]))
    best, _ = best_of(_scatter_weights(_projected(y - lg1, inverse, w, w_sum), inverse, w, w_sum), [first.x])
    f_r, zeta, gamma, beta = float(np.exp(best.x[0])), float(np.exp(best.x[1])), float(best.x[2]), float(best.x[3])
    lg, _ = general_log_power_gain(f, f_r, zeta, gamma, beta)
    if predicted is None:
        levels = np.bincount(inverse, w * (y - lg), minlength=w_sum.size) / w_sum
    else:
        measured = np.bincount(inverse, predicted * np.exp(y), minlength=w_sum.size)
        levels = np.log(np.maximum(measured, 1e-300)) - np.log(np.maximum(
            np.bincount(inverse, predicted * np.exp(lg), minlength=w_sum.size), 1e-300))
    # a line the resonance does not reach keeps its level (LEVEL_MIN_LOG_GAIN)
    reach = np.zeros(w_sum.size, bool)
    np.logical_or.at(reach, inverse, np.abs(lg) >= LEVEL_MIN_LOG_GAIN)
    return f_r, zeta, peak_of(zeta, gamma, beta), beta, np.where(reach, levels, 0.0), float(best.cost)


def starts_of(f: np.ndarray, y: np.ndarray, w: np.ndarray, lines: np.ndarray, peak, f0: float | None) -> list:
    """Starting points (f_r, ζ, γ, β) of :func:`fit_with_levels`: at ``f0`` or the strongest excess of the
    line-demeaned gains (``peak``: :meth:`FixedResonance.peak`, a callable of (f, y) giving (Hz, mean log gain) or
    None), ζ 0.01, 0.03 and 0.1, a peak returning to 1 above it (β = 1) and a transmissibility (β = 0)."""
    inverse = np.asarray(lines, dtype=int)
    w_sum = np.maximum(np.bincount(inverse, w), 1e-300)
    pk = peak(f, _projected(y, inverse, w, w_sum))
    if pk is None and f0 is None:
        return []
    centre = float(f0 if f0 is not None else pk[0])
    g0 = float(np.clip(np.exp(abs(pk[1]) / 2.0), 1.2, 50.0)) if pk is not None else 3.0
    return [(centre, z0, gamma, beta) for z0 in (0.01, 0.03, 0.1) for gamma, beta in ((g0, 1.0), (1.0, 0.0))]


def levelled_harmonics(model, line_levels) -> dict:
    """``model``'s empirical harmonics ({direction: [Harmonic]}, new lists) with each (direction, h, factor) of
    ``line_levels`` multiplying that line's C (the level fitted with a test stand, on every speed: its speeds the base
    left out as modally amplified are no longer listed, ``excluded_rpm`` emptied; its ``C_stderr`` scaled alike: the
    relative error the base measured, not an absolute one of another C)."""
    from dataclasses import replace

    out = {d: list(v) for d, v in model.empirical.items()}
    for direction, h, factor in line_levels:
        out[direction] = [replace(x, C=x.C * factor, excluded_rpm=[],
                                  C_stderr=None if x.C_stderr is None else x.C_stderr * factor)
                          if abs(x.h - h) <= 1e-9 * h else x
                          for x in out.get(direction, [])]
    return out
