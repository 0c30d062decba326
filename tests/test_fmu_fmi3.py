"""The FMI 3.0 native FMU (issue 35): the same model file and C kernel as the FMI 2.0 FMU, checked by fmpy (an
independent FMI 3.0 host and validator): validation with 0 problems, the FMI 3.0 binary folders, outputs equal to
the FMI 2.0 FMU's (every effect on, a mounting), FMU state get/set and serialize replaying a run bit for bit, the
FMI state machine (a call out of order is fmi3Error with a logged message) and `rwadist fmu build --fmi-version 3`."""
from __future__ import annotations

import os
import shutil
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rwadist.fmu import hosts
from rwadist.fmu.build import native_supported

pytest.importorskip("fmpy")
pytestmark = pytest.mark.skipif(not (native_supported() and shutil.which(os.environ.get("CC", "cc"))),
                                reason="the native FMU's binary is built on Linux x86-64 with a C compiler")

from rwadist.fmu.native_build import build_native_fmu  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fmu_native import mount_params, slope, spin_up, wheel_doc, worst  # noqa: E402

RPM = 2 * np.pi / 60


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """(FMI 2.0 FMU, FMI 3.0 FMU) of the wheel with every effect class, one model file."""
    d = tmp_path_factory.mktemp("fmi3")
    doc = wheel_doc()
    return (build_native_fmu(doc, d / "wheel2.fmu", windows=False),
            build_native_fmu(doc, d / "wheel3.fmu", fmi_version=3, windows=False))


class Fmi3:
    """One FMI 3.0 instance in fmpy (FMU3Slave) with a logger that keeps the messages."""

    def __init__(self, path, name, params=None, speed0=0.0, accel0=0.0):
        from fmpy import extract, read_model_description
        from fmpy.fmi3 import FMU3Slave
        self.md = read_model_description(path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.messages = []
        self.unzipdir = extract(path)
        self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(loggingOn=True, logMessage=self._log)
        self.outputs = [v.valueReference for v in self.md.modelVariables if v.causality == "output"]
        self.params = params or {}
        self.speed0, self.accel0 = speed0, accel0

    def _log(self, env, status, category, message):
        self.messages.append((int(status), message.decode() if message else ""))

    def errors(self):
        return [m for s, m in self.messages if s >= 3]

    def start(self):
        self.fmu.enterInitializationMode(startTime=0.0)
        for k, v in self.params.items():
            vr = [self.vars[k].valueReference]
            typ = self.vars[k].type
            if typ == "Boolean":
                self.fmu.setBoolean(vr, [bool(v)])
            elif typ == "Int32":
                self.fmu.setInt32(vr, [int(v)])
            else:
                self.fmu.setFloat64(vr, [float(v)])
        self.fmu.setFloat64([self.vars["wheel_speed"].valueReference, self.vars["wheel_acceleration"].valueReference],
                            [float(self.speed0), float(self.accel0)])
        self.fmu.exitInitializationMode()
        return self

    def steps(self, t0, h, w, a=None):
        out = []
        for n, wn in enumerate(w):
            vrs, vals = [0], [float(wn)]
            if a is not None:
                vrs, vals = [0, 1], [float(wn), float(a[n])]
            self.fmu.setFloat64(vrs, vals)
            self.fmu.doStep(t0 + n * h, h)
            out.append(self.fmu.getFloat64(self.outputs))
        return np.array(out)

    def close(self):
        try:
            self.fmu.terminate()
        except Exception:       # noqa: BLE001 -- not stepping: nothing to terminate
            pass
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)      # fmpy's extract() leaves it in the temp folder


def test_fmi3_validates_with_its_binary_folders(fmus):
    """fmpy validates the FMI 3.0 FMU with 0 problems; binaries in x86_64-linux (x86_64-windows: test_fmu_win64.py),
    the build description in sources/, the FMI 2.0 FMU's variables and value references."""
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu
    f2, f3 = fmus
    problems = validate_fmu(str(f3))
    print("fmpy validate (FMI 3.0):", problems)
    assert problems == []
    names = zipfile.ZipFile(f3).namelist()
    md3 = read_model_description(str(f3))
    ident = md3.coSimulation.modelIdentifier
    assert f"binaries/x86_64-linux/{ident}.so" in names and "sources/buildDescription.xml" in names
    assert md3.fmiVersion == "3.0" and md3.coSimulation.canGetAndSetFMUstate and md3.coSimulation.canSerializeFMUstate
    v2 = {v.name: (v.valueReference, v.causality, v.variability, v.start) for v in read_model_description(str(f2))
          .modelVariables}
    v3 = {v.name: (v.valueReference, v.causality, v.variability, v.start) for v in md3.modelVariables}
    assert v3.pop("time")[1] == "independent"
    assert v3 == v2


@pytest.mark.parametrize("profile", [spin_up])
def test_fmi3_outputs_equal_fmi2(fmus, profile):
    """Spin-up 0→3000 rpm with every effect on, a mounting, a seed and the acceleration input: the FMI 3.0 FMU's 12
    outputs equal the FMI 2.0 FMU's (the same kernel) to 1e-12 of each channel's peak (in fact bit for bit)."""
    f2, f3 = fmus
    t, w = profile(T=1.0)
    a = slope(t, w)
    ref = hosts.run_fmpy(f2, t, {"wheel_speed": w, "wheel_acceleration": a}, mount_params(5))
    inst = Fmi3(f3, "w3", mount_params(5), w[0], a[0]).start()
    try:
        got = np.vstack([inst.fmu.getFloat64(inst.outputs), inst.steps(0.0, t[1] - t[0], w[:-1], a[:-1])])
    finally:
        inst.close()
    err = worst(got, ref)
    print(f"FMI 3.0 vs FMI 2.0, every effect: max rel. error {np.max(err):.3g}")
    assert np.max(err) <= 1e-12


