"""Measured vs assumed (issue 16): a catalogue wheel whose suspension modes are assumed
(``analytical.modes_assumed``) runs hard-mounted by default in the coupling kit and in a ``rwadist psd
--wheels`` set -- its fundamental force and torque are the datasheet's U_s·Ω² and U_d·Ω² -- and runs
its assumed modes only on request, with a warning / a note next to the outputs."""
import json

import numpy as np
import pytest

from rwadist import catalogue
from rwadist import coupling as cp
from rwadist import extended as ext
from rwadist.cli import main
from rwadist.coupling.components import wheel_matrices
from rwadist.coupling.performance import rigid_wheel_frf, wheel_spec_from_model
from rwadist.mounting import load_wheels

HR16 = "honeywell-hr16-75"
RPM = np.array([3000.0, 6000.0])
OMEGA = RPM * 2 * np.pi / 60


def _plant():
    """A six-DOF modal plant (two performance outputs) the wheel is mounted on."""
    rng = np.random.default_rng(4)
    phi = rng.normal(size=(6, 6)) * 0.3
    return cp.modal_plant(np.linspace(20.0, 140.0, 6), 0.02, phi, rng.normal(size=(2, 6)), ("y0", "y1"))


def _fundamental(responses):
    """(S, 6) blocked-load phasors of the h = 1 group of wheel 0."""
    j = int(np.nonzero(responses.h[0] == 1.0)[0][0])
    return responses.hard_mounted[0][:, j, :]


def test_coupling_runs_assumed_modes_hard_mounted_by_default():
    model = catalogue.load(HR16)
    an = ext.params_from_model(model)
    U_s, U_d = an.U_s, an.U_d
    assert an.height == 0.0                      # no lever arm: the torque is U_d·Ω² alone
    with pytest.warns(RuntimeWarning, match="hard-mounted"):
        spec = wheel_spec_from_model(model)
    assert spec.hard_mounted
    r = cp.line_responses(_plant(), [spec], OMEGA)
    F = _fundamental(r)
    np.testing.assert_allclose(np.abs(F[:, 0]), U_s * OMEGA**2, rtol=1e-6)
    np.testing.assert_allclose(np.abs(F[:, 1]), U_s * OMEGA**2, rtol=1e-6)
    np.testing.assert_allclose(np.abs(F[:, 3]), U_d * OMEGA**2, rtol=1e-6)
    np.testing.assert_allclose(np.abs(F[:, 4]), U_d * OMEGA**2, rtol=1e-6)
    assert np.all(np.isfinite(r.y["coupled"][0]))


def test_coupling_assumed_modes_opt_in_keeps_the_old_numbers_and_warns():
    model = catalogue.load(HR16)
    with pytest.warns(RuntimeWarning, match="assumed_modes=True"):
        spec = wheel_spec_from_model(model, assumed_modes=True)
    assert not spec.hard_mounted
    r = cp.line_responses(_plant(), [spec], OMEGA)
    F = _fundamental(r)
    # the old numbers: the blocked loads through the assumed modes (extended model's closed form)
    _, amp = ext.steady_lines(spec.params, spec.lines, OMEGA)
    np.testing.assert_allclose(np.abs(F), np.abs(amp.sum(axis=1)), rtol=1e-12, atol=1e-18)
    an = ext.params_from_model(model)
    ratio_f = np.abs(F[1, 0]) / (an.U_s * OMEGA[1] ** 2)
    ratio_t = np.abs(F[1, 3]) / (an.U_d * OMEGA[1] ** 2)
    assert ratio_f == pytest.approx(1.23, abs=0.01)         # issue 16: radial force +23 % at 6000 rpm
    assert ratio_t == pytest.approx(0.23, abs=0.01)         # radial torque -77 %


def test_measured_modes_wheel_is_untouched():
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spec = wheel_spec_from_model(catalogue.load("ithaco-e"))
    assert not spec.hard_mounted


def test_rigid_wheel_frf_is_the_stiff_suspension_limit():
    """The hard-mounted wheel's (Zc, B) are the flexible wheel's as its stiffnesses grow (×1e8, damping
    ×1e4 so the modes stay damped): a second method, the 12-state model of coupling.components."""
    p = ext.params_from_model(catalogue.load(HR16))
    from dataclasses import replace
    p = replace(p, height=0.03)                         # exercise the lever arm and the h² terms
    stiff = replace(p, k_r=p.k_r * 1e8, k_rock=p.k_rock * 1e8, k_z=p.k_z * 1e8,
                    c_r=p.c_r * 1e4, c_rock=p.c_rock * 1e4, c_z=p.c_z * 1e4)
    om = np.array([300.0, -500.0])
    f = np.array([[7.0, 45.0], [12.0, 90.0]])
    Zr, Br = rigid_wheel_frf(p, om, f, 1.5, (0.01, 0.02, 0.03))
    A, B, C, D = wheel_matrices(stiff, om, 1.5, (0.01, 0.02, 0.03))
    s = 2j * np.pi * f
    H = C @ np.linalg.solve(s[..., None, None] * np.eye(12) - A[:, None], np.broadcast_to(B, (2, 2, 12, 12))) + D
    np.testing.assert_allclose(H[..., :6], Zr, rtol=1e-5, atol=1e-6 * np.abs(Zr).max())
    np.testing.assert_allclose(H[..., 6:], np.broadcast_to(Br, H[..., 6:].shape), rtol=1e-5, atol=1e-6)
    assert np.abs(Zr[..., 3, 4]).max() > 1e-3          # the gyroscopic coupling is there


