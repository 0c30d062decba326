"""The floor grid's poles without their eigen-decompositions (issue 37): a modal plant's poles in closed form and the
mass-loaded structure's from practice 'ii''s closed form are the eigenvalues of the state matrices they stand for,
and the grid built from them is the grid built from those decompositions."""
from dataclasses import replace

import numpy as np

from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.coupling import performance as perf
from rwadist.coupling import rigid_practice
from rwadist.presets import preset
from rwadist.units import RPM_TO_RAD_S


def _plant():
    plant = cp.random_modal_plant(n_modes=30, n_nodes=2, n_perf=2, f_range=(3.0, 600.0), seed=5)
    wn, z, Phi, Phip = plant.modal
    z = z.copy()
    z[6:] = np.linspace(0.004, 0.08, z.size - 6)
    z[-1] = 1.5                                    # an over-damped mode: two real poles, no oscillation
    return cp.modal_plant(wn / (2 * np.pi), z, Phi, Phip)


def _wheels():
    p = preset("ithaco-e").extended
    lines = (ext.Line("radial_force", 1.0, p.U_s),)
    fl = (cp.Floor(0, np.array([5.0, 300.0]), np.array([1e-4, 3e-5]), 200.0, 2.0),)
    return [cp.WheelSpec(p, lines, cp.Mount(0, cp.spin_axis_dcm((1, 0, 0)), (0.1, 0.0, 0.1)), housing_mass=2.0,
                         floors=fl),
            cp.WheelSpec(replace(p, height=0.04), lines, cp.Mount(1, cp.spin_axis_dcm((0, 1, 1)), (0.0, 0.1, 0.0)),
                         housing_mass=1.0, speed_scale=-0.8, floors=fl)]


def _oscillatory(lam):
    lam = np.asarray(lam)
    lam = lam[np.abs(lam.imag) > 1e-9 * np.abs(lam)]
    return np.sort_complex(lam)


def test_modal_poles_are_the_state_matrix_eigenvalues():
    plant = _plant()
    ref = _oscillatory(np.linalg.eigvals(np.asarray(plant.state_space().A)))
    got = _oscillatory(perf._modal_poles(plant))
    assert got.size == ref.size == 2 * (plant.modal[0].size - 7)          # 6 rigid and one over-damped mode out
    assert np.max(np.abs(got - ref) / np.abs(ref)) < 1e-12


def test_rigid_form_poles_are_the_mass_loaded_assembly_eigenvalues():
    from rwadist.coupling.assemble import Attachment, assemble
    from rwadist.coupling.components import rigid_mass, wheel_rigid_mass_matrix

    plant, wheels = _plant(), _wheels()
    _, _, Zm = perf._setup(plant, wheels, ("ii",), np.array([100.0]))
    form = rigid_practice.rigid_practice(plant, -Zm)
    rig = [Attachment(rigid_mass(wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia)), w.mount)
           for w in wheels]
    ref = _oscillatory(np.linalg.eigvals(np.asarray(assemble(plant, rig).sys.A)))
    got = _oscillatory(form.lam)
    assert got.size == ref.size
    assert np.max(np.abs(got - ref) / np.abs(ref)) < 1e-10


def test_the_grid_is_the_grid_of_the_decompositions():
    """floor_grid with the closed forms equals it with every pole from an eigen-decomposition (the plant handed over
    without its modal data, no rigid form)."""
    plant, wheels = _plant(), _wheels()
    om = np.linspace(300.0, 4000.0, 40) * RPM_TO_RAD_S
    _, _, Zm = perf._setup(plant, wheels, ("ii",), om)
    form = rigid_practice.rigid_practice(plant, -Zm)
    bare = cp.Plant("accelerance", plant.n_interface, plant.perf_names, sys=plant.sys)
    f_ref = perf.floor_grid(bare, wheels, om)
    f_got = perf.floor_grid(plant, wheels, om, rigid_form=form)
    assert f_got.size == f_ref.size > 100
    np.testing.assert_array_equal(f_got, f_ref)
    assert np.array_equal(perf.floor_grid(plant, wheels, om), f_ref)
