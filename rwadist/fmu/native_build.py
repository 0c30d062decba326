"""Build the rwadist wheel FMU in pure C (FMI 2.0 or 3.0 co-simulation, no Python on the host).

:func:`build_native_fmu` reads the model file with the FMU runtime's own readers
(:func:`rwadist.fmu.runtime.model_from_doc`, :func:`rwadist.fmu.runtime.effects_from_doc`,
:func:`rwadist.fmu.runtime.expand_lines`), writes the parsed model as C data (``wheel_model.h``: every
number as a C99 hexadecimal float literal, so the C model holds the very doubles Python holds),
and compiles the FMI API -- ``native/rwadist_wheel_fmu.c`` (FMI 2.0) or ``native/rwadist_wheel_fmi3.c`` (FMI 3.0) --
with the wrapper layer both share, ``native/rwadist_wheel_instance.h`` (every call's work: the state machine of
``native/rwadist_fmi_rules.h``, variables by value reference, FMU state), ``native/rwadist_wheel_runtime.h`` (model set-up from the parameters, input checks, ripple,
floors), the step
kernel ``native/rwadist_kernel.h`` (shared with the pythonfmu FMU's native layer) and
``native/rwadist_rng.h`` (numpy's ``default_rng`` in C: the same seed gives the same line, ripple
and floor phases as the Python FMU) into ``binaries/linux64/<id>.so`` and, with mingw-w64
(``x86_64-w64-mingw32-gcc``, Debian's ``gcc-mingw-w64-x86-64-win32``), ``binaries/win64/<id>.dll`` (FMI 3.0:
``x86_64-linux``, ``x86_64-windows``); without mingw-w64 the FMU is Linux-only (a warning says how to get it).  The
FMU ships those sources and the FMI headers in ``sources/`` (FMI 2.0: listed in ``<SourceFiles>``; FMI 3.0:
``sources/buildDescription.xml``), so a host on another platform can compile it (e.g.
``fmpy.build.build_platform_binary`` on the unzipped FMU; needs a C99 compiler with ``complex.h``: gcc, clang).

Its variables, value references, parameters, units and start values are those of the pythonfmu
FMU (``rwadist/fmu/slave.py``; tests compare the two modelDescriptions), except that
``model_file`` accepts only the empty string: the native FMU's model is compiled in.  The FMI 3.0 FMU has the same
variables and value references (Real as Float64, Integer as Int32) and the independent variable ``time``.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import subprocess
import tempfile
import uuid
import warnings
import zipfile
from datetime import datetime, timezone
from pathlib import Path
from xml.sax.saxutils import quoteattr

from . import runtime as rt
from .build import NativeBuildError, model_document, model_physics, native_supported

HERE = Path(__file__).resolve().parent
NATIVE = HERE / "native"
#: the FMI API source of each FMI version (C_SOURCE: FMI 2.0's, the one every native FMU ships)
C_SOURCES = {2: "rwadist_wheel_fmu.c", 3: "rwadist_wheel_fmi3.c"}
C_SOURCE = C_SOURCES[2]
#: what every native FMU compiles besides its API source: wrapper layer, runtime, kernel, random numbers
COMMON_SOURCES = ("rwadist_wheel_instance.h", "rwadist_fmi_rules.h", "rwadist_wheel_runtime.h", "rwadist_kernel.h",
                  "rwadist_rng.h")
SOURCES = (C_SOURCE, *COMMON_SOURCES)
FMI2_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
FMI3_HEADERS = ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")
FMI_HEADERS = {2: ("fmi2", FMI2_HEADERS), 3: ("fmi3", FMI3_HEADERS)}
PLATFORM = "linux64"
#: binaries/ folder of each FMI version and target
PLATFORMS = {2: {"linux": "linux64", "windows": "win64"}, 3: {"linux": "x86_64-linux", "windows": "x86_64-windows"}}
#: the mingw-w64 cross compiler (``$RWADIST_MINGW_CC`` overrides it) and how to get it
MINGW = "x86_64-w64-mingw32-gcc"
MINGW_HINT = ("install Debian's gcc-mingw-w64-x86-64-win32 (apt-get install gcc-mingw-w64-x86-64-win32) or point "
              "RWADIST_MINGW_CC at another x86_64 mingw-w64 gcc")

#: (name, value reference, type, causality, variability, start, unit, description): the pythonfmu FMU's
#: variables (rwadist/fmu/slave.py registers them in this order; value references count from 0)
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
] + [
    # the effect switches: their elements name and describe them (rwadist.effects, runtime.fmu_switches)
    (name, "Boolean", _PAR, _FIX, "true", None, description) for name, description in rt.fmu_switches()
] + [
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
SENSES = {"co": 0, "counter": 1, "planar": 2, rt.PLANAR_Y: 3}      # 3: planar along y


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
    out = ["/* generated by rwadist/fmu/native_build.py from the model file: do not edit */",
           "#ifndef RWADIST_WHEEL_MODEL_H", "#define RWADIST_WHEEL_MODEL_H",
           "typedef struct { int dir; double h, C; int sense, imbalance, has_law; double a_ref, w_ref, p, f_off; } RwLine;",
           "typedef struct { unsigned dirmask; double f_hz, zeta, g; } RwRes;",
           "typedef struct { int channel, at, n, sw; double w_ref, p; } RwFloor;",
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
    # the effect switches (value references RW_VR_SWITCH + slot) and the slot that turns each ripple and floor off
    switches = [name for name, _ in rt.fmu_switches()]
    slot = {name: i for i, name in enumerate(switches)}
    slot[None] = -1                     # an element without a switch: always on
    out += [f"#define RW_N_SWITCHES {len(switches)}",
            "static const char *const RW_SWITCH_NAMES[" + str(max(1, len(switches))) + "] = {"
            + (", ".join(_c_string(n) for n in switches) or "0") + "};"]
    rip = eff["ripples"]
    out += [f"#define RW_N_RIPPLES {len(rip)}", f"#define RW_N_RIPPLES_ALLOC {max(1, len(rip))}",
            "static const double RW_RIPPLES[RW_N_RIPPLES_ALLOC][4] = {"]
    out += ["    {" + ", ".join(_f(v) for v in r) + "}," for r in rip] + (["    {0}"] if not rip else []) + ["};"]
    out += ["static const int RW_RIPPLE_SWITCH[RW_N_RIPPLES_ALLOC] = {"
            + (", ".join(str(slot[s]) for s in eff["switch_of"]["ripples"]) or "0") + "};"]
    floors: list[str] = []
    f_knots: list[float] = []
    p_knots: list[float] = []
    for (ch, f_k, psd_k, w_ref, p), sw in zip(eff["floors"], eff["switch_of"]["floors"]):
        floors.append(f"    {{{ch}, {len(f_knots)}, {len(f_k)}, {slot[sw]}, {_f(w_ref)}, {_f(p)}}},")
        f_knots += list(f_k)
        p_knots += list(psd_k)
    out += [f"#define RW_N_FLOORS {len(floors)}", "static const RwFloor RW_FLOORS[" + str(max(1, len(floors))) + "] = {"]
    out += floors + (["    {0}"] if not floors else []) + ["};"]
    for name, vals in (("RW_FLOOR_F", f_knots), ("RW_FLOOR_PSD", p_knots)):
        out.append(f"static const double {name}[{max(1, len(vals))}] = {{" + (", ".join(_f(v) for v in vals) or "0")
                   + "};")
    out.append("#endif")
    return "\n".join(out) + "\n"


def _generated_now() -> str:
    """The modelDescription's generationDateAndTime attribute (with its leading space): now, UTC."""
    return f' generationDateAndTime="{datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")}"'


