"""The analytical / extended wheel model: a rigid rotor on a flexible suspension.

Physics (Masterson 1999 §4.1, axial mode from Aghalari & Iranzad), small motion,
linear, checked against Newton–Euler.  Five degrees of freedom of the rotor
(mass ``M``, polar inertia ``I_zz``, transverse inertia ``I_rr``) relative to the
housing, which is rigid and bolted to the interface:

* radial translation ``u = x + i·y`` of the rotor centre::

      M ü + c_r u̇ + k_r u = F(t)

* rocking ``ψ = θx + i·θy`` (small rotations of the spin axis about the wheel
  x and y axes).  The rotor's transverse angular momentum is
  ``H = I_rr ψ̇ − i·I_zz·Ω·ψ`` (spin axis ``n ≈ (θy, −θx, 1)``), and dH/dt = torque::

      I_rr ψ̈ + (c_rock − i·I_zz·Ω) ψ̇ + k_rock ψ = T(t)

  (the thesis's Eq. 4.19 written with ψ; its Eq. 4.5 swaps the inertias, see
  CONVENTIONS.md).  With ψ ∝ e^{iνt} the undamped characteristic polynomial is
  ``I_rr ν² − I_zz Ω ν − k_rock = 0``: ν = aΩ/2 ± sqrt((aΩ/2)² + ω0²), a = I_zz/I_rr,
  ω0² = k_rock/I_rr.  For Ω > 0 the root ν > 0 whirls with the spin (forward, rises
  with speed) and ν < 0 against it (backward, falls).  For Ω < 0 the roles swap:
  the forward whirl still rotates with the spin, now about −z.

* axial translation ``z``:  ``M z̈ + c_z ż + k_z z = Fz(t)``.

Translation and rocking decouple because the suspension is symmetric about the
rotor centre (thesis Fig. 4-1: springs k/2 at ±d_k, so k_rock = k·d_k²,
c_rock = c·d_c²).

Geometry and outputs.  The forces and torques the wheel exerts on the interface
are the reactions of the suspension (spring *and* damper) on the housing::

    F_int = k_r u + c_r u̇          (Fx = Re, Fy = Im)
    Fz    = k_z z + c_z ż
    T_int = k_rock ψ + c_rock ψ̇ + i·height·F_int      (Tx = Re, Ty = Im)
    Tz    = axial-torque harmonics (passed through; no torsional mode)

``height`` is the signed z coordinate of the rotor centre (where the radial force
acts) above the interface point; ``r × F = height·ẑ × F = i·height·F`` in complex
form.  For the E wheel we take the thesis's h = 8.30 cm (Table 4.2; in the thesis
it is the axial offset of the dynamic-imbalance masses, half the wheel thickness,
i.e. the rotor centre sits half a wheel thickness above its base plane) -- an
assumption, stated here.  The reaction torque of the motor (I_zz·Ω̇, the wheel's
intended output) is not a disturbance and is not included in Tz.

Forcing.  Every line has a rotation sense: co-rotating ``C Ω² e^{+i(hφ+p)}``,
counter-rotating ``C Ω² e^{−i(hφ+p)}``, planar = both halves with amplitude C/2
each (a straight-line load of amplitude C Ω² along ``angle``), φ = ∫Ω dt the
rotor angle.  Static imbalance is ``U_s (Ω² − iΩ̇) e^{iφ}`` on translation (the
−iΩ̇ part is the tangential force of the imbalance mass when the wheel
accelerates), dynamic imbalance ``U_d (Ω² − iΩ̇) e^{iφ}`` on rocking.  A
co-rotating load at whirl frequency ν = +hΩ only meets the pole at ν = +hΩ of
the complex-coordinate transfer function 1/(k − I ν² + I_zz Ω ν + i c ν), i.e.
the forward whirl; a counter-rotating one (ν = −hΩ) only the backward whirl.  In
real x/y coordinates a planar load is the sum of both, which is why the thesis
found one whirl "cancelled" (its Eq. 4.87 forcing is co-rotating, Eq. 4.92 the
counter-rotating counterpart): no cancellation is needed, only the sense.

Steady-state complex amplitudes ``A`` of a channel at line frequency
ω_line = h|Ω| mean ``signal(t) = Re(A e^{i ω_line (t − t0)})`` with the rotor angle
φ(t0) = 0.

All quantities SI: kg, m, kg·m², N/m, N·s/m, N·m/rad, N·m·s/rad, rad/s, Hz for
frequencies returned as Hz.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from scipy import optimize, signal

from .data import DataError
from .resonance import resonance_gain
from .units import CHANNELS, G_CM2_TO_KG_M2, G_CM_TO_KG_M, RAD_S_TO_RPM

MODES = ("radial_translation", "rocking_forward", "rocking_backward", "axial_translation")
SENSES = ("co", "counter", "planar")
DIRECTIONS = ("radial_force", "radial_torque", "axial_force", "axial_torque")
ANALYTICAL_KIND = "rigid_rotor_5dof"
#: Largest |dΩ/dt| (rad/s²) a speed profile may show before it counts as a jump.
DEFAULT_MAX_ACCEL = 500.0

#: Model-file keys of :class:`ExtendedParams` (field -> key with unit).
_DICT_KEYS = {
    "mass": "mass_kg", "I_zz": "I_zz_kg_m2", "I_rr": "I_rr_kg_m2",
    "k_r": "k_r_N_per_m", "c_r": "c_r_N_s_per_m",
    "k_rock": "k_rock_Nm_per_rad", "c_rock": "c_rock_Nm_s_per_rad",
    "k_z": "k_z_N_per_m", "c_z": "c_z_N_s_per_m",
    "height": "height_m", "U_s": "U_s_kg_m", "U_d": "U_d_kg_m2",
}


def thin_disc(mass: float, radius: float) -> tuple:
    """(I_zz, I_rr) of a thin disc, kg·m²: polar ½MR², transverse ¼MR²."""
    return 0.5 * mass * radius**2, 0.25 * mass * radius**2


@dataclass(frozen=True)
class ExtendedParams:
    """Parameters of the rigid rotor on its suspension (SI; see module docstring).

    mass : rotor mass M, kg.  I_zz, I_rr : polar and transverse inertia about the rotor
    centre, kg·m².  k_r, c_r : radial translation stiffness N/m and damping N·s/m.
    k_rock, c_rock : rocking stiffness N·m/rad and damping N·m·s/rad (thesis k·d_k², c·d_c²).
    k_z, c_z : axial stiffness N/m and damping N·s/m.  height : signed axial position of
    the rotor centre above the interface point, m (lever arm of the radial force).
    U_s : static imbalance, kg·m.  U_d : dynamic imbalance, kg·m².
    """

    mass: float
    I_zz: float
    I_rr: float
    k_r: float
    c_r: float
    k_rock: float
    c_rock: float
    k_z: float
    c_z: float
    height: float = 0.0
    U_s: float = 0.0
    U_d: float = 0.0

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
                raise ValueError(f"ExtendedParams.{f.name} must be a finite number, got {v!r}")
        for name in ("mass", "I_zz", "I_rr", "k_r", "k_rock", "k_z"):
            if getattr(self, name) <= 0:
                raise ValueError(f"ExtendedParams.{name} must be > 0, got {getattr(self, name)!r}")
        for name in ("c_r", "c_rock", "c_z", "U_s", "U_d"):
            if getattr(self, name) < 0:
                raise ValueError(f"ExtendedParams.{name} must be >= 0, got {getattr(self, name)!r}")
        if self.I_zz > 2.0 * self.I_rr * (1 + 1e-12):
            raise ValueError(f"ExtendedParams.I_zz = {self.I_zz!r} exceeds 2·I_rr = {2 * self.I_rr!r}; "
                             "no rigid body has that (I_zz <= I_xx + I_yy)")
        for mode, zeta, cname in (("radial_translation", self.zeta_r, "c_r"),
                                  ("rocking (at rest)", self.zeta_rock, "c_rock"),
                                  ("axial_translation", self.zeta_z, "c_z")):
            if zeta >= 1.0:
                raise ValueError(f"ExtendedParams.{cname} = {getattr(self, cname)!r} makes the {mode} mode "
                                 f"overdamped (damping ratio {zeta:.3g} >= 1)")

    # ------------------------------------------------------------------ derived
    @property
    def inertia_ratio(self) -> float:
        """a = I_zz / I_rr (2 for a thin disc)."""
        return self.I_zz / self.I_rr

    @property
    def omega_r(self) -> float:
        """Radial translation natural frequency sqrt(k_r/M), rad/s."""
        return math.sqrt(self.k_r / self.mass)

    @property
    def omega_rock(self) -> float:
        """Rocking natural frequency at rest sqrt(k_rock/I_rr), rad/s."""
        return math.sqrt(self.k_rock / self.I_rr)

    @property
    def omega_z(self) -> float:
        """Axial natural frequency sqrt(k_z/M), rad/s."""
        return math.sqrt(self.k_z / self.mass)

    @property
    def zeta_r(self) -> float:
        return self.c_r / (2.0 * math.sqrt(self.k_r * self.mass))

    @property
    def zeta_rock(self) -> float:
        """Rocking damping ratio at rest."""
        return self.c_rock / (2.0 * math.sqrt(self.k_rock * self.I_rr))

    @property
    def zeta_z(self) -> float:
        return self.c_z / (2.0 * math.sqrt(self.k_z * self.mass))


def from_table_4_2(zeta_z: float = 0.05) -> ExtendedParams:
    """Ithaco E wheel, thesis Table 4.2 (M 10.6 kg, R 19.65 cm, k 21.7 N/µm, d_k = d_c 2.37 cm,
    c 5067 kg/s, h 8.30 cm, U_s 0.38 g·cm, U_d 24.77 g·cm²), thin-disc inertias.

    The thesis has no axial parameters: k_z puts the axial mode at the maker's 70 Hz
    (Table 2.3) with the same mass; c_z gives the damping ratio ``zeta_z`` (default 0.05,
    an assumption -- fit it from the axial ridge when data exist).

    Note: Table 4.2 is not self-consistent on U_d.  Its m_d = 0.062 g with r_d = 19.65 cm and
    h = 8.30 cm gives U_d = 2·m_d·r_d·h = 20.2 g·cm², which is Table 3.7's C_tor1 after mode
    removal (0.2205e-7 N·m/rpm²); its U_d = 24.77 g·cm² is the coefficient *before* removal
    (0.2716e-7).  We follow the printed U_d.
    """
    M, R = 10.6, 0.1965
    k, d_k, c, d_c = 21.7e6, 0.0237, 5067.0, 0.0237
    I_zz, I_rr = thin_disc(M, R)
    k_z = M * (2 * math.pi * 70.0) ** 2
    return ExtendedParams(mass=M, I_zz=I_zz, I_rr=I_rr, k_r=k, c_r=c, k_rock=k * d_k**2, c_rock=c * d_c**2,
                          k_z=k_z, c_z=2 * zeta_z * math.sqrt(k_z * M), height=0.083,
                          U_s=0.38 * G_CM_TO_KG_M, U_d=24.77 * G_CM2_TO_KG_M2)


# ---------------------------------------------------------------- model file

def params_to_dict(p: ExtendedParams) -> dict:
    """The ``analytical`` section of the model file (flat, units in the key names)."""
    d = {"kind": ANALYTICAL_KIND}
    d.update({key: float(getattr(p, name)) for name, key in _DICT_KEYS.items()})
    return d


def params_from_dict(d, source="<model>") -> ExtendedParams:
    """Inverse of :func:`params_to_dict`; DataError(source, 'analytical.<key>', ...) on a missing
    or invalid field, DataError(source, 'analytical', ...) when the values are unphysical."""
    if d is None:
        raise DataError(source, "analytical", "missing: the model file has no analytical parameters")
    if not isinstance(d, dict):
        raise DataError(source, "analytical", f"must be an object, got {type(d).__name__}")
    kind = d.get("kind", ANALYTICAL_KIND)
    if kind != ANALYTICAL_KIND:
        raise DataError(source, "analytical.kind", f"{kind!r} is not {ANALYTICAL_KIND!r}")
    vals = {}
    for name, key in _DICT_KEYS.items():
        if key not in d:
            raise DataError(source, f"analytical.{key}", "missing")
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise DataError(source, f"analytical.{key}", f"must be a finite number, got {v!r}")
        vals[name] = float(v)
    try:
        return ExtendedParams(**vals)
    except ValueError as exc:
        raise DataError(source, "analytical", str(exc)) from exc


def params_from_model(model, source="<model>") -> ExtendedParams:
    """Parameters from a :class:`rwadist.model.WheelModel`'s ``analytical`` section."""
    return params_from_dict(model.analytical, source)


