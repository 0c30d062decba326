"""The model file (``rwadist.model`` version 1) as typed objects: parsed and validated once.

One reader for every consumer: the kit (:mod:`rwadist.model`, :mod:`rwadist.extended`,
``rwadist psd``), the coupling package and the FMU runtime.  A bad field gives the same
:class:`ModelError` everywhere, naming the file and the field (``model.json:
effects[2].amplitude_ref: missing``).

This module imports numpy only (never rwadist): ``rwadist fmu build`` copies it byte for byte
into the FMU's resources, where the runtime imports the copy (a test pins the copy to this file).

Effects.  Every diagnosed effect kind (``rwadist diagnose``) is an element of :mod:`rwadist.effects`
(one module per kind, shipped into the FMU beside this one): a frozen dataclass derived from
:class:`Effect` and registered under its ``kind`` in :data:`EFFECT_KINDS`; its fields are the file's
keys, each declared with its check (:func:`number`, :func:`choice`, ...)::

    @register
    @dataclass(frozen=True, eq=False, kw_only=True)
    class NewKind(Effect):
        KIND: ClassVar[str] = "new_kind"
        direction: str = field(metadata=check(choice(DIRECTIONS)))
        h: float = field(metadata=check(POSITIVE))

This module knows no kind: it reads the kinds registered when it parses.  Keys a class does not declare (the ``evidence`` of the search, ``law`` texts, ``unit``) are
carried through unchanged, and an entry parsed from a file is written back exactly as read
(:meth:`Effect.to_json`), so loading and saving a file changes no byte.  An effect kind this
version does not know is kept as an :class:`UnknownEffect` (read by no consumer), as a
newer writer's section would be.  Effects read like the JSON objects they came from
(``effect["h"]``, ``effect.get("role")``) and compare equal to them.

Units: SI (rad/s, Hz, N, N·m, kg, m), rpm only in ``excluded_rpm`` and the ``wheel`` section.
"""
from __future__ import annotations

import copy
import math
from abc import abstractmethod
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

SCHEMA = "rwadist.model"
SCHEMA_VERSION = 1
DIRECTIONS = ("radial_force", "radial_torque", "axial_force", "axial_torque")
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
SENSES = ("co", "counter", "planar")
ANALYTICAL_KIND = "rigid_rotor_5dof"
#: Suspension modes an extended fit may leave unidentified (``analytical.unconstrained``).
UNCONSTRAINED_MODES = ("radial_translation", "rocking", "axial")
#: ... and the damping ratios of located modes the data do not measure (held, with the bounds the data allow in
#: ``analytical.fit.zeta_bounds``): either may be listed in ``analytical.unconstrained``
UNCONSTRAINED_DAMPING = ("zeta_radial_translation", "zeta_rocking", "zeta_axial")
#: Model-file keys of the extended-model parameters (parameter name -> key with its unit): the one
#: table the kit (:class:`rwadist.extended.ExtendedParams`) and the FMU runtime read.
PARAM_KEYS = {
    "mass": "mass_kg", "I_zz": "I_zz_kg_m2", "I_rr": "I_rr_kg_m2",
    "k_r": "k_r_N_per_m", "c_r": "c_r_N_s_per_m",
    "k_rock": "k_rock_Nm_per_rad", "c_rock": "c_rock_Nm_s_per_rad",
    "k_z": "k_z_N_per_m", "c_z": "c_z_N_s_per_m",
    "height": "height_m", "U_s": "U_s_kg_m", "U_d": "U_d_kg_m2",
}
#: Parameters that must be > 0 (the others >= 0, except the signed ``height``).
POSITIVE_PARAMS = ("mass", "I_zz", "I_rr", "k_r", "k_rock", "k_z")
NONNEGATIVE_PARAMS = ("c_r", "c_rock", "c_z", "U_s", "U_d")
#: The largest I_zz/I_rr of a model's rotor (``analytical``, and ``suspension_modes.inertia_ratio``).  A rigid rotor
#: about its centre of mass has I_zz <= 2 I_rr, but the ratio a fit from measured whirls gives is an effective one (a
#: flexible rim or spokes, rocking coupled with other motion, or a test wheel generated beyond that bound: the
#: issue-33 family goes to 2.2): a model holding up to this is valid; above 2 the fit says so in its notes.
MAX_INERTIA_RATIO = 3.0
#: The largest magnitude of each parameter (SI; a per-unit model's k/M and c/M are far below): a value beyond is a
#: unit slip or a corrupted file (the ranges of the whole file: "physical ranges" below)
PARAM_MAX = {"mass": 1e4, "I_zz": 1e4, "I_rr": 1e4, "k_r": 1e13, "c_r": 1e10, "k_rock": 1e13, "c_rock": 1e10,
             "k_z": 1e13, "c_z": 1e10, "height": 10.0, "U_s": 1.0, "U_d": 1.0}


