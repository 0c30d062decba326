"""The extended fit locates the suspension modes of wheels of the family generated without rwadist's physics
(tests/family_wheel.py: masses 2-12 kg, I_zz/I_rr 1.2-2.0, modes 54-600 Hz, bearing-like lines with random rotation
senses), on a short test (16 speeds, 4096 samples): every mode within 2 %, none declared unconstrained.

The case that failed: a scan that took a radial line measured >= 90 % co-rotating at the load cell for a purely
co-rotating load.  The whirls amplify one sense more than the other, so a line forced 80 % co-rotating reads more
co-rotating near the forward whirl; scanned co-rotating only, the rocking mode of wheel #0 (95 Hz) came out at 87 Hz
and the least squares then ran off to 1848 Hz (#3: 70 Hz -> 2409 Hz).

The family's wheels #2 and #7 have I_zz/I_rr 2.2 and 2.1, above the 2 of a rigid rotor about its centre of mass: a
scan capped at 2 put their rocking mode 4.1 % and 2.8 % high to make up the whirl (and diagnose then invented an
amplitude law on the imbalance).  The ratio is an effective one (rwadist.schema.MAX_INERTIA_RATIO): it is fitted
there too, within 5 % of the generator's.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.data import SteadyTest  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.extended_fit import fit_extended  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_resonance import _mode_hz  # noqa: E402


def _test_of(wheel, n_speeds=16, n_samples=4096, seed=1, noise=0.01) -> SteadyTest:
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, n_speeds), n_samples=n_samples,
                     noise=noise, seed=seed)
    return steady_test(data)


@pytest.mark.parametrize("index", range(8))
def test_family_wheel_modes_are_located(index):
    wheel = fw.family()[index]
    test = _test_of(wheel)
    efit = fit_extended(test, fit_empirical(compute_spectra(test)))
    assert not efit.unconstrained
    got = _mode_hz(efit.params)
    for name, truth in wheel.modes_hz().items():
        assert got[name] == pytest.approx(truth, rel=0.02), (name, got[name], truth)
    assert efit.params.inertia_ratio == pytest.approx(wheel.inertia_ratio, rel=0.05)


@pytest.mark.parametrize("seed", [1, 2, 6])
def test_the_imbalance_tells_the_rocking_from_its_inertia_ratio(seed):
    """Wheel #2 (I_zz/I_rr 2.2, rocking 50 Hz, 300-3000 rpm) at 3 % noise, 20 speeds: its radial torque shows two
    lines clear of the noise, the imbalance and a co-rotating bearing line, so only the forward whirl, and with
    a > 2 the 1x line never crosses it: the imbalance's attenuation 1/(1 + (a − 1)(Ω/ω0)²) (U_d·Ω² through the
    rocking, a smooth trend over the speeds) is what tells f0 from a.  With an exponent of its own allowed to it (the
    scan's and the least squares' off-law option), f0 traded off against a (seeds 1, 2, 6: 44.7, 46.3, 48.0 Hz at
    a = 2.68, 2.54, 2.40), and diagnose named the trend an amplitude law on the imbalance."""
    wheel = fw.family()[2]
    test = _test_of(wheel, n_speeds=20, seed=seed, noise=0.03)
    efit = fit_extended(test, fit_empirical(compute_spectra(test)))
    assert not efit.unconstrained
    assert _mode_hz(efit.params)["rocking"] == pytest.approx(wheel.modes_hz()["rocking"], rel=0.02)
    assert efit.params.inertia_ratio == pytest.approx(wheel.inertia_ratio, rel=0.05)
    assert not [n for n in efit.notes if n.startswith("radial_torque h=1:")]


def test_a_fitted_ratio_above_two_is_reported_as_an_effective_one():
    """The fitted I_zz/I_rr of wheel #7 (2.1) is described as above a rigid rotor's bound, #0's (1.56) is not."""
    from rwadist.effects.suspension_modes import SuspensionModes

    for index, above in ((7, True), (0, False)):
        test = _test_of(fw.family()[index])
        p = fit_extended(test, fit_empirical(compute_spectra(test))).params
        entry = {"radial_translation_Hz": 1.0, "rocking_Hz": 1.0, "axial_Hz": 1.0, "zeta_radial_translation": 0.01,
                 "zeta_rocking": 0.01, "zeta_axial": 0.01, "inertia_ratio": p.inertia_ratio}
        assert ("no rigid rotor" in SuspensionModes.describe(entry)) is above, (index, p.inertia_ratio)


@pytest.mark.parametrize("index, ratio", [(0, 1.567), (6, 1.65), (1, 1.213)])
@pytest.mark.parametrize("seed", [1, 2])
def test_the_inertia_ratio_is_read_between_the_scans_grid_points(index, ratio, seed):
    """trial15: a wheel of I_zz/I_rr 1.95 read 1.96 (the scan's grid step, 0.02, never refined: the extended fit frees
    k and c only); its forward whirl moved 0.4 %, the 2x radial torque line passing near it was under-predicted by
    up to 16 % and diagnose named an amplitude law on clean data.  Family wheels #0, #6 and #1 with ratios off that
    grid: read within 0.004 (was 0.007-0.01 off)."""
    from dataclasses import replace

    wheel = replace(fw.family()[index], I_zz=ratio * fw.family()[index].I_rr)
    test = _test_of(wheel, seed=seed)
    efit = fit_extended(test, fit_empirical(compute_spectra(test)))
    assert not efit.unconstrained
    assert efit.params.inertia_ratio == pytest.approx(ratio, abs=0.004)
