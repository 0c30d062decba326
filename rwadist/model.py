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
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import effects as _effects  # noqa: F401  (imports every element: the schema reads every kind)
from . import schema
from .data import DataError, read_json
from .errors import RwadistWarning
from .schema import (
    _ABSENT,
    COEFFICIENT,
    HARMONIC_NUMBER,
    MAX_COUNT,
    MAX_FREQ_HZ,
    MAX_HARMONICS,
    MAX_LENGTH_M,
    MAX_RPM,
    PARAM_MAX,
    SENSES,
    STDERR,
    Analytical,
    Effect,
    ModelError,
    _is_number,
    _refuse_unknown,
    choice,
    integer,
    number,
    optional,
    parse_effects,
)
from .units import DIRECTION_C_UNIT, DIRECTION_CHANNELS

SCHEMA = schema.SCHEMA
SCHEMA_VERSION = schema.SCHEMA_VERSION
DIRECTIONS = tuple(DIRECTION_CHANNELS)

__all__ = ["Analytical", "Effect", "Harmonic", "ModelError", "ModelFileError", "WheelModel", "from_json", "load",
           "line_amplitudes", "model_rms", "save", "to_json"]


# --------------------------------------------------------------------------- the document: harmonics, wheel, keys

#: Checks of an empirical harmonic's keys (``excluded_rpm``, a list of [lo, hi] rpm pairs, is checked apart).
HARMONIC_CHECKS = {"h": HARMONIC_NUMBER, "C": COEFFICIENT, "C_stderr": STDERR,
                   "n_points": optional(integer(le=MAX_COUNT), 0),
                   "presence": optional(number(ge=0, le=1)), "sense": optional(choice(SENSES))}


@dataclass
class Harmonic:
    """One empirical harmonic: amplitude C·Ω² at frequency h·|Ω|.

    h : harmonic number (dimensionless, > 0).  C : SI per (rad/s)² (>= 0; kg·m forces, kg·m² torques).
    C_stderr : standard error of C (same unit, >= 0), None if unknown.
    n_points : measurements the fit used (integer >= 0).  presence : fraction (0..1) of possible speeds
    where the line was detected.  excluded_rpm : speed ranges left out of the fit because a structural
    mode amplified the line, [[lo, hi], ...] in rpm, lo <= hi.  sense : 'co', 'counter', 'planar' or None.
    """

    h: float
    C: float
    C_stderr: float | None = None
    n_points: int = 0
    presence: float | None = None
    excluded_rpm: list = field(default_factory=list)
    sense: str | None = None

    def to_json(self) -> dict:
        # a standard error that could not be computed (NaN) is written null: NaN is no JSON
        stderr = None if self.C_stderr is None or not math.isfinite(self.C_stderr) else self.C_stderr
        d = {"h": self.h, "C": self.C, "C_stderr": stderr, "n_points": self.n_points,
             "presence": self.presence, "excluded_rpm": [list(p) for p in self.excluded_rpm], "sense": self.sense}
        return {k: v for k, v in d.items() if v is not None}

    @classmethod
    def from_json(cls, item: Any, source: str, path: str, error: type = ModelError) -> "Harmonic":
        if not isinstance(item, Mapping):
            raise error(source, path, f"must be an object, got {type(item).__name__}")
        _refuse_unknown(item, (*HARMONIC_CHECKS, "excluded_rpm"), source, f"{path}.", error)
        kw: dict = {}
        for key, fn in HARMONIC_CHECKS.items():
            v = fn(item.get(key, _ABSENT), (source, f"{path}.{key}"), error)
            if key in item:
                kw[key] = v
        ex = item.get("excluded_rpm", [])
        where = f"{path}.excluded_rpm"
        if not isinstance(ex, list):
            raise error(source, where, f"must be a list of [lo, hi] rpm pairs, got {ex!r}")
        for j, pair in enumerate(ex):
            if not isinstance(pair, (list, tuple)) or len(pair) != 2 or not all(
                    _is_number(x) and math.isfinite(x) and abs(x) <= MAX_RPM for x in pair) or pair[0] > pair[1]:
                raise error(source, f"{where}[{j}]", f"must be a pair [lo, hi] of finite speeds in rpm, |speed| <= "
                            f"{MAX_RPM:g}, with lo <= hi, got {pair!r}")
        kw["excluded_rpm"] = [list(p) for p in ex]
        return cls(**kw)


#: The keys of a model document (``units`` is a note for readers, written and not read).
DOCUMENT_KEYS = ("schema", "schema_version", "name", "units", "wheel", "empirical", "analytical", "effects",
                 "provenance")
