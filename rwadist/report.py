"""Validation report of an empirical fit: plots and tables (thesis §3.1.3-3.1.4,
``find_coeff.m`` / ``remove_mode.m`` curve-fit plots and ``comp_model.m``).

The ``plot_*`` functions draw on a given Axes or on a new
:class:`matplotlib.figure.Figure` (Agg canvas, no pyplot global state) and
return ``(figure, axes)`` so notebooks can reuse them.  :func:`write_report`
is the only function that touches the disk.

Speeds are plotted as |speed| in rpm (the model depends on |Ω|); frequencies in
Hz; amplitudes and RMS in N or N·m.  The ``fit`` argument is an
``rwadist.empirical.EmpiricalFit`` (``model``, ``spectra``, ``lines``, ``bins``,
``settings``); anything with those attributes works.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from . import compare
from .empirical import line_C
from .plot_util import PNG_COMPRESS_LEVEL, log_axis, save_png  # noqa: F401 (PNG_COMPRESS_LEVEL: its old home)
from .spectra import cumulative_rms
from .text_table import write_rows
from .units import (
    CHANNEL_DIRECTION,
    CHANNEL_UNIT,
    DIRECTION_C_UNIT,
    DIRECTION_CHANNELS,
    RAD_S_TO_RPM,
    rad_s_to_rpm,
    rpm_to_rad_s,
)

_UNIT_LABEL = {"N": "N", "Nm": "N·m"}
_DPI = 110
# drawing order: model markers and curves under the measured data, so the data stay readable
MODEL_ZORDER = 2.0
DATA_ZORDER = 3.0
# relative half-width (2σ/C) below which the C ± 2σ band would be thinner than the curve's line
COEFFICIENT_BAND_VISIBLE = 0.02


def _unit(channel: str) -> str:
    return _UNIT_LABEL[CHANNEL_UNIT[channel]]


def _direction_unit(direction: str) -> str:
    return _unit(DIRECTION_CHANNELS[direction][0])


def _direction_label(direction: str) -> str:
    return direction.replace("_", " ")


def _new_figure(figsize) -> Figure:
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: Path) -> Path:
    # no fig.clear() afterwards: the figure is dropped by the caller, and clearing it rebuilt every
    # axis's ticks only to throw them away (~10 % of write_report's CPU, same PNG bytes without it)
    # One draw: Figure.draw runs the constrained layout, then renders (savefig on a figure with a layout
    # engine draws it twice: a draw-disabled pass for the layout, then the real draw; same PNG bytes
    # without it).  zlib level 3 instead of PIL's 6: the same pixels, half the encoding time, ~7 % larger files.
    return save_png(fig, path, _DPI)


def _band_top(spectra, f_max):
    top = float(spectra.band_limit)
    return top if f_max is None else min(float(f_max), top)


def has_signal(spectra, channel: str) -> bool:
    """True when ``channel`` was measured in some run and is not identically zero there
    (absent and all-zero channels are left out of the plots)."""
    if channel not in spectra.psd:
        return False
    have = np.asarray(spectra.available(channel), dtype=bool)
    if not have.any():
        return False
    rows = np.asarray(spectra.psd[channel])[have]
    return bool(np.any(np.isfinite(rows) & (rows > 0)))


def content_top(spectra, lines, f_max: float | None = None) -> float:
    """Upper frequency (Hz) of the band that holds the harmonic content: 1.5x the highest
    fitted line at the top speed, capped by ``f_max`` and the band limit ``f_lim``; the band
    limit itself when there are no lines."""
    top = _band_top(spectra, f_max)
    w_max = float(np.max(np.abs(spectra.speed))) if len(spectra.speed) else 0.0
    line_top = max((float(x.h) * w_max / (2 * np.pi) for x in (lines or ())), default=0.0)
    return min(top, 1.5 * line_top) if line_top > 0 else top


def _is_modal(line) -> np.ndarray:
    """Measurements of a LineFit left out as modal amplification: unused and inside an excluded range."""
    rpm = np.abs(rad_s_to_rpm(line.speed))
    inside = np.zeros(rpm.shape, dtype=bool)
    for lo, hi in line.excluded_rpm:
        inside |= (rpm >= lo) & (rpm <= hi)
    return inside & ~np.asarray(line.used, dtype=bool)


# --------------------------------------------------------------------------- waterfall

def _merge_speeds(rpm: np.ndarray, rows: np.ndarray):
    """Average rows of runs at the same |speed| (NaN-aware); returns (unique rpm, rows)."""
    u, inv = np.unique(rpm, return_inverse=True)
    good = np.isfinite(rows)
    total = np.zeros((len(u), rows.shape[1]))
    count = np.zeros_like(total)
    np.add.at(total, inv, np.where(good, rows, 0.0))
    np.add.at(count, inv, good)
    with np.errstate(invalid="ignore"):
        return u, np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _edges(centres: np.ndarray, default_half: float) -> np.ndarray:
    if len(centres) == 1:
        return np.array([centres[0] - default_half, centres[0] + default_half])
    mid = 0.5 * (centres[1:] + centres[:-1])
    return np.concatenate([[centres[0] - (mid[0] - centres[0])], mid, [centres[-1] + (centres[-1] - mid[-1])]])


#: Most markers drawn along one line of a waterfall (:func:`plot_waterfall`): ~11 px rings 540 px apart at most
MAX_MARKERS_PER_LINE = 40


def plot_waterfall(spectra, channel: str, ax=None, model=None, f_max: float | None = None,
                   lines=None, max_columns: int = 1500):
    """Data PSD of ``channel`` as a |speed| (rpm) × frequency (Hz) image, log10 colour, up to
    min(f_max, band limit); the model's lines h·|Ω| (Eq. 3.12) overlaid as circles, and the
    measurements ``lines`` (LineFit list) left out as modal amplification as red crosses, both at no more than
    :data:`MAX_MARKERS_PER_LINE` evenly spaced speeds per line (the data stay visible between them).

    Runs at the same |speed| are averaged; when the band holds more than ``max_columns``
    bins, adjacent bins are merged by their maximum so narrow lines stay visible.
    Returns (figure, axes).
    """
    fig = ax.figure if ax is not None else _new_figure((9.0, 6.0))
    ax = ax if ax is not None else fig.add_subplot()
    top = _band_top(spectra, f_max)
    f = spectra.f
    keep = f <= top
    rpm = np.abs(rad_s_to_rpm(spectra.speed))
    u_rpm, rows = _merge_speeds(rpm, spectra.psd[channel][:, keep])
    fk = f[keep]
    df = f[1] - f[0]
    k = int(np.ceil(len(fk) / max_columns))
    if k > 1:
        n = (len(fk) // k) * k
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks of absent runs
            rows = np.nanmax(rows[:, :n].reshape(len(u_rpm), n // k, k), axis=-1)
        f_edges = np.concatenate([fk[:n:k] - df / 2, [fk[n - 1] + df / 2]])
    else:
        f_edges = np.concatenate([fk - df / 2, [fk[-1] + df / 2]])
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.log10(np.where(rows > 0, rows, np.nan))
    z = np.ma.masked_invalid(z)
    unit = _unit(channel)
    y_edges = _edges(u_rpm, 50.0)
    if z.count():
        vals = z.compressed()
        mesh = ax.pcolormesh(f_edges, y_edges, z, cmap="viridis", shading="flat", zorder=1,
                             vmin=np.percentile(vals, 2), vmax=vals.max(), rasterized=True)
        fig.colorbar(mesh, ax=ax, label=f"log10 PSD ({unit}²/Hz)")
    handles = []
    # markers on at most MAX_MARKERS_PER_LINE speeds of each line: a sweep sliced into 170 runs drew rings and crosses
    # so close that they merged into tubes hiding the lines they mark
    stride = max(1, int(np.ceil(len(u_rpm) / MAX_MARKERS_PER_LINE)))
    marked = u_rpm[::stride]
    # every marker is a pair of ticks either side of the line, never on it: the measured ridge stays visible
    # between them (rings and crosses centred on the line covered it)
    gap = ridge_gap(f_edges, top, ax.get_position().width * fig.get_figwidth() * _DPI)
    labelled: list = []
    if model is not None and channel in CHANNEL_DIRECTION:
        direction = CHANNEL_DIRECTION[channel]
        f_line, _ = compare.model_psd_lines(model, direction, rpm_to_rad_s(marked))
        if f_line.size:
            yy = np.broadcast_to(marked[:, None], f_line.shape)
            m = (f_line <= top) & (yy > 0)
            handles += ax.plot(np.concatenate([f_line[m] - gap, f_line[m] + gap]), np.concatenate([yy[m], yy[m]]),
                               "|", color="white", mew=1.1, ms=7, alpha=0.9, zorder=MODEL_ZORDER,
                               label="model lines h·Ω (ticks either side)")
            labelled = [hm.h for hm in model.harmonics(direction)]
    if lines is not None:
        fx_parts: list[np.ndarray] = []     # per line: Hz, rpm of its excluded (modal) points
        fy_parts: list[np.ndarray] = []
        for ln in lines:
            sel = (np.asarray(ln.channel) == channel) & _is_modal(ln) \
                & np.isin(np.round(np.abs(ln.speed) * RAD_S_TO_RPM, 6), np.round(marked, 6))
            fx_parts.append(ln.h * np.abs(ln.speed[sel]) / (2 * np.pi))
            fy_parts.append(np.abs(ln.speed[sel]) * RAD_S_TO_RPM)
        fx = np.concatenate(fx_parts) if fx_parts else np.empty(0)
        if fx.size:
            fy = np.concatenate(fy_parts)
            handles += ax.plot(np.concatenate([fx - 1.6 * gap, fx + 1.6 * gap]), np.concatenate([fy, fy]), "|",
                               color="red", mew=1.4, ms=5, zorder=DATA_ZORDER,
                               label="excluded (modal) measurement (red ticks)")
    ax.set_xlim(max(f_edges[0], 0.0), min(f_edges[-1], top))
    ax.set_ylim(max(y_edges[0], 0.0), y_edges[-1])
    _label_lines(ax, labelled, float(u_rpm.max()), float(y_edges[-1]), min(f_edges[-1], top))
    ax.set_xlabel("Frequency (Hz)")
    ax.set_ylabel("Wheel speed |Ω| (rpm)")
    name = f" vs model '{model.name}'" if model is not None else ""
    ax.set_title(f"{channel} PSD waterfall{name} (0–{top:.0f} Hz)", pad=16 if labelled else 6)
    if handles:
        leg = ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=len(handles),
                        facecolor="0.35", framealpha=1.0, fontsize="small")
        for t in leg.get_texts():
            t.set_color("white")
    return fig, ax


#: the least clearance between a line's ticks and its ridge on a waterfall, pixels of the saved figure
RIDGE_CLEARANCE_PX = 3.5


def ridge_gap(f_edges, top: float, width_px: float = 700.0) -> float:
    """Half the distance (Hz) between the two ticks that mark a line on a waterfall: clear of the ridge -- 2.5 image
    columns (merged bins included), and at least :data:`RIDGE_CLEARANCE_PX` pixels of a band drawn ``width_px``
    wide."""
    col = float(np.max(np.diff(f_edges))) if len(f_edges) > 1 else 0.0
    return max(2.5 * col, RIDGE_CLEARANCE_PX * (top - max(float(f_edges[0]), 0.0)) / width_px)


def _label_lines(ax, hs, rpm_top: float, y_top: float, f_top: float) -> None:
    """Each model line labelled by its h where it leaves the plot: at the top edge (its frequency at the top speed),
    or on the right edge where it reaches the band's top; labels spread so that none overlaps another."""
    from .plot_util import spread_labels

    hs = sorted({round(float(h), 4) for h in hs if h > 0})
    top_x, side_y, top_h, side_h = [], [], [], []
    for h in hs:
        f = h * rpm_top / 60.0
        if f <= f_top:
            top_x.append(f)
            top_h.append(h)
        else:
            side_y.append(f_top * 60.0 / h)
            side_h.append(h)
    style = dict(fontsize=6.5, color="white", zorder=DATA_ZORDER + 1, clip_on=False,
                 bbox=dict(boxstyle="round,pad=0.15", fc="0.25", ec="none", alpha=0.8))
    if top_x:
        xs = spread_labels(np.asarray(top_x), 0.045 * f_top)
        for x, h in zip(xs, top_h):
            ax.text(x, y_top, f"{h:.3g}", ha="center", va="bottom", **style)
    if side_y:
        ys = spread_labels(np.asarray(side_y), 0.04 * rpm_top)
        for y, h in zip(ys, side_h):
            ax.text(f_top, y, f"{h:.3g}", ha="left", va="center", **style)
    if hs:
        ax.text(0.0, 1.0, "h =", transform=ax.transAxes, ha="right", va="bottom", **style)


