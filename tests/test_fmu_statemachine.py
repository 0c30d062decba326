"""The FMI state machine of the wheel FMUs (issue 35): native C FMI 2.0 and FMI 3.0, pythonfmu with its native
layer.  Random call orders against an independent model of the co-simulation state machine (FMI 2.0.4 section
4.2.4; FMI 3.0 section 4.2 without event mode), written here from the standards' tables, not from the FMUs' code.

Each order instantiates one FMU and makes 6-30 calls: mostly calls the standard allows in the model's state (so
the orders reach initialisation, stepping, termination, reset, a failed initialisation and FMU state restores),
the rest drawn from every call, in or out of order.  A call out of order must answer fmi2Error with a logged
message and leave the instance in its state (the next calls are judged from it); a call in order must answer
fmi2OK.  The orders run in a child process, so a crash is counted, not fatal.

Out of order here (the standard's table; the FMU's documented rules in brackets):
setupExperiment after instantiation [and a stop time before the start], enter/exit initialisation twice or out of
turn, terminate before initialisation or twice, doStep outside stepping, get before initialisation, set after
termination, a fixed parameter set after initialisation, an unknown value reference or an output set, cancelStep
(steps are synchronous), getRealStatus before stepping, [setFMUstate into a terminated instance].
FMI 3.0 adds: a stop time before the start in EnterInitializationMode, EnterEventMode and EnterStepMode (no event
mode: ExitInitializationMode leads to Step Mode).  The pythonfmu FMU refuses every FMU-state call (its capability
flags are false).
"""
from __future__ import annotations

import json
import os
import random
import shutil
import subprocess
import sys
from pathlib import Path

INST, INIT, STEP, TERM, FAILED = "instantiated", "init", "step", "terminated", "failed"
READABLE = {INIT, STEP, TERM, FAILED}
SETTABLE = {INST, INIT, STEP}
OPS = ("setup", "setup_stop_before_start", "enter", "exit", "bad_exit", "step", "terminate", "reset", "get_outputs",
       "set_speed", "set_seed", "get_state", "set_state", "cancel", "real_status", "get_unknown", "set_output")
#: FMI 3.0: the start time comes with EnterInitializationMode; no event mode (hasEventMode false), no Step Mode entry
OPS3 = ("enter", "enter_stop_before_start", "exit", "bad_exit", "step", "terminate", "reset", "get_outputs",
        "set_speed", "set_seed", "get_state", "set_state", "event_mode", "step_mode", "get_unknown", "set_output")
H = 1e-3


class Model:
    """The FMI 2.0 co-simulation state machine: which calls are legal, and where they lead."""

    def __init__(self, kind: str):
        self.kind, self.state, self.t, self.saved = kind, INST, 0.0, []

    def legal(self, op: str) -> bool:
        s = self.state
        return {"setup": s == INST, "setup_stop_before_start": False, "enter": s == INST, "exit": s == INIT,
                "bad_exit": s == INIT, "step": s == STEP, "terminate": s == STEP, "reset": True,
                "get_outputs": s in READABLE, "set_speed": s in SETTABLE, "set_seed": s in (INST, INIT),
                "get_state": self.kind != "python", "set_state": self.kind != "python" and s != TERM and
                bool(self.saved), "cancel": False, "real_status": s in (STEP, TERM), "get_unknown": False,
                "set_output": False, "enter_stop_before_start": False, "event_mode": False, "step_mode": False}[op]

    def after(self, op: str) -> None:
        """The state after a legal ``op`` answered as the standard says."""
        if op == "enter":
            self.state = INIT
        elif op == "exit":
            self.state = STEP
        elif op == "bad_exit":
            self.state = FAILED
        elif op == "step":
            self.t += H
        elif op == "terminate":
            self.state = TERM
        elif op == "reset":
            self.state, self.t = INST, 0.0


class Log3:
    """The messages of an FMI 3.0 instance (fmpy's logMessage callback)."""

    def __init__(self):
        self.records = []

    def callback(self, env, status, category, message):
        self.records.append((int(status), message.decode() if message else ""))

    def messages(self, min_status=0):
        return [m for s, m in self.records if s >= min_status]


