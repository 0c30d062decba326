"""Fitting the extended model: round trip on data generated from known parameters.

Fast test: data made here with numpy from extended.steady_lines (random line phases per
run, imbalances sharing one phase).  The slow acceptance test uses the virtual test stand.
"""
from dataclasses import replace

import numpy as np
import pytest

from rwadist import extended as ext
from rwadist.data import Run, SteadyTest
from rwadist.empirical import fit_empirical
from rwadist.extended_fit import fit_extended, line_senses, rms_comparison, to_model
from rwadist.spectra import compute_spectra
from rwadist.units import rpm_to_rad_s

TRUE = replace(ext.from_table_4_2(), height=0.0)
HARMONICS = [("radial_force", 2.0, 7.6e-7, "counter"), ("radial_force", 3.0, 5.0e-7, "co"),
             ("radial_torque", 2.0, 5.5e-7, "counter"), ("radial_torque", 3.0, 2.2e-7, "co"),
             ("axial_force", 1.0, 2.8e-6, "co"), ("axial_force", 1.98, 2.6e-6, "co")]


def make_data(params, speeds_rpm, fs=1920.0, n=4096, noise=0.01, seed=0, harmonics=HARMONICS):
    rng = np.random.default_rng(seed)
    lines = ext.imbalance_lines(params) + [ext.Line(d, h, c, s) for d, h, c, s in harmonics]
    w = rpm_to_rad_s(np.asarray(speeds_rpm, float))
    f, A = ext.steady_lines(params, lines, w)
    t = np.arange(n) / fs
    std_f, std_t = noise * params.U_s * w.max() ** 2, noise * params.U_d * w.max() ** 2
    runs = []
    for i in range(w.size):
        ph = rng.uniform(0, 2 * np.pi, len(lines))
        ph[1] = ph[0]  # static and dynamic imbalance are fixed on one rotor
        sig = np.real(np.einsum("lc,ln->cn", A[i], np.exp(1j * (2 * np.pi * f[i][:, None] * t + ph[:, None]))))
        chans = {c: sig[k] + (std_f if k < 3 else std_t) * rng.standard_normal(n)
                 for k, c in enumerate(("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))}
        runs.append(Run(float(w[i]), fs, chans, name=f"r{i:03d}.csv"))
    return SteadyTest(runs)


@pytest.fixture(scope="module")
def fitted():
    test = make_data(TRUE, np.linspace(600, 2400, 50))
    fit = fit_empirical(compute_spectra(test))
    return test, fit, fit_extended(test, fit, TRUE.mass, 0.1965)


def test_round_trip_recovers_parameters(fitted):
    _, _, ef = fitted
    p = ef.params
    assert p.k_rock == pytest.approx(TRUE.k_rock, rel=0.02)
    assert p.k_z == pytest.approx(TRUE.k_z, rel=0.02)
    assert p.U_s == pytest.approx(TRUE.U_s, rel=0.05)
    assert p.U_d == pytest.approx(TRUE.U_d, rel=0.05)
    assert ef.zeta["rocking"] == pytest.approx(TRUE.zeta_rock, rel=0.2)
    assert ef.zeta["axial_translation"] == pytest.approx(TRUE.zeta_z, rel=0.2)
    # radial translation (227.7 Hz, ζ = 0.17) is above every line, but its wide skirt lifts the
    # h = 3 force line by ~30 % at the top speed: enough to place it
    assert p.k_r == pytest.approx(TRUE.k_r, rel=0.02)
    assert ef.rel_stderr["k_r"] < 0.05


def test_senses_from_xy_phase(fitted):
    test, fit, ef = fitted
    s = {(d, round(h, 2)): v[0] for (d, h), v in ef.senses.items()}
    assert s[("radial_force", 2.0)] == "counter" and s[("radial_torque", 2.0)] == "counter"
    assert s[("radial_force", 1.0)] == "co" and s[("radial_torque", 3.0)] == "co"
    # the same data run backwards (negative speeds, mirrored y) keep the senses relative to the spin
    mirrored = SteadyTest([Run(-r.speed, r.sample_rate, {**r.signals, "Fy": -r.signals["Fy"], "Ty": -r.signals["Ty"]},
                               name=r.name) for r in test.runs])
    s2 = {(d, round(h, 2)): v[0] for (d, h), v in line_senses(mirrored, fit).items()}
    assert s2 == {k: v for k, v in s.items() if k in s2}


def test_extended_model_beats_empirical_where_modes_act(fitted):
    _, fit, ef = fitted
    cmp = rms_comparison(ef, fit)
    for d in ("radial_torque", "axial_force"):
        assert cmp[d]["error_extended"] * 3 <= cmp[d]["error_empirical"], (d, cmp[d]["error_extended"],
                                                                            cmp[d]["error_empirical"])


def test_model_file_carries_analytical_section(fitted, tmp_path):
    from rwadist import model as model_io

    _, fit, ef = fitted
    m = model_io.load(model_io.save(to_model(ef, fit), tmp_path / "m.json"))
    p = ext.params_from_model(m)
    assert p.k_rock == pytest.approx(ef.params.k_rock)
    assert {h.sense for h in m.harmonics("radial_force")} >= {"co", "counter"}


def test_harmonics_count_the_measurements_they_were_fitted_to(fitted):
    """Every line of the data stands far above the noise at all 50 speeds: a radial line is measured on its x and
    y channel at each (100 points), an axial line on Fz (50); the extended fit wrote n_points 0 for every line."""
    _, fit, ef = fitted
    m = to_model(ef, fit)
    for d in ("radial_force", "radial_torque"):
        assert [x.n_points for x in m.harmonics(d)] == [100, 100, 100]
    assert [x.n_points for x in m.harmonics("axial_force")] == [50, 50]
