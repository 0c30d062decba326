"""diagnose on too few speeds (an independent trial, trial12): one steady run file given as the data was read as a
sweep of 8 slices at one speed, its h 3.3 line taken for the 1x, a harmonic added, and no word that the speed never
changed; a steady-test folder of one run ended in an internal error.  Runs at fewer than 2 distinct speeds are
refused naming the file (a sweep at one speed said to be one steady run); fewer than the empirical fit's 5 speeds,
without a model, are warned of."""
from __future__ import annotations

import numpy as np
import pytest

from rwadist.cli import main

FS, N, RPM = 4096.0, 16384, 2400.0


def _write_run(path, rpm=RPM, seed=0):
    """A steady run in the documented run-file format (docs/formats.md: time_s, Fx_N ... Tz_Nm), made here with numpy:
    a rotating imbalance force and torque at h 1 and 2 (x cos, y sin: co-rotating), a non-integer line at h 3.3 on
    every channel, white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    w = 2 * np.pi * rpm / 60.0
    cols = {c: 1e-3 * rng.standard_normal(N) for c in ("Fx_N", "Fy_N", "Fz_N", "Tx_Nm", "Ty_Nm", "Tz_Nm")}
    for h, a in ((1.0, 0.5), (2.0, 0.1), (3.3, 0.05)):
        ph = rng.uniform(0, 2 * np.pi)
        cols["Fx_N"] += a * np.cos(h * w * t + ph)
        cols["Fy_N"] += a * np.sin(h * w * t + ph)
        cols["Tx_Nm"] += 0.1 * a * np.cos(h * w * t + ph + 1.0)
        cols["Ty_Nm"] += 0.1 * a * np.sin(h * w * t + ph + 1.0)
        cols["Fz_N"] += 0.2 * a * np.cos(h * w * t + 2 * ph)
    data = np.column_stack([t] + list(cols.values()))
    np.savetxt(path, data, delimiter=",", header="time_s," + ",".join(cols), comments="", fmt="%.9g")


def test_one_steady_run_given_as_the_data_is_refused_naming_the_file(tmp_path, capsys):
    run = tmp_path / "run_0005.csv"
    _write_run(run)
    assert main(["diagnose", str(run), "-o", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert f"{run}: speed_rpm: runs at 1 distinct speed" in err
    assert "read as a sweep" in err and "one steady run recorded as one file" in err and "steady-test folder" in err
    assert not (tmp_path / "r").exists()


def test_a_steady_folder_of_one_speed_is_refused_and_of_three_warned(tmp_path, capsys):
    one = tmp_path / "one"
    one.mkdir()
    _write_run(one / "run_a.csv")
    (one / "runs.csv").write_text(f"file,speed_rpm\nrun_a.csv,{RPM}\n")
    assert main(["diagnose", str(one), "-o", str(tmp_path / "r1")]) == 2
    err = capsys.readouterr().err
    assert f"{one}: speed_rpm: runs at 1 distinct speed (2400 rpm)" in err and "internal error" not in err
    assert not (tmp_path / "r1").exists()
    three = tmp_path / "three"
    three.mkdir()
    rows = []
    for i, rpm in enumerate((1200.0, 1800.0, 2400.0)):
        _write_run(three / f"run_{i}.csv", rpm, seed=i)
        rows.append(f"run_{i}.csv,{rpm}")
    (three / "runs.csv").write_text("file,speed_rpm\n" + "\n".join(rows) + "\n")
    assert main(["diagnose", str(three), "-o", str(tmp_path / "r3")]) == 0
    err = capsys.readouterr().err
    assert f"WARNING: {three}: runs at 3 distinct speeds (1200, 1800, 2400 rpm)" in err
    assert (tmp_path / "r3" / "summary.json").exists()


@pytest.mark.parametrize("speeds", [[1000.0, 1000.5, 1001.0], [-1500.0, 1500.0]])
def test_speeds_within_a_thousandth_or_of_opposite_sign_count_as_one(speeds):
    """0.1 % of the top speed apart is one speed; a run at -Ω is the same speed spun the other way (no new point of a
    law in |Ω|)."""
    from types import SimpleNamespace

    from rwadist.errors import DataError
    from rwadist.validate import check_test_speeds

    test = SimpleNamespace(runs=[SimpleNamespace(speed=2 * np.pi * s / 60.0) for s in speeds], meta={})
    with pytest.raises(DataError, match="runs at 1 distinct speed"):
        check_test_speeds(test, "x")


def test_a_slow_sweeps_many_slices_count_and_a_speed_not_finite_does_not():
    """600 slices from 2000 to 3000 rpm (1.67 rpm apart, under 0.1 % of the top speed each) are 334 speeds, not one
    (each speed is counted against the last one counted, not its neighbour; review12); a run whose speed is NaN is
    left out, not read as the test having one speed."""
    from types import SimpleNamespace

    from rwadist.validate import check_test_speeds

    slow = SimpleNamespace(runs=[SimpleNamespace(speed=2 * np.pi * s / 60.0) for s in np.linspace(2000, 3000, 600)],
                           meta={"slicing": {}})
    check_test_speeds(slow, "sweep.csv", model_given=True)
    odd = SimpleNamespace(runs=[SimpleNamespace(speed=s) for s in (np.nan, 100.0, 200.0, 300.0, 400.0, 500.0)], meta={})
    check_test_speeds(odd, "x")


def test_runs_without_a_finite_speed_are_named_as_such():
    """Every speed NaN or infinite: no "0 distinct speed ()" (review12), the reason in words."""
    from types import SimpleNamespace

    from rwadist.errors import DataError
    from rwadist.validate import check_test_speeds

    test = SimpleNamespace(runs=[SimpleNamespace(speed=s) for s in (np.nan, np.inf)], meta={})
    with pytest.raises(DataError, match=r"no run with a finite speed \(every speed is NaN or infinite\): diagnose "
                                        r"needs runs at 2 speeds"):
        check_test_speeds(test, "x")
