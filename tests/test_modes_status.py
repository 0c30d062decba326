"""Why a no-model diagnosis ends without the wheel's suspension modes (rwadist.diagnose.modes_status; trial25: a
suspension coupling translation and rocking left every line on the empirical base and nothing said so).

The record reads the amplification peaks of the data's empirical fit: on the family generator's wheels (modes on)
they sit at the generator's own mode frequencies, with its modes moved out of the band there are none."""
import dataclasses
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.modes_status import WHOLE_DATA_FIT as KEY  # noqa: E402
from rwadist.diagnose.modes_status import modes_status  # noqa: E402


def _diag(wheel, base_switch=True, effects=(), hypotheses=()):
    test = family_test.steady_test(fw.steady(wheel, seed=5, noise=0.01))
    fit = api.fit(test)
    ctx = SimpleNamespace(base_switch=base_switch, test=test, _memo={KEY: fit})
    return SimpleNamespace(ctx=ctx, state_after=SimpleNamespace(base="empirical", effects=list(effects)),
                           hypotheses=list(hypotheses))


@pytest.mark.parametrize("index", [3, 6])
def test_lines_rising_through_the_modes_are_said_when_no_mode_is_fitted(index):
    """Family wheels 3 (7 kg, modes 230 / 70 / 120 Hz) and 6 (12 kg, 150 / 110 / 85 Hz): the radial-force and axial
    lines peak at the translation and axial modes (the generator's own frequencies, within the speed grid's step)."""
    wheel = fw.family()[index]
    status = modes_status(_diag(wheel))
    assert status["status"] == "not_located" and status["tried"] == []
    assert status["peaks_Hz"]["radial_force"]["median_Hz"] == pytest.approx(wheel.f_trans, rel=0.06)
    assert status["peaks_Hz"]["axial_force"]["median_Hz"] == pytest.approx(wheel.f_axial, rel=0.06)
    assert status["text"].startswith("NOT FITTED, although the lines rise as through a resonance: radial force near")


def test_a_wheel_without_modes_in_its_band_is_said_to_show_none():
    wheel = dataclasses.replace(fw.family()[3], f_trans=40000.0, f_rock=30000.0, f_axial=35000.0)
    status = modes_status(_diag(wheel))
    assert status["status"] == "no_amplification" and status["peaks_Hz"] == {}


def test_nothing_is_said_when_the_modes_were_not_to_be_fitted_or_a_named_resonance_explains_the_rise():
    wheel = fw.family()[3]
    assert modes_status(_diag(wheel, base_switch=False)) is None
    # every peak within 10 % of a named fixed resonance: the rise is that resonance's
    named = [SimpleNamespace(kind="fixed_resonance", f_r=f) for f in (wheel.f_trans, wheel.f_axial, wheel.f_rock)]
    status = modes_status(_diag(wheel, effects=named))
    assert "radial_force" not in status["peaks_Hz"] and "axial_force" not in status["peaks_Hz"]


def test_a_modes_hypothesis_not_taken_is_reported_with_its_evidence():
    wheel = fw.family()[6]
    modes = SimpleNamespace(kind="suspension_modes", unconstrained=("rocking",),
                            f0_Hz={"radial_translation": 150.2, "rocking": 2400.0, "axial": 85.1})
    hyp = SimpleNamespace(effect=modes, passed=False, iteration=1, gain_fraction=0.031, t=2.5)
    status = modes_status(_diag(wheel, hypotheses=[hyp]))
    assert status["status"] == "rejected"
    assert status["tried"] == [{"iteration": 1, "heldout_gain_fraction": 0.031, "t": 2.5,
                                "modes_Hz": {"radial_translation": 150.2, "axial": 85.1}}]
    assert "tried, iteration 1: radial translation 150.2 Hz, axial 85.1 Hz located, held-out gain 3.1 %" \
        in status["text"]


def test_the_diagnosis_of_a_wheel_without_modes_in_its_band_says_so_in_its_summary():
    """End to end (``api.diagnose`` without a model): the record is in summary.json, from the diagnosis's own fit."""
    wheel = dataclasses.replace(fw.family()[3], f_trans=40000.0, f_rock=30000.0, f_axial=35000.0, n_speeds=12,
                                n_samples=4096)
    diag = api.diagnose(family_test.steady_test(fw.steady(wheel, seed=2, noise=0.01)))
    assert diag.state_after.base == "empirical"
    assert diag.summary()["suspension_modes_status"]["status"] == "no_amplification"