class RwadistError(Exception):
    """The root of every error rwadist raises on purpose (:mod:`rwadist.errors` has the hierarchy).

    Defined here, not in :mod:`rwadist.errors`, because this module is copied alone into the FMU (numpy
    only): the FMU runtime's :class:`ModelError` needs its base beside it."""


class ModelError(RwadistError, ValueError):
    """An invalid model file or entry.

    ``ModelError(source, field, problem)`` reads ``"<source>: <field>: <problem>"``; the parts are kept
    as ``source`` (also ``file``), ``field`` and ``problem``.  ``ModelError(message)`` is an error that
    is not about one field (a refused input of the FMU runtime).  Consumers with their own error
    types subclass it (``class X(ModelError, TheirError)``) so one ``except ModelError`` catches all."""

    def __init__(self, source: object, field: str | None = None, problem: str | None = None):
        self.source = self.file = str(source)
        self.field = field
        self.problem = problem
        message = self.source if field is None else f"{self.source}: {field}: {problem}"
        Exception.__init__(self, message)


# =========================================================================== field checks
#
# A check is fn(value, where, err) -> the typed value: ``where`` = (source, field path) for the error
# ``err(source, path, problem)``, ``value`` the file's value or _ABSENT.  Its ``json`` attribute is the
# JSON Schema fragment of the same rule (rwadist/schema_json.py builds docs/model.schema.json from it).

Check = Callable[[Any, tuple, type], Any]
_ABSENT = object()


def _fail(where: tuple, err: type, problem: str):
    raise err(where[0], where[1], problem)


def _is_number(v: Any) -> bool:
    return (not isinstance(v, (bool, np.bool_))) and isinstance(v, (int, float, np.integer, np.floating))


def _plain(v: Any) -> Any:
    """Python int/float of a numpy scalar (JSON-serialisable); other values as they are."""
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.floating):
        return float(v)
    return v


def number(gt: float | None = None, ge: float | None = None, le: float | None = None) -> Check:
    """A finite number (booleans are not numbers) with optional bounds gt < v, ge <= v, v <= le."""
    need = " and ".join(f"{op} {b:g}" for op, b in ((">", gt), (">=", ge), ("<=", le)) if b is not None)
    text = "a finite number" + (f" {need}" if need else "")

    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if not _is_number(v) or not math.isfinite(v) or (gt is not None and not v > gt) \
                or (ge is not None and not v >= ge) or (le is not None and not v <= le):
            _fail(where, err, f"must be {text}, got {v!r}")
        return _plain(v)
    run.json = {"type": "number", **({"exclusiveMinimum": gt} if gt is not None else {}),  # type: ignore[attr-defined]
                **({"minimum": ge} if ge is not None else {}), **({"maximum": le} if le is not None else {})}
    return run


def integer(ge: int = 0, le: int | None = None) -> Check:
    """An integer >= ``ge`` (and <= ``le``); a float with an integral value, as JSON may write it, is refused."""
    text = f"an integer >= {ge}" + (f" and <= {le}" if le is not None else "")

    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < ge \
                or (le is not None and v > le):
            _fail(where, err, f"must be {text}, got {v!r}")
        return int(v)
    run.json = {"type": "integer", "minimum": ge, **({"maximum": le} if le is not None else {})}  # type: ignore[attr-defined]
    return run


