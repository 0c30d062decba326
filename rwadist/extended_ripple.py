"""The extended model's periodic wheel-speed ripple (a diagnosed speed modulation): its Bessel-type
sideband coefficients and its lines through the rotor's modes.  Part of the extended model
(:mod:`rwadist.extended`, which re-exports these names); physics and conventions there."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import schema
from .effects.actions import SpeedModulation, of_effects
from .extended import ExtendedParams, Line, _add_to_channels, _omega_array, transmissibility


@dataclass(frozen=True)
class Ripple:
    """A periodic wheel-speed ripple (a diagnosed speed modulation, :class:`rwadist.effects.actions.SpeedModulation`):
    Ω(t) = Ω0 + ΔΩ·sin(2π f_r t) with
    ΔΩ(Ω0) = delta_omega·(|Ω0|/omega_ref)^exponent.

    f_hz : ripple frequency f_r, Hz (> 0).  delta_omega : ΔΩ at omega_ref, rad/s (>= 0).  omega_ref : rad/s
    (> 0).  exponent : speed exponent q (>= 0; 0 = the same ΔΩ at every speed, e.g. a torque ripple at a
    fixed frequency; 1 = a fixed fraction of the speed)."""

    f_hz: float
    delta_omega: float
    omega_ref: float = 1.0
    exponent: float = 0.0

    def __post_init__(self):
        for name, ok, need in (("f_hz", lambda v: v > 0, "> 0"), ("delta_omega", lambda v: v >= 0, ">= 0"),
                               ("omega_ref", lambda v: v > 0, "> 0"), ("exponent", lambda v: v >= 0, ">= 0")):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
                    or not math.isfinite(v) or not ok(v):
                raise ValueError(f"Ripple.{name} must be a finite number {need}, got {v!r}")

    def delta(self, omega):
        """ΔΩ (rad/s) at mean speeds ``omega`` (rad/s)."""
        return self.delta_omega * (np.abs(np.asarray(omega, dtype=float)) / self.omega_ref) ** self.exponent


def ripple_from_effects(effects, source: str = "<model>"):
    """The :class:`Ripple` of a model file's ``effects`` list: the speed modulation its elements say the wheel has
    (:class:`rwadist.effects.actions.SpeedModulation`, at most one per wheel), or None.  Read by the schema
    (:func:`rwadist.schema.parse_effects`): :class:`rwadist.schema.ModelError` (a ValueError) naming
    ``effects[i].<field>`` on a bad entry, and on a second one."""
    for a in of_effects(schema.parse_effects(effects, source)):
        if isinstance(a, SpeedModulation):
            return Ripple(a.f_hz, a.delta_omega, a.omega_ref, a.exponent)
    return None


def ripple_k_max(beta_max: float, p_max: float = 2.0) -> int:
    """Highest sideband order K kept for a ripple of largest phase-modulation index ``beta_max`` (rad) and
    largest amplitude exponent ``p_max``: ceil(1.1β + 4β^(1/3) + p + 4) (the Bessel tail J_k(β) beyond
    ≈ β + 4β^(1/3) is below 1e-8 of the carrier; (1 + ε sin θ)^p adds up to p orders)."""
    b = abs(float(beta_max))
    return int(np.ceil(1.1 * b + 4.0 * b ** (1.0 / 3.0) + abs(float(p_max)) + 4))


def _ripple_grid(k_max: int):
    n = 1 << int(np.ceil(np.log2(4 * (2 * k_max + 1))))
    return n, 2 * np.pi * np.arange(n) / n


def ripple_coefficients(beta, eps, p=2.0, k_max: int | None = None, tau=0.0):
    """Complex Fourier coefficients c_k of g(θ) = (|1 + ε sin θ|^p − jτ cos θ) · exp(−jβ cos θ) = Σ_k c_k e^{jkθ}.

    With Ω(t) = Ω0 + ΔΩ sin θ, θ = 2π f_r t, the rotor angle is φ = Ω0 t − (ΔΩ/2πf_r) cos θ, so a co-rotating
    (or axial) line of harmonic h and amplitude a(Ω) ∝ |Ω|^p becomes a(Ω0)·g(θ)·e^{jhΩ0 t} with β = h·ΔΩ/(2πf_r)
    and ε = ΔΩ/Ω0 -- SIGNED: for Ω0 < 0, |Ω(t)| = |Ω0|(1 − (ΔΩ/|Ω0|) sin θ).  A counter-rotating component
    e^{−jhφ} has β → −β.  Pure phase modulation (ε = 0): c_k = (−j)^k J_k(β); Σ_k |c_k|² is the mean of
    |1 + ε sin θ|^{2p} (Parseval).  The modulus |·| makes it exact through a speed reversal (|ε| > 1).
    By an FFT over one ripple period.

    τ: an imbalance's tangential force.  The mass m at radius e on the rotor angle φ loads the rotor with
    −m·d²(e·e^{jφ})/dt² = m·e·(φ̇² − jφ̈)·e^{jφ}: beside m·e·Ω(t)² (the amplitude term, p = 2) it pushes m·e·Ω̇
    along the rim, Ω̇ = 2πf_r·ΔΩ·cos θ, i.e. −jτ cos θ relative to m·e·Ω0² with τ = ΔΩ·2πf_r/Ω0² (signed as β for
    a counter-rotating component).  With ε = 0 the coefficients are c_k = (−j)^k (J_k(β) + τ·J_k'(β)); to first
    order the sidebands are (pε/2 ± (β + τ)/2) above and below.  Default 0: lines that are no imbalance.

    beta, eps, tau : broadcastable arrays (shape S); p : scalar or broadcastable.  k_max : highest order
    (default :func:`ripple_k_max` of the largest |β| and p).  Returns (k (2K+1,), c (S + (2K+1,)) complex)."""
    beta, eps, p, tau = np.broadcast_arrays(np.asarray(beta, float), np.asarray(eps, float), np.asarray(p, float),
                                            np.asarray(tau, float))
    if k_max is None:
        k_max = ripple_k_max(float(np.max(np.abs(beta))) if beta.size else 0.0,
                             float(np.max(np.abs(p))) if p.size else 2.0)
    n, th = _ripple_grid(k_max)
    g = np.abs(1.0 + eps[..., None] * np.sin(th)) ** p[..., None] * np.exp(-1j * beta[..., None] * np.cos(th))
    if np.any(tau):
        g = g - 1j * tau[..., None] * np.cos(th) * np.exp(-1j * beta[..., None] * np.cos(th))
    c = np.fft.fft(g, axis=-1) / n
    k = np.arange(-k_max, k_max + 1)
    return k, c[..., k % n]


def _line_exponent(ln: Line) -> float:
    return 2.0 if ln.law is None else float(ln.law[2])


def ripple_order(lines, omega, ripple: Ripple, tol: float = 1e-6) -> int:
    """Sideband order K needed for ``lines`` under ``ripple`` at mean speeds ``omega`` (rad/s): at most
    :func:`ripple_k_max` of the largest β = h·ΔΩ/(2πf_r) and exponent, trimmed to the highest order whose
    coefficient reaches ``tol`` × the line's RMS coefficient sqrt(Σ|c_k|²) for some line and speed (the
    orders dropped carry < tol² of a line's power each).  For an amplitude law with a non-integer exponent
    the amplitude term |1 + ε sin θ|^p has every order, decaying as ρ^k, ρ = (1 − √(1 − ε²))/|ε|; the
    p + 4 orders the bound allows for it lose < 1e-8 of the power for |ε| <= 0.5 (mean speed at least twice
    the ripple amplitude), more as |ε| -> 1."""
    w = np.atleast_1d(_omega_array(omega))
    lines = list(lines)
    if not lines or w.size == 0:
        return 0
    dW = ripple.delta(w)
    # the coefficients depend on a line only through its h and exponent: each distinct pair once
    hp = np.unique(np.array([(ln.h, _line_exponent(ln)) for ln in lines], dtype=float), axis=0)
    hs, ps = hp[:, 0], hp[:, 1]
    k_max = ripple_k_max(float(hs.max() * dW.max() / (2 * np.pi * ripple.f_hz)), float(ps.max()))
    eps = dW / np.where(w == 0.0, 1.0, w)
    eps = np.where(w == 0.0, np.where(dW > 0, 1e6, 0.0), eps)
    k, c = ripple_coefficients(hs[:, None] * dW[None, :] / (2 * np.pi * ripple.f_hz), eps[None, :], ps[:, None],
                               k_max)
    a = np.abs(c)
    rel = a / np.maximum(np.sqrt(np.sum(a**2, axis=-1, keepdims=True)), 1e-300)
    big = np.nonzero(np.max(rel.reshape(-1, k.size), axis=0) >= tol)[0]
    return int(np.max(np.abs(k[big]))) if big.size else 0


def ripple_lines(p: ExtendedParams, lines, omega, ripple: Ripple, k_max: int | None = None,
                 rigid: bool = False) -> tuple:
    """Steady-state lines under a periodic speed ripple (mean speeds ``omega`` rad/s, signed), closed form.

    Each component σ (whirl sense, ±1) of each line, load = coef·a(Ω(t))·e^{jσ(hφ + 2π f_offset t)}, is
    expanded over the ripple period: a(Ω0 + ΔΩ sin θ)·exp(−jσβ cos θ) = Σ_k d_k e^{jkθ}, β = h·ΔΩ/(2πf_r),
    d_k by an FFT of the line's own amplitude law (:meth:`Line.amplitude`: C·Ω² or the diagnosed law; this is
    a(Ω0)·:func:`ripple_coefficients` with ε = ΔΩ/Ω0 and stays finite at Ω0 = 0).  Term k whirls at
    ν = σ(hΩ0 + 2πf_offset) + 2πk f_r = σ(hΩ0 + 2π(f_offset + m f_r)), m = σk: it is the line's sideband of
    order m (for a planar line the two senses of one m land at the same frequency and are coherent), passed
    through the rotor's modes and the line's wheel-mode resonances AT ITS OWN whirl rate ν, exactly as
    :func:`steady_lines` does for a line with f_offset + m·f_r.

    Phase convention: θ = 0 and the rotor's mean angle Ω0·t is 0 at t0 (the rippled angle there is
    φ(t0) = −ΔΩ/(2πf_r)).  Neglected (first order in small quantities, stated): the imbalance's tangential
    force −jC·Ω̇ (relative size ΔΩ·2πf_r/Ω0²), the modulation of the rocking mode's gyroscopic stiffness by
    the ripple (the modes are evaluated at Ω0), and the wheel-mode resonance gains' variation with the
    instantaneous speed.  With ΔΩ = 0 the order-0 lines are :func:`steady_lines` (test).  Measured against the
    FMU's time-domain ripple (tests/test_fmu_effects.py): force channels within 1e-5 of the largest line;
    the rocking channels Tx, Ty off by up to ~10 % of their largest line at sidebands near a rocking whirl
    (the gyroscopic modulation is not small there).

    k_max : highest order (default :func:`ripple_order`).  rigid : a rigid suspension (hard-mounted wheel,
    as :func:`steady_lines`): no transmissibility.  Returns (m (M,), f_hz (S, L, M),
    amplitude (S, L, M, 6) complex): channel = Re(A e^{i2πf(t − t0)}), N or N·m."""
    w = np.atleast_1d(_omega_array(omega))
    lines = list(lines)
    K = ripple_order(lines, w, ripple) if k_max is None else int(k_max)
    m = np.arange(-K, K + 1)
    n, th = _ripple_grid(K)
    dW = ripple.delta(w)
    sin_t, cos_t = np.sin(th), np.cos(th)
    S, L, M = w.size, len(lines), m.size
    amp = np.zeros((S, L, M, 6), dtype=complex)
    f_hz = np.zeros((S, L, M))
    w2 = w[:, None]
    for j, ln in enumerate(lines):
        off = ln.f_offset + m[None, :] * ripple.f_hz                         # (1, M) Hz
        f_hz[:, j] = np.abs(ln.h * w2 / (2 * np.pi) + off)
        a_th = ln.amplitude(w2 + dW[:, None] * sin_t[None, :])              # (S, n)
        beta = ln.h * dW / (2 * np.pi * ripple.f_hz)
        for sigma, coef in ln.components():
            d = np.fft.fft(a_th * np.exp(-1j * sigma * beta[:, None] * cos_t[None, :]), axis=-1) / n
            dk = d[:, (sigma * m) % n]                                          # (S, M): order m = σk
            nu = sigma * (ln.h * w2 + 2 * np.pi * off)
            resp = coef * dk if rigid else transmissibility(p, ln.direction, nu, w2) * coef * dk
            if ln.resonances:
                resp = resp * ln.gain(nu)
            _add_to_channels(amp[:, j], ln.direction, p.height, resp, nu)
    return m, f_hz, amp
