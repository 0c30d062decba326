"""A radial force copied into one radial torque is a copy, not a load-cell offset (rwadist.diagnose.channel_copy:
RADIAL_LEVER, _mirror_missing).

The classic crosstalk of a six-axis load cell, a force into a moment (Ty += κ·Fx), is on the lines exactly a load-cell
offset's r_z·F_x in T_y, so such pairs were left to the ``cross_coupling`` class, and the copy was read on the noise
floor only, where Fx's noise times κ stays under Ty's own (the family's noise: Fx's 1.8-3.9 times Ty's, in N and N·m).
Undeclared, on the code before, the family's wheels lost their rocking mode (wheels 0, 1, 3: "not located", the fit
ended at 18-34 times it), had a counter-rotating part (wheels 0, 1) or a test stand (wheel 1) named, and wheel 3 with
Fy in Tx ended in LinAlgError (its copy called a distortion of Tx, rwadist.channel_distortion); no copy was described.
An offset moves both of r_z's terms (T_y = r_z·F_x with T_x = −r_z·F_y); a copy one: the mirror pair tells."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


def _diagnosed(index, effect):
    wheel = fw.family()[index]
    return wheel, api.diagnose(family_test.steady_test(fw.steady(wheel, seed=1, noise=0.01, effects=[effect])))


@pytest.mark.parametrize("index, source, target, kappa", [(0, "Fx", "Ty", 0.08), (1, "Fy", "Tx", 0.05),
                                                          (3, "Fy", "Tx", 0.05)])
def test_a_force_copied_into_a_moment_is_described_and_the_modes_kept(index, source, target, kappa):
    wheel, diag = _diagnosed(index, fe.Crosstalk(source, target, kappa))
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes"]
    (copy,) = [u for u in diag.unexplained if u.signature == "channel_copy"]
    assert (copy.parameters["source"], copy.parameters["target"]) == (source, target)
    assert abs(copy.parameters["gain"]) == pytest.approx(kappa, rel=0.02)
    modes, truth = diag.model.effects[0], wheel.modes_hz()
    for key, name in (("radial_translation_Hz", "radial_translation"), ("rocking_Hz", "rocking"), ("axial_Hz", "axial")):
        assert modes[key] == pytest.approx(truth[name], rel=0.005), key


@pytest.mark.parametrize("r", [(0.0, 0.0, -0.06), (0.004, -0.003, 0.03)])     # with a lateral part: r_y·Fz in Tx
@pytest.mark.slow
def test_an_offset_reads_in_both_mirrors_and_stays_the_offset(r):
    _, diag = _diagnosed(0, fe.CrossCoupling(r=r))
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes", "cross_coupling"]
    assert not [u for u in diag.unexplained if u.signature == "channel_copy"]
