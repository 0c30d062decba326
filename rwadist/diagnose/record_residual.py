"""The whole-run DFT residual of a channel (the record route of ``missing_harmonic`` and of the classes that read
lines below the Welch band or apart from their neighbours): each run's windowed transform at given frequencies, less the
leakage of every line the state predicts there, and the noise it is read against."""
from __future__ import annotations

import numpy as np

from .constants import LINE_HALF
from .engine import Context
from .measure import hann_transform_ratio, record_dfts, state_line_freqs
from .reduce import column_nanmedian
from .state import State

#: Lowest frequency of a point of the record route, record bins (fs/n): the mean is taken off the record, and the
#: Hann window's own lobe at 0 Hz is ±2 bins wide; 4 bins as the matrix's signature of a line (SIGNATURE_MIN_BIN).
RECORD_MIN_BINS = 4.0
#: Smallest separation (record bins) of a point from every line the state predicts on the channel: the edge of the
#: Hann main lobe (beyond it the transform is below −31 dB, and those lines' leakage is subtracted with their phasors).
RECORD_SEP_BINS = 2.0
#: Grid of the record spectrum, record bins: the Hann-windowed record zero-padded 4× (a line between grid points
#: loses at most 0.1 dB).
RECORD_GRID_BINS = 0.25


def welch_low_limit(ctx: Context) -> float:
    """Lowest frequency (Hz) whose line the Welch route measures: its window of ±LINE_HALF bins from the band's
    lowest bin k_lo up (:meth:`rwadist.diagnose.engine.Context.measure_line`)."""
    return (ctx.k_lo + LINE_HALF) * ctx.df


def _record_grid(ctx: Context, r: int) -> tuple:
    """(f (G,) Hz, X (G, K) complex, record df Hz, n) of run ``r``: the whole-run phasors X = 2·Σ w x e^{−2πj f t}/Σ w
    (Hann, the mean taken off; x ≈ Re(X e^{2πj f t})) of every channel of ``ctx.channels`` on a grid of
    RECORD_GRID_BINS record bins up to the Welch route's lowest frequency plus 20 record bins (a 4× zero-padded FFT);
    kept on the context (the data's, the same at every search step)."""
    key = ("missing_harmonic_record", r)
    if key not in ctx._memo:
        from scipy import fft as sp_fft

        from ..dft import demeaned_windowed, run_window

        run = ctx.test.runs[r]
        n = run.n_samples
        w, wsum, _ = run_window(ctx.sp.window, n)
        df_rec = run.sample_rate / n
        pad = int(round(1.0 / RECORD_GRID_BINS))
        n_keep = int(np.ceil((welch_low_limit(ctx) / df_rec + 20.0) / RECORD_GRID_BINS)) + 1
        X = np.full((n_keep, len(ctx.channels)), np.nan + 0j)
        have = [j for j, c in enumerate(ctx.channels) if run.usable(c)]
        if have:
            xs = demeaned_windowed([run.signals[ctx.channels[j]] for j in have], w)
            # every channel in one call (scipy.fft: the numbers of numpy.fft's, channel by channel, in half the time)
            X[:, have] = (2.0 * sp_fft.rfft(xs, pad * n, axis=-1)[:, :n_keep] / wsum).T
        ctx._memo[key] = (np.arange(n_keep) * df_rec * RECORD_GRID_BINS, X, df_rec, n)
    return ctx._memo[key]


def _has_channel(ctx: Context, r: int, j: int) -> bool:
    """Run ``r`` has channel ``ctx.channels[j]`` (its record grid is finite there)."""
    key = ("missing_harmonic_has", r, j)
    if key not in ctx._memo:
        ctx._memo[key] = bool(np.all(np.isfinite(_record_grid(ctx, r)[1][:, j])))
    return ctx._memo[key]


def _record_run_residual(ctx: Context, r: int, j: int, fl: np.ndarray, f_top: float, A=None) -> tuple:
    """(X (G,) complex, A (L,) complex, local noise) of run ``r``, channel ``ctx.channels[j]`` on the record grid
    (:func:`_record_grid`) less the leakage of the lines ``fl`` (L,) Hz (their whole-run phasors A times the
    window's transform, the negative-frequency image too), and the median |X|²/ln 2 over the grid points of the
    record route's range clear of those lines (0 with fewer than 8).  The data's and the lines' only: kept on the
    context, so each search step and each caller that asks the same run, channel and lines reuses them.  ``A``: the
    lines' phasors when already computed (:func:`record_dfts` of several runs at once)."""
    key = ("missing_harmonic_run", r, j, fl.tobytes(), f_top)
    if key in ctx._memo:
        return ctx._memo[key]
    grid, X, df_rec, n = _record_grid(ctx, r)
    c = ctx.channels[j]
    Xr = X[:, j]
    A = None
    clear = (grid >= RECORD_MIN_BINS * df_rec) & (grid < f_top)
    if fl.size:
        # the leakage on the whole (short) grid once, then read at the points' nearest grid frequencies
        if A is None:
            A = record_dfts(ctx, [r], c, fl[None, :])[0]                                              # (L,)
        key_t = ("missing_harmonic_leak", n, df_rec, grid.size, fl.tobytes())   # the same lines at every step
        if key_t not in ctx._memo:
            ctx._memo[key_t] = (hann_transform_ratio(n, (grid[:, None] - fl[None, :]) / df_rec),
                                hann_transform_ratio(n, (grid[:, None] + fl[None, :]) / df_rec))
        t_minus, t_plus = ctx._memo[key_t]
        Xr = Xr - (t_minus * A[None, :] + t_plus * np.conj(A)[None, :]).sum(1)
        clear &= np.all(np.abs(grid[:, None] - fl[None, :]) >= RECORD_SEP_BINS * df_rec, axis=1)
    Xg = Xr[clear]
    local = float(np.median(np.abs(Xg) ** 2)) / np.log(2.0) if Xg.size >= 8 else 0.0
    ctx._memo[key] = (Xr, A, local)
    return ctx._memo[key]