def model_description(model_identifier: str, guid: str, physics: str, modes_default: bool,
                      generated: str | None = None) -> str:
    """modelDescription.xml of the native FMU (``generated``: the generationDateAndTime attribute, '' for none;
    default now)."""
    now = _generated_now() if generated is None else generated
    x = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<fmiModelDescription fmiVersion="2.0" modelName="{model_identifier}" guid="{guid}" '
         f'description={quoteattr("Reaction-wheel micro-vibration, time domain; outputs in wheel and spacecraft frames. Physics: " + physics)} '
         'generationTool="rwadist native FMU builder (rwadist/fmu/native_build.py)"'
         f'{now} variableNamingConvention="structured" numberOfEventIndicators="0">',
         f'  <CoSimulation modelIdentifier="{model_identifier}" needsExecutionTool="false" '
         'canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" '
         'canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" '
         'canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="true" canSerializeFMUstate="true" '
         'providesDirectionalDerivative="false">',
         f'    <SourceFiles>\n      <File name="{C_SOURCE}"/>\n    </SourceFiles>',
         '  </CoSimulation>']
    x += _unit_definitions() + ['  <ModelVariables>']
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


def windows_compiler() -> str | None:
    """Path of the mingw-w64 cross compiler (``$RWADIST_MINGW_CC`` or x86_64-w64-mingw32-gcc), None when absent."""
    return shutil.which(os.environ.get("RWADIST_MINGW_CC", MINGW))


