"""Drive the wheel FMU (or any FMU with one real input) in two FMI hosts: fmpy and libcosim.

Self-contained (numpy + the host package only; no rwadist, no other module of this package), so
it also runs as a script in a fresh virtual environment (tests/test_fmu.py copies it there).

Each run steps the FMU as a co-simulation master does: at every communication point t_n set
the inputs, ``doStep(t_n, h)``, read all outputs.  Returns (n+1, n_outputs) with row 0 the
outputs after initialisation.
"""
from __future__ import annotations

import math
import shutil

import numpy as np


class HostLog:
    """Collects (instance, status, category, message) of an fmpy FMU's logger callback."""

    def __init__(self):
        self.records = []

    def callbacks(self):
        from fmpy import calloc, free
        from fmpy.fmi2 import (
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
        )

        def log(env, instance, status, category, message):
            self.records.append((instance.decode() if instance else "", int(status),
                                 category.decode() if category else "", message.decode() if message else ""))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(log)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._keep = cb
        return cb

    def messages(self, min_status=0):
        return [r[3] for r in self.records if r[1] >= min_status]


def _describe(path):
    from fmpy import read_model_description
    md = read_model_description(path)
    return md, {v.name: v for v in md.modelVariables}


class FmpyInstance:
    """One instance of an FMU in fmpy (FMU2Slave), set up to the end of initialisation
    (``exit_init=False``: left in initialisation mode, parameters and inputs set)."""

    def __init__(self, path, name, params=None, inputs=None, log: HostLog | None = None, unzipdir=None,
                 exit_init=True):
        from fmpy import extract
        from fmpy.fmi2 import FMU2Slave
        self.md, self.vars = _describe(path)
        # an FMU this instance unpacked itself is removed again on close (fmpy's extract() leaves it in the
        # temporary folder: one ~0.6 MB folder per instance otherwise accumulates over a test session)
        self._own_unzipdir = unzipdir is None
        self.unzipdir = unzipdir or extract(path)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.log = log
        self.fmu.instantiate(callbacks=log.callbacks() if log else None, loggingOn=log is not None)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in (params or {}).items():
            self.set(k, v)
        for k, v in (inputs or {}).items():
            self.set(k, v)
        if exit_init:
            self.fmu.exitInitializationMode()
        self.outputs = [v.valueReference for v in self.md.modelVariables if v.causality == "output"]
        self.output_names = [v.name for v in self.md.modelVariables if v.causality == "output"]

    def set(self, name, value):
        v = self.vars[name]
        vr = [v.valueReference]
        if v.type == "Real":
            self.fmu.setReal(vr, [float(value)])
        elif v.type == "Integer":
            self.fmu.setInteger(vr, [int(value)])
        elif v.type == "Boolean":
            self.fmu.setBoolean(vr, [bool(value)])
        else:
            self.fmu.setString(vr, [str(value)])

    def get(self):
        return self.fmu.getReal(self.outputs)

    def close(self):
        """Terminate (where FMI allows it: an instance stepping) and free the instance."""
        from fmpy.fmi1 import FMICallException
        try:
            self.fmu.terminate()
        except FMICallException:    # not stepping (initialisation failed or never ended): nothing to terminate
            pass
        finally:
            self.fmu.freeInstance()
            if self._own_unzipdir:
                shutil.rmtree(self.unzipdir, ignore_errors=True)


def run_fmpy(path, t, inputs, params=None, name="wheel"):
    """Step one instance through uniform times ``t`` with ``inputs`` = {name: array per sample}."""
    return run_fmpy_many(path, t, [(name, inputs, params)])[0]


