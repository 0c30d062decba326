"""The record route of ``missing_harmonic`` (:func:`rwadist.effects.missing_harmonic_diagnose.record_residual`) with its
whole-run phasors kept on the context and computed for many runs at once, against the plain per-run sums it replaces:
each run's windowed record transformed alone (:func:`rwadist.dft.windowed_dft`), the state's lines' leakage
subtracted with the Hann window's transform written as Dirichlet sums, the noise from the run's own median."""
import numpy as np
import pytest

from rwadist.dft import run_window, windowed_dft
from rwadist.diagnose import measure
from rwadist.diagnose import record_residual as mh
from rwadist.diagnose.engine import Context, initial_state
from rwadist.effects.sidebands_diagnose import Sidebands
from rwadist.empirical import fit_empirical
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady


def _dirichlet_hann(n, delta):
    """W(δ)/W(0) of the periodic Hann window from its three Dirichlet sums (δ in record bins)."""
    def dirichlet(d):
        num = 1.0 - np.exp(-2j * np.pi * d)
        den = 1.0 - np.exp(-2j * np.pi * d / n)
        small = np.abs(den) < 1e-12
        return np.where(small, n, num / np.where(small, 1.0, den))

    d = np.asarray(delta, dtype=float)
    return (0.5 * dirichlet(d) - 0.25 * dirichlet(d - 1.0) - 0.25 * dirichlet(d + 1.0)) / (0.5 * n)


def _plain_record_residual(ctx, state, c, runs, f_hz, exact):
    """record_residual one run at a time, nothing kept: the 4× zero-padded FFT of the windowed record, each line's
    phasor by its own DFT and its leakage subtracted on the grid, |X|² read at the nearest grid point or (``exact``)
    the DFT at the point itself less the leakage there."""
    P, N, ok = np.full(f_hz.shape, np.nan), np.full(f_hz.shape, np.nan), np.zeros(f_hz.shape, bool)
    lines = measure.state_line_freqs(ctx, state, c, runs)
    f_top = mh.welch_low_limit(ctx)
    k_w = np.clip(np.rint(f_hz / ctx.df).astype(int), ctx.k_lo, ctx.k_hi)
    S = np.take_along_axis(ctx.floor_psd(state, c, runs), k_w, axis=1)
    for i, r in enumerate(runs):
        run = ctx.test.runs[r]
        n, fs = run.n_samples, run.sample_rate
        w, wsum, w2sum = run_window(ctx.sp.window, n)
        xw = (run.signals[c] - np.mean(run.signals[c])) * w
        df_rec = fs / n
        n_keep = int(np.ceil((f_top / df_rec + 20.0) / mh.RECORD_GRID_BINS)) + 1
        grid = np.arange(n_keep) * df_rec * mh.RECORD_GRID_BINS
        Xr = 2.0 * np.fft.rfft(xw, 4 * n)[:n_keep] / wsum
        fl = lines[i][lines[i] < f_top + 20.0 * df_rec]
        valid = (f_hz[i] >= mh.RECORD_MIN_BINS * df_rec) & (f_hz[i] < f_top)
        clear = (grid >= mh.RECORD_MIN_BINS * df_rec) & (grid < f_top)
        A = 2.0 * windowed_dft(xw[:, None], fs, fl)[:, 0] / wsum
        for f_l, a in zip(fl, A):
            valid &= np.abs(f_hz[i] - f_l) >= mh.RECORD_SEP_BINS * df_rec
            clear &= np.abs(grid - f_l) >= mh.RECORD_SEP_BINS * df_rec
            Xr = Xr - _dirichlet_hann(n, (grid - f_l) / df_rec) * a - _dirichlet_hann(n, (grid + f_l) / df_rec) * np.conj(a)
        if exact:
            Xi = 2.0 * windowed_dft(xw[:, None], fs, f_hz[i])[:, 0] / wsum
            for f_l, a in zip(fl, A):
                Xi = Xi - _dirichlet_hann(n, (f_hz[i] - f_l) / df_rec) * a \
                    - _dirichlet_hann(n, (f_hz[i] + f_l) / df_rec) * np.conj(a)
        else:
            Xi = Xr[np.clip(np.rint(f_hz[i] / (df_rec * mh.RECORD_GRID_BINS)).astype(int), 0, grid.size - 1)]
        Xg = Xr[clear]
        local = float(np.median(np.abs(Xg) ** 2)) / np.log(2.0) if Xg.size >= 8 else 0.0
        P[i] = np.abs(Xi) ** 2
        N[i] = np.maximum(2.0 * S[i] * fs * w2sum / wsum**2, local)
        ok[i] = valid
    return P, N, ok


