"""A numpy generator of steady load-cell runs with a structure mode in the load path whose frequency moves with speed.

Written for tests/test_moving_structure_mode.py, independent of rwadist's physics: each line a phasor C·Ω²·e^{j(hΩt+φ)}
through the suspension's transmissibility (radial translation and axial: (k + jcω)/(k − mω² + jcω); the rocking mode's
co-rotating whirl: (ω0² + 2jζω0ω)/(ω0² − ω² + aΩω + 2jζω0ω)), radial lines co-rotating (x = Re, y = Im), times a
structure mode holding a share μ of the rotor's mass on the chosen channels, H = 1 + μr²/(1 − r² + 2jζr) with
r = f/f_s(rpm), f_s = f0 + slope·rpm (1 below, 1 − μ far above, an antiresonance at f_s/sqrt(1 − μ); a slope of either
sign: rising with speed, tests/test_moving_structure_mode.py, or falling on every channel, a structure under the load
cell, tests/test_moving_stand_reach.py), and white noise; written in the interchange format of docs/formats.md (runs.csv, run_NNNN.csv, meta.json).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

TWO_PI = 2 * np.pi
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
#: a 4.5-kg wheel, I_zz/I_rr 1.45, modes 180 / 95 / 260 Hz, a 9-ball bearing (cage 0.418): (h, C) per direction
WHEEL = dict(f_trans=180.0, z_trans=0.025, f_rock=95.0, z_rock=0.02, ratio=1.45, f_ax=260.0, z_ax=0.03,
             radial_force=((1.0, 4e-6), (2.0, 2.4e-7), (0.418, 1.2e-7), (3.762, 3.2e-7), (5.238, 1.6e-7),
                           (7.524, 8e-8)),
             radial_torque=((1.0, 1.5e-7), (2.0, 7.5e-9), (3.762, 1.8e-8), (5.238, 1.05e-8)),
             axial_force=((1.0, 2e-7), (3.762, 2e-7), (7.524, 6e-8)), axial_torque=((1.0, 1.5e-9), (6.0, 1.5e-9)),
             noise_force=4e-3, noise_torque=4e-4)


def _through(w, f0, zeta):
    w0 = TWO_PI * f0
    return (w0**2 + 2j * zeta * w0 * w) / (w0**2 - w**2 + 2j * zeta * w0 * w)


def _rocking(w, spin, f0, zeta, ratio):
    w0 = TWO_PI * f0
    return (w0**2 + 2j * zeta * w0 * w) / (w0**2 - w**2 + ratio * spin * w + 2j * zeta * w0 * w)


def write_runs(directory, speeds_rpm, seed: int, structure: dict | None = None, sample_rate: float = 4000.0,
               n_samples: int = 8192) -> Path:
    """The runs at ``speeds_rpm`` in ``directory``; ``structure``: {"f0": Hz, "slope": Hz per rpm, "zeta", "mu",
    "channels"} or None (a clean wheel)."""
    rng = np.random.default_rng(seed)
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    t = np.arange(n_samples) / sample_rate
    rows = []
    for i, rpm in enumerate(speeds_rpm):
        spin = TWO_PI * rpm / 60.0
        sig = {c: np.zeros(n_samples) for c in CHANNELS}

        def path(f, chan):
            if structure is None or chan not in structure["channels"]:
                return 1.0
            r = f / (structure["f0"] + structure["slope"] * rpm)
            return 1.0 + structure["mu"] * r**2 / (1.0 - r**2 + 2j * structure["zeta"] * r)

        for direction, (cx, cy) in (("radial_force", ("Fx", "Fy")), ("radial_torque", ("Tx", "Ty"))):
            for h, C in WHEEL[direction]:
                w = h * spin
                T = _through(w, WHEEL["f_trans"], WHEEL["z_trans"]) if direction == "radial_force" else \
                    _rocking(w, spin, WHEEL["f_rock"], WHEEL["z_rock"], WHEEL["ratio"])
                z = C * spin**2 * T * np.exp(1j * (w * t + rng.uniform(0, TWO_PI)))
                f = w / TWO_PI
                sig[cx] += np.real(z * path(f, cx))
                sig[cy] += np.imag(z * path(f, cy))
        for direction, chan in (("axial_force", "Fz"), ("axial_torque", "Tz")):
            for h, C in WHEEL[direction]:
                w = h * spin
                T = _through(w, WHEEL["f_ax"], WHEEL["z_ax"]) if chan == "Fz" else 1.0
                sig[chan] += np.real(C * spin**2 * T * path(w / TWO_PI, chan) * np.exp(1j * (w * t + rng.uniform(0, TWO_PI))))
        for c in CHANNELS:
            sig[c] += rng.standard_normal(n_samples) * (WHEEL["noise_force"] if c[0] == "F" else WHEEL["noise_torque"])
        name = f"run_{i:04d}.csv"
        np.savetxt(d / name, np.column_stack([t] + [sig[c] for c in CHANNELS]), delimiter=",", fmt="%.9g",
                   header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm", comments="")
        rows.append(f"{name},{rpm:.0f}")
    (d / "runs.csv").write_text("file,speed_rpm\n" + "\n".join(rows) + "\n")
    (d / "meta.json").write_text(json.dumps({"sample_rate_hz": sample_rate, "wheel": {"name": "structure-mode wheel"}}))
    return d
