"""Diagnosed broadband floors and speed ripple in the coupling kit: floors through the coupled plant vs
the Lyapunov covariance of the assembled state-space system and a closed form; ripple coefficients vs
their closed form and Parseval; rippled hard-mounted lines vs a time-domain simulation; both effects read
from a model file (jitter, output PSD, bad entries)."""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pytest
from scipy import integrate, linalg
from scipy.special import jv

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.coupling.performance import wheel_spec_from_model
from rwadist.diagnose import ripple_sideband_powers
from rwadist.extended_ripple import Ripple, ripple_coefficients, ripple_lines
from rwadist.extended_time import simulate_time
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S

# ------------------------------------------------------------------ broadband floors

def _grounded_plant(seed=3, n_modes=8):
    """A plant with flexible modes only (no rigid-body modes, so a white floor has a finite displacement
    variance), one 6-DOF node, two displacement-type outputs."""
    rng = np.random.default_rng(seed)
    fn = np.geomspace(4.0, 300.0, n_modes)
    phi = rng.normal(scale=0.15, size=(6, n_modes))
    phip = rng.normal(scale=1e-3, size=(2, n_modes))
    return cp.modal_plant(fn, 0.02, phi, phip, ("y0", "y1")), phi


def _reduced(sys, plant_phi, mounts, n_modes):
    """(A, B, C) of an assembly's state-space with each wheel's housing-rate states ω_hx, ω_hy eliminated:
    they are the integral of the interface angular acceleration, ω_h = (Mt Φ_if η̇)[3:5] from rest, and
    keeping them leaves an undriven zero eigenvalue that a Lyapunov solver cannot take."""
    A, B, C, D = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
    assert np.all(D == 0)                                            # displacement outputs: finite variance
    n, nxp = A.shape[0], 2 * n_modes
    hidx, rows = [], []
    for j, m in enumerate(mounts):
        hidx += [nxp + 12 * j + 10, nxp + 12 * j + 11]
        for r in (3, 4):
            row = np.zeros(n)
            row[n_modes:nxp] = (m.selector(6, 6) @ plant_phi)[r]
            rows.append(row)
    keep = np.setdiff1d(np.arange(n), hidx)
    S = np.array(rows)[:, keep]
    return A[np.ix_(keep, keep)] + A[np.ix_(keep, hidx)] @ S, B[keep], C[:, keep] + C[:, hidx] @ S


