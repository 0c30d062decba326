"""A line that starts at one speed in the radial force and the radial torque is described in both directions, the
weaker one read where it stands 13 dB over its window's noise (rwadist.diagnose.describe_structure.ABSENT_SNR_DB).

Session 60's new-user trial (a 7-kg wheel, h 5.46 present above 3000 rpm only in the radial force and torque): the
torque's line stood 14-17 dB over the noise of its Welch window where present, under the 20 dB the lines' ratios were
read at, and the line was named "in Fx Fy" alone.  Here family wheels with a forward line at h 2.9 added to the records
in the runs over the median speed (generated again with it, through the suspension modes), in the forces 0.2 x the
imbalance's C and in the torques 0.01-0.03 x the dynamic imbalance's: 8-44 dB over its window's noise."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402

H = 2.9


def _test(index: int, torque_share: float):
    """Family wheel ``index`` whose runs over the median speed are generated with a forward line at h :data:`H` in the
    radial force (0.2 x the imbalance's C) and the radial torque (``torque_share`` x the dynamic imbalance's C), the
    others without it (a second generation of the same test)."""
    import dataclasses

    wheel = fw.family()[index]
    c_f = next(x.C for x in wheel.lines if x.direction == "radial_force" and x.h == 1.0)
    c_t = next(x.C for x in wheel.lines if x.direction == "radial_torque" and x.h == 1.0)
    lit = dataclasses.replace(wheel, lines=tuple(wheel.lines) + (fw.Line("radial_force", H, 0.2 * c_f),
                                                                   fw.Line("radial_torque", H, torque_share * c_t)))
    without, with_line = (family_test.steady_test(fw.steady(w, seed=2, noise=0.01)) for w in (wheel, lit))
    speeds = np.array([abs(r.speed) for r in without.runs])
    on = speeds > np.median(speeds)
    without.runs[:] = [b if o else a for a, b, o in zip(without.runs, with_line.runs, on)]
    return without, np.sort(speeds[on]) * 30 / np.pi


@pytest.mark.parametrize("index, torque_share", [(1, 0.01), (5, 0.03)])
def test_a_line_starting_at_one_speed_in_two_directions_is_named_in_both(index, torque_share):
    test, lit = _test(index, torque_share)
    diag = api.diagnose(test)
    partial = [u for u in diag.unexplained if u.signature == "partial_line" and abs(u.h - H) < 0.01]
    assert sorted(u.parameters["direction"] for u in partial) == ["radial_force", "radial_torque"], \
        [(u.parameters["direction"], u.channels) for u in partial]
    for u in partial:                   # the runs read: those where the line stands 13 dB over the noise
        assert np.all(np.isin(np.round(u.parameters["present_rpm"], 3), np.round(lit, 3)))
        assert len(u.parameters["absent_rpm"]) >= 3 and max(u.parameters["absent_rpm"]) < lit[0]