def _record_run_residuals(ctx: Context, j: int, items, f_top: float, A_of: dict) -> None:
    """:func:`_record_run_residual` of every (run, lines) of ``items`` not yet kept, the runs of one record length and
    number of lines at once, kept as each would be: the same operations on each run's own rows (the leakage's sum over
    the lines per grid point, the median of the clear points' |X|²: :func:`column_nanmedian`).  ``A_of``: run ->
    its lines' phasors, where already computed."""
    groups: dict = {}
    for r, fl in items:
        if ("missing_harmonic_run", r, j, fl.tobytes(), f_top) in ctx._memo or not fl.size:
            continue
        run = ctx.test.runs[r]
        groups.setdefault((run.n_samples, run.sample_rate, fl.size), []).append((r, fl))
    c = ctx.channels[j]
    for group in groups.values():
        rows = [r for r, _ in group]
        grid, _, df_rec, n = _record_grid(ctx, rows[0])
        fls = np.array([fl for _, fl in group])                                              # (R, L)
        missing = [k for k, r in enumerate(rows) if r not in A_of]
        A_new = record_dfts(ctx, [rows[k] for k in missing], c, fls[missing]) if missing else \
            np.empty((0, fls.shape[1]), dtype=complex)
        A = np.array([A_of[r] if r in A_of else A_new[missing.index(k)] for k, r in enumerate(rows)])   # (R, L)
        X = np.array([_record_grid(ctx, r)[1][:, j] for r in rows])                          # (R, G)
        t_minus = hann_transform_ratio(n, (grid[None, :, None] - fls[:, None, :]) / df_rec)
        t_plus = hann_transform_ratio(n, (grid[None, :, None] + fls[:, None, :]) / df_rec)
        Xr = X - (t_minus * A[:, None, :] + t_plus * np.conj(A)[:, None, :]).sum(2)
        clear = ((grid >= RECORD_MIN_BINS * df_rec) & (grid < f_top))[None, :] \
            & np.all(np.abs(grid[None, :, None] - fls[:, None, :]) >= RECORD_SEP_BINS * df_rec, axis=2)
        med = column_nanmedian(np.where(clear, np.abs(Xr) ** 2, np.nan).T)
        local = np.where(clear.sum(1) >= 8, med / np.log(2.0), 0.0)
        for k, (r, fl) in enumerate(group):
            ctx._memo[("missing_harmonic_run", r, j, fl.tobytes(), f_top)] = (Xr[k], A[k], float(local[k]))


