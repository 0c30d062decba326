"""Benchmark and acceptance table of ``rwadist diagnose`` (issue 7).

Run: ``.venv/bin/python benchmarks/bench_diagnose.py [--quick]``

1. Acceptance table: each effect class injected alone into E-wheel data (40 speeds, 4096 samples at
   1920 Hz, modes off), three seeds; the class named, the recovered parameter, error before/after
   (``waterfall_unexplained_fraction``).  Clean data, 10 seeds: false additions.  Two effects together.
   Thesis-like B-wheel data (broadband floor below 1x).
2. Timing: the 120-speed, 6-channel E dataset (3840 Hz, 8192 samples) with one injected effect
   (the h = 4.42 radial-force line growing as Ω^2.5): the plain empirical fit and diagnose (starting
   from that fit), same run.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_diagnose import C1, FLOOR_LEVEL, NPERSEG, SPEEDS, TRUTH, W_MID, e_data, inject_floor, inject_line, spectra  # noqa: E402

from rwadist.diagnose import diagnose  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.teststand import simulate_steady  # noqa: E402


def row(label, seed, d, param):
    ks = ",".join(e["kind"] + (f"({e['channel'][0]})" if e["kind"] == "broadband_floor" else "")
                  for e in d.model.effects) or "-"
    cut = d.error_before / max(d.error_after, 1e-300)
    print(f"| {label} | {seed} | {ks} | {param} | {d.error_before:.4f} | {d.error_after:.5f} | {cut:.1f}x | "
          f"{d.iterations} |")


def table(seeds):
    print("| class | seed | found | parameter (truth) | error before | error after | cut | iterations |")
    print("|---|---|---|---|---|---|---|---|")
    for s in seeds:
        t = e_data(s)
        inject_line(t, "radial_force", 0.5, lambda w: 0.5 * C1 * w**2, s)
        d = diagnose(spectra(t), TRUTH)
        e = d.model.effects[0] if d.model.effects else {}
        row("missing_harmonic h=0.5", s, d, f"h={e.get('h')}, C/C_true={e.get('C', np.nan) / (0.5 * C1):.3f}")
    h, p = 4.42, 2.5
    C = dict(preset("ithaco-e").harmonics["radial_force"])[h]
    for s in seeds:
        t = e_data(s, drop=("radial_force", h))
        inject_line(t, "radial_force", h, lambda w: C * W_MID**2 * (w / W_MID) ** p, s)
        d = diagnose(spectra(t), TRUTH)
        e = d.model.effects[0] if d.model.effects else {}
        row("amplitude_law h=4.42 p=2.5", s, d, f"p={e.get('exponent', np.nan):.3f}")
    wmax = np.abs(SPEEDS).max() * 2 * np.pi / 60
    for s in seeds:
        t = e_data(s)
        inject_floor(t, ("Fx", "Fy", "Fz"), {c: FLOOR_LEVEL * C1 * wmax**2 for c in ("Fx", "Fy", "Fz")},
                     p=3.0, fc=60.0, fs=1920.0, seed=s)
        d = diagnose(spectra(t), TRUTH)
        row("broadband_floor Fx,Fy,Fz p=3", s, d, "p=" + ",".join(f"{e['exponent']:g}" for e in d.model.effects))
    n_false = 0
    for s in range(10):
        d = diagnose(spectra(e_data(100 + s)), TRUTH)
        n_false += len(d.model.effects)
        row("clean", 100 + s, d, "-")
    print(f"\nclean data, 10 seeds: {n_false} false additions")
    t = e_data(4, drop=("radial_force", h))
    inject_line(t, "radial_force", h, lambda w: C * W_MID**2 * (w / W_MID) ** p, 4)
    inject_line(t, "radial_force", 0.5, lambda w: 0.5 * C1 * w**2, 5)
    row("two: h=0.5 + p=2.5", 4, diagnose(spectra(t), TRUTH), "see found")
    w = preset("ithaco-b")
    t = simulate_steady(w, np.linspace(500, 3400, 30), sample_rate=1000.0, n_samples=4096, modes=False,
                        test_stand=False, noise=0.01, seed=3)
    wb = 3400 * 2 * np.pi / 60
    ref = {c: 0.1 * w.harmonics["radial_force" if c[0] == "F" else "radial_torque"][0][1] * wb**2
           for c in ("Fx", "Fy", "Fz", "Tx", "Ty")}
    inject_floor(t, tuple(ref), ref, p=3.0, fc=15.0, fs=1000.0, seed=3)
    row("B wheel, floor below 1x (from fit)", 3, diagnose(compute_spectra(t, nperseg=NPERSEG, f_lim=200.0)), "-")


def timing():
    from dataclasses import replace

    w = preset("ithaco-e")
    h, p = 4.42, 2.5
    C = dict(w.harmonics["radial_force"])[h]
    w = replace(w, harmonics={d: [(hh, c) for hh, c in v if not (d == "radial_force" and hh == h)]
                              for d, v in w.harmonics.items()}, senses={})
    t = simulate_steady(w, w.default_speeds_rpm, sample_rate=w.default_sample_rate, n_samples=w.default_n_samples,
                        modes=False, noise=0.01, seed=11)
    wm = float(np.median(w.default_speeds_rpm)) * np.pi / 30
    inject_line(t, "radial_force", h, lambda x: C * wm**2 * (x / wm) ** p, 11)    # amplitude law Ω^2.5
    sp = compute_spectra(t, nperseg=2048)
    t0 = time.perf_counter()
    fit = fit_empirical(sp)
    t_fit = time.perf_counter() - t0
    t0 = time.perf_counter()
    d = diagnose(sp, fit.model)
    t_diag = time.perf_counter() - t0
    print(f"\n120 speeds x 6 channels, 8192 samples, nperseg 2048: plain fit {t_fit:.2f} s, diagnose "
          f"{t_diag:.2f} s (x{t_diag / t_fit:.1f}); {d.iterations} iterations, added "
          f"{[(e['kind'], e.get('h'), e.get('exponent')) for e in d.model.effects]}, error {d.error_before:.4f} -> {d.error_after:.5f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="timing only")
    a = ap.parse_args()
    if not a.quick:
        table([0, 1, 2])
    timing()
