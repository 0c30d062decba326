"""Build the FMU of the extended wheel model with pythonfmu.

:func:`build_fmu` renders ``slave_template.py`` under a module and class name unique to the
build (two FMUs whose slave modules share a name cannot load in one process), and ships the slave it loads,
``slave.py`` (as ``rwadist_fmu_slave.py``), ``runtime.py`` (as ``rwadist_fmu_runtime.py``) with its sibling modules, ``rwadist/schema.py`` (as
``rwadist_model_schema.py``, the runtime's reader of the model file, with the effect elements of
:mod:`rwadist.effects` in ``rwadist_model_effects/`` and the units they read, ``rwadist_model_units.py``;
:func:`runtime_files`) and the model file
(``wheel_model.json``) in the FMU's resources.  pythonfmu embeds itself there too, so a host needs Python + numpy only.

Native layer (Linux x86-64, when a C compiler is found): ``native/rwadist_fmu_native.c`` is
compiled into ``binaries/linux64/<id>.so`` in front of pythonfmu's library (renamed
``<id>_pythonfmu.so``).  It forwards every FMI call, turns a refused input into fmi2Error
(pythonfmu alone reports fmi2Discard or fmi2Fatal), refuses the FMU-state calls with fmi2Error (the
modelDescription says canGetAndSetFMUstate = canSerializeFMUstate = false; pythonfmu's own would save the
variables only, not the modal and phase state) and carries the C step kernel the slave uses instead of numpy.
Without a compiler the FMU is pythonfmu's plain one: same results, slower steps, refused inputs reported as
fmi2Discard, and pythonfmu's own FMU-state calls (they answer fmi2OK
and restore the variables only: a host must not roll back with them; the capability flags say false).
"""
from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import uuid
import warnings
import zipfile
from pathlib import Path

from rwadist.presets import preset

HERE = Path(__file__).resolve().parent
TEMPLATE = HERE / "slave_template.py"
#: the slave implementation, shipped verbatim as resources/SLAVE_RESOURCE (the template loads it)
SLAVE = HERE / "slave.py"
SLAVE_RESOURCE = "rwadist_fmu_slave.py"
RUNTIME = HERE / "runtime.py"
TEMPLATE_CLASS = "RwadistWheelSlave"
NATIVE_SOURCE = HERE / "native" / "rwadist_fmu_native.c"
NATIVE_PLATFORM = "linux64"


class NativeBuildError(RuntimeError):
    """The native layer was required (``native=True``) but cannot be compiled here."""


def native_supported() -> bool:
    """True on Linux x86-64 (the platform the native layer is written for)."""
    return sys.platform.startswith("linux") and platform.machine() in ("x86_64", "AMD64")


#: compiled native layers of this process: (compiler, flags, digest of the sources) -> the library's bytes
_NATIVE_BUILDS: dict = {}


def compile_native(output) -> Path:
    """Compile the native layer to the shared library ``output``; NativeBuildError on failure.

    The compiler is ``$CC`` or ``cc``.  The library does not depend on the model (every FMU carries the same one),
    so a process compiles it once per compiler and source text and copies those bytes afterwards (the compiler's
    output is the same for the same input; ~0.5 s of CPU per FMU build saved).  A failure is not remembered."""
    cc = shutil.which(os.environ.get("CC", "cc"))
    if cc is None:
        raise NativeBuildError(f"no C compiler ({os.environ.get('CC', 'cc')!r} not on PATH)")
    output = Path(output)
    flags = ("-O2", "-fPIC", "-shared", "-ldl", "-lm", "-pthread")
    sources = hashlib.sha256()
    for f in (NATIVE_SOURCE, *sorted(NATIVE_SOURCE.parent.glob("*.h"))):      # the source and the headers it includes
        sources.update(f.name.encode() + b"\0" + f.read_bytes() + b"\0")
    key = (cc, flags, sources.hexdigest())
    if key in _NATIVE_BUILDS:
        output.write_bytes(_NATIVE_BUILDS[key])
        output.chmod(0o755)
        return output
    cmd = [cc, "-O2", "-fPIC", "-shared", "-o", str(output), str(NATIVE_SOURCE), "-ldl", "-lm", "-pthread"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise NativeBuildError(f"{' '.join(cmd)} failed:\n{res.stderr.strip()}")
    _NATIVE_BUILDS[key] = output.read_bytes()
    return output


def _add_native(fmu_path: Path, model_identifier: str, lib: Path) -> None:
    """Rewrite the FMU zip: pythonfmu's linux64 library moves to <id>_pythonfmu.so, ``lib``
    takes its place as <id>.so."""
    ours = f"binaries/{NATIVE_PLATFORM}/{model_identifier}.so"
    theirs = f"binaries/{NATIVE_PLATFORM}/{model_identifier}_pythonfmu.so"
    tmp = fmu_path.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(fmu_path) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        names = src.namelist()
        if ours not in names:
            raise NativeBuildError(f"pythonfmu wrote no {ours} into {fmu_path}")
        for info in src.infolist():
            data = src.read(info)
            if info.filename == ours:
                info = zipfile.ZipInfo(theirs, date_time=info.date_time)
                info.external_attr = 0o755 << 16
            dst.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED)
        zi = zipfile.ZipInfo(ours, date_time=(2026, 1, 1, 0, 0, 0))
        zi.external_attr = 0o755 << 16
        dst.writestr(zi, lib.read_bytes(), compress_type=zipfile.ZIP_DEFLATED)
    os.replace(tmp, fmu_path)


