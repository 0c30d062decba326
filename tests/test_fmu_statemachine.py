"""The FMI state machine of the wheel FMUs (issue 35): native C FMI 2.0 and FMI 3.0, pythonfmu with its native
layer, driven through random call orders and judged against a model of the standards' tables written here, not
from the FMUs' code.

The model is the table of allowed calls of each standard, for the states a co-simulation FMU without event mode,
asynchronous steps or fmi2Discard can be in:

* FMI 2.0.4, section 4.2.4 (the table and figure 11): instantiated, Initialization Mode, stepComplete ("step"),
  terminated, error.  fmi2Error from a call in instantiated, Initialization Mode or stepComplete moves the FMU to
  error; in terminated it stays.  FMU-state calls (fmi2SetFMUstate included) are allowed in every state, the getters
  from Initialization Mode on (after an error for debugging), the setters of inputs in Initialization Mode and
  stepComplete, of (fixed) parameters in instantiated and Initialization Mode.
* FMI 3.0.2, sections 2.3 and 4.2: Instantiated, Initialization Mode, Step Mode, Terminated; any fmi3Error moves the
  FMU to Terminated; the getters are allowed in every state (start values in Instantiated), the FMU-state calls and
  fmi3Reset everywhere, fmi3Set{Type} of inputs in Instantiated, Initialization Mode and Step Mode, of parameters in
  Instantiated and Initialization Mode, never in Terminated.

One leniency of the FMUs, documented in rwadist/fmu/native/rwadist_fmi_rules.h, is in the model: an FMI 2.0 input set in
instantiated is accepted (FMI 3.0 allows it; fmpy's simulate_fmu does it).  Cross-checked against the Modelica
Association's Reference FMUs (src/fmi2Functions.c, src/fmi3Functions.c: their MASK_* tables): the same rows, except
that they allow fmi3Set{Type} in Terminated (the standard lists only the getters there) and take FMI 2.0's error
state as terminated.

Each order instantiates one FMU, leads it into one of the states (order k: PREFIXES[k % 5], so every state is
reached whatever the seeds) and makes 6-30 random calls: mostly calls the model says are allowed and valid, the rest
drawn from every call.  The speeds are legal by construction: before the first
step after initialisation any speed, after it the speed of the last step ± 0.1 rad/s (1-ms steps: 100 rad/s² and a
second difference of 200 rad/s² at most, under max_acceleration = 500 rad/s²).  Expected: a call allowed and valid
answers OK (or Warning) and moves the model as the standard says; any other call answers Error with a logged
message and moves the model to the error state of its FMI version.  The orders run in child processes, so a crash
is counted, not fatal.  The first seed is drawn anew for every run (RWADIST_FUZZ_SEED fixes it, to replay one).
"""
from __future__ import annotations

import copy
import json
import os
import random
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

INST, INIT, STEP, TERM, ERR = "instantiated", "init", "step", "terminated", "error"
ALL2, ALL3 = {INST, INIT, STEP, TERM, ERR}, {INST, INIT, STEP, TERM}
#: FMI 2.0 co-simulation: the states each row of the table allows
FMI2 = {"setupExperiment": {INST}, "enterInitializationMode": {INST}, "exitInitializationMode": {INIT},
        "doStep": {STEP}, "terminate": {STEP}, "reset": ALL2, "get": {INIT, STEP, TERM, ERR},
        "set_input": {INST, INIT, STEP}, "set_parameter": {INST, INIT}, "getStatus": {STEP, TERM},
        "fmu_state": ALL2, "cancelStep": set()}
#: FMI 3.0 co-simulation without event mode
FMI3 = {"enterInitializationMode": {INST}, "exitInitializationMode": {INIT}, "doStep": {STEP}, "terminate": {STEP},
        "reset": ALL3, "get": ALL3, "set_input": {INST, INIT, STEP}, "set_parameter": {INST, INIT},
        "fmu_state": ALL3, "enterEventMode": set(), "enterStepMode": set()}
H = 1e-3
#: a call's row of the table, and whether its arguments are valid (else a legal call is still refused)
ROWS = {"setup": "setupExperiment", "setup_stop_before_start": "setupExperiment", "enter": "enterInitializationMode",
        "enter_stop_before_start": "enterInitializationMode", "exit": "exitInitializationMode", "step": "doStep",
        "terminate": "terminate", "reset": "reset", "get_outputs": "get", "get_start": "get", "get_unknown": "get",
        "set_speed": "set_input", "set_output": "set_input", "set_seed": "set_parameter",
        "set_bad_seed": "set_parameter", "set_speed_and_dcm": "set_parameter", "get_state": "fmu_state",
        "set_state": "fmu_state", "cancel": "cancelStep", "real_status": "getStatus", "event_mode": "enterEventMode",
        "step_mode": "enterStepMode"}