def test_floor_through_coupled_plant_equals_lyapunov_covariance():
    """Two E wheels (one reversed at 0.8 × speed) with white blocked-load floors on Fx (wheel 1) and Ty
    (wheel 2, two floors on one channel, one ∝ Ω²) on a lightly damped plant, over 1e-3-2e4 Hz: the
    mean square of floor_responses = diag(C X Cᵀ) with A X + X Aᵀ + B (G/2) Bᵀ = 0 (one-sided PSD G is
    the two-sided intensity G/2), the floor entering the assembly as an external load Mt_kᵀ e_c at the
    plant interface (= a blocked load at the wheel's interface).  Coupled and practice (ii) (the
    plant with rigid wheel masses) to 1e-4; the default grid agrees with a 4× finer one to 2e-5."""
    plant, phi = _grounded_plant()
    p = replace(preset("ithaco-e").extended, height=0.06)
    lines = (ext.Line("radial_force", 1.0, p.U_s),)
    G1, G2, w_ref = 3e-4, 2e-6, 150.0
    fk = np.array([1e-3, 2e4])
    m1 = cp.Mount(0, cp.spin_axis_dcm((0.3, 1, 0.2)), (0.4, -0.2, 0.3))
    m2 = cp.Mount(0, cp.spin_axis_dcm((1, 0, 0.5)), (-0.3, 0.1, -0.2))
    w1 = cp.WheelSpec(p, lines, m1, housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03),
                      floors=(cp.Floor(0, fk, np.full(2, G1), w_ref, 0.0),))
    w2 = cp.WheelSpec(p, lines, m2, housing_mass=1.5, speed_scale=-0.8,
                      floors=(cp.Floor(4, fk, np.full(2, G2), w_ref, 2.0), cp.Floor(4, fk, np.full(2, G2), w_ref)))
    om = 1700 * RPM_TO_RAD_S
    t0 = time.perf_counter()
    fr = cp.floor_responses(plant, [w1, w2], [om], practices=("coupled", "ii", "i"))
    dt = time.perf_counter() - t0
    fine = cp.floor_responses(plant, [w1, w2], [om], practices=("coupled", "ii", "i"),
                              f_hz=cp.floor_grid(plant, [w1, w2], [om], points_per_halfwidth=8.0))
    conv = {k: float(np.max(np.abs(fr.ms[k] / fine.ms[k] - 1))) for k in fr.ms}
    # Lyapunov: white noise per channel, two-sided intensity G/2
    W = np.diag([G1 / 2, G2 * ((0.8 * om / w_ref) ** 2 + 1) / 2])
    Bsel = np.column_stack([m1.selector(6, 6).T[:, 0], m2.selector(6, 6).T[:, 4]])
    asm = cp.assemble(plant, [(cp.wheel(p, om, 2.0, (0.02, 0.02, 0.03)), m1), (cp.wheel(p, -0.8 * om, 1.5), m2)])
    A, B, C = _reduced(asm.external_to("perf"), phi, [m1, m2], 8)
    assert np.linalg.eigvals(A).real.max() < 0
    X = linalg.solve_continuous_lyapunov(A, -(B @ Bsel) @ W @ (B @ Bsel).T)
    var_c = np.diag(C @ X @ C.T)
    rig = [(cp.rigid_mass(cp.wheel_rigid_mass_matrix(p, 2.0, (0.02, 0.02, 0.03))), m1),
           (cp.rigid_mass(cp.wheel_rigid_mass_matrix(p, 1.5)), m2)]
    s2 = cp.assemble(plant, rig).external_to("perf")
    A2, B2, C2 = (np.asarray(x) for x in (s2.A, s2.B, s2.C))
    X2 = linalg.solve_continuous_lyapunov(A2, -(B2 @ Bsel) @ W @ (B2 @ Bsel).T)
    var_ii = np.diag(C2 @ X2 @ C2.T)
    err_c = np.max(np.abs(fr.ms["coupled"][0] / var_c - 1))
    err_ii = np.max(np.abs(fr.ms["ii"][0] / var_ii - 1))
    print(f"\nfloor vs Lyapunov: coupled {err_c:.2e}, practice ii {err_ii:.2e}; grid {fr.f_hz.size} points, "
          f"{dt * 1e3:.0f} ms; vs 4x finer grid {conv}")
    assert err_c < 1e-4 and err_ii < 1e-4
    assert max(conv.values()) < 2e-5
    # the coupling matters here (the test is not passed by the plant alone)
    assert np.max(np.abs(fr.ms["i"][0] / var_c - 1)) > 0.1
    # chunked in frequency and speed (bounded work arrays) = all at once
    chunked = cp.floor_responses(plant, [w1, w2], [om, 0.5 * om], practices=("coupled", "ii", "i", "iii"),
                                 f_hz=fr.f_hz, chunk_points=97)
    whole = cp.floor_responses(plant, [w1, w2], [om, 0.5 * om], practices=("coupled", "ii", "i", "iii"),
                               f_hz=fr.f_hz, chunk_points=10**7)
    for k in whole.psd:
        assert np.allclose(chunked.psd[k], whole.psd[k], rtol=1e-12, atol=0)