# --------------------------------------------------------------------------- RMS vs speed

def plot_rms_vs_speed(spectra, model, direction: str, ax=None, f_max: float | None = None):
    """Data RMS of each channel of ``direction`` and the model RMS (Eq. 3.19), band-limited
    alike, vs |speed| (rpm).  With ``ax=None`` and a model with harmonics in ``direction`` a
    second panel shows model/data (no ratio panel when the model has nothing to compare).
    Channels absent or all zero are left out.
    Returns (figure, axes) -- axes a tuple (rms, ratio) when the ratio panel is drawn.
    """
    has_model = len(model.harmonics(direction)) > 0
    own = ax is None
    if own and has_model:
        fig = _new_figure((8.0, 6.0))
        ax_rms, ax_ratio = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1])
    elif own:
        fig = _new_figure((8.0, 4.6))
        ax_rms, ax_ratio = fig.add_subplot(), None
    else:
        fig, ax_rms, ax_ratio = ax.figure, ax, None
    top = _band_top(spectra, f_max)
    unit = _direction_unit(direction)
    omega = np.asarray(spectra.speed, dtype=float)
    rpm = np.abs(rad_s_to_rpm(omega))
    model_runs = compare.model_rms_vs_speed(model, direction, omega, top)
    for ch, marker in zip(DIRECTION_CHANNELS[direction], ("o", "s")):
        if not has_signal(spectra, ch):
            continue
        d = compare.data_rms(spectra, ch, top)
        ok = np.isfinite(d) & (d > 0)
        ax_rms.plot(rpm[ok], d[ok], marker, mfc="none", zorder=DATA_ZORDER, label=f"data {ch}")
        if ax_ratio is not None:
            r = np.where(ok, model_runs / np.where(ok, d, 1.0), np.nan)
            ax_ratio.plot(rpm[ok & (rpm > 0)], r[ok & (rpm > 0)], marker, mfc="none", label=ch)
    if has_model and rpm.max() > 0:
        grid = np.linspace(max(rpm[rpm > 0].min(), 1.0) * 0.5, rpm.max() * 1.02, 600)
        ax_rms.plot(grid, compare.model_rms_vs_speed(model, direction, rpm_to_rad_s(grid), top), "-",
                    color="k", zorder=MODEL_ZORDER, label=f"model (lines ≤ {top:g} Hz)")
    log_axis(ax_rms)
    ax_rms.set_ylabel(f"RMS 0–{top:g} Hz ({unit})")
    what = "data vs model" if has_model else "data (the model has no harmonics here)"
    ax_rms.set_title(f"{_direction_label(direction)}: RMS over 0–{top:g} Hz vs wheel speed, {what}")
    ax_rms.grid(True, which="both", alpha=0.3)
    if ax_rms.get_legend_handles_labels()[0]:
        ax_rms.legend()
    if ax_ratio is not None:
        ax_ratio.axhline(1.0, color="k", lw=0.8)
        ax_ratio.set_ylabel("model / data")
        ax_ratio.set_xlabel("Wheel speed |Ω| (rpm)")
        ax_ratio.grid(True, alpha=0.3)
        if ax_ratio.get_legend_handles_labels()[0]:
            ax_ratio.legend(fontsize="small")
        return fig, (ax_rms, ax_ratio)
    ax_rms.set_xlabel("Wheel speed |Ω| (rpm)")
    return fig, ax_rms


