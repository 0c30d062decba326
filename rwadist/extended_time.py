"""Time-domain simulation of the extended model (rigid rotor on its suspension) for a speed
profile: exact modal integration of every line's forcing.  Part of the extended model
(:mod:`rwadist.extended`, which re-exports these names); physics and conventions there."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import signal

from .extended import DEFAULT_MAX_ACCEL, DIRECTIONS, ExtendedParams, _quad_roots, _subsystem
from .units import CHANNELS


def _check_profile(t, omega, max_accel):
    t = np.asarray(t, dtype=float)
    w = np.asarray(omega, dtype=float)
    if t.ndim != 1 or t.shape != w.shape or t.size < 2:
        raise ValueError(f"t and omega must be 1-D of equal length >= 2, got {t.shape} and {w.shape}")
    bad = ~np.isfinite(w)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"speed profile omega is not finite at sample {i} (t = {t[i]!r} s): {w[i]!r}")
    if not np.all(np.isfinite(t)):
        raise ValueError("time vector t contains NaN or inf")
    dt = np.diff(t)
    T = (t[-1] - t[0]) / (t.size - 1)
    if T <= 0 or np.max(np.abs(dt - T)) > 1e-6 * T:
        raise ValueError("time vector t must be uniformly sampled and increasing")
    acc = np.abs(np.diff(w)) / T
    if acc.max() > max_accel:
        i = int(np.argmax(acc))
        raise ValueError(f"speed profile jumps between samples {i} and {i + 1} (t = {t[i]:.6g} s): "
                         f"omega {w[i]:.6g} -> {w[i + 1]:.6g} rad/s, |dΩ/dt| = {acc[i]:.3g} rad/s² "
                         f"> max_accel = {max_accel:.3g}")
    return t, w, T


def _small_z_terms(z):
    """Series of ∫0^1 e^{zu} du and ∫0^1 u e^{zu} du for |z| < 1e-3 (error < 1e-13)."""
    e0 = 1 + z * (1 / 2 + z * (1 / 6 + z * (1 / 24 + z / 120)))
    e1 = 1 / 2 + z * (1 / 3 + z * (1 / 8 + z * (1 / 30 + z / 144)))
    return e0, e1


def _forcing_terms(lam, lines_comp, phi_tau, T):
    """Input integral over each sample interval for one mode with eigenvalue ``lam`` (scalar, or one
    per interval) of the loads ``lines_comp`` = [(σh, ω_off, coef, amplitude (n+1))]; ``phi_tau`` =
    (rotor angle φ, time since t0) at the samples.

    For a load coef·(a_n + Δa·τ/T)·e^{i(σh(φ_n + Δφ_n τ/T) + ω_off(t_n + τ))} the integral
    ∫0^T e^{λ(T−τ)} load dτ = T·coef·(a_n·X S0 E0(z) + Δa·X S0 E1(z)), z = i(σhΔφ_n + ω_off T) − λT,
    X = e^{λT}, S0 = e^{i(σhφ_n + ω_off t_n)}, E0 = (e^z − 1)/z, E1 = (e^z − E0)/z.  Since X S0 e^z = S1:
    X S0 E0 = (S1 − X S0)/z and X S0 E1 = (S1 − X S0 E0)/z; a series replaces them where |z| < 1e-3.
    """
    phi, tau = phi_tau
    n = phi.size - 1
    lams = lam if isinstance(lam, tuple) else (lam,)
    accs = [np.zeros(n, dtype=complex) for _ in lams]
    Xs = [np.exp(lm * T) for lm in lams]
    dphi = np.diff(phi)
    for sh, woff, coef, a in lines_comp:
        if woff == 0.0:
            S = np.exp(1j * sh * phi)
            iw = 1j * sh * dphi
        else:
            S = np.exp(1j * (sh * phi + woff * tau))
            iw = 1j * (sh * dphi + woff * T)
        S0, S1 = S[:-1], S[1:]
        a0 = a[:-1]
        da = a[1:] - a0
        for lm, X, acc in zip(lams, Xs, accs):
            z = iw - lm * T
            XS0 = X * S0
            small = np.abs(z) < 1e-3
            if small.any():
                zb = np.where(small, 1.0, z)
            else:
                zb = z
            t0 = (S1 - XS0) / zb
            t1 = (S1 - t0) / zb
            if small.any():
                e0, e1 = _small_z_terms(z[small])
                t0[small] = XS0[small] * e0
                t1[small] = XS0[small] * e1
            acc += (T * coef) * (a0 * t0 + da * t1)
    return accs if isinstance(lam, tuple) else accs[0]


def _modal_lti(m, c, k, comps, phi_tau, T, x0):
    """Constant-coefficient subsystem m q̈ + c q̇ + k q = load, exact per interval; lfilter on modes.

    Returns (q, qdot) at every sample (n+1)."""
    l1, l2 = _quad_roots(m, c, k)
    l1, l2 = complex(l1), complex(l2)
    phi = phi_tau[0]
    q = np.zeros(phi.size, dtype=complex)
    qd = np.zeros(phi.size, dtype=complex)
    # modal coordinates: q = η1 + η2, q̇ = λ1 η1 + λ2 η2; η̇_j = λ_j η_j + load/(m(λ_j − λ_k))
    q0, qd0 = x0
    eta0 = ((qd0 - l2 * q0) / (l1 - l2), (l1 * q0 - qd0) / (l1 - l2))
    ws = _forcing_terms((l1, l2), comps, phi_tau, T)
    for lam, other, e0, w in ((l1, l2, eta0[0], ws[0]), (l2, l1, eta0[1], ws[1])):
        w = w / (m * (lam - other))
        pole = np.exp(lam * T)
        eta = np.empty(phi.size, dtype=complex)
        eta[0] = e0
        eta[1:], _ = signal.lfilter([1.0], [1.0, -pole], w, zi=[pole * e0])
        q += eta
        qd += lam * eta
    return q, qd


def _affine_scan(P, g, x0, block=256):
    """x_{n+1} = P_n x_n + g_n for 2×2 complex P (n,2,2), g (n,2); returns x (n+1, 2).

    Blocked Hillis–Steele scan: log2(block) vectorised passes, then a loop over blocks."""
    n = g.shape[0]
    nb = -(-n // block)
    pad = nb * block - n
    if pad:
        P = np.concatenate([P, np.broadcast_to(np.eye(2, dtype=complex), (pad, 2, 2))])
        g = np.concatenate([g, np.zeros((pad, 2), dtype=complex)])
    a, b = P[:, 0, 0].reshape(nb, block).copy(), P[:, 0, 1].reshape(nb, block).copy()
    c, d = P[:, 1, 0].reshape(nb, block).copy(), P[:, 1, 1].reshape(nb, block).copy()
    u, v = g[:, 0].reshape(nb, block).copy(), g[:, 1].reshape(nb, block).copy()
    s = 1
    while s < block:
        # (P_i, g_i) <- (P_i P_{i-s}, P_i g_{i-s} + g_i) for i >= s
        A, B, C, D, U, V = (x[:, :-s] for x in (a, b, c, d, u, v))
        a2, b2, c2, d2, u2, v2 = (x[:, s:] for x in (a, b, c, d, u, v))
        na, nb_, nc, nd = a2 * A + b2 * C, a2 * B + b2 * D, c2 * A + d2 * C, c2 * B + d2 * D
        nu, nv = a2 * U + b2 * V + u2, c2 * U + d2 * V + v2
        a[:, s:], b[:, s:], c[:, s:], d[:, s:], u[:, s:], v[:, s:] = na, nb_, nc, nd, nu, nv
        s *= 2
    x = np.empty((nb * block + 1, 2), dtype=complex)
    x[0] = x0
    cur = np.asarray(x0, dtype=complex)
    for i in range(nb):
        sl = slice(i * block + 1, (i + 1) * block + 1)
        x[sl, 0] = a[i] * cur[0] + b[i] * cur[1] + u[i]
        x[sl, 1] = c[i] * cur[0] + d[i] * cur[1] + v[i]
        cur = x[(i + 1) * block]
    return x[: n + 1]


def _rocking_ltv(p, comps, phi_tau, omega_mid, T, x0):
    """Rocking with speed-dependent gyroscopic term: exact transition per interval at the
    interval's mean speed, exact exponential-times-linear forcing, affine scan."""
    l1, l2 = _quad_roots(p.I_rr, p.c_rock - 1j * p.I_zz * omega_mid, p.k_rock)
    e1, e2 = np.exp(l1 * T), np.exp(l2 * T)
    dl = l1 - l2
    # A = [[0, 1], [−k/I, λ1+λ2]];  P_j = (A − λ_k I)/(λ_j − λ_k); Φ = e1 P_1 + e2 P_2
    k_over_i = p.k_rock / p.I_rr
    P = np.empty((phi_tau[0].size - 1, 2, 2), dtype=complex)
    P[:, 0, 0] = (e1 * (-l2) - e2 * (-l1)) / dl
    P[:, 0, 1] = (e1 - e2) / dl
    P[:, 1, 0] = (-k_over_i) * (e1 - e2) / dl
    P[:, 1, 1] = (e1 * l1 - e2 * l2) / dl
    # P_j B = [1, λ_j]/(I (λ_j − λ_k))
    w1, w2 = _forcing_terms((l1, l2), comps, phi_tau, T)
    w1 = w1 / (p.I_rr * dl)
    w2 = w2 / (-p.I_rr * dl)
    g = np.stack([w1 + w2, l1 * w1 + l2 * w2], axis=1)
    x = _affine_scan(P, g, x0)
    return x[:, 0], x[:, 1]


