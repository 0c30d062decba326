"""Detector of the open world (issue 33, item 3) on the final model's residual: one channel of a radial pair reading
every line stronger than its partner (a ``line_property``: a gain or calibration error of a load-cell channel).

A radial line is a load rotating with or against the spin (or both: an ellipse), and the wheel and its suspension
are axisymmetric, so x and y carry its power alike: exactly for a line of one sense, on average over the runs for an
ellipse (its orientation is the parts' phase in the run).  The model gives x and y the same power.  A channel whose
gain is off (a calibration, an amplifier's range, a bridge's excitation) reads every line of the pair by one factor
against its partner: the lines' measured-over-predicted ratios differ between the two channels by one constant in
every run and for every line, which no effect class describes (trial13: Ty reading 1.10 x, nothing said, error 5.7x
the clean level).  Read on the model's lines standing :data:`LINE_SNR_DB` over the noise in both channels: the
median over (line, run) of 10·log10(P_y/P̂_y) − 10·log10(P_x/P̂_x), described when it is :data:`MIN_DB` or more,
:data:`MIN_Z` standard errors from 0 (the median's, from the scatter's MAD), and held by :data:`MIN_LINES` lines or
more, each with its own median of the same sign within a factor 2 of it (an ellipse of fixed orientation, e.g. a
support stiffer in x, tilts one line; a gain tilts them all).

The pairs are read as recorded, not corrected for a load-cell offset (:func:`as_recorded`): a gain acts on the
channel as the load cell gives it, T + r × F, and the correction T − r × F with an r fitted to both channels (the
``cross_coupling`` fit takes one r_z from Tx = −r_z·Fy and Ty = r_z·Fx) cancels the gain's share of the force
lines' r × F in one channel and not in the other: trial13's Ty × 1.10 with r = 25 mm fitted r = 26.2 mm, read
through the correction its lines disagreed and nothing was described.  A rotating r × F is a load rotating with
its force, so the recorded x and y still carry each line's power alike.
"""
from __future__ import annotations

import numpy as np

from ..units import RAD_S_TO_RPM, RADIAL_PAIRS, unit_words
from .constants import LINE_HALF
from .describe_direction import fixed_direction
from .gain_step import gain_step
from .unexplained import Unexplained

#: A line's predicted power over the noise in its window, in both channels, at least (dB).
LINE_SNR_DB = 20.0
#: The median difference at least (dB of power: 0.4 dB is a 4.7 % amplitude gain) ...
MIN_DB = 0.4
#: ... and this many standard errors of the median.
MIN_Z = 5.0
#: Lines (h) that must each show it, with MIN_RUNS runs or more each.
MIN_LINES = 2
MIN_RUNS = 4
#: ... and at least this share of the lines read (a gain moves every line: the session-52 generator's W1 sweep, four
#: planar lines of their own directions and two rotating ones, read "Fx reads 1.58 x Fy" on two of the six)
READ_SHARE = 0.5
#: The runs' robust scatter of the pair's ratio (per run the median over its lines, dB of power) at which a constant
#: ratio is said to change from run to run: clean family wheels scatter 0.01-0.05 dB (:mod:`.gain_step`); trial 30b's
#: Fy gain 1.0-1.3 in recording order, shuffled against the speeds, 0.6-0.9 dB (read as a constant 1.14× before)
RUN_SCATTER_DB = 0.3




#: Effect kinds that read the torques corrected for a load-cell offset (left out by :func:`as_recorded`).
CORRECTION_KINDS = ("cross_coupling", "lever_arm_noise")


def as_recorded(state):
    """``state`` reading the torques as recorded: a copy without the effects of :data:`CORRECTION_KINDS` (the same
    lines, noise and other effects; the model's torque lines are the wheel's, r × F is not predicted: the two
    channels of a pair miss it alike)."""
    if not any(getattr(e, "kind", None) in CORRECTION_KINDS for e in state.effects):
        return state
    out = state.copy()
    out.effects = [e for e in state.effects if getattr(e, "kind", None) not in CORRECTION_KINDS]
    return out


