"""Wheel mountings in the spacecraft frame and the ``wheels.json`` file (thesis Fig. 1-4 block (g)).

A :class:`Mounting` is a direction-cosine matrix ``dcm`` (wheel → spacecraft: v_sc = dcm · v_wheel)
and the interface position ``position_m`` (m, spacecraft frame, from the spacecraft reference
point).  Loads move to the reference point as::

    F_sc = R F_w,      T_sc = R T_w + r × (R F_w)

i.e. the 6×6 ``transform`` [[R, 0], [[r]× R, R]] acting on (Fx, Fy, Fz, Tx, Ty, Tz); a CSD
matrix transforms as T S Tᵀ (real T).

``wheels.json``::

    {"wheels": [
       {"name": "RW1", "model": "e_wheel.json"          # or "preset": "ithaco-e"
        "dcm": [[...], [...], [...]], "position_m": [x, y, z],
        # or "mounting": {"preset": "pyramid-4", "index": 0}
        "speed": {"dist": "uniform", "min_rpm": 500, "max_rpm": 3000}   # optional
        # or "tie": {"to": "RW1", "ratio": -1, "phase_lock": false, "phase_offset_deg": 0}
       }, ...]}

A top-level list of wheel objects is accepted too.  ``model`` paths are relative to the
wheels file; a wheel with neither ``model`` nor ``preset`` uses the model given on the command
line.  ``speed`` defaults to the command line's law; ``dist`` is 'uniform', 'normal' (with
optional ``std_rpm``) or a CSV path (relative to the wheels file).  A tied wheel runs at
``ratio`` (±1) times the speed of wheel ``to``; see :mod:`rwadist.broadband` for what ties and
``phase_lock`` mean.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import geometry
from .data import DataError, read_json
from .geometry import skew  # noqa: F401  (re-exported: its home is rwadist.geometry)
from .model import WheelModel

#: Tolerance on ‖RᵀR − I‖ (max abs) and on det R − 1: the one of :data:`rwadist.geometry.DCM_TOL`.
ORTHO_TOL = geometry.DCM_TOL
#: Spin-axis elevation of the pyramid preset from the spacecraft x-y plane: the classic
#: "NASA standard" pyramid with all four spin axes at arctan(1/√2) = 35.26° (equal authority on x, y, z).
PYRAMID_ELEVATION_DEG = math.degrees(math.atan(1 / math.sqrt(2)))


@dataclass(frozen=True)
class Mounting:
    """dcm : 3×3 wheel → spacecraft, orthonormal with det +1.  position_m : interface point (m)."""

    dcm: tuple
    position_m: tuple = (0.0, 0.0, 0.0)
    name: str = ""

    def __post_init__(self):
        where = f"mounting {self.name!r}" if self.name else "mounting"
        problem = geometry.rotation_problem(self.dcm)
        if problem is not None:
            raise DataError(where, "dcm", problem)
        R = np.asarray(self.dcm, float)
        r = np.asarray(self.position_m, float)
        if r.shape != (3,) or not np.all(np.isfinite(r)):
            raise DataError(where, "position_m", f"must be 3 finite numbers (m), got {self.position_m!r}")
        object.__setattr__(self, "dcm", tuple(tuple(float(x) for x in row) for row in R))
        object.__setattr__(self, "position_m", tuple(float(x) for x in r))

    @property
    def R(self) -> np.ndarray:
        return np.asarray(self.dcm, float)

    @property
    def transform(self) -> np.ndarray:
        """6×6 map of (F, T) at the interface, wheel frame → (F, T) at the reference point, s/c frame."""
        return geometry.load_transform(self.R, self.position_m)

    @property
    def spin_axis(self) -> np.ndarray:
        return self.R[:, 2]

    def apply(self, loads) -> np.ndarray:
        """Loads (..., 6) wheel frame at the interface → spacecraft frame at the reference point."""
        return np.asarray(loads) @ self.transform.T


def dcm_from_spin_axis(axis, ref=(0.0, 0.0, 1.0)) -> np.ndarray:
    """A DCM whose third column (wheel z) is ``axis``: :func:`rwadist.geometry.spin_axis_dcm`."""
    return geometry.spin_axis_dcm(axis, ref)


def preset_mountings(name: str, radius_m: float = 0.3, elevation_deg: float = PYRAMID_ELEVATION_DEG) -> list:
    """Mounting presets.

    'pyramid-4' : four wheels, spin axes at azimuth 45°, 135°, 225°, 315° about spacecraft z and
        ``elevation_deg`` above the x-y plane (default 35.26°), interfaces on a circle of
        ``radius_m`` at those azimuths (z = 0).
    'ortho-3-skew' : wheels along spacecraft +x, +y, +z and a fourth skewed along (1, 1, 1)/√3,
        interfaces at ``radius_m`` along their own spin axes.
    """
    key = str(name).strip().lower()
    out = []
    if key == "pyramid-4":
        el = math.radians(elevation_deg)
        for i, az_deg in enumerate((45.0, 135.0, 225.0, 315.0)):
            az = math.radians(az_deg)
            axis = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
            pos = (radius_m * math.cos(az), radius_m * math.sin(az), 0.0)
            out.append(Mounting(tuple(map(tuple, dcm_from_spin_axis(axis))), pos, f"pyramid-4[{i}]"))
    elif key == "ortho-3-skew":
        axes = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), tuple(np.ones(3) / math.sqrt(3))]
        for i, ax in enumerate(axes):
            out.append(Mounting(tuple(map(tuple, dcm_from_spin_axis(ax))), tuple(radius_m * np.asarray(ax)),
                                f"ortho-3-skew[{i}]"))
    else:
        raise DataError("mounting preset", "name", f"unknown preset {name!r}; available: pyramid-4, ortho-3-skew")
    return out


@dataclass
class Tie:
    """Speed tie: this wheel runs at ``ratio`` (±1) × the speed of wheel index ``to``; with
    ``phase_lock`` the two rotors are identical and locked at rotor-angle offset ``phase_offset`` rad."""

    to: int
    ratio: float = 1.0
    phase_lock: bool = False
    phase_offset: float = 0.0


@dataclass
class WheelSpec:
    """One wheel of a set: name, line sources (:class:`rwadist.broadband.WheelLines`), mounting,
    speed law (rad/s; None when tied) and tie."""

    name: str
    lines: object
    mounting: Mounting
    law: object = None
    tie: Tie | None = None
    model_ref: str = ""
    meta: dict = field(default_factory=dict)


def _speed_law(spec, default_law, base: Path, where: str):
    from . import broadband as bb

    if spec is None:
        if default_law is None:
            raise DataError(where, "speed", "no speed law: give one here or a default speed range for the set")
        return default_law
    if not isinstance(spec, dict):
        raise DataError(where, "speed", f"must be an object, got {spec!r}")
    dist = spec.get("dist", "uniform")
    if dist in ("uniform", "normal"):
        for k in ("min_rpm", "max_rpm"):
            if not isinstance(spec.get(k), (int, float)):
                raise DataError(where, f"speed.{k}", f"must be a number (rpm), got {spec.get(k)!r}")
        if not spec["min_rpm"] < spec["max_rpm"]:
            raise DataError(where, "speed.min_rpm/max_rpm", f"{spec['min_rpm']!r} rpm / {spec['max_rpm']!r} rpm: an "
                            "empty or inverted speed range; give min_rpm < max_rpm")
        return bb.law_from_spec(dist, spec["min_rpm"], spec["max_rpm"], spec.get("std_rpm"), f"{where}.speed")
    p = Path(dist)
    return bb.law_from_csv(p if p.is_absolute() else base / p)


#: the keys of a wheels.json wheel, its mounting and its tie: any other is refused (a typo of ``position_m`` put the
#: wheel at the origin and took its r × F torques away, silently)
WHEEL_KEYS = ("name", "model", "preset", "dcm", "position_m", "mounting", "speed", "tie")
MOUNTING_KEYS = ("preset", "index", "radius_m", "elevation_deg")
TIE_KEYS = ("to", "ratio", "phase_lock", "phase_offset_deg")
SPEED_KEYS = ("dist", "min_rpm", "max_rpm", "std_rpm")
#: pairs of keys one wheel may not give together: the second would be ignored
EXCLUSIVE_KEYS = (("model", "preset"), ("mounting", "dcm"), ("mounting", "position_m"), ("tie", "speed"))


def _check_keys(path, where: str, obj: dict, known: tuple) -> None:
    """DataError naming the first key of ``obj`` not in ``known`` (with the closest known one)."""
    import difflib

    for k in obj:
        if k not in known:
            near = difflib.get_close_matches(str(k), known, n=1)
            raise DataError(path, f"{where}.{k}", "unknown key" + (f" (did you mean {near[0]!r}?)" if near else "")
                            + f"; known: {', '.join(known)}")


def _wheel_items(wheels) -> tuple:
    """(source, wheel objects, folder model and speed-file paths are relative to) of a wheels.json path or of its
    parsed content (a list of wheel objects, or ``{"wheels": [...]}``; paths then relative to the working folder)."""
    path: str | Path
    if isinstance(wheels, (str, Path)):
        path, base = Path(wheels), Path(wheels).parent
        doc = read_json(path)
    else:
        path, base, doc = "wheels", Path("."), wheels
    if isinstance(doc, dict):
        _check_keys(path, "document", doc, ("wheels",))
    items = doc.get("wheels") if isinstance(doc, dict) else doc
    if not isinstance(items, (list, tuple)) or not items:
        raise DataError(path, "wheels", "must be a non-empty list of wheel objects")
    return path, list(items), base


def _check_wheel(path, where: str, w, names: list, i: int) -> None:
    """The keys of wheel object ``w``: known, objects where objects go, no pair of which one would be ignored, its
    name its own."""
    if not isinstance(w, dict):
        raise DataError(path, where, f"must be an object, got {w!r}")
    _check_keys(path, where, w, WHEEL_KEYS)
    for key, known in (("mounting", MOUNTING_KEYS), ("tie", TIE_KEYS), ("speed", SPEED_KEYS)):
        if key in w:
            if not isinstance(w[key], dict):
                raise DataError(path, f"{where}.{key}", f"must be an object with keys {', '.join(known)}; got "
                                f"{w[key]!r}")
            _check_keys(path, f"{where}.{key}", w[key], known)
    for a, b in EXCLUSIVE_KEYS:
        if a in w and b in w:
            raise DataError(path, f"{where}.{b}", f"given beside '{a}', which decides it: give one of the two")
    if names.count(names[i]) > 1:
        raise DataError(path, f"{where}.name", f"{names[i]!r} names more than one wheel; names: {names}")


def _wheel_lines(path, where: str, w: dict, base: Path, cache: dict, default_lines_loader, empirical: bool,
                 assumed_modes: bool) -> tuple:
    """(lines, model reference, modes assumed) of wheel object ``w``: its model file or preset, under the
    assumed-modes rule of :func:`rwadist.wheel_source.wheel_source` (one source read once per set)."""
    from .wheel_source import wheel_source

    if "model" in w and isinstance(w["model"], WheelModel):     # from Python: the model object itself
        model: WheelModel | Path | None = w["model"]
        key, ref, preset = ("object", str(id(model))), f"model {w['model'].name}", None
    elif "model" in w:
        if not isinstance(w["model"], (str, Path)):
            raise DataError(path, f"{where}.model", f"a {type(w['model']).__name__}: expected a model-file path "
                            "(or, from Python, a WheelModel)")
        mp = Path(w["model"])
        mp = mp if mp.is_absolute() else base / mp
        if not mp.exists():
            raise DataError(path, f"{where}.model", f"model file {str(mp)!r} does not exist")
        key, ref, model, preset = ("model", str(mp)), str(mp), mp, None
    elif "preset" in w:
        key, ref, model, preset = ("preset", w["preset"]), f"preset {w['preset']}", None, w["preset"]
    else:
        if default_lines_loader is None:
            raise DataError(path, f"{where}.model", "no model: give 'model' or 'preset' here, or a default model "
                            "for the set")
        if "default" not in cache:
            cache["default"] = default_lines_loader()
        return cache["default"], "command-line model", False   # the caller notes its own
    if key not in cache:
        try:
            src = wheel_source(model, preset=preset, empirical=empirical, assumed_modes=assumed_modes)
        except ValueError as exc:
            if model is not None:
                raise
            raise DataError(path, f"{where}.preset", getattr(exc, "problem", None) or str(exc)) from None
        cache[key] = (src.lines, src.modes_assumed)
    lines, assumed = cache[key]
    return lines, ref, assumed


def _wheel_mounting(path, where: str, w: dict, i: int, name: str) -> Mounting:
    """The mounting of wheel object ``w`` (index ``i``): a preset's ``index``-th, or its ``dcm`` and ``position_m``."""
    try:
        if "mounting" in w:
            mspec = w["mounting"]
            ms = preset_mountings(mspec.get("preset", ""), **{k: v for k, v in mspec.items()
                                                                if k in ("radius_m", "elevation_deg")})
            idx = int(mspec.get("index", i))
            if not 0 <= idx < len(ms):
                raise DataError(path, f"{where}.mounting.index", f"{idx} out of range 0..{len(ms) - 1}")
            return ms[idx]
        if "dcm" not in w:
            raise DataError(path, f"{where}.dcm", "missing (give 'dcm' and 'position_m' or 'mounting')")
        return Mounting(w["dcm"], w.get("position_m", (0.0, 0.0, 0.0)), name)
    except DataError as exc:
        if exc.file == str(path):
            raise
        raise DataError(path, f"{where}.{exc.field}", str(exc).split(": ", 2)[-1]) from None