def test_floor_practice_i_spring_mass_closed_form():
    """Practice (i) on six uncoupled spring-mass DOFs (modal plant, Φ = 1/√m): a white force of one-sided
    PSD G on Fx gives the displacement variance G/(4kc) (∫|1/(k − mω² + icω)|² over all f = 1/(2kc))."""
    m, fn, zeta, G = 2.0, 10.0, 0.05, 4e-3
    k = m * (2 * np.pi * fn) ** 2
    c = 2 * zeta * 2 * np.pi * fn * m
    plant = cp.modal_plant(np.full(6, fn), zeta, np.eye(6) / np.sqrt(m), np.eye(6)[:1] / np.sqrt(m), ("x",))
    p = preset("ithaco-e").extended
    spec = cp.WheelSpec(p, (ext.Line("radial_force", 1.0, p.U_s),),
                        floors=(cp.Floor(0, [1e-4, 1e5], [G, G], 100.0),))
    fr = cp.floor_responses(plant, [spec], [300.0], practices=("i",))
    exact = G / (4 * k * c)
    print(f"\npractice i, spring-mass: {fr.ms['i'][0, 0]:.6e} vs G/(4kc) {exact:.6e} "
          f"({fr.ms['i'][0, 0] / exact - 1:+.1e}), {fr.f_hz.size} points")
    assert fr.ms["i"][0, 0] == pytest.approx(exact, rel=1e-4, abs=0)


# ------------------------------------------------------------------ speed ripple

def test_ripple_coefficients_closed_form_and_parseval():
    """c_k of (1 + ε sin θ)² e^{−jβ cos θ} = the convolution of (1 + ε sin θ)²'s Fourier coefficients
    (1 + ε²/2; ∓jε at ±1; −ε²/4 at ±2) with (−j)^k J_k(β) (Jacobi-Anger), for either sign of ε; for a
    non-integer exponent Σ|c_k|² = the mean of |1 + ε sin θ|^{2p} by quadrature (Parseval); and
    diagnose's ripple_sideband_powers is |c_k|²."""
    beta = np.array([0.0, 0.3, 1.7, 4.0])
    for eps in (0.2, -0.35, 0.0):
        k, c = ripple_coefficients(beta, eps, 2.0)
        a = {0: 1 + eps**2 / 2, 1: -1j * eps, -1: 1j * eps, 2: -eps**2 / 4, -2: -eps**2 / 4}
        ref = np.zeros((beta.size, k.size), dtype=complex)
        for i, kk in enumerate(k):
            for mm, am in a.items():
                ref[:, i] += am * (-1j) ** (kk - mm) * jv(kk - mm, beta)
        assert np.max(np.abs(c - ref)) < 1e-13
        _, P = ripple_sideband_powers(beta, eps, 2.0)
        assert np.array_equal(P, np.abs(c) ** 2)
    for p, eps, b in ((2.6, 0.3, 0.8), (2.6, -0.3, 2.5), (1.3, 0.9, 0.1)):
        _, c = ripple_coefficients(b, eps, p, k_max=60)    # non-integer p: (1 + ε sin θ)^p has all orders
        mean = integrate.quad(lambda t: abs(1 + eps * np.sin(t)) ** (2 * p), 0, 2 * np.pi, epsabs=0,
                              epsrel=1e-13)[0] / (2 * np.pi)
        assert np.sum(np.abs(c) ** 2) == pytest.approx(mean, rel=1e-10)


def _ripple_lines(p):
    """Lines of every kind: imbalance-like co lines (as plain lines: no tangential term), a counter line
    with an amplitude law, a planar torque, axial force and torque, and a sideband line (f_offset)."""
    return [ext.Line("radial_force", 1.0, p.U_s, "co", 0.3),
            ext.Line("radial_torque", 1.0, p.U_d, "co", 1.1),
            ext.Line("radial_force", 2.0, 2e-6, "counter", 0.7, law=(0.004, 150.0, 2.6)),
            ext.Line("radial_torque", 3.0, 3e-7, "planar", 0.2, angle=0.9),
            ext.Line("axial_force", 2.96, 1.5e-6, phase=2.0),
            ext.Line("axial_torque", 1.5, 1e-7, phase=-0.4),
            ext.Line("radial_force", 4.42, 1e-6, "co", 0.5, f_offset=3.7)]


