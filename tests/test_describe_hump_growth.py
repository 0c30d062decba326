"""A broadband hump in every run that grows with the speed is the wheel's, not the surroundings'
(rwadist.diagnose.describe_hump.speed_growth).

The new-user trial (session 51, an independent generator): a noise hump at 120 Hz whose power grew as Ω⁶ (+60 dB over
600-6000 rpm) was described as "a resonance of the fixture or the load cell excited by the surroundings ... at every
speed".  Here the family generator's band-pass hump (tests/family_effects.Hump) scaled in amplitude as (Ω/Ω_max)^(p/2)
-- its power ∝ Ω^p -- on family wheels 0 and 3; the same hump unscaled keeps the surroundings' words.

Such a hump is a floor of the ``broadband_floor`` class's form, psd_ref(f)·(|Ω|/Ω_ref)^p: the class names it where it
gains on the held-out runs, and what is left of it is described only where it stands over all the floor, the class's
included (session 58: the class's floor at the median speed taken off the runs clear of lines, which differ from bin
to bin, left false humps beside a true floor, nuI c6: 300, 517, 555, 668 Hz; taken off run by run, it explains the hump,
and the class, once taken back for it, is kept: the error after 6-7x lower)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


class GrowingHump(fe.Hump):
    """The family's hump, its power ∝ |Ω|^p (``rise_db`` at the top speed)."""

    def __init__(self, f_hz, p, top_omega, rise_db=40.0):
        super().__init__(f_hz=f_hz, rise_db=rise_db)
        self.p, self.top = p, top_omega

    def cell_signal(self, t, omega, run, rng, wheel, std):
        return super().cell_signal(t, omega, run, rng, wheel, std) * (abs(omega) / self.top) ** (self.p / 2)


def _humps(index, effect):
    wheel = fw.family()[index]
    diag = api.diagnose(family_test.steady_test(fw.steady(wheel, seed=2, noise=0.01, effects=[effect])))
    return wheel, [u for u in diag.unexplained if u.signature == "broadband_hump"]


@pytest.mark.parametrize("index, p", [(0, 4.0), (3, 6.0)])
def test_a_hump_growing_with_the_speed_is_the_wheels_floor(index, p):
    """The class named on four channels or more, its exponent within 10 % and its floor peaking at the hump within 5 %;
    a channel it is not named on keeps the hump described, at its frequency within 10 %, its exponent within 40 % (the
    runs' floor, not the hump, holds the slowest runs' band) and its causes the wheel's loads."""
    wheel = fw.family()[index]
    f_hump = float(np.sqrt(wheel.f_rock * wheel.f_axial))
    diag = api.diagnose(family_test.steady_test(fw.steady(wheel, seed=2, noise=0.01, effects=[
        GrowingHump(f_hump, p, wheel.max_rpm * fw.RPM)])))
    floors = [e for e in diag.model.effects if e["kind"] == "broadband_floor"]
    named = {c for e in floors for c in e["channel"]}
    assert len(named) >= 4, [e["channel"] for e in floors]
    for e in floors:
        assert e["exponent"] == pytest.approx(p, rel=0.1)
        assert e["f_Hz"][int(np.argmax(e["psd_ref"]))] == pytest.approx(f_hump, rel=0.05)
    humps = [u for u in diag.unexplained if u.signature == "broadband_hump"]
    assert not [u for u in humps if named & set(u.channels)], humps
    # the hump is on every channel (family_effects.Hump): where no floor is named it is described
    assert {c for u in humps for c in u.channels} == set(fw.CHANNELS) - named
    for u in humps:
        assert u.parameters["peak_Hz"] == pytest.approx(f_hump, rel=0.1)
        assert u.parameters["speed_exponent"] == pytest.approx(p, rel=0.4)
        assert "rung by the wheel's own broadband loads" in u.causes[0] and "surroundings" not in u.causes[0][:60]


def test_a_hump_the_same_at_every_speed_keeps_the_surroundings():
    wheel = fw.family()[0]
    f_hump = float(np.sqrt(wheel.f_rock * wheel.f_axial))
    _, humps = _humps(0, fe.Hump(f_hump, rise_db=15.0))
    (u,) = [u for u in humps if u.f_Hz[0] <= f_hump <= u.f_Hz[1]]
    assert u.parameters["speed_exponent"] is None
    assert u.causes[0].startswith("a resonance of the fixture or the load cell excited by the surroundings")