def compile_sources(src_dir, output, *, source: str = C_SOURCE, windows: bool = False) -> Path:
    """Compile the FMU's ``sources/`` (``src_dir``; the API file ``source``) into the shared library ``output``:
    with ``$CC``/``cc`` for Linux, or the mingw-w64 cross compiler for a Windows DLL (``windows``);
    NativeBuildError on failure.  Only the fmi functions are exported; libm is linked (no libpython; the DLL imports
    KERNEL32 and msvcrt only, libgcc linked in).
    ``-fcx-limited-range``: complex products without the NaN/infinity recovery branch (the kernel's values are
    finite; checked after every step) -- the same finite results, ~9 % fewer instructions per step;
    ``-ffp-contract=off``: no fused multiply-adds where the target has them, so a build on another platform
    (aarch64, ``-march=native``) gives the same bits as this one.  The build is reproducible: the same sources give
    the same bytes."""
    if windows:
        cc = windows_compiler()
        if cc is None:
            raise NativeBuildError(f"no Windows cross compiler ({os.environ.get('RWADIST_MINGW_CC', MINGW)!r} not on "
                                   f"PATH): {MINGW_HINT}")
        # no build time in the PE header, an image base that does not hash the (temporary) output path
        target = ["-static-libgcc", "-Wl,--no-insert-timestamp,--disable-auto-image-base"]
    else:
        cc = shutil.which(os.environ.get("CC", "cc"))
        if cc is None:
            raise NativeBuildError(f"no C compiler ({os.environ.get('CC', 'cc')!r} not on PATH)")
        target = ["-fPIC", "-fvisibility=hidden"]
    # run in src_dir, the source named relative to it: no build folder in the binary (the same sources give the
    # same bytes, whichever temporary folder they were built in)
    cmd = [cc, "-std=gnu11", "-O2", "-fcx-limited-range", "-ffp-contract=off", "-shared", *target,
           "-I.", "-o", str(Path(output).resolve()), source, "-lm"]
    res = subprocess.run(cmd, capture_output=True, text=True, cwd=src_dir)
    if res.returncode != 0:
        raise NativeBuildError(f"{' '.join(cmd)} failed:\n{res.stderr.strip()}")
    return Path(output)


def binary_platforms(fmu_path) -> list:
    """The binaries/ folders of the FMU at ``fmu_path`` that hold a library (e.g. ['linux64', 'win64'])."""
    with zipfile.ZipFile(fmu_path) as z:
        return sorted({n.split("/")[1] for n in z.namelist()
                       if n.startswith("binaries/") and n.count("/") == 2 and n.endswith((".so", ".dll"))})


FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}
#: value reference of FMI 3.0's independent variable ``time`` (after the FMI 2.0 variables; VR_TIME in C)
VR_TIME = len(VARIABLES)


