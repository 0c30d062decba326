"""The resonance gain H(r): the one home of the single-mode amplification used across the kit.

A line at frequency f passing a simple resonance at f_r (Hz) with damping ratio ζ and peak gain g
is multiplied by::

    H(r) = (1 − r² + 2j·g·ζ·r) / (1 − r² + 2j·ζ·r),   r = f / f_r

so H(0) = 1, |H(1)| = g and H → 1 far above the mode (the line is amplified near f_r only).  For g > 1
it amplifies, for g < 1 it notches.

A fixture resonance need not return to 1 above f_r: the force a load cell reads through a fixture spring falls
as 2ζ/r above it (the transmissibility (1 + 2jζr)/(1 − r² + 2jζr)), one without the damper's path as 1/r².  The
general single-mode gain with H(0) = 1 (the static load passes whole) and H → β far above is::

    H(r) = (1 − β·r² + 2j·γ·ζ·r) / (1 − r² + 2j·ζ·r),   |H(1)| = g = sqrt((1 − β)² + (2γζ)²) / (2ζ)

(β = 1, γ = g: the form above; β = 0, γ = 1: the transmissibility; β = γ = 0: the bare single mode).  A model file
gives it by f_r, ζ, the peak gain g and ``gain_above`` β (default 1); γ follows from them (:func:`numerator_damping`).  Used by the test-stand simulator (:class:`rwadist.teststand.Mode`),
``rwadist diagnose`` (``fixed_resonance`` effects), the extended model and ``rwadist psd`` (wheel-mode
resonances of a model file).  The FMU runtime (``rwadist/fmu/runtime.py``) keeps its own inline copy on
purpose, so that it stays self-contained for simulation hosts; ``tests/test_resonance.py`` pins that
copy to this one numerically.
"""
from __future__ import annotations

import numpy as np


def numerator_damping(zeta: float, peak_gain: float, gain_above: float = 1.0) -> float:
    """γ of the general gain (module docstring) with |H(1)| = ``peak_gain`` and H → ``gain_above`` far above:
    sqrt((2ζg)² − (1 − β)²)/(2ζ), 0 when g is below |1 − β|/(2ζ) (no such gain has that peak); g itself when β = 1."""
    if gain_above == 1.0:
        return float(peak_gain)
    two_z = 2.0 * zeta
    return float(np.sqrt(max((two_z * peak_gain) ** 2 - (1.0 - gain_above) ** 2, 0.0)) / two_z)


def smallest_peak(zeta: float, gain_above: float) -> float:
    """The least |H(1)| a gain of damping ``zeta`` reaching ``gain_above`` far above can have: |1 − β|/(2ζ) (γ = 0)."""
    return abs(1.0 - gain_above) / (2.0 * zeta)


def peak_of(zeta: float, gamma: float, gain_above: float) -> float:
    """|H(1)| of the general gain (module docstring) of numerator damping ``gamma``: sqrt((1 − β)² + (2γζ)²)/(2ζ)."""
    return float(np.hypot(1.0 - gain_above, 2.0 * gamma * zeta) / (2.0 * zeta))


def resonance_response(r, zeta: float, peak_gain: float, gain_above: float = 1.0) -> np.ndarray:
    """H(r) at frequency ratio ``r`` (any shape, SIGNED: a negative r gives the complex conjugate).

    Parameters
    ----------
    r : array_like
        Frequency ratio f/f_r, dimensionless, any shape.
    zeta : float
        Damping ratio, dimensionless (> 0).
    peak_gain : float
        |H| at r = ±1, dimensionless.
    gain_above : float
        H far above the resonance (β of the module docstring), dimensionless; 1 (default): H → 1 on both sides.

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``r``.
    """
    r = np.asarray(r, dtype=float)
    base = 1.0 - r * r
    two_zr = 2.0 * zeta * r
    if gain_above == 1.0:
        return (base + 1j * peak_gain * two_zr) / (base + 1j * two_zr)
    gamma = numerator_damping(zeta, peak_gain, gain_above)
    return (1.0 - gain_above * r * r + 1j * gamma * two_zr) / (base + 1j * two_zr)


