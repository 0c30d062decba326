"""Kill matrix of the command line's outputs (issues 17, 36): every writing command killed with SIGKILL and with
SIGINT (Ctrl-C) at random instants -- a quarter of them in the first 0.5 s, a quarter just after its first
temporary output appears, the rest over the whole run -- each kill starting from an old complete set of outputs
unlike any new one.  After each kill the command's output SET is classed:

- ``old``: every member byte for byte the old one;
- ``new``: every member present, valid (parsed by its reader) and new;
- ``partial``: members absent, the rest all old or all new (a SIGKILL inside the few renames of a set's swap);
- ``MIXED``: old and new members side by side -- a failure;
- ``BAD``: a member truncated or invalid -- a failure.

For SIGINT also: the exit code (130), stderr's last line (one line, "interrupted"), no traceback, no temporary
left behind; a SIGINT never leaves a partial set (it waits for the swap).  ``pre`` counts the kills that landed
before rwadist's first instruction (the Python interpreter's own start, ~10-60 ms, more on a loaded machine, which
no Python program controls: the process dies of the signal, exit -2, or Python prints "Fatal Python error:
init_import_site" with its traceback, counted apart as ``pre-tb``); their output sets are classed as any other.  Must be 0 MIXED, 0 BAD, 0 tracebacks, every SIGINT exit 130 with one line.

    python benchmarks/kill_outputs.py [--kills 20] [--seed 0] [--only fit --only psd ...]
    python benchmarks/kill_outputs.py --early 100 --only fit --only "convert h5"   # Ctrl-C in the first 0.5 s only
    python benchmarks/kill_outputs.py --window 10 [--module]    # the traceback window after exec (strace)

The command run is the installed ``rwadist`` (the launcher a user types, scripts/rwadist).  Baseline before issue 17: a kill at
the first write left a 0-byte output (2 of 2); before issue 36: the psd set was not swapped as a set (p.csv new beside
p_cross.csv old after a kill), and 10 of 39 early Ctrl-C printed a KeyboardInterrupt traceback.  ``--early`` and
``--window``: what is left is the interpreter's start (docs/cli.md, "Ctrl-C while Python starts").
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path


def _rwadist() -> list:
    exe = Path(sys.executable).parent / "rwadist"
    return [str(exe)] if exe.exists() else [shutil.which("rwadist") or "rwadist"]


# --------------------------------------------------------------------------- validity of one member

def _valid_file(p: Path) -> bool:
    try:
        if p.suffix == ".json":
            doc = json.loads(p.read_text())
            if isinstance(doc, dict) and doc.get("schema") == "rwadist.model":
                from rwadist.model import from_json
                from_json(doc, str(p))
            return True
        if p.suffix == ".csv":
            rows = list(csv.reader(p.read_text().splitlines()))
            return len(rows) >= 1 and p.read_text().endswith("\n") and len({len(r) for r in rows[1:]} | {len(rows[0])}) == 1
        if p.suffix == ".png":
            from PIL import Image
            with Image.open(p) as im:
                im.load()
            return True
        if p.suffix in (".h5", ".hdf5"):
            import h5py
            with h5py.File(p, "r") as fh:
                fh.visit(lambda name: None)
            return True
        if p.suffix == ".fmu":
            with zipfile.ZipFile(p) as z:
                return z.testzip() is None and "modelDescription.xml" in z.namelist()
        if p.suffix == ".bdf":
            text = p.read_text()
            cards = [ln.split()[0] for ln in text.splitlines() if ln.strip() and not ln.startswith("$")]
            # every table complete (its ENDT), one RANDPS per table; the deck's comments name the cards too
            return text.endswith("\n") and cards.count("TABRND1") == cards.count("RANDPS") == \
                sum(ln.rstrip().endswith("ENDT") for ln in text.splitlines() if not ln.startswith("$")) > 0
        if p.suffix in (".md", ".txt"):
            return p.read_text().endswith("\n")
        return p.stat().st_size > 0
    except Exception:
        return False


def _snapshot(p: Path):
    """The bytes of a member: a file's, or {relative path: bytes} of a folder's visible files."""
    if not p.exists():
        return None
    if p.is_dir():
        return {q.relative_to(p).as_posix(): q.read_bytes() for q in sorted(p.rglob("*")) if q.is_file()}
    return p.read_bytes()


def _valid_member(p: Path) -> bool:
    if p.is_dir():
        listed = json.loads((p / ".rwadist-files.json").read_text())["files"] if (p / ".rwadist-files.json").exists() \
            else None
        files = sorted(q.relative_to(p).as_posix() for q in p.rglob("*") if q.is_file() and q.name != ".rwadist-files.json")
        return listed == files and all(_valid_file(p / f) for f in files)
    return _valid_file(p)


def classify(members: list, old: dict) -> str:
    """The state of an output set after a kill (see the module docstring)."""
    states = []
    for m in members:
        now = _snapshot(m)
        if now is None:
            states.append("absent")
        elif now == old[m]:
            states.append("old")
        elif _valid_member(m):
            states.append("new")
        else:
            return "BAD"
    kinds = set(states)
    if kinds == {"old"}:
        return "old"
    if kinds == {"new"}:
        return "new"
    if "old" in kinds and "new" in kinds:
        return "MIXED"
    return "partial"


# --------------------------------------------------------------------------- the commands

def cases(tmp: Path) -> dict:
    """name -> (argv of the old run, argv of the killed run, the set's members)."""
    psd = ["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-speeds", "400"]
    o = tmp / "out"
    return {
        "simulate-test": (["simulate-test", str(o / "sim"), "--preset", "ithaco-e", "--speeds-rpm", "600:2400:600",
                           "--samples", "2048", "--seed", "1"],
                          ["simulate-test", str(o / "sim"), "--preset", "ithaco-e", "--speeds-rpm", "600:2400:300",
                           "--samples", "4096", "--seed", "2"], [o / "sim"]),
        "fit": (["fit", str(tmp / "ds"), "-o", str(o / "m.json"), "--presence", "0.5"],
                ["fit", str(tmp / "ds"), "-o", str(o / "m.json")], [o / "m.json", o / "m_report"]),
        "psd": (psd + ["--n-freq", "2001", "-o", str(o / "p.csv")], psd + ["--n-freq", "8001", "-o", str(o / "p.csv")],
                [o / "p.csv", o / "p_cross.csv", o / "p_envelope.csv", o / "p_envelope_harmonics.csv", o / "p.png"]),
        "psd nastran": (psd + ["--n-freq", "201", "--format", "nastran", "-o", str(o / "d.bdf")],
                        psd + ["--n-freq", "2001", "--format", "nastran", "-o", str(o / "d.bdf")],
                        [o / "d.bdf", o / "d_cross.csv", o / "d_envelope.csv", o / "d_envelope_harmonics.csv",
                         o / "d.png"]),
        "campbell": (["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:500", "-o", str(o / "c.csv")],
                     ["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:6000:20", "-o", str(o / "c.csv")],
                     [o / "c.csv", o / "c.png"]),
        "convert h5": (["convert", str(tmp / "ds_small"), "-o", str(o / "x.h5")],
                       ["convert", str(tmp / "ds"), "-o", str(o / "x.h5")], [o / "x.h5"]),
        "convert sweep": (["convert", str(tmp / "sw_small.csv"), "-o", str(o / "s.tdms")],
                          ["convert", str(tmp / "sw.csv"), "-o", str(o / "s.tdms")],
                          [o / "s.tdms", o / "s.meta.json"]),
        "diagnose": (["diagnose", str(tmp / "ds_small"), "-o", str(o / "diag")],
                     ["diagnose", str(tmp / "ds"), "-o", str(o / "diag")], [o / "diag"]),
        "fmu build": (["fmu", "build", "--preset", "ithaco-b", "--native", "-o", str(o / "w.fmu")],
                      ["fmu", "build", "--preset", "ithaco-e", "--native", "-o", str(o / "w.fmu")], [o / "w.fmu"]),
        "demo": (["demo", "--out", str(o / "demo"), "--n-speeds", "6", "--seed", "1"],
                 ["demo", "--out", str(o / "demo"), "--n-speeds", "12"],
                 [o / "demo" / "data.h5", o / "demo" / "model.json", o / "demo" / "report"]),
    }


def _prepare(tmp: Path) -> None:
    run = lambda *a: subprocess.run(_rwadist() + list(a), cwd=tmp, check=True, capture_output=True)  # noqa: E731
    run("simulate-test", "ds", "--preset", "ithaco-e", "--speeds-rpm", "600:2400:150", "--samples", "4096")
    run("simulate-test", "ds_small", "--preset", "ithaco-e", "--speeds-rpm", "600:2400:600", "--samples", "2048")
    run("simulate-test", "swd", "--preset", "ithaco-e", "--sweep", "--duration", "20", "--sweep-end-rpm", "1200")
    shutil.copy(tmp / "swd" / "sweep.csv", tmp / "sw.csv")
    # another sample rate: the old set's sidecar (sample_rate_hz) unlike the new one's, or a complete new set with an
    # identical sidecar would count as MIXED (3-7 of 20 kills did)
    run("simulate-test", "swd2", "--preset", "ithaco-e", "--sweep", "--duration", "5", "--sweep-end-rpm", "900",
        "--sample-rate", "3000")
    shutil.copy(tmp / "swd2" / "sweep.csv", tmp / "sw_small.csv")


def _rwadist_started(pid: int) -> bool:
    """True once the process runs rwadist's own code: its entry point (``rwadist.__main__``) catches SIGTERM from its
    first lines (/proc/PID/status SigCgt); before that the Python interpreter itself is starting."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        exe = os.readlink(f"/proc/{pid}/exe")
    except OSError:
        return True
    if "python" not in Path(exe).name:     # the launcher's shell (which traps SIGTERM too) or env
        return False
    caught = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt:")), 16)
    return bool(caught >> (signal.SIGTERM - 1) & 1)


def _temporaries(members: list) -> list:
    out = []
    for parent in {m.parent for m in members}:
        if parent.exists():
            out += [p for p in parent.iterdir() if ".part-" in p.name or ".old-" in p.name]
    return out


def _clean(members: list) -> None:
    for p in _temporaries(members):
        shutil.rmtree(p) if p.is_dir() else p.unlink()


def _save(members: list, saved: Path) -> None:
    saved.mkdir()
    for i, m in enumerate(members):
        if m.is_dir():
            shutil.copytree(m, saved / str(i))
        elif m.exists():
            shutil.copy2(m, saved / str(i))


def _restore(members: list, saved: Path) -> None:
    for i, m in enumerate(members):
        if m.is_dir():
            shutil.rmtree(m)
        elif m.exists():
            m.unlink()
        src = saved / str(i)
        if src.is_dir():
            shutil.copytree(src, m)
        elif src.exists():
            m.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, m)


def run_matrix(name, old_argv, argv, members, kills, rng, tmp: Path) -> dict:
    t0 = time.perf_counter()
    subprocess.run(_rwadist() + old_argv, cwd=tmp, check=True, capture_output=True)
    saved = tmp / f"saved_{name.replace(' ', '_')}"
    _save(members, saved)
    old = {m: _snapshot(m) for m in members}
    t1 = time.perf_counter()     # the reference run of the killed command: its duration and its first temporary
    proc = subprocess.run(_rwadist() + argv, cwd=tmp, capture_output=True, text=True)
    duration = time.perf_counter() - t1
    if proc.returncode != 0:
        raise SystemExit(f"{name}: the reference run failed (exit {proc.returncode}): {proc.stderr[-500:]}")
    counts = {sig: {"old": 0, "new": 0, "partial": 0, "MIXED": 0, "BAD": 0, "traceback": 0, "exit_not_130": 0,
                    "not_one_line": 0, "temporaries_left": 0, "early": 0, "before_rwadist": 0,
                    "pre_traceback": 0}
              for sig in ("SIGKILL", "SIGINT")}
    for sig_name, sig in (("SIGKILL", signal.SIGKILL), ("SIGINT", signal.SIGINT)):
        c = counts[sig_name]
        for k in range(kills):
            _restore(members, saved)
            mode = k % 4
            proc = subprocess.Popen(_rwadist() + argv, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                    text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
            start = time.perf_counter()
            if mode == 0:                      # the first 0.5 s: imports, checks, the first reads
                time.sleep(rng.uniform(0.0, 0.5))
                c["early"] += 1
            elif mode == 1:                    # just after the first temporary appears: the write and the swap
                deadline = start + 3 * duration + 30
                while proc.poll() is None and time.perf_counter() < deadline and not _temporaries(members):
                    time.sleep(0.0005)
                time.sleep(rng.uniform(0.0, 0.02))
            else:
                time.sleep(rng.uniform(0.0, 1.1) * duration)
            pre = not _rwadist_started(proc.pid)      # Python's own start: before rwadist's first instruction
            proc.send_signal(sig)
            _, err = proc.communicate(timeout=600)
            state = classify(members, old)
            c[state] += 1
            if sig == signal.SIGINT and state == "partial":     # Ctrl-C waits for a set's swap: never partial
                c["MIXED"] += 1
            printed = "Traceback" in err or "internal error" in err or "Fatal Python error" in err
            if pre:         # the interpreter's own reaction (no program runs yet): counted apart
                c["before_rwadist"] += 1
                c["pre_traceback"] += printed
                continue
            c["traceback"] += printed
            if sig == signal.SIGINT and proc.returncode is not None and proc.returncode != 0:
                lines = [ln for ln in err.replace("\r", "\n").splitlines() if ln.strip() and "%|" not in ln
                         and "elapsed" not in ln and not ln.startswith(("WARNING", "note", "rwadist: warning"))]
                c["exit_not_130"] += proc.returncode not in (130, -signal.SIGINT)
                # -SIGINT: killed before Python itself ran (the interpreter's start), nothing printed
                if proc.returncode == 130 and (len(lines) != 1 or "interrupted" not in lines[0]):
                    c["not_one_line"] += 1
                if _temporaries(members):
                    c["temporaries_left"] += 1
            _clean(members)
    counts["run_s"] = round(duration, 1)
    counts["prep_s"] = round(t1 - t0, 1)
    return counts


def _in_interpreter_start(pid: int) -> bool | None:
    """True while Python's own SIGINT handler is in place and rwadist's is not yet (the instant a Ctrl-C printed
    Python's traceback); False before it; None once it has passed or the process is gone."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        exe = os.readlink(f"/proc/{pid}/exe")
    except OSError:
        return None
    if "python" not in Path(exe).name:
        return False
    caught = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("SigCgt:")), 16)
    if caught >> (signal.SIGTERM - 1) & 1:
        return None
    return bool(caught >> (signal.SIGINT - 1) & 1)