@pytest.mark.parametrize("rpm", [1500.0, -1100.0])
def test_rippled_hard_mounted_lines_match_time_simulation(rpm):
    """line_responses' hard-mounted sidebands of a rippled wheel (modes on) = complex line amplitudes at
    f + m·f_r fitted by least squares to rwadist.extended_time.simulate_time driven by the rippled speed
    Ω0 + ΔΩ sin 2πf_r t (20 s after a 2 s settling, 2 kHz; the same rotor-angle origin).  Fx, Fy, Fz,
    Tz: the only neglected term there is none (no imbalance tangential term in these lines): < 1e-4 of
    the channel's largest line.  Tx, Ty: the ripple's modulation of the gyroscopic rocking dynamics,
    neglected by design, is what differs: the error stays within 2× its first-order size
    |carrier|·I_zz·ΔΩ·|ν|/(2|den(ν)|) -- for the real E wheel and for I_zz / 100 (error 100× smaller)."""
    p0 = replace(preset("ithaco-e").extended, height=0.05)
    rip = Ripple(3.1, 4.0, 150.0)
    om = rpm * RPM_TO_RAD_S
    # with ΔΩ = 0 the order-0 lines are the steady lines
    m0, f0, a0 = ripple_lines(p0, _ripple_lines(p0), [om], Ripple(3.1, 0.0, 150.0), k_max=2)
    fs_, as_ = ext.steady_lines(p0, _ripple_lines(p0), [om])
    assert np.array_equal(a0[:, :, 2], as_) and np.array_equal(f0[:, :, 2], fs_)
    assert np.all(a0[:, :, [0, 1, 3, 4]] == 0)
    for izz in (1.0, 0.01):
        p = replace(p0, I_zz=p0.I_zz * izz)
        lines = _ripple_lines(p)
        spec = cp.WheelSpec(p, lines, ripple=rip)
        lr = cp.line_responses(cp.example_spacecraft(), [spec], [om], practices=("coupled",))
        f, A = lr.f_hz[0][0], lr.hard_mounted[0][0]
        assert np.unique(lr.ripple_order[0]).size >= 7                          # sidebands to |m| >= 3
        fu, idx = np.unique(np.round(f, 9), return_inverse=True)
        assert fu.size == f.size and fu[0] > 0 and np.min(np.diff(fu)) > 0.09   # resolvable in 20 s
        fsamp = 2000.0
        t = np.arange(int(22.0 * fsamp)) / fsamp
        w = om + rip.delta(om) * np.sin(2 * np.pi * rip.f_hz * t)
        d = rip.delta(om) / (2 * np.pi * rip.f_hz)          # simulate_time has φ(0) = 0, ripple_lines −ΔΩ/2πf_r
        y = simulate_time(p, lines, t, w, phases=[ln.phase - ln.h * d for ln in lines], start="steady")
        sel = t >= 2.0
        E = np.exp(2j * np.pi * fu[None, :] * t[sel, None])
        X = np.hstack([E.real, -E.imag])                 # near-orthogonal columns: normal equations
        XtX = X.T @ X
        assert np.linalg.cond(XtX) < 1e3
        coef = np.linalg.solve(XtX, X.T @ y[sel])
        fit = coef[:fu.size] + 1j * coef[fu.size:]
        pred = np.zeros_like(fit)
        np.add.at(pred, idx, A)
        err = np.abs(fit - pred)
        scale = np.abs(pred).max(0)
        est = 0.0                                          # neglected gyroscopic modulation, first order
        for ln in lines:
            if ln.direction == "radial_torque":
                for sg, c in ln.components():
                    nu = sg * ln.h * om
                    den = p.k_rock - p.I_rr * nu**2 + p.I_zz * om * nu + 1j * p.c_rock * nu
                    carrier = abs(c * ln.amplitude(om) * (p.k_rock + 1j * p.c_rock * nu) / den)
                    est = max(est, carrier * p.I_zz * rip.delta(om) * abs(nu) / (2 * abs(den)))
        rel = err.max(0) / scale
        print(f"\n{rpm:+.0f} rpm, I_zz x{izz}: {fu.size} lines; error / channel max "
              f"{np.array2string(rel, precision=1)}; Tx/Ty error {err[:, 3:5].max():.2e} vs gyroscopic "
              f"estimate {est:.2e}")
        assert rel[[0, 1, 2, 5]].max() < 1e-4
        assert err[:, 3:5].max() < 2.0 * est
        first = np.abs(pred[idx[np.abs(lr.ripple_order[0]) == 1]])
        assert first.max() > 0.05 * scale.max()            # the sidebands are large, the test is not empty


