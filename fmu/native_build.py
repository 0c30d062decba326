"""Build the rwadist wheel FMU in pure C (FMI 2.0 co-simulation, no Python on the host).

:func:`build_native_fmu` reads the model file with the FMU runtime's own readers
(:func:`fmu.runtime.model_from_doc`, :func:`fmu.runtime.effects_from_doc`,
:func:`fmu.runtime.expand_lines`), writes the parsed model as C data (``wheel_model.h``: every
number as a C99 hexadecimal float literal, so the C model holds the very doubles Python holds),
and compiles ``native/rwadist_wheel_fmu.c`` (FMI 2.0 API, FMU state) with
``native/rwadist_wheel_runtime.h`` (model set-up from the parameters, input checks, ripple, floors), the step
kernel ``native/rwadist_kernel.h`` (shared with the pythonfmu FMU's native layer) and
``native/rwadist_rng.h`` (numpy's ``default_rng`` in C: the same seed gives the same line, ripple
and floor phases as the Python FMU) into ``binaries/linux64/<id>.so``.  The FMU ships those
sources and the FMI 2.0 headers in ``sources/`` (listed in ``<SourceFiles>``), so a host on
another platform can compile it (e.g. ``fmpy.build.build_platform_binary`` on the unzipped FMU; needs a C99 compiler
with ``complex.h``: gcc, clang).

Its variables, value references, parameters, units and start values are those of the pythonfmu
FMU (``fmu/slave.py``; tests compare the two modelDescriptions), except that
``model_file`` accepts only the empty string: the native FMU's model is compiled in.
"""
from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
import uuid
import zipfile
from datetime import datetime, timezone
from pathlib import Path
from xml.sax.saxutils import quoteattr

from . import runtime as rt
from .build import NativeBuildError, model_document, model_physics, native_supported

HERE = Path(__file__).resolve().parent
NATIVE = HERE / "native"
C_SOURCE = "rwadist_wheel_fmu.c"
SOURCES = (C_SOURCE, "rwadist_wheel_instance.h", "rwadist_wheel_runtime.h", "rwadist_kernel.h", "rwadist_rng.h")
FMI2_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
PLATFORM = "linux64"

#: (name, value reference, type, causality, variability, start, unit, description): the pythonfmu FMU's
#: variables (fmu/slave.py registers them in this order; value references count from 0)
_PAR, _FIX = "parameter", "fixed"
VARIABLES = [
    ("wheel_speed", "Real", "input", "continuous", "0", "rad/s",
     "wheel speed, signed (positive about +z of the wheel frame)"),
    ("wheel_acceleration", "Real", "input", "continuous", "0", "rad/s2",
     "wheel acceleration over the coming step; used when use_wheel_acceleration is true, else derived from "
     "wheel_speed"),
    ("model_file", "String", _PAR, _FIX, "", None,
     "model file: the native FMU's model is compiled in; only the empty string is accepted"),
    ("use_wheel_acceleration", "Boolean", _PAR, _FIX, "false", None,
     "take the acceleration from the wheel_acceleration input (else the previous step's mean rate of wheel_speed)"),
    ("seed", "Integer", _PAR, _FIX, "-1", None, "random line phases from this seed; -1: the model file's phases (0)"),
    ("imbalance", "Boolean", _PAR, _FIX, "true", None, "static and dynamic imbalance (h = 1) on"),
    ("harmonics", "Boolean", _PAR, _FIX, "true", None, "all other empirical harmonics on"),
    ("modes", "Boolean", _PAR, _FIX, None, None,
     "suspension modes on (off: internal loads reach the interface directly)"),
    ("start_steady", "Boolean", _PAR, _FIX, "false", None,
     "start from the steady state at the first speed instead of rest"),
    ("speed_ripple", "Boolean", _PAR, _FIX, "true", None,
     "diagnosed wheel-speed ripple (model file effects) added to wheel_speed; off when wheel_speed is a measured "
     "speed that already carries it"),
    ("broadband_floor", "Boolean", _PAR, _FIX, "true", None,
     "diagnosed broadband floors (model file effects) added to the outputs as random-phase multisines"),
    ("floor_resolution", "Real", _PAR, _FIX, "0.1", "Hz",
     "frequency spacing of the broadband-floor multisine (it repeats after 1/floor_resolution s)"),
    ("max_acceleration", "Real", _PAR, _FIX, "500", "rad/s2",
     "largest |dΩ/dt| accepted; a faster speed change is an error"),
    ("max_step_size", "Real", _PAR, _FIX, "0.01", "s", "largest communication step accepted"),
] + [(f"dcm_{i + 1}{j + 1}", "Real", _PAR, _FIX, "1" if i == j else "0", "1",
      f"mounting DCM wheel -> spacecraft, row {i + 1} column {j + 1}") for i in range(3) for j in range(3)] + [
    (f"r_{ax}", "Real", _PAR, _FIX, "0", "m", f"interface position in the spacecraft frame, {ax}") for ax in "xyz"
] + [(ch, "Real", "output", "continuous", "0", unit, desc) for ch, unit, desc in (
    ("Fx", "N", "force the wheel exerts on its interface, wheel frame x"),
    ("Fy", "N", "force on the interface, wheel frame y"),
    ("Fz", "N", "force on the interface, wheel frame z (spin axis)"),
    ("Tx", "N.m", "torque on the interface about wheel x, at the interface point"),
    ("Ty", "N.m", "torque on the interface about wheel y, at the interface point"),
    ("Tz", "N.m", "torque on the interface about wheel z (axial-torque harmonics)"))] + [
    (ch + "_sc", "Real", "output", "continuous", "0", unit, f"{ch} in the spacecraft frame, about its reference point")
    for ch, unit in (("Fx", "N"), ("Fy", "N"), ("Fz", "N"), ("Tx", "N.m"), ("Ty", "N.m"), ("Tz", "N.m"))]