def _wheel_tie(path, where: str, t: dict, i: int, names: list) -> Tie:
    """The :class:`Tie` of a wheel object's ``tie`` (wheel ``i`` of those named ``names``)."""
    to = t.get("to")
    if isinstance(to, str):
        if to not in names:
            raise DataError(path, f"{where}.tie.to", f"no wheel named {to!r}; names: {names}")
        to = names.index(to)
    if not isinstance(to, int) or not 0 <= to < len(names) or to == i:
        raise DataError(path, f"{where}.tie.to", f"must name or index another wheel, got {t.get('to')!r}")
    ratio = float(t.get("ratio", 1.0))
    if ratio not in (1.0, -1.0):
        raise DataError(path, f"{where}.tie.ratio", f"must be +1 or -1, got {ratio!r}")
    return Tie(to, ratio, bool(t.get("phase_lock", False)), math.radians(float(t.get("phase_offset_deg", 0))))


def _check_tie_cycles(path, wheels: list) -> None:
    """DataError when ties lead from a wheel back to itself (every chain of ties must end at a wheel with a law)."""
    for i in range(len(wheels)):
        seen = {i}
        j = i
        while wheels[j].tie is not None:
            j = wheels[j].tie.to
            if j in seen:
                raise DataError(path, f"wheels[{i}].tie", "ties form a cycle")
            seen.add(j)


