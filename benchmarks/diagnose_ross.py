"""The default command on third-party data: ROSS's new wheel, clean, with a counter-rotating fundamental, on a test stand (issue 33).

For each stored ROSS document (tests/data/ross_new_wheel*.json, made by benchmarks/ross_new_wheel.py) the
load-cell records are written at 5 kHz (tests/ross_dataset.py) and ``rwadist diagnose DATA -o REPORT`` runs in a
subprocess, as a user types it.  Printed per case: the effects added, the suspension modes against ROSS's own
(hard-mounted truth, and ROSS's modes with the stand when there is one: a stand of finite mass moves them, and
either counts), the
stand's frequency, the descriptions, and the error before -> after::

    python benchmarks/diagnose_ross.py [--samples 8192] [--keep DIR]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import ross_dataset as rd  # noqa: E402

from rwadist import data as data_io  # noqa: E402

DOCS = sorted((ROOT / "tests" / "data").glob("ross_new_wheel*.json"))


def modes_of(an: dict) -> dict:
    """Hard-mounted modes (Hz) of a model file's analytical section."""
    m, i_rr = an["mass_kg"], an["I_rr_kg_m2"]
    return {"translation": np.sqrt(an["k_r_N_per_m"] / m) / (2 * np.pi),
            "rocking": np.sqrt(an["k_rock_Nm_per_rad"] / i_rr) / (2 * np.pi),
            "axial": np.sqrt(an["k_z_N_per_m"] / m) / (2 * np.pi)}


def run_case(doc_path: Path, work: Path, samples: int) -> dict:
    doc = rd.load_doc(doc_path)
    data, out = work / (doc_path.stem + "_data"), work / (doc_path.stem + "_report")
    data_io.write_steady(rd.ross_test(sample_rate=5000.0, n_samples=samples, path=doc_path), data)
    proc = subprocess.run([sys.executable, "-m", "rwadist", "diagnose", str(data), "-o", str(out)],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        return {"case": doc_path.stem, "failed": proc.stderr.strip().splitlines()[-1:]}
    model = json.loads((out / "model.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    truth = doc["truth"]
    hard = {"translation": truth["translation_hz"], "rocking": truth["rocking_hz"], "axial": truth["axial_hz"]}
    rest = next(c for c in doc["campbell"] if c["speed_rpm"] < 10)["modes_hz"]
    got = modes_of(model["analytical"]) if model.get("analytical") else {}
    unconstrained = (model.get("analytical") or {}).get("unconstrained", [])
    stands = [e for e in model["effects"] if e["kind"] == "fixed_resonance"]
    expected = ["suspension_modes"] + (["counter_rotation"] if truth.get("counter_fundamental") else [])
    return {"case": doc_path.stem, "fixture_hz": truth.get("fixture_hz"), "expected": expected,
            "effects": [e["kind"] for e in model["effects"]],
            # (Hz, % from the hard-mounted truth, % from the nearest of ROSS's modes at rest with the stand)
            "modes": {k: (round(v, 2), round(100 * (v / hard[k] - 1), 2),
                          round(100 * min((v / f - 1 for f in rest), key=abs), 2)) for k, v in got.items()},
            "unconstrained": unconstrained,
            "stand_hz": [round(e["f_Hz"], 1) for e in stands],
            "unexplained": [u.get("signature") for u in summary.get("unexplained", [])],
            "error_before_after": (round(summary["error_before"], 4), round(summary["error_after"], 5)),
            "ross_modes_at_rest_hz": [round(f, 2) for f in rest]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=8192)
    ap.add_argument("--keep", type=Path, default=None, help="keep data and reports here")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        for p in DOCS:
            r = run_case(p, work, args.samples)
            print(json.dumps(r))
            ok = ("failed" not in r and "suspension_modes" in r["effects"]
                  and all(min(abs(e), abs(c)) <= 2 for k, (_, e, c) in r["modes"].items() if k not in r["unconstrained"])
                  and set(r["effects"]) - {"fixed_resonance"} == set(r["expected"])
                  and (r["fixture_hz"] is None) == (not r["stand_hz"]))
            print(f"  {p.stem}: {'PASS' if ok else 'FAIL'} (modes within 2 % of the hard-mounted truth or of "
                  f"ROSS's with the stand, or unconstrained, the classes the data hold and nothing else, the stand named iff there is one)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
