"""A channel's gain that changes between runs (the open world, issue 33, item 3: "a run-to-run change", where it is,
its strength, and what it could be), read on the ratio of a radial channel's lines to its partner's.

A radial line of an axisymmetric wheel is a load rotating with or against the spin, so x and y carry its power alike
(:mod:`.describe_gain`).  A load-cell channel whose gain is switched between runs (an amplifier's range or gain
setting, a connector re-seated, a bridge's excitation changed) reads every line of the pair by one factor against
its partner in the runs before the switch and by another after it: the ratio of the pair's lines, per run the median
over the lines of 10·log10(P_y/P̂_y) − 10·log10(P_x/P̂_x), steps between two runs.  A constant ratio over every run
(trial13's Ty × 1.10) is the ``line_property`` of :func:`.describe_gain.channel_gain`; described as a constant, a
step hides where the change is (trial24 gainstep: Fx × 1.3 from the 9th of 16 runs, 5800 rpm, described as "Fx
reads 1.3 x Fy" over 1600-10000 rpm).

The change point (:func:`change_point`): the runs in speed order, the split with the smallest sum of absolute
deviations of each side from its median (two runs on a side at least: :data:`MIN_SIDE`), against the Theil-Sen line
through every run (a ratio that changes smoothly with speed, e.g. one channel's gain warming, is a ``trend``, not a
step).  It is significant when the step is ``min_db`` (:data:`.describe_gain.MIN_DB`) or more and :data:`STEP_Z`
standard errors of the two sides' medians (from the runs' robust scatter about their side's median, never taken
below :data:`SCATTER_FLOOR_DB`); a gain acts on every line, so ``min_lines`` (:data:`.describe_gain.MIN_LINES`) lines,
and half of the lines read on both sides (:data:`READ_SHARE`), must each step the same way, within a factor 2 of
it.  The channel that moved is the one whose own lines step against the model (the model's lines are smooth in
speed, its C the same in x and y): its per-run median of 10·log10(P/P̂), each line's own median out, steps by about
the whole ratio's step and the partner's by little.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..units import RAD_S_TO_RPM
from .unexplained import Unexplained

#: Runs on either side of a change point, at least.
MIN_SIDE = 2
#: The step over its standard error, at least.
STEP_Z = 5.0
#: The runs' scatter about their side's median is never taken below this (dB): the per-run medians of clean data of
#: the wheel family scatter by 0.01-0.05 dB; a perfect step on noiseless data is still a finite number of errors.
SCATTER_FLOOR_DB = 0.02
#: The lines stepping with the change, at least this share of the lines read on both sides of it (a gain acts on all)
READ_SHARE = 0.5
#: The channel that moved holds at least this fraction more of the step than its partner (else both are named).
OWN_FACTOR = 2.0
#: What a record says of the modes the stepped channel's lines hold, fitted on the records as given ...
THROUGH_THE_GAINS = "fitted through the two gains: suspect"
#: ... and when the search was run again with the step taken out (:func:`channel_steps`)
TAKEN_OUT = "fitted on the records with {moved}'s gain brought to {reference}'s on either side of the step"
#: A side whose gain is within this of its partner's (dB of power) is left as recorded.
SIDE_TOLERANCE_DB = 1e-3


def per_run(d: np.ndarray, good: np.ndarray) -> np.ndarray:
    """Per run (R,): the median over the lines read in it (``good`` (L, R)) of ``d`` (L, R), NaN without any."""
    out = np.full(d.shape[1], np.nan)
    for j in range(d.shape[1]):
        if good[:, j].any():
            out[j] = float(np.median(d[good[:, j], j]))
    return out


def change_point(spin: np.ndarray, y: np.ndarray) -> dict | None:
    """The change point of ``y`` (R,, NaN where not read) against the runs' speeds ``spin`` (R,): a dict with the
    positions ``below`` and ``above`` (into ``y``) either side of it, the sides' medians ``below_dB`` and
    ``above_dB``, ``step_dB``, its ``z`` (standard errors), ``scatter_dB`` and ``pattern`` ("step", or "trend" when
    the Theil-Sen line through every run leaves less than the step does); None with fewer than 2·:data:`MIN_SIDE`
    runs read."""
    from scipy.stats import theilslopes

    ok = np.flatnonzero(np.isfinite(y))
    if ok.size < 2 * MIN_SIDE:
        return None
    order = ok[np.argsort(spin[ok], kind="stable")]
    ys, xs = y[order], spin[order]
    costs = []
    for k in range(MIN_SIDE, ys.size - MIN_SIDE + 1):
        a, b = ys[:k], ys[k:]
        costs.append(float(np.sum(np.abs(a - np.median(a))) + np.sum(np.abs(b - np.median(b)))))
    k = MIN_SIDE + int(np.argmin(costs))
    a, b = ys[:k], ys[k:]
    lo, hi = float(np.median(a)), float(np.median(b))
    rest = np.concatenate([a - lo, b - hi])
    scatter = max(1.4826 * float(np.median(np.abs(rest))), SCATTER_FLOOR_DB)
    # the standard error of a median is about 1.25 that of a mean of Gaussian scatter
    z = abs(hi - lo) / (1.2533 * scatter * np.sqrt(1.0 / a.size + 1.0 / b.size))
    pattern = "step"
    if np.ptp(xs) > 0:
        slope, icpt = theilslopes(ys, xs)[:2]
        if float(np.sum(np.abs(ys - (icpt + slope * xs)))) < min(costs):
            pattern = "trend"
    return {"below": order[:k], "above": order[k:], "below_dB": lo, "above_dB": hi, "step_dB": hi - lo,
            "z": float(z), "scatter_dB": scatter, "pattern": pattern}


def _lines_stepping(d: np.ndarray, good: np.ndarray, cp: dict) -> np.ndarray:
    """Bool (L,): the lines whose own step across ``cp`` (the median of ``d`` over the runs above less that below,
    two runs on each side at least) has the step's sign and lies within a factor 2 of it."""
    step = cp["step_dB"]
    out = np.zeros(d.shape[0], bool)
    for i in range(d.shape[0]):
        lo, hi = cp["below"][good[i, cp["below"]]], cp["above"][good[i, cp["above"]]]
        if lo.size >= MIN_SIDE and hi.size >= MIN_SIDE:
            s = float(np.median(d[i, hi]) - np.median(d[i, lo]))
            out[i] = np.sign(s) == np.sign(step) and 0.5 * abs(step) <= abs(s) <= 2.0 * abs(step)
    return out