def has_native(fmu_path) -> bool:
    """True when the FMU at ``fmu_path`` carries the rwadist native layer."""
    with zipfile.ZipFile(fmu_path) as z:
        return any(n.endswith("_pythonfmu.so") for n in z.namelist())


def _schema_source() -> Path:
    """rwadist/schema.py (the installed package's, so an installed rwadist ships its own schema)."""
    from rwadist import schema
    return Path(schema.__file__)


def _runtime():
    from . import runtime
    return runtime


def model_document(model) -> dict:
    """The model-file document of ``model``: a path (JSON file), a parsed dict, or an
    ``rwadist.model.WheelModel``.  Validated with the FMU's own reader (runtime.ModelError)."""
    if isinstance(model, (str, Path)):
        path = Path(model)
        try:
            doc = json.loads(path.read_text())
        except OSError as exc:
            raise _runtime().ModelError(f"model file {str(path)!r} cannot be read: {exc.strerror or exc}") from None
        except json.JSONDecodeError as exc:
            raise _runtime().ModelError(f"model file {str(path)!r} is not valid JSON: {exc}") from None
        source = str(path)
    elif isinstance(model, dict):
        doc, source = model, "<model>"
    else:
        from rwadist import model as model_io
        doc, source = model_io.to_json(model), "<model>"
    from rwadist.model import from_json

    from_json(doc, source)      # the kit's one validation of the model file (keys, sections, physical ranges)
    rt = _runtime()
    params, lines = rt.model_from_doc(doc, source)
    effects = rt.effects_from_doc(doc, source)
    laws = effects["laws"]
    probe = rt.WheelRuntime(params, lines, modes=params["suspension"], **effects)
    for d, h in sorted(set(laws) - probe.laws_used):
        warnings.warn(f"{source}: amplitude_law of {d} h={h:g} matches no line of the model; the FMU ignores it",
                      RuntimeWarning, stacklevel=3)
    for j, (d, h, f_mod, _) in enumerate(effects["sidebands"]):
        if j not in probe.sidebands_used:
            warnings.warn(f"{source}: sidebands of {d} h={h:g} (f_mod {f_mod:g} Hz) match no line of the model; "
                          "the FMU ignores them", RuntimeWarning, stacklevel=3)
    return doc


def _check_shipped(doc, source: str = "<model>") -> None:
    """ModelError unless every effect of ``doc`` is of a kind the FMU's shipped elements read (rwadist/effects/): a
    kind registered elsewhere (a user's own module) would be read as unknown inside the FMU, and its actions
    silently left out."""
    from rwadist import effects, schema

    shipped = {f"{effects.__name__}.{p.stem}" for p in effects.shipped_files()}
    for i, e in enumerate(schema.parse_effects(doc.get("effects"), source)):
        module = type(e).__module__
        if not isinstance(e, schema.UnknownEffect) and module not in shipped:
            raise _runtime().ModelError(source, f"effects[{i}].kind", f"{e.kind!r} is registered by {module}, which "
                                        "the pythonfmu FMU does not ship (it reads the model file with rwadist's own "
                                        "elements); build the native FMU (`native`), which compiles the kind's "
                                        "actions in")


def _render(src: str, cls: str, physics: str, modes_default: bool) -> str:
    """The slave template for one build: class renamed, physics and ``modes`` start value set."""
    for name, value in (("BUILD_PHYSICS", physics), ("BUILD_MODES_DEFAULT", modes_default)):
        lines = [ln for ln in src.splitlines() if ln.lstrip().startswith(f"{name} = ")]
        if len(lines) != 1:
            raise RuntimeError(f"slave template lost its {name} line")
        indent = lines[0][:len(lines[0]) - len(lines[0].lstrip())]
        src = src.replace(lines[0], f"{indent}{name} = {value!r}")
    return src.replace(TEMPLATE_CLASS, cls)


def model_physics(doc, assumed_modes: bool = False) -> tuple:
    """(physics sentence, ``modes`` default) of a validated model document: modes default on only for a
    model with measured suspension modes, or assumed ones when ``assumed_modes`` (``--assumed-modes``)."""
    rt = _runtime()
    params, lines = rt.model_from_doc(doc)
    effects = rt.effects_from_doc(doc)
    modes_default = bool(params["suspension"]) and (not params["modes_assumed"] or bool(assumed_modes))
    return rt.physics_of(params, lines, effects), modes_default