UNITS = {"N": dict(kg=1, m=1, s=-2), "N.m": dict(kg=1, m=2, s=-2), "rad/s": dict(s=-1, rad=1),
         "rad/s2": dict(s=-2, rad=1), "s": dict(s=1), "m": dict(m=1), "Hz": dict(s=-1), "1": {}}
SENSES = {"co": 0, "counter": 1, "planar": 2}


def _f(x) -> str:
    """A double as an exact C99 hexadecimal literal."""
    x = float(x)
    if not math.isfinite(x):
        raise rt.ModelError(f"non-finite model value {x!r}")
    return x.hex()


def _c_string(s: str) -> str:
    return '"' + s.encode("ascii", "replace").decode().replace("\\", "\\\\").replace('"', '\\"') + '"'


def model_header(doc, guid: str, physics: str, modes_default: bool) -> str:
    """The C data of a validated model document (``wheel_model.h``)."""
    params, lines = rt.model_from_doc(doc)
    eff = rt.effects_from_doc(doc)
    full, _, _ = rt.expand_lines(lines, eff["laws"], eff["sidebands"])
    susp = bool(params["suspension"])
    lam = (rt.quad_roots(params["mass"], params["c_r"], params["k_r"]) +
           rt.quad_roots(params["mass"], params["c_z"], params["k_z"])) if susp else (-1.0, -2.0, -1.0, -2.0)
    out = ["/* generated by fmu/native_build.py from the model file: do not edit */",
           "#ifndef RWADIST_WHEEL_MODEL_H", "#define RWADIST_WHEEL_MODEL_H",
           "typedef struct { int dir; double h, C; int sense, imbalance, has_law; double a_ref, w_ref, p, f_off; } RwLine;",
           "typedef struct { unsigned dirmask; double f_hz, zeta, g; } RwRes;",
           "typedef struct { int channel, at, n; double w_ref, p; } RwFloor;",
           f"#define RW_GUID {_c_string(guid)}", f"#define RW_PHYSICS {_c_string(physics)}",
           f"#define RW_SUSPENSION {int(susp)}", f"#define RW_MODES_ASSUMED {int(bool(params['modes_assumed']))}",
           f"#define RW_MODES_DEFAULT {int(modes_default)}",
           "/* " + ", ".join(rt.KERNEL_PARAMS) + " */",
           "static const double RW_PARAMS[10] = {" + ", ".join(_f(params[k]) for k in rt.KERNEL_PARAMS) + "};",
           "/* radial then axial poles (re, im) */",
           "static const double RW_LAM[8] = {" + ", ".join(_f(v) for z in lam for v in (complex(z).real, complex(z).imag)) + "};",
           f"#define RW_N_LINES {len(full)}", f"#define RW_N_LINES_ALLOC {max(1, len(full))}",
           "static const RwLine RW_LINES[RW_N_LINES_ALLOC] = {"]
    for d, h, c, sense, imb, law, off in full:
        a, w, p = law if law is not None else (0.0, 1.0, 0.0)
        out.append(f"    {{{rt.DIRECTIONS.index(d)}, {_f(h)}, {_f(c)}, {SENSES[sense]}, {int(bool(imb))}, "
                   f"{int(law is not None)}, {_f(a)}, {_f(w)}, {_f(p)}, {_f(off)}}}, /* {d} h={h:g} */")
    if not full:
        out.append("    {0}")
    out.append("};")
    res = eff["resonances"]
    out += [f"#define RW_N_RES {len(res)}", "static const RwRes RW_RES[" + str(max(1, len(res))) + "] = {"]
    for dirs, f_r, z, g in res:
        mask = sum(1 << rt.DIRECTIONS.index(d) for d in set(dirs))
        out.append(f"    {{{mask}u, {_f(f_r)}, {_f(z)}, {_f(g)}}},")
    out += (["    {0}"] if not res else []) + ["};"]
    rip = eff["ripples"]
    out += [f"#define RW_N_RIPPLES {len(rip)}", f"#define RW_N_RIPPLES_ALLOC {max(1, len(rip))}",
            "static const double RW_RIPPLES[RW_N_RIPPLES_ALLOC][4] = {"]
    out += ["    {" + ", ".join(_f(v) for v in r) + "}," for r in rip] + (["    {0}"] if not rip else []) + ["};"]
    floors, f_knots, p_knots = [], [], []
    for ch, f_k, psd_k, w_ref, p in eff["floors"]:
        floors.append(f"    {{{ch}, {len(f_knots)}, {len(f_k)}, {_f(w_ref)}, {_f(p)}}},")
        f_knots += list(f_k)
        p_knots += list(psd_k)
    out += [f"#define RW_N_FLOORS {len(floors)}", "static const RwFloor RW_FLOORS[" + str(max(1, len(floors))) + "] = {"]
    out += floors + (["    {0}"] if not floors else []) + ["};"]
    for name, vals in (("RW_FLOOR_F", f_knots), ("RW_FLOOR_PSD", p_knots)):
        out.append(f"static const double {name}[{max(1, len(vals))}] = {{" + (", ".join(_f(v) for v in vals) or "0")
                   + "};")
    out.append("#endif")
    return "\n".join(out) + "\n"


