"""Diagnosed effects in a model file flow into the broadband PSD (Parseval against quadrature)."""
import numpy as np
import pytest
from scipy import integrate

from rwadist.broadband import Uniform, broadband_psd, empirical_lines
from rwadist.model import Harmonic, WheelModel
from rwadist.units import rpm_to_rad_s

LAW = Uniform(float(rpm_to_rad_s(600.0)), float(rpm_to_rad_s(3000.0)))
W_REF = float(rpm_to_rad_s(1800.0))


def _model(effects):
    m = WheelModel(name="t")
    m.empirical["radial_force"] = [Harmonic(2.0, 1.0e-6, sense="co")]
    m.effects = effects
    return m


def _mean(fn):
    val, _ = integrate.quad(lambda w: fn(w) * LAW.pdf(w), LAW.lo, LAW.hi, limit=200)
    return val


def test_amplitude_law_changes_the_psd_as_quadrature_says():
    a_ref, p = 1.0e-6 * W_REF**2, 2.5
    m = _model([{"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": p,
                 "amplitude_ref": a_ref, "omega_ref_rad_s": W_REF}])
    res = broadband_psd(empirical_lines(m), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    ms = np.sum(res.psd[:, 0]) * (res.f[1] - res.f[0])
    expected = _mean(lambda w: (a_ref * (abs(w) / W_REF) ** p) ** 2 / 2)
    assert ms == pytest.approx(expected, rel=5e-3)
    plain = broadband_psd(empirical_lines(_model([])), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    assert abs(np.sum(plain.psd[:, 0]) * (plain.f[1] - plain.f[0]) / expected - 1) > 0.02   # the law matters


def test_broadband_floor_adds_its_speed_averaged_power():
    f_k = np.linspace(0.0, 150.0, 31)
    psd_k = 1e-6 * (1 + f_k / 150.0)
    floor = {"kind": "broadband_floor", "channel": ["Fx"], "exponent": 3.0, "omega_ref_rad_s": W_REF,
             "f_Hz": f_k.tolist(), "psd_ref": psd_k.tolist()}
    with_floor = broadband_psd(empirical_lines(_model([floor])), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    without = broadband_psd(empirical_lines(_model([])), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    df = with_floor.f[1] - with_floor.f[0]
    added = np.sum(with_floor.psd[:, 0] - without.psd[:, 0]) * df
    expected = _mean(lambda w: (abs(w) / W_REF) ** 3) * np.trapezoid(psd_k, f_k)
    assert added == pytest.approx(expected, rel=2e-3)
    np.testing.assert_allclose(with_floor.psd[:, 1], without.psd[:, 1])    # only Fx carries it


def test_wheel_mode_resonance_enters_the_psd_test_stand_does_not():
    from rwadist.diagnose import resonance

    res_e = {"kind": "fixed_resonance", "f_Hz": 80.0, "zeta": 0.05, "peak_gain": 4.0, "role": "wheel_mode",
             "directions": ["radial_force"]}
    m = _model([res_e])
    res = broadband_psd(empirical_lines(m), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    ms = np.sum(res.psd[:, 0]) * (res.f[1] - res.f[0])
    expected = _mean(lambda w: abs(1.0e-6 * w**2 * resonance(2 * abs(w) / (2 * np.pi), 80.0, 0.05, 4.0)) ** 2 / 2)
    assert ms == pytest.approx(expected, rel=5e-3)
    stand = dict(res_e, role="test_stand")
    coupling = {"kind": "cross_coupling", "r_m": [0.0, 0.0, 0.05]}
    plain = broadband_psd(empirical_lines(_model([])), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    artefacts = broadband_psd(empirical_lines(_model([stand, coupling])), LAW, f_max=150.0, n_freq=30001,
                              n_speeds=4000)
    np.testing.assert_allclose(artefacts.psd, plain.psd)


def test_sidebands_sit_at_the_carrier_plus_minus_f_mod():
    """At (nearly) one speed the sidebands of the h = 2 line appear at 2f₁ ± f_mod with (m/2)² of the
    carrier's power each, and nothing else moves (bin sums over ±0.5 Hz windows)."""
    rpm = 1500.0
    law = Uniform(float(rpm_to_rad_s(rpm - 0.5)), float(rpm_to_rad_s(rpm + 0.5)))
    sb = {"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 7.0, "depth": 0.4}
    res = broadband_psd(empirical_lines(_model([sb])), law, f_max=120.0, n_freq=24001, n_speeds=64)
    plain = broadband_psd(empirical_lines(_model([])), law, f_max=120.0, n_freq=24001, n_speeds=64)
    df = res.f[1] - res.f[0]
    f2 = 2.0 * rpm / 60.0

    def window(r, fc):
        sel = np.abs(r.f - fc) <= 0.5
        return r.psd[sel, 0].sum() * df

    carrier = window(plain, f2)
    assert carrier > 0
    assert window(res, f2) == pytest.approx(carrier, rel=1e-9)
    for fc in (f2 + 7.0, f2 - 7.0):
        assert window(plain, fc) < 1e-12 * carrier
        assert window(res, fc) == pytest.approx(0.2**2 * carrier, rel=1e-6)
