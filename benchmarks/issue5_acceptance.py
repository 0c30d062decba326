"""Print the numbers behind issue 5's acceptance list (tests/test_fmu.py asserts them).

    python benchmarks/issue5_acceptance.py

FMU (built here, with its native layer where a C compiler is found) against
rwadist.extended_time.simulate_time through fmpy and libcosim; constant-speed line amplitudes against
C·Ω²·|modal gain|; fmpy validation; step-size convergence; the FMI status and message of each bad
input.  The timing benchmark is benchmarks/bench_fmu.py.
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import test_fmu as T  # noqa: E402  (the tests' reference, profiles and helpers)

from rwadist import model as model_io  # noqa: E402
from rwadist.fmu import hosts  # noqa: E402
from rwadist.fmu import runtime as rt
from rwadist.fmu.build import build_fmu, has_native  # noqa: E402


def main() -> int:
    model = T.wheel_model()
    tmp = Path(tempfile.mkdtemp(prefix="rwadist_issue5_"))
    fmu = build_fmu(model, tmp / "wheel.fmu")
    print(f"FMU {fmu.name}: native layer {'yes' if has_native(fmu) else 'no'}")

    # 1. equality with simulate_time, 12 outputs, both hosts
    R = np.array([[0.0, -1.0, 0.0], [np.sqrt(0.5), 0.0, -np.sqrt(0.5)], [np.sqrt(0.5), 0.0, np.sqrt(0.5)]])
    r = np.array([0.3, -0.2, 0.5])
    params = {"use_wheel_acceleration": True, "seed": 3, "r_x": r[0], "r_y": r[1], "r_z": r[2]}
    params.update({f"dcm_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)})
    for name, prof in (("spin-up 0->3000 rpm, 4 s", T.spin_up), ("reversal +1500->-1500 rpm, 4 s", T.reversal)):
        t, w = prof(T=4.0)
        ref = T.reference(model, t, w, 3)
        F = ref[:, :3] @ R.T
        ref12 = np.hstack([ref, F, ref[:, 3:] @ R.T + np.cross(r, F)])
        inputs = {"wheel_speed": w, "wheel_acceleration": T.slope(t, w)}
        for host, run in (("fmpy", hosts.run_fmpy), ("libcosim", hosts.run_libcosim)):
            try:
                out = run(fmu, t, inputs, params)
            except ImportError:
                print(f"  {host}: not installed")
                continue
            # (libcosim has no outputs at t0: rows from the first step on)
            print(f"{name:<32} {host:<9} max relative error (12 outputs) "
                  f"{np.max(T.rel_err(out[1:], ref12[1:])):.2e}")

    # 2. constant-speed amplitudes (the test's least-squares check, which also returns its worst case)
    for rpm in (2400.0, -1100.0):
        worst, n = T.check_amplitudes(fmu, model, rpm, lambda ln, omega: ln.C * omega**2)
        print(f"constant speed {rpm:+.0f} rpm: {n} line components, "
              f"worst |amplitude / (C·Ω²·|gain|) - 1| = {worst:.2e}")

    # 3. validation
    from fmpy.validation import validate_fmu
    print(f"fmpy validate: {len(validate_fmu(str(fmu)))} problem(s)")

    # 4. step-size convergence (runtime = FMU physics; native kernel where built)
    params_rt, lines_rt = rt.load_model(model_io.save(model, tmp / "m.json"))
    Tt = 4.0
    t_ref = np.arange(int(round(Tt / 1e-5)) + 1) * 1e-5
    ref = T.reference(model, t_ref, 3000 * T.RPM * t_ref / Tt, 6)[::1000]
    scale = np.max(np.abs(ref), axis=0)
    for mode in ("slope", None):
        errs = []
        for h in (1e-4, 1e-3, 1e-2):
            n = int(round(Tt / h))
            t = np.arange(n + 1) * h
            out = rt.WheelRuntime(params_rt, lines_rt, seed=6).run(t, 3000 * T.RPM * t / Tt, alpha=mode)
            every = int(round(1e-2 / h))
            errs.append(float(np.max(np.max(np.abs(out[::every] - ref), axis=0) / scale)))
        print(f"step 1e-4/1e-3/1e-2 s, acceleration {'input' if mode else 'derived'}: "
              + " / ".join(f"{e:.1e}" for e in errs))

    # 5. bad input through fmpy: status and message
    from fmpy.fmi1 import FMICallException
    cases = {"NaN speed": ("wheel_speed", float("nan"), 1e-3), "inf speed": ("wheel_speed", float("inf"), 1e-3),
             "speed jump": ("wheel_speed", 200.0, 1e-3), "step 0.05 s": ("wheel_speed", 100.0, 0.05)}
    for name, (var, val, h) in cases.items():
        log = hosts.HostLog()
        inst = hosts.FmpyInstance(fmu, "bad", {}, {"wheel_speed": 100.0}, log=log)
        inst.fmu.doStep(0.0, 1e-3)
        inst.set(var, val)
        try:
            inst.fmu.doStep(1e-3, h)
            status = 0
        except FMICallException as exc:
            status = exc.status
        inst.set("wheel_speed", 100.0)
        inst.fmu.doStep(1e-3, 1e-3)
        inst.close()
        print(f"bad input {name:<12} fmi2DoStep status {status} (3 = fmi2Error); host goes on; "
              f"message: {log.messages(3)[-1][:110]}")
    bad_files = {"missing model file": {"model_file": str(tmp / "nope.json")}, "DCM not a rotation": {"dcm_11": 2.0},
                 "seed -5": {"seed": -5}, "max_step_size -1": {"max_step_size": -1.0}}
    for name, par in bad_files.items():
        log = hosts.HostLog()
        inst = hosts.FmpyInstance(fmu, "bad", par, {"wheel_speed": 100.0}, log=log, exit_init=False)
        try:
            inst.fmu.exitInitializationMode()
            status = 0
        except FMICallException as exc:
            status = exc.status
        inst.close()
        print(f"bad parameter {name:<20} fmi2ExitInitializationMode status {status}; "
              f"message: {log.messages(3)[-1][:100]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
