"""The empirical fit of a diagnosis's runs at the fit's own resolution (``rwadist fit``'s: the longest segment),
computed once per diagnosis and shared: the suspension modes are located on it (of the fit runs, of every run), and
the search's starting model reads the speed-sideband pairs and their carriers on it (the whole records, when those
are the fit's segments: :func:`whole_records_fit`).
"""
from __future__ import annotations

import numpy as np

from .engine import Context
from .modes_status import WHOLE_DATA_FIT


def fit_spectra(ctx: Context, test, runs: list):
    """(spectra, detections) of ``test`` (the context's runs ``runs``) at the fit's own resolution, as ``rwadist fit``
    computes them (:func:`rwadist.spectra.compute_spectra`'s default segment: the longest): close lines (h = 5.37,
    5.57 of the E wheel) that diagnose's shorter Welch segments cannot separate are resolved here; ``detections``
    their block floors and detected lines (:func:`rwadist.empirical.line_detections`), or None.

    A run's Welch PSD, block floor and lines are its own: those of every run of the context are computed once (kept
    on the context) and the rows of ``runs`` taken, so the fit on the fit runs and the refit on every run share
    them; computed on ``test`` alone when the context's runs cannot be (a run outside ``runs`` too short)."""
    from dataclasses import replace

    from ..data import DataError
    from ..empirical import detections_of_runs, line_detections
    from ..spectra import _default_nperseg, compute_spectra

    nperseg = _default_nperseg(int(np.median([r.n_samples for r in test.runs])))
    key = ("suspension_modes.spectra", nperseg)
    if key not in ctx._memo:
        try:
            full = compute_spectra(ctx.test, nperseg=nperseg, window=ctx.sp.window, f_lim=ctx.sp.f_lim)
            ctx._memo[key] = (full, line_detections(full))
        except DataError:
            ctx._memo[key] = None
    if ctx._memo[key] is None:
        return compute_spectra(test, nperseg=nperseg, window=ctx.sp.window, f_lim=ctx.sp.f_lim), None
    full, det = ctx._memo[key]
    rows = np.asarray(runs, dtype=int)
    chans = [c for c in test.channels if c in full.psd]      # a channel left out of every run is not read
    # consecutive runs (every run with a speed): views, not copies
    sel = slice(rows[0], rows[-1] + 1) if rows.size and np.all(np.diff(rows) == 1) else rows
    sp = replace(full, speed=full.speed[sel], psd={c: full.psd[c][sel] for c in chans},
                 amplitude={c: full.amplitude[c][sel] for c in chans}, n_segments=full.n_segments[sel],
                 run_names=[full.run_names[r] for r in rows])
    if rows.size and np.any(np.diff(rows) <= 0):
        return sp, None                 # the lines' renumbering needs the runs in order
    return sp, detections_of_runs({c: det[c] for c in chans if c in det}, rows)


def fit_of_runs(ctx: Context, runs) -> tuple:
    """(SteadyTest, EmpiricalFit) of the context's runs ``runs`` (positions), at the modes' resolution
    (:func:`fit_spectra`)."""
    from ..data import SteadyTest
    from ..empirical import fit_empirical

    runs = [int(r) for r in runs]
    test = SteadyTest([ctx.test.runs[r] for r in runs], dict(ctx.test.meta))
    sp, detections = fit_spectra(ctx, test, runs)
    return test, fit_empirical(sp, detections=detections)


def whole_data_fit(ctx: Context):
    """The empirical fit of EVERY run (at the fit's own resolution, as the suspension modes' fit of some runs,
    :func:`rwadist.effects.suspension_modes_diagnose._fit_runs`), computed once per diagnosis.  What the data as a
    whole show, asked only when the fit runs alone do not show it: the empirical fit marks a line amplified only over
    a speed range several of its speeds cover, and a fixture resonance is detected from the lines near it, so half
    of a short speed grid (10 of 20 speeds) can hide both while every run shows them.  A detection only: the modes
    (and the stand) are still fitted on the fit runs and judged on the held-out ones."""
    key = WHOLE_DATA_FIT
    if key not in ctx._memo:
        ctx._memo[key] = fit_of_runs(ctx, ctx.runs)[1]
    return ctx._memo[key]


def whole_records_fit(ctx: Context, nperseg: int):
    """The empirical fit of every run of ``ctx.test`` with its records read in segments of ``nperseg`` samples, on
    the context's channels: :func:`whole_data_fit` (the same spectra, lines and fit, computed once) when that is this
    fit -- ``nperseg`` the fit's own segment, every run of the test in order, the context's channels those the fit
    reads, its window Hann and no frequency limit -- else fitted here.  Raises ValueError as
    :func:`rwadist.spectra.compute_spectra` does (runs of other lengths)."""
    from ..empirical import fit_empirical
    from ..spectra import _default_nperseg, compute_spectra

    test = ctx.test
    channels = list(ctx.channels)
    usable = [c for c in test.channels if any(r.usable(c) for r in test.runs)]
    if (nperseg == _default_nperseg(int(np.median([r.n_samples for r in test.runs]))) and ctx.sp.window == "hann"
            and ctx.sp.f_lim is None and np.array_equal(ctx.runs, np.arange(len(test.runs)))
            and channels == usable):
        return whole_data_fit(ctx)
    return fit_empirical(compute_spectra(test, nperseg=nperseg, channels=channels))
