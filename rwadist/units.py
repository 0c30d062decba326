"""Units, channels and directions fixed by ``docs/formats.md``.

SI inside the code (rad/s for wheel speed ``omega``); rpm exists only at the
edges and is converted here, once.
"""
from __future__ import annotations

import numpy as np

#: Channel order everywhere: forces (N) then torques (N·m), wheel frame.
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
#: The radial pairs: the two channels of a radial force or torque, x then y (a rotating vector reads on both).
RADIAL_PAIRS = (("Fx", "Fy"), ("Tx", "Ty"))
CHANNEL_UNIT = {"Fx": "N", "Fy": "N", "Fz": "N", "Tx": "Nm", "Ty": "Nm", "Tz": "Nm"}
#: Column name of each channel in the interchange CSV files.
CHANNEL_COLUMN = {ch: f"{ch}_{CHANNEL_UNIT[ch]}" for ch in CHANNELS}
COLUMN_CHANNEL = {v: k for k, v in CHANNEL_COLUMN.items()}
#: Column name of each channel's PSD in PSD tables.
PSD_COLUMN = {ch: f"{ch}_{CHANNEL_UNIT[ch]}2_per_Hz" for ch in CHANNELS}

#: Empirical-model directions and the channels each is fitted from.
DIRECTION_CHANNELS = {
    "radial_force": ("Fx", "Fy"),
    "radial_torque": ("Tx", "Ty"),
    "axial_force": ("Fz",),
    "axial_torque": ("Tz",),
}
CHANNEL_DIRECTION = {ch: d for d, chs in DIRECTION_CHANNELS.items() for ch in chs}
#: SI unit of the amplitude coefficient C of each direction (amplitude = C·Ω², Ω in rad/s).
DIRECTION_C_UNIT = {
    "radial_force": "kg·m",
    "radial_torque": "kg·m²",
    "axial_force": "kg·m",
    "axial_torque": "kg·m²",
}

RPM_TO_RAD_S = 2.0 * np.pi / 60.0
RAD_S_TO_RPM = 60.0 / (2.0 * np.pi)
#: The thesis tables give C in N/rpm² ×1e-7; multiply by this to get SI per (rad/s)².
THESIS_C_TO_SI = 1e-7 * RAD_S_TO_RPM**2
G_CM_TO_KG_M = 1e-5
G_CM2_TO_KG_M2 = 1e-7


def rpm_to_rad_s(rpm):
    """Wheel speed in rpm -> rad/s."""
    return np.asarray(rpm, dtype=float) * RPM_TO_RAD_S


def rad_s_to_rpm(omega):
    """Wheel speed in rad/s -> rpm."""
    return np.asarray(omega, dtype=float) * RAD_S_TO_RPM


def rad_s_to_hz(omega):
    """Wheel speed in rad/s -> revolutions per second (Hz)."""
    return np.asarray(omega, dtype=float) / (2.0 * np.pi)


#: Unit factors a channel recorded in the wrong unit reads by (amplitude ratio, the unit, the unit the other reads),
#: forces then torques; a ratio within :data:`UNIT_TOLERANCE` of one is named as such.
UNIT_FACTORS = {"F": ((4.44822, "lbf", "N"), (9.80665, "kgf", "N"), (3.59694, "N", "ozf")),
                "T": ((1.35582, "ft·lbf", "N·m"), (8.85075, "N·m", "in·lbf"), (1000.0, "N·m", "N·mm"),
                      (12.0, "ft·lbf", "in·lbf"))}
UNIT_TOLERANCE = 0.02


def unit_words(ratio: float, channel: str) -> str:
    """'' or, when the amplitude ratio ``ratio`` (> 1) of a radial pair's channels is a unit factor of the pair of
    ``channel`` ('Fx', 'Ty', ...: :data:`UNIT_FACTORS` of its first letter), the words naming the mix-up."""
    for factor, big, small in UNIT_FACTORS[channel[0]]:
        if abs(ratio / factor - 1.0) <= UNIT_TOLERANCE:
            return (f"; {ratio:.4g} is near the number of {small} in one {big} ({factor:g}): one of the two "
                    "recorded or declared in the other unit (the channel map's unit in meta.json, docs/formats.md)?")
    return ""