def resonance(f_hz, f_r: float, zeta: float, peak_gain: float, gain_above: float = 1.0) -> np.ndarray:
    """Complex gain H(r), r = |f|/f_r, of a simple resonance at ``f_r``, H(0) = 1 and H → ``gain_above`` far above.

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
    gain_above : float
        H far above f_r, dimensionless (default 1).

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``f_hz``.
    """
    return resonance_response(np.abs(np.asarray(f_hz, dtype=float)) / f_r, zeta, peak_gain, gain_above)


def resonance_gain(nu, resonances) -> np.ndarray:
    """Product of H over ``resonances`` at whirl rates ``nu`` taken SIGNED.

    For ν >= 0 each factor is :func:`resonance` at ν/2π; for ν < 0 its complex conjugate, so a load's
    Re/Im pair sees the same real filter.

    Parameters
    ----------
    nu : array_like
        Whirl rates, rad/s, any shape, signed.
    resonances : iterable of (float, float, float[, float])
        (f_r Hz, ζ, peak gain[, gain above]) of each resonance; empty gives ones.

    Returns
    -------
    numpy.ndarray
        Complex gain, dimensionless, the shape of ``nu``.
    """
    nu = np.asarray(nu, dtype=float)
    out = np.ones(nu.shape, dtype=complex)
    for f_r, zeta, g, *above in resonances:
        out = out * resonance_response(nu / (2.0 * np.pi * f_r), zeta, g, *above)
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


def general_log_power_gain(f_hz, f_r: float, zeta: float, gamma: float, gain_above: float):
    """(ln|H|², its derivatives) of the general gain (module docstring) in its least-squares parameters.

    With B = 1 − βr², b = 1 − r², A = 2ζr, r = |f|/f_r: ln|H|² = ln(B² + γ²A²) − ln(b² + A²) =: ln N − ln D, and::

        ∂/∂ln f_r = (4Bβr² − 2γ²A²)/N − (4br² − 2A²)/D
        ∂/∂ln ζ   = 2γ²A²/N − 2A²/D
        ∂/∂γ      = 2γA²/N
        ∂/∂β      = −2Br²/N

    (β = 1, γ = g: γ·∂/∂γ is :func:`log_power_gain_jacobian`'s ∂/∂ln g).

    Parameters
    ----------
    f_hz : array_like
        Line frequencies, Hz, shape (n,) (the sign is ignored).
    f_r : float
        Resonance frequency, Hz (> 0).
    zeta : float
        Damping ratio, dimensionless (> 0).
    gamma : float
        Numerator damping γ, dimensionless (>= 0).
    gain_above : float
        β, H far above f_r, dimensionless.

    Returns
    -------
    tuple of numpy.ndarray
        ln|H|² (n,) and its derivatives (n, 4) with respect to (ln f_r, ln ζ, γ, β).
    """
    r = np.abs(np.asarray(f_hz, dtype=float)) / f_r
    r2 = r * r
    B = 1.0 - gain_above * r2
    b = 1.0 - r2
    A2 = (2.0 * zeta * r) ** 2
    gA2 = gamma * gamma * A2
    N = np.maximum(B * B + gA2, 1e-300)
    D = b * b + A2
    out = np.empty(r.shape + (4,))
    out[..., 0] = (4.0 * B * gain_above * r2 - 2.0 * gA2) / N - (4.0 * b * r2 - 2.0 * A2) / D
    out[..., 1] = 2.0 * gA2 / N - 2.0 * A2 / D
    out[..., 2] = 2.0 * gamma * A2 / N
    out[..., 3] = -2.0 * B * r2 / N
    return np.log(N) - np.log(D), out


#: The greatest gain far above a mode of the path between the wheel's load and the load cell (a housing, a mode of
#: the wheel's structure on one direction).  The cell reads the load F less the momentum of the structure's moving
#: mass (Newton on the structure): a mode q of modal mass m_q and stiffness k_q, driven by φ_P·F (φ_P its shape at the
#: load's point) and of participation L = ∫ρφ dV, gives R = F − L·q̈ = F·(1 + μr²/(1 − r² + 2jζr)),
#: μ = φ_P·L/m_q, r = f/f_r: the general gain with β = 1 − μ, γ = 1 (the damper also reacts on the cell).  For a
#: mode that moves the load's point with its mass (φ_P·L >= 0, a fundamental mode), μ >= 0 and β <= 1: the lines
#: above it keep 1 − μ of the load, with an antiresonance at f_r/sqrt(β) above the resonance (β = 0: the whole load
#: drives it, the transmissibility of a suspension).
PATH_MODE_MAX_ABOVE = 1.0


