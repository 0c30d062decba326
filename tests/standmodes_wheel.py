"""Any rigid wheel on its suspension, on a load cell with a fixture, generated WITHOUT rwadist's physics (test helper).

A generalised copy of tests/independent_wheel.py: the same textbook real-coordinate equations (radial translation
M ẍ + c ẋ + k x = F; rocking with the gyroscopic coupling I_zz Ω written out; axial M z̈ + c_z ż + k_z z = F_z), each
line's harmonic balance solved as a 2x2 (radial) or 1x1 (axial) complex system, the load cell reading the suspension
reaction (k + iωc)·q; here the wheel (mass, inertias, the three modes, the lines) is a parameter, not the thesis's E
wheel.  What the stand adds is written out too:

* fixture resonances: each multiplies every line of every channel by H(r) = (1 − r² + 2j g ζ r)/(1 − r² + 2j ζ r),
  r = f/f_r (a fixture resonance whose peak |H| is g), sensor noise added after it;
* effects that are wheel loads, each in its own physical form: a counter-rotating part of any radial line (the
  co-rotating power fraction), speed sidebands (an amplitude modulation of a line at a fixed fraction of the
  speed: lines at (h ± δ)Ω of (depth/2)·C·Ω² each, co-rotating), an amplitude law (the line A(Ω) =
  C·Ω_mid²·(Ω/Ω_mid)^p).

Only numpy; nothing imported from rwadist but the data containers.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Wheel:
    """A rigid rotor on a linear suspension.

    mass kg; i_zz, i_rr kg·m²; f_trans, f_rock, f_axial Hz (modes at rest); zeta_* damping ratios; lines: tuples
    (direction, h, C in N/(rad/s)² or N·m/(rad/s)², co-rotating power fraction of a radial line).  h = 1 radial
    lines are the imbalances (static and dynamic: one phase between them per run)."""

    name: str
    mass: float
    i_zz: float
    i_rr: float
    f_trans: float
    f_rock: float
    f_axial: float
    zeta_trans: float
    zeta_rock: float
    zeta_axial: float
    lines: tuple = field(default=())

    @property
    def truth_hz(self) -> dict:
        return {"radial_translation": self.f_trans, "rocking": self.f_rock, "axial": self.f_axial}

    @property
    def inertia_ratio(self) -> float:
        return self.i_zz / self.i_rr

    def kc(self, direction: str):
        """(stiffness, damping, inertia) of the subsystem ``direction`` loads."""
        if direction == "radial_force":
            k = self.mass * (2 * np.pi * self.f_trans) ** 2
            return k, 2 * self.zeta_trans * np.sqrt(k * self.mass), self.mass
        if direction == "radial_torque":
            k = self.i_rr * (2 * np.pi * self.f_rock) ** 2
            return k, 2 * self.zeta_rock * np.sqrt(k * self.i_rr), self.i_rr
        k = self.mass * (2 * np.pi * self.f_axial) ** 2
        return k, 2 * self.zeta_axial * np.sqrt(k * self.mass), self.mass

    def C(self, direction: str, h: float) -> float:
        return next(c for d, hh, c, _ in self.lines if d == direction and abs(hh - h) < 1e-9)


_THESIS = 1e-7 * (60.0 / (2.0 * np.pi)) ** 2          # thesis N/rpm² ×1e-7 -> SI per (rad/s)²
_E_MASS, _E_RADIUS, _E_K, _E_C, _E_D = 10.6, 0.1965, 21.7e6, 5067.0, 0.0237
_E_IRR = 0.25 * _E_MASS * _E_RADIUS**2

#: the E wheel of tests/independent_wheel.py (thesis Tables 3.4, 4.2), written as a Wheel
E_WHEEL = Wheel(
    "E-like", _E_MASS, 0.5 * _E_MASS * _E_RADIUS**2, _E_IRR,
    f_trans=float(np.sqrt(_E_K / _E_MASS) / (2 * np.pi)), f_rock=float(np.sqrt(_E_K * _E_D**2 / _E_IRR) / (2 * np.pi)),
    f_axial=70.0, zeta_trans=float(_E_C / (2 * np.sqrt(_E_K * _E_MASS))),
    zeta_rock=float(_E_C * _E_D**2 / (2 * np.sqrt(_E_K * _E_D**2 * _E_IRR))), zeta_axial=0.05,
    lines=tuple((d, h, c * _THESIS, fr) for d, h, c, fr in [
        ("radial_force", 1.00, 0.4155, 1.0), ("radial_force", 2.00, 0.0832, 0.0), ("radial_force", 3.00, 0.0543, 1.0),
        ("radial_force", 4.00, 0.0621, 1.0), ("radial_force", 4.42, 0.1097, 1.0), ("radial_force", 5.37, 0.0542, 1.0),
        ("radial_force", 5.57, 0.0690, 1.0), ("radial_torque", 1.00, 0.2205, 1.0), ("radial_torque", 2.00, 0.0609, 0.0),
        ("radial_torque", 3.00, 0.0242, 1.0), ("radial_torque", 4.00, 0.0243, 1.0), ("radial_torque", 4.42, 0.0485, 1.0),
        ("radial_torque", 5.58, 0.0498, 1.0), ("axial_force", 1.00, 0.3038, 1.0), ("axial_force", 1.98, 0.2818, 1.0),
        ("axial_force", 2.96, 0.0719, 1.0), ("axial_force", 4.00, 0.0685, 1.0), ("axial_force", 4.33, 0.1011, 1.0)]))


def bearing_wheel(name="new", mass=4.2, inertia_ratio=1.56, radius=0.12, f_trans=310.0, f_rock=95.0, f_axial=140.0,
                  zeta=(0.05, 0.03, 0.04), u_s=1.5e-6, cage=0.41, bpfo=3.08, bpfi=4.92) -> Wheel:
    """A wheel with bearing-like non-integer lines (a cage line, ball-pass outer/inner and twice the outer), the
    issue's new wheel by default (4.2 kg, I_zz/I_rr 1.56, modes 310/95/140 Hz).  u_s: static imbalance N/(rad/s)²;
    the other lines are fractions of it (torques: of u_s·0.03 m, the dynamic imbalance)."""
    i_zz = 0.5 * mass * radius**2
    u_d = 0.03 * u_s
    lines = [("radial_force", 1.0, u_s, 1.0), ("radial_force", cage, 0.08 * u_s, 1.0),
             ("radial_force", bpfo, 0.15 * u_s, 1.0), ("radial_force", bpfi, 0.12 * u_s, 1.0),
             ("radial_force", 2 * bpfo, 0.05 * u_s, 1.0),
             ("radial_torque", 1.0, u_d, 1.0), ("radial_torque", bpfo, 0.2 * u_d, 1.0),
             ("radial_torque", bpfi, 0.15 * u_d, 1.0),
             ("axial_force", 1.0, 0.4 * u_s, 1.0), ("axial_force", bpfo, 0.3 * u_s, 1.0),
             ("axial_force", bpfi, 0.2 * u_s, 1.0), ("axial_force", 2 * bpfo, 0.1 * u_s, 1.0)]
    return Wheel(name, mass, i_zz, i_zz / inertia_ratio, f_trans, f_rock, f_axial, *zeta, lines=tuple(lines))


NEW_WHEEL = bearing_wheel()


def _reaction(wheel: Wheel, direction: str, a: complex, nu: float, omega: float):
    """Load-cell reaction phasors (X, Y) at |nu| of the radial load a·e^{i nu t} (nu < 0: against the spin)."""
    w = abs(nu)
    k, c, m = wheel.kc(direction)
    g = wheel.i_zz * omega if direction == "radial_torque" else 0.0
    Z = np.array([[k - m * w**2 + 1j * w * c, 1j * w * g], [-1j * w * g, k - m * w**2 + 1j * w * c]])
    load = np.array([a, -1j * a]) if nu >= 0 else np.array([np.conj(a), 1j * np.conj(a)])
    return (k + 1j * w * c) * np.linalg.solve(Z, load)


#: fixture forms: "peak" H = (1 − r² + 2j g ζ r)/(1 − r² + 2j ζ r) (back to 1 above f_r; g = |H(f_r)|);
#: "transmissibility" (1 + 2j ζ r)/(1 − r² + 2j ζ r) (the force through a fixture spring, falling as 2ζ/r above f_r;
#: g unused, |H(f_r)| ≈ 1/(2ζ)); "sdof" 1/(1 − r² + 2j ζ r) (the same without the damper's path, falling as 1/r²)
FIXTURE_FORMS = ("peak", "transmissibility", "sdof")


def _fixture(f_hz: float, fixtures) -> complex:
    out = 1.0 + 0j
    for f_r, zeta, gain, *form in fixtures:
        r = f_hz / f_r
        form = form[0] if form else "peak"
        num = {"peak": 1 - r * r + 2j * gain * zeta * r, "transmissibility": 1 + 2j * zeta * r, "sdof": 1.0}[form]
        out *= num / (1 - r * r + 2j * zeta * r)
    return out


def generate(wheel: Wheel, speeds_rpm, sample_rate=5000.0, n_samples=8192, noise=0.01, seed=0, fixtures=(),
             counter=None, speed_sidebands=None, law=None):
    """Steady runs as an rwadist SteadyTest (speeds in rad/s on the runs).  Returns (test, truth dict).

    fixtures : (f_r Hz, ζ, peak gain[, form of :data:`FIXTURE_FORMS`]) each, on every channel.  counter : {(direction, h): co-rotating power
    fraction} overriding the wheel's.  speed_sidebands : (direction, h, per_rev δ, depth m): lines at (h ± δ)·Ω of
    (m/2)·C·Ω² co-rotating.  law : (direction, h, exponent p): that line's amplitude C·Ω_mid²·(Ω/Ω_mid)^p.  Noise:
    white, std ``noise`` × the top-speed radial fundamental of its group (forces / torques)."""
    from rwadist.data import Run, SteadyTest

    rng = np.random.default_rng(seed)
    omegas = np.asarray(speeds_rpm, float) * 2 * np.pi / 60
    t = np.arange(int(n_samples)) / sample_rate
    w_top, w_mid = omegas.max(), float(np.median(omegas))
    fund = {d: wheel.C(d, 1.0) * w_top**2 for d in ("radial_force", "radial_torque")}
    lines = list(wheel.lines)
    if speed_sidebands is not None:
        d, h, dl, m = speed_sidebands
        lines += [(d, h - dl, 0.5 * m * wheel.C(d, h), 1.0), (d, h + dl, 0.5 * m * wheel.C(d, h), 1.0)]
    runs = []
    for i, om in enumerate(omegas):
        sig = {ch: np.zeros(t.size) for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        beta = rng.uniform(0, 2 * np.pi)
        for d, h, c_si, frac in lines:
            f_hz = h * om / (2 * np.pi)
            phase = rng.uniform(0, 2 * np.pi)
            if f_hz >= 0.45 * sample_rate:
                continue
            amp = c_si * om**2
            if law is not None and law[0] == d and abs(law[1] - h) < 1e-9:
                amp = c_si * w_mid**2 * (om / w_mid) ** law[2]
            fix = _fixture(f_hz, fixtures)
            e = np.exp(1j * h * om * t)
            if d == "axial_force":
                k, c, m = wheel.kc(d)
                w = h * om
                phasor = (k + 1j * w * c) / (k - m * w**2 + 1j * w * c) * amp * np.exp(1j * phase) * fix
                sig["Fz"] += np.real(phasor * e)
                continue
            fr = frac
            if counter and (d, h) in counter:
                fr = counter[(d, h)]
            if h == 1.0:
                # the two imbalances share one phase per run; a counter part of one is a second load, own phase
                phase = beta + (0.6 if d == "radial_torque" else 0.0)
            cx, cy = ("Fx", "Fy") if d == "radial_force" else ("Tx", "Ty")
            phase2 = rng.uniform(0, 2 * np.pi)
            for sgn, share in ((+1, np.sqrt(fr)), (-1, np.sqrt(1 - fr))):
                if share == 0:
                    continue
                a = share * amp * np.exp(1j * (phase if sgn > 0 else phase2))
                X, Y = _reaction(wheel, d, a, sgn * h * om, om)
                sig[cx] += np.real(X * fix * e)
                sig[cy] += np.real(Y * fix * e)
        for ch in sig:
            std = noise * fund["radial_force" if ch.startswith("F") else "radial_torque"]
            sig[ch] += std * rng.standard_normal(t.size)
        runs.append(Run(speed=float(om), sample_rate=float(sample_rate), signals=sig, t0=0.0,
                        name=f"run_{i:04d}.csv"))
    truth = {"modes_hz": wheel.truth_hz, "inertia_ratio": wheel.inertia_ratio, "fixtures": list(fixtures)}
    return SteadyTest(runs=runs, meta={"generator": "tests/standmodes_wheel.py", "wheel": wheel.name}), truth
