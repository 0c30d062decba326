"""The pythonfmu FMU (the default of ``rwadist fmu build``) under a memory checker, on every exit path (issue 17).

Hosts: fmpy (the slave runs in the host's own interpreter) and the C hosts of rwadist/fmu/native (no Python of their own:
pythonfmu starts an interpreter in the process; libpython is preloaded, the resource location is a file:// URI).

* valgrind memcheck over fmpy: instantiate, setup, initialise, steps, terminate, free; reset and a second run;
  refused inputs (a non-finite speed, a communication point that goes backwards or is NaN, a negative step,
  unknown value references); the refused FMU-state calls; free without terminate; free before initialisation;
  then process exit with every instance of one FMU freed and two instances of a second FMU still alive.  No
  invalid read, write or free may be reported (rwadist/fmu/native/valgrind-host.supp lists the one loader report
  suppressed, and why); an overflow planted through ctypes shows the checker is live.  Before the fix in
  rwadist/fmu/slave.py (_guard_pythonfmu_exit) valgrind reported pythonfmu's exit-time use-after-free here: "Invalid
  read of size 4 at finalizePythonInterpreter ... 8 bytes inside a block of size 128 free'd".
* The same exit in the C hosts aborted with ``free(): corrupted unsorted chunks`` (3 of 3 runs without
  PYTHONPATH; with it the corruption stayed silent): c_host steps the pythonfmu FMU, must exit 0 with fmpy's
  outputs, and under memcheck report no invalid read, write or free; c_stress must pass every check (GUID
  refusal, refused state calls, bad inputs, reset) and exit 0.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")

from rwadist import model as model_io  # noqa: E402
from rwadist.fmu.build import build_fmu, native_supported  # noqa: E402
from rwadist.presets import preset  # noqa: E402

NATIVE = Path(__file__).resolve().parents[1] / "rwadist" / "fmu" / "native"
SUPPRESSIONS = NATIVE / "valgrind-host.supp"
CC = shutil.which(os.environ.get("CC", "cc"))
#: kinds of memcheck report that are heap corruption (addressability and allocation errors)
INVALID = re.compile(r"^(Invalid (read|write|free)|Mismatched free|Source and destination overlap)")
PLANTED_SIZE = 13   # the planted overflow's block size (unique in the report)

DRIVER = r'''
import ctypes, sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2FMUstate

def open_fmu(path, name):
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    return fmu, vr, [v.valueReference for v in md.modelVariables if v.causality == "output"]

def start(fmu, vr):
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([vr["wheel_speed"]], [100.0])
    fmu.exitInitializationMode()

def steps(fmu, outs, n, t=0.0):
    for k in range(n):
        fmu.doStep(t + k * 1e-3, 1e-3)
        fmu.getReal(outs)
    return t + n * 1e-3

def refused(call, *args):
    try:
        call(*args)
    except Exception:
        return
    raise SystemExit(f"{call.__name__}{args} was accepted")

fmu, vr, outs = open_fmu(sys.argv[1], "freed")
start(fmu, vr); steps(fmu, outs, 5); fmu.terminate(); fmu.fmi2FreeInstance(fmu.component)       # normal
start(fmu, vr); steps(fmu, outs, 3); fmu.reset()                                                  # reset
fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
steps(fmu, outs, 3); fmu.terminate(); fmu.fmi2FreeInstance(fmu.component)
start(fmu, vr); t = steps(fmu, outs, 3)                                                           # bad input
fmu.setReal([vr["wheel_speed"]], [float("nan")]); refused(fmu.doStep, t, 1e-3)
refused(fmu.setReal, [vr["wheel_speed"]], [100.0])                                                # error state
refused(fmu.doStep, t - 1e-3, 1e-3); refused(fmu.doStep, float("nan"), 1e-3); refused(fmu.doStep, t, -1.0)
refused(fmu.getReal, [99999]); refused(fmu.setReal, [99999], [1.0])
fmu.reset(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode()                    # error state:
fmu.setReal([vr["wheel_speed"]], [100.0]); fmu.exitInitializationMode(); steps(fmu, outs, 2)     # a new run
refused(fmu.getFMUstate); refused(fmu.setFMUstate, fmi2FMUstate())                               # FMU state
refused(fmu.serializeFMUstate, fmi2FMUstate()); refused(fmu.deSerializeFMUstate, bytes(16))
refused(fmu.terminate); fmu.fmi2FreeInstance(fmu.component)                                       # (error state)
start(fmu, vr); steps(fmu, outs, 3); fmu.fmi2FreeInstance(fmu.component)                          # no terminate
fmu.instantiate(); fmu.fmi2FreeInstance(fmu.component)                                            # uninitialised

other, vr2, outs2 = open_fmu(sys.argv[2], "alive")                                                # alive at exit
start(other, vr2); steps(other, outs2, 3)
start(other, vr2); steps(other, outs2, 2)

libc = ctypes.CDLL(None)                                                                          # planted
libc.malloc.restype, libc.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
block = libc.malloc(%d)
ctypes.string_at(block, %d + 8)
print("done", flush=True)
''' % (PLANTED_SIZE, PLANTED_SIZE)


def _wheel_doc():
    return model_io.to_json(preset("ithaco-e").to_model())


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """Two default builds (the native layer where it compiles) of the E wheel: (FMU whose instances are all freed
    before exit, FMU whose instances are alive at exit)."""
    d = tmp_path_factory.mktemp("heap")
    return build_fmu(_wheel_doc(), d / "freed.fmu"), build_fmu(_wheel_doc(), d / "alive.fmu")


def memcheck_reports(log: str) -> list[str]:
    """The error reports of a valgrind log (each: its lines, without the ``==pid==`` prefix)."""
    reports = []
    for block in re.split(r"\n==\d+== \n", log):
        lines = [re.sub(r"^==\d+== ?", "", ln) for ln in block.splitlines()]
        if lines and INVALID.match(lines[0] if not lines[0].startswith("Memcheck") else ""):
            reports.append("\n".join(lines))
        elif any(INVALID.match(ln) for ln in lines):
            at = next(i for i, ln in enumerate(lines) if INVALID.match(ln))
            reports.append("\n".join(lines[at:]))
    return reports


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_fmpy_host_under_valgrind_every_exit_path(fmus, tmp_path):
    log = tmp_path / "memcheck.log"
    # PYTHONMALLOC=malloc: every Python object is a malloc block memcheck tracks; --undef-value-errors=no: the
    # reports asked for are heap corruption (addressability, frees), and this halves the run time
    cmd = ["valgrind", "--tool=memcheck", "--undef-value-errors=no", "--num-callers=30", f"--log-file={log}",
           f"--suppressions={SUPPRESSIONS}", sys.executable, "-c", DRIVER, str(fmus[0]), str(fmus[1])]
    env = dict(os.environ, PYTHONMALLOC="malloc", OMP_NUM_THREADS="1")
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env)
    text = log.read_text()
    assert res.returncode == 0 and "done" in res.stdout, res.stdout + res.stderr[-3000:] + text[-3000:]
    reports = memcheck_reports(text)
    planted = [r for r in reports if f"block of size {PLANTED_SIZE} alloc'd" in r]
    others = [r for r in reports if r not in planted]
    assert planted, "the planted overflow was not reported: is memcheck live?\n" + text[-3000:]
    assert others == [], "\n\n".join(others)[:8000]


def _libpython() -> str | None:
    """The shared libpython this interpreter runs on (a C host preloads it for pythonfmu), or None."""
    name = sysconfig.get_config_var("INSTSONAME")
    path = Path(sysconfig.get_config_var("LIBDIR") or "") / (name or "")
    return str(path) if name and sysconfig.get_config_var("Py_ENABLE_SHARED") and path.is_file() else None


def _c_host_env() -> dict:
    """The environment of a C host that runs the pythonfmu FMU: libpython preloaded, this interpreter's
    import path (numpy) for the interpreter pythonfmu starts."""
    return dict(os.environ, LD_PRELOAD=_libpython(), OMP_NUM_THREADS="1",
                PYTHONPATH=os.pathsep.join(p for p in sys.path if p))


c_hosts = pytest.mark.skipif(not (native_supported() and CC and _libpython()),
                             reason="the C hosts need Linux x86-64, a C compiler and a shared libpython")


def _unpack(fmu: Path, into: Path) -> tuple[Path, str, Path]:
    from fmpy import read_model_description
    md = read_model_description(fmu)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(into)
    return into, md.guid, into / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"


def _cc(args):
    res = subprocess.run([CC, *args], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr


@c_hosts
def test_c_host_steps_the_pythonfmu_fmu_and_exits_cleanly(fmus, tmp_path):
    """c_host (no Python of its own) steps the pythonfmu FMU over a speed ramp; its outputs equal fmpy's on the
    same inputs, and the process exits 0 (before: ``free(): corrupted unsorted chunks``, exit 134)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    folder, guid, lib = _unpack(fmus[0], tmp_path / "x")
    host = tmp_path / "c_host"
    _cc(["-O2", f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_host.c"), "-ldl"])
    n, h, w0, w1 = 200, 1e-3, 100.0, 140.0
    res = subprocess.run([str(host), str(lib), guid, str(n), str(h), str(w0), str(w1),
                          f"resources={(folder / 'resources').as_uri()}"],
                         capture_output=True, text=True, timeout=300, env=_c_host_env())
    assert res.returncode == 0, res.stderr[-3000:]
    assert "corrupted" not in res.stderr and "free()" not in res.stderr, res.stderr[-3000:]
    y_c = np.array([float(v) for v in res.stdout.split()])

    md = read_model_description(fmus[0])
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmus[0]), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="fmpy")
    out_vr = list(range(26, 38))
    assert [v.name for v in md.modelVariables if v.valueReference in out_vr][:2] == ["Fx", "Fy"]
    slope = (w1 - w0) / (n * h)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([0, 1], [w0, slope])
    fmu.exitInitializationMode()
    for k in range(n):
        fmu.setReal([0, 1], [w0 + (w1 - w0) * k / n, slope])
        fmu.doStep(k * h, h)
    y_fmpy = np.array(fmu.getReal(out_vr))
    fmu.terminate()
    fmu.freeInstance()
    assert y_c.shape == (12,) and np.any(y_c != 0.0)
    np.testing.assert_array_equal(y_c, y_fmpy)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
