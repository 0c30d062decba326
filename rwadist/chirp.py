"""A line swept in frequency across a spectrum segment: how far it moves, and how much of its power a fixed window
of bins about its centre holds.

A run cut from a sweep (:func:`rwadist.sweep.slice_sweep`) is not steady: the speed moves by dΩ/dt·L over a
segment of L seconds, so a line of harmonic h moves by h·|dΩ/dt|·L/(2π) Hz, i.e. c = h·|dΩ/dt|·L²/(2π) bins of the
segment's 1/L-Hz grid.  The windowed spectrum of a linear chirp is no longer the window's kernel: for c beyond a
few bins its power spreads over about c bins (the window's shape, read by the stationary phase), and a line read as
the power in ±``half`` bins about its peak (the empirical fit's ``line_half_width`` = 3) is read short.  The share
kept, :func:`window_fraction`, is computed here from the windowed chirp itself (a zero-padded FFT of
w(n)·exp(iπc(n/N − ½)²), tabulated in c and the centre's sub-bin offset), so a measured line power can be divided
by it.  For the Hann window and ±3 bins: c = 5, 8.8, 17.6 keep 99.8-99.9 %, 98.4-98.8 %, 82-83 % (trial 11's
120-s run-up in 8192-sample slices: h 3.6 and 7.2 read 0.6 % and 9.5 % low in amplitude, as these say).

Units: s, rad/s, rad/s²; bins of the segment's frequency grid.
"""
from __future__ import annotations

import copy

import numpy as np

#: samples of the tabulating segment (the chirp's shape in bins does not depend on it once it is long)
TABLE_N = 512
#: zero-padding of the tabulating FFT: the kernel read every 1/TABLE_PAD bin
TABLE_PAD = 32
#: step of the table in c, bins (linear interpolation between)
TABLE_DC = 0.25


def speed_rates(t_mid, speeds) -> np.ndarray:
    """|dΩ/dt| of each run of one sweep, rad/s², in the order given: ``np.gradient`` of the speeds (rad/s) against the
    runs' centre times ``t_mid`` (s), taken in time order.  NaN for a run without a speed (0 or nan); all NaN with
    fewer than 3 runs with a speed or two of them at one time (not one sweep: steady runs all start at 0)."""
    return np.abs(_gradient(t_mid, speeds))


def _gradient(t_mid, speeds) -> np.ndarray:
    """:func:`speed_rates` signed: ``np.gradient`` of ``speeds`` against ``t_mid`` in time order (same NaN rules)."""
    t = np.asarray(t_mid, dtype=float)
    w = np.asarray(speeds, dtype=float)
    out = np.full(w.shape, np.nan)
    ok = np.isfinite(w) & (w != 0) & np.isfinite(t)
    if ok.sum() < 3:
        return out
    idx = np.flatnonzero(ok)[np.argsort(t[ok], kind="stable")]
    if np.any(np.diff(t[idx]) <= 0):
        return out
    out[idx] = np.gradient(w[idx], t[idx])
    return out


def _centres(test) -> np.ndarray:
    """Each run's centre time, s (its ``t0`` the first sample's time)."""
    return np.array([r.t0 + 0.5 * r.n_samples / r.sample_rate for r in test.runs])


def sliced_rates(test) -> np.ndarray | None:
    """:func:`speed_rates` of the runs of a test cut from a sweep (``test.meta["slicing"]``, every run's ``t0`` its
    first sample's time), in the test's run order; None for any other test (steady runs)."""
    if test is None or "slicing" not in (getattr(test, "meta", None) or {}):
        return None
    rates = speed_rates(_centres(test), [r.speed for r in test.runs])
    return rates if np.isfinite(rates).any() else None


def sliced_slopes(test) -> np.ndarray | None:
    """d|Ω|/dt (rad/s², signed: > 0 while the wheel speeds up) of each run of a test cut from a sweep, in the test's
    run order (:func:`speed_rates` of |speed|, its sign kept); None for any other test (:func:`sliced_rates`) and NaN
    for a run without a speed."""
    if sliced_rates(test) is None:
        return None
    return _gradient(_centres(test), np.abs([r.speed for r in test.runs]))


