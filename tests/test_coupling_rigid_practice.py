"""Practice 'ii' in closed form (rwadist.coupling.rigid_practice) against the mass-loaded structure solved directly and
against the interface solve it replaces."""
import numpy as np

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.coupling import geometry, rigid_practice
from rwadist.coupling.components import wheel_rigid_mass_matrix
from rwadist.coupling.interface import _interface_matrix
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S


def _direct(plant, M_r, f):
    """y/X of the mass-loaded modal structure, (s²(I + ΦᵀM_rΦ) + sD + K)⁻¹ solved at each frequency: (F, n_perf, n_if)."""
    wn, zeta, Phi, Phip = plant.modal
    s = 2j * np.pi * f
    Mp = np.eye(wn.size) + Phi.T @ M_r @ Phi
    Z = s[:, None, None] ** 2 * Mp + s[:, None, None] * np.diag(2 * zeta * wn) + np.diag(wn**2)
    return Phip @ np.linalg.solve(Z, np.broadcast_to(Phi.T, (f.size,) + Phi.T.shape))


def _load_response(form, Mt, F, f):
    return form.outputs(f, [Mt], [F])[..., 0]


def test_rigid_body_and_one_mode_against_the_loaded_structure():
    """One rigid-body mode and one flexible mode, a 6x6 rigid mass on the interface: the closed form (rigid part split
    off, flexible part by its modes) equals the 2-DOF loaded structure solved at each frequency."""
    rng = np.random.default_rng(3)
    phi = rng.normal(scale=0.3, size=(6, 2))
    plant = cp.modal_plant([0.0, 40.0], [0.0, 0.03], phi, rng.normal(size=(1, 2)), ("y",))
    A = rng.normal(size=(6, 6))
    M_r = A @ A.T + 6 * np.eye(6)
    form = rigid_practice.rigid_practice(plant, M_r)
    assert form is not None and form.lam.size == 2          # the rigid mode split off, one flexible pair left
    f = np.geomspace(0.5, 500.0, 400)
    F = rng.normal(size=(f.size, 6)) + 1j * rng.normal(size=(f.size, 6))
    want = (_direct(plant, M_r, f) @ F[..., None])[..., 0]
    got = _load_response(form, np.eye(6), F, f)
    assert np.max(np.abs(got - want) / np.abs(want)) < 1e-11
    # the rigid body alone: y = Φ_p M'⁻¹ Φᵀ X / s²
    rigid_only = cp.modal_plant([0.0], [0.0], phi[:, :1], [[2.0]], ("y",))
    form0 = rigid_practice.rigid_practice(rigid_only, M_r)
    mass = 1.0 + phi[:, 0] @ M_r @ phi[:, 0]
    want0 = (2.0 * (F @ phi[:, 0]) / mass / (2j * np.pi * f) ** 2)[:, None]
    assert np.max(np.abs(_load_response(form0, np.eye(6), F, f) - want0) / np.abs(want0)) < 1e-13


def test_equals_the_interface_solve_with_wheels_on_a_free_free_plant():
    """A free-free plant (6 rigid-body modes, 40 flexible), two wheels' rigid masses on rotated, offset mounts: the
    closed form's outputs equal P·(I − Zm·G)⁻¹·Mtᵀ·F, the interface solve line_responses used before, to 1e-11 of each
    output's largest value; line_responses' practice 'ii' is unchanged to 1e-12 of its RMS."""
    plant = cp.random_modal_plant(n_modes=46, n_nodes=2, n_perf=2, f_range=(2.0, 800.0), zeta=0.02, seed=7)
    desc = preset("ithaco-e")
    lines = tuple(ext.lines_from_model(desc.to_model(), desc.extended))
    wheels = [cp.WheelSpec(desc.extended, lines, cp.Mount(i, cp.spin_axis_dcm(ax), (0.1, -0.05, 0.2)),
                           housing_mass=1.5, housing_inertia=(0.01, 0.01, 0.02))
              for i, ax in enumerate([(1, 0, 0), (0.3, 1, 0.2)])]
    Mts = [geometry.selector(w.mount, 6, plant.n_interface) for w in wheels]
    M6s = [wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia) for w in wheels]
    M_r = sum(Mt.T @ M6 @ Mt for Mt, M6 in zip(Mts, M6s))
    form = rigid_practice.rigid_practice(plant, M_r)
    assert form is not None
    rng = np.random.default_rng(5)
    f = np.concatenate([rng.uniform(0.2, 900.0, 500), np.geomspace(0.05, 3000.0, 200)])
    G, P = plant.frf(f)
    L = _interface_matrix(G, [(Mt, -M6) for Mt, M6 in zip(Mts, M6s)])
    for Mt in Mts:
        F = rng.normal(size=(f.size, 6)) + 1j * rng.normal(size=(f.size, 6))
        want = (P @ np.linalg.solve(L, (Mt.T @ F[..., None])))[..., 0]
        got = _load_response(form, Mt, F, f)
        assert np.max(np.abs(got - want) / np.max(np.abs(want), axis=0)) < 1e-11
    speeds = np.linspace(300.0, 3000.0, 7) * RPM_TO_RAD_S
    new = cp.line_responses(plant, wheels, speeds, practices=("coupled", "ii"))
    before = rigid_practice.rigid_practice
    try:
        rigid_practice.rigid_practice = lambda *a: None          # the interface solve
        old = cp.line_responses(plant, wheels, speeds, practices=("coupled", "ii"))
    finally:
        rigid_practice.rigid_practice = before
    assert np.max(np.abs(new.rms("ii") - old.rms("ii")) / old.rms("ii")) < 1e-12
    assert np.array_equal(new.rms("coupled"), old.rms("coupled"))


def test_falls_back_without_modal_data_or_with_defective_modes():
    """No modal data (a StateSpace plant) or a flexible mode at critical damping (a defective pair): no closed form,
    line_responses keeps the interface solve."""
    plant = cp.random_modal_plant(n_modes=12, n_nodes=1, n_perf=1, seed=2)
    ss_plant = cp.plant_from_statespace(plant.sys, plant.n_interface)
    assert rigid_practice.rigid_practice(ss_plant, np.eye(6)) is None
    crit = cp.modal_plant([10.0, 25.0], [1.0, 0.02], np.eye(6)[:, :2], np.ones((1, 2)))
    assert rigid_practice.rigid_practice(crit, np.zeros((6, 6))) is None


def test_a_plant_too_large_for_one_decomposition_keeps_the_solve():
    """More than MAX_STATES flexible states: no closed form (its O(n³) decomposition and O(n) product per point would
    cost more than the interface solves)."""
    n = rigid_practice.MAX_STATES // 2 + 1
    plant = cp.modal_plant(np.geomspace(1.0, 900.0, n), 0.02, np.ones((6, n)) * 1e-3, np.ones((1, n)))
    assert rigid_practice.rigid_practice(plant, np.eye(6)) is None
