"""Every fixture resonance fitted at once with the wheel's modes (rwadist.stand_every).

Two fixtures on either side of the radial translation, found one at a time and each fitted while the other was held,
settled off their truth and pulled the translation with them (family wheel 1, 0.81x and 1.25x its 520 Hz translation:
the second stand ζ 0.026 against 0.03, the translation +0.16 %, the error after 15.7x the clean cell's).  References
independent of the fit: the closed form of the single-mode gain (:func:`rwadist.resonance.resonance`) and the
family generator's truth (tests/family_wheel.py writes its own physics, not rwadist's).
"""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.extended_fit import to_model  # noqa: E402
from rwadist.model import from_json as model_from_json  # noqa: E402
from rwadist.model import to_json as model_to_json  # noqa: E402
from rwadist.resonance import resonance  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_every import FittedStands, log_data  # noqa: E402
from rwadist.stand_resonance import _mode_hz, fit_extended_beside_stand  # noqa: E402

STANDS = ((120.0, 0.03, 5.0, 1.0), (210.0, 0.05, 3.0, 0.8))


def test_the_group_gain_is_the_product_of_the_closed_forms():
    """Σ ln|H_k|² at the starts is ln of the product of each resonance's closed-form |H|² (γ from the peak gain)."""
    f = np.linspace(50.0, 400.0, 301)
    group = FittedStands(STANDS, f)
    want = sum(np.log(np.abs(resonance(f, *s)) ** 2) for s in STANDS)
    lg, _ = group.log_gain(group.x0)
    np.testing.assert_allclose(lg, want, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(group.start_log_gain, want, rtol=1e-10, atol=1e-12)
    for got, s in zip((group.stand(group.x0),) + group.more(group.x0), STANDS):
        np.testing.assert_allclose(got, s, rtol=1e-9)
    assert len(set(group.NAMES)) == len(group.NAMES) == 8


def test_the_group_derivatives_are_the_central_differences():
    f = np.linspace(50.0, 400.0, 301)
    group = FittedStands(STANDS, f)
    x = group.x0 + np.array([0.01, -0.05, 0.3, 0.02, -0.01, 0.1, -0.2, 0.05])
    _, d = group.log_gain(x)
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(x[i]))
        up, dn = x.copy(), x.copy()
        up[i] += h
        dn[i] -= h
        num = (group.log_gain(up)[0] - group.log_gain(dn)[0]) / (2 * h)
        np.testing.assert_allclose(d[:, i], num, rtol=1e-4, atol=1e-6)


def test_two_fixtures_are_fitted_at_their_truth_beside_the_modes():
    """Family wheel 1 (modes 520/180/260 Hz, 16 speeds to 10000 rpm, 8192 samples, noise 0.3 % of the top imbalance
    load) with the matrix's fixture pair (0.81x and 1.25x the translation, ζ 0.03, peak gain 5 each): both stands within
    0.1 % in frequency and 2 % in ζ and peak gain, the translation within 0.05 % and its ζ within 1 % of the generator's
    (measured: at most 0.044 %, 0.5 %, 0.9 %; 0.002 %, 0.2 %).  Each found with the other held (before): the 421.9 Hz
    stand -0.22 %, ζ +3.4 %; the 650.8 Hz one ζ -14 %, peak gain -4.4 %; the translation +0.16 %, its ζ +2.8 %."""
    wheel = replace(fw.family()[1], n_speeds=16, n_samples=8192)
    f_tr = wheel.modes_hz()["radial_translation"]
    fixtures = [fe.Fixture(f_hz=k * f_tr, zeta=0.03, gain=5.0) for k in (0.81, 1.25)]
    data = fw.steady(wheel, noise=0.003, seed=101, effects=fixtures)
    test = steady_test(data)
    fit = fit_empirical(compute_spectra(test))
    efit = fit_extended_beside_stand(test, fit)
    stands = sorted(((efit.stand,) if efit.stand is not None else ()) + tuple(efit.more_stands))
    assert len(stands) == 2
    # the model file records both (the one the modes were first fitted beside, and the further one)
    record = model_from_json(model_to_json(to_model(efit, fit))).analytical["fit"]
    written = sorted([record["test_stand"]] + record["more_test_stands"], key=lambda k: k["f_Hz"])
    assert [k["f_Hz"] for k in written] == pytest.approx([s[0] for s in stands], rel=1e-12)
    for (f_r, zeta, gain, _above), fx in zip(stands, fixtures):
        assert f_r == pytest.approx(fx.params["f_hz"], rel=0.001)
        assert zeta == pytest.approx(0.03, rel=0.02)
        assert gain == pytest.approx(5.0, rel=0.02)
    assert not efit.unconstrained
    assert _mode_hz(efit.params)["radial_translation"] == pytest.approx(f_tr, rel=0.0005)
    assert efit.zeta["radial_translation"] == pytest.approx(wheel.zeta_trans, rel=0.01)


def test_further_stands_beside_a_structure_mode_are_refused_not_left_held():
    """log_data fits further stands (FittedStands) or one structure mode on one direction, never both at once."""
    z = np.zeros(0)
    with pytest.raises(ValueError, match="structure mode on radial_force"):
        log_data([], z.astype(int), z, z, z.astype(int), z, z, (100.0, 0.03, 5.0, 1.0), "radial_force",
                 ((200.0, 0.03, 5.0, 1.0),))


def test_a_line_at_the_noise_floor_does_not_choose_the_stands():
    """Family wheel 2 (modes 90/50/62 Hz, 20 speeds to 3000 rpm, 4096 samples, noise 3 % of the top imbalance load)
    with the matrix's fixture pair (70.93 and 115.71 Hz, 0.79x and 1.29x the translation, ζ 0.03, peak gain 5 each;
    seed 201, the matrix's cell): both stands within 0.2 % in frequency, 5 % in ζ and 3 % in peak gain, the rocking
    within 0.6 % of the generator's (measured: +0.10 %/-0.045 %, +1.7 %/+0.5 %, -0.55 %/-0.76 %; +0.35 %).  The stands
    fitted at once were refused before on the plain cost, which one axial line at the noise floor decided (197.2 Hz,
    its log amplitude's noise 0.37): 70.29 Hz ζ 0.0252 peak 5.82 and 115.94 Hz ζ 0.0286 peak 4.79, the rocking +1.25 %."""
    wheel = replace(fw.family()[2], n_speeds=20, n_samples=4096)
    fixtures = [fe.Fixture(f_hz=f, zeta=0.03, gain=5.0) for f in (70.92739043534804, 115.71470403903852)]
    test = steady_test(fw.steady(wheel, noise=0.03, seed=201, effects=fixtures))
    efit = fit_extended_beside_stand(test, fit_empirical(compute_spectra(test)))
    stands = sorted(((efit.stand,) if efit.stand is not None else ()) + tuple(efit.more_stands))
    assert len(stands) == 2
    for (f_r, zeta, gain, _above), fx in zip(stands, fixtures):
        assert f_r == pytest.approx(fx.params["f_hz"], rel=0.002)
        assert zeta == pytest.approx(0.03, rel=0.05)
        assert gain == pytest.approx(5.0, rel=0.03)
    assert not efit.unconstrained
    assert _mode_hz(efit.params)["rocking"] == pytest.approx(wheel.modes_hz()["rocking"], rel=0.006)
    # every row of the least squares carries the noise of its log amplitude (what chose the stands)
    assert efit.line_noise.shape == efit.line_residuals[1].shape and np.all(efit.line_noise >= 0)
