"""The wheel model and its versioned JSON file (``docs/formats.md``).

One document drives the kit, ``rwadist psd`` and the FMU::

    {
      "schema": "rwadist.model",
      "schema_version": 1,
      "name": "...",
      "wheel": {"mass_kg": ..., "radius_m": ..., "max_speed_rpm": ...},
      "empirical": {
        "radial_force":  [{"h": 1.0, "C": 3.79e-6, "C_stderr": 2e-8, ...}, ...],
        "radial_torque": [...], "axial_force": [...], "axial_torque": [...]
      },
      "analytical": {...}, "effects": [...], "provenance": {...}
    }

``C`` is SI per (rad/s)²: kg·m for forces (amplitude N = C·Ω²), kg·m² for
torques.  The document is read by the one typed schema, :mod:`rwadist.schema` (the
``analytical`` section and every ``effects`` entry become typed objects, validated once);
keys and effect kinds this version does not interpret are carried through unchanged.
"""
from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import effects as _effects  # noqa: F401  (imports every element: the schema reads every kind)
from . import schema
from .data import DataError, read_json
from .errors import RwadistWarning
from .schema import Analytical, Effect, Harmonic, ModelError
from .units import DIRECTION_C_UNIT, DIRECTION_CHANNELS

SCHEMA = schema.SCHEMA
SCHEMA_VERSION = schema.SCHEMA_VERSION
DIRECTIONS = tuple(DIRECTION_CHANNELS)

__all__ = ["Analytical", "Effect", "Harmonic", "ModelError", "ModelFileError", "WheelModel", "from_json", "load",
           "line_amplitudes", "model_rms", "save", "to_json"]


class ModelFileError(ModelError, DataError):
    """A bad model file read by the kit: a :class:`rwadist.schema.ModelError` (the one error of every
    consumer) that is also the kit's :class:`rwadist.data.DataError` (``file``, ``field``)."""


@dataclass
class WheelModel:
    """A wheel: geometry, empirical harmonics per direction, its extended-model parameters and its
    diagnosed effects.

    name : wheel name.  wheel : the ``wheel`` section (mass_kg, radius_m, max_speed_rpm, ...).
    empirical : {direction: [Harmonic]}.  analytical : :class:`rwadist.schema.Analytical` (a model
    file read by :func:`from_json`; a plain dict set in code is read the same way by its consumers)
    or None.  effects : [:class:`rwadist.schema.Effect`] (typed when read from a file).
    provenance : free-form."""

    name: str = "wheel"
    wheel: dict = field(default_factory=dict)
    empirical: dict = field(default_factory=lambda: {d: [] for d in DIRECTIONS})
    analytical: Any = None
    effects: list = field(default_factory=list)
    provenance: dict = field(default_factory=dict)

    def harmonics(self, direction: str) -> list:
        return list(self.empirical.get(direction, []))

    def h_and_C(self, direction: str) -> tuple:
        """Arrays (h, C) of a direction, SI."""
        hs = self.harmonics(direction)
        return (np.array([x.h for x in hs], dtype=float), np.array([x.C for x in hs], dtype=float))

    def typed_effects(self, source: str = "<model>", error: type = ModelError) -> tuple:
        """The effects as typed objects, validated (:func:`rwadist.schema.parse_effects`)."""
        return schema.parse_effects(self.effects, source, error)

    def typed_analytical(self, source: str = "<model>", error: type = ModelError) -> Analytical | None:
        """The analytical section as :class:`rwadist.schema.Analytical` (validated), or None."""
        return None if self.analytical is None else Analytical.from_json(self.analytical, source, error)


def line_amplitudes(model: WheelModel, direction: str, omega) -> tuple:
    """Line frequencies (Hz) and amplitudes (N or N·m) at wheel speeds ``omega`` (rad/s).

    Returns (f, a), each (n_speeds, n_harmonics): f = h·|Ω|/2π, a = C·Ω².
    """
    h, C = model.h_and_C(direction)
    w = np.abs(np.atleast_1d(np.asarray(omega, dtype=float)))[:, None]
    return h * w / (2 * np.pi), C * w**2


def model_rms(model: WheelModel, direction: str, omega, f_max: float | None = None) -> np.ndarray:
    """RMS (N or N·m) of one channel of a direction at speeds ``omega`` (rad/s), thesis Eq. 3.19,
    counting only lines at or below ``f_max`` Hz."""
    f, a = line_amplitudes(model, direction, omega)
    if f_max is not None:
        a = np.where(f <= f_max, a, 0.0)
    return np.sqrt(np.sum(a**2 / 2.0, axis=-1))


# --------------------------------------------------------------------------- file

def _json(x: Any) -> Any:
    return x.to_json() if isinstance(x, (Effect, Analytical)) else x


def to_json(model: WheelModel) -> dict:
    doc = {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "name": model.name,
        "units": {"C": dict(DIRECTION_C_UNIT), "note": "amplitude = C * omega^2, omega in rad/s"},
        "wheel": model.wheel,
        "empirical": {d: [h.to_json() for h in model.empirical.get(d, [])] for d in DIRECTIONS},
        "effects": [_json(e) for e in model.effects],
        "provenance": model.provenance,
    }
    if model.analytical is not None:
        doc["analytical"] = _json(model.analytical)
    return doc