def _wheels_file(tmp_path):
    wj = tmp_path / "wheels.json"
    wj.write_text(json.dumps({"wheels": [
        {"name": "a", "preset": HR16, "mounting": {"preset": "pyramid-4", "index": 0},
         "speed": {"dist": "uniform", "min_rpm": 2500, "max_rpm": 6500}},
        {"name": "b", "model": str(catalogue.path(HR16)), "mounting": {"preset": "pyramid-4", "index": 1},
         "speed": {"dist": "uniform", "min_rpm": 2500, "max_rpm": 6500}}]}))
    return wj


def test_wheels_set_runs_assumed_modes_hard_mounted_by_default(tmp_path):
    an = ext.params_from_model(catalogue.load(HR16))
    wj = _wheels_file(tmp_path)
    for w in load_wheels(wj):
        assert w.meta["modes_assumed"] == "hard-mounted"
        a = w.lines.amplitudes(OMEGA)                    # (S, sources, 6)
        j = int(np.nonzero(w.lines.h == 1.0)[0][0])
        fund = a[:, np.nonzero(w.lines.h == 1.0)[0], :]
        assert fund.shape[1] == 2                        # force and torque sources
        np.testing.assert_allclose(np.abs(fund[:, :, 0]).max(axis=1), an.U_s * OMEGA**2, rtol=1e-6)
        np.testing.assert_allclose(np.abs(fund[:, :, 3]).max(axis=1), an.U_d * OMEGA**2, rtol=1e-6)
        assert j >= 0
    # opt in: the assumed modes' numbers (extended model through the modes)
    for w in load_wheels(wj, assumed_modes=True):
        assert w.meta["modes_assumed"] == "assumed modes used"
        a = w.lines.amplitudes(OMEGA)
        _, ref = ext.steady_lines(w.lines.params, [ln for g in w.lines.groups for ln in g], OMEGA)
        np.testing.assert_allclose(a.sum(axis=1), ref.sum(axis=1), rtol=1e-12)
        assert np.abs(a[1, :, 3]).max() / (an.U_d * OMEGA[1] ** 2) == pytest.approx(0.23, abs=0.01)


def test_psd_wheels_cli_notes_assumed_modes(tmp_path, capsys):
    wj = _wheels_file(tmp_path)
    out = tmp_path / "set.csv"
    args = ["psd", "--wheels", str(wj), "--speed-rpm", "2500:6500", "--fmax", "150", "--n-freq", "301",
            "--n-speeds", "50", "-o", str(out)]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "hard-mounted" in text and "a, b" in text
    assert not (tmp_path / "set_ASSUMED_MODES.txt").exists()
    assert main(args + ["--assumed-modes"]) == 0
    cap = capsys.readouterr()
    assert "ASSUMED" in cap.err
    note = (tmp_path / "set_ASSUMED_MODES.txt").read_text()
    assert "ASSUMED" in note and "a (preset" in note and "b (" in note


def test_diagnose_starts_hard_mounted_on_assumed_modes(tmp_path, capsys):
    """diagnose from a datasheet wheel: the starting prediction is hard-mounted (its data, simulated
    hard-mounted as the datasheet states, is then explained); --base extended runs the assumed modes and
    writes the note into the report directory."""
    data = tmp_path / "t"
    assert main(["simulate-test", str(data), "--preset", HR16, "--speeds-rpm", "2000,4000,6000",
                 "--samples", "2048"]) == 0
    assert main(["diagnose", str(data), "--preset", HR16, "-o", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert "hard-mounted" in out and "empirical base" in out
    assert not (tmp_path / "r" / "ASSUMED_MODES.txt").exists()
    assert main(["diagnose", str(data), "--preset", HR16, "--base", "extended", "-o", str(tmp_path / "r2")]) == 0
    cap = capsys.readouterr()
    assert "extended base" in cap.out and "ASSUMED" in cap.err
    assert "ASSUMED" in (tmp_path / "r2" / "ASSUMED_MODES.txt").read_text()


def test_the_presets_model_of_a_datasheet_wheel_says_its_modes_are_assumed():
    """The coupling notebook's route, rwadist.presets.preset(NAME).to_model(), carries analytical.modes_assumed as the
    catalogue's model does (it dropped it: the HR16 ran through its guessed modes, LOS jitter +20 % at 6000 rpm,
    without a warning); a wheel with measured modes stays without it."""
    from rwadist.presets import preset

    model = preset(HR16).to_model()
    assert model.analytical["modes_assumed"] is True
    with pytest.warns(RuntimeWarning, match="hard-mounted"):
        assert wheel_spec_from_model(model).hard_mounted
    assert "modes_assumed" not in preset("ithaco-e").to_model().analytical
