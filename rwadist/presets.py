"""Wheel descriptions from Masterson (1999), for the virtual test stand.

Harmonic coefficients are typed as printed in the thesis (N/rpm² ×1e-7, N·m/rpm² ×1e-7
for torques) and converted once with :data:`rwadist.units.THESIS_C_TO_SI` to SI per
(rad/s)² (kg·m, kg·m²).

Mode damping and peak gains are not in the thesis.  The stand's resonance
H(r) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r) departs from 1 far from the mode by
about 2(g² − 1)ζ²r²/(1 − r²)², so its skirts are set by g·ζ; a lightly
participating mode has g·ζ small.  With ζ = 0.01 and g = 6 (g·ζ = 0.06) a line is
amplified by more than 3 % only for 0.79 < r < 1.27 and by more than 1 % for
0.67 < r < 1.50.  For the E wheel's crossings the > 3 % ranges contain those of
Tables 3.6, 3.7 and 3.9: h = 1 backward whirl 1618–2221 rpm (thesis 1900–2000),
h = 2 backward 971–1387 (800–1300), h = 3 forward 1258–2400 (1800–2000), h = 4
forward 835–1726 (1150–1400), h = 4.42 forward 733–1447 (900–1100), h = 5.57
radial translation 1935+ (2200+).  With thesis-like widths (ζ = 0.03, g = 6)
every line is amplified by several percent at every speed and C·Ω² is visible
nowhere in the data.

The same values are used for the B wheel's modes (the thesis gives no table for them).

Extended physics (``physics="extended"``, issue 3).  Each preset also carries
:class:`rwadist.extended.ExtendedParams`, rotation senses and an imbalance phase:

* E wheel: ``replace(from_table_4_2(), height=0.0)``.  Height 0 because the thesis's
  Eq. 4.96 gives the interface loads as F = k·x, T = k_θ·θ, with no lever arm, and the
  empirical radial-torque coefficients (Table 3.4) were measured at the interface: a
  lever arm would add height·F to the torque and count the force lines' torque twice.
  Senses from the whirl each harmonic excites in Tables 3.6/3.7 (a co-rotating load
  only meets the forward whirl, counter-rotating content is what excites backward
  whirl): h = 2 counter (backward whirl, 800–1300 / 1150–1350 rpm); h = 3, 4, 4.42
  co (forward whirl); h = 5.37, 5.57, 5.58 co (radial translation, no whirl split);
  the imbalance is co-rotating by nature.  Note: Tables 3.6/3.7 also attribute an h = 1
  amplification near 1900–2000 rpm to the *backward* whirl, which a co-rotating
  imbalance cannot excite; the model does not reproduce it.
* B wheel: mass 5.9 kg and radius 0.1275 m (Table 2.2) as a thin disc; k_r puts radial
  translation at 200 Hz, k_rock rocking at 85 Hz at rest, k_z axial at 65 Hz (Table
  2.3); damping ratios equal to the E wheel's (radial ζ_r = 0.167 and rocking
  ζ_rock = 0.040 of Table 4.2's c, d_c; axial ζ_z = 0.05, the assumption of
  :func:`rwadist.extended.from_table_4_2`); U_s, U_d = Table 3.3's h = 0.99 radial
  force / torque coefficients (0.2134, 0.0630 ×1e-7 N/rpm², N·m/rpm²) in SI; height 0
  (as for E).  Senses: h = 1.99 counter (the radial-torque amplification of §3.2.1 at
  1200–1900 rpm lies on the backward whirl: 85 Hz/√(1.99·3.99) → 1810 rpm), all others
  co.  The 0.99 radial lines are the imbalances (``IMBALANCE_H_TOL``).
* ``imbalance_phase`` (dynamic imbalance ahead of static, rad) is not measured in the
  thesis; both presets use 0.6 rad, a fixed assumed value.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import extended as ext
from .errors import ParameterError
from .units import THESIS_C_TO_SI
from .wheel_description import Mode, WheelDescription

#: Assumed angle of the dynamic imbalance ahead of the static one, rad (not in the thesis).
IMBALANCE_PHASE = 0.6

RADIAL_CHANNELS = ("Fx", "Fy", "Tx", "Ty")
ALL_CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")


def _si(pairs):
    """[(h, C thesis units N/rpm² ×1e-7)] -> [(h, C SI per (rad/s)²)]."""
    return [(float(h), float(c) * THESIS_C_TO_SI) for h, c in pairs]


def ithaco_e() -> WheelDescription:
    """Ithaco TW-50E300 (E wheel) as tested at NASA GSFC (thesis §2.2.2)."""
    harmonics = {
        # Table 3.4, radial force (n_rad = 7), N/rpm² ×1e-7
        "radial_force": _si([(1.00, 0.4155), (2.00, 0.0832), (3.00, 0.0543), (4.00, 0.0621),
                             (4.42, 0.1097), (5.37, 0.0542), (5.57, 0.0690)]),
        # Table 3.4, radial torque (n_tor = 6), N·m/rpm² ×1e-7
        "radial_torque": _si([(1.00, 0.2205), (2.00, 0.0609), (3.00, 0.0242), (4.00, 0.0243),
                              (4.42, 0.0485), (5.58, 0.0498)]),
        # Table 3.4, axial force (n_axi = 5).  Note: Table 3.9 prints C = 0.0101 for h = 4.33
        # (after mode removal, from 0.0218 before); Table 3.4's 0.1011 is kept as the stated source.
        "axial_force": _si([(1.00, 0.3038), (1.98, 0.2818), (2.96, 0.0719), (4.00, 0.0685),
                            (4.33, 0.1011)]),
    }
    modes = [
        # Rocking: ω_r = 54.9 Hz fitted (Table 4.2; maker: 60 Hz, Table 2.3); thin-disc whirl a = I_zz/I_rr = 2.
        Mode("rocking_backward", 54.9, 0.01, 6.0, RADIAL_CHANNELS, whirl=-1, inertia_ratio=2.0),
        Mode("rocking_forward", 54.9, 0.01, 6.0, RADIAL_CHANNELS, whirl=+1, inertia_ratio=2.0),
        # Radial translation: ω_T = 227.7 Hz fitted (Table 4.2; maker: 250 Hz).
        Mode("radial_translation", 227.7, 0.01, 6.0, RADIAL_CHANNELS),
        # Axial translation: 70 Hz (Table 2.3).
        Mode("axial_translation", 70.0, 0.01, 6.0, ("Fz",)),
    ]
    return WheelDescription(
        name="ithaco-e", harmonics=harmonics, modes=modes, test_stand_modes=[],  # stiff fixture, clean to 300 Hz
        max_speed_rpm=3850.0,          # Table 2.2
        mass_kg=10.6, radius_m=0.1965,  # Table 4.2
        f_lim_hz=None,
        default_speeds_rpm=np.linspace(300.0, 2400.0, 120),  # 120 speeds, as the 120 slices of §2.2.2
        default_sample_rate=3840.0, default_n_samples=8192,  # 8192 points = 2.133 s slices (§2.2.2)
        default_sweep={"rpm_start": 0.0, "rpm_end": 2400.0, "duration": 390.0, "sample_rate": 3840.0,
                       "profile": "exp"},  # full-torque spin-up saturating near 2400 rpm, 390 s (§2.2.2)
        notes="Ithaco TW-50E300: harmonics Table 3.4, modes Tables 2.3/4.2, specs Table 2.2 (Masterson 1999)",
        extended=replace(ext.from_table_4_2(), height=0.0),   # Eq. 4.96: interface loads, no lever arm
        senses=_senses(harmonics, counter=(2.0,)),             # Tables 3.6/3.7: h = 2 on the backward whirl
        imbalance_phase=IMBALANCE_PHASE,
    )


def _senses(harmonics: dict, counter=()) -> dict:
    """(direction, h) -> sense for every radial harmonic: 'counter' for h in ``counter``, else 'co'."""
    return {(d, h): ("counter" if any(abs(h - c) < 1e-9 for c in counter) else "co")
            for d in ("radial_force", "radial_torque") for h, _ in harmonics.get(d, [])}


def ithaco_b_extended() -> ext.ExtendedParams:
    """B wheel rotor: thin disc 5.9 kg, R 0.1275 m; modes at Table 2.3's 200 / 85 / 65 Hz; E-wheel damping
    ratios; imbalances from Table 3.3's h = 0.99 coefficients; height 0."""
    M, R = 5.9, 0.1275
    I_zz, I_rr = ext.thin_disc(M, R)
    e = ext.from_table_4_2()
    k_r = M * (2 * np.pi * 200.0) ** 2
    k_rock = I_rr * (2 * np.pi * 85.0) ** 2
    k_z = M * (2 * np.pi * 65.0) ** 2
    return ext.ExtendedParams(
        mass=M, I_zz=I_zz, I_rr=I_rr,
        k_r=k_r, c_r=2 * e.zeta_r * np.sqrt(k_r * M),
        k_rock=k_rock, c_rock=2 * e.zeta_rock * np.sqrt(k_rock * I_rr),
        k_z=k_z, c_z=2 * e.zeta_z * np.sqrt(k_z * M),
        height=0.0, U_s=0.2134 * THESIS_C_TO_SI, U_d=0.0630 * THESIS_C_TO_SI)


