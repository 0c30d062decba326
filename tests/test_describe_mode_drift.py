"""A suspension mode of the wheel whose frequency moves over the runs (rwadist.diagnose.describe_mode_drift: a
``moving_resonance`` of the model's own mode).

The new-user trial of session 54 (its own generator: a 9 kg wheel, its 140 Hz radial translation falling 6 % from the
first run to the last, recorded in speed order) had "63.3 -> 131.6 Hz, slope +1.20 Hz per Hz of spin" described
beside a fixed 148 Hz resonance, its lifted lines at 141-152 Hz, the causes a rotor mode stiffening.  Here the
family generator's wheels (tests/family_wheel.py, the matrix's conditions) with the radial translation moving
linearly with the run's speed: the generator's own transfer of the moved mode over its fixed one, on Fx and Fy."""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import diagnose_family_matrix as dfm  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


class MovingTranslation:
    """The wheel's radial translation at f_trans·(1 + change·(Ω − Ω_min)/(Ω_max − Ω_min)) in the run at Ω."""

    def __init__(self, wheel, change: float):
        self.wheel, self.change = wheel, change
        self.lo, self.hi = wheel.min_rpm * fw.RPM, wheel.max_rpm * fw.RPM

    def f_trans(self, omega: float) -> float:
        return self.wheel.f_trans * (1 + self.change * (omega - self.lo) / (self.hi - self.lo))

    def gain(self, f_hz, omega):
        w = 2 * np.pi * np.asarray(f_hz, dtype=float)
        moved = replace(self.wheel, f_trans=self.f_trans(omega))
        ratio = fw.transfer(moved, "radial_force", w, omega)[..., 0, 0] / fw.transfer(self.wheel, "radial_force", w,
                                                                                      omega)[..., 0, 0]
        g = np.ones((len(w), 6), dtype=complex)
        g[:, list(fw.DIRECTION_CHANNELS["radial_force"])] = ratio[:, None]
        return g


@pytest.mark.slow
@pytest.mark.parametrize("index, change", [(0, 0.06), (1, -0.06), (3, 0.05), (4, -0.05), (6, -0.06)])
def test_a_suspension_mode_moving_over_the_runs_is_described_as_that_mode(index, change):
    wheel = dfm.wheels()[index]
    moving = MovingTranslation(wheel, change)
    data = fw.steady(wheel, noise=dfm.CONDITIONS[index][2], seed=1, effects=(moving,))
    diag = api.diagnose(family_test.steady_test(data))
    moved = [u for u in diag.unexplained if u.signature == "moving_resonance"
             and u.parameters.get("direction") == "radial_force"]
    assert [u.parameters.get("mode") for u in moved] == ["radial_translation"], [u.text() for u in moved]
    p = moved[0].parameters
    speeds = np.array([u * 2 * np.pi / 60 for u in moved[0].speed_rpm])
    for f, om in ((p["f_at_lowest_speed_Hz"], speeds[0]), (p["f_at_highest_speed_Hz"], speeds[1])):
        assert abs(f / moving.f_trans(om) - 1) < 0.015, (f, moving.f_trans(om))
    assert sorted(e["kind"] for e in diag.model.effects) == ["suspension_modes"]


@pytest.mark.slow
def test_a_fixed_suspension_mode_is_not_described_as_moving(family_clean_cell):
    """Family wheel 1's clean cell: nothing moving is described."""
    _, folder = family_clean_cell(1)
    import json

    summary = json.loads((folder / "report" / "summary.json").read_text())
    assert [u for u in summary["unexplained"] if u["signature"] == "moving_resonance"] == []
