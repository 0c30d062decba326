"""A line whose strength scatters from run to run is read at its median law by the suspension-mode fit
(rwadist.line_scatter), judged on the fit's own residuals; a line's smooth gain through a mode is not scatter."""
import numpy as np

from rwadist.empirical import LineFit
from rwadist.line_scatter import at_median_law, scattering, spread

OMEGA = np.linspace(300.0, 3000.0, 20) * np.pi / 30.0


def _line(amplitude, omega, channels=("Fx", "Fy")):
    """A radial line measured on both channels of the pair at every speed, clear of the noise."""
    n = omega.size
    return LineFit(direction="radial_force", h=2.3, C=1e-6, C_stderr=0.0, C_all=1e-6,
                   speed=np.tile(omega, len(channels)), channel=np.repeat(np.array(channels), n),
                   amplitude=np.tile(amplitude, len(channels)), used=np.ones(n * len(channels), bool),
                   excluded_rpm=[], presence=1.0, n_possible=n, noise=np.full(n * len(channels), 0.01))


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


def test_the_line_whose_residuals_scatter_far_beyond_the_others_is_the_one_read_at_its_median_law():
    rng = np.random.default_rng(5)
    n_lines = 6
    row_line = np.repeat(np.arange(n_lines), OMEGA.size)
    row_speed = np.tile(OMEGA, n_lines)
    residuals = rng.normal(0.0, 0.03, row_line.size)                  # the fit's own scatter, ~0.3 dB
    residuals[row_line == 4] = rng.normal(0.0, 0.9, OMEGA.size)       # 8 dB from run to run
    # a smooth misfit (a law of its own, Ω^2.5 read as Ω²) and one run far off (a crossing the fit misses): no scatter
    residuals[row_line == 1] += 0.5 * np.log(OMEGA / OMEGA.mean())
    residuals[(row_line == 2) & (row_speed == OMEGA[7])] += 2.0
    assert scattering(residuals, row_line, row_speed) == [4]
    # every line alike scattering (a noisy test): none stands out
    assert scattering(rng.normal(0.0, 0.9, row_line.size), row_line, row_speed) == []
    # too few speeds to tell
    few = row_speed < OMEGA[7]
    assert scattering(residuals[few], row_line[few], row_speed[few]) == []


def test_a_line_read_at_its_median_law_keeps_its_median_strength_in_each_channel():
    rng = np.random.default_rng(5)
    strength = 10 ** (rng.normal(0.0, 8.0, OMEGA.size) / 20)
    noisy, steady = _line(1e-6 * OMEGA**2 * strength, OMEGA), _line(2e-6 * OMEGA**2, OMEGA)
    out = at_median_law([steady, noisy], [1])
    assert out[0] is steady and out[1] is not noisy
    assert np.allclose(out[1].amplitude / out[1].speed**2, np.median(strength) * 1e-6, rtol=1e-12)
    assert np.array_equal(noisy.amplitude, np.tile(1e-6 * OMEGA**2 * strength, 2))     # the input left as it was
