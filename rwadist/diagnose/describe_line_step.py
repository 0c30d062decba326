"""A model line whose level steps between two runs while the other lines keep their course (the open world, issue 33,
item 3: "a run-to-run change" of one line): a ``line_property`` of property ``line_step``.

The model holds each line as C·Ω² (or its law) through the wheel's modes: one C for every run.  A line's source that
changes between runs -- a balance mass moved or a part shifted between two runs of the test (the imbalance), a
bearing re-lubricated or re-preloaded (its lines) -- leaves that line's measured-over-predicted ratio on two levels:
the runs before the change on one, those after on the other, the fitted C between them.  No class models it (the
imbalance is pinned at U·Ω², :mod:`rwadist.off_law_lines`), and the runs' change of every line alike
(:func:`.describe_structure.run_change`) does not see one line: the new-user trial of session 52, the static
imbalance 20 % stronger in the upper half of the runs (in speed order), left 360-1480x the clean error and nothing
said.

Per line (its direction's channels pooled, :func:`.describe_structure.line_ratios`), the runs in speed order, the
change point of :func:`.gain_step.change_point`: described when it is a step (a law, smooth in speed, is a
``trend``, and each side's own course moves by at most :data:`SIDE_COURSE_SHARE` of it), :data:`MIN_STEP_DB` or
more, :data:`STEP_OVER_SCATTER` times the runs' scatter about their side's median or more (pooled, and each side's
own: :func:`_side_scatter`), and :data:`~.gain_step.STEP_Z` standard errors of the two sides' medians,
with :data:`MIN_SIDE_RUNS` runs on each side; when the other lines, read across the same split, step by less than
:data:`OTHERS_SHARE` of it, those of its own direction too (a change of every line is a gain or a re-mounting, the
run-change's; of every line of one direction, a gain of its channels); and when the split
is no crossing of the line with a suspension mode of the model (:func:`.mode_reach.crossing_groups`: a mode's
frequency or damping a little off leaves the runs below its crossing and those above on two levels too) or with a
fixed resonance of the state (a test stand).
"""
from __future__ import annotations

import numpy as np

from ..resonance import resonance
from ..stand_detect import STAND_MIN_LOG_GAIN
from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .gain_step import STEP_Z, change_point
from .mode_reach import crossing_groups
from .unexplained import Unexplained

#: The step at least (dB of power: 1 dB is 12 % in amplitude)
MIN_STEP_DB = 1.0
#: Runs on either side of the step, at least
MIN_SIDE_RUNS = 3
#: The other lines' median step across the same split, at most this share of the line's (else a common change)
OTHERS_SHARE = 0.5
#: Over either side's runs, the line's own course (its Theil-Sen slope times the side's span of speeds) moves by at most
#: this share of the step: two flat levels (a line growing fast at the top speeds, the session-51 generator's quadratic
#: channel's Ω⁴ line at h 7.26, rose +15 dB over its top four runs and read as a step into them)
SIDE_COURSE_SHARE = 0.25
#: The step over the runs' robust scatter about their side's median, at least: two levels, each flat (a line rising
#: through a resonance the model lacks scatters about any two levels: the new-user trial's W1 with its modes unfitted,
#: h 5.39 through the 420 Hz translation read +8.4 dB at 3.1 dB scatter; a step of the imbalance 1.6 dB at 0.02)
STEP_OVER_SCATTER = 4.0
#: A line's drift over the test (``line_drift``): its level rank-correlated with the order the runs were recorded in
#: (Kendall's τ) with a chance below this, two-sided ...
DRIFT_CHANCE = 1e-4
#: ... and not with their speed below this (a misfit with speed is read in any order the runs were recorded in)
DRIFT_SPEED_CHANCE = 1e-3


def _series(ctx, ratios: list) -> list:
    """[(direction, h, y (R,))]: each line's dB ratio per run of the context, NaN where it is not read."""
    out = []
    for r in ratios:
        for i in np.unique(r.line):
            m = r.line == i
            y = np.full(ctx.runs.size, np.nan)
            y[r.run[m]] = r.q[m]
            out.append((r.direction, float(r.h[m][0]), y))
    return out


