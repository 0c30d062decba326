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
"""
from __future__ import annotations

import numpy as np

from .teststand import Mode, WheelDescription
from .units import THESIS_C_TO_SI

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
    )


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
    )


_FACTORIES = {"ithaco-e": ithaco_e, "ithaco-b": ithaco_b}

#: Preset name -> WheelDescription.  Use :func:`preset` for a fresh copy to modify.
PRESETS = {name: make() for name, make in _FACTORIES.items()}


def preset(name: str) -> WheelDescription:
    """A fresh :class:`WheelDescription` of a named preset; ValueError listing the names if unknown."""
    key = str(name).strip().lower()
    if key not in _FACTORIES:
        raise ValueError(f"unknown wheel preset {name!r}; available: {', '.join(sorted(_FACTORIES))}")
    return _FACTORIES[key]()
