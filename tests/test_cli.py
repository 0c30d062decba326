"""The rwadist command line end to end on small generated data."""
import csv
import io
import json

import numpy as np
import pytest
from cli_run import run

from rwadist.cli import parse_speeds
from rwadist.data import DataError, read_steady, read_sweep
from rwadist.presets import preset


def test_parse_speeds():
    np.testing.assert_allclose(parse_speeds("0:3000:1000"), [0, 1000, 2000, 3000])
    np.testing.assert_allclose(parse_speeds("300:2400", 3), [300, 1350, 2400])
    np.testing.assert_allclose(parse_speeds("-500,0,500"), [-500, 0, 500])
    with pytest.raises(DataError):
        parse_speeds("300:2400")          # needs --n-speeds
    with pytest.raises(DataError):
        parse_speeds("a,b")
    with pytest.raises(DataError, match="gives its own number of speeds: drop --n-speeds"):
        parse_speeds("0:3000:100", 5)          # --n-speeds beside a STEP was ignored


def test_simulate_fit_show(tmp_path, capsys):
    data = tmp_path / "e"
    code, out, _ = run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400",
                       "--n-speeds", "16", "--samples", "4096", "--no-modes", "--seed", "3")
    assert code == 0 and "16 runs" in out
    assert len(read_steady(data).runs) == 16
    model = tmp_path / "m.json"
    code, out, _ = run(capsys, "fit", data, "-o", model, "--cumulative-rpm", "700,1500")
    assert code == 0 and model.exists() and (tmp_path / "m_report" / "summary.md").exists()
    code, out, _ = run(capsys, "model", "show", model, "--format", "csv")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert list(rows[0]) == ["direction", "h", "C_SI", "C_stderr_SI", "sense"]
    truth = preset("ithaco-e").to_model()
    for d in ("radial_force", "radial_torque", "axial_force"):
        got = {round(float(r["h"]), 2): float(r["C_SI"]) for r in rows if r["direction"] == d}
        th, tc = truth.h_and_C(d)
        # the fundamental of every direction within 1 % (the full check is the slow acceptance suite)
        assert got[1.0] == pytest.approx(tc[0], rel=0.01)
        assert all(float(r["C_stderr_SI"]) > 0 for r in rows)


def test_fit_a_sweep_file(tmp_path, capsys):
    out_dir = tmp_path / "s"
    code, _, _ = run(capsys, "simulate-test", "--preset", "ithaco-e", out_dir, "--sweep", "--duration", "60",
                     "--sweep-start-rpm", "600", "--sweep-end-rpm", "2400", "--sample-rate", "1920", "--no-modes")
    assert code == 0
    sweep = read_sweep(out_dir / "sweep.csv")
    assert sweep.tach is not None
    code, out, _ = run(capsys, "fit", out_dir / "sweep.csv", "-o", tmp_path / "s.json", "--slice-samples", "4096",
                       "--no-report")
    assert code == 0 and "sliced sweep" in out


def test_fit_no_report_writes_the_model_only(tmp_path, capsys):
    """``--no-report``: the model file of the Python API's fit (what the report is drawn from), no report directory;
    with ``--report`` refused."""
    from rwadist import api
    from rwadist import model as model_io
    from rwadist.outputs import MANIFEST

    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "8",
        "--samples", "2048", "--sample-rate", "1920", "--no-modes")
    code, out, _ = run(capsys, "fit", data, "-o", tmp_path / "a.json", "--no-report")
    assert code == 0 and "--no-report" in out and not (tmp_path / "a_report").exists()
    assert {p.name for p in tmp_path.iterdir()} == {"e", "a.json", MANIFEST}   # the model and the record of it
    got = json.loads((tmp_path / "a.json").read_text())
    want = json.loads(json.dumps(model_io.to_json(api.fit(api.read(data)).model)))
    assert got["empirical"] == want["empirical"] and got["empirical"]
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "c.json", "--no-report", "--report", tmp_path / "r")
    assert code == 2 and "--no-report" in err and "--report" in err
    assert not (tmp_path / "c.json").exists() and not (tmp_path / "r").exists()


def _one_run(text):
    def make(d):
        (d / "runs.csv").write_text("file,speed_rpm\nr.csv,1000\n")
        (d / "r.csv").write_text(text)
    return make


@pytest.mark.parametrize("make,field", [
    (lambda d: None, "runs.csv"),                                              # empty directory
    (_one_run("time_s,Fx_N\n0,1\n0.001,nan\n0.002,1\n"), "Fx_N"),              # NaN sample
    (_one_run("time_s,Fx_lbf\n0,1\n0.001,1\n"), "Fx_lbf"),                      # wrong units
])
def test_bad_input_exits_2_naming_file_and_field(tmp_path, capsys, make, field):
    d = tmp_path / "bad"
    d.mkdir()
    make(d)
    code, _, err = run(capsys, "fit", d, "-o", tmp_path / "m.json")
    assert code == 2
    msg = err.splitlines()[-1]
    assert "rwadist: error:" in msg and field in msg and str(d) in msg


