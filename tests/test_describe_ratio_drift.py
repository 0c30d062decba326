"""A line whose ratio to the speed drifts with it (a bearing's cage slipping) is described as a ``ratio_drift``
(trial 30b: a wheel whose cage slipped 5 % at its top speed, three seeds: never described, a mode declared
unconstrained, a test stand invented on one seed).

Records made here with numpy alone (no rwadist physics): rotating radial-force lines at h 1, the outer race's ball
pass BPFO = 8·0.41·(1 − s) and the inner race's 8 − BPFO, s = 0.05·(Ω/Ω_max)², on Fx/Fy and Fz; the truth of each
line's ratio at the lowest and highest speed is the formula's.  Without slip nothing is described."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.describe_drift import MIN_DRIFT, ratio_drift
from rwadist.diagnose.engine import Context
from rwadist.empirical import fit_empirical
from rwadist.spectra import compute_spectra

FS, N = 2000.0, 8192
RPM = np.linspace(600.0, 3000.0, 16)
CAGE, BALLS = 0.41, 8


def _test(slip: float, seed: int = 1) -> SteadyTest:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    runs = []
    for i, rpm in enumerate(RPM):
        om = rpm * 2 * np.pi / 60
        s = slip * (rpm / RPM[-1]) ** 2
        bpfo = BALLS * CAGE * (1 - s)
        sig = {c: 1e-4 * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        for h, C in ((1.0, 1e-5), (bpfo, 3e-6), (BALLS - bpfo, 2e-6)):
            a, ph = C * om**2, rng.uniform(0, 2 * np.pi)
            sig["Fx"] += a * np.cos(h * om * t + ph)
            sig["Fy"] += a * np.sin(h * om * t + ph)
            sig["Fz"] += 0.3 * a * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
            sig["Tx"] += 0.02 * a * np.cos(h * om * t + ph)
            sig["Ty"] += 0.02 * a * np.sin(h * om * t + ph)
        runs.append(Run(speed=om, sample_rate=FS, t0=0.0, name=f"run_{i:04d}.csv", signals=sig))
    return SteadyTest(runs=runs, meta={})


def _drifts(slip: float) -> list:
    test = _test(slip)
    sp = compute_spectra(test)
    ctx = Context(sp, test=test)
    return ratio_drift(ctx, SimpleNamespace(model=fit_empirical(sp).model), lambda chans, h, runs: (0.0, 0.0))


def test_a_slipping_cages_ball_pass_lines_are_described_with_their_drift():
    got = {(u.parameters["direction"], round(u.parameters["h"], 1)): u for u in _drifts(0.05)}
    lo, hi = (BALLS * CAGE * (1 - 0.05 * (r / RPM[-1]) ** 2) for r in (RPM[0], RPM[-1]))
    # the axial force's lines are in the empirical fit (these rotating radial ones, spread over their bins by the
    # drift, do not pass its presence threshold here: only a model's lines are read)
    assert {d for d, _ in got} == {"axial_force"}
    for d in ("axial_force",):
        outer = next(u for (dd, h), u in got.items() if dd == d and abs(h - 3.2) < 0.15)
        assert outer.parameters["h_at_lowest_speed"] == pytest.approx(lo, rel=0.005)
        assert outer.parameters["h_at_highest_speed"] == pytest.approx(hi, rel=0.005)
        inner = next(u for (dd, h), u in got.items() if dd == d and abs(h - 4.8) < 0.15)
        assert inner.parameters["h_at_highest_speed"] == pytest.approx(BALLS - hi, rel=0.005)
        assert outer.parameters["drift_percent"] < 0 < inner.parameters["drift_percent"]
        assert "cage slipping" in outer.causes[0] and "falls" in outer.causes[0] and "rises" in inner.causes[0]
    # no line read twice in a direction (a drifting line may be split in two by the fit's binning)
    dirs = [u.parameters["direction"] for u in got.values()]
    assert len(dirs) == len(set(zip(dirs, [round(u.parameters["h"], 1) for u in got.values()])))


def test_lines_at_constant_ratios_hold_no_drift():
    assert _drifts(0.0) == []
    assert MIN_DRIFT == 0.01