def _own_step(q: np.ndarray, good: np.ndarray, cp: dict) -> float:
    """The step across ``cp`` of one channel's lines against the model: per run the median over its lines of ``q``
    (L, R: 10·log10(P/P̂)), each line's own median over the runs out."""
    centred = q - np.array([np.median(q[i, good[i]]) if good[i].any() else 0.0 for i in range(q.shape[0])])[:, None]
    y = per_run(np.where(good, centred, 0.0), good)
    lo, hi = y[cp["below"]], y[cp["above"]]
    lo, hi = lo[np.isfinite(lo)], hi[np.isfinite(hi)]
    return float(np.median(hi) - np.median(lo)) if lo.size and hi.size else 0.0


def gain_step(ctx, state, pair: tuple, h: np.ndarray, q: tuple, good: np.ndarray, shares, min_db: float,
              min_lines: int) -> Unexplained | None:
    """A ``line_property`` record (property ``channel_gain``, pattern ``step`` or ``trend``) of the radial ``pair``
    (cx, cy) of ``state``'s lines whose ratio changes between runs, or None.  ``h`` (L,) the lines, ``q`` = (q_x, q_y) each (L, R)
    10·log10(P/P̂) of the pair's channels on the context's runs, ``good`` (L, R) the cells read (both channels over the
    noise), ``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB); ``min_db`` the step (dB of power)
    and ``min_lines`` the lines holding it at least (those of a constant gain, :mod:`.describe_gain`)."""
    cx, cy = pair
    d = q[1] - q[0]
    d = np.where(good, d, np.nan)
    spin = ctx.omega[ctx.runs] / (2 * np.pi)
    cp = change_point(spin, per_run(np.nan_to_num(d), good))
    if cp is None or not (abs(cp["step_dB"]) >= min_db and cp["z"] >= STEP_Z):
        return None
    stepping = _lines_stepping(np.nan_to_num(d), good, cp)
    # a gain moves every line: most of the lines read on both sides step with it (the session-52 generator's W1, planar
    # bearing lines through its translation mode: 2 of the 5 lines read stepped within a factor 2 of 10.9 dB, two not
    # at all (0.02, 0.00 dB), one 25 dB; "Fx's gain changed by x 0.286" had been described)
    read = (good[:, cp["below"]].sum(axis=1) >= MIN_SIDE) & (good[:, cp["above"]].sum(axis=1) >= MIN_SIDE)
    if stepping.sum() < min_lines or stepping.sum() < READ_SHARE * read.sum():
        return None
    own = {c: _own_step(q[j], good, cp) for j, c in enumerate(pair)}
    # the channel that moved steps against the model; its partner by little (the model's lines are smooth in speed)
    big = max(pair, key=lambda c: abs(own[c]))
    other = cy if big == cx else cx
    moved = (big,) if abs(own[big]) >= OWN_FACTOR * abs(own[other]) else pair
    u = _record(ctx, pair, h, stepping, cp, own, moved, shares)
    # the modes the pair's direction reads on runs of either side: the two sides' gains disagree, and the fit
    # takes the lines of both (which side is right the data cannot say)
    from .run_gains import modes_in_changed_runs

    both = np.isin(np.arange(ctx.runs.size), np.concatenate([cp["below"], cp["above"]]))
    direction = "radial_force" if cx.startswith("F") else "radial_torque"
    modes = modes_in_changed_runs(ctx, state, both, np.full(both.size, abs(cp["step_dB"])), (direction,))
    if not modes:
        return replace(u, parameters={**u.parameters, "modes_on_changed_runs": []})
    note = (f"; the {', '.join(m.replace('_', ' ') for m in modes)} mode{'s rest' if len(modes) > 1 else ' rests'} "
            f"on {cx} and {cy} across the step, {THROUGH_THE_GAINS}")
    return replace(u, parameters={**u.parameters, "modes_on_changed_runs": modes},
                   causes=(u.causes[0] + note,) + tuple(u.causes[1:]))