def _step_across(y: np.ndarray, below: np.ndarray, above: np.ndarray) -> float | None:
    """The median of ``y`` over the runs ``above`` less that over ``below`` (2 runs read on each side at least)."""
    lo, hi = y[below], y[above]
    lo, hi = lo[np.isfinite(lo)], hi[np.isfinite(hi)]
    return float(np.median(hi) - np.median(lo)) if lo.size >= 2 and hi.size >= 2 else None


def _side_course(spin: np.ndarray, y: np.ndarray) -> float:
    """|Theil-Sen slope of ``y`` against ``spin``| times the span of ``spin`` (dB): how far one side's runs move along
    their own course."""
    from scipy.stats import theilslopes

    ok = np.isfinite(y)
    if ok.sum() < 2 or np.ptp(spin[ok]) <= 0:
        return 0.0
    return float(abs(theilslopes(y[ok], spin[ok])[0]) * np.ptp(spin[ok]))


def _side_scatter(y: np.ndarray) -> float:
    """The robust scatter (dB, 1.4826 x the median absolute deviation) of one side's runs about that side's median.

    The change point's scatter is pooled over both sides, and the longer side rules it: the session-51 generator's
    quadratic Fz channel put h 7.26 = 2 x 3.63 on the square of its parent's course through the unlocated 580 Hz axial
    mode, a hump over the top five runs (+7.9, 14.3, 18.2, 12.5, 4.9 dB) after 39 flat ones: pooled scatter 2.3 dB, the
    hump's own 6.8 dB, and a "step" of 13.6 dB was described.  Each level must be flat on its own."""
    v = y[np.isfinite(y)]
    return 1.4826 * float(np.median(np.abs(v - np.median(v)))) if v.size else 0.0


def _lifted(f: np.ndarray, f_r, zeta: float, gain: float, above: float = 1.0) -> bool:
    """Whether a resonance at ``f_r`` Hz (a number, or one per frequency: a moving one's track) changes the power of a
    line at ``f`` Hz (the two runs either side of a step) by a factor 1.5 or more in either run, or lies between them:
    the stand detection's own threshold (:data:`rwadist.stand_detect.STAND_MIN_LOG_GAIN`)."""
    lift = np.abs(np.log(np.maximum(np.abs(resonance(f, f_r, zeta, gain, above)) ** 2, 1e-300)))
    off = np.asarray(f - f_r, dtype=float)
    return bool(np.any(lift >= STAND_MIN_LOG_GAIN) or off[0] * off[-1] <= 0)


def _at_a_crossing(ctx, state, direction: str, h: float, last: int, first: int) -> bool:
    """Whether the line (direction, h) crosses one of the model's suspension modes (a whirl branch included) or a
    fixed resonance of the state (a test stand: the new-user W2's force fixture at 105 Hz, fitted on every channel,
    left its h 4.12 line on two levels either side of 105 Hz) between the runs at positions ``last`` and ``first``,
    or either of them lies in such a resonance's reach (its power gain 1.5 or more, up or down)."""
    senses = [getattr(x, "sense", None) or "co" for x in state.model.harmonics(direction) if abs(x.h - h) < 1e-3]
    group = crossing_groups(state, direction, h, senses or ["co"], ctx.omega[ctx.runs[[last, first]]])
    if group[0] != group[1] or np.any(group < 0):
        return True
    f = h * np.abs(ctx.omega[ctx.runs[[last, first]]]) / (2 * np.pi)
    return any(_lifted(f, e.f_r, e.zeta, e.peak_gain, e.gain_above)
               for e in state.effects if getattr(e, "kind", "") == "fixed_resonance")


