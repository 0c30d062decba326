"""Benchmark (issue 17): process memory over many instantiate/free cycles of both wheel FMUs.

Each cycle, in one fmpy process per FMU (the library loaded once): fmi2Instantiate, fmi2SetupExperiment, enter/exit initialisation,
10 steps, fmi2Terminate, fmi2FreeInstance.  The resident set size (VmRSS of /proc/self/status) is read after
WARMUP cycles and after WARMUP + CYCLES; the growth is printed against the 1 MB target.  The native FMU is also
run by the C stress host (fmu/native/c_stress.c: no Python in the process; instantiate, steps, bad input,
state get/set/serialize, reset, free), which prints its own RSS growth after its warm-up cycles.

    .venv/bin/python benchmarks/fmu_memory.py [--cycles 1000] [--warmup 50]

Baseline (issue 17 audit): the pythonfmu FMU grew ~50 kB per instantiate/free (9.4 MB over 190 cycles); measured
here before the fix: 62 kB per cycle (pythonfmu's findClass keeps every class the slave module defines or imports
alive at each instantiation; fmu/slave_template.py now makes it find one class only).  What is left in the
pythonfmu FMU is pythonfmu 0.7's own: its findClass never releases the list of the slave class's MRO nor the repr
and UTF-8 strings it makes of each entry, ~0.9 kB per fmi2Instantiate (tracemalloc: ~13 objects per instance,
allocated inside fmi2Instantiate); the native C FMU has no Python and no such leak.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

TARGET_MB = 1.0

CHILD = r'''
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

def rss_kb():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])

path, cycles, warmup = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
md = read_model_description(path)
unzip = extract(path)
fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="mem")
vr = {v.name: v.valueReference for v in md.modelVariables}
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
marks = {}
for k in range(warmup + cycles):
    if k == warmup:
        marks["after_warmup"] = rss_kb()
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([vr["wheel_speed"]], [100.0 + k % 13])
    fmu.exitInitializationMode()
    for n in range(10):
        fmu.doStep(n * 1e-3, 1e-3)
        fmu.getReal(outs)
    fmu.terminate()
    # fmi2FreeInstance itself: fmpy's freeInstance() would also unload the library (then the cycles would measure
    # dlopen/dlclose and fmpy's ctypes set-up, which grow the process by ~0.5 kB per load, not the FMU)
    fmu.fmi2FreeInstance(fmu.component)
marks["end"] = rss_kb()
print(marks["after_warmup"], marks["end"])
'''


def fmpy_growth(fmu: Path, cycles: int, warmup: int) -> tuple[float, float]:
    """(RSS after warm-up, growth over ``cycles`` more cycles) in MB, fmpy in a fresh process."""
    res = subprocess.run([sys.executable, "-c", CHILD, str(fmu), str(cycles), str(warmup)], capture_output=True,
                         text=True, timeout=3600)
    if res.returncode != 0:
        raise RuntimeError(f"fmpy cycles of {fmu.name} failed:\n{res.stderr[-3000:]}")
    a, b = (int(v) for v in res.stdout.split()[-2:])
    return a / 1024, (b - a) / 1024


def c_host_growth(fmu: Path, cycles: int, warmup: int, tmp: Path) -> tuple[float, str]:
    """(RSS growth in MB after ``warmup`` cycles, the host's check line) of the C stress host on the native FMU."""
    from fmpy import read_model_description
    from rwadist.fmu.native_build import NATIVE
    md = read_model_description(fmu)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(tmp / "c")
    lib = tmp / "c" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    host = tmp / "c_stress"
    cc = shutil.which("cc") or shutil.which("gcc")
    subprocess.run([cc, "-O2", f"-I{NATIVE}", "-o", str(host), str(NATIVE / "c_stress.c"), "-ldl", "-lm"],
                   check=True)
    res = subprocess.run([str(host), str(lib), md.guid, str(cycles + warmup), "1", str(warmup)], capture_output=True,
                         text=True, timeout=3600)
    if res.returncode != 0:
        raise RuntimeError(f"c_stress failed:\n{res.stdout}{res.stderr[-3000:]}")
    lines = res.stdout.strip().splitlines()
    growth = next(float(ln.split()[1]) for ln in lines if ln.startswith("rss_growth_kB"))
    return growth / 1024, next(ln for ln in lines if ln.startswith("checks"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=1000)
    ap.add_argument("--warmup", type=int, default=50)
    args = ap.parse_args(argv)
    from rwadist.fmu.build import build_fmu
    from rwadist.fmu.native_build import build_native_fmu

    from rwadist import model as model_io
    from rwadist.presets import preset
    doc = model_io.to_json(preset("ithaco-e").to_model())
    doc["effects"] = json.loads(json.dumps([
        {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 200.0,
         "speed_exponent": 0.5},
        {"kind": "broadband_floor", "channel": ["Fx", "Fz"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
         "f_Hz": [5.0, 60.0, 140.0], "psd_ref": [1.0e-5, 4.0e-5, 1.0e-5]}]))
    ok = True
    print(f"{args.cycles} instantiate/free cycles after {args.warmup} warm-up cycles; target: RSS growth "
          f"< {TARGET_MB:g} MB")
    with tempfile.TemporaryDirectory(prefix="rwadist_fmu_memory_") as tmp:
        tmp = Path(tmp)
        fmus = {"pythonfmu FMU (fmpy)": build_fmu(doc, tmp / "py.fmu"),
                "native C FMU (fmpy)": build_native_fmu(doc, tmp / "c.fmu")}
        for name, fmu in fmus.items():
            base, growth = fmpy_growth(fmu, args.cycles, args.warmup)
            ok &= growth < TARGET_MB
            print(f"  {name:28s} RSS after warm-up {base:7.1f} MB, growth {growth * 1024:8.1f} kB "
                  f"({growth * 1024 / args.cycles:.2f} kB/cycle)  {'OK' if growth < TARGET_MB else 'OVER TARGET'}")
        growth, checks = c_host_growth(fmus["native C FMU (fmpy)"], args.cycles, args.warmup, tmp)
        ok &= growth < TARGET_MB
        print(f"  {'native C FMU (C host)':28s} growth {growth * 1024:8.1f} kB  "
              f"{'OK' if growth < TARGET_MB else 'OVER TARGET'}  [{checks}]")
    print("all within target" if ok else "OVER TARGET")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
