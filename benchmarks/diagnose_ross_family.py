"""The default command on third-party data of a wheel family: ROSS load cells, clean and on heavy test stands.

A family of wheels (default 8, deterministic from ``--seed``) is computed by ROSS (benchmarks/ross_new_wheel.py, run
with a python where ROSS imports, ``--ross-python``): mass 2-15 kg, I_zz/I_rr 1.2-2.2, radius 0.08-0.15 m (I_zz =
½·m·r²), hard-mounted suspension modes 50-600 Hz (translation, rocking and axial in varied orders, each >= 15 % from
the others), ζ 0.01-0.03, top speed 3000, 6000 or 10000 rpm from 10 % of it (40 speeds), a sample rate of 2-10 kHz at
least 2.5x the highest line (h 6.16 at top speed, the modes and the stands), 8192 samples.  Per wheel four cells:

* ``clean``: the wheel hard-mounted on the load cell;
* ``stand k x MODE`` (k = 0.5, 1.0, 1.5): the wheel on a heavy test stand (``--fixture k·f_MODE --fixture-mass``
  10x the wheel's mass per support, ζ 0.03), MODE rotating through translation / rocking / axial from wheel to wheel.

Each cell's records are written by tests/ross_dataset.py and diagnosed by the command a user types,
``nice -n 10 rwadist diagnose DATA -o REPORT`` (no model; a subprocess), at most two cells at a time.  Counted per
cell, from REPORT/model.json and REPORT/summary.json:

* the wall time of diagnose; the effect kinds in the model;
* each suspension mode's relative error against the truth: the hard-mounted value for ``clean``; for a stand cell
  the smaller of the errors against the hard-mounted value and against ROSS's coupled mode at rest (the doc's
  ``campbell`` row at < 10 rpm) nearest to that value (which one is said: ``hard`` / ``coupled``); a mode listed in
  the effect's ``unconstrained`` counts as declared, not as an error;
* the damping ratios against the closed form (translation ζ, axial ζ, rocking ζ·f_rock/f_trans) and I_zz/I_rr;
* for a stand cell: a ``fixed_resonance`` of role ``test_stand`` named, its frequency against the fixture's and
  against ROSS's nearest coupled mode at rest;
* "added": every other effect (``amplitude_law``, ``fixed_resonance`` role ``wheel_mode``, a ``test_stand`` in a
  clean cell, ...); the ``unexplained`` records' signatures.

A cell passes when ``suspension_modes`` is in the model with every mode within 2 % (as above) or unconstrained,
nothing is added, and (stand cells) the stand is named within 2 % of the fixture or of ROSS's nearest coupled mode.
Prints one line per cell as it finishes and a summary table; writes rows.json (every row, with the commands that
reproduce the cell) and keeps each cell's ROSS document and report (the records only with ``--keep-data``)::

    python benchmarks/diagnose_ross_family.py OUT_DIR [--wheels 8] [--seed 33] [--ross-python /tmp/rossvenv/bin/python]

ROSS is not a project dependency (see benchmarks/ross_new_wheel.py for its venv); it runs from /tmp, not the repo.
One cell takes ~15 s of ROSS and ~1-2 min of diagnose on a shared two-core machine.

Record (default 8 wheels, seed 33).  At 6894472: clean 8/8; stand cells 14/24 with every mode within 2 % or declared,
the stand named 13/24, effects invented in 10/24.  At c6eb5a0 (2026-12-04, ROSS 2.3.0, plotly<6; 668 s wall on two
cores, diagnose median 12 s, max 96 s): clean 8/8 (nothing added, every mode within 2 % or declared); stand cells 17/24
(modes: 39 within 2 %, 19 unconstrained, 14 off, of 72); a test_stand within 2 % of the fixture or of ROSS's nearest
coupled mode 14/24; effects invented in 6/24 stand cells (amplitude_law 6, fixed_resonance wheel_mode 5); every
criterion in 21/32 cells.  Failing: the stand at 1x the translation (w0: the axial 8 % off, the stand named 3.5 % off;
w3: the translation 10.5 % off, no stand), every stand cell of w1 (I_zz/I_rr 1.22, rocking 405.6 Hz above its 334.5 Hz
axial: the rocking declared, two amplitude laws invented, no stand), w4 at 0.5x/1.5x rocking (no mode located:
suspension_modes not named), w5 at 0.5x axial (the translation 8 % off, no stand), w7 at every rocking stand (its
rocking at 462.6 Hz, I_zz/I_rr 1.24: wheel_mode resonances invented).  At 3abf466 (2026-12-04, 512 s wall, diagnose
median 9 s, max 69 s): the same but for w5 at 0.5x axial, where a take-back had left the model worse than the start
(0.53 -> 0.70) and the stand is now kept at 66.0 Hz (ROSS's coupled mode 66.4 Hz; the error 0.53 -> 0.21; its
translation still 8 % off): the stand named within 2 % of the fixture or ROSS's nearest coupled mode 15/24, every
criterion 21/32.  w4 at 0.5x rocking (a 75-kg stand at 37 Hz; ROSS's coupled rocking at rest 100.6 Hz, 35 % above
the hard-mounted 74.5 Hz, the stand's own tilt whirling with speed): no mode located, and the 1x lines, amplified at
nearly every speed, left out of the model -- now said (suspension_modes_status.left_out, the console, the h = 1
ridges' first cause; tests/test_diagnose_left_out.py).  Session 50 (120fcc5: the test stand on the empirical base
refitted at the end, its lines weighted by their scatter; 1733 s wall, one cell at a time beside other runs): every
cell's pass the same as main 5e64498's, run beside it (21/32; stand named within 2 % of the fixture or ROSS's coupled
mode 15/24; effects invented in 6/24 stand cells), the diagnoses identical but w7 at 1x rocking (its stand 464.057 ->
464.059 Hz, the error after 0.033997 -> 0.033991).
"""
from __future__ import annotations