def optional(inner: Check, default: Any = None) -> Check:
    """``inner`` when present and not null; ``default`` when absent or null."""
    def run(v, where, err):
        if v is _ABSENT or v is None:
            return default
        return inner(v, where, err)
    run.json = {"anyOf": [inner.json, {"type": "null"}]}  # type: ignore[attr-defined]
    run.optional = True  # type: ignore[attr-defined]
    return run


def statistic(ge: float | None = 0.0, le: float | None = None) -> Check:
    """A fitted statistic (a standard error, a phase): null or absent -> None (unknown, or could not be computed),
    else a finite number in [``ge``, ``le``].  NaN is refused: it is not JSON (other tools cannot read the file),
    and null says the same."""
    inner = number(ge=ge, le=le)

    def run(v, where, err):
        if v is _ABSENT or v is None:
            return None
        if _is_number(v) and math.isnan(v):
            _fail(where, err, "NaN is not a JSON number: write null for a statistic that could not be computed")
        return inner(v, where, err)
    run.json = {"anyOf": [inner.json, {"type": "null"}]}  # type: ignore[attr-defined]
    run.optional = True  # type: ignore[attr-defined]
    return run


def choice(options: tuple) -> Check:
    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if not isinstance(v, str) or v not in options:
            _fail(where, err, f"{v!r} is not one of {', '.join(options)}")
        return v
    run.json = {"enum": list(options)}  # type: ignore[attr-defined]
    return run


def names(options: tuple) -> Check:
    """One name of ``options`` or a non-empty list of them -> tuple (duplicates dropped, order kept)."""
    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        items = [v] if isinstance(v, str) else v
        if not isinstance(items, (list, tuple)) or not items or any(not isinstance(x, str) or x not in options
                                                                    for x in items):
            _fail(where, err, f"{v!r} must be one of {', '.join(options)} or a non-empty list of them")
        return tuple(dict.fromkeys(items))
    run.json = {"anyOf": [{"enum": list(options)},  # type: ignore[attr-defined]
                          {"type": "array", "items": {"enum": list(options)}, "minItems": 1}]}
    return run


def numbers(min_len: int = 0, length: int | None = None, ge: float | None = None,
            increasing: bool = False, le: float | None = None, max_len: int | None = None) -> Check:
    """A list of finite numbers (each in [``ge``, ``le``], at most ``max_len`` of them) -> float array (read-only)."""
    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if not isinstance(v, (list, tuple, np.ndarray)) or any(not _is_number(x) for x in v):
            _fail(where, err, f"must be a list of numbers, got {v!r}")
        a = np.array(v, dtype=float)
        if a.ndim != 1 or not np.all(np.isfinite(a)):
            _fail(where, err, f"must be a list of finite numbers, got {v!r}")
        if a.size < min_len:
            _fail(where, err, f"must have at least {min_len} values, got {a.size}")
        if length is not None and a.size != length:
            _fail(where, err, f"must have {length} values, got {a.size}")
        if max_len is not None and a.size > max_len:
            _fail(where, err, f"must have at most {max_len} values, got {a.size}")
        if ge is not None and a.size and a.min() < ge:
            _fail(where, err, f"values must be >= {ge:g}, got {float(a.min())!r}")
        if le is not None and a.size and a.max() > le:
            _fail(where, err, f"values must be <= {le:g}, got {float(a.max())!r}")
        if increasing and np.any(np.diff(a) <= 0):
            _fail(where, err, f"must be strictly increasing, got {v!r}")
        a.setflags(write=False)
        return a
    run.json = {"type": "array", "items": {"type": "number", **({"minimum": ge} if ge is not None else {}),  # type: ignore[attr-defined]
                                           **({"maximum": le} if le is not None else {})},
                **({"minItems": min_len} if min_len else {}), **({"maxItems": max_len} if max_len else {}),
                **({"minItems": length, "maxItems": length} if length is not None else {})}
    return run


def text() -> Check:
    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if not isinstance(v, str):
            _fail(where, err, f"must be a string, got {v!r}")
        return v
    run.json = {"type": "string"}  # type: ignore[attr-defined]
    return run


def boolean() -> Check:
    def run(v, where, err):
        if v is _ABSENT:
            _fail(where, err, "missing")
        if not isinstance(v, bool):
            _fail(where, err, f"must be true or false, got {v!r}")
        return v
    run.json = {"type": "boolean"}  # type: ignore[attr-defined]
    return run


