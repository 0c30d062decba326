"""One channel of a radial pair reading every line by another factor than its partner (a gain or calibration error;
trial13: Ty x 1.10, nothing said, error 5.7x clean) is described as a ``line_property`` with the ratio, on the default
path (:func:`rwadist.api.diagnose`), on a wheel that is not the E wheel (tests/standmodes_wheel.py, written without
rwadist's physics).  The truth is the factor the test applies to the channel's samples: a rotating load gives x and y
the same power, so the lines' power ratio is the gain squared."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import standmodes_wheel as sw  # noqa: E402

from rwadist import api  # noqa: E402


def _test(channel: str, gain: float):
    test, _ = sw.generate(sw.NEW_WHEEL, np.linspace(600.0, 6000.0, 24), sample_rate=5000.0, n_samples=4096,
                          noise=0.01, seed=11)
    for run in test.runs:
        run.signals[channel] = gain * run.signals[channel]
    return test


@pytest.mark.slow
@pytest.mark.parametrize("channel, partner, gain", [("Ty", "Tx", 1.10), ("Fx", "Fy", 0.92)])
def test_a_channel_gain_is_described_with_its_ratio(channel, partner, gain):
    d = api.diagnose(_test(channel, gain))
    (u,) = [u for u in d.unexplained if u.signature == "line_property"]
    assert set(u.channels) == {channel, partner}
    y_over_x = gain if channel in ("Fy", "Ty") else 1.0 / gain
    assert u.parameters["amplitude_ratio"] == pytest.approx(y_over_x, rel=0.02)
    assert u.level_dB == pytest.approx(20 * np.log10(y_over_x), abs=0.15)
    assert f"{channel} reads {max(gain, 1 / gain):.3g} x {partner}" in u.causes[0] or \
        f"{partner} reads {max(gain, 1 / gain):.3g} x {channel}" in u.causes[0]
    assert [e["kind"] for e in d.summary()["effects"]] == ["suspension_modes"]


@pytest.mark.slow
def test_a_torque_gain_under_a_load_cell_offset_is_read_on_the_recorded_channels():
    """Ty × 1.10 on a load cell whose reference sits 30 mm below the bearing centre (T + r × F applied to the samples
    before the gain, as the cell reads it): the offset is named, and the gain is read on the torques as recorded, where
    the lines' power ratio is still the gain squared (r × F of a rotating force rotates with it).  Read through the
    correction T − r × F, with one r_z fitted to both channels, the lines disagreed and nothing was described
    (trial13)."""
    r_z, gain = 0.030, 1.10
    test = _test("Ty", 1.0)
    for run in test.runs:
        fx, fy = run.signals["Fx"], run.signals["Fy"]
        run.signals["Tx"] = run.signals["Tx"] - r_z * fy
        run.signals["Ty"] = gain * (run.signals["Ty"] + r_z * fx)
    d = api.diagnose(test)
    kinds = [e["kind"] for e in d.summary()["effects"]]
    assert "cross_coupling" in kinds
    (u,) = [u for u in d.unexplained if u.signature == "line_property"]
    assert set(u.channels) == {"Tx", "Ty"}
    assert u.parameters["amplitude_ratio"] == pytest.approx(gain, rel=0.02)
