"""The whole-run scans of ``sidebands`` (offsets to 2.5 Welch bins) and ``speed_ripple`` (the same grid to 4) read one set
of line powers per carrier and runs (:meth:`rwadist.effects.sidebands_diagnose.Sidebands._scan_powers`): each scan's
powers must be those computed for its own offsets alone (the uncached route, :func:`_line_powers` at exactly those
frequencies), and the shared set must be transformed once.

"The same powers" is not "the same bits": the sums run in single precision through the BLAS
(:func:`rwadist.dft.windowed_dfts`), whose blocking, and so its rounding, depends on the matrix shapes (how many
frequencies, how many carriers at once) and on the library.  Each phasor is exact to ~1e-7 of the record's strongest line
(:func:`rwadist.effects.speed_sidebands_diagnose._line_powers`); two routes must agree within :data:`PHASOR_TOL` of the
largest line the record can hold (sqrt(2)·its RMS, per run and channel): the single-precision route is 8e-8 of it
from the double-precision sums here, and the noise's phasors stand 5e-5 or more of it up, so a fault (another
frequency, run, carrier or channel) moves them by far more (:func:`test_the_tolerance_tells_a_grid_shifted_by_a_thousandth_of_a_bin`:
a grid 1/1000 of a record bin off moves them by 7e-4).

Data: the E-wheel data of tests/test_diagnose.py with the whole records (the context's ``test``)."""
from __future__ import annotations

import numpy as np
from test_diagnose import TRUTH, e_data, spectra

from rwadist.diagnose.engine import Context, initial_state
from rwadist.effects import sidebands_diagnose as sd
from rwadist.effects import speed_sidebands_diagnose as ssd
from rwadist.effects.speed_ripple_diagnose import RECORD_WELCH_BINS
from rwadist.units import DIRECTION_CHANNELS

#: Largest difference of |X| (the phasor's magnitude, sqrt of a line power) two routes of the single-precision sums may
#: show, relative to the largest line amplitude the record can hold (sqrt(2)·RMS of its channel)
PHASOR_TOL = 1e-6


def _line_scale(ctx, chans, runs) -> np.ndarray:
    """sqrt(2)·RMS of each run's channel (len(runs), 1, len(chans)): no line of the record is stronger."""
    return np.array([[np.sqrt(2.0 * np.mean(np.square(ctx.test.runs[int(r)].signals[c]))) for c in chans]
                     for r in runs])[:, None, :]


def _misfit(P, ref, scale) -> float:
    """Largest | |X| − |X_ref| | of two arrays of line powers (len(runs), L, len(chans)), relative to ``scale``."""
    return float(np.nanmax(np.abs(np.sqrt(P) - np.sqrt(ref)) / scale))


def assert_same_powers(P, ref, scale) -> None:
    """P and ref are the same line powers, but for the BLAS's rounding (:data:`PHASOR_TOL`); NaN where ref's is."""
    P, ref = np.asarray(P), np.asarray(ref)
    assert P.shape == ref.shape
    np.testing.assert_array_equal(np.isnan(P), np.isnan(ref))
    assert _misfit(P, ref, scale) <= PHASOR_TOL, _misfit(P, ref, scale)


