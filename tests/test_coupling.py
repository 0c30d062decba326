"""Coupling package (issue 6): thesis §5.3 two-mass cases against Table 5.4, limits, the
worked example cross-checked by two methods, bad input, dask sweeps, the example notebook."""
from __future__ import annotations

from dataclasses import replace

import control
import numpy as np
import pytest

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S

F_TEST = np.geomspace(0.1, 1000.0, 500)          # Hz, the acceptance band
REL = 1e-9


def _rel(a, b):
    return np.max(np.abs(a - b) / np.abs(b))


def _eval(sys, f):
    """Frequency response (n_out, n_in, F) of a python-control StateSpace (coupling.frf: balanced,
    refined LU; python-control's plain sys(s) is checked against it in test_frf_matches_python_control)."""
    return cp.frf(sys, f)


def test_frf_matches_python_control():
    sys = cp.assemble(cp.spring_mass_plant(1800.0, 7e6), [(cp.spring_mass(6.0, 1e6), None)]).free_to("perf")
    a, b = cp.frf(sys, F_TEST), sys(2j * np.pi * F_TEST, squeeze=False)
    err = np.max(np.abs(a - b) / np.abs(a))
    print(f"\npython-control sys(s) vs refined frf, 1800/6 kg chain: max rel. diff {err:.2e}")
    assert err < 1e-7


# ------------------------------------------------------------------ thesis Table 5.4

@pytest.mark.parametrize("m1, m2, k1, k2", [(1.0, 1.0, 1.0, 1.0), (1800.0, 6.0, 7e6, 1e6)])
def test_table_5_4_disturbance_model_1_rigid_wheel(m1, m2, k1, k2):
    """Disturbance model 1 (rigid wheel of mass m2) on plant i/ii: the assembled coupled transfer
    functions = Eq. 5.55 / Table 5.4 H_sys' and practice (ii) is exact, (i) is not."""
    w = 2 * np.pi * F_TEST
    s = 1j * w
    ps = cp.practice_systems(cp.spring_mass_plant(m1, k1), [(cp.rigid_mass(m2), None)], ("coupled", "i", "ii"))
    H = {p: _eval(v, F_TEST)[:2, 0, :] for p, v in ps.items()}      # outputs [F_l1, a_r1]
    den = (m1 + m2) * s**2 + k1
    H_exact = np.array([-k1 / den, s**2 / den])
    assert _rel(H["coupled"], H_exact) < REL
    assert _rel(H["ii"], H_exact) < REL                               # practice (ii) exact here
    H_i = np.array([-k1 / (m1 * s**2 + k1), s**2 / (m1 * s**2 + k1)])
    assert _rel(H["i"], H_i) < REL                                    # Eq. 5.50 with Eq. 5.49
    assert _rel(H["i"], H_exact) > 1e-3                               # and (i) is not exact
    # PSD matrices (S_F = 1): Table 5.4 column 1 with the printed typo corrected
    # (denominator (−(m1+m2)ω² + k1)², the table prints (−m1 + m2)ω² + k1 unsquared)
    num = np.array([[k1**2 + 0 * w, k1 * w**2], [k1 * w**2, w**4]])
    S_exact = num / (-(m1 + m2) * w**2 + k1) ** 2
    S_ii = np.einsum("if,jf->ijf", H["ii"], np.conj(H["ii"]))
    S_i = np.einsum("if,jf->ijf", H["i"], np.conj(H["i"]))
    assert _rel(S_ii, S_exact) < REL
    assert _rel(S_i, num / (-m1 * w**2 + k1) ** 2) < REL