def act3(f, op, model, outputs, states, rng):
    """One call of ``op`` on the FMI 3.0 instance ``f`` (fmpy FMU3Slave)."""
    if op in ("enter", "enter_stop_before_start"):
        f.enterInitializationMode(startTime=0.0, stopTime=-1.0 if op == "enter_stop_before_start" else None)
    elif op in ("exit", "bad_exit"):
        if op == "bad_exit" and model.state == INIT:
            f.setInt32([4], [-5])
        f.exitInitializationMode()
    elif op == "step":
        f.doStep(model.t, H)
    elif op == "terminate":
        f.terminate()
    elif op == "reset":
        f.reset()
    elif op == "get_outputs":
        f.getFloat64(outputs)
    elif op == "set_speed":
        f.setFloat64([0], [50.0])
    elif op == "set_seed":
        f.setInt32([4], [3])
    elif op == "get_state":
        states[len(states)] = (f.getFMUState(), model.state, model.t)
        model.saved = list(states)
    elif op == "set_state":
        key = rng.choice(model.saved) if model.saved else None
        s, st, t = states[key] if key is not None else (None, None, None)
        f.setFMUState(s)
        if model.legal("set_state"):
            model.state, model.t = st, t
    elif op == "event_mode":
        f.enterEventMode()
    elif op == "step_mode":
        f.enterStepMode()
    elif op == "get_unknown":
        f.getFloat64([9999])
    elif op == "set_output":
        f.setFloat64([26], [1.0])


def run_order(path: str, kind: str, seed: int) -> dict:
    """One random call order on a fresh instance; counts of legal/illegal calls and how they were answered."""
    from fmpy import read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime
    from fmpy.fmi3 import FMU3Slave
    from rwadist.fmu import hosts
    rng = random.Random(seed)
    md = read_model_description(path)
    fmi3 = md.fmiVersion == "3.0"
    ops = OPS3 if fmi3 else OPS
    kw = dict(guid=md.guid, unzipDirectory=_unzipped(path), modelIdentifier=md.coSimulation.modelIdentifier,
              instanceName=f"order{seed}")
    if fmi3:
        log = Log3()
        f = FMU3Slave(**kw)
        f.instantiate(loggingOn=True, logMessage=log.callback)
    else:
        log = hosts.HostLog()
        f = FMU2Slave(**kw)
        f.instantiate(callbacks=log.callbacks(), loggingOn=True)   # pythonfmu passes its messages on only so
    outputs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
    model = Model(kind)
    out = {"calls": 0, "illegal": 0, "illegal_ok": [], "illegal_unlogged": [], "legal_not_ok": [], "ops": []}
    states = {}     # id -> (fmpy state pointer, model state, model t)

    def act(op):
        c = f.component
        if fmi3:
            return act3(f, op, model, outputs, states, rng)
        if op == "setup":
            f.setupExperiment(startTime=0.0)
        elif op == "setup_stop_before_start":
            f.setupExperiment(startTime=0.0, stopTime=-1.0)
        elif op == "enter":
            f.enterInitializationMode()
        elif op in ("exit", "bad_exit"):
            if op == "bad_exit" and model.state == INIT:
                f.setInteger([4], [-5])      # seed -5: ExitInitializationMode then fails (a legal call, refused)
            f.exitInitializationMode()
        elif op == "step":
            f.doStep(model.t, H)
        elif op == "terminate":
            f.terminate()
        elif op == "reset":
            f.reset()
        elif op == "get_outputs":
            f.getReal(outputs)
        elif op == "set_speed":
            f.setReal([0], [50.0])
        elif op == "set_seed":
            f.setInteger([4], [3])
        elif op == "get_state":
            s = f.getFMUstate()
            states[len(states)] = (s, model.state, model.t)
            model.saved = list(states)
        elif op == "set_state":
            key = rng.choice(model.saved) if model.saved else None
            s, st, t = states[key] if key is not None else (None, None, None)
            f.setFMUstate(s)
            if model.legal("set_state"):
                model.state, model.t = st, t
        elif op == "cancel":
            f.fmi2CancelStep(c)
        elif op == "real_status":
            import ctypes
            v = ctypes.c_double()
            f.fmi2GetRealStatus(c, fmi2LastSuccessfulTime, ctypes.byref(v))
        elif op == "get_unknown":
            f.getReal([9999])
        elif op == "set_output":
            f.setReal([26], [1.0])

    try:
        for _ in range(rng.randint(6, 30)):
            legal_ops = [op for op in ops if model.legal(op)]
            op = rng.choice(legal_ops) if rng.random() < 0.6 and legal_ops else rng.choice(ops)
            legal = model.legal(op)
            n_err = len(log.messages(3))
            before = (model.state, model.t)
            try:
                act(op)
                status = 0
            except FMICallException as exc:
                status = exc.status
            out["calls"] += 1
            out["ops"].append(f"{op}@{before[0]}:{status}")
            if not legal:
                out["illegal"] += 1
                if status < 3:
                    out["illegal_ok"].append(f"{op} in {before[0]}")
                elif len(log.messages(3)) == n_err:
                    out["illegal_unlogged"].append(f"{op} in {before[0]}")
                model.state, model.t = before       # refused: nothing changes
            else:
                expect_error = op == "bad_exit"
                if (status >= 3) != expect_error:
                    out["legal_not_ok"].append(f"{op} in {before[0]}: status {status}")
                if op != "set_state":
                    model.after(op)
    finally:
        for s, _, _ in states.values():
            try:
                (f.freeFMUState if fmi3 else f.freeFMUstate)(s)
            except FMICallException:
                pass
        f.freeInstance()
    return out


