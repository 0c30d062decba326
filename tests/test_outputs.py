"""Outputs safe to keep (issue 17): atomic files and folders, an output never overwrites an input,
Ctrl-C stops cleanly, a kill during a write leaves the old complete file."""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from cli_run import run

from rwadist.data import DataError
from rwadist.outputs import MANIFEST, atomic_dir, atomic_file, refuse_input_overwrite


def own(path, text: str) -> None:
    """Write ``path`` as rwadist writes an output (recorded in its folder's MANIFEST): a later output may replace it,
    where it would refuse a file rwadist did not write (tests/test_outputs_foreign_files.py)."""
    with atomic_file(path) as tmp:
        tmp.write_text(text)


def test_atomic_file_replaces_only_when_complete(tmp_path):
    target = tmp_path / "model.json"
    own(target, "old")
    with pytest.raises(RuntimeError):
        with atomic_file(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer failed")
    assert target.read_text() == "old" and sorted(os.listdir(tmp_path)) == [MANIFEST, "model.json"]
    with atomic_file(target) as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".json" and tmp != target
        tmp.write_text("new")
        assert target.read_text() == "old"       # not visible until complete
    assert target.read_text() == "new" and sorted(os.listdir(tmp_path)) == [MANIFEST, "model.json"]


def test_atomic_dir_swaps_the_whole_folder(tmp_path):
    target = tmp_path / "report"
    target.mkdir()
    (target / "stale.png").write_text("old")
    with pytest.raises(KeyboardInterrupt):
        with atomic_dir(target) as tmp:
            (tmp / "summary.md").write_text("partial")
            raise KeyboardInterrupt
    assert sorted(os.listdir(target)) == ["stale.png"] and os.listdir(tmp_path) == ["report"]
    with atomic_dir(target) as tmp:
        (tmp / "summary.md").write_text("new")
    # the folder's record of what rwadist wrote (outputs.MANIFEST) beside the new file
    assert sorted(os.listdir(target)) == [MANIFEST, "summary.md"] and os.listdir(tmp_path) == ["report"]


def test_refuse_input_overwrite(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ds = tmp_path / "DS"
    ds.mkdir()
    (ds / "runs.csv").write_text("file,speed_rpm\n")
    sweep = tmp_path / "sweep.csv"
    sweep.write_text("t\n")
    for outputs, inputs in (([("-o", sweep, "file")], [sweep]),
                            ([("-o", ds / "runs.csv", "file")], [ds]),
                            ([("-o", ds, "file")], [ds]),
                            ([("--report", tmp_path, "dir")], [sweep]),          # holds the input
                            ([("-o", tmp_path / "sweep.meta.json", "file")], [sweep])):
        with pytest.raises(DataError) as err:
            refuse_input_overwrite(outputs, inputs)
        assert outputs[0][0] in str(err.value)
    refuse_input_overwrite([("-o", ds / "model.json", "file"), ("--report", tmp_path / "r", "dir")], [ds, sweep])


def test_output_equal_to_input_is_refused_and_untouched(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, _ = run(capsys, "simulate-test", "ds", "--preset", "ithaco-e", "--speeds-rpm", "600,1800",
                     "--samples", "1024", "--no-modes")
    assert code == 0
    before = {p.name: p.read_bytes() for p in (tmp_path / "ds").iterdir()}
    for argv in (("fit", "ds", "-o", "ds/runs.csv"), ("fit", "ds", "-o", "ds/run_0000.csv"),
                 ("fit", "ds", "-o", "m.json", "--report", "ds"), ("fit", "ds", "-o", "ds"),
                 ("convert", "ds", "-o", "ds")):
        code, _, err = run(capsys, *argv)
        assert code == 2 and "error" in err and "Traceback" not in err, argv
    assert {p.name: p.read_bytes() for p in (tmp_path / "ds").iterdir()} == before
    assert sorted(os.listdir(tmp_path)) == ["ds"]     # nothing else written, no temporary left


def test_psd_refuses_a_coefficient_that_overflows(tmp_path, capsys):
    """C = 1e300 gave non-finite PSD values (refused after the work); the model file's physical ranges now refuse it
    on reading, naming the field (issue 36)."""
    import json

    from rwadist import catalogue
    from rwadist.model import to_json

    doc = to_json(catalogue.load("ithaco-e"))
    doc.pop("analytical", None)
    doc["empirical"]["radial_force"][0]["C"] = 1e300     # finite in the file, overflows in the PSD
    path = tmp_path / "m.json"
    path.write_text(json.dumps(doc))
    out = tmp_path / "psd.csv"
    code, _, err = run(capsys, "psd", path, "--speed-rpm", "600:2400", "--empirical", "--n-freq", "501",
                       "--n-speeds", "50", "-o", out)
    assert code == 2 and "empirical.radial_force[0].C" in err and "<= 1" in err and not out.exists(), err


_SLOW_WRITER = textwrap.dedent("""
    import signal, sys, time
    # Ctrl-C as in a terminal, however pytest was started (a background job inherits SIGINT ignored)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from rwadist.outputs import atomic_file
    with atomic_file(sys.argv[1]) as tmp:
        with open(tmp, "w") as fh:
            fh.write("new-begin\\n"); fh.flush()
            print("writing", flush=True)
            time.sleep(30)
            fh.write("new-end\\n")
""")


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
def test_kill_during_the_write_keeps_the_old_file(tmp_path, sig):
    target = tmp_path / "out.json"
    own(target, "old complete\n")
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(target)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"   # killed at its first write
    proc.send_signal(sig)
    proc.wait(timeout=20)
    assert target.read_text() == "old complete\n"
    left = [p for p in os.listdir(tmp_path) if p not in ("out.json", MANIFEST)]
    # SIGINT runs the clean-up; SIGKILL can leave only the hidden temporary, never a truncated output
    assert left == [] if sig == signal.SIGINT else all(p.startswith(".out.part-") for p in left)


def test_ctrl_c_is_one_line_exit_130(tmp_path):
    out = tmp_path / "psd.csv"
    own(out, "old")
    # four wheels of the extended model on 200001 frequencies: a CSD long enough to be interrupted while its
    # progress bar runs (one empirical wheel took 1 s before issue 37's closed form, 0.1 s after)
    wheels = tmp_path / "wheels.json"
    wheels.write_text(json.dumps({"wheels": [{"name": f"RW{i}", "preset": "ithaco-e",
                                              "mounting": {"preset": "pyramid-4", "index": i}} for i in range(4)]}))
    # ``python -m rwadist.cli`` with Ctrl-C as in a terminal, however pytest was started (a background job inherits
    # SIGINT ignored, and Python then leaves it ignored)
    as_in_a_terminal = ("import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
                        "runpy.run_module('rwadist.cli', run_name='__main__', alter_sys=True)")
    proc = subprocess.Popen([sys.executable, "-c", as_in_a_terminal, "psd", "--wheels", str(wheels), "--speed-rpm",
                             "600:2400", "--n-freq", "200001", "-o", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.2)
    deadline = time.time() + 60
    while time.time() < deadline:       # wait past the imports: main() is running once it prints progress
        if proc.poll() is not None:
            break
        line = proc.stderr.read(1)
        if line:
            break
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted" in err.strip().splitlines()[-1]
    assert out.read_text() == "old" and sorted(os.listdir(tmp_path)) == [MANIFEST, "psd.csv", "wheels.json"]


def test_a_failed_set_removes_the_companions_its_writers_made_beside_a_temporary(tmp_path):
    """The native FMU's zip is written to ``<temporary>.tmp`` and renamed: after a Ctrl-C at that moment the
    ``.w.part-PID-x.fmu.tmp`` stayed (5 of 20 Ctrl-C of `fmu build` in the kill matrix).  Whatever a writer makes under
    the temporary's unique name goes with it; another file beside it stays."""
    from rwadist.outputs import output_set

    keep = tmp_path / ".w.partial-notes.txt"
    keep.write_text("mine")
    with pytest.raises(KeyboardInterrupt), output_set() as outs:
        tmp = outs.file(tmp_path / "w.fmu")
        tmp.with_name(tmp.name + ".tmp").write_text("zip being written")
        tmp.with_suffix(".meta.json").write_text("{}")
        raise KeyboardInterrupt
    assert sorted(os.listdir(tmp_path)) == [keep.name]