def _steady_state_init(p, direction, comps_c, omega0):
    """(q, q̇) at t0 of the steady solution at constant speed omega0 for complex loads."""
    sub = _subsystem(p, direction)
    m, c, k, gyro = sub
    q = qd = 0j
    for sh, woff, coef, amp0 in comps_c:
        nu = sh * omega0 + woff
        G = 1.0 / (k - m * nu**2 + gyro * omega0 * nu + 1j * c * nu)
        q += G * coef * amp0
        qd += 1j * nu * G * coef * amp0
    return q, qd


def simulate_time(p: ExtendedParams, lines, t, omega, *, seed=None, phases=None, start="rest",
                  max_accel: float = DEFAULT_MAX_ACCEL) -> np.ndarray:
    """Interface forces and torques (n_t, 6: Fx, Fy, Fz, Tx, Ty, Tz; N, N·m) for a speed profile.

    t : uniform sample times, s.  omega : wheel speed at each sample, rad/s (signed; may pass
    through zero).  Rotor angle φ = cumulative trapezoid of Ω from t[0] (φ(t0) = 0); line phases
    h·φ (+ 2π f_offset (t − t0) for a sideband line); imbalance lines add the tangential −iΩ̇ term
    (Ω̇ by central differences).  A line's wheel-mode resonances multiply each component's amplitude
    by H at the sample's whirl rate (quasi-static: exact at constant speed, no ringing in transients).
    seed : draw every line's phase uniformly (overrides ``phases``; sideband lines get their own
    draws: the same spectrum as the amplitude modulation, whose exact phase relation to the
    carrier holds with the lines' own phases); phases : one per line, rad
    (default: each Line's own phase).  start : 'rest' (all states zero) or 'steady' (the closed-form
    steady state at Ω(t0)).  max_accel : |dΩ/dt| above which a step counts as a jump, rad/s².

    Method: the modes are linear; over each sample interval the load of a line is exactly
    (amplitude linear in time) × e^{i(σhΔφ + ω_off T) τ/T}, and its integral against the mode's exponentials is
    taken in closed form; translation and axial modes (fixed coefficients) run as two complex
    first-order recursions each through scipy.signal.lfilter; the rocking mode's transition matrix
    is the exact exponential at the interval's mean speed and the time-varying recursion runs as a
    blocked associative scan.  At constant speed the result is exact (steady state = closed form to
    rounding); with changing speed the per-interval errors are O(a·|dΩ/dt|·T²) (frozen speed) and
    O(T³) in amplitude.
    """
    t, w, T = _check_profile(t, omega, max_accel)
    if start not in ("rest", "steady"):
        raise ValueError(f"start must be 'rest' or 'steady', got {start!r}")
    lines = list(lines)
    if seed is not None:
        ph = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(lines))
    elif phases is not None:
        ph = np.asarray(phases, dtype=float)
        if ph.shape != (len(lines),):
            raise ValueError(f"phases must have one value per line ({len(lines)}), got shape {ph.shape}")
    else:
        ph = np.array([ln.phase for ln in lines])
    lines = [replace(ln, phase=float(q)) for ln, q in zip(lines, ph)]

    phi = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * T)])
    tau = t - t[0]
    wdot = np.gradient(w, T)
    out = np.zeros((t.size, 6))
    # per direction: (σh, frequency offset rad/s, coefficient, amplitude per sample) of each component
    groups: dict[str, list[tuple]] = {d: [] for d in DIRECTIONS}
    for ln in lines:
        amp = ln.amplitude(w) - 1j * ln.C * wdot if ln.imbalance else ln.amplitude(w)
        for sigma, coef in ln.components():
            # quasi-static wheel-mode resonance: the gain at each sample's whirl rate
            a = amp * ln.gain(ln.nu(sigma, w)) if ln.resonances else amp
            groups[ln.direction].append((sigma * ln.h, sigma * 2.0 * np.pi * ln.f_offset, coef, a))

    # Tz: axial torque lines pass straight through
    for sh, woff, coef, amp in groups["axial_torque"]:
        out[:, 5] += np.real(coef * amp * np.exp(1j * (sh * phi + woff * tau)))

    def init(direction):
        if start == "rest" or not groups[direction]:
            return (0j, 0j)
        return _steady_state_init(p, direction, [(sh, wo, coef, a[0]) for sh, wo, coef, a in groups[direction]],
                                  w[0])

    F = np.zeros(t.size, dtype=complex)
    if groups["radial_force"]:
        q, qd = _modal_lti(p.mass, p.c_r, p.k_r, groups["radial_force"], (phi, tau), T, init("radial_force"))
        F = p.k_r * q + p.c_r * qd
    if groups["axial_force"]:
        q, qd = _modal_lti(p.mass, p.c_z, p.k_z, groups["axial_force"], (phi, tau), T, init("axial_force"))
        out[:, 2] = np.real(p.k_z * q + p.c_z * qd)
    Tc = np.zeros(t.size, dtype=complex)
    if groups["radial_torque"]:
        w_mid = 0.5 * (w[1:] + w[:-1])
        q, qd = _rocking_ltv(p, groups["radial_torque"], (phi, tau), w_mid, T, init("radial_torque"))
        Tc = p.k_rock * q + p.c_rock * qd
    Tint = Tc + 1j * p.height * F
    out[:, 0], out[:, 1] = F.real, F.imag
    out[:, 3], out[:, 4] = Tint.real, Tint.imag
    return out


def channel_index(name: str) -> int:
    return CHANNELS.index(name)