def _powers(ctx, state, c: str, runs: np.ndarray):
    """(h (L,), measured power (L, R), predicted power (L, R), noise power in the line's window (L, R)) of the model's
    lines on channel ``c``; None without lines."""
    cl = ctx.channel_lines(state, c, runs)
    if not cl:
        return None
    h = np.array([x[0] for x in cl])
    f = h[:, None] * ctx.omega[runs][None, :] / (2 * np.pi)
    a = np.array([x[2] for x in cl]) * ctx.gain(state, c, f)
    m = ctx.measure_lines(state, c, runs)
    k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)
    noise = ctx.floor_psd(state, c, runs)[np.arange(runs.size)[None, :], k] * ctx.df * (2 * LINE_HALF + 1)
    ok = np.isfinite(ctx.sp.psd[c][runs, 0])[None, :]
    return h, np.where(ok, np.nan_to_num(m) ** 2 / 2, np.nan), np.where(ok, a**2 / 2, np.nan), noise


def _lines_words(agreeing: np.ndarray, read: np.ndarray) -> str:
    """The lines that carry the ratio, in words, when some lines read do not (``agreeing`` among ``read``: h)."""
    return (f"the lines h {', '.join(f'{x:.3g}' for x in agreeing)} ({agreeing.size} of the {read.size} read; the "
            "others differ: a gain acts on all)")


