"""Both FMUs (pythonfmu and native C) against the FMI time rules, non-finite results and FMU state (issue 17):

* a communication point must be the previous one plus the previous step: one that goes backwards, is NaN, skips
  ahead or jumps by 1e9 s is refused with fmi2Error (logged), the outputs keep their values, the instance is in
  FMI 2.0's error state (a step at the right point is refused too) and a stored FMU state (native FMU) or a reset
  (both) lead on;
* outputs that are not finite are never reported with fmi2OK (an initial speed of 1e300 rad/s; a step to a speed
  whose Ω² overflows);
* FMU state: the capability flags of the modelDescription and the behaviour agree -- the native FMU declares and
  supports it (replay tests in test_fmu_native.py), the pythonfmu FMU declares it unsupported and refuses every
  state call with fmi2Error (its native layer), fmi2SetFMUstate(NULL) included.
"""
from __future__ import annotations

import ctypes
import os
import shutil

import numpy as np
import pytest

from rwadist.fmu import hosts
from rwadist.fmu.build import build_fmu, has_native, native_supported
from rwadist.presets import preset

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")
pytestmark = pytest.mark.skipif(not (native_supported() and shutil.which(os.environ.get("CC", "cc"))),
                                reason="fmi2Error from both FMUs needs their native layers (Linux x86-64, a C compiler)")

from fmpy.fmi1 import FMICallException  # noqa: E402

from rwadist.fmu.native_build import build_native_fmu  # noqa: E402

ERROR = 3


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """{"python": pythonfmu FMU, "native": native C FMU} of the E-wheel preset."""
    d = tmp_path_factory.mktemp("safety")
    doc = preset("ithaco-e").to_model()
    out = {"python": build_fmu(doc, d / "py.fmu"), "native": build_native_fmu(doc, d / "c.fmu", windows=False)}
    assert has_native(out["python"])
    return out


KINDS = ["python", "native"]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("case", ["backwards", "nan", "skips_ahead", "jump_1e9", "inf"])
def test_communication_point_must_continue(fmus, kind, case):
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(fmus[kind], "t", {}, {"wheel_speed": 100.0}, log=log)
    try:
        h = 1e-3
        for n in range(3):
            inst.fmu.doStep(n * h, h)
        y = inst.get()
        stored = inst.fmu.getFMUstate() if kind == "native" else None
        t = {"backwards": 1 * h, "nan": float("nan"), "skips_ahead": 4 * h, "jump_1e9": 3 * h + 1e9,
             "inf": float("inf")}[case]
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(t, h)
        assert exc.value.status == ERROR
        assert any("does not continue the last step" in m for m in log.messages(ERROR)), log.records
        assert inst.get() == y
        with pytest.raises(FMICallException):
            inst.fmu.doStep(3 * h, h)        # FMI 2.0: after fmi2Error the instance is in the error state
        assert "in the error state" in log.messages(ERROR)[-1], log.records[-1]
        if kind == "native":                 # a state stored before the error restores the run
            inst.fmu.setFMUstate(stored)
            inst.fmu.doStep(3 * h, h)
        else:                                # no FMU state: a reset starts a new run
            inst.fmu.reset()
            inst.fmu.setupExperiment(startTime=0.0)
            inst.fmu.enterInitializationMode()
            inst.set("wheel_speed", 100.0)
            inst.fmu.exitInitializationMode()
            inst.fmu.doStep(0.0, h)
        assert all(np.isfinite(inst.get())) and inst.get() != y
    finally:
        inst.close()


@pytest.mark.parametrize("kind", KINDS)
def test_start_time_is_the_first_communication_point(fmus, kind):
    """fmi2SetupExperiment(startTime = 2.5): the first step starts there, not at 0."""
    log = hosts.HostLog()
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    md = fmpy.read_model_description(fmus[kind])
    u = extract(fmus[kind])
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=u, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="t0")
    fmu.instantiate(callbacks=log.callbacks(), loggingOn=True)
    try:
        fmu.setupExperiment(startTime=2.5)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        with pytest.raises(FMICallException):
            fmu.doStep(0.0, 1e-3)
        fmu.reset()                     # the refusal put it in the error state: a new run
        fmu.setupExperiment(startTime=2.5)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(2.5, 1e-3)
        fmu.doStep(2.501, 1e-3)
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(u, ignore_errors=True)


