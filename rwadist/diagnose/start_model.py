"""The empirical starting model of ``rwadist diagnose`` (no model given): the speed-sideband pairs its Welch
resolution cannot tell from their carrier, and the rotation sense of its radial lines.

Diagnose reads the runs as Welch PSDs of quarter-record segments (:func:`rwadist.api.diagnose_nperseg`: its held-out
evidence needs averaged segments), 4x coarser than a whole record.  Two lines at h₀ ± δ beside a strong line h₀ (an
amplitude modulation of the line at δ times the speed: ``speed_sidebands``) lie within a few of those bins of their
carrier at the low speeds, and the empirical fit there leaves the whole cluster out of the starting model, carrier
included (the W7 trial wheel, 0.95/1.05 x the speed at 20 % of its imbalance, 16384 samples at 6 kHz: no line near
h = 1; the imbalance came back as a ``missing_harmonic`` of the cluster's power, 3.4 % high, and the sidebands were
never named).  The whole records resolve them (``rwadist fit`` fits all three within 0.1 %): read there, the carrier
goes into the starting model at its own C and the pair is handed to the ``speed_sidebands`` family, which proposes it
as measured, judged on the held-out runs like any effect (as the wheel's suspension-mode base hands the pairs it
left out, :func:`rwadist.diagnose.modes_base.wheel_base`).

The empirical fit reads each line's power, not the way it turns: its radial lines were written with no sense, which
every consumer reads co-rotating (the W7 trial wheel's counter-rotating ball-pass lines h 3.12 and 6.24: the flight
CSD's Im(Fx·Fy*) of the wrong sign).  The x/y phase of the whole runs tells it (:func:`rwadist.line_senses.line_senses`,
the extended fit's own reading): co, counter or planar (both alike), on every radial line but the imbalance's order,
whose counter-rotating part is the ``counter_rotation`` family's to name."""
from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from ..units import CHANNELS, DIRECTION_CHANNELS

#: Two lines are one when their h agree within this (the empirical fit's precision on h, 4 places, and a margin)
SAME_H = 2e-3
#: The whole records are read when they resolve this many times finer than diagnose's Welch segments
FINER = 2.0


def start_model(ctx, fit0):
    """The empirical fit ``fit0``'s model (a copy, when changed) with the carriers of the speed-sideband pairs its
    resolution left out (their C read on the whole records); the pairs ((direction, h₀, h_lower, h_upper, C_lower,
    C_upper, measurements) each) set on ``ctx.base_sideband_pairs``.  The model as it is without the records, on a
    sweep's slices (a line sweeps over a slice) or when the records are no finer than the segments."""
    from ..line_senses import with_senses
    from .modes_base import _sideband_pairs
    from .whole_fit import whole_records_fit

    ctx.base_sideband_pairs = ()
    test = ctx.test
    if test is None or not test.runs:
        return fit0.model
    model = with_senses(fit0, test)
    if (getattr(test, "meta", None) or {}).get("slicing"):
        return model
    n = min(r.n_samples for r in test.runs)
    fs = min(r.sample_rate for r in test.runs)
    if fs / n * FINER > ctx.df:
        return model
    try:
        fine = whole_records_fit(ctx, n)
    except ValueError:
        return model                        # the records cannot be read whole (runs of other lengths)
    out, pairs = None, []
    for d in DIRECTION_CHANNELS:
        have = model.harmonics(d)
        for c, a, b in _sideband_pairs(fine.model.harmonics(d)):
            if any(abs(x.h - a.h) <= SAME_H or abs(x.h - b.h) <= SAME_H for x in have):
                continue                    # resolved by the segments: the base's own lines
            out = out or (model if model is not fit0.model else copy.deepcopy(model))
            carrier = [x for x in out.harmonics(d) if abs(x.h - c.h) <= SAME_H]
            kept = [x for x in out.harmonics(d) if abs(x.h - c.h) > SAME_H]
            out.empirical[d] = sorted(kept + [replace(carrier[0], C=c.C) if carrier else c], key=lambda x: x.h)
            pairs.append((d, float(c.h), float(a.h), float(b.h), float(a.C), float(b.C), int(min(a.n_points, b.n_points))))
    ctx.base_sideband_pairs = tuple(pairs)
    return model if out is None else out


def sensed_lines(diag):
    """``diag``'s model (a copy when changed) with a sense on each radial harmonic of the empirical base that has
    none, but the imbalance's order: the lines the search added (a line the base left out and completed after a test
    stand, a speed-sideband pair beside a carrier of no sense) read as the starting model's were, on the x/y phase of
    the whole runs; the model as it is beside a model given, on the extended base, or without the records.

    An independent trial (session 48: a counter-rotating ball-pass line the base left out under a 140-Hz fixture,
    completed after it; a counter-rotating sideband pair beside the imbalance) had them written with no sense, which
    every consumer reads co-rotating."""
    from ..line_senses import IMBALANCE_H_TOL, SENSE_SHARE

    ctx, model = diag.ctx, diag.model
    if diag.model_given or diag.state_after.base != "empirical" or ctx.test is None:
        return model
    runs = np.asarray(ctx.runs)
    w = ctx.omega[runs]
    fs = np.array([ctx.test.runs[r].sample_rate for r in runs], dtype=float)
    out = None
    for d in ("radial_force", "radial_torque"):
        cx, cy = DIRECTION_CHANNELS[d]
        if not {cx, cy} <= set(ctx.channels):
            continue
        todo = [i for i, x in enumerate(model.harmonics(d)) if x.sense is None and abs(x.h - 1.0) > IMBALANCE_H_TOL]
        if not todo:
            continue
        hs = np.array([model.harmonics(d)[i].h for i in todo])
        f = np.abs(w)[:, None] * hs[None, :] / (2 * np.pi)
        X = ctx.phasors(runs, f)
        x, y = X[..., CHANNELS.index(cx)], X[..., CHANNELS.index(cy)]
        co, ct = np.abs(x + 1j * y) ** 2, np.abs(x - 1j * y) ** 2
        back = (w < 0)[:, None]
        co, ct = np.where(back, ct, co), np.where(back, co, ct)
        ok = np.isfinite(co) & np.isfinite(ct) & (f < 0.45 * fs[:, None]) & (f >= ctx.k_lo * ctx.df)
        p_co, p_ct = np.where(ok, co, 0.0).sum(axis=0), np.where(ok, ct, 0.0).sum(axis=0)
        share = p_co / np.maximum(p_co + p_ct, 1e-300)
        lines = list(model.harmonics(d))
        for i, q, n in zip(todo, share, ok.sum(axis=0)):
            if n:
                lines[i] = replace(lines[i], sense="co" if q >= SENSE_SHARE else "counter" if q <= 1 - SENSE_SHARE
                                   else "planar")
        out = out or copy.deepcopy(model)
        out.empirical[d] = lines
    return model if out is None else out
