"""Self-contained runtime of the extended wheel model for the FMU (numpy only, no rwadist).

This file is copied verbatim into the FMU's ``resources/`` so a host needs only Python and
numpy; next to it goes a verbatim copy of :mod:`rwadist.schema` (``rwadist_model_schema.py``), the
one reader of the model file, which this module imports from there (from rwadist itself when run
from the source tree; a test pins the copy to the source byte for byte).  It re-implements, step by step, the equations of :mod:`rwadist.extended` (rigid rotor
on a flexible suspension; see that module's docstring for the physics and sign conventions)
and is tested against :func:`rwadist.extended.simulate_time` to 1e-9 relative
(tests/test_fmu.py).  Everything is SI: rad/s, rad/s², s, N, N·m, kg, m.

One communication step [t_n, t_n + h] with wheel speed Ω_n and acceleration α (rad/s²):

* speed is linear over the step, Ω(τ) = Ω_n + α τ; rotor angle φ += (Ω_n + Ω_{n+1}) h / 2
  (exact for the linear speed, the trapezoid of ``simulate_time``);
* each forcing line is C·coef·amp(τ)·e^{iσh(φ_n + Δφ τ/h)}, amplitude linear over the step from
  C(Ω_n² − iΩ̇_n) to C(Ω_{n+1}² − iΩ̇_{n+1}) (the −iΩ̇ tangential term for imbalance lines only;
  Ω̇_n is the mean of the previous and this step's α -- the central difference of
  ``simulate_time`` -- and Ω̇_{n+1} = α);
* every mode is a linear state integrated exactly against that load over the step: radial and
  axial translation through their two complex eigen-coordinates (fixed poles), rocking through
  the exact 2×2 transition matrix at the step's mean speed (gyroscopic term frozen over a step);
* outputs are the suspension reactions at t_n + h (wheel frame, Fx, Fy, Fz, Tx, Ty, Tz) and
  their spacecraft-frame image F_sc = R F, T_sc = R T + r × F_sc.

The step runs in numpy, or, when the FMU carries its native library (built from
``fmu/native/rwadist_fmu_native.c`` by ``rwadist fmu build`` where a C compiler is found), in
that library's ``rwadist_kernel_step`` -- the same equations in C, ~10× faster per step, tested
against this numpy code (:func:`load_kernel`, :data:`KERNEL_LAYOUT`).
"""
from __future__ import annotations

import cmath
import ctypes
import importlib.util
import json
import math
import os
import sys

import numpy as np

#: the schema's file name in the FMU's resources (``fmu/build.py`` copies rwadist/schema.py there)
SCHEMA_FILE = "rwadist_model_schema.py"


def _load_schema():
    """The model-file schema: the copy next to this file (inside an FMU), else :mod:`rwadist.schema`."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), SCHEMA_FILE)
    if not os.path.isfile(path):
        from rwadist import schema
        return schema
    name = f"{__name__}_schema"          # unique per FMU: two FMUs may load side by side
    mod = sys.modules.get(name)
    if mod is None:
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod          # dataclasses look their module up while the class is made
        spec.loader.exec_module(mod)
    return mod


_schema = _load_schema()
SCHEMA = _schema.SCHEMA
SCHEMA_VERSION = _schema.SCHEMA_VERSION
ANALYTICAL_KIND = _schema.ANALYTICAL_KIND
DIRECTIONS = _schema.DIRECTIONS
CHANNELS = _schema.CHANNELS
PARAM_KEYS = _schema.PARAM_KEYS
SMALL_Z = 1e-3

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
    """Diagnosed amplitude laws of a model document (``effects`` entries of kind
    ``amplitude_law``, written by ``rwadist diagnose``): {(direction, h): (A_ref, Ω_ref, p)} with
    the line's amplitude A_ref·(|Ω|/Ω_ref)^p (N or N·m, rad/s) in place of C·Ω².  Other effect
    kinds are not time-domain forcing the FMU models and are ignored (missing harmonics are
    already harmonics of ``empirical``).  The effects are read (all of them) by the schema."""
    return {(e.direction, float(e.h)): e.law for e in _schema.of_kind(doc.get("effects"), _schema.AmplitudeLaw,
                                                                      source)}


def effects_from_doc(doc, source="<model>"):
    """All time-domain forcing effects of a model document (``rwadist diagnose``), validated by the
    schema (:func:`rwadist.schema.parse_effects`), as keyword arguments of :class:`WheelRuntime`:

    * ``laws``: :func:`laws_from_doc`;
    * ``resonances``: [(directions, f_r Hz, ζ, peak_gain)] of each ``fixed_resonance`` of role
      ``wheel_mode`` (an unmodelled wheel mode): every component of every line of those directions
      is multiplied by H(ν/2π) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r), r = ν/(2π f_r) signed, at
      its instantaneous whirl rate ν = σ(hΩ + 2π f_offset) -- QUASI-STATIC (exact at constant speed,
      no ringing of that resonance in transients).  Role ``test_stand`` (a fixture resonance) is a
      measurement artefact: left out, as are ``cross_coupling`` (load-cell offset) entries;
    * ``sidebands``: [(direction, h, f_mod Hz, depth m)]: the matching lines (|Δh| < LAW_H_TOL) are
      amplitude modulated, a(1 + m·cos 2πf_mod t) = the carrier + two lines of amplitude m·a/2 whose
      phases advance by ±2πf_mod·t (exact in the time domain).

    * ``floors``: [(channel index, f knots Hz, psd_ref knots unit²/Hz, Ω_ref rad/s, p)] of each
      ``broadband_floor`` (one entry per channel it names): a blocked-load PSD
      S(f, Ω) = psd_ref(f)·(|Ω|/Ω_ref)^p (linear between knots, 0 outside), added to the wheel-frame
      output as a random-phase multisine (see :class:`WheelRuntime`);
    * ``ripples``: [(ΔΩ_ref rad/s, Ω_ref rad/s, q, f_r Hz)] of the ``speed_ripple`` (at most one): the wheel
      turns at Ω(t) + ΔΩ_ref·(|Ω|/Ω_ref)^q·sin(2π f_r t + θ) (see :class:`WheelRuntime`).

    ModelError naming ``effects[i].<field>`` on a bad entry."""
    effects = _schema.parse_effects(doc.get("effects"), source)
    out = {"laws": laws_from_doc({"effects": effects}, source), "resonances": [], "sidebands": [], "floors": [],
           "ripples": []}
    for e in effects:
        if isinstance(e, _schema.FixedResonance) and e.role == "wheel_mode":
            out["resonances"].append((e.directions, *e.resonance))
        elif isinstance(e, _schema.Sidebands):
            out["sidebands"].append((e.direction, float(e.h), float(e.f_mod_Hz), float(e.depth)))
        elif isinstance(e, _schema.BroadbandFloor):
            out["floors"].extend(_floor_from_entry(e))
        elif isinstance(e, _schema.SpeedRipple):
            out["ripples"].append((float(e.delta_omega_rad_s), float(e.omega_ref_rad_s), float(e.speed_exponent),
                                   float(e.f_ripple_Hz)))
    return out


def _floor_from_entry(e):
    """[(channel index, f knots, psd knots, Ω_ref, p)] of one (typed, validated) ``broadband_floor``; a
    channel named twice has one floor (as the coupling kit reads it)."""
    return [(c, np.array(e.f_Hz), np.array(e.psd_ref), float(e.omega_ref_rad_s), float(e.exponent))
            for c in e.channel_indices]


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
    if p["I_zz"] > 2.0 * p["I_rr"] * (1 + 1e-12):
        raise ModelError(f"{source}: analytical: I_zz exceeds 2·I_rr (no rigid body has that)")
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
    The co-rotating radial fundamentals are the imbalance: they keep their tangential term −i·C·Ω̇
    (zero at constant speed) and follow the ``imbalance`` switch.  params carry
    ``suspension`` False and no modal values (0): :class:`WheelRuntime` refuses modes on."""
    lines = [(d, h, C, sense, fundamental) for d, h, C, sense, fundamental in _harmonics(doc, source)]
    if not lines:
        raise ModelError(f"{source}: empirical: no harmonics and no analytical section; the model has no lines")
    p = {name: 0.0 for name in PARAM_KEYS}
    p["suspension"] = False
    p["modes_assumed"] = False
    return p, lines


