"""The rotation sense of each radial line from the x/y phase of the whole runs (:func:`line_senses`), for the
extended fit's start of each line's co- and counter-rotating parts and the rocking scan's forcing of a line that turns
one way in every run (:func:`one_sense_rows`)."""
from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from .data import Run, SteadyTest
from .dft import blocked_records, run_window, windowed_dfts
from .empirical import EmpiricalFit
from .extended_fit_power import RADIAL
from .resonance import resonance
from .units import DIRECTION_CHANNELS

#: samples (runs × record length) of the x/y records :func:`line_senses` transforms together
SENSE_CHUNK_SAMPLES = 1 << 20


#: A radial line is read co (counter) when that share of its x/y power turns so, else planar (:func:`line_senses`)
SENSE_SHARE = 0.75


def line_senses(test: SteadyTest, fit: EmpiricalFit, threshold: float = SENSE_SHARE, stand: tuple | None = None) -> dict:
    """Rotation sense of each radial line from the x/y phase, (direction, h) -> (sense, co_fraction, every_run).

    For each run the complex Hann-windowed DFT of the x and y channels at +h|Ω|
    gives the co-rotating power |X + iY|² and the counter-rotating |X − iY|²
    (swapped for Ω < 0); summed over runs, co_fraction = P_co / (P_co + P_counter).
    Above ``threshold``: "co"; below 1 − threshold: "counter"; between: "planar".
    every_run: "co" ("counter") when the response turns that way by more than :data:`ONE_SENSE` of its power in every
    run the fit measures the line in (:data:`ONE_SENSE_RUNS` at least), else "" (:func:`rwadist.line_senses.one_sense_rows`).
    ``stand``: ((f_r Hz, ζ, peak gain, gain above), channels) of a fixture resonance on some channels, its complex gain
    divided out of those channels' DFTs first (a fixture on Fy alone turns every circular line into an ellipse).
    """
    out = {}
    by_dir = {d: [x for x in fit.lines if x.direction == d] for d in RADIAL}
    for d, lines in by_dir.items():
        cx, cy = DIRECTION_CHANNELS[d]
        if not lines:
            continue
        h = np.array([x.h for x in lines])
        p_co = np.zeros(h.size)
        p_ct = np.zeros(h.size)
        # per line the least and the greatest co-rotating share of one run's response, over the runs it is measured in
        q_lo, q_hi, n_runs = np.ones(h.size), np.zeros(h.size), np.zeros(h.size, int)
        measured = [np.unique(np.abs(x.speed)) for x in lines]
        use = [run for run in test.runs if run.usable(cx) and run.usable(cy) and run.speed != 0]
        # consecutive runs of one record length are transformed together (rwadist.dft.windowed_dfts), and their
        # powers added in the runs' order
        batches: list[list[Run]] = []
        for run in use:
            if batches and (batches[-1][0].n_samples, batches[-1][0].sample_rate) == (run.n_samples, run.sample_rate) \
                    and len(batches[-1]) * run.n_samples < SENSE_CHUNK_SAMPLES:
                batches[-1].append(run)
            else:
                batches.append([run])
        for batch in batches:
            n, fs = batch[0].n_samples, batch[0].sample_rate
            w = run_window("hann", n)[0]             # = signal.windows.hann(n, sym=False)
            f = h[None, :] * np.abs([run.speed for run in batch])[:, None] / (2 * np.pi)
            x = blocked_records([[run.signals[cx], run.signals[cy]] for run in batch], w)
            XY = windowed_dfts(x, fs, f)
            # every run's powers at once, added run after run in the batch's order (a cumulative sum along the runs:
            # the adds of a loop over them; a line out of a run's band adds 0 there)
            X, Y = XY[..., 0], XY[..., 1]
            if stand is not None:
                gain = resonance(f, *stand[0])
                X, Y = (X / gain if cx in stand[1] else X), (Y / gain if cy in stand[1] else Y)
            co, ct = np.abs(X + 1j * Y) ** 2, np.abs(X - 1j * Y) ** 2
            back = np.array([run.speed < 0 for run in batch])[:, None]
            co, ct = np.where(back, ct, co), np.where(back, co, ct)
            ok = f < 0.45 * fs
            p_co = np.cumsum(np.vstack([p_co, np.where(ok, co, 0.0)]), axis=0)[-1]
            p_ct = np.cumsum(np.vstack([p_ct, np.where(ok, ct, 0.0)]), axis=0)[-1]
            speeds = np.abs([run.speed for run in batch])
            seen = ok & np.array([np.isclose(speeds[:, None], m[None, :], rtol=1e-9, atol=0).any(axis=1)
                                  for m in measured]).T
            q = co / np.maximum(co + ct, 1e-300)
            q_lo = np.minimum(q_lo, np.where(seen, q, 1.0).min(axis=0))
            q_hi = np.maximum(q_hi, np.where(seen, q, 0.0).max(axis=0))
            n_runs += seen.sum(axis=0)
        frac = p_co / np.maximum(p_co + p_ct, 1e-300)
        for hk, fr, lo, hi, n_k, read in zip(h, frac, q_lo, q_hi, n_runs, p_co + p_ct > 0):
            if not read:
                # no run holds both channels of the pair (one missing or frozen throughout): no phase, no sense (a
                # line read as 0 of its power co-rotating was made counter-rotating, the imbalance too: session 62's
                # trial without Fy, U_s 0 and every radial force line counter)
                continue
            sense = "co" if fr >= threshold else ("counter" if fr <= 1 - threshold else "planar")
            every = "" if n_k < ONE_SENSE_RUNS else "co" if lo > ONE_SENSE else "counter" if hi < 1 - ONE_SENSE else ""
            out[(d, float(hk))] = (sense, float(fr), every)
    return out


