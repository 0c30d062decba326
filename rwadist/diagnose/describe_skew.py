"""Detector of the open world (issue 33, item 3) on the records: a timing skew between the two channels of a radial
pair (a ``line_property`` of property ``channel_skew``: one channel sampled or filtered later than the other).

A line of one rotation sense reaches x and y a quarter turn apart: at +f (the DFT kernel e^{−2πjft}) a co-rotating
line reads Y = −jX, a counter-rotating one Y = +jX, whatever its amplitude, the modes it passes (the suspension is
axisymmetric: x and y see one transmissibility) or its phase in the run.  Sampled τ later, y reads Y·e^{−2πjfτ}: every
line's x/y phase leaves its quarter turn by d = −2πfτ, in proportion to its frequency, the same for both senses, and
each line reads a part sin²(πfτ) of its power in the other sense.  The search's counter_rotation class (and the
line senses of the base) then take that part as the wheel's (trial26, Fy 0.8 ms late: counter_rotation q 0.054 on the
imbalance, opposite-sense parts on every radial-force line, the error figure 0.05-0.4x clean, as a PSD cannot see an
x/y phase, and nothing said).

Read on the records (``ctx.test``) at the final model's lines of each radial direction, in every run where the line's
x/y power stands :data:`MIN_SNR` over the power beside it and its two channels' amplitudes agree within
:data:`MAX_AXIS_DB` (a line of one sense: a co + counter mix with phases of its own, an ellipse, reads neither |Y| = |X|
nor a phase that follows f); d fitted as −2πτf (a grid of τ, then least squares, cells beyond 3 robust scatters of
the first fit left out once; d is known modulo a half turn, :func:`fit_skew`); described when τ stands :data:`MIN_T` standard errors from 0, the course explains
:data:`MIN_EXPLAINED` of the cells' d², reaches :data:`MIN_PHASE_DEG` at the highest line read, on
:data:`MIN_LINES` lines or more.  Sweeps (a spin acceleration in the state) are not read: a line's phase moves over
the record.
"""
from __future__ import annotations

import numpy as np

from ..dft import blocked_records, run_window, windowed_dfts
from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .unexplained import Unexplained

#: A cell is read where the line's x/y power is this many times the power beside it (20 dB) ...
MIN_SNR = 100.0
#: ... and its two channels' amplitudes agree within this (dB)
MAX_AXIS_DB = 1.0
#: The DFT bins beside a line where the noise is read (outside the Hann window's main lobe of ±2)
NOISE_BINS = (-4, -3, 3, 4)
#: Described when τ is this many standard errors from 0 ...
MIN_T = 5.0
#: ... the course −2πτf explains this fraction of the cells' d² ...
MIN_EXPLAINED = 0.8
#: ... reaches this x/y phase (degrees) at the highest line read ...
MIN_PHASE_DEG = 5.0
#: ... on this many lines (and cells) or more
MIN_LINES = 2
MIN_CELLS = 6
#: A line is not read where the state's fixed resonances lift one channel of the pair over the other by this (dB), or
#: turn it by half MIN_PHASE_DEG
STAND_REACH_DB = 0.5
#: Samples (runs × record length) of the records transformed together
CHUNK_SAMPLES = 1 << 20
#: The skews searched, ± this (s): 10 ms, a hundred samples at 10 kHz
TAU_MAX_S = 0.01


