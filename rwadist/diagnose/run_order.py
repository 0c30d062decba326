"""The runs read in the order they were recorded: a drift or a step of every line's level over the test
(:func:`.describe_structure.run_change` describes it as a ``run_change``).

A steady test's ``runs.csv`` rows are the order its runs were recorded (docs/formats.md, section 1; the HDF5 file keeps
no order).  A load cell's gain drifting with its temperature, or a wheel re-mounted part way, moves every line of a
run by one factor, in that order; recorded in shuffled speed order, each run's factor against the model's lines
(:func:`.run_gains.run_gains`, no trend with speed taken off: a line's neighbours in speed were recorded anywhere) read
in that order tells them; a step is then placed and sized again with the runs' common trend with speed fitted beside
it (:func:`speed_trend`).  New-user trial nuL (session 58, an independent generator, 30 runs): a gain rising 15 % was
described on one seed of three from the runs' scatter about the lines' trends with speed (0.25-0.6 dB) and said
``recorded_order: unknown``; a 0.83 dB step at the 16th run recorded read as three levels against those trends (found
at the 23rd, or called a drift).  In that order: the drift +1.17 to +1.21 dB (truth +1.21), the steps at the 16th,
0.79 and 0.82 dB.
"""
from __future__ import annotations

import numpy as np

from .describe_line_step import _recorded_order
from .describe_structure import RUN_MIN_RUNS, RUN_SCATTER_DB
from .gain_step import STEP_Z, change_point
from .run_gains import run_gains

#: A drift: the runs' factors rank-correlated with the order of recording with a chance below this (two-sided), and
#: moving RUN_SCATTER_DB or more over the test along a Theil-Sen line; a step: two flat levels in that order
#: (:func:`.gain_step.change_point`, RUN_SCATTER_DB or more apart, STEP_Z standard errors, leaving less than the line)
DRIFT_CHANCE = 1e-4
#: ... neither where the factors follow the speed with a chance below this (a model's misfit with speed, the runs
#: recorded nearly in speed order)
SPEED_CHANCE = 1e-3


def order_note(ctx) -> str:
    """"known" when the runs carry places in an order of recording that is not their speed order (a steady test's
    ``runs.csv`` rows, :func:`.describe_line_step._recorded_order`) or distinct start times; "speed order" when their
    rows are in speed order (recorded so, or written by speed: the order cannot be told from it); else "unknown"."""
    test = ctx.test
    if test is None:
        return "unknown"
    if _recorded_order(ctx, ctx.omega[ctx.runs] / (2 * np.pi)) is not None:
        return "known"
    t0 = np.array([getattr(test.runs[r], "t0", 0.0) for r in ctx.runs], dtype=float)
    if np.unique(t0).size == t0.size:
        return "known"
    return "speed order" if all(test.runs[int(r)].recorded >= 0 for r in ctx.runs) else "unknown"


#: The runs' common trend with speed is taken off a step's size only while the step and the trend stay apart: the
#: variance inflation of the step's coefficient by the trend's (1 / (1 − R²) of the runs after it on the trend's
#: terms) under this
TREND_INFLATION = 4.0


def speed_trend(x: np.ndarray, gains: np.ndarray, later: np.ndarray) -> np.ndarray | None:
    """The runs' common trend with speed (R,, dB; 0 mean over the runs read) fitted together with a step of the runs
    ``later``: gains ≈ step·later + a + b·u + c·u², u the runs' log speed ``x`` standardised, least squares over the
    runs read; None when the step's coefficient is inflated :data:`TREND_INFLATION` times or more by the trend's
    terms (the runs after the step recorded at other speeds than those before: step and trend cannot be told).
    The model's lines are fitted over every run, those after the step among them: where the runs after it lie
    more at some speeds than at others, the model leans there and leaves a trend with speed common to both sides
    (the new-user trial nuM, a +0.668 dB step after the 20th run of 40 in shuffled speed order: the runs' factors
    fell 0.3 dB from the low to the high speeds on both sides, and the sides' medians read 0.55 dB)."""
    ok = np.isfinite(gains)
    u = (x - x[ok].mean()) / max(float(x[ok].std()), 1e-12)
    terms = np.column_stack([np.ones(u.size), u, u * u])[ok]
    g = later[ok].astype(float)
    if g.min() == g.max():
        return None
    fitted = terms @ np.linalg.lstsq(terms, g, rcond=None)[0]
    r2 = 1.0 - float(np.sum((g - fitted) ** 2)) / float(np.sum((g - g.mean()) ** 2))
    if r2 >= 1.0 - 1.0 / TREND_INFLATION:
        return None
    coef = np.linalg.lstsq(np.column_stack([g, terms]), gains[ok], rcond=None)[0]
    trend = np.full(u.size, np.nan)
    trend[ok] = coef[2] * u[ok] + coef[3] * u[ok] ** 2
    trend[ok] -= trend[ok].mean()
    return trend


