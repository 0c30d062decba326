"""Outputs never destroy (issue 36 item 1): a folder holding files rwadist did not write is refused, untouched; a
device or FIFO is written into, never replaced; a set of outputs is swapped in as a set; a full disk is one line and
no part file; Ctrl-C at any moment from the command's first instruction is one line and exit 130."""
from __future__ import annotations

import ast
import os
import resource
import shutil
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rwadist import outputs
from rwadist.cli import main
from rwadist.data import DataError

SIM = ["simulate-test", "--preset", "ithaco-e", "--samples", "1024", "--speeds-rpm", "600,1200,1800,2400",
       "--no-modes"]
PSD = ["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-freq", "401", "--n-speeds", "40"]


def _rwadist() -> str:
    """The installed command (the launcher scripts/rwadist), as a user types it."""
    exe = Path(sys.executable).parent / "rwadist"
    return str(exe) if exe.exists() else shutil.which("rwadist")


def _as_in_a_terminal():
    """Ctrl-C reaches the child as from a terminal, however pytest was started (a background job's SIGINT is
    ignored, and an ignored signal stays ignored across exec)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "ds"
    assert main(SIM + [str(out)]) == 0
    return out


def _visible(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file() and not p.name.startswith(".")}


# --------------------------------------------------------------------------- folders with files rwadist did not write

@pytest.mark.parametrize("how", ["--report", "default", "diagnose"])
def test_a_folder_holding_a_users_file_is_refused_untouched(dataset, tmp_path, capsys, how):
    """`fit --report DIR`, its default `<model>_report` and `diagnose -o DIR` deleted a reviewer's notes in DIR."""
    folder = tmp_path / ("m_report" if how == "default" else "rep")
    folder.mkdir()
    (folder / "reviewer_notes.txt").write_text("checked page 3\n")
    argv = {"--report": ["fit", dataset, "-o", tmp_path / "m.json", "--report", folder],
            "default": ["fit", dataset, "-o", tmp_path / "m.json"],
            "diagnose": ["diagnose", dataset, "-o", folder]}[how]
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert "reviewer_notes.txt" in err and "rwadist did not write" in err
    assert [p.name for p in folder.iterdir()] == ["reviewer_notes.txt"]
    assert not (tmp_path / "m.json").exists()


def test_a_report_rwadist_wrote_is_replaced_and_a_file_added_later_stops_it(dataset, tmp_path, capsys):
    rep = tmp_path / "rep"
    argv = ["fit", str(dataset), "-o", str(tmp_path / "m.json"), "--report", str(rep)]
    assert main(argv) == 0 and main(argv) == 0          # its own report: replaced
    assert outputs.foreign_files(rep) == []
    (rep / "notes.md").write_text("mine")
    capsys.readouterr()
    assert main(argv) == 2 and "notes.md" in capsys.readouterr().err
    assert (rep / "notes.md").read_text() == "mine"


# --------------------------------------------------------------------------- devices and FIFOs

@pytest.mark.skipif(os.geteuid() != 0, reason="mknod needs root")
def test_a_device_is_written_into_never_replaced(dataset, tmp_path, capsys):
    """As root, `fit -o /dev/null` replaced the device with a regular file (its copy here: the same device)."""
    null, full = tmp_path / "null", tmp_path / "full"
    os.mknod(null, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    os.mknod(full, 0o666 | stat.S_IFCHR, os.makedev(1, 7))
    assert main(["fit", str(dataset), "-o", str(null), "--no-report"]) == 0
    assert stat.S_ISCHR(os.stat(null).st_mode)
    capsys.readouterr()
    assert main(["fit", str(dataset), "-o", str(full), "--no-report"]) == 2
    err = capsys.readouterr().err
    assert "No space left on device" in err and str(full) in err
    assert stat.S_ISCHR(os.stat(full).st_mode)
    # companions named after a device would land beside it: refused before any work
    for argv in (["fit", str(dataset), "-o", str(null)], PSD + ["-o", str(null)],
                 ["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:500", "-o", str(null)]):
        assert main(argv) == 2
        assert "not a regular file" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["full", "null"]


def test_a_fifo_is_written_into(dataset, tmp_path):
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_text()))
    reader.start()
    assert main(["fit", str(dataset), "-o", str(fifo), "--no-report"]) == 0
    reader.join(30)
    assert got and '"schema": "rwadist.model"' in got[0]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_symbolic_link_is_followed_and_a_loop_refused(dataset, tmp_path, capsys):
    real = tmp_path / "real.json"
    with outputs.atomic_file(real) as tmp:      # rwadist's own output: replaced (a file it did not write is not)
        tmp.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    assert main(["fit", str(dataset), "-o", str(link), "--no-report"]) == 0
    assert link.is_symlink() and '"rwadist.model"' in real.read_text()
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.symlink_to(b)
    b.symlink_to(a)
    capsys.readouterr()
    assert main(["fit", str(dataset), "-o", str(a), "--no-report"]) == 2
    assert "loop" in capsys.readouterr().err


