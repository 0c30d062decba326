"""The wheel model and its versioned JSON file (``shared/CONVENTIONS.md``).

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
torques.  Sections this version does not interpret (``analytical``,
``effects``) are carried through unchanged.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .data import DataError, read_json
from .units import DIRECTION_CHANNELS, DIRECTION_C_UNIT

SCHEMA = "rwadist.model"
SCHEMA_VERSION = 1
DIRECTIONS = tuple(DIRECTION_CHANNELS)


@dataclass
class Harmonic:
    """One empirical harmonic: amplitude C·Ω² at frequency h·|Ω|.

    h : harmonic number (dimensionless).  C : SI per (rad/s)².
    C_stderr : standard error of C (same unit), None if unknown.
    n_points : measurements the fit used.  presence : fraction of possible speeds
    where the line was detected.  excluded_rpm : speed ranges left out of the fit
    because a structural mode amplified the line, [[lo, hi], ...] in rpm.
    """

    h: float
    C: float
    C_stderr: float | None = None
    n_points: int = 0
    presence: float | None = None
    excluded_rpm: list = field(default_factory=list)
    sense: str | None = None

    def to_json(self) -> dict:
        d = asdict(self)
        return {k: v for k, v in d.items() if v is not None}


@dataclass
class WheelModel:
    """A wheel: geometry, empirical harmonics per direction, and pass-through sections."""

    name: str = "wheel"
    wheel: dict = field(default_factory=dict)
    empirical: dict = field(default_factory=lambda: {d: [] for d in DIRECTIONS})
    analytical: dict | None = None
    effects: list = field(default_factory=list)
    provenance: dict = field(default_factory=dict)

    def harmonics(self, direction: str) -> list:
        return self.empirical.get(direction, [])

    def h_and_C(self, direction: str):
        """Arrays (h, C) of a direction, SI."""
        hs = self.harmonics(direction)
        return (np.array([x.h for x in hs], dtype=float), np.array([x.C for x in hs], dtype=float))


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

def to_json(model: WheelModel) -> dict:
    doc = {
        "schema": SCHEMA,
        "schema_version": SCHEMA_VERSION,
        "name": model.name,
        "units": {"C": dict(DIRECTION_C_UNIT), "note": "amplitude = C * omega^2, omega in rad/s"},
        "wheel": model.wheel,
        "empirical": {d: [h.to_json() for h in model.empirical.get(d, [])] for d in DIRECTIONS},
        "effects": model.effects,
        "provenance": model.provenance,
    }
    if model.analytical is not None:
        doc["analytical"] = model.analytical
    return doc


def save(model: WheelModel, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_json(model), indent=2) + "\n")
    return path


def from_json(doc: dict, source: str = "<model>") -> WheelModel:
    if not isinstance(doc, dict):
        raise DataError(source, "document", "must be a JSON object")
    if doc.get("schema") != SCHEMA:
        raise DataError(source, "schema", f"{doc.get('schema')!r} is not {SCHEMA!r}; not an rwadist model file")
    version = doc.get("schema_version")
    if version != SCHEMA_VERSION:
        raise DataError(source, "schema_version", f"file has version {version!r}; this rwadist reads version "
                        f"{SCHEMA_VERSION} only")
    emp = doc.get("empirical", {}) or {}
    if not isinstance(emp, dict):
        raise DataError(source, "empirical", "must be an object keyed by direction")
    empirical = {}
    for d, items in emp.items():
        if d not in DIRECTIONS:
            raise DataError(source, f"empirical.{d}", f"unknown direction; expected one of {list(DIRECTIONS)}")
        hs = []
        for i, item in enumerate(items):
            where = f"empirical.{d}[{i}]"
            for key in ("h", "C"):
                v = item.get(key)
                if not isinstance(v, (int, float)) or not np.isfinite(v):
                    raise DataError(source, f"{where}.{key}", f"must be a finite number, got {v!r}")
            if item["h"] <= 0 or item["C"] < 0:
                raise DataError(source, where, f"needs h > 0 and C >= 0, got h={item['h']!r}, C={item['C']!r}")
            if item.get("sense") not in (None, "co", "counter", "planar"):
                raise DataError(source, f"{where}.sense", f"{item['sense']!r}; expected co, counter or planar")
            known = {k: item[k] for k in ("h", "C", "C_stderr", "n_points", "presence", "excluded_rpm", "sense")
                     if k in item}
            hs.append(Harmonic(**known))
        empirical[d] = hs
    for d in DIRECTIONS:
        empirical.setdefault(d, [])
    return WheelModel(name=doc.get("name", "wheel"), wheel=doc.get("wheel", {}) or {}, empirical=empirical,
                      analytical=doc.get("analytical"), effects=doc.get("effects", []) or [],
                      provenance=doc.get("provenance", {}) or {})


def load(path) -> WheelModel:
    return from_json(read_json(path), str(path))