def save(model: WheelModel, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_json(model), indent=2) + "\n")
    return path


def from_json(doc: dict, source: str = "<model>") -> WheelModel:
    """The typed, validated model of a parsed model document; :class:`ModelFileError` naming
    ``source`` and the field (``effects[2].amplitude_ref: missing``) on any bad entry."""
    err = ModelFileError
    schema.check_header(doc, source, err)
    for key in ("wheel", "provenance"):
        if doc.get(key) is not None and not isinstance(doc[key], dict):
            raise err(source, key, f"must be an object, got {type(doc[key]).__name__}")
    for key, value in (doc.get("wheel") or {}).items():
        if key == "bearings":
            continue                    # the bearings' geometry, checked below
        # the wheel's physical numbers (mass_kg, radius_m, max_speed_rpm, ...) feed presets and FMUs
        if isinstance(value, bool) or (isinstance(value, (int, float)) and not (
                math.isfinite(value) and value > 0)):
            raise err(source, f"wheel.{key}", f"{value!r}: must be a finite number > 0")
    from .bearings import BearingError, bearings_of

    try:
        bearings_of(doc.get("wheel"), source)
    except BearingError as exc:
        raise err(source, exc.field, exc.problem) from None
    name = doc.get("name", "wheel")
    if not isinstance(name, str):
        raise err(source, "name", f"must be a string, got {name!r}")
    analytical = doc.get("analytical")
    return WheelModel(name=name, wheel=doc.get("wheel", {}) or {},
                      empirical=schema.parse_empirical(doc.get("empirical", {}), source, err),
                      analytical=None if analytical is None else Analytical.from_json(analytical, source, err),
                      effects=list(schema.parse_effects(doc.get("effects", []), source, err)),
                      provenance=doc.get("provenance", {}) or {})


#: The keys of a model document (``units`` is a note for readers, written and not read).
DOCUMENT_KEYS = ("schema", "schema_version", "name", "units", "wheel", "empirical", "analytical", "effects",
                 "provenance")
#: Keys of the ``analytical`` section besides the parameters (:data:`PARAM_KEYS`): the model's kind, the flags and
#: the extended fit's own record
ANALYTICAL_KEYS = ("kind", "modes_assumed", "unconstrained", "fit")


def unread_keys(doc: Any) -> list:
    """Notes ``(path, what)`` on what of a model document this version does not read (a misspelt key is read as
    absent: ``"empirial"`` leaves the model without harmonics): keys of the document, of a harmonic and of the
    ``analytical`` section it does not know, and effect kinds it does not know (kept, as a newer writer's would be,
    but used by nothing); each with the closest known name.  Keys an effect carries besides its fields (evidence,
    law texts) are not listed: a writer may add them."""
    import difflib

    def like(key, known) -> str:
        close = difflib.get_close_matches(str(key), list(known), n=1, cutoff=0.6)
        return f" (did you mean {close[0]!r}?)" if close else ""

    if not isinstance(doc, dict):
        return []
    out = [(str(k), f"unknown key, not read{like(k, DOCUMENT_KEYS)}") for k in doc if k not in DOCUMENT_KEYS]
    emp = doc.get("empirical")
    if isinstance(emp, dict):
        known_h = (*schema.HARMONIC_CHECKS, "excluded_rpm")
        for d, items in emp.items():
            for i, item in enumerate(items if isinstance(items, list) else []):
                if isinstance(item, dict):
                    out += [(f"empirical.{d}[{i}].{k}", f"unknown key, not read{like(k, known_h)}")
                            for k in item if k not in known_h]
    ana = doc.get("analytical")
    if isinstance(ana, dict):
        known_a = (*schema.PARAM_KEYS.values(), *ANALYTICAL_KEYS)
        out += [(f"analytical.{k}", f"unknown key, not read{like(k, known_a)}") for k in ana if k not in known_a]
    effects = doc.get("effects")
    for i, e in enumerate(effects if isinstance(effects, list) else []):
        kind = e.get("kind") if isinstance(e, dict) else None
        if isinstance(kind, str) and kind not in schema.EFFECT_KINDS:
            out.append((f"effects[{i}].kind", f"{kind!r} is no effect kind this version knows{like(kind, schema.EFFECT_KINDS)}: "
                        "kept in the file, used by nothing"))
    return out


class ModelKeyWarning(RwadistWarning):
    """A model file holds a key or effect kind this version does not read (:func:`unread_keys`)."""


def load(path) -> WheelModel:
    """The model file at ``path``, parsed and validated; a :class:`ModelKeyWarning` per key or effect kind of the file
    this version does not read (the command line prints each as one line)."""
    doc = read_json(path)
    model = from_json(doc, str(path))
    for where, what in unread_keys(doc):
        warnings.warn(f"{path}: {where}: {what}", ModelKeyWarning, stacklevel=2)
    return model
