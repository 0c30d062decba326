"""Detector of the open world (issue 33, item 3) on the final model's residual: radial lines of a fixed direction in
the x-y plane (a ``line_property`` of property ``fixed_direction``: planar loads, not rotating ones).

A radial line is a co-rotating part a₊e^{+iωt} and a counter-rotating part a₋e^{−iωt} of the complex load
F_x + iF_y.  Their powers are what the model holds (the line's senses); the phase between them sets the orientation
of the ellipse they trace, ψ = (arg a₊ + arg a₋)/2, and with it how the power divides between x and y:
P_x/P_y = (|a₊|² + |a₋|² + 2|a₊||a₋|cos 2ψ)/(|a₊|² + |a₋|² − 2|a₊||a₋|cos 2ψ).  A line of one sense reads x and y
alike.  When the phase is the run's (parts of independent causes) the ratio scatters from run to run about 1; when
it is the wheel's -- a load acting along one direction of the housing: an outer-race defect or a bearing seat's
out-of-roundness at a fixed place, the ball-pass impacts landing there; a stator's fixed axis -- each such line
keeps its own x/y ratio in every run, line by line, while the rotating lines read x and y alike (the session-52
generator's W1 sweep: planar h 2, 3.61, 5.39, 10.78 on the radial forces at −6.4, −9.9, −3.9, −26 dB of Fy against
Fx, within 0.1 dB over the runs; the imbalance and the cage at 0.0: read as "Fx reads 1.58 x Fy", a gain of two of
the six lines).  A gain moves every line alike (:mod:`.describe_gain`); this is what is left when it does not.

Read on the lines :func:`.describe_gain.channel_gain` reads (the model's lines standing over the noise in both
channels, in :data:`MIN_RUNS` runs or more): a line is of a fixed direction when the median over its runs of the
x/y power ratio against the model's is :data:`MIN_DB` or more from 0, :data:`MIN_Z` standard errors from it, and
its robust scatter over the runs within :data:`MAX_SCATTER_DB` (or a quarter of the ratio).  Its ellipse is then
measured on the records (a whole-run DFT of both channels at the line): the counter/co ratio |a₋|/|a₊| (1: a load
along one direction) and the direction ψ of its major axis from +x, medians over the runs.
"""
from __future__ import annotations

import numpy as np

from ..dft import run_window, windowed_dfts
from ..units import RAD_S_TO_RPM
from .unexplained import Unexplained

#: A line's x/y power ratio (against the model's) at least this far from 0 dB ...
MIN_DB = 1.0
#: ... this many standard errors of its median over the runs ...
MIN_Z = 5.0
#: ... its runs' robust scatter at most this (dB), or a quarter of the ratio when that is larger ...
MAX_SCATTER_DB = 0.5
#: ... read in this many runs or more
MIN_RUNS = 4


def directed_lines(d: np.ndarray, good: np.ndarray, lines) -> tuple:
    """(index of the lines of a fixed direction, their median ratio dB, their robust scatter dB) among ``lines``
    (indices into ``d``, (lines, runs) of dB: y's measured-over-model power less x's, read where ``good``)."""
    keep, med, scatter = [], [], []
    for i in lines:
        cells = d[i][good[i]]
        if cells.size < MIN_RUNS:
            continue
        m = float(np.median(cells))
        s = 1.4826 * float(np.median(np.abs(cells - m)))
        se = 1.2533 * s / np.sqrt(cells.size)
        if abs(m) >= MIN_DB and abs(m) >= MIN_Z * se and s <= max(MAX_SCATTER_DB, abs(m) / 4):
            keep.append(int(i))
            med.append(m)
            scatter.append(s)
    return np.asarray(keep, dtype=int), np.asarray(med), np.asarray(scatter)


def ellipses(ctx, pair: tuple, h: np.ndarray, runs: np.ndarray) -> tuple:
    """(counter/co ratio (L,), direction of the major axis from +x, degrees in [−90, 90) (L,), its steadiness (L,):
    the length of the runs' mean of e^{2iψ}, 1 when every run has one direction, ~0 when each has its own) of the lines
    ``h`` of the radial ``pair`` (x, y channels) over ``runs`` (indices into ``ctx.test.runs``; the ratio the median)
    from the whole-run phasors X, Y at h·Ω/2π: a₊ = (X + iY)/2, a₋ = conj(X − iY)/2 (x = Re(X e^{iωt}),
    y = Re(Y e^{iωt})); NaN where no run of both channels is read."""
    cx, cy = pair
    q_all, psi_all = [], []
    for r in runs:
        run = ctx.test.runs[int(r)]
        if run.speed == 0 or not (run.usable(cx) and run.usable(cy)):
            continue
        n, fs = run.n_samples, float(run.sample_rate)
        w = run_window("hann", n)[0]
        x = np.stack([(np.asarray(run.signals[c], dtype=float) - np.mean(run.signals[c])) * w for c in pair], axis=1)
        XY = windowed_dfts(x[None], fs, (h * abs(run.speed) / (2 * np.pi))[None, :])[0]       # (L, 2)
        co, counter = (XY[:, 0] + 1j * XY[:, 1]) / 2, np.conj(XY[:, 0] - 1j * XY[:, 1]) / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            q_all.append(np.abs(counter) / np.abs(co))
        psi_all.append(np.angle(co) + np.angle(counter))                                   # 2ψ
    if not q_all:
        nan = np.full(h.size, np.nan)
        return nan, nan, nan
    mean = np.exp(1j * np.array(psi_all)).mean(axis=0)
    return np.nanmedian(np.array(q_all), axis=0), np.degrees(np.angle(mean) / 2), np.abs(mean)


