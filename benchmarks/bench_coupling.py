"""Benchmark (issues 6, 7, 37): 200-mode plant, 4 wheels, 1000 speeds.

Times, interleaved in one run (``--repeats`` rounds, default 3; min and median of wall-clock and CPU time, with the
load average):
  * the peer: python-control's own frequency response of the same plant (StateSpace, 400 states) over the
    frequency points the plain sweep visits (each wheel's distinct line frequencies at each speed);
  * the plain coupled sweep (:func:`rwadist.coupling.jitter_vs_speed`, all four practices), serial;
  * the same wheels with diagnosed effects (a broadband floor on Fx, Fy, Fz and a speed ripple of 3 rad/s at 8 Hz,
    read from a model file's effects list as rwadist diagnose writes it): target <= 3x the plain sweep;
  * its two parts apart: the ripple alone (the same sweep without the floors) and the floors alone
    (:func:`rwadist.coupling.floor_responses` on its default grid), with the work each does against the plain
    sweep's: line points (speed x line group; a ripple's sideband orders m = -K..K multiply the groups by 2K + 1,
    each at its own frequency, i.e. one coupled interface solve per point) and floor points (speed x grid frequency).
  * the plant's modal sums G, P alone at the ripple's points (:func:`modal_sums`): the part of the ripple's work no
    exact evaluation through the interface equation avoids (every point is at its own frequency).
``--no-peer``: leave python-control out (60-70 s CPU a round; the effects' baseline is the plain sweep).
``--dask``: the plain sweep on a 2-worker local dask cluster (processes, 1 thread each) as well.
``--orders``: the ripple's points an oracle pruning would keep at 1e-9 of every RMS (:func:`needed_points`, untimed): the
least work any exact per-point evaluation of the ripple's sidebands needs; the points at distinct frequencies (the solves
an exact evaluation needs when coincident lines and sidebands share one, :func:`distinct_points`); and what a pruning by
the blocked loads (known before the solve) would move the RMS by (:func:`load_trimmed`).  The CPU per line point, plain and with the ripple, is
printed beside: the ripple's cost is its points' count at the plain sweep's cost per point.
BLAS is pinned to one thread so serial and parallel compare like for like.

Run: python benchmarks/bench_coupling.py [--speeds N] [--repeats R] [--no-peer] [--dask] [--orders]

Measured (1000 speeds, CPU min / median of 3 rounds; session 9, main and the branch alternated, load 3.4-4.3):
  167d71a --no-peer: plain 0.77 / 0.78 s, effects 11.25 / 11.61 s (14.55x / 14.96x); again 0.73 / 0.75 s, 10.29 / 10.61 s
    (14.10x / 14.23x); ripple alone 9.20 / 8.48 s min, floors alone 1.69 / 1.58 s min.
  3fc8baa (outputs-only adjoint solve, G's upper triangle, interface matrix in place) --no-peer: plain 0.64 / 0.69 s,
    effects 8.94 / 9.19 s (14.07x / 13.40x); again 0.67 / 0.70 s, 9.31 / 9.65 s (13.80x / 13.80x); ripple alone 7.15 /
    7.13 s min, floors alone 1.56 / 1.62 s min.  With the peer (load 3.2-4.8): python-control 63.7 / 71.0 s, plain
    0.69 / 0.77 s, effects 9.76 / 10.26 s (14.17x / 13.28x).
  1fe9ae9 against the grouped lines at every speed at once (this commit), alternated, load 3.8-4.1: plain 0.67 / 0.78 ->
    0.64 / 0.73 s, ripple alone 8.34 / 8.36 -> 7.21 / 7.43 s, effects 10.43 / 10.89 -> 9.38 / 10.09 s (15.68x / 14.03x
    -> 14.56x / 13.73x).
  --orders: an oracle pruning at 1e-9 keeps 5.09x the plain points; of the ripple's 143000 points 142993 sit at
    distinct frequencies (a ripple at 8 Hz meets the speed grid's lines only by chance), so no exact evaluation shares
    its solves: the 3x target needs a tolerance or a cheaper point for plain and ripple alike.
  Session 15 (--no-peer, main 8853a00 and couple15 alternated, load 4.6-8.4; CPU min / median of 3 rounds): effects /
    plain 15.5x / 15.3x and 13.8x / 14.6x on main, 15.3x / 14.1x and 13.2x / 14.1x on the branch (its floor grid and
    ripple order ~0.1 s cheaper, within the noise); the plant's modal sums alone at the ripple's 143 000 points
    (G, P, nothing else) 3.38x / 3.16x and 3.28x / 3.36x the whole plain sweep: above the target before any solve.
  Session 26 (--no-peer, main 86ff871 = base26 and couple26 alternated in one window; CPU min / median of 3 rounds):
    a6f3d05, load 4.5-7.0: main plain 0.52 / 0.53 s, effects 7.34 / 7.58 s (14.16x / 14.36x); branch 0.51 / 0.52 s,
    6.99 / 7.45 s (13.84x / 14.38x); again main 0.52 / 0.53 s, 7.16 / 7.31 s (13.73x / 13.84x), branch 0.48 / 0.48 s,
    6.73 / 7.01 s (14.15x / 14.50x).  5d3f9a8, load 2.5-5.1: main plain 0.51 / 0.52 s, effects 7.32 / 7.55 s
    (14.45x / 14.62x), ripple alone 5.57 s, floors alone 1.30 s, G, P only 3.13x; branch 0.47 / 0.48 s, 6.80 / 6.97 s
    (14.32x / 14.52x), 5.24 s, 1.32 s, 3.06x; again main 0.52 / 0.55 s, 7.18 / 7.98 s (13.94x / 14.53x), branch
    0.49 / 0.50 s, 7.04 / 7.27 s (14.39x / 14.67x), 5.62 s, 1.33 s, 2.91x.  The branch's per-point work (G's mirror by
    one gather, complex reciprocals in real arithmetic, the interface matrix without zeroing) takes 3-8 % off plain
    and effects alike: the ratio does not move.  Same numbers: 2.6e-12 at most (coupling_same_numbers.py --compare).
    The floor, measured: the modal sums alone at the ripple's points 2.9-3.1x the plain sweep; the floors 2.4-2.8x
    (about half of it the default grid's poles: 16 eigen-decompositions of the 448-state coupled system, ~40 ms
    each, so a per-speed pole-residue form of the coupled system, 1000 of them, would cost ~80x the plain sweep); an
    oracle pruning of the ripple's points keeps 5.09x the plain points at 1e-9 of every RMS, 3.01x at 1e-6, 1.38x at
    1e-4; a pruning by the blocked loads (load_trimmed) keeps 10.2x and moves an RMS by 6.1e-5 at 1e-8 of its speed's
    largest load (the coupled response lifts sidebands near its modes by ~1e3): no exact evaluation, and no a-priori
    tolerance a jitter engineer would accept (1e-6), reaches 3x.
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from rwadist import coupling as cp  # noqa: E402
from rwadist import extended as ext  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.units import RPM_TO_RAD_S  # noqa: E402

EFFECTS = [{"kind": "broadband_floor", "channel": ["Fx", "Fy", "Fz"], "exponent": 3.0, "omega_ref_rad_s": 300.0,
            "f_Hz": [5.0, 100.0, 300.0, 500.0], "psd_ref": [1e-6, 2e-6, 1e-6, 2e-7]},
           {"kind": "speed_ripple", "f_ripple_Hz": 8.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 300.0}]


def setup(n_speeds=1000, n_modes=200):
    """(plant, plain wheels, wheels with effects, speeds rad/s)."""
    plant = cp.random_modal_plant(n_modes=n_modes, n_nodes=4, n_perf=2, seed=1)
    desc = preset("ithaco-e")
    lines = tuple(ext.lines_from_model(desc.to_model(), desc.extended))
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
    wheels = [cp.WheelSpec(desc.extended, lines, cp.Mount(i, cp.spin_axis_dcm(axes[i]), (0.1, 0.0, 0.1)),
                           housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03), name=f"E{i}") for i in range(4)]
    model = desc.to_model()
    model.effects = EFFECTS
    spec = cp.wheel_spec_from_model(model)
    eff = [cp.WheelSpec(spec.params, spec.lines, w.mount, housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03),
                        floors=spec.floors, ripple=spec.ripple, name=w.name) for w in wheels]
    return plant, wheels, eff, np.linspace(1.0, 3000.0, n_speeds) * RPM_TO_RAD_S


def without_floors(wheels):
    """The wheels with their speed ripple and no broadband floors."""
    return [dataclasses.replace(w, floors=()) for w in wheels]


def line_points(wheels, speeds):
    """Speed x line-group points the line sweep evaluates for ``wheels`` (one wheel: they are equal but for the
    mount and share them)."""
    from rwadist import extended_ripple
    w = wheels[0]
    groups = len({(ln.h, ln.f_offset) for ln in w.lines})
    k = 0 if w.ripple is None else extended_ripple.ripple_order(w.lines, speeds * w.speed_scale, w.ripple)
    return speeds.size * groups * (2 * k + 1), k


def load_trimmed(lr, tols=(1e-14, 1e-12, 1e-10, 1e-8, 1e-6)):
    """What an a-priori pruning of the ripple's points costs in accuracy (issue 37): a point (speed, line group) left
    out when its blocked load (the only size known before the coupled solve) is below ``tol`` x the largest blocked
    load of its speed.  Leaving a point out is exactly its phasors set to 0, so from the full responses ``lr``
    (:class:`rwadist.coupling.LineResponses` of wheels that share their lines): [(tol, points kept as a share of all,
    largest relative change of any practice's, output's and speed's lines' RMS)]."""
    mag = np.sqrt(np.sum(np.abs(lr.hard_mounted[0]) ** 2, axis=-1))          # (S, J): the wheels share the lines
    rel = mag / np.maximum(mag.max(axis=1, keepdims=True), 1e-300)
    rows = []
    for tol in tols:
        keep = (rel >= tol)[..., None]
        worst = 0.0
        for ys in lr.y.values():
            ms = sum(np.sum(np.abs(y) ** 2, axis=1) for y in ys)
            ms_kept = sum(np.sum(np.abs(np.where(keep, y, 0)) ** 2, axis=1) for y in ys)
            live = ms > 0
            worst = max(worst, float(np.max(np.abs(np.sqrt(ms_kept[live] / ms[live]) - 1), initial=0.0)))
        rows.append((tol, float(keep.mean()), worst))
    return rows


def needed_points(plant, wheels, speeds, tol=1e-9):
    """Points an oracle pruning would keep (issue 37): per practice, speed and output, the (speed, line group) points
    of the smallest power that can be left out together while the lines' RMS moves by <= ``tol`` relative (their
    mean square by <= 2·tol), the rest kept; a point is kept when any practice or output keeps it.  Computed from
    the responses themselves (a posteriori: no pruning rule can know them beforehand, so no exact per-point
    evaluation can need fewer points).  Returns (points kept, {ripple order m: share of its points kept})."""
    lr = cp.line_responses(plant, wheels, speeds)
    keep = np.zeros(lr.f_hz[0].shape, dtype=bool)                          # (S, J): the wheels share the points
    for p, ys in lr.y.items():
        power = sum(np.abs(y) ** 2 / 2 for y in ys)                          # (S, J, n_perf), every wheel's part
        ms = power.sum(axis=1, keepdims=True)
        order = np.argsort(power, axis=1)
        dropped = np.cumsum(np.take_along_axis(power, order, axis=1), axis=1) <= 2 * tol * ms
        kept = np.ones_like(dropped)
        np.put_along_axis(kept, order, ~dropped, axis=1)
        keep |= kept.any(axis=2)
    m = lr.ripple_order[0]
    return int(keep.sum()), {int(k): float(keep[:, m == k].mean()) for k in np.unique(m)}, lr


def distinct_points(lr, rtol=1e-12):
    """(speed, frequency) points of :class:`rwadist.coupling.LineResponses` ``lr`` that differ by more than ``rtol``
    relative, over every wheel's line groups: the coupled solves an exact evaluation needs when lines and sidebands
    that meet at one frequency and speed share their solve (issue 37's idea (1); the blocked loads of incoherent
    sources at one frequency add in power, H·S·Hᴴ with S summed)."""
    f = np.sort(np.concatenate(lr.f_hz, axis=1), axis=1)                   # (S, all wheels' groups)
    return int(f.shape[0] + np.count_nonzero(np.diff(f, axis=1) > rtol * f[:, 1:]))


def modal_sums(plant, wheels, speeds):
    """A function that evaluates only the plant's modal sums G, P (:meth:`rwadist.coupling.Plant.frf`) at the points
    the line sweep of ``wheels`` visits (their grouped lines' frequencies, speed blocks as the sweep's chunks): the
    least per-point work of any evaluation through the interface equation (one G, P per distinct frequency)."""
    from rwadist.coupling.line_groups import grouped_lines_blocked
    from rwadist.coupling.performance import LINE_POINTS
    w = wheels[0]
    k = line_points(wheels, speeds)[1]
    f = grouped_lines_blocked(w, speeds * w.speed_scale, k)[3]                 # (S, J) Hz, the wheels share them
    step = max(1, LINE_POINTS // f.shape[1])

    def run():
        for i0 in range(0, f.shape[0], step):
            plant.frf(f[i0:i0 + step])
    return run


def _timed(fn):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return (time.perf_counter() - t0, time.process_time() - c0), out


def main(n_speeds=1000, repeats=3, dask=False, orders=False, peer=True):
    plant, wheels, eff, speeds = setup(n_speeds)
    lines = wheels[0].lines
    hu = np.unique([ln.h for ln in lines])
    f_pts = np.sort((hu[None, :] * speeds[:, None] / (2 * np.pi)).ravel())   # python-control sorts
    print(f"plant: {plant.sys.nstates} states, {plant.n_interface} interface DOFs, {plant.n_perf} outputs; 4 wheels x "
          f"{len(lines)} lines ({hu.size} distinct h); {n_speeds} speeds -> {f_pts.size} frequency points per wheel; "
          f"load average {os.getloadavg()[0]:.2f} at start")
    ripple_only = without_floors(eff)
    t: dict = {"python-control": [], "plain": [], "effects": [], "ripple alone": [], "floors alone": [],
               "ripple G, P only": []}
    sums = modal_sums(plant, ripple_only, speeds)
    if not peer:
        del t["python-control"]
    plain = with_eff = floors = None
    for _ in range(repeats):
        if peer:
            dt, H = _timed(lambda: plant.sys.frequency_response(2 * np.pi * f_pts))
            t["python-control"].append(dt)
        dt, plain = _timed(lambda: cp.jitter_vs_speed(plant, wheels, speeds))
        t["plain"].append(dt)
        dt, with_eff = _timed(lambda: cp.jitter_vs_speed(plant, eff, speeds))
        t["effects"].append(dt)
        dt, _ = _timed(lambda: cp.jitter_vs_speed(plant, ripple_only, speeds))
        t["ripple alone"].append(dt)
        dt, floors = _timed(lambda: cp.floor_responses(plant, eff, speeds))
        t["floors alone"].append(dt)
        dt, _ = _timed(sums)
        t["ripple G, P only"].append(dt)
    load = os.getloadavg()[0]
    st = {}
    for k, v in t.items():
        w, c = np.array(v).T
        st[k] = (w.min(), float(np.median(w)), c.min(), float(np.median(c)))
        print(f"  {k:16s} wall min {w.min():7.2f} s  median {np.median(w):7.2f} s   CPU min {c.min():7.2f} s  "
              f"median {np.median(c):7.2f} s")
    pts_plain, _ = line_points(wheels, speeds)
    pts_eff, k_rip = line_points(eff, speeds)
    work = {"effects": "   target <= 3x",
            "ripple alone": f"   line points {pts_eff / pts_plain:.1f}x ({pts_eff} vs {pts_plain}: orders +-{k_rip})",
            "floors alone": f"   floor points {speeds.size * floors.f_hz.size} ({floors.f_hz.size} frequencies)",
            "ripple G, P only": "   the plant's modal sums alone at the ripple's points: an exact per-point "
                                "evaluation's least work"}
    print(f"CPU per line point (min): plain {st['plain'][2] / pts_plain * 1e6:.1f} us ({pts_plain} points), ripple "
          f"alone {st['ripple alone'][2] / pts_eff * 1e6:.1f} us ({pts_eff} points)")
    for label, a, b in (("plain sweep / python-control FRF", "plain", "python-control"),
                        ("with effects / plain sweep", "effects", "plain"),
                        ("  ripple alone / plain sweep", "ripple alone", "plain"),
                        ("  floors alone / plain sweep", "floors alone", "plain"),
                        ("  ripple G, P only / plain sweep", "ripple G, P only", "plain")):
        if b not in st:
            continue
        r = [st[a][i] / st[b][i] for i in range(4)]
        print(f"{label:34s} wall {r[0]:6.2f}x (min) {r[1]:6.2f}x (median)   CPU {r[2]:6.2f}x (min) {r[3]:6.2f}x "
              f"(median){work.get(a, '')}")
    print(f"load average at end {load:.2f}")
    if peer:
        G, P = plant.frf(f_pts)
        Hc = np.asarray(H.fresp)                       # (n_out, n_in, F)
        err = np.max(np.abs(np.moveaxis(Hc[plant.n_interface:], -1, 0) - P)) / np.max(np.abs(P))
        print(f"check: our modal FRF agrees with python-control's to {err:.1e} of the peak")
    print(f"median coupled RMS with effects {np.median(with_eff.rms['coupled'] / plain.rms['coupled']):.4f}x the plain one")
    if orders:
        kept, share, lr = needed_points(plant, ripple_only, speeds)
        print(f"ripple points an oracle pruning keeps at 1e-9 of every lines' RMS: {kept} = {kept / pts_plain:.2f}x the "
              f"plain sweep's ({pts_eff / pts_plain:.1f}x evaluated); share kept per order: "
              + ", ".join(f"{k:+d}: {v:.3f}" for k, v in share.items()))
        n_distinct = distinct_points(lr)
        print(f"ripple points at distinct frequencies (1e-12) per speed, all wheels: {n_distinct} = "
              f"{n_distinct / pts_plain:.2f}x the plain sweep's points (the wheels share theirs; "
              f"{pts_eff - n_distinct} of {pts_eff} meet another point's frequency)")
        for tol, share_kept, worst in load_trimmed(lr):
            print(f"  a-priori pruning, blocked load < {tol:.0e} x its speed's largest left out: "
                  f"{share_kept * pts_eff / pts_plain:5.2f}x the plain sweep's points, lines' RMS moved by up to {worst:.1e}")
    if dask:
        from distributed import Client, LocalCluster
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
                Client(lc) as client:
            client.run(lambda: None)                  # workers up before timing
            t0 = time.perf_counter()
            par = cp.sweep(plant, wheels, speeds, chunk=n_speeds // 2, client=client)["wheels"]
            t_par = time.perf_counter() - t0
        same = np.allclose(par.rms["coupled"], plain.rms["coupled"], rtol=1e-12, atol=0)
        print(f"plain sweep on a dask LocalCluster, 2 workers x 1 thread: {t_par:7.2f} s wall (serial min "
              f"{st['plain'][0]:.2f} s; results identical: {same})")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--dask", action="store_true")
    ap.add_argument("--no-peer", action="store_true", help="leave python-control's FRF out of the rounds")
    ap.add_argument("--orders", action="store_true", help="also the points an oracle pruning of the ripple's orders "
                    "would keep (untimed)")
    a = ap.parse_args()
    main(a.speeds, a.repeats, a.dask, a.orders, peer=not a.no_peer)