def _unit_definitions() -> list:
    x = ['  <UnitDefinitions>']
    for name, exps in UNITS.items():
        base = " ".join(f'{k}="{v}"' for k, v in exps.items())
        x.append(f'    <Unit name="{name}"><BaseUnit {base}/></Unit>' if base else
                 f'    <Unit name="{name}"><BaseUnit/></Unit>')
    return x + ['  </UnitDefinitions>', '  <LogCategories>',
                '    <Category name="logStatusWarning" description="Log messages with Warning status."/>',
                '    <Category name="logStatusError" description="Log messages with Error status."/>',
                '    <Category name="logAll" description="Log all messages."/>', '  </LogCategories>',
                '  <DefaultExperiment startTime="0.0" stopTime="1.0" stepSize="0.001"/>']


def model_description3(model_identifier: str, guid: str, physics: str, modes_default: bool,
                       generated: str | None = None) -> str:
    """modelDescription.xml of the FMI 3.0 native FMU: the FMI 2.0 FMU's variables and value references (Real as
    Float64, Integer as Int32) and the independent variable ``time`` (``generated``: as :func:`model_description`)."""
    now = _generated_now() if generated is None else generated
    x = ['<?xml version="1.0" encoding="UTF-8"?>',
         f'<fmiModelDescription fmiVersion="3.0" modelName="{model_identifier}" instantiationToken="{guid}" '
         f'description={quoteattr("Reaction-wheel micro-vibration, time domain; outputs in wheel and spacecraft frames. Physics: " + physics)} '
         'generationTool="rwadist native FMU builder (rwadist/fmu/native_build.py)"'
         f'{now} variableNamingConvention="structured">',
         f'  <CoSimulation modelIdentifier="{model_identifier}" needsExecutionTool="false" '
         'canBeInstantiatedOnlyOncePerProcess="false" canGetAndSetFMUState="true" canSerializeFMUState="true" '
         'providesDirectionalDerivatives="false" providesAdjointDerivatives="false" '
         'canHandleVariableCommunicationStepSize="true" maxOutputDerivativeOrder="0" hasEventMode="false" '
         'providesIntermediateUpdate="false" canReturnEarlyAfterIntermediateUpdate="false"/>']
    x += _unit_definitions() + ['  <ModelVariables>',
                                f'    <Float64 name="time" valueReference="{VR_TIME}" causality="independent" '
                                'variability="continuous" unit="s" description="simulation time"/>']
    outputs = []
    for vr, (name, typ, caus, var, start, unit, desc) in enumerate(VARIABLES):
        if name == "modes":
            start = "true" if modes_default else "false"
        if caus == "output":
            outputs.append(vr)
        attrs = (f'name="{name}" valueReference="{vr}" description={quoteattr(desc)} causality="{caus}" '
                 f'variability="{var}"' + (' initial="exact"' if caus == "output" else ""))
        if typ == "String":
            x.append(f'    <String {attrs}><Start value="{start}"/></String>')
        else:
            x.append(f'    <{FMI3_TYPES[typ]} {attrs} start="{start}"' + (f' unit="{unit}"' if unit else "") + '/>')
    x += ['  </ModelVariables>', '  <ModelStructure>']
    x += [f'    <Output valueReference="{vr}"/>' for vr in outputs]
    x += ['  </ModelStructure>', '</fmiModelDescription>']
    return "\n".join(x) + "\n"


def build_description3(model_identifier: str) -> str:
    """sources/buildDescription.xml of the FMI 3.0 native FMU (FMI 3.0 section 2.5.1)."""
    return "\n".join([
        '<?xml version="1.0" encoding="UTF-8"?>', '<fmiBuildDescription fmiVersion="3.0">',
        f'  <BuildConfiguration modelIdentifier="{model_identifier}" description="C11 with complex.h (gcc, clang); '
        'link libm">', '    <SourceFileSet language="C11">',
        f'      <SourceFile name="{C_SOURCES[3]}"/>', '    </SourceFileSet>', '  </BuildConfiguration>',
        '</fmiBuildDescription>']) + "\n"