def _cells(ctx, state, direction: str) -> tuple | None:
    """(f Hz, d rad, line index, run position, h) of the direction's model lines read in one sense: per cell the x/y
    phase's departure from its quarter turn, or None without records of both channels.  Consecutive runs of one
    record length are transformed together (:func:`rwadist.dft.windowed_dfts`)."""
    test = ctx.test
    cx, cy = DIRECTION_CHANNELS[direction]
    h = np.unique([x.h for x in state.model.harmonics(direction) if x.h > 0])
    if test is None or h.size < MIN_LINES or not {cx, cy} <= set(ctx.channels):
        return None
    batches: list[list] = []
    for pos, r in enumerate(ctx.runs):
        run = test.runs[int(r)]
        if run.speed == 0 or not (run.usable(cx) and run.usable(cy)):
            continue
        if (batches and (batches[-1][0][1].n_samples, batches[-1][0][1].sample_rate) == (run.n_samples, run.sample_rate)
                and len(batches[-1]) * run.n_samples < CHUNK_SAMPLES):
            batches[-1].append((pos, run))
        else:
            batches.append([(pos, run)])
    f_all, d_all, li_all, ri_all = [], [], [], []
    for batch in batches:
        n, fs = batch[0][1].n_samples, batch[0][1].sample_rate
        f = h[None, :] * np.abs([run.speed for _, run in batch])[:, None] / (2 * np.pi)         # (runs, lines)
        x = blocked_records([[run.signals[cx], run.signals[cy]] for _, run in batch], run_window("hann", n)[0])
        XY = windowed_dfts(x, fs, np.concatenate([f] + [f + b * fs / n for b in NOISE_BINS], axis=1))
        X, Y = XY[:, :h.size, 0], XY[:, :h.size, 1]
        beside = (np.abs(XY[:, h.size:]) ** 2).sum(axis=2).reshape(len(batch), len(NOISE_BINS), h.size).mean(axis=1)
        power = np.abs(X) ** 2 + np.abs(Y) ** 2
        # a fixed resonance of the state on one channel of the pair (a fixture swaying along one axis) lifts that
        # channel and turns its phase: the lines in its reach are not read, and its course is taken off the others.
        # Fitted to the lines' powers, the resonance's general form has the truth's |H| and not always its phase (the
        # new-user trial nuN's 480 Hz Fx/Ty fixture of a spring mount, (1 + 2jζr)/(1 − r² + 2jζr): 4-45 degrees off
        # below and above it, read as "Fx sampled 0.113 ms after Fy"): out of its reach what it turns, right or
        # wrong, stays under half of what a skew must reach to be described
        gx, gy = state.channel_gain(cx, f), state.channel_gain(cy, f)
        g = gx / gy
        if not np.array_equal(gx, gy):
            X, Y = X / gx, Y / gy
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = (np.abs(20 * np.log10(np.abs(g))) > STAND_REACH_DB) | \
                (np.abs(np.angle(g)) > np.radians(0.5 * MIN_PHASE_DEG))
            axis_db = 20 * np.log10(np.abs(Y) / np.abs(X))
            good = ((power >= MIN_SNR * beside) & (np.abs(axis_db) <= MAX_AXIS_DB) & (f > 4 * fs / n)
                    & (f < 0.45 * fs) & ~reach)
        co = np.abs(X + 1j * Y) >= np.abs(X - 1j * Y)
        d = _wrap(np.angle(Y / np.where(X != 0, X, 1.0) * np.where(co, 1j, -1j)))
        rows, cols = np.nonzero(good)
        f_all.append(f[rows, cols])
        d_all.append(d[rows, cols])
        li_all.append(cols)
        ri_all.append(np.array([batch[i][0] for i in rows], dtype=int))
    if not f_all:
        return None
    return (np.concatenate(f_all), np.concatenate(d_all), np.concatenate(li_all).astype(int),
            np.concatenate(ri_all).astype(int), h)


def _wrap(x: np.ndarray) -> np.ndarray:
    """``x`` (rad) modulo π, in [−π/2, π/2): a line's sense is read from its phase, so d is known modulo a half turn
    (beyond a quarter turn the other sense looks the larger)."""
    return (x + np.pi / 2) % np.pi - np.pi / 2