import argparse
import itertools
import json
import shlex
import shutil
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
GENERATOR = ROOT / "benchmarks" / "ross_new_wheel.py"
RECORDS = ROOT / "tests" / "ross_dataset.py"
MODES = ("translation", "rocking", "axial")
#: the model's names of the modes (suspension_modes keys / unconstrained names)
EFFECT_KEY = {"translation": "radial_translation_Hz", "rocking": "rocking_Hz", "axial": "axial_Hz"}
UNC_NAME = {"translation": "radial_translation", "rocking": "rocking", "axial": "axial"}
ZETA_KEY = {"translation": "zeta_radial_translation", "rocking": "zeta_rocking", "axial": "zeta_axial"}
FACTORS = (0.5, 1.0, 1.5)
H_TOP = 6.16              # the generator's highest line
MODE_TOL, STAND_TOL = 0.02, 0.02
SAMPLES = 8192
N_SPEEDS = 40


def _rwadist_cmd() -> list:
    exe = Path(sys.executable).with_name("rwadist")
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "rwadist"]


def family(n: int, seed: int) -> list:
    """n wheels drawn from seed: the generator's flags (rounded, so the printed command reproduces them)."""
    rng = np.random.default_rng(seed)
    orders = list(itertools.permutations(MODES))
    rng.shuffle(orders)
    wheels = []
    for i in range(n):
        mass = round(float(rng.uniform(2.0, 15.0)), 2)
        i_ratio = round(float(rng.uniform(1.2, 2.2)), 2)
        radius = round(float(rng.uniform(0.08, 0.15)), 3)
        while True:       # three modes in 50-600 Hz, each >= 15 % from the others
            f = np.sort(np.round(np.exp(rng.uniform(np.log(50.0), np.log(600.0), 3)), 1))
            if f[1] >= 1.15 * f[0] and f[2] >= 1.15 * f[1]:
                break
        order = orders[i % len(orders)]            # lowest to highest
        modes = {name: float(fr) for name, fr in zip(order, f)}
        zeta = round(float(rng.uniform(0.01, 0.03)), 4)
        top = float(rng.choice([3000.0, 6000.0, 10000.0]))
        stand_mode = MODES[i % 3]
        highest = max(H_TOP * top / 60.0, max(modes.values()), max(FACTORS) * modes[stand_mode])
        lo = max(2000.0, 2.5 * highest)
        fs = float(np.ceil(rng.uniform(lo, 10000.0) / 100.0) * 100.0)
        wheels.append({"wheel": i, "mass": mass, "i_ratio": i_ratio, "radius": radius, "modes": modes,
                       "order": "<".join(order), "zeta": zeta, "rpm": (0.1 * top, top, N_SPEEDS),
                       "sample_rate": fs, "stand_mode": stand_mode})
    return wheels


