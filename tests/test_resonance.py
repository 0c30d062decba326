"""The resonance gain H(r) has one home, rwadist.resonance; the FMU runtime keeps a self-contained copy.

Checked against the closed form written out here, and every user pinned to the home numerically."""
import numpy as np
import pytest

from rwadist import extended as ext
from rwadist import model as model_io
from rwadist.presets import preset
from rwadist.resonance import resonance, resonance_gain, resonance_response
from rwadist.teststand import Mode

RESONANCES = [(47.0, 0.03, 4.0), (130.0, 0.1, 0.4)]      # (f_r Hz, zeta, peak gain): a peak and a notch


def closed_form(f_hz, f_r, zeta, g):
    """(1 - r² + 2j g ζ r)/(1 - r² + 2j ζ r), r = f/f_r, each term written out."""
    r = np.asarray(f_hz, dtype=float) / f_r
    return (1.0 - r**2 + 2j * g * zeta * r) / (1.0 - r**2 + 2j * zeta * r)


def test_closed_form_and_its_landmarks():
    f = np.linspace(-400.0, 400.0, 1601)
    for f_r, zeta, g in RESONANCES:
        assert np.allclose(resonance(f, f_r, zeta, g), closed_form(np.abs(f), f_r, zeta, g), rtol=1e-13, atol=0)
        assert abs(abs(resonance(f_r, f_r, zeta, g)) - g) < 1e-12          # |H(f_r)| = g
        assert abs(resonance(0.0, f_r, zeta, g) - 1.0) < 1e-15              # H(0) = 1
        assert abs(resonance(1e3 * f_r, f_r, zeta, g) - 1.0) < 1e-3 * g      # H -> 1 far above
    r = np.linspace(-3.0, 3.0, 601)
    assert np.allclose(resonance_response(-r, 0.05, 3.0), np.conj(resonance_response(r, 0.05, 3.0)), rtol=1e-14)


def test_signed_product_is_the_product_of_single_gains():
    nu = 2 * np.pi * np.linspace(-300.0, 300.0, 1201)                       # rad/s, signed
    want = np.ones(nu.size, complex)
    for f_r, zeta, g in RESONANCES:
        h = closed_form(np.abs(nu) / (2 * np.pi), f_r, zeta, g)
        want *= np.where(nu < 0, np.conj(h), h)
    assert np.allclose(resonance_gain(nu, RESONANCES), want, rtol=1e-13, atol=0)
    assert ext.resonance_gain is resonance_gain
    assert np.array_equal(resonance_gain(nu, []), np.ones(nu.size))


def test_teststand_mode_uses_the_home():
    m = Mode("fixture", 80.0, 0.04, 6.0, ("Fx",))
    f = np.linspace(0.0, 300.0, 301)
    assert np.array_equal(m.gain(f, 100.0), resonance(f, 80.0, 0.04, 6.0))


@pytest.mark.parametrize("rpm", [1500.0, -900.0])
def test_fmu_runtime_copy_matches_the_home(rpm):
    """rwadist/fmu/runtime.py applies H inline (self-contained for hosts): each component's amplitude with the
    resonances over the one without is resonance_gain at its whirl rate ν = σhΩ + ω_off, to 1e-12."""
    from rwadist.fmu.runtime import WheelRuntime, model_from_doc

    params, lines = model_from_doc(model_io.to_json(preset("ithaco-e").to_model()))
    dirs = ("radial_force", "radial_torque", "axial_force", "axial_torque")
    res = [(dirs, f_r, z, g) for f_r, z, g in RESONANCES]
    sidebands = [("radial_force", 2.0, 7.5, 0.3)]                          # components with an offset too
    plain = WheelRuntime(params, lines, sidebands=sidebands)
    shaped = WheelRuntime(params, lines, sidebands=sidebands, resonances=res)
    assert np.any(shaped.woff != 0.0)
    w = rpm * np.pi / 30.0
    ratio = shaped._amp(w, 0.0) / plain._amp(w, 0.0)
    want = resonance_gain(shaped.sh * w + shaped.woff, RESONANCES)
    assert np.allclose(ratio, want, rtol=1e-12, atol=0)
