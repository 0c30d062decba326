"""Fuzz of the FMU surface (issue 17): seeded random and hostile parameters and inputs (NaN, ±inf, 1e308, negative,
zero and huge steps, communication points that go backwards, are NaN or skip ahead, bad DCM entries, bad seeds, FMU
state calls) through fmpy into both wheel FMUs (pythonfmu with its native layer, and native C).

Each case instantiates one FMU, sets its parameters, initialises and runs a few operations.  Outcomes per case:

* ``traceback``: a Python exception other than fmpy's FMICallException reached the host, an fmi2Fatal, a message
  holding a Python traceback, or the host process died (crash);
* ``silent``: an invalid value used silently -- a call answered fmi2OK although it carried a value known to be
  invalid (a non-finite speed or acceleration, a wrong communication point, a step size that is not positive and
  finite or exceeds max_step_size, a parameter out of its range), or outputs that are not finite after fmi2OK;
* ``unclear``: refused without a logged fmi2Error message;
* ``clear``: at least one refusal, each with a logged message; ``ok``: every call accepted, every output finite.

CI runs a sample here (tests must see 0 traceback and 0 silent); ``benchmarks/fuzz_all.py --surface fmu`` runs
>= 300 cases per FMU.  Cases run in a child process (fmpy in-process), restarted after a crash.
"""
from __future__ import annotations

import json
import math
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

OUTCOMES = ("ok", "clear", "unclear", "silent", "traceback")
KINDS = ("python", "native")
ERROR = 3
SPEEDS = [0.0, 100.0, -100.0, 523.6, -523.6, 1e3, 1e-300, 5e-324, 1e160, -1e160, 1e308, -1e308,
          math.nan, math.inf, -math.inf]
ACCELS = [0.0, 10.0, -10.0, 499.0, 501.0, 1e308, math.nan, math.inf, -math.inf]
STEPS = [1e-3, 1e-3, 1e-3, 1e-3, 5e-4, 0.01, 0.0100001, 0.0, -1e-3, 1e-12, 1e9, math.nan, math.inf]
TIMES = ["ok"] * 6 + ["back", "nan", "gap", "inf", "jitter"]
R_VALID = [[0.0, -1.0, 0.0], [math.sqrt(0.5), 0.0, -math.sqrt(0.5)], [math.sqrt(0.5), 0.0, math.sqrt(0.5)]]
HOSTILE_REALS = [math.nan, math.inf, -math.inf, 1e308, -1e308, 0.0, -1.0, 2.0, 1e-300]