#: The sections a model document must have (a wheel without harmonics has ``"empirical": {}``): a misspelt one
#: (``"empirial"``) is then an unknown key AND a missing section, never a model read without its harmonics.
REQUIRED_KEYS = ("schema", "schema_version", "empirical")
#: The ``wheel`` section: the wheel's datasheet numbers, each checked (a key not listed is an error: free-form notes
#: belong in ``provenance``).
WHEEL_CHECKS = {"mass_kg": optional(number(gt=0, le=PARAM_MAX["mass"])),
                "radius_m": optional(number(gt=0, le=MAX_LENGTH_M)),
                "max_speed_rpm": optional(number(gt=0, le=MAX_RPM)),
                "spin_inertia_kg_m2": optional(number(gt=0, le=PARAM_MAX["I_zz"])),
                "max_momentum_Nms": optional(number(gt=0, le=1e6)),
                "f_lim_hz": optional(number(gt=0, le=MAX_FREQ_HZ))}


def parse_document(doc: Any, source: str = "<model>", error: type = ModelError) -> dict:
    """The one validation of a model document, shared by every consumer: the header, every key known (or an
    extension, :data:`EXTENSION_PREFIX`), the required sections present, and every value of every section within
    its physical range (:data:`MAX_H` ...).  Returns the typed sections: ``name`` (str), ``wheel`` (dict),
    ``empirical`` ({direction: [Harmonic]}), ``analytical`` (:class:`Analytical` or None), ``effects`` (tuple of
    :class:`Effect`) and ``provenance`` (dict); ``error(source, field, problem)`` on the first bad one."""
    check_header(doc, source, error)
    _refuse_unknown(doc, DOCUMENT_KEYS, source, "", error, extensions=True)
    for key in REQUIRED_KEYS:
        if key not in doc:
            raise error(source, key, "missing: every model file has this section (a wheel without harmonics: "
                        '"empirical": {})')
    for key in ("wheel", "provenance", "units"):
        if doc.get(key) is not None and not isinstance(doc[key], Mapping):
            raise error(source, key, f"must be an object, got {type(doc[key]).__name__}")
    name = doc.get("name", "wheel")
    if not isinstance(name, str):
        raise error(source, "name", f"must be a string, got {name!r}")
    wheel = dict(doc.get("wheel") or {})
    _refuse_unknown(wheel, (*WHEEL_CHECKS, "bearings"), source, "wheel.", error)
    for key, fn in WHEEL_CHECKS.items():
        if key in wheel:
            fn(wheel[key], (source, f"wheel.{key}"), error)
    from .bearings import BearingError, bearings_of

    try:
        bearings_of(wheel, source)          # the bearings' geometry (rwadist.bearings)
    except BearingError as exc:
        raise error(source, exc.field, exc.problem) from None
    analytical = doc.get("analytical")
    return {"name": name, "wheel": wheel, "empirical": parse_empirical(doc["empirical"], source, error),
            "analytical": None if analytical is None else Analytical.from_json(analytical, source, error),
            "effects": parse_effects(doc.get("effects"), source, error), "provenance": dict(doc.get("provenance") or {})}


def check_header(doc: Any, source: str = "<model>", error: type = ModelError, reader: str = "this rwadist") -> None:
    """``error`` unless ``doc`` is a JSON object of schema rwadist.model, version :data:`SCHEMA_VERSION`."""
    if not isinstance(doc, Mapping):
        raise error(source, "document", "must be a JSON object")
    if doc.get("schema") != SCHEMA:
        raise error(source, "schema", f"{doc.get('schema')!r} is not {SCHEMA!r}; not an rwadist model file")
    version = doc.get("schema_version")
    if version != SCHEMA_VERSION:
        raise error(source, "schema_version", f"file has version {version!r}; {reader} reads version "
                    f"{SCHEMA_VERSION} only")


def parse_empirical(emp: Any, source: str = "<model>", error: type = ModelError) -> dict:
    """{direction: [Harmonic]} of the ``empirical`` section (every direction present, maybe empty)."""
    if emp is None:
        emp = {}
    if not isinstance(emp, Mapping):
        raise error(source, "empirical", "must be an object keyed by direction")
    out: dict = {}
    for d, items in emp.items():
        if d not in DIRECTIONS:
            raise error(source, f"empirical.{d}", f"unknown direction; expected one of {list(DIRECTIONS)}")
        if items is None:
            items = []
        if not isinstance(items, list):
            raise error(source, f"empirical.{d}", f"must be a list of harmonics, got {type(items).__name__}")
        if len(items) > MAX_HARMONICS:
            raise error(source, f"empirical.{d}", f"{len(items)} harmonics: at most {MAX_HARMONICS} per direction "
                        "(a real wheel shows tens)")
        out[d] = [Harmonic.from_json(item, source, f"empirical.{d}[{i}]", error) for i, item in enumerate(items)]
        _refuse_twice(out[d], source, f"empirical.{d}", error)
    for d in DIRECTIONS:
        out.setdefault(d, [])
    return out


