"""Weak speed sidebands beside a test-stand resonance: judged on the narrow-line misfit as well as on the misplaced
power (``SpeedSidebands.judged_on_narrow_lines``, rwadist.diagnose.search._narrow_judge).

The new-user trial of session 55 (its own generator: a 7 kg wheel, modes 180/70/260 Hz, on a fixture at 162 Hz,
ζ 0.03) had 3 % sidebands of the imbalance at 0.95/1.05 x the speed fitted at t ≈ 1600 noise standard errors, but
2.6-4.8 % of the misplaced power the fixture's compromise leaves, under ``min_gain`` (5 %): left out of the model on 3
of 6 seeds and described nowhere ("Nothing: no structure the classes leave stands above the noise").  Here the family
generator's wheels (tests/family_wheel.py) on a fixture at 0.9x their radial translation (ζ 0.03, peak gain 5), their
imbalance amplitude-modulated at 0.05 x the speed to a depth of 6 % (two lines of 3 % of the imbalance each): on
ce37b70 none of the 8 wheels had the pair named (nor described); now wheels 0, 1, 2, 3 and 7 (4: the fixture is not
found; 5, 6: the pair is still left out, issue 33 stays open on them)."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import diagnose_family_matrix as dfm  # noqa: E402
import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402

PER_REV, DEPTH = 0.05, 0.06


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 3, 7])
def test_weak_speed_sidebands_beside_a_fixture_are_named(index):
    wheel = dfm.wheels()[index]
    f_fix = 0.9 * wheel.modes_hz()["radial_translation"]
    data = fw.steady(wheel, noise=dfm.CONDITIONS[index][2], seed=1,
                     effects=(fe.Fixture(f_hz=f_fix, zeta=0.03, gain=5.0), fe.SpeedSidebands(per_rev=PER_REV, depth=DEPTH)))
    diag = api.diagnose(family_test.steady_test(data))
    kinds = sorted(e.kind for e in diag.effects)
    assert kinds == ["fixed_resonance", "speed_sidebands", "suspension_modes"], kinds
    (stand,) = [e for e in diag.effects if e.kind == "fixed_resonance"]
    assert stand.f_r == pytest.approx(f_fix, rel=0.02)
    (pair,) = [e.params() for e in diag.effects if e.kind == "speed_sidebands"]
    assert pair["direction"] == "radial_force" and pair["h"] == pytest.approx(1.0)
    assert pair["per_rev"] == pytest.approx(PER_REV, abs=0.001)
    # each side DEPTH/2 of the carrier (the generator's modulation), read through the fitted modes and stand
    assert pair["ratio_lower"] == pytest.approx(DEPTH / 2, rel=0.15)
    assert pair["ratio_upper"] == pytest.approx(DEPTH / 2, rel=0.15)