def _record(ctx, pair, h, stepping, cp, own, moved, shares) -> Unexplained:
    """The record of :func:`gain_step`'s change point ``cp``."""
    cx, cy = pair
    runs = ctx.runs
    rpm = ctx.omega[runs] * RAD_S_TO_RPM
    names = [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in runs]
    below, above = cp["below"], cp["above"]
    last, first = below[np.argmax(rpm[below])], above[np.argmin(rpm[above])]
    r_lo, r_hi = 10 ** (cp["below_dB"] / 20), 10 ** (cp["above_dB"] / 20)
    used = np.concatenate([below, above])
    share, _ = shares(pair, h[stepping], runs[used])
    f = h[stepping][:, None] * ctx.omega[runs[used]][None, :] / (2 * np.pi)
    who = moved[0] if len(moved) == 1 else f"{cx} or {cy}"
    # the factors said of the channel that moved against its partner (Fy/Fx as measured, inverted for Fx)
    a, b, x_lo, x_hi = (cy, cx, r_lo, r_hi) if moved[0] == cy else (cx, cy, 1.0 / r_lo, 1.0 / r_hi)
    if cp["pattern"] == "step":
        where = (f"by x {x_hi / x_lo:.3g} between {names[last]} ({rpm[last]:.0f} rpm) and {names[first]} "
                 f"({rpm[first]:.0f} rpm), in speed order: {a} reads {x_lo:.3g} x {b} below and {x_hi:.3g} x {b} "
                 f"from {rpm[first]:.0f} rpm")
    else:
        where = (f"smoothly with speed: {a} reads {x_lo:.3g} x {b} at the lower speeds and {x_hi:.3g} x {b} at the "
                 f"upper (the change point at {rpm[first]:.0f} rpm)")
    lines = ", ".join(f"{x:.3g}" for x in h[stepping])
    causes = (f"{who}'s gain changed {where} ({cp['step_dB']:+.2f} dB of power, {cp['z']:.0f} standard errors, on the "
              f"lines h {lines}; {cx} {own[cx]:+.2f} dB and {cy} {own[cy]:+.2f} dB against the model): a load-cell "
              "channel's gain switched between runs (an amplifier's range or gain, a connector or cable re-seated, a "
              "bridge's excitation)",
              "the load cell or the wheel re-mounted between those runs (seated or turned differently): a re-mounting "
              "moves the lines of every channel, a channel's gain those of that channel alone")
    would = (f"the runs in the order they were recorded (a step in time between {names[last]} and {names[first]} "
             f"is a switch or a re-mounting then; a gain that changes with speed, e.g. warming, is not a step in time), "
             f"a run below {rpm[first]:.0f} rpm repeated after the upper ones, and a calibration of {cx} and {cy} "
             "with one known load before and after")
    return Unexplained(
        signature="line_property", channels=pair, speed_rpm=(float(rpm[used].min()), float(rpm[used].max())),
        f_Hz=(float(f.min()), float(f.max())), level_dB=float(cp["step_dB"]), share=share, n_runs=int(used.size),
        parameters={"property": "channel_gain", "pattern": cp["pattern"], "channel": cy, "reference": cx,
                    "moved": list(moved), "step_dB": float(cp["step_dB"]), "stderr_z": float(cp["z"]),
                    "amplitude_ratio_below": float(r_lo), "amplitude_ratio_above": float(r_hi),
                    "amplitude_ratio": float(r_hi / r_lo), "power_ratio_dB": float(cp["step_dB"]),
                    "step_between_runs": [names[last], names[first]],
                    "step_between_rpm": [float(rpm[last]), float(rpm[first])],
                    "runs_above": [names[i] for i in above], "own_step_dB": {c: float(v) for c, v in own.items()},
                    "lines_h": [float(x) for x in h[stepping]], "scatter_dB": float(cp["scatter_dB"])},
        causes=causes, would_tell=would)


