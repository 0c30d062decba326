"""A radial translation split into an x and a y mode (a support stiffer along one axis) is described as such
(rwadist.diagnose.describe_split; trial25 "aniso": the translation was declared not located and report.md said
"Nothing" at 5x the clean level).

The family generator's translation is axisymmetric: x and y each react (k + iwc)·X with one k.  A support stiffer
along x by a factor s gives x its own mode, f_x = f_t·sqrt(s), and x alone the reaction of that mode: Fx multiplied
by T(f; f_x)/T(f; f_t), with T the generator's own transfer of the radial force (tests/family_wheel.transfer), the
rotor's loads and Fy unchanged (translation has no gyroscopic coupling of x and y)."""
import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.describe_split import fit_split  # noqa: E402


class StifferAlongX:
    """Fx through a translation mode at f_t·sqrt(stiffness) (the generator's hook: a gain at the cell)."""

    def __init__(self, wheel, stiffness):
        self.wheel, self.stiff = wheel, dataclasses.replace(wheel, f_trans=wheel.f_trans * np.sqrt(stiffness))

    def gain(self, f_hz, omega):
        w = 2 * np.pi * np.asarray(f_hz, dtype=float)
        g = np.ones((w.size, 6), dtype=complex)
        g[:, 0] = (fw.transfer(self.stiff, "radial_force", w, omega)[:, 0, 0]
                   / fw.transfer(self.wheel, "radial_force", w, omega)[:, 0, 0])
        return g


def _splits(wheel, effects=(), seed=4):
    diag = api.diagnose(family_test.steady_test(fw.steady(wheel, seed=seed, noise=0.01, effects=effects)))
    return [u for u in diag.unexplained if u.signature == "line_property"
            and u.parameters.get("property") == "split_mode"]


@pytest.mark.parametrize("index, stiffness", [(3, 1.08), (6, 0.9)])
def test_a_support_stiffer_along_one_axis_is_described_with_both_modes(index, stiffness):
    """Family wheels 3 (translation 230 Hz, 6000 rpm) and 6 (150 Hz, 3000 rpm), x stiffer by 8 % / softer by 10 %."""
    wheel = fw.family()[index]
    (u,) = _splits(wheel, [StifferAlongX(wheel, stiffness)])
    assert u.parameters["f_x_Hz"] == pytest.approx(wheel.f_trans * np.sqrt(stiffness), rel=0.015)
    assert u.parameters["f_y_Hz"] == pytest.approx(wheel.f_trans, rel=0.015)
    assert u.parameters["stiffness_ratio"] == pytest.approx(max(stiffness, 1 / stiffness), rel=0.03)
    stiff = "x" if stiffness > 1 else "y"
    assert u.causes[0].startswith(f"a radial translation split in two: along {stiff} at")
    if index == 3:
        assert _splits(wheel) == []                 # the same wheel's clean data: no split


def test_the_split_course_is_fitted_where_it_is_and_a_constant_is_not_taken_for_one():
    """fit_split on the closed form itself (modes at 190 and 200 Hz, ζ 0.02, cells over 100-400 Hz) returns them;
    a constant 1 dB (a gain) leaves the split course no better than the constant."""
    f = np.linspace(100.0, 400.0, 120)

    def L(f0):
        r = f / f0
        return 10 * np.log10((1 + (0.04 * r) ** 2) / ((1 - r**2) ** 2 + (0.04 * r) ** 2))

    fit = fit_split(f, L(200.0) - L(190.0))
    assert fit["f_y_Hz"] == pytest.approx(200.0, rel=0.006) and fit["f_x_Hz"] == pytest.approx(190.0, rel=0.006)
    assert fit["misfit_dB"] < 0.05 * fit["constant_misfit_dB"]
    flat = fit_split(f, np.full(f.size, 1.0) + 0.05 * np.sin(f))
    assert flat["misfit_dB"] > 0.5 * flat["constant_misfit_dB"]
