"""The floors' coupled responses factorised once per frequency (coupling.gyro_split: the speed enters a wheel's
dynamic mass only through its rank-2 gyroscopic term) are the direct solves of the interface equation at every
speed and frequency, for flexible and hard-mounted wheels, reversed and scaled speeds, practices 'coupled' and
'iii'."""
from dataclasses import replace

import numpy as np

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.coupling import performance as perf
from rwadist.coupling.gyro_split import gyro_gain, wheel_split
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S


def _wheels():
    p = replace(preset("ithaco-e").extended, height=0.05)
    lines = (ext.Line("radial_force", 1.0, p.U_s),)
    fk = np.array([2.0, 400.0])
    m = [cp.Mount(i % 2, cp.spin_axis_dcm(ax), r) for i, (ax, r) in enumerate(
        [((0.3, 1, 0.2), (0.4, -0.2, 0.3)), ((1, 0, 0.5), (-0.3, 0.1, -0.2)), ((0, 0.2, 1), (0.1, 0.1, 0.0))])]
    return [cp.WheelSpec(p, lines, m[0], housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03),
                         floors=(cp.Floor(0, fk, np.array([1e-4, 3e-5]), 200.0, 2.0),)),
            cp.WheelSpec(p, lines, m[1], housing_mass=1.5, speed_scale=-0.7,
                         floors=(cp.Floor(4, fk, np.array([1e-6, 1e-6]), 200.0, 0.0),)),
            cp.WheelSpec(p, lines, m[2], housing_mass=1.0, hard_mounted=True,
                         floors=(cp.Floor(2, fk, np.array([2e-5, 1e-5]), 200.0, 1.0),))]


def _direct(plant, wheels, om, f, practice):
    """P·Lc⁻¹·(loads) by assembling Lc at every (speed, frequency) and solving it (the method before issue 37)."""
    _, Mts, _ = perf._setup(plant, wheels, ("coupled",), om)
    cols = [(k, c) for k, w in enumerate(wheels) for c in sorted({fl.channel for fl in w.floors})]
    G, P = plant.frf(f)
    fe = np.broadcast_to(f, (om.size, f.size))
    parts, Bs = [], []
    for w, Mt in zip(wheels, Mts):
        Zc, Bw = perf._wheel_frf(w, om * w.speed_scale, fe)
        parts.append((Mt, Zc))
        Bs.append(Bw)
    Lc = perf._interface_matrix(G, parts)
    if practice == "coupled":
        R = np.stack([Mts[k].T[:, c] for k, c in cols], axis=1)
        X = np.broadcast_to(R, Lc.shape[:-2] + R.shape)
    else:
        X = np.stack([np.einsum("jn,sfj->sfn", Mts[k], Bs[k][..., :, c]) for k, c in cols], axis=-1)
    return P @ np.linalg.solve(Lc, X)


def _solver_case():
    """The floor solver's test case: a 30-mode plant, the test wheels, four speeds (both senses and rest), 301
    frequencies; the wheels' interface rows, the floor columns, their right-hand sides and the plant FRF."""
    plant = cp.random_modal_plant(n_modes=30, n_nodes=2, n_perf=2, seed=4)
    wheels = _wheels()
    om = np.array([-2500.0, 0.0, 300.0, 3000.0]) * RPM_TO_RAD_S
    f = np.geomspace(2.0, 400.0, 301)
    _, Mts, _ = perf._setup(plant, wheels, ("coupled",), om)
    cols = [(k, c) for k, w in enumerate(wheels) for c in sorted({fl.channel for fl in w.floors})]
    R = np.stack([Mts[k].T[:, c] for k, c in cols], axis=1)
    G, P = plant.frf(f)
    return plant, wheels, om, f, Mts, cols, R, G, P


def test_woodbury_split_is_the_direct_solve():
    plant, wheels, om, f, Mts, cols, R, G, P = _solver_case()
    from rwadist.coupling.gyro_split import FloorSolver

    solver = FloorSolver(G, P, Mts, [wheel_split(w, f) for w in wheels], R, cols)
    got = solver.solve(solver.gains([om * w.speed_scale for w in wheels]), ("coupled", "iii"))
    for practice in ("coupled", "iii"):
        ref = _direct(plant, wheels, om, f, practice)
        err = np.abs(got[practice] - ref).max() / np.abs(ref).max()
        assert err < 1e-10, (practice, err)


def test_split_dynamic_mass_is_the_wheels():
    """Zc0 + a·K·b = the wheel's dynamic mass at each speed (flexible: modal form; hard-mounted: rigid_wheel_frf)."""
    f = np.geomspace(1.0, 500.0, 97)
    for w in _wheels():
        sp = wheel_split(w, f)
        om = np.array([-3000.0, 1200.0]) * RPM_TO_RAD_S
        K = gyro_gain(sp, om)
        Zc = sp["Zc0"][None] + sp["a"][None] @ K @ sp["b"][None]
        B = sp["B0"][None] + sp["a"][None] @ K @ sp["bw"][None]
        Zr, Br = perf._wheel_frf(w, om, np.broadcast_to(f, (2, f.size)))
        assert np.abs(Zc - Zr).max() <= 1e-10 * np.abs(Zr).max()
        assert np.abs(B - Br).max() <= 1e-10 * np.abs(Br).max()


def test_eigen_sum_over_speeds_is_the_direct_solve():
    """FloorSolver.responses (one eigen-decomposition of H = Γ(Q + Y) per frequency, a sum over its eigenvalues per
    speed) gives the direct solves' numbers for flexible, reversed/scaled and hard-mounted wheels, and so does its
    per-speed fallback where the eigenvectors are ill-conditioned (forced here)."""
    from rwadist.coupling import gyro_split

    plant, wheels, om, f, Mts, cols, R, G, P = _solver_case()
    scales = [w.speed_scale for w in wheels]
    for cond in (gyro_split.EIG_COND, 0.0):
        gyro_split.EIG_COND, keep = cond, gyro_split.EIG_COND
        try:
            solver = gyro_split.FloorSolver(G, P, Mts, [wheel_split(w, f) for w in wheels], R, cols)
            got = solver.responses(om, scales, ("coupled", "iii"))
        finally:
            gyro_split.EIG_COND = keep
        for practice in ("coupled", "iii"):
            ref = _direct(plant, wheels, om, f, practice)
            err = np.abs(got[practice] - ref).max() / np.abs(ref).max()
            assert err < 1e-10, (cond, practice, err)
