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
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import schema
from .data import DataError, read_json
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
        # the wheel's physical numbers (mass_kg, radius_m, max_speed_rpm, ...) feed presets and FMUs
        if isinstance(value, bool) or (isinstance(value, (int, float)) and not (
                math.isfinite(value) and value > 0)):
            raise err(source, f"wheel.{key}", f"{value!r}: must be a finite number > 0")
    name = doc.get("name", "wheel")
    if not isinstance(name, str):
        raise err(source, "name", f"must be a string, got {name!r}")
    analytical = doc.get("analytical")
    return WheelModel(name=name, wheel=doc.get("wheel", {}) or {},
                      empirical=schema.parse_empirical(doc.get("empirical", {}), source, err),
                      analytical=None if analytical is None else Analytical.from_json(analytical, source, err),
                      effects=list(schema.parse_effects(doc.get("effects", []), source, err)),
                      provenance=doc.get("provenance", {}) or {})


def load(path) -> WheelModel:
    return from_json(read_json(path), str(path))