@pytest.mark.parametrize("what", ["fit", "psd", "fmu"])
def test_an_output_below_a_file_names_the_flag(dataset, tmp_path, capsys, what):
    """`fmu build -o FILE/w.fmu` said "FILE/w.fmu: path: Not a directory", naming no option."""
    (tmp_path / "FILE").write_text("a user's file\n")
    out = str(tmp_path / "FILE" / {"fit": "m.json", "psd": "p.csv", "fmu": "w.fmu"}[what])
    argv = {"fit": ["fit", str(dataset), "-o", out, "--no-report"], "psd": PSD + ["-o", out],
            "fmu": ["fmu", "build", "--preset", "ithaco-e", "-o", out]}[what]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rwadist: error: -o: ") and "FILE" in err[0], err
    assert "a folder on the way to it is a file" in err[0]
    assert (tmp_path / "FILE").read_text() == "a user's file\n"


def test_a_block_device_is_refused(tmp_path):
    if os.geteuid() != 0:
        pytest.skip("mknod needs root")
    disk = tmp_path / "disk"
    os.mknod(disk, 0o600 | stat.S_IFBLK, os.makedev(7, 200))     # a loop-device number: never opened
    with pytest.raises(DataError, match="block device"):
        outputs.check_output_file(disk)


# --------------------------------------------------------------------------- sets

def _psd_set(stem: Path) -> dict:
    return {s: (stem.parent / (stem.name + s)) for s in (".csv", "_cross.csv", "_envelope.csv",
                                                          "_envelope_harmonics.csv", ".png")}


def test_psd_outputs_are_replaced_as_a_set(tmp_path, monkeypatch, capsys):
    """A failure while the set is swapped in (the second new member's rename) leaves the whole old set; a run with
    --cross none removes the older cross-spectra, which belonged to another run."""
    stem = tmp_path / "p"
    assert main(PSD + ["-o", str(stem) + ".csv", "--cross", "csv"]) == 0
    old = {s: p.read_bytes() for s, p in _psd_set(stem).items()}
    real, calls = os.rename, []

    def failing(a, b):
        calls.append((a, b))
        if len(calls) == 7:     # 5 old members moved aside, then the 2nd new one moved in
            raise OSError(5, "Input/output error", str(b))
        return real(a, b)

    monkeypatch.setattr(os, "rename", failing)
    assert main(PSD + ["--n-freq", "301", "-o", str(stem) + ".csv", "--cross", "csv"]) == 2
    monkeypatch.setattr(os, "rename", real)
    assert {s: p.read_bytes() for s, p in _psd_set(stem).items()} == old
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([outputs.MANIFEST] + [p.name for p in _psd_set(stem).values()])
    assert main(PSD + ["--n-freq", "301", "-o", str(stem) + ".csv", "--cross", "none"]) == 0
    assert not _psd_set(stem)["_cross.csv"].exists()
    assert all(_psd_set(stem)[s].read_bytes() != old[s] for s in (".csv", "_envelope.csv"))