@pytest.mark.parametrize("m1, m2, k1, k2", [(1.0, 1.0, 1.0, 1.0), (1800.0, 6.0, 7e6, 1e6)])
def test_table_5_4_disturbance_model_2_flexible_wheel(m1, m2, k1, k2):
    """Disturbance model 2 (wheel m2 on spring k2) with plants i, ii, iii: every entry of Table 5.4
    column 2 to 1e-9 relative over 0.1-1000 Hz; the coupled result also equals a direct Newton
    solution of Eq. 5.7's two-mass system; practice (ii) is not exact (error reported)."""
    w = 2 * np.pi * F_TEST
    s = 1j * w
    wheel = cp.spring_mass(m2, k2)
    ps = cp.practice_systems(cp.spring_mass_plant(m1, k1), [(wheel, None)])
    H = {p: _eval(v, F_TEST)[:2, 0, :] for p, v in ps.items()}
    Delta = (m1 * s**2 + k1) * (m2 * s**2 + k2) + m2 * k2 * s**2
    H_exact = k2 / Delta * np.array([-k1 + 0 * s, s**2])                       # Eq. 5.64
    assert _rel(H["coupled"], H_exact) < REL
    # independent: Newton, [K − ω² M] x = [0, F] (Eq. 5.7 with the ground spring k1)
    Kn = np.array([[k1 + k2, -k2], [-k2, k2]])
    Mn = np.diag([m1, m2])
    x = np.linalg.solve(Kn[None] - w[:, None, None] ** 2 * Mn[None], np.array([0.0, 1.0]))
    assert _rel(H["coupled"][1], -w**2 * x[:, 0]) < REL
    assert _rel(H["coupled"][0], -k1 * x[:, 0]) < REL
    # measured (hard-mounted) force PSD, Eq. 5.62
    hm = _eval(wheel.hard_mounted(), F_TEST)[0, 0]
    assert _rel(np.abs(hm) ** 2, k2**2 / (-m2 * w**2 + k2) ** 2) < REL
    num = np.array([[k1**2 + 0 * w, k1 * w**2], [k1 * w**2, w**4]])
    D1 = (-m1 * w**2 + k1)
    D2 = (-m2 * w**2 + k2)
    Dx = D1 * D2 - m2 * k2 * w**2
    Dii = -(m1 + m2) * w**2 + k1
    S = {p: np.einsum("if,jf->ijf", v, np.conj(v)) for p, v in H.items()}
    assert _rel(S["coupled"], k2**2 * num / Dx**2) < REL                 # Eq. 5.65
    assert _rel(S["i"], k2**2 * num / (D1**2 * D2**2)) < REL             # Eq. 5.63
    assert _rel(S["ii"], k2**2 * num / (Dii**2 * D2**2)) < REL           # Eq. 5.66
    assert _rel(S["iii"], k2**4 * num / (Dx**2 * D2**2)) < REL           # Eq. 5.67
    err_ii = np.max(np.abs(S["ii"][1, 1] - S["coupled"][1, 1]) / S["coupled"][1, 1])
    if m1 == 1.0:
        assert err_ii > 0.5          # Fig. 5-9 upper plot: quite different
    else:
        assert err_ii > 1e-6         # lower plot: close but not exact
    print(f"\nmodel 2, m1={m1} m2={m2} k1={k1} k2={k2}: max rel. error of S_ii[a,a] vs exact {err_ii:.3g}")


def test_acceleration_feedback_equals_python_control_feedback():
    """The assembly's closed loop = python-control's own feedback() of the same two blocks."""
    m1, k1, c1, m2, k2, c2 = 3.0, 50.0, 0.4, 1.5, 20.0, 0.2
    plant = cp.spring_mass_plant(m1, k1, c1)
    wh = cp.spring_mass(m2, k2, c2)
    mine = cp.assemble(plant, [(wh, None)]).free_to("accel")
    # plant: u -> a ; wheel: a -> f (first input), w -> f (second); f = Zc a + B w, u = f
    P = control.ss(plant.sys.A, plant.sys.B, np.asarray(plant.sys.C)[:1], np.asarray(plant.sys.D)[:1])
    Zc = control.ss(wh.sys.A, np.asarray(wh.sys.B)[:, :1], wh.sys.C, np.asarray(wh.sys.D)[:, :1])
    B = wh.hard_mounted()
    loop = control.feedback(P, Zc, sign=+1)                  # a = P (f), f = Zc a + B w
    ref = control.series(B, loop)
    f = np.geomspace(0.05, 50, 200)
    assert _rel(_eval(mine, f), _eval(ref, f)) < 1e-10