def load_wheels(wheels, default_lines_loader=None, default_law=None, empirical: bool = False,
                assumed_modes: bool = False) -> list:
    """Read a set of wheels into :class:`WheelSpec` objects.

    wheels : a wheels.json path, or its content: a list of wheel objects (or ``{"wheels": [...]}``) whose model
    and speed-file paths are relative to the working folder.  default_lines_loader : callable() -> WheelLines used
    for wheels without ``model``/``preset``.  default_law : speed law for wheels without ``speed`` (rad/s).
    empirical : Melody's model (harmonics only) instead of the extended model.  assumed_modes : run a wheel whose
    suspension modes are assumed (``analytical.modes_assumed``: a catalogue datasheet wheel) through those modes;
    without it such a wheel is hard-mounted (Melody's model of its lines), as its datasheet states.  Either way
    the wheel's ``meta["modes_assumed"]`` says which ('hard-mounted' or 'assumed modes used').
    DataError names the file (or ``wheels``) and the field (missing model file, bad DCM, unknown tie, ...).
    """
    path, items, base = _wheel_items(wheels)
    names = [str(w.get("name", f"wheel{i}")) if isinstance(w, dict) else "" for i, w in enumerate(items)]
    out: list[WheelSpec] = []
    cache: dict[tuple[str, str] | str, object] = {}      # one read per model file or preset of the set, and the default
    for i, w in enumerate(items):
        where = f"wheels[{i}]"
        _check_wheel(path, where, w, names, i)
        lines, ref, assumed = _wheel_lines(path, where, w, base, cache, default_lines_loader, empirical,
                                           assumed_modes)
        mount = _wheel_mounting(path, where, w, i, names[i])
        if "tie" in w:
            tie, law = _wheel_tie(path, where, w["tie"], i, names), None
        else:
            tie, law = None, _speed_law(w.get("speed"), default_law, base, f"{path}: {where}")
        meta = {"modes_assumed": "assumed modes used" if assumed_modes else "hard-mounted"} if (
            assumed and not empirical) else {}
        out.append(WheelSpec(names[i], lines, mount, law, tie, ref, meta))
    _check_tie_cycles(path, out)
    return out


