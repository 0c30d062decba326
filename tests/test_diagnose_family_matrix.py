"""The default-path family matrix (benchmarks/diagnose_family_matrix.py): its cells cover what issue 33 asks,
its judgement of a diagnosis is right on summaries built by hand, and -- slow -- the cells that hold today on
``rwadist diagnose DATA -o R`` (no model) stay held.

Pinned today (commit of this test): the issue's new wheel (family wheel 0), clean: nothing added, every mode
within 2 %; the same wheel with a fixture at 1.5x its axial mode (210 Hz): the stand named within 5 %, the modes
within 2 %, nothing else added, the error within 5x the clean cell's.  Family wheel 2 (15 kg, I_zz/I_rr 2.2, modes
90/50/62 Hz, 300-3000 rpm at 2 kHz) with a fixture at 0.75x its axial mode (46.5 Hz, crossed by the imbalance at
2790 rpm): the modes within 2 % and the stand named, nothing else added (no mode was named before the modes were
judged beside the stand fitted with them).
"""
import csv
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "tests"))

import diagnose_family_matrix as dfm  # noqa: E402
import family_effects as fe  # noqa: E402


def test_cells_cover_every_class_fixtures_at_every_factor_pairs_and_unknowns():
    wheels = dfm.wheels()
    assert len(wheels) >= 8
    seen = {}
    for i, w in enumerate(wheels):
        cells = dfm.cells(i, w)
        labels = [c[1] for c in cells]
        assert labels.count("clean") == 1
        assert set(fe.KNOWN) <= set(labels) and set(fe.UNKNOWN) <= set(labels)
        assert labels.count("fixture") == 3 and labels.count("pair") == 2
        assert labels.count("fixture_offset") == dfm.FIXTURE_OFFSET_CELLS
        for name, label, effects in cells:
            if label == "fixture":
                mode = name.split()[-1]
                factor = effects[0].params["f_hz"] / w.modes_hz()[mode]
                assert 0.5 - 1e-9 <= factor <= 1.5 + 1e-9
                seen.setdefault(mode, set()).add(round(factor, 2))
            if label == "fixture_offset":
                fix, lever = effects
                assert fix.kind == "fixture" and lever.kind == "cross_coupling"
                mode = name.split()[2]
                assert round(fix.params["f_hz"] / w.modes_hz()[mode], 2) in set(dfm.FIXTURE_FACTORS)
                assert 0.02 - 1e-9 <= abs(lever.params["r"][2]) <= 0.04 + 1e-9
    # across the family every mode meets a fixture at each of 0.5, 0.75, 1, 1.25, 1.5 x its frequency
    assert all(v == {0.5, 0.75, 1.0, 1.25, 1.5} for v in seen.values()) and len(seen) == 3


def _summary(effects, error=0.01, unexplained=()):
    modes = {"kind": "suspension_modes", "radial_translation_Hz": 310.0, "rocking_Hz": 95.0, "axial_Hz": 140.0,
             "unconstrained": []}
    return {"effects": [modes, *effects], "error_before": 0.9, "error_after": error, "base_lines": [],
            "unexplained": [{"signature": s} for s in unexplained]}