@c_hosts
def test_c_host_under_valgrind(fmus, tmp_path):
    """c_host (20 steps, then terminate, free, dlclose and exit; pythonfmu starts and ends the interpreter) under
    memcheck: no invalid read, write or free (before the fix: pythonfmu's "Invalid read of size 4 at
    finalizePythonInterpreter", the same exit that aborts with ``free(): corrupted unsorted chunks``)."""
    folder, guid, lib = _unpack(fmus[0], tmp_path / "x")
    host, log = tmp_path / "c_host", tmp_path / "memcheck.log"
    _cc(["-O1", "-g", f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_host.c"), "-ldl"])
    cmd = ["valgrind", "--tool=memcheck", "--undef-value-errors=no", "--num-callers=30", f"--log-file={log}",
           f"--suppressions={SUPPRESSIONS}", str(host), str(lib), guid, "20", "1e-3", "100", "101",
           f"resources={(folder / 'resources').as_uri()}"]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900,
                         env=dict(_c_host_env(), PYTHONMALLOC="malloc"))
    text = log.read_text()
    assert res.returncode == 0 and len(res.stdout.split()) == 12, res.stderr[-3000:] + text[-3000:]
    reports = memcheck_reports(text)
    assert reports == [], "\n\n".join(reports)[:8000]
    assert "ERROR SUMMARY: 0 errors" in text


@c_hosts
def test_c_stress_host_passes_every_check_on_the_pythonfmu_fmu(fmus, tmp_path):
    """c_stress on the pythonfmu FMU (its state calls must be refused): wrong GUID refused, bad inputs refused
    with fmi2Error, reset, free; 3 cycles, 0 failed checks, exit 0."""
    folder, guid, lib = _unpack(fmus[0], tmp_path / "x")
    host = tmp_path / "c_stress"
    _cc(["-O1", f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_stress.c"), "-ldl", "-lm"])
    res = subprocess.run([str(host), str(lib), guid, "3", "0", "-1", (folder / "resources").as_uri()],
                         capture_output=True, text=True, timeout=600, env=_c_host_env())
    assert res.returncode == 0, res.stdout + res.stderr[-3000:]
    checks, failures = (int(v) for v in res.stdout.split()[1:4:2])
    assert failures == 0 and checks > 3 * 300, res.stdout