def model_description(model_identifier: str, guid: str, physics: str, modes_default: bool) -> str:
    """modelDescription.xml of the native FMU."""
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    x = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<fmiModelDescription fmiVersion="2.0" modelName="{model_identifier}" guid="{guid}" '
         f'description={quoteattr("Reaction-wheel micro-vibration, time domain; outputs in wheel and spacecraft frames. Physics: " + physics)} '
         'generationTool="rwadist native FMU builder (fmu/native_build.py)" '
         f'generationDateAndTime="{now}" variableNamingConvention="structured" numberOfEventIndicators="0">',
         f'  <CoSimulation modelIdentifier="{model_identifier}" needsExecutionTool="false" '
         'canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" '
         'canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" '
         'canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" '
         'providesDirectionalDerivative="false">',
         f'    <SourceFiles>\n      <File name="{C_SOURCE}"/>\n    </SourceFiles>',
         '  </CoSimulation>', '  <UnitDefinitions>']
    for name, exps in UNITS.items():
        base = " ".join(f'{k}="{v}"' for k, v in exps.items())
        x.append(f'    <Unit name="{name}"><BaseUnit {base}/></Unit>' if base else
                 f'    <Unit name="{name}"><BaseUnit/></Unit>')
    x += ['  </UnitDefinitions>', '  <LogCategories>',
          '    <Category name="logStatusWarning" description="Log messages with fmi2Warning status."/>',
          '    <Category name="logStatusError" description="Log messages with fmi2Error status."/>',
          '    <Category name="logAll" description="Log all messages."/>',
          '  </LogCategories>',
          '  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="0.001"/>', '  <ModelVariables>']
    outputs = []
    for vr, (name, typ, caus, var, start, unit, desc) in enumerate(VARIABLES):
        if name == "modes":
            start = "true" if modes_default else "false"
        if caus == "output":
            outputs.append(vr + 1)
        init = ' initial="exact"' if caus == "output" else ""
        attrs = f'start="{start}"' + (f' unit="{unit}"' if unit else "")
        x.append(f'    <ScalarVariable name="{name}" valueReference="{vr}" description={quoteattr(desc)} '
                 f'causality="{caus}" variability="{var}"{init}>\n      <{typ} {attrs}/>\n    </ScalarVariable>')
    x += ['  </ModelVariables>', '  <ModelStructure>', '    <Outputs>']
    x += [f'      <Unknown index="{i}"/>' for i in outputs]
    x += ['    </Outputs>', '  </ModelStructure>', '</fmiModelDescription>']
    return "\n".join(x) + "\n"


