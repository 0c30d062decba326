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


def _lines_and_fitted_offset(test, lines):
    """(context, the state holding the wheel's true ``lines``, the load-cell offset the ``cross_coupling`` fit gives
    on it) of ``test`` (test_describe_offset_floor's numpy wheel)."""
    from test_describe_offset_floor import NPERSEG

    from rwadist.diagnose.engine import Context, initial_state
    from rwadist.effects.cross_coupling_diagnose import CrossCoupling
    from rwadist.model import Harmonic, WheelModel
    from rwadist.spectra import compute_spectra

    ctx = Context(compute_spectra(test, nperseg=NPERSEG), test=test)
    model = WheelModel(name="the wheel's lines")
    for d, h, C in lines:
        model.empirical[d].append(Harmonic(h=h, C=C))
    start = initial_state(ctx, model)
    return ctx, start, CrossCoupling.fit(ctx, start, ctx.runs)


@pytest.mark.parametrize("seed", [13, 14, 15])
def test_a_torque_gain_under_a_load_cell_offset_is_read_on_the_recorded_channels(seed):
    """Ty × 1.10 on a load cell whose reference sits 30 mm below the bearing centre (test_describe_offset_floor's numpy
    wheel, T + r × F before the gain, as the cell reads it), the state holding the wheel's lines and the offset as the
    ``cross_coupling`` fit measures it: one r_z for Tx = −r_z·Fy and Ty = 1.1·r_z·Fx lies between r_z and 1.1·r_z,
    and the torques corrected by it keep a share of r × F that differs between the two channels (trial13: 26.2 mm for
    25, and no gain described).  Read as recorded (:func:`as_recorded`), where r × F of a rotating force rotates with
    it, every line's power ratio is the gain squared: the ratio within 0.5 %."""
    from test_describe_offset_floor import LINES, SPEEDS_RPM, R, lever_arm_test

    from rwadist.diagnose.describe_gain import as_recorded, channel_gain

    test = lever_arm_test(LINES, R, SPEEDS_RPM, seed)
    for run in test.runs:
        run.signals["Ty"] = 1.10 * run.signals["Ty"]
    ctx, start, offset = _lines_and_fitted_offset(test, LINES)
    assert R[2] * 1.01 < offset.r[2] < R[2] * 1.10            # the fitted offset takes part of the gain
    (u,) = channel_gain(ctx, as_recorded(offset.apply(start)), lambda chans, hs, runs: (0.0, 0.0))
    assert set(u.channels) == {"Tx", "Ty"}
    assert u.parameters["amplitude_ratio"] == pytest.approx(1.10, rel=0.005)


@pytest.mark.parametrize("r_mm", [(10.0, -5.0, 30.0), (30.0, -15.0, 30.0)])
def test_a_lateral_load_cell_offset_without_a_gain_describes_none(r_mm):
    """review14: read as recorded, a lateral offset puts r_y·Fz in Tx and −r_x·Fz in Ty, unequal, so it tilts the pair
    on the axial lines' orders; two such orders (axial force lines of 0.4 µkg·m at h 3 and 4, the radial torque lines
    there of 5 nkg·m², as weak as the lateral r × F: 2-12 nkg·m) must not read as a gain: a gain tilts every line.  The offset as the ``cross_coupling`` fit gives it
    (within 0.1 mm), the data with no gain: nothing described, on the recorded channels (as diagnose reads them) and
    on the corrected ones."""
    from test_describe_offset_floor import LINES, SPEEDS_RPM, lever_arm_test

    from rwadist.diagnose.describe_gain import as_recorded, channel_gain

    lines = LINES + [("axial_force", 3.0, 4e-7), ("radial_torque", 3.0, 5e-9),
                     ("axial_force", 4.0, 4e-7), ("radial_torque", 4.0, 5e-9)]
    r = np.array(r_mm) * 1e-3
    ctx, start, offset = _lines_and_fitted_offset(lever_arm_test(lines, r, SPEEDS_RPM, 13), lines)
    np.testing.assert_allclose(offset.r, r, atol=1e-4)
    state = offset.apply(start)
    for read in (as_recorded(state), state):
        assert channel_gain(ctx, read, lambda chans, hs, runs: (0.0, 0.0)) == []
