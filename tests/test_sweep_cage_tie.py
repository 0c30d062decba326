"""A wheel whose only lines are its imbalance and its bearing's, read on a sweep without a speed column.

Session 64's new-user trial (nuA): a hard-mounted rigid wheel, a 1x line in the radial force and torque, its
bearing's cage at 0.4137 and ball-pass lines at 3.6871 and 2 x 3.6871, no integer harmonic, every radial line
co-rotating.  The 1x and the cage tie for the 1x line (one integer multiple each) and the lowest was taken: every speed
2.42x low, every h 2.42x high in the model `rwadist fit` wrote.  Generated here with numpy alone (phases integrated from
the speed, C·Ω² amplitudes, 1 % white noise), not with rwadist's physics; the truth is this file's line list.  The
fit report's summary.md says how the speed was obtained and that the lines alone cannot settle the tie.
"""
import json

import numpy as np
import pytest

from rwadist.cli import main

#: (direction, h, C) of the wheel: C in N/(rad/s)² (forces) or N·m/(rad/s)² (torques)
LINES = (("radial_force", 1.0, 2.2e-6), ("radial_force", 0.4137, 2.0e-7), ("radial_force", 3.6871, 4.5e-7),
         ("radial_force", 7.3742, 1.6e-7), ("radial_torque", 1.0, 1.4e-7), ("radial_torque", 0.4137, 2.5e-8),
         ("radial_torque", 3.6871, 5.0e-8), ("axial_force", 0.4137, 1.2e-7), ("axial_force", 3.6871, 3.0e-7),
         ("axial_force", 7.3742, 1.3e-7))
CHANNELS = {"radial_force": ("Fx", "Fy"), "radial_torque": ("Tx", "Ty"), "axial_force": ("Fz",)}


def _run_up(path, rpm0=600.0, rpm1=4800.0, seconds=24.0, fs=4000.0, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    w0, alpha = rpm0 * np.pi / 30, (rpm1 - rpm0) * np.pi / 30 / seconds
    w, theta = w0 + alpha * t, w0 * t + 0.5 * alpha * t**2
    sig = {c: np.zeros(t.size) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
    for d, h, C in LINES:
        arg = h * theta + rng.uniform(0, 2 * np.pi)
        chans = CHANNELS[d]
        sig[chans[0]] += C * w**2 * np.cos(arg)
        if len(chans) == 2:                                     # co-rotating: y a quarter turn behind x
            sig[chans[1]] += C * w**2 * np.sin(arg)
    rms = {c: np.sqrt(np.mean(x**2)) for c, x in sig.items()}
    rms["Tz"] = rms["Tx"]
    cols = [t] + [sig[c] + 0.01 * rms[c] * rng.standard_normal(t.size) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")]
    np.savetxt(path, np.column_stack(cols), delimiter=",", fmt=["%.7f"] + ["%.8e"] * 6,
               header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm", comments="")
    return path


@pytest.mark.slow
def test_the_imbalance_not_its_cage_is_the_one_x_line(tmp_path, capsys):
    csv = _run_up(tmp_path / "run_up.csv")
    assert main(["fit", str(csv), "-o", str(tmp_path / "model.json"), "--report", str(tmp_path / "r")]) == 0
    capsys.readouterr()
    # the report says how the speed was read, and that the lines alone cannot settle the tie (on the console only before)
    md = (tmp_path / "r" / "summary.md").read_text()
    speed = md.split("## Speed", 1)[1].split("\n## ", 1)[0]
    assert "speed from the data" in speed and "the 1x line" in speed and "agree with the speed" in speed
    assert "cannot tell the 1x line" in speed and "h 0.4137" in speed and "tach" in speed
    model = json.loads((tmp_path / "model.json").read_text())
    for d, rows in model["empirical"].items():
        truth = np.array([h for dd, h, _ in LINES if dd == d])
        for r in rows:
            assert np.min(np.abs(r["h"] / truth - 1)) < 0.002, (d, r["h"], truth)
    ones = [r for r in model["empirical"]["radial_force"] if abs(r["h"] - 1) < 0.002]
    assert len(ones) == 1 and ones[0]["C"] == pytest.approx(2.2e-6, rel=0.05)
