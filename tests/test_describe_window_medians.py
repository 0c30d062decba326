"""The running median of the open world's run-change trend (rwadist.diagnose.describe_structure._window_medians, all
windows at once) gives numpy.median's numbers of each window, taken one by one as the definition says: the ``half``
kept neighbours on either side of each point and the point itself when kept, NaN when a window holds one."""
import numpy as np

from rwadist.diagnose.describe_structure import _window_medians


def _one_by_one(rest, kept, half):
    out = np.empty(rest.size)
    for i in range(rest.size):
        p = int(np.searchsorted(kept, i))
        own = p < kept.size and kept[p] == i
        out[i] = np.median(rest[kept[max(0, p - half):p + half + (1 if own else 0)]])
    return out


def test_window_medians_are_numpy_medians_of_each_window():
    rng = np.random.default_rng(7)
    for case in range(400):
        n = int(rng.integers(1, 30))
        rest = rng.standard_normal(n).round(int(rng.integers(0, 3)))       # ties too
        if case % 5 == 0:
            rest[rng.integers(n)] = np.nan
        kept = np.flatnonzero(rng.random(n) > (0.0 if case % 2 else 0.4))
        if kept.size == 0:
            kept = np.array([int(rng.integers(n))])
        half = int(rng.integers(1, 5))
        got, want = _window_medians(rest, kept, half), _one_by_one(rest, kept, half)
        assert np.array_equal(got, want, equal_nan=True), (case, got, want)
