"""An E-like wheel on a load cell, generated WITHOUT rwadist's physics (test helper).

rwadist.extended writes the suspension in complex coordinates (ψ = θx + iθy, one complex
equation per mode).  This generator writes the same rigid rotor on springs the textbook way, in
real coordinates, and solves the harmonic balance of each line as a 2x2 (radial) or 1x1 (axial)
complex linear system:

* radial translation  M ẍ + c ẋ + k x = F_x,  same for y;
* rocking  I_rr θ̈x + I_zz Ω θ̇y + c_θ θ̇x + k_θ θx = T_x,  I_rr θ̈y − I_zz Ω θ̇x + c_θ θ̇y + k_θ θy = T_y
  (the gyroscopic coupling written out, not the complex-coordinate form);
* axial  M z̈ + c_z ż + k_z z = F_z.

The load cell reads the suspension reaction (k + iωc)·q.  Every line has a random phase per
run (the two imbalances share one), radial lines are split into co- and counter-rotating parts
by a given fraction, and white noise is a fraction of the top-speed fundamental per group
(forces: radial-force fundamental; torques: radial-torque fundamental).  Only numpy; the
physical parameters are typed here (thesis Tables 3.4, 4.2; axial 70 Hz, Table 2.3), not
imported from rwadist, so the data do not share the package's assumptions.
"""
from __future__ import annotations

import numpy as np

C_UNIT = 1e-7 * (60.0 / (2.0 * np.pi)) ** 2          # thesis N/rpm² ×1e-7 -> SI per (rad/s)²
MASS, RADIUS = 10.6, 0.1965
I_ZZ, I_RR = 0.5 * MASS * RADIUS**2, 0.25 * MASS * RADIUS**2
K, C, D = 21.7e6, 5067.0, 0.0237
K_Z = MASS * (2 * np.pi * 70.0) ** 2
C_Z = 2 * 0.05 * np.sqrt(K_Z * MASS)
TRUTH_HZ = {"radial_translation": np.sqrt(K / MASS) / (2 * np.pi),
            "rocking": np.sqrt(K * D**2 / I_RR) / (2 * np.pi),
            "axial": np.sqrt(K_Z / MASS) / (2 * np.pi)}

# (direction, h, C thesis units, co-rotating power fraction); h = 1 radial are the imbalances
E_LINES = [("radial_force", 1.00, 0.4155, 1.0), ("radial_force", 2.00, 0.0832, 0.0),
           ("radial_force", 3.00, 0.0543, 1.0), ("radial_force", 4.00, 0.0621, 1.0),
           ("radial_force", 4.42, 0.1097, 1.0), ("radial_force", 5.37, 0.0542, 1.0),
           ("radial_force", 5.57, 0.0690, 1.0),
           ("radial_torque", 1.00, 0.2205, 1.0), ("radial_torque", 2.00, 0.0609, 0.0),
           ("radial_torque", 3.00, 0.0242, 1.0), ("radial_torque", 4.00, 0.0243, 1.0),
           ("radial_torque", 4.42, 0.0485, 1.0), ("radial_torque", 5.58, 0.0498, 1.0),
           ("axial_force", 1.00, 0.3038, 1.0), ("axial_force", 1.98, 0.2818, 1.0),
           ("axial_force", 2.96, 0.0719, 1.0), ("axial_force", 4.00, 0.0685, 1.0),
           ("axial_force", 4.33, 0.1011, 1.0)]


def _radial_system(direction, w, omega):
    """(Z (2x2 complex) of the EOM at frequency w >= 0, reaction matrix (k + iwc)·I)."""
    if direction == "radial_force":
        m, c, k, g = MASS, C, K, 0.0
    else:
        m, c, k, g = I_RR, C * D**2, K * D**2, I_ZZ * omega
    Z = np.array([[k - m * w**2 + 1j * w * c, 1j * w * g], [-1j * w * g, k - m * w**2 + 1j * w * c]])
    return Z, (k + 1j * w * c)


def _component(direction, a, nu, omega):
    """Reaction phasors (X, Y) at |nu| of the load component a·e^{i nu t} in the x-y plane."""
    w = abs(nu)
    load = np.array([a, -1j * a]) if nu >= 0 else np.array([np.conj(a), 1j * np.conj(a)])
    Z, react = _radial_system(direction, w, omega)
    return react * np.linalg.solve(Z, load)


def generate(speeds_rpm, sample_rate=3840.0, n_samples=8192, noise=0.01, seed=0, lines=E_LINES,
             co_fraction=None):
    """Steady runs as an rwadist SteadyTest; ``co_fraction`` overrides every non-imbalance radial
    line's co-rotating power fraction (e.g. 0.5 for planar loads).  Returns (test, truth dict)."""
    from rwadist.data import Run, SteadyTest

    rng = np.random.default_rng(seed)
    omegas = np.asarray(speeds_rpm, float) * 2 * np.pi / 60
    t = np.arange(int(n_samples)) / sample_rate
    w_top = omegas.max()
    fund = {d: next(c for dd, h, c, _ in lines if dd == d and h == 1.0) * C_UNIT * w_top**2
            for d in ("radial_force", "radial_torque")}
    runs = []
    for i, om in enumerate(omegas):
        sig = {ch: np.zeros(t.size) for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        beta = rng.uniform(0, 2 * np.pi)
        for d, h, c_th, frac in lines:
            f_hz = h * om / (2 * np.pi)
            phase = rng.uniform(0, 2 * np.pi)
            if f_hz >= 0.45 * sample_rate:
                continue
            amp = c_th * C_UNIT * om**2
            if d == "axial_force":
                w = h * om
                Z = K_Z - MASS * w**2 + 1j * w * C_Z
                phasor = (K_Z + 1j * w * C_Z) / Z * amp * np.exp(1j * phase)
                sig["Fz"] += np.real(phasor * np.exp(1j * w * t))
                continue
            if h == 1.0:
                fr, phase = 1.0, beta + (0.6 if d == "radial_torque" else 0.0)
            else:
                fr = frac if co_fraction is None else co_fraction
            cx, cy = ("Fx", "Fy") if d == "radial_force" else ("Tx", "Ty")
            parts = [(+1, np.sqrt(fr)), (-1, np.sqrt(1 - fr))]
            phase2 = rng.uniform(0, 2 * np.pi)
            for sgn, share in parts:
                if share == 0:
                    continue
                a = share * amp * np.exp(1j * (phase if sgn > 0 else phase2))
                X, Y = _component(d, a, sgn * h * om, om)
                e = np.exp(1j * h * om * t)
                sig[cx] += np.real(X * e)
                sig[cy] += np.real(Y * e)
        for ch in sig:
            std = noise * fund["radial_force" if ch.startswith("F") else "radial_torque"]
            sig[ch] += std * rng.standard_normal(t.size)
        runs.append(Run(speed=float(om), sample_rate=float(sample_rate), signals=sig, t0=0.0, name=f"run_{i:04d}.csv"))
    return SteadyTest(runs=runs, meta={"generator": "tests/independent_wheel.py"}), dict(TRUTH_HZ)
