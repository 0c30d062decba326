"""Benchmark: the whole empirical fit of the 120-speed, 6-channel E-wheel dataset
against its floor, the Welch PSDs alone, measured in the same run.

Target (issue 2): whole fit (spectra + identification + coefficients + modal
exclusion) within 3x the floor.  Data are generated in memory by the virtual
test stand, so disk and CSV parsing are not timed (they are the same for any
method).  Prints both timings and their ratio; exits 1 when the target is missed.

    python benchmarks/bench_fit.py [--repeat 5]
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from scipy import signal

from rwadist.empirical import fit_empirical
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady


def best_of_interleaved(fns, repeat):
    """Best time of each function, the repeats interleaved so load changes hit all alike."""
    best = [np.inf] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--target", type=float, default=3.0)
    args = ap.parse_args(argv)
    wheel = preset("ithaco-e")
    test = simulate_steady(wheel, np.linspace(300, 2400, 120), sample_rate=3840.0, n_samples=8192,
                           noise=0.01, modes=True, seed=0)
    blocks = [np.stack([r.signals[ch] for r in test.runs]) for ch in test.channels]

    def welch_alone():  # the floor: scipy's Welch on the stacked runs, nothing else
        for b in blocks:
            signal.welch(b, fs=3840.0, window="hann", nperseg=8192, axis=-1)

    fit_empirical(compute_spectra(test))  # warm-up (imports, FFT plans)
    floor, whole = best_of_interleaved([welch_alone, lambda: fit_empirical(compute_spectra(test))], args.repeat)
    ratio = whole / floor
    print(f"dataset: {len(test.runs)} runs x {test.runs[0].n_samples} samples x {len(test.channels)} channels")
    print(f"floor  (scipy.signal.welch alone): {floor * 1e3:8.1f} ms")
    print(f"whole fit (spectra + fit):         {whole * 1e3:8.1f} ms")
    print(f"ratio whole/floor: {ratio:.2f}  (target <= {args.target:g})  {'PASS' if ratio <= args.target else 'FAIL'}")
    return 0 if ratio <= args.target else 1


if __name__ == "__main__":
    sys.exit(main())