def test_isolator_on_rigid_mass_is_spring_mass():
    """A rigid mass on a spring-damper isolator is the spring-mass component (same physics)."""
    m2, k2, c2 = 6.0, 1e6, 30.0
    iso = cp.with_isolator(cp.rigid_mass(m2), k2, c2)
    ref = cp.spring_mass(m2, k2, c2)
    plant = cp.spring_mass_plant(1800.0, 7e6, 100.0)
    a = _eval(cp.assemble(plant, [(iso, None)]).free_to("perf"), F_TEST)
    b = _eval(cp.assemble(plant, [(ref, None)]).free_to("perf"), F_TEST)
    assert _rel(a, b) < 1e-9
    with pytest.raises(cp.SingularInterfaceError):
        cp.with_isolator(cp.rigid_mass(0.0), k2)


# ------------------------------------------------------------------ the wheel component

@pytest.mark.parametrize("height", [0.0, 0.083])
@pytest.mark.parametrize("rpm", [-2200.0, 1500.0])
def test_wheel_hard_mounted_equals_extended_steady_lines(height, rpm):
    """Wheel StateSpace with a = 0, driven by the free line loads, = extended.steady_lines."""
    desc = preset("ithaco-e")
    p = replace(desc.extended, height=height)
    lines = ext.lines_from_model(desc.to_model(), p)
    om = rpm * RPM_TO_RAD_S
    wc = cp.wheel(p, om)
    f, W = cp.free_lines(p, lines, om)
    _, B = wc.frf(f[0])
    got = np.einsum("lij,lj->li", B, W[0])
    _, ref = ext.steady_lines(p, lines, om)
    assert np.max(np.abs(got - ref[0])) < 1e-10 * np.max(np.abs(ref[0]))


def test_geometry_lever_arm_and_rotation_give_parallel_axis_mass():
    """A point mass mounted with a rotation and an offset adds exactly the parallel-axis mass matrix."""
    m = 4.0
    r = np.array([0.3, -0.2, 0.5])
    R = cp.rotation("z", 0.7) @ cp.rotation("x", -0.4)
    pm = np.zeros((6, 6))
    pm[:3, :3] = m * np.eye(3)
    Mt = cp.Mount(0, R, r).selector(6, 6)
    got = Mt.T @ pm @ Mt
    rt = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    ref = np.block([[m * np.eye(3), -m * rt], [m * rt, -m * rt @ rt]])
    assert np.max(np.abs(got - ref)) < 1e-12


# ------------------------------------------------------------------ limits

def _e_specs(n=4, height=0.0):
    desc = preset("ithaco-e")
    p = replace(desc.extended, height=height)
    lines = tuple(ext.lines_from_model(desc.to_model(), p))
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
    pos = [(0.5, 0.3, 0.2), (-0.5, 0.3, 0.2), (0.3, -0.5, 0.2), (-0.3, -0.5, 0.2)]
    return [cp.WheelSpec(p, lines, cp.Mount(0, cp.spin_axis_dcm(axes[i]), pos[i]), housing_mass=2.0,
                         housing_inertia=(0.02, 0.02, 0.03), name=f"E{i}") for i in range(n)]


def test_huge_stiff_spacecraft_returns_hard_mounted_loads():
    plant = cp.example_spacecraft(total_mass=1e12, first_mode_hz=1e6)
    specs = _e_specs(2, height=0.05)
    om = np.linspace(200, 3000, 15) * RPM_TO_RAD_S
    lr = cp.line_responses(plant, specs, om, practices=("coupled",))
    for loads, hm in zip(lr.loads, lr.hard_mounted):
        assert np.max(np.abs(loads - hm)) < 1e-8 * np.max(np.abs(hm))


