"""The model file as the FMU runtime reads it (part of :mod:`rwadist.fmu.runtime`; numpy only, no rwadist).

Copied verbatim into the FMU's ``resources/`` (as ``rwadist_fmu_runtime_model.py``) beside the runtime, with a
verbatim copy of :mod:`rwadist.schema` (``rwadist_model_schema.py``), the one reader of the model file, which this
module imports from there (from rwadist itself when run from the source tree; a test pins the copies to the
source byte for byte).  Here: the model's parameters and lines (:func:`load_model`, :func:`model_from_doc`), its
diagnosed time-domain effects (:func:`effects_from_doc`), the expansion of lines by laws and sidebands
(:func:`expand_lines`), a line's rotating components (:func:`components`) and the mounting check
(:func:`rotation_check`).  Everything is SI: rad/s, N, N·m, kg, m.
"""
from __future__ import annotations

import cmath
import importlib.util
import json
import math
import os
import sys
import types

import numpy as np

#: the schema's file name in the FMU's resources (``rwadist/fmu/build.py`` copies rwadist/schema.py there)
SCHEMA_FILE = "rwadist_model_schema.py"
#: the units module's file name in the FMU's resources (rwadist/units.py: the elements read their units there)
UNITS_FILE = "rwadist_model_units.py"
#: the folder of the effect elements in the FMU's resources (``rwadist/fmu/build.py`` copies rwadist/effects/ there:
#: :func:`rwadist.effects.shipped_files`)
EFFECTS_DIR = "rwadist_model_effects"


def _exec_module(name, path, package_dir=None):
    """Module ``name`` executed from the file ``path`` (a package's ``__init__.py`` with ``package_dir``)."""
    spec = importlib.util.spec_from_file_location(
        name, path, submodule_search_locations=None if package_dir is None else [package_dir])
    if spec is None or spec.loader is None:
        raise ImportError(f"rwadist FMU: cannot load the model module {path}")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod              # dataclasses look their module up while the class is made
    try:
        spec.loader.exec_module(mod)
    except BaseException:
        sys.modules.pop(name, None)
        raise
    return mod


def _load_schema():
    """(schema, actions): the model-file schema with every effect element registered, and the elements' generic
    actions (:mod:`rwadist.effects.actions`): the copies next to this file (inside an FMU), else
    :mod:`rwadist.schema` and :mod:`rwadist.effects`.

    In an FMU the copies are loaded as the modules ``schema``, ``units`` and ``effects`` of a package named after
    this module (two FMUs load side by side), so the elements' ``from ..schema import ...`` reads this schema copy."""
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, SCHEMA_FILE)
    if not os.path.isfile(path):
        from rwadist import effects, schema  # noqa: F401  (effects: imports every element)
        from rwadist.effects import actions
        return schema, actions
    pkg = f"{__name__}_reader"          # unique per FMU
    mod = sys.modules.get(f"{pkg}.schema")
    if mod is None:
        parent = sys.modules.setdefault(pkg, types.ModuleType(pkg))
        parent.__path__ = []             # a package: its two modules are loaded from their files below
        mod = _exec_module(f"{pkg}.schema", path)
        _exec_module(f"{pkg}.units", os.path.join(here, UNITS_FILE))
        folder = os.path.join(here, EFFECTS_DIR)
        _exec_module(f"{pkg}.effects", os.path.join(folder, "__init__.py"), folder)
    return mod, sys.modules[f"{pkg}.effects.actions"]


_schema, _actions = _load_schema()
SCHEMA = _schema.SCHEMA
SCHEMA_VERSION = _schema.SCHEMA_VERSION
ANALYTICAL_KIND = _schema.ANALYTICAL_KIND
DIRECTIONS = _schema.DIRECTIONS
CHANNELS = _schema.CHANNELS
PARAM_KEYS = _schema.PARAM_KEYS

#: Invalid or unreadable model file, parameter or input; the message names the problem.  The schema's
#: one error type, so a bad model-file entry reads the same here as in rwadist and the coupling kit.
ModelError = _schema.ModelError


# ------------------------------------------------------------------ model file

#: as rwadist.extended.IMBALANCE_H_TOL
IMBALANCE_H_TOL = 0.02