def test_both_record_scans_read_their_own_offsets_powers_computed_once(monkeypatch):
    test = e_data(3)
    ctx = Context(spectra(test), test=test)
    state = initial_state(ctx, TRUTH)
    runs = ctx.fit_runs[np.argsort(ctx.omega[ctx.fit_runs])[::-1][:sd.RECORD_SCAN_RUNS]]
    df_rec = float(np.max(ssd._record_df(ctx, ctx.runs)))
    own = sd.Sidebands._record_offsets(ctx)
    ripple = np.arange(ssd.RUN_MIN_BINS * df_rec, RECORD_WELCH_BINS * ctx.df, sd.RECORD_STEP_BINS * df_rec)
    assert sd.RECORD_SCAN_WELCH_BINS == RECORD_WELCH_BINS    # the shared grid is the ripple's
    assert 3 <= own.size < ripple.size          # the sidebands' grid is the first part of the ripple's
    calls = []
    transform = ssd._line_powers
    monkeypatch.setattr(ssd, "_line_powers", lambda *a, **k: calls.append(a[3].shape) or transform(*a, **k))
    direction, h = "radial_force", 2.0
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
    fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
    scale = _line_scale(ctx, chans, runs)
    for offsets in (own, ripple, own[:5]):
        f, P, _, _ = sd.Sidebands._record_power(ctx, state, direction, h, runs, offsets, single=True)
        alone = transform(ctx, chans, runs, np.concatenate([fc - offsets, fc + offsets], axis=1), h, single=True)
        np.testing.assert_array_equal(f, np.concatenate([fc - offsets, fc + offsets], axis=1))
        assert_same_powers(P, alone, scale)
        assert not P.flags.writeable
    assert calls == [(runs.size, 2 * ripple.size)]      # one transform, of the farther grid
    # offsets that do not begin the grid (a fit's refinement around one offset) are transformed as asked
    grid = own[4] + np.arange(-2, 3) * 0.02 * df_rec
    _, P, _, _ = sd.Sidebands._record_power(ctx, state, direction, h, runs, grid, single=True)
    assert_same_powers(P, transform(ctx, chans, runs, np.concatenate([fc - grid, fc + grid], axis=1), h, single=True),
                       scale)
    assert len(calls) == 2


def test_record_candidates_transform_every_carrier_at_once_to_the_bit(monkeypatch):
    """The scan of :meth:`Sidebands.record_candidates` over a direction's carriers: their line powers computed together
    (:func:`ssd._carrier_line_powers`, one transform) are each carrier's own (:func:`_line_powers` alone) to the bit,
    and the candidates are those of the carriers computed one at a time (the prefetch switched off)."""
    test = e_data(3)
    direction = "radial_force"
    hs = [x.h for x in TRUTH.harmonics(direction)]
    assert len(hs) >= 3
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in test.channels]
    together = []
    batched = ssd._carrier_line_powers
    monkeypatch.setattr(ssd, "_carrier_line_powers", lambda *a, **k: together.append(len(a[4])) or batched(*a, **k))
    got = {}
    for prefetch in (True, False):
        ctx = Context(spectra(test), test=test)
        state = initial_state(ctx, TRUTH)
        if not prefetch:
            monkeypatch.setattr(sd.Sidebands, "_prefetch_scan_powers", staticmethod(lambda *a, **k: None))
        got[prefetch] = (sd.Sidebands.record_candidates(ctx, state, ctx.fit_runs, direction, hs),
                         {k: v for k, v in ctx._memo.items() if k[0] == "sidebands_scan_powers"})
    assert together == [len(hs)]                    # every carrier in one transform, with the prefetch only
    (cand, kept), (cand_alone, kept_alone) = got[True], got[False]
    # the same carriers and offsets; each score (a median of |X|²/noise) within the powers' rounding: the noise's
    # phasors sit 5e-5 or more of the line scale up, so |X|² moves by 2·PHASOR_TOL/5e-5 of itself at most
    assert [c[1:] for c in cand] == [c[1:] for c in cand_alone]
    np.testing.assert_allclose([c[0] for c in cand], [c[0] for c in cand_alone], rtol=2 * PHASOR_TOL / 5e-5)
    assert kept.keys() == kept_alone.keys() and len(kept) == len(hs)
    for key, P in kept.items():
        _, _, h, runs, grid = key
        runs, grid = np.frombuffer(runs, dtype=np.intp), np.frombuffer(grid)
        fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
        alone = ssd._line_powers(ctx, chans, runs, np.concatenate([fc - grid, fc + grid], axis=1), h, single=True)
        scale = _line_scale(ctx, chans, runs)
        assert_same_powers(P, alone, scale)
        assert_same_powers(P, kept_alone[key], scale)


