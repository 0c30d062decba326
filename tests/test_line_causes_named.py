"""A line an effect names has that effect for its cause (rwadist.diagnose.describe.line_causes).

``speed_sidebands`` puts its two lines into the model as harmonics; read as base lines they were given bearing
ratios or sums and differences of other lines.  Session 59: the E wheel's sidebands at 0.95/1.05 printed, beside the
named sidebands, "h = 0.95: could be the difference of the lines h = 2 and 1.05".  Here the family's speed
sidebands (±0.04, depth 0.2): on the code before, wheel 3's 0.96 was "the difference of the lines h = 2 and 1.04"
and wheel 0's 1.04 "the difference of the lines h = 4.118 and 3.08"."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.effects.speed_sidebands import SpeedSidebands  # noqa: E402


def test_a_sideband_pair_names_its_two_lines():
    sb = SpeedSidebands(direction="radial_force", h=1.0, h_lower=0.96, h_upper=1.04, C_lower=1e-7, C_upper=1e-7)
    assert sb.named_lines() == (("radial_force", 0.96), ("radial_force", 1.04))


@pytest.mark.parametrize("index, seed", [(3, 2), (0, 1)])
def test_named_sidebands_get_no_other_cause_and_still_lend_their_ratios(index, seed):
    test = family_test.steady_test(fw.steady(fw.family()[index], seed=seed, noise=0.01, effects=[
        fe.SpeedSidebands(per_rev=0.04, depth=0.2)]))
    diag = api.diagnose(test)
    (sb,) = [e for e in diag.model.effects if e["kind"] == "speed_sidebands"]
    pair = {round(sb["h_lower"], 3), round(sb["h_upper"], 3)}
    assert pair == {0.96, 1.04}
    assert not [lc for lc in diag.line_causes if lc["direction"] == "radial_force" and round(lc["h"], 3) in pair]
    # the bearing lines keep theirs (wheel 3's and wheel 0's non-integer lines are named causes as before)
    assert any(abs(lc["h"] - round(lc["h"])) > 0.05 for lc in diag.line_causes)
