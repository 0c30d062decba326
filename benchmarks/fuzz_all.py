"""Fuzz every edge of the kit (issues 17, 36): >= 300 seeded cases per surface, in-process, and a table.

Surfaces:

- ``cli``: mutated numeric flags and output paths of every command (tests/fuzz_cases.py);
- ``readers``: damaged data files (flipped bytes, truncation, UTF-16, NaN samples, HDF5 dangling links) and bad
  values of the fields the readers read (meta.json tach/f_lim_hz/sample_rate_hz, runs.csv speeds, a 1e308 sample,
  TDMS wf_start_offset NaN, a MATLAB v7.3 channel stored as a group), through `convert` and `fit`;
- ``models``: mutated model files (values beyond any real wheel's, NaN, strings, misspelt keys, a missing section,
  unknown effect kinds, absurd effect parameters, 20 000 harmonics, extensions) through EVERY consumer: model show,
  psd, campbell, the Python API, the coupling kit on each case, fmu build --native and diagnose on every 4th/6th;
  a file `model show` refuses and another consumer accepts counts as silent (valid everywhere or nowhere);
- ``api``: the public API's arguments (NaN, inf, negatives, 1e308, strings, booleans, lists, None) of
  simulate_test, fit, psd, campbell, diagnose, load_model, save_model (tests/fuzz_surfaces.py);
- ``fmu``: hostile parameters, inputs, communication points and state calls through fmpy into both FMUs
  (tests/test_fuzz_fmu.py).

    python benchmarks/fuzz_all.py [--n 300] [--seed 17] [--surface cli|readers|models|api|fmu] [-v]
    python benchmarks/fuzz_all.py --surface models --consumers fmu,diagnose     # the slow consumers on every case

Prints per surface (per consumer for ``models``) the counts: ok (accepted, may be valid), clear (an error naming the
file, flag or argument), unclear (refused without naming it), silent (a known-invalid value accepted, or accepted
by one consumer and refused by another) and traceback.  Must be 0 tracebacks and 0 silent.  Baseline (before
issue 36, its audit of 2,163 cases): 43 reader cases and 69 model-file cases silent; C = 1e308 passed model show,
campbell and fmu build; the API checked no argument.  Before issue 17: readers 3 tracebacks / 14 unclear of 360;
model files 45 tracebacks / 30 silent of 480; CLI 21 tracebacks / 18 silent of 174.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter, defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import fuzz_cases as fz  # noqa: E402
import fuzz_surfaces as fs  # noqa: E402
import test_fuzz_fmu as fzf  # noqa: E402


def _line(name: str, n: int, seconds: float, counts: dict) -> str:
    return f"{name:<18} {n:>5} {seconds:>6.0f} " + " ".join(f"{counts.get(k, 0):>9}" for k in fz.OUTCOMES)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=17)
    ap.add_argument("--surface", choices=("cli", "readers", "models", "api", "fmu"), action="append")
    ap.add_argument("-v", "--verbose", action="store_true", help="print every case that is not ok/clear")
    ap.add_argument("--consumers", help="models: these consumers (comma separated, of "
                    f"{','.join(fs.CONSUMERS)}) on every case; default the fast ones on every case, fmu on every "
                    "4th, diagnose on every 6th")
    a = ap.parse_args(argv)
    surfaces = a.surface or ["cli", "readers", "models", "api", "fmu"]
    bad = 0
    print(f"{'surface':<18} {'cases':>5} {'s':>6} " + " ".join(f"{k:>9}" for k in fz.OUTCOMES), flush=True)
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
                    print(_line(f"fmu/{kind}", len(mine), time.perf_counter() - t0, c), flush=True)
                continue
            if surface == "models":
                sets = fz.make_datasets(work)
                per = defaultdict(Counter)
                cases = fs.model_consumer_cases(a.n, a.seed, work, sets["steady"],
                                                a.consumers.split(",") if a.consumers else None)
                for path, invalid, what, consumers, data in cases:
                    out = fs.run_model_case(path, invalid, consumers, data, work)
                    for consumer, (outcome, detail) in out.items():
                        per[consumer][outcome] += 1
                        if a.verbose and outcome not in ("ok", "clear"):
                            print(f"  {outcome:<9} {consumer} {what}\n            {detail}")
                for consumer in [c for c in fs.CONSUMERS if c in per]:
                    c = per[consumer]
                    bad += c["traceback"] + c["silent"]
                    print(_line(f"models/{consumer}", sum(c.values()), time.perf_counter() - t0, c), flush=True)
                continue
            if surface == "api":
                cases = fs.api_cases(a.n, a.seed, work)
                results = [fs.run_api_case(c) for c in cases]
                if a.verbose:
                    for c, r in zip(cases, results):
                        if r[0] not in ("ok", "clear"):
                            print(f"  {r[0]:<9} {c[3]}\n            {r[1]}")
            else:
                if surface == "cli":
                    cases = [c + ("",) for c in fz.cli_cases(a.n, a.seed, work)]
                else:
                    sets = fz.make_datasets(work)
                    cases = fz.reader_cases(a.n // 2, a.seed, work, sets) + \
                        fs.reader_field_cases(a.n - a.n // 2, a.seed, work, sets["steady"])
                results = []
                for argv_, names, invalid, what in cases:
                    res = fz.run_case(argv_, names, invalid)
                    results.append(res)
                    if a.verbose and res[0] not in ("ok", "clear"):
                        print(f"  {res[0]:<9} {what} | {' '.join(map(str, argv_))[:160]}\n            {res[1]}")
            c = fz.tally(results)
            bad += c["traceback"] + c["silent"]
            print(_line(surface, len(cases), time.perf_counter() - t0, c), flush=True)
    print(f"tracebacks + silent: {bad} (must be 0).  Baseline before issue 36: 43 reader and 69 model-file cases "
          "silent of 2,163; C = 1e308 passed model show, campbell and fmu build; the API checked no argument")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
