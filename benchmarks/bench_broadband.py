"""Benchmark (issue 37): the spacecraft CSD of 4 wheels × 20 harmonics × 1e5 frequencies, against its peers.

Printed in one run, with the load average:

* baseline: one numpy pass over an output-sized array (n_freq × 6 × 6 complex: allocated and written once);
* the project's CSD (:func:`rwadist.mounting.spacecraft_csd`);
* the peer: Melody's closed form written plainly here -- one scalar density per wheel, line class and spin sign,
  each line's bin integral from its antiderivative over the whole grid (uniform law: C²Ω⁴ is a polynomial; normal
  law: the normal's partial moments), then one (n_f × K)·(K × 36) product; checked equal to the project's within
  1e-9 of the largest channel's mean square (Σ_k |ΔS_k|·df);
* the project at 500 and 8000 speed cells (``n_speeds``; the closed form needs none: flat).

Timings are interleaved (baseline, project, peer; then 500/8000 cells), ``--repeats`` times (default 5), min and
median printed.  Peak memory comes from separate runs in child processes (tracemalloc's peak of the call, and the
maximum RSS over the child's RSS before the call), never during a timing run.

BLAS and OpenMP are held to one thread, as every rwadist command runs.

Usage: python benchmarks/bench_broadband.py [--n-freq N] [--repeats R]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np

from rwadist import broadband as bb
from rwadist import mounting as mt
from rwadist.model import Harmonic, WheelModel
from rwadist.units import rpm_to_rad_s

W = float(rpm_to_rad_s(1.0))
F_MAX = 1.2 * 8.0 * 3000 * W / (2 * np.pi)
_BASE = {"radial_force": 0, "radial_torque": 3, "axial_force": 2, "axial_torque": 5}


def wheel_model(n_harm=20):
    rng = np.random.default_rng(1)
    hs = np.sort(rng.uniform(0.5, 8.0, n_harm))
    dirs = ("radial_force", "radial_torque", "axial_force", "axial_torque")
    emp = {d: [] for d in dirs}
    for i, h in enumerate(hs):
        emp[dirs[i % 4]].append(Harmonic(h=float(h), C=float(rng.uniform(1e-7, 4e-6))))
    return WheelModel(name="bench", empirical=emp)


def wheels():
    model = wheel_model()
    lines = bb.empirical_lines(model)
    laws = [bb.Uniform(-3000 * W, 3000 * W), bb.TruncatedNormal(1500 * W, 400 * W, 0.0, 3000 * W),
            bb.Uniform(300 * W, 2500 * W), bb.Uniform(-2500 * W, 2500 * W)]
    return model, [mt.WheelSpec(f"RW{i}", lines, m, law)
                   for i, (m, law) in enumerate(zip(mt.preset_mountings("pyramid-4"), laws))]


# ------------------------------------------------------------------ the peer: the closed form, plainly

def _moment4_antiderivative(z, mu, sigma):
    """∫ (μ + σz)^4 φ(z) dz as a function of z (up to a constant), from M_k = ∫ z^k φ: M_0 = Φ, M_1 = −φ,
    M_k = −z^{k−1}φ + (k−1)·M_{k−2}."""
    from scipy.special import ndtr

    phi = np.exp(-0.5 * z * z) / np.sqrt(2 * np.pi)
    Phi = ndtr(z)
    M = [Phi, -phi, -z * phi + Phi, -(z * z + 2) * phi, -(z**3 + 3 * z) * phi + 3 * Phi]
    coef = [mu**4, 4 * mu**3 * sigma, 6 * mu**2 * sigma**2, 4 * mu * sigma**3, sigma**4]
    return sum(c * m for c, m in zip(coef, M))


def _line_bin_powers(h, C, law, sign, f_edges):
    """Σ over the bins of (1/df)∫ S(f) df for one line on one spin sign: S(f) = ½C²Ω⁴p(Ω)·2π/h, Ω = sign·2πf/h,
    from the antiderivative at every bin edge of the grid (0 outside the law's support)."""
    lo, hi = law.support
    a, b = (max(lo, 0.0), hi) if sign > 0 else (max(-hi, 0.0), -lo)
    if not b > a:
        return None
    u = np.clip(2 * np.pi * np.maximum(f_edges, 0.0) / h, a, b)            # |Ω| at the edges, clipped to the support
    if isinstance(law, bb.Uniform):
        F = u**5 / 5 / (law.hi - law.lo)
    else:
        from scipy.special import ndtr

        mass = ndtr((law.hi - law.mean) / law.std) - ndtr((law.lo - law.mean) / law.std)
        F = sign * _moment4_antiderivative((sign * u - law.mean) / law.std, law.mean, law.std) / mass
    return 0.5 * C**2 * np.diff(F)


def _pattern(direction, mode, sign):
    v = np.zeros(6, complex)
    base = _BASE[direction]
    v[base] = 1.0
    if mode in ("co", "counter"):
        v[base + 1] = (-1j if mode == "co" else 1j) * sign
    return v


def peer_csd(model, wheel_specs, f_max, n_freq):
    """The plain closed form: columns per (wheel, class, sign), then one product."""
    f = np.linspace(0.0, f_max, n_freq)
    df = f[1] - f[0]
    edges = np.append(f - df / 2, f[-1] + df / 2)
    cols, mats = [], []
    for ws in wheel_specs:
        T = ws.mounting.transform
        for d in _BASE:
            mode = "axial" if d.startswith("axial") else "co"
            for sign in (1.0, -1.0):
                acc = None
                for hm in model.harmonics(d):
                    p = _line_bin_powers(hm.h, hm.C, ws.law, sign, edges)
                    if p is not None:
                        acc = p if acc is None else acc + p
                if acc is not None:
                    v = T @ _pattern(d, mode, sign)
                    cols.append(acc / df)
                    mats.append(np.outer(v, np.conj(v)).ravel())
    D = np.array(cols).T                                             # (n_f, K)
    return f, (D @ np.array(mats)).reshape(n_freq, 6, 6)             # (n_f × K)·(K × 36)


# ------------------------------------------------------------------ timing and memory

def baseline(n_freq):
    a = np.zeros((n_freq, 6, 6), dtype=complex)
    a += 1.0                                          # one numpy pass over the output array
    return a


def _timed(fn):
    """(wall s, CPU s of this process, result)."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return (time.perf_counter() - t0, time.process_time() - c0), out


def _status_kb(field):
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith(field + ":"))


def memory_child(which, n_freq):
    """In a fresh process, two calls: tracemalloc's peak of the first, the peak RSS (VmHWM, reset before the call)
    over the RSS before the second (Linux), bytes."""
    import tracemalloc

    model, ws = wheels()
    fn = {"project": lambda: mt.spacecraft_csd(ws, F_MAX, n_freq, 2000),
          "peer": lambda: peer_csd(model, ws, F_MAX, n_freq),
          "baseline": lambda: baseline(n_freq)}[which]
    tracemalloc.start()
    out = fn()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    del out
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")                                   # reset VmHWM to the current RSS
        rss0 = _status_kb("VmRSS")
        again = fn()
        rss = (_status_kb("VmHWM") - rss0) * 1024
        del again
    except OSError:
        rss = -1
    print(peak, rss)


def _memory(which, n_freq):
    r = subprocess.run([sys.executable, __file__, "--memory-child", which, "--n-freq", str(n_freq)],
                       capture_output=True, text=True, check=True)
    peak, rss = (int(x) for x in r.stdout.split())
    return peak, rss


def stats(xs):
    return min(xs), float(np.median(xs))


def main(n_freq=100_000, repeats=5):
    model, ws = wheels()
    out_mb = n_freq * 36 * 16 / 1e6
    print(f"4 wheels x {len(ws[0].lines)} harmonics x {n_freq} frequencies (f_max {F_MAX:.1f} Hz), output {out_mb:.1f} MB;"
          f" load average {os.getloadavg()[0]:.2f} at start")
    names = ("baseline", "project", "peer", "cells500", "cells8000")
    t: dict = {k: [] for k in names}
    res = peer = None
    for _ in range(repeats):
        dt, _b = _timed(lambda: baseline(n_freq))
        t["baseline"].append(dt)
        del _b
        dt, res = _timed(lambda: mt.spacecraft_csd(ws, F_MAX, n_freq, 2000))
        t["project"].append(dt)
        dt, peer = _timed(lambda: peer_csd(model, ws, F_MAX, n_freq))
        t["peer"].append(dt)
        for cells in (500, 8000):
            dt, _r = _timed(lambda: mt.spacecraft_csd(ws, F_MAX, n_freq, cells))
            t[f"cells{cells}"].append(dt)
            del _r
    load = os.getloadavg()[0]
    for k in names:
        (wl, wm), (cl, cm) = stats([x[0] for x in t[k]]), stats([x[1] for x in t[k]])
        print(f"  {k:10s} wall min {wl * 1e3:8.1f} ms  median {wm * 1e3:8.1f} ms   CPU min {cl * 1e3:8.1f} ms  "
              f"median {cm * 1e3:8.1f} ms")
    for label, num, den, target in (("project / one pass over the output", "project", "baseline", "<= 20x"),
                                    ("project / plain closed form (peer)", "project", "peer", "<= 0.5x"),
                                    ("8000 / 500 speed cells", "cells8000", "cells500", "0.8-1.2x")):
        r = [stats([x[j] for x in t[num]])[q] / stats([x[j] for x in t[den]])[q] for j in (0, 1) for q in (0, 1)]
        print(f"{label:36s} wall {r[0]:5.2f}x (min) {r[1]:5.2f}x (median)   CPU {r[2]:5.2f}x (min) {r[3]:5.2f}x "
              f"(median)   target {target}")
    print(f"load average at end {load:.2f}")
    df = res.f[1] - res.f[0]
    ms = res.mean_square()
    diff = np.abs(res.csd - peer[1]).sum(axis=0) * df / ms.max()
    print(f"check: project vs peer, max over channel pairs of sum|dS|*df / max mean square = {diff.max():.2e} "
          f"({'OK' if diff.max() <= 1e-9 else 'FAIL'}: <= 1e-9); RMS Fx..Tz = {np.array2string(res.rms(), precision=4)}")
    for which in ("baseline", "project", "peer"):
        peak, rss = _memory(which, n_freq)
        print(f"memory ({which:8s}, separate run): tracemalloc peak {peak / 1e6:7.1f} MB = {peak / 1e6 / out_mb:4.2f}x "
              f"the output; peak RSS growth {rss / 1e6:7.1f} MB = {rss / 1e6 / out_mb:4.2f}x")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-freq", type=int, default=100_000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--memory-child", choices=("project", "peer", "baseline"))
    a = ap.parse_args()
    if a.memory_child:
        memory_child(a.memory_child, a.n_freq)
    else:
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1):          # as every rwadist command runs (rwadist.cli.one_blas_thread)
            main(a.n_freq, a.repeats)