OPS2 = ("setup", "setup_stop_before_start", "enter", "exit", "step", "terminate", "reset", "get_outputs", "get_start",
        "get_unknown", "set_speed", "set_output", "set_seed", "set_bad_seed", "set_speed_and_dcm", "get_state",
        "set_state", "cancel", "real_status")
OPS3 = ("enter", "enter_stop_before_start", "exit", "step", "terminate", "reset", "get_outputs", "get_start",
        "get_unknown", "set_speed", "set_output", "set_seed", "set_bad_seed", "set_speed_and_dcm", "get_state",
        "set_state", "event_mode", "step_mode")
VR_SPEED, VR_SEED, VR_DCM11, VR_FX = 0, 4, 14, 26
#: the calls an order starts with (order k: PREFIXES[k % 5]), so that the random calls after them start in every
#: state whatever the seed: instantiated, init, step, terminated, error (FMI 3.0: Terminated after an error)
PREFIXES = ((), ("enter",), ("enter", "exit", "step"), ("enter", "exit", "step", "terminate"),
            ("enter", "exit", "step", "get_unknown"))


@dataclass
class Model:
    """The standard's view of one instance: its state and what the next calls depend on."""

    fmi: int
    kind: str
    state: str = INST
    t: float = 0.0                    # the next communication point
    speed: float = 0.0                # the wheel_speed input
    last_step_speed: float | None = None   # the speed of the last step since initialisation (None: none yet)
    bad_seed: bool = False            # seed -5 set: ExitInitializationMode fails
    saved: list = field(default_factory=list)

    def table(self) -> dict:
        table = dict(FMI3 if self.fmi == 3 else FMI2)
        if self.kind == "python":     # canGetAndSetFMUstate = false: every FMU-state call is refused
            table["fmu_state"] = set()
        return table

    def legal(self, op: str) -> bool:
        if op == "set_state" and not self.saved:
            return False
        return self.state in self.table()[ROWS[op]]

    def valid(self, op: str) -> bool:
        """The arguments are right (a call in order with wrong ones is refused all the same)."""
        return op not in ("setup_stop_before_start", "enter_stop_before_start", "get_unknown", "set_output") and not (
            op == "exit" and self.bad_seed)

    def after_ok(self, op: str, restored=None) -> None:
        """The state after ``op`` answered OK."""
        if op in ("enter", "exit", "terminate"):
            self.state = {"enter": INIT, "exit": STEP, "terminate": TERM}[op]
            if op == "exit":
                self.last_step_speed = None
        elif op == "step":
            self.t += H
            self.last_step_speed = self.speed
        elif op == "reset":
            self.state, self.t, self.speed, self.last_step_speed, self.bad_seed = INST, 0.0, 0.0, None, False
        elif op in ("set_seed", "set_bad_seed"):
            self.bad_seed = op == "set_bad_seed"
        elif op == "set_state":
            for k in ("state", "t", "speed", "last_step_speed", "bad_seed"):
                setattr(self, k, getattr(restored, k))

    def after_error(self) -> None:
        """FMI 2.0: error (terminated stays); FMI 3.0: Terminated."""
        self.state = TERM if self.fmi == 3 or self.state == TERM else ERR

    def next_speed(self, rng: random.Random) -> float:
        """A speed the next step accepts whatever else happens (see the module docstring)."""
        if self.last_step_speed is None:
            return rng.uniform(-300.0, 300.0)
        return self.last_step_speed + rng.uniform(-0.1, 0.1)