@pytest.fixture(scope="module")
def record_case():
    # runs of two record lengths (grouped apart by the batched transform), modes on, a low line to leak
    test = simulate_steady(preset("ithaco-e"), np.linspace(300.0, 1500.0, 10), sample_rate=1000.0, n_samples=4096,
                           noise=0.01, seed=7, physics="extended", test_stand=False)
    from dataclasses import replace

    test.runs[3] = replace(test.runs[3], signals={k: v[:3000] for k, v in test.runs[3].signals.items()})
    sp = compute_spectra(test, nperseg=1024)
    ctx = Context(sp, test=test)
    plain = initial_state(ctx, fit_empirical(sp).model)
    # a pair of sidebands on the fundamental: more lines (and of another count) below the Welch route
    busy = Sidebands("radial_force", plain.model.harmonics("radial_force")[0].h, 2.0, 0.4).apply(plain)
    return test, sp, plain, busy


def test_record_residual_is_the_plain_per_run_sum(record_case):
    test, sp, plain, busy = record_case
    ctx = Context(sp, test=test)
    runs = ctx.runs
    f_top = mh.welch_low_limit(ctx)
    w_hz = ctx.omega[runs] / (2 * np.pi)
    h_grid = np.linspace(0.1, f_top / w_hz.min(), 37)
    f_grid = np.outer(w_hz, h_grid)
    f_exact = np.outer(w_hz, [0.5, 0.731, 1.27])
    checked = 0
    for state in (plain, busy, plain):          # the third: every phasor read back from the context
        for c in ("Fx", "Fy", "Tx", "Fz"):
            for f, exact in ((f_grid, False), (f_exact, True), (f_exact, False)):
                got = mh.record_residual(ctx, state, c, runs, f, exact)
                ref = _plain_record_residual(ctx, state, c, runs, f, exact)
                np.testing.assert_array_equal(got[2], ref[2])
                for g, r in zip(got[:2], ref[:2]):
                    np.testing.assert_allclose(g, r, rtol=1e-9, atol=0)
                checked += int(got[2].sum())
    assert checked > 100                        # the points compared are the route's valid ones too
    # the leakage subtracted matters here (the comparison would not see a route that skipped it)
    lines = measure.state_line_freqs(ctx, busy, "Fx", runs)
    assert np.any(lines < f_top)


def test_record_phasors_of_many_runs_are_each_run_alone(record_case):
    test, sp, _, _ = record_case
    ctx = Context(sp, test=test)
    rows = [0, 3, 5, 9]                          # run 3 is shorter: its own group
    f = np.array([[3.0, 7.25, 11.0], [2.5, 6.0, 9.75], [4.0, 8.0, 12.5], [5.5, 9.0, 13.0]])
    got = measure.record_dfts(ctx, rows, "Fy", f)
    for k, r in enumerate(rows):
        run = test.runs[r]
        w, wsum, _ = run_window(sp.window, run.n_samples)
        x = run.signals["Fy"]
        np.testing.assert_array_equal(got[k], 2.0 * windowed_dft(((x - x.mean()) * w)[:, None], run.sample_rate,
                                                                  f[k])[:, 0] / wsum)
