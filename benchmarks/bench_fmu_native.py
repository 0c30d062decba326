"""Benchmark (issue 16): the native C wheel FMU.

1. fmpy stepping the native wheel FMU (E wheel, modes on, all 12 outputs read) vs a trivial C FMU
   (y_k = u, k = 0..11, compiled the same way: fmu.native_build.compile_sources) read once for one output (the
   first wave's comparison) and once for all 12 (the same fmpy marshalling as the wheel's), 60 s at 1 kHz each
   (set input, doStep, read outputs), interleaved repeats, best of each, wall and process-CPU time; ratio
   target <= 1.2.  The load average is printed with the figures (the machine may be shared).
2. The native step alone: a small C program (rwadist/fmu/native/c_host.c) dlopens the FMU's library and calls
   fmi2DoStep in a loop (speed ramp 0 -> 3000 rpm, acceleration input): steps per second for the E wheel
   with modes (target >= 1 M) and for the same with broadband floors on three channels (Fx, Fy, Fz,
   2-500 Hz at 0.1 Hz: 14 970 sinusoids; target >= 50 k).

Baselines printed in the same run: the pythonfmu FMU's figures of issue 16 (16.9 us per fmpy step,
1.9x a trivial pythonfmu FMU; 35 us with floors) and the target ratios.

    .venv/bin/python benchmarks/bench_fmu_native.py [--seconds 60] [--steps 2000000]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from rwadist import model as model_io
from rwadist.fmu.native_build import (
    FMI2_HEADERS,
    NATIVE,
    build_native_fmu,
    compile_c_host,
    compile_sources,
)
from rwadist.presets import preset

TRIVIAL_C = r'''
#include <stdlib.h>
#include <string.h>
#include "fmi2Functions.h"
typedef struct { double u, y, t; } Echo;
FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }
FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean o, size_t n, const fmi2String k[]) { return fmi2OK; }
FMI2_Export fmi2Component fmi2Instantiate(fmi2String n, fmi2Type t, fmi2String g, fmi2String r,
    const fmi2CallbackFunctions *f, fmi2Boolean v, fmi2Boolean l) { return calloc(1, sizeof(Echo)); }
FMI2_Export void fmi2FreeInstance(fmi2Component c) { free(c); }
FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean a, fmi2Real b, fmi2Real t0, fmi2Boolean d,
    fmi2Real e) { ((Echo *)c)->t = t0; return fmi2OK; }
FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return fmi2OK; }
FMI2_Export fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
FMI2_Export fmi2Status fmi2Reset(fmi2Component c) { memset(c, 0, sizeof(Echo)); return fmi2OK; }
FMI2_Export fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] > 12) return fmi2Error; v[i] = vr[i] ? ((Echo *)c)->y : ((Echo *)c)->u; }
    return fmi2OK; }
FMI2_Export fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    for (size_t i = 0; i < n; i++) { if (vr[i] != 0) return fmi2Error; ((Echo *)c)->u = v[i]; }
    return fmi2OK; }
FMI2_Export fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean p) {
    Echo *e = (Echo *)c; e->y = e->u; e->t = t + h; return fmi2OK; }
#define NO(name, ...) FMI2_Export fmi2Status name(fmi2Component c, __VA_ARGS__) { return fmi2Error; }
NO(fmi2GetInteger, const fmi2ValueReference vr[], size_t n, fmi2Integer v[])
NO(fmi2GetBoolean, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[])
NO(fmi2GetString, const fmi2ValueReference vr[], size_t n, fmi2String v[])
NO(fmi2SetInteger, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[])
NO(fmi2SetBoolean, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[])
NO(fmi2SetString, const fmi2ValueReference vr[], size_t n, const fmi2String v[])
NO(fmi2GetFMUstate, fmi2FMUstate *s)
NO(fmi2SetFMUstate, fmi2FMUstate s)
NO(fmi2FreeFMUstate, fmi2FMUstate *s)
NO(fmi2SerializedFMUstateSize, fmi2FMUstate s, size_t *n)
NO(fmi2SerializeFMUstate, fmi2FMUstate s, fmi2Byte b[], size_t n)
NO(fmi2DeSerializeFMUstate, const fmi2Byte b[], size_t n, fmi2FMUstate *s)
NO(fmi2GetDirectionalDerivative, const fmi2ValueReference u[], size_t nu, const fmi2ValueReference z[], size_t nz,
   const fmi2Real dv[], fmi2Real dz[])
NO(fmi2SetRealInputDerivatives, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], const fmi2Real v[])
NO(fmi2GetRealOutputDerivatives, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[], fmi2Real v[])
FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c) { return fmi2Error; }
NO(fmi2GetStatus, const fmi2StatusKind k, fmi2Status *v)
NO(fmi2GetRealStatus, const fmi2StatusKind k, fmi2Real *v)
NO(fmi2GetIntegerStatus, const fmi2StatusKind k, fmi2Integer *v)
NO(fmi2GetBooleanStatus, const fmi2StatusKind k, fmi2Boolean *v)
NO(fmi2GetStringStatus, const fmi2StatusKind k, fmi2String *v)
'''

_TRIVIAL_OUTPUTS = "\n".join(f'    <ScalarVariable name="y{k}" valueReference="{k + 1}" causality="output" '
                             'variability="continuous" initial="exact"><Real start="0"/></ScalarVariable>'
                             for k in range(12))
TRIVIAL_MD = f'''<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="TrivialEchoC" guid="{{trivial-echo-c}}" description="y_k = u"
  variableNamingConvention="structured" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="TrivialEchoC" canHandleVariableCommunicationStepSize="true"/>
  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="0.001"/>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="0" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
{_TRIVIAL_OUTPUTS}
  </ModelVariables>
  <ModelStructure><Outputs>{"".join(f'<Unknown index="{k + 2}"/>' for k in range(12))}</Outputs></ModelStructure>
</fmiModelDescription>
'''


FLOORS = {"kind": "broadband_floor", "channel": ["Fx", "Fy", "Fz"], "exponent": 2.0, "omega_ref_rad_s": 300.0,
          "f_Hz": [2.0, 500.0], "psd_ref": [1e-6, 1e-6]}


def build_trivial(dest: Path) -> Path:
    """The trivial C FMU (y = u), compiled like the native wheel FMU."""
    src = dest / "trivial_src"
    src.mkdir()
    (src / "rwadist_wheel_fmu.c").write_text(TRIVIAL_C)        # compile_sources builds that file name
    for name in FMI2_HEADERS:
        (src / name).write_bytes((NATIVE / "fmi2" / name).read_bytes())
    so = compile_sources(src, dest / "TrivialEchoC.so")
    fmu = dest / "trivial_c.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.writestr("modelDescription.xml", TRIVIAL_MD)
        z.write(so, "binaries/linux64/TrivialEchoC.so")
    return fmu


def fmpy_loop(path, n, h, in_vr, out_vrs, params=None):
    """(wall, process CPU) time of n fmpy steps: setReal(input), doStep, getReal(outputs)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for vr, v in (params or {}).items():
        fmu.setBoolean([vr], [v]) if isinstance(v, bool) else fmu.setInteger([vr], [v])
    fmu.exitInitializationMode()
    w = np.linspace(0.0, 300.0, n).tolist()
    t0, c0 = time.perf_counter(), time.process_time()
    for k in range(n):
        fmu.setReal([in_vr], [w[k]])
        fmu.doStep(k * h, h)
        fmu.getReal(out_vrs)
    dt = (time.perf_counter() - t0, time.process_time() - c0)
    fmu.terminate()
    fmu.freeInstance()
    return dt


