"""The sideband scans' per-offset medians (:func:`rwadist.effects.speed_sidebands_diagnose.side_pair_medians`, every
offset at once) against np.median of each offset's values one at a time, as the scans computed them: odd and even
counts, fewer than 6 values, a NaN among them, repeated values, one and several channels."""
import numpy as np
import pytest

from rwadist.effects.speed_sidebands_diagnose import side_pair_medians


def _loop(z, ok, cols):
    n = z.shape[1] // 2
    out = np.zeros(cols.size)
    for i, j in enumerate(cols):
        vals = np.concatenate([z[ok[:, j], j, :].ravel(), z[ok[:, n + j], n + j, :].ravel()])
        out[i] = float(np.median(vals)) if vals.size >= 6 else 0.0
    return out


@pytest.mark.parametrize("runs, n_side, chans, p_ok, seed", [(60, 117, 2, 0.8, 1), (7, 30, 1, 0.5, 2),
                                                             (30, 40, 3, 0.3, 3), (4, 10, 1, 0.9, 4)])
def test_side_pair_medians_are_numpy_medians(runs, n_side, chans, p_ok, seed):
    rng = np.random.default_rng(seed)
    z = rng.exponential(1.0, (runs, 2 * n_side, chans)) * rng.choice([1.0, 30.0], (runs, 2 * n_side, chans))
    z[:, ::7] = np.round(z[:, ::7])                              # ties
    ok = rng.random((runs, 2 * n_side)) < p_ok
    z[~ok] = np.nan                                             # unused points may hold anything (NaN here)
    z[0, 3, 0] = np.nan                                         # a NaN among the used values of one offset
    ok[0, 3] = True
    cols = np.arange(n_side)
    got, ref = side_pair_medians(z, ok, cols), _loop(z, ok, cols)
    np.testing.assert_array_equal(got, ref)
    assert np.any(got > 0) and np.any(got == 0) or runs > 10
    sub = cols[::3]
    np.testing.assert_array_equal(side_pair_medians(z, ok, sub), _loop(z, ok, sub))
    assert side_pair_medians(z, ok, cols[:0]).shape == (0,)


def test_both_sides_mask_as_the_record_scan_of_sidebands():
    """sidebands.record_candidates: per offset the runs whose two sides are both valid."""
    rng = np.random.default_rng(9)
    z = rng.exponential(1.0, (12, 2 * 25, 2))
    ok = rng.random((12, 50)) < 0.7
    L = 25
    ref = np.zeros(L)
    for j in range(L):
        both = ok[:, j] & ok[:, L + j]
        vals = np.concatenate([z[both, j, :].ravel(), z[both, L + j, :].ravel()])
        ref[j] = float(np.median(vals)) if vals.size >= 6 else 0.0
    both = ok[:, :L] & ok[:, L:]
    np.testing.assert_array_equal(side_pair_medians(z, np.concatenate([both, both], axis=1), np.arange(L)), ref)


def test_column_nanmedian_is_numpys():
    """rwadist.diagnose.measure.column_nanmedian against np.nanmedian(axis=0): odd and even counts of valid values,
    NaN-free columns, infinities, a column of one value, and an all-NaN column (NaN)."""
    import warnings

    from rwadist.diagnose.reduce import column_nanmedian

    rng = np.random.default_rng(11)
    for rows in (1, 2, 7, 120, 700):
        z = rng.exponential(size=(rows, 50)) * np.exp(3 * rng.standard_normal((1, 50)))
        z[rng.random(z.shape) < 0.3] = np.nan
        z[:, 0] = 1.5                                      # no NaN
        z[:, 1] = np.nan                                   # nothing valid
        if rows > 2:
            z[0, 2], z[1, 2] = np.inf, -np.inf
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ref = np.nanmedian(z, axis=0)
        got = column_nanmedian(z)
        assert np.array_equal(got, ref, equal_nan=True)