# ---------------------------------------------------------------- harmonics

@dataclass(frozen=True)
class Line:
    """One forcing line of the extended model.

    direction : 'radial_force' | 'radial_torque' | 'axial_force' | 'axial_torque'.
    h : harmonic number.  C : SI per (rad/s)² (kg·m forces, kg·m² torques).
    sense : 'co' | 'counter' | 'planar' (radial directions; ignored for axial ones).
    phase : rad.  angle : direction of a planar load in the x-y plane, rad.
    imbalance : an imbalance line (h = 1, co-rotating) with the tangential −iΩ̇ term.
    law : (A_ref, Ω_ref, p) of a diagnosed ``amplitude_law`` (N or N·m, rad/s, -): the line's
        amplitude is A_ref·(|Ω|/Ω_ref)^p instead of C·Ω² (an imbalance keeps its −iC·Ω̇ term);
        None: C·Ω².
    f_offset : fixed frequency offset, Hz (signed; 0 for a harmonic).  Each component's phase is
        σ·(h·φ + 2π·f_offset·(t − t0)), its whirl rate ν = σ·(hΩ + 2π·f_offset) rad/s and the line's
        frequency |hΩ/2π + f_offset| Hz.  A diagnosed ``sidebands`` effect (depth m, f_mod) is two
        such copies of its carrier, f_offset = ±f_mod with C (and A_ref) times m/2:
        a(1 + m·cos 2πf_mod t) = a + (m/2)a·e^{+i2πf_mod t} + (m/2)a·e^{−i2πf_mod t} per component.
    resonances : ((f_r Hz, ζ, peak_gain), ...) of diagnosed ``fixed_resonance`` effects of role
        ``wheel_mode``: each component's load is multiplied by H(ν/2π) (:func:`resonance_gain`,
        the formula of :func:`rwadist.resonance.resonance` with a signed frequency, i.e. a real
        filter acting on x and y alike) at the component's instantaneous whirl rate ν.
        QUASI-STATIC: exact at constant speed; in a transient the gain follows the speed at once
        (no ringing of that resonance, no lag).
    """

    direction: str
    h: float
    C: float
    sense: str = "co"
    phase: float = 0.0
    angle: float = 0.0
    imbalance: bool = False
    law: tuple | None = None
    f_offset: float = 0.0
    resonances: tuple = ()

    def __post_init__(self):
        if self.direction not in DIRECTIONS:
            raise ValueError(f"Line.direction {self.direction!r} not in {DIRECTIONS}")
        if self.sense not in SENSES:
            raise ValueError(f"Line.sense {self.sense!r} not in {SENSES}")
        if not (math.isfinite(self.h) and self.h > 0):
            raise ValueError(f"Line.h must be finite and > 0, got {self.h!r}")
        if not (math.isfinite(self.C) and self.C >= 0):
            raise ValueError(f"Line.C must be finite and >= 0, got {self.C!r}")
        if self.imbalance and (self.h != 1.0 or self.sense != "co"):
            raise ValueError("an imbalance Line must have h = 1 and sense 'co'")
        if self.law is not None:
            a, w, x = (float(v) for v in self.law)
            if not (math.isfinite(a) and a >= 0 and math.isfinite(w) and w > 0 and math.isfinite(x) and x >= 0):
                raise ValueError(f"Line.law (A_ref, omega_ref, exponent) needs A_ref >= 0, omega_ref > 0, "
                                 f"exponent >= 0, got {self.law!r}")
        if not math.isfinite(self.f_offset):
            raise ValueError(f"Line.f_offset must be finite, got {self.f_offset!r}")
        object.__setattr__(self, "resonances", tuple(tuple(float(v) for v in r) for r in self.resonances))
        for r in self.resonances:
            if len(r) != 3 or not all(math.isfinite(v) and v > 0 for v in r):
                raise ValueError(f"Line.resonances entries (f_r Hz, zeta, peak_gain) must be finite and > 0, "
                                 f"got {r!r}")

    def amplitude(self, omega):
        """Load amplitude at wheel speeds ``omega`` (rad/s): C·Ω², or A_ref·(|Ω|/Ω_ref)^p with a law."""
        w = np.asarray(omega, dtype=float)
        if self.law is None:
            return self.C * w**2
        a, w_ref, x = self.law
        return a * (np.abs(w) / w_ref) ** x

    def nu(self, sigma, omega):
        """Whirl rate (rad/s, signed) of component ``sigma`` at speeds ``omega``: σ(hΩ + 2π f_offset)."""
        return sigma * (self.h * np.asarray(omega, dtype=float) + 2.0 * np.pi * self.f_offset)

    def frequency(self, omega):
        """Line frequency, Hz, at speeds ``omega`` (rad/s): |hΩ/2π + f_offset| (h|Ω|/2π for a harmonic)."""
        w = np.asarray(omega, dtype=float)
        if self.f_offset == 0.0:
            return self.h * np.abs(w) / (2 * np.pi)
        return np.abs(self.h * w / (2 * np.pi) + self.f_offset)

    def gain(self, nu):
        """Product of the line's wheel-mode resonance gains at whirl rates ``nu`` (rad/s, signed)."""
        return resonance_gain(nu, self.resonances)

    def components(self):
        """[(sigma, coefficient)]: load = C·coefficient·amp(t)·e^{i·sigma·(h·φ + 2π f_offset t)}; sigma = ±1."""
        if self.direction in ("axial_force", "axial_torque") or self.sense == "co":
            return [(1, np.exp(1j * self.phase))]
        if self.sense == "counter":
            return [(-1, np.exp(-1j * self.phase))]
        return [(1, 0.5 * np.exp(1j * (self.angle + self.phase))),
                (-1, 0.5 * np.exp(1j * (self.angle - self.phase)))]


