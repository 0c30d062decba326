"""A line that reaches the load cell without the suspension is said to be C·Ω² there, not only a steep law of a
load carried through the modes.

Session 62's trial: a motor-stator line h 24 (co-rotating, exactly C·Ω² at the interface, on a 7.5-kg wheel whose
translation mode is 135 Hz) was named ``amplitude law ... |Ω|^3.87``: the law of a load on the rotor that the
suspension's roll-off (about 1/ν² above the mode) brings to Ω² at the load cell; the source's law and amplitude it
stated were false, and nothing said what the data show at the interface.

Data: family wheel 2 (tests/family_wheel.py, time-integrated physics; translation 90 Hz) over 900-3000 rpm, with a
co-rotating radial-force line at h 10 added at the cell (150-500 Hz, above every mode and its whirl: the suspension
never carries it), C·Ω² with C 3 % of the imbalance's."""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from cli_run import run  # noqa: E402

H = 10.0


class StatorLine(fe.Effect):
    """A co-rotating radial-force line C·Ω² at ``h`` × the speed added at the cell (the housing side)."""

    kind = "stator_line"
    expects = "unexplained"

    def __init__(self, h: float, C: float):
        super().__init__(h=h, C=C)

    def cell_components(self, omega, run, rng, wheel):
        a = self.params["C"] * omega ** 2 * np.exp(1j * rng.uniform(0, 2 * np.pi))
        A = np.zeros((1, 6), complex)
        A[0, 0], A[0, 1] = a, -1j * a                  # co-rotating: Fx = cos, Fy = sin
        w = np.array([self.params["h"] * abs(omega)])
        return fw.Components(["cell"], w, np.ones(1), np.ones(1, complex), [self.kind]), A


def test_a_stator_line_reads_omega_squared_at_the_load_cell(tmp_path, capsys):
    """``rwadist diagnose DATA -o R``: the h 10 line's ``amplitude_law`` (a load's law through the modes, |Ω|^p with
    p 3 or more) carries ``exponent_at_interface`` within 0.15 of 2, and the console says C·Ω² at the interface and a
    load that bypasses the suspension; the wheel's modes within 2 %."""
    wheel = fw.family()[2]
    effect = StatorLine(H, 0.03 * wheel.imbalance("radial_force"))
    speeds = np.linspace(900.0, 3000.0, 24)
    data = fw.write_steady(fw.steady(wheel, speeds_rpm=speeds, seed=201, effects=[effect]), tmp_path / "data")
    code, out, err = run(capsys, "diagnose", data, "-o", tmp_path / "r")
    assert code == 0, err
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    laws = [e for e in summary["effects"] if e["kind"] == "amplitude_law" and abs(e["h"] - H) < 0.01]
    assert laws, [(e["kind"], e.get("h")) for e in summary["effects"]]
    law = laws[0]
    assert law["exponent"] >= 3.0 and law["exponent_at_interface"] == pytest.approx(2.0, abs=0.15), law
    assert any("h 10," in row and "without the suspension" in row for row in out.splitlines()), out
    modes = next(e for e in summary["effects"] if e["kind"] == "suspension_modes")
    for m, f in wheel.modes_hz().items():
        assert modes[f"{m}_Hz"] == pytest.approx(f, rel=0.02), (m, modes[f"{m}_Hz"], f)