def zip_fmu(root, output) -> Path:
    """Zip the FMU folder ``root`` into ``output`` (written beside it, then moved: never half a file); the entries
    sorted, with fixed times and modes, so the same folder gives the same bytes."""
    output = Path(output)
    tmp_out = output.with_name(output.name + ".tmp")
    with zipfile.ZipFile(tmp_out, "w", zipfile.ZIP_DEFLATED) as z:
        for f in sorted(Path(root).rglob("*")):
            if f.is_file():
                info = zipfile.ZipInfo(f.relative_to(root).as_posix(), date_time=(2026, 1, 1, 0, 0, 0))
                info.external_attr = (0o755 if f.suffix in (".so", ".dll") else 0o644) << 16
                z.writestr(info, f.read_bytes(), compress_type=zipfile.ZIP_DEFLATED)
    os.replace(tmp_out, output)
    return output


def content_identity(*parts) -> tuple:
    """(tag, GUID) from a digest of ``parts`` (text or bytes) and of the native sources: the same content gives the same
    identity (a reproducible build), other content another."""
    digest = hashlib.sha256()
    for part in (*parts, *(f.read_bytes() for f in sorted(NATIVE.rglob("*.[ch]")))):
        data = part if isinstance(part, bytes) else str(part).encode()
        digest.update(len(data).to_bytes(8, "little") + data)
    h = digest.hexdigest()
    return h[:12], "{" + str(uuid.UUID(h[:32])) + "}"


def _identity(doc, fmi_version, assumed_modes, windows, tag, reproducible) -> tuple:
    """(model identifier, GUID, generationDateAndTime attribute) of a build: random and now, or (``reproducible``)
    from the content and none."""
    if reproducible:
        auto_tag, guid = content_identity(json.dumps(doc, sort_keys=True), fmi_version, assumed_modes, windows)
        tag, generated = tag or auto_tag, ""
    else:
        tag, guid, generated = tag or uuid.uuid4().hex[:12], "{" + str(uuid.uuid4()) + "}", None
    if not ("x" + tag).isidentifier():
        raise ValueError(f"tag {tag!r} must be alphanumeric")
    return f"RwadistWheelC_{tag}", guid, generated


def build_native_fmu(model, output, *, tag: str | None = None, assumed_modes: bool = False, fmi_version: int = 2,
                     windows: bool | None = None, reproducible: bool = False) -> Path:
    """Write the pure-C FMU of ``model`` (path, dict or WheelModel) to ``output`` (.fmu); returns its path.

    ``tag`` (default random) makes the model identifier ``RwadistWheelC_<tag>``.  ``assumed_modes``: as
    :func:`rwadist.fmu.build.build_fmu` (the start value of ``modes`` for a wheel with assumed modes).  ``fmi_version``: 2
    (FMI 2.0 co-simulation) or 3 (FMI 3.0).  The binary is built for Linux x86-64 (NativeBuildError elsewhere or
    without a C compiler) and, ``windows`` True or None, cross-compiled for Windows x86-64 with mingw-w64: None adds it
    where the cross compiler is found and warns (RuntimeWarning, saying how to get it) where it is not, True raises
    NativeBuildError there, False builds Linux only (~2.5 s less per build: the test suite's choice where it does not
    test Windows; a user's ``rwadist fmu build --native`` keeps None, so the FMU ships win64 wherever mingw-w64 is).
    ``reproducible``: tag (unless given) and GUID from the content, no generation time: the same model, options and
    sources give the same bytes (the SSP's FMUs).  ``sources/`` lets other platforms build their own."""
    if fmi_version not in C_SOURCES:
        raise ValueError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    doc = model_document(model)
    output = Path(output)
    if output.suffix != ".fmu":
        raise ValueError(f"output {str(output)!r} must end in .fmu")
    if not native_supported():
        raise NativeBuildError("the native FMU's binary is built on Linux x86-64 only (its sources/ build elsewhere)")
    if windows is None:
        windows = windows_compiler() is not None
        if not windows:
            warnings.warn(f"no Windows binary in the FMU ({os.environ.get('RWADIST_MINGW_CC', MINGW)} not found): "
                          f"{MINGW_HINT}", RuntimeWarning, stacklevel=2)
    model_identifier, guid, generated = _identity(doc, fmi_version, assumed_modes, windows, tag, reproducible)
    physics, modes_default = model_physics(doc, assumed_modes)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rwadist_cfmu_") as tmp:
        root = Path(tmp) / "fmu"
        src = root / "sources"
        src.mkdir(parents=True)
        source = C_SOURCES[fmi_version]
        copy_sources(src, fmi_version, (source, *COMMON_SOURCES))
        (src / "wheel_model.h").write_text(model_header(doc, guid, physics, modes_default))
        describe = model_description if fmi_version == 2 else model_description3
        (root / "modelDescription.xml").write_text(describe(model_identifier, guid, physics, modes_default, generated))
        if fmi_version == 3:
            (src / "buildDescription.xml").write_text(build_description3(model_identifier))
        compile_binaries(root, model_identifier, fmi_version, source, windows)
        (root / "documentation").mkdir()
        (root / "documentation" / "index.txt").write_text(
            f"rwadist wheel FMU (native C, FMI {fmi_version}.0 co-simulation).\nPhysics: {physics}\n"
            f"Binaries: {', '.join(sorted(p.name for p in (root / 'binaries').iterdir()))}.\n"
            f"Build on another platform: compile sources/{source} (C11 with complex.h) into a shared\n"
            f"library named {model_identifier} (e.g. fmpy.build.build_platform_binary on the unzipped FMU).\n")
        return zip_fmu(root, output)


