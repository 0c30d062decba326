"""The ``gain_trend`` record's slope and its standard error (:func:`rwadist.diagnose.describe_trend.gain_trend`)
against a Monte Carlo of their generator.

Each line's ratios (dB of measured over predicted power) are the trend's slope times the speed plus the line's own
offset plus a noise of the line's own level, over 300-3000 rpm.  Two generators: six lines of 6 runs sharing one
noise level (4 degrees of freedom per line: weights 1/se² from them read the slope's scatter ~40 % low), and five
lines of 16-18 runs whose noise levels are family wheel 2's agreeing lines' (0.028-0.21 dB: their signal over the
noise from 10 to 40 dB; weighted by sxx alone, one pooled variance, the slope scatters 2.4x the optimum).  The record's
``slope_stderr_dB_per_krpm`` must read the draws' own scatter of its ``slope_dB_per_krpm`` within 20 %, and that
scatter stay within 1.3x the generator's inverse-variance optimum 1/sqrt(Σ sxx_l/σ_l²)."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.diagnose import describe_trend as dt
from rwadist.units import RAD_S_TO_RPM

#: the trend (dB of power per 1000 rpm: 1 − 0.08·Ω/Ω_max over 300-3000 rpm is −0.24)
SLOPE = -0.24
#: (direction, h) of the lines read: different h (a filter's slope against the frequency is told apart), 3 directions
LINES = [("radial_force", 1.0), ("radial_force", 4.57), ("radial_force", 6.43), ("axial_force", 1.0),
         ("axial_force", 2.0), ("radial_torque", 1.0)]
#: generators: (noise of each line dB, runs of each line)
EQUAL = ([0.08] * 6, [6] * 6)
WHEEL2 = ([0.028, 0.081, 0.042, 0.129, 0.212], [16, 17, 16, 17, 18])
RPM_ALL = np.linspace(300.0, 3000.0, 18)


def _ctx():
    return SimpleNamespace(runs=np.arange(RPM_ALL.size), omega=RPM_ALL / RAD_S_TO_RPM,
                           channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))


def _draw(rng, sds, ns):
    """[(direction, h, runs, rpm, f Hz, dB, has a law)] as :func:`describe_trend.read_lines` gives them: each line on
    ``n`` runs spread over the whole range."""
    out = []
    for (d, h), sd, n in zip(LINES, sds, ns):
        runs = np.unique(np.linspace(0, RPM_ALL.size - 1, n).round().astype(int))
        rpm = RPM_ALL[runs]
        db = SLOPE * rpm / 1000.0 + rng.normal(0.0, 1.0) + rng.normal(0.0, sd, rpm.size)
        out.append((d, h, runs, rpm, h * rpm / 60.0, db, False))
    return out


def _records(gen, n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    ctx, out = _ctx(), []
    orig = dt.read_lines
    try:
        for _ in range(n):
            lines = _draw(rng, *gen)
            dt.read_lines = lambda ctx, state, runs, lines=lines: lines
            (u,) = dt.gain_trend(ctx, None, lambda chans, hs, runs: (0.5, 1.0))
            p = u.parameters
            out.append((p["slope_dB_per_krpm"], p["slope_stderr_dB_per_krpm"], p["change_dB"]))
    finally:
        dt.read_lines = orig
    return np.array(out)


def _optimum(gen) -> float:
    """The inverse-variance weighted slope's standard error with the generator's own noise levels."""
    sds, ns = gen
    prec = 0.0
    for sd, n in zip(sds, ns):
        rpm = RPM_ALL[np.unique(np.linspace(0, RPM_ALL.size - 1, n).round().astype(int))] / 1000.0
        prec += float(np.sum((rpm - rpm.mean()) ** 2)) / sd**2
    return 1.0 / np.sqrt(prec)


@pytest.mark.parametrize("gen", [EQUAL, WHEEL2], ids=["one_noise_level", "wheel2_levels"])
def test_the_slopes_stderr_reads_its_scatter_over_draws_of_the_generator(gen):
    slope, se, change = _records(gen, 800).T
    # unbiased: the mean within 4 of its own standard errors of the truth
    assert abs(slope.mean() - SLOPE) < 4 * slope.std() / np.sqrt(slope.size)
    # the reported standard error (its rms over the draws) the draws' own scatter within 20 %
    assert np.sqrt(np.mean(se**2)) == pytest.approx(slope.std(), rel=0.2)
    # ... and that scatter near what the lines' noise allows at best
    assert slope.std() <= 1.3 * _optimum(gen)
    # the change over the speed range is the slope's
    assert change == pytest.approx(slope * np.ptp(RPM_ALL) / 1000.0)


def test_weighted_slope_of_lines_with_their_own_offsets():
    """Lines of one slope with offsets and runs of their own: the slope exactly when one line's noise is all there
    is; a line of 4 runs (ν = 2: no finite precision) gets no weight."""
    rng = np.random.default_rng(3)
    x1, x2 = np.linspace(0.3, 3.0, 8), np.linspace(0.5, 2.8, 7)
    y1 = 2.0 - 0.3 * x1 + rng.normal(0, 0.05, x1.size)
    s1, se1 = dt._weighted_slope([x1], [y1])
    xc = x1 - x1.mean()
    assert s1 == pytest.approx(float(xc @ (y1 - y1.mean()) / (xc @ xc)))
    r = y1 - y1.mean() - s1 * xc
    assert se1 == pytest.approx(np.sqrt((r @ r) / 6 / (xc @ xc) * 6 / 4))
    x4 = np.array([0.3, 1.0, 2.0, 3.0])
    assert dt._weighted_slope([x1, x4], [y1, 5.0 * x4]) == pytest.approx((s1, se1))
    s, _ = dt._weighted_slope([x1, x2], [y1, -1.0 - 0.3 * x2 + rng.normal(0, 0.05, x2.size)])
    assert s == pytest.approx(-0.3, abs=0.05)