def check(fn: Check, key: str | None = None) -> dict:
    """Field metadata: the field's check and, when it differs from the field name, its file key."""
    return {"check": fn, "key": key}


def _json_value(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return [float(x) for x in v]
    if isinstance(v, tuple):
        return [_json_value(x) for x in v]
    v = _plain(v)
    return None if isinstance(v, float) and math.isnan(v) else v    # NaN is no JSON: null (refused where required)


# =========================================================================== effects

class _ReadsAsJson(Mapping):
    """Read-only mapping view of a typed section: it reads as (and iterates like) its ``to_json()`` object,
    so code written for the file's dicts reads the typed value unchanged."""

    @abstractmethod
    def to_json(self) -> dict:
        """The section as the model file's JSON object."""

    def __getitem__(self, key: str) -> Any:
        return self.to_json()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.to_json())

    def __len__(self) -> int:
        return len(self.to_json())


@dataclass(frozen=True, eq=False, kw_only=True)
class Effect(_ReadsAsJson):
    """A diagnosed effect of the model file's ``effects`` list (base class; see the module docstring).

    extra : keys the class does not interpret (``evidence``, ``law`` texts, ...), carried through.
    Reads as the JSON object it came from (a read-only Mapping) and equals it."""

    KIND: ClassVar[str] = ""
    #: True for a kind a wheel has at most one of (:func:`parse_effects` refuses a second)
    ONE_PER_WHEEL: ClassVar[bool] = False
    extra: Mapping = field(default_factory=dict, repr=False)

    # the document this effect was parsed from, written back unchanged (not an init field, so
    # dataclasses.replace() makes an effect that is serialised from its fields)
    _source_json: dict | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def kind(self) -> str:
        return self.KIND

    @classmethod
    def spec(cls) -> list:
        """[(field name, file key, check)] of the class's typed fields."""
        return [(f.name, f.metadata.get("key") or f.name, f.metadata["check"]) for f in fields(cls)
                if "check" in f.metadata]

    @classmethod
    def from_json(cls, doc: Mapping, source: str, path: str, error: type = ModelError) -> "Effect":
        kw = {}
        for name, key, fn in cls.spec():
            kw[name] = fn(doc.get(key, _ABSENT), (source, f"{path}.{key}"), error)
        keys = {key for _, key, _ in cls.spec()} | {"kind"}
        kw["extra"] = {k: v for k, v in doc.items() if k not in keys}
        out = cls(**kw)
        cls._validate(out, source, path, error)
        object.__setattr__(out, "_source_json", _plain_doc(doc))
        return out

    def _validate(self, source: str, path: str, error: type) -> None:
        """Checks across fields (a subclass's); ``error(source, f"{path}.<key>", problem)``."""

    def to_json(self) -> dict:
        """The file's JSON object: the parsed document unchanged, or the fields (then ``extra``)."""
        if self._source_json is not None:
            return copy.deepcopy(self._source_json)
        out: dict = {"kind": self.KIND}
        for name, key, _ in self.spec():
            v = getattr(self, name)
            if v is not None:
                out[key] = _json_value(v)
        out.update(copy.deepcopy(dict(self.extra)))
        return out

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Mapping):
            return self.to_json() == dict(other.items()) if not isinstance(other, Effect) \
                else self.to_json() == other.to_json()
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]


