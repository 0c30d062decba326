"""A test-stand resonance changes the lines of every load direction near it (issue 33, item 1).

diagnose's own ``fixed_resonance`` fit of role test_stand is pooled over every channel; a resonance that changes the
lines of one direction only is that direction's misfit, not a fixture.  References: the single-mode gain written out
here in closed form, H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr) (|H(1)| = g, H → 1 far from f_r), the counting done on
it by hand; and family wheel 7 (tests/family_wheel.py, generated without rwadist's physics) clean, seed 3, where a
"stand" at 52.9 Hz (ζ 0.0026, gain 0.05: a notch under one line at one speed) was added beside the modes.
"""
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rwadist.effects.fixed_resonance_diagnose import FixedResonance, _lifted_directions  # noqa: E402

CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")


def _gain_sq(f, f_r, zeta, g):
    r = np.asarray(f, float) / f_r
    return np.abs((1 - r**2 + 2j * g * zeta * r) / (1 - r**2 + 2j * zeta * r)) ** 2


def test_directions_counted_where_the_resonance_explains_the_lines_it_changes_by_half_their_power():
    stand = FixedResonance(195.0, 0.03, 5.0, CHANNELS, "test_stand")
    f = np.array([150.0, 194.0, 197.0, 260.0, 201.0, 120.0])
    dirs = np.array(["radial_force", "radial_force", "radial_torque", "radial_torque", "axial_force", "axial_force"])
    w = np.ones(f.size)
    # power gains 1.30, 24.32, 22.51, 1.25, 12.88, 1.08: each direction has one line changed 1.5x or more, one not
    lifted = np.log(_gain_sq(f, 195.0, 0.03, 5.0))
    assert [round(float(v), 2) for v in np.exp(lifted)] == [1.3, 24.32, 22.51, 1.25, 12.88, 1.08]
    # a fixture: every direction's lines lifted as it says (within 20 % of the log gain)
    assert _lifted_directions(stand, f, 0.8 * lifted, w, dirs) == 3
    # lines outside its band do not count
    assert _lifted_directions(stand, f[[0, 3, 5]], lifted[[0, 3, 5]], w[:3], dirs[[0, 3, 5]]) == 0
    # a resonance of the radial forces alone (a housing mode) pooled over every channel: the torque and axial lines
    # it passes are not lifted -- it makes them worse, and is no stand
    housing = np.where(dirs == "radial_force", lifted, 0.0)
    assert _lifted_directions(stand, f, housing, w, dirs) == 0
    # a notch (gain 0.05, ζ 0.0026) changes only what lies within ~0.5 % of it: the axial line at 53.0 Hz
    notch = FixedResonance(52.9, 0.0026, 0.05, CHANNELS, "test_stand")
    f2 = np.array([53.0, 53.4, 55.0, 50.0])
    dirs2 = np.array(["axial_force", "radial_force", "radial_torque", "radial_force"])
    ratio = _gain_sq(f2, 52.9, 0.0026, 0.05)
    assert np.flatnonzero(np.abs(np.log(ratio)) >= np.log(1.5)).tolist() == [0]
    assert _lifted_directions(notch, f2, np.log(ratio), np.ones(4), dirs2) == 1
    assert _lifted_directions(notch, np.empty(0), np.empty(0), np.empty(0), np.empty(0, str)) == 0


def test_a_stand_of_one_direction_is_not_significant():
    stand = FixedResonance(52.9, 0.0026, 0.05, CHANNELS, "test_stand")
    assert stand.significant()                                    # not counted: the modes' stand has its own rule
    assert not replace(stand, lifted_directions=1).significant()
    assert replace(stand, lifted_directions=2).significant()
    # a wheel mode is one direction's by definition
    assert FixedResonance(283.0, 0.03, 5.0, ("Fx", "Fy"), "wheel_mode", lifted_directions=1).significant()


@pytest.mark.slow
def test_no_stand_invented_on_a_clean_wheel():
    """Family wheel 7 clean (the family matrix's conditions, seed 3): the suspension modes and nothing else."""
    import family_wheel as fw

    from rwadist import api
    from rwadist.data import read_steady

    wheel = replace(fw.family()[7], n_speeds=16, n_samples=8192)
    data = fw.steady(wheel, noise=0.03, seed=3 + 100 * 7)
    with tempfile.TemporaryDirectory() as tmp:
        test = read_steady(fw.write_steady(data, Path(tmp) / "data", wheel.name))
    d = api.diagnose(test)
    assert [e.kind for e in d.effects] == ["suspension_modes"]
    modes = d.effects[0]
    for m, truth in wheel.modes_hz().items():
        assert m in modes.unconstrained or modes.f0_Hz[m] == pytest.approx(truth, rel=0.02), m