def channel_gain(ctx, state, shares, resonances=()) -> list:
    """``line_property`` records of a radial pair whose two channels read the model's lines by different factors
    (``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines' cells).  ``resonances``:
    the ``channel_resonance`` records of the pairs (:func:`.describe_split.channel_resonance`), whose course is divided
    out of their channel's lines before a gain is read from them: a gain is one factor at every frequency, and a
    channel's resonance lifting the lines near it changes the pair's ratio where the speed brings them there (the
    new-user trial's Tx resonance at 380 Hz, ζ 0.03, peak gain 5, was also a "Tx's gain changed by x 1.11" step from
    4316 rpm, where the h 5.37 line passes 380 Hz)."""
    from ..resonance import resonance

    runs = ctx.runs
    out: list[Unexplained] = []
    for cx, cy in RADIAL_PAIRS:
        if cx not in ctx.channels or cy not in ctx.channels:
            continue
        px, py = _powers(ctx, state, cx, runs), _powers(ctx, state, cy, runs)
        if px is None or py is None or px[0].size != py[0].size or np.any(np.abs(px[0] - py[0]) > 1e-9):
            continue
        h = px[0]
        snr = np.minimum(px[2] / np.maximum(px[3], 1e-300), py[2] / np.maximum(py[3], 1e-300))
        good = (snr >= 10 ** (LINE_SNR_DB / 10)) & (px[1] > 0) & (py[1] > 0) & np.isfinite(px[1] + py[1])
        with np.errstate(divide="ignore", invalid="ignore"):
            qx, qy = 10 * np.log10(px[1] / px[2]), 10 * np.log10(py[1] / py[2])
        f_cells = h[:, None] * ctx.omega[runs][None, :] / (2 * np.pi)
        for u in resonances:
            p = u.parameters
            if p["channel"] in (cx, cy):
                course = 20 * np.log10(np.abs(resonance(f_cells, p["f_r_Hz"], p["zeta"], p["peak_gain"])))
                qx, qy = (qx - course, qy) if p["channel"] == cx else (qx, qy - course)
        with np.errstate(invalid="ignore"):
            d = qy - qx
        # a gain is read on the cells of a load of one sense (x and y a quarter turn apart); the others' x/y ratio is
        # their ellipse's, kept for the loads of a fixed direction
        sensed = good & in_quadrature(ctx, (cx, cy), h, runs)
        lines = [i for i in range(h.size) if sensed[i].sum() >= MIN_RUNS]
        if len(lines) < MIN_LINES:
            lines = [i for i in range(h.size) if good[i].sum() >= MIN_RUNS]
            directed = fixed_direction(ctx, (cx, cy), h, np.where(good, d, 0.0), good, lines, shares) \
                if len(lines) >= MIN_LINES else None
            if directed is not None:
                out.append(directed)
            continue
        good_all, good = good, sensed
        # a ratio that changes between runs (a gain switched) is described where it changes, not as one constant
        stepped = gain_step(ctx, state, (cx, cy), h, (np.where(good, qx, 0.0), np.where(good, qy, 0.0)), good, shares,
                            MIN_DB, MIN_LINES)
        if stepped is not None:
            out.append(stepped)
            continue
        cells = np.concatenate([d[i][good[i]] for i in lines])
        med = float(np.median(cells))
        se = 1.2533 * 1.4826 * float(np.median(np.abs(cells - med))) / np.sqrt(cells.size)
        per_line = np.array([np.median(d[i][good[i]]) for i in lines])
        agree = (np.sign(per_line) == np.sign(med)) & (np.abs(per_line) >= 0.5 * abs(med)) & \
            (np.abs(per_line) <= 2.0 * abs(med))
        if abs(med) < MIN_DB or abs(med) < MIN_Z * se or agree.sum() < max(MIN_LINES, READ_SHARE * len(lines)):
            # no gain: a gain moves every line read alike; lines that keep their own x/y ratios are loads of a fixed
            # direction (:mod:`.describe_direction`)
            every = [i for i in range(h.size) if good_all[i].sum() >= MIN_RUNS]
            directed = fixed_direction(ctx, (cx, cy), h, np.where(good_all, d, 0.0), good_all, every, shares)
            if directed is not None:
                out.append(directed)
            continue
        used = np.flatnonzero(good[lines].any(axis=0))
        share, _ = shares((cx, cy), h[lines], runs[used])
        rpm = ctx.omega[runs[used]] * RAD_S_TO_RPM
        f = np.concatenate([h[i] * ctx.omega[runs[good[i]]] / (2 * np.pi) for i in lines])
        ratio = 10 ** (med / 20)
        hi_c, lo_c = (cy, cx) if med > 0 else (cx, cy)
        carry = np.zeros_like(good)                 # the lines that carry the ratio (a gain acts on all alike)
        carry[np.asarray(lines)[agree]] = good[np.asarray(lines)[agree]]
        scatter, spread = _run_scatter(np.where(good, d, 0.0), carry)
        order = _in_recorded_order(ctx, np.where(good, d, 0.0), carry) if _varies(scatter) else None
        out.append(Unexplained(
            signature="line_property", channels=(cx, cy), speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=med, share=share, n_runs=int(used.size),
            parameters={"property": "channel_gain", "channel": cy, "reference": cx,
                        "amplitude_ratio": float(ratio), "power_ratio_dB": med, "stderr_dB": se,
                        "lines_h": [float(x) for x in h[lines][agree]], "cells": int(cells.size),
                        "run_scatter_dB": scatter, "run_range_dB": spread, **(order or {}).get("parameters", {})},
            causes=_varying(hi_c, lo_c, scatter, spread, order) + (
                    f"a gain or calibration error of {hi_c} or {lo_c}: {hi_c} reads {max(ratio, 1 / ratio):.3g} x "
                    f"{lo_c} on {'every line read' if agree.all() else _lines_words(h[lines][agree], h[lines])} (a "
                    f"rotating load gives x and y the same power){unit_words(max(ratio, 1 / ratio), cx)}",
                    "a support or fixture stiffer in one direction: the suspension mode splits into an x and a y mode, "
                    "and the ratio changes across them but stays nearly constant on the lines well above both "
                    "(about (f_x/f_y)² in amplitude), as a gain's does"),
            would_tell=("the runs in the order they were recorded (a drift grows with time); "
                        if _varies(scatter) and order is None else "")
            + f"a calibration of {cx} and {cy} with one known load (a mass hung, a shaker's force), or the "
              "load cell turned 90 degrees on the stand (a channel's gain goes with the channel)"))
    return out


#: A cell is a load of one sense where the pair's x/y phase lies within this of a quarter turn (degrees): a gain
#: scales one channel and keeps the quarter turn; a co- and a counter-rotating part together (an ellipse tilted off
#: the axes, a load of a fixed direction) or a channel read late move it (noise at 20 dB: a few degrees)
QUADRATURE_DEG = 15.0


def in_quadrature(ctx, pair: tuple, h: np.ndarray, runs: np.ndarray) -> np.ndarray:
    """Bool (L, R): whether each line h of the pair's channels, in each run, reads x and y a quarter turn apart
    (within :data:`QUADRATURE_DEG`) on the records (True where it cannot be read: no records).  A line of both senses
    reads its ellipse's x/y ratio, which moves as the parts pass the whirl branches of the rocking mode apart (family
    wheel 4, its h 2 (co 0.8) and 4.62 (co 0.5) lines about the 55 Hz rocking mode, clean: "Fx's gain changed by
    x 3.23 between 770 and 887 rpm" was described); a gain error of one channel keeps every line's quarter turn."""
    out = np.ones((h.size, runs.size), bool)
    if ctx.test is None or not h.size:
        return out
    f = h[None, :] * np.abs(ctx.omega[runs])[:, None] / (2 * np.pi)
    z = ctx.transforms(runs, f, pair)                                   # (R, L, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.abs(np.abs(np.angle(z[..., 1] / z[..., 0])) - np.pi / 2)
    return (~np.isfinite(off) | (off <= np.radians(QUADRATURE_DEG))).T