@pytest.mark.parametrize("kind", KINDS)
def test_initial_speed_with_non_finite_outputs_is_an_error(fmus, kind):
    """wheel_speed 1e300 rad/s at initialisation: Ω² overflows.  Either initialisation is fmi2Error (outputs not
    finite) or its outputs are finite (at rest the suspension reactions are 0) and the first step is fmi2Error:
    never outputs of inf or NaN with fmi2OK."""
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(fmus[kind], "init", {}, {"wheel_speed": 1e300}, log=log, exit_init=False)
    try:
        try:
            inst.fmu.exitInitializationMode()
            initialised = True
        except FMICallException as refused:
            assert refused.status == ERROR
            assert any("not finite" in m for m in log.messages(ERROR)), log.records
            initialised = False
        assert all(np.isfinite(inst.get()))
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(0.0, 1e-3)
        assert exc.value.status == ERROR
        if initialised:
            assert any("non-finite output" in m for m in log.messages(ERROR)), log.records
        assert all(np.isfinite(inst.get()))
    finally:
        inst.close()


@pytest.mark.parametrize("kind", KINDS)
def test_step_with_non_finite_outputs_is_an_error(fmus, kind):
    """max_acceleration 1e300 lets the speed reach 1e160 rad/s in one step: Ω² = inf; that step is fmi2Error and the
    outputs keep their last finite values."""
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(fmus[kind], "huge", {"max_acceleration": 1e300}, {"wheel_speed": 0.0}, log=log)
    try:
        inst.fmu.doStep(0.0, 1e-3)
        y = inst.get()
        inst.set("wheel_speed", 1e160)
        with pytest.raises(FMICallException) as exc:
            inst.fmu.doStep(1e-3, 1e-3)
        assert exc.value.status == ERROR
        assert any("non-finite output" in m for m in log.messages(ERROR)), log.records
        assert inst.get() == y and all(np.isfinite(y))
    finally:
        inst.close()


def test_pythonfmu_fmu_state_flags_false_and_every_state_call_refused(fmus):
    """The pythonfmu FMU saves no modal or phase state: its modelDescription says canGetAndSetFMUstate and
    canSerializeFMUstate false, and each state call -- get, set (also NULL), size, serialize, deserialize -- is
    fmi2Error with a logged message (the instance then in FMI 2.0's error state, a reset leading on); freeing no
    state is a no-op."""
    md = fmpy.read_model_description(fmus["python"])
    assert md.coSimulation.canGetAndSetFMUstate is False and md.coSimulation.canSerializeFMUstate is False
    log = hosts.HostLog()
    inst = hosts.FmpyInstance(fmus["python"], "state", {}, {"wheel_speed": 100.0}, log=log)
    f = inst.fmu
    try:
        f.doStep(0.0, 1e-3)
        state = ctypes.c_void_p()
        size = ctypes.c_size_t(7)
        buf = (ctypes.c_char * 64)()
        calls = {
            "fmi2GetFMUstate": lambda: f.fmi2GetFMUstate(f.component, ctypes.byref(state)),
            "fmi2SetFMUstate": lambda: f.fmi2SetFMUstate(f.component, None),
            "fmi2SerializedFMUstateSize": lambda: f.fmi2SerializedFMUstateSize(f.component, None, ctypes.byref(size)),
            "fmi2SerializeFMUstate": lambda: f.fmi2SerializeFMUstate(f.component, None, buf, 64),
            "fmi2DeSerializeFMUstate": lambda: f.fmi2DeSerializeFMUstate(f.component, buf, 64, ctypes.byref(state)),
        }
        for name, call in calls.items():
            with pytest.raises(FMICallException) as exc:
                call()
            assert exc.value.status == ERROR, name
            assert any(m.startswith(name) and "does not support FMU state" in m for m in log.messages(ERROR)), name
        assert state.value is None and size.value == 0
        assert f.fmi2FreeFMUstate(f.component, ctypes.byref(ctypes.c_void_p())) == 0
        with pytest.raises(FMICallException):
            f.doStep(1e-3, 1e-3)             # the refusals put it in FMI 2.0's error state: a reset leads on
        f.reset()
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
        inst.set("wheel_speed", 100.0)
        f.exitInitializationMode()
        f.doStep(0.0, 1e-3)
        assert all(np.isfinite(inst.get()))
    finally:
        inst.close()


def test_native_fmu_state_flags_true(fmus):
    md = fmpy.read_model_description(fmus["native"])
    assert md.coSimulation.canGetAndSetFMUstate is True and md.coSimulation.canSerializeFMUstate is True