def test_evaluation_of_hand_made_diagnoses():
    w = dfm.wheels()[0]
    fix = fe.Fixture(f_hz=210.0)
    ok = dfm.evaluate(0, w, "fixture", "fixture", [fix],
                      _summary([{"kind": "fixed_resonance", "role": "test_stand", "f_Hz": 208.0}], 0.02), {}, "", 0.01, 1)
    assert ok["found"] == [True] and not ok["added"] and ok["modes_ok"] and ok["error_ratio"] == pytest.approx(2.0)
    # a wheel-mode resonance at the stand's frequency is not the stand, and is an addition
    bad = dfm.evaluate(0, w, "fixture", "fixture", [fix],
                       _summary([{"kind": "fixed_resonance", "role": "wheel_mode", "f_Hz": 210.0}]), {}, "", 0.01, 1)
    assert bad["found"] == [False] and bad["added"]
    # a mode 3 % off and not declared is wrong; declared, it is not
    s = _summary([])
    s["effects"][0]["rocking_Hz"] = 98.0
    assert not dfm.evaluate(0, w, "clean", "clean", [], s, {}, "", None, 1)["modes_ok"]
    s["effects"][0]["unconstrained"] = ["rocking"]
    assert dfm.evaluate(0, w, "clean", "clean", [], s, {}, "", None, 1)["modes_ok"]
    # a missing harmonic completed into the fitted base is found on this path (no model to miss it from)
    mh = fe.MissingHarmonic()
    model = {"empirical": {"radial_force": [{"h": 1.5006, "C": 1e-6}]}}
    r = dfm.evaluate(0, w, "missing_harmonic", "missing_harmonic", [mh], _summary([]), model, "", 0.01, 1)
    assert r["found"] == [True] and not r["added"]
    # an unknown kind: described with the right signature, classes added counted
    pk = fe.Pickup()
    summ = _summary([{"kind": "amplitude_law", "direction": "radial_force", "h": 1.0}], unexplained=["fixed_line"])
    summ["unexplained"][0]["f_Hz"] = [49.9, 150.2]
    r = dfm.evaluate(0, w, "pickup", "pickup", [pk], summ, {}, "", 0.01, 1) | {"truths": [pk.truth()]}
    assert dfm._described(r) and r["added"] == ["amplitude_law(radial_f h 1)"]
    summ["unexplained"][0]["f_Hz"] = [300.0, 320.0]                     # a fixed line, but not the pickup's
    r = dfm.evaluate(0, w, "pickup", "pickup", [pk], summ, {}, "", 0.01, 1) | {"truths": [pk.truth()]}
    assert not dfm._described(r)
    assert dfm.DESCRIBED_AS.keys() == set(fe.UNKNOWN)


def _cell(i, name, tmp_path):
    w = dfm.wheels()[i]
    name_, label, effects = next(c for c in dfm.cells(i, w) if c[0] == name)
    return dfm.run_cell(i, w, name_, label, effects, 1 + 100 * i, tmp_path, None)


@pytest.mark.slow
def test_new_wheel_clean_and_a_fixture_above_its_axial_mode_hold(tmp_path, family_clean_cell):
    clean, _ = family_clean_cell(0)
    assert "crashed" not in clean and not clean["added"] and clean["modes_ok"], clean
    fix = _cell(0, "fixture 1.5x axial", tmp_path)
    assert fix["found"] == [True] and not fix["added"] and fix["modes_ok"], fix
    assert fix["error"][1] <= dfm.ERROR_FACTOR * clean["error"][1]
    assert np.isfinite(fix["error"][0])


@pytest.mark.slow
def test_a_planar_lines_share_of_one_channel_is_no_wheel_mode(tmp_path):
    """Family wheel 3 clean, seed 300 (600-6000 rpm, 4 kHz): its planar 2xBPFO line (h 8.03, co 0.5) read on Fy
    alone at 5147 rpm (Fx did not measure it there) was fitted as a wheel mode at 688.8 Hz, peak gain 1.42, and added;
    the pair's power sum holds no such lift (tests/test_line_gain_pair.py)."""
    w = dfm.wheels()[3]
    clean = dfm.run_cell(3, w, "clean", "clean", [], 300, tmp_path, None)
    assert "crashed" not in clean and not clean["added"] and clean["modes_ok"], clean


@pytest.mark.slow
def test_a_fixture_under_the_modes_of_a_heavy_wheel_is_named_beside_them(tmp_path):
    fix = _cell(2, "fixture 0.75x axial", tmp_path)
    assert "crashed" not in fix and fix["found"] == [True] and not fix["added"] and fix["modes_ok"], fix


def _assert_named_alone_near_clean(wheel: int, label: str, tmp_path, clean_cell, ratio: float = 1.5) -> None:
    """Family wheel ``wheel``'s cell ``label``: its effect named, nothing else added, the modes within 2 % or declared,
    the error within ``ratio`` times the same wheel's clean cell's (``clean_cell``: the ``family_clean_cell``
    fixture)."""
    clean, _ = clean_cell(wheel)
    cell = _cell(wheel, label, tmp_path)
    assert "crashed" not in cell and cell["found"] == [True] and not cell["added"] and cell["modes_ok"], cell
    assert cell["error"][1] <= ratio * clean["error"][1], (cell["error"], clean["error"])