def imbalance_lines(p: ExtendedParams, phase_s: float = 0.0, phase_d: float = 0.0) -> list:
    """The static (U_s, radial force) and dynamic (U_d, radial torque) imbalance lines."""
    return [Line("radial_force", 1.0, p.U_s, "co", phase_s, imbalance=True),
            Line("radial_torque", 1.0, p.U_d, "co", phase_d, imbalance=True)]


#: A radial harmonic within this of h = 1 that rotates with the spin is the imbalance (fitted
#: fundamentals come out at 0.99 or 1.01; thesis Table 3.3 lists 0.99).
IMBALANCE_H_TOL = 0.02


def is_imbalance(direction: str, h: float, sense) -> bool:
    """True for the co-rotating radial fundamental, which the imbalances U_s, U_d describe."""
    return (direction in ("radial_force", "radial_torque") and abs(h - 1.0) <= IMBALANCE_H_TOL
            and sense in (None, "co"))


#: |Δh| within which a diagnosed amplitude law belongs to a line (as rwadist.broadband.apply_effects)
LAW_H_TOL = 1e-3


def _effect_number(e, i, key, ok, need):
    """effects[i][key] as a float; ValueError naming ``effects[i].key`` unless finite and ``ok``."""
    v = e.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not ok(v):
        raise ValueError(f"effects[{i}].{key}: must be {need}, got {v!r}")
    return float(v)


def _effect_direction(e, i, key="direction"):
    d = e.get(key)
    if d not in DIRECTIONS:
        raise ValueError(f"effects[{i}].{key}: {d!r} is not one of {', '.join(DIRECTIONS)}")
    return d


def line_effects(effects) -> dict:
    """The time-domain forcing effects of a model file's ``effects`` list (``rwadist diagnose``),
    validated: {'laws': [(direction, h, (A_ref, Ω_ref, p))], 'resonances': [(directions, (f_r, ζ, g))],
    'sidebands': [(direction, h, f_mod Hz, depth)]} in file order.  A ``fixed_resonance`` of role
    ``test_stand`` (a fixture resonance) and a ``cross_coupling`` (load-cell offset) are measurement
    artefacts and are left out; ``missing_harmonic`` is already a harmonic; ``broadband_floor`` and
    ``speed_ripple`` are not line forcing.  ValueError naming ``effects[i].<field>`` on a bad entry."""
    out = {"laws": [], "resonances": [], "sidebands": []}
    if effects is None:
        return out
    if not isinstance(effects, (list, tuple)):
        raise ValueError(f"effects: must be a list, got {type(effects).__name__}")
    pos = "a finite number > 0"
    for i, e in enumerate(effects):
        if not isinstance(e, dict):
            raise ValueError(f"effects[{i}]: must be an object")
        kind = e.get("kind")
        if kind == "amplitude_law":
            d = _effect_direction(e, i)
            h = _effect_number(e, i, "h", lambda v: v > 0, pos)
            law = (_effect_number(e, i, "amplitude_ref", lambda v: v >= 0, "a finite number >= 0"),
                   _effect_number(e, i, "omega_ref_rad_s", lambda v: v > 0, pos),
                   _effect_number(e, i, "exponent", lambda v: v >= 0, "a finite number >= 0"))
            out["laws"].append((d, h, law))
        elif kind == "fixed_resonance":
            role = e.get("role")
            if role not in ("wheel_mode", "test_stand"):
                raise ValueError(f"effects[{i}].role: {role!r} is not 'wheel_mode' or 'test_stand'")
            res = (_effect_number(e, i, "f_Hz", lambda v: v > 0, pos),
                   _effect_number(e, i, "zeta", lambda v: v > 0, pos),
                   _effect_number(e, i, "peak_gain", lambda v: v > 0, pos))
            dirs = e.get("directions")
            dirs = [dirs] if isinstance(dirs, str) else dirs
            if not isinstance(dirs, (list, tuple)) or not dirs or any(d not in DIRECTIONS for d in dirs):
                raise ValueError(f"effects[{i}].directions: {e.get('directions')!r} must be a non-empty list of "
                                 f"{', '.join(DIRECTIONS)}")
            if role == "wheel_mode":
                out["resonances"].append((tuple(dirs), res))
        elif kind == "sidebands":
            d = _effect_direction(e, i)
            out["sidebands"].append((d, _effect_number(e, i, "h", lambda v: v > 0, pos),
                                     _effect_number(e, i, "f_mod_Hz", lambda v: v > 0, pos),
                                     _effect_number(e, i, "depth", lambda v: v >= 0, "a finite number >= 0")))
    return out


