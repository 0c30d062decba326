"""Load-cell time series from ROSS's steady-state response (tests/data/ross_loadcell.json).

``benchmarks/ross_loadcell.py`` (run with ROSS) stores, per speed and forcing line, the complex
phasors of the six channels and ROSS's Campbell diagram.  Here each run is built as
Σ_lines Re(A·e^{iφ}·e^{i2πft}) with a random phase φ per line and run (the two imbalances share one:
they sit on one rotor), plus white noise as a fraction of the top-speed fundamental (forces: the
static imbalance's Fx; torques: the dynamic imbalance's Tx).  Feed it to anything that takes a
SteadyTest, or write it for the command line::

    python tests/ross_dataset.py OUT_DIR [--doc DOC.json --sample-rate HZ --samples N]
    rwadist diagnose OUT_DIR -o report
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "ross_loadcell.json"
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")


def load_doc(path=DATA) -> dict:
    """The stored ROSS document (json)."""
    return json.loads(Path(path).read_text())


def campbell(doc=None) -> list:
    """ROSS's own whirl frequencies: [{speed_rpm, modes_hz, whirl}] (run_modal, lateral modes)."""
    return (doc or load_doc())["campbell"]


def ross_test(noise=0.01, seed=0, sample_rate=3840.0, n_samples=4096, path=DATA):
    """The ROSS dataset as an rwadist SteadyTest (one run per stored speed)."""
    from rwadist.data import Run, SteadyTest

    doc = load_doc(path)
    rng = np.random.default_rng(seed)
    speeds = np.asarray(doc["speeds_rpm"], float) * 2 * np.pi / 60
    lines = doc["lines"]
    A = np.array([np.asarray(ln["phasors_re"]) + 1j * np.asarray(ln["phasors_im"]) for ln in lines])  # (L, S, 6)
    h = np.array([ln["h"] for ln in lines])
    imb = np.array([bool(ln["imbalance"]) for ln in lines])
    std_f = noise * abs(A[0, -1, 0])
    std_t = noise * abs(A[1, -1, 3])
    t = np.arange(int(n_samples)) / sample_rate
    runs = []
    for k, om in enumerate(speeds):
        phase = rng.uniform(0, 2 * np.pi, len(lines))
        phase[imb] = phase[np.argmax(imb)]
        f = h * om / (2 * np.pi)
        keep = f < 0.45 * sample_rate
        z = (A[keep, k, :] * np.exp(1j * phase[keep])[:, None]).T @ np.exp(2j * np.pi * np.outer(f[keep], t))
        sig = {c: z[i].real + (std_f if c.startswith("F") else std_t) * rng.standard_normal(t.size)
               for i, c in enumerate(CHANNELS)}
        runs.append(Run(speed=float(om), sample_rate=float(sample_rate), signals=sig, t0=0.0, name=f"run_{k:04d}.csv"))
    meta = {"source": doc["source"], "generator": "tests/ross_dataset.py", "noise": noise, "seed": seed}
    return SteadyTest(runs=runs, meta=meta)


def diagnosed(path: Path, tmp_path: Path, sample_rate: float, n_samples: int = 8192) -> tuple:
    """(ROSS document, model.json, summary.json, console) of ``rwadist diagnose DATA -o REPORT`` -- the command a user
    types, no model -- on the records of the ROSS document at ``path`` (``sample_rate`` Hz, ``n_samples`` per run),
    written under ``tmp_path``."""
    import contextlib
    import io

    from rwadist import data as data_io
    from rwadist.cli import main as rwadist_main

    data, out = tmp_path / "data", tmp_path / "report"
    data_io.write_steady(ross_test(sample_rate=sample_rate, n_samples=n_samples, path=path), data)
    console = io.StringIO()
    with contextlib.redirect_stdout(console):
        assert rwadist_main(["diagnose", str(data), "-o", str(out)]) == 0
    return (load_doc(path), json.loads((out / "model.json").read_text()),
            json.loads((out / "summary.json").read_text()), console.getvalue())


def main(argv=None):
    import argparse

    from rwadist import data as data_io

    ap = argparse.ArgumentParser(description="write the ROSS dataset as load-cell records")
    ap.add_argument("out", type=Path)
    ap.add_argument("--doc", type=Path, default=DATA, help="a ROSS document (default: tests/data/ross_loadcell.json)")
    ap.add_argument("--sample-rate", type=float, default=3840.0, help="Hz")
    ap.add_argument("--samples", type=int, default=4096, help="samples per run")
    ap.add_argument("--noise", type=float, default=0.01, help="white noise, a fraction of the top-speed fundamental")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    test = ross_test(noise=args.noise, seed=args.seed, sample_rate=args.sample_rate, n_samples=args.samples,
                     path=args.doc)
    data_io.write_steady(test, args.out)
    print(f"wrote {len(test.runs)} runs of {args.doc.name} to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