# --------------------------------------------------------------------------- cumulative RMS

def nearest_run(spectra, channels, speed_rpm: float) -> int:
    """Index of the run whose |speed| is nearest ``speed_rpm`` among runs having any of ``channels``."""
    have = np.zeros(len(spectra.speed), dtype=bool)
    for ch in channels:
        if ch in spectra.psd:
            have |= spectra.available(ch)
    if not have.any():
        raise ValueError(f"no run has any of the channels {tuple(channels)}")
    dist = np.abs(np.abs(rad_s_to_rpm(spectra.speed)) - abs(speed_rpm))
    return int(np.argmin(np.where(have, dist, np.inf)))


def default_speeds_rpm(spectra, n: int = 3) -> list:
    """Low, middle and top |speed| (rpm) among the spinning runs (fewer if fewer distinct speeds)."""
    u = np.unique(np.abs(rad_s_to_rpm(spectra.speed)))
    u = u[u > 0]
    if len(u) <= n:
        return [float(x) for x in u]
    return [float(u[int(round(i))]) for i in np.linspace(0, len(u) - 1, n)]


def plot_cumulative_rms(spectra, model, direction: str, speed_rpm: float, axes=None,
                        f_max: float | None = None):
    """At the run nearest ``speed_rpm``: data amplitude spectra of the direction's channels
    with the model amplitudes C·Ω² as stems (thesis Fig. 3-13, upper panel) and the data
    cumulative RMS (Eq. 2.13) with the model's staircase (lower panel), over [0, f_max]
    (default and ceiling: the band limit; :func:`content_top` gives the band of the lines).
    Data are drawn over the model; absent or all-zero channels and a model without
    harmonics in ``direction`` are left out.  ``axes`` = (upper, lower) or None.
    Returns (figure, (upper, lower)).
    """
    if axes is None:
        fig = _new_figure((7.0, 6.5))
        ax_a, ax_c = fig.subplots(2, 1, sharex=True)
    else:
        ax_a, ax_c = axes
        fig = ax_a.figure
    top = _band_top(spectra, f_max)
    chans = [ch for ch in DIRECTION_CHANNELS[direction] if has_signal(spectra, ch)]
    j = nearest_run(spectra, chans, speed_rpm)
    omega = float(spectra.speed[j])
    rpm = abs(omega) * RAD_S_TO_RPM
    unit = _direction_unit(direction)
    keep = spectra.f <= top
    f = spectra.f[keep]
    floor = []
    for ch in chans:
        if not spectra.available(ch)[j]:
            continue
        floor.append(np.median(spectra.amplitude[ch][j, keep]))
        ax_a.plot(f, spectra.amplitude[ch][j, keep], lw=0.8, zorder=DATA_ZORDER, label=f"data {ch}")
        ax_c.plot(f, cumulative_rms(spectra.psd[ch][j, keep], f), lw=1.2, zorder=DATA_ZORDER, label=f"data {ch}")
    has_model = len(model.harmonics(direction)) > 0
    f_line, var = compare.model_psd_lines(model, direction, omega)
    m = f_line[0] <= top if f_line.size else np.zeros(0, dtype=bool)
    if m.any():
        amp = np.sqrt(2.0 * var[0][m])
        base = 0.5 * min(floor) if floor and min(floor) > 0 else amp.min() * 1e-2
        ax_a.vlines(f_line[0][m], np.minimum(base, amp), amp, color="0.45", lw=0.8, zorder=MODEL_ZORDER)
        ax_a.plot(f_line[0][m], amp, "o", mfc="none", ms=8, color="k", zorder=MODEL_ZORDER, label="model C·Ω²")
    if has_model:
        ax_c.plot(f, compare.model_cumulative_rms(model, direction, omega, f), "k--", lw=1.2,
                  drawstyle="steps-post", zorder=MODEL_ZORDER, label="model (staircase)")
    log_axis(ax_a)
    ax_a.set_ylabel(f"Amplitude ({unit})")
    ax_a.set_title(f"{_direction_label(direction)} at {rpm:.0f} rpm, 0–{top:.0f} Hz")
    ax_a.legend(fontsize="small")
    ax_a.grid(True, which="both", alpha=0.3)
    ax_c.set_xlabel("Frequency (Hz)")
    ax_c.set_ylabel(f"Cumulative RMS 0–f ({unit})")
    ax_a.set_xlim(0, top)
    ax_c.set_xlim(0, top)
    ax_c.legend(fontsize="small", loc="lower right")
    ax_c.grid(True, alpha=0.3)
    return fig, (ax_a, ax_c)