@pytest.mark.slow
def test_a_fixture_above_the_translation_mode_is_named_beside_a_beating_band(tmp_path, family_clean_cell):
    """Family wheel 4 (translation 227.7 Hz) with a fixture at 1.5x it (341.55 Hz): the modes are fitted with the stand
    beside them, but the stand's held-out evidence was hidden by one band of the top speed where a bearing line
    (h 4.62) beats near the translation mode: 0.296 of the radial forces' 0.300 noise variance, its own gain 0, and
    the stand (77 % of the held-out misplaced power) was at t 0.64 and not named (main 167d71a: the error 4.9x the
    clean cell's).  That band is judged apart (rwadist.diagnose.search.held_out_t): the stand is named within 5 %,
    nothing else is added, the modes within 2 %, the error within 1.5x the clean cell's."""
    _assert_named_alone_near_clean(4, "fixture 1.5x radial_translation", tmp_path, family_clean_cell)


@pytest.mark.slow
def test_a_load_cell_offset_beside_close_modes_is_named_and_the_rocking_located(tmp_path):
    """Family wheel 6 (12 kg, translation 150 Hz, rocking 110 Hz) with a load-cell offset r_z = -60 mm: the offset's
    first estimate, made beside the rocking it pulls to 138 Hz, is 3 % short and leaves the rocking 2 % off and
    declared; estimated again beside the modes the corrected torques give, every mode is within 2 % (none declared),
    the offset is named and nothing else is added (main a588f38: rocking declared, offset missed, 177x clean)."""
    cell = _cell(6, "cross_coupling", tmp_path)
    assert "crashed" not in cell and cell["found"] == [True] and not cell["added"], cell
    assert cell["modes_ok"] and "unc" not in cell["modes"], cell


@pytest.mark.slow
def test_a_rocking_located_on_the_offsets_lines_is_located_again_on_the_corrected_torques(tmp_path):
    """Family wheel 3 (7 kg, translation 230 Hz, rocking 70 Hz) with a load-cell offset r_z = -60 mm and force sensors
    noisier than the torque ones (``lever_arm_noise``): on the uncorrected torques the fit runs locate every mode, the
    rocking at 221 Hz (the forces' lines through the translation mode, moved into the torques by r × F), so no mode
    is left unconstrained to ask for the offset; the offset the data show beside those modes, taken out, gives modes
    that explain the runs better (rocking 70.4 Hz, then 70.0 Hz on every run).  The offset and the noise it moves
    are named, nothing else is added, every mode within 2 % and none declared (main 7064d75: the offset named, the
    rocking 69.68 Hz, lever_arm_noise missed, error 9x the clean cell's, 75 speed_line records on Tx, Ty)."""
    cell = _cell(3, "lever_arm_noise", tmp_path)
    assert "crashed" not in cell and cell["found"] == [True] and not cell["added"], cell
    assert cell["modes_ok"] and "unc" not in cell["modes"], cell


@pytest.mark.slow
@pytest.mark.parametrize("wheel", [1, 5])
def test_force_sensors_noisier_than_the_torque_ones_are_named_near_the_clean_error(wheel, tmp_path, family_clean_cell):
    """Family wheels 1 and 5 with a load-cell offset r_z = -60 mm and force sensors noisier than the torque ones
    (``lever_arm_noise``): the force family, decided once on the data as recorded, weighs its measurements by their
    noise in every fit of the modes, the corrected torques' included (rwadist.extended_fit_lsq.recorded_noisy_sensors).
    The offset and the noise it moves are named, nothing else is added, the modes within 2 %, the error within 2x the
    clean cell's (main f0413c8: wheel 1 12.5x, its 520 Hz translation 519.815 Hz; wheel 5 the noise missed, 3.2x,
    hundreds of speed_line records on Tx, Ty; now 1.49x and 0.93x)."""
    _assert_named_alone_near_clean(wheel, "lever_arm_noise", tmp_path, family_clean_cell, ratio=2.0)


