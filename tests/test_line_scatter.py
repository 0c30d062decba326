"""The run-to-run spread of a line's strength (rwadist.line_scatter): independent runs read their scatter, a line's
smooth gain through a mode reads none."""
import numpy as np

from rwadist.line_scatter import spread

OMEGA = np.linspace(300.0, 3000.0, 20) * np.pi / 30.0


def test_the_spread_of_independent_runs_is_their_scatter_and_a_mode_crossing_is_none():
    rng = np.random.default_rng(3)
    # independent runs of rms s: the departure from the median of four neighbours has rms ~1.2 s (the median's own
    # scatter adds), its robust spread reads that; many draws, so the check is of the estimator, not of one draw
    reads = [spread(rng.normal(0.0, 0.5, 40)) for _ in range(200)]
    assert 0.5 < np.median(reads) < 0.75
    # a smooth gain through a mode (ζ 0.01, crossed between two speeds: a peak of 34 dB over one or two runs)
    f = 2.3 * OMEGA / (2 * np.pi)
    for f_mode in (60.0, 87.0):
        gain = 1.0 / np.abs(1.0 - (f / f_mode) ** 2 + 2j * 0.01 * f / f_mode)
        assert spread(np.log(gain)) < 0.05, f_mode