def test_carriers_transformed_in_bounded_batches_to_the_bit(monkeypatch):
    """:func:`ssd._carrier_line_powers` takes the carriers in batches of at most :data:`ssd.CARRIER_BATCH_ELEMENTS`
    frequency x (block, channel) elements a record (one transform of every carrier held ~24 bytes per element: 195 MB at
    65536 samples x 3 channels for 18 carriers of 224 points, linear in the carriers): each carrier's powers are the
    same to the bit with one carrier a batch, two, or all at once, and each batch stays within the bound (or is one
    carrier)."""
    test = e_data(3)
    direction = "radial_force"
    hs = [x.h for x in TRUTH.harmonics(direction)]
    ctx = Context(spectra(test), test=test)
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in test.channels]
    runs = np.asarray(ctx.fit_runs)[:4]
    grid = np.arange(1.0, 30.0, 0.5)
    f_list = []
    for h in hs:
        fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
        f_list.append(np.concatenate([fc - grid, fc + grid], axis=1))
    n = test.runs[int(runs[0])].n_samples
    per_f = max(128, -(-n // 128) * len(chans))
    got = {}
    for bound in (1, 3 * (f_list[0].shape[1] + 1) * per_f - 1, 1 << 40):
        monkeypatch.setattr(ssd, "CARRIER_BATCH_ELEMENTS", bound)
        batches = ssd._carrier_batches([f.shape[1] for f in f_list], n, len(chans))
        assert sorted(k for b in batches for k in b) == list(range(len(hs)))
        assert all(len(b) == 1 or sum(f_list[k].shape[1] + 1 for k in b) * per_f <= bound for b in batches)
        got[bound] = (len(batches), ssd._carrier_line_powers(ctx, chans, runs, f_list, hs, single=True))
    assert [v[0] for v in got.values()] == [len(hs), -(-len(hs) // 2), 1]
    scale = _line_scale(ctx, chans, runs)
    for _, P in got.values():
        for k, h in enumerate(hs):
            assert_same_powers(P[k], got[1 << 40][1][k], scale)
    alone = ssd._line_powers(ctx, chans, runs, f_list[0], hs[0], single=True)
    assert_same_powers(got[1][1][0], alone, scale)


def test_the_tolerance_tells_a_grid_shifted_by_a_thousandth_of_a_bin():
    """:data:`PHASOR_TOL` against the faults it must catch: the powers of a grid shifted by 1/1000 of a record bin (a
    frequency slightly off: 7e-4 of the line scale), of other runs (2.5), and of the channels swapped (1e-2), each fail
    it by 10x or more; the double-precision sums pass it (the single-precision route is 8e-8 from them)."""
    test = e_data(3)
    ctx = Context(spectra(test), test=test)
    chans = [c for c in DIRECTION_CHANNELS["radial_force"] if c in test.channels]
    runs = np.asarray(ctx.fit_runs)[:6]
    h = 2.0
    df_rec = float(np.max(ssd._record_df(ctx, runs)))
    grid = np.arange(1.0, 30.0, 0.5)
    fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
    f = np.concatenate([fc - grid, fc + grid], axis=1)
    scale = _line_scale(ctx, chans, runs)
    P = ssd._line_powers(ctx, chans, runs, f, h, single=True)
    assert_same_powers(P, ssd._line_powers(ctx, chans, runs, f, h, single=False), scale)
    shifted = ssd._line_powers(ctx, chans, runs, f + df_rec / 1000, h, single=True)
    assert _misfit(shifted, P, scale) > 10 * PHASOR_TOL
    assert _misfit(P[::-1], P, scale) > 10 * PHASOR_TOL
    assert _misfit(P[..., ::-1], P, scale) > 10 * PHASOR_TOL