def _rel_peak(a, b):
    """Largest error relative to each transfer function's peak over frequency."""
    return np.max(np.abs(a - b) / np.max(np.abs(b), axis=-1, keepdims=True))


def test_zero_compliance_wheel_reduces_to_practice_ii():
    """Stiffen the wheel ×k: at rest the coupled system -> practice (ii) (rigid mass); spinning, ->
    the rigid wheel with its gyroscopic torque (practice (ii) lacks it and differs).  The gap
    closes as 1/k (the wheel's compliance), 1e-8 of the peak at k = 1e10."""
    desc = preset("ithaco-e")
    p = desc.extended
    plant = cp.example_spacecraft()
    mount = cp.Mount(0, cp.spin_axis_dcm((0, 1, 1)), (0.4, 0.2, 0.3))
    f = np.geomspace(0.1, 1000, 200)
    om = 2000 * RPM_TO_RAD_S
    errs = {}
    for k in (1e8, 1e10):
        stiff = replace(p, k_r=p.k_r * k, k_rock=p.k_rock * k, k_z=p.k_z * k, height=0.05)
        ps = cp.practice_systems(plant, [(cp.wheel(stiff, 0.0, housing_mass=2.0), mount)], ("coupled", "ii"))
        e0 = _rel_peak(_eval(ps["coupled"], f), _eval(ps["ii"], f))
        flex = cp.assemble(plant, [(cp.wheel(stiff, om, housing_mass=2.0), mount)]).free_to("perf+accel")
        rigid = cp.assemble(plant, [(cp.wheel(stiff, om, housing_mass=2.0, rigid=True), mount)])
        Hf = _eval(flex, f)
        e1 = _rel_peak(Hf, _eval(rigid.free_to("perf+accel"), f))
        errs[k] = (e0, e1)
    print(f"\nzero-compliance limit, error / peak: k x1e8 {errs[1e8]}, k x1e10 {errs[1e10]}")
    assert errs[1e10][0] < 1e-7 and errs[1e10][1] < 1e-7
    assert 50 < errs[1e8][0] / errs[1e10][0] < 200 and 50 < errs[1e8][1] / errs[1e10][1] < 200
    mass_only = cp.practice_systems(plant, [(cp.wheel(stiff, om, housing_mass=2.0), mount)], ("ii",))["ii"]
    assert _rel_peak(_eval(mass_only, f), Hf) > 1e-4


# ------------------------------------------------------------------ worked example

def test_worked_example_two_methods_agree_and_errors_reported():
    """1800 kg spacecraft, 10 Hz first mode, four E wheels, LOS: the frequency-domain sweep equals
    the state-space assembly (python-control) evaluated at each line, for all four practices;
    then jitter vs speed 0-3000 rpm and the common practice's largest error."""
    plant = cp.example_spacecraft()
    specs = _e_specs(4)
    rpm = 1800.0
    om = rpm * RPM_TO_RAD_S
    lr = cp.line_responses(plant, specs, np.array([om]))
    atts = [(cp.wheel(s.params, om, s.housing_mass, s.housing_inertia), s.mount) for s in specs]
    ps = cp.practice_systems(plant, atts)
    for prac, sys in ps.items():
        for k, s in enumerate(specs):
            f, W = cp.free_lines(s.params, s.lines, om)
            hu, inv = np.unique([ln.h for ln in s.lines], return_inverse=True)
            Wg = np.zeros((hu.size, 6), dtype=complex)
            np.add.at(Wg, inv, W[0])
            H = _eval(sys, hu * om / (2 * np.pi))[:2, 6 * k:6 * k + 6, :]     # LOS per wheel-k free loads
            y_ss = np.einsum("ijl,lj->li", H, Wg)
            y_fd = lr.y[prac][k][0]
            assert np.max(np.abs(y_ss - y_fd)) < 1e-8 * np.max(np.abs(y_fd))
    speeds = np.linspace(0, 3000, 301) * RPM_TO_RAD_S
    jr = cp.jitter_vs_speed(plant, specs, speeds)
    assert np.all(jr.rms["coupled"][0] == 0) and np.all(jr.rms["coupled"][1:] > 0)
    out = {p: jr.worst(p) for p in ("i", "ii", "iii")}
    print("\nworked example, LOS (rss of x, y), largest |rel. error| vs coupled and speed:")
    for p, (e, es, r) in out.items():
        print(f"  practice {p}: {100 * es:+.2f} % at {r:.0f} rpm")
    print(f"  coupled LOS rms max {np.sqrt((jr.rms['coupled'] ** 2).sum(1)).max():.3e} rad")


