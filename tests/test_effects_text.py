"""Each diagnosed effect on one console line with its key numbers and units (issue 14 item 8):
`rwadist model show` lists a model file's effects, `rwadist diagnose` names what it added.  The
numbers are read back from the printed line and compared with the file's values (converted to the
units printed: rpm, mm)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from rwadist import model as model_io
from rwadist.cli import main
from rwadist.effects_text import describe_effect, diagnose_lines
from rwadist.model import Harmonic, WheelModel
from rwadist.schema import EFFECT_KINDS

EFFECTS = [
    {"kind": "missing_harmonic", "direction": "radial_force", "h": 3.5, "C": 1.25e-7},
    {"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": 2.77, "exponent_stderr": 0.04,
     "amplitude_ref": 0.003, "omega_ref_rad_s": 200.0},
    {"kind": "broadband_floor", "channel": ["Fx", "Fy"], "exponent": 1.5, "omega_ref_rad_s": 250.0,
     "f_Hz": [0.0, 40.0, 500.0], "psd_ref": [2e-9, 5e-9, 1e-9]},
    {"kind": "fixed_resonance", "f_Hz": 180.0, "zeta": 0.02, "peak_gain": 4.5, "role": "test_stand",
     "directions": ["radial_force", "axial_force"]},
    {"kind": "cross_coupling", "r_m": [0.0, 0.001, -0.058]},
    {"kind": "sidebands", "direction": "radial_force", "h": 1.0, "f_mod_Hz": 2.5, "depth": 0.12},
    {"kind": "speed_ripple", "f_ripple_Hz": 0.7, "delta_omega_rad_s": 0.5, "omega_ref_rad_s": 150.0},
    {"kind": "counter_rotation", "direction": "radial_force", "h": 1.0, "counter_fraction": 0.3},
    {"kind": "spin_acceleration", "alpha_rad_s2": 0.25},
    {"kind": "suspension_modes", "radial_translation_Hz": 227.7, "rocking_Hz": 54.9, "axial_Hz": 70.0,
     "zeta_radial_translation": 0.01, "zeta_rocking": 0.02, "zeta_axial": 0.015, "inertia_ratio": 1.9},
    {"kind": "speed_sidebands", "direction": "radial_force", "h": 1.0, "h_lower": 0.94, "h_upper": 1.06,
     "per_rev": 0.06, "C_lower": 1e-7, "C_upper": 1.2e-7, "ratio_lower": 0.2, "ratio_upper": 0.24},
    {"kind": "lever_arm_noise", "r_m": [0.0, 0.0, -0.06], "noise_transfer": 1.009, "noise_transfer_stderr": 0.005,
     "floor_rise_dB": {"Tx": 2.52, "Ty": 2.54}},
]

#: per kind, numbers that must appear on its line (in the printed units)
EXPECTED = {"missing_harmonic": ["3.5", "1.250e-07 kg·m"], "amplitude_law": ["2.77", "±0.04", "0.003 N", "1910 rpm"],
            "broadband_floor": ["Fx Fy", "1.5", "26–440 Hz", "5e-09", "at 40 Hz"], "fixed_resonance": ["test stand", "180.00 Hz",
            "0.02", "4.5", "radial force, axial force"], "cross_coupling": ["(0.0, 1.0, -58.0) mm"],
            "sidebands": ["±2.5 Hz", "0.12"], "speed_ripple": ["0.7 Hz", "4.77 rpm", "1432 rpm"],
            "counter_rotation": ["q 0.3"], "spin_acceleration": ["0.25 rad/s²"],
            "suspension_modes": ["227.7 Hz", "54.9 Hz", "70 Hz", "1.9"],
            "speed_sidebands": ["h 0.94 and 1.06", "±0.06", "0.2 and 0.24"],
            "lever_arm_noise": ["1.01", "±0.005", "Tx +2.52 dB", "Ty +2.54 dB"]}


def test_every_known_kind_has_its_numbers_on_one_line():
    assert set(EXPECTED) == {e["kind"] for e in EFFECTS} <= set(EFFECT_KINDS)
    for e in EFFECTS:
        line = describe_effect(e)
        assert "\n" not in line and line.startswith(e["kind"].replace("_", " ") + ":")
        for token in EXPECTED[e["kind"]]:
            assert token in line, (token, line)
        assert "[" not in line and "'" not in line and "_" not in line.split(":", 1)[1].replace("I_zz/I_rr", "")
    # a kind from a newer file: its scalar fields, still one line
    assert describe_effect({"kind": "new_thing", "f_Hz": 12.5, "knots": [1, 2]}) == "new thing: f Hz 12.5"


def test_speed_ripple_rpm_matches_the_conversion():
    line = describe_effect(EFFECTS[6])
    rpm = float(re.search(r"amplitude ([\d.]+) rpm", line).group(1))
    assert rpm == pytest.approx(0.5 * 60 / (2 * np.pi), rel=1e-3)


def test_model_show_lists_the_effects(tmp_path, capsys):
    m = WheelModel(name="w", empirical={"radial_force": [Harmonic(h=1.0, C=1e-6)]}, effects=list(EFFECTS))
    path = tmp_path / "m.json"
    model_io.save(m, path)
    assert main(["model", "show", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    at = out.index(f"effects ({len(EFFECTS)}):")
    lines = out[at + 1:]
    assert len(lines) == len(EFFECTS)
    for i, (line, e) in enumerate(zip(lines, EFFECTS)):
        assert line.startswith(f"  {i + 1}. {e['kind'].replace('_', ' ')}:")
    model_io.save(WheelModel(name="w", empirical={"radial_force": [Harmonic(h=1.0, C=1e-6)]}), path)
    assert main(["model", "show", str(path)]) == 0
    assert "effects: none" in capsys.readouterr().out


def test_model_show_gives_each_radial_line_its_sense(tmp_path, capsys):
    """The table and the CSV say the rotation sense every consumer reads (a radial line without one: co)."""
    m = WheelModel(name="w", empirical={"radial_force": [Harmonic(h=1.0, C=1e-6),
                                                         Harmonic(h=2.5, C=2e-7, sense="counter")],
                                        "radial_torque": [Harmonic(h=3.1, C=1e-8, sense="planar")],
                                        "axial_force": [Harmonic(h=2.0, C=3e-7)]})
    path = tmp_path / "m.json"
    model_io.save(m, path)
    assert main(["model", "show", str(path)]) == 0
    rows = {tuple(line.split()[:3]) for line in capsys.readouterr().out.splitlines()[2:6]}
    assert rows == {("radial_force", "1.000", "co"), ("radial_force", "2.500", "counter"),
                    ("radial_torque", "3.100", "planar"), ("axial_force", "2.000", "3.0000e-07")}
    assert main(["model", "show", str(path), "--format", "csv"]) == 0
    senses = [line.split(",")[-1] for line in capsys.readouterr().out.splitlines()[1:]]
    assert senses == ["co", "counter", "planar", ""]


def test_diagnose_lines_carry_the_held_out_gain():
    e = dict(EFFECTS[3], evidence={"heldout_gain_fraction": 0.118})
    (line,) = diagnose_lines([e])
    assert line.startswith("  + fixed resonance: test stand, 180.00 Hz") and line.endswith("(held-out gain 11.8 %)")
    # above 100 %: an effect's own held-out evidence (trial25's counter rotation read 124 %) is said to be so
    (line,) = diagnose_lines([dict(e, evidence={"heldout_gain_fraction": 1.24})])
    assert line.endswith("(held-out gain 124.0 % of the misplaced power the PSDs show: the effect's own held-out "
                         "evidence reads more than they see)")


def test_counter_rotation_says_its_fraction_is_of_power_and_gives_the_amplitude_ratio():
    """q = abs(a₋)²/(abs(a₊)² + abs(a₋)²): a counter part of a quarter of the co part's amplitude is q = 1/17 (trial12
    read "q 0.0588" for its 25 % counter-rotating line and had to look the definition up)."""
    text = describe_effect({"kind": "counter_rotation", "direction": "radial_force", "h": 1.0,
                            "counter_fraction": 0.25**2 / (1 + 0.25**2)})
    assert "q 0.0588 (power; counter/co amplitude 0.25)" in text
    assert "amplitude" not in describe_effect({"kind": "counter_rotation", "direction": "radial_force", "h": 1.0,
                                               "counter_fraction": 1.0})


def test_a_mode_the_data_do_not_locate_is_said_not_located_not_given_a_frequency():
    """trial20 (outside generator): "rocking at rest 1810 Hz" was printed for a rocking mode at 80 Hz that the fit
    had lost and declared unconstrained; the number is where the fit ended, no finding."""
    modes = dict(next(e for e in EFFECTS if e["kind"] == "suspension_modes"), rocking_Hz=1810.0,
                 unconstrained=["rocking"])
    line = describe_effect(modes)
    assert "rocking at rest not located (the fit ended at 1810 Hz)" in line
    assert "rocking at rest 1810" not in line and "ζ 0.02)" not in line    # its damping is no finding either
    assert "radial translation 227.7 Hz (ζ 0.01)" in line and "axial 70 Hz (ζ 0.015)" in line
    # the inertia ratio is the split of the rocking's whirls (trial21 printed "I_zz/I_rr 1.21" for a lost rocking)
    assert "I_zz/I_rr not located" in line and "1.9" not in line


def test_a_held_damping_is_said_held_with_the_range_the_data_allow():
    """A located mode whose damping the data do not measure (zeta_<mode> in unconstrained, zeta_bounds): its frequency
    is a finding, its held ζ is not; the range is."""
    modes = dict(next(e for e in EFFECTS if e["kind"] == "suspension_modes"), unconstrained=["zeta_rocking"],
                 zeta_bounds={"rocking": [5e-5, 0.0167]})
    line = describe_effect(modes)
    assert "rocking at rest 54.9 Hz (ζ not constrained by the data: held, 5e-05-0.017 allowed)" in line
    assert "I_zz/I_rr 1.9" in line and "not located" not in line


def test_a_fixed_resonance_whose_gain_at_its_frequency_is_under_one_is_said_to_be_a_notch():
    """trial 30b: a 'test stand' of peak gain 0.271 (fitted to bearing lines whose ratios slip with speed) read as a
    resonance; |H(f_r)| < 1 attenuates the lines there, and the line says so.  A gain over 1 reads as before."""
    e = dict(EFFECTS[3], evidence={"heldout_gain_fraction": 0.069})
    (line,) = diagnose_lines([dict(e, peak_gain=0.271)])
    assert "peak gain 0.271 (under 1: a notch, the lines attenuated there)" in line
    (line,) = diagnose_lines([dict(e, peak_gain=1.5)])
    assert "notch" not in line and "peak gain 1.5," in line
