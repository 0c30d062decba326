"""The axial suspension mode is judged on the axial force's lines alone: the axial torque has no mode.

The extended model passes the axial-torque (Tz) lines through (hard-mounted: no torsional mode, rwadist.extended).
The misfit check near a mode (rwadist.extended_fit.MISFIT_DB) took every axial row within 10 % of the axial mode's
frequency, Tz's as well: on trial15's clean data (seeds 1 and 2) a weak motor line of Tz (h 12 at 1000 rpm, read with
its noise: +3.8 dB) passing 220 Hz made the axial force's mode "not constrained" (1.15 and 1.46 dB RMS) though every
axial-force line there fitted within 0.01 dB.

Here a family wheel (tests/family_wheel.py, generated without rwadist's physics) gets a Tz line whose amplitude
alternates run to run by e^(±0.5) (4.3 dB off any C·Ω² law) and sweeps through the axial mode: the axial mode stays
constrained, within 2 %.  The same scatter on an axial-force line there is still seen (the check is not blind).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.extended_fit import MISFIT_DB, fit_extended  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_resonance import _mode_hz  # noqa: E402

N_SPEEDS = 24


def _scattered_line(wheel, data, channel: int, scale: float) -> float:
    """Add to ``channel`` of every run a line at 1.5·f_axial/f_spin,max times the speed, amplitude ``scale``·Ω² times
    e^(+0.5) on even runs and e^(−0.5) on odd ones; returns its h."""
    h = 1.5 * wheel.f_axial / (wheel.max_rpm / 60.0)
    t = np.arange(data.signals.shape[2]) / data.sample_rate
    for i, om in enumerate(data.speeds):
        a = scale * om**2 * np.exp(0.5 if i % 2 == 0 else -0.5)
        data.signals[i, channel] += a * np.cos(h * om * t + 0.3 * i)
    return h


def _efit(wheel, channel: int, seed: int):
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, N_SPEEDS), n_samples=4096,
                     noise=0.01, seed=seed)
    # a line 30 % of the imbalance's load: clear of the noise (1 % of the top-speed imbalance) from the lowest speed
    group = "radial_torque" if channel == 5 else "radial_force"
    _scattered_line(wheel, data, channel, 0.3 * wheel.imbalance(group))
    test = steady_test(data)
    return fit_extended(test, fit_empirical(compute_spectra(test)))


@pytest.mark.parametrize("index, seed", [(0, 1), (3, 2), (7, 3)])
def test_a_scattered_axial_torque_line_leaves_the_axial_mode_constrained(index, seed):
    wheel = fw.family()[index]
    efit = _efit(wheel, 5, seed)
    assert "axial" not in efit.unconstrained, efit.notes
    assert efit.residual_db["axial_translation"] < MISFIT_DB
    assert _mode_hz(efit.params)["axial"] == pytest.approx(wheel.f_axial, rel=0.02)


def test_a_scattered_axial_force_line_is_still_a_misfit():
    wheel = fw.family()[3]
    efit = _efit(wheel, 2, 2)
    assert efit.residual_db["axial_translation"] > MISFIT_DB
