"""``rwadist psd`` writes the envelope's table per line (``<out>_envelope_harmonics.csv``, docs/formats.md section 6): each
line's worst peak amplitude per channel over the wheel's speeds, with the signed speed and the frequency where it
occurs (docs review: :attr:`rwadist.broadband.Envelope.table` was computed and never written).  Checked against the
closed form of hard-mounted lines, C·Ω² at the range's largest |speed|, computed here from the model's coefficients."""
from __future__ import annotations

import csv

import numpy as np
import pytest
from cli_run import run

import rwadist
from rwadist.model import Harmonic, WheelModel, save
from rwadist.psd_files import envelope_harmonics_columns, wheel_names, write_envelope_harmonics_csv
from rwadist.units import CHANNEL_UNIT, CHANNELS, DIRECTION_CHANNELS, rpm_to_rad_s

LINES = {"radial_force": [(1.0, 2e-6), (2.5, 3e-7)], "radial_torque": [(1.0, 5e-7)], "axial_force": [(3.0, 1e-7)],
         "axial_torque": [(4.0, 2e-8)]}


def _rows(path) -> list:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _model(lines=LINES) -> WheelModel:
    return WheelModel(name="wheel-x", empirical={d: [Harmonic(h=h, C=C) for h, C in v] for d, v in lines.items()})


def test_the_worst_amplitude_of_each_line_is_C_omega_squared_at_the_top_speed(capsys, tmp_path):
    """A range of negative speeds: every line peaks at -2400 rpm, h·40 Hz, C·Ω² in its direction's channels, 0 in
    the others (their speed and frequency empty); the file's columns carry their units."""
    save(_model(), tmp_path / "m.json")
    out = tmp_path / "psd.csv"
    code, _, err = run(capsys, "psd", tmp_path / "m.json", "--empirical", "--speed-rpm=-2400:-600", "--n-freq", "257",
                       "-o", out)
    assert code == 0, err
    path = tmp_path / "psd_envelope_harmonics.csv"
    rows = _rows(path)
    assert list(rows[0]) == envelope_harmonics_columns()
    assert list(rows[0])[3:6] == ["Fx_max_N", "Fx_speed_rpm", "Fx_f_Hz"] and list(rows[0])[-3] == "Tz_max_Nm"
    assert "nan" not in path.read_text().lower()
    w_top = float(rpm_to_rad_s(2400.0))
    expected = [(d, h, C) for d in ("radial_force", "radial_torque", "axial_force", "axial_torque")
                for h, C in LINES[d]]
    assert [(r["wheel"], r["source"], float(r["h"])) for r in rows] == [("wheel-x", f"{d} h={h:g}", h)
                                                                      for d, h, _ in expected]
    for r, (d, h, C) in zip(rows, expected):
        for ch in CHANNELS:
            amp, speed, f = (r[f"{ch}_max_{CHANNEL_UNIT[ch]}"], r[f"{ch}_speed_rpm"], r[f"{ch}_f_Hz"])
            if ch in DIRECTION_CHANNELS[d]:
                assert float(amp) == pytest.approx(C * w_top**2, rel=1e-7), (d, h, ch)
                assert (float(speed), float(f)) == (pytest.approx(-2400.0, rel=1e-7), pytest.approx(h * 40.0, rel=1e-7))
            else:
                assert (amp, speed, f) == ("0", "", ""), (d, h, ch)
    # the envelope is the largest of these lines at each frequency: nowhere above their worst amplitude
    env = np.loadtxt(tmp_path / "psd_envelope.csv", delimiter=",", skiprows=1)
    for k, ch in enumerate(CHANNELS):
        worst = max(float(r[f"{ch}_max_{CHANNEL_UNIT[ch]}"]) for r in rows)
        assert env[:, 1 + k].max() <= worst * (1 + 1e-7)


def test_a_set_names_its_wheels_each_over_its_own_speeds(tmp_path):
    """Wheel A (wheel frame = spacecraft frame, 0-3000 rpm) and B (spin axis along x: its radial force on Fy and Fz,
    1000-2000 rpm), one radial-force line each: A's worst at 3000 rpm in Fx and Fy, B's at 2000 rpm in Fy and Fz."""
    C = 2e-6
    m = _model({"radial_force": [(1.0, C)], "radial_torque": [], "axial_force": [], "axial_torque": []})
    along_x = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]
    wheels = [{"name": "A", "model": m, "dcm": np.eye(3).tolist()},
              {"name": "B", "model": m, "dcm": along_x, "speed": {"dist": "uniform", "min_rpm": 1000, "max_rpm": 2000}}]
    res = rwadist.psd(wheels=wheels, speed_rpm=(0, 3000), empirical=True, envelope=True, fmax=60.0, n_freq=601)
    assert wheel_names(res) == ["A", "B"]
    a, b = _rows(write_envelope_harmonics_csv(res.meta["envelope"], tmp_path / "e.csv", wheel_names(res)))
    assert (a["wheel"], b["wheel"]) == ("A", "B")
    for row, top, live, dead in ((a, 3000.0, ("Fx", "Fy"), "Fz"), (b, 2000.0, ("Fy", "Fz"), "Fx")):
        for ch in live:
            assert float(row[f"{ch}_max_N"]) == pytest.approx(C * float(rpm_to_rad_s(top)) ** 2, rel=1e-7)
            assert float(row[f"{ch}_speed_rpm"]) == pytest.approx(top, rel=1e-7)
            assert float(row[f"{ch}_f_Hz"]) == pytest.approx(top / 60.0, rel=1e-7)
        assert (row[f"{dead}_max_N"], row[f"{dead}_speed_rpm"]) == ("0", "")