def chirp_bins(h, rate, seconds: float):
    """Bins of a segment of ``seconds`` s a line of harmonic ``h`` sweeps across it at |dΩ/dt| = ``rate`` rad/s²:
    h·rate·L²/(2π) (broadcast)."""
    return np.asarray(h, dtype=float) * np.asarray(rate, dtype=float) * seconds**2 / (2 * np.pi)


_TABLES: dict = {}


def _table(window: str, half: int, c_max: float) -> tuple:
    """(c grid, δ grid, share (n_c, n_δ)) of :func:`window_fraction` for ``window`` and ``half``, up to c_max bins."""
    key = (window, half)
    got = _TABLES.get(key)
    if got is not None and got[0][-1] >= c_max:
        return got
    from scipy import signal

    n, pad = TABLE_N, TABLE_PAD
    c = np.arange(0.0, max(np.ceil(c_max / TABLE_DC) * TABLE_DC, 8.0) + TABLE_DC / 2, TABLE_DC)
    x = (np.arange(n) - n / 2) / n
    w = signal.get_window(window, n)
    # instantaneous frequency c·(n/N − ½) bins: from −c/2 to c/2 about the centre
    spec = np.abs(np.fft.fft(w[None, :] * np.exp(1j * np.pi * c[:, None] * x[None, :] ** 2), n * pad, axis=1)) ** 2
    total = spec.sum(axis=1) / pad                    # Parseval: the sum over the native bins of any sub-bin grid
    delta = np.arange(-pad // 2, pad // 2 + 1) / pad   # the centre's offset from the window's middle bin
    k = np.arange(-half, half + 1)
    cols = (np.rint((k[None, :] - delta[:, None]) * pad).astype(int)) % (n * pad)      # (n_δ, 2·half + 1)
    share = spec[:, cols].sum(axis=2) / total[:, None]
    _TABLES[key] = (c, delta, share)
    return _TABLES[key]


def window_fraction(c, delta, half: int = 3, window: str = "hann") -> np.ndarray:
    """Share of a linear chirp's power that the 2·half + 1 bins about a bin hold, on one windowed segment.

    Parameters
    ----------
    c : array_like
        Bins the line sweeps across the segment (:func:`chirp_bins`), ≥ 0.
    delta : array_like
        The line's centre frequency (its mean over the segment) less the window's middle bin, bins, in [−½, ½].
    half : int
        Bins either side of the middle bin.
    window : str
        The segment's window (:func:`scipy.signal.get_window` name).

    Returns
    -------
    ndarray
        The share (0, 1] (broadcast of ``c`` and ``delta``); for c = 0 the window's own kernel's share.
    """
    c, delta = np.broadcast_arrays(np.abs(np.asarray(c, dtype=float)), np.asarray(delta, dtype=float))
    if c.size == 0:
        return np.zeros(c.shape)
    cg, dg, share = _table(window, half, float(np.nanmax(c, initial=0.0)))
    x = np.clip(c / TABLE_DC, 0.0, cg.size - 1.0)
    i0 = np.minimum(np.floor(x).astype(int), cg.size - 2)
    fx = x - i0
    y = (np.clip(delta, dg[0], dg[-1]) - dg[0]) * TABLE_PAD
    j0 = np.minimum(np.floor(y).astype(int), dg.size - 2)
    fy = y - j0
    return ((share[i0, j0] * (1 - fx) + share[i0 + 1, j0] * fx) * (1 - fy)
            + (share[i0, j0 + 1] * (1 - fx) + share[i0 + 1, j0 + 1] * fx) * fy)


def unsmeared_lines(test, fit, n_window: int) -> list | None:
    """The lines of an empirical fit (:class:`rwadist.empirical.EmpiricalFit`) of a test cut from a sweep, each
    measured amplitude divided by the square root of the share of its line's power the fit's window of ±
    ``line_half_width`` bins held (:func:`window_fraction` at the line's chirp across the fit's segment, over the
    window's own share without a chirp, so a steady line is as it was); None for any other test (:func:`sliced_rates`).
    Only the first ``n_window`` lines were measured in that window (the close lines after them were fitted together on
    the records).  A measurement's run is the one of nearest |speed|; δ is the line's offset h·|Ω|/2π from its nearest
    bin (where the window is centred)."""
    from dataclasses import replace

    rates = sliced_rates(test)
    if rates is None:
        return None
    sp = fit.spectra
    half = int(fit.fit_settings.line_half_width)
    run_w = np.abs([r.speed for r in test.runs])
    out = list(fit.lines)
    for i, x in enumerate(out[:n_window]):
        w = np.abs(np.asarray(x.speed, dtype=float))
        near = np.argmin(np.abs(run_w[None, :] - w[:, None]), axis=1)
        c = np.nan_to_num(chirp_bins(x.h, rates[near], sp.nperseg / sp.sample_rate))
        pos = x.h * w / (2 * np.pi) / sp.df
        delta = pos - np.rint(pos)
        share = window_fraction(c, delta, half, sp.window) / window_fraction(0.0, delta, half, sp.window)
        out[i] = replace(x, amplitude=x.amplitude / np.sqrt(share))
    return out


def unsmeared_fit(test, fit):
    """``fit`` (the empirical fit of ``test``'s spectra, :func:`rwadist.empirical.fit_empirical`) with every line's
    amplitudes corrected for its chirp across the fit's segment (:func:`unsmeared_lines`: all its lines were read in
    the ±``line_half_width`` window) and its C, C_all and C_stderr, and the model's, recomputed from them, the modal
    exclusion kept; ``fit`` itself for a test not cut from a sweep (steady runs: unchanged).  :func:`rwadist.api.fit`
    reads a slice in one segment of its whole length, 4² = 16 times the chirp in bins of the quarter-slice segments
    the slice length is chosen for (:data:`rwadist.sweep.CHIRP_BINS`): a new user's exponential run-down 6000 -> 600
    rpm in 60 s (4096-sample slices at 5 kHz) swept h 7.37 by 18 bins in its fastest slice, which ±3 bins read 11 %
    low in amplitude, and C came out 6.6 % low in every direction, outside its ±2σ.  Not :attr:`without_mode_exclusion`
    (recomputed from the uncorrected measurements), which the extended fit corrects itself (``_unsmeared_once``)."""
    from dataclasses import replace

    from .empirical import _cluster_stderr, line_C

    lines = unsmeared_lines(test, fit, len(fit.lines))
    if lines is None:
        return fit
    out = []
    for x in lines:
        if not np.any(x.used):          # nothing to fit C to (the fit's own C of such a line kept as it is)
            out.append(x)
            continue
        w = np.abs(np.asarray(x.speed, dtype=float))
        run = np.unique(w, return_inverse=True)[1]           # one speed per run (as unsmeared_lines reads them)
        C = line_C(x.amplitude[x.used], w[x.used])
        out.append(replace(x, C=C, C_all=line_C(x.amplitude, w),
                           C_stderr=_cluster_stderr(x.amplitude[x.used], w[x.used], run[x.used], C)))
    model = copy.deepcopy(fit.model)
    for d, harmonics in model.empirical.items():
        # each model harmonic is the fit's line of its direction at its h (the model's h rounded to 4 decimals)
        model.empirical[d] = [replace(hm, C=x.C, C_stderr=x.C_stderr) if x is not None else hm for hm, x in
                              ((hm, min((x for x in out if x.direction == d and abs(x.h - hm.h) < 1e-3),
                                        key=lambda x: abs(x.h - hm.h), default=None)) for hm in harmonics)]
    return replace(fit, model=model, lines=out)