class Order:
    """One random call order on a fresh instance of the FMU at ``path`` (fmpy FMU2Slave or FMU3Slave)."""

    def __init__(self, path: str, kind: str, seed: int):
        self.prefix = PREFIXES[seed % len(PREFIXES)]
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave
        from fmpy.fmi3 import FMU3Slave

        from rwadist.fmu import hosts
        self.rng = random.Random(seed)
        md = read_model_description(path)
        fmi = 3 if md.fmiVersion.startswith("3") else 2
        self.model = Model(fmi, kind)
        kw = dict(guid=md.guid, unzipDirectory=_unzipped(path), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName=f"order{seed}")
        if fmi == 3:
            self.log, self.f = Log3(), FMU3Slave(**kw)
            self.f.instantiate(loggingOn=True, logMessage=self.log.callback)
        else:
            self.log, self.f = hosts.HostLog(), FMU2Slave(**kw)
            self.f.instantiate(callbacks=self.log.callbacks(), loggingOn=True)
        self.ops = OPS3 if fmi == 3 else OPS2
        self.states: list = []        # (fmpy state, model snapshot)
        self.speed, self.restored = 0.0, (None, None)

    def act(self, op: str) -> None:
        """Make the FMI call of ``op`` (FMICallException when it answers Error)."""
        f, m, real = self.f, self.model, self.model.fmi == 2
        get, set_ = (f.getReal, f.setReal) if real else (f.getFloat64, f.setFloat64)
        set_int = f.setInteger if real else f.setInt32
        calls = {
            "setup": lambda: f.setupExperiment(startTime=0.0),
            "setup_stop_before_start": lambda: f.setupExperiment(startTime=0.0, stopTime=-1.0),
            "enter": (lambda: f.enterInitializationMode()) if real else
            (lambda: f.enterInitializationMode(startTime=0.0)),
            "enter_stop_before_start": lambda: f.enterInitializationMode(startTime=0.0, stopTime=-1.0),
            "exit": f.exitInitializationMode, "step": lambda: f.doStep(m.t, H), "terminate": f.terminate,
            "reset": f.reset, "get_outputs": lambda: get(list(range(VR_FX, VR_FX + 12))),
            "get_start": lambda: get([VR_DCM11]), "get_unknown": lambda: get([9999]),
            "set_output": lambda: set_([VR_FX], [1.0]), "set_seed": lambda: set_int([VR_SEED], [3]),
            "set_bad_seed": lambda: set_int([VR_SEED], [-5]),   # accepted: ExitInitializationMode then fails
            "event_mode": lambda: f.enterEventMode(), "step_mode": lambda: f.enterStepMode(),
            "cancel": lambda: f.fmi2CancelStep(f.component), "real_status": self._real_status,
        }
        if op in ("set_speed", "set_speed_and_dcm"):
            self.speed = m.next_speed(self.rng)
            n = 1 + (op == "set_speed_and_dcm")
            set_([VR_SPEED, VR_DCM11][:n], [self.speed, 1.0][:n])
        elif op == "get_state":
            self.states.append((f.getFMUstate() if real else f.getFMUState(), copy.deepcopy(m)))
        elif op == "set_state":
            self.restored = self.rng.choice(self.states) if self.states else (None, None)
            (f.setFMUstate if real else f.setFMUState)(self.restored[0])
        else:
            calls[op]()

    def _real_status(self):
        import ctypes

        from fmpy.fmi2 import fmi2LastSuccessfulTime
        self.f.fmi2GetRealStatus(self.f.component, fmi2LastSuccessfulTime, ctypes.byref(ctypes.c_double()))

    def judge(self, op: str, status: int, n_logged: int, out: dict) -> None:
        """Count ``op``'s answer against the model and move the model."""
        m = self.model
        legal, valid, before = m.legal(op), m.valid(op), m.state
        out["ops"].append(f"{op}@{before}:{status}")
        if legal and valid:
            if status >= 3:
                out["legal_not_ok"].append(f"{op} in {before}: status {status}")
            if op in ("set_speed", "set_speed_and_dcm"):
                m.speed = self.speed
            m.after_ok(op, self.restored[1] if op == "set_state" else None)
            if op == "get_state":
                m.saved = list(range(len(self.states)))
            return
        out["illegal"] += not legal
        if status < 3:
            out["refusable_ok" if legal else "illegal_ok"].append(f"{op} in {before}")
        elif len(self.log.messages(3)) == n_logged:
            out["refused_unlogged"].append(f"{op} in {before}")
        m.after_error()

    def run(self) -> dict:
        from fmpy.fmi1 import FMICallException
        out = {"calls": 0, "illegal": 0, "illegal_ok": [], "refusable_ok": [], "refused_unlogged": [],
               "legal_not_ok": [], "ops": []}
        try:
            for k in range(len(self.prefix) + self.rng.randint(6, 30)):
                good = [op for op in self.ops if self.model.legal(op) and self.model.valid(op)]
                op = self.rng.choice(good) if self.rng.random() < 0.6 and good else self.rng.choice(self.ops)
                op = self.prefix[k] if k < len(self.prefix) else op
                n_logged = len(self.log.messages(3))
                try:
                    self.act(op)
                    status = 0
                except FMICallException as exc:
                    status = exc.status
                out["calls"] += 1
                self.judge(op, status, n_logged, out)
        finally:
            self.close()
        return out

    def close(self) -> None:
        from fmpy.fmi1 import FMICallException
        for s, _ in self.states:
            try:
                (self.f.freeFMUState if self.model.fmi == 3 else self.f.freeFMUstate)(s)
            except FMICallException:
                pass
        self.f.freeInstance()


