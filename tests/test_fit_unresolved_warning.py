"""``rwadist fit`` says which harmonics it detected but did not measure apart from a line beside them.

The empirical fit measures a line by the power in its window of ±line_half_width bins; two lines closer than that at
every speed are detected (present in enough runs) and neither is measured: the model lacked them with no word (a
session-63 trial's run-up: a line the speed smeared over its slices read as two candidates, neither kept; family wheel
1's 30-s run-up: its axial 6.66 line).  Independent references: an E-like wheel generated without rwadist's physics
(tests/standmodes_wheel.py) with speed sidebands 0.06 beside its imbalance (1.5 Hz at 1500 rpm on 0.61-Hz bins: all
three inside one window), the same wheel without them, and a family wheel's time-integrated run-up
(tests/family_wheel.py) written without a speed column.
"""
import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
import standmodes_wheel as sw  # noqa: E402

from rwadist.cli import main  # noqa: E402
from rwadist.data import write_steady  # noqa: E402

SAID = "were not measured apart from a line beside them"


def _fit_stderr(tmp_path, capsys, data, *flags) -> str:
    assert main(["fit", str(data), "-o", str(tmp_path / "model.json"), "--no-report", *flags]) == 0
    return capsys.readouterr().err


@pytest.mark.parametrize("sidebands", [True, False])
def test_sidebands_inside_the_fits_window_are_named_on_steady_runs(tmp_path, capsys, sidebands):
    test, _ = sw.generate(sw.E_WHEEL, np.linspace(300.0, 2400.0, 16), sample_rate=5000.0, n_samples=8192,
                          noise=0.01, seed=7, speed_sidebands=("radial_force", 1.0, 0.06, 0.4) if sidebands else None)
    err = _fit_stderr(tmp_path, capsys, write_steady(test, tmp_path / "runs"))
    said = [ln for ln in err.splitlines() if SAID in ln]
    if not sidebands:
        assert said == [], err
        return
    assert len(said) == 1, err
    hs = [float(x) for x in re.findall(r"radial_force h=([0-9.]+)", said[0])]
    assert hs and all(min(abs(h - t) for t in (0.94, 1.0, 1.06)) < 0.02 for h in hs), said
    assert "--nperseg" in said[0] and "--extended" in said[0]


@pytest.mark.slow
def test_a_line_a_run_up_smears_over_its_slices_is_named(tmp_path, capsys):
    wheel = fw.family()[1]
    csv = fw.write_sweep(fw.sweep(wheel, wheel.min_rpm, wheel.max_rpm, 30.0, noise=0.01, seed=1), tmp_path / "s.csv",
                         tach=False)
    err = _fit_stderr(tmp_path, capsys, csv)
    said = [ln for ln in err.splitlines() if SAID in ln]
    assert len(said) == 1 and "axial_force h=6.6" in said[0] and "smears across a slice" in said[0], err


@pytest.mark.slow
def test_the_extended_fit_measures_them_and_says_nothing(tmp_path, capsys):
    """``rwadist fit --extended`` measures the sidebands and the imbalance together on the records (a reviewer: the
    warning said "the empirical model lacks them" above a model file that held all three): no such warning, and the
    model's radial-force lines at 0.94, 1 and 1.06."""
    test, _ = sw.generate(sw.E_WHEEL, np.linspace(300.0, 2400.0, 16), sample_rate=5000.0, n_samples=8192,
                          noise=0.01, seed=7, speed_sidebands=("radial_force", 1.0, 0.06, 0.4))
    err = _fit_stderr(tmp_path, capsys, write_steady(test, tmp_path / "runs"), "--extended")
    assert SAID not in err, err
    hs = [r["h"] for r in json.loads((tmp_path / "model.json").read_text())["empirical"]["radial_force"]]
    assert all(min(abs(h - t) for h in hs) < 0.002 for t in (0.94, 1.0, 1.06)), hs