def build_fmu(model, output, *, tag: str | None = None, native: bool | None = None,
              assumed_modes: bool = False) -> Path:
    """Write the FMU of ``model`` (path, dict or WheelModel) to ``output`` (.fmu path); returns it.

    ``tag`` (default: random) makes the slave module ``rwadist_wheel_<tag>`` and the class /
    model identifier ``RwadistWheel_<tag>`` unique to this build.  ``native``: add the native
    layer (module docstring); None (default) adds it where it can be compiled and warns where it
    cannot, True raises NativeBuildError where it cannot, False builds pythonfmu's plain FMU.
    ``assumed_modes``: a wheel whose suspension modes are assumed (``analytical.modes_assumed``) gets
    ``modes`` = true by default (else false: hard-mounted); the FMU warns at instantiation when it runs
    assumed modes.  A model without ``analytical`` is hard-mounted (``modes`` false)."""
    from pythonfmu import FmuBuilder

    doc = model_document(model)
    _check_shipped(doc)
    tag = tag or uuid.uuid4().hex[:12]
    if not tag.isidentifier() and not ("x" + tag).isidentifier():
        raise ValueError(f"tag {tag!r} must be alphanumeric")
    module, cls = f"rwadist_wheel_{tag}", f"RwadistWheel_{tag}"
    output = Path(output)
    if output.suffix != ".fmu":
        raise ValueError(f"output {str(output)!r} must end in .fmu")
    output.parent.mkdir(parents=True, exist_ok=True)
    if native and not native_supported():
        raise NativeBuildError(f"the native layer is for Linux x86-64, not {sys.platform} {platform.machine()}")
    src = TEMPLATE.read_text()
    if src.count(f"class {TEMPLATE_CLASS}(") != 1:
        raise RuntimeError("slave template lost its class")
    physics, modes_default = model_physics(doc, assumed_modes)
    with tempfile.TemporaryDirectory(prefix="rwadist_fmu_") as tmp_dir:
        tmp = Path(tmp_dir)
        extra = tmp / "extra"
        extra.mkdir()
        # the slave module beside its project files: pythonfmu imports it from there to find its class
        script = extra / f"{module}.py"
        script.write_text(_render(src, cls, physics, modes_default))
        project_files = runtime_files(extra)
        project_files.append(extra / SLAVE_RESOURCE)
        shutil.copy2(SLAVE, project_files[-1])
        (extra / "wheel_model.json").write_text(json.dumps(doc, indent=1) + "\n")
        path_before = list(sys.path)
        try:
            out = FmuBuilder.build_FMU(script, dest=output,
                                       project_files=project_files + [extra / "wheel_model.json"])
        finally:
            sys.path[:] = path_before
            # the slave module and everything it loaded under names made from it (runtime, siblings, model reader)
            for name in [n for n in sys.modules if n == module or n.startswith(f"{module}_slave")]:
                sys.modules.pop(name, None)
        if native is not False and native_supported():
            try:
                _add_native(Path(out), cls, compile_native(tmp / "native.so"))
            except NativeBuildError as exc:
                if native:
                    raise
                warnings.warn(f"rwadist FMU built without its native layer ({exc}): refused inputs are "
                              "reported as fmi2Discard and steps run in numpy", RuntimeWarning, stacklevel=2)
    return Path(out)


def runtime_files(folder) -> list:
    """Copy the FMU runtime into ``folder`` under its resource names: ``runtime.py`` as
    ``rwadist_fmu_runtime.py``, each sibling module (``runtime.SIBLINGS``) as ``runtime.fmu_file_name``,
    ``rwadist/schema.py`` as ``runtime.SCHEMA_FILE``, ``rwadist/units.py`` as ``runtime.UNITS_FILE`` and the effect
    elements (:func:`rwadist.effects.shipped_files`) into the folder ``runtime.EFFECTS_DIR``; returns the copies'
    paths (the FMU's project files)."""
    rt = _runtime()
    folder = Path(folder)
    out = [folder / "rwadist_fmu_runtime.py"]
    shutil.copy2(RUNTIME, out[0])
    for stem in rt.SIBLINGS:
        out.append(folder / rt.fmu_file_name(stem))
        shutil.copy2(HERE / f"{stem}.py", out[-1])
    out.append(folder / rt.SCHEMA_FILE)
    shutil.copyfile(_schema_source(), out[-1])
    # the effect elements, read by the schema copy, and the units they read (the runtime loads them as its package)
    from rwadist import effects, units

    out.append(folder / rt.UNITS_FILE)
    shutil.copyfile(units.__file__, out[-1])

    out.append(folder / rt.EFFECTS_DIR)
    out[-1].mkdir()
    for f in effects.shipped_files():
        shutil.copyfile(f, out[-1] / f.name)
    return out


def build_preset(name: str, output, **kw) -> Path:
    """FMU of a test-stand preset (e.g. 'ithaco-e'): ``rwadist.presets.preset(name).to_model()``."""
    return build_fmu(preset(name).to_model(), output, **kw)