def apply_line_effects(lines, effects) -> list:
    """``lines`` with the forcing effects of :func:`line_effects` (a model file's ``effects`` list):

    1. ``amplitude_law`` -> :attr:`Line.law` of the lines of its direction with |Δh| < LAW_H_TOL;
    2. ``fixed_resonance`` (role ``wheel_mode``) -> appended to :attr:`Line.resonances` of every line of
       its directions (quasi-static gain, see :class:`Line`);
    3. ``sidebands`` -> for each matching line (as 1; carriers only, in line order) two copies appended
       after all lines, f_offset = +f_mod then −f_mod, C and A_ref times depth/2, everything else (phase,
       sense, imbalance with its tangential term, resonances) the carrier's.  The FMU runtime builds the
       same list in the same order (its random phases are drawn over it)."""
    eff = line_effects(effects)
    out = list(lines)
    for d, h, law in eff["laws"]:
        out = [replace(ln, law=law) if ln.direction == d and abs(ln.h - h) < LAW_H_TOL else ln for ln in out]
    for dirs, res in eff["resonances"]:
        out = [replace(ln, resonances=ln.resonances + (res,)) if ln.direction in dirs else ln for ln in out]
    carriers = list(out)
    for d, h, f_mod, m in eff["sidebands"]:
        for ln in carriers:
            if ln.direction == d and abs(ln.h - h) < LAW_H_TOL:
                law = None if ln.law is None else (ln.law[0] * 0.5 * m, ln.law[1], ln.law[2])
                for off in (f_mod, -f_mod):
                    out.append(replace(ln, C=ln.C * 0.5 * m, law=law, f_offset=ln.f_offset + off))
    return out


def lines_from_model(model, p: ExtendedParams, senses: dict | None = None, effects: bool = True) -> list:
    """Lines of a :class:`~rwadist.model.WheelModel`: the imbalances from ``p`` replace the
    co-rotating radial fundamentals (|h − 1| <= IMBALANCE_H_TOL; thesis Eqs. 4.48–4.49); every
    other empirical harmonic -- a counter-rotating fundamental included -- becomes a line with
    sense ``senses.get((direction, h))``, else the harmonic's own ``sense`` from the model file,
    else 'co'.  effects : apply the model's diagnosed effects (``rwadist diagnose``) with
    :func:`apply_line_effects`: amplitude laws, wheel-mode resonances (quasi-static gains) and
    sidebands (extra lines at a fixed frequency offset, appended after the harmonics)."""
    senses = senses or {}
    out = imbalance_lines(p)
    for d in DIRECTIONS:
        for hm in model.harmonics(d):
            sense = senses.get((d, float(hm.h))) or getattr(hm, "sense", None)
            if is_imbalance(d, hm.h, sense):
                continue
            out.append(Line(d, float(hm.h), float(hm.C), sense or "co"))
    if effects:
        out = apply_line_effects(out, getattr(model, "effects", None))
    return out


# ---------------------------------------------------------------- modes

def _omega_array(omega):
    w = np.asarray(omega, dtype=float)
    if not np.all(np.isfinite(w)):
        raise ValueError("wheel speed omega contains NaN or inf")
    return w


def whirl_frequencies(p: ExtendedParams, omega) -> dict:
    """Undamped mode frequencies (Hz) at wheel speeds ``omega`` (rad/s), closed form.

    Forward/backward are relative to the spin: f± = sqrt((a|Ω|/2)² + f0²) ± a|Ω|/2 (a = I_zz/I_rr).
    """
    w = np.abs(_omega_array(omega))
    half = 0.5 * p.inertia_ratio * w
    root = np.sqrt(half**2 + p.omega_rock**2)
    ones = np.ones_like(w)
    two_pi = 2 * np.pi
    return {"radial_translation": ones * p.omega_r / two_pi,
            "rocking_forward": (root + half) / two_pi,
            "rocking_backward": (root - half) / two_pi,
            "axial_translation": ones * p.omega_z / two_pi}


def _quad_roots(m, c, k):
    """Both roots of m λ² + c λ + k = 0 (c may be complex, arrays), stable form."""
    c = np.asarray(c, dtype=complex)
    disc = np.sqrt(c * c - 4 * m * k + 0j)
    sgn = np.where((np.conj(c) * disc).real >= 0, 1.0, -1.0)
    q = -0.5 * (c + sgn * disc)
    return q / m, k / q


def damped_modes(p: ExtendedParams, omega) -> dict:
    """Damped eigenvalues s (1/s) of each mode at speeds ``omega`` (rad/s), complex coordinates.

    Returns mode -> complex array; the whirl frequency is |Im s|/2π Hz, the damping ratio
    −Re s/|s|.  For the rocking mode the root whirling with the spin is 'rocking_forward'.
    """
    w = _omega_array(omega)
    r1, r2 = _quad_roots(p.mass, p.c_r + 0 * w, p.k_r)
    z1, z2 = _quad_roots(p.mass, p.c_z + 0 * w, p.k_z)
    q1, q2 = _quad_roots(p.I_rr, p.c_rock - 1j * p.I_zz * w, p.k_rock)
    # a root e^{st} whirls with the spin when sign(Im s) == sign(Ω)  (Ω = 0: take Im s > 0)
    sgn = np.where(w >= 0, 1.0, -1.0)
    fwd_is_1 = np.sign(q1.imag) * sgn >= 0
    return {"radial_translation": np.where(r1.imag >= 0, r1, r2),
            "rocking_forward": np.where(fwd_is_1, q1, q2),
            "rocking_backward": np.where(fwd_is_1, q2, q1),
            "axial_translation": np.where(z1.imag >= 0, z1, z2)}


def campbell(p: ExtendedParams, speeds_rad_s) -> dict:
    """Campbell table: 'speed_rad_s', 'speed_rpm' and '<mode>_Hz' (undamped) columns."""
    w = _omega_array(np.atleast_1d(speeds_rad_s))
    out = {"speed_rad_s": w, "speed_rpm": w * RAD_S_TO_RPM}
    out.update({f"{m}_Hz": v for m, v in whirl_frequencies(p, w).items()})
    return out


def _excites(line: Line, mode: str) -> bool:
    """Whether a line's load can excite a mode in this model (sense and direction)."""
    if mode == "radial_translation":
        return line.direction == "radial_force"
    if mode == "axial_translation":
        return line.direction == "axial_force"
    if line.direction != "radial_torque":
        return False
    return line.sense == "planar" or (line.sense == "co") == (mode == "rocking_forward")


def crossing_closed_form(p: ExtendedParams, h: float, mode: str) -> float:
    """|Ω| (rad/s) where h·|Ω| equals the mode frequency, closed form; nan if never."""
    a, w0 = p.inertia_ratio, p.omega_rock
    if mode == "radial_translation":
        return p.omega_r / h
    if mode == "axial_translation":
        return p.omega_z / h
    if mode == "rocking_backward":        # h²Ω² + a h Ω² = ω0²
        return w0 / math.sqrt(h * h + a * h)
    if mode == "rocking_forward":         # h²Ω² − a h Ω² = ω0², only for h > a
        return w0 / math.sqrt(h * h - a * h) if h > a else float("nan")
    raise ValueError(f"unknown mode {mode!r}")


def crossings(p: ExtendedParams, lines, speed_range) -> list:
    """Speeds where each line h·|Ω| meets each mode, by root finding (brentq) in ``speed_range``
    = (lo, hi) rad/s of |Ω|, with the closed form alongside.

    ``lines``: :class:`Line` objects or bare harmonic numbers (sideband lines, with a frequency
    offset, are skipped).  Returns a list of dicts with
    keys h, direction, sense, mode, speed_rad_s, speed_rpm, closed_form_rad_s, f_Hz, excited
    (whether the line's direction and sense can drive that mode in this model).
    """
    lo, hi = float(speed_range[0]), float(speed_range[1])
    if not (0 <= lo < hi and math.isfinite(hi)):
        raise ValueError(f"speed_range must be 0 <= lo < hi, got {speed_range!r}")
    grid = np.linspace(lo, hi, 2001)
    out = []
    for ln in lines:
        line = ln if isinstance(ln, Line) else Line("radial_force", float(ln), 0.0)
        if line.f_offset != 0.0:      # a sideband: not a harmonic of the speed, no h·|Ω| crossing
            continue
        for mode in MODES:
            def g(w, mode=mode):
                return line.h * w / (2 * np.pi) - whirl_frequencies(p, w)[mode]
            gv = g(grid)
            idx = np.nonzero(np.sign(gv[:-1]) * np.sign(gv[1:]) <= 0)[0]
            seen = []
            for i in idx:
                if gv[i] == 0 and gv[i + 1] == 0:
                    continue
                w = optimize.brentq(g, grid[i], grid[i + 1], xtol=1e-12, rtol=1e-14)
                if any(abs(w - s) < 1e-9 for s in seen):
                    continue
                seen.append(w)
                out.append({"h": line.h, "direction": line.direction, "sense": line.sense, "mode": mode,
                            "speed_rad_s": w, "speed_rpm": w * RAD_S_TO_RPM,
                            "closed_form_rad_s": crossing_closed_form(p, line.h, mode),
                            "f_Hz": line.h * w / (2 * np.pi), "excited": _excites(line, mode)})
    return out


