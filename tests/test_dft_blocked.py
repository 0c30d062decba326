"""Windowed records made once in the blocked layout of rwadist.dft.windowed_dfts (issue 37): the transform of
:func:`rwadist.dft.blocked_records` against the plain sum Σ x·w·e^{−2πj f t} written out, and bit for bit the numbers
of the stacked records (:func:`rwadist.dft.windowed_records`) it replaces, in both precisions; the records the
sidebands' whole-run route keeps on a context (speed_sidebands_diagnose._run_records) are those made anew."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.dft import BlockedRecords, blocked_records, run_window, windowed_dfts, windowed_records


@pytest.mark.parametrize("n, k", [(8192, 2), (5000, 3), (300, 1)])
def test_blocked_records_transform_is_the_plain_sum_and_the_stacked_records_bit_for_bit(n, k):
    rng = np.random.default_rng(n + k)
    fs = 3840.0
    records = [[rng.standard_normal(n) for _ in range(k)] for _ in range(5)]
    w = run_window("hann", n)[0]
    f = rng.uniform(1.0, 0.45 * fs, (5, 9))
    blocked = blocked_records(records, w)
    got = windowed_dfts(blocked, fs, f)
    t = np.arange(n) / fs
    for r in range(5):
        direct = np.exp(-2j * np.pi * np.outer(f[r], t)) @ np.column_stack([x * w for x in records[r]])
        np.testing.assert_allclose(got[r], direct, rtol=0, atol=1e-11 * np.abs(direct).max())
    stacked = windowed_records(records, w)
    for single in (False, True):
        assert np.array_equal(windowed_dfts(blocked, fs, f, single=single), windowed_dfts(stacked, fs, f, single=single))
    assert not blocked.values.flags.writeable and not blocked.single.flags.writeable


def _context(n_runs=4, n=4096):
    rng = np.random.default_rng(2)
    runs = [SimpleNamespace(n_samples=n, signals={c: rng.standard_normal(n) for c in ("Fx", "Fy")})
            for _ in range(n_runs)]
    return SimpleNamespace(_memo={}, test=SimpleNamespace(runs=runs))


def test_run_records_kept_from_the_second_request_within_the_budget(monkeypatch):
    from rwadist.effects import speed_sidebands_diagnose as ssd

    ctx = _context()
    runs = np.array([0, 2, 3])
    fresh = blocked_records([[ctx.test.runs[r].signals[c] for c in ("Fx", "Fy")] for r in runs],
                            run_window(ssd.RUN_WINDOW, 4096)[0])
    first = ssd._run_records(ctx, runs, ["Fx", "Fy"])
    second = ssd._run_records(ctx, runs, ["Fx", "Fy"])
    third = ssd._run_records(ctx, runs, ["Fx", "Fy"])
    assert isinstance(first, BlockedRecords) and first is not second and second is third
    for got in (first, second):
        assert np.array_equal(got.values, fresh.values)
    assert ssd._run_records(ctx, runs, ["Fx"]) is not ssd._run_records(ctx, runs, ["Fx"])   # kept from the 2nd on
    assert ssd._run_records(ctx, runs, ["Fx"]) is ssd._run_records(ctx, runs, ["Fx"])
    monkeypatch.setattr(ssd, "RUN_RECORDS_KEPT_BYTES", fresh.values.nbytes)        # less than one set and its copy
    ctx = _context()
    for _ in range(3):
        assert ssd._run_records(ctx, runs, ["Fx", "Fy"]) is not ssd._run_records(ctx, runs, ["Fx", "Fy"])
    assert ctx._memo.get("run_records_bytes", 0) == 0
