"""The wheel's suspension modes are located beside a gain common to every channel that changes with speed (issue 33:
"clean data: 0 effects added, every suspension mode within 2 % or marked unconstrained, on any wheel").

Family wheel 7 (16 speeds 1000-10000 rpm, 8192 samples, noise 0.03: the family matrix's conditions) with every
channel's gain 1 − 0.08·Ω/Ω_max (a load cell warming with speed, as tests/test_describe_gain_trend.py builds it),
diagnosed as the user's ``rwadist diagnose DATA -o R`` does with no model (:func:`rwadist.api.diagnose`).  At the
seeds below the gain's −0.65 dB bent the 1x torque line's trend the rocking mode is read from (its forward whirl
never crossed: I_zz/I_rr 2.1): the rocking's damping ran to the fit's floor on both folds, no suspension mode was
named and amplitude laws were added (seed 701: on the 1x lines of the radial torque and axial force, error after
0.50 against 0.034).  The same draws clean locate every mode within 1 %.  Now the lines' common trend is divided out
before the modes are located again (:mod:`rwadist.diagnose.modes_trend`).

Truth: the generator's modes (tests/family_wheel.py) and the gain's own change over the speed range,
20·log10((1 − k)/(1 − k·Ω_min/Ω_max)) dB of power, which the open world describes (``line_property``,
``gain_trend``) to 20 %, as tests/test_describe_gain_trend.py asks of wheels 0-6.
"""
import functools
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import diagnose_family_matrix as dfm  # noqa: E402
import diagnose_open_world as dow  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist import api  # noqa: E402

#: the gain's fall at the top speed
K = 0.08
#: the draws whose modes the gain lost (land f035afa: no suspension_modes, amplitude laws added)
SEEDS = (701, 703, 706, 709, 1)
WHEEL = 7


@functools.lru_cache(maxsize=None)
def _diagnosed(seed: int):
    wheel = dfm.wheels()[WHEEL]
    data = fw.steady(wheel, noise=dfm.CONDITIONS[WHEEL][2], seed=seed,
                     effects=[dow.SpeedGain(wheel.max_rpm * fw.RPM, k=K)])
    return wheel, api.diagnose(steady_test(data))


def _located_with_damping_held_honestly(modes, wheel):
    """Every mode located (none of the mode names in ``unconstrained``); a damping the data do not measure may be
    declared there as zeta_<mode> (:mod:`rwadist.extended_fit_damping`: the rocking's, whose forward whirl the 1x line
    never crosses at I_zz/I_rr 2.1: seed 701 clean, bounds 5e-5-0.016), and then its bounds hold the generator's ζ."""
    listed = modes.get("unconstrained") or []
    assert not [m for m in listed if m in dfm.MODES], listed
    truth = {"radial_translation": wheel.zeta_trans, "rocking": wheel.zeta_rock, "axial": wheel.zeta_axial}
    for name in listed:
        m = name[len("zeta_"):]
        lo, hi = modes["zeta_bounds"][m]
        assert lo <= truth[m] <= hi, (m, lo, hi, truth[m])
        assert lo <= modes[name] <= hi


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
def test_the_modes_are_located_beside_a_gain_that_changes_with_speed(seed):
    wheel, d = _diagnosed(seed)
    s = d.summary()
    (modes,) = [e for e in s["effects"] if e["kind"] == "suspension_modes"]
    truth = wheel.modes_hz()
    # every mode located (the rocking mode is the one the gain had left unconstrained), within 2 % (the bound;
    # seed 703 puts the rocking at 128.6 Hz, 1.05 % low); a damping the data do not measure declared with true bounds
    _located_with_damping_held_honestly(modes, wheel)
    for m in dfm.MODES:
        assert modes[f"{m}_Hz"] == pytest.approx(truth[m], rel=dfm.MODE_TOL), m
    # nothing forced into a class for the gain: no amplitude law, nothing beside the wheel's modes
    assert [e["kind"] for e in s["effects"]] == ["suspension_modes"]
    # the gain described, its change to 20 %
    (u,) = [u for u in d.unexplained if u.signature == "line_property" and u.parameters.get("property") == "gain_trend"]
    truth_dB = 20 * np.log10((1 - K) / (1 - K * wheel.min_rpm / wheel.max_rpm))
    assert u.parameters["change_dB"] == pytest.approx(truth_dB, rel=0.2)


@pytest.mark.slow
def test_the_same_draws_clean_are_diagnosed_as_before():
    """Control: seed 701 clean locates every mode within 1 % and adds nothing (the trend is only read when a mode is
    left unconstrained, and none is)."""
    wheel = dfm.wheels()[WHEEL]
    data = fw.steady(wheel, noise=dfm.CONDITIONS[WHEEL][2], seed=SEEDS[0], effects=[])
    s = api.diagnose(steady_test(data)).summary()
    (modes,) = [e for e in s["effects"] if e["kind"] == "suspension_modes"]
    _located_with_damping_held_honestly(modes, wheel)
    for m, f in wheel.modes_hz().items():
        assert modes[f"{m}_Hz"] == pytest.approx(f, rel=0.01), m
    assert [e["kind"] for e in s["effects"]] == ["suspension_modes"]
    assert not s.get("unexplained")
