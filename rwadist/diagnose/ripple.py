"""A periodic speed ripple's lines in the diagnosis: their power fractions and which of them the engine sends through
the modes at their own frequency (:meth:`rwadist.diagnose.engine.Context.ripple_powers`, :meth:`Context._ripple_gains`,
:meth:`rwadist.diagnose.metric.Metric.beat_variance`)."""
from __future__ import annotations

import numpy as np

#: Directions whose line h = 1 is an imbalance (its tangential force rides on a speed ripple's Ω̇).
RIPPLE_IMBALANCE_DIRECTIONS = ("radial_force", "radial_torque")
#: Orders of a speed ripple's lines predicted through the modes and resonances at their own frequency
#: (:meth:`Context._ripple_gains`).
RIPPLE_OWN_GAIN_ORDERS = 2


def ripple_sideband_powers(beta, eps, p=2.0, k_max: int | None = None, tau=0.0):
    """Power fractions of the lines a periodic speed ripple makes of one harmonic line.

    With Ω(t) = Ω0 + ΔΩ·sin θ, θ = 2π f_r t, the rotation angle is ψ = Ω0 t − (ΔΩ/2πf_r)·cos θ, so the line
    h of amplitude a(Ω) ∝ |Ω|^p becomes a·g(θ)·e^{j2πf_i t} with
    g(θ) = (1 + ε sin θ)^p · exp(−jβ cos θ),  β = h·ΔΩ/(2π f_r) (phase-modulation index, rad),
    ε = ΔΩ/|Ω0|, and g = Σ_k c_k e^{jkθ}: lines at f_i + k·f_r of amplitude |c_k|·a.  Without the amplitude
    term (ε = 0) c_k = J_k(β)e^{-jkπ/2}, |c_k|² = J_k(β)² and Σ_k |c_k|² = 1 (Parseval); with it Σ|c_k|² is the
    mean of (1 + ε sin θ)^{2p} (1 + 3ε² + 3ε⁴/8 for p = 2).  c_k by an FFT over one period of θ: the complex
    coefficients are :func:`rwadist.extended_ripple.ripple_coefficients` (which the coupling kit applies per line);
    this returns their squared moduli.  (For ε > 1, a speed reversal within the ripple, the amplitude is
    |1 + ε sin θ|^p, the exact |Ω(t)|^p.)

    beta, eps : broadcastable arrays (shape S); p : amplitude exponent (scalar or broadcastable); tau : an
    imbalance's tangential term (:func:`rwadist.extended_ripple.ripple_coefficients`), 0 for other lines.
    Returns (k (2K+1,), P (S + (2K+1,))), P = |c_k|².
    """
    from ..extended_ripple import ripple_coefficients

    k, c = ripple_coefficients(beta, eps, p, k_max, tau=tau)
    return k, np.abs(c) ** 2