def fit_skew(f: np.ndarray, d: np.ndarray, tau_max: float = TAU_MAX_S) -> dict:
    """τ (s) of d = −2πτf (modulo π) fitted to the cells (f Hz, d rad): the τ of a grid over ±``tau_max`` whose
    course the cells follow best (the length of Σ e^{2j(d + 2πfτ)}: the doubled angle reads a half turn as none), then
    least squares on the residuals, the cells beyond 3 robust scatters left out once.  Returns ``tau_s``, ``stderr_s``,
    ``explained`` (1 − Σ residual² / Σ d² on the kept cells, both modulo π) and ``kept`` (bool mask)."""
    def best(grid):
        return float(grid[int(np.argmax(np.abs(np.exp(2j * (d[None, :] + 2 * np.pi * f[None, :] * grid[:, None]))
                                               .sum(axis=1))))])

    # a coarse grid (the doubled phase moves ≤ 0.2 rad a step at the highest cell), then a fine one about its best
    step = 0.1 / (4 * np.pi * float(f.max()))
    tau = best(np.arange(-tau_max, tau_max + step, step))
    tau = best(tau + np.linspace(-step, step, 21))
    kept = np.ones(f.size, bool)
    for _ in range(3):
        x = -2 * np.pi * f[kept]
        tau += float(np.dot(x, _wrap(d[kept] - x * tau)) / np.dot(x, x))
        resid = _wrap(d + 2 * np.pi * f * tau)
        scatter = 1.4826 * float(np.median(np.abs(resid[kept])))
        new = np.abs(resid) <= max(3 * scatter, 1e-9)
        if new.sum() < MIN_CELLS or np.array_equal(new, kept):
            break
        kept = new
    x = -2 * np.pi * f[kept]
    resid = _wrap(d[kept] - x * tau)
    dof = max(int(kept.sum()) - 1, 1)
    stderr = float(np.sqrt(np.dot(resid, resid) / dof / np.dot(x, x)))
    total = float(np.dot(_wrap(d[kept]), _wrap(d[kept])))
    explained = 1.0 - float(np.dot(resid, resid)) / total if total > 0 else 0.0
    return {"tau_s": tau, "stderr_s": stderr, "explained": explained, "kept": kept}


def channel_skew(ctx, state, shares) -> list:
    """The ``channel_skew`` records of the radial directions (:mod:`module docstring <.describe_skew>`);
    ``shares(chans, h, runs)`` -> (share, level dB) of the lines' cells."""
    if getattr(state, "smear", None) is not None:
        return []
    out = []
    for direction in ("radial_force", "radial_torque"):
        got = _cells(ctx, state, direction)
        if got is None:
            continue
        f, d, li, ri, h = got
        if f.size < MIN_CELLS or np.unique(li).size < MIN_LINES:
            continue
        fit = fit_skew(f, d)
        kept = fit["kept"]
        tau, se = fit["tau_s"], fit["stderr_s"]
        top = float(f[kept].max())
        phase_deg = float(np.degrees(2 * np.pi * top * abs(tau)))
        if (abs(tau) < MIN_T * se or fit["explained"] < MIN_EXPLAINED or phase_deg < MIN_PHASE_DEG
                or np.unique(li[kept]).size < MIN_LINES or kept.sum() < MIN_CELLS):
            continue
        cx, cy = DIRECTION_CHANNELS[direction]
        late, early = (cy, cx) if tau > 0 else (cx, cy)
        runs = ctx.runs[np.unique(ri[kept])]
        lines_h = h[np.unique(li[kept])]
        share, _ = shares((cx, cy), lines_h, runs)
        other = float(np.sin(np.pi * top * tau) ** 2)
        rpm = ctx.omega[runs] * RAD_S_TO_RPM
        out.append(Unexplained(
            signature="line_property", channels=(cx, cy), speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f[kept].min()), top), level_dB=float(10 * np.log10(max(other, 1e-30))), share=share,
            n_runs=int(runs.size),
            parameters={"property": "channel_skew", "late": late, "early": early, "tau_s": abs(tau),
                        "stderr_s": se, "explained": fit["explained"], "phase_at_highest_deg": phase_deg,
                        "other_sense_share_at_highest": other, "cells": int(kept.sum()),
                        "lines_h": [float(x) for x in lines_h]},
            causes=(f"a timing skew: {late} sampled or filtered {1e3 * abs(tau):.3g} ms after {early} (a multiplexed "
                    "ADC, an anti-alias filter or cable delay in one channel); every line of one sense then reads a "
                    f"part sin²(π·f·τ) of its power in the other sense ({_percent(other)} at {top:.4g} Hz), which a "
                    "counter_rotation or the lines' senses in the model take as the wheel's",),
            would_tell=f"one signal recorded on {cx} and {cy} at once (the skew reads as their phase), or the DAQ's "
                       f"channel-to-channel delay; diagnose again with {late} moved {1e3 * abs(tau):.3g} ms earlier"))
    return out


def _percent(x: float) -> str:
    """A share as a percentage with three significant figures."""
    return f"{100 * x:.3g} %"