def read_document(path):
    """The parsed JSON document of a model file; ModelError naming the file if unreadable."""
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except OSError as exc:
        raise ModelError(f"model file {path!r} cannot be read: {exc.strerror or exc}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ModelError(f"model file {path!r} is not valid JSON: {exc}") from None


#: |Δh| within which a diagnosed amplitude law belongs to a line (as rwadist.broadband.apply_effects)
LAW_H_TOL = 1e-3


def laws_from_doc(doc, source="<model>"):
    """Diagnosed amplitude laws of a model document (the line laws its effects' elements give,
    :mod:`rwadist.effects.actions`): {(direction, h): (A_ref, Ω_ref, p)} with the line's amplitude
    A_ref·(|Ω|/Ω_ref)^p (N or N·m, rad/s) in place of C·Ω².  The effects are read (all of them) by the schema."""
    return {(a.direction, a.h): a.law for a in _doc_actions(doc, source) if isinstance(a, _actions.LineLaw)}


def _doc_actions(doc, source, sources=False):
    """The actions of a model document's effects (:func:`rwadist.effects.actions.of_effects`), validated."""
    return _actions.of_effects(_schema.parse_effects(doc.get("effects"), source), sources)


#: The FMUs' effect switches: Boolean parameters whose value references follow ``start_steady`` (9, 10), one per
#: element that names one (``FMU_SWITCH``, :class:`rwadist.effects.element.FmuSwitch`), in slot order.
SWITCH_SLOTS = 2


def fmu_switches():
    """[(name, description)] of the FMUs' effect switches, in slot order (their value references follow
    ``start_steady``), from the registered elements; ModelError unless every slot is named once."""
    named = sorted((c.FMU_SWITCH for c in _schema.EFFECT_KINDS.values() if getattr(c, "FMU_SWITCH", None) is not None),
                   key=lambda s: s.slot)
    if [s.slot for s in named] != list(range(SWITCH_SLOTS)):
        raise ModelError(f"the FMU's effect switches are slots 0..{SWITCH_SLOTS - 1}, one element each; the "
                         f"elements name {[(s.slot, s.name) for s in named]}")
    return [(s.name, s.description) for s in named]


def effects_from_doc(doc, source="<model>"):
    """All time-domain forcing effects of a model document (``rwadist diagnose``), validated by the
    schema (:func:`rwadist.schema.parse_effects`), as the generic actions their elements give
    (:mod:`rwadist.effects.actions`; a measurement artefact or a record gives none), as keyword arguments of
    :class:`WheelRuntime`:

    * ``laws``: :func:`laws_from_doc` (line laws);
    * ``resonances``: [(directions, f_r Hz, ζ, peak_gain)] of each line filter (an unmodelled wheel mode): every
      component of every line of those directions is multiplied by H(ν/2π) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r),
      r = ν/(2π f_r) signed, at its instantaneous whirl rate ν = σ(hΩ + 2π f_offset) -- QUASI-STATIC (exact at
      constant speed, no ringing of that resonance in transients);
    * ``sidebands``: [(direction, h, f_mod Hz, depth m)] of each line modulation: the matching lines
      (|Δh| < LAW_H_TOL) are amplitude modulated, a(1 + m·cos 2πf_mod t) = the carrier + two lines of amplitude
      m·a/2 whose phases advance by ±2πf_mod·t (exact in the time domain);
    * ``floors``: [(channel index, f knots Hz, psd_ref knots unit²/Hz, Ω_ref rad/s, p)] of each noise floor: a
      blocked-load PSD S(f, Ω) = psd_ref(f)·(|Ω|/Ω_ref)^p (linear between knots, 0 outside), added to the
      wheel-frame output as a random-phase multisine (see :class:`WheelRuntime`);
    * ``ripples``: [(ΔΩ_ref rad/s, Ω_ref rad/s, q, f_r Hz)] of the speed modulation (at most one): the wheel
      turns at Ω(t) + ΔΩ_ref·(|Ω|/Ω_ref)^q·sin(2π f_r t + θ) (see :class:`WheelRuntime`);
    * ``switch_of``: {"floors": [...], "ripples": [...]}: per floor and ripple, the name of the FMU switch that turns
      it off (its element's ``FMU_SWITCH``, :func:`fmu_switches`), or None.

    ModelError naming ``effects[i].<field>`` on a bad entry."""
    pairs = _doc_actions(doc, source, sources=True)
    acts = [a for _, a in pairs]
    resonances: list[tuple] = []
    sidebands: list[tuple] = []
    floors: list[tuple] = []
    ripples: list[tuple] = []
    switch_of: dict[str, list[str | None]] = {"floors": [], "ripples": []}
    for e, a in pairs:
        switch = getattr(getattr(e, "FMU_SWITCH", None), "name", None)
        if isinstance(a, _actions.LineFilter):
            if a.gain_above != 1.0:
                raise ModelError(f"{source}: the wheel_mode fixed_resonance at {a.resonance[0]:.6g} Hz keeps gain_above "
                                 f"{a.gain_above!r} of the load far above it: the FMU's wheel-mode filter returns to 1 "
                                 "above the resonance (not supported in an FMU yet); to build the FMU without it, "
                                 "remove that effect from a copy of the model file ('rwadist psd' models it)")
            resonances.append((a.directions, *a.resonance))
        elif isinstance(a, _actions.LineModulation):
            sidebands.append((a.direction, a.h, a.f_mod_hz, a.depth))
        elif isinstance(a, _actions.NoiseFloor):
            floors.append((a.channel, a.f_hz, a.psd_ref, a.omega_ref, a.exponent))
            switch_of["floors"].append(switch)
        elif isinstance(a, _actions.SpeedModulation):
            ripples.append((a.delta_omega, a.omega_ref, a.exponent, a.f_hz))
            switch_of["ripples"].append(switch)
    return {"laws": {(a.direction, a.h): a.law for a in acts if isinstance(a, _actions.LineLaw)},
            "resonances": resonances, "sidebands": sidebands, "floors": floors, "ripples": ripples,
            "switch_of": switch_of}


def load_model(path):
    """(params dict, lines) from a model file of schema rwadist.model v1.

    lines: list of (direction, h, C, sense, imbalance) in the order of
    ``rwadist.extended.lines_from_model``: the static and dynamic imbalance first (U_s, U_d of
    the analytical section), then every empirical harmonic per direction except the radial
    h = 1 ones.  ModelError naming the file and field on any problem."""
    return model_from_doc(read_document(path), str(path))


def _num(v, where):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ModelError(f"{where}: must be a finite number, got {v!r}")
    return float(v)


def model_from_doc(doc, source="<model>"):
    """Validated (params, lines) of a parsed model document (see :func:`load_model`)."""
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise ModelError(f"{source}: schema: not an rwadist model file")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise ModelError(f"{source}: schema_version: file has version {doc.get('schema_version')!r}; "
                         f"this FMU reads version {SCHEMA_VERSION} only")
    an = doc.get("analytical")
    if an is None:
        return _empirical_only(doc, source)
    if not isinstance(an, dict):
        raise ModelError(f"{source}: analytical: must be an object (the extended-model parameters), "
                         f"got {type(an).__name__}")
    if an.get("kind", ANALYTICAL_KIND) != ANALYTICAL_KIND:
        raise ModelError(f"{source}: analytical.kind: {an.get('kind')!r} is not {ANALYTICAL_KIND!r}")
    p = {}
    for name, key in PARAM_KEYS.items():
        if key not in an:
            raise ModelError(f"{source}: analytical.{key}: missing")
        p[name] = _num(an[key], f"{source}: analytical.{key}")
    for name in ("mass", "I_zz", "I_rr", "k_r", "k_rock", "k_z"):
        if p[name] <= 0:
            raise ModelError(f"{source}: analytical.{PARAM_KEYS[name]}: must be > 0, got {p[name]!r}")
    for name in ("c_r", "c_rock", "c_z", "U_s", "U_d"):
        if p[name] < 0:
            raise ModelError(f"{source}: analytical.{PARAM_KEYS[name]}: must be >= 0, got {p[name]!r}")
    if p["I_zz"] > _schema.MAX_INERTIA_RATIO * p["I_rr"] * (1 + 1e-12):
        raise ModelError(f"{source}: analytical: I_zz exceeds {_schema.MAX_INERTIA_RATIO:g}·I_rr "
                         "(a rigid rotor has I_zz <= 2·I_rr)")
    for m, c, k, what in ((p["mass"], p["c_r"], p["k_r"], "radial"), (p["I_rr"], p["c_rock"], p["k_rock"], "rocking"),
                          (p["mass"], p["c_z"], p["k_z"], "axial")):
        if c / (2.0 * math.sqrt(k * m)) >= 1.0:
            raise ModelError(f"{source}: analytical: the {what} mode is overdamped")
    p["suspension"] = True
    p["modes_assumed"] = _modes_assumed(an, source)
    lines = [("radial_force", 1.0, p["U_s"], "co", True), ("radial_torque", 1.0, p["U_d"], "co", True)]
    for d, h, C, sense, fundamental in _harmonics(doc, source):
        if not fundamental:        # the imbalances U_s, U_d above replace the co-rotating radial fundamentals
            lines.append((d, h, C, sense, False))
    return p, lines


def _modes_assumed(an, source):
    """``analytical.modes_assumed`` (default false): the suspension modes are assumed, not measured."""
    v = an.get("modes_assumed", False)
    if not isinstance(v, bool):
        raise ModelError(f"{source}: analytical.modes_assumed: must be true or false, got {v!r}")
    return v


def _harmonics(doc, source):
    """[(direction, h, C, sense, co-rotating radial fundamental?)] of the ``empirical`` section, validated."""
    emp = doc.get("empirical") or {}
    if not isinstance(emp, dict):
        raise ModelError(f"{source}: empirical: must be an object keyed by direction")
    for d in emp:
        if d not in DIRECTIONS:
            raise ModelError(f"{source}: empirical.{d}: unknown direction")
    out = []
    for d in DIRECTIONS:
        for i, item in enumerate(emp.get(d) or []):
            where = f"{source}: empirical.{d}[{i}]"
            if not isinstance(item, dict):
                raise ModelError(f"{where}: must be an object")
            h, C = _num(item.get("h"), where + ".h"), _num(item.get("C"), where + ".C")
            if h <= 0 or C < 0:
                raise ModelError(f"{where}: needs h > 0 and C >= 0, got h={h!r}, C={C!r}")
            sense = item.get("sense")
            if sense not in (None, "co", "counter", "planar"):
                raise ModelError(f"{where}.sense: {sense!r}; expected co, counter or planar")
            # the co-rotating radial fundamental is the imbalance (same rule as
            # rwadist.extended.is_imbalance; the runtime is self-contained, a test pins the tolerance)
            fundamental = d in ("radial_force", "radial_torque") and abs(h - 1.0) <= IMBALANCE_H_TOL \
                and sense in (None, "co")
            out.append((d, h, C, sense or "co", fundamental))
    return out


def _empirical_only(doc, source):
    """(params, lines) of a model without an ``analytical`` section: every empirical harmonic is a
    line of amplitude C·Ω² at its own h and sense, hard-mounted (the loads measured at the
    interface reach it directly: no suspension, torques already about the interface, height 0).
    A planar radial line is two loads of amplitude C·Ω², along x and along y, each with a phase of its own (the
    fit read C from each channel's power, C²Ω⁴/2 on each, as :func:`rwadist.broadband.empirical_lines` reads it;
    one load along x carried all of it on x and none on y).  The co-rotating radial fundamentals are the imbalance: they keep their tangential term −i·C·Ω̇
    (zero at constant speed) and follow the ``imbalance`` switch.  params carry
    ``suspension`` False and no modal values (0): :class:`WheelRuntime` refuses modes on."""
    lines = []
    for d, h, C, sense, fundamental in _harmonics(doc, source):
        lines.append((d, h, C, sense, fundamental))
        if sense == "planar" and d in ("radial_force", "radial_torque"):
            lines.append((d, h, C, PLANAR_Y, False))      # the fit's C on each channel, phases of their own
    if not lines:
        raise ModelError(f"{source}: empirical: no harmonics and no analytical section; the model has no lines")
    p = {name: 0.0 for name in PARAM_KEYS}
    p["suspension"] = False
    p["modes_assumed"] = False
    return p, lines


def physics_of(params, lines, effects=None) -> str:
    """One sentence saying which physics a model carries (for the FMU's description and logs)."""
    if not params.get("suspension", True):
        n = sum(1 for line in lines if line[3] != PLANAR_Y)           # a planar line's y load is not a line
        what = f"empirical harmonics only ({n} lines, amplitude C*Omega^2), hard-mounted"
    elif params.get("modes_assumed"):
        what = ("extended model with ASSUMED suspension modes (datasheet wheel; hard-mounted unless "
                "modes = true)")
    else:
        what = "extended model: harmonics through the measured suspension modes"
    kinds = [k for k, v in (effects or {}).items() if v and k != "switch_of"]
    names = {"laws": "amplitude laws", "resonances": "wheel-mode resonances", "sidebands": "sidebands",
             "floors": "broadband floors", "ripples": "speed ripple"}
    if kinds:
        what += "; diagnosed effects: " + ", ".join(names.get(k, k) for k in kinds)
    return what


#: Internal sense of the y load of an empirical model's planar line (:func:`_empirical_only`): planar along +y.
PLANAR_Y = "planar_y"


def components(direction, sense, phase, angle=0.0):
    """[(sigma, coef)] of a line, as ``rwadist.extended.Line.components`` (sense :data:`PLANAR_Y`: planar at
    ``angle`` + π/2)."""
    if direction in ("axial_force", "axial_torque") or sense == "co":
        return [(1, cmath.exp(1j * phase))]
    if sense == "counter":
        return [(-1, cmath.exp(-1j * phase))]
    if sense == PLANAR_Y:
        angle = angle + 0.5 * math.pi
    return [(1, 0.5 * cmath.exp(1j * (angle + phase))), (-1, 0.5 * cmath.exp(1j * (angle - phase)))]


def rotation_check(R, tol=1e-6):
    """ModelError unless R (3×3) is a proper rotation (RᵀR = I within ``tol``, det > 0)."""
    R = np.asarray(R, dtype=float).reshape(3, 3)
    if not np.all(np.isfinite(R)):
        raise ModelError("mounting DCM has non-finite entries")
    err = float(np.max(np.abs(R.T @ R - np.eye(3))))
    if err > tol or np.linalg.det(R) <= 0:
        raise ModelError(f"mounting DCM is not a proper rotation (max |RᵀR − I| = {err:.3g}, "
                         f"det = {np.linalg.det(R):.6g})")
    return R



def expand_lines(lines, laws=None, sidebands=None):
    """(full, laws_used, sidebands_used): every line of the model as (direction, h, C, sense, imbalance,
    law (A_ref, Ω_ref, p) or None, f_offset Hz) -- the model's lines with their amplitude laws
    (|Δh| < LAW_H_TOL), then per sideband effect, per matching carrier, the +f_mod and −f_mod copies
    (C and A_ref times depth/2); the order of ``rwadist.extended.apply_line_effects`` (the seed's
    phases are drawn over this list).  Used by :class:`WheelRuntime` and the native FMU builder."""
    laws = dict(laws or {})
    laws_used, sidebands_used = set(), set()
    full = []
    for d, h, c, sense, is_imb in lines:
        key = next((k for k in laws if k[0] == d and abs(k[1] - h) < LAW_H_TOL), None)
        if key is not None:
            laws_used.add(key)
        full.append((d, h, c, sense, is_imb, None if key is None else tuple(laws[key]), 0.0))
    carriers = list(full)
    for j, (sd, shh, f_mod, m) in enumerate(sidebands or []):
        for d, h, c, sense, is_imb, lw, _ in carriers:
            if d == sd and abs(h - shh) < LAW_H_TOL:
                sidebands_used.add(j)
                lw2 = None if lw is None else (lw[0] * 0.5 * m, lw[1], lw[2])
                for off in (f_mod, -f_mod):
                    full.append((d, h, c * 0.5 * m, sense, is_imb, lw2, off))
    return full, laws_used, sidebands_used


