"""Benchmark: the virtual test stand writing the default E-wheel steady test (120 speeds x 8192 samples x
6 channels at 3840 Hz, modes off and on), against numpy generating the same number of random samples in
the same run (the floor: any generator must at least write its output).

Target: 10 s for the whole test (the timed unit test this replaces measured ~0.7 s on a quiet machine).

    python benchmarks/bench_teststand.py [--repeat 3]
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from rwadist.presets import preset
from rwadist.teststand import simulate_steady


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--target", type=float, default=10.0)
    args = ap.parse_args(argv)
    wheel = preset("ithaco-e")
    speeds = wheel.default_speeds_rpm
    n = len(speeds) * 8192 * 6
    rng = np.random.default_rng(0)
    best = {"floor": np.inf, "modes off": np.inf, "modes on": np.inf}
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        rng.standard_normal(n)
        best["floor"] = min(best["floor"], time.perf_counter() - t0)
        for label, modes in (("modes off", False), ("modes on", True)):
            t0 = time.perf_counter()
            test = simulate_steady(wheel, speeds, sample_rate=3840.0, n_samples=8192, modes=modes, noise=0.01, seed=0)
            best[label] = min(best[label], time.perf_counter() - t0)
    print(f"dataset: {len(test.runs)} runs x {test.runs[0].n_samples} samples x {len(test.channels)} channels")
    print(f"floor (numpy, {n:,} normal samples): {best['floor']:.3f} s")
    ok = True
    for label in ("modes off", "modes on"):
        t = best[label]
        ok &= t < args.target
        print(f"simulate_steady, {label}: {t:.3f} s  ({t / best['floor']:.1f}x the floor; target < {args.target:g} s; "
              f"baseline ~0.7 s)  {'PASS' if t < args.target else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
