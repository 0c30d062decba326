"""Disk size of the demo's test data: the CSV interchange (what `rwadist demo` wrote before) against the HDF5
file it writes now (float32 samples, gzip), and lossless HDF5 (float64, gzip) for reference.

Run: python benchmarks/bench_demo_storage.py   (writes ~140 MB to a temporary directory, then deletes it)
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from rwadist.data import write_steady
from rwadist.hdf5 import read_hdf5, write_hdf5
from rwadist.presets import preset
from rwadist.teststand import simulate_steady


def size(path: Path) -> int:
    return path.stat().st_size if path.is_file() else sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def main():
    speeds = np.linspace(300.0, 2400.0, 120)  # as `rwadist demo`
    test = simulate_steady(preset("ithaco-e"), speeds, sample_rate=3840.0, n_samples=8192, noise=0.01, modes=True,
                           seed=0)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        t = time.perf_counter()
        csv_bytes = size(write_steady(test, tmp / "csv"))
        t_csv = time.perf_counter() - t
        t = time.perf_counter()
        demo = write_hdf5(test, tmp / "demo.h5", compression="gzip", precision="float32")
        t_h5 = time.perf_counter() - t
        lossless = write_hdf5(test, tmp / "lossless.h5", compression="gzip")
        back = read_hdf5(demo)
        worst = max(float(np.max(np.abs(b.signals[c] - a.signals[c]) / np.max(np.abs(a.signals[c]))))
                    for a, b in zip(test.runs, back.runs) for c in a.channels)
        print(f"CSV interchange (baseline, before): {csv_bytes / 1e6:8.1f} MB  written in {t_csv:5.1f} s")
        print(f"HDF5 float32 + gzip (demo now):     {size(demo) / 1e6:8.1f} MB  written in {t_h5:5.1f} s  "
              f"shrink {csv_bytes / size(demo):.1f}x  (largest sample change {worst:.1e} of the channel's peak)")
        print(f"HDF5 float64 + gzip (lossless):     {size(lossless) / 1e6:8.1f} MB  "
              f"shrink {csv_bytes / size(lossless):.1f}x")


if __name__ == "__main__":
    main()