#: A line read with both parts (counter/co within this factor of 1) and one direction in every run (the runs' mean
#: of e^{2iψ} this long or longer) is of a fixed direction whatever its x/y power ratio (one along ±45° reads x and y
#: alike)
PLANAR_Q = 2.0
STEADY_DIRECTION = 0.9


def _shape(q: float) -> str:
    """The ellipse of counter/co ratio ``q`` in words, before its direction."""
    return "a load along" if 1 / PLANAR_SHAPE <= q <= PLANAR_SHAPE else "an ellipse, its major axis at"


#: counter/co within this factor of 1: a load along one direction (its ellipse's minor axis under 1/9 of its major)
PLANAR_SHAPE = 1.25


def fixed_direction(ctx, pair: tuple, h: np.ndarray, d: np.ndarray, good: np.ndarray, lines, shares):
    """The ``line_property`` record (property ``fixed_direction``) of the radial ``pair``'s lines that keep their own
    x/y power ratio in every run (:func:`directed_lines` of ``d``, (lines, runs) dB, read where ``good``, among
    ``lines``), or None (``shares(chans, hs, runs)`` -> (share of the misplaced power, level dB) of the lines'
    cells)."""
    cx, cy = pair
    idx, med, _ = directed_lines(d, good, lines)
    if idx.size == 0:
        return None
    runs = ctx.runs
    lines = np.asarray(lines, dtype=int)
    used = np.flatnonzero(good[lines].any(axis=0))
    q, psi, steady = ellipses(ctx, pair, h[lines], runs[used])
    ratio = np.array([float(np.median(d[i][good[i]])) for i in lines])
    planar = (q >= 1 / PLANAR_Q) & (q <= PLANAR_Q) & (steady >= STEADY_DIRECTION)
    chosen = np.isin(lines, idx) | planar
    alike = [float(h[i]) for i, r, c in zip(lines, ratio, chosen) if not c and abs(r) < MIN_DB]
    keep = lines[chosen]
    used = np.flatnonzero(good[keep].any(axis=0))
    share, _ = shares(pair, h[keep], runs[used])
    rpm = ctx.omega[runs[used]] * RAD_S_TO_RPM
    f = np.concatenate([h[i] * ctx.omega[runs[good[i]]] / (2 * np.pi) for i in keep])
    each = ", ".join(f"h {h[i]:.3g} ({m:+.1f} dB, counter/co {qq:.2f}: {_shape(qq)} {p:+.0f} deg from +{cx})"
                     for i, m, qq, p in zip(keep, ratio[chosen], q[chosen], psi[chosen]))
    spread = [1.4826 * float(np.median(np.abs(d[i][good[i]] - np.median(d[i][good[i]])))) for i in keep]
    rest = (f"; the lines h {', '.join(f'{x:.3g}' for x in alike)} read {cx} and {cy} alike, as a rotating load does "
            "(a channel's gain would move them too)") if alike else ""
    return Unexplained(
        signature="line_property", channels=(cx, cy), speed_rpm=(float(rpm.min()), float(rpm.max())),
        f_Hz=(float(f.min()), float(f.max())), level_dB=float(med[np.argmax(np.abs(med))]), share=share,
        n_runs=int(used.size),
        parameters={"property": "fixed_direction", "channel": cy, "reference": cx,
                    "lines_h": [float(h[i]) for i in keep], "power_ratio_dB": [float(x) for x in ratio[chosen]],
                    "run_scatter_dB": spread, "counter_over_co": [float(x) for x in q[chosen]],
                    "direction_deg": [float(x) for x in psi[chosen]],
                    "direction_steadiness": [float(x) for x in steady[chosen]], "lines_alike_h": alike},
        causes=(f"loads of a fixed shape and direction in the x-y plane, not rotating ones: each line keeps its own "
                f"{cy}/{cx} power ratio and direction in every run (ratios within {max(spread):.2g} dB): {each}{rest}.  "
                "A co- and a counter-rotating part whose phase is the wheel's trace an ellipse of one orientation (of "
                "equal parts, a load along one direction); the model holds both parts' power, not that phase: a "
                "load of one direction of the housing, an outer-race defect or a bearing seat's "
                "out-of-roundness at a fixed place of the housing (the ball-pass impacts land there), a misaligned "
                "seat, a motor stator's fixed axis",),
        would_tell="the test repeated with the wheel turned about its spin axis in its mount (a direction fixed in "
                   "the wheel's housing turns with it; a load-cell channel's gain or a stand's stiffness stays)")