def _plain_doc(x: Any) -> Any:
    """A JSON-safe deep copy (numpy scalars to Python numbers)."""
    if isinstance(x, Mapping):
        return {k: _plain_doc(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain_doc(v) for v in x]
    return _plain(x)


#: kind -> Effect subclass
EFFECT_KINDS: dict[str, type[Effect]] = {}


def register(cls: type[Effect]) -> type[Effect]:
    """Class decorator: make ``cls`` the reader of effects of kind ``cls.KIND``."""
    if not cls.KIND or cls.KIND in EFFECT_KINDS:
        raise ValueError(f"effect kind {cls.KIND!r} is empty or registered twice")
    EFFECT_KINDS[cls.KIND] = cls
    return cls


@dataclass(frozen=True, eq=False, kw_only=True)
class UnknownEffect(Effect):
    """An effect kind this version does not know: carried through unchanged, read by no consumer."""

    unknown_kind: str = ""

    @property
    def kind(self) -> str:
        return self.unknown_kind

    def to_json(self) -> dict:
        if self._source_json is not None:
            return copy.deepcopy(self._source_json)
        return {"kind": self.unknown_kind, **copy.deepcopy(dict(self.extra))}


# =========================================================================== physical ranges
#
# The widest values a real reaction wheel shows, with a wide margin: a value beyond one is a unit slip, a corrupted
# file or an overflow, and every consumer (show, psd, campbell, the FMU, diagnose, coupling, the API) refuses it
# alike, naming the field (docs/formats.md, "Value ranges").  Real wheels: h 0.1-100, C 1e-9-1e-4 kg·m (kg·m²),
# speeds to ~10 000 rpm, resonances below a few kHz with gains below ~200, amplitude exponents 0-4.

MAX_H = 1000.0                      #: harmonic number h (bearing and motor harmonics reach a few hundred)
MAX_C = 1.0                         #: C, kg·m (forces) or kg·m² (torques): 1 gives 1e6 N at 1000 rad/s
MAX_RPM = 100_000.0                 #: wheel speed, rpm (as the command line's speeds)
MAX_OMEGA_RAD_S = MAX_RPM * 2.0 * math.pi / 60.0
MAX_FREQ_HZ = 1e6                   #: a frequency of the model (mode, modulation, ripple, knots), Hz
MAX_EXPONENT = 10.0                 #: amplitude ∝ |Ω|^exponent (C·Ω² is 2; measured laws 0-4)
MAX_GAIN = 1e4                      #: a resonance's peak gain (Q = 1/2ζ)
MAX_ZETA = 10.0                     #: a damping ratio
MAX_DEPTH = 10.0                    #: a sideband's modulation depth (relative to its carrier)
MAX_AMPLITUDE = 1e6                 #: a line's amplitude, N or N·m
MAX_PSD = 1e12                      #: a blocked-load PSD, N²/Hz or (N·m)²/Hz
MAX_LENGTH_M = 10.0                 #: a length (lever arm, height), m
MAX_ALPHA_RAD_S2 = 1e5              #: a spin acceleration, rad/s²
MAX_TRANSFER = 1e6                  #: a noise transfer factor
MAX_COUNT = 10**9                   #: a count of points or runs
MAX_HARMONICS = 1000                #: harmonics per direction
MAX_EFFECTS = 1000                  #: entries of ``effects``
MAX_KNOTS = 100_000                 #: knots of a broadband floor

#: Checks the elements' fields share: a number > 0, a number >= 0, a count (an integer >= 0 or absent), a
#: standard error (absent or >= 0), and the physical ranges (a field names the one it is: h, C, a frequency, ...).
POSITIVE = number(gt=0)
NON_NEGATIVE = number(ge=0)
COUNT = optional(integer(ge=0, le=MAX_COUNT))
STDERR = statistic(ge=0.0, le=MAX_C)
HARMONIC_NUMBER = number(gt=0, le=MAX_H)
COEFFICIENT = number(ge=0, le=MAX_C)
FREQUENCY = number(gt=0, le=MAX_FREQ_HZ)
SPEED = number(gt=0, le=MAX_OMEGA_RAD_S)
SPEED_AMPLITUDE = number(ge=0, le=MAX_OMEGA_RAD_S)
EXPONENT = number(ge=0, le=MAX_EXPONENT)
GAIN = number(gt=0, le=MAX_GAIN)
ZETA = number(ge=0, le=MAX_ZETA)
DEPTH = number(ge=0, le=MAX_DEPTH)
AMPLITUDE = number(ge=0, le=MAX_AMPLITUDE)
LEVER_ARM = numbers(length=3, ge=-MAX_LENGTH_M, le=MAX_LENGTH_M)


def parse_effect(doc: Any, source: str = "<model>", path: str = "effects[0]", error: type = ModelError) -> Effect:
    """The typed effect of one ``effects`` entry (an Effect is returned as it is)."""
    if isinstance(doc, Effect):
        return doc
    if not isinstance(doc, Mapping):
        raise error(source, path, f"must be an object, got {type(doc).__name__}")
    kind = doc.get("kind", _ABSENT)
    if kind is _ABSENT:
        raise error(source, f"{path}.kind", "missing")
    if not isinstance(kind, str):
        raise error(source, f"{path}.kind", f"must be a string, got {kind!r}")
    cls = EFFECT_KINDS.get(kind)
    if cls is None and kind.startswith(EXTENSION_PREFIX):   # an extension: carried through, applied by no consumer
        out: Effect = UnknownEffect(unknown_kind=kind, extra={k: v for k, v in doc.items() if k != "kind"})
        object.__setattr__(out, "_source_json", _plain_doc(doc))
        return out
    if cls is None:     # a consumer would leave it out of every prediction, silently
        raise error(source, f"{path}.kind", f"{kind!r} is no effect kind this version knows{_like(kind, EFFECT_KINDS)}; "
                    f"its effect would be left out of every prediction (a newer rwadist's file? an extension's kind "
                    f"starts with {EXTENSION_PREFIX!r})")
    return cls.from_json(doc, source, path, error)


def parse_effects(effects: Any, source: str = "<model>", error: type = ModelError) -> tuple:
    """The typed effects of a model file's ``effects`` list (None or absent: none), validated: every
    entry by its kind's class, and at most one effect of a kind that says so (:attr:`Effect.ONE_PER_WHEEL`).
    ``error`` (a :class:`ModelError` subclass) is raised naming ``effects[i].<field>``."""
    if effects is None:
        return ()
    if not isinstance(effects, (list, tuple)):
        raise error(source, "effects", f"must be a list, got {type(effects).__name__}")
    if len(effects) > MAX_EFFECTS:
        raise error(source, "effects", f"{len(effects)} entries: at most {MAX_EFFECTS}")
    out = tuple(parse_effect(e, source, f"effects[{i}]", error) for i, e in enumerate(effects))
    first: dict = {}
    for i, e in enumerate(out):
        if not type(e).ONE_PER_WHEEL:
            continue
        if e.kind in first:
            raise error(source, f"effects[{i}].kind", f"a second {e.kind} (the first is effects[{first[e.kind]}]); "
                        f"one {e.kind.replace('_', ' ')} per wheel is supported")
        first[e.kind] = i
    return out


def of_kind(effects: Any, cls: type, source: str = "<model>", error: type = ModelError) -> list:
    """The effects of class ``cls`` in ``effects`` (parsed and validated as a whole, see
    :func:`parse_effects`), in file order."""
    return [e for e in parse_effects(effects, source, error) if isinstance(e, cls)]


# =========================================================================== analytical section

@dataclass(frozen=True, eq=False)
class Analytical(_ReadsAsJson):
    """The ``analytical`` section: the extended model's parameters (SI, keys of :data:`PARAM_KEYS`).

    params : parameter name -> value for the keys present (each finite; mass, inertias and stiffnesses
    > 0; dampings and imbalances >= 0; height signed).  A section may lack parameters (a partial
    model); :meth:`require` names the first missing one when the extended model needs them all.
    modes_assumed : the suspension modes are assumed (a datasheet wheel), not measured.
    unconstrained : modes the extended fit could not identify (their values are starting values, or fitted values
        not told apart from a test stand).
    extra : other keys (e.g. ``fit``), carried through.  Reads as (and equals) the JSON object."""

    kind: str = ANALYTICAL_KIND
    params: Mapping = field(default_factory=dict)
    modes_assumed: bool | None = None
    unconstrained: tuple | None = None
    extra: Mapping = field(default_factory=dict, repr=False)
    _source_json: dict | None = field(default=None, init=False, repr=False, compare=False)

    @classmethod
    def from_json(cls, doc: Any, source: str = "<model>", error: type = ModelError) -> "Analytical":
        if isinstance(doc, Analytical):
            return doc
        if not isinstance(doc, Mapping):
            raise error(source, "analytical", f"must be an object, got {type(doc).__name__}")
        kind = doc.get("kind", ANALYTICAL_KIND)
        if kind != ANALYTICAL_KIND:
            raise error(source, "analytical.kind", f"{kind!r} is not {ANALYTICAL_KIND!r}")
        _refuse_unknown(doc, (*PARAM_KEYS.values(), *ANALYTICAL_KEYS), source, "analytical.", error)
        params = {}
        for name, key in PARAM_KEYS.items():
            if key not in doc:
                continue
            v = float(number()(doc[key], (source, f"analytical.{key}"), error))
            if (name in POSITIVE_PARAMS and not v > 0) or (name in NONNEGATIVE_PARAMS and not v >= 0):
                raise error(source, "analytical", f"{name} must be {'> 0' if name in POSITIVE_PARAMS else '>= 0'}, "
                            f"got {v!r} ({key})")
            if abs(v) > PARAM_MAX[name]:
                raise error(source, f"analytical.{key}", f"{v!r} is beyond any real wheel's (|value| <= "
                            f"{PARAM_MAX[name]:g} SI): a unit slip?")
            params[name] = v
        assumed = optional(boolean())(doc.get("modes_assumed", _ABSENT), (source, "analytical.modes_assumed"), error)
        unc = doc.get("unconstrained", _ABSENT)
        unconstrained = None
        if unc is not _ABSENT:
            allowed = UNCONSTRAINED_MODES + UNCONSTRAINED_DAMPING
            if not isinstance(unc, list) or any(not isinstance(m, str) or m not in allowed for m in unc):
                raise error(source, "analytical.unconstrained", f"{unc!r} must be a list of "
                            f"{', '.join(allowed)}")
            unconstrained = tuple(unc)
        known = set(PARAM_KEYS.values()) | {"kind", "modes_assumed", "unconstrained"}
        out = cls(kind=kind, params=params, modes_assumed=assumed, unconstrained=unconstrained,
                  extra={k: v for k, v in doc.items() if k not in known})
        object.__setattr__(out, "_source_json", _plain_doc(doc))
        return out

    def require(self, source: str = "<model>", error: type = ModelError) -> dict:
        """All parameters {name: value} (SI); ``error`` naming ``analytical.<key>: missing`` otherwise."""
        for name, key in PARAM_KEYS.items():
            if name not in self.params:
                raise error(source, f"analytical.{key}", "missing")
        return dict(self.params)

    def to_json(self) -> dict:
        if self._source_json is not None:
            return copy.deepcopy(self._source_json)
        out: dict = {"kind": self.kind}
        out.update({key: self.params[name] for name, key in PARAM_KEYS.items() if name in self.params})
        if self.modes_assumed is not None:
            out["modes_assumed"] = self.modes_assumed
        if self.unconstrained is not None:
            out["unconstrained"] = list(self.unconstrained)
        out.update(copy.deepcopy(dict(self.extra)))
        return out

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Mapping):
            return self.to_json() == (other.to_json() if isinstance(other, Analytical) else dict(other.items()))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]