def test_ripple_in_coupled_path_equals_explicit_sideband_lines():
    """Coupled/practice outputs of a rippled wheel = those of the same wheel without ripple whose lines are
    replaced, at that speed, by explicit sideband lines (f_offset + m·f_r, amplitude × |c_m|, phase +
    arg c_m, c_m = ripple_coefficients(β, ε = ΔΩ/Ω0 signed, p); whirl sense handled by the phase, which a
    counter-rotating component takes conjugated) -- an independent route (closed-form ε, not the FFT of
    the line's amplitude law) through the plant at each sideband's own frequency, at both speed signs."""
    p = replace(preset("ithaco-e").extended, height=0.05)
    lines = _ripple_lines(p)
    rip = Ripple(2.3, 3.0, 150.0, 0.5)
    plant = cp.example_spacecraft()
    for rpm in (1800.0, -2400.0):
        om = rpm * RPM_TO_RAD_S
        dW = float(rip.delta(om))
        lr = cp.line_responses(plant, [cp.WheelSpec(p, lines, ripple=rip)], [om])
        K = int(np.max(lr.ripple_order[0]))
        explicit = []
        for ln in lines:
            pe = 2.0 if ln.law is None else ln.law[2]
            k, c = ripple_coefficients(ln.h * dW / (2 * np.pi * rip.f_hz), dW / om, pe, K)
            for kk, ck in zip(k, c):
                law = None if ln.law is None else (ln.law[0] * abs(ck), ln.law[1], ln.law[2])
                explicit.append(replace(ln, C=ln.C * abs(ck), law=law, phase=ln.phase + np.angle(ck),
                                        f_offset=ln.f_offset + kk * rip.f_hz))
        ref = cp.line_responses(plant, [cp.WheelSpec(p, explicit)], [om])
        for prac in ("coupled", "i", "ii", "iii"):
            assert lr.rms(prac) == pytest.approx(ref.rms(prac), rel=1e-9, abs=0)
        ours, theirs = {}, {}
        for d, r in ((ours, lr), (theirs, ref)):
            for fj, yj in zip(np.round(r.f_hz[0][0], 8), r.y["coupled"][0][0]):
                d[fj] = d.get(fj, 0) + yj
        scale = max(np.abs(v).max() for v in ours.values())
        assert max(np.abs(ours[f] - theirs.get(f, 0)).max() for f in ours) < 1e-9 * scale


def test_wheels_sharing_their_lines_keep_their_own_ripple_speed_and_mount():
    """A wheel set built from one lines tuple (as wheel_spec_from_model's callers do) shares the sideband orders
    and blocked loads only between wheels equal but for the mount: responses equal to those of the same wheels
    each given its own copy of the lines (nothing shared), for a wheel with another ripple and one reversed at 0.9 x
    the speed beside two that differ only in their mount."""
    p = replace(preset("ithaco-e").extended, height=0.05)
    lines = tuple(_ripple_lines(p))
    plant = cp.example_spacecraft()
    specs = [(Ripple(2.3, 3.0, 150.0, 0.5), 1.0, cp.Mount(0, cp.spin_axis_dcm((1, 0, 0)), (0.3, 0.0, 0.1))),
             (Ripple(2.3, 3.0, 150.0, 0.5), 1.0, cp.Mount(0, cp.spin_axis_dcm((0, 1, 0)), (0.0, 0.3, 0.1))),
             (Ripple(5.0, 1.0, 150.0, 0.0), -0.9, cp.Mount(0, cp.spin_axis_dcm((0, 0, 1)), (0.0, 0.0, 0.4)))]
    speeds = np.array([300.0, 1800.0, 2900.0]) * RPM_TO_RAD_S
    shared = cp.line_responses(plant, [cp.WheelSpec(p, lines, m, ripple=r, speed_scale=sc) for r, sc, m in specs],
                               speeds)
    own = cp.line_responses(plant, [cp.WheelSpec(p, tuple(replace(ln) for ln in lines), m, ripple=r, speed_scale=sc)
                                    for r, sc, m in specs], speeds)
    assert shared.ripple_order[2].max() != shared.ripple_order[0].max()       # the third wheel has its own orders
    for prac in ("coupled", "i", "ii", "iii"):
        for k in range(3):
            assert np.array_equal(shared.y[prac][k], own.y[prac][k])
    for k in range(3):
        assert np.array_equal(shared.loads[k], own.loads[k]) and np.array_equal(shared.f_hz[k], own.f_hz[k])
    assert not np.allclose(shared.y["coupled"][0], shared.y["coupled"][1], rtol=1e-3, atol=0)   # mounts differ


