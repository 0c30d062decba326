"""Benchmark (issue 6): 200-mode plant, 4 wheels, 1000 speeds.

Times, in one run:
  * baseline: python-control's own frequency response of the same plant (StateSpace, 400
    states) over the same frequency points the sweep visits (each wheel's distinct line
    frequencies at each speed);
  * the coupled sweep (all four practices) serial, in this process;
  * the same sweep on a 2-worker local dask cluster (processes, 1 thread each).
BLAS is pinned to one thread so serial and parallel compare like for like.

Run: .venv/bin/python benchmarks/bench_coupling.py
"""
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import time  # noqa: E402

import numpy as np  # noqa: E402

from rwadist import coupling as cp  # noqa: E402
from rwadist import extended as ext  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.units import RPM_TO_RAD_S  # noqa: E402


def main(n_speeds=1000, n_modes=200):
    plant = cp.random_modal_plant(n_modes=n_modes, n_nodes=4, n_perf=2, seed=1)
    desc = preset("ithaco-e")
    lines = tuple(ext.lines_from_model(desc.to_model(), desc.extended))
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
    wheels = [cp.WheelSpec(desc.extended, lines, cp.Mount(i, cp.spin_axis_dcm(axes[i]), (0.1, 0.0, 0.1)),
                           housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03), name=f"E{i}") for i in range(4)]
    speeds = np.linspace(1.0, 3000.0, n_speeds) * RPM_TO_RAD_S
    hu = np.unique([ln.h for ln in lines])
    f_pts = np.sort((hu[None, :] * speeds[:, None] / (2 * np.pi)).ravel())   # python-control sorts
    print(f"plant: {n_modes} modes, {plant.sys.nstates} states, {plant.n_interface} interface DOFs, "
          f"{plant.n_perf} outputs; 4 wheels x {len(lines)} lines ({hu.size} distinct h); {n_speeds} speeds "
          f"-> {f_pts.size} frequency points per wheel")

    t = time.perf_counter()
    H = plant.sys.frequency_response(2 * np.pi * f_pts)
    t_base = time.perf_counter() - t
    print(f"baseline  python-control frequency_response of the plant at those {f_pts.size} points: {t_base:8.2f} s")
    # same points through our modal evaluation, for agreement
    G, P = plant.frf(f_pts)
    Hc = np.asarray(H.fresp)                       # (n_out, n_in, F)
    err = np.max(np.abs(np.moveaxis(Hc[plant.n_interface:], -1, 0) - P)) / np.max(np.abs(P))
    print(f"          (our modal FRF agrees with it to {err:.1e} of the peak)")

    t = time.perf_counter()
    serial = cp.jitter_vs_speed(plant, wheels, speeds)
    t_ser = time.perf_counter() - t
    print(f"sweep     serial, 4 practices, 4 wheels:                         {t_ser:8.2f} s")

    from distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
            Client(lc) as client:
        client.run(lambda: None)                  # workers up before timing
        t = time.perf_counter()
        par = cp.sweep(plant, wheels, speeds, chunk=n_speeds // 2, client=client)["wheels"]
        t_par = time.perf_counter() - t
    same = np.allclose(par.rms["coupled"], serial.rms["coupled"], rtol=1e-12, atol=0)
    print(f"sweep     dask LocalCluster, 2 workers x 1 thread (2 tasks)  :   {t_par:8.2f} s  "
          f"(speed-up {t_ser / t_par:.2f}x, results identical: {same})")
    print(f"ratio     serial coupled sweep / python-control plant-only FRF:  {t_ser / t_base:8.3f}")

    # the same wheels with diagnosed effects (issue 7): a broadband floor on Fx, Fy, Fz and a speed ripple
    # (3 rad/s at 8 Hz), read from a model file's effects list as rwadist diagnose writes it
    effects = [{"kind": "broadband_floor", "channel": ["Fx", "Fy", "Fz"], "exponent": 3.0, "omega_ref_rad_s": 300.0,
                "f_Hz": [5.0, 100.0, 300.0, 500.0], "psd_ref": [1e-6, 2e-6, 1e-6, 2e-7]},
               {"kind": "speed_ripple", "f_ripple_Hz": 8.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 300.0}]
    model = desc.to_model()
    model.effects = effects
    spec = cp.wheel_spec_from_model(model)
    eff_wheels = [cp.WheelSpec(spec.params, spec.lines, w.mount, housing_mass=2.0, housing_inertia=(0.02, 0.02, 0.03),
                               floors=spec.floors, ripple=spec.ripple, name=w.name) for w in wheels]
    t = time.perf_counter()
    with_eff = cp.jitter_vs_speed(plant, eff_wheels, speeds)
    t_eff = time.perf_counter() - t
    ratio = np.median(with_eff.rms["coupled"] / serial.rms["coupled"])
    print(f"sweep     serial, with a floor (3 channels) + speed ripple per wheel: {t_eff:8.2f} s  "
          f"({t_eff / t_ser:.1f}x the plain sweep; median coupled RMS {ratio:.3f}x the plain one)")


if __name__ == "__main__":
    main()