def early_matrix(table: dict, chosen: list, n: int, rng, tmp: Path, window: float = 0.5, aim: bool = False) -> int:
    """``--early N``: N Ctrl-C per command at uniform instants in the first ``window`` s after exec (the launcher,
    the interpreter's start: site, pip's console script; rwadist's entry point, then the imports); ``--aim``: each
    at the instant Python's own SIGINT handler is seen in place and rwadist's not yet (``aimed``: how many were; the
    others are sent as soon as that instant is seen to have passed).  Counts every traceback (``tb``; ``tb<h``:
    those that landed before rwadist's handler), the exit codes, Ctrl-C ending in one line and exit 130, temporaries
    left, the output set's state, and ``done``: commands that had ended before the Ctrl-C was sent (not
    interrupts; their exit 0 is no failure).  -2 is a process killed by the signal before any handler exists (the
    launcher's shell or env, or the interpreter's first milliseconds without the launcher): silent, as any
    program's, and a shell reports it as 130."""
    from collections import Counter
    print(f"{'command':<14} {'n':>4} {'<h':>4} {'tb':>3} {'tb<h':>4} {'1line130':>8} {'temps':>5} {'not old':>7} "
          f"{'done':>4} {'aimed':>5}  exit codes")
    failures = 0
    for name in chosen:
        old_argv, argv, members = table[name]
        subprocess.run(_rwadist() + old_argv, cwd=tmp, check=True, capture_output=True)
        saved = tmp / f"early_{name.replace(' ', '_')}"
        _save(members, saved)
        old = {m: _snapshot(m) for m in members}
        codes: Counter = Counter()
        c = Counter()
        examples: dict = {}         # exit code -> the end of one stderr (exit codes other than 130)
        for _ in range(n):
            proc = subprocess.Popen(_rwadist() + argv, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                    text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
            if aim:
                while (state := _in_interpreter_start(proc.pid)) is False:
                    pass
                c["aimed"] += bool(state)
            else:
                time.sleep(rng.uniform(0.0, window))
            before_handler = not _rwadist_started(proc.pid)
            if proc.poll() is not None:         # ended before the Ctrl-C: not an interrupt
                proc.communicate(timeout=600)
                c["done"] += 1
                _clean(members)
                _restore(members, saved)
                continue
            proc.send_signal(signal.SIGINT)
            _, err = proc.communicate(timeout=600)
            codes[proc.returncode] += 1
            if proc.returncode != 130:      # 0: the Ctrl-C swallowed (raised in a callback: "Exception ignored")
                examples.setdefault(proc.returncode, err[:200] + " ... " + err[-200:] if len(err) > 400 else err)
            printed = "Traceback" in err or "internal error" in err or "Fatal Python error" in err
            lines = [ln for ln in err.replace("\r", "\n").splitlines() if ln.strip() and "%|" not in ln
                     and "elapsed" not in ln and not ln.startswith(("WARNING", "note", "rwadist: warning"))]
            c["before_handler"] += before_handler
            c["tb"] += printed
            c["tb_before_handler"] += printed and before_handler
            c["one_line_130"] += proc.returncode == 130 and len(lines) == 1 and "interrupted" in lines[0]
            c["temps"] += bool(_temporaries(members))
            c["not_old"] += classify(members, old) != "old"
            _clean(members)
            _restore(members, saved)
        fail = c["tb"] + c["temps"] + sum(k for code, k in codes.items() if code not in (130, -signal.SIGINT))
        failures += fail
        print(f"{name:<14} {n:>4} {c['before_handler']:>4} {c['tb']:>3} {c['tb_before_handler']:>4} "
              f"{c['one_line_130']:>8} {c['temps']:>5} {c['not_old']:>7} {c['done']:>4} {c['aimed']:>5}  "
              f"{dict(sorted(codes.items()))}", flush=True)
        for code, tail in sorted(examples.items()):
            print(f"    exit {code}, stderr ends: {tail!r}")
    print(f"failures (tracebacks + temporaries left + exit codes other than 130 and -2): {failures}; baseline "
          "(91cc6dc, the entry point importing signal and types; --early 100 --only fit --only 'convert h5' --seed 1, "
          "twice, pip 26.3's console script, load 15-23): 93 tracebacks of 400 (38 in site, exit 1), 4 Ctrl-C lost "
          "(exit 0); e2f6fb7 (no launcher): 44 (37 in site), 0 lost; --early 30 --aim, same commands, load ~4: "
          "e2f6fb7 48 tracebacks of 60 (49 aimed), the launcher 0 of 60 (55 aimed; all one line and 130)")
    return 1 if failures else 0


def handler_window(runs: int, command: list) -> int:
    """``--window N``: when, after the interpreter's exec, Python installs its SIGINT handler (before it a Ctrl-C
    kills the process silently) and when rwadist's entry point replaces it (after it, one line and 130): between
    the two a Ctrl-C is Python's traceback -- unless the launcher (scripts/rwadist) started the interpreter with
    SIGINT blocked, and the window is then 0 (the Ctrl-C waits for rwadist's handler).  Read from ``strace -e
    execve,rt_sigaction,rt_sigprocmask`` (the launcher's shell and env are the same process: exec keeps the pid);
    ms from the first exec, min / median / max over N runs of ``COMMAND --version``."""
    import re
    import statistics
    if shutil.which("strace") is None:
        raise SystemExit("--window needs strace")
    stamps: dict = {"interpreter exec": [], "python handler": [], "rwadist handler": [], "window": []}
    blocked_runs = 0
    for _ in range(runs):
        err = subprocess.run(["strace", "-ttt", "-e", "trace=execve,rt_sigaction,rt_sigprocmask"] + command +
                             ["--version"], capture_output=True, text=True).stderr
        execs = [m for m in re.finditer(r"^(\d+\.\d+) execve\(.*\) = 0$", err, re.M)]
        t0, last = float(execs[0].group(1)), execs[-1]
        # SIGINT blocked between the exec before the interpreter's (env's) and the interpreter's own
        before = err[execs[-2].end():last.start()] if len(execs) > 1 else ""
        blocked = re.search(r"rt_sigprocmask\(SIG_(BLOCK|SETMASK), \[[^]]*\bINT\b", before) is not None
        blocked_runs += blocked
        after = err[last.start():]
        sets = [float(m.group(1)) for m in re.finditer(r"^(\d+\.\d+) rt_sigaction\(SIGINT, \{sa_handler=0x", after, re.M)]
        stamps["interpreter exec"].append(1e3 * (float(last.group(1)) - t0))
        stamps["python handler"].append(1e3 * (sets[0] - t0))
        stamps["rwadist handler"].append(1e3 * (sets[1] - t0))
        stamps["window"].append(0.0 if blocked else 1e3 * (sets[1] - sets[0]))
    for what, v in stamps.items():
        print(f"{what:<16} ms after exec: min {min(v):6.1f}  median {statistics.median(v):6.1f}  max {max(v):6.1f}"
              if what != "window" else f"{what:<16} ms (traceback): min {min(v):6.1f}  median "
              f"{statistics.median(v):6.1f}  max {max(v):6.1f}")
    print(f"SIGINT blocked from before the interpreter's exec to rwadist's handler in {blocked_runs} of {runs} runs")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kills", type=int, default=20, help="kills per signal and command (default 20)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", action="append", help="a command of the matrix (repeatable)")
    ap.add_argument("--early", type=int, metavar="N",
                    help="instead of the matrix: N Ctrl-C per command at uniform instants 0-0.5 s after exec")
    ap.add_argument("--aim", action="store_true",
                    help="--early: each Ctrl-C at the interpreter's start (its handler in place, rwadist's not yet)")
    ap.add_argument("--window", type=int, metavar="N",
                    help="instead of the matrix: the traceback window after exec, from N runs under strace")
    ap.add_argument("--module", action="store_true", help="--window of `python -m rwadist` (default: the rwadist command)")
    a = ap.parse_args(argv)
    if a.window:
        return handler_window(a.window, [sys.executable, "-m", "rwadist"] if a.module else _rwadist())
    rng = random.Random(a.seed)
    bad = 0
    with tempfile.TemporaryDirectory(prefix="rwadist_kill_") as tmp:
        tmp = Path(tmp)
        _prepare(tmp)
        table = cases(tmp)
        chosen = a.only or list(table)
        if a.early:
            return early_matrix(table, chosen, a.early, rng, tmp, aim=a.aim)
        print(f"{'command':<14} {'signal':<8} {'kills':>5} {'<0.5s':>5} {'pre':>3} {'pre-tb':>6} {'old':>4} {'new':>4} "
              f"{'partial':>7} {'MIXED':>5} {'BAD':>4} {'tb':>3} {'!130':>4} {'!1line':>6} {'temps':>5}  run s")
        for name in chosen:
            old_argv, argv_, members = table[name]
            c = run_matrix(name, old_argv, argv_, members, a.kills, rng, tmp)
            for sig in ("SIGKILL", "SIGINT"):
                r = c[sig]
                fail = r["MIXED"] + r["BAD"] + r["traceback"] + r["exit_not_130"] + r["not_one_line"] + \
                    r["temporaries_left"]
                bad += fail
                print(f"{name:<14} {sig:<8} {a.kills:>5} {r['early']:>5} {r['before_rwadist']:>3} "
                      f"{r['pre_traceback']:>6} {r['old']:>4} "
                      f"{r['new']:>4} {r['partial']:>7} "
                      f"{r['MIXED']:>5} {r['BAD']:>4} {r['traceback']:>3} {r['exit_not_130']:>4} "
                      f"{r['not_one_line']:>6} {r['temporaries_left']:>5}  {c['run_s']}", flush=True)
    print(f"failures (MIXED + BAD + tracebacks + SIGINT not 130 / not one line / temporaries left): {bad}; baseline "
          "(before issue 36): psd sets mixed after a kill, 10 of 39 early Ctrl-C with a traceback")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