#: A radial line whose response turns one way by more than this share of its power in every run it is measured in
#: (:func:`line_senses`' every_run) is forced that way alone in the modes' scans (:func:`one_sense_rows`): a load
#: turning the other way, or both ways, shows its other sense where the other whirl amplifies it
ONE_SENSE = 0.5
#: Runs a line must be measured in for its every-run sense to count
ONE_SENSE_RUNS = 5


def one_sense_rows(meas_lines: list, row_line: np.ndarray, senses_xy: dict) -> np.ndarray:
    """Per radial row (its measured line ``row_line``), +1 when its line's response is co-rotating in every run
    (:func:`line_senses`' every_run), −1 counter-rotating, 0 otherwise: the rocking scan's forcing of that line
    (:func:`rwadist.mode_scan.scan_mode`'s ``sense``).

    The x²+y² power of a line does not tell a co-rotating load through the forward whirl from a counter-rotating one
    through the backward whirl of another rotor, and the two can fit the power alike at every speed (trial 33, a 6.3 kg
    wheel, rocking 63 Hz at I_zz/I_rr 1.38: the h 3.27 torque line co-rotating, 93-100 % of its power in every run,
    fitted as counter-rotating through a rocking at 105 Hz and 2.03, its amplitudes within 1-2 %, on 2 of 9 clean
    seeds).  A response turning one way in every run is a load turning that way: a load of both senses reads its
    counter part where the backward whirl amplifies it and its co part where neither whirl does."""
    every = {k: v[2] for k, v in senses_xy.items()}
    per_line = np.array([{"co": 1, "counter": -1}.get(every.get((x.direction, float(x.h)), ""), 0)
                         for x in meas_lines], int)
    return per_line[np.asarray(row_line, int)] if per_line.size else np.zeros(len(row_line), int)


def _line_senses_once(test: SteadyTest, fit: EmpiricalFit, stand: tuple | None = None) -> dict:
    """:func:`line_senses` of ``test`` and ``fit``, computed once per (test, fit) and kept on the fit: a fixture
    resonance's joint fit (:func:`rwadist.stand_resonance.fit_extended_beside_stand`) fits the same test and empirical
    fit again and again with another stand divided out,
    which changes the lines' amplitudes, never their directions, h or the time series the senses are read from.
    ``stand``: as :func:`line_senses`' (a fixture on some channels changes the senses read: kept by it)."""
    cached = fit.__dict__.setdefault("_line_senses", {}).get(stand)
    if cached is None or cached[0] is not test:
        cached = (test, line_senses(test, fit, stand=stand))
        fit.__dict__["_line_senses"][stand] = cached
    return cached[1]


#: The imbalance's order: its sense is left to ``rwadist diagnose``'s ``counter_rotation`` family (within this of h = 1)
IMBALANCE_H_TOL = 1e-3
#: A measured line and a model harmonic within this of one another in h are one line (:func:`with_senses`)
SAME_LINE_H = 2e-3


def with_senses(fit: EmpiricalFit, test: SteadyTest, kept: tuple = ("co", "counter", "planar")):
    """``fit``'s model with the rotation sense of each radial line the x/y phase of the whole runs reads
    (:func:`line_senses`) on each harmonic that has none, when it is one of ``kept``, but the imbalance's order; a
    copy when one is set, else the model itself.  Without a sense every consumer reads a radial line co-rotating
    (docs/formats.md): a counter-rotating cage line fitted by ``rwadist fit`` was shown and used co-rotating (session
    61's new-user trial); ``rwadist diagnose`` starts from the model so sensed."""
    model = fit.model
    try:
        senses = _line_senses_once(test, fit)
    except (ValueError, KeyError):
        return model                        # a run without both channels of a pair: no sense read
    out = None
    for d in RADIAL:
        new = []
        for x in model.harmonics(d):
            got = next((v[0] for (dd, h), v in senses.items() if dd == d and abs(h - x.h) <= SAME_LINE_H), None)
            if got in kept and x.sense is None and abs(x.h - 1.0) > IMBALANCE_H_TOL:
                x = replace(x, sense=got)
            new.append(x)
        if any(a is not b for a, b in zip(new, model.harmonics(d))):
            out = out or copy.deepcopy(model)
            out.empirical[d] = new
    return model if out is None else out
