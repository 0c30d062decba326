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
``trend``), :data:`MIN_STEP_DB` or more, :data:`STEP_OVER_SCATTER` times the runs' scatter about their side's
median or more, and :data:`~.gain_step.STEP_Z` standard errors of the two sides' medians,
with :data:`MIN_SIDE_RUNS` runs on each side; when the other lines, read across the same split, step by less than
:data:`OTHERS_SHARE` of it (a change of every line is a gain or a re-mounting, the run-change's); and when the split
is no crossing of the line with a suspension mode of the model (:func:`.mode_reach.crossing_groups`: a mode's
frequency or damping a little off leaves the runs below its crossing and those above on two levels too) or with a
fixed resonance of the state (a test stand).
"""
from __future__ import annotations

import numpy as np

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
#: The step over the runs' robust scatter about their side's median, at least: two levels, each flat (a line rising
#: through a resonance the model lacks scatters about any two levels: the new-user trial's W1 with its modes unfitted,
#: h 5.39 through the 420 Hz translation read +8.4 dB at 3.1 dB scatter; a step of the imbalance 1.6 dB at 0.02)
STEP_OVER_SCATTER = 4.0


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


#: A fixed resonance of the state (a test stand, a wheel mode) reaches a line within this many half-power widths
#: (ζ·f_r each) of its frequency
RESONANCE_REACH = 3.0


def _at_a_crossing(ctx, state, direction: str, h: float, last: int, first: int) -> bool:
    """Whether the line (direction, h) crosses one of the model's suspension modes (a whirl branch included) or a
    fixed resonance of the state (a test stand: the new-user W2's force fixture at 105 Hz, fitted on every channel,
    left its h 4.12 line on two levels either side of 105 Hz) between the runs at positions ``last`` and ``first``,
    or either of them lies in such a resonance's reach."""
    senses = [getattr(x, "sense", None) or "co" for x in state.model.harmonics(direction) if abs(x.h - h) < 1e-3]
    group = crossing_groups(state, direction, h, senses or ["co"], ctx.omega[ctx.runs[[last, first]]])
    if group[0] != group[1] or np.any(group < 0):
        return True
    lo, hi = sorted(h * np.abs(ctx.omega[ctx.runs[[last, first]]]) / (2 * np.pi))
    return any(lo - RESONANCE_REACH * e.zeta * e.f_r <= e.f_r <= hi + RESONANCE_REACH * e.zeta * e.f_r
               for e in state.effects if getattr(e, "kind", "") == "fixed_resonance")


def line_steps(ctx, state, ratios: list, shares) -> list:
    """``line_property`` records (property ``line_step``) of the model's lines whose level steps between two runs
    (module docstring); ``ratios``: :func:`.describe_structure.line_ratios` of ``state``; ``shares(chans, hs, runs)``
    -> (share of the misplaced power, level dB) of the lines' cells."""
    series = _series(ctx, ratios)
    spin = ctx.omega[ctx.runs] / (2 * np.pi)
    rpm = np.abs(ctx.omega[ctx.runs]) * RAD_S_TO_RPM
    names = [ctx.sp.run_names[int(r)] if r < len(ctx.sp.run_names) else str(int(r)) for r in ctx.runs]
    out = []
    for direction, h, y in series:
        if np.isfinite(y).sum() < 2 * MIN_SIDE_RUNS or np.nanmax(y) - np.nanmin(y) < MIN_STEP_DB:
            continue            # no two sides' medians of it lie MIN_STEP_DB apart: the change point is not sought
        cp = change_point(np.abs(spin), y)
        if cp is None or cp["pattern"] != "step" or abs(cp["step_dB"]) < max(MIN_STEP_DB, STEP_OVER_SCATTER *
                                                                               cp["scatter_dB"]) or cp["z"] < STEP_Z:
            continue
        below, above = cp["below"], cp["above"]
        if below.size < MIN_SIDE_RUNS or above.size < MIN_SIDE_RUNS:
            continue
        others = [s for d, x, v in series if (d, x) != (direction, h)
                  if (s := _step_across(v, below, above)) is not None]
        if others and abs(float(np.median(others))) >= OTHERS_SHARE * abs(cp["step_dB"]):
            continue
        last, first = int(below[np.argmax(rpm[below])]), int(above[np.argmin(rpm[above])])
        if _at_a_crossing(ctx, state, direction, h, last, first):
            continue
        chans = tuple(c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels)
        used = np.concatenate([below, above])
        share, _ = shares(chans, h, ctx.runs[used])
        factor = 10 ** (cp["step_dB"] / 20)
        what = ("the imbalance (a balance mass moved, a part shifted or a screw loosened between those runs)"
                if abs(h - 1.0) < 1e-3 and direction in ("radial_force", "radial_torque") else
                "the line's source (a bearing re-lubricated or re-preloaded, a part shifted between those runs)")
        f = h * np.abs(spin[used])
        out.append(Unexplained(
            signature="line_property", channels=chans, speed_rpm=(float(rpm[used].min()), float(rpm[used].max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=float(cp["step_dB"]), share=share, n_runs=int(used.size),
            parameters={"property": "line_step", "direction": direction, "h": h, "step_dB": float(cp["step_dB"]),
                        "amplitude_ratio": float(factor), "stderr_z": float(cp["z"]),
                        "step_between_runs": [names[last], names[first]],
                        "step_between_rpm": [float(rpm[last]), float(rpm[first])],
                        "others_step_dB": float(np.median(others)) if others else None},
            causes=(f"{direction.replace('_', ' ')} h = {h:.4g} changed by x {factor:.3g} in amplitude between "
                    f"{names[last]} ({rpm[last]:.0f} rpm) and {names[first]} ({rpm[first]:.0f} rpm), in speed order, "
                    f"the other lines on their course: {what}; the model's C is a compromise of the two",),
            would_tell=(f"the runs in the order they were recorded (a change in time between {names[last]} and "
                        f"{names[first]}), and a run below {rpm[first]:.0f} rpm repeated at the end of the test")))
    return out