def _refuse_twice(harmonics: list, source: str, path: str, error: type) -> None:
    """Refuse one line written twice in a direction: the same h (to 1e-9 relative) and the same sense.  Every
    consumer sums a direction's harmonics, so a repeated entry is counted twice (a new user's model with its 1x line
    copied: psd's Fx RMS 0.1033 N for 0.0762).  A co and a counter part of one h are two lines."""
    seen: dict = {}
    for i, hm in enumerate(harmonics):
        for j in seen.get(hm.sense, ()):
            if abs(harmonics[j].h - hm.h) <= 1e-9 * max(abs(hm.h), 1.0):
                sense = f"sense {hm.sense!r}" if hm.sense is not None else "no sense"
                raise error(source, f"{path}[{i}]", f"h {hm.h:g} ({sense}) is {path}[{j}] again: one line would be "
                            "counted twice; remove one (a line's co- and counter-rotating parts are two entries with "
                            "sense 'co' and 'counter')")
        seen.setdefault(hm.sense, []).append(i)


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
        "provenance": _json_safe(model.provenance),
    }
    if model.analytical is not None:
        doc["analytical"] = _json(model.analytical)
    return doc


def _json_safe(x: Any) -> Any:
    """A copy of a free-form JSON section (``provenance``) with every non-finite number as null (NaN is no JSON)."""
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    if isinstance(x, (float, np.floating)) and not math.isfinite(x):
        return None
    return x


def validate(model: WheelModel, source: str = "<model>") -> WheelModel:
    """``model`` (a :class:`WheelModel` built in code or read from a file) through the one validation of the model
    file (:func:`rwadist.schema.parse_document`): :class:`ModelFileError` naming ``source`` and the field when a
    consumer reading its file would refuse it; ``model`` itself otherwise."""
    from_json(to_json(model), source)
    return model


def save(model: WheelModel, path) -> Path:
    """Write ``model`` as a model file (valid JSON: no NaN); a model that :func:`from_json` would refuse is refused
    (:class:`ModelFileError` naming ``path`` and the field), nothing written."""
    path = Path(path)
    doc = to_json(model)
    from_json(doc, str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=2, allow_nan=False) + "\n")
    return path


def stamp(data: Any = None) -> dict:
    """What a model made now records of its making (its ``provenance``): the rwadist version, the date (UTC, ISO
    8601) and the data it came from (a path, or a description of a test built in memory)."""
    import datetime

    from .output_record import _version
    if isinstance(data, (str, Path)):
        source = str(data)
    elif data is not None and hasattr(data, "runs"):
        rpm = [abs(r.speed) * 60.0 / (2.0 * math.pi) for r in data.runs]
        source = (f"a test built in memory ({len(rpm)} runs, {min(rpm):.0f}-{max(rpm):.0f} rpm)" if rpm
                  else "a test built in memory")
    else:
        source = None
    out = {"rwadist": _version(), "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
    return out if source is None else dict(out, data=source)


def from_json(doc: dict, source: str = "<model>") -> WheelModel:
    """The typed, validated model of a parsed model document (:func:`rwadist.schema.parse_document`, the one
    validation of every consumer); :class:`ModelFileError` naming ``source`` and the field
    (``effects[2].amplitude_ref: missing``, ``empirial: unknown key (did you mean 'empirical'?)``) on any bad entry."""
    parts = parse_document(doc, source, ModelFileError)
    return WheelModel(name=parts["name"], wheel=parts["wheel"], empirical=parts["empirical"],
                      analytical=parts["analytical"], effects=list(parts["effects"]), provenance=parts["provenance"])


def unread_keys(doc: Any) -> list:
    """Notes ``(path, what)`` on what of a valid model document no consumer reads: extension keys and effect kinds
    (:data:`rwadist.schema.EXTENSION_PREFIX`), kept in the file and used by nothing.  (Any other key or kind a
    version does not know is an error of :func:`from_json`.)"""
    if not isinstance(doc, dict):
        return []
    out = [(str(k), "an extension key: kept in the file, read by no consumer") for k in doc
           if str(k).startswith(schema.EXTENSION_PREFIX)]
    effects = doc.get("effects")
    for i, e in enumerate(effects if isinstance(effects, list) else []):
        kind = e.get("kind") if isinstance(e, dict) else None
        if isinstance(kind, str) and kind.startswith(schema.EXTENSION_PREFIX):
            out.append((f"effects[{i}].kind", f"{kind!r} is an extension's effect kind: kept in the file, used by "
                        "nothing"))
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
