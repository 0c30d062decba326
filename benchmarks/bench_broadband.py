"""Benchmark: 4 wheels × 20 harmonics × 1e5 frequencies × 2000-point speed grid (spacecraft-frame CSD).

Prints wall time and peak traced memory (tracemalloc) of the CSD, and the same for a baseline
measured in this run: one numpy pass over an output-sized array (n_freq × 6 × 6 complex).
Usage: .venv/bin/python benchmarks/bench_broadband.py [n_freq] [n_speeds]
"""
import sys
import time
import tracemalloc

import numpy as np

from rwadist import broadband as bb
from rwadist import mounting as mt
from rwadist.model import Harmonic, WheelModel
from rwadist.units import rpm_to_rad_s


def wheel_model(n_harm=20):
    rng = np.random.default_rng(1)
    hs = np.sort(rng.uniform(0.5, 8.0, n_harm))
    dirs = ("radial_force", "radial_torque", "axial_force", "axial_torque")
    emp = {d: [] for d in dirs}
    for i, h in enumerate(hs):
        emp[dirs[i % 4]].append(Harmonic(h=float(h), C=float(rng.uniform(1e-7, 4e-6))))
    return WheelModel(name="bench", empirical=emp)


def measure(fn):
    tracemalloc.start()
    t0 = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return out, dt, peak


def main(n_freq=100_000, n_speeds=2000):
    lines = bb.empirical_lines(wheel_model())
    w = float(rpm_to_rad_s(1.0))
    laws = [bb.Uniform(-3000 * w, 3000 * w), bb.TruncatedNormal(1500 * w, 400 * w, 0.0, 3000 * w),
            bb.Uniform(300 * w, 2500 * w), bb.Uniform(-2500 * w, 2500 * w)]
    wheels = [mt.WheelSpec(f"RW{i}", lines, m, law)
              for i, (m, law) in enumerate(zip(mt.preset_mountings("pyramid-4"), laws))]
    f_max = 1.2 * 8.0 * 3000 * w / (2 * np.pi)

    def baseline():
        a = np.zeros((n_freq, 6, 6), dtype=complex)
        a += 1.0                                    # one numpy pass over the output array
        return a

    _, tb, pb = measure(baseline)
    res, t, p = measure(lambda: mt.spacecraft_csd(wheels, f_max, n_freq, n_speeds))
    out_mb = res.csd.nbytes / 1e6
    print(f"4 wheels x {len(lines)} harmonics x {n_freq} frequencies x {n_speeds} speeds (f_max {f_max:.1f} Hz)")
    print(f"baseline (one pass over the {out_mb:.1f} MB output array): {tb * 1e3:8.1f} ms, peak {pb / 1e6:7.1f} MB")
    print(f"spacecraft CSD:                                          {t * 1e3:8.1f} ms, peak {p / 1e6:7.1f} MB "
          f"({t / tb:.0f}x time, {p / pb:.1f}x memory of the baseline)")
    print(f"check: RMS Fx..Tz = {np.array2string(res.rms(), precision=4)}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:]))