def recorded_change(ctx, gains: np.ndarray) -> dict | None:
    """The change of the runs' factors ``gains`` (R,, dB) in the order the runs were recorded: a ``step`` {"kind",
    "step_dB", "later": bool (R,) the runs recorded after it, "recorded_before": how many were, "z"} or a ``drift``
    {"kind", "drift_dB" over the test, "drift_per_run_dB", "rank_correlation", "chance"}; None when that order is
    unknown or the speed order, when the factors follow the speed (:data:`SPEED_CHANCE`), or neither is seen."""
    from scipy.stats import spearmanr, theilslopes

    recorded = _recorded_order(ctx, ctx.omega[ctx.runs] / (2 * np.pi))
    ok = np.isfinite(gains)
    if recorded is None or ok.sum() < 2 * RUN_MIN_RUNS + 1 or \
            spearmanr(ctx.omega[ctx.runs][ok], gains[ok])[1] < SPEED_CHANCE:
        return None
    place = np.argsort(np.argsort(recorded)).astype(float)      # 0 .. R-1 in the order of recording
    cp = change_point(place, gains)
    if cp is not None and cp["pattern"] == "step" and abs(cp["step_dB"]) >= RUN_SCATTER_DB and cp["z"] >= STEP_Z:
        later = np.zeros(gains.size, bool)
        later[cp["above"]] = True
        # the runs' common trend with speed taken off (:func:`speed_trend`), the step placed and sized again
        trend = speed_trend(np.log(np.abs(ctx.omega[ctx.runs])), gains, later)
        if trend is not None:
            again = change_point(place, gains - trend)
            if again is not None and again["pattern"] == "step" and again["z"] >= STEP_Z and \
                    abs(again["step_dB"]) >= RUN_SCATTER_DB:
                cp = again
                later = np.zeros(gains.size, bool)
                later[cp["above"]] = True
            else:
                trend = None
        return {"kind": "step", "step_dB": float(cp["step_dB"]), "later": later, "z": float(cp["z"]),
                "recorded_before": int(np.sum(place < place[cp["above"]].min())),
                "trend": np.zeros(gains.size) if trend is None else np.nan_to_num(trend)}
    rho, chance = spearmanr(place[ok], gains[ok])
    slope = float(theilslopes(gains[ok], place[ok])[0])
    drift = slope * float(np.ptp(place[ok]))
    if not (np.isfinite(chance) and chance <= DRIFT_CHANCE and abs(drift) >= RUN_SCATTER_DB):
        return None
    return {"kind": "drift", "drift_dB": drift, "drift_per_run_dB": slope, "rank_correlation": float(rho),
            "chance": float(chance)}


def _changed(gains: np.ndarray, change: dict) -> tuple:
    """:func:`.describe_structure._changed_runs`'s tuple (positions set apart, offsets dB, mask, scatter dB, runs not
    read) of a change in the order of recording: a step's runs recorded after it set apart (offsets from the median
    of those before), a drift's every run read (a spread)."""
    ok = np.isfinite(gains)
    if change["kind"] == "step":
        gains = gains - change["trend"]
        dev = gains[ok] - np.median(gains[ok & ~change["later"]])
        off = change["later"][ok]
        rest = np.concatenate([dev[~off], dev[off] - change["step_dB"]])
        return np.flatnonzero(ok & change["later"]), dev, off, 1.4826 * float(np.median(np.abs(rest))), \
            np.flatnonzero(~ok)
    dev = gains[ok] - np.median(gains[ok])
    return np.flatnonzero(ok), dev, np.ones(dev.size, bool), 1.4826 * float(np.median(np.abs(dev))), \
        np.flatnonzero(~ok)


def ordinal(n: int) -> str:
    """'1st', '2nd', '3rd', '4th', ..., '11th', '21st'."""
    return f"{n}{'th' if 10 <= n % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def read_in_recorded_order(ctx, ratios: list) -> dict:
    """What :func:`.describe_structure.run_change` takes of the order of recording (``ratios``: its
    :class:`.describe_structure.LineRatios`): {"recorded_order": :func:`order_note`, "kind": "step", "drift" or None,
    "runs": the changed runs' tuple, "parameters": the record's, "words": said after the cause it supports}."""
    out: dict = {"recorded_order": order_note(ctx), "kind": None}
    if out["recorded_order"] != "known" or not ratios:
        return out
    gains = run_gains(ctx, ratios)
    change = recorded_change(ctx, gains)
    if change is None:
        return out
    out.update(kind=change["kind"], runs=_changed(gains, change))
    if change["kind"] == "drift":
        out["parameters"] = {k: float(v) for k, v in change.items() if k != "kind"}
        out["words"] = (f": the runs' factors move {change['drift_dB']:+.2f} dB from the first run recorded to the "
                        f"last (rank correlation {change['rank_correlation']:.2f} with the recording order)")
    else:
        n = change["recorded_before"]
        out["parameters"] = {"step_dB": change["step_dB"], "recorded_before_the_step": n, "step_z": change["z"],
                             "speed_trend_taken_off": bool(np.any(change["trend"] != 0))}
        out["words"] = (f": the runs recorded from the {ordinal(n + 1)} on stand {change['step_dB']:+.2f} dB off the "
                        f"{n} recorded before")
    return out
