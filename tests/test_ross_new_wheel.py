"""A wheel the project was never tuned on, computed by a third party, diagnosed by the command a user types (issue 33).

ROSS (benchmarks/ross_new_wheel.py, stored in tests/data/ross_new_wheel.json) computes the steady-state load-cell
response of the issue's "new wheel": 4.2 kg, I_zz/I_rr 1.56, hard-mounted modes near 140 / 95 / 310 Hz, bearing-like
lines at h 0.4 (counter-rotating), 3.08, 4.92, 6.16, 600-6000 rpm; written as 5 kHz records by tests/ross_dataset.py.
The truth is ROSS's: its own modal analysis at rest (run_modal) and the forcing it was given, not rwadist's equations.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import ross_dataset as rd  # noqa: E402

DATA = Path(__file__).resolve().parent / "data"


def _diagnosed(doc_name, tmp_path, capsys):
    """(ROSS document, model.json, summary.json) of ``rwadist diagnose DATA -o REPORT`` on the document's records
    (5 kHz, 8192 samples per run)."""
    doc, model, summary, _ = rd.diagnosed(DATA / doc_name, tmp_path, 5000.0)
    return doc, model, summary


@pytest.mark.slow
@pytest.mark.parametrize("doc_name, classes", [("ross_new_wheel.json", ["suspension_modes"]),
                                               ("ross_new_wheel_counter30.json", ["suspension_modes", "counter_rotation"]),
                                               ("ross_wheel_D.json", ["suspension_modes"])])
def test_new_wheel_from_ross_default_command_gives_its_modes_lines_and_nothing_else(tmp_path, capsys, doc_name, classes):
    """Clean, and with a counter-rotating force on the fundamental (0.3 of the static imbalance's: ROSS carries it
    through the backward whirls): the modes, the lines, the counter-rotating part, nothing else.  A second wheel,
    "D" (8 kg, I_zz/I_rr 1.9, modes at 150 / 70 / 120 Hz: rocking below and axial between, 400-4500 rpm, so the spin
    passes the rocking mode), clean.  The damping ratios are ROSS's: each bearing's damper is ζ's share of its spring
    (c/k = 2ζ/ω_t), so the rocking pair, the same springs at the bearings' half span, has ζ·f_rock/f_t."""
    doc, model, summary = _diagnosed(doc_name, tmp_path, capsys)
    assert [e["kind"] for e in model["effects"]] == classes
    assert summary["unexplained"] == []
    q_true = doc["truth"]["counter_fundamental"] ** 2 / (1 + doc["truth"]["counter_fundamental"] ** 2)
    for e in model["effects"]:
        if e["kind"] == "counter_rotation":         # q: the counter part's share of the line's power
            assert (e["direction"], e["h"]) == ("radial_force", pytest.approx(1.0, abs=1e-3))
            assert e["counter_fraction"] == pytest.approx(q_true, rel=0.03)

    # ROSS's modes at rest (rocking: two whirls), each the one nearest the frequency it was built for
    rest = np.array(next(c for c in doc["campbell"] if c["speed_rpm"] < 10)["modes_hz"])
    truth = doc["truth"]
    rocking, translation, axial = (rest[np.argmin(np.abs(rest - truth[k]))]
                                   for k in ("rocking_hz", "translation_hz", "axial_hz"))
    an = model["analytical"]
    ratio = an["I_zz_kg_m2"] / an["I_rr_kg_m2"]
    got_t = np.sqrt(an["k_r_N_per_m"] / an["mass_kg"]) / (2 * np.pi)
    got_r = np.sqrt(an["k_rock_Nm_per_rad"] / an["I_rr_kg_m2"]) / (2 * np.pi)
    got_z = np.sqrt(an["k_z_N_per_m"] / an["mass_kg"]) / (2 * np.pi)
    assert got_t == pytest.approx(translation, rel=0.005)
    assert got_r == pytest.approx(rocking, rel=0.005)
    assert got_z == pytest.approx(axial, rel=0.01)
    assert ratio == pytest.approx(doc["truth"]["I_zz_over_I_rr"], rel=0.01)
    modes = next(e for e in model["effects"] if e["kind"] == "suspension_modes")
    for name, zeta in (("radial_translation", truth["zeta"]), ("axial", truth["zeta"]),
                       ("rocking", truth["zeta"] * truth["rocking_hz"] / truth["translation_hz"])):
        assert modes[f"zeta_{name}"] == pytest.approx(zeta, rel=0.1), name
    # per unit mass (no --mass given): the imbalances are read as kg·m and kg·m²
    assert an["U_s_kg_m"] == pytest.approx(doc["truth"]["U_s_kg_m"], rel=0.01)
    assert an["U_d_kg_m2"] == pytest.approx(doc["truth"]["U_d_kg_m2"], rel=0.01)

    # every forced line in the base, once (a radial one with its rotation sense), at its ratio and coefficient
    for ln in doc["lines"]:
        if ln["imbalance"]:
            continue
        radial = ln["direction"] != "axial_force"
        got = [x for x in model["empirical"][ln["direction"]]
               if abs(x["h"] - ln["h"]) < 0.01 and (not radial or x["sense"] == ln["sense"])]
        assert len(got) == 1, (ln["direction"], ln["h"], got)
        assert got[0]["h"] == pytest.approx(ln["h"], rel=0.002)
        assert got[0]["C"] == pytest.approx(ln["C"], rel=0.05), (ln["direction"], ln["h"])
    forced = {(ln["direction"], ln["h"]) for ln in doc["lines"]}
    for d, lines in model["empirical"].items():
        for x in lines:
            assert (d, round(x["h"], 2)) in forced, (d, x["h"])      # no line ROSS was not given