def test_fmi3_state_round_trip_bit_for_bit(fmus):
    """State at 0.2 s: set back, the replay is bit-identical; serialized and deserialized into a second instance
    (other parameters), the same."""
    _, f3 = fmus
    h = 1e-3
    w = 300 * RPM * np.sin(np.linspace(0, 3, 600))
    a = Fmi3(f3, "a", {"seed": 11}, w[0]).start()
    b = Fmi3(f3, "b", {"seed": 2, "modes": False}).start()
    try:
        a.steps(0.0, h, w[:200])
        state = a.fmu.getFMUState()
        blob = a.fmu.serializeFMUState(state)
        first = a.steps(200 * h, h, w[200:])
        a.fmu.setFMUState(state)
        again = a.steps(200 * h, h, w[200:])
        assert np.array_equal(first, again)
        s2 = b.fmu.deserializeFMUState(blob)
        b.fmu.setFMUState(s2)
        other = b.steps(200 * h, h, w[200:])
        assert np.array_equal(first, other)
        a.fmu.freeFMUState(state)
        b.fmu.freeFMUState(s2)
    finally:
        a.close()
        b.close()


def test_fmi3_calls_out_of_order_are_errors(fmus):
    """FMI 3.0 state machine (section 2.3): the getters give the start values in Instantiated; a call out of order
    (exit initialisation without enter, a step before initialisation, enter twice, a fixed parameter after
    initialisation, event mode: there is none) is fmi3Error with a logged message saying what to do, and any
    fmi3Error moves the instance to Terminated (no step there); fmi3Reset, or fmi3SetFMUState with a state stored
    before the error (allowed in Terminated), lead on."""
    from fmpy.fmi1 import FMICallException
    _, f3 = fmus
    inst = Fmi3(f3, "order")
    f, v = inst.fmu, inst.vars

    def refused(call, *words):
        n = len(inst.errors())
        with pytest.raises(FMICallException) as exc:
            call()
        assert exc.value.status == 3 and len(inst.errors()) == n + 1, inst.errors()[-1:]
        assert all(w in inst.errors()[-1] for w in words), inst.errors()[-1]

    try:
        start = f.getFloat64([v["wheel_speed"].valueReference, v["dcm_11"].valueReference, v["Fx_sc"]
                              .valueReference])
        assert start == [0.0, 1.0, 0.0]                         # start values, in Instantiated
        refused(f.exitInitializationMode, "is instantiated", "fmi3EnterInitializationMode")
        refused(lambda: f.doStep(0.0, 1e-3), "is terminated", "fmi3Reset", "after any error")
        assert np.all(np.isfinite(f.getFloat64(inst.outputs)))  # getters in Terminated
        f.reset()
        f.enterInitializationMode(startTime=0.0)
        refused(lambda: f.enterInitializationMode(startTime=0.0), "in initialization mode", "fmi3Reset")
        f.reset()
        f.enterInitializationMode(startTime=0.0)
        f.exitInitializationMode()
        f.setFloat64([0], [10.0])
        f.doStep(0.0, 1e-3)
        stored = f.getFMUState()
        y = f.getFloat64(inst.outputs)
        refused(lambda: f.setInt32([v["seed"].valueReference], [4]), "fixed parameters are set before",
                "fmi3ExitInitializationMode")
        for call in (f.enterEventMode, f.enterStepMode, f.terminate, lambda: f.doStep(1e-3, 1e-3)):
            refused(call)                                       # Terminated after the error: none of these
        f.setFMUState(stored)                                   # a stored state restores the run
        assert f.getFloat64(inst.outputs) == y
        f.setFloat64([0], [10.1])
        f.doStep(1e-3, 1e-3)
        f.terminate()
        refused(f.terminate, "is terminated")
        f.setFMUState(stored)                                   # also into a terminated instance
        f.doStep(1e-3, 1e-3)
        f.freeFMUState(stored)
        f.terminate()
        f.reset()
    finally:
        f.freeInstance()


def test_cli_fmi_version_3(tmp_path, capsys):
    """`rwadist fmu build --native --fmi-version 3` writes the FMI 3.0 FMU; `rwadist fmu check` runs it; the
    pythonfmu FMU has no FMI 3.0 and says so."""
    from fmpy import read_model_description

    from rwadist.cli import main
    out = tmp_path / "w3.fmu"
    assert main(["fmu", "build", "--native", "--fmi-version", "3", "--preset", "ithaco-e", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "FMI 3.0" in text and "x86_64-linux" in text
    assert read_model_description(str(out)).fmiVersion == "3.0"
    assert main(["fmu", "check", str(out), "--stop-time", "0.5"]) == 0
    text = capsys.readouterr().out
    assert "fmpy validation: 0 problem(s)" in text and "missing input" not in text.lower()
    assert main(["fmu", "build", "--fmi-version", "3", "-o", str(tmp_path / "p.fmu")]) == 2
    assert "--fmi-version" in capsys.readouterr().err