def test_run_shorter_than_fft_segment(tmp_path, capsys):
    d = tmp_path / "short"
    run(capsys, "simulate-test", "--preset", "ithaco-e", d, "--speeds-rpm", "1000,2000", "--samples", "256")
    code, _, err = run(capsys, "fit", d, "-o", tmp_path / "m.json", "--nperseg", "1024")
    assert code == 2 and "samples" in err and "shorter than one FFT segment" in err


def test_model_show_refuses_other_schema(tmp_path, capsys):
    p = tmp_path / "m.json"
    p.write_text('{"schema": "rwadist.model", "schema_version": 99}')
    code, _, err = run(capsys, "model", "show", p)
    assert code == 2 and "schema_version" in err and "99" in err


def test_demo_small(tmp_path, capsys):
    code, out, _ = run(capsys, "demo", "--out", tmp_path / "demo", "--n-speeds", "24")
    assert code == 0
    assert (tmp_path / "demo" / "model.json").exists() and (tmp_path / "demo" / "report" / "summary.md").exists()
    assert "h fit" in out and "radial_force" in out



def test_fit_warns_of_harmonics_left_out_as_modally_amplified(tmp_path, capsys):
    """Through the wheel's modes (extended physics, 300-3000 rpm) the rocking whirls lift the radial-torque lines at
    nearly every speed: the plain fit leaves them out of the C·Ω² model (the file had 9 of the data's 18 lines and the
    console said nothing); it now names them and what to do.  The extended fit keeps every line and says how many."""
    from rwadist import model as model_io

    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "300:3000", "--n-speeds", "40",
        "--samples", "4096", "--physics", "extended")
    code, out, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--no-report")
    assert code == 0
    fitted = model_io.load(tmp_path / "m.json")
    assert ("radial_torque", 1.0) not in {(d, round(h.h, 2)) for d in fitted.empirical for h in fitted.empirical[d]}
    assert "WARNING" in err and "radial_torque h=1," in err and "--extended" in err and "--no-mode-exclusion" in err
    code, out, err = run(capsys, "fit", data, "-o", tmp_path / "x.json", "--no-report", "--extended")
    n = sum(len(v) for v in model_io.load(tmp_path / "x.json").empirical.values())
    assert code == 0 and f"extended model: {n} forcing lines" in out and "WARNING" not in err


def test_fit_extended_then_campbell_from_the_fitted_model(tmp_path, capsys):
    """simulate (extended physics) -> fit --extended -> campbell on the fitted model file."""
    from rwadist import extended as ext
    from rwadist import model as model_io

    data = tmp_path / "e"
    code, _, _ = run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400",
                     "--n-speeds", "30", "--samples", "4096", "--sample-rate", "1920", "--physics", "extended")
    assert code == 0
    code, out, _ = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--extended", "--preset", "ithaco-e")
    assert code == 0 and "rocking at rest" in out
    p = ext.params_from_model(model_io.load(tmp_path / "m.json"))
    assert p.k_rock == pytest.approx(preset("ithaco-e").extended.k_rock, rel=0.02)
    assert (tmp_path / "m_report" / "extended_params.csv").exists()
    code, out, _ = run(capsys, "campbell", tmp_path / "m.json", "--speeds-rpm", "0:3000:500",
                       "-o", tmp_path / "c.csv")
    assert code == 0 and (tmp_path / "c.csv").exists() and (tmp_path / "c.png").exists()


def test_fit_extended_without_mass_and_radius_is_per_unit(tmp_path, capsys):
    # issue 14: mass and radius are optional (the interface loads depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr,
    # I_zz/I_rr); 8 speeds of hard-mounted-like data pin no mode, and the fit says so in the file
    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "8",
        "--samples", "2048", "--sample-rate", "1920")
    code, out, _ = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--extended", "--no-report")
    assert code == 0 and "per unit mass" in out
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["analytical"]["mass_kg"] == 1.0 and doc["analytical"]["unconstrained"]
    # an imbalance read through an unconstrained mode says it rests on that mode's starting value
    loose = [u for u, m in (("U_s", "radial_translation"), ("U_d", "rocking")) if m in doc["analytical"]["unconstrained"]]
    assert not loose or f"({' and '.join(loose)} read through a mode the data do not constrain" in out
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m2.json", "--extended", "--mass", "0", "--radius", "0.2")
    assert code == 2 and "--mass" in err



