"""Fuzz every edge of the command line (issue 17): >= 300 seeded cases per surface (CLI values, model
files through show/psd/campbell/fmu build, damaged data files through the readers), in-process; and the FMU
surface (tests/test_fuzz_fmu.py: hostile parameters, inputs, communication points and state calls through fmpy
into both wheel FMUs, --n cases per FMU, in child processes restarted after a crash).

    python benchmarks/fuzz_all.py [--n 300] [--seed 17] [--surface cli|models|readers|fmu] [-v]

Prints per surface the counts: ok (accepted, may be valid), clear errors (naming the file or flag),
unclear errors, silent (a known-invalid value accepted with exit 0) and tracebacks.  Must be 0
tracebacks and 0 silent.  Baseline (the audit of issue 17, before this work): readers 3 tracebacks /
14 unclear of 360; model files 45 tracebacks / 30 silent of 480; CLI 21 tracebacks / 18 silent of 174; FMU (its
audit through fmpy): an initial speed of 1e300 stepped with fmi2OK and non-finite outputs, backwards/NaN/1e9-s
communication points accepted, FMU state answered fmi2OK with the flag false (replay off by 0.0136).
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import fuzz_cases as fz  # noqa: E402
import test_fuzz_fmu as fzf  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=17)
    ap.add_argument("--surface", choices=("cli", "models", "readers", "fmu"), action="append")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every case that is not ok/clear")
    a = ap.parse_args(argv)
    surfaces = a.surface or ["cli", "models", "readers", "fmu"]
    bad = 0
    with tempfile.TemporaryDirectory(prefix="rwadist_fuzz_") as tmp:
        tmp = Path(tmp)
        for surface in surfaces:
            t0 = time.perf_counter()
            work = tmp / surface
            work.mkdir()
            if surface == "fmu":
                cases = fzf.fmu_cases(a.n, a.seed)
                results = fzf.run_cases(cases, fzf.build_fmus(work), work)
                for kind in fzf.KINDS:
                    mine = [r for cs, r in zip(cases, results) if cs["kind"] == kind]
                    if a.verbose:
                        for cs, r in zip(cases, results):
                            if cs["kind"] == kind and r[0] not in ("ok", "clear"):
                                print(f"  {r[0]:<9} {kind} {cs['params']} {cs['ops']}\n            {r[1]}")
                    c = fzf.tally(mine)
                    bad += c["traceback"] + c["silent"]
                    print(f"fmu/{kind:<6} {len(mine)} cases in {time.perf_counter() - t0:.0f} s: " +
                          ", ".join(f"{k} {v}" for k, v in c.items()), flush=True)
                continue
            if surface == "cli":
                cases = [c + ("",) for c in fz.cli_cases(a.n, a.seed, work)]
            elif surface == "models":
                cases = fz.model_cases(a.n, a.seed, work)
            else:
                cases = fz.reader_cases(a.n, a.seed, work, fz.make_datasets(work))
            results = []
            for argv, names, invalid, what in cases:
                res = fz.run_case(argv, names, invalid)
                results.append(res)
                if a.verbose and res[0] not in ("ok", "clear"):
                    print(f"  {res[0]:<9} {what} | {' '.join(map(str, argv))[:160]}\n            {res[1]}")
            c = fz.tally(results)
            bad += c["traceback"] + c["silent"]
            print(f"{surface:<8} {len(cases)} cases in {time.perf_counter() - t0:.0f} s: " +
                  ", ".join(f"{k} {v}" for k, v in c.items()), flush=True)
    print("baseline (issue 17 audit): readers 3 tracebacks/14 unclear of 360; model files 45 tracebacks/"
          "30 silent of 480; CLI 21 tracebacks/18 silent of 174")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
