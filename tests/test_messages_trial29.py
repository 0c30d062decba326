"""What new-user trial 29 found unsaid on the command line: an earlier report beside a model written without one, one
steady run's file read as a sweep, a negative value after a flag."""
import pytest
from cli_run import run


def test_a_model_written_without_its_report_names_the_earlier_report_beside_it(tmp_path, capsys):
    """``fit -o m.json --no-report`` over a model whose report folder is beside it (new-user trial 29: the old report
    listed 11 harmonics beside a new empty model, nothing said): the note names the folder as an earlier fit's."""
    data = tmp_path / "eight"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "8",
        "--samples", "2048")
    (tmp_path / "m_report").mkdir()            # where `fit -o m.json` put its report (tests/test_cli.py)
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--no-report")
    assert code == 0 and "m_report is the report of an earlier fit" in err
    code, _, err = run(capsys, "fit", data, "-o", tmp_path / "n.json", "--no-report")
    assert code == 0 and "earlier fit" not in err


def test_one_steady_run_file_read_as_a_sweep_is_named(tmp_path, capsys):
    """A steady run's CSV given alone (no runs.csv) is read as a sweep with its speed from the data; the slices all
    sit at one speed, which the command now says (new-user trial 29: "sliced sweep into 8 quasi-steady runs", nothing
    else).  A real sweep gets no such note."""
    data = tmp_path / "eight"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "8",
        "--samples", "65536")
    run_file = sorted(data.glob("run_*.csv"))[3]
    code, out, err = run(capsys, "fit", run_file, "-o", tmp_path / "m.json", "--no-report")
    assert "the speed hardly changes over" in out + err and "one steady run?" in out + err
    sweep = tmp_path / "sweep"
    run(capsys, "simulate-test", "--preset", "ithaco-e", sweep, "--sweep", "--duration", "60")
    code, out, err = run(capsys, "fit", next(sweep.glob("*.csv")), "-o", tmp_path / "s.json", "--no-report")
    assert code == 0 and "hardly changes" not in out + err


def test_a_negative_value_after_a_flag_is_told_to_go_after_equals(capsys):
    """``--speed-rpm -3000:-600`` (argparse reads the value as a flag) says how to give it (new-user trial 29)."""
    with pytest.raises(SystemExit) as info:
        run(capsys, "psd", "m.json", "--empirical", "--speed-rpm", "-3000:-600")
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "argument --speed-rpm: expected one argument" in err and "--speed-rpm=-VALUE" in err


def test_a_channel_in_pound_force_is_named_by_its_unit_factor():
    """Fy recorded in lbf and declared N: Fy × 4.44822 of its true value in N (new-user trial 29).  The
    diagnosis names the gain (it did) and now the unit factor it is; a plain gain error (× 1.10) names no unit."""
    from dataclasses import replace

    import numpy as np

    import rwadist
    from rwadist.units import unit_words

    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 24), n_samples=4096, seed=1,
                                 physics="extended")
    test = type(test)([replace(r, signals={**r.signals, "Fy": r.signals["Fy"] * 4.44822}) for r in test.runs],
                      test.meta)
    (gain,) = [u for u in rwadist.diagnose(test).unexplained if u.parameters.get("property") == "channel_gain"]
    assert gain.parameters["amplitude_ratio"] == pytest.approx(4.44822, rel=0.01)
    assert "near the number of N in one lbf" in gain.causes[0]
    assert unit_words(1.10, "Fx") == "" and "in·lbf in one N·m" in unit_words(8.9, "Tx")


def test_the_demo_is_not_written_into_a_dataset_folder(tmp_path, capsys):
    """``rwadist demo --out LAB`` put data.h5, model.json and report/ beside a lab's runs (trial 29): refused, exit 2,
    nothing written."""
    data = tmp_path / "lab"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "600:2400", "--n-speeds", "3",
        "--samples", "512")
    before = sorted(p.name for p in data.iterdir())
    code, _, err = run(capsys, "demo", "--out", data)
    assert code == 2 and "holds a steady-test dataset (runs.csv)" in err
    assert sorted(p.name for p in data.iterdir()) == before