# ------------------------------------------------------------------ from the model file

FLOOR = {"kind": "broadband_floor", "channel": ["Fx", "Ty"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
         "f_Hz": [2.0, 4.0, 40.0, 250.0, 400.0], "psd_ref": [0.0, 2e-9, 5e-9, 1e-9, 0.0]}
RIPPLE = {"kind": "speed_ripple", "f_ripple_Hz": 2.3, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 200.0,
          "speed_exponent": 0.0}


def _mounted(model, **kw):
    return wheel_spec_from_model(model, cp.Mount(0, cp.spin_axis_dcm((1, 1, 0)), (0.4, 0.3, 0.2)),
                                 housing_mass=2.0, **kw)


def test_model_file_floor_and_ripple_reach_jitter_and_output_psd():
    """A preset model with a diagnosed floor (two channels) and ripple: wheel_spec_from_model reads both;
    jitter RMS² with the floor = RMS² without it + the floor's mean square (incoherent, exactly), every
    practice; a vanishing ripple gives the plain lines; output_psd still integrates to the speed-averaged
    mean square (lines and floor)."""
    model = preset("ithaco-e").to_model()
    model.effects = [dict(FLOOR), dict(RIPPLE)]
    spec = _mounted(model)
    assert [f.channel for f in spec.floors] == [0, 4] and spec.ripple == Ripple(2.3, 3.0, 200.0, 0.0)
    plant = cp.example_spacecraft()
    speeds = np.linspace(300, 3000, 12) * RPM_TO_RAD_S
    t0 = time.perf_counter()
    jr = cp.jitter_vs_speed(plant, [spec], speeds)
    dt = time.perf_counter() - t0
    bare = cp.jitter_vs_speed(plant, [replace(spec, floors=())], speeds)
    fr = cp.floor_responses(plant, [spec], speeds)
    for prac in cp.PRACTICES:
        assert np.allclose(jr.rms[prac] ** 2, bare.rms[prac] ** 2 + fr.ms[prac], rtol=1e-12, atol=0)
    share = float(np.max(fr.ms["coupled"] / jr.rms["coupled"] ** 2))
    print(f"\nmodel-file floor + ripple, 12 speeds: {dt:.2f} s; floor share of the mean square up to {share:.2f}")
    assert 0.01 < share < 0.99                                    # both parts count
    # ripple: present (sidebands raise the RMS) and, vanishing, the plain lines
    plain = cp.jitter_vs_speed(plant, [replace(spec, floors=(), ripple=None)], speeds)
    assert np.max(np.abs(bare.rms["coupled"] / plain.rms["coupled"] - 1)) > 1e-3
    tiny = cp.jitter_vs_speed(plant, [replace(spec, floors=(), ripple=Ripple(2.3, 0.0, 200.0))], speeds)
    assert np.allclose(tiny.rms["coupled"], plain.rms["coupled"], rtol=1e-12, atol=0)
    # output PSD: integral = Σ_s w_s (lines in band + floor)
    lr = cp.line_responses(plant, [spec], speeds, practices=("coupled", "ii"))
    wts = np.random.default_rng(1).uniform(0.5, 1.5, speeds.size)
    wts /= wts.sum()
    edges = np.concatenate([[0.0], np.geomspace(1.0, 500.0, 700)])
    for prac in ("coupled", "ii"):
        _, psd = cp.output_psd(lr, prac, wts, edges)
        ms = np.sum(psd * np.diff(edges)[:, None], axis=0)
        lines = sum(np.sum(np.abs(y) ** 2 / 2 * (f < 500.0)[..., None] * wts[:, None, None], axis=(0, 1))
                    for f, y in zip(lr.f_hz, lr.y[prac]))
        assert np.allclose(ms, lines + wts @ lr.floor.ms[prac], rtol=1e-12, atol=0)
        assert np.allclose(ms - lines, wts @ lr.floor.ms[prac], rtol=1e-8, atol=0)   # the floor part itself
    # a partial band gets the floor's integral over that band only
    _, psd = cp.output_psd(lr, "coupled", wts, [100.0, 200.0])
    fg = lr.floor.f_hz
    x = np.concatenate([[100.0], fg[(fg > 100.0) & (fg < 200.0)], [200.0]])
    fl = np.einsum("s,sfp->fp", wts, lr.floor.psd["coupled"])
    fl = np.column_stack([np.interp(x, fg, fl[:, j]) for j in range(fl.shape[1])])
    ln = sum(np.sum(np.abs(y) ** 2 / 2 * ((f >= 100.0) & (f < 200.0))[..., None] * wts[:, None, None], axis=(0, 1))
             for f, y in zip(lr.f_hz, lr.y["coupled"]))
    got = psd[0] * 100.0 - ln
    exact = np.sum(0.5 * (fl[1:] + fl[:-1]) * np.diff(x)[:, None], axis=0)    # the interpolant's integral
    assert np.allclose(got, exact, rtol=1e-9)


@pytest.mark.parametrize("i, bad, field", [
    (0, {"channel": "Fq"}, r"effects\[0\]\.channel"),
    (0, {"channel": []}, r"effects\[0\]\.channel"),
    (0, {"f_Hz": [2.0, 4.0, 3.0, 250.0, 400.0]}, r"effects\[0\]\.f_Hz"),
    (0, {"f_Hz": "4, 40"}, r"effects\[0\]\.f_Hz"),
    (0, {"psd_ref": [1e-9, 2e-9]}, r"effects\[0\]\.psd_ref"),
    (0, {"psd_ref": [0.0, -2e-9, 5e-9, 1e-9, 0.0]}, r"effects\[0\]\.psd_ref"),
    (0, {"exponent": -1.0}, r"effects\[0\]\.exponent"),
    (0, {"omega_ref_rad_s": None}, r"effects\[0\]\.omega_ref_rad_s"),
    (1, {"f_ripple_Hz": 0.0}, r"effects\[1\]\.f_ripple_Hz"),
    (1, {"delta_omega_rad_s": -1.0}, r"effects\[1\]\.delta_omega_rad_s"),
    (1, {"omega_ref_rad_s": float("nan")}, r"effects\[1\]\.omega_ref_rad_s"),
    (1, {"speed_exponent": "1"}, r"effects\[1\]\.speed_exponent"),
])
def test_bad_effect_entries_name_the_field(i, bad, field):
    model = preset("ithaco-e").to_model()
    effects = [dict(FLOOR), dict(RIPPLE)]
    effects[i].update(bad)
    model.effects = effects
    with pytest.raises(cp.CouplingError, match=field):
        wheel_spec_from_model(model)


def test_second_ripple_and_unresolvable_floor_refused():
    model = preset("ithaco-e").to_model()
    model.effects = [dict(RIPPLE), dict(FLOOR), dict(RIPPLE, f_ripple_Hz=5.0)]
    with pytest.raises(cp.CouplingError, match=r"effects\[2\]\.kind: a second speed_ripple"):
        wheel_spec_from_model(model)
    # an undamped plant mode inside the floor band: infinite mean square, refused with the mode named
    model.effects = [dict(FLOOR)]
    spec = wheel_spec_from_model(model)
    plant = cp.modal_plant([30.0, 80.0], [0.0, 0.02], np.eye(6)[:, :2], np.ones((1, 2)))
    with pytest.raises(cp.CouplingError, match="Hz near the floor band .* damping ratio .* infinite"):
        cp.floor_responses(plant, [spec], [100.0])
    # a floor reaching 0 Hz: the default grid cannot choose the low end; an explicit grid is taken
    model.effects = [dict(FLOOR, f_Hz=[0.0, 40.0, 250.0], psd_ref=[2e-9, 5e-9, 1e-9])]
    spec = wheel_spec_from_model(model)
    good = cp.modal_plant([30.0, 80.0], [0.02, 0.02], np.eye(6)[:, :2], np.ones((1, 2)))
    with pytest.raises(cp.CouplingError, match="reaches 0 Hz: pass f_hz"):
        cp.floor_responses(good, [spec], [100.0])
    fr = cp.floor_responses(good, [spec], [100.0], f_hz=np.geomspace(1.0, 250.0, 3000))
    assert np.all(np.isfinite(fr.ms["coupled"])) and np.all(fr.ms["coupled"] > 0)


def test_a_model_fitted_per_unit_mass_needs_the_rotor_mass_to_be_coupled():
    """``rwadist fit --extended`` without --mass/--radius fits k/M, c/M, k_θ/I_rr, c_θ/I_rr, I_zz/I_rr with M = 1 kg and
    I_rr = 1 kg·m² as units: coupled as is, it was a 1 kg rotor (LOS jitter +22 % to +148 % against the 10.6 kg
    wheel).  Refused, naming analytical.fit.per_unit; with the rotor's mass and radius the stiffnesses come back to
    the preset's (the truth the data were made from) within the fit's 2 %, and the imbalances are the fitted ones."""
    from rwadist import api

    wheel = preset("ithaco-e")
    test = api.simulate_test("ithaco-e", np.linspace(300.0, 3000.0, 24), sample_rate=1920.0, n_samples=4096,
                             physics="extended", seed=5)
    efit, model = api.fit_extended(test)
    assert efit.per_unit and model.analytical["mass_kg"] == 1.0
    with pytest.raises(cp.CouplingError, match=r"analytical\.fit\.per_unit.*mass_kg= and radius_m="):
        wheel_spec_from_model(model)
    spec = wheel_spec_from_model(model, mass_kg=wheel.mass_kg, radius_m=wheel.radius_m)
    truth = wheel.extended
    assert spec.params.mass == wheel.mass_kg
    for k in ("k_r", "k_rock", "k_z", "I_rr"):
        assert getattr(spec.params, k) == pytest.approx(getattr(truth, k), rel=0.04), k   # k ∝ f²: 2 % in f
    assert spec.params.U_s == pytest.approx(model.analytical["U_s_kg_m"])
    with pytest.raises(cp.CouplingError, match="in SI already"):       # they were ignored for a model in SI
        wheel_spec_from_model(wheel.to_model(), mass_kg=1.0, radius_m=0.05)


def test_a_floor_of_another_type_is_refused_naming_the_class_to_use():
    """The message names the class by an import path that works (it named coupling.performance.Floor, the
    package's path before it moved into rwadist)."""
    import importlib

    p = preset("ithaco-e").extended
    with pytest.raises(cp.CouplingError, match="floors must be") as info:
        cp.WheelSpec(p, (ext.Line("radial_force", 1.0, p.U_s),), floors=(object(),))
    path = str(info.value).split("floors must be ")[1].split()[0]
    module, name = path.rsplit(".", 1)
    assert getattr(importlib.import_module(module), name) is cp.Floor


def test_the_kit_without_python_control_says_which_extra_installs_it():
    """``from rwadist import coupling`` with python-control missing (sys.modules entry None: its import fails) names
    the package and the extra (it was a bare "No module named 'control'" from a module inside the kit)."""
    import subprocess
    import sys

    code = ("import sys; sys.modules['control'] = None\n"
            "try:\n    from rwadist import coupling\nexcept ImportError as e:\n"
            "    print(type(e).__name__, e.name, e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.startswith("MissingDependencyError control ") and "pip install 'rwadist[coupling]'" in out, out