# --------------------------------------------------------------------------- coefficient curve fits

#: What the two uncertainties of a coefficient cover (the coefficient plots and summary.md say it)
UNCERTAINTY_NOTE = ("±2σ: the fit's statistical error of C (measurement noise, run to run). Held-out: the RMS error of "
                    "C·Ω² fitted on every other speed, at the speeds left out (the model's form: a line that does not "
                    "grow as Ω²). Neither covers a bias common to every speed kept (a mode above or below the speed "
                    "range amplifying every point, which an empirical fit takes into C): fit the modes with --extended")


def model_form_error(line) -> float:
    """Held-out error of C·Ω² for ``line`` (a :class:`rwadist.empirical.LineFit`), relative: C fitted as the fit does
    (:func:`~rwadist.empirical.line_C`) on every other speed of the measurements the fit used (sorted by speed), the RMS of (measured − predicted) at the
    others over the RMS predicted, both ways, the larger; NaN with fewer than 4 points.  The noise is in it too:
    compare with 2σ/C (a pure C·Ω² line gives about the noise's scatter)."""
    used = np.asarray(line.used, dtype=bool)
    d, w = np.asarray(line.amplitude, float)[used], np.abs(np.asarray(line.speed, float)[used])
    if d.size < 4:
        return float("nan")
    order = np.argsort(w, kind="stable")
    worst = 0.0
    for fit_idx, test_idx in ((order[::2], order[1::2]), (order[1::2], order[::2])):
        C = line_C(d[fit_idx], w[fit_idx])
        pred = C * w[test_idx] ** 2
        den = np.sqrt(np.mean(pred ** 2))
        if not den > 0:
            return float("nan")
        worst = max(worst, float(np.sqrt(np.mean((d[test_idx] - pred) ** 2)) / den))
    return worst


