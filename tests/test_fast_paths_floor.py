"""``broadband_floor``'s floor law (:func:`rwadist.effects.broadband_floor_diagnose._floor_law`: every exponent of an
IRLS pass solved at once) against the plain loop over the exponents it replaces, on floors that grow (with scatter,
empty bands and bands of zero data) and on flat noise."""
import numpy as np
import pytest

from rwadist.diagnose.constants import FLOOR_EXPONENTS
from rwadist.effects.broadband_floor_diagnose import _floor_law


def _plain_floor_law(wt, y, x0):
    """Three IRLS passes, one exponent at a time (the least squares y = n + g·x per band, the smallest SSE kept)."""
    level = np.maximum(np.sum(wt * y, 0) / np.maximum(wt.sum(0), 1e-300), 1e-300)
    expected = np.broadcast_to(level, y.shape)
    for _ in range(3):
        wts = wt / np.maximum(expected / float(np.max(level)), 1e-12) ** 2
        best = None
        for p in FLOOR_EXPONENTS:
            x = x0[:, None] ** p
            s0, s1, s2 = wts.sum(0), (wts * x).sum(0), (wts * x * x).sum(0)
            t0, t1 = (wts * y).sum(0), (wts * x * y).sum(0)
            det = s0 * s2 - s1 * s1
            with np.errstate(divide="ignore", invalid="ignore"):
                g = np.maximum(np.where(det > 0, (s0 * t1 - s1 * t0) / det, 0.0), 0.0)
            n = np.where(s0 > 0, np.maximum((t0 - g * s1) / np.maximum(s0, 1e-300), 0.0), 0.0)
            sse = float(np.sum(wts * (y - n - g * x) ** 2))
            if best is None or sse < best[0]:
                best = (sse, p, n, g)
        _, p, n, g = best
        expected = np.maximum(n[None, :] + g[None, :] * x0[:, None] ** p, 1e-300)
    return best[1:]


@pytest.mark.parametrize("n_runs, n_bands, p_true, seed", [(60, 48, 3.0, 1), (20, 9, 1.5, 2), (120, 100, 6.0, 3),
                                                             (5, 3, 0.0, 4), (40, 30, 2.0, 5)])
def test_floor_law_is_the_loop_over_exponents(n_runs, n_bands, p_true, seed):
    rng = np.random.default_rng(seed)
    x0 = np.sort(rng.uniform(0.15, 1.6, n_runs))
    noise = rng.uniform(0.5, 2.0, n_bands)
    growth = rng.uniform(0.0, 3.0, n_bands) * (p_true > 0)
    y = (noise[None, :] + growth[None, :] * x0[:, None] ** p_true) * rng.gamma(8.0, 1 / 8.0, (n_runs, n_bands))
    wt = rng.integers(0, 9, (n_runs, n_bands)).astype(float)
    wt[:, 0] = 0.0                              # a band no run can use
    y[:, -1] = 0.0                              # a band of zero data
    got, ref = _floor_law(wt, y, x0), _plain_floor_law(wt, y, x0)
    assert got[0] == ref[0]
    if p_true > 0:
        assert abs(got[0] - p_true) <= 1.0      # the law found is the one made (the comparison is not of two zeros)
    np.testing.assert_array_equal(got[1], ref[1])
    np.testing.assert_array_equal(got[2], ref[2])