# ---------------------------------------------------------------- steady state

def _subsystem(p: ExtendedParams, direction: str):
    """(inertia, damping, stiffness, gyro) of the subsystem a direction loads; None for Tz."""
    if direction == "radial_force":
        return p.mass, p.c_r, p.k_r, 0.0
    if direction == "radial_torque":
        return p.I_rr, p.c_rock, p.k_rock, p.I_zz
    if direction == "axial_force":
        return p.mass, p.c_z, p.k_z, 0.0
    return None


def transmissibility(p: ExtendedParams, direction: str, nu, omega):
    """Interface load per internal load for a complex-coordinate load e^{iνt} (ν rad/s, signed)
    at wheel speed ``omega``: (k + icν)/(k − mν² + I_zz Ω ν + icν) (gyro term for rocking only)."""
    sub = _subsystem(p, direction)
    if sub is None:
        return np.ones(np.broadcast(nu, omega).shape, dtype=complex)
    m, c, k, gyro = sub
    nu = np.asarray(nu, dtype=float)
    return (k + 1j * c * nu) / (k - m * nu**2 + gyro * omega * nu + 1j * c * nu)


def steady_lines(p: ExtendedParams, lines, omega) -> tuple:
    """Steady-state lines at constant wheel speeds ``omega`` (rad/s, signed), closed form.

    Returns (f_hz (n_speeds, n_lines), amplitude (n_speeds, n_lines, 6) complex): each channel
    (Fx, Fy, Fz, Tx, Ty, Tz) of each line is Re(A e^{i 2π f (t − t0)}), N or N·m.  f = h|Ω|/2π for a
    harmonic, |hΩ/2π + f_offset| for a line with a frequency offset (a sideband, :class:`Line`); a
    line's wheel-mode resonances multiply each component by H at its whirl rate.
    """
    w = _omega_array(np.atleast_1d(omega))[:, None]
    lines = list(lines)
    n_l = len(lines)
    amp = np.zeros((w.shape[0], n_l, 6), dtype=complex)
    f_hz = np.zeros((w.shape[0], n_l))
    for j, ln in enumerate(lines):
        wj = w[:, 0]
        f_hz[:, j] = ln.frequency(wj)
        load0 = ln.amplitude(wj)
        for sigma, coef in ln.components():
            nu = ln.nu(sigma, wj)
            resp = transmissibility(p, ln.direction, nu, wj) * coef * load0
            if ln.resonances:
                resp = resp * ln.gain(nu)
            _add_to_channels(amp[:, j], ln.direction, p.height, resp, nu)
    return f_hz, amp


def _add_to_channels(out, direction, height, resp, nu):
    """Add the interface-load phasors of complex-coordinate load responses ``resp`` (whirl rates ``nu``,
    rad/s signed; any shape ...) of a ``direction`` to ``out`` (..., 6): a component resp·e^{iνt} is the
    channel pair Re/Im at frequency |ν|."""
    pos = nu >= 0
    a_re = np.where(pos, resp, np.conj(resp))              # Re(resp e^{iνt}) at e^{i|ν|t}
    a_im = np.where(pos, -1j * resp, 1j * np.conj(resp))   # Im(resp e^{iνt})
    if direction == "radial_force":
        out[..., 0] += a_re
        out[..., 1] += a_im
        # T_int += i·height·F  ->  Tx += −height·Fy, Ty += height·Fx
        out[..., 3] += -height * a_im
        out[..., 4] += height * a_re
    elif direction == "radial_torque":
        out[..., 3] += a_re
        out[..., 4] += a_im
    elif direction == "axial_force":
        out[..., 2] += a_re
    else:
        out[..., 5] += a_re


def steady_rms(p: ExtendedParams, lines, omega, f_max: float | None = None) -> np.ndarray:
    """RMS (N or N·m) per channel at speeds ``omega``: sqrt(Σ|A|²/2) over lines at or below
    ``f_max`` Hz (lines assumed at distinct frequencies).  Shape (n_speeds, 6)."""
    f, a = steady_lines(p, lines, omega)
    keep = np.ones_like(f, dtype=bool) if f_max is None else f <= f_max
    return np.sqrt(np.sum(np.abs(a) ** 2 * keep[..., None] / 2.0, axis=1))


# ---------------------------------------------------------------- speed ripple

@dataclass(frozen=True)
class Ripple:
    """A periodic wheel-speed ripple (a diagnosed ``speed_ripple``): Ω(t) = Ω0 + ΔΩ·sin(2π f_r t) with
    ΔΩ(Ω0) = delta_omega·(|Ω0|/omega_ref)^exponent.

    f_hz : ripple frequency f_r, Hz (> 0).  delta_omega : ΔΩ at omega_ref, rad/s (>= 0).  omega_ref : rad/s
    (> 0).  exponent : speed exponent q (>= 0; 0 = the same ΔΩ at every speed, e.g. a torque ripple at a
    fixed frequency; 1 = a fixed fraction of the speed)."""

    f_hz: float
    delta_omega: float
    omega_ref: float = 1.0
    exponent: float = 0.0

    def __post_init__(self):
        for name, ok, need in (("f_hz", lambda v: v > 0, "> 0"), ("delta_omega", lambda v: v >= 0, ">= 0"),
                               ("omega_ref", lambda v: v > 0, "> 0"), ("exponent", lambda v: v >= 0, ">= 0")):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
                    or not math.isfinite(v) or not ok(v):
                raise ValueError(f"Ripple.{name} must be a finite number {need}, got {v!r}")

    def delta(self, omega):
        """ΔΩ (rad/s) at mean speeds ``omega`` (rad/s)."""
        return self.delta_omega * (np.abs(np.asarray(omega, dtype=float)) / self.omega_ref) ** self.exponent


def ripple_from_effects(effects):
    """The :class:`Ripple` of a model file's ``effects`` list (its ``speed_ripple`` entry: f_ripple_Hz,
    delta_omega_rad_s, omega_ref_rad_s, speed_exponent (default 0)), or None.  ValueError naming
    ``effects[i].<field>`` on a bad entry, and on a second ``speed_ripple`` (one per wheel)."""
    if not effects:
        return None
    if not isinstance(effects, (list, tuple)):
        raise ValueError(f"effects: must be a list, got {type(effects).__name__}")
    out, first = None, None
    for i, e in enumerate(effects):
        if not isinstance(e, dict) or e.get("kind") != "speed_ripple":
            continue
        if out is not None:
            raise ValueError(f"effects[{i}].kind: a second speed_ripple (the first is effects[{first}]); "
                             "one speed ripple per wheel is supported")
        q = e.get("speed_exponent", 0.0)
        out = Ripple(_effect_number(e, i, "f_ripple_Hz", lambda v: v > 0, "a finite number > 0"),
                     _effect_number(e, i, "delta_omega_rad_s", lambda v: v >= 0, "a finite number >= 0"),
                     _effect_number(e, i, "omega_ref_rad_s", lambda v: v > 0, "a finite number > 0"),
                     _effect_number({"speed_exponent": q}, i, "speed_exponent", lambda v: v >= 0,
                                    "a finite number >= 0"))
        first = i
    return out


