"""Benchmark of the extended wheel model, with baselines measured in the same run.

    .venv/bin/python benchmarks/bench_extended.py

1. Steady-state waterfall: 1000 speeds × 20 lines × 6 channels (closed form,
   rwadist.extended.steady_lines); baseline: the empirical model C·Ω² on the same grid.
2. Time domain: 390 s at 3840 Hz (1.5 M samples), a speed profile through zero
   (rwadist.extended_time.simulate_time, 20 lines); baseline: one numpy pass np.sin over
   1.5 M × 6 samples.
"""
import time

import numpy as np

from rwadist import extended as ex
from rwadist.extended_time import simulate_time
from rwadist.units import RPM_TO_RAD_S


def timed(fn, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main():
    p = ex.from_table_4_2()
    rng = np.random.default_rng(0)
    dirs = ("radial_force", "radial_torque", "axial_force", "axial_torque")
    senses = ("co", "counter", "planar")
    lines = ex.imbalance_lines(p) + [
        ex.Line(dirs[i % 4], float(h), float(c), senses[i % 3], float(ph))
        for i, (h, c, ph) in enumerate(zip(rng.uniform(0.5, 6, 18), rng.uniform(1e-8, 1e-6, 18),
                                           rng.uniform(0, 2 * np.pi, 18)))]
    assert len(lines) == 20
    speeds = np.linspace(1, 3000, 1000) * RPM_TO_RAD_S

    t_ss, (f, A) = timed(lambda: ex.steady_lines(p, lines, speeds))
    h = np.array([ln.h for ln in lines])
    C = np.array([ln.C for ln in lines])
    t_emp, _ = timed(lambda: (h[None, :] * speeds[:, None] / (2 * np.pi),
                              np.broadcast_to((C[None, :] * speeds[:, None] ** 2)[..., None], (1000, 20, 6)).copy()))
    print(f"steady-state waterfall 1000 speeds × 20 lines × 6 channels: {t_ss * 1e3:8.2f} ms "
          f"(empirical C·Ω² on the same grid: {t_emp * 1e3:.2f} ms; ratio {t_ss / t_emp:.0f}×)  "
          f"amplitude array {A.shape}")

    fs, dur = 3840.0, 390.0
    t = np.arange(int(dur * fs)) / fs
    omega = 3000 * RPM_TO_RAD_S * np.sin(2 * np.pi * t / dur)     # up, through zero, down, back
    t_td, x = timed(lambda: simulate_time(p, lines, t, omega, seed=1), repeat=1)
    t_np, _ = timed(lambda: np.sin(np.outer(t, np.arange(1, 7))), repeat=3)
    print(f"time domain 390 s at 3840 Hz ({t.size} samples, 20 lines, 6 channels): {t_td:6.2f} s "
          f"(np.sin over {t.size} × 6: {t_np:.3f} s; ratio {t_td / t_np:.0f}×)  peak |F| {np.abs(x[:, :3]).max():.3g} N")


if __name__ == "__main__":
    main()