def physics_of(params, lines, effects=None) -> str:
    """One sentence saying which physics a model carries (for the FMU's description and logs)."""
    if not params.get("suspension", True):
        what = f"empirical harmonics only ({len(lines)} lines, amplitude C*Omega^2), hard-mounted"
    elif params.get("modes_assumed"):
        what = ("extended model with ASSUMED suspension modes (datasheet wheel; hard-mounted unless "
                "modes = true)")
    else:
        what = "extended model: harmonics through the measured suspension modes"
    kinds = [k for k, v in (effects or {}).items() if v]
    names = {"laws": "amplitude laws", "resonances": "wheel-mode resonances", "sidebands": "sidebands",
             "floors": "broadband floors", "ripples": "speed ripple"}
    if kinds:
        what += "; diagnosed effects: " + ", ".join(names.get(k, k) for k in kinds)
    return what


def components(direction, sense, phase, angle=0.0):
    """[(sigma, coef)] of a line, as ``rwadist.extended.Line.components``."""
    if direction in ("axial_force", "axial_torque") or sense == "co":
        return [(1, cmath.exp(1j * phase))]
    if sense == "counter":
        return [(-1, cmath.exp(-1j * phase))]
    return [(1, 0.5 * cmath.exp(1j * (angle + phase))), (-1, 0.5 * cmath.exp(1j * (angle - phase)))]


def quad_roots(m, c, k):
    """Both roots of m λ² + c λ + k = 0 (c complex), the stable form of rwadist.extended."""
    c = complex(c)
    disc = cmath.sqrt(c * c - 4 * m * k)
    sgn = 1.0 if (c.conjugate() * disc).real >= 0 else -1.0
    q = -0.5 * (c + sgn * disc)
    return q / m, k / q


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


def to_spacecraft(out, R, r):
    """Spacecraft-frame loads (…, 6) of wheel-frame loads ``out`` (…, 6): F_sc = R F,
    T_sc = R T + r × F_sc (R wheel → spacecraft DCM, r interface position in m)."""
    out = np.asarray(out, dtype=float)
    F = out[..., :3] @ np.asarray(R).T
    T = out[..., 3:] @ np.asarray(R).T + np.cross(np.asarray(r, dtype=float), F)
    return np.concatenate([F, T], axis=-1)


# ------------------------------------------------------------------ native kernel

#: cfg layout of ``rwadist_kernel_step`` (fmu/native/rwadist_fmu_native.c): parameter order,
#: offsets of the fixed poles, mounting, and the per-component block (σh, direction, coef·C,
#: −i·coef·C·[imbalance], coef·A_ref, Ω_ref, p of an amplitude law, ω_off (rad/s, sidebands),
#: number of resonances, cfg index of its resonance entries), then the resonance table
#: (KERNEL_RES doubles per entry: 2π f_r, 2·g·ζ, 2·ζ).  State: [0] φ, [1] time since t0, then the
#: complex states.  The C file repeats it; tests/test_fmu.py checks both agree by running.
KERNEL_PARAMS = ("mass", "c_r", "k_r", "I_rr", "c_rock", "k_rock", "I_zz", "c_z", "k_z", "height")
KERNEL_COMP = 32
KERNEL_STRIDE = 13
KERNEL_RES = 3