def test_commands_run_with_one_blas_thread_unless_the_environment_says(monkeypatch, capsys):
    """The command line limits BLAS to one thread (its least squares are small; on 2 busy cores OpenBLAS's threads
    made fit --extended 23x slower), and leaves a count the user set alone."""
    from contextlib import contextmanager

    from threadpoolctl import threadpool_info

    from rwadist import cli, threads

    def blas_threads():
        return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]

    for name in threads.BLAS_THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    with cli.one_blas_thread():
        inside = blas_threads()
    assert inside and all(n == 1 for n in inside)
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    before = blas_threads()
    with cli.one_blas_thread():
        assert blas_threads() == before
    entered = []
    real = cli.one_blas_thread

    @contextmanager
    def recording():
        with real():
            entered.append(True)
            yield

    monkeypatch.setattr(cli, "one_blas_thread", recording)
    assert cli.main(["catalogue", "list"]) == 0 and entered == [True]


def test_a_pool_loaded_during_a_command_runs_one_thread_too():
    """scipy.linalg loads its own OpenBLAS at its first use, after the command started: limited where it stood, it ran
    a thread per core beside busy neighbours (issue 37).  In a fresh interpreter without the thread variables: every
    pool has one thread inside one_blas_thread (numpy's, limited there; scipy's, loaded there), none after."""
    import json
    import os
    import subprocess
    import sys

    from rwadist import threads

    code = """
import json
from threadpoolctl import threadpool_info
from rwadist import threads
def pools():
    return sorted((i["filepath"], i["num_threads"]) for i in threadpool_info())
with threads.one_blas_thread():
    import scipy.linalg
    scipy.linalg.lu_factor([[2.0, 1.0], [1.0, 3.0]])
    inside = pools()
print(json.dumps({"inside": inside, "after": pools()}))
"""
    env = {k: v for k, v in os.environ.items() if k not in threads.ONE_THREAD_ENVIRONMENT}
    out = json.loads(subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                    check=True).stdout)
    assert len(out["inside"]) >= 2                                  # numpy's OpenBLAS and scipy's
    assert all(n == 1 for _, n in out["inside"]), out
    cores = len(os.sched_getaffinity(0))
    assert all(n == cores for _, n in out["after"]), out


def test_fit_refuses_flags_it_would_ignore(tmp_path, capsys):
    """--mass (and --radius, --height, --preset) without --extended were ignored; --cumulative-rpm 5000 on a
    600-2400 rpm test plotted the 2400 rpm run under a title of 5000."""
    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "6",
        "--samples", "1024", "--sample-rate", "1920", "--no-modes")
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--mass", "10")
    assert code == 2 and "--mass" in err and "add --extended" in err
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--cumulative-rpm", "700,5000")
    assert code == 2 and "--cumulative-rpm" in err and "5000 rpm is outside the test's speeds 600-2400 rpm" in err
    assert not (tmp_path / "m.json").exists() and not (tmp_path / "m_report").exists()


def test_f_lim_above_nyquist_names_the_flag(tmp_path, capsys):
    """--f-lim above the data's Nyquist frequency: the error named '<spectra>: f_lim', which the user never typed."""
    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "6",
        "--samples", "1024", "--sample-rate", "1920", "--no-modes")
    for argv in (["fit", data, "-o", tmp_path / "m.json", "--no-report"], ["diagnose", data, "-o", tmp_path / "r"]):
        code, _, err = run(capsys, *argv, "--f-lim", "5000")
        assert code == 2 and "--f-lim: value: 5000 Hz is above the data's Nyquist frequency 960 Hz" in err


def test_simulate_test_says_which_lines_the_sample_rate_drops(tmp_path, capsys):
    code, out, _ = run(capsys, "simulate-test", "--preset", "ithaco-e", tmp_path / "e", "--speeds-rpm", "600:1200",
                       "--n-speeds", "3", "--samples", "1024", "--sample-rate", "100")
    assert code == 0 and "note: 12 of the wheel's lines reach the Nyquist frequency in 3 run(s)" in out
    assert "raise --sample-rate" in out


def test_fit_mass_needs_radius_and_cumulative_needs_the_report(tmp_path, capsys):
    """--mass alone (or --radius alone) gave a per-unit fit with a note only; --cumulative-rpm with --no-report did
    nothing."""
    data = tmp_path / "e"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "6",
        "--samples", "1024", "--sample-rate", "1920", "--no-modes")
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--extended", "--mass", "10.6")
    assert code == 2 and "--mass: value: needs --radius too" in err
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--no-report", "--cumulative-rpm", "700")
    assert code == 2 and "--cumulative-rpm: value: picks the report's plots" in err