def record_residual(ctx: Context, state: State, c: str, runs, f_hz, exact: bool = False) -> tuple:
    """(|X|² (len(runs), L), noise (len(runs), L), valid (len(runs), L)) of channel ``c`` at frequencies ``f_hz``
    (len(runs), L) on the whole-run DFT, less the leakage of every line the state predicts on the channel (each
    line's own phasor times the window's transform, :func:`hann_transform_ratio`, its negative-frequency image too).

    |X|² is read on the record grid at the nearest point (:func:`_record_grid`), or with ``exact`` at ``f_hz`` itself
    (:func:`rwadist.dft.windowed_dft`); the noise is the larger of the white
    noise of the state's floor there (2·S·fs·Σw²/(Σw)², S at the nearest Welch bin of the band) and the run's own
    median |X|² over the record route's range (/ln 2: the median of an exponential), so that a noise rising below the
    Welch band is not taken for lines.  Valid: in the record route's range (RECORD_MIN_BINS record bins up to
    :func:`welch_low_limit`) and RECORD_SEP_BINS record bins from every line of the state on the channel."""
    from ..dft import run_window

    j = ctx.channels.index(c)
    f_hz = np.asarray(f_hz, dtype=float)
    P = np.full(f_hz.shape, np.nan)
    N = np.full(f_hz.shape, np.nan)
    ok = np.zeros(f_hz.shape, bool)
    lines = state_line_freqs(ctx, state, c, runs)
    f_top = welch_low_limit(ctx)
    k_w = np.clip(np.rint(f_hz / ctx.df).astype(int), ctx.k_lo, ctx.k_hi)
    S = np.take_along_axis(ctx.floor_psd(state, c, runs), k_w, axis=1)
    # every run's record grid, the points' validity and nearest grid points at once (the same expressions per run)
    grids = [_record_grid(ctx, int(r)) for r in runs]
    df_rec = np.array([g[2] for g in grids])
    near = lines < (f_top + 20.0 * df_rec)[:, None]             # the lines whose leakage reaches the route's range
    valid = (f_hz >= RECORD_MIN_BINS * df_rec[:, None]) & (f_hz < f_top)
    for m in range(lines.shape[1]):
        valid &= ~near[:, m:m + 1] | (np.abs(f_hz - lines[:, m:m + 1]) >= RECORD_SEP_BINS * df_rec[:, None])
    gi = np.clip(np.rint(f_hz / (df_rec * RECORD_GRID_BINS)[:, None]).astype(int), 0,
                 np.array([g[0].size for g in grids])[:, None] - 1)
    todo = [(i, int(r), lines[i][near[i]], valid[i], gi[i])     # the runs that have the channel
            for i, r in enumerate(runs) if _has_channel(ctx, int(r), j)]
    # the lines' phasors of the runs not yet on the context, runs of one number of lines transformed together
    new_lines: dict[int, list[tuple[int, np.ndarray]]] = {}
    for i, r, fl, _, _ in todo:
        if fl.size and ("missing_harmonic_run", r, j, fl.tobytes(), f_top) not in ctx._memo:
            new_lines.setdefault(fl.size, []).append((r, fl))
    A_new = {}
    for items in new_lines.values():
        A = record_dfts(ctx, [r for r, _ in items], c, np.array([fl for _, fl in items]))
        A_new.update({r: A[k] for k, (r, _) in enumerate(items)})
    _record_run_residuals(ctx, j, [(r, fl) for _, r, fl, _, _ in todo], f_top, A_new)
    # with ``exact``: the data's phasors at the points' own frequencies (a fit's h refined finer than the grid), kept
    # on the context (the fit's grid of h is asked again on the refit's runs and by the held-out evidence)
    ex_key = {i: ("missing_harmonic_exact", r, j, fl.tobytes(), f_hz[i].tobytes()) for i, r, fl, _, _ in todo} \
        if exact else {}
    ex_new = [t for t in todo if exact and ex_key[t[0]] not in ctx._memo]
    X_ex = record_dfts(ctx, [t[1] for t in ex_new], c, f_hz[[t[0] for t in ex_new]]) if ex_new else \
        np.empty((0, f_hz.shape[1]), dtype=complex)
    ex_row = {t[0]: k for k, t in enumerate(ex_new)}
    # their lines' leakage (the window's transform at the points less and plus each line, times its phasor), the runs
    # of one record length and number of lines at once (elementwise: the numbers of one run at a time)
    leak = {}
    ex_groups: dict[tuple[int, float, int], list[tuple[int, int, np.ndarray]]] = {}
    for i, r, fl, _, _ in ex_new:
        if fl.size:
            run = ctx.test.runs[r]
            ex_groups.setdefault((run.n_samples, run.sample_rate, fl.size), []).append((i, r, fl))
    for (n, fs, _), ex_items in ex_groups.items():
        df_g = fs / n
        fi = f_hz[[i for i, _, _ in ex_items]][:, :, None]                                # (R, L, 1)
        fls = np.array([fl for _, _, fl in ex_items])[:, None, :]                          # (R, 1, nl)
        A = np.array([_record_run_residual(ctx, r, j, fl, f_top, A_new.get(r))[1]
                      for _, r, fl in ex_items])[:, None, :]
        d = (hann_transform_ratio(n, (fi - fls) / df_g) * A + hann_transform_ratio(n, (fi + fls) / df_g) * np.conj(A)).sum(2)
        leak.update({i: d[k] for k, (i, _, _) in enumerate(ex_items)})
    for i, r, fl, _, g in todo:
        Xr, A, local = _record_run_residual(ctx, r, j, fl, f_top, A_new.get(r))
        Xi = Xr[g]
        if exact:
            if ex_key[i] not in ctx._memo:
                ctx._memo[ex_key[i]] = X_ex[ex_row[i]] - leak[i] if fl.size else X_ex[ex_row[i]]
            Xi = ctx._memo[ex_key[i]]
        run = ctx.test.runs[r]
        _, wsum, w2sum = run_window(ctx.sp.window, run.n_samples)
        white = 2.0 * S[i] * run.sample_rate * w2sum / wsum**2
        P[i] = np.abs(Xi) ** 2
        N[i] = np.maximum(white, local)
        ok[i] = valid[i]
    return P, N, ok