def _on_a_track(records, direction: str, f: np.ndarray, spin: np.ndarray) -> bool:
    """Whether a line of ``direction`` at frequencies ``f`` (Hz) at the spins ``spin`` (Hz, signed as the runs'; two
    runs) is lifted (:func:`_lifted`) by a ``moving_resonance`` among ``records`` (its frequency linear in the spin
    from its lowest speed to its highest) or a ``channel_resonance`` of the direction's channels: family wheel 4, an
    axial mode stiffening with speed, read its h 3 line x 1.38 across the two runs where the line rose into it; the
    session-51 generator's one-channel resonances."""
    for u in records:
        p = u.parameters
        if p.get("property") == "channel_resonance" and set(u.channels) & set(DIRECTION_CHANNELS[direction]):
            if _lifted(f, p["f_r_Hz"], p["zeta"], p["peak_gain"]):
                return True
        elif u.signature == "moving_resonance" and direction in (p.get("direction"), *p.get("directions", ())):
            s_lo, s_hi = (x / 60.0 for x in u.speed_rpm)
            f_lo, f_hi = p["f_at_lowest_speed_Hz"], p["f_at_highest_speed_Hz"]
            track = f_lo + (f_hi - f_lo) * (spin - s_lo) / (s_hi - s_lo) if s_hi > s_lo else np.full(spin.shape, f_lo)
            if _lifted(f, track, p["zeta"], p["peak_gain"]):
                return True
    return False


def two_levels(x: np.ndarray, y: np.ndarray) -> dict | None:
    """The change point of :func:`.gain_step.change_point` of ``y`` (R,, dB, NaN where not read) against ``x`` (R,,
    the runs' speeds or any increasing function of them) when it is a step between two flat levels, else None: a step
    (not a Theil-Sen trend against ``x``), :data:`MIN_STEP_DB` or more, :data:`STEP_OVER_SCATTER` times the runs'
    scatter about their side's median or more (pooled, and each side's own: :func:`_side_scatter`), each side's own
    course at most :data:`SIDE_COURSE_SHARE` of it (:func:`_side_course`), :data:`~.gain_step.STEP_Z` standard errors
    of the two sides' medians, and :data:`MIN_SIDE_RUNS` runs on each side."""
    if np.isfinite(y).sum() < 2 * MIN_SIDE_RUNS or np.nanmax(y) - np.nanmin(y) < MIN_STEP_DB:
        return None             # no two sides' medians of it lie MIN_STEP_DB apart: the change point is not sought
    cp = change_point(x, y)
    if cp is None or cp["pattern"] != "step" or abs(cp["step_dB"]) < max(MIN_STEP_DB, STEP_OVER_SCATTER *
                                                                           cp["scatter_dB"]) or cp["z"] < STEP_Z:
        return None
    if any(side.size < MIN_SIDE_RUNS or _side_course(x[side], y[side]) > SIDE_COURSE_SHARE * abs(cp["step_dB"]) or
           STEP_OVER_SCATTER * _side_scatter(y[side]) > abs(cp["step_dB"]) for side in (cp["below"], cp["above"])):
        return None
    return cp


def drift(recorded: np.ndarray, spin: np.ndarray, y: np.ndarray) -> dict | None:
    """A line's drift over the test: its dB ratios ``y`` (R,, NaN where not read) against the runs' positions in the
    order they were recorded (``recorded``, R,), the runs' speeds ``spin`` (R,) beside, when they follow that order
    (Kendall's τ, chance below :data:`DRIFT_CHANCE`) and not the speed (:data:`DRIFT_SPEED_CHANCE`), along a Theil-Sen
    line that moves :data:`MIN_STEP_DB` or more over the test and :data:`STEP_OVER_SCATTER` times the runs' robust
    scatter about it: a dict (``change_dB`` over the test, ``slope_dB_per_run``, ``scatter_dB``, ``chance``), or None.
    Fewer than 2·:data:`MIN_SIDE_RUNS` + 2 runs read: None."""
    from scipy.stats import kendalltau, theilslopes

    ok = np.isfinite(y)
    if ok.sum() < 2 * MIN_SIDE_RUNS + 2 or np.ptp(y[ok]) < MIN_STEP_DB:
        return None
    x, v = recorded[ok], y[ok]
    chance = float(kendalltau(x, v)[1])
    if not chance < DRIFT_CHANCE or float(kendalltau(np.abs(spin[ok]), v)[1]) < DRIFT_SPEED_CHANCE:
        return None
    slope, icpt = (float(a) for a in theilslopes(v, x)[:2])
    change = slope * float(np.ptp(x))
    scatter = 1.4826 * float(np.median(np.abs(v - (icpt + slope * x))))
    if abs(change) < max(MIN_STEP_DB, STEP_OVER_SCATTER * scatter):
        return None
    return {"change_dB": change, "slope_dB_per_run": slope, "scatter_dB": scatter, "chance": chance}


