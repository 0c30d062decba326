"""An empty empirical fit says its cause: too few spinning runs for a harmonic's 5 measurements (a new user's two-run
test was told to lower the presence threshold, which cannot help), else where to look (the band read, the speeds'
unit, the presence threshold)."""
import numpy as np
import pytest

import rwadist


def test_two_runs_are_told_a_harmonic_needs_five():
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=[900.0, 1800.0], n_samples=2048, seed=1)
    with pytest.warns(rwadist.RwadistWarning, match=r"needs 5 measurements and the test has 2 spinning run") as rec:
        fit = rwadist.fit(test)
    assert not any(fit.model.empirical.values())
    assert not any("lower `presence`" in str(w.message) for w in rec)


def test_a_band_below_every_line_is_told_to_check_the_band_and_the_speeds():
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 8), n_samples=2048, seed=1)
    with pytest.warns(rwadist.RwadistWarning, match=r"lines lie in the band read \(`f_lim`\).*speeds are in rpm"):
        fit = rwadist.fit(test, f_lim=3.0)
    assert not any(fit.model.empirical.values())


@pytest.mark.parametrize("wheel, factor", [
    ("ithaco-e", 60.0),                 # runs.csv speed_rpm written in rev/s: every line at 60 x its h
    ("ithaco-b", 60.0),
])
def test_speeds_given_in_rev_per_second_are_named_with_the_factor(wheel, factor):
    """A new user's speed column in Hz (rev/s) gave "the model is empty ... check that the speeds are in rpm" beside
    other causes; the imbalance's radial-force line says which: it sits at the column's value read in rev/s."""
    from dataclasses import replace

    test = rwadist.simulate_test(wheel, speeds_rpm=np.linspace(600, 2400, 8), n_samples=4096, seed=1)
    in_hz = type(test)([replace(r, speed=r.speed / factor) for r in test.runs], test.meta)
    with pytest.warns(rwadist.RwadistWarning, match=r"the speeds look like rev/s \(Hz\), not rpm") as rec:
        fit = rwadist.fit(in_hz)
    assert not any(fit.model.empirical.values())
    text = next(str(w.message) for w in rec if "rev/s" in str(w.message))
    assert "multiply them by 60" in text
    runs = int(text.split(" of 8 spinning")[0].rsplit(" ", 1)[1])
    assert runs >= 4, text
    # the same data in rpm: not named (a fit that is empty for another reason keeps the general words)
    with pytest.warns(rwadist.RwadistWarning, match=r"lines lie in the band read") as rec:
        rwadist.fit(test, f_lim=3.0)
    assert not any("rev/s" in str(w.message) for w in rec)


def test_the_command_exits_1_on_an_empty_model_and_keeps_it_for_inspection(tmp_path, capsys):
    """``rwadist fit`` of a two-run test: the empty model is written (to look at) but the command fails (exit 1,
    a check failed), so a script does not go on to a PSD or an FMU of zeros."""
    from cli_run import run

    data = tmp_path / "two"
    code, _, _ = run(capsys, "simulate-test", "--preset", "ithaco-e", data, "--speeds-rpm", "900,1800",
                     "--samples", "2048")
    assert code == 0
    code, out, err = run(capsys, "fit", data, "-o", tmp_path / "m.json", "--no-report")
    assert code == 1
    assert "needs 5 measurements" in err
    assert "ERROR: the model is empty" in err and "written for inspection" in err
    assert not any(rwadist.load_model(tmp_path / "m.json").empirical.values())
    # a test with lines still exits 0
    data8 = tmp_path / "eight"
    run(capsys, "simulate-test", "--preset", "ithaco-e", data8, "--speeds-rpm", "600:2400", "--n-speeds", "8",
        "--samples", "2048")
    code, _, _ = run(capsys, "fit", data8, "-o", tmp_path / "m8.json", "--no-report")
    assert code == 0

