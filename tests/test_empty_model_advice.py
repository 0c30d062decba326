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