def ithaco_b() -> WheelDescription:
    """Ithaco TW-16B32 (B wheel, FUSE flight unit) as tested at Orbital (thesis §2.2.1)."""
    harmonics = {
        # Table 3.3, radial force (n_rad = 13), N/rpm² ×1e-7
        "radial_force": _si([(0.99, 0.2134), (1.99, 0.0510), (2.46, 0.0609), (3.16, 0.0783),
                             (3.87, 0.0528), (4.56, 0.0905), (5.28, 0.1752), (5.98, 0.3040),
                             (6.71, 0.2053), (8.09, 0.3246), (8.83, 0.3517), (9.54, 0.2991),
                             (10.25, 0.3183)]),
        # Table 3.3, radial torque (n_tor = 11), N·m/rpm² ×1e-7
        "radial_torque": _si([(0.99, 0.0630), (1.99, 0.0314), (3.16, 0.0089), (4.56, 0.0119),
                              (5.28, 0.0261), (5.97, 0.0372), (6.23, 0.0237), (6.68, 0.0276),
                              (7.38, 0.0335), (8.09, 0.0477), (8.80, 0.0400)]),
        # Table 3.3, axial force (n_axi = 4)
        "axial_force": _si([(0.99, 0.0727), (1.41, 0.0497), (2.82, 0.0975), (5.95, 0.1989)]),
    }
    modes = [
        # Table 2.3 (maker's values): rocking 85 Hz, axial 65 Hz, radial translation 200 Hz.
        Mode("rocking_backward", 85.0, 0.01, 6.0, RADIAL_CHANNELS, whirl=-1, inertia_ratio=2.0),
        Mode("rocking_forward", 85.0, 0.01, 6.0, RADIAL_CHANNELS, whirl=+1, inertia_ratio=2.0),
        Mode("radial_translation", 200.0, 0.01, 6.0, RADIAL_CHANNELS),
        Mode("axial_translation", 65.0, 0.01, 6.0, ("Fz",)),
    ]
    # §2.2.1 / Fig. 2-3: fixture resonances at ~300 Hz and ~460 Hz dominate every channel, so the
    # thesis truncates the data at f_lim = 200 Hz.  Gain 10 makes them the dominant ridges; with
    # ζ = 0.01 their skirt adds < 3 % below 200 Hz.
    stand = [
        Mode("test_stand_300Hz", 300.0, 0.01, 10.0, ALL_CHANNELS),
        Mode("test_stand_460Hz", 460.0, 0.01, 10.0, ALL_CHANNELS),
    ]
    return WheelDescription(
        name="ithaco-b", harmonics=harmonics, modes=modes, test_stand_modes=stand,
        max_speed_rpm=5100.0,           # Table 2.2
        mass_kg=5.9, radius_m=0.1275,   # Table 2.2 (< 5.9 kg, diameter < 25.5 cm)
        f_lim_hz=200.0,
        default_speeds_rpm=np.arange(500.0, 3401.0, 100.0),  # every 100 rpm, 500-3400 (§2.2.1)
        default_sample_rate=1000.0, default_n_samples=8192,    # 1 kHz, about 8 s per speed (§2.2.1)
        default_sweep=None,
        notes="Ithaco TW-16B32: harmonics Table 3.3, modes Table 2.3, stand §2.2.1, specs Table 2.2 "
              "(Masterson 1999)",
        extended=ithaco_b_extended(),
        senses=_senses(harmonics, counter=(1.99,)),            # §3.2.1: h = 1.99 on the backward whirl
        imbalance_phase=IMBALANCE_PHASE,
    )


