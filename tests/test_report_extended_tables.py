"""The extended fit's tables (docs/formats.md section 6; docs review): extended_rms_vs_speed.csv names its units and
its noise-floor convention in the columns and keeps the speed's sign; extended_params.csv gives a relative standard
error wherever the fit has one (the imbalances' from their lines) and none where the least squares did not move the
parameter (a held damping's error read 0)."""
from __future__ import annotations

import csv
from types import SimpleNamespace

import numpy as np
import pytest

import rwadist
from rwadist.extended import Line
from rwadist.extended_fit import rms_comparison
from rwadist.report_extended import param_rel_stderr, write_extended_report
from rwadist.units import RAD_S_TO_RPM


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def negative_spin(tmp_path_factory):
    """The smallest extended fit on a wheel spinning about −z (negative speeds), its report's two tables."""
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=-np.linspace(600, 2400, 6), n_samples=1024, seed=1)
    fit = rwadist.fit(test)
    efit, model = rwadist.fit_extended(test, fit)
    out = tmp_path_factory.mktemp("ext")
    write_extended_report(efit, fit, out, model=model)
    return fit, efit, out


def test_rms_table_keeps_the_sign_and_names_units_and_floor(negative_spin):
    fit, efit, out = negative_spin
    rows = _rows(out / "extended_rms_vs_speed.csv")
    assert list(rows[0]) == ["speed_rpm"] + [f"{kind}_{ch}_rms_{u}" if kind != "modes_act" else f"modes_act_{d}"
                                             for ch, u, d in (("Fx", "N", "radial_force"), ("Tx", "Nm", "radial_torque"),
                                                              ("Fz", "N", "axial_force"))
                                             for kind in ("data_floor_removed", "empirical", "extended", "modes_act")]
    sp = fit.spectra
    spin = np.abs(sp.speed) > 0
    np.testing.assert_array_equal([float(r["speed_rpm"]) for r in rows], sp.speed[spin] * RAD_S_TO_RPM)
    assert all(float(r["speed_rpm"]) < 0 for r in rows)
    comparison = rms_comparison(efit, fit)
    for d, ch, u in (("radial_force", "Fx", "N"), ("radial_torque", "Tx", "Nm"), ("axial_force", "Fz", "N")):
        c = comparison[d]
        np.testing.assert_array_equal([float(r[f"data_floor_removed_{ch}_rms_{u}"]) for r in rows], c["data"])
        np.testing.assert_array_equal([float(r[f"extended_{ch}_rms_{u}"]) for r in rows], c["extended"])
        assert [r[f"modes_act_{d}"] for r in rows] == ["true" if m else "false" for m in c["in_modes"]]


def test_params_give_the_imbalances_their_lines_errors(negative_spin):
    _, efit, out = negative_spin
    rows = {r["parameter"]: r["rel_stderr"] for r in _rows(out / "extended_params.csv")}
    for name, direction in (("U_s_kg_m", "radial_force"), ("U_d_kg_m2", "radial_torque")):
        (line,) = [ln for ln in efit.lines if ln.imbalance and ln.direction == direction]
        assert float(rows[name]) == efit.rel_stderr[f"C[{direction},{line.h:g},{line.sense}]"] > 0
    for name in ("mass_kg", "I_zz_kg_m2", "I_rr_kg_m2", "height_m"):
        assert rows[name] == ""
    # this small fit locates no mode: no stiffness or damping has an error
    assert set(efit.unconstrained) == {"radial_translation", "rocking", "axial"}
    assert all(rows[k] == "" for k in rows if k.startswith(("k_", "c_")))


def test_rel_stderr_where_the_least_squares_estimates_it():
    """A free mode's stiffness and damping keep theirs; a held damping's 0 (its Jacobian column zero) and rounding's
    1e-18 are no errors; a parameter the least squares has not: NaN."""
    efit = SimpleNamespace(rel_stderr={"k_r": 0.004, "c_r": 0.12, "k_rock": 0.01, "c_rock": 0.0, "k_z": 0.02,
                                       "c_z": 3.5e-18, "C[radial_force,1,co]": 0.05},
                           zeta_bounds={"rocking": (0.001, 0.2)},
                           lines=[Line("radial_force", 1.0, 1e-6, "co", imbalance=True),
                                  Line("radial_force", 2.0, 1e-7, "co")])
    got = {n: param_rel_stderr(efit, n) for n in ("k_r", "c_r", "k_rock", "c_rock", "k_z", "c_z", "U_s", "U_d",
                                                  "mass", "I_zz", "height")}
    assert {n: v for n, v in got.items() if np.isfinite(v)} == {"k_r": 0.004, "c_r": 0.12, "k_rock": 0.01,
                                                                "k_z": 0.02, "U_s": 0.05}