@pytest.mark.slow
def test_the_offset_the_modes_are_fitted_beside_is_the_one_the_search_names(tmp_path, family_clean_cell):
    """Family wheel 2 (15 kg, modes 90/50/62 Hz, 300-3000 rpm) with a load-cell offset r_z = -60 mm: the refit on every
    run estimates the offset beside the modes twice, -63.19 then -61.93 mm (the search's cross_coupling: -61.92 ±
    1.27); the second round is no better by 4 standard errors but no worse, and it is the one the torque lines are now
    fitted beside.  The error within 1.5x the clean cell's (main 45f9c67, the first round kept: 2.0x; now 1.1x)."""
    _assert_named_alone_near_clean(2, "cross_coupling", tmp_path, family_clean_cell)


@pytest.mark.slow
def test_a_fixture_on_a_table_with_a_load_cell_offset_is_named_with_the_offset_near_the_clean_error(tmp_path,
                                                                                                    family_clean_cell):
    """Family wheel 5 (translation 600 Hz, rocking 250 Hz, axial 400 Hz) with a fixture at 1.5x its axial mode (600 Hz,
    on the translation) on a table whose load-cell reference sits r_z = +35 mm off the bearing centre (the
    ``fixture_offset`` kind): the modes within 2 %, the stand and the offset named, nothing else added, the error
    within 1.5x the clean cell's.  The offset taken out before the modes are located is weighed by the wheel's own
    torque (``CrossCoupling.own_weighted``); weighed by the torque as measured (main 5666f58) the stand was named at
    598 Hz and the error 5.03x the clean cell's; now 600 Hz, 1.07x."""
    w = dfm.wheels()[5]
    clean, _ = family_clean_cell(5)
    name = next(c[0] for c in dfm.cells(5, w) if c[1] == "fixture_offset")
    cell = _cell(5, name, tmp_path)
    assert "crashed" not in cell and cell["found"] == [True, True] and not cell["added"] and cell["modes_ok"], cell
    assert cell["error"][1] <= 1.5 * clean["error"][1], (cell["error"], clean["error"])


@pytest.mark.slow
def test_a_resonance_moving_with_speed_is_described_and_no_wheel_mode_is_named(tmp_path):
    """Family wheel 0 with a radial-force resonance softening with speed, 248 -> 149 Hz over 600-6000 rpm
    (benchmarks/diagnose_open_world.py's softening_mode, generated by tests/family_wheel.py): one fixed resonance
    fitted to it sits between its ends (e2f6fb7: a 'wheel mode' fixed_resonance at 198 Hz added, nothing described).
    The slower and the faster half of the runs each want a resonance of their own, 7 % apart: it is described as a
    resonance moving with speed on Fx, Fy, falling, within the injected range, and no class is added."""
    import diagnose_open_world as dow

    row = dow.cell(0, dow.fw.family()[0], "softening_mode", tmp_path)
    assert "failed" not in row, row
    assert row["added"] == [] and row["right"], row