#: floor phasors are recomputed from the time every so many steps (rounding of the rotation stays ~1e-13)
FLOOR_RESYNC = 1000
#: most sinusoids the broadband floors may take (~200 MB with the rotation caches, ~3 ms per step)
FLOOR_MAX_COMPONENTS = 2_000_000
#: seed of the floors' phases when the FMU has none (seed -1): deterministic, still independent per sinusoid
FLOOR_DEFAULT_SEED = 20_251_122
#: a speed ripple needs this many communication steps per ripple period (the rotor's speed is linear over
#: a step: at 20 the sidebands are within ~1 % of their closed form)
RIPPLE_STEPS_PER_PERIOD = 20


def load_kernel(path):
    """``rwadist_kernel_step`` of the native library at ``path`` as a ctypes function, or None
    when the file is missing or is not the rwadist native library (then numpy steps)."""
    try:
        lib = ctypes.CDLL(str(path))
        fn = lib.rwadist_kernel_step
    except (OSError, AttributeError):
        return None
    fn.restype = None
    fn.argtypes = [ctypes.c_void_p] * 3 + [ctypes.c_double] * 4
    return fn


def frame12(o, R, r):
    """[wheel-frame 6] + [spacecraft-frame 6] as a list of floats (R 3×3 nested, r 3)."""
    f0, f1, f2, t0, t1, t2 = (float(v) for v in o)
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    rx, ry, rz = r
    fx = r00 * f0 + r01 * f1 + r02 * f2
    fy = r10 * f0 + r11 * f1 + r12 * f2
    fz = r20 * f0 + r21 * f1 + r22 * f2
    return [f0, f1, f2, t0, t1, t2, fx, fy, fz,
            r00 * t0 + r01 * t1 + r02 * t2 + ry * fz - rz * fy,
            r10 * t0 + r11 * t1 + r12 * t2 + rz * fx - rx * fz,
            r20 * t0 + r21 * t1 + r22 * t2 + rx * fy - ry * fx]


# ------------------------------------------------------------------ the stepping model

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


