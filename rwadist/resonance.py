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


def log_power_gain_jacobian(f_hz, f_r: float, zeta: float, peak_gain: float) -> np.ndarray:
    """Derivatives of ln|H|² (:func:`resonance`) with respect to (ln f_r, ln ζ, ln g), in closed form.

    With b = 1 − r², a = 2ζr, r = |f|/f_r: ln|H|² = ln(b² + g²a²) − ln(b² + a²), and since
    ∂r/∂ln f_r = −r, ∂b/∂ln f_r = 2r², ∂a/∂ln f_r = −a, ∂a/∂ln ζ = a::

        ∂/∂ln f_r = (4br² − 2g²a²)/N − (4br² − 2a²)/D
        ∂/∂ln ζ   = 2g²a²/N − 2a²/D
        ∂/∂ln g   = 2g²a²/N,            N = b² + g²a², D = b² + a²

    (an analytic Jacobian for least-squares fits of log power gains in log parameters).

    Parameters
    ----------
    f_hz : array_like
        Line frequencies, Hz, shape (n,) (the sign is ignored).
    f_r : float
        Resonance frequency, Hz (> 0).
    zeta : float
        Damping ratio, dimensionless (> 0).
    peak_gain : float
        |H(f_r)|, dimensionless (> 0).

    Returns
    -------
    numpy.ndarray
        (n, 3): ∂ln|H|²/∂(ln f_r, ln ζ, ln g), dimensionless.
    """
    r = np.abs(np.asarray(f_hz, dtype=float)) / f_r
    b = 1.0 - r * r
    a2 = (2.0 * zeta * r) ** 2
    g2a2 = peak_gain * peak_gain * a2
    N = b * b + g2a2
    D = b * b + a2
    br = 4.0 * b * r * r
    out = np.empty(r.shape + (3,))
    out[..., 0] = (br - 2.0 * g2a2) / N - (br - 2.0 * a2) / D
    out[..., 2] = 2.0 * g2a2 / N
    out[..., 1] = out[..., 2] - 2.0 * a2 / D
    return out