def ripple_k_max(beta_max: float, p_max: float = 2.0) -> int:
    """Highest sideband order K kept for a ripple of largest phase-modulation index ``beta_max`` (rad) and
    largest amplitude exponent ``p_max``: ceil(1.1β + 4β^(1/3) + p + 4) (the Bessel tail J_k(β) beyond
    ≈ β + 4β^(1/3) is below 1e-8 of the carrier; (1 + ε sin θ)^p adds up to p orders)."""
    b = abs(float(beta_max))
    return int(np.ceil(1.1 * b + 4.0 * b ** (1.0 / 3.0) + abs(float(p_max)) + 4))


def _ripple_grid(k_max: int):
    n = 1 << int(np.ceil(np.log2(4 * (2 * k_max + 1))))
    return n, 2 * np.pi * np.arange(n) / n


def ripple_coefficients(beta, eps, p=2.0, k_max: int | None = None):
    """Complex Fourier coefficients c_k of g(θ) = |1 + ε sin θ|^p · exp(−jβ cos θ) = Σ_k c_k e^{jkθ}.

    With Ω(t) = Ω0 + ΔΩ sin θ, θ = 2π f_r t, the rotor angle is φ = Ω0 t − (ΔΩ/2πf_r) cos θ, so a co-rotating
    (or axial) line of harmonic h and amplitude a(Ω) ∝ |Ω|^p becomes a(Ω0)·g(θ)·e^{jhΩ0 t} with β = h·ΔΩ/(2πf_r)
    and ε = ΔΩ/Ω0 -- SIGNED: for Ω0 < 0, |Ω(t)| = |Ω0|(1 − (ΔΩ/|Ω0|) sin θ).  A counter-rotating component
    e^{−jhφ} has β → −β.  Pure phase modulation (ε = 0): c_k = (−j)^k J_k(β); Σ_k |c_k|² is the mean of
    |1 + ε sin θ|^{2p} (Parseval).  The modulus |·| makes it exact through a speed reversal (|ε| > 1).
    By an FFT over one ripple period.

    beta, eps : broadcastable arrays (shape S); p : scalar or broadcastable.  k_max : highest order
    (default :func:`ripple_k_max` of the largest |β| and p).  Returns (k (2K+1,), c (S + (2K+1,)) complex)."""
    beta, eps, p = np.broadcast_arrays(np.asarray(beta, float), np.asarray(eps, float), np.asarray(p, float))
    if k_max is None:
        k_max = ripple_k_max(float(np.max(np.abs(beta))) if beta.size else 0.0,
                             float(np.max(np.abs(p))) if p.size else 2.0)
    n, th = _ripple_grid(k_max)
    g = np.abs(1.0 + eps[..., None] * np.sin(th)) ** p[..., None] * np.exp(-1j * beta[..., None] * np.cos(th))
    c = np.fft.fft(g, axis=-1) / n
    k = np.arange(-k_max, k_max + 1)
    return k, c[..., k % n]


def _line_exponent(ln: Line) -> float:
    return 2.0 if ln.law is None else float(ln.law[2])


def ripple_order(lines, omega, ripple: Ripple, tol: float = 1e-6) -> int:
    """Sideband order K needed for ``lines`` under ``ripple`` at mean speeds ``omega`` (rad/s): at most
    :func:`ripple_k_max` of the largest β = h·ΔΩ/(2πf_r) and exponent, trimmed to the highest order whose
    coefficient reaches ``tol`` × the line's RMS coefficient sqrt(Σ|c_k|²) for some line and speed (the
    orders dropped carry < tol² of a line's power each).  For an amplitude law with a non-integer exponent
    the amplitude term |1 + ε sin θ|^p has every order, decaying as ρ^k, ρ = (1 − √(1 − ε²))/|ε|; the
    p + 4 orders the bound allows for it lose < 1e-8 of the power for |ε| <= 0.5 (mean speed at least twice
    the ripple amplitude), more as |ε| -> 1."""
    w = np.atleast_1d(_omega_array(omega))
    lines = list(lines)
    if not lines or w.size == 0:
        return 0
    dW = ripple.delta(w)
    hs = np.array([ln.h for ln in lines])
    ps = np.array([_line_exponent(ln) for ln in lines])
    k_max = ripple_k_max(float(hs.max() * dW.max() / (2 * np.pi * ripple.f_hz)), float(ps.max()))
    eps = dW / np.where(w == 0.0, 1.0, w)
    eps = np.where(w == 0.0, np.where(dW > 0, 1e6, 0.0), eps)
    k, c = ripple_coefficients(hs[:, None] * dW[None, :] / (2 * np.pi * ripple.f_hz), eps[None, :], ps[:, None],
                               k_max)
    a = np.abs(c)
    rel = a / np.maximum(np.sqrt(np.sum(a**2, axis=-1, keepdims=True)), 1e-300)
    big = np.nonzero(np.max(rel.reshape(-1, k.size), axis=0) >= tol)[0]
    return int(np.max(np.abs(k[big]))) if big.size else 0


def ripple_lines(p: ExtendedParams, lines, omega, ripple: Ripple, k_max: int | None = None) -> tuple:
    """Steady-state lines under a periodic speed ripple (mean speeds ``omega`` rad/s, signed), closed form.

    Each component σ (whirl sense, ±1) of each line, load = coef·a(Ω(t))·e^{jσ(hφ + 2π f_offset t)}, is
    expanded over the ripple period: a(Ω0 + ΔΩ sin θ)·exp(−jσβ cos θ) = Σ_k d_k e^{jkθ}, β = h·ΔΩ/(2πf_r),
    d_k by an FFT of the line's own amplitude law (:meth:`Line.amplitude`: C·Ω² or the diagnosed law; this is
    a(Ω0)·:func:`ripple_coefficients` with ε = ΔΩ/Ω0 and stays finite at Ω0 = 0).  Term k whirls at
    ν = σ(hΩ0 + 2πf_offset) + 2πk f_r = σ(hΩ0 + 2π(f_offset + m f_r)), m = σk: it is the line's sideband of
    order m (for a planar line the two senses of one m land at the same frequency and are coherent), passed
    through the rotor's modes and the line's wheel-mode resonances AT ITS OWN whirl rate ν, exactly as
    :func:`steady_lines` does for a line with f_offset + m·f_r.

    Phase convention: θ = 0 and the rotor's mean angle Ω0·t is 0 at t0 (the rippled angle there is
    φ(t0) = −ΔΩ/(2πf_r)).  Neglected (first order in small quantities, stated): the imbalance's tangential
    force −jC·Ω̇ (relative size ΔΩ·2πf_r/Ω0²), the modulation of the rocking mode's gyroscopic stiffness by
    the ripple (the modes are evaluated at Ω0), and the wheel-mode resonance gains' variation with the
    instantaneous speed.  With ΔΩ = 0 the order-0 lines are :func:`steady_lines` (test).  Measured against the
    FMU's time-domain ripple (tests/test_fmu_effects.py): force channels within 1e-5 of the largest line;
    the rocking channels Tx, Ty off by up to ~10 % of their largest line at sidebands near a rocking whirl
    (the gyroscopic modulation is not small there).

    k_max : highest order (default :func:`ripple_order`).  Returns (m (M,), f_hz (S, L, M),
    amplitude (S, L, M, 6) complex): channel = Re(A e^{i2πf(t − t0)}), N or N·m."""
    w = np.atleast_1d(_omega_array(omega))
    lines = list(lines)
    K = ripple_order(lines, w, ripple) if k_max is None else int(k_max)
    m = np.arange(-K, K + 1)
    n, th = _ripple_grid(K)
    dW = ripple.delta(w)
    sin_t, cos_t = np.sin(th), np.cos(th)
    S, L, M = w.size, len(lines), m.size
    amp = np.zeros((S, L, M, 6), dtype=complex)
    f_hz = np.zeros((S, L, M))
    w2 = w[:, None]
    for j, ln in enumerate(lines):
        off = ln.f_offset + m[None, :] * ripple.f_hz                         # (1, M) Hz
        f_hz[:, j] = np.abs(ln.h * w2 / (2 * np.pi) + off)
        a_th = ln.amplitude(w2 + dW[:, None] * sin_t[None, :])              # (S, n)
        beta = ln.h * dW / (2 * np.pi * ripple.f_hz)
        for sigma, coef in ln.components():
            d = np.fft.fft(a_th * np.exp(-1j * sigma * beta[:, None] * cos_t[None, :]), axis=-1) / n
            dk = d[:, (sigma * m) % n]                                          # (S, M): order m = σk
            nu = sigma * (ln.h * w2 + 2 * np.pi * off)
            resp = transmissibility(p, ln.direction, nu, w2) * coef * dk
            if ln.resonances:
                resp = resp * ln.gain(nu)
            _add_to_channels(amp[:, j], ln.direction, p.height, resp, nu)
    return m, f_hz, amp