class WheelRuntime:
    """The extended wheel model as a stepping state machine.

    params, lines : from :func:`load_model`.  seed : None -> each line's phase 0 (the model
    file's), else phases = numpy default_rng(seed).uniform(0, 2π, len(lines)) over *all* lines
    (as ``simulate_time(seed=...)``), so switching effects off keeps the others' phases.
    imbalance, harmonics, modes : effect switches (modes off: the internal loads reach the
    interface directly).  start_steady : start from the closed-form steady state at the first
    step's speed instead of rest.  max_accel : |dΩ/dt| limit, rad/s².  max_step : largest
    communication step accepted, s.  dcm, position : mounting, wheel → spacecraft DCM (3×3,
    default identity) and interface position, m (default 0), for the spacecraft-frame outputs.
    kernel : ``rwadist_kernel_step`` from :func:`load_kernel`, or None to step in numpy.
    laws : diagnosed amplitude laws from :func:`laws_from_doc`; a line (same direction,
    |Δh| < LAW_H_TOL) with a law has amplitude A_ref·(|Ω|/Ω_ref)^p instead of C·Ω² (an imbalance
    line keeps its tangential term −i·C·Ω̇).  resonances, sidebands : diagnosed wheel-mode
    resonances and sidebands from :func:`effects_from_doc` (see there).  Sideband lines are appended
    after the model's lines (per sideband effect, per matching carrier: +f_mod then −f_mod; the
    order of ``rwadist.extended.apply_line_effects``) and the seed's phases are drawn over that
    whole list; they follow their carrier's imbalance/harmonics switch.

    ripples : diagnosed speed ripples (:func:`effects_from_doc`), used when ``speed_ripple``: the rotor
    turns at the input speed plus r(t) = Σ ΔΩ_ref·(|Ω(t)|/Ω_ref)^q·sin(2π f_r t + θ) (t since t0; θ = 0
    without a seed, else uniform from ``default_rng((seed, 1))``).  Each step runs from Ω_n + r(t_n) to
    Ω_{n+1} + r(t_{n+1}) (linear in between, like any step), so the lines are phase and amplitude
    modulated through the same equations as a rippled input speed would be -- exactly the FMU fed that
    speed with the slope as acceleration (tested).  Switch it off when the input is a measured speed that
    already carries the ripple.  Input checks (finite, max_acceleration, jumps) apply to the input speed.

    floors : diagnosed broadband floors (:func:`effects_from_doc`), used when ``broadband_floor``: each is
    added to its wheel-frame output channel (a blocked load, like the measurement it was fitted to) as
    g(Ω)·Σ_k a_k cos(2π f_k t + φ_k) with f_k = k·``floor_resolution`` (Hz) over the knots' span,
    a_k = sqrt(2·psd_ref(f_k)·df) and g = (|Ω|/Ω_ref)^{p/2} at the step's end speed: over one period
    1/df its mean square is Σ_k psd_ref(f_k)·df·g² (Parseval; the floor's integral) and its PSD at a
    resolution coarser than df is psd_ref·g².  Phases φ_k: independent, uniform, from
    ``default_rng((seed, 2))`` (``(FLOOR_DEFAULT_SEED, 2)`` without a seed): the channels and floors are
    incoherent with each other; two wheels need two seeds to be incoherent with each other (as their lines).
    The sum is kept as rotating phasors (one complex multiply per component per step), resynchronised to t
    every FLOOR_RESYNC steps.  The output is sampled at the host's steps: floor content above 1/(2h) folds
    back (the FMU slave warns once).
    """

    def __init__(self, params, lines, *, seed=None, imbalance=True, harmonics=True, modes=True,
                 start_steady=False, max_accel=500.0, max_step=0.01, dcm=None, position=None, kernel=None,
                 laws=None, resonances=None, sidebands=None, ripples=None, floors=None, speed_ripple=True,
                 broadband_floor=True, floor_resolution=0.1):
        self.p = dict(params)
        if not (math.isfinite(max_accel) and max_accel > 0):
            raise ModelError(f"max_acceleration must be finite and > 0, got {max_accel!r}")
        if not (math.isfinite(max_step) and max_step > 0):
            raise ModelError(f"max_step_size must be finite and > 0, got {max_step!r}")
        self.max_accel, self.max_step = float(max_accel), float(max_step)
        self.modes, self.start_steady = bool(modes), bool(start_steady)
        self.suspension = bool(self.p.get("suspension", True))
        if self.modes and not self.suspension:
            raise ModelError("modes: on, but the model has no suspension (analytical: missing -- an empirical "
                             "fit, harmonics only); it runs hard-mounted: set modes = false")
        resonances = list(resonances or [])
        full, self.laws_used, self.sidebands_used = expand_lines(lines, laws, sidebands)
        n = len(full)
        self.n_lines = n
        ph = (np.random.default_rng(int(seed)).uniform(0, 2 * np.pi, n) if seed is not None else np.zeros(n))
        sh, woff, coef, C, imb, dirs, law, res = [], [], [], [], [], [], [], []
        for (d, h, c, sense, is_imb, lw, off), q in zip(full, ph):
            if (is_imb and not imbalance) or (not is_imb and not harmonics):
                continue
            rs = [(2.0 * math.pi * f_r, 2.0 * g * z, 2.0 * z) for dd, f_r, z, g in resonances if d in dd]
            for sigma, cf in components(d, sense, float(q)):
                sh.append(sigma * h)
                woff.append(sigma * 2.0 * math.pi * off)
                coef.append(cf)
                C.append(c)
                imb.append(is_imb)
                dirs.append(DIRECTIONS.index(d))
                law.append((1.0, *lw) if lw is not None else (0.0, 0.0, 1.0, 0.0))
                res.append(rs)
        self.sh = np.array(sh, dtype=float)
        self.woff = np.array(woff, dtype=float)
        self.has_off = bool(np.any(self.woff != 0.0))
        # resonance table: one row per (component, resonance): component index, 2π f_r, 2gζ, 2ζ
        self.res_comp = np.array([i for i, rs in enumerate(res) for _ in rs], dtype=int)
        tab = np.array([r for rs in res for r in rs], dtype=float).reshape(-1, 3)
        self.res_w, self.res_2gz, self.res_2z = tab[:, 0], tab[:, 1], tab[:, 2]
        self.res_sh, self.res_off = self.sh[self.res_comp], self.woff[self.res_comp]
        self.coef = np.array(coef, dtype=complex)
        self.C = np.array(C, dtype=float)
        self.imb = np.array(imb, dtype=float)
        self.dirs = np.array(dirs, dtype=int)
        self.sel = np.zeros((4, self.sh.size), dtype=complex)
        self.sel[self.dirs, np.arange(self.sh.size)] = 1.0
        self.at = self.dirs == 3
        self.ish = 1j * self.sh
        self.cC = self.coef * self.C
        self.cCi = -1j * self.coef * self.C * self.imb
        law = np.array(law, dtype=float).reshape(-1, 4)
        self.law_idx = np.nonzero(law[:, 0] > 0)[0]             # components with a diagnosed law
        self.law_scale = self.coef[self.law_idx] * law[self.law_idx, 1]
        self.law_ref = law[self.law_idx, 2]
        self.law_p = law[self.law_idx, 3]
        self.cC[self.law_idx] = 0.0                              # C·Ω² replaced by the law
        self.rock = np.nonzero(self.dirs == 1)[0]
        p = self.p
        if self.suspension:
            self.lam_r = quad_roots(p["mass"], p["c_r"], p["k_r"])
            self.lam_z = quad_roots(p["mass"], p["c_z"], p["k_z"])
        else:       # never used (modes are off); distinct poles keep the kernel's layout finite
            self.lam_r = self.lam_z = (-1.0 + 0j, -2.0 + 0j)
        lam = np.zeros((self.sh.size, 2), dtype=complex)
        for j, ls in ((0, self.lam_r), (2, self.lam_z)):
            lam[self.dirs == j] = ls
        # axial-torque components load no mode; a dummy pole keeps their (discarded) integrals
        # finite so that 0·x in the direction sums stays 0
        lam[self.dirs == 3] = -1.0
        self._lam_static = lam
        self._cache = {}
        R = np.eye(3) if dcm is None else rotation_check(dcm)
        pos = np.zeros(3) if position is None else np.asarray(position, dtype=float).reshape(3)
        if not np.all(np.isfinite(pos)):
            raise ModelError(f"interface position r = {pos.tolist()!r} m is not finite")
        self.R = [list(map(float, row)) for row in R]
        self.pos = [float(v) for v in pos]
        self._kernel = kernel
        if kernel is not None:
            n = self.sh.size
            cfg = np.zeros(KERNEL_COMP + KERNEL_STRIDE * n + KERNEL_RES * self.res_comp.size)
            cfg[0], cfg[1] = n, float(self.modes)
            cfg[2:12] = [p[k] for k in KERNEL_PARAMS]
            cfg[12:16] = np.array(self.lam_r, dtype=complex).view(float)
            cfg[16:20] = np.array(self.lam_z, dtype=complex).view(float)
            cfg[20:29] = np.ravel(self.R)
            cfg[29:32] = self.pos
            comp = cfg[KERNEL_COMP:KERNEL_COMP + KERNEL_STRIDE * n].reshape(n, KERNEL_STRIDE)
            comp[:, 0], comp[:, 1] = self.sh, self.dirs
            comp[:, 2:4] = self.cC.view(float).reshape(n, 2)
            comp[:, 4:6] = self.cCi.view(float).reshape(n, 2)
            comp[:, 8] = 1.0
            comp[self.law_idx, 6:8] = self.law_scale.view(float).reshape(-1, 2)
            comp[self.law_idx, 8] = self.law_ref
            comp[self.law_idx, 9] = self.law_p
            comp[:, 10] = self.woff
            base = KERNEL_COMP + KERNEL_STRIDE * n
            table = cfg[base:].reshape(-1, KERNEL_RES)
            table[:, 0], table[:, 1], table[:, 2] = self.res_w, self.res_2gz, self.res_2z
            for i in range(n):
                rows = np.nonzero(self.res_comp == i)[0]
                comp[i, 11] = rows.size
                comp[i, 12] = base + KERNEL_RES * rows[0] if rows.size else 0.0
            self._cfg = cfg
            self._st = np.zeros(2 + 2 * n + 12)
            self._kout = np.zeros(12)
            self._ptrs = (cfg.ctypes.data, self._st.ctypes.data, self._kout.ctypes.data)
        self._init_ripple(ripples if speed_ripple else None, seed)
        self._init_floor(floors if broadband_floor else None, seed, floor_resolution)
        self.reset()

    def _init_ripple(self, ripples, seed):
        rip = [tuple(float(v) for v in r) for r in (ripples or [])]
        self.has_ripple = bool(rip)
        theta = (np.random.default_rng((int(seed), 1)).uniform(0, 2 * np.pi, len(rip)) if seed is not None
                 else np.zeros(len(rip)))
        # (ΔΩ_ref, Ω_ref, q, 2π f_r, θ) per ripple; plain floats: one or two per model, called twice a step
        self.ripples = [(dw, w_ref, q, 2.0 * math.pi * f_r, float(th)) for (dw, w_ref, q, f_r), th in zip(rip, theta)]
        self.ripple_f_max = max((r[3] for r in rip), default=0.0)

    def ripple(self, omega, t):
        """Speed ripple r (rad/s) at input speed ``omega`` (rad/s) and time ``t`` since t0 (s)."""
        r = 0.0
        for dw, w_ref, q, w_r, th in self.ripples:
            r += (dw * (abs(omega) / w_ref) ** q if q else dw) * math.sin(w_r * t + th)
        return r

    def ripple_rate(self, omega, t):
        """dr/dt (rad/s²) of the speed ripple at input speed ``omega`` (held) and time ``t``."""
        r = 0.0
        for dw, w_ref, q, w_r, th in self.ripples:
            r += (dw * (abs(omega) / w_ref) ** q if q else dw) * w_r * math.cos(w_r * t + th)
        return r

    def _init_floor(self, floors, seed, df):
        if not (isinstance(df, (int, float)) and math.isfinite(df) and df > 0):
            raise ModelError(f"floor_resolution must be finite and > 0, got {df!r} Hz")
        floors = list(floors or [])
        self.has_floor = bool(floors)
        self.floor_f_max = 0.0
        if not self.has_floor:
            return
        spans = [(max(1, math.ceil(f_k[0] / df)), math.floor(f_k[-1] / df)) for _, f_k, _, _, _ in floors]
        n_max = sum(max(0, k1 - k0 + 1) for k0, k1 in spans)       # before allocating anything
        if n_max > FLOOR_MAX_COMPONENTS:
            raise ModelError(f"broadband floors need {n_max} sinusoids at floor_resolution = {df:g} Hz (limit "
                             f"{FLOOR_MAX_COMPONENTS}); use a coarser floor_resolution")
        amp, wk, chan, ref, expo, starts = [], [], [], [], [], []
        for (c, f_k, psd_k, w_ref, p), (k0, k1) in zip(floors, spans):
            k = np.arange(k0, k1 + 1)
            S = np.interp(k * df, f_k, psd_k, left=0.0, right=0.0)
            keep = S > 0
            if not keep.any():
                if np.any(psd_k > 0):
                    raise ModelError(f"a broadband floor of {CHANNELS[c]} ({f_k[0]:g}-{f_k[-1]:g} Hz) has no "
                                     f"sinusoid at floor_resolution = {df:g} Hz; use a finer floor_resolution")
                continue
            starts.append(sum(a.size for a in amp))
            amp.append(np.sqrt(2.0 * S[keep] * df))
            wk.append(2.0 * math.pi * df * k[keep])
            chan.append(c)
            ref.append(w_ref)
            expo.append(0.5 * p)
        self.has_floor = bool(amp)
        if not self.has_floor:
            return
        A, self.floor_w = np.concatenate(amp), np.concatenate(wk)
        self.floor_f_max = float(self.floor_w.max() / (2.0 * math.pi))
        # independent uniform phases for every sinusoid of every channel and floor (channels are
        # incoherent); without a seed from a fixed one, so the FMU stays deterministic
        ph = np.random.default_rng((FLOOR_DEFAULT_SEED if seed is None else int(seed), 2)).uniform(0, 2 * np.pi, A.size)
        self.floor_A = A * np.exp(1j * ph)
        self.floor_starts = np.array(starts, dtype=int)
        self.floor_chan = np.array(chan, dtype=int)
        self.floor_ref = np.array(ref)
        self.floor_half_p = np.array(expo)
        self.floor_rot = {}

    def floor_now(self, omega, t, advance=None):
        """(6,) floor loads at input speed ``omega`` and time ``t``: the phasors advanced by ``advance``
        seconds (a step) or, with None or every FLOOR_RESYNC steps, set from t exactly."""
        if advance is None or self._floor_count >= FLOOR_RESYNC:
            self._floor_Z = self.floor_A * np.exp(1j * self.floor_w * t)
            self._floor_count = 0
        else:
            rot = self.floor_rot.get(advance)
            if rot is None:
                if len(self.floor_rot) >= 4:         # a host with a varying step: a few sizes, bounded memory
                    self.floor_rot.clear()
                rot = self.floor_rot[advance] = np.exp(1j * self.floor_w * advance)
            self._floor_Z *= rot
            self._floor_count += 1
        sums = np.add.reduceat(self._floor_Z.real, self.floor_starts)
        g = (abs(omega) / self.floor_ref) ** self.floor_half_p
        return np.bincount(self.floor_chan, weights=g * sums, minlength=6)

    @property
    def native(self) -> bool:
        """True when steps run in the native kernel."""
        return self._kernel is not None

    def _pack(self):
        """Current state into the kernel's state array."""
        n = self.sh.size
        st = self._st
        st[0] = self.phi
        st[1] = self.t
        st[2:].view(complex)[:] = np.concatenate([self.S, self.eta_r, self.eta_z, self.x_rock])[: n + 6]

    # ------------------------------------------------------------ state
    def reset(self):
        """Back to t0: rotor angle 0, all modal states zero, no previous step."""
        self.phi = 0.0
        self.t = 0.0
        self.S = np.ones(self.sh.size, dtype=complex)
        self.eta_r = [0j, 0j]
        self.eta_z = [0j, 0j]
        self.x_rock = [0j, 0j]
        self.prev_alpha = None
        self.prev_end = None          # (Ω at the end of the previous step, step size)
        self.started = False
        self.out = np.zeros(6)
        self.y = [0.0] * 12
        self._floor_count = FLOOR_RESYNC      # the first floor value is set from t

    def _amp(self, w, wdot):
        """coef·C·(Ω² − iΩ̇·[imbalance]) per component (coef·A_ref·(|Ω|/Ω_ref)^p in place of
        coef·C·Ω² for a line with a diagnosed amplitude law)."""
        a = self.cC * (w * w) + self.cCi * wdot
        if self.law_idx.size:
            a[self.law_idx] += self.law_scale * (abs(w) / self.law_ref) ** self.law_p
        if self.res_comp.size:
            # quasi-static wheel-mode resonances at each component's whirl rate ν = σhΩ + ω_off
            r = (self.res_sh * w + self.res_off) / self.res_w
            base = 1.0 - r * r
            G = np.ones(a.size, dtype=complex)
            np.multiply.at(G, self.res_comp, (base + 1j * self.res_2gz * r) / (base + 1j * self.res_2z * r))
            a = a * G
        return a

    def _phase(self, phi, t):
        """e^{i(σhφ + ω_off t)} per component."""
        if self.has_off:
            return np.exp(1j * (self.sh * phi + self.woff * t))
        return np.exp(self.ish * phi)

    def _loads(self, w, wdot, phi):
        """Internal complex loads per direction (4,) at speed w, acceleration wdot, angle phi."""
        return self.sel @ (self._amp(w, wdot) * self._phase(phi, self.t))

    def _steady_init(self, w0, wdot0):
        p = self.p
        amp0 = self._amp(w0, wdot0)
        subs = ((p["mass"], p["c_r"], p["k_r"], 0.0), (p["I_rr"], p["c_rock"], p["k_rock"], p["I_zz"]),
                (p["mass"], p["c_z"], p["k_z"], 0.0))
        st = []
        for j, (m, c, k, g) in enumerate(subs):
            keep = self.dirs == j
            nu = self.sh[keep] * w0 + self.woff[keep]
            G = 1.0 / (k - m * nu**2 + g * w0 * nu + 1j * c * nu)
            st.append((complex(np.sum(G * amp0[keep])), complex(np.sum(1j * nu * G * amp0[keep]))))
        (q, qd), (qr, qdr), (qz, qdz) = st
        l1, l2 = self.lam_r
        self.eta_r = [(qd - l2 * q) / (l1 - l2), (l1 * q - qd) / (l1 - l2)]
        l1, l2 = self.lam_z
        self.eta_z = [(qdz - l2 * qz) / (l1 - l2), (l1 * qz - qdz) / (l1 - l2)]
        self.x_rock = [qr, qdr]

    def _lti_consts(self, h):
        """Per step size h: (λh (n,2) and e^{λh} (n,2) with the rocking rows left to fill, the
        smallest |Re λh| of the fixed modes, e^{λ_r h}, e^{λ_z h})."""
        c = self._cache.get(h)
        if c is None:
            if len(self._cache) > 64:
                self._cache.clear()
            lamh = self._lam_static * h
            fixed = np.concatenate([np.array(self.lam_r), np.array(self.lam_z)]) * h
            c = (lamh, np.exp(lamh), float(np.min(np.abs(fixed.real))),
                 np.exp(np.array(self.lam_r) * h), np.exp(np.array(self.lam_z) * h))
            self._cache[h] = c
        return c

    # ------------------------------------------------------------ checks
    def check_step(self, omega, alpha, h):
        """ModelError naming the problem if (Ω, α, h) cannot be stepped; None if fine."""
        if not math.isfinite(h) or h <= 0:
            raise ModelError(f"communication step size {h!r} s is not a positive finite number")
        if h > self.max_step * (1 + 1e-12):
            raise ModelError(f"communication step size {h:.6g} s exceeds max_step_size = {self.max_step:.6g} s "
                             "(the frozen-speed rocking transition and the derived acceleration are only "
                             "resolved below it)")
        if h < 1e-9:
            raise ModelError(f"communication step size {h:.3g} s is below the 1 ns the FMU resolves")
        if self.has_ripple and h * self.ripple_f_max * RIPPLE_STEPS_PER_PERIOD > 1 + 1e-12:
            raise ModelError(f"communication step size {h:.6g} s does not resolve the speed ripple of "
                             f"{self.ripple_f_max:.6g} Hz (at most {1 / (RIPPLE_STEPS_PER_PERIOD * self.ripple_f_max):.6g}"
                             f" s: {RIPPLE_STEPS_PER_PERIOD} steps per period); use smaller steps or speed_ripple = "
                             "false")
        if not math.isfinite(omega):
            raise ModelError(f"wheel_speed is not finite: {omega!r} rad/s")
        if alpha is not None and not math.isfinite(alpha):
            raise ModelError(f"wheel_acceleration is not finite: {alpha!r} rad/s²")
        if alpha is not None and abs(alpha) > self.max_accel:
            raise ModelError(f"wheel_acceleration {alpha:.6g} rad/s² exceeds max_acceleration = "
                             f"{self.max_accel:.6g} rad/s²")
        if self.prev_end is not None:
            w_end, h_prev = self.prev_end
            jump = abs(omega - w_end) / h_prev
            if jump > self.max_accel:
                raise ModelError(f"wheel_speed jumps from {w_end:.6g} to {omega:.6g} rad/s over one step "
                                 f"({h_prev:.6g} s): |dΩ/dt| = {jump:.3g} rad/s² > max_acceleration = "
                                 f"{self.max_accel:.6g} rad/s²")

    # ------------------------------------------------------------ step
    def step(self, omega, alpha, h):
        """Advance one communication step from speed ``omega`` (rad/s) with acceleration ``alpha``
        (rad/s²; None: derived as the previous step's mean rate, 0 on the first step) over ``h``
        seconds.  Returns the wheel-frame outputs at the step's end (6,).  Raises ModelError
        (state untouched) on bad input."""
        return np.array(self.step12(omega, alpha, h)[:6])

    def step12(self, omega, alpha, h):
        """As :meth:`step`, returning the 12 outputs (wheel frame, then spacecraft frame) as a list."""
        omega, h = float(omega), float(h)
        alpha = None if alpha is None else float(alpha)
        self.check_step(omega, alpha, h)
        if alpha is None:
            if self.prev_end is None:
                alpha = 0.0
            else:
                w_end, h_prev = self.prev_end
                # previous step's start speed -> this step's start speed
                alpha = (omega - self._prev_start) / h_prev
                if abs(alpha) > self.max_accel:
                    raise ModelError(f"derived wheel acceleration {alpha:.6g} rad/s² exceeds max_acceleration = "
                                     f"{self.max_accel:.6g} rad/s²")
        w_in, w1_in = omega, omega + alpha * h
        t_end = self.t + h
        if self.has_ripple:      # the rotor's speed: input + ripple, linear over the step
            r0 = self.ripple(omega, self.t)
            alpha = alpha + (self.ripple(w1_in, t_end) - r0) / h
            omega = omega + r0
        wd0 = alpha if self.prev_alpha is None else 0.5 * (self.prev_alpha + alpha)
        if not self.started:
            if self.start_steady and self.suspension:
                self._steady_init(omega, wd0)
            self.started = True
            if self._kernel is not None:
                self._pack()
        w1 = omega + alpha * h
        if self._kernel is not None:
            cfg, st, out = self._ptrs
            self._kernel(cfg, st, out, omega, wd0, alpha, h)
            self._prev_start = w_in
            self.prev_alpha = alpha
            self.prev_end = (w1_in, h)
            self.t = t_end
            if self.has_floor:
                self.out = self._kout[:6] + self.floor_now(w1_in, t_end, h)
                self.y = y = frame12(self.out, self.R, self.pos)
            else:
                self.y = y = self._kout.tolist()
            return y
        p = self.p
        dphi = 0.5 * (omega + w1) * h
        phi1 = self.phi + dphi
        S0 = self.S
        S1 = self._phase(phi1, t_end)
        a0 = self._amp(omega, wd0)
        a1 = self._amp(w1, alpha)
        loads1 = self.sel @ (a1 * S1)
        if self.modes and self.sh.size:
            w_mid = 0.5 * (omega + w1)
            lk1, lk2 = quad_roots(p["I_rr"], p["c_rock"] - 1j * p["I_zz"] * w_mid, p["k_rock"])
            lamh0, X0, min_re, Xr, Xz = self._lti_consts(h)
            e1, e2 = cmath.exp(lk1 * h), cmath.exp(lk2 * h)
            lamh, X = lamh0.copy(), X0.copy()
            lamh[self.rock] = (lk1 * h, lk2 * h)
            X[self.rock] = (e1, e2)
            z = ((1j * (self.sh * dphi + self.woff * h)) if self.has_off else (self.ish * dphi))[:, None] - lamh
            XS0 = X * S0[:, None]
            S1c = S1[:, None]
            # |z| >= |Re z| = |Re λh|: the series is needed only if some |Re λh| < SMALL_Z
            if min(min_re, abs(lk1.real * h), abs(lk2.real * h)) >= SMALL_Z:
                t0 = (S1c - XS0) / z
                t1 = (S1c - t0) / z
            else:
                small = np.abs(z) < SMALL_Z
                zb = np.where(small, 1.0, z)
                t0 = (S1c - XS0) / zb
                t1 = (S1c - t0) / zb
                if small.any():
                    zs = z[small]
                    e0s = 1 + zs * (1 / 2 + zs * (1 / 6 + zs * (1 / 24 + zs / 120)))
                    e1s = 1 / 2 + zs * (1 / 3 + zs * (1 / 8 + zs * (1 / 30 + zs / 144)))
                    t0[small] = XS0[small] * e0s
                    t1[small] = XS0[small] * e1s
            W = (self.sel @ (a0[:, None] * t0 + (a1 - a0)[:, None] * t1)) * h   # (4, 2)
            # radial and axial translation: eigen-coordinates η_j' = pole η_j + w_j/(m(λ_j − λ_k))
            for eta, (l1, l2), Xp, row, (m, c, k) in (
                    (self.eta_r, self.lam_r, Xr, 0, (p["mass"], p["c_r"], p["k_r"])),
                    (self.eta_z, self.lam_z, Xz, 2, (p["mass"], p["c_z"], p["k_z"]))):
                eta[0] = Xp[0] * eta[0] + W[row, 0] / (m * (l1 - l2))
                eta[1] = Xp[1] * eta[1] + W[row, 1] / (m * (l2 - l1))
            # rocking: exact transition at the mean speed of the step
            dl = lk1 - lk2
            q, qd = self.x_rock
            kI = p["k_rock"] / p["I_rr"]
            P00 = (e1 * (-lk2) - e2 * (-lk1)) / dl
            P01 = (e1 - e2) / dl
            P10 = (-kI) * (e1 - e2) / dl
            P11 = (e1 * lk1 - e2 * lk2) / dl
            w1r = W[1, 0] / (p["I_rr"] * dl)
            w2r = W[1, 1] / (-p["I_rr"] * dl)
            self.x_rock = [P00 * q + P01 * qd + w1r + w2r, P10 * q + P11 * qd + lk1 * w1r + lk2 * w2r]
        self.phi = phi1
        self.t = t_end
        self.S = S1
        self._prev_start = w_in
        self.prev_alpha = alpha
        self.prev_end = (w1_in, h)
        self.out = self._outputs(loads1)
        if self.has_floor:
            self.out = self.out + self.floor_now(w1_in, t_end, h)
        self.y = frame12(self.out, self.R, self.pos)
        return self.y

    def outputs_now(self, omega, alpha=0.0):
        """Outputs at the current state for speed ``omega`` (used at t0 before the first step)."""
        w_in = float(omega)
        omega, alpha = w_in, float(alpha)
        if self.has_ripple:
            omega += self.ripple(w_in, self.t)
            alpha += self.ripple_rate(w_in, self.t)
        if not self.started and self.start_steady and self.suspension:
            self._steady_init(omega, alpha)
        loads = self._loads(omega, alpha, self.phi)
        self.out = self._outputs(loads)
        if self.has_floor:
            self.out = self.out + self.floor_now(w_in, self.t)
        self.y = frame12(self.out, self.R, self.pos)
        return self.out

    def _outputs(self, loads):
        p = self.p
        if self.modes:
            l1, l2 = self.lam_r
            q, qd = self.eta_r[0] + self.eta_r[1], l1 * self.eta_r[0] + l2 * self.eta_r[1]
            F = p["k_r"] * q + p["c_r"] * qd
            l1, l2 = self.lam_z
            qz, qdz = self.eta_z[0] + self.eta_z[1], l1 * self.eta_z[0] + l2 * self.eta_z[1]
            Fz = (p["k_z"] * qz + p["c_z"] * qdz).real
            Tc = p["k_rock"] * self.x_rock[0] + p["c_rock"] * self.x_rock[1]
        else:
            F, Fz, Tc = complex(loads[0]), float(loads[2].real), complex(loads[1])
        Tint = Tc + 1j * p["height"] * F
        return np.array([F.real, F.imag, Fz, Tint.real, Tint.imag, float(loads[3].real)])

    # ------------------------------------------------------------ convenience
    def run(self, t, omega, alpha="slope"):
        """Step through a uniform profile (t, omega) as a host would; returns (n, 6) outputs with
        row 0 the t0 outputs.  alpha: 'slope' (each step gets (Ω_{n+1} − Ω_n)/h as
        wheel_acceleration), None (derived), or an array per sample."""
        t = np.asarray(t, dtype=float)
        w = np.asarray(omega, dtype=float)
        h = (t[-1] - t[0]) / (t.size - 1)
        if isinstance(alpha, str):
            acc = np.append(np.diff(w) / h, 0.0)
        elif alpha is None:
            acc = [None] * w.size
        else:
            acc = np.asarray(alpha, dtype=float)
        out = np.empty((t.size, 6))
        out[0] = self.outputs_now(w[0], 0.0 if acc[0] is None else acc[0])
        for n in range(t.size - 1):
            out[n + 1] = self.step(w[n], acc[n], h)
        return out
