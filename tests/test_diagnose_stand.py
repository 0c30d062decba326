"""``rwadist diagnose`` with no model on data of a wheel on a resonant test stand (issue 14, item 3).

The wheel's own suspension modes are named (``suspension_modes``) and a fixture resonance acting on every
channel at one frequency is a ``fixed_resonance`` of role ``test_stand`` beside them, never inside them.
Independent references: the injected stand resonance (f, ζ, peak gain written into the data by
:mod:`rwadist.inject`) and the thesis's wheel E modes (tests/independent_wheel.py: Tables 3.4/4.2, typed, not
read from rwadist).  The full-size case prints its numbers in benchmarks/diagnose_stand_resonance.py.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402

from rwadist import api, catalogue  # noqa: E402
from rwadist.data import SteadyTest  # noqa: E402
from rwadist.diagnose import Context, initial_state  # noqa: E402
from rwadist.diagnose.search import _judge, fits_modes_from_data, resolve_base  # noqa: E402
from rwadist.effects.missing_harmonic_diagnose import MissingHarmonic  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.inject import parse, simulate_with_injections  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_detect import stand_resonance_start  # noqa: E402
from rwadist.teststand import simulate_steady  # noqa: E402

F_STAND = 180.0


def _stand_test(speeds_rpm, f_stand=F_STAND, sample_rate=1920.0, n_samples=4096, seed=1, modes=True):
    return simulate_with_injections(preset("ithaco-e"), [parse(f"fixed_resonance:f_hz={f_stand:g}")], speeds_rpm,
                                    physics="extended" if modes else "simple", sample_rate=sample_rate,
                                    n_samples=n_samples, noise=0.01, seed=seed)


def _injected(test):
    (inj,) = [x for x in test.meta["injected"] if x["kind"] == "fixed_resonance"]
    return inj


def test_stand_resonance_is_seen_in_every_direction_and_only_there():
    """The detector of a fixture resonance (every direction's lines lifted at one frequency) finds the injected
    one within 3 %, and nothing on the same wheel without the stand (its modes only)."""
    speeds = np.linspace(300.0, 3000.0, 20)
    test = _stand_test(speeds)
    got = stand_resonance_start(fit_empirical(compute_spectra(test)))
    assert got is not None
    assert got[0] == pytest.approx(_injected(test)["f_hz"], rel=0.03)
    assert got[2] > 2.0                                    # injected peak gain 5: a resonance, not model error
    clean = simulate_steady(preset("ithaco-e"), speeds, sample_rate=1920.0, n_samples=4096, noise=0.01, seed=1,
                            physics="extended", test_stand=False)
    assert stand_resonance_start(fit_empirical(compute_spectra(clean))) is None


def test_stand_resonance_named_beside_the_suspension_modes():
    """No model: suspension_modes (each mode within 2 % of the thesis's) and the fixture at the injected
    frequency within 1 %, role test_stand, on every channel -- and nothing else."""
    test = _stand_test(np.linspace(300.0, 3000.0, 20), n_samples=8192)
    d = api.diagnose(test)
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds == ["suspension_modes", "fixed_resonance"], kinds
    modes, stand = d.model.effects
    assert modes["rocking_Hz"] == pytest.approx(iw.TRUTH_HZ["rocking"], rel=0.02)
    assert modes["radial_translation_Hz"] == pytest.approx(iw.TRUTH_HZ["radial_translation"], rel=0.02)
    assert modes["axial_Hz"] == pytest.approx(iw.TRUTH_HZ["axial"], rel=0.02)
    inj = _injected(test)
    assert stand["role"] == "test_stand" and set(stand["channel"]) == {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"}
    assert stand["f_Hz"] == pytest.approx(inj["f_hz"], rel=0.01)
    assert stand["peak_gain"] == pytest.approx(inj["gain"], rel=0.15)
    assert d.error_after < 0.05 * d.error_before
    # a stand taken from the modes' joint fit counts no measurements of its own: null, never "fitted on 0 points"
    assert stand.get("n_points") != 0


def test_an_effect_that_changes_nothing_never_passes():
    """A missing harmonic of C = 0 (or any effect leaving the prediction as it was) has no held-out gain: the
    acceptance rule refuses it whatever k_sigma and min_gain."""
    test = simulate_steady(preset("ithaco-e"), np.linspace(600.0, 2400.0, 8), sample_rate=1920.0,
                           n_samples=2048, noise=0.01, seed=2, modes=False, test_stand=False)
    sp = compute_spectra(test, nperseg=512)
    ctx = Context(sp, None, test)
    state = initial_state(ctx, fit_empirical(sp).model)
    nothing = MissingHarmonic("radial_torque", 1.37, 0.0, 8)
    for k_sigma, min_gain in ((4.0, 0.05), (1e-9, 1e-12)):
        hyp = _judge(ctx, state, nothing, k_sigma, min_gain, 1)
        assert hyp.gain == 0.0 and not hyp.passed


def test_one_default_base_for_the_library_and_the_command_line():
    """'auto' on a datasheet wheel whose modes are assumed: the library resolves the empirical base and lets the
    search fit the modes from the data, as the CLI does (which now only passes 'auto' on); a wheel with
    measured modes (E, thesis) keeps its extended base; a test recording the modes off never switches."""
    hr = next(n for n in catalogue.names() if catalogue.source_modes_assumed(None, n))
    assumed = catalogue.preset_model(hr)
    measured = preset("ithaco-e").to_model()
    on = SteadyTest([], {"modes": True})
    off = SteadyTest([], {"modes": False})
    assert resolve_base(assumed, "auto", on) == "empirical" and fits_modes_from_data(assumed, "auto", on)
    assert resolve_base(measured, "auto", on) == "extended" and not fits_modes_from_data(measured, "auto", on)
    assert resolve_base(None, "auto", on) == "empirical" and fits_modes_from_data(None, "auto", on)
    assert not fits_modes_from_data(None, "auto", off) and not fits_modes_from_data(None, "empirical", on)
    assert resolve_base(assumed, "extended", on) == "extended"
    # through the library's entry point: the preset name alone marks the datasheet wheel's modes assumed
    data = simulate_steady(preset(hr), [2000.0, 4000.0, 6000.0], n_samples=2048, seed=0)
    d = api.diagnose(data, preset=hr)
    assert d.state_before.base == "empirical"
    assert d.ctx.base_switch == fits_modes_from_data(assumed, "auto", data)