def cells_of(w: dict) -> list:
    out = [dict(w, cell=f"w{w['wheel']}_clean", fixture_hz=None, factor=None)]
    for k in FACTORS:
        out.append(dict(w, cell=f"w{w['wheel']}_stand{k:g}x{w['stand_mode'][:5]}",
                        fixture_hz=round(k * w["modes"][w["stand_mode"]], 1), factor=k,
                        fixture_mass=round(10.0 * w["mass"], 2)))
    return out


def generator_args(c: dict, out_json: Path, ross_python: str) -> list:
    m = c["modes"]
    args = [ross_python, str(GENERATOR), str(out_json), "--mass", f"{c['mass']:g}", "--i-ratio", f"{c['i_ratio']:g}",
            "--radius", f"{c['radius']:g}", "--modes", f"{m['translation']:g}", f"{m['rocking']:g}", f"{m['axial']:g}",
            "--zeta", f"{c['zeta']:g}", "--rpm", f"{c['rpm'][0]:g}", f"{c['rpm'][1]:g}", f"{c['rpm'][2]:d}"]
    if c["fixture_hz"] is not None:
        args += ["--fixture", f"{c['fixture_hz']:g}", "--fixture-mass", f"{c['fixture_mass']:g}"]
    return args


def rel(a, b):
    return None if a is None or b is None or not b else float(a / b - 1.0)


def evaluate(c: dict, doc: dict, model: dict, summary: dict) -> dict:
    truth = doc["truth"]
    hard = {"translation": truth["translation_hz"], "rocking": truth["rocking_hz"], "axial": truth["axial_hz"]}
    rest = next(r for r in doc["campbell"] if r["speed_rpm"] < 10)["modes_hz"]
    effects = model.get("effects") or []
    kinds = [e["kind"] for e in effects]
    sm = next((e for e in effects if e["kind"] == "suspension_modes"), None)
    row = {"effects": kinds, "ross_rest_modes_hz": [round(f, 2) for f in rest],
           "suspension_modes_status": (summary.get("suspension_modes_status") or {}).get("status")}
    modes, all_ok = {}, sm is not None
    unc = list((sm or {}).get("unconstrained") or [])
    for name in MODES:
        got = sm.get(EFFECT_KEY[name]) if sm else None
        e_hard = rel(got, hard[name])
        coupled = min(rest, key=lambda f: abs(f - hard[name])) if c["fixture_hz"] is not None else None
        e_coup = rel(got, coupled)
        best, via = e_hard, "hard"
        if e_coup is not None and e_hard is not None and abs(e_coup) < abs(e_hard):
            best, via = e_coup, "coupled"
        declared = UNC_NAME[name] in unc
        ok = sm is not None and (declared or (best is not None and abs(best) <= MODE_TOL))
        all_ok &= ok
        modes[name] = {"true_hz": hard[name], "coupled_hz": coupled, "fit_hz": got, "err": best, "via": via,
                       "err_hard": e_hard, "err_coupled": e_coup, "unconstrained": declared, "ok": ok}
    row["modes"], row["modes_ok"] = modes, all_ok
    z_true = {"translation": truth["zeta"], "axial": truth["zeta"],
              "rocking": truth["zeta"] * hard["rocking"] / hard["translation"]}
    row["zeta"] = {name: {"true": z_true[name], "fit": sm.get(ZETA_KEY[name]) if sm else None,
                          "err": rel(sm.get(ZETA_KEY[name]), z_true[name]) if sm else None,
                          "held": ZETA_KEY[name] in unc} for name in MODES}
    row["inertia_ratio"] = {"true": truth["I_zz_over_I_rr"], "fit": sm.get("inertia_ratio") if sm else None,
                            "err": rel(sm.get("inertia_ratio"), truth["I_zz_over_I_rr"]) if sm else None}
    stands = [e for e in effects if e["kind"] == "fixed_resonance" and e.get("role") == "test_stand"]
    stand, chosen = None, None
    if c["fixture_hz"] is not None and stands:
        s = chosen = min(stands, key=lambda e: abs(e["f_Hz"] / c["fixture_hz"] - 1))
        near = min(rest, key=lambda f: abs(f - s["f_Hz"]))
        stand = {"f_hz": s["f_Hz"], "zeta": s.get("zeta"), "err_fixture": rel(s["f_Hz"], c["fixture_hz"]),
                 "coupled_hz": near, "err_coupled": rel(s["f_Hz"], near)}
        stand["ok"] = min(abs(stand["err_fixture"]), abs(stand["err_coupled"])) <= STAND_TOL
    row["stand"] = stand
    added = [e for e in effects if e["kind"] != "suspension_modes" and e is not chosen]
    row["added"] = [e["kind"] + (f"({e.get('role')} {e['f_Hz']:.1f} Hz)" if e["kind"] == "fixed_resonance" else "")
                    + (f"({e.get('direction')} h {e.get('h'):g})" if e["kind"] == "amplitude_law" else "")
                    for e in added]
    row["unexplained"] = [u.get("signature") for u in summary.get("unexplained") or []]
    row["error_before_after"] = [summary.get("error_before"), summary.get("error_after")]
    stand_ok = c["fixture_hz"] is None or bool(stand and stand["ok"])
    row["pass"] = bool(all_ok and not added and stand_ok)
    return row


