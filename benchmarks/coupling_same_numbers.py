"""Same numbers (issue 37): the coupling results of this checkout, dumped for comparison with another's.

Computes, on bench_coupling's case (200-mode plant, 4 wheels, 1000 speeds) and on variants that take the other code
paths (hard-mounted wheels, a wheel spinning the other way, a floor on a torque channel, a ripple with a speed
exponent, a plant given as a StateSpace with no modal data, a few speeds): the RMS of every practice of
:func:`rwadist.coupling.jitter_vs_speed`, the floors' PSD and mean square (:func:`rwadist.coupling.floor_responses`)
and the line phasors of :func:`rwadist.coupling.line_responses`, and writes them to an .npz.  ``--compare A B``
prints the largest relative difference of each array's elements (|A − B| / |A|, elements below 1e-12 of the array's
largest taken at that size) and fails above
``--rtol`` (default 1e-9).

Run: PYTHONPATH=REPO_A python benchmarks/coupling_same_numbers.py --out a.npz; the same with REPO_B and b.npz; then
python benchmarks/coupling_same_numbers.py --compare a.npz b.npz
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_coupling as bc  # noqa: E402

from rwadist import coupling as cp  # noqa: E402
from rwadist import extended_ripple as er  # noqa: E402


def cases():
    """{name: (plant, wheels, speeds rad/s)}."""
    plant, wheels, eff, speeds = bc.setup(1000)
    out = {"bench_plain": (plant, wheels, speeds), "bench_effects": (plant, eff, speeds),
           "bench_ripple": (plant, bc.without_floors(eff), speeds)}
    small = cp.random_modal_plant(n_modes=40, n_nodes=3, n_perf=2, seed=3)
    sp = np.linspace(50.0, 4000.0, 37) * 2 * np.pi / 60
    w0 = eff[0]
    fl_t = cp.Floor(3, np.array([10.0, 80.0, 400.0]), np.array([1e-8, 4e-8, 1e-9]), 200.0, 1.5)
    mixed = [dataclasses.replace(w0, mount=cp.Mount(0, cp.spin_axis_dcm((1, 0, 0)), (0.1, 0.0, 0.1)), name="A"),
             dataclasses.replace(w0, mount=cp.Mount(1, cp.spin_axis_dcm((0, 1, 0)), (0.0, 0.1, 0.1)), speed_scale=-1.0,
                                 floors=w0.floors + (fl_t,), ripple=er.Ripple(5.5, 0.02, 300.0, 1.0), name="B"),
             dataclasses.replace(w0, mount=cp.Mount(2, cp.spin_axis_dcm((1, 1, 1)), (0.0, 0.0, 0.1)), hard_mounted=True,
                                 speed_scale=0.9, name="C")]
    out["mixed_modal"] = (small, mixed, sp)
    ss = cp.Plant("accelerance", small.n_interface, small.perf_names, sys=small.sys, name="ss")
    out["mixed_statespace"] = (ss, mixed, sp[::3])
    return out


def dump(path):
    arrays = {}
    for name, (plant, wheels, speeds) in cases().items():
        jr = cp.jitter_vs_speed(plant, wheels, speeds)
        for p, v in jr.rms.items():
            arrays[f"{name}/jitter/{p}"] = v
        if name.startswith("bench") and name != "bench_plain":
            continue
        lr = cp.line_responses(plant, wheels, speeds)
        for p, ys in lr.y.items():
            for k, y in enumerate(ys):
                arrays[f"{name}/lines/{p}/{k}"] = y
        for k, ld in enumerate(lr.loads):
            arrays[f"{name}/loads/{k}"] = ld
        if lr.floor is not None:
            arrays[f"{name}/floor/f_hz"] = lr.floor.f_hz
            for p in lr.floor.psd:
                arrays[f"{name}/floor/psd/{p}"] = lr.floor.psd[p]
                arrays[f"{name}/floor/ms/{p}"] = lr.floor.ms[p]
    plant, _, eff, speeds = bc.setup(1000)
    fr = cp.floor_responses(plant, eff, speeds)
    arrays["bench_floors/f_hz"] = fr.f_hz
    for p in fr.psd:
        arrays[f"bench_floors/psd/{p}"] = fr.psd[p]
        arrays[f"bench_floors/ms/{p}"] = fr.ms[p]
    np.savez(path, **arrays)
    print(f"{len(arrays)} arrays -> {path}")


def compare(a_path, b_path, rtol):
    a, b = np.load(a_path), np.load(b_path)
    worst, bad = 0.0, []
    if set(a.files) != set(b.files):
        bad.append(f"different arrays: only in A {sorted(set(a.files) - set(b.files))}, only in B "
                   f"{sorted(set(b.files) - set(a.files))}")
    for k in sorted(set(a.files) & set(b.files)):
        x, y = a[k], b[k]
        if x.shape != y.shape:
            bad.append(f"{k}: shapes {x.shape} vs {y.shape}")
            continue
        scale = max(float(np.max(np.abs(x), initial=0.0)), 1e-300)
        d = float(np.max(np.abs(x - y) / np.maximum(np.abs(x), 1e-12 * scale), initial=0.0))
        worst = max(worst, d)
        print(f"  {k:45s} {x.shape!s:18s} max |A-B| / |A| = {d:.2e}")
        if not d <= rtol:
            bad.append(f"{k}: {d:.2e}")
    print(f"largest relative difference {worst:.2e} (tolerance {rtol:g})")
    if bad:
        print("DIFFER:\n  " + "\n  ".join(bad))
        sys.exit(1)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"))
    ap.add_argument("--rtol", type=float, default=1e-9)
    args = ap.parse_args()
    if args.compare:
        compare(*args.compare, args.rtol)
    else:
        dump(args.out)
