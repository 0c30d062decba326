"""A steady-test folder (`simulate-test OUT`, `convert SRC -o OUT`) is replaced as ONE set (issue 17 item 2):
written into a temporary sibling folder and swapped in by rename, never file by file, so a kill or a
failure mid-write leaves the old complete dataset, and a finished write leaves exactly the new one
(no run files of the old set beside the new index)."""
from __future__ import annotations

import hashlib
import signal
import subprocess
import sys
import textwrap

import pytest

from rwadist import data as data_io
from rwadist.cli import main
from rwadist.data import DataError
from rwadist.outputs import atomic_dataset_dir

SIM = ["simulate-test", "--preset", "ithaco-e", "--samples", "256", "--sample-rate", "1024"]


def _snapshot(folder):
    """{file name: sha256} of every visible file in ``folder``."""
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())
            if not p.name.startswith(".")}


@pytest.fixture()
def old_dataset(tmp_path):
    out = tmp_path / "ds"
    assert main(SIM + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "5", "--seed", "1"]) == 0
    snap = _snapshot(out)
    assert len([n for n in snap if n.startswith("run_")]) == 5
    return out, snap


def test_complete_write_replaces_the_whole_set(old_dataset):
    out, old = old_dataset
    assert main(SIM + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "3", "--seed", "2"]) == 0
    new = _snapshot(out)
    # file-by-file replacement would have left run_0003/run_0004 of the old set beside the new index
    assert len([n for n in new if n.startswith("run_")]) == 3
    assert len(data_io.read_steady(out).runs) == 3
    assert all(not p.name.startswith(".ds") for p in out.parent.iterdir())    # no temporary left


def test_failure_mid_write_keeps_the_old_set(old_dataset, monkeypatch):
    out, old = old_dataset
    real = data_io.write_run
    calls = []

    def failing(path, run, fmt="csv"):
        calls.append(path)
        if len(calls) == 2:
            raise OSError(28, "No space left on device", str(path))
        return real(path, run, fmt)

    monkeypatch.setattr(data_io, "write_run", failing)
    assert main(SIM + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "4", "--seed", "3"]) == 2
    assert len(calls) == 2
    assert _snapshot(out) == old
    assert [p.name for p in out.parent.iterdir()] == ["ds"]                  # the temporary folder removed


_KILLED_WRITER = textwrap.dedent("""
    import signal, sys, time
    # Ctrl-C as in a terminal, however pytest was started (a background job inherits SIGINT ignored)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from rwadist import data as data_io
    from rwadist.cli import main
    real = data_io.write_run
    n = [0]
    def slow(path, run, fmt="csv"):
        real(path, run, fmt)
        n[0] += 1
        if n[0] == 2:
            print("writing", flush=True)
            time.sleep(60)
    data_io.write_run = slow
    sys.exit(main(sys.argv[1:]))
""")


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
def test_kill_mid_write_keeps_the_old_set(old_dataset, sig):
    out, old = old_dataset
    proc = subprocess.Popen([sys.executable, "-c", _KILLED_WRITER] + SIM
                            + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "4", "--seed", "4"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"      # two run files of the new set written
    proc.send_signal(sig)
    proc.wait(timeout=30)
    assert _snapshot(out) == old
    assert len(data_io.read_steady(out).runs) == 5
    left = [p.name for p in out.parent.iterdir() if p.name != "ds"]
    # Ctrl-C cleans up; a SIGKILL can leave only the hidden temporary folder, never a mixed dataset
    assert left == [] if sig == signal.SIGINT else all(n.startswith(".ds.part-") for n in left)


def test_a_folder_with_other_files_is_refused_untouched(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    assert main(SIM + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "3"]) == 2
    err = capsys.readouterr().err
    assert "notes.txt" in err and "OUT_DIR" in err and "new or dedicated folder" in err
    assert [p.name for p in out.iterdir()] == ["notes.txt"]
    with pytest.raises(DataError, match="not a steady-test dataset"):
        with atomic_dataset_dir(out):
            pass


def test_convert_into_the_folder_of_its_input_is_refused(old_dataset, capsys):
    out, old = old_dataset
    sweep = out / "run_0000.csv"
    assert main(["convert", str(out), "-o", str(out)]) == 2
    assert "input" in capsys.readouterr().err
    assert _snapshot(out) == old
    assert sweep.exists()


def _lab_dataset(folder, n=4):
    """A steady-test folder as a lab writes it by hand (docs/formats.md section 1): runs.csv, meta.json without
    rwadist's ``written_by``, one CSV per run."""
    import numpy as np

    folder.mkdir()
    t = np.arange(256) / 1024.0
    lines = ["file,speed_rpm"]
    for i in range(n):
        x = np.sin(2 * np.pi * (10 + i) * t)
        rows = ["time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm"] + [f"{a:.6f}" + f",{b:.6f}" * 6 for a, b in zip(t, x)]
        (folder / f"r{i:02d}.csv").write_text("\n".join(rows) + "\n")
        lines.append(f"r{i:02d}.csv,{600 + 60 * i}")
    (folder / "runs.csv").write_text("\n".join(lines) + "\n")
    (folder / "meta.json").write_text('{"sample_rate_hz": 1024, "notes": "bench 3, 2026-11-20"}\n')
    return folder


def test_a_dataset_rwadist_did_not_write_is_refused_untouched(tmp_path, capsys):
    """A lab's measured runs in the output folder: simulate-test and convert refuse it (they replace the folder whole,
    which deleted the runs and printed 'wrote 3 runs'), and leave every file as it was."""
    lab = _lab_dataset(tmp_path / "lab")
    before = _snapshot(lab)
    assert len(data_io.read_steady(lab).runs) == 4
    assert main(SIM + [str(lab), "--speeds-rpm", "600:2400", "--n-speeds", "3"]) == 2
    err = capsys.readouterr().err
    assert "OUT_DIR" in err and "rwadist did not write" in err and "choose a new folder" in err
    assert _snapshot(lab) == before
    sim = tmp_path / "sim"
    assert main(SIM + [str(sim), "--speeds-rpm", "600:2400", "--n-speeds", "3"]) == 0
    assert main(["convert", str(sim), "-o", str(lab)]) == 2
    assert "-o" in capsys.readouterr().err
    assert _snapshot(lab) == before


def test_a_dataset_rwadist_wrote_is_replaced(tmp_path):
    """What convert writes carries written_by: rwadist, so it may be written again (a lab's runs converted once)."""
    lab = _lab_dataset(tmp_path / "lab")
    out = tmp_path / "converted"
    assert main(["convert", str(lab), "-o", str(out)]) == 0
    assert main(["convert", str(lab), "-o", str(out)]) == 0
    assert len(data_io.read_steady(out).runs) == 4


def test_a_folder_holding_simulate_tests_sweep_is_replaced(tmp_path):
    """simulate-test OUT --sweep, then simulate-test OUT: the sweep is simulate-test's own output (no meta.json)."""
    out = tmp_path / "s"
    assert main(["simulate-test", "--preset", "ithaco-e", str(out), "--sweep", "--duration", "2",
                 "--sample-rate", "512"]) == 0
    assert main(SIM + [str(out), "--speeds-rpm", "600:2400", "--n-speeds", "3"]) == 0
    assert len(data_io.read_steady(out).runs) == 3
