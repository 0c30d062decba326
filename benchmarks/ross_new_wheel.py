"""Third-party load-cell data of a wheel the project was never tuned on, computed with ROSS (issue 33).

The issue's "new wheel": a 4.2 kg rotor with I_zz/I_rr = 1.56, hard-mounted suspension modes near
140 Hz (radial translation), 95 Hz (rocking) and 310 Hz (axial), bearing-like non-integer lines
(a counter-rotating cage line at h 0.4, ball passes at 3.08 and 4.92 and the outer race's second
multiple 6.16), 600-6000 rpm.  ROSS (ross-rotordynamics) computes every steady-state response, as in
``benchmarks/ross_loadcell.py`` (same load cell: the bearings' reactions on the ground and their moment
about the rotor centre), so neither the gyroscopic whirl nor the modes' amplification comes from
rwadist's own equations.  With ``--fixture HZ`` the two bearings sit on two point masses of
``--fixture-mass`` kg each, each on a spring to the ground (the load cell) with damping ratio 0.03:
a test stand between the wheel and the load cell, in ROSS's coupled equations (the wheel's modes
then move too; the document stores ROSS's modes with and without the stand).  The wheel itself is a set of
flags (``--mass --i-ratio --radius --modes --zeta --rpm``; defaults: the new wheel above), so a family of wheels
comes from the same third-party equations; tests/data/ross_wheel_D.json is::

    ross_new_wheel.py ross_wheel_D.json --mass 8 --i-ratio 1.9 --radius 0.1 --modes 150 70 120 --zeta 0.015 --rpm 400 4500 40

ROSS is not a project dependency.  Run where it imports (ROSS 2.3 needs ``plotly<6``; run from a
folder without a ``librefprop.so``)::

    python3 -m venv /tmp/rossvenv && /tmp/rossvenv/bin/pip install ross-rotordynamics "plotly<6"
    /tmp/rossvenv/bin/python benchmarks/ross_new_wheel.py OUT.json [--fixture 230 --fixture-mass 40]

then write load-cell records and diagnose them with the command a user types::

    python tests/ross_dataset.py DATA --doc OUT.json --sample-rate 5000 --samples 8192
    rwadist diagnose DATA -o REPORT
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import ross as rs
from ross_loadcell import NDOF, rotating  # the same ROSS conventions (DOF order, rotating-load phasors)

# The new wheel (the stored documents); every value a flag, so a family of wheels can be made.
DEFAULTS = {"mass": 4.2, "i_ratio": 1.56, "radius": 0.12, "translation": 140.0, "rocking": 95.0,
            "axial": 310.0, "zeta": 0.02, "rpm": (600.0, 6000.0, 40)}
U_S, U_D, U_PHASE = 0.5e-5, 2.0e-6, 1.1            # kg·m, kg·m², rad
# (direction, h, C in SI per (rad/s)², +1 with the spin / -1 against)
HARMONICS = [("radial_force", 0.4, 0.5e-6, -1), ("radial_force", 3.08, 1.2e-6, +1),
             ("radial_torque", 3.08, 0.6e-7, +1), ("radial_force", 4.92, 0.9e-6, +1),
             ("radial_torque", 4.92, 0.4e-7, +1), ("radial_force", 6.16, 0.3e-6, +1),
             ("axial_force", 1.0, 1.0e-6, +1), ("axial_force", 3.08, 0.5e-6, +1)]
ZETA_FIXTURE = 0.03


class Wheel:
    """The rotor's constants (SI) derived from the flags: stiffness from each mode's frequency."""

    def __init__(self, mass, i_ratio, radius, translation, rocking, axial, zeta):
        self.M, self.I_RATIO, self.R, self.ZETA = mass, i_ratio, radius, zeta
        self.F_TRANS, self.F_ROCK, self.F_AXIAL = translation, rocking, axial
        self.I_P = 0.5 * mass * radius**2                       # I_zz = ½·M·R²
        self.I_D = self.I_P / i_ratio
        self.K = mass * (2 * np.pi * translation) ** 2          # both bearings together, N/m
        self.D_K = np.sqrt(self.I_D * (2 * np.pi * rocking) ** 2 / self.K)  # K·D_K² = rocking stiffness
        self.C = 2 * zeta * np.sqrt(self.K * mass)
        self.K_Z = mass * (2 * np.pi * axial) ** 2
        self.C_Z = 2 * zeta * np.sqrt(self.K_Z * mass)


def build_rotor(w, fixture_hz=None, fixture_mass=40.0):
    mat = rs.Material(name="rigid_massless", rho=1e-6, E=2e12, G_s=8e11)
    shaft = [rs.ShaftElement(L=w.D_K, idl=0.0, odl=0.1, material=mat, shear_effects=False,
                             rotary_inertia=False, gyroscopic=False) for _ in range(2)]
    disk = rs.DiskElement(n=1, m=w.M, Id=w.I_D, Ip=w.I_P)
    if fixture_hz is None:
        bearings = [rs.BearingElement(n=0, kxx=w.K / 2, cxx=w.C / 2, kzz=w.K_Z, czz=w.C_Z),
                    rs.BearingElement(n=2, kxx=w.K / 2, cxx=w.C / 2)]
        return rs.Rotor(shaft, [disk], bearings), None
    k_f = fixture_mass * (2 * np.pi * fixture_hz) ** 2
    c_f = 2 * ZETA_FIXTURE * np.sqrt(k_f * fixture_mass)
    bearings = [rs.BearingElement(n=0, kxx=w.K / 2, cxx=w.C / 2, kzz=w.K_Z, czz=w.C_Z, n_link=3),
                rs.BearingElement(n=2, kxx=w.K / 2, cxx=w.C / 2, n_link=4),
                rs.BearingElement(n=3, kxx=k_f, cxx=c_f, kzz=k_f, czz=c_f),
                rs.BearingElement(n=4, kxx=k_f, cxx=c_f, kzz=k_f, czz=c_f)]
    masses = [rs.PointMass(n=3, m=fixture_mass), rs.PointMass(n=4, m=fixture_mass)]
    return rs.Rotor(shaft, [disk], bearings, point_mass_elements=masses), (k_f, c_f)


def load_cell(w, rotor, q, nu, fixture):
    """(Fx, Fy, Fz, Tx, Ty, Tz) phasors of the reactions on the ground for the response phasors q."""
    z = np.asarray(rotor.nodes_pos, float)
    zc = z[1]
    out = np.zeros(6, complex)
    for shaft_node, support in ((0, 3), (2, 4)):
        if fixture is None:       # the bearing itself stands on the load cell
            kx, ky = w.K / 2 + 1j * nu * w.C / 2, w.K / 2 + 1j * nu * w.C / 2
            kz = (w.K_Z + 1j * nu * w.C_Z) if shaft_node == 0 else 0.0
            ix, iy, iz = (shaft_node * NDOF + k for k in range(3))
        else:                     # the stand's spring stands on it
            kx = ky = kz = fixture[0] + 1j * nu * fixture[1]
            idx = rotor.point_mass_elements[support - 3].dof_global_index
            ix, iy, iz = idx[f"x_{support}"], idx[f"y_{support}"], idx[f"z_{support}"]
        fx, fy = kx * q[ix], ky * q[iy]
        out[0] += fx
        out[1] += fy
        out[2] += kz * q[iz]
        out[3] += -(z[shaft_node] - zc) * fy
        out[4] += (z[shaft_node] - zc) * fx
    return out


def lateral_modes(rotor, rpm):
    modal = rotor.run_modal(speed=rpm * 2 * np.pi / 60, num_modes=24)
    wn = np.asarray(modal.wn, float) / (2 * np.pi)
    whirl = list(modal.whirl_direction())
    return sorted((float(f), w) for f, w in zip(wn, whirl) if f < 2e3)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--fixture", type=float, default=None, help="test-stand resonance, Hz (default: none)")
    ap.add_argument("--fixture-mass", type=float, default=40.0, help="each stand mass, kg")
    ap.add_argument("--counter-fundamental", type=float, default=0.0,
                    help="a counter-rotating force at h 1 on the rotor, a fraction of the static imbalance (default 0)")
    ap.add_argument("--mass", type=float, default=DEFAULTS["mass"], help="rotor mass, kg")
    ap.add_argument("--i-ratio", type=float, default=DEFAULTS["i_ratio"], help="I_zz / I_rr")
    ap.add_argument("--radius", type=float, default=DEFAULTS["radius"], help="m: I_zz = ½·mass·radius²")
    ap.add_argument("--modes", type=float, nargs=3, metavar=("TRANSLATION", "ROCKING", "AXIAL"),
                    default=[DEFAULTS[k] for k in ("translation", "rocking", "axial")],
                    help="hard-mounted suspension modes at rest, Hz")
    ap.add_argument("--zeta", type=float, default=DEFAULTS["zeta"], help="every bearing's damping ratio")
    ap.add_argument("--rpm", type=float, nargs=3, metavar=("FROM", "TO", "N"), default=list(DEFAULTS["rpm"]),
                    help="speeds: N evenly spaced from FROM to TO rpm")
    args = ap.parse_args(argv)
    w = Wheel(args.mass, args.i_ratio, args.radius, *args.modes, args.zeta)
    speeds_rpm = np.linspace(args.rpm[0], args.rpm[1], int(args.rpm[2]))
    rotor, fixture = build_rotor(w, args.fixture, args.fixture_mass)
    harmonics = list(HARMONICS)
    if args.counter_fundamental:
        harmonics.append(("radial_force", 1.0, args.counter_fundamental * U_S, -1))
    rigid, _ = build_rotor(w, None)
    ndof = rotor.ndof
    lines = [{"direction": "radial_force", "h": 1.0, "sense": "co", "imbalance": True},
             {"direction": "radial_torque", "h": 1.0, "sense": "co", "imbalance": True}]
    lines += [{"direction": d, "h": h, "sense": "co" if s > 0 else "counter", "imbalance": False, "C": c}
              for d, h, c, s in harmonics]
    phasors = np.zeros((len(lines), speeds_rpm.size, 6), complex)
    for k, rpm in enumerate(speeds_rpm):
        om = rpm * 2 * np.pi / 60
        H = rotor.transfer_matrix(speed=om, frequency=om)
        f_s = rotating(1 * NDOF, 1 * NDOF + 1, U_S * om**2, +1, ndof)
        couple = U_D / (2 * w.D_K) * om**2 * np.exp(1j * U_PHASE)
        f_d = rotating(2 * NDOF, 2 * NDOF + 1, couple, +1, ndof) - rotating(0, 1, couple, +1, ndof)
        phasors[0, k] = load_cell(w, rotor, H @ f_s, om, fixture)
        phasors[1, k] = load_cell(w, rotor, H @ f_d, om, fixture)
        for j, (d, h, c, s) in enumerate(harmonics, start=2):
            nu = h * om
            amp = c * om**2
            H = rotor.transfer_matrix(speed=om, frequency=nu)
            if d == "radial_force":
                f = rotating(NDOF, NDOF + 1, amp, s, ndof)
            elif d == "radial_torque":
                f = rotating(NDOF + 3, NDOF + 4, amp, s, ndof)
            else:
                f = np.zeros(ndof, complex)
                f[NDOF + 2] = amp
            phasors[j, k] = load_cell(w, rotor, H @ f, nu, fixture)
    campbell, rigid_campbell = [], []
    for rpm in (1.0, 0.5 * speeds_rpm[-1], speeds_rpm[-1]):   # at rest, half and top speed
        for rot, rows in ((rotor, campbell), (rigid, rigid_campbell)):
            lat = lateral_modes(rot, rpm)
            rows.append({"speed_rpm": rpm, "modes_hz": [f for f, _ in lat], "whirl": [w for _, w in lat]})
        print(f"{rpm:6.0f} rpm: " + ", ".join(f"{f:.2f} {w[0]}" for f, w in lateral_modes(rotor, rpm)))
    doc = {"source": f"ROSS {rs.__version__}, benchmarks/ross_new_wheel.py",
           "channels": ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"],
           "speeds_rpm": speeds_rpm.tolist(),
           "lines": [dict(ln, phasors_re=phasors[j].real.tolist(), phasors_im=phasors[j].imag.tolist())
                     for j, ln in enumerate(lines)],
           "campbell": campbell, "campbell_hard_mounted": rigid_campbell,
           "truth": {"translation_hz": w.F_TRANS, "rocking_hz": w.F_ROCK, "axial_hz": w.F_AXIAL, "zeta": w.ZETA,
                     "I_zz_over_I_rr": w.I_RATIO, "U_s_kg_m": U_S, "U_d_kg_m2": U_D, "fixture_hz": args.fixture, "fixture_mass_kg": args.fixture_mass,
                     "fixture_zeta": ZETA_FIXTURE if args.fixture else None,
                     "counter_fundamental": args.counter_fundamental},
           "rotor": {"mass_kg": w.M, "radius_m": w.R, "I_p": w.I_P, "I_d": w.I_D, "k_N_m": w.K, "c_N_s_m": w.C,
                     "bearing_half_span_m": w.D_K, "k_z_N_m": w.K_Z, "c_z_N_s_m": w.C_Z}}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc, indent=None, separators=(",", ":")))
    print("wrote", args.out, f"{args.out.stat().st_size / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