def test_ctrl_c_during_the_swap_waits_for_it(tmp_path):
    """Ctrl-C arriving between the renames of a set runs after the last one: both members new, then the interrupt."""
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    with outputs.output_set() as s:     # rwadist's own outputs: replaced (a file it did not write is not)
        s.file(a).write_text("old a")
        s.file(b).write_text("old b")
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    real = os.rename
    try:
        def rename_then_interrupt(src, dst):
            real(src, dst)
            if Path(dst) == a:
                os.kill(os.getpid(), signal.SIGINT)
        os.rename = rename_then_interrupt
        with pytest.raises(KeyboardInterrupt):
            with outputs.output_set() as s:
                s.file(a).write_text("new a")
                s.file(b).write_text("new b")
    finally:
        os.rename = real
        signal.signal(signal.SIGINT, previous)
    assert (a.read_text(), b.read_text()) == ("new a", "new b")
    assert sorted(p.name for p in tmp_path.iterdir()) == [outputs.MANIFEST, "a.txt", "b.txt"]


_CTRL_C_AFTER_MKDIR = """
import os, pathlib, signal, sys
from rwadist import outputs
real = pathlib.Path.mkdir
def mkdir_then_interrupt(self, *args, **kwargs):
    real(self, *args, **kwargs)
    if ".part-" in self.name:
        os.kill(os.getpid(), signal.SIGINT)     # Ctrl-C the instant the temporary exists
pathlib.Path.mkdir = mkdir_then_interrupt
with outputs.exit_on_interrupt("diagnose"):
    with outputs.output_set() as s:
        s.folder(pathlib.Path(sys.argv[1]) / "report")
"""


def test_ctrl_c_the_instant_a_report_folders_temporary_exists_leaves_nothing(tmp_path):
    """A Ctrl-C between the temporary folder's mkdir and its registration for the clean-up left .report.part-*
    behind (1 of 20 Ctrl-C of diagnose in the kill matrix); here the interrupt lands exactly there."""
    proc = subprocess.run([sys.executable, "-c", _CTRL_C_AFTER_MKDIR, str(tmp_path)], capture_output=True,
                          text=True, timeout=120, preexec_fn=_as_in_a_terminal)
    assert proc.returncode == 130 and "Traceback" not in proc.stderr, proc.stderr
    assert list(tmp_path.iterdir()) == [], list(tmp_path.iterdir())


def test_stale_temporaries_of_a_killed_write_are_removed(tmp_path):
    out = tmp_path / "m.json"
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    left = tmp_path / f".m.part-{dead}-0123abcd.json"
    left.write_text("half")
    other = tmp_path / f".n.part-{dead}-0123abcd.json"        # another output's: not this write's business
    other.write_text("half")
    with outputs.atomic_file(out) as tmp:
        tmp.write_text("new")
    assert not left.exists() and other.exists() and out.read_text() == "new"


# --------------------------------------------------------------------------- a full disk

def _file_size_limit(limit: int):
    def apply():
        _as_in_a_terminal()
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)       # a write past the limit fails (EFBIG), as on a full disk
    return apply


@pytest.mark.parametrize("what", ["convert", "fit", "psd"])
def test_a_full_disk_is_one_line_and_leaves_no_part_file(dataset, tmp_path, what):
    """`convert -o x.h5` on a full disk printed HDF5 tracebacks and crashed (exit 139), leaving `.x.part-*.h5`."""
    out = tmp_path / "out"
    out.mkdir()
    argv = {"convert": ["convert", str(dataset), "-o", str(out / "x.h5")],
            "fit": ["fit", str(dataset), "-o", str(out / "m.json")],
            "psd": PSD + ["-o", str(out / "p.csv")]}[what]
    proc = subprocess.run([_rwadist()] + argv, capture_output=True, text=True, timeout=600,
                          preexec_fn=_file_size_limit(20_000))
    err = [ln for ln in proc.stderr.replace("\r", "\n").splitlines() if "error" in ln]
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr and len(err) == 1 and "File too large" in err[0]
    assert list(out.iterdir()) == [], list(out.iterdir())


# --------------------------------------------------------------------------- Ctrl-C

