"""Build the FMU of the extended wheel model with pythonfmu.

:func:`build_fmu` renders ``slave_template.py`` under a module and class name unique to the
build (two FMUs whose slave modules share a name cannot load in one process), and ships
``runtime.py`` (as ``rwadist_fmu_runtime.py``) and the model file (``wheel_model.json``) in the
FMU's resources.  pythonfmu embeds itself there too, so a host needs Python + numpy only.
"""
from __future__ import annotations

import json
import shutil
import sys
import tempfile
import uuid
from pathlib import Path

HERE = Path(__file__).resolve().parent
TEMPLATE = HERE / "slave_template.py"
RUNTIME = HERE / "runtime.py"
TEMPLATE_CLASS = "RwadistWheelSlave"


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
    _runtime().model_from_doc(doc, source)
    return doc


def build_fmu(model, output, *, tag: str | None = None) -> Path:
    """Write the FMU of ``model`` (path, dict or WheelModel) to ``output`` (.fmu path); returns it.

    ``tag`` (default: random) makes the slave module ``rwadist_wheel_<tag>`` and the class /
    model identifier ``RwadistWheel_<tag>`` unique to this build."""
    from pythonfmu import FmuBuilder

    doc = model_document(model)
    tag = tag or uuid.uuid4().hex[:12]
    if not tag.isidentifier() and not ("x" + tag).isidentifier():
        raise ValueError(f"tag {tag!r} must be alphanumeric")
    module, cls = f"rwadist_wheel_{tag}", f"RwadistWheel_{tag}"
    output = Path(output)
    if output.suffix != ".fmu":
        raise ValueError(f"output {str(output)!r} must end in .fmu")
    output.parent.mkdir(parents=True, exist_ok=True)
    src = TEMPLATE.read_text()
    if src.count(f"class {TEMPLATE_CLASS}(") != 1:
        raise RuntimeError("slave template lost its class")
    with tempfile.TemporaryDirectory(prefix="rwadist_fmu_") as tmp:
        tmp = Path(tmp)
        script = tmp / f"{module}.py"
        script.write_text(src.replace(TEMPLATE_CLASS, cls))
        extra = tmp / "extra"
        extra.mkdir()
        shutil.copy2(RUNTIME, extra / "rwadist_fmu_runtime.py")
        (extra / "wheel_model.json").write_text(json.dumps(doc, indent=1) + "\n")
        path_before = list(sys.path)
        try:
            out = FmuBuilder.build_FMU(script, dest=output,
                                       project_files=[extra / "rwadist_fmu_runtime.py", extra / "wheel_model.json"])
        finally:
            sys.path[:] = path_before
            for name in (module, f"{module}_runtime"):
                sys.modules.pop(name, None)
    return Path(out)


def build_preset(name: str, output, **kw) -> Path:
    """FMU of a test-stand preset (e.g. 'ithaco-e'): ``rwadist.teststand.preset(name).to_model()``."""
    from rwadist.presets import preset
    return build_fmu(preset(name).to_model(), output, **kw)
