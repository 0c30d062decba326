"""Every run's common factor of a run-to-run change spread over the runs (a ``run_change`` of pattern ``spread``: a
load cell's gain drifting over the test, the speeds recorded in shuffled order), and the wheel's suspension modes
whose estimate rests on runs so changed.

:func:`.describe_structure.run_change` reads each run against the lines' smooth trends with speed and sets apart
the runs beyond the runs' scatter: a few runs switched are all set apart, but under a drift every run is off and
only those beyond the scatter are named (family wheel 7, shuffled drift ±20 %: 3 of 16 runs named, each line's
running median having followed part of the drift).  The lines of the model are smooth in speed (C·Ω² through the
modes), so a run's common factor is read against the model itself (:func:`run_gains`): each line's measured over
predicted power (dB), its own median over the runs out (its C takes the mean gain), the median over the run's lines.
Taken out of every run (:func:`rwadist.diagnose.describe.run_steps`), the drift no longer bends the lines' course
through the modes the extended fit reads them from (family wheel 7, the true factors taken out: rocking 130.07 Hz
for 130; left in: 125.8 Hz, −3.3 %, and its damping not constrained).

A mode's frequency and damping are read on the runs where the mode sets a line's level: where doubling that mode's
damping changes a model line's power by :data:`rwadist.stand_detect.STAND_MIN_LOG_GAIN` (a factor 1.5) or more
(:func:`rwadist.diagnose.mode_reach.damping_log_gain`'s test, one mode at a time).  A mode with such runs among the
changed ones is fitted through their factors: :func:`modes_in_changed_runs` names it, so that the record says so
(no mode wrong silently).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..units import CHANNELS, DIRECTION_CHANNELS
from .describe_structure import per_run_median

#: A run's factor needs this many lines read in it.
MIN_LINES = 2
#: The (stiffness, damping) attributes of each mode of ``state.ext`` (:class:`rwadist.extended.ExtendedParams`).
MODE_PARAMS = {"radial_translation": ("k_r", "c_r"), "rocking": ("k_rock", "c_rock"), "axial": ("k_z", "c_z")}
#: A mode's frequency moved by this fraction (the tolerance docs/diagnose.md holds the modes to: 2 %) ...
MODE_SHIFT = 0.02


def run_gains(ctx, ratios: list, min_lines: int = MIN_LINES) -> np.ndarray:
    """Per run of the context (R,): its common factor (dB of power) against the model's lines, the runs' median 0,
    NaN where fewer than ``min_lines`` lines are read; ``ratios`` the :class:`.describe_structure.LineRatios`."""
    out = per_run_median(ratios, ctx.runs.size, 3, min_lines, lambda r, m: np.median(r.q[m]))
    ok = np.isfinite(out)
    if ok.any():
        out[ok] -= np.median(out[ok])
    return out


#: A direction takes part in a run-to-run change when its own runs' factors follow the common ones by this share or
#: more (the slope of its factors on the common factors, through 0)
CHANGED_SHARE = 0.5


def in_changed_directions(ctx, ratios: list) -> list:
    """``ratios`` of the directions whose runs change with the common factor (:func:`run_gains` of each direction
    alone against that of all: a slope of :data:`CHANGED_SHARE` or more), all of them when none or every one does.
    A gain drifting on the force bridges alone was read over every channel at the median of all the lines (session
    60's trial: forces −1.5 dB over the test, the torques steady: "in Fx Fy Fz Tx Ty Tz", −1.22 dB)."""
    common = run_gains(ctx, ratios)
    keep = []
    for r in ratios:
        own = run_gains(ctx, [r], min_lines=1)          # a direction of one line reads its factor on that line
        ok = np.isfinite(own) & np.isfinite(common)
        den = float(np.sum(common[ok] ** 2))
        # a direction whose factor cannot be read against the common one is kept: no evidence it stayed still
        if ok.sum() < 3 or den <= 0 or float(np.sum(own[ok] * common[ok])) / den >= CHANGED_SHARE:
            keep.append(r)
    return keep if keep else list(ratios)


def _line_powers(state, par, w: np.ndarray, directions=None) -> list:
    """Per direction with model lines (of ``directions``, default every one): ln of each line's power (R, lines)
    pooled over the direction's channels, both senses of each radial line at unit load, through the modes of ``par``."""
    from .. import extended as ext

    out = []
    for direction, chans in DIRECTION_CHANNELS.items():
        if directions is not None and direction not in directions:
            continue
        idx = [CHANNELS.index(c) for c in chans]
        hs = [x.h for x in state.model.harmonics(direction)]
        if hs:
            lines = [ext.Line(direction, float(h), 1.0, s) for h in hs for s in ("co", "counter")]
            _, A = ext.steady_lines(par, lines, w)
            out.append(np.log(np.maximum((np.abs(A[:, :, idx]) ** 2).sum(axis=2), 1e-300)))
    return out


def mode_runs(ctx, state, factors_db: np.ndarray, directions=None) -> dict:
    """Mode name -> bool (R,) over the context's runs: the runs that set the mode's estimate, where doubling its
    damping changes some model line's power by a factor 1.5 or more (the damping's reach,
    :func:`rwadist.diagnose.mode_reach.damping_log_gain`), or moving its frequency by :data:`MODE_SHIFT` changes
    some line's power by the run's own factor (``factors_db`` (R,), dB of power: that run's change can be taken for
    such a shift) or more, on the lines of ``directions`` (default every direction); {} without the modes."""
    from ..stand_detect import STAND_MIN_LOG_GAIN

    p = getattr(state, "ext", None)
    if p is None:
        return {}
    w = ctx.omega[ctx.runs]
    base = _line_powers(state, p, w, directions)
    factor = np.abs(np.nan_to_num(np.asarray(factors_db, float))) * np.log(10.0) / 10.0       # ln of power
    out = {}
    for mode, (k, c) in MODE_PARAMS.items():
        damped = _line_powers(state, replace(p, **{c: 2.0 * getattr(p, c)}), w, directions)
        moved = _line_powers(state, replace(p, **{k: (1.0 + MODE_SHIFT) ** 2 * getattr(p, k)}), w, directions)
        hit = np.zeros(w.size, bool)
        for b, d, m in zip(base, damped, moved):
            hit |= np.any(np.abs(d - b) >= STAND_MIN_LOG_GAIN, axis=1)
            hit |= (factor > 0) & np.any(np.abs(m - b) >= factor[:, None], axis=1)
        out[mode] = hit
    return out


def modes_in_changed_runs(ctx, state, changed: np.ndarray, factors_db: np.ndarray, directions=None) -> list:
    """The modes of ``state`` (names) whose estimate rests on runs among ``changed`` (bool (R,) over the context's
    runs, ``factors_db`` their factors, :func:`mode_runs` on the lines of ``directions``)."""
    hits = mode_runs(ctx, state, np.where(changed, factors_db, 0.0), directions)
    return [m for m, hit in hits.items() if np.any(hit & changed)]


def annotate(ctx, state, records: list, ratios: list, taken_out: bool = False) -> list:
    """``records`` (:func:`.describe_structure.run_change`'s) with, on a ``spread`` change, every run's factor
    (:func:`run_gains`: ``run_gains_dB`` beside ``run_gain_runs``; the record's speed range and run count those of
    every run read), and on either pattern the modes of ``state`` whose estimate rests on the changed runs
    (:func:`modes_in_changed_runs`) named in ``modes_on_changed_runs`` and in the first cause: fitted through the
    runs' factors, or (``taken_out``) on records with the factors taken out (:func:`rwadist.diagnose.describe.
    run_steps`)."""
    from dataclasses import replace as copy_with

    from ..units import RAD_S_TO_RPM

    names = [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in ctx.runs]
    out = []
    for u in records:
        p, extra = dict(u.parameters), {}
        if p.get("pattern") == "spread":
            g = run_gains(ctx, ratios)
            changed = np.isfinite(g)
            p["run_gain_runs"] = [names[i] for i in np.flatnonzero(changed)]
            p["run_gains_dB"] = [float(x) for x in g[changed]]
            rpm = ctx.omega[ctx.runs[changed]] * RAD_S_TO_RPM
            spread = 1.4826 * float(np.median(np.abs(g[changed] - np.median(g[changed]))))
            extra = {"speed_rpm": (float(rpm.min()), float(rpm.max())), "n_runs": int(changed.sum()),
                     "level_dB": spread}
            factors = np.nan_to_num(g)
        else:
            changed = np.isin(names, p.get("runs", ()))
            factors = np.zeros(changed.size)
            factors[changed] = [x for n, x in zip(p.get("runs", ()), p.get("run_offsets_dB", ())) if n in names]
        modes = modes_in_changed_runs(ctx, state, changed, factors)
        p["modes_on_changed_runs"] = modes
        p["factors_taken_out"] = bool(taken_out)
        causes = tuple(u.causes)
        if modes and causes:
            how = ("fitted on the records with the runs' factors taken out" if taken_out else
                   "fitted through the runs' factors: suspect")
            causes = (causes[0] + f"; the {', '.join(m.replace('_', ' ') for m in modes)} mode"
                      f"{'s rest' if len(modes) > 1 else ' rests'} on the changed runs, {how}",) + causes[1:]
        out.append(copy_with(u, parameters=p, causes=causes, **extra))
    return out


def step_sets(diag, run_steps, located: int = 3) -> list:
    """The run factors (run index -> dB, NaN: left out) the search is tried again with (``run_steps``:
    :func:`rwadist.diagnose.describe.run_steps`, passed in: describe reads this module), in order: the runs read, then with those whose change was not read
    left out.  Under a change spread over every run (:func:`is_spread`) also every run's factor (:func:`run_gains`),
    the unread runs left out first (a drift changes them too), and the runs held apart as for a step: the factors
    against the model are only as good as its course in speed, and a first search that located no mode has none
    (the open world's family wheel 3, every third run 3.5 dB up: no mode in the first search, its runs read as a
    spread, factors of −3.7 to +4.3 dB against it; the runs held apart, all three modes located).  So every run's
    factors come first when the first search located a mode (``located``: how many), else last: the search's tries
    end at the best standing there is, which the runs held apart reach on that wheel (its diagnosis 67 → 39 s, the
    same answer)."""
    spread = is_spread(diag)
    out: list = []
    for every in (((True, False) if located else (False, True)) if spread else (False,)):
        steps = run_steps(diag, every_run=every)
        read = type(steps)({r: dB for r, dB in steps.items() if np.isfinite(dB)}, steps.channels)
        if not read:
            continue
        sets = [read] + ([steps] if len(read) < len(steps) else [])
        out += sets[::-1] if every else sets
    return out


def is_spread(diag) -> bool:
    """Whether ``diag`` describes a ``run_change`` spread over every run (a drift): then a run whose factor was not
    read (too few lines over the noise) is changed too, by an unknown factor, and the search that leaves it out is
    tried first (family wheel 7, shuffled drift ±20 %, the 1000 and 1600 rpm runs unread: left out, rocking 129.96 Hz
    for 130; left in unscaled, 132.26 Hz)."""
    return any(u.signature == "run_change" and u.parameters.get("pattern") == "spread" for u in diag.unexplained)