def copy_sources(src, fmi_version: int, names) -> None:
    """Copy the native sources ``names`` and the FMI headers of ``fmi_version`` into the FMU's folder ``src``."""
    for name in names:
        shutil.copy2(NATIVE / name, src / name)
    folder, headers = FMI_HEADERS[fmi_version]
    for name in headers:
        shutil.copy2(NATIVE / folder / name, src / name)


def compile_binaries(root, model_identifier: str, fmi_version: int, source: str, windows: bool) -> None:
    """binaries/<platform>/<model_identifier>.so (and .dll with ``windows``) of the FMU folder ``root`` from its
    sources/ (the API file ``source``)."""
    platforms = PLATFORMS[fmi_version]
    for win in ((False, True) if windows else (False,)):
        bindir = Path(root) / "binaries" / platforms["windows" if win else "linux"]
        bindir.mkdir(parents=True)
        compile_sources(Path(root) / "sources", bindir / f"{model_identifier}.{'dll' if win else 'so'}",
                        source=source, windows=win)


def compile_c_host(output, *, windows: bool = False, fmi_version: int = 2) -> Path:
    """Compile ``native/c_host.c`` (a co-simulation host in C, no Python: dlopen or LoadLibrary, DoStep over a speed
    ramp; FMI 2.0, or FMI 3.0 with ``fmi_version`` 3) into the executable ``output``: for Linux with ``$CC``/``cc``,
    or for Windows (``windows``: a static .exe for Wine) with the mingw-w64 cross compiler; NativeBuildError on
    failure."""
    if fmi_version not in C_SOURCES:
        raise ValueError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    version = ["-DFMI3"] if fmi_version == 3 else []
    if windows:
        cc = windows_compiler()
        if cc is None:
            raise NativeBuildError(f"no Windows cross compiler: {MINGW_HINT}")
        cmd = [cc, "-O2", *version, f"-I{NATIVE}", "-o", str(output), str(NATIVE / "c_host.c"), "-static"]
    else:
        cc = shutil.which(os.environ.get("CC", "cc"))
        if cc is None:
            raise NativeBuildError(f"no C compiler ({os.environ.get('CC', 'cc')!r} not on PATH)")
        cmd = [cc, "-O2", *version, f"-I{NATIVE}", "-o", str(output), str(NATIVE / "c_host.c"), "-ldl"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise NativeBuildError(f"{' '.join(cmd)} failed:\n{res.stderr.strip()}")
    return Path(output)
