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


def test_a_wheel_mode_keeping_part_of_the_load_above_enters_the_extended_psd():
    """A wheel_mode ``fixed_resonance`` with ``gain_above`` < 1 (what diagnose writes for a mode holding a share of
    the load above it) on an extended model: the PSD's mean square (Parseval) is the quadrature over the speed law of
    the axial line C·Ω² through the axial mode's transmissibility |(k + icν)/(k − Mν² + icν)|² and the model file's
    gain law H = (1 − a·r² + 2j·c·ζ·r)/(1 − r² + 2jζr), c = √((2ζP)² − (1 − a)²)/(2ζ), written out here.  `rwadist psd`
    stopped with an internal error on such a model (trial26's rattle: a 4-tuple unpacked from a 5-tuple)."""
    from rwadist import extended as ext
    from rwadist.broadband import extended_lines_from_model

    C, h, f_r, zeta, peak, above = 2e-6, 2.0, 90.0, 0.05, 4.0, 0.6
    m = WheelModel(name="one", empirical={"radial_force": [], "radial_torque": [], "axial_torque": [],
                                          "axial_force": [Harmonic(h=h, C=C)]},
                   analytical=ext.params_to_dict(ext.from_table_4_2()))
    m.effects = [{"kind": "fixed_resonance", "f_Hz": f_r, "zeta": zeta, "peak_gain": peak, "gain_above": above,
                  "role": "wheel_mode", "directions": ["axial_force"]}]
    res = broadband_psd(extended_lines_from_model(m), LAW, f_max=150.0, n_freq=30001, n_speeds=4000)
    p = ext.from_table_4_2()
    c = np.sqrt((2 * zeta * peak) ** 2 - (1 - above) ** 2) / (2 * zeta)

    def line_ms(w, resonance=True):
        nu = h * abs(w)
        r = nu / (2 * np.pi * f_r)
        gain = (1 - above * r**2 + 2j * c * zeta * r) / (1 - r**2 + 2j * zeta * r)
        trans = (p.k_z + 1j * p.c_z * nu) / (p.k_z - p.mass * nu**2 + 1j * p.c_z * nu)
        return abs(C * w**2 * trans * (gain if resonance else 1.0)) ** 2 / 2

    ms = np.sum(res.psd[:, 2]) * (res.f[1] - res.f[0])
    assert ms == pytest.approx(_mean(line_ms), rel=5e-3)
    assert abs(_mean(line_ms) / _mean(lambda w: line_ms(w, resonance=False)) - 1) > 0.1      # the resonance matters