def _run_scatter(d: np.ndarray, good: np.ndarray) -> tuple:
    """(robust scatter dB, [lowest, highest] dB) over the runs of the pair's ratio per run (:func:`.gain_step.per_run`
    of ``d`` (lines, runs) where ``good``: the lines that carry the ratio, within a factor 2 of it; a line of its own
    x/y asymmetry, a co- and counter-rotating part, reads off in every run, and a run holding few lines took its
    median from it: family wheel 1, +2.95 dB for a run's +2.28)."""
    from .gain_step import per_run

    # two passes: the lines that scatter about the runs' first medians far more than the others (a line through a
    # split mode, or of a sense mix that changes with speed: ±10 dB from run to run on family wheel 4) are left out
    first = per_run(d, good)
    off = np.where(good & np.isfinite(first)[None, :], np.abs(d - np.nan_to_num(first)[None, :]), np.nan)
    read = np.isfinite(off).any(axis=1)
    line_mad = np.full(d.shape[0], np.nan)
    line_mad[read] = np.nanmedian(off[read], axis=1)
    keep = np.isfinite(line_mad) & (line_mad <= max(3.0 * float(np.nanmedian(line_mad)), 0.1)) \
        if np.isfinite(line_mad).any() else np.zeros(d.shape[0], bool)
    y = per_run(d, good & keep[:, None])
    y = y[np.isfinite(y)]
    if y.size == 0:
        return 0.0, [float("nan"), float("nan")]
    return 1.4826 * float(np.median(np.abs(y - np.median(y)))), [float(y.min()), float(y.max())]


def _varies(scatter: float) -> bool:
    return scatter >= RUN_SCATTER_DB


def _in_recorded_order(ctx, d: np.ndarray, carry: np.ndarray) -> dict | None:
    """The change of the pair's ratio per run (:func:`.gain_step.per_run` of ``d`` where ``carry``, dB of power) in
    the order the runs were recorded (:func:`.run_order.recorded_change`: a drift or a step), as {"parameters", "words"},
    or None when that order is unknown or shows neither."""
    from .gain_step import per_run
    from .run_order import ordinal, recorded_change

    change = recorded_change(ctx, per_run(d, carry))
    if change is None:
        return None
    if change["kind"] == "drift":
        return {"parameters": {"recorded_drift_dB": change["drift_dB"], "rank_correlation": change["rank_correlation"]},
                "words": f"in the order the runs were recorded it drifts {change['drift_dB']:+.2f} dB of power from the "
                         f"first to the last (rank correlation {change['rank_correlation']:.2f})"}
    n = change["recorded_before"]
    return {"parameters": {"recorded_step_dB": change["step_dB"], "recorded_before_the_step": n},
            "words": f"in the order the runs were recorded it steps {change['step_dB']:+.2f} dB of power from the "
                     f"{ordinal(n + 1)} run recorded on"}


def _varying(hi_c: str, lo_c: str, scatter: float, spread: list, order: dict | None = None) -> tuple:
    """() or the first cause of a ratio that scatters from run to run by :data:`RUN_SCATTER_DB` or more (with no
    step or trend in speed: :mod:`.gain_step` read none), with what the order of recording shows (``order``:
    :func:`_in_recorded_order`) when it is known."""
    if not _varies(scatter):
        return ()
    known = f"; {order['words']}" if order else ", so the runs' order of recording decides"
    return (f"a gain of {hi_c} or {lo_c} that changes from run to run: the ratio scatters {scatter:.2g} dB between "
            f"runs ({spread[0]:+.2f} to {spread[1]:+.2f} dB of power; a fixed gain's ratio scatters 0.01-0.05 dB), "
            "with no step or trend in speed: a drift with time (an amplifier or bridge warming, a connector working "
            f"loose){known}",)