def wheel_doc() -> dict:
    """The E-wheel preset with a speed ripple and a broadband floor (the stateful effects)."""
    from rwadist import model as model_io
    from rwadist.presets import preset
    doc = model_io.to_json(preset("ithaco-e").to_model())
    doc["effects"] = [
        {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 200.0,
         "speed_exponent": 0.5},
        {"kind": "broadband_floor", "channel": ["Fx", "Tz"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
         "f_Hz": [5.0, 60.0, 140.0], "psd_ref": [1.0e-5, 4.0e-5, 1.0e-5]}]
    return doc


def build_fmus(folder: Path) -> dict:
    """{kind: path} of both FMUs of :func:`wheel_doc`."""
    from rwadist.fmu.build import build_fmu
    from rwadist.fmu.native_build import build_native_fmu
    folder = Path(folder)
    doc = wheel_doc()
    return {"python": str(build_fmu(doc, folder / "fuzz_py.fmu")),
            "native": str(build_native_fmu(doc, folder / "fuzz_c.fmu"))}


# ------------------------------------------------------------------ cases

def _param(rng: random.Random, kind: str) -> tuple:
    """(name, value, invalid) of one random parameter setting."""
    what = rng.choice(["seed", "max_acceleration", "max_step_size", "floor_resolution", "dcm", "r", "bool",
                       "model_file", "use_wheel_acceleration"])
    if what == "seed":
        v = rng.choice([-1, 0, 7, 2**31 - 1, -2, -5, -(2**31)])
        return "seed", v, v < -1
    if what in ("max_acceleration", "max_step_size", "floor_resolution"):
        v = rng.choice([500.0, 1e3, 0.02, 1.0] + HOSTILE_REALS)
        return what, v, not (math.isfinite(v) and v > 0)
    if what == "dcm":
        i, j = rng.randrange(3), rng.randrange(3)
        v = rng.choice([R_VALID[i][j]] + HOSTILE_REALS)
        return f"dcm_{i + 1}{j + 1}", v, v != (1.0 if i == j else 0.0)   # any change of the identity's entry
    if what == "r":
        v = rng.choice([0.3, -2.0] + HOSTILE_REALS)
        return f"r_{rng.choice('xyz')}", v, not math.isfinite(v)
    if what == "bool":
        return rng.choice(["imbalance", "harmonics", "start_steady", "speed_ripple", "broadband_floor"]), \
            rng.random() < 0.5, False
    if what == "model_file":
        v = rng.choice(["", "/nonexistent/model.json", "/", "\u00e9\u0000x"[:2]])
        return "model_file", v, v != "" and kind == "python"    # the native FMU refuses any file (compiled in)
    return "use_wheel_acceleration", rng.random() < 0.5, False


def fmu_cases(n: int, seed: int, kinds=KINDS) -> list:
    """``n`` cases per FMU kind: dicts with kind, params [(name, value, invalid)], first speed, ops."""
    rng = random.Random(seed)
    cases = []
    for kind in kinds:
        for _ in range(n):
            params = [_param(rng, kind) for _ in range(rng.choice([0, 0, 0, 1, 1, 2, 3]))]
            ops = []
            for _ in range(rng.randint(1, 8)):
                r = rng.random()
                if r < 0.65:
                    ops.append(["step", rng.choice(SPEEDS[:5]) if rng.random() < 0.8 else rng.choice(SPEEDS),
                                rng.choice(ACCELS[:3]) if rng.random() < 0.8 else rng.choice(ACCELS),
                                rng.choice(STEPS[:4]) if rng.random() < 0.8 else rng.choice(STEPS),
                                "ok" if rng.random() < 0.7 else rng.choice(TIMES)])
                elif r < 0.8:
                    ops.append(["state"])
                elif r < 0.9:
                    ops.append(["reset"])
                else:
                    ops.append(["bad_vr"])
            speed0 = rng.choice(SPEEDS[:5]) if rng.random() < 0.8 else rng.choice(SPEEDS)
            cases.append({"kind": kind, "params": params, "speed0": speed0, "ops": ops})
    return cases


# ------------------------------------------------------------------ running one case (in the child)

def run_fmu_case(case: dict, fmus: dict) -> tuple:
    """(outcome, detail) of one case, in this process."""
    import numpy as np
    from fmpy.fmi1 import FMICallException

    from rwadist.fmu import hosts
    from rwadist.fmu import runtime as rt
    log = hosts.HostLog()
    state = {"refused": 0, "silent": None}

    def call(fn, invalid, what):
        """Run fn; True if accepted.  Accepted with ``invalid``: silent; a refusal needs a logged message."""
        n_err = len(log.messages(ERROR))
        try:
            fn()
        except FMICallException as exc:
            if exc.status >= 4:
                raise RuntimeError(f"fmi2Fatal from {what}") from None
            if exc.status >= ERROR:
                state["refused"] += 1
                if len(log.messages(ERROR)) == n_err:
                    state["unclear"] = what
                return False
            return True           # Warning / Discard: treated as accepted (the plain pythonfmu build)
        if invalid and state["silent"] is None:
            state["silent"] = what
        return True

    kind = case["kind"]
    try:
        inst = hosts.FmpyInstance(fmus[kind], "fuzz", None, None, log=log, exit_init=False)
    except Exception as exc:        # noqa: BLE001 -- a host-side failure to even instantiate is a finding
        return "traceback", f"instantiate: {type(exc).__name__}: {exc}"
    f = inst.fmu
    try:
        use_acc, max_step, max_accel = False, 0.01, 500.0
        accepted = {}                # parameter -> (last value accepted, invalid)
        for name, value, invalid in case["params"]:
            if call(lambda: inst.set(name, value), False, f"set {name}={value!r}"):
                accepted[name] = (value, invalid)
        for name, (value, invalid) in accepted.items():
            if name == "use_wheel_acceleration":
                use_acc = bool(value)
            elif name == "max_step_size" and not invalid:
                max_step = value
            elif name == "max_acceleration" and not invalid:
                max_accel = value
        invalid_params = any(inv for name, (_, inv) in accepted.items() if not name.startswith("dcm_"))
        dcm = [[accepted.get(f"dcm_{i + 1}{j + 1}", (float(i == j), False))[0] for j in range(3)] for i in range(3)]
        try:
            rt.rotation_check(dcm)         # the documented rule: a proper rotation within 1e-6
        except rt.ModelError:
            invalid_params = True
        call(lambda: inst.set("wheel_speed", case["speed0"]), False, "set wheel_speed")
        initialised = call(f.exitInitializationMode, invalid_params, "exitInitializationMode")
        t, h_prev = 0.0, None
        for op in case["ops"]:
            if op[0] == "step":
                _, w, a, h, tmode = op
                call(lambda: inst.set("wheel_speed", w), False, "set wheel_speed")
                call(lambda: inst.set("wheel_acceleration", a), False, "set wheel_acceleration")
                tc = {"ok": t, "back": t - 1e-3, "nan": math.nan, "gap": t + 0.5, "inf": math.inf,
                      "jitter": t + 1e-13}[tmode]
                bad = (not math.isfinite(w) or (use_acc and not (math.isfinite(a) and abs(a) <= max_accel))
                       or tmode in ("back", "nan", "gap", "inf")
                       or not (math.isfinite(h) and 1e-9 <= h <= max_step * (1 + 1e-12)) or not initialised)
                if call(lambda: f.doStep(tc, h), bad, f"doStep(t={tc!r}, h={h!r}, speed={w!r}, acc={a!r})"):
                    t = tc + h
                    h_prev = h
            elif op[0] == "state":
                blob = None
                try:
                    s = f.getFMUstate()
                    blob = f.serializeFMUstate(s)
                    s2 = f.deSerializeFMUstate(blob)
                    f.setFMUstate(s2)
                    f.freeFMUstate(s2)
                    f.freeFMUstate(s)
                    if kind == "python" and state["silent"] is None:
                        state["silent"] = "FMU state accepted though the flag says false"
                except FMICallException as exc:
                    if exc.status >= 4:
                        raise RuntimeError("fmi2Fatal from an FMU state call") from None
                    state["refused"] += 1
                    if kind == "native" and initialised:
                        state.setdefault("unclear", "FMU state refused by the native FMU")
                call(lambda: f.fmi2SetFMUstate(f.component, None), True, "fmi2SetFMUstate(NULL)")
            elif op[0] == "reset":
                call(f.reset, False, "reset")
                # fmi2Reset: every variable back to its start value (the parameters set above are gone)
                invalid_params, use_acc, max_step, max_accel = False, False, 0.01, 500.0
                f.setupExperiment(startTime=0.0)
                f.enterInitializationMode()
                initialised = call(f.exitInitializationMode, False, "exitInitializationMode after reset")
                t = 0.0
            else:
                call(lambda: f.setReal([99999], [1.0]), True, "setReal of an unknown value reference")
            y = inst.get()
            if not all(np.isfinite(y)) and state["silent"] is None:
                state["silent"] = f"non-finite outputs after {op!r}: {y}"
        del h_prev
    except Exception as exc:        # noqa: BLE001 -- any Python exception reaching the host is the finding
        return "traceback", f"{type(exc).__name__}: {exc}"
    finally:
        try:
            inst.close()
        except Exception:           # noqa: BLE001
            pass
    if any("Traceback" in m for m in log.messages(0)):
        return "traceback", next(m for m in log.messages(0) if "Traceback" in m)[:300]
    if state["silent"]:
        return "silent", state["silent"]
    if "unclear" in state:
        return "unclear", state["unclear"]
    return ("clear" if state["refused"] else "ok"), ""


def _child(fmus_json: str, cases_json: str, start: int) -> None:
    fmus = json.loads(Path(fmus_json).read_text())
    cases = json.loads(Path(cases_json).read_text())
    for i in range(start, len(cases)):
        outcome, detail = run_fmu_case(cases[i], fmus)
        print(json.dumps([i, outcome, detail]), flush=True)


def run_cases(cases: list, fmus: dict, work: Path) -> list:
    """[(outcome, detail)] of every case, run in child processes (one restarted after each crash)."""
    work = Path(work)
    (work / "fmus.json").write_text(json.dumps(fmus))
    (work / "cases.json").write_text(json.dumps(cases))
    results: dict = {}
    start = 0
    while start < len(cases):
        res = subprocess.run([sys.executable, __file__, "child", str(work / "fmus.json"), str(work / "cases.json"),
                              str(start)], capture_output=True, text=True, timeout=3600)
        for line in res.stdout.splitlines():
            if line.startswith("["):
                i, outcome, detail = json.loads(line)
                results[i] = (outcome, detail)
        done = max(results, default=start - 1) + 1
        if done >= len(cases):
            break
        # the child died inside case ``done``: a crash of the host process
        results[done] = ("traceback", f"host process died (exit {res.returncode}): {res.stderr[-300:]}")
        start = done + 1
    return [results[i] for i in range(len(cases))]


def tally(results) -> dict:
    counts = {k: 0 for k in OUTCOMES}
    for outcome, _ in results:
        counts[outcome] += 1
    return counts


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "child":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    _child(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    sys.exit(0)


# ------------------------------------------------------------------ the CI sample

import pytest  # noqa: E402

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")


@pytest.mark.skipif(not shutil.which(os.environ.get("CC", "cc")), reason="the native FMU needs a C compiler")
def test_fmu_fuzz_sample(tmp_path):
    """25 seeded cases per FMU: 0 tracebacks or crashes, 0 invalid values used silently, 0 unclear refusals; the
    sample reaches both accepted and refused cases."""
    cases = fmu_cases(25, seed=2026)
    results = run_cases(cases, build_fmus(tmp_path), tmp_path)
    counts = tally(results)
    print("FMU fuzz sample:", counts)
    bad = [(c["kind"], r) for c, r in zip(cases, results) if r[0] in ("traceback", "silent", "unclear")]
    assert not bad, bad[:5]
    assert counts["ok"] > 0 and counts["clear"] > 0
