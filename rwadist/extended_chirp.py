"""The suspension's response to a line that sweeps through it: a linear chirp through a second-order transmissibility,
closed form.

A line whose whirl rate moves, ν(t) = ν + ν̇·t (a run-up or run-down: ν̇ = σ·h·dΩ/dt), loads a subsystem of
:mod:`rwadist.extended` (inertia m, damping c, stiffness k, gyroscopic term g·Ω for rocking) with the complex-coordinate
load u(t) = e^{iθ(t)}, θ̇ = ν(t).  The interface load is y = T * u with T(s) = (k + c·s)/(m·s² + (c − i·g·Ω)·s + k),
whose poles p₁, p₂ give T(s) = Σ r_j/(s − p_j), r_j = (k + c·p_j)/(m·(p_j − p_other)).  Then, exactly for a linear
chirp and the poles held at the instant's speed,

    y(t) = u(t)·Σ_j r_j·G_j(t),   G_j(t) = ∫₀^∞ e^{(p_j − iν(t))·s + i(ν̇/2)·s²} ds
                                        = (√π / 2√γ)·w(i·β/2√γ),   β = iν(t) − p_j,   γ = −iν̇/2,

w the Faddeeva function (``scipy.special.wofz``; √γ the principal root, Re > 0).  With ν̇ = 0 it is 1/β, so
Σ_j r_j·G_j is the steady transmissibility T(iν) (:func:`rwadist.extended.transmissibility`).  Where the line crosses
a mode too fast for it (η = ḟ/(2π(ζf)²) of order 1, ḟ = ν̇/2π Hz/s, ζf the mode's half-power half-width, Hz) the
response lags, its peak falls, and once the line has passed, w's term 2·e^{−z²} (Im z < 0) is the mode ringing on at
its own frequency, decaying as e^{−ζω·t} (Lollock, AIAA 2002-1230).  tests/test_extended_chirp.py checks it against
``scipy.signal.lsim`` of the mode driven by the chirp.

Neglected: the speed's change of the gyroscopic term over the mode's decay time (the poles are the instant's), and a
profile's curvature (the chirp is linear over the mode's decay time).

Units: rad/s, rad/s², SI (kg, N/m, N·s/m; kg·m², N·m/rad for rocking).
"""
from __future__ import annotations

import numpy as np
from scipy import special


def pole_chirp(pole, nu, nu_dot) -> np.ndarray:
    """G = ∫₀^∞ e^{(p − iν)s + i(ν̇/2)s²} ds (s), broadcast: the response of 1/(s − p) to a chirp of whirl rate ``nu``
    (rad/s, at the instant) moving at ``nu_dot`` (rad/s²), relative to the chirp's own phasor; 1/(iν − p) where
    ν̇ = 0.  ``pole`` (1/s, Re < 0)."""
    beta = 1j * np.asarray(nu, dtype=float) - np.asarray(pole, dtype=complex)
    nu_dot = np.asarray(nu_dot, dtype=float)
    moving = nu_dot != 0.0
    root = np.sqrt(-0.5j * np.where(moving, nu_dot, 1.0))          # √γ, Re > 0
    z = 1j * beta / (2.0 * root)
    g = np.sqrt(np.pi) / (2.0 * root) * special.wofz(z)
    return np.where(moving, g, 1.0 / beta)


def poles(m: float, c: float, k: float, g_omega) -> tuple:
    """(p₁, p₂, r₁, r₂): the poles (1/s) of m·s² + (c − i·gΩ)·s + k and the residues of (k + c·s)/(that) at them,
    ``g_omega`` the gyroscopic term g·Ω (kg·m²/s; 0 for translation), broadcast."""
    b = c - 1j * np.asarray(g_omega, dtype=complex)
    disc = np.sqrt(b * b - 4.0 * m * k)
    p1, p2 = (-b + disc) / (2.0 * m), (-b - disc) / (2.0 * m)
    diff = np.where(p1 == p2, 1e-300, p1 - p2)                      # a critically damped pair: no such wheel
    return p1, p2, (k + c * p1) / (m * diff), -(k + c * p2) / (m * diff)


def chirp_transmissibility(sub, nu, nu_dot, omega) -> np.ndarray:
    """Interface load per internal load, relative to the load's own phasor, for a complex-coordinate load whose whirl
    rate is ``nu`` (rad/s, signed) at the instant and moves at ``nu_dot`` (rad/s²), at wheel speed ``omega`` (rad/s):
    Σ_j r_j·G_j (module docstring); :func:`rwadist.extended.transmissibility` where ``nu_dot`` is 0.  ``sub`` the
    subsystem the load's direction loads, (inertia, damping, stiffness, gyro) in SI units, or None (no suspension:
    ones)."""
    shape = np.broadcast(nu, nu_dot, omega).shape
    if sub is None:
        return np.ones(shape, dtype=complex)
    m, c, k, gyro = sub
    p1, p2, r1, r2 = poles(m, c, k, gyro * np.asarray(omega, dtype=float))
    return np.broadcast_to(r1 * pole_chirp(p1, nu, nu_dot) + r2 * pole_chirp(p2, nu, nu_dot), shape)
