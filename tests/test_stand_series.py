"""Two fixtures in series on every channel, each a base-excitation transmissibility (1 + 2jζr)/(1 − r² + 2jζr), the
upper one crossed by the lines of the fastest runs only (rwadist.diagnose.stands.StandSet, and the fixed-resonance
rules it needed: rwadist.effects.fixed_resonance_diagnose ``DIRECTION_MIN_POINTS`` and
rwadist.diagnose.fixed_resonance_moving ``straddles``).

The new-user trial of session 54 (its own generator: a 2.5 kg wheel, modes 480 / 190 / 650 Hz, on fixtures at 350 Hz,
ζ 0.03, and 800 Hz, ζ 0.02) had one resonance at 349 Hz with 0.67 of the load far above named, a compromise over
both, and the 800 Hz lift read as an 8-pole anti-alias filter at 882 Hz, on 3 seeds (62x the clean error): the modes'
fit had located both, but judged one at a time the 800 Hz one lost (alone it lifts lines the 350 Hz one's roll-off
lowers), the generic fit's second stand was refused for Tz's 4 points and as moving with the speed (the slower runs'
lines reach its lower skirt only).  Here the family generator's wheels (tests/family_wheel.py) on such a pair placed
from their own modes and top line frequency: on 4bfa256 (before) wheel 7 alone had both named; now wheels 0, 1, 4, 5,
7; with the stands proposed at a second frequency when none at the best is confirmed
(rwadist.stand_detect.further_stand_starts), wheel 6 too (before: neither named).  Wheels 2 and 3 still name the
lower fixture only (issue 33 stays open on them)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import diagnose_family_matrix as dfm  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


class SeriesFixtures:
    """Fixtures at ``f_hz`` (ζ each) under the load cell's every channel: the product of their transmissibilities."""

    def __init__(self, f_hz, zeta):
        self.f_hz, self.zeta = tuple(f_hz), tuple(zeta)

    def gain(self, f_hz, omega):
        h = np.ones(len(f_hz), dtype=complex)
        for f_r, z in zip(self.f_hz, self.zeta):
            r = np.asarray(f_hz, dtype=float) / f_r
            h = h * (1 + 2j * z * r) / (1 - r**2 + 2j * z * r)
        return np.repeat(h[:, None], 6, axis=1)


def _pair(wheel):
    """(lower, upper) fixture frequencies (Hz): 0.73x the radial translation, and 0.8x the highest frequency of the
    wheel's radial-force lines (so the slower half of the runs does not reach it), at least 1.2x every mode."""
    top = max(ln.h for ln in wheel.lines if ln.direction == "radial_force") * wheel.max_rpm / 60.0
    modes = max(wheel.f_trans, wheel.f_rock, wheel.f_axial)
    return 0.73 * wheel.f_trans, max(0.8 * min(top, fw.ANTI_ALIAS * wheel.sample_rate), 1.2 * modes)


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 1, 4, 5, 6, 7])
def test_two_fixtures_in_series_are_both_named(index):
    wheel = dfm.wheels()[index]
    lower, upper = _pair(wheel)
    data = fw.steady(wheel, noise=dfm.CONDITIONS[index][2], seed=1,
                     effects=(SeriesFixtures((lower, upper), (0.03, 0.02)),))
    diag = api.diagnose(family_test.steady_test(data))
    stands = sorted(e.f_r for e in diag.state_after.effects if e.kind == "fixed_resonance")
    assert len(stands) == 2 and abs(stands[0] / lower - 1) < 0.02 and abs(stands[1] / upper - 1) < 0.02, (
        lower, upper, [(e.kind, getattr(e, "f_r", None)) for e in diag.state_after.effects])
    assert sorted(e["kind"] for e in diag.model.effects) == ["fixed_resonance", "fixed_resonance", "suspension_modes"]


def test_a_stand_set_judged_and_refused_is_written_with_its_members():
    """A ``StandSet`` among the judged hypotheses that did not pass is written to summary.json's hypotheses and
    hypotheses.csv with each member's parameters (on 9f60da1 its entry raised AttributeError, 'StandSet' object has no
    attribute 'to_schema', an internal error after the whole search: family wheel 1's fixture pair, once the modes'
    stands were proposed at a second frequency); a round trip of the entry through the csv module."""
    import csv
    import io

    from rwadist.diagnose.report import hypotheses_csv
    from rwadist.diagnose.search import Hypothesis, effect_entry
    from rwadist.diagnose.stands import StandSet
    from rwadist.effects.fixed_resonance_diagnose import FixedResonance

    chans = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
    stands = [(421.9, 0.030, 5.01, 1.0), (650.5, 0.030, 5.04, 1.0)]
    group = StandSet(tuple(FixedResonance.of_stand(s, chans, s) for s in stands))
    hyp = Hypothesis(group, gain=0.35, gain_fraction=0.35, t=282.0, passed=False, iteration=2)
    entry = effect_entry(hyp)
    assert entry["kind"] == "fixed_resonance" and entry["channel"] == list(chans)
    assert [m["f_Hz"] for m in entry["members"]] == [421.9, 650.5]
    assert [m["role"] for m in entry["members"]] == ["test_stand", "test_stand"]
    assert entry["evidence"]["passed"] is False
    (row,) = list(csv.DictReader(io.StringIO(hypotheses_csv([hyp]))))
    assert row["kind"] == "fixed_resonance" and row["passed"] == "false" and "421.9" in row["parameters"]