class Log3:
    """The messages of an FMI 3.0 instance (fmpy's logMessage callback)."""

    def __init__(self):
        self.records = []

    def callback(self, env, status, category, message):
        self.records.append((int(status), message.decode() if message else ""))

    def messages(self, min_status=0):
        return [m for s, m in self.records if s >= min_status]


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
        print(json.dumps([kind, seed, Order(path, kind, seed).run()]), flush=True)


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


def test_model_is_the_standards_table():
    """The model's rows against cells of the standards' tables read off the documents (FMI 2.0.4 4.2.4's table,
    FMI 3.0.2 2.3): fmi2SetFMUstate allowed in terminated and error, fmi2GetReal not in instantiated, fmi2DoStep
    only in stepComplete; fmi3GetFloat64 in Instantiated and Terminated, fmi3SetFMUState in Terminated, no
    fmi3Set{Type} in Terminated; FMI 2.0 errors lead to error (terminated stays), FMI 3.0 errors to Terminated."""
    assert {TERM, ERR} <= FMI2["fmu_state"] and INST not in FMI2["get"] and FMI2["doStep"] == {STEP}
    assert {INST, TERM} <= FMI3["get"] and TERM in FMI3["fmu_state"] and TERM not in FMI3["set_input"]
    for fmi, state, after in ((2, STEP, ERR), (2, INIT, ERR), (2, TERM, TERM), (3, INST, TERM), (3, STEP, TERM)):
        m = Model(fmi, "native", state)
        m.after_error()
        assert m.state == after


def test_random_call_orders_follow_the_fmi_state_machine(tmp_path):
    """100 random call orders per FMU (native C FMI 2.0 and FMI 3.0, pythonfmu with its native layer): 0 calls out
    of order or with wrong arguments answered OK, each refusal logged, 0 calls allowed and valid refused, 0 crashes;
    the orders reach every state of the standard's table."""
    from rwadist.fmu.build import build_fmu
    from rwadist.fmu.native_build import build_native_fmu
    from rwadist.presets import preset
    first = int(os.environ.get("RWADIST_FUZZ_SEED", random.SystemRandom().randrange(1_000_000)))
    print(f"first seed {first} (RWADIST_FUZZ_SEED={first} replays these orders)")
    model = preset("ithaco-e").to_model()
    fmus = {"native": str(build_native_fmu(model, tmp_path / "sm_c.fmu", windows=False)),
            "native3": str(build_native_fmu(model, tmp_path / "sm_c3.fmu", fmi_version=3, windows=False)),
            "python": str(build_fmu(model, tmp_path / "sm_py.fmu"))}
    res = run_orders(fmus, 100, tmp_path, first)
    assert not res["crashes"], (first, res["crashes"])
    for kind, orders in res["results"].items():
        assert len(orders) == 100
        calls = sum(r["calls"] for r in orders.values())
        illegal = sum(r["illegal"] for r in orders.values())
        bad = {k: [(seed, x) for seed, r in orders.items() for x in r[k]]
               for k in ("illegal_ok", "refusable_ok", "refused_unlogged", "legal_not_ok")}
        reached = {op.split("@")[1].split(":")[0] for r in orders.values() for op in r["ops"]}
        print(f"{kind}: {len(orders)} orders, {calls} calls, {illegal} out of order: "
              + ", ".join(f"{k} {len(v)}" for k, v in bad.items()) + f"; states reached {sorted(reached)}")
        assert not any(bad.values()), (f"RWADIST_FUZZ_SEED={first}", {k: v[:5] for k, v in bad.items()})
        assert illegal > 200
        assert reached == (ALL3 if kind == "native3" else ALL2)
