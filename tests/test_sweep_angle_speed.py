"""A sweep slice's speed from the data is its mean speed, read on the imbalance's angle (rwadist.sweep._angle_speeds).

A line's peak in a slice of a run-up lies where the line spends its power: its amplitude C·Ω² grows across the slice,
so every line's peak, and the speed fitted to them, read high by ~(ΔΩ/Ω)²/20 of the slice's change ΔΩ.  The
session-69 new-user trial's 60-s run-up 500 -> 9000 rpm without a speed column read 0.30 % high at 572 rpm and
0.041 % at 1733 rpm, where its 3.62 line crossed the rocking whirl at the whirl's peak: there the line's peak, pulled
0.57 Hz to the whirl, fell out of its harmonic's tolerance, the one measured speed on the peak was lost and the
rocking mode's damping (0.015) was "not constrained, 5e-05-0.0072" (0.016 with the tach).  The imbalance turns at
exactly 1x the rotor: its angle's rise over the slice is the slice's mean speed, as a tach's mean is.

Truth: tests/family_wheel.py's own speed profile (the generator's, no rwadist physics), each slice's mean.
"""
import functools
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist.sweep import estimate_speed_track  # noqa: E402

#: (wheel, rpm from, rpm to, duration s, sample rate Hz, slice samples): run-ups whose low slices change by 5-20 %
CASES = ((0, 500.0, 6000.0, 40.0, 2500.0, 2048), (2, 400.0, 3000.0, 40.0, 2000.0, 2048))


@functools.lru_cache(maxsize=None)
def _errors(case: tuple) -> tuple:
    """(relative error of each slice's speed from the data against its true mean speed, the speed's relative change
    across the slice), the slices with a speed, in time order."""
    w, lo, hi, duration, fs, n = case
    data = fw.sweep(fw.family()[w], lo, hi, duration, sample_rate=fs, noise=0.002, seed=5)
    infos, _ = estimate_speed_track(family_test.sweep_record(data), n)
    truth = np.array([data.speed[i.start:i.stop].mean() for i in infos])
    change = np.array([np.ptp(data.speed[i.start:i.stop]) for i in infos]) / np.abs(truth)
    err = np.array([i.speed for i in infos]) / truth - 1.0
    ok = np.isfinite(err)
    return err[ok], change[ok]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"wheel{c[0]}-{c[1]:.0f}-{c[2]:.0f}rpm")
def test_slice_speed_is_the_slice_mean_not_the_power_weighted_peak(case):
    """The slices after the first whose speed changes by 5 % or more across them (7-17 %): their speeds from the data
    within 0.1 % of the true means each and unbiased (median within 0.03 %); the peaks had read them 0.12-0.16 %
    high (median) and up to 0.9 % off.  Every slice within 0.5 %."""
    err, change = _errors(case)
    fast = np.arange(err.size) >= 1
    fast &= change >= 0.05
    assert fast.sum() >= 8
    assert abs(float(np.median(err[fast]))) < 3e-4, np.round(100 * err[fast], 4)
    assert np.max(np.abs(err[fast])) < 1e-3, np.round(100 * err[fast], 4)
    assert np.max(np.abs(err)) < 5e-3