_FACTORIES = {"ithaco-e": ithaco_e, "ithaco-b": ithaco_b}

#: Preset name -> WheelDescription.  Use :func:`preset` for a fresh copy to modify.
PRESETS = {name: make() for name, make in _FACTORIES.items()}


def from_model(model) -> WheelDescription:
    """A :class:`WheelDescription` of a model file (e.g. a catalogue wheel): its harmonics, its
    analytical parameters as the extended physics, the senses of its radial harmonics.  A model
    carries no simple resonances, so ``physics="simple"`` gives the harmonics alone; use
    ``physics="extended"`` for the modes."""
    from . import extended as ext
    from .catalogue import modes_assumed

    harmonics = {d: [(h.h, h.C) for h in model.harmonics(d)] for d in model.empirical if model.harmonics(d)}
    senses = {(d, h.h): h.sense for d in ("radial_force", "radial_torque") for h in model.harmonics(d) if h.sense}
    params = ext.params_from_model(model, model.name) if model.analytical else None
    wheel = model.wheel or {}
    return WheelDescription(
        name=model.name, harmonics=harmonics, modes=[], test_stand_modes=[],
        max_speed_rpm=float(wheel.get("max_speed_rpm", 6000.0)),
        mass_kg=wheel.get("mass_kg"), radius_m=wheel.get("radius_m"),
        notes=str(model.provenance.get("source", "")), extended=params, senses=senses,
        modes_assumed=modes_assumed(model))


def names() -> list:
    """Every preset name: the test-stand wheels and the catalogue."""
    from . import catalogue

    return sorted(set(_FACTORIES) | set(catalogue.names()))


def preset(name: str) -> WheelDescription:
    """A fresh :class:`WheelDescription` of a named preset (a test-stand wheel of this module, else a
    catalogue wheel of :mod:`rwadist.catalogue`); ValueError listing the names if unknown."""
    from . import catalogue

    key = str(name).strip().lower()
    if key in _FACTORIES:
        return _FACTORIES[key]()
    if key in catalogue.names():
        return from_model(catalogue.load(key))
    raise ParameterError("preset", f"{name!r}: unknown wheel preset; available: {', '.join(names())}")
