"""A wheel swept without a speed column, generated WITHOUT rwadist's physics (test helper).

A copy of the sweep part of the independent generator written for trial 11 (session 11's independent trial,
``gen.py``, numpy only; not the package's code and not tests/family_wheel.py), cut down to what the speed-scale
tests need, with three switches of its line set.  Physics (steady state, small motions, a rigid rotor on a linear
isotropic suspension whose elastic centre is at its centre of mass; the load-cell point in the rotor's plane):

* a radial load of harmonic h and sense s (+1 co-rotating with +z, −1 counter) is L = A·e^{i·s·h·φ(t)} in complex
  coordinates (F_x = Re L, F_y = Im L), its whirl rate w = s·h·Ω;
* radial translation: F_mount = F·(k + i·c·w)/(k − M·w² + i·c·w) (no gyroscopic term);
* rocking: T_mount = T·(k_θ + i·c_θ·w)/(k_θ − I_rr·w² + I_zz·Ω·w + i·c_θ·w), whirls I_rr·w² − I_zz·Ω·w − k_θ = 0
  (forward rising to (I_zz/I_rr)·Ω); axial like the translation; spin-axis torque hard-mounted;
* every line C·Ω², a random phase each; quasi-static through the sweep (each line's complex amplitude the steady
  gain at the instantaneous speed, its phase h·φ(t)); white sensor noise.

Wheel (trial 11's): 7 kg, I_rr 0.05 kg·m², I_zz/I_rr 1.8, modes 140 / 70 (rocking at rest) / 260 Hz, lines at h
0.41 (cage, radial force), 1, 2, 3.6 (ball pass) and 7.2 (its 2×; counter-rotating in the radial torque).
"""
from __future__ import annotations

import numpy as np

TWO_PI = 2 * np.pi
M = 7.0                       # rotor mass, kg
I_RR = 0.05                   # transverse inertia, kg m^2
RATIO = 1.8                   # I_zz / I_rr
F_R, Z_R = 140.0, 0.03        # radial translation, Hz, damping ratio
F_T, Z_T = 70.0, 0.02         # rocking at rest, Hz, damping ratio
F_Z, Z_Z = 260.0, 0.03        # axial, Hz
U_S = 1.5e-5                  # static imbalance, kg m
U_D = 1.5e-6                  # dynamic imbalance, kg m^2
FS = 4000.0
SIGMA_F, SIGMA_T = 0.003, 2.0e-4     # N, N m
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")

# (direction, h, sense, C)  C in kg m (forces) or kg m^2 (torques)
LINES = (
    ("radial_force", 1.0, +1, U_S),
    ("radial_torque", 1.0, +1, U_D),
    ("radial_force", 0.41, +1, 0.06 * U_S),     # cage
    ("radial_force", 2.0, +1, 0.10 * U_S),
    ("radial_force", 3.6, +1, 0.08 * U_S),      # ball pass
    ("radial_force", 7.2, +1, 0.04 * U_S),      # 2x ball pass
    ("radial_torque", 3.6, +1, 0.10 * U_D),
    ("radial_torque", 7.2, -1, 0.06 * U_D),     # counter-rotating: meets the backward whirl
    ("axial_force", 1.0, +1, 0.10 * U_S),
    ("axial_force", 3.6, +1, 0.15 * U_S),
    ("axial_force", 7.2, +1, 0.10 * U_S),
    ("axial_torque", 2.0, +1, 1.0e-8),
    ("axial_torque", 3.6, +1, 2.0e-8),
)


def lines(ball_pass: float = 1.0, cage_in_torque: bool = False) -> tuple:
    """The line set: trial 11's with the ball-pass lines (3.6, 7.2) × ``ball_pass`` in strength, and with
    ``cage_in_torque`` the cage line co-rotating in the radial torque too, with its 2× (0.82) in the radial force
    (a cage imbalance seen at both bearings, and its harmonic)."""
    out = [(d, h, s, C * (ball_pass if h in (3.6, 7.2) else 1.0)) for d, h, s, C in LINES]
    if cage_in_torque:
        out += [("radial_torque", 0.41, +1, 0.06 * U_D), ("radial_force", 0.82, +1, 0.05 * U_S)]
    return tuple(out)


def sweep(rpm0: float, rpm1: float, duration: float, line_set=LINES, seed: int = 11, modes: bool = True) -> tuple:
    """(time s (n,), signals (6, n) N and N·m in CHANNELS order, true speed rad/s (n,)): a linear sweep rpm0 -> rpm1
    in ``duration`` s at FS; ``modes`` False: hard-mounted (every gain 1)."""
    rng = np.random.default_rng(seed)
    i_zz = RATIO * I_RR
    k_r, k_t, k_z = M * (TWO_PI * F_R) ** 2, I_RR * (TWO_PI * F_T) ** 2, M * (TWO_PI * F_Z) ** 2
    c_r, c_t, c_z = (2 * Z_R * np.sqrt(k_r * M), 2 * Z_T * np.sqrt(k_t * I_RR), 2 * Z_Z * np.sqrt(k_z * M))
    n = int(round(duration * FS))
    t = np.arange(n) / FS
    w0, w1 = rpm0 * TWO_PI / 60, rpm1 * TWO_PI / 60
    omega = w0 + (w1 - w0) * t / duration
    angle = w0 * t + 0.5 * (w1 - w0) * t**2 / duration
    ch = np.zeros((6, n))
    for direction, h, s, C in line_set:
        ph = rng.uniform(0, TWO_PI)
        w = s * h * omega
        if not modes or direction == "axial_torque":
            g = 1.0
        elif direction == "radial_force":
            g = (k_r + 1j * c_r * w) / (k_r - M * w**2 + 1j * c_r * w)
        elif direction == "radial_torque":
            g = (k_t + 1j * c_t * w) / (k_t - I_RR * w**2 + i_zz * omega * w + 1j * c_t * w)
        else:
            g = (k_z + 1j * c_z * w) / (k_z - M * w**2 + 1j * c_z * w)
        L = C * omega**2 * g * np.exp(1j * (s * h * angle + ph))
        if direction in ("radial_force", "radial_torque"):
            i0 = 0 if direction == "radial_force" else 3
            ch[i0] += L.real
            ch[i0 + 1] += L.imag
        else:
            ch[2 if direction == "axial_force" else 5] += L.real
    ch[:3] += rng.normal(0, SIGMA_F, (3, n))
    ch[3:] += rng.normal(0, SIGMA_T, (3, n))
    return t, ch, omega
