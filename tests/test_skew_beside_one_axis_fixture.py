"""A fixture swaying along one axis is no timing skew (rwadist.diagnose.describe_skew).

A test-stand resonance on Fx and Ty alone (a table mode along x) lifts Fx and turns its phase as it lifts it:
H(f/f_r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr) has a phase that grows with f below f_r, the course a late channel's
phase takes.  The stand was found on its two channels, and its phase was then read again as a skew of Fx against Fy
and of Ty against Tx ("the other rotation sense's share of a line's power", −10 to −23 dB; family wheels 3, 4 and 6
with the fixture at 1.5x their radial translation, session 57's list).  The state's fixed resonances are now taken off
each channel's lines before their phases are read: nothing described, and a real skew beside the fixture is still
read to its sample."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


class AlongX(fe.Fixture):
    """The family's fixture (ζ 0.03, peak gain 5) on Fx and Ty only."""

    def _channels(self):
        return (0, 4)


def _diagnose(index: int, late_samples: int = 0):
    wheel = fw.family()[index]
    test = family_test.steady_test(fw.steady(wheel, seed=1, noise=0.01, effects=[AlongX(1.5 * wheel.f_trans)]))
    for run in test.runs:
        if late_samples:
            x = run.signals["Fy"].copy()
            x[late_samples:] = run.signals["Fy"][:-late_samples]
            run.signals["Fy"] = x
    return api.diagnose(test), wheel, late_samples / test.runs[0].sample_rate


@pytest.mark.parametrize("index", [4, 6])
def test_a_one_axis_fixture_is_named_on_its_channels_and_read_as_no_skew(index):
    diag, wheel, _ = _diagnose(index)
    (stand,) = [e for e in diag.model.effects if e["kind"] == "fixed_resonance"]
    assert stand["role"] == "test_stand" and sorted(stand["channels"]) == ["Fx", "Ty"]
    assert stand["f_Hz"] == pytest.approx(1.5 * wheel.f_trans, rel=0.01)
    assert not [u for u in diag.unexplained if u.parameters.get("property") == "channel_skew"]


def test_a_real_skew_beside_the_one_axis_fixture_is_still_read():
    """Wheel 3, Fy 3 samples (0.75 ms) late beside the stand: the stand named, the skew read to 1 % and undone.  (On wheels 4 and 6 the skew
    makes the stand search lose the one-axis stand: left open.)"""
    diag, _, tau = _diagnose(3, late_samples=3)
    (stand,) = [e for e in diag.model.effects if e["kind"] == "fixed_resonance"]
    assert sorted(stand["channels"]) == ["Fx", "Ty"]
    (rec,) = [r for r in diag.data_quality if r.get("type") == "late_channel"]      # read, and moved back
    assert (rec["channel"], rec["reference"]) == ("Fy", "Fx")
    assert rec["tau_s"] == pytest.approx(tau, rel=0.01)


class SpringMountAlongX(AlongX):
    """A fixture of a spring mount along x, (1 + 2jζr)/(1 − r² + 2jζr) (the new-user trial nuN's; peak gain 16.7 at
    ζ 0.03, falling as 1/r above), on Fx and Ty: its phase is not the fitted general form's."""

    def gain(self, f_hz, omega):
        r = np.asarray(f_hz, dtype=float) / self.params["f_hz"]
        g = np.ones((len(f_hz), 6), dtype=complex)
        g[:, list(self._channels())] = ((1 + 0.06j * r) / (1 - r**2 + 0.06j * r))[:, None]
        return g


@pytest.mark.parametrize("index", [3, 6])
def test_a_spring_mount_along_one_axis_is_read_as_no_skew(index):
    """nuN: such a fixture at 0.8x the radial translation, found on Fx and Ty, was also "Fx sampled 0.113 ms after Fy"
    and "Ty 0.108 ms after Tx" (its phase taken off with the fitted form's, 4-45 degrees off the truth's)."""
    wheel = fw.family()[index]
    test = family_test.steady_test(fw.steady(wheel, seed=1, noise=0.01, effects=[SpringMountAlongX(0.8 * wheel.f_trans)]))
    diag = api.diagnose(test)
    assert not [u for u in diag.unexplained if u.parameters.get("property") == "channel_skew"]
