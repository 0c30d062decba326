"""rwadist.inject / ``simulate-test --inject``: known effects added to virtual-stand data.  Each injection is
checked by measuring it back from the time series with a method of its own (a DFT at the line frequency,
X ± iY for the rotation sense, r × F for the load-cell offset), and one end-to-end case through diagnose."""
import numpy as np
import pytest

from rwadist import data as data_io
from rwadist.cli import main
from rwadist.data import DataError
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.teststand import simulate_steady

SPEEDS = np.linspace(900.0, 2400.0, 6)
KW = dict(sample_rate=1920.0, n_samples=4096, noise=0.0, modes=False, test_stand=False)


def dft(x, f, fs):
    """Complex amplitude of x at f (Hz): 2/N Σ x e^{-i2πft} with a Hann window (coherent gain 0.5)."""
    n = x.size
    w = np.hanning(n + 1)[:-1]
    return 2 * np.sum(w * x * np.exp(-2j * np.pi * f * np.arange(n) / fs)) / np.sum(w)


@pytest.mark.parametrize("spec, field", [("bogus:h=1", "kind"), ("sidebands:depth=abc,per_rev=0.1", "depth"),
                                         ("cross_coupling:q=1", "q"), ("fixed_resonance:role=fixture", "role"),
                                         ("broadband_floor:channels=Fx+Qz", "channels"),
                                         ("counter_rotation:fraction=1.5", "fraction"), ("missing_harmonic:h=-1", "h"),
                                         ("sidebands:h=2", "f_mod_hz/per_rev"), ("missing_harmonic:h", "h")])
def test_bad_specs_name_the_field(spec, field):
    with pytest.raises(DataError) as err:
        parse(spec)
    assert err.value.field == field and spec in str(err.value)


def test_cli_error_is_one_line_no_traceback(tmp_path, capsys):
    assert main(["simulate-test", str(tmp_path / "x"), "--preset", "ithaco-e", "--inject", "amplitude_law:h=7"]) == 2
    err = capsys.readouterr().err
    assert "no radial_force line at h = 7" in err and "Traceback" not in err


def test_counter_rotation_fraction_measured_from_xy_phase():
    w = preset("ithaco-e")
    test = simulate_with_injections(w, [parse("counter_rotation:direction=radial_torque,h=3,fraction=0.3")],
                                    SPEEDS, **KW)
    for r in test.runs:
        f = 3 * abs(r.speed) / (2 * np.pi)
        X, Y = dft(r.signals["Tx"], f, r.sample_rate), dft(r.signals["Ty"], f, r.sample_rate)
        co, ct = abs(X + 1j * Y) ** 2, abs(X - 1j * Y) ** 2
        assert ct / (co + ct) == pytest.approx(0.3, abs=0.01)
        C = dict(w.harmonics["radial_torque"])[3.0]
        assert np.sqrt((abs(X) ** 2 + abs(Y) ** 2) / 2) == pytest.approx(C * r.speed**2, rel=0.01)


def test_cross_coupling_is_r_cross_f():
    w = preset("ithaco-e")
    clean = simulate_steady(w, SPEEDS, seed=3, **KW)
    test = simulate_with_injections(w, [parse("cross_coupling:r_x=0.01,r_z=-0.06")], SPEEDS, seed=3, **KW)
    for a, b in zip(clean.runs, test.runs):
        F = np.column_stack([a.signals[c] for c in ("Fx", "Fy", "Fz")])
        T = np.cross([0.01, 0.0, -0.06], F)
        for j, c in enumerate(("Tx", "Ty", "Tz")):
            np.testing.assert_allclose(b.signals[c] - a.signals[c], T[:, j], atol=1e-12 * np.abs(F).max())


def test_speed_proportional_sidebands_at_h_plus_minus_per_rev():
    w = preset("ithaco-e")
    # 16384 samples: the sidebands (0.9-2.4 Hz from the carrier) sit >= 7 bins from it, outside its leakage
    test = simulate_with_injections(w, [parse("sidebands:direction=radial_force,h=1,depth=0.4,per_rev=0.06")],
                                    SPEEDS, **{**KW, "n_samples": 16384})
    for r in test.runs:
        fw = abs(r.speed) / (2 * np.pi)
        X = {k: dft(r.signals["Fx"], k * fw, r.sample_rate) for k in (0.94, 1.0, 1.06)}
        assert abs(X[0.94]) / abs(X[1.0]) == pytest.approx(0.2, rel=0.05)
        assert abs(X[1.06]) / abs(X[1.0]) == pytest.approx(0.2, rel=0.05)


def test_fixture_resonance_reaches_the_stand_and_meta(tmp_path, capsys):
    out = tmp_path / "d"
    assert main(["simulate-test", str(out), "--preset", "ithaco-e", "--speeds-rpm", "600:2400", "--n-speeds", "4",
                 "--samples", "1024", "--inject", "fixed_resonance:f_hz=180,zeta=0.02,gain=4"]) == 0
    test = data_io.read_data(out)
    inj = test.meta["injected"]
    assert inj[0]["kind"] == "fixed_resonance" and inj[0]["f_hz"] == 180.0 and len(inj[0]["channels"]) == 6


def test_diagnose_names_the_injected_missing_harmonic(tmp_path, capsys):
    """End to end as a user would: simulate with an injection, diagnose against the preset, read it back.
    16 speeds (24 took 8.5 s of CPU, 16 take 5.4 s): h = 0.5000 and C/C_true = 1.00002 (24 speeds: 0.5000,
    0.99978; 12 speeds: 0.4999, 0.99995) against tolerances of 0.01 and 5 %."""
    import json

    data, rep = tmp_path / "d", tmp_path / "r"
    assert main(["simulate-test", str(data), "--preset", "ithaco-e", "--speeds-rpm", "600:2400", "--n-speeds", "16",
                 "--sample-rate", "1920", "--samples", "4096", "--no-modes",
                 "--inject", "missing_harmonic:direction=radial_force,h=0.5,fraction=0.5"]) == 0
    assert main(["diagnose", str(data), "-o", str(rep), "--preset", "ithaco-e"]) == 0
    effects = json.loads((rep / "model.json").read_text())["effects"]
    assert [e["kind"] for e in effects] == ["missing_harmonic"]
    c1 = dict(preset("ithaco-e").harmonics["radial_force"])[1.0]
    assert effects[0]["h"] == pytest.approx(0.5, abs=0.01)
    assert effects[0]["C"] == pytest.approx(0.5 * c1, rel=0.05)
