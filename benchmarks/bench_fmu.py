"""Benchmark (issue 5): the wheel FMU vs a trivial pythonfmu FMU (y = u), both stepped the same
way at 1 kHz for 60 s of simulated time (60 000 steps: set input, doStep, read all outputs), in
fmpy and in libcosim (libcosimpy).  Prints wall times, their ratio (target <= 2) and the
real-time factor (simulated / wall time).  A third FMU, the same wheel with diagnosed effects (issue 7:
broadband floors on Fx, Fy, Fz from 2 to 500 Hz at the default 0.1-Hz multisine resolution, 14 970
sinusoids, and a speed ripple), is timed in the same interleaved runs.

    .venv/bin/python benchmarks/bench_fmu.py [--seconds 60] [--hosts fmpy,libcosim]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rwadist.fmu import hosts
from rwadist.fmu.build import build_preset

TRIVIAL = '''
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class TrivialEcho(Fmi2Slave):
    description = "y = u"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u = 0.0
        self.y = 0.0
        self.register_variable(Real("u", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous))
        self.register_variable(Real("y", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                                    initial=Fmi2Initial.exact))

    def do_step(self, current_time, step_size):
        self.y = self.u
        return True
'''


def build_trivial(dest: Path) -> Path:
    from pythonfmu import FmuBuilder
    src = dest / "rwadist_bench_trivial_echo.py"
    src.write_text(TRIVIAL)
    path_before = list(sys.path)
    try:
        return Path(FmuBuilder.build_FMU(src, dest=dest / "trivial.fmu"))
    finally:
        sys.path[:] = path_before


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated time, s (default 60)")
    ap.add_argument("--rate", type=float, default=1000.0, help="communication rate, Hz (default 1000)")
    ap.add_argument("--hosts", default="fmpy,libcosim")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved runs of each FMU; the best is reported")
    args = ap.parse_args(argv)
    h = 1.0 / args.rate
    n = int(round(args.seconds * args.rate))
    t = np.arange(n + 1) * h
    # spin-up 0 -> 3000 rpm then reversal to -3000 rpm (max 21 rad/s²)
    w = 3000 * 2 * np.pi / 60 * np.interp(t, [0, args.seconds / 3, args.seconds], [0.0, 1.0, -1.0])
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        wheel = build_preset("ithaco-e", tmp / "wheel.fmu")
        trivial = build_trivial(tmp)
        from rwadist.fmu.build import build_fmu
        from rwadist.presets import preset
        model = preset("ithaco-e").to_model()
        model.effects = [{"kind": "broadband_floor", "channel": ["Fx", "Fy", "Fz"], "exponent": 3.0,
                          "omega_ref_rad_s": 300.0, "f_Hz": [2.0, 100.0, 300.0, 500.0],
                          "psd_ref": [1e-6, 2e-6, 1e-6, 2e-7]},
                         {"kind": "speed_ripple", "f_ripple_Hz": 8.0, "delta_omega_rad_s": 3.0,
                          "omega_ref_rad_s": 300.0}]
        effects = build_fmu(model, tmp / "wheel_effects.fmu")
        from rwadist.fmu.build import has_native
        print(f"{n} steps of {h:g} s ({args.seconds:g} s simulated); wheel: ithaco-e preset, 18 lines, 12 outputs, "
              f"native layer: {'yes (C kernel)' if has_native(wheel) else 'no (numpy steps)'}")
        for host in args.hosts.split(","):
            run = {"fmpy": hosts.run_fmpy, "libcosim": hosts.run_libcosim}[host]
            walls = {"trivial y=u": [], "wheel": [], "wheel+effects": []}
            # interleaved repeats, best of each: the ratio should not depend on what else the machine does
            for _ in range(args.repeat):
                for name, path, inputs in (("trivial y=u", trivial, {"u": w}), ("wheel", wheel, {"wheel_speed": w}),
                                           ("wheel+effects", effects, {"wheel_speed": w})):
                    t0 = time.perf_counter()
                    out = run(path, t, inputs)
                    walls[name].append(time.perf_counter() - t0)
                    assert np.all(np.isfinite(out[1:])), f"{host} {name}: non-finite outputs"
            for name, ws in walls.items():
                best = min(ws)
                print(f"{host:>8} {name:<13} wall {best:7.2f} s  {best / n * 1e6:6.1f} us/step  "
                      f"real-time factor {args.seconds / best:6.1f}  (best of {len(ws)}: "
                      + ", ".join(f"{x:.2f}" for x in ws) + ")")
            ratio = min(walls["wheel"]) / min(walls["trivial y=u"])
            print(f"{host:>8} ratio wheel / trivial = {ratio:.2f} (target <= 2)")
            print(f"{host:>8} ratio wheel+effects / trivial = {min(walls['wheel+effects']) / min(walls['trivial y=u']):.2f}"
                  " (no target: the floors' multisine costs one complex multiply per sinusoid per step)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
