"""A speed line is a line: its lit bins stand over their own neighbourhood (trial 34).

An independent generator's wheel (9 kg, 400-4500 rpm) with a resonance moving 90 -> 140 Hz over the speeds on every
channel, lines and noise, its noise hump +22 dB: the bins of the hump, where the model holds only the white floor,
lit ridges along h = 2.58-2.97 through the runs where it lay, and three ``speed_line`` records were described, one on
Tz, which held noise only; with the narrow test, none (the hump and the moving resonance described as before).
Here the data-over-model ratio of a Welch estimate is drawn from its χ² law (``dof`` degrees of freedom) over a
hump of that height and width, with lines on and beside it."""
from __future__ import annotations

import numpy as np
from scipy import stats

from rwadist.diagnose.describe_lines import LIT_FALSE_ALARM, _narrow

DOF = 14


def _ratio(seed, lines=()):
    rng = np.random.default_rng(seed)
    k = np.arange(1024)
    hump = 1.0 + 160.0 / (1.0 + ((k - 400.0) / 16.0) ** 2)                 # +22 dB, half-width 16 bins
    ratio = hump[None, :] * rng.chisquare(DOF, (24, k.size)) / DOF
    for at, x in lines:
        ratio[:, at] *= x
    return ratio, hump


def test_a_hump_of_noise_lights_no_more_bins_than_the_false_alarm_level_and_a_line_on_it_stands():
    thr = stats.chi2.isf(LIT_FALSE_ALARM, DOF) / DOF
    for seed in (1, 2, 3):
        ratio, hump = _ratio(seed, lines=((700, 30.0), (410, 30.0)))
        in_hump = hump > 2.0
        plain = ratio > thr
        narrow = _narrow(ratio, thr, plain)
        assert plain[:, in_hump].mean() > 0.5                 # without the test: the hump lit throughout
        hump_bins = in_hump.copy()
        hump_bins[[409, 410, 411]] = False
        assert narrow[:, hump_bins].mean() < 0.01
        assert narrow[:, 700].all() and narrow[:, 410].all()  # a line alone, and one 10 bins off the hump's centre