# =========================================================================== keys

#: The forward-compatibility rule: a key (top level) or an effect kind starting with this prefix is an extension,
#: carried through unchanged and read by no consumer; any other key or kind a version does not know is an error.
#: A change that readers must understand (a new section, a new meaning) raises ``schema_version`` instead.
EXTENSION_PREFIX = "x-"
#: Keys of the ``analytical`` section besides the parameters (:data:`PARAM_KEYS`): the model's kind, the flags and
#: the extended fit's own record (``fit``, free-form)
ANALYTICAL_KEYS = ("kind", "modes_assumed", "unconstrained", "fit")


def _like(key: Any, known) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to ``key``, or ''."""
    import difflib

    close = difflib.get_close_matches(str(key), [str(k) for k in known], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _refuse_unknown(doc: Mapping, known, source: str, prefix: str, error: type, extensions: bool = False) -> None:
    """``error`` naming the first key of ``doc`` not in ``known`` (and, with ``extensions``, not an extension)."""
    for key in doc:
        if key not in known and not (extensions and str(key).startswith(EXTENSION_PREFIX)):
            raise error(source, f"{prefix}{key}", f"unknown key{_like(key, known)}; this version reads "
                        f"{', '.join(known)}" + (f" (an extension's key starts with {EXTENSION_PREFIX!r})"
                                                 if extensions else ""))