def c_host_rate(host, fmu, tmp, steps):
    """Steps per second of the native FMU's fmi2DoStep driven by the C host (1-ms steps, ramp 0 -> 3000 rpm,
    seed 3, acceleration input, modes on)."""
    from fmpy import read_model_description
    md = read_model_description(fmu)
    d = tmp / md.coSimulation.modelIdentifier
    with zipfile.ZipFile(fmu) as z:
        z.extractall(d)
    lib = d / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    res = subprocess.run([str(host), str(lib), md.guid, str(steps), "1e-3", "0", repr(3000 * np.pi / 30),
                          "i4=3", "b3=1", "b7=1"], capture_output=True, text=True, check=True)
    cpu = float(res.stderr.split("cpu_steps_per_s")[-1].split()[0])
    return float(res.stderr.split("steps_per_s")[-1]), cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated time per fmpy run, s (default 60)")
    ap.add_argument("--repeats", type=int, default=3, help="interleaved fmpy repeats (best of each; default 3)")
    ap.add_argument("--steps", type=int, default=2_000_000, help="C-host steps for the E wheel (default 2e6)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="rwadist_bench_native_") as tmp:
        tmp = Path(tmp)
        wheel = build_native_fmu(preset("ithaco-e").to_model(), tmp / "wheel_c.fmu", windows=False)
        doc = model_io.to_json(preset("ithaco-e").to_model())
        doc["effects"] = [FLOORS]
        floors = build_native_fmu(doc, tmp / "wheel_floors_c.fmu", windows=False)
        trivial = build_trivial(tmp)
        host = compile_c_host(tmp / "c_host")

        n, h = int(round(args.seconds * 1000)), 1e-3
        runs = {"trivial, 1 output": (trivial, [1], None), "trivial, 12 outputs": (trivial, list(range(1, 13)), None),
                "wheel, 12 outputs": (wheel, list(range(26, 38)), {7: True})}
        times: dict = {k: [] for k in runs}     # (wall, CPU) of every repeat
        loads = []
        for _ in range(args.repeats):            # interleaved: every repeat runs all three back to back
            loads.append(os.getloadavg()[0])
            for k, (path, outs, par) in runs.items():
                times[k].append(fmpy_loop(path, n, h, 0, outs, par))
        best = {k: np.min(np.array(v), axis=0) for k, v in times.items()}
        med = {k: np.median(np.array(v), axis=0) for k, v in times.items()}
        print(f"fmpy, {args.seconds:g} s at 1 kHz ({n} steps: setReal, doStep, getReal), min / median of "
              f"{args.repeats} interleaved repeats; load average (1 min) during the repeats: "
              f"{', '.join(f'{x:.2f}' for x in loads)}")
        for k in runs:
            print(f"  {k:22s} wall {1e6 * best[k][0] / n:6.2f} / {1e6 * med[k][0] / n:6.2f} us/step   process CPU "
                  f"{1e6 * best[k][1] / n:6.2f} / {1e6 * med[k][1] / n:6.2f} us/step")
        for ref in ("trivial, 1 output", "trivial, 12 outputs"):
            print(f"  ratio wheel / {ref:20s} min: wall {best['wheel, 12 outputs'][0] / best[ref][0]:.3f}, CPU "
                  f"{best['wheel, 12 outputs'][1] / best[ref][1]:.3f};  median: wall "
                  f"{med['wheel, 12 outputs'][0] / med[ref][0]:.3f}, CPU {med['wheel, 12 outputs'][1] / med[ref][1]:.3f}"
                  "   (target <= 1.2)")
        print("  (baseline: the pythonfmu FMU, 16.9 us/step, 1.9x a trivial pythonfmu FMU; the 12-output trivial "
              "FMU costs fmpy the same per-value marshalling as the wheel's 12 outputs)")

        print(f"native step alone (C host: dlopen, fmi2SetReal + fmi2DoStep + fmi2GetReal in a loop); load average "
              f"(1 min) {os.getloadavg()[0]:.2f}:")
        wall, cpu = c_host_rate(host, wheel, tmp, args.steps)
        print(f"  E wheel, modes on              {wall:12,.0f} steps/s wall, {cpu:12,.0f} per CPU second   "
              "(target >= 1,000,000)")
        wall, cpu = c_host_rate(host, floors, tmp, max(20_000, args.steps // 20))
        print(f"  + floors on Fx, Fy, Fz (14 970 sinusoids) {wall:10,.0f} steps/s wall, {cpu:10,.0f} per CPU second "
              "  (target >= 50,000; pythonfmu FMU baseline with floors: 35 us per fmpy step = 28,600 steps/s)")
        print(f"  load average (1 min) after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