_UNZIPPED: dict = {}


def _unzipped(path: str) -> str:
    """The FMU extracted once per process (every order instantiates from it)."""
    from fmpy import extract
    if path not in _UNZIPPED:
        _UNZIPPED[path] = extract(path)
    return _UNZIPPED[path]


def _child(fmus_json: str, kind: str, n: int, first_seed: int) -> None:
    path = json.loads(Path(fmus_json).read_text())[kind]
    for seed in range(first_seed, first_seed + n):
        print(json.dumps([kind, seed, run_order(path, kind, seed)]), flush=True)


def run_orders(fmus: dict, n: int, work: Path, first_seed: int = 0) -> dict:
    """{kind: [result per order]} of ``n`` orders per FMU, run in child processes; a child that dies is a crash."""
    (Path(work) / "fmus.json").write_text(json.dumps(fmus))
    results: dict = {kind: {} for kind in fmus}
    crashes = []
    for kind in fmus:
        start = first_seed
        while start < first_seed + n:
            res = subprocess.run([sys.executable, __file__, "child", str(Path(work) / "fmus.json"), kind,
                                  str(n - (start - first_seed)), str(start)], capture_output=True, text=True,
                                 timeout=1800)
            for line in res.stdout.splitlines():
                if line.startswith("["):
                    k, seed, r = json.loads(line)
                    results[k][seed] = r
            done = max(results[kind], default=start - 1) + 1
            if done >= first_seed + n:
                break
            crashes.append((kind, done, res.returncode, res.stderr[-300:]))
            start = done + 1
    return {"results": results, "crashes": crashes}


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "child":
    _child(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]))
    sys.exit(0)


# ------------------------------------------------------------------ tests

import pytest  # noqa: E402

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")
pytestmark = pytest.mark.skipif(not shutil.which(os.environ.get("CC", "cc")),
                                reason="the FMUs' native code needs a C compiler")


def test_random_call_orders_follow_the_fmi_state_machine(tmp_path):
    """100 random call orders per FMU (native C FMI 2.0 and FMI 3.0, pythonfmu with its native layer): 0 calls out of
    order answered OK, each refusal logged, 0 calls in order refused, 0 crashes; the orders reach every state."""
    from rwadist.fmu.build import build_fmu
    from rwadist.fmu.native_build import build_native_fmu

    from rwadist.presets import preset
    model = preset("ithaco-e").to_model()
    fmus = {"native": str(build_native_fmu(model, tmp_path / "sm_c.fmu", windows=False)),
            "native3": str(build_native_fmu(model, tmp_path / "sm_c3.fmu", fmi_version=3, windows=False)),
            "python": str(build_fmu(model, tmp_path / "sm_py.fmu"))}
    res = run_orders(fmus, 100, tmp_path)
    assert not res["crashes"], res["crashes"]
    for kind, orders in res["results"].items():
        assert len(orders) == 100
        calls = sum(r["calls"] for r in orders.values())
        illegal = sum(r["illegal"] for r in orders.values())
        bad = {k: [x for r in orders.values() for x in r[k]] for k in ("illegal_ok", "illegal_unlogged",
                                                                         "legal_not_ok")}
        reached = {op.split("@")[1].split(":")[0] for r in orders.values() for op in r["ops"]}
        print(f"{kind}: {len(orders)} orders, {calls} calls, {illegal} out of order: "
              + ", ".join(f"{k} {len(v)}" for k, v in bad.items()) + f"; states reached {sorted(reached)}")
        assert not any(bad.values()), {k: v[:5] for k, v in bad.items()}
        assert illegal > 200
        assert reached == {INST, INIT, STEP, TERM, FAILED}