# ---------------------------------------------------------------- time domain

def _check_profile(t, omega, max_accel):
    t = np.asarray(t, dtype=float)
    w = np.asarray(omega, dtype=float)
    if t.ndim != 1 or t.shape != w.shape or t.size < 2:
        raise ValueError(f"t and omega must be 1-D of equal length >= 2, got {t.shape} and {w.shape}")
    bad = ~np.isfinite(w)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"speed profile omega is not finite at sample {i} (t = {t[i]!r} s): {w[i]!r}")
    if not np.all(np.isfinite(t)):
        raise ValueError("time vector t contains NaN or inf")
    dt = np.diff(t)
    T = (t[-1] - t[0]) / (t.size - 1)
    if T <= 0 or np.max(np.abs(dt - T)) > 1e-6 * T:
        raise ValueError("time vector t must be uniformly sampled and increasing")
    acc = np.abs(np.diff(w)) / T
    if acc.max() > max_accel:
        i = int(np.argmax(acc))
        raise ValueError(f"speed profile jumps between samples {i} and {i + 1} (t = {t[i]:.6g} s): "
                         f"omega {w[i]:.6g} -> {w[i + 1]:.6g} rad/s, |dΩ/dt| = {acc[i]:.3g} rad/s² "
                         f"> max_accel = {max_accel:.3g}")
    return t, w, T


def _small_z_terms(z):
    """Series of ∫0^1 e^{zu} du and ∫0^1 u e^{zu} du for |z| < 1e-3 (error < 1e-13)."""
    e0 = 1 + z * (1 / 2 + z * (1 / 6 + z * (1 / 24 + z / 120)))
    e1 = 1 / 2 + z * (1 / 3 + z * (1 / 8 + z * (1 / 30 + z / 144)))
    return e0, e1


def _forcing_terms(lam, lines_comp, phi_tau, T):
    """Input integral over each sample interval for one mode with eigenvalue ``lam`` (scalar, or one
    per interval) of the loads ``lines_comp`` = [(σh, ω_off, coef, amplitude (n+1))]; ``phi_tau`` =
    (rotor angle φ, time since t0) at the samples.

    For a load coef·(a_n + Δa·τ/T)·e^{i(σh(φ_n + Δφ_n τ/T) + ω_off(t_n + τ))} the integral
    ∫0^T e^{λ(T−τ)} load dτ = T·coef·(a_n·X S0 E0(z) + Δa·X S0 E1(z)), z = i(σhΔφ_n + ω_off T) − λT,
    X = e^{λT}, S0 = e^{i(σhφ_n + ω_off t_n)}, E0 = (e^z − 1)/z, E1 = (e^z − E0)/z.  Since X S0 e^z = S1:
    X S0 E0 = (S1 − X S0)/z and X S0 E1 = (S1 − X S0 E0)/z; a series replaces them where |z| < 1e-3.
    """
    phi, tau = phi_tau
    n = phi.size - 1
    lams = lam if isinstance(lam, tuple) else (lam,)
    accs = [np.zeros(n, dtype=complex) for _ in lams]
    Xs = [np.exp(lm * T) for lm in lams]
    dphi = np.diff(phi)
    for sh, woff, coef, a in lines_comp:
        if woff == 0.0:
            S = np.exp(1j * sh * phi)
            iw = 1j * sh * dphi
        else:
            S = np.exp(1j * (sh * phi + woff * tau))
            iw = 1j * (sh * dphi + woff * T)
        S0, S1 = S[:-1], S[1:]
        a0 = a[:-1]
        da = a[1:] - a0
        for lm, X, acc in zip(lams, Xs, accs):
            z = iw - lm * T
            XS0 = X * S0
            small = np.abs(z) < 1e-3
            if small.any():
                zb = np.where(small, 1.0, z)
            else:
                zb = z
            t0 = (S1 - XS0) / zb
            t1 = (S1 - t0) / zb
            if small.any():
                e0, e1 = _small_z_terms(z[small])
                t0[small] = XS0[small] * e0
                t1[small] = XS0[small] * e1
            acc += (T * coef) * (a0 * t0 + da * t1)
    return accs if isinstance(lam, tuple) else accs[0]


def _modal_lti(m, c, k, comps, phi_tau, T, x0):
    """Constant-coefficient subsystem m q̈ + c q̇ + k q = load, exact per interval; lfilter on modes.

    Returns (q, qdot) at every sample (n+1)."""
    l1, l2 = _quad_roots(m, c, k)
    l1, l2 = complex(l1), complex(l2)
    phi = phi_tau[0]
    q = np.zeros(phi.size, dtype=complex)
    qd = np.zeros(phi.size, dtype=complex)
    # modal coordinates: q = η1 + η2, q̇ = λ1 η1 + λ2 η2; η̇_j = λ_j η_j + load/(m(λ_j − λ_k))
    q0, qd0 = x0
    eta0 = ((qd0 - l2 * q0) / (l1 - l2), (l1 * q0 - qd0) / (l1 - l2))
    ws = _forcing_terms((l1, l2), comps, phi_tau, T)
    for lam, other, e0, w in ((l1, l2, eta0[0], ws[0]), (l2, l1, eta0[1], ws[1])):
        w = w / (m * (lam - other))
        pole = np.exp(lam * T)
        eta = np.empty(phi.size, dtype=complex)
        eta[0] = e0
        eta[1:], _ = signal.lfilter([1.0], [1.0, -pole], w, zi=[pole * e0])
        q += eta
        qd += lam * eta
    return q, qd


