"""trial21's 11-kg wheel on a stand with a fixture resonance, generated WITHOUT rwadist's physics (test helper).

A cut-down copy of the independent generator written for trial 21 (session 21's independent trial, ``gen.py``,
numpy only; not the package's code and not tests/family_wheel.py), its steady ``fixture`` case only, drawing its
random numbers in the same order.  Physics (steady state, small motions, a rigid rotor on a linear isotropic
suspension whose elastic centre is at its centre of mass, the load-cell point at the rotor's centre):

* a blocked radial load of harmonic h and sense s (+1 co-rotating with +z, −1 counter) is C·Ω²·e^{i(s·h·θ + φ)} in
  complex coordinates (F_x = Re, F_y = Im), φ random per line and run;
* the housing reads it through the suspension, k·x + c·ẋ: translation G = (k + i·s·c·w)/(k − M·w² + i·s·c·w);
  rocking (k_θ + i·s·c_θ·w)/(k_θ − I_rr·w² + s·I_zz·Ω·w + i·s·c_θ·w); axial like the translation;
* a fixture resonance on every channel, H(f) = 1 + (P − 1)·2jζr/(1 − r² + 2jζr), r = f/f_fix (its conjugate for
  a counter-rotating line), on the lines (the noise is not shaped);
* white sensor noise 2 % of the top speed's measured 1x in every channel; Tz noise only.

Wheel "T21": 11 kg, I_rr 0.060 kg·m², I_zz 0.081 kg·m² (1.35), translation 75 Hz ζ 0.03, rocking 45 Hz at rest
ζ 0.02, axial 190 Hz ζ 0.02; the fixture at 0.9 × 75 = 67.5 Hz, ζ 0.03, peak gain 5; 24 speeds 300-9000 rpm, 10 s
at 8 kHz.
"""
from __future__ import annotations

import numpy as np

TWO_PI = 2 * np.pi
M = 11.0
I_RR = 0.060
I_ZZ = 0.081
F_TR, Z_TR = 75.0, 0.03
F_RK, Z_RK = 45.0, 0.02
F_AX, Z_AX = 190.0, 0.02
K_TR = M * (TWO_PI * F_TR) ** 2
C_TR = 2 * Z_TR * np.sqrt(K_TR * M)
K_RK = I_RR * (TWO_PI * F_RK) ** 2
C_RK = 2 * Z_RK * np.sqrt(K_RK * I_RR)
K_AX = M * (TWO_PI * F_AX) ** 2
C_AX = 2 * Z_AX * np.sqrt(K_AX * M)
U_S = 8e-6                         # kg m
U_D = 5e-7                         # kg m^2

# (h, C, sense) blocked-load lines; sense +1 co, -1 counter, 0 axial
RF = [(1.0, U_S, +1), (0.42, 1.2e-6, -1), (3.3, 6e-7, +1), (6.6, 2e-7, +1), (4.7, 4e-7, -1), (9.4, 1.2e-7, -1)]
RT = [(1.0, U_D, +1), (0.42, 6e-8, -1), (3.3, 4e-8, +1), (6.6, 1.5e-8, +1), (4.7, 3e-8, -1), (9.4, 1e-8, -1)]
AF = [(2.0, 1.5e-6, 0), (3.3, 3e-7, 0)]

FS = 8000.0
T_RUN = 10.0
SPEEDS_RPM = np.linspace(300.0, 9000.0, 24)
NOISE_FRAC = 0.02
FIX_F, FIX_Z, FIX_P = 0.9 * F_TR, 0.03, 5.0
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")


def _g_tr(w, s):
    return (K_TR + 1j * s * C_TR * w) / (K_TR - M * w ** 2 + 1j * s * C_TR * w)


def _g_rk(w, s, om):
    return (K_RK + 1j * s * C_RK * w) / (K_RK - I_RR * w ** 2 + s * I_ZZ * om * w + 1j * s * C_RK * w)


def _g_ax(w):
    return (K_AX + 1j * C_AX * w) / (K_AX - M * w ** 2 + 1j * C_AX * w)


def _fixture(f):
    r = f / FIX_F
    return 1 + (FIX_P - 1) * (2j * FIX_Z * r) / (1 - r ** 2 + 2j * FIX_Z * r)


def _fix_s(w, s):
    h = _fixture(w / TWO_PI)
    return h if s > 0 else np.conj(h)


def _channels(om, t, rng, fixture_on):
    theta = om * t
    Fr = np.zeros(t.size, complex)
    Tr = np.zeros(t.size, complex)
    Fz = np.zeros(t.size)
    for lines, gain, out in ((RF, lambda w, s: _g_tr(w, s), "F"), (RT, lambda w, s: _g_rk(w, s, om), "T")):
        for h, c, s in lines:
            w = h * om
            ph = rng.uniform(0, TWO_PI)
            a = c * om ** 2 * gain(w, s)
            if fixture_on:
                a = a * _fix_s(w, s)
            sig = a * np.exp(1j * (s * h * theta + ph))
            if out == "F":
                Fr += sig
            else:
                Tr += sig
    for h, c, _s in AF:
        w = h * om
        ph = rng.uniform(0, TWO_PI)
        a = c * om ** 2 * _g_ax(w)
        if fixture_on:
            a = a * _fixture(w / TWO_PI)
        Fz += np.real(a * np.exp(1j * (h * theta + ph)))
    om_top = SPEEDS_RPM[-1] * TWO_PI / 60
    sf = NOISE_FRAC * abs(U_S * om_top ** 2 * _g_tr(om_top, 1))
    st = NOISE_FRAC * abs(U_D * om_top ** 2 * _g_rk(om_top, 1, om_top))
    ch = np.vstack([Fr.real, Fr.imag, Fz, Tr.real, Tr.imag, np.zeros(t.size)])
    return ch + np.array([sf, sf, sf, st, st, st])[:, None] * rng.standard_normal(ch.shape)


def steady(seed: int, fixture: bool = True) -> tuple:
    """(speeds rad/s (24,), signals (24, 6, n) in :data:`CHANNELS` order, sample rate Hz) of the steady runs, the
    fixture resonance on every channel when ``fixture``."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(FS * T_RUN)) / FS
    speeds = SPEEDS_RPM * TWO_PI / 60
    return speeds, np.stack([_channels(om, t, rng, fixture) for om in speeds]), FS
