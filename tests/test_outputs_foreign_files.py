"""A single-file output never replaces a file rwadist did not write (new-user trial 27): `convert` onto a lab's CSV or
.h5, `fit -o` onto another dataset's run file, `psd -o` onto a dataset's runs.csv replaced them silently.  A file
rwadist wrote itself (recorded in its folder's .rwadist-files.json, or a model file) is still replaced, so a re-run
works; `save_model` onto a folder is a DataError, not a raw IsADirectoryError."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_run import run

import rwadist
from rwadist.cli import main
from rwadist.outputs import MANIFEST

SIM = ["simulate-test", "--preset", "ithaco-e", "--samples", "1024", "--speeds-rpm", "600,1200,1800,2400",
       "--no-modes"]
PSD = ["psd", "--empirical", "--speed-rpm", "600:2400", "--n-freq", "201", "--n-speeds", "20"]



@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "ds"
    assert main(SIM + [str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Path:
    """A short run-up 300 -> 3000 rpm with a speed_rpm column (a lab's file: rwadist did not write it)."""
    fs, t_end = 2000.0, 2.0
    t = np.arange(int(fs * t_end)) / fs
    rpm = 300.0 + 2700.0 * t / t_end
    w = rpm * 2 * np.pi / 60
    theta = np.cumsum(w) / fs
    rng = np.random.default_rng(0)
    ch = [2e-6 * w**2 * np.cos(theta) + 1e-3 * rng.standard_normal(t.size) for _ in range(6)]
    path = tmp_path_factory.mktemp("sweep") / "sweep.csv"
    np.savetxt(path, np.column_stack([t] + ch + [rpm]), delimiter=",", comments="", fmt="%.10g",
               header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm,speed_rpm")
    return path


def _refused(code: int, err: str, path: Path) -> None:
    assert code == 2, err
    line = err.strip().splitlines()[-1]
    assert "rwadist did not write" in line and str(path) in line and "Traceback" not in err


@pytest.mark.parametrize("suffix", [".csv", ".h5"])
def test_convert_onto_a_foreign_file_is_refused_untouched(sweep, tmp_path, capsys, suffix):
    """`convert sw.h5 -o labsweep.csv` replaced the lab's CSV with float32-rounded values; an .h5 alike."""
    h5 = tmp_path / "sw.h5"
    assert run(capsys, "convert", sweep, "-o", h5, "--precision", "float32")[0] == 0
    lab = tmp_path / ("lab" + suffix)
    shutil.copy(sweep if suffix == ".csv" else h5, lab)
    before = lab.read_bytes()
    code, _, err = run(capsys, "convert", h5 if suffix == ".csv" else sweep, "-o", lab)
    _refused(code, err, lab)
    assert lab.read_bytes() == before
    assert not lab.with_suffix(".meta.json").exists()


def test_fit_onto_another_datasets_files_is_refused_untouched(dataset, tmp_path, capsys):
    """`fit DS -o other/run_0002.csv` wrote a model over a run of another dataset; its meta.json alike."""
    other = tmp_path / "other"
    shutil.copytree(dataset, other)
    before = {p.name: p.read_bytes() for p in other.iterdir()}
    code, _, err = run(capsys, "fit", dataset, "-o", other / "run_0002.csv", "--no-report")
    assert code == 2 and str(other / "run_0002.csv") in err and "JSON document" in err
    code, _, err = run(capsys, "fit", dataset, "-o", other / "meta.json", "--no-report")
    _refused(code, err, other / "meta.json")
    assert {p.name: p.read_bytes() for p in other.iterdir()} == before


def test_psd_onto_a_datasets_runs_csv_is_refused_untouched(dataset, tmp_path, capsys):
    other = tmp_path / "other"
    shutil.copytree(dataset, other)
    model = tmp_path / "m.json"
    assert run(capsys, "fit", dataset, "-o", model, "--no-report")[0] == 0
    before = {p.name: p.read_bytes() for p in other.iterdir()}
    code, _, err = run(capsys, *PSD, model, "-o", other / "runs.csv")
    _refused(code, err, other / "runs.csv")
    assert {p.name: p.read_bytes() for p in other.iterdir()} == before


def test_a_psd_companion_rwadist_did_not_write_is_refused(tmp_path, capsys):
    """The plot beside the table (`p.png`) is an output too: a user's own p.png is not replaced."""
    (tmp_path / "p.png").write_bytes(b"my figure")
    code, _, err = run(capsys, *PSD, "--preset", "ithaco-e", "-o", tmp_path / "p.csv")
    _refused(code, err, tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes() == b"my figure" and not (tmp_path / "p.csv").exists()


def test_rerunning_a_command_replaces_what_it_wrote(dataset, tmp_path, capsys):
    model = tmp_path / "m.json"
    argv = ["fit", dataset, "-o", model, "--no-report"]
    assert run(capsys, *argv)[0] == 0
    model.write_text(model.read_text())         # a model file (an older run's, or rewritten) stays rwadist's own
    assert run(capsys, *argv)[0] == 0
    psd = PSD + ["--preset", "ithaco-e", "-o", tmp_path / "p.csv"]
    assert run(capsys, *psd)[0] == 0 and run(capsys, *psd)[0] == 0
    assert (tmp_path / MANIFEST).exists()
    # a file rwadist wrote and someone changed since is no longer its own
    with open(tmp_path / "p.csv", "a") as f:
        f.write("# my note\n")
    code, _, err = run(capsys, *psd)
    _refused(code, err, tmp_path / "p.csv")
    assert (tmp_path / "p.csv").read_text().endswith("# my note\n")


def test_save_model_onto_a_folder_or_a_foreign_file_is_a_data_error(tmp_path):
    from rwadist.presets import preset as get_preset

    model = get_preset("ithaco-e").to_model()
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(rwadist.DataError, match="is a directory"):
        rwadist.save_model(model, folder)
    notes = tmp_path / "notes.txt"
    notes.write_text("mine\n")
    with pytest.raises(rwadist.DataError, match="rwadist did not write"):
        rwadist.save_model(model, notes)
    assert notes.read_text() == "mine\n" and list(folder.iterdir()) == []
    out = tmp_path / "w.json"
    assert rwadist.save_model(model, out) == out and rwadist.save_model(model, out) == out
    assert rwadist.load_model(out).name == model.name


@pytest.mark.parametrize("name", ["new_run.csv", "model.h5"])
def test_a_model_path_with_a_data_formats_extension_is_refused(dataset, tmp_path, capsys, name):
    """A model file is a JSON document (docs/formats.md section 4): `fit -o x.csv` is a slip onto a measurement."""
    code, _, err = run(capsys, "fit", dataset, "-o", tmp_path / name, "--no-report")
    assert code == 2 and "a model file is a JSON document" in err and name in err
    assert list(tmp_path.iterdir()) == []
    from rwadist.presets import preset

    with pytest.raises(rwadist.DataError, match="JSON document"):
        rwadist.save_model(preset("ithaco-e").to_model(), tmp_path / name)
    assert list(tmp_path.iterdir()) == []