@pytest.mark.slow
def test_new_wheel_on_a_ross_test_stand_keeps_its_modes_and_names_one_stand(tmp_path, capsys):
    """ROSS's new wheel on two 40-kg masses sprung at 230 Hz (ζ 0.03) between its bearings and the load cell: the
    radial modes within 2 % of the hard-mounted truth (the stand's finite mass moves them 1.5 %: ROSS's coupled modes
    at rest are given in the document), one test stand near 230 Hz, nothing else.  The axial mode and the stand's
    axial couple into two resonances (210 / 339 Hz) that no hard-mounted mode is: the axial mode may be left
    unconstrained, never put elsewhere silently."""
    doc, model, _ = _diagnosed("ross_new_wheel_fixture230.json", tmp_path, capsys)
    kinds = [e["kind"] for e in model["effects"]]
    assert sorted(kinds) == ["fixed_resonance", "suspension_modes"], kinds
    stand = next(e for e in model["effects"] if e["kind"] == "fixed_resonance")
    assert stand["role"] == "test_stand"
    assert stand["f_Hz"] == pytest.approx(doc["truth"]["fixture_hz"], rel=0.02)
    modes = next(e for e in model["effects"] if e["kind"] == "suspension_modes")
    truth = doc["truth"]
    assert modes["radial_translation_Hz"] == pytest.approx(truth["translation_hz"], rel=0.02)
    assert modes["rocking_Hz"] == pytest.approx(truth["rocking_hz"], rel=0.02)
    assert "axial" in modes["unconstrained"] or modes["axial_Hz"] == pytest.approx(truth["axial_hz"], rel=0.02)


def _chain_modes_hz(m, k, m_s, k_s):
    """Undamped natural frequencies (Hz, ascending) of a mass ``m`` (kg) on a spring ``k`` (N/m) to a mass ``m_s`` on a
    spring ``k_s`` to the ground: the roots in ω² of m·m_s·ω⁴ − (k·m_s + (k + k_s)·m)·ω² + k·k_s = 0."""
    w2 = np.roots([m * m_s, -(k * m_s + (k + k_s) * m), k * k_s])
    return np.sort(np.sqrt(w2.real)) / (2 * np.pi)


@pytest.mark.slow
def test_new_wheel_on_a_ross_stand_between_its_modes_gives_the_coupled_modes_and_no_amplitude_law(tmp_path, capsys):
    """ROSS's new wheel on two 40-kg masses sprung at 120 Hz (ζ 0.03), between its 95 Hz rocking and 140 Hz
    translation: wheel and stand are one structure.  In translation it is a two-mass chain (4.2 kg on k, 80 kg on
    2·k_f): its closed-form modes, 112.08 Hz (the stand's) and 149.89 Hz (the wheel's), are ROSS's at rest (run_modal,
    stored in the document) within 0.05 %, and at every speed (translation has no gyroscopic term).  The load cell
    reads the force through the stand's springs: in translation it is (undamped, exactly) the product of the two modes'
    transmissibilities, so a model of the wheel's translation times one stand resonance holds the imbalance's force,
    U_s·Ω² in ROSS's forcing.  The default command gives the wheel's modes at the coupled frequencies, one test stand at
    the stand's translation mode, and no amplitude law (an Ω^2.10 law on the imbalance's radial force was named, a
    patch on the stand's shape: the stand of a finite mass is at 113.3 Hz axially and 126-137 Hz in rocking, moving
    with speed, and one resonance on every channel holds them only as a compromise)."""
    doc = rd.load_doc(DATA / "ross_new_wheel_fixture120.json")
    rotor, truth = doc["rotor"], doc["truth"]
    m_s = 2 * truth["fixture_mass_kg"]
    stand_t, wheel_t = _chain_modes_hz(rotor["mass_kg"], rotor["k_N_m"], m_s,
                                       m_s * (2 * np.pi * truth["fixture_hz"]) ** 2)
    for row in doc["campbell"]:               # the closed form is ROSS's coupled translation pair at every speed
        modes = np.asarray(row["modes_hz"])
        for f in (stand_t, wheel_t):
            assert np.sum(np.abs(modes / f - 1) < 5e-4) == 2, (row["speed_rpm"], f, modes)

    doc, model, _ = _diagnosed("ross_new_wheel_fixture120.json", tmp_path, capsys)
    kinds = sorted(e["kind"] for e in model["effects"])
    assert kinds == ["fixed_resonance", "suspension_modes"], kinds
    stand = next(e for e in model["effects"] if e["kind"] == "fixed_resonance")
    assert stand["role"] == "test_stand"
    assert stand["f_Hz"] == pytest.approx(stand_t, rel=0.01)
    modes = next(e for e in model["effects"] if e["kind"] == "suspension_modes")
    rest = np.asarray(next(c for c in doc["campbell"] if c["speed_rpm"] < 10)["modes_hz"])
    assert modes["radial_translation_Hz"] == pytest.approx(wheel_t, rel=0.005)
    # the wheel's rocking pair, lowest at rest: 88.38 Hz with the rocking scanned on the lines' power alone, 89.00 Hz
    # with the torque lines scanned in the sense their responses turn in every run (rwadist.extended_fit.one_sense_rows);
    # the stand's own rocking (126-137 Hz, moving with speed) is held as one resonance on every channel, a compromise
    assert modes["rocking_Hz"] == pytest.approx(rest[0], rel=0.01)


