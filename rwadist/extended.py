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
  docs/formats.md).  With ψ ∝ e^{iνt} the undamped characteristic polynomial is
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

from . import schema
from .effects.actions import LineFilter, LineLaw, LineModulation, of_effects
from .resonance import resonance_gain
from .units import G_CM2_TO_KG_M2, G_CM_TO_KG_M, RAD_S_TO_RPM

MODES = ("radial_translation", "rocking_forward", "rocking_backward", "axial_translation")
SENSES = ("co", "counter", "planar")
DIRECTIONS = ("radial_force", "radial_torque", "axial_force", "axial_torque")
ANALYTICAL_KIND = schema.ANALYTICAL_KIND
#: Largest |dΩ/dt| (rad/s²) a speed profile may show before it counts as a jump.
DEFAULT_MAX_ACCEL = 500.0

#: Model-file keys of :class:`ExtendedParams` (field -> key with unit): the schema's one table.
_DICT_KEYS = schema.PARAM_KEYS


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
        if self.I_zz > schema.MAX_INERTIA_RATIO * self.I_rr * (1 + 1e-12):
            # a rigid body has I_zz <= I_xx + I_yy = 2 I_rr; an effective ratio from measured whirls may exceed 2
            raise ValueError(f"ExtendedParams.I_zz = {self.I_zz!r} exceeds {schema.MAX_INERTIA_RATIO:g}·I_rr = "
                             f"{schema.MAX_INERTIA_RATIO * self.I_rr!r} (a rigid rotor has I_zz <= 2·I_rr)")
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
    d: dict[str, str | float] = {"kind": ANALYTICAL_KIND}
    d.update({key: float(getattr(p, name)) for name, key in _DICT_KEYS.items()})
    return d


def params_from_dict(d, source="<model>", needed_for: str | None = None) -> ExtendedParams:
    """Inverse of :func:`params_to_dict` (a dict or a :class:`rwadist.schema.Analytical`), read by the
    schema: a :class:`rwadist.model.ModelFileError` (a DataError) naming ``analytical.<key>`` on a
    missing or invalid field, ``analytical`` when the values are unphysical.  ``needed_for``: what asked for the
    parameters (``"the Campbell diagram"``), said with what gives them when they are missing (the general advice
    names the psd's choices, which such a caller does not have)."""
    from .model import ModelFileError

    if d is None and needed_for:
        raise ModelFileError(source, "analytical", f"missing: the model file has no analytical parameters "
                             f"(suspension modes), which {needed_for} is made of; add them with the extended fit "
                             "(rwadist.fit_extended, or the fit command's `extended` option; the rotor's mass and "
                             "radius are optional) or give a wheel `preset` instead of the model")
    if d is None:
        raise ModelFileError(source, "analytical", "missing: the model file has no analytical parameters (suspension "
                             "modes); add them with the extended fit (rwadist.fit_extended, or the fit command's "
                             "`extended` option; the rotor's mass and radius are optional) or use a wheel `preset`; "
                             "the empirical PSD (`empirical`) needs only the harmonics")
    vals = schema.Analytical.from_json(d, source, ModelFileError).require(source, ModelFileError)
    try:
        return ExtendedParams(**vals)
    except ValueError as exc:
        raise ModelFileError(source, "analytical", str(exc)) from exc


def params_from_model(model, source="<model>", needed_for: str | None = None) -> ExtendedParams:
    """Parameters from a :class:`rwadist.model.WheelModel`'s ``analytical`` section (``needed_for``: as
    :func:`params_from_dict`'s)."""
    return params_from_dict(model.analytical, source, needed_for)


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
    resonances : ((f_r Hz, ζ, peak_gain[, gain_above]), ...) of diagnosed ``fixed_resonance`` effects of role
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
            if len(r) not in (3, 4) or not all(math.isfinite(v) and v > 0 for v in r[:3]) or not math.isfinite(r[-1]):
                raise ValueError(f"Line.resonances entries (f_r Hz, zeta, peak_gain[, gain_above]) must be finite, the "
                                 f"first three > 0, got {r!r}")

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