def _affine_scan(P, g, x0, block=256):
    """x_{n+1} = P_n x_n + g_n for 2×2 complex P (n,2,2), g (n,2); returns x (n+1, 2).

    Blocked Hillis–Steele scan: log2(block) vectorised passes, then a loop over blocks."""
    n = g.shape[0]
    nb = -(-n // block)
    pad = nb * block - n
    if pad:
        P = np.concatenate([P, np.broadcast_to(np.eye(2, dtype=complex), (pad, 2, 2))])
        g = np.concatenate([g, np.zeros((pad, 2), dtype=complex)])
    a, b = P[:, 0, 0].reshape(nb, block).copy(), P[:, 0, 1].reshape(nb, block).copy()
    c, d = P[:, 1, 0].reshape(nb, block).copy(), P[:, 1, 1].reshape(nb, block).copy()
    u, v = g[:, 0].reshape(nb, block).copy(), g[:, 1].reshape(nb, block).copy()
    s = 1
    while s < block:
        # (P_i, g_i) <- (P_i P_{i-s}, P_i g_{i-s} + g_i) for i >= s
        A, B, C, D, U, V = (x[:, :-s] for x in (a, b, c, d, u, v))
        a2, b2, c2, d2, u2, v2 = (x[:, s:] for x in (a, b, c, d, u, v))
        na, nb_, nc, nd = a2 * A + b2 * C, a2 * B + b2 * D, c2 * A + d2 * C, c2 * B + d2 * D
        nu, nv = a2 * U + b2 * V + u2, c2 * U + d2 * V + v2
        a[:, s:], b[:, s:], c[:, s:], d[:, s:], u[:, s:], v[:, s:] = na, nb_, nc, nd, nu, nv
        s *= 2
    x = np.empty((nb * block + 1, 2), dtype=complex)
    x[0] = x0
    cur = np.asarray(x0, dtype=complex)
    for i in range(nb):
        sl = slice(i * block + 1, (i + 1) * block + 1)
        x[sl, 0] = a[i] * cur[0] + b[i] * cur[1] + u[i]
        x[sl, 1] = c[i] * cur[0] + d[i] * cur[1] + v[i]
        cur = x[(i + 1) * block]
    return x[: n + 1]


def _rocking_ltv(p, comps, phi_tau, omega_mid, T, x0):
    """Rocking with speed-dependent gyroscopic term: exact transition per interval at the
    interval's mean speed, exact exponential-times-linear forcing, affine scan."""
    l1, l2 = _quad_roots(p.I_rr, p.c_rock - 1j * p.I_zz * omega_mid, p.k_rock)
    e1, e2 = np.exp(l1 * T), np.exp(l2 * T)
    dl = l1 - l2
    # A = [[0, 1], [−k/I, λ1+λ2]];  P_j = (A − λ_k I)/(λ_j − λ_k); Φ = e1 P_1 + e2 P_2
    k_over_i = p.k_rock / p.I_rr
    P = np.empty((phi_tau[0].size - 1, 2, 2), dtype=complex)
    P[:, 0, 0] = (e1 * (-l2) - e2 * (-l1)) / dl
    P[:, 0, 1] = (e1 - e2) / dl
    P[:, 1, 0] = (-k_over_i) * (e1 - e2) / dl
    P[:, 1, 1] = (e1 * l1 - e2 * l2) / dl
    # P_j B = [1, λ_j]/(I (λ_j − λ_k))
    w1, w2 = _forcing_terms((l1, l2), comps, phi_tau, T)
    w1 = w1 / (p.I_rr * dl)
    w2 = w2 / (-p.I_rr * dl)
    g = np.stack([w1 + w2, l1 * w1 + l2 * w2], axis=1)
    x = _affine_scan(P, g, x0)
    return x[:, 0], x[:, 1]


def _steady_state_init(p, direction, comps_c, omega0):
    """(q, q̇) at t0 of the steady solution at constant speed omega0 for complex loads."""
    sub = _subsystem(p, direction)
    m, c, k, gyro = sub
    q = qd = 0j
    for sh, woff, coef, amp0 in comps_c:
        nu = sh * omega0 + woff
        G = 1.0 / (k - m * nu**2 + gyro * omega0 * nu + 1j * c * nu)
        q += G * coef * amp0
        qd += 1j * nu * G * coef * amp0
    return q, qd


def simulate_time(p: ExtendedParams, lines, t, omega, *, seed=None, phases=None, start="rest",
                  max_accel: float = DEFAULT_MAX_ACCEL) -> np.ndarray:
    """Interface forces and torques (n_t, 6: Fx, Fy, Fz, Tx, Ty, Tz; N, N·m) for a speed profile.

    t : uniform sample times, s.  omega : wheel speed at each sample, rad/s (signed; may pass
    through zero).  Rotor angle φ = cumulative trapezoid of Ω from t[0] (φ(t0) = 0); line phases
    h·φ (+ 2π f_offset (t − t0) for a sideband line); imbalance lines add the tangential −iΩ̇ term
    (Ω̇ by central differences).  A line's wheel-mode resonances multiply each component's amplitude
    by H at the sample's whirl rate (quasi-static: exact at constant speed, no ringing in transients).
    seed : draw every line's phase uniformly (overrides ``phases``; sideband lines get their own
    draws: the same spectrum as the amplitude modulation, whose exact phase relation to the
    carrier holds with the lines' own phases); phases : one per line, rad
    (default: each Line's own phase).  start : 'rest' (all states zero) or 'steady' (the closed-form
    steady state at Ω(t0)).  max_accel : |dΩ/dt| above which a step counts as a jump, rad/s².

    Method: the modes are linear; over each sample interval the load of a line is exactly
    (amplitude linear in time) × e^{i(σhΔφ + ω_off T) τ/T}, and its integral against the mode's exponentials is
    taken in closed form; translation and axial modes (fixed coefficients) run as two complex
    first-order recursions each through scipy.signal.lfilter; the rocking mode's transition matrix
    is the exact exponential at the interval's mean speed and the time-varying recursion runs as a
    blocked associative scan.  At constant speed the result is exact (steady state = closed form to
    rounding); with changing speed the per-interval errors are O(a·|dΩ/dt|·T²) (frozen speed) and
    O(T³) in amplitude.
    """
    t, w, T = _check_profile(t, omega, max_accel)
    if start not in ("rest", "steady"):
        raise ValueError(f"start must be 'rest' or 'steady', got {start!r}")
    lines = list(lines)
    if seed is not None:
        ph = np.random.default_rng(seed).uniform(0, 2 * np.pi, len(lines))
    elif phases is not None:
        ph = np.asarray(phases, dtype=float)
        if ph.shape != (len(lines),):
            raise ValueError(f"phases must have one value per line ({len(lines)}), got shape {ph.shape}")
    else:
        ph = np.array([ln.phase for ln in lines])
    lines = [replace(ln, phase=float(q)) for ln, q in zip(lines, ph)]

    phi = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * T)])
    tau = t - t[0]
    wdot = np.gradient(w, T)
    out = np.zeros((t.size, 6))
    groups = {d: [] for d in DIRECTIONS}
    for ln in lines:
        amp = ln.amplitude(w) - 1j * ln.C * wdot if ln.imbalance else ln.amplitude(w)
        for sigma, coef in ln.components():
            # quasi-static wheel-mode resonance: the gain at each sample's whirl rate
            a = amp * ln.gain(ln.nu(sigma, w)) if ln.resonances else amp
            groups[ln.direction].append((sigma * ln.h, sigma * 2.0 * np.pi * ln.f_offset, coef, a))

    # Tz: axial torque lines pass straight through
    for sh, woff, coef, amp in groups["axial_torque"]:
        out[:, 5] += np.real(coef * amp * np.exp(1j * (sh * phi + woff * tau)))

    def init(direction):
        if start == "rest" or not groups[direction]:
            return (0j, 0j)
        return _steady_state_init(p, direction, [(sh, wo, coef, a[0]) for sh, wo, coef, a in groups[direction]],
                                  w[0])

    F = np.zeros(t.size, dtype=complex)
    if groups["radial_force"]:
        q, qd = _modal_lti(p.mass, p.c_r, p.k_r, groups["radial_force"], (phi, tau), T, init("radial_force"))
        F = p.k_r * q + p.c_r * qd
    if groups["axial_force"]:
        q, qd = _modal_lti(p.mass, p.c_z, p.k_z, groups["axial_force"], (phi, tau), T, init("axial_force"))
        out[:, 2] = np.real(p.k_z * q + p.c_z * qd)
    Tc = np.zeros(t.size, dtype=complex)
    if groups["radial_torque"]:
        w_mid = 0.5 * (w[1:] + w[:-1])
        q, qd = _rocking_ltv(p, groups["radial_torque"], (phi, tau), w_mid, T, init("radial_torque"))
        Tc = p.k_rock * q + p.c_rock * qd
    Tint = Tc + 1j * p.height * F
    out[:, 0], out[:, 1] = F.real, F.imag
    out[:, 3], out[:, 4] = Tint.real, Tint.imag
    return out


def channel_index(name: str) -> int:
    return CHANNELS.index(name)