@pytest.mark.slow
def test_modes_above_every_line_stay_where_their_rise_puts_them(tmp_path, capsys):
    """A ROSS wheel whose axial (334.5 Hz) and rocking (405.6 Hz) modes lie above every line of their direction
    (12.45 kg, I_zz/I_rr 1.22, 300-3000 rpm: the axial lines reach 154 Hz, the torques' 246 Hz): the data show only
    the rise of the lines below each mode, along which f0 and ζ trade.  The translation within 0.5 %; the axial mode,
    not pinned to 2 % by a rise, is declared, but kept within 10 % of ROSS's with its damping held (before: located at
    243.9 Hz with ζ 0.58, reset to a start of 924 Hz, and the rise of the Fz line h 3.08 described as its source
    growing as Ω^2.2, 'a bearing defect's impacts'); nothing is described on the axial force."""
    doc, model, summary = _diagnosed("ross_wheel_high_modes.json", tmp_path, capsys)
    assert [e["kind"] for e in model["effects"]] == ["suspension_modes"]
    modes = model["effects"][0]
    truth = doc["truth"]
    assert modes["radial_translation_Hz"] == pytest.approx(truth["translation_hz"], rel=0.005)
    assert "axial" in modes["unconstrained"]
    assert modes["axial_Hz"] == pytest.approx(truth["axial_hz"], rel=0.10)
    assert not [u for u in summary["unexplained"] if "Fz" in u.get("channels", [])], summary["unexplained"]


@pytest.mark.slow
def test_wheel_d_on_a_heavy_ross_stand_between_its_modes_gives_no_law_on_the_imbalance(tmp_path, capsys):
    """ROSS's wheel D (8 kg, modes 150 / 70 / 120 Hz) on two 200-kg masses sprung at 105 Hz, between its rocking and
    its axial mode: one structure, whose stand rocks at 108.6 Hz and translates at 103.1 Hz at rest, so one resonance
    on every channel holds the stand only as a compromise.  The 1x torque's departure from the model was named an
    amplitude law Ω^2.14 on the dynamic imbalance, with a 'wheel mode' at 106.65 Hz beside it: the imbalances are
    U·Ω² by their physics and get no law.  Every mode within 2 % of ROSS's coupled mode at rest nearest its hard-mounted
    frequency, or declared; the stand named within 2 % of ROSS's coupled translation of it; nothing else added."""
    doc, model, _ = _diagnosed("ross_wheel_D_stand105.json", tmp_path, capsys)
    assert sorted(e["kind"] for e in model["effects"]) == ["fixed_resonance", "suspension_modes"], model["effects"]
    rest = np.asarray(next(c for c in doc["campbell"] if c["speed_rpm"] < 10)["modes_hz"])
    truth = doc["truth"]
    modes = next(e for e in model["effects"] if e["kind"] == "suspension_modes")
    for name, key in (("radial_translation", "translation_hz"), ("rocking", "rocking_hz"), ("axial", "axial_hz")):
        if name in (modes["unconstrained"] or []):
            continue
        coupled = rest[np.argmin(np.abs(rest - truth[key]))]
        assert modes[f"{name}_Hz"] == pytest.approx(coupled, rel=0.02), name
    stand = next(e for e in model["effects"] if e["kind"] == "fixed_resonance")
    assert stand["role"] == "test_stand"
    row = next(c for c in doc["campbell"] if c["speed_rpm"] < 10)
    lateral = rest[np.array([w != "None" for w in row["whirl"]])]       # the whirling (radial) modes at rest
    assert stand["f_Hz"] == pytest.approx(lateral[np.argmin(np.abs(lateral - truth["fixture_hz"]))], rel=0.02)
