"""A broadband floor through a narrow suspension mode is the floor class's and the mode's, no hump of what they leave
(rwadist.diagnose.describe_hump._at_a_fitted_resonance).

Family wheel 6's floor (tests/family_effects.BroadbandFloor: loads on the rotor growing as Ω³) reaches the load cell
through its 85 Hz axial mode of ζ 0.011, a peak 1.9 Hz wide, narrower than the knots of the class's floor there.  The
hump test reads the floor the class leaves run by run (session 58); what the class's knots cut off the mode's peak
stood 18 dB over that, was described as a hump, and the Fz floor was taken back for it (the error after 2.15x ->
2.38x the clean level): a hump within a bin and three half widths of a suspension mode that does not move with the
speed (the axial mode on Fz, the radial translation on the radial forces) is the noise through it."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


def test_the_floor_through_the_axial_mode_is_named_on_fz_and_no_hump_is_described():
    wheel = fw.family()[6]
    diag = api.diagnose(family_test.steady_test(fw.steady(wheel, seed=1, noise=0.01, effects=[
        fe.default_effect("broadband_floor", wheel)])))
    named = {c for e in diag.model.effects if e["kind"] == "broadband_floor" for c in e["channel"]}
    assert named == {"Fx", "Fy", "Fz"}
    assert not [u for u in diag.unexplained if u.signature == "broadband_hump"], diag.unexplained