def _root(wheels, i):
    ratio, offset, lock = 1.0, 0.0, True
    while wheels[i].tie is not None:
        t = wheels[i].tie
        ratio *= t.ratio
        offset += t.phase_offset
        lock = lock and t.phase_lock
        i = t.to
    return i, ratio, offset, lock


def wheel_groups(wheels: list) -> list:
    """Groups for :func:`rwadist.broadband.csd_groups`: phase-locked tied wheels share a group
    (coherent); all other wheels -- tied without lock included -- are groups of one, with the
    root wheel's law (a ratio −1 shows as the member's ratio)."""
    from .broadband import Member

    groups: dict[int | tuple[str, int], tuple[list, object]] = {}
    order = []
    for i, ws in enumerate(wheels):
        root, ratio, offset, lock = _root(wheels, i)
        key = root if (lock and (ws.tie is not None or any(
            w.tie is not None and _root(wheels, k)[0] == i and _root(wheels, k)[3]
            for k, w in enumerate(wheels)))) else ("solo", i)
        if key not in groups:
            groups[key] = ([], wheels[root].law)
            order.append(key)
        groups[key][0].append(Member(ws.lines, ws.mounting, ratio, offset if lock else 0.0))
    return [groups[k] for k in order]


def spacecraft_csd(wheels: list, f_max: float, n_freq: int = 20001, n_speeds: int = 2000, progress: bool = False):
    """6×6 CSD in the spacecraft frame at the reference point of a list of :class:`WheelSpec`."""
    from .broadband import csd_groups

    res = csd_groups(wheel_groups(wheels), f_max, n_freq, n_speeds, progress, frame="spacecraft")
    res.meta["wheels"] = [{"name": w.name, "model": w.model_ref, "dcm": [list(r) for r in w.mounting.dcm],
                           "position_m": list(w.mounting.position_m),
                           "law": repr(w.law) if w.tie is None else f"tied to {wheels[w.tie.to].name}"}
                          for w in wheels]
    return res
