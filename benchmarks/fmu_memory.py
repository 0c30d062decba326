"""Benchmark (issue 17): process memory over many instantiate/free cycles of the wheel FMUs.

Each cycle, in one fmpy process per FMU (the library loaded once): fmi2Instantiate, fmi2SetupExperiment, enter/exit
initialisation, 10 steps, fmi2Terminate, fmi2FreeInstance.  The resident set size (VmRSS of /proc/self/status) is
read after WARMUP cycles and after WARMUP + CYCLES; the growth is printed against the 1 MB target.  FMUs: the
pythonfmu FMU (``rwadist fmu build``'s default) of the E wheel with a speed ripple and broadband floors (numpy
multisine tables per instance), the same without floors, and the native C FMU of the first model.  The native FMU
is also run by the C stress host (rwadist/fmu/native/c_stress.c: no Python in the process; instantiate, steps, bad input,
state get/set/serialize, reset, free), which prints its own RSS growth after its warm-up cycles.

    .venv/bin/python benchmarks/fmu_memory.py [--cycles 1000] [--warmup 50]

Baseline (this command, same machine, code before the issue-17 fixes, printed below as BASELINE_KB): pythonfmu
FMU with floors 3.7-4.1 MB over 1000 cycles, without floors 1.9-2.2 MB; native C FMU 0.0 kB (fmpy), 64 kB (C
host).  Earlier (issue 17 audit) ~50 kB per cycle, then 62 kB per cycle before the slave module's findClass
work-around.  What grew, measured (tracemalloc, gc, /proc/self/smaps, sys._debugmallocstats):

* each freed slave instance sat in reference cycles (pythonfmu's variable getters/setters close over it; a ctypes
  CDLL per instance is a cycle and defines a class) until a full garbage collection, with its model's arrays --
  fixed: weak references, the native library opened once per process (rwadist/fmu/slave.py);
* pythonfmu 0.7 compiles the slave module again at every fmi2Instantiate: 1.3 MB of transient allocations per
  instance for the whole slave, fragmenting pymalloc's arenas around the objects pythonfmu leaks -- fixed: that
  module is a short shim (rwadist/fmu/slave_template.py), 0.1 MB;
* pythonfmu's own leaks per fmi2Instantiate: sys.path grew by one entry (now dropped); findClass's list of the
  slave class's __mro__ with a repr and a bytes object per entry and the name's bytes, ~0.9 kB -- now it is shown
  a stand-in, and leaks 219 bytes per instance (a two-entry list 56 + 16 B, one 72-B bytes object, the 75-B
  sys.path string it never releases; 4 objects), ~0.29 kB per cycle in pymalloc blocks.  That, and the pools it
  pins, is what is left of the growth; the glibc heap (numpy's tables included) stays flat, and the floors' tables
  are not the cause (the floor FMU with broadband_floor = false grew 584-596 kB, with it 616-620 kB).

The growth over the cycles holds a one-time step besides that leak: once the leak has used the arenas' slack,
pymalloc takes one more arena and the per-instance working set moves into it.  Its size depends on the process's
layout (a variant of the slave module without its comments grew 1.02 MB over the same 1000 cycles, with the same
rate afterwards), so the rate over the second half of the cycles is printed too: the steady growth per cycle
(~0.25-0.3 kB/cycle; over 3000 cycles 0.28 kB/cycle with floors, 0.25 without).
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
#: growth over 1000 cycles before the issue-17 fixes (this benchmark, same machine), kB
BASELINE_KB = {"pythonfmu FMU, floors (fmpy)": 3692.0, "pythonfmu FMU, no floors (fmpy)": 1940.0,
               "native C FMU (fmpy)": 0.0, "native C FMU (C host)": 64.0}

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
    if k == warmup + cycles // 2:
        marks["half"] = rss_kb()
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
print(marks["after_warmup"], marks["half"], marks["end"])
'''


def fmpy_growth(fmu: Path, cycles: int, warmup: int) -> tuple[float, float, float]:
    """(RSS after warm-up, growth over ``cycles`` more cycles, growth over their second half) in MB, fmpy in a
    fresh process."""
    res = subprocess.run([sys.executable, "-c", CHILD, str(fmu), str(cycles), str(warmup)], capture_output=True,
                         text=True, timeout=3600)
    if res.returncode != 0:
        raise RuntimeError(f"fmpy cycles of {fmu.name} failed:\n{res.stderr[-3000:]}")
    a, h, b = (int(v) for v in res.stdout.split()[-3:])
    return a / 1024, (b - a) / 1024, (b - h) / 1024


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
    from rwadist import model as model_io
    from rwadist.fmu.build import build_fmu
    from rwadist.fmu.native_build import build_native_fmu
    from rwadist.presets import preset
    plain = model_io.to_json(preset("ithaco-e").to_model())
    doc = json.loads(json.dumps(plain))
    doc["effects"] = [
        {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 3.0, "omega_ref_rad_s": 200.0,
         "speed_exponent": 0.5},
        {"kind": "broadband_floor", "channel": ["Fx", "Fz"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
         "f_Hz": [5.0, 60.0, 140.0], "psd_ref": [1.0e-5, 4.0e-5, 1.0e-5]}]
    ok = True
    print(f"{args.cycles} instantiate/free cycles after {args.warmup} warm-up cycles; target: RSS growth "
          f"< {TARGET_MB:g} MB; baseline: before the issue-17 fixes, 1000 cycles")

    def report(name, growth, extra=""):
        base = BASELINE_KB[name]
        print(f"  {name:32s} growth {growth * 1024:8.1f} kB ({growth * 1024 / args.cycles:.2f} kB/cycle), "
              f"baseline {base:7.1f} kB  {'OK' if growth < TARGET_MB else 'OVER TARGET'}{extra}")
        return growth < TARGET_MB

    with tempfile.TemporaryDirectory(prefix="rwadist_fmu_memory_") as tmp:
        tmp = Path(tmp)
        fmus = {"pythonfmu FMU, floors (fmpy)": build_fmu(doc, tmp / "py.fmu"),
                "pythonfmu FMU, no floors (fmpy)": build_fmu(plain, tmp / "py_plain.fmu"),
                "native C FMU (fmpy)": build_native_fmu(doc, tmp / "c.fmu")}
        for name, fmu in fmus.items():
            rss, growth, late = fmpy_growth(fmu, args.cycles, args.warmup)
            ok &= report(name, growth, f"  [RSS after warm-up {rss:.1f} MB; second half of the cycles "
                                       f"{late * 1024 / (args.cycles - args.cycles // 2):.2f} kB/cycle]")
        growth, checks = c_host_growth(fmus["native C FMU (fmpy)"], args.cycles, args.warmup, tmp)
        ok &= report("native C FMU (C host)", growth, f"  [{checks}]")
    print("all within target" if ok else "OVER TARGET")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
