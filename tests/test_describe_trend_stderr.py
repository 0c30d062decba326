"""The ``gain_trend`` record's slope and its standard error (:func:`rwadist.diagnose.describe_trend.gain_trend`)
against a Monte Carlo of their generator.

Each line's ratios (dB of measured over predicted power) are the trend's slope times the speed plus the line's own
offset plus a noise of one level common to the lines (6 runs over 300-3000 rpm, as family wheel 2's test: 4 degrees
of freedom per line).  The record's ``slope_stderr_dB_per_krpm`` must read the draws' own scatter of its
``slope_dB_per_krpm``: weighting each line by 1/se² from its own 4 degrees of freedom read it ~40 % low (and scattered
the slope more); the residual variance pooled over the agreeing lines reads it."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.diagnose import describe_trend as dt
from rwadist.units import RAD_S_TO_RPM

#: the trend (dB of power per 1000 rpm: 1 − 0.08·Ω/Ω_max over 300-3000 rpm is −0.24) and the lines' noise (dB)
SLOPE, SIGMA = -0.24, 0.08
RPM = np.linspace(300.0, 3000.0, 6)
#: (direction, h) of the lines read: different h (a filter's slope against the frequency is told apart), 3 directions
LINES = [("radial_force", 1.0), ("radial_force", 4.57), ("radial_force", 6.43), ("axial_force", 1.0),
         ("axial_force", 2.0), ("radial_torque", 1.0)]


def _ctx():
    runs = np.arange(RPM.size)
    return SimpleNamespace(runs=runs, omega=RPM / RAD_S_TO_RPM, channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))


def _draw(rng):
    """[(direction, h, runs, rpm, f Hz, dB, has a law)] as :func:`describe_trend._lines` gives them."""
    runs = np.arange(RPM.size)
    return [(d, h, runs, RPM, h * RPM / 60.0, SLOPE * RPM / 1000.0 + rng.normal(0.0, 1.0) + rng.normal(0.0, SIGMA, RPM.size),
             False) for d, h in LINES]


def _records(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    ctx, out = _ctx(), []
    orig = dt._lines
    try:
        for _ in range(n):
            lines = _draw(rng)
            dt._lines = lambda ctx, state, runs, lines=lines: lines
            (u,) = dt.gain_trend(ctx, None, lambda chans, hs, runs: (0.5, 1.0))
            p = u.parameters
            out.append((p["slope_dB_per_krpm"], p["slope_stderr_dB_per_krpm"], p["change_dB"]))
    finally:
        dt._lines = orig
    return np.array(out)


def test_the_slopes_stderr_reads_its_scatter_over_draws_of_the_generator():
    got = _records(1500)
    slope, se, change = got.T
    # unbiased: the mean within 4 of its own standard errors of the truth
    assert abs(slope.mean() - SLOPE) < 4 * slope.std() / np.sqrt(slope.size)
    # the reported standard error (its rms over the draws) the draws' own scatter within 20 %; the generator's own
    # (σ/sqrt(Σ sxx), every line's sxx alike) within 20 % too
    sxx = float(np.sum((RPM / 1000.0 - RPM.mean() / 1000.0) ** 2))
    truth = SIGMA / np.sqrt(len(LINES) * sxx)
    assert np.sqrt(np.mean(se**2)) == pytest.approx(slope.std(), rel=0.2)
    assert slope.std() == pytest.approx(truth, rel=0.2)
    assert np.median(se) == pytest.approx(truth, rel=0.2)
    # the change over the speed range is the slope's
    assert change == pytest.approx(slope * np.ptp(RPM) / 1000.0)


def test_pooled_slope_of_lines_with_their_own_offsets():
    """Noise-free lines of one slope, offsets and runs of their own: the slope exactly, its standard error 0; one
    run's ratio moved by d on a line of sxx q moves the slope by d·(x − x̄)/Σ sxx."""
    x1, x2 = np.array([0.3, 1.0, 2.0, 3.0]), np.array([0.5, 0.9, 1.4, 2.2, 2.8])
    s, se = dt._pooled_slope([x1, x2], [2.0 - 0.3 * x1, -1.0 - 0.3 * x2])
    assert s == pytest.approx(-0.3) and se == pytest.approx(0.0, abs=1e-12)
    y2 = -1.0 - 0.3 * x2
    y2[4] += 0.1
    s, se = dt._pooled_slope([x1, x2], [2.0 - 0.3 * x1, y2])
    sxx = np.sum((x1 - x1.mean()) ** 2) + np.sum((x2 - x2.mean()) ** 2)
    assert s == pytest.approx(-0.3 + 0.1 * (x2[4] - x2.mean()) / sxx)
    assert se > 0