def _rwadist_started(pid: int) -> bool:
    """True once the process runs rwadist's first instruction: its entry point (``rwadist.__main__``) has installed
    its SIGTERM handler (Python itself catches SIGINT only; before that, the interpreter is starting, which no
    program can take over)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        exe = os.readlink(f"/proc/{pid}/exe")
    except OSError:
        return True
    if "python" not in Path(exe).name:     # the launcher's shell (which traps SIGTERM too) or env
        return False
    caught = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt:")), 16)
    return bool(caught >> (signal.SIGTERM - 1) & 1)


def _interrupt(argv, delay: float, cwd) -> tuple:
    """Ctrl-C ``delay`` s after rwadist's first instruction; (exit code, stderr, its lines without progress)."""
    proc = subprocess.Popen([_rwadist()] + argv, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, preexec_fn=_as_in_a_terminal)
    while proc.poll() is None and not _rwadist_started(proc.pid):
        time.sleep(0.0002)
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    lines = [ln for ln in err.replace("\r", "\n").splitlines() if ln.strip() and "%|" not in ln
             and "elapsed" not in ln and not ln.startswith(("WARNING", "note"))]
    return proc.returncode, err, lines


@pytest.mark.parametrize("flags", [[], ["-I"]])
def test_the_entry_point_imports_nothing_before_its_handler(flags):
    """Until :mod:`rwadist.__main__` installs its handler a Ctrl-C is Python's traceback: loading the entry point
    imports the package and itself, nothing the interpreter's start did not load (``typing`` was a 7 ms window;
    ``signal`` with its enums, and ``types``, were half of the ~10 ms left under pip's current console script:
    ``python benchmarks/kill_outputs.py --window 7``).  ``-I``: no user site, no environment variables."""
    code = "import sys; before = set(sys.modules); import rwadist.__main__; print(sorted(set(sys.modules) - before))"
    out = subprocess.run([sys.executable, *flags, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert set(ast.literal_eval(out.stdout)) == {"rwadist", "rwadist.__main__"}


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc")
@pytest.mark.parametrize("delay", [0.0, 0.01, 0.05, 0.15, 0.3, 0.6])
def test_ctrl_c_from_the_first_instruction_is_one_line_and_130(tmp_path, delay):
    """In the first 0.1-0.7 s (the imports) a Ctrl-C printed a KeyboardInterrupt traceback (10 of 39 tries).  The
    command runs well beyond the last delay (demo: 4-5 s): `campbell` ends ~0.7 s after its first instruction on a
    fast machine, and a Ctrl-C as Python exits (its handlers reset by the interpreter) is no test of ours."""
    code, err, lines = _interrupt(["demo", "--out", "d", "--n-speeds", "12"], delay, tmp_path)
    assert code == 130 and "Traceback" not in err and len(lines) == 1 and "interrupted" in lines[0], err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc")
def test_a_background_jobs_ignored_ctrl_c_stays_ignored(tmp_path):
    """A shell starts a background job with SIGINT ignored: the entry point's and the command's handlers leave it
    so (the terminal's Ctrl-C is for the foreground job); SIGTERM is caught from the entry point on."""
    proc = subprocess.Popen([_rwadist(), "campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:10", "-o", "c.csv"],
                            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    while proc.poll() is None and not _rwadist_started(proc.pid):
        time.sleep(0.0002)
    for delay in (0.0, 0.05, 0.3):
        time.sleep(delay)
        if proc.poll() is None:
            status = Path(f"/proc/{proc.pid}/status").read_text()
            ignored = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigIgn:")), 16)
            assert ignored >> (signal.SIGINT - 1) & 1, status
            proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0 and "Traceback" not in err, err
    assert (tmp_path / "c.csv").exists()


def test_ctrl_c_during_the_demo_is_never_swallowed(tmp_path):
    """During `demo` a Ctrl-C was sometimes swallowed (`Exception ignored in: WeakValueDictionary`) and the demo ran
    on to exit 0."""
    for delay in (1.0, 2.0, 3.0):      # the demo runs 4.4-4.9 s here: a Ctrl-C after its end is no test
        code, err, lines = _interrupt(["demo", "--out", "d", "--n-speeds", "12"], delay, tmp_path)
        assert code == 130 and "Exception ignored" not in err and "Traceback" not in err, err
        assert len(lines) == 1 and "interrupted" in lines[0], err
        left = [p.name for p in (tmp_path / "d").iterdir()] if (tmp_path / "d").exists() else []
        assert all(not n.startswith(".") for n in left), left      # no temporary left behind
