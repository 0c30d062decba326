"""A narrow "hump" at a fixed line taken out before the search is the line's leftover main lobe (trial 30: a 50 Hz
mains family on every channel of an independent generator's wheel, described as three fixed lines, and on one seed
of three also as broadband humps at 47.6-52.5 and 147.7-152.6 Hz in Fz, 4 bins of 1.22 Hz, with fixture causes).
A hump wider than a lobe at the same place, or a narrow one on another channel or away from the line, stays."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.diagnose.describe import LINE_LOBE_BINS, on_a_fixed_line

DF = 1.220703125            # 5 kHz / 4096


def _hump(f0, f1, peak, chans=("Fz",)):
    return SimpleNamespace(f_Hz=(f0, f1), parameters={"peak_Hz": peak}, channels=chans)


MAINS = [SimpleNamespace(f_Hz=50.0 * k, channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")) for k in (1, 2, 3)]


@pytest.mark.parametrize("hump, lobe", [
    (_hump(47.61, 52.49, 50.05), True),                       # trial 30's, 4 bins on the 50 Hz line
    (_hump(147.7, 152.6, 150.15), True),
    (_hump(47.61, 52.49, 50.05, ("Tz",)), True),
    (_hump(30.0, 70.0, 50.0), False),                         # 33 bins: a hump that holds the line
    (_hump(57.0, 61.9, 59.5), False),                         # narrow, but 9.5 Hz off any line
    (_hump(47.61, 52.49, 50.05, ("Fq",)), False),              # no channel of the line's
])
def test_a_hump_is_a_lines_lobe_only_where_the_line_is_and_as_narrow(hump, lobe):
    assert on_a_fixed_line(hump, MAINS, DF) == lobe


def test_the_lobe_width_covers_a_hann_line_after_the_floors_three_bin_mean():
    # a Hann-windowed line between bins: its power over the floor by > 2 dB (the hump's edge) over at most 4 bins,
    # widened by the floor's 3-bin mean to 6: within LINE_LOBE_BINS
    n = 4096
    w = np.hanning(n + 1)[:-1]
    x = w * np.cos(2 * np.pi * 41.37 * np.arange(n) / n)
    p = np.abs(np.fft.rfft(x)) ** 2
    p = p / p.max() + 1e-3                       # a line 30 dB over a white floor
    db = 10 * np.log10(np.convolve(p, np.ones(3) / 3, mode="same") / 1e-3)
    assert (db > 2.0).sum() <= LINE_LOBE_BINS
