"""Third-party load-cell data: a disk on a shaft with two bearings, computed with ROSS (issue 14).

ROSS (ross-rotordynamics, finite-element rotordynamics) is not a project dependency.  Run this
script where ROSS imports (ROSS 2.3 needs ``plotly<6``)::

    python3 -m venv /tmp/rossvenv
    /tmp/rossvenv/bin/pip install ross-rotordynamics "plotly<6"
    /tmp/rossvenv/bin/python benchmarks/ross_loadcell.py

It writes ``tests/data/ross_loadcell.json`` (~0.2 MB): for each steady speed and each forcing line,
the complex phasors of the six load-cell channels, and ROSS's own Campbell diagram (run_modal) at
three speeds.  ``tests/ross_dataset.py`` turns the phasors into load-cell time series (random line
phases per run, white noise), so only ROSS's steady-state response is stored, not the samples.

Model: a rigid disk (m = 10.6 kg, Ip = ½MR², Id = ¼MR², R = 19.65 cm) at the middle node of a
two-element shaft, bearings at ±2.37 cm with k/2 = 10.85 N/µm and c/2 = 2533.5 N·s/m in x and y
(thesis Table 4.2) and an axial stiffness putting the axial mode at 70 Hz (ζ 0.05); shaft
practically rigid and massless (E = 2e12 Pa, ρ = 1e-6 kg/m³, 0.1 m diameter).  Gyroscopics: ROSS
assembles the disk's gyroscopic matrix G and the response at spin Ω and excitation frequency ν is
ROSS's ``Rotor.transfer_matrix(speed=Ω, frequency=ν)`` = (K − ν²M + iν(C + ΩG))⁻¹.

Forcing (all at the disk or its bearing nodes):

* an unbalance at the disk (static, 0.38 g·cm) and a couple of two unbalances at the bearing nodes in
  opposite phase (dynamic, 24.77 g·cm², 0.6 rad ahead), ROSS's own unbalance convention
  (``Rotor.unbalance_force_over_time``: Fx = m·e·Ω²·cos φ, Fy = m·e·Ω²·sin φ, which defines the
  co-rotating sense: x towards y for Ω > 0);
* rotating forces and moments at the disk at h = 2 (against the spin), 3, 4.42 and 5.57 (with the
  spin), and axial forces at h = 1, 1.98, 4 -- E-wheel-like coefficients (thesis Table 3.4).

Load cell: the bearings' reactions on the ground, F_i = (k + iνc)·q_i per bearing i, summed, and
their moment about the disk centre (Tx = −Σ z_i F_y,i, Ty = Σ z_i F_x,i, z_i from the disk), so
the torque reference is the rotor centre (height 0).  Axial: the axial bearing reaction.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import ross as rs

M, R = 10.6, 0.1965
K, D_K, C = 21.7e6, 0.0237, 5067.0
K_Z = M * (2 * np.pi * 70.0) ** 2
C_Z = 2 * 0.05 * np.sqrt(K_Z * M)
I_P, I_D = 0.5 * M * R**2, 0.25 * M * R**2
C_UNIT = 1e-7 * (60 / (2 * np.pi)) ** 2          # thesis N/rpm² ×1e-7 -> SI per (rad/s)²
U_S, U_D, U_PHASE = 0.38e-5, 24.77e-7, 0.6        # kg·m, kg·m², rad
# (direction, h, C in thesis units, +1 with the spin / -1 against)
HARMONICS = [("radial_force", 2.0, 0.0832, -1), ("radial_torque", 2.0, 0.0609, -1),
             ("radial_force", 3.0, 0.0543, +1), ("radial_torque", 3.0, 0.0242, +1),
             ("radial_force", 4.42, 0.1097, +1), ("radial_torque", 4.42, 0.0485, +1),
             ("radial_force", 5.57, 0.0690, +1), ("radial_torque", 5.58, 0.0498, +1),
             ("axial_force", 1.0, 0.3038, +1), ("axial_force", 1.98, 0.2818, +1), ("axial_force", 4.0, 0.0685, +1)]
SPEEDS_RPM = np.linspace(300.0, 3000.0, 60)
CAMPBELL_RPM = [1000.0, 2000.0, 3000.0]
OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ross_loadcell.json"
NDOF = 6                                          # ROSS 2.x: x, y, z, alpha, beta, theta per node


def build_rotor():
    mat = rs.Material(name="rigid_massless", rho=1e-6, E=2e12, G_s=8e11)
    shaft = [rs.ShaftElement(L=D_K, idl=0.0, odl=0.1, material=mat, shear_effects=False,
                             rotary_inertia=False, gyroscopic=False) for _ in range(2)]
    disk = rs.DiskElement(n=1, m=M, Id=I_D, Ip=I_P)
    bearings = [rs.BearingElement(n=0, kxx=K / 2, cxx=C / 2, kzz=K_Z, czz=C_Z),
                rs.BearingElement(n=2, kxx=K / 2, cxx=C / 2)]
    return rs.Rotor(shaft, [disk], bearings)


def load_cell(rotor, q, nu):
    """(Fx, Fy, Fz, Tx, Ty, Tz) phasors of the bearing reactions for the response phasor vector q."""
    z = np.asarray(rotor.nodes_pos, float)
    zc = z[1]
    out = np.zeros(6, complex)
    for n, kz, cz in ((0, K_Z, C_Z), (2, 0.0, 0.0)):
        fx = (K / 2 + 1j * nu * C / 2) * q[n * NDOF + 0]
        fy = (K / 2 + 1j * nu * C / 2) * q[n * NDOF + 1]
        out[0] += fx
        out[1] += fy
        out[2] += (kz + 1j * nu * cz) * q[n * NDOF + 2]
        out[3] += -(z[n] - zc) * fy
        out[4] += (z[n] - zc) * fx
    return out


def rotating(dof_x, dof_y, amp, sense, ndof):
    """Force vector of a load amp·(cos, sin)(±νt) on DOFs (dof_x, dof_y): phasors (1, ∓i)·amp."""
    f = np.zeros(ndof, complex)
    f[dof_x] += amp
    f[dof_y] += -1j * sense * amp
    return f


def main():
    rotor = build_rotor()
    ndof = rotor.ndof
    lines = [{"direction": "radial_force", "h": 1.0, "sense": "co", "imbalance": True},
             {"direction": "radial_torque", "h": 1.0, "sense": "co", "imbalance": True}]
    lines += [{"direction": d, "h": h, "sense": "co" if s > 0 else "counter", "imbalance": False}
              for d, h, _, s in HARMONICS]
    phasors = np.zeros((len(lines), SPEEDS_RPM.size, 6), complex)
    for k, rpm in enumerate(SPEEDS_RPM):
        om = rpm * 2 * np.pi / 60
        # unbalances (ROSS's convention), one transfer matrix at nu = Ω
        H = rotor.transfer_matrix(speed=om, frequency=om)
        f_s = rotating(1 * NDOF, 1 * NDOF + 1, U_S * om**2, +1, ndof)
        couple = U_D / (2 * D_K) * om**2 * np.exp(1j * U_PHASE)   # ± at the bearing nodes, 2·D_K apart
        f_d = rotating(2 * NDOF, 2 * NDOF + 1, couple, +1, ndof) - rotating(0, 1, couple, +1, ndof)
        phasors[0, k] = load_cell(rotor, H @ f_s, om)
        phasors[1, k] = load_cell(rotor, H @ f_d, om)
        for j, (d, h, c_th, s) in enumerate(HARMONICS, start=2):
            nu = h * om
            amp = c_th * C_UNIT * om**2
            H = rotor.transfer_matrix(speed=om, frequency=nu)
            if d == "radial_force":
                f = rotating(NDOF, NDOF + 1, amp, s, ndof)
            elif d == "radial_torque":
                f = rotating(NDOF + 3, NDOF + 4, amp, s, ndof)
            else:
                f = np.zeros(ndof, complex)
                f[NDOF + 2] = amp
            phasors[j, k] = load_cell(rotor, H @ f, nu)
    campbell = []
    for rpm in CAMPBELL_RPM:
        modal = rotor.run_modal(speed=rpm * 2 * np.pi / 60, num_modes=16)
        wn = np.asarray(modal.wn, float) / (2 * np.pi)
        whirl = list(modal.whirl_direction())
        lateral = [(f, w) for f, w in zip(wn, whirl) if f < 1e3]
        lateral.sort()
        row = {"speed_rpm": rpm, "modes_hz": [f for f, _ in lateral], "whirl": [w for _, w in lateral]}
        campbell.append(row)
        print(f"{rpm:6.0f} rpm: " + ", ".join(f"{f:.4f} Hz {w}" for f, w in lateral))
    doc = {"source": f"ROSS {rs.__version__}, benchmarks/ross_loadcell.py",
           "channels": ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"],
           "speeds_rpm": SPEEDS_RPM.tolist(),
           "lines": [dict(ln, phasors_re=phasors[j].real.tolist(), phasors_im=phasors[j].imag.tolist())
                     for j, ln in enumerate(lines)],
           "campbell": campbell,
           "rotor": {"mass_kg": M, "radius_m": R, "I_p": I_P, "I_d": I_D, "k_N_m": K, "c_N_s_m": C,
                     "bearing_half_span_m": D_K, "k_z_N_m": K_Z, "c_z_N_s_m": C_Z}}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(doc, indent=None, separators=(",", ":")))
    print("wrote", OUT, f"{OUT.stat().st_size / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