def run_cell(c: dict, out: Path, ross_python: str, keep_data: bool, timeout: float) -> dict:
    cell_dir = out / c["cell"]
    cell_dir.mkdir(parents=True, exist_ok=True)
    doc_path, data, report = cell_dir / "ross.json", cell_dir / "data", cell_dir / "report"
    gen = ["nice", "-n", "10"] + generator_args(c, doc_path, ross_python)
    rec = [sys.executable, str(RECORDS), str(data), "--doc", str(doc_path), "--sample-rate", f"{c['sample_rate']:g}",
           "--samples", str(SAMPLES)]
    diag = ["nice", "-n", "10"] + _rwadist_cmd() + ["diagnose", str(data), "-o", str(report)]
    row = {k: c[k] for k in ("cell", "wheel", "mass", "i_ratio", "radius", "modes", "order", "zeta", "rpm",
                             "sample_rate", "fixture_hz", "factor")}
    row["stand_mode"] = c["stand_mode"] if c["fixture_hz"] is not None else None
    row["fixture_mass"] = c.get("fixture_mass")
    row["reproduce"] = ["cd /tmp && " + shlex.join(gen[3:]), shlex.join(rec), shlex.join(diag)]
    log = cell_dir / "log.txt"
    with log.open("w") as fh:
        for step, cmd, cwd in (("ross", gen, "/tmp"), ("records", rec, None), ("diagnose", diag, None)):
            fh.write(f"$ {shlex.join(cmd)}\n")
            fh.flush()
            t0 = time.perf_counter()
            try:
                p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=timeout)
            except subprocess.TimeoutExpired:
                row.update(error=f"{step}: timed out after {timeout:.0f} s", **{"pass": False})
                return row
            row[f"{step}_s"] = round(time.perf_counter() - t0, 1)
            fh.write(p.stdout + "\n--- stderr ---\n" + p.stderr + "\n")
            fh.flush()
            if p.returncode != 0:
                tail = [ln for ln in p.stderr.strip().splitlines() if ln.strip()][-3:]
                row.update(error=f"{step}: exit {p.returncode}: " + " | ".join(tail), **{"pass": False})
                return row
            if step == "diagnose":
                row["traceback_in_stderr"] = "Traceback" in p.stderr
    if not keep_data:
        shutil.rmtree(data, ignore_errors=True)
    doc = json.loads(doc_path.read_text())
    model = json.loads((report / "model.json").read_text())
    summary = json.loads((report / "summary.json").read_text())
    row.update(evaluate(c, doc, model, summary))
    return row


def pct(x, nd=2):
    return "  n/a" if x is None else f"{100 * x:+.{nd}f}%"