def _course(recorded: np.ndarray, y: np.ndarray) -> float | None:
    """A line's change over the test in the recorded order (dB: its Theil-Sen slope against ``recorded`` times their
    span), None with fewer than 2·:data:`MIN_SIDE_RUNS` runs read."""
    from scipy.stats import theilslopes

    ok = np.isfinite(y)
    if ok.sum() < 2 * MIN_SIDE_RUNS:
        return None
    return float(theilslopes(y[ok], recorded[ok])[0]) * float(np.ptp(recorded[ok]))


def line_drifts(ctx, series: list, recorded: np.ndarray, stepped: set, shares) -> list:
    """``line_property`` records (property ``line_drift``) of the model's lines (``series``: [(direction, h, y)] as
    :func:`line_steps` reads them) whose level drifts over the test in the order the runs were recorded (``recorded``:
    positions, not the speed order) while the other lines keep their course (their own change over the test, and their
    own direction's, less than :data:`OTHERS_SHARE` of it: every line alike is a ``run_change``); not a line of
    ``stepped`` ((direction, h) already described as a step).  New-user trial nuR (a 12-kg wheel, its bearing line h
    3.31 growing x 1 -> x 3 over 40 runs recorded in shuffled speed order): nothing was said, 11x the clean error."""
    spin = ctx.omega[ctx.runs] / (2 * np.pi)
    rpm = np.abs(ctx.omega[ctx.runs]) * RAD_S_TO_RPM
    names = [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in ctx.runs]
    out = []
    course = None                       # every line's change over the test, read once, when a drift asks for it
    for direction, h, y in series:
        if (direction, h) in stepped or (d := drift(recorded, spin, y)) is None:
            continue
        if course is None:
            course = [(dd, x, _course(recorded, v)) for dd, x, v in series]
        courses = [(dd, c) for dd, x, c in course if (dd, x) != (direction, h) and c is not None]
        others = [c for _, c in courses]
        own = [c for dd, c in courses if dd == direction]
        if any(x and abs(float(np.median(x))) >= OTHERS_SHARE * abs(d["change_dB"]) for x in (others, own)):
            continue
        used = np.flatnonzero(np.isfinite(y))
        first, last = int(used[np.argmin(recorded[used])]), int(used[np.argmax(recorded[used])])
        chans = tuple(c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels)
        share, _ = shares(chans, h, ctx.runs[used])
        factor = 10 ** (d["change_dB"] / 20)
        f = h * np.abs(spin[used])
        what = ("the imbalance moving (a part creeping, a balance mass working loose)"
                if abs(h - 1.0) < 1e-3 and direction in ("radial_force", "radial_torque") else
                "the line's source wearing in or warming (a bearing's lubricant, its preload relaxing, a defect growing)")
        out.append(Unexplained(
            signature="line_property", channels=chans, speed_rpm=(float(rpm[used].min()), float(rpm[used].max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=d["change_dB"], share=share, n_runs=int(used.size),
            parameters={"property": "line_drift", "direction": direction, "h": h, "change_dB": d["change_dB"],
                        "amplitude_ratio": float(factor), "slope_dB_per_run": d["slope_dB_per_run"],
                        "scatter_dB": d["scatter_dB"], "chance": d["chance"], "order": "recorded",
                        "from_run": names[first], "to_run": names[last],
                        "others_change_dB": float(np.median(others)) if others else None},
            causes=(f"{direction.replace('_', ' ')} h = {h:.4g} drifted by x {factor:.3g} in amplitude from "
                    f"{names[first]} to {names[last]} in the order the runs were recorded (runs.csv's rows), the other "
                    f"lines on their course: {what}; the model's C is their average",),
            would_tell=("a run at one speed repeated at the start and at the end of the test (a drift in time holds at "
                        "every speed), and the line's level against the test's time or temperature")))
    return out


def without_steps(ctx, r):
    """The line ratios ``r`` (:class:`.describe_structure.LineRatios`) without the points of a line whose levels step
    between two flat levels over the runs in speed order (:func:`two_levels`): its runs above the step are no
    resonance's lift (a resonance lifts a line where it crosses, and lets it go).  The new-user trial of session 55, a
    bearing line at h 3.55 doubling from the 20th of 40 runs: once no amplitude law took it, a moving resonance
    "f_rotor + 3·f_spin of a rotor mode of 3 nodal diameters" was fitted through its upper runs and its step, "100 %
    of what is left", was never described.  Not on a sweep's slices (``ctx``'s test sliced), where no step is
    described either (:func:`line_steps`): a line crossing a mode faster than it settles rings on below it, two
    levels that are the crossing's (family wheel 6's run-down without a speed column: its radial lines so read left
    out, a moving resonance at 149-151 Hz, on its 150 Hz translation, was described on clean data)."""
    from dataclasses import replace

    if (getattr(ctx.test, "meta", None) or {}).get("slicing") is not None:
        return r
    keep = np.ones(r.q.size, bool)
    for ln in np.unique(r.line):
        m = r.line == ln
        if two_levels(np.abs(r.spin[m]), r.q[m]) is not None:
            keep &= ~m
    return r if keep.all() else replace(r, **{k: getattr(r, k)[keep] for k in ("q", "f", "run", "spin", "line", "h",
                                                                                "w")})


def _recorded_order(ctx, spin: np.ndarray) -> np.ndarray | None:
    """(R,) the context's runs' positions in the order they were recorded (:attr:`rwadist.formats.records.Run.
    recorded`), or None when any is unknown or that order is their speed order (``spin``, Hz)."""
    test = getattr(ctx, "test", None)
    if test is None:
        return None
    rec = np.array([test.runs[int(r)].recorded for r in ctx.runs], dtype=float)
    if rec.size < 2 or np.any(rec < 0) or np.all(np.diff(rec[np.argsort(np.abs(spin), kind="stable")]) > 0):
        return None
    return rec


def line_steps(ctx, state, ratios: list, shares, described=()) -> list:
    """``line_property`` records (property ``line_step``) of the model's lines whose level steps between two runs
    (module docstring); ``ratios``: :func:`.describe_structure.line_ratios` of ``state``, read where each line is
    resolved from the others (:func:`.describe_structure.resolved_lines`: a speed sideband's measure near its carrier
    is the carrier's misfit); ``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines'
    cells; ``described``: the records made before (no step across a ``moving_resonance``'s track)."""
    from .describe_structure import resolved_lines

    if (getattr(ctx.test, "meta", None) or {}).get("slicing") is not None:
        return []           # a sweep's slices: a line's level through the modes' crossings is no steady run's
    series = _series(ctx, [resolved_lines(ctx, state, r) for r in ratios])
    spin = ctx.omega[ctx.runs] / (2 * np.pi)
    rpm = np.abs(ctx.omega[ctx.runs]) * RAD_S_TO_RPM
    names = [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in ctx.runs]
    recorded = _recorded_order(ctx, spin)
    out = []
    for direction, h, y in series:
        cp, key = two_levels(np.abs(spin), y), np.abs(spin)
        if recorded is not None:
            # the runs as they were recorded, when that is not their speed order: a change in time between two runs
            # is two flat levels there, and scatter in speed order (the session-55 trials' imbalance 1.5x from the
            # 18th of 36 runs recorded in random speed order: read "x 0.667 between 4720 and 4880 rpm")
            in_time = two_levels(recorded, y)
            if in_time is not None and (cp is None or in_time["z"] > cp["z"]):
                cp, key = in_time, recorded
        if cp is None:
            continue
        timed = key is recorded
        below, above = cp["below"], cp["above"]
        steps = [(d, s) for d, x, v in series if (d, x) != (direction, h)
                 if (s := _step_across(v, below, above)) is not None]
        others = [s for _, s in steps]
        own = [s for d, s in steps if d == direction]       # a gain of the direction's channels steps them all
        if any(x and abs(float(np.median(x))) >= OTHERS_SHARE * abs(cp["step_dB"]) for x in (others, own)):
            continue
        last, first = int(below[np.argmax(key[below])]), int(above[np.argmin(key[above])])
        # a mode's crossing or a resonance's track puts a line on two levels in speed order, not in time
        if not timed and (_at_a_crossing(ctx, state, direction, h, last, first) or
                          _on_a_track(described, direction, h * np.abs(spin[[last, first]]), spin[[last, first]])):
            continue
        chans = tuple(c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels)
        used = np.concatenate([below, above])
        share, _ = shares(chans, h, ctx.runs[used])
        factor = 10 ** (cp["step_dB"] / 20)
        what = ("the imbalance (a balance mass moved, a part shifted or a screw loosened between those runs)"
                if abs(h - 1.0) < 1e-3 and direction in ("radial_force", "radial_torque") else
                "the line's source (a bearing re-lubricated or re-preloaded, a part shifted between those runs)")
        f = h * np.abs(spin[used])
        order = "in the order they were recorded (runs.csv's rows)" if timed else "in speed order"
        would = (f"a run at a speed recorded before {names[first]} repeated after it (a change in time holds at "
                 "every speed)" if timed else
                 f"the runs in the order they were recorded (a change in time between {names[last]} and "
                 f"{names[first]}), and a run below {rpm[first]:.0f} rpm repeated at the end of the test")
        out.append(Unexplained(
            signature="line_property", channels=chans, speed_rpm=(float(rpm[used].min()), float(rpm[used].max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=float(cp["step_dB"]), share=share, n_runs=int(used.size),
            parameters={"property": "line_step", "direction": direction, "h": h, "step_dB": float(cp["step_dB"]),
                        "amplitude_ratio": float(factor), "stderr_z": float(cp["z"]),
                        "order": "recorded" if timed else "speed",
                        "step_between_runs": [names[last], names[first]],
                        "step_between_rpm": [float(rpm[last]), float(rpm[first])],
                        "others_step_dB": float(np.median(others)) if others else None},
            causes=(f"{direction.replace('_', ' ')} h = {h:.4g} changed by x {factor:.3g} in amplitude between "
                    f"{names[last]} ({rpm[last]:.0f} rpm) and {names[first]} ({rpm[first]:.0f} rpm), {order}, "
                    f"the other lines on their course: {what}; the model's C is a compromise of the two",),
            would_tell=would))
    if recorded is not None:
        out += line_drifts(ctx, series, recorded, {(u.parameters["direction"], u.parameters["h"]) for u in out},
                           shares)
    return out


def with_line_steps(records: list, steps: list) -> list:
    """``records`` and the ``steps`` (:func:`line_steps`), without a ``partial_line`` record of a line's strength
    scattering from run to run where the line steps in the order the runs were recorded: that step, read in speed
    order (one description: the session-55 trials' bearing line doubling from the 20th of 40 runs recorded in random
    speed order was also described as 'its strength scattering 4.5 dB (rms) from run to run')."""
    timed = {(u.parameters["direction"], round(u.parameters["h"], 4)) for u in steps
             if u.parameters.get("order") == "recorded"}
    # nor a step in speed order at an edge of the runs a ``partial_line`` is present in: that line's stop, said
    # there (the new-user trial nuN's rub, h 0.5 present over 4029-6743 rpm only, was also "changed by x 0.003
    # between 6743 and 7557 rpm", a second share of one content)
    present = {(u.parameters.get("direction"), round(u.parameters.get("h", -1.0), 4)): u.parameters["present_rpm"]
               for u in records if u.signature == "partial_line" and u.parameters.get("present_rpm")}

    def at_an_edge(u) -> bool:
        rpm = present.get((u.parameters["direction"], round(u.parameters["h"], 4)))
        if u.parameters["property"] != "line_step":
            return False
        lo, hi = u.parameters["step_between_rpm"]
        return (rpm is not None and u.parameters.get("order") == "speed"
                and any(lo - 1e-6 <= x <= hi + 1e-6 for x in (min(rpm), max(rpm))))

    return [u for u in records if not (u.signature == "partial_line" and "scatter_dB" in u.parameters and
                                       (u.parameters.get("direction"), round(u.parameters.get("h", -1.0), 4)) in timed)
            ] + [u for u in steps if not at_an_edge(u)]