def _step_with_modes(diag) -> Unexplained | None:
    """The first ``step`` record of ``diag`` (:func:`gain_step`) of one channel that moved, with a wheel's mode on its
    lines (``modes_on_changed_runs``), or None."""
    return next((u for u in diag.unexplained if u.signature == "line_property"
                 and u.parameters.get("property") == "channel_gain" and u.parameters.get("pattern") == "step"
                 and len(u.parameters.get("moved", ())) == 1 and u.parameters.get("modes_on_changed_runs")), None)


def channel_steps(diag) -> tuple | None:
    """(run index -> dB of power, (channel,)): the gain of the one channel that moved in a ``step`` record of ``diag``
    (:func:`gain_step`) on whose lines a wheel's mode rests, per run of the test, against its partner's on the run's
    side of the step: taken out of that channel's records (:func:`rwadist.diagnose.describe.scale_runs`), the two
    channels read alike in every run, as an axisymmetric wheel's lines do.  None when no such record (or no time
    series).  Which side's gain is right the data cannot say; the partner's, unmoved, is the reference.  Left in, the
    modes are fitted through the two gains (the session-68 trial, wheel A, Ty × 1.35 from 4100 rpm: rocking +2.5 %,
    I_zz/I_rr −7.3 %, described "suspect" and kept)."""
    ctx = diag.ctx
    u = _step_with_modes(diag)
    if u is None or ctx.test is None:
        return None
    p = u.parameters
    # the ratios are the partner's (``channel``) over the reference's amplitude: the reference moving inverts them
    sign = 1.0 if p["moved"][0] == p["channel"] else -1.0
    below, above = (sign * 20.0 * np.log10(p[k]) for k in ("amplitude_ratio_below", "amplitude_ratio_above"))
    first = p["step_between_rpm"][1]
    # unsigned, as the record's speeds (a test run clockwise has negative speeds)
    rpm = np.abs(np.array([run.speed for run in ctx.test.runs], dtype=float)) * RAD_S_TO_RPM
    # each run of the test on its side by speed: the runs the step was not read on (too few lines: the lowest) too
    steps = {i: float(above if r >= first * (1 - 1e-9) else below) for i, r in enumerate(rpm)}
    return {i: dB for i, dB in steps.items() if abs(dB) >= SIDE_TOLERANCE_DB}, tuple(p["moved"])


def with_step_taken_out(again, first) -> tuple:
    """The ``unexplained`` records of ``again`` (the search run on the records with :func:`channel_steps` of ``first``
    taken out) with ``first``'s step record in front, in place of any gain record of that pair: the corrected records
    no longer show the step, the data as given do; its modes' words say where they were fitted."""
    u = _step_with_modes(first)
    if u is None:
        return tuple(again.unexplained)
    p = u.parameters
    words = TAKEN_OUT.format(moved=p["moved"][0], reference=p["reference"] if p["moved"][0] == p["channel"]
                             else p["channel"])
    step = replace(u, parameters={**p, "factors_taken_out": True},
                   causes=(u.causes[0].replace(THROUGH_THE_GAINS, words),) + tuple(u.causes[1:]))
    others = [v for v in again.unexplained if not (v.signature == "line_property"
                                                     and v.parameters.get("property") == "channel_gain"
                                                     and set(v.channels) == set(u.channels))]
    return (step, *others)
