"""Kill test of the command line's outputs (issue 17): SIGKILL `rwadist fit -o`, `psd -o` and
`fmu build -o` at random instants (and once at the first write of the output) and check that the
output path holds the old complete file or a new complete one, never a truncated one.

    python benchmarks/kill_outputs.py [--kills 20] [--seed 0]

Prints per command: kills, how many landed while the output's temporary file existed (the write
phase), old kept, new complete, truncated/invalid (must be 0).  Baseline before issue 17: the outputs
were opened with truncate, a kill at the first write left a 0-byte file (2 of 2 tries).
"""
from __future__ import annotations

import argparse
import json
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

RWADIST = [sys.executable, "-m", "rwadist.cli"]


def valid_model(path: Path) -> bool:
    from rwadist.model import from_json
    try:
        from_json(json.loads(path.read_text()), str(path))
        return True
    except Exception:
        return False


def mark_model(path: Path) -> None:
    """The old model: the reference fit renamed (still a complete, valid model file)."""
    doc = json.loads(path.read_text())
    doc["name"] = "OLD reference"
    path.write_text(json.dumps(doc, indent=2) + "\n")


def mark_psd(path: Path) -> None:
    """The old PSD table: the reference one with a different first value (still complete, 20001 rows)."""
    lines = path.read_text().splitlines()
    cells = lines[1].split(",")
    cells[1] = "1.2345678900e-30"
    lines[1] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")


def valid_psd(path: Path, n_freq: int) -> bool:
    from rwadist.broadband import read_psd_csv
    try:
        f, cols = read_psd_csv(path)
        return f.size == n_freq and len(cols) == 6
    except Exception:
        return False


def valid_fmu(path: Path) -> bool:
    try:
        with zipfile.ZipFile(path) as z:
            return z.testzip() is None and "modelDescription.xml" in z.namelist()
    except Exception:
        return False


def run_kills(name, cmd, out: Path, is_valid, kills: int, rng: random.Random, cwd: Path, mark_old=None) -> dict:
    t0 = time.perf_counter()      # a complete output ("the old file"); when its temporary file appears
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t_write = None
    while proc.poll() is None:
        if t_write is None and out.parent.exists() and any(
                p.name.startswith(f".{out.stem}.part-") for p in out.parent.iterdir()):
            t_write = time.perf_counter() - t0
        time.sleep(0.001)
    duration = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{name}: the reference run failed (exit {proc.returncode})")
    t_write = duration if t_write is None else t_write
    counts = dict(kills=0, during_write=0, old_kept=0, new_complete=0, truncated_or_invalid=0, first_write=None)

    def one(delay=None, at_first_write=False, after_write_starts=0.0):
        if mark_old is not None:      # each kill starts from an old complete file unlike any new one
            mark_old(out)
        before = out.read_bytes()
        proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if at_first_write:       # poll for the temporary sibling of the output: its first write
            deadline = time.perf_counter() + 5 * duration + 30
            while proc.poll() is None and time.perf_counter() < deadline:
                if any(p.name.startswith(f".{out.stem}.part-") for p in out.parent.iterdir()):
                    break
                time.sleep(0.0002)
            time.sleep(after_write_starts)
        else:
            time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        during = any(p.name.startswith(f".{out.stem}.part-") for p in out.parent.iterdir())
        for p in out.parent.iterdir():      # leftovers of the kill (hidden temporaries)
            if ".part-" in p.name:
                shutil.rmtree(p) if p.is_dir() else p.unlink()
        data = out.read_bytes() if out.exists() else b""
        if data == before:
            state = "old_kept"
        elif is_valid(out):
            state = "new_complete"
        else:
            state = "truncated_or_invalid"
        return during, state

    for k in range(kills):   # half at random over the whole run, half at random just after the write began
        if k % 2 == 0:
            during, state = one(delay=rng.uniform(0.2, 1.05) * duration)
        else:
            during, state = one(at_first_write=True, after_write_starts=rng.uniform(0.0, 0.05))
        counts["kills"] += 1
        counts["during_write"] += during
        counts[state] += 1
    during, state = one(at_first_write=True)
    counts["first_write"] = f"{state} (temporary file present: {during})"
    counts["truncated_or_invalid"] += state == "truncated_or_invalid"
    counts["run_s"] = round(duration, 1)
    counts["write_s"] = round(duration - t_write, 2)
    return counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kills", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", choices=("fit", "psd", "fmu"), action="append")
    a = ap.parse_args(argv)
    rng = random.Random(a.seed)
    with tempfile.TemporaryDirectory(prefix="rwadist_kill_") as tmp:
        tmp = Path(tmp)
        subprocess.run(RWADIST + ["simulate-test", "ds", "--preset", "ithaco-e", "--speeds-rpm", "600:2400:600",
                                  "--samples", "4096"], cwd=tmp, check=True, capture_output=True)
        cases = {
            "fit -o": (RWADIST + ["fit", "ds", "-o", "out/m.json"], tmp / "out" / "m.json", valid_model,
                       mark_model),
            "psd -o": (RWADIST + ["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical",
                                  "--n-freq", "20001", "-o", "out/psd.csv"], tmp / "out" / "psd.csv",
                       lambda p: valid_psd(p, 20001), mark_psd),
            "fmu build -o": (RWADIST + ["fmu", "build", "--preset", "ithaco-e", "--native", "-o", "out/w.fmu"],
                             tmp / "out" / "w.fmu", valid_fmu, None),     # each build has its own GUID
        }
        keys = {"fit": "fit -o", "psd": "psd -o", "fmu": "fmu build -o"}
        chosen = [keys[k] for k in a.only] if a.only else list(cases)
        bad = 0
        for name in chosen:
            cmd, out, check, mark = cases[name]
            c = run_kills(name, cmd, out, check, a.kills, rng, tmp, mark)
            bad += c["truncated_or_invalid"]
            print(f"{name:<13} {c['kills']} random kills (run {c['run_s']} s, write phase {c['write_s']} s): {c['during_write']} during the write, "
                  f"old kept {c['old_kept']}, new complete {c['new_complete']}, truncated/invalid "
                  f"{c['truncated_or_invalid']}; kill at the first write: {c['first_write']}", flush=True)
    print(f"baseline (before issue 17): a kill at the first write left a 0-byte output (2 of 2); now: "
          f"{bad} truncated or invalid outputs")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