@pytest.mark.slow
def test_a_floor_of_the_rotor_forces_split_over_three_channels_is_found_at_its_level(tmp_path, family_clean_cell):
    """Family wheel 4 (4096 samples at 3840 Hz, 300-3000 rpm) with random rotor forces of PSD ∝ Ω³/(1 + (f/32.9 Hz)⁴)
    (tests/family_effects.py, 28.5 dB over the noise at the top speed) on the radial and axial forces: each force
    channel held 2-5 % of the held-out misplaced power, below the search's min_gain, and no single-channel floor was
    fitted; the floor on Fz alone took p 8 (cdd25f1: missed, described as two broadband humps).  One law of the force
    channels (rwadist.effects.broadband_floor_diagnose.FloorGroup) is named on Fx, Fy and Fz, nothing else added, the
    error within 1.5x the clean cell's; its exponent within 0.25 of 3 and its level at Ω_ref within 30 % of the injected
    PSD through the suspension, S(f, Ω_ref)·|T(f)|², at the band centres whose band ends below the mode that lifts it
    (Fx, Fy: 28-178 Hz, below the translation at 227.7 Hz, measured 3-18 % off; Fz: 28 Hz, below the axial at 70 Hz,
    3 % off)."""
    import json

    import family_wheel as fw

    _assert_named_alone_near_clean(4, "broadband_floor", tmp_path, family_clean_cell)
    w = dfm.wheels()[4]
    floor = next(c for c in dfm.cells(4, w) if c[0] == "broadband_floor")[2][0]
    model = json.loads((tmp_path / "w4_broadband_floor" / "report" / "model.json").read_text())
    floors = {e["channel"][0]: e for e in model["effects"] if e["kind"] == "broadband_floor"}
    assert set(floors) == {"Fx", "Fy", "Fz"} and all(len(e["channel"]) == 1 for e in floors.values())
    # the search passed the three parts as one hypothesis (Hypothesis.group, wired in search._search): its held-out
    # gain written once in hypotheses.csv, each part's row marked part_of the group's channels
    with open(tmp_path / "w4_broadband_floor" / "report" / "hypotheses.csv") as fh:
        rows = [r for r in csv.DictReader(fh) if r["kind"] == "broadband_floor" and r["passed"] == "true"]
    assert sorted(r["channels"] for r in rows) == ["Fx", "Fy", "Fz"]
    assert all("part_of=Fx Fy Fz" in r["parameters"] for r in rows)
    assert sum(r["heldout_gain"] != "" for r in rows) == 1
    summary = json.loads((tmp_path / "w4_broadband_floor" / "report" / "summary.json").read_text())
    parts = [e for e in summary["effects"] if e["kind"] == "broadband_floor"]
    assert len(parts) == 3 and all(e["evidence"]["part_of"] == ["Fx", "Fy", "Fz"] for e in parts)
    for c, e in floors.items():
        assert abs(e["exponent"] - floor.params["exponent"]) <= 0.25, (c, e["exponent"])
        f = np.asarray(e["f_Hz"])
        w_ref = e["omega_ref_rad_s"]
        direction, row = ("axial_force", 0) if c == "Fz" else ("radial_force", "xy".index(c[1].lower()))
        T = fw.transfer(w, direction, 2 * np.pi * f, w_ref)[:, row, :]
        truth = floor._psd(w, w_ref, f, w.max_rpm * fw.RPM) * np.sum(np.abs(T) ** 2, -1)
        # the knots (band centres) whose band, 8 bins of 3.75 Hz, ends below the mode (its peak in a band makes the
        # band mean, which the knot holds, no value at the centre)
        mode = w.f_axial if c == "Fz" else w.f_trans
        sel = (f > 20.0) & (f + 15.0 < 0.9 * mode)
        assert sel.sum() >= (1 if c == "Fz" else 5)
        np.testing.assert_allclose(np.asarray(e["psd_ref"])[sel], truth[sel], rtol=0.3, err_msg=c)


@pytest.mark.slow
@pytest.mark.parametrize("wheel, kind", [(4, "affine_line"), (6, "affine_line"), (0, "rattle"), (1, "wide_hump")])
def test_an_affine_line_a_rattle_in_some_runs_and_a_wide_hump_are_each_one_description(wheel, kind, tmp_path):
    """Session 44's open-world kinds on the family (tests/family_effects.py :class:`AffineLine`, :class:`Rattle`,
    :class:`WideHump`): each described with its signature where it is, alone, and no class added.  Before, wheel 4's
    and 6's line at f0 + 0.5·f_spin on Fz and Tz came with a 'hump' of 20 Hz (its bins lifting the floor the model
    reads, kurtosis 1.5: a sinusoid's) beside it; the rattle and the wide hump were not described at all."""
    row = _cell(wheel, kind, tmp_path)
    assert "crashed" not in row and not row["added"] and row["modes_ok"], row
    assert dfm._described(row) and row["unexplained"] == [dfm.DESCRIBED_AS[kind]], row["unexplained_records"]


def test_speed_sidebands_beating_in_one_direction_are_no_run_change(tmp_path):
    """Session 60: read on the radial force's lines alone (the direction a change was located in), family wheel 2's
    speed sidebands beating with their carrier scattered the runs 0.26 dB and were described as a run_change of Fx Fy
    (-4.8 to +2.4 dB, every mode "on the changed runs"), which no direction's change had been seen in.  Whether the runs
    changed is read on every direction; where, on those that follow it.  The matrix's cell: seed 1 + 100·2."""
    w = dfm.wheels()[2]
    cell = dfm.run_cell(2, w, "speed_sidebands", "speed_sidebands", [fe.default_effect("speed_sidebands", w)], 201,
                        tmp_path, None)
    assert "crashed" not in cell and cell["found"] == [True], cell
    assert "run_change" not in cell["unexplained"], cell["unexplained_records"]