def run_fmpy_many(path_or_paths, t, instances):
    """Several instances in one process, stepped in lockstep; ``instances`` = [(name, inputs,
    params)], ``path_or_paths`` one FMU for all or one per instance.  Returns a list of arrays."""
    t = np.asarray(t, dtype=float)
    h = (t[-1] - t[0]) / (t.size - 1)
    paths = path_or_paths if isinstance(path_or_paths, (list, tuple)) else [path_or_paths] * len(instances)
    insts, outs = [], []
    try:
        for p, (name, inputs, params) in zip(paths, instances):
            first = {k: np.asarray(v, dtype=float)[0] for k, v in inputs.items()}
            insts.append(FmpyInstance(p, name, params, first))
        for inst in insts:
            outs.append(np.empty((t.size, len(inst.outputs))))
            outs[-1][0] = inst.get()
        series = [{inst.vars[k].valueReference: np.asarray(v, dtype=float) for k, v in inputs.items()}
                  for inst, (_, inputs, _) in zip(insts, instances)]
        for n in range(t.size - 1):
            tn = t[0] + n * h
            for inst, ser, out in zip(insts, series, outs):
                vrs = list(ser)
                inst.fmu.setReal(vrs, [float(ser[vr][n]) for vr in vrs])
                inst.fmu.doStep(tn, h)
                out[n + 1] = inst.fmu.getReal(inst.outputs)
    finally:
        for inst in insts:
            inst.close()
    return outs


def run_libcosim(path, t, inputs, params=None, name="wheel"):
    """One instance in libcosim (libcosimpy): override manipulator sets the inputs before each
    step, last-value observer reads the outputs.  Step sizes are integer nanoseconds, so h must
    be a whole number of ns."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    t = np.asarray(t, dtype=float)
    h = (t[-1] - t[0]) / (t.size - 1)
    h_ns = int(round(h * 1e9))
    if abs(h_ns - h * 1e9) > 1e-6 * h * 1e9:
        raise ValueError(f"libcosim needs a whole number of nanoseconds per step, got {h!r} s")
    log_output_level(CosimLogLevel.WARNING)
    md, vars_ = _describe(path)
    ex = CosimExecution.from_step_size(step_size=h_ns)
    slave = CosimLocalSlave(fmu_path=str(path), instance_name=name)
    idx = ex.add_local_slave(local_slave=slave)
    for k, v in (params or {}).items():
        var = vars_[k]
        vr = var.valueReference
        if var.type == "Real":
            ex.real_initial_value(idx, vr, float(v))
        elif var.type == "Integer":
            ex.integer_initial_value(idx, vr, int(v))
        elif var.type == "Boolean":
            ex.boolean_initial_value(idx, vr, bool(v))
        else:
            ex.string_initial_value(idx, vr, str(v))
    ser = {vars_[k].valueReference: np.asarray(v, dtype=float) for k, v in inputs.items()}
    for vr, arr in ser.items():
        ex.real_initial_value(idx, vr, float(arr[0]))
    manip = CosimManipulator.create_override()
    ex.add_manipulator(manipulator=manip)
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
    out = np.full((t.size, len(outs)), math.nan)
    vrs = list(ser)
    for n in range(t.size - 1):
        manip.slave_real_values(idx, vrs, [float(ser[vr][n]) for vr in vrs])
        if not ex.step():
            raise RuntimeError(f"libcosim step {n} failed")
        out[n + 1] = obs.last_real_values(idx, outs)
    return out


if __name__ == "__main__":      # used by the fresh-venv test: python hosts.py FMU PROFILE.npz OUT.npz
    import sys
    fmu_path, prof, dest = sys.argv[1:4]
    d = np.load(prof)
    t, w, a = d["t"], d["omega"], d["alpha"]
    params = {"use_wheel_acceleration": True, "seed": int(d["seed"])}
    res = {"fmpy": run_fmpy(fmu_path, t, {"wheel_speed": w, "wheel_acceleration": a}, params)}
    try:
        res["libcosim"] = run_libcosim(fmu_path, t, {"wheel_speed": w, "wheel_acceleration": a}, params)
    except ImportError:
        pass
    try:
        import rwadist  # noqa: F401
        res["rwadist_importable"] = np.array(True)
    except ImportError:
        res["rwadist_importable"] = np.array(False)
    np.savez(dest, **res)
    print("host run ok:", ", ".join(k for k in res if k != "rwadist_importable"))