def compile_sources(src_dir, output) -> Path:
    """Compile the FMU's ``sources/`` (``src_dir``) into the shared library ``output`` with ``$CC``/``cc``;
    NativeBuildError on failure.  Only the fmi2 functions are exported; libm is linked (no libpython).
    ``-fcx-limited-range``: complex products without the NaN/infinity recovery branch (the kernel's values are
    finite; checked after every step) -- the same finite results, ~9 % fewer instructions per step;
    ``-ffp-contract=off``: no fused multiply-adds where the target has them, so a build on another platform
    (aarch64, ``-march=native``) gives the same bits as this one."""
    cc = shutil.which(os.environ.get("CC", "cc"))
    if cc is None:
        raise NativeBuildError(f"no C compiler ({os.environ.get('CC', 'cc')!r} not on PATH)")
    cmd = [cc, "-std=gnu11", "-O2", "-fcx-limited-range", "-ffp-contract=off", "-fPIC", "-shared",
           "-fvisibility=hidden", f"-I{src_dir}", "-o", str(output), str(Path(src_dir) / C_SOURCE), "-lm"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise NativeBuildError(f"{' '.join(cmd)} failed:\n{res.stderr.strip()}")
    return Path(output)


def build_native_fmu(model, output, *, tag: str | None = None, assumed_modes: bool = False) -> Path:
    """Write the pure-C FMU of ``model`` (path, dict or WheelModel) to ``output`` (.fmu); returns its path.

    ``tag`` (default random) makes the model identifier ``RwadistWheelC_<tag>``.  ``assumed_modes``: as
    :func:`fmu.build.build_fmu` (the start value of ``modes`` for a wheel with assumed modes).  The binary is
    built for Linux x86-64 (NativeBuildError elsewhere or without a C compiler); ``sources/`` lets other
    platforms build their own."""
    doc = model_document(model)
    output = Path(output)
    if output.suffix != ".fmu":
        raise ValueError(f"output {str(output)!r} must end in .fmu")
    if not native_supported():
        raise NativeBuildError("the native FMU's binary is built on Linux x86-64 only (its sources/ build elsewhere)")
    tag = tag or uuid.uuid4().hex[:12]
    if not ("x" + tag).isidentifier():
        raise ValueError(f"tag {tag!r} must be alphanumeric")
    model_identifier = f"RwadistWheelC_{tag}"
    guid = "{" + str(uuid.uuid4()) + "}"
    physics, modes_default = model_physics(doc, assumed_modes)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rwadist_cfmu_") as tmp:
        root = Path(tmp) / "fmu"
        src = root / "sources"
        src.mkdir(parents=True)
        for name in SOURCES:
            shutil.copy2(NATIVE / name, src / name)
        for name in FMI2_HEADERS:
            shutil.copy2(NATIVE / "fmi2" / name, src / name)
        (src / "wheel_model.h").write_text(model_header(doc, guid, physics, modes_default))
        (root / "modelDescription.xml").write_text(model_description(model_identifier, guid, physics,
                                                                     modes_default))
        bindir = root / "binaries" / PLATFORM
        bindir.mkdir(parents=True)
        compile_sources(src, bindir / f"{model_identifier}.so")
        (root / "documentation").mkdir()
        (root / "documentation" / "index.txt").write_text(
            f"rwadist wheel FMU (native C, FMI 2.0 co-simulation).\nPhysics: {physics}\n"
            "Build on another platform: compile sources/rwadist_wheel_fmu.c (C11 with complex.h) into a shared\n"
            f"library named {model_identifier} (e.g. fmpy.build.build_platform_binary on the unzipped FMU).\n")
        tmp_out = output.with_suffix(".fmu.tmp")
        with zipfile.ZipFile(tmp_out, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(root.rglob("*")):
                if f.is_file():
                    info = zipfile.ZipInfo(f.relative_to(root).as_posix(), date_time=(2026, 1, 1, 0, 0, 0))
                    info.external_attr = (0o755 if f.suffix == ".so" else 0o644) << 16
                    z.writestr(info, f.read_bytes(), compress_type=zipfile.ZIP_DEFLATED)
        os.replace(tmp_out, output)
    return output


def compile_c_host(output) -> Path:
    """Compile ``native/c_host.c`` (an FMI 2.0 host in C, no Python: dlopen, fmi2DoStep over a speed ramp)
    into the executable ``output``; NativeBuildError on failure."""
    cc = shutil.which(os.environ.get("CC", "cc"))
    if cc is None:
        raise NativeBuildError(f"no C compiler ({os.environ.get('CC', 'cc')!r} not on PATH)")
    cmd = [cc, "-O2", f"-I{NATIVE}", "-o", str(output), str(NATIVE / "c_host.c"), "-ldl"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise NativeBuildError(f"{' '.join(cmd)} failed:\n{res.stderr.strip()}")
    return Path(output)