def plot_coefficient(line, ax=None, rpm_max: float | None = None):
    """One harmonic's curve fit (thesis Figs. 3-7, 3-9): measured amplitudes vs |speed| (used: dark
    crosses; left out: light circles), C·Ω² solid, C_all·Ω² dashed, (C ± 2·stderr)·Ω² band,
    excluded speed ranges shaded.  Returns (figure, axes)."""
    fig = ax.figure if ax is not None else _new_figure((5.0, 3.8))
    ax = ax if ax is not None else fig.add_subplot()
    rpm = np.abs(rad_s_to_rpm(line.speed))
    used = np.asarray(line.used, dtype=bool)
    for k, (lo, hi) in enumerate(line.excluded_rpm):
        ax.axvspan(lo, hi, color="tab:red", alpha=0.08, lw=0, label="excluded speed range" if k == 0 else None)
    if (~used).any():
        ax.plot(rpm[~used], line.amplitude[~used], "o", color="tab:orange", mfc="none", alpha=0.8, ms=5,
                zorder=DATA_ZORDER, label="left out of C")
    if used.any():
        ax.plot(rpm[used], line.amplitude[used], "x", color="tab:blue", ms=5, zorder=DATA_ZORDER, label="used")
    top = rpm_max if rpm_max is not None else (rpm.max() * 1.05 if rpm.size else 1.0)
    g = np.linspace(0.0, top, 300)
    w2 = rpm_to_rad_s(g) ** 2
    band = 2.0 * (line.C_stderr if np.isfinite(line.C_stderr) else 0.0)
    # the 2σ band is drawn (and named in the legend) only where it is wide enough to see;
    # the title always gives its value
    if line.C > 0 and band / line.C >= COEFFICIENT_BAND_VISIBLE:
        ax.fill_between(g, np.maximum(line.C - band, 0.0) * w2, (line.C + band) * w2, color="k", alpha=0.2,
                        lw=0, zorder=MODEL_ZORDER - 0.5, label="C ± 2σ")
    ax.plot(g, line.C * w2, "k-", lw=1.2, zorder=MODEL_ZORDER, label="C·Ω²")
    ax.plot(g, line.C_all * w2, "--", color="tab:orange", lw=1.2, zorder=MODEL_ZORDER, label="C_all·Ω² (all points)")
    cu = DIRECTION_C_UNIT[line.direction]
    rel = f" ± {100 * band / line.C:.2g} % (2σ noise)" if line.C > 0 and band > 0 else ""
    held = model_form_error(line)
    form = f"\nheld-out error {100 * held:.2g} % (model form)" if np.isfinite(held) else ""
    ax.set_title(f"h = {line.h:.4g}: C = {line.C:.3g} {cu}{rel}{form}", fontsize="medium")
    ax.set_xlim(0.0, top)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    return fig, ax


