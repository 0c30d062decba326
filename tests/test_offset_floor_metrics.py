"""The figures of merit after the search read the torques against their floor as the final model reads them.

A load-cell offset r (``cross_coupling``) is taken out as T − r × F: the correction carries the force sensors' noise
into the torques, raising their floor by 10·log10(1 + r_z²σ_F²/σ_T²).  Below what the ``lever_arm_noise`` class
needs to be named, the metrics after the search compared the corrected torques with the floor of the uncorrected
ones: trial16's exact 30 mm offset (a 1.3 dB rise) read a narrow-line error 78x its clean cell's, with the torques
red in every band of the "after" waterfall.

Family wheel 1 (tests/family_wheel.py, generated without rwadist's physics) with r_z = 60 mm and force sensors noisy
enough for a 3 dB rise of the corrected torque floor: the offset is named, nothing else is added, and the narrow-line
error after is within 2x the same wheel's clean cell's (main 906dfd9: 44x).
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))

import diagnose_family_matrix as dfm  # noqa: E402
import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

WHEEL = 1
R_Z = 0.06
RISE_DB = 3.0


def _force_noise(wheel, noise: float) -> float:
    """The extra force-sensor noise (a fraction of the top-speed radial imbalance load, as
    :class:`family_effects.LeverArmNoise` takes it) that raises the corrected torques' floor by :data:`RISE_DB`."""
    om = wheel.max_rpm * fw.RPM
    s_f = noise * wheel.imbalance("radial_force") * om**2
    s_t = noise * wheel.imbalance("radial_torque") * om**2
    extra = (10 ** (RISE_DB / 10) - 1) * s_t**2 / R_Z**2 - s_f**2
    return float(np.sqrt(extra) / (wheel.imbalance("radial_force") * om**2))


def _summary(wheel, name, effects, tmp_path):
    dfm.run_cell(WHEEL, wheel, name, "lever_arm_noise", effects, 1 + 100 * WHEEL, tmp_path, None)
    return json.loads((tmp_path / f"w{WHEEL}_{name}" / "report" / "summary.json").read_text())


@pytest.mark.slow
def test_an_offsets_corrected_torques_are_read_against_their_own_floor(tmp_path, family_clean_cell):
    wheel = dfm.wheels()[WHEEL]
    lever = fe.LeverArmNoise(r=(0.0, 0.0, R_Z), force_noise=_force_noise(wheel, dfm.CONDITIONS[WHEEL][2]))
    clean = json.loads((family_clean_cell(WHEEL)[1] / "report" / "summary.json").read_text())
    cell = _summary(wheel, "offset", [lever], tmp_path)
    kinds = [e["kind"] for e in cell["effects"]]
    assert "cross_coupling" in kinds and set(kinds) <= {"suspension_modes", "cross_coupling", "lever_arm_noise"}, kinds
    assert cell["narrow_line_error_after"] <= 2.0 * clean["narrow_line_error_after"], (
        cell["narrow_line_error_after"], clean["narrow_line_error_after"])
    assert cell["error_after"] <= 5.0 * clean["error_after"], (cell["error_after"], clean["error_after"])