def line_of(r: dict) -> str:
    if "error" in r:
        return f"{r['cell']:<22} ERROR {r['error']}"
    ms = []
    for name in MODES:
        m = r["modes"][name]
        tag = "U" if m["unconstrained"] else ("h" if m["via"] == "hard" else "c")
        ms.append(f"{name[0].upper()} {m['fit_hz'] if m['fit_hz'] is None else round(m['fit_hz'], 1)}/"
                  f"{m['true_hz']:g} {pct(m['err'])}{tag}")
    zs = " ".join(f"z{n[0]}{'*' if r['zeta'][n]['held'] else ''} {pct(r['zeta'][n]['err'], 0)}" for n in MODES)
    st = ""
    if r["fixture_hz"] is not None:
        s = r["stand"]
        st = (f" | stand {r['fixture_hz']:g}: " + ("NONE" if s is None else
              f"{s['f_hz']:.1f} fix {pct(s['err_fixture'])} coup {s['coupled_hz']:.1f} {pct(s['err_coupled'])}"))
    return (f"{r['cell']:<22} {r['diagnose_s']:6.1f}s {'PASS' if r['pass'] else 'FAIL'} | {'; '.join(ms)} | {zs} "
            f"| Ir {pct(r['inertia_ratio']['err'], 1)}{st} | added {r['added'] or '-'} | unexpl "
            f"{r['unexplained'] or '-'}")


