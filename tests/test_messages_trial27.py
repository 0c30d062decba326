"""Messages a new-user trial (27) found wrong, each asserted by the key parts of its new text.

(a) ``campbell`` of a model without extended parameters advised the psd's choices (``--empirical``, "with the
rotor's --mass and --radius"): it now says what the Campbell diagram needs.  (b) ``fit -o X --report X`` ran the
whole fit, then said ``X: Is a directory``: refused up front.  (c) A speed profile whose time goes back printed
``np.float64(5.0)``: plain numbers.  (d) ``fit sweep.csv --speed-source tach`` on a sweep without a tach named
``<sweep>`` and ``speed_source='tach'``: the file and the flag.  (e) ``fit --cumulative-rpm abc`` suggested
``--n-speeds``, which fit does not have."""
from __future__ import annotations

import numpy as np
import pytest
from cli_run import run

import rwadist
from rwadist.cli import main


@pytest.fixture(scope="module")
def steady(tmp_path_factory):
    path = tmp_path_factory.mktemp("m27") / "w"
    assert main(["simulate-test", str(path), "--preset", "ithaco-e", "--speeds-rpm", "600:3000", "--n-speeds", "8",
                 "--samples", "2048"]) == 0
    return path


@pytest.fixture(scope="module")
def empirical_model(steady, tmp_path_factory):
    path = tmp_path_factory.mktemp("m27m") / "m.json"
    assert main(["fit", str(steady), "-o", str(path), "--no-report"]) == 0
    return path


def test_campbell_of_a_model_without_modes_says_what_campbell_needs(empirical_model, tmp_path, capsys):
    code, _, err = run(capsys, "campbell", empirical_model, "-o", tmp_path / "c.csv")
    assert code == 2
    assert "which the Campbell diagram is made of" in err
    assert "--extended" in err and "--preset" in err
    assert "mass and radius are optional" in err
    assert "--empirical" not in err and "needs only the harmonics" not in err
    with pytest.raises(rwadist.DataError, match="the Campbell diagram") as info:
        rwadist.campbell(str(empirical_model), [600.0, 1200.0])
    assert "`preset`" in str(info.value)


def test_fit_refuses_a_report_at_the_model_s_path_before_fitting(steady, tmp_path, capsys):
    out = tmp_path / "r1.json"
    code, text, err = run(capsys, "fit", steady, "-o", out, "--report", out)
    assert code == 2
    assert "--report: value:" in err and "the same path as -o" in err
    assert f"--report {tmp_path / 'r1_report'}" in err
    assert "Is a directory" not in err
    assert "fitted" not in text and "reading runs" not in err       # refused before the data are read
    assert not out.exists()


def test_a_profile_going_back_in_time_names_plain_numbers(tmp_path, capsys):
    prof = tmp_path / "prof_back.csv"
    prof.write_text("time_s,speed_rpm\n0,1000\n10,2000\n5,1500\n")
    code, _, err = run(capsys, "psd", "--preset", "ithaco-e", "--speed-rpm", "1000:2000", "--dist", prof,
                       "-o", tmp_path / "p.csv")
    assert code == 2
    assert "time_s: must increase: data row 3 (5 s) <= data row 2 (10 s)" in err
    assert "np.float64" not in err


def _sweep_without_tach(path):
    fs, n = 1000.0, 20_000
    t = np.arange(n) / fs
    w = (300 + 2700 * t / t[-1]) * 2 * np.pi / 60
    theta = np.cumsum(w) / fs
    rng = np.random.default_rng(0)
    cols = {c: 1e-6 * w**2 * np.cos(theta + k) + 1e-3 * rng.standard_normal(n)
            for k, c in enumerate(("Fx_N", "Fy_N", "Fz_N", "Tx_Nm", "Ty_Nm", "Tz_Nm"))}
    np.savetxt(path, np.column_stack([t, *cols.values()]), delimiter=",", header="time_s," + ",".join(cols),
               comments="", fmt="%.10g")
    return path


def test_speed_source_tach_on_a_sweep_without_tach_names_the_file_and_flag(tmp_path, capsys):
    sweep = _sweep_without_tach(tmp_path / "sweep.csv")
    code, _, err = run(capsys, "fit", sweep, "-o", tmp_path / "s.json", "--no-report", "--speed-source", "tach")
    assert code == 2
    assert f"{sweep}: " in err and "<sweep>" not in err
    assert "--speed-source tach, but the sweep has no tach column" in err
    assert "--speed-source data" in err
    assert "speed_source=" not in err
    with pytest.raises(rwadist.DataError, match="sweep.csv") as info:
        rwadist.read(sweep, speed_source="tach")
    assert "<sweep>" not in str(info.value)


@pytest.mark.parametrize("value, words", [("abc", "not a number; give speeds in rpm as A,B,C or START:STOP:STEP"),
                                          ("600:2400", "START:STOP gives no number of speeds")])
def test_fit_cumulative_rpm_suggests_no_flag_fit_lacks(steady, tmp_path, capsys, value, words):
    code, _, err = run(capsys, "fit", steady, "-o", tmp_path / "m.json", "--cumulative-rpm", value)
    assert code == 2
    assert "--cumulative-rpm: value:" in err and words in err
    assert "--n-speeds" not in err


def test_campbell_speeds_still_suggest_n_speeds(tmp_path, capsys):
    code, _, err = run(capsys, "campbell", "--preset", "ithaco-e", "-o", tmp_path / "c.csv", "--speeds-rpm", "abc")
    assert code == 2 and "START:STOP with --n-speeds" in err
