"""The line levels fitted with a test stand on the empirical base (rwadist.diagnose.stand_levels), against closed
forms."""
import numpy as np
import pytest

from rwadist.diagnose.stand_levels import fit_with_levels, levelled_harmonics
from rwadist.model import Harmonic, WheelModel
from rwadist.resonance import general_log_power_gain


def _points(scatter: bool):
    """Three lines h 1, 2, 3.5 over 300-3000 rpm under a transmissibility at 90 Hz (ζ 0.03), their levels off the base
    by factors 0.5, 1.3 and 2 in power; ``scatter``: the first line's power on one channel changes from run to run as
    a planar line's does, 2cos²(θ/2) of its mean (θ uniform: a geometric mean of 1/4), scaled so that its mean power,
    weighted as the level reads it (predicted·|H|²), is the line's."""
    rng = np.random.default_rng(2)
    w = np.linspace(300, 3000, 24) * np.pi / 30
    f = np.concatenate([h * w / (2 * np.pi) for h in (1.0, 2.0, 3.5)])
    lines = np.repeat(np.arange(3), w.size)
    lg, _ = general_log_power_gain(f, 90.0, 0.03, 1.0, 0.0)
    predicted = np.concatenate([(h * w) ** 4 for h in (1.0, 2.0, 3.5)]) * 1e-12
    share = np.ones(f.size)
    if scatter:
        s = 2 * np.cos(rng.uniform(0, 2 * np.pi, w.size) / 2) ** 2
        weight = (predicted * np.exp(lg))[: w.size]
        share[: w.size] = s * weight.sum() / np.sum(weight * s)
    y = lg + np.log(np.array([0.5, 1.3, 2.0]))[lines] + np.log(share)
    return f, y, np.ones(f.size), lines, predicted


@pytest.mark.parametrize("scatter", [False, True])
def test_levels_are_the_lines_mean_power_over_the_resonance(scatter):
    f, y, wt, lines, predicted = _points(scatter)
    start = [(85.0, 0.03, 1.0, 0.0)]
    f_r, zeta, _, _, levels, _ = fit_with_levels(f, y, wt, lines, 20.0, 400.0, start, predicted)
    tol = 0.01 if scatter else 1e-6
    assert (f_r, zeta) == pytest.approx((90.0, 0.03), rel=tol)
    assert levels == pytest.approx(np.log([0.5, 1.3, 2.0]), abs=3 * tol)
    if scatter:
        # the mean of the log gains reads the scattering line at its geometric mean
        *_, log_mean, _ = fit_with_levels(f, y, wt, lines, 20.0, 400.0, start)
        assert log_mean[0] < np.log(0.5) - 0.3


def test_a_levelled_line_keeps_its_relative_error_and_loses_its_exclusions():
    m = WheelModel(name="w", empirical={"radial_force": [
        Harmonic(h=1.0, C=2e-6, C_stderr=1e-8), Harmonic(h=2.0, C=1e-6, C_stderr=4e-9, excluded_rpm=[[900, 1200]])]})
    (a, b) = levelled_harmonics(m, [("radial_force", 2.0, 3.0)])["radial_force"]
    assert (a.C, a.C_stderr) == (2e-6, 1e-8)
    assert (b.C, b.C_stderr) == pytest.approx((3e-6, 1.2e-8)) and b.excluded_rpm == []


def _two_kinds_of_line(seed: int):
    """Four lines over 1000-10000 rpm (24 speeds) under a transmissibility at 300 Hz (ζ 0.03): two lifted through it
    whose log powers scatter 0.002 (h 2 and 3.36, far over the noise), two above it at every speed that the fixture
    attenuates toward the noise, scattering 0.05 (h 5.64 and 6.72), every point of SNR weight 1."""
    rng = np.random.default_rng(seed)
    w = np.linspace(1000, 10000, 24) * np.pi / 30
    hs, sd = (2.0, 3.358, 5.642, 6.716), (0.002, 0.002, 0.05, 0.05)
    f = np.concatenate([h * w / (2 * np.pi) for h in hs])
    lines = np.repeat(np.arange(len(hs)), w.size)
    lg, _ = general_log_power_gain(f, 300.0, 0.03, 0.0, 0.0)
    y = lg + np.array(sd)[lines] * rng.standard_normal(f.size)
    return f, y, np.ones(f.size), lines


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lines_that_scatter_more_weigh_less(seed, monkeypatch):
    """Each line weighted by its own scatter about the first fit (second pass): the resonance is read where the lines
    measure it best.  With one weight for every line (the first pass alone) the scattered lines pull its frequency
    (family wheel 5 hard mounted on a 300-Hz transmissibility: 1.2e-4 off, the error after 6x what the truth's
    frequency leaves)."""
    from rwadist.diagnose import stand_levels as sl

    f, y, wt, lines = _two_kinds_of_line(seed)
    start = [(295.0, 0.03, 1.0, 0.0)]
    f_r, zeta, gain, above, _, _ = fit_with_levels(f, y, wt, lines, 20.0, 1000.0, start)
    assert f_r == pytest.approx(300.0, rel=2e-5) and zeta == pytest.approx(0.03, rel=2e-3)
    assert gain == pytest.approx(1 / 0.06, rel=3e-3) and abs(above) < 1e-3
    # the premise: one weight for every line reads the frequency several times farther off
    monkeypatch.setattr(sl, "_scatter_weights", lambda res, inverse, w, w_sum: w)
    f_one, *_ = fit_with_levels(f, y, wt, lines, 20.0, 1000.0, start)
    assert abs(f_one / 300.0 - 1) > 3 * abs(f_r / 300.0 - 1)