def summarize(rows: list) -> str:
    ok_rows = [r for r in rows if "error" not in r]
    clean = [r for r in ok_rows if r["fixture_hz"] is None]
    stand = [r for r in ok_rows if r["fixture_hz"] is not None]
    n_clean = sum(1 for r in rows if r["fixture_hz"] is None)
    n_stand = len(rows) - n_clean

    def modes_count(rs):
        cells = sum(r["modes_ok"] for r in rs)
        ms = [m for r in rs for m in r["modes"].values()]
        within = sum(1 for m in ms if m["ok"] and not m["unconstrained"])
        unc = sum(1 for m in ms if m["unconstrained"])
        return cells, within, unc, len(ms)

    lines = ["", "summary (criteria: modes within 2 % of the truth -- stand cells: of the hard-mounted value or of "
             "ROSS's coupled mode at rest nearest to it -- or unconstrained; stand = fixed_resonance role test_stand "
             "within 2 % of the fixture or of ROSS's nearest coupled mode)",
             f"  cells run: {len(rows)} ({len(rows) - len(ok_rows)} errors)"]
    lines.append(f"  clean cells with 0 effects beyond suspension_modes: "
                 f"{sum(1 for r in clean if not set(r['effects']) - {'suspension_modes'})}/{n_clean}")
    for label, rs, n in (("clean", clean, n_clean), ("stand", stand, n_stand), ("all", ok_rows, len(rows))):
        cells, within, unc, nm = modes_count(rs)
        lines.append(f"  {label:<5} cells with every mode within 2 % or unconstrained: {cells}/{n}  "
                     f"(modes: {within} within 2 %, {unc} unconstrained, {nm - within - unc} off, of {nm})")
    named = [r for r in stand if r["stand"] is not None]
    lines.append(f"  stand cells with a test_stand named: {len(named)}/{n_stand}; within 2 % of the fixture: "
                 f"{sum(1 for r in named if abs(r['stand']['err_fixture']) <= STAND_TOL)}/{n_stand}; within 2 % of "
                 f"the fixture or ROSS's nearest coupled mode: {sum(1 for r in named if r['stand']['ok'])}/{n_stand}")
    inv = [r for r in ok_rows if r["added"]]
    lines.append(f"  cells with invented (added) effects: {len(inv)}/{len(rows)}  (clean "
                 f"{sum(1 for r in inv if r['fixture_hz'] is None)}, stand {sum(1 for r in inv if r['fixture_hz'])})")
    kinds = {}
    for r in inv:
        for a in r["added"]:
            k = a.split("(")[0] + (" " + a.split("(")[1].split()[0] if a.startswith("fixed_resonance") else "")
            kinds[k] = kinds.get(k, 0) + 1
    lines.append(f"  added effect kinds (count): {kinds or '-'}")
    sig = {}
    for r in ok_rows:
        for u in r["unexplained"]:
            sig[u] = sig.get(u, 0) + 1
    lines.append(f"  unexplained signatures (count over cells): {sig or '-'}")
    zs = [abs(r["zeta"][n]["err"]) for r in ok_rows for n in MODES
          if r["zeta"][n]["err"] is not None and not r["zeta"][n]["held"] and not r["modes"][n]["unconstrained"]]
    if zs:
        lines.append(f"  damping of located modes (not held): |err| median {100 * np.median(zs):.0f} %, within 20 %: "
                     f"{sum(z <= 0.2 for z in zs)}/{len(zs)}")
    ir = [abs(r["inertia_ratio"]["err"]) for r in ok_rows if r["inertia_ratio"]["err"] is not None]
    if ir:
        lines.append(f"  I_zz/I_rr: |err| median {100 * np.median(ir):.1f} %, within 5 %: "
                     f"{sum(x <= 0.05 for x in ir)}/{len(ir)}")
    ts = [r["diagnose_s"] for r in rows if "diagnose_s" in r]
    if ts:
        lines.append(f"  diagnose wall time: median {np.median(ts):.0f} s, max {max(ts):.0f} s, > 60 s: "
                     f"{sum(t > 60 for t in ts)}/{len(ts)}")
    lines.append(f"  PASS (all of the above in the cell): {sum(r['pass'] for r in rows)}/{len(rows)}")
    fails = [r for r in rows if not r["pass"]]
    if fails:
        lines.append("failing cells (reproduce: ROSS doc, records, diagnose):")
        for r in fails:
            lines.append(f"  {r['cell']}: " + (r.get("error") or "") + "\n    " + "\n    ".join(r["reproduce"]))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="output folder (ROSS documents, reports, rows.json)")
    ap.add_argument("--ross-python", default="/tmp/rossvenv/bin/python", help="a python where ROSS imports")
    ap.add_argument("--wheels", type=int, default=8)
    ap.add_argument("--only", default=None, help="comma-separated wheel indices (default: all)")
    ap.add_argument("--seed", type=int, default=33)
    ap.add_argument("--jobs", type=int, default=2, help="cells at a time (at most 2 on a shared two-core machine)")
    ap.add_argument("--timeout", type=float, default=1200.0, help="s per step")
    ap.add_argument("--keep-data", action="store_true", help="keep the records (~45 MB a cell)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    wheels = family(args.wheels, args.seed)
    if args.only:
        keep = {int(x) for x in args.only.split(",")}
        wheels = [w for w in wheels if w["wheel"] in keep]
    print("family (seed %d):" % args.seed)
    for w in wheels:
        print(f"  w{w['wheel']}: {w['mass']:g} kg, I_zz/I_rr {w['i_ratio']:g}, r {w['radius']:g} m, modes T "
              f"{w['modes']['translation']:g} R {w['modes']['rocking']:g} A {w['modes']['axial']:g} Hz ({w['order']}), "
              f"ζ {w['zeta']:g}, {w['rpm'][0]:g}-{w['rpm'][1]:g} rpm, {w['sample_rate']:g} Hz, stand on {w['stand_mode']}")
    cells = [c for w in wheels for c in cells_of(w)]
    print(f"{len(cells)} cells, {min(args.jobs, 2)} at a time; per cell: diagnose s, PASS/FAIL, modes fit/true err "
          f"(h hard-mounted, c coupled, U unconstrained), ζ errors (* held), I_zz/I_rr, stand, added, unexplained",
          flush=True)
    rows, lock, t_all = [], threading.Lock(), time.perf_counter()
    rows_path = args.out / "rows.json"
    with ThreadPoolExecutor(max_workers=max(1, min(args.jobs, 2))) as pool:
        futs = {pool.submit(run_cell, c, args.out, args.ross_python, args.keep_data, args.timeout): c for c in cells}
        for f in as_completed(futs):
            try:
                r = f.result()
            except Exception as exc:  # noqa: BLE001 - a harness error is a row, not a crash
                c = futs[f]
                r = {"cell": c["cell"], "wheel": c["wheel"], "fixture_hz": c["fixture_hz"], "pass": False,
                     "error": f"harness: {type(exc).__name__}: {exc}", "reproduce": []}
            with lock:
                rows.append(r)
                print(line_of(r), flush=True)
                rows_path.write_text(json.dumps(sorted(rows, key=lambda x: x["cell"]), indent=1))
    rows.sort(key=lambda x: (x["wheel"], x["cell"]))
    rows_path.write_text(json.dumps(rows, indent=1))
    print(summarize(rows))
    print(f"total wall time {time.perf_counter() - t_all:.0f} s; rows: {rows_path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
