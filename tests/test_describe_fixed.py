"""A line at one fixed frequency over part of the speed range (trial13: a stand's 317 Hz machine running above
5000 rpm, +10 dB on the waterfall in five channels, described by nothing) is described as a ``fixed_line`` with the
speeds it holds, on the default path (:func:`rwadist.api.diagnose`), on a wheel that is not the E wheel
(tests/standmodes_wheel.py, written without rwadist's physics); the same data without it describe nothing.

Checks against the truth the test puts in: the frequency within a Welch bin, the first speed it is in, the channels."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import standmodes_wheel as sw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.describe_fixed import _blocks  # noqa: E402

SPEEDS = np.linspace(600.0, 6000.0, 24)
TONE_HZ, ABOVE_RPM = 433.3, 3500.0


def _test(tone: bool):
    test, _ = sw.generate(sw.NEW_WHEEL, SPEEDS, sample_rate=5000.0, n_samples=4096, noise=0.01, seed=11)
    if tone:
        rng = np.random.default_rng(5)
        for run in test.runs:
            if run.speed * 60 / (2 * np.pi) > ABOVE_RPM:
                t = np.arange(run.signals["Fx"].size) / run.sample_rate
                std = np.std(run.signals["Fz"])
                for c in ("Fx", "Fz"):
                    run.signals[c] = run.signals[c] + 0.5 * std * np.cos(2 * np.pi * TONE_HZ * t + rng.uniform(0, 6.3))
    return test


@pytest.mark.slow
def test_a_tone_over_the_upper_speeds_is_described_with_its_speeds():
    d = api.diagnose(_test(tone=True))
    fixed = [u for u in d.unexplained if u.signature == "fixed_line"]
    assert len(fixed) == 1, [u.text() for u in d.unexplained]
    (u,) = fixed
    df = d.ctx.df
    assert u.f_Hz[0] == pytest.approx(TONE_HZ, abs=df)
    first = SPEEDS[SPEEDS > ABOVE_RPM].min()
    assert u.speed_rpm == pytest.approx((first, SPEEDS.max()), abs=1.0)
    assert {"Fx", "Fz"} <= set(u.channels)
    assert u.parameters["removed_before_the_search"] is False
    assert [e["kind"] for e in d.summary()["effects"]] == ["suspension_modes"]


@pytest.mark.slow
def test_the_same_wheel_without_it_describes_nothing():
    d = api.diagnose(_test(tone=False))
    assert not d.unexplained, [u.text() for u in d.unexplained]


def test_the_block_is_where_the_lit_runs_agree():
    """Runs sorted by speed: lit from run 15 of 24 (one gap) is the block 15-24; lit in every run, or in 3 only, or in
    alternate runs, is none (the other detector's, too short, no edge); lit in the top 4 is a block."""
    lit = np.zeros((24, 4), bool)
    lit[15:, 0] = True
    lit[18, 0] = False
    lit[:, 1] = True
    lit[21:, 2] = True
    lit[::2, 3] = True
    first, end, inside, outside = _blocks(lit)
    assert (first[0], end[0]) == (15, 24) and inside[0] == pytest.approx(8 / 9) and outside[0] == 0.0
    assert (end - first)[1:].tolist() == [0, 0, 0]
    lit[20, 2] = True
    first, end, inside, outside = _blocks(lit)
    assert (first[2], end[2]) == (20, 24) and inside[2] == 1.0 and outside[2] == 0.0