def line_effects(effects, source: str = "<model>") -> dict:
    """The line actions of a model file's ``effects`` list (``rwadist diagnose``; dicts or typed
    :class:`rwadist.schema.Effect` s), validated by the schema (:func:`rwadist.schema.parse_effects`), as their
    elements say they act on the wheel's lines (:mod:`rwadist.effects.actions`):
    {'laws': [(direction, h, (A_ref, Ω_ref, p))], 'resonances': [(directions, (f_r, ζ, g))],
    'sidebands': [(direction, h, f_mod Hz, depth)]} in file order.  Effects that are measurement artefacts (a test
    stand's resonance, a load-cell offset) or records (a missing harmonic is already a harmonic) have no line action;
    broadband floors and a speed modulation are not line forcing.  :class:`rwadist.schema.ModelError` (a ValueError)
    naming ``effects[i].<field>`` on a bad entry."""
    out: dict = {"laws": [], "resonances": [], "sidebands": []}
    for a in of_effects(schema.parse_effects(effects, source)):
        if isinstance(a, LineLaw):
            out["laws"].append((a.direction, a.h, a.law))
        elif isinstance(a, LineFilter):
            out["resonances"].append((a.directions, a.resonance))
        elif isinstance(a, LineModulation):
            out["sidebands"].append((a.direction, a.h, a.f_mod_hz, a.depth))
    return out


def apply_line_effects(lines, effects) -> list:
    """``lines`` with the forcing effects of :func:`line_effects` (a model file's ``effects`` list):

    1. a line law (an amplitude law) -> :attr:`Line.law` of the lines of its direction with |Δh| < LAW_H_TOL;
    2. a line filter (a wheel mode's resonance) -> appended to :attr:`Line.resonances` of every line of
       its directions (quasi-static gain, see :class:`Line`);
    3. a line modulation (sidebands) -> for each matching line (as 1; carriers only, in line order) two copies appended
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
    from scipy import optimize  # 0.7 s to import: only where a crossing is solved

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
            seen: list[float] = []        # crossing speeds found, rad/s
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


def steady_lines(p: ExtendedParams, lines, omega, rigid: bool = False, omega_dot=None) -> tuple:
    """Steady-state lines at constant wheel speeds ``omega`` (rad/s, signed), closed form.

    Returns (f_hz (n_speeds, n_lines), amplitude (n_speeds, n_lines, 6) complex): each channel
    (Fx, Fy, Fz, Tx, Ty, Tz) of each line is Re(A e^{i 2π f (t − t0)}), N or N·m.  f = h|Ω|/2π for a
    harmonic, |hΩ/2π + f_offset| for a line with a frequency offset (a sideband, :class:`Line`); a
    line's wheel-mode resonances multiply each component by H at its whirl rate.  ``rigid``: the
    suspension is rigid (a hard-mounted wheel, e.g. a datasheet wheel whose modes are only assumed): no
    transmissibility, each line's free load (C·Ω², U_s·Ω², U_d·Ω²) reaches the interface as it is, the
    radial force with its lever arm ``height``.  ``omega_dot`` (rad/s², signed dΩ/dt, broadcast with ``omega``): the
    lines at the instants of a run-up or run-down where the speed is ``omega``, each component through the suspension
    as a linear chirp (:func:`rwadist.extended_chirp.chirp_transmissibility`: the lag, the lower peak and the ringing
    of a mode crossed fast), relative to the line's own phasor at the instant.
    """
    w = _omega_array(np.atleast_1d(omega))[:, None]
    if omega_dot is not None:
        from .extended_chirp import chirp_transmissibility
        w_dot = np.broadcast_to(np.asarray(omega_dot, dtype=float), w[:, 0].shape)
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
            if rigid:
                resp = coef * load0
            elif omega_dot is None:
                resp = transmissibility(p, ln.direction, nu, wj) * coef * load0
            else:           # ν̇ = σ·h·dΩ/dt (ν is linear in Ω)
                nu_dot = ln.nu(sigma, wj + w_dot) - nu
                resp = chirp_transmissibility(_subsystem(p, ln.direction), nu, nu_dot, wj) * coef * load0
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
