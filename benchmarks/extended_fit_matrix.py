"""Robustness matrix of the extended fit (issue 14): per cell the fitted radial translation, rocking and
axial frequencies against the truth, and whether each mode was found or declared unconstrained.

Two generators: the project's virtual stand (``simulate_steady(..., physics="extended")``, E preset,
whose closed form is rwadist's own) and ``tests/independent_wheel.py`` (real-coordinate harmonic
balance written without rwadist; co-rotating fraction of the non-imbalance radial lines either the
E wheel's or 0.5, planar).  The axes (speed range 300-2400 / 300-3000 / 100-6000 rpm; 20 / 60 / 120
speeds; 2048 / 8192 / 32768 samples; 1000 / 3840 / 10000 Hz) form an L9 orthogonal array (every
pair of levels of every two axes once), crossed with noise 0.1 / 1 / 5 % of the top-speed
fundamental and the generators: 54 cells, a new random seed (phases, noise) per cell.

Acceptance per cell: a found mode within 2 % of the truth; a mode not found listed in
``unconstrained`` and in the notes.  ``ok`` is False otherwise.  Run::

    python benchmarks/extended_fit_matrix.py            # full table (~10 min on one core)
    python benchmarks/extended_fit_matrix.py --cells 5  # the first 5 cells

The CI test ``tests/test_extended_fit_matrix.py`` runs a sample of these cells.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

RANGES = [(300.0, 2400.0), (300.0, 3000.0), (100.0, 6000.0)]
N_SPEEDS = [20, 60, 120]
SAMPLES = [2048, 8192, 32768]
RATES = [1000.0, 3840.0, 10000.0]
NOISES = [0.001, 0.01, 0.05]
GENERATORS = ["stand", "independent", "independent-planar"]
# L9(3^4) orthogonal array: columns range, n_speeds, samples, rate
L9 = [(0, 0, 0, 0), (0, 1, 1, 1), (0, 2, 2, 2), (1, 0, 1, 2), (1, 1, 2, 0), (1, 2, 0, 1),
      (2, 0, 2, 1), (2, 1, 0, 2), (2, 2, 1, 0)]
MODES = ("radial_translation", "rocking", "axial")
FIT_KEY = {"radial_translation": "radial_translation", "rocking": "rocking", "axial": "axial_translation"}


def cells(generators=("stand", "independent")):
    """Every cell as a dict (generator, range, n_speeds, samples, rate, noise, seed)."""
    out = []
    for g in generators:
        for noise in NOISES:
            for a, b, c, d in L9:
                out.append({"generator": g, "rpm": RANGES[a], "n_speeds": N_SPEEDS[b], "samples": SAMPLES[c],
                            "rate": RATES[d], "noise": noise, "seed": 1000 + len(out)})
    return out


def generate(cell):
    """(SteadyTest, truth Hz per mode, mass, radius) of one cell."""
    speeds = np.linspace(*cell["rpm"], cell["n_speeds"])
    if cell["generator"] == "stand":
        from rwadist.presets import preset
        from rwadist.teststand import simulate_steady

        wheel = preset("ithaco-e")
        test = simulate_steady(wheel, speeds, sample_rate=cell["rate"], n_samples=cell["samples"],
                               noise=cell["noise"], seed=cell["seed"], physics="extended")
        p = wheel.extended
        truth = {"radial_translation": p.omega_r / (2 * np.pi), "rocking": p.omega_rock / (2 * np.pi),
                 "axial": p.omega_z / (2 * np.pi)}
        return test, truth, wheel.mass_kg, wheel.radius_m
    import independent_wheel as iw

    co = 0.5 if cell["generator"] == "independent-planar" else None
    test, truth = iw.generate(speeds, sample_rate=cell["rate"], n_samples=cell["samples"], noise=cell["noise"],
                              seed=cell["seed"], co_fraction=co)
    return test, truth, iw.MASS, iw.RADIUS


def run_cell(cell, with_mass=True):
    """Fit one cell; returns a row dict with the fitted/true frequencies, found/unconstrained, ok."""
    from rwadist.empirical import fit_empirical
    from rwadist.extended_fit import fit_extended
    from rwadist.spectra import compute_spectra

    test, truth, mass, radius = generate(cell)
    t0 = time.perf_counter()
    fit = fit_empirical(compute_spectra(test))
    ef = fit_extended(test, fit, mass if with_mass else None, radius if with_mass else None)
    p = ef.params
    fitted = {"radial_translation": p.omega_r / (2 * np.pi), "rocking": p.omega_rock / (2 * np.pi),
              "axial": p.omega_z / (2 * np.pi)}
    row = dict(cell, seconds=time.perf_counter() - t0, ok=True, problems=[])
    for m in MODES:
        found = bool(ef.identified[FIT_KEY[m]])
        declared = m in ef.unconstrained and any(n.startswith(FIT_KEY[m]) and "NOT CONSTRAINED" in n for n in ef.notes)
        err = fitted[m] / truth[m] - 1
        row[m] = {"fitted_hz": fitted[m], "truth_hz": truth[m], "error": err, "found": found,
                  "declared_unconstrained": declared}
        if found and abs(err) > 0.02:
            row["ok"] = False
            row["problems"].append(f"{m} found at {fitted[m]:.2f} Hz, truth {truth[m]:.2f} Hz ({100 * err:+.1f} %)")
        if not found and not declared:
            row["ok"] = False
            row["problems"].append(f"{m} not found and not declared unconstrained")
    if not with_mass:
        row["inertia_ratio"] = p.I_zz / p.I_rr
    return row


def format_row(r):
    def mode(m):
        x = r[m]
        tag = "found" if x["found"] else "UNCONSTR" if x["declared_unconstrained"] else "SILENT!"
        return f"{x['fitted_hz']:8.2f}/{x['truth_hz']:6.2f} {100 * x['error']:+6.2f}% {tag:8s}"
    return (f"{r['generator']:18s} {r['rpm'][0]:4.0f}-{r['rpm'][1]:4.0f} {r['n_speeds']:4d} {r['samples']:6d} "
            f"{r['rate']:6.0f} {100 * r['noise']:4.1f}% | " + " | ".join(mode(m) for m in MODES)
            + f" | {r['seconds']:5.1f}s {'ok' if r['ok'] else 'FAIL: ' + '; '.join(r['problems'])}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=None, help="run only the first N cells")
    ap.add_argument("--planar", action="store_true", help="also the independent generator with planar lines")
    ap.add_argument("--no-mass", action="store_true", help="fit without mass and radius (per unit, a fitted)")
    args = ap.parse_args(argv)
    gens = ("stand", "independent", "independent-planar") if args.planar else ("stand", "independent")
    todo = cells(gens)[: args.cells]
    print(f"{'generator':18s} {'rpm':9s} {'n':>4s} {'samp':>6s} {'Hz':>6s} noise | "
          + " | ".join(f"{m + ' fit/true':<33s}" for m in MODES))
    rows = []
    for c in todo:
        r = run_cell(c, with_mass=not args.no_mass)
        rows.append(r)
        print(format_row(r), flush=True)
    n_ok = sum(r["ok"] for r in rows)
    found = {m: sum(r[m]["found"] for r in rows) for m in MODES}
    worst = {m: max((abs(r[m]["error"]) for r in rows if r[m]["found"]), default=float("nan")) for m in MODES}
    print(f"\ncells ok: {n_ok}/{len(rows)};  found per mode: "
          + ", ".join(f"{m} {found[m]}/{len(rows)} (worst |error| {100 * worst[m]:.2f} %)" for m in MODES))
    return 0 if n_ok == len(rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
