"""The resonance gain H(r): the one home of the single-mode amplification used across the kit.

A line at frequency f passing a simple resonance at f_r (Hz) with damping ratio ζ and peak gain g
is multiplied by::

    H(r) = (1 − r² + 2j·g·ζ·r) / (1 − r² + 2j·ζ·r),   r = f / f_r

so H(0) = 1, |H(1)| = g and H → 1 far above the mode (the line is amplified near f_r only).  For g > 1
it amplifies, for g < 1 it notches.  Used by the test-stand simulator (:class:`rwadist.teststand.Mode`),
``rwadist diagnose`` (``fixed_resonance`` effects), the extended model and ``rwadist psd`` (wheel-mode
resonances of a model file).  The FMU runtime (``fmu/runtime.py``) keeps its own inline copy on
purpose, so that it stays self-contained for simulation hosts; ``tests/test_resonance.py`` pins that
copy to this one numerically.
"""
from __future__ import annotations

import numpy as np


def resonance_response(r, zeta: float, peak_gain: float) -> np.ndarray:
    """H(r) at frequency ratio ``r`` (any shape, SIGNED: a negative r gives the complex conjugate).

    Parameters
    ----------
    r : array_like
        Frequency ratio f/f_r, dimensionless, any shape.
    zeta : float
        Damping ratio, dimensionless (> 0).
    peak_gain : float
        |H| at r = ±1, dimensionless.

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``r``.
    """
    r = np.asarray(r, dtype=float)
    base = 1.0 - r * r
    two_zr = 2.0 * zeta * r
    return (base + 1j * peak_gain * two_zr) / (base + 1j * two_zr)


def resonance(f_hz, f_r: float, zeta: float, peak_gain: float) -> np.ndarray:
    """Complex gain H(r), r = |f|/f_r, of a simple resonance at ``f_r`` with H → 1 far from it.

    Parameters
    ----------
    f_hz : array_like
        Line frequencies, Hz, any shape (the sign is ignored).
    f_r : float
        Resonance frequency, Hz (> 0).
    zeta : float
        Damping ratio, dimensionless (> 0).
    peak_gain : float
        |H(f_r)|, dimensionless.

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``f_hz``.
    """
    return resonance_response(np.abs(np.asarray(f_hz, dtype=float)) / f_r, zeta, peak_gain)


def resonance_gain(nu, resonances) -> np.ndarray:
    """Product of H over ``resonances`` at whirl rates ``nu`` taken SIGNED.

    For ν >= 0 each factor is :func:`resonance` at ν/2π; for ν < 0 its complex conjugate, so a load's
    Re/Im pair sees the same real filter.

    Parameters
    ----------
    nu : array_like
        Whirl rates, rad/s, any shape, signed.
    resonances : iterable of (float, float, float)
        (f_r Hz, ζ, peak gain) of each resonance; empty gives ones.

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``nu``.
    """
    nu = np.asarray(nu, dtype=float)
    out = np.ones(nu.shape, dtype=complex)
    for f_r, zeta, g in resonances:
        out = out * resonance_response(nu / (2.0 * np.pi * f_r), zeta, g)
    return out