def test_output_psd_integrates_to_speed_averaged_mean_square():
    plant = cp.example_spacecraft()
    specs = _e_specs(2)
    speeds = np.linspace(100, 3000, 60) * RPM_TO_RAD_S
    lr = cp.line_responses(plant, specs, speeds, practices=("coupled",))
    wts = np.full(speeds.size, 1.0 / speeds.size)
    edges = np.linspace(0, 400, 801)
    fc, psd = cp.output_psd(lr, "coupled", wts, edges)
    ms = np.sum(psd * np.diff(edges)[:, None], axis=0)
    inband = sum(np.sum(np.abs(y) ** 2 / 2 * (f < 400)[..., None] * wts[:, None, None], axis=(0, 1))
                 for f, y in zip(lr.f_hz, lr.y["coupled"]))
    assert np.allclose(ms, inband, rtol=1e-12)


# ------------------------------------------------------------------ bad input

def test_bad_input_clear_errors():
    p = preset("ithaco-e").extended
    plant6 = cp.example_spacecraft()
    # mismatched interface sizes
    with pytest.raises(cp.InterfaceMismatchError, match="1 interface DOFs, plant has 6"):
        cp.assemble(plant6, [(cp.spring_mass(6.0, 1e6), None)])
    with pytest.raises(cp.InterfaceMismatchError, match="not a multiple of 6"):
        cp.assemble(cp.spring_mass_plant(1.0, 1.0), [(cp.wheel(p, 100.0), cp.Mount())])
    with pytest.raises(cp.InterfaceMismatchError, match="node"):
        cp.assemble(plant6, [(cp.wheel(p, 100.0), cp.Mount(node=1))])
    # unstable plant
    bad = control.ss([[0.0, 1.0], [4.0, -0.1]], [[0.0], [1.0]], [[4.0, -0.1], [1.0, 0.0]], [[1.0], [0.0]])
    with pytest.raises(cp.UnstablePlantError, match="unstable"):
        cp.plant_from_statespace(bad, 1)
    # singular interface: rigid on rigid without mass
    with pytest.raises(cp.SingularInterfaceError, match="rigid on rigid without mass"):
        cp.assemble(cp.rigid_plant(0.0), [(cp.rigid_mass(0.0), None)])
    with pytest.raises(cp.SingularInterfaceError):
        cp.assemble(cp.rigid_plant(np.zeros((6, 6))), [(cp.wheel(p, 50.0, rigid=True), cp.Mount())])
    assert cp.assemble(cp.rigid_plant(0.0), [(cp.rigid_mass(2.0), None)]).sys.D[0, 0] == pytest.approx(0.5)
    # DCM not a rotation
    with pytest.raises(cp.NotARotationError, match="reflection"):
        cp.Mount(0, np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(cp.NotARotationError, match="orthonormal"):
        cp.Mount(0, 1.01 * np.eye(3))
    # no speeds (was numpy's "need at least one array to concatenate")
    with pytest.raises(cp.CouplingError, match="no speeds: give at least one wheel speed"):
        cp.jitter_vs_speed(plant6, _e_specs(1), np.array([]))


# ------------------------------------------------------------------ dask sweeps

def test_sweep_local_and_cluster_equal_serial():
    plant = cp.example_spacecraft()
    specs = _e_specs(2)
    speeds = np.linspace(0, 3000, 40) * RPM_TO_RAD_S
    serial = cp.jitter_vs_speed(plant, specs, speeds)
    sets = {"nominal": specs, "stiffer": [replace(s, params=replace(s.params, k_r=2 * s.params.k_r)) for s in specs]}
    local = cp.sweep(plant, sets, speeds, chunk=7)
    assert np.array_equal(local["nominal"].rms["ii"], serial.rms["ii"])
    assert np.array_equal(local["nominal"].omega, speeds)
    assert not np.allclose(local["stiffer"].rms["coupled"], serial.rms["coupled"], rtol=1e-6, atol=0)
    from distributed import LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as lc:
        remote = cp.sweep(plant, specs, speeds, chunk=10, address=lc.scheduler_address)
    assert np.array_equal(remote["wheels"].rms["coupled"], serial.rms["coupled"])


# ------------------------------------------------------------------ notebook

def test_example_notebook_executes(executed_notebook):
    nb, _ = executed_notebook          # examples/coupling_study.ipynb run once by a Jupyter kernel (conftest.py)
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors


def test_diagnosed_amplitude_law_reaches_the_coupled_prediction():
    """A model improved by diagnose (amplitude law on a radial-force harmonic) flows into the
    coupling kit: wheel_spec_from_model attaches the law, the free excitation of that line is
    A_ref·(|Ω|/Ω_ref)^p (= a harmonic with C rescaled to that amplitude at each speed, built by
    hand), the hard-mounted path still equals extended.steady_lines, other lines unchanged."""
    from rwadist.coupling.performance import wheel_spec_from_model
    model = preset("ithaco-e").to_model()
    model.effects = [{"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": 2.6,
                      "amplitude_ref": 0.003, "omega_ref_rad_s": 200.0}]
    spec = wheel_spec_from_model(model)
    law_lines = [ln for ln in spec.lines if ln.law is not None]
    assert [(ln.direction, ln.h) for ln in law_lines] == [("radial_force", 2.0)]
    plain = ext.lines_from_model(model, spec.params, effects=False)
    for rpm in (700.0, -2300.0):
        om = rpm * RPM_TO_RAD_S
        f, W = cp.free_lines(spec.params, spec.lines, om)
        f0, W0 = cp.free_lines(spec.params, plain, om)
        j = next(i for i, ln in enumerate(spec.lines) if ln.law is not None)
        target = 0.003 * (abs(om) / 200.0) ** 2.6
        by_hand = [replace(ln, C=target / om**2) if i == j else ln for i, ln in enumerate(plain)]
        _, Wh = cp.free_lines(spec.params, by_hand, om)
        assert np.allclose(W, Wh, rtol=1e-13, atol=0)
        assert np.allclose(np.delete(W, j, axis=1), np.delete(W0, j, axis=1), rtol=0, atol=0)
        assert abs(W[0, j, 0]) == pytest.approx(target, rel=1e-12)
        wc = cp.wheel(spec.params, om)
        _, B = wc.frf(f[0])
        _, ref = ext.steady_lines(spec.params, spec.lines, om)
        assert np.max(np.abs(np.einsum("lij,lj->li", B, W[0]) - ref[0])) < 1e-10 * np.max(np.abs(ref[0]))


#: a wheel-mode resonance on the radial force, sidebands on the imbalance and on a rocking line, and a
#: test-stand resonance (a fixture artefact: must not reach the prediction)
EFFECTS = [{"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 70.0, "zeta": 0.05, "peak_gain": 3.0,
            "directions": ["radial_force"]},
           {"kind": "fixed_resonance", "role": "test_stand", "f_Hz": 40.0, "zeta": 0.02, "peak_gain": 8.0,
            "directions": ["radial_force", "radial_torque", "axial_force", "axial_torque"]},
           {"kind": "sidebands", "direction": "radial_force", "h": 1.0, "f_mod_Hz": 6.0, "depth": 0.3},
           {"kind": "sidebands", "direction": "radial_torque", "h": 4.42, "f_mod_Hz": 9.0, "depth": 0.25}]


def test_diagnosed_resonance_and_sidebands_reach_the_coupled_prediction():
    """wheel_spec_from_model applies wheel-mode resonances and sidebands: each radial-force line's free
    excitation is the effect-free one times H(f) (rwadist.diagnose.resonance), each sideband is its
    carrier times m/2 (and H at its own frequency) at |hΩ/2π ± f_mod|; the hard-mounted path still
    equals extended.steady_lines; and the coupled prediction (line_responses on a flexible spacecraft)
    equals the one where every sideband is replaced, at that speed, by a plain harmonic of the same
    whirl rate h' = h ± 2πf_mod/Ω -- an independent route to the frequency the plant is evaluated at."""
    from rwadist.coupling.performance import wheel_spec_from_model
    from rwadist.diagnose import resonance
    model = preset("ithaco-e").to_model()
    model.effects = [dict(e) for e in EFFECTS]
    spec = wheel_spec_from_model(model)
    plain = ext.lines_from_model(model, spec.params, effects=False)
    n0 = len(plain)
    assert len(spec.lines) == n0 + 4
    plant = cp.example_spacecraft()
    for rpm in (1900.0, -2600.0):
        om = rpm * RPM_TO_RAD_S
        f, W = cp.free_lines(spec.params, spec.lines, om)
        f0, W0 = cp.free_lines(spec.params, plain, om)
        assert np.array_equal(f[:, :n0], f0)
        for j, ln in enumerate(plain):
            g = resonance(f0[0, j], 70.0, 0.05, 3.0) if ln.direction == "radial_force" else 1.0
            assert np.allclose(W[0, j], W0[0, j] * g, rtol=1e-13, atol=0)
        carriers = [next(j for j, ln in enumerate(plain) if ln.direction == d and ln.h == h)
                    for d, h in (("radial_force", 1.0), ("radial_force", 1.0), ("radial_torque", 4.42),
                                 ("radial_torque", 4.42))]
        for k, (j, sgn) in enumerate(zip(carriers, (1, -1, 1, -1))):
            e = EFFECTS[2] if k < 2 else EFFECTS[3]
            fs = abs(plain[j].h * om / (2 * np.pi) + sgn * e["f_mod_Hz"])
            assert f[0, n0 + k] == pytest.approx(fs, rel=1e-14)
            g = resonance(fs, 70.0, 0.05, 3.0) if k < 2 else 1.0
            expect = 0.5 * e["depth"] * np.abs(W0[0, j]) * abs(g)
            assert np.allclose(np.abs(W[0, n0 + k]), expect, rtol=1e-12, atol=0)
        wc = cp.wheel(spec.params, om)
        _, B = wc.frf(f[0])
        _, ref = ext.steady_lines(spec.params, spec.lines, om)
        assert np.max(np.abs(np.einsum("lij,lj->li", B, W[0]) - ref[0])) < 1e-10 * np.max(np.abs(ref[0]))
        # the coupled prediction vs sidebands rewritten as plain harmonics of the same whirl rate
        same = [replace(ln, h=ln.h + 2 * np.pi * ln.f_offset / om, f_offset=0.0, imbalance=False) if ln.f_offset
                else ln
                for ln in spec.lines]
        lr = cp.line_responses(plant, [spec], [om])
        lr2 = cp.line_responses(plant, [replace(spec, lines=tuple(same))], [om])
        assert np.sort(lr.f_hz[0][0]) == pytest.approx(np.sort(lr2.f_hz[0][0]), rel=1e-12)
        for p in ("coupled", "i", "ii", "iii"):
            assert lr.rms(p) == pytest.approx(lr2.rms(p), rel=1e-10)
        assert sorted(lr.f_offset[0]) == sorted([0.0] * (len(lr.h[0]) - 4) + [-9.0, -6.0, 6.0, 9.0])