def plot_coefficients(lines, direction: str, fig=None):
    """Grid of :func:`plot_coefficient`, one subplot per harmonic of ``direction`` (by h).
    Returns (figure, array of axes)."""
    sel = sorted((ln for ln in lines if ln.direction == direction), key=lambda ln: ln.h)
    if not sel:
        raise ValueError(f"no harmonics of direction {direction!r} among the lines")
    n = len(sel)
    ncol = int(np.ceil(np.sqrt(n)))
    nrow = int(np.ceil(n / ncol))
    fig = fig if fig is not None else _new_figure((3.6 * ncol + 0.6, 2.9 * nrow + 0.8))
    axes = np.atleast_1d(fig.subplots(nrow, ncol, squeeze=False)).ravel()
    rpm_max = max((np.abs(rad_s_to_rpm(ln.speed)).max() for ln in sel if ln.speed.size), default=1.0) * 1.05
    unit = _direction_unit(direction)
    for ax, ln in zip(axes, sel):
        plot_coefficient(ln, ax, rpm_max)
    for i, ax in enumerate(axes):
        if i >= n:
            ax.set_visible(False)
            continue
        if i % ncol == 0:
            ax.set_ylabel(f"Amplitude ({unit})")
        if i >= n - ncol:
            ax.set_xlabel("Wheel speed |Ω| (rpm)")
    handles: dict[str, Artist] = {}     # label -> its first handle
    for ax in axes[:n]:
        for hd, lb in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lb, hd)
    import textwrap

    # title and note wrapped to the figure's width (characters of ~0.55 em) and placed by the constrained layout: the
    # suptitle above the panels, the note as the title of the legend under them.  A note written at a fixed height
    # overprinted the title and the top row's panel titles, and the title ran off both edges of a 3-panel row
    width_pt = fig.get_figwidth() * 72.0
    note = "\n".join(textwrap.wrap(UNCERTAINTY_NOTE, max(int(width_pt / (8.0 * 0.55)), 60)))
    fig.legend(handles.values(), handles.keys(), loc="outside lower center", ncol=min(len(handles), 6),
               fontsize="small", title=note, title_fontsize=8)
    f_lines = [ln.h * np.abs(ln.speed) / (2 * np.pi) for ln in sel if ln.speed.size]
    band = f", lines at {min(f.min() for f in f_lines):.3g}–{max(f.max() for f in f_lines):.3g} Hz" if f_lines else ""
    title = (f"{_direction_label(direction)}: amplitude coefficient curve fits (line amplitudes at every speed of the "
             f"data{band})")
    fig.suptitle("\n".join(textwrap.wrap(title, max(int(width_pt / (12.0 * 0.55)), 40))), fontsize=12)
    return fig, axes[:n]


# --------------------------------------------------------------------------- tables

def _same_h(a: float, b: float) -> bool:
    """Harmonic numbers equal to the model file's precision (it rounds h to 4 decimals)."""
    return abs(float(a) - float(b)) <= 1e-4 * max(1.0, abs(float(b)))


def harmonic_rows(fit) -> list:
    """One dict per harmonic: direction, h, C_SI, C_stderr_SI, C_all_SI, n_points, presence,
    excluded_rpm (list of [lo, hi] rpm: summary.md's column, excluded_ranges.csv's rows), in_model, heldout_rel.
    From the fit's lines; harmonics of the model without a line are added from the model (C_all unknown: NaN)."""
    model_h = {d: [float(hm.h) for hm in fit.model.harmonics(d)] for d in DIRECTION_CHANNELS}
    rows = []
    matched: dict[str, set[int]] = {d: set() for d in DIRECTION_CHANNELS}    # indices into model_h[d] with a line
    for ln in fit.lines:
        hit = [i for i, h in enumerate(model_h.get(ln.direction, [])) if _same_h(ln.h, h)]
        matched.setdefault(ln.direction, set()).update(hit)
        rows.append({"direction": ln.direction, "h": float(ln.h), "C_SI": float(ln.C),
                     "C_stderr_SI": float(ln.C_stderr), "C_all_SI": float(ln.C_all),
                     "n_points": int(np.count_nonzero(ln.used)), "presence": float(ln.presence),
                     "excluded_rpm": [[float(a), float(b)] for a, b in ln.excluded_rpm],
                     "in_model": bool(hit), "heldout_rel": model_form_error(ln)})
    for d in DIRECTION_CHANNELS:
        for i, hm in enumerate(fit.model.harmonics(d)):
            if i in matched[d]:
                continue
            rows.append({"direction": d, "h": float(hm.h), "C_SI": float(hm.C),
                         "C_stderr_SI": float(hm.C_stderr) if hm.C_stderr is not None else np.nan,
                         "C_all_SI": np.nan, "n_points": int(hm.n_points),
                         "presence": float(hm.presence) if hm.presence is not None else np.nan,
                         "excluded_rpm": [[float(a), float(b)] for a, b in hm.excluded_rpm],
                         "in_model": True, "heldout_rel": np.nan})
    order = {d: i for i, d in enumerate(DIRECTION_CHANNELS)}
    rows.sort(key=lambda r: (order.get(r["direction"], 99), r["h"]))
    return rows


