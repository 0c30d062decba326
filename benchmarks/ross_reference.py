"""Independent whirl-frequency reference for the Ithaco E wheel, computed with ROSS.

ROSS (ross-rotordynamics, a finite-element rotordynamics package) is NOT a project
dependency.  Run this script in its own virtual environment::

    python3 -m venv /tmp/rossvenv
    /tmp/rossvenv/bin/pip install ross-rotordynamics "plotly<6"   # ROSS 2.3 imports fail with plotly 6
    /tmp/rossvenv/bin/python benchmarks/ross_reference.py

It writes ``tests/data/ross_whirl_ithaco_e.csv`` (speed_rpm and the undamped natural
frequencies in Hz of the rocking backward/forward whirl and the radial translation
modes), which ``tests/test_extended.py`` compares with ``rwadist.extended``.

Model (thesis Table 4.2, Fig. 4-1): a rigid disk (m = 10.6 kg, Ip = ½MR², Id = ¼MR²,
R = 19.65 cm) at the middle node of a two-element shaft, bearings at ±d_k = ±2.37 cm,
each with k/2 = 10.85 N/µm in x and y and no damping.  Then the lateral stiffness is k
and the rocking stiffness 2·(k/2)·d_k² = k·d_k².  The shaft is made practically rigid and
massless (E = 2e15 Pa, ρ = 1e-6 kg/m³, 0.1 m diameter): its bending stiffness is ~1e8
times the bearings', so it changes the frequencies by ~1e-8 relative.  ROSS models lateral
dynamics only, so the axial mode is not in the reference.  The parameters are typed here
(not imported from rwadist) so the reference stays independent.
"""
from pathlib import Path

import numpy as np
import ross as rs

M, R = 10.6, 0.1965
K, D_K = 21.7e6, 0.0237
I_P, I_D = 0.5 * M * R**2, 0.25 * M * R**2
OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "ross_whirl_ithaco_e.csv"


def build_rotor():
    mat = rs.Material(name="rigid_massless", rho=1e-6, E=2e15, G_s=8e14)
    shaft = [rs.ShaftElement(L=D_K, idl=0.0, odl=0.1, material=mat, shear_effects=False,
                             rotary_inertia=False, gyroscopic=False) for _ in range(2)]
    disk = rs.DiskElement(n=1, m=M, Id=I_D, Ip=I_P)
    bearings = [rs.BearingElement(n=n, kxx=K / 2, kyy=K / 2, cxx=0.0, cyy=0.0) for n in (0, 2)]
    return rs.Rotor(shaft, [disk], bearings)


def main():
    rotor = build_rotor()
    rpm = np.arange(0.0, 3001.0, 100.0)
    rows = []
    for n in rpm:
        modal = rotor.run_modal(speed=n * 2 * np.pi / 60, num_modes=12)
        wn = np.asarray(modal.wn, dtype=float) / (2 * np.pi)
        whirl = list(modal.whirl_direction())
        low = np.argsort(wn)[:4]          # two rocking whirls, then the translation pair
        f = wn[low]
        w = [whirl[i] for i in low]
        if n > 0:
            assert w[0] == "Backward" and w[1] == "Forward", (n, f, w)
        rows.append((n, f[0], f[1], 0.5 * (f[2] + f[3])))
        print(f"{n:6.0f} rpm  backward {f[0]:9.4f}  forward {f[1]:9.4f}  translation {f[2]:9.4f} {f[3]:9.4f} Hz  {w}")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with OUT.open("w") as fh:
        fh.write(f"# ROSS {rs.__version__} run_modal, undamped rigid disk on bearings; benchmarks/ross_reference.py\n")
        fh.write("speed_rpm,rocking_backward_Hz,rocking_forward_Hz,radial_translation_Hz\n")
        for r in rows:
            fh.write(",".join(f"{v:.10g}" for v in r) + "\n")
    print("wrote", OUT)


if __name__ == "__main__":
    main()