class FittedResonance:
    """A fixture resonance's parameters in a least squares of log line amplitudes (the extended fit's, fitted with the
    wheel's modes: :func:`rwadist.extended_fit.fit_extended` with ``fit_stand``).

    Parameters θ = (ln f_r, ln ζ, γ, β) of the general single-mode gain H(r) = (1 − βr² + 2jγζr)/(1 − r² + 2jζr)
    (:mod:`rwadist.resonance`), the same on every channel; each least-squares row (a line at f Hz) divides it out:
    r = ln(measured) − ln|H(f)| − ln(model), so the modes' standard errors are those with the stand free.
    ``start``: (f_r Hz, ζ, peak gain[, gain above]); ``f_rows``: each row's line frequency, Hz.  Bounds: f_r within
    ±10 % of the start, ζ in [0.001, 0.3], γ in [0, 200], β in [−1, 3].

    ``rows`` (bool per row, or None: every row): the rows the resonance acts on (a resonance of one load direction's
    channels: a mode of the wheel's structure; 1 elsewhere).  ``gain_above`` (None: fitted): β held at this value, θ
    then (ln f_r, ln ζ, γ).  ``max_above``: the upper bound of a fitted β (:data:`PATH_MODE_MAX_ABOVE` for a mode of
    the path the load passes: β = 1 − μ, μ >= 0)."""

    NAMES: tuple[str, ...] = ("stand_ln_f", "stand_ln_zeta", "stand_gamma", "stand_gain_above")

    def __init__(self, start, f_rows, rows=None, gain_above: float | None = None, max_above: float = 3.0):
        f_r, zeta, gain, *above = (float(v) for v in start)
        beta = gain_above if gain_above is not None else (above[0] if above else 1.0)
        self.fixed_above = gain_above
        self.f_rows = np.asarray(f_rows, dtype=float)
        self.rows = None if rows is None else np.asarray(rows, dtype=bool)
        n = 4 if gain_above is None else 3
        self.NAMES = FittedResonance.NAMES[:n]
        self.x0 = np.array([np.log(f_r), np.log(np.clip(zeta, 0.0011, 0.29)),
                            min(numerator_damping(zeta, gain, beta), 199.0),
                            np.clip(beta, -0.99, max_above - 0.01)])[:n]
        self.lower = np.array([np.log(0.9 * f_r), np.log(1e-3), 0.0, -1.0])[:n]
        self.upper = np.array([np.log(1.1 * f_r), np.log(0.3), 200.0, max_above])[:n]
        self.start_log_gain = self._masked(np.log(np.abs(resonance(self.f_rows, f_r, zeta, gain, beta)) ** 2))

    def _masked(self, v):
        """``v`` (rows, ...) with the rows the resonance does not act on zeroed."""
        return v if self.rows is None else np.where(self.rows.reshape((-1,) + (1,) * (np.ndim(v) - 1)), v, 0.0)

    def _theta4(self, theta) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        return theta if self.fixed_above is None else np.append(theta, self.fixed_above)

    def log_gain(self, theta):
        """(ln|H|² at every row (rows,), its derivatives (rows, len(θ)) in θ)."""
        t = self._theta4(theta)
        lg, d = general_log_power_gain(self.f_rows, float(np.exp(t[0])), float(np.exp(t[1])), float(t[2]),
                                       float(t[3]))
        return self._masked(lg), self._masked(d[:, :len(self.NAMES)])

    def stand(self, theta) -> tuple:
        """(f_r Hz, ζ, peak gain, gain above) of θ."""
        t = self._theta4(theta)
        zeta = float(np.exp(t[1]))
        return (float(np.exp(t[0])), zeta, peak_of(zeta, float(t[2]), float(t[3])), float(t[3]))

    def more(self, theta, held=()) -> tuple:
        """The further stands of the fit: ``held`` (one resonance fitted, the others held)."""
        return tuple(held)