#: harmonics.csv's columns: a line's excluded speed ranges are the rows of excluded_ranges.csv with its direction and h
HARMONICS_COLUMNS = ["direction", "h", "C_SI", "C_stderr_SI", "C_all_SI", "n_points", "presence", "in_model",
                     "heldout_rel"]
BINS_COLUMNS = ["direction", "h", "n_bin", "n_possible", "presence", "kept", "reason"]
EXCLUDED_COLUMNS = ["direction", "h", "lo_rpm", "hi_rpm"]


def _summary_md(fit, rows, table, top, files, extended=None) -> str:
    """summary.md of the report: the empirical fit (its harmonics, what their uncertainties cover, model/data RMS);
    with ``extended`` (:func:`_extended_md`'s lines) the extended model first, the empirical fit as its start."""
    sp = fit.spectra
    rpm = np.abs(rad_s_to_rpm(sp.speed))
    prov = getattr(fit.model, "provenance", {}) or {}
    made = ", ".join(f"{k} {prov[k]}" for k in ("rwadist", "created_utc", "data") if prov.get(k))
    title = "Extended fit report" if extended else "Empirical fit report"
    out = [f"# {title}: {fit.model.name}", ""] + ([f"- made by: {made}"] if made else []) + [
           f"- runs: {len(sp.speed)}, |speed| {rpm.min():.0f}–{rpm.max():.0f} rpm; channels: "
           f"{', '.join(sp.channels)}",
           f"- sample rate {sp.sample_rate:g} Hz, resolution {sp.df:.4g} Hz, band used 0–{top:g} Hz", ""]
    out += _speed_md(prov)
    if extended:
        out += extended + ["", "# The empirical fit (the extended fit's starting point)", ""]
    out += ["## Harmonics (amplitude = C·Ω², Ω in rad/s)", "",
            "| direction | h | C (SI) | ±2σ noise | held-out (model form) | C_all (SI) | points | presence | "
            "excluded rpm | in model |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        exc = "; ".join(f"{a:.0f}–{b:.0f}" for a, b in r["excluded_rpm"]) or "–"
        two = f"{200 * r['C_stderr_SI'] / r['C_SI']:.2g} %" if r["C_SI"] > 0 and np.isfinite(r["C_stderr_SI"]) else "–"
        held = f"{100 * r['heldout_rel']:.2g} %" if np.isfinite(r["heldout_rel"]) else "–"
        out.append(f"| {r['direction']} | {r['h']:.4g} | {r['C_SI']:.4g} {DIRECTION_C_UNIT[r['direction']]} | "
                   f"{two} | {held} | {r['C_all_SI']:.4g} | {r['n_points']} | {r['presence']:.2f} | "
                   f"{exc} | {'yes' if r['in_model'] else 'no'} |")
    if not rows:
        out.append("| (none) | | | | | | | | | |")
    out += ["", f"What they cover: {UNCERTAINTY_NOTE}.", ""]
    out += ["## RMS empirical model/data (median over spinning runs)", ""]
    spin = np.abs(table["speed_rpm"]) > 0
    for key, v in table.items():
        if not key.startswith("ratio_"):
            continue
        ch = key[6:]
        if ch in sp.psd and not has_signal(sp, ch):
            continue                                 # all-zero channel: left out, as in the plots
        if ch in CHANNEL_DIRECTION and not fit.model.harmonics(CHANNEL_DIRECTION[ch]):
            out.append(f"- {ch}: n/a (the model has no {_direction_label(CHANNEL_DIRECTION[ch])} harmonics)")
            continue
        vals = v[spin & np.isfinite(v)]
        med = f"{np.median(vals):.3f}" if vals.size else "n/a"
        out.append(f"- {ch}: {med}")
    out += ["", "## Files", ""] + [f"- `{p.name}`" for p in files] + ["- `summary.md`", ""]
    return "\n".join(out)


def _speed_md(prov: dict) -> list:
    """summary.md's "Speed" section for a sweep cut into slices (the model's ``provenance.reading.slicing``): where the
    speeds came from, which line the data's speed scale took as 1x and how well the lines agree with it, and a tie the
    lines cannot settle (a new user's run-up fitted on its cage line said so on the console only); [] otherwise."""
    slicing = ((prov.get("reading") or {}).get("slicing") or {}) if isinstance(prov, dict) else {}
    if not slicing:
        return []
    out = ["## Speed", "", f"- a sweep cut into {slicing.get('n_kept', '?')} slices of "
           f"{slicing.get('slice_duration_s', float('nan')):.3g} s; speed from the {slicing.get('speed_source', '?')}"]
    scale = slicing.get("speed_scale") or {}
    if scale:
        out.append(f"- {str(scale.get('method', '')).removeprefix('speed from the data: ')}")
        if scale.get("agreement_rel_rms") is not None:
            out.append(f"- the lines agree with the speed to {100 * scale['agreement_rel_rms']:.3g} % RMS")
        tied = [t["h"] for t in (scale.get("one_x") or {}).get("tied") or []]
        if tied:
            out.append("- **the data cannot tell the 1x line**: the line" + ("s" if len(tied) > 1 else "") + " at h "
                       + ", ".join(f"{h:.4g}" for h in tied) + " of the one taken ha" + ("ve" if len(tied) > 1 else "s")
                       + " as many integer multiples, and every ratio holds at either scale (every h and speed off by "
                       "that factor): record the wheel's speed (a tach or speed_rpm column), or let `rwadist diagnose` "
                       "test the scale with the wheel's gyroscopic whirl")
    return out + [""]


def write_report(fit, out_dir, cumulative_speeds_rpm=None, f_max: float | None = None,
                 progress: bool = False) -> list:
    """Write the validation report of ``fit`` to ``out_dir``; return the paths written.

    Files: ``waterfall_<ch>.png`` per channel, ``rms_vs_speed_<direction>.png`` and
    ``cumulative_rms_<direction>.png`` per direction with data, ``coefficients_<direction>.png``
    per direction with fitted lines, ``harmonics.csv``, ``rms_vs_speed.csv``, ``bins.csv``,
    ``excluded_ranges.csv`` and ``summary.md``.  ``cumulative_speeds_rpm``: speeds of the
    cumulative-RMS panels (nearest runs), default low, middle and top speed.  ``f_max``: upper
    band edge, Hz (default and ceiling: the spectra's band limit).  ``progress``: a bar on stderr
    over the figures and tables.
    """
    from .progress import steps

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    sp, model = fit.spectra, fit.model
    top = _band_top(sp, f_max)
    # frequency axes are drawn up to 1.5x the highest fitted line (where the harmonics are);
    # RMS values still integrate the whole band
    view = content_top(sp, fit.lines) if f_max is None else top
    files = []
    channels = [ch for ch in sp.channels if has_signal(sp, ch)]
    directions = [d for d in DIRECTION_CHANNELS if any(has_signal(sp, ch) for ch in DIRECTION_CHANNELS[d])]
    speeds = default_speeds_rpm(sp) if cumulative_speeds_rpm is None else [float(s) for s in cumulative_speeds_rpm]
    fitted = [d for d in DIRECTION_CHANNELS if any(ln.direction == d for ln in fit.lines)]
    bar = steps(len(channels) + len(directions) * (2 if speeds else 1) + len(fitted) + 1, "writing the report",
                progress, unit="file")
    for ch in channels:
        fig, _ = plot_waterfall(sp, ch, model=model, f_max=view, lines=fit.lines)
        files.append(_save(fig, out / f"waterfall_{ch}.png"))
        bar.update()
    for d in directions:
        fig, _ = plot_rms_vs_speed(sp, model, d, f_max=top)
        files.append(_save(fig, out / f"rms_vs_speed_{d}.png"))
        bar.update()
        if speeds:
            fig = _new_figure((4.6 * len(speeds) + 0.4, 7.0))
            axes = fig.subplots(2, len(speeds), sharex="col", squeeze=False)
            for k, s in enumerate(speeds):
                plot_cumulative_rms(sp, model, d, s, axes=(axes[0, k], axes[1, k]), f_max=view)
            fig.suptitle(f"{_direction_label(d)}: amplitude spectra and cumulative RMS over 0–{view:.0f} Hz, "
                         "data vs model")
            files.append(_save(fig, out / f"cumulative_rms_{d}.png"))
            bar.update()
    for d in fitted:
        fig, _ = plot_coefficients(fit.lines, d)
        files.append(_save(fig, out / f"coefficients_{d}.png"))
        bar.update()

    rows = harmonic_rows(fit)
    files.append(write_rows(out / "harmonics.csv", HARMONICS_COLUMNS, rows))
    table = compare.rms_table(fit, top)
    cols = list(table)
    files.append(write_rows(out / "rms_vs_speed.csv", cols,
                            ({c: float(table[c][i]) for c in cols} for i in range(len(table["speed_rpm"])))))
    files.append(write_rows(out / "bins.csv", BINS_COLUMNS,
                            ({c: getattr(b, c, "") for c in BINS_COLUMNS} for b in fit.bins)))
    exc = [{"direction": r["direction"], "h": r["h"], "lo_rpm": float(lo), "hi_rpm": float(hi)}
           for r in rows for lo, hi in r["excluded_rpm"]]
    files.append(write_rows(out / "excluded_ranges.csv", EXCLUDED_COLUMNS, exc))
    summary = out / "summary.md"
    summary.write_text(_summary_md(fit, rows, table, top, files))
    files.append(summary)
    bar.update()
    bar.refresh()                  # show the completed count even when the last update came fast
    bar.close()
    return files
