"""A catalogue of real wheels for early design: one model file per wheel (docs/formats.md).

Each file's ``provenance`` says where every number comes from: ``source`` (citation),
``measured`` (what was measured, what is a datasheet value, what is assumed) and
``date``; datasheet imbalance limits, where known, under ``datasheet_limits``.
:mod:`rwadist.catalogue.build_catalogue` writes the files from their sources.

    names()        -> sorted catalogue names
    load(name)     -> WheelModel (DataError for a file without source/measured/date)
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..data import DataError
from ..errors import ParameterError
from ..model import WheelModel
from ..model import load as _load_model

HERE = Path(__file__).parent
REQUIRED = ("source", "measured", "date")


def names() -> list:
    """Names of the catalogue wheels (file stems), sorted."""
    return sorted(p.stem for p in HERE.glob("*.json"))


def path(name: str) -> Path:
    key = str(name).strip().lower()
    p = HERE / f"{key}.json"
    if not p.exists():
        raise ParameterError("preset", f"{name!r}: unknown wheel; known: {', '.join(names())}")
    return p


def check_provenance(model: WheelModel, source) -> WheelModel:
    """A catalogue entry must say where its numbers come from."""
    for key in REQUIRED:
        if not model.provenance.get(key):
            raise DataError(source, f"provenance.{key}", "missing: every catalogue entry states its source, "
                            "what was measured and the date")
    return model


def load(name: str) -> WheelModel:
    """The catalogue wheel ``name`` as a :class:`~rwadist.model.WheelModel`."""
    p = path(name)
    return check_provenance(_load_model(p), p)


def _imbalances(model: WheelModel) -> dict:
    """U_s (kg·m), U_d (kg·m²) of a model: its analytical section, else its h ≈ 1 radial lines."""
    out = {}
    a = model.analytical or {}
    if "U_s_kg_m" in a:
        out["U_s_kg_m"], out["U_d_kg_m2"] = float(a["U_s_kg_m"]), float(a["U_d_kg_m2"])
        return out
    for d, key in (("radial_force", "U_s_kg_m"), ("radial_torque", "U_d_kg_m2")):
        near = [h for h in model.harmonics(d) if abs(h.h - 1.0) <= 0.03]
        if near:
            out[key] = max(h.C for h in near)
    return out


def compare(fitted: WheelModel, reference: WheelModel, h_tol: float = 0.03) -> dict:
    """A fitted model next to a catalogue wheel of the same type.

    Returns {"harmonics": [(direction, h_fit, C_fit, h_ref, C_ref)], "imbalance": [(name, fitted,
    limit, above)]}: harmonics matched by nearest h within ``h_tol`` (None where only one side
    has the line); imbalances against the reference's datasheet limits (or its values when no
    limit is stated), ``above`` True when the fitted one exceeds it.
    """
    rows = []
    for d in ("radial_force", "radial_torque", "axial_force", "axial_torque"):
        ref = list(reference.harmonics(d))
        used = set()
        for h in fitted.harmonics(d):
            best = min(range(len(ref)), key=lambda i: abs(ref[i].h - h.h), default=None)
            if best is not None and abs(ref[best].h - h.h) <= h_tol and best not in used:
                used.add(best)
                rows.append((d, h.h, h.C, ref[best].h, ref[best].C))
            else:
                rows.append((d, h.h, h.C, None, None))
        rows += [(d, None, None, r.h, r.C) for i, r in enumerate(ref) if i not in used]
    limits = reference.provenance.get("datasheet_limits") or _imbalances(reference)
    mine = _imbalances(fitted)
    imb = [(k, mine.get(k), limits.get(k), bool(mine.get(k) is not None and limits.get(k) is not None
                                                 and mine[k] > limits[k]))
           for k in ("U_s_kg_m", "U_d_kg_m2")]
    return {"harmonics": rows, "imbalance": imb}


#: what every output built on assumed suspension modes says (psd note files, FMU log, simulate-test meta)
ASSUMED_MODES_NOTE = ("the suspension modes of {name} are ASSUMED (datasheet wheel: analytical.modes_assumed), "
                      "not measured; outputs with the modes are built on assumed values -- unless they are asked "
                      "for (`assumed_modes`) the wheel runs hard-mounted, as its datasheet states")


def write_assumed_note(note_path, names, outputs, wording=str, write_to=None):
    """Say on stderr and in ``note_path`` (a text file next to ``outputs``) that the outputs of wheels
    ``names`` rest on assumed (datasheet) suspension modes (:data:`ASSUMED_MODES_NOTE`, passed through
    ``wording``: the command line names its flags).  Returns the path.  ``write_to``: the temporary of
    ``note_path`` in a set of outputs (:func:`rwadist.outputs.output_set`) to write instead, swapped in with the set."""
    import sys
    from pathlib import Path

    note_path = Path(note_path)
    note = "WARNING: " + wording(ASSUMED_MODES_NOTE.format(name=", ".join(str(n) for n in names)))
    print(note, file=sys.stderr)
    from ..outputs import atomic_file

    text = note + "\n(this note belongs to " + ", ".join(str(p) for p in outputs) + ")\n"
    if write_to is not None:
        Path(write_to).write_text(text)
    else:
        note_path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_file(note_path) as tmp:
            Path(tmp).write_text(text)
    print(f"note written next to the outputs: {note_path}")
    return note_path


def modes_assumed(model) -> bool:
    """True when ``model`` (a :class:`~rwadist.model.WheelModel`) carries ``analytical.modes_assumed``:
    its suspension modes are assumed (a datasheet wheel), not measured.  DataError on a non-boolean."""
    an = getattr(model, "analytical", None)
    if not isinstance(an, Mapping):
        return False
    v = an.get("modes_assumed", False)
    if not isinstance(v, bool):
        raise DataError(getattr(model, "name", "<model>"), "analytical.modes_assumed",
                        f"must be true or false, got {v!r}")
    return v


def preset_model(name: str):
    """The catalogue model of preset ``name`` (with its provenance and ``modes_assumed``), or None for a
    test-stand preset that is not in the catalogue."""
    key = str(name).strip().lower()
    return load(key) if key in names() else None


def source_modes_assumed(model=None, preset: str | None = None) -> bool:
    """True when a command's wheel has assumed suspension modes: ``model`` (a WheelModel or a model file
    path), else the catalogue wheel ``preset`` (a test-stand preset outside the catalogue: False)."""
    if isinstance(model, (str, Path)):
        model = _load_model(model)
    if model is None and preset:
        model = preset_model(preset)
    return model is not None and modes_assumed(model)
