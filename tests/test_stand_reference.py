"""The reference fit (``rwadist fit --extended``) of a wheel on a resonant test stand.

A fixture resonance acting on every channel is fitted beside the wheel's suspension modes
(:func:`rwadist.stand_resonance.fit_extended_beside_stand`) and divided out of every line amplitude by
|H(f)| at the line's frequency.  Two checks, against references independent of the fit:

* the virtual stand applies the fixture resonance the way the fit assumes: each channel's complex line
  amplitude multiplied by H(h|Ω|/2π) (closed form, :func:`rwadist.resonance.resonance`), read from noiseless
  records by least squares on the known line frequencies;
* the stand and the radial translation's mode, coupled near each other (180 Hz stand, 228 Hz mode), are both
  fitted to their truth: the injected stand (f, ζ, peak gain written into the data by :mod:`rwadist.inject`)
  and the thesis's wheel E translation (tests/independent_wheel.py, typed, not read from rwadist).  A stand
  left 2 % weak made the translation 0.4-0.6 % low (and the lines above the stand 1-3 % off in the model
  path of the robustness matrix).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.extended import steady_lines  # noqa: E402
from rwadist.inject import parse, prepare_wheel, simulate_with_injections  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.resonance import resonance  # noqa: E402
from rwadist.teststand import simulate_steady  # noqa: E402
from rwadist.units import CHANNELS  # noqa: E402

STAND = "fixed_resonance:f_hz=180,zeta=0.03,gain=5,role=test_stand"


def _line_amplitudes(run, freqs):
    """Complex amplitude A of each channel's Re(A e^{2πjft}) at every frequency of ``freqs`` (Hz), least squares
    on the run's record: (n_freqs, 6)."""
    t = np.arange(run.n_samples) / run.sample_rate + run.t0
    basis = np.hstack([np.cos(2 * np.pi * np.outer(t, freqs)), -np.sin(2 * np.pi * np.outer(t, freqs))])
    y = np.column_stack([run.signals[c] for c in CHANNELS])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    n = len(freqs)
    return coef[:n] + 1j * coef[n:]


def test_virtual_stand_multiplies_each_channel_line_by_the_resonance_the_fit_divides_out():
    """Noiseless runs with and without the injected stand: each channel's line amplitude ratio is H(f) of the
    resonance the fit divides out (same f_r, ζ, g; f = the line's frequency), to 1e-6."""
    spec = parse(STAND)
    wheel = prepare_wheel(preset("ithaco-e"), [spec], "extended")
    speeds = np.array([1500.0, 2700.0])       # 2700 rpm: h = 4 at 180 Hz, on the stand's peak
    kw = dict(sample_rate=1920.0, n_samples=4096, noise=0.0, seed=3, physics="extended")
    on = simulate_steady(wheel, speeds, test_stand=True, **kw)
    off = simulate_steady(wheel, speeds, test_stand=False, **kw)
    checked = 0
    for run_on, run_off in zip(on.runs, off.runs):
        f, _ = steady_lines(wheel.extended, wheel.extended_lines(), [run_on.speed])
        freqs = np.unique(np.round(f[0][(f[0] > 0) & (f[0] < 0.45 * run_on.sample_rate)], 9))
        a_on, a_off = _line_amplitudes(run_on, freqs), _line_amplitudes(run_off, freqs)
        h = resonance(freqs, spec["f_hz"], spec["zeta"], spec["gain"])
        strong = np.abs(a_off) > 1e-6 * np.abs(a_off).max()
        ratio = np.where(strong, a_on / np.where(strong, a_off, 1.0), np.nan)
        err = np.abs(ratio - h[:, None])[strong] / np.abs(np.broadcast_to(h[:, None], ratio.shape)[strong])
        assert err.max() < 1e-6
        checked += int(strong.sum())
    assert checked >= 12
    assert np.abs(resonance([180.0], spec["f_hz"], spec["zeta"], spec["gain"]))[0] == pytest.approx(5.0)


def test_reference_fit_beside_a_stand_settles_the_stand_and_the_translation():
    """E wheel, 20 speeds 300-3000 rpm, stand 180 Hz ζ 0.03 gain 5 on all six channels: the fitted stand within
    1 % (peak gain) and 1.5 % (ζ) of the injection, f_r within 0.1 %, and the radial translation within 0.2 % of
    the thesis's, as without a stand (before the stand's rounds were run to convergence: gain -2.4 %, ζ -2.7 %,
    translation -0.6 %)."""
    wheel = preset("ithaco-e")
    test = simulate_with_injections(wheel, [parse(STAND)], np.linspace(300.0, 3000.0, 20), physics="extended",
                                    sample_rate=1920.0, n_samples=4096, noise=0.01, seed=1)
    (inj,) = [x for x in test.meta["injected"] if x["kind"] == "fixed_resonance"]
    efit, model = api.fit_extended(test, mass=wheel.mass_kg, radius=wheel.radius_m)
    assert efit.stand is not None
    f_r, zeta, gain, above = efit.stand
    assert f_r == pytest.approx(inj["f_hz"], rel=1e-3)
    assert zeta == pytest.approx(inj["zeta"], rel=0.015)
    assert gain == pytest.approx(inj["gain"], rel=0.01)
    assert above == pytest.approx(1.0, abs=0.02)            # the injected form returns to 1 above the stand
    p = efit.params
    f_tr = np.sqrt(p.k_r / p.mass) / (2 * np.pi)
    assert f_tr == pytest.approx(iw.TRUTH_HZ["radial_translation"], rel=0.002)
    assert "radial_translation" not in efit.unconstrained
    assert model.analytical["fit"]["test_stand"]["peak_gain"] == pytest.approx(gain)


def test_a_stand_beside_a_load_cell_offset_is_not_taken_for_the_translation_silently():
    """E wheel, 40 speeds 300-2400 rpm, 2048 samples: the 180 Hz stand with the load cell's reference 60 mm below the
    wheel (torques + r × F).  The stand is not confirmed on the modes' residual (the offset's torques), and the fit
    without it put the radial translation at 184.5 Hz (the thesis's is 227.7 Hz: -19 %) with its damping at the fit's
    floor (ζ = 5e-5) and said nothing.  A mode whose damping runs to that floor is not located, nor one the stand
    fitted with the modes leaves known to more than 2 % only: the translation is either within 2 % of the thesis's or
    declared (analytical.unconstrained, a note saying why)."""
    test = simulate_with_injections(preset("ithaco-e"), [parse(STAND), parse("cross_coupling:r_z=-0.06")],
                                    np.linspace(300.0, 2400.0, 40), physics="extended", sample_rate=3840.0,
                                    n_samples=2048, noise=0.01, seed=1)
    efit, model = api.fit_extended(test)
    p = efit.params
    f_tr = np.sqrt(p.k_r / p.mass) / (2 * np.pi)
    located = abs(f_tr / iw.TRUTH_HZ["radial_translation"] - 1) <= 0.02
    assert located or "radial_translation" in model.analytical["unconstrained"]
    assert located or any(n.startswith("radial_translation: NOT CONSTRAINED") and ("damping runs to the fit's floor"
                          in n or "standard errors" in n) for n in efit.notes)
