"""Campbell analysis of the extended wheel model (issue 3 item 5): mode frequencies vs speed,
harmonic lines h·|Ω| and the speeds where they cross.

rpm appears only here at the edge (tables, plot axes); the physics is
:func:`rwadist.extended.whirl_frequencies` (undamped, closed form) and
:func:`rwadist.extended.crossings` (root finding with the closed form alongside).
Plots use a bare matplotlib ``Figure`` with the Agg canvas (no pyplot state).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import extended as ext
from .errors import ParameterError
from .text_table import write_rows
from .units import RPM_TO_RAD_S

#: Column of each mode in a Campbell table (Hz): mode and whirl in the name.
MODE_COLUMNS = {m: f"{m}_Hz" for m in ext.MODES}
_STYLE = {"radial_translation": ("tab:blue", "-"), "rocking_forward": ("tab:red", "-"),
          "rocking_backward": ("tab:red", "--"), "axial_translation": ("tab:green", "-")}


def _speeds(speeds_rpm) -> np.ndarray:
    s = np.atleast_1d(np.asarray(speeds_rpm, dtype=float))
    if s.ndim != 1 or s.size == 0 or not np.all(np.isfinite(s)):
        raise ParameterError("speeds_rpm", f"{speeds_rpm!r}: must be a non-empty 1-D list of finite speeds")
    return s


def campbell_table(params: ext.ExtendedParams, speeds_rpm) -> dict:
    """{'speed_rpm': speeds, '<mode>_Hz': undamped mode frequency (Hz) for each mode} at the given
    wheel speeds (rpm, signed; whirl is relative to the spin, so ±Ω give the same row).  Mode columns:
    radial_translation_Hz, rocking_forward_Hz, rocking_backward_Hz, axial_translation_Hz."""
    s = _speeds(speeds_rpm)
    freqs = ext.whirl_frequencies(params, s * RPM_TO_RAD_S)
    out = {"speed_rpm": s}
    out.update({MODE_COLUMNS[m]: np.asarray(freqs[m], dtype=float) for m in ext.MODES})
    return out


def write_campbell_csv(table: dict, path) -> Path:
    """Write a :func:`campbell_table` as CSV (speed_rpm first, then the mode columns, Hz; every digit, a NaN empty as in
    every table: :func:`rwadist.text_table.cell`); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    cols = ["speed_rpm"] + [c for c in table if c != "speed_rpm"]
    return write_rows(path, cols, zip(*(np.asarray(table[c], dtype=float) for c in cols)))


def speed_range_rad_s(speeds_rpm) -> tuple:
    """(lo, hi) of |Ω| in rad/s covered by ``speeds_rpm``: [0, max|s|] when the speeds change sign
    or include 0, else [min|s|, max|s|]."""
    s = _speeds(speeds_rpm)
    hi = float(np.abs(s).max())
    lo = 0.0 if s.min() <= 0.0 <= s.max() else float(np.abs(s).min())
    if not hi > lo:
        raise ParameterError("speeds_rpm", f"{speeds_rpm!r}: must span a range of |speed|")
    return lo * RPM_TO_RAD_S, hi * RPM_TO_RAD_S


def _as_lines(lines) -> list:
    if lines is None:
        return [ext.Line("radial_force", float(h), 0.0) for h in range(1, 7)]
    return [ln if isinstance(ln, ext.Line) else ext.Line("radial_force", float(ln), 0.0) for ln in lines]


def campbell_crossings(params: ext.ExtendedParams, speeds_rpm, lines=None) -> list:
    """:func:`rwadist.extended.crossings` of ``lines`` (Line objects or harmonic numbers; default
    h = 1…6) over the |speed| range of ``speeds_rpm``, sorted by speed."""
    rows = ext.crossings(params, _as_lines(lines), speed_range_rad_s(speeds_rpm))
    return sorted(rows, key=lambda r: (r["speed_rad_s"], r["h"], r["mode"]))


def plot_campbell(params: ext.ExtendedParams, speeds_rpm, lines=None):
    """Campbell diagram: mode frequencies (Hz) vs wheel speed (rpm), harmonic lines h·|Ω|/2π
    (one per distinct h of ``lines``; default h = 1…6) and their crossings with the modes
    (filled marker: the line's direction and sense can excite the mode; open: it cannot).
    Returns a matplotlib Figure (Agg canvas attached)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .plot_util import spread_labels

    s = _speeds(speeds_rpm)
    grid = np.linspace(s.min(), s.max(), max(400, s.size))
    tab = campbell_table(params, grid)
    lines = _as_lines(lines)
    fig = Figure(figsize=(8, 5.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(111)
    for m in ext.MODES:
        color, ls = _STYLE[m]
        ax.plot(grid, tab[MODE_COLUMNS[m]], color=color, ls=ls, lw=2, label=m.replace("_", " "))
    fmax = 1.3 * max(float(np.max(tab[MODE_COLUMNS[m]])) for m in ext.MODES)
    x_end = float(grid[np.argmax(np.abs(grid))])
    w_end = abs(x_end)
    harmonics = sorted({ln.h for ln in lines})
    for h in harmonics:
        ax.plot(grid, h * np.abs(grid) / 60.0, color="0.55", lw=0.8, zorder=1)
    # label each harmonic line where it leaves the plot (right edge or top), labels moved
    # apart so close harmonics (2x and 1.98x) stay readable
    right = [h for h in harmonics if h * w_end / 60.0 <= 0.97 * fmax]
    top = [h for h in harmonics if h * w_end / 60.0 > 0.97 * fmax]
    y_right = spread_labels([h * w_end / 60.0 for h in right], 0.035 * fmax)
    for h, y in zip(right, y_right):
        ax.annotate(f"{h:g}×", (x_end, h * w_end / 60.0), xytext=(x_end, y), textcoords="data",
                    fontsize=7, color="0.35", va="center", ha="left", annotation_clip=False)
    span = float(np.ptp(grid)) or 1.0
    x_top = spread_labels([60.0 * 0.97 * fmax / h for h in top], 0.045 * span)
    for h, x in zip(top, x_top):
        x_at = np.sign(x_end) * 60.0 * 0.97 * fmax / h
        ax.annotate(f"{h:g}×", (x_at, 0.97 * fmax), xytext=(np.sign(x_end) * abs(x), 1.005 * fmax),
                    textcoords="data", fontsize=7, color="0.35", ha="center", va="bottom",
                    annotation_clip=False)
    rows = campbell_crossings(params, s, lines)
    for r in sorted(rows, key=lambda r: r["excited"]):          # excitable crossings drawn on top
        sign = -1.0 if s.max() <= 0 else 1.0
        color = _STYLE[r["mode"]][0]
        ax.plot(sign * r["speed_rpm"], r["f_Hz"], "o", ms=6, mec=color,
                mfc=color if r["excited"] else "none", zorder=5)
    ax.set_ylim(0, fmax)
    ax.set_xlim(grid.min(), grid.max())
    ax.set_xlabel("wheel speed (rpm)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"Campbell diagram, 0–{fmax:.0f} Hz, {grid.min():g}–{grid.max():g} rpm: modes (coloured) and harmonic "
                 "lines h×speed (grey, labelled h×);\nfilled marker: the crossing can excite the mode", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return fig
