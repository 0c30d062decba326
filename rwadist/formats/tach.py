"""Wheel speed from a tach pulse channel (once-per-revolution TTL, or N pulses per revolution).

``meta.json`` names the channel: ``"tach": {"channel": "tach", "pulses_per_rev": 1}``.
Rising edges are found with a Schmitt trigger (thresholds at 40 % and 60 % of
the pulse height, so noise on a level does not retrigger) and timed to a
fraction of a sample by linear interpolation through the 50 % level.  Each
interval between edges is checked against the running median of its
neighbours: one longer than 1.5 times it is a **missing pulse**, one shorter
than 0.5 times it a **double trigger**; both are refused, naming the channel,
the time and the sample.

The shaft angle at edge k is 2·pi·k/N.  A steady run's speed is the
least-squares slope of angle against edge time (every edge weighs in, so the
sub-sample timing error averages out); a sweep's speed is the slope of a local
quadratic least-squares fit of angle against time (exact for a constant
acceleration), over a window of at least ``SWEEP_WINDOW_S`` seconds and
``SWEEP_WINDOW_EDGES`` edges, evaluated on a grid every ``SWEEP_GRID_S`` seconds,
interpolated to every sample; before the first and after the last edge the
fit of the nearest window is extrapolated (less than one pulse interval at
speed; at standstill the first window's).  A pulse gives the magnitude of the speed: it is reported positive.
"""
from __future__ import annotations

import numpy as np

from .records import DataError

MISSING_PULSE_RATIO = 1.5
DOUBLE_TRIGGER_RATIO = 0.5
#: Local fit window of a sweep's speed: at least this long (s) and this many edges.
SWEEP_WINDOW_S = 0.5
SWEEP_WINDOW_EDGES = 16
#: Spacing of the sweep's speed estimates before interpolation to the samples, s.
SWEEP_GRID_S = 0.02


def tach_settings(meta: dict, meta_path) -> tuple | None:
    """(channel name, pulses per revolution) from ``meta['tach']``, or None when absent."""
    tach = meta.get("tach") if isinstance(meta, dict) else None
    if tach is None:
        return None
    if not isinstance(tach, dict) or not isinstance(tach.get("channel"), str):
        raise DataError(meta_path, "tach", f"{tach!r}: expected {{\"channel\": NAME, \"pulses_per_rev\": N}}")
    ppr = tach.get("pulses_per_rev", 1)
    if not (isinstance(ppr, int) and not isinstance(ppr, bool) and ppr >= 1):
        raise DataError(meta_path, "tach.pulses_per_rev", f"{ppr!r}: must be a positive integer")
    return tach["channel"], ppr


def pulse_edges(path, channel: str, x: np.ndarray, fs: float, ppr: int) -> np.ndarray:
    """Rising-edge times of a pulse train, s from the first sample, shape (n_edges,); checked.

    Parameters
    ----------
    path, channel : named in errors.
    x : samples of the pulse channel, shape (n,), any unit.
    fs : sample rate, Hz.
    ppr : pulses per revolution (sets the running-median window of the interval checks).
    """
    x = np.asarray(x, dtype=float)
    lo, hi = np.percentile(x, [1.0, 99.0])
    if not hi > lo:
        raise DataError(path, f"channel {channel}", f"tach channel is flat (value {lo:g}): no pulses")
    mid, band = 0.5 * (lo + hi), 0.1 * (hi - lo)
    idx = np.arange(len(x))
    decided = (x > mid + band) | (x < mid - band)
    last = np.maximum.accumulate(np.where(decided, idx, -1))
    state = np.where(last >= 0, x[np.maximum(last, 0)] > mid, False)
    rising = np.flatnonzero(state[1:] & ~state[:-1]) + 1
    if len(rising) and last[rising[0] - 1] < 0:
        rising = rising[1:]  # the record starts inside a pulse's rise: its time is unknown
    below = np.maximum.accumulate(np.where(x <= mid, idx, -1))
    k = below[rising]
    keep = k >= 0
    k = k[keep]
    edges = (k + (mid - x[k]) / (x[k + 1] - x[k])) / fs
    if len(edges) < 3:
        raise DataError(path, f"channel {channel}", f"only {len(edges)} tach pulse(s) in the record; "
                        "need at least 3")
    d = np.diff(edges)
    window = max(5, 2 * ppr + 1)
    from scipy.ndimage import median_filter  # here, not at import: `import rwadist` stays light

    typical = median_filter(d, size=window, mode="nearest")
    ratio = d / typical
    bad = np.flatnonzero((ratio > MISSING_PULSE_RATIO) | (ratio < DOUBLE_TRIGGER_RATIO))
    if bad.size:
        i = int(bad[0])
        what = "missing pulse" if ratio[i] > 1 else "double trigger"
        raise DataError(path, f"channel {channel}", f"{what} between t = {edges[i]:.6g} s and {edges[i + 1]:.6g} s "
                        f"(samples {int(round(edges[i] * fs))}-{int(round(edges[i + 1] * fs))}): pulse interval "
                        f"{d[i]:.6g} s is {ratio[i]:.3g} times its neighbours' {typical[i]:.6g} s "
                        f"({ppr} pulse(s) per revolution)")
    return edges


def steady_speed(edges: np.ndarray, ppr: int) -> float:
    """Mean wheel speed of a steady run from its edge times, rad/s (least-squares slope of angle)."""
    angle = 2.0 * np.pi * np.arange(len(edges)) / ppr
    return float(np.polyfit(edges, angle, 1)[0])


def sweep_speed(edges: np.ndarray, ppr: int, time: np.ndarray) -> np.ndarray:
    """Wheel speed at each sample time (s from the first sample), rad/s, shape (n,).

    Local quadratic least squares of angle against edge time around each grid point (window: the
    larger of ``SWEEP_WINDOW_S`` and ``SWEEP_WINDOW_EDGES`` edges), its slope at the grid point.
    """
    angle = 2.0 * np.pi * np.arange(len(edges)) / ppr
    time = np.asarray(time, dtype=float)
    grid = np.arange(time[0], time[-1] + SWEEP_GRID_S, SWEEP_GRID_S)
    half_edges = SWEEP_WINDOW_EDGES // 2
    speed = np.empty(len(grid))
    nearest = np.searchsorted(edges, grid)
    lo_t = np.searchsorted(edges, grid - 0.5 * SWEEP_WINDOW_S)
    hi_t = np.searchsorted(edges, grid + 0.5 * SWEEP_WINDOW_S, side="right")
    lo = np.maximum(0, np.minimum(lo_t, nearest - half_edges))
    hi = np.minimum(len(edges), np.maximum(hi_t, nearest + half_edges))
    for j, (a, b) in enumerate(zip(lo, hi)):
        if b - a < 4:
            a, b = max(0, b - 4), min(len(edges), a + 4)
        centre = 0.5 * (edges[a] + edges[b - 1])  # fit about the window's centre (conditioning)
        coef = np.polyfit(edges[a:b] - centre, angle[a:b], 2)
        speed[j] = coef[1] + 2.0 * coef[0] * (grid[j] - centre)  # d(angle)/dt at the grid point
    return np.abs(np.interp(time, grid, speed))


def _pulse_channel(path, extras: dict, meta: dict, meta_path):
    settings = tach_settings(meta, meta_path)
    if settings is None:
        return None
    channel, ppr = settings
    if channel not in extras:
        raise DataError(path, f"channel {channel}", f"tach channel named in {meta_path} is not in the file")
    return channel, ppr, extras[channel]


def steady_speed_from_tach(path, extras: dict, fs: float, meta: dict, meta_path) -> float:
    """Speed of a steady run from its tach pulse channel, rad/s; DataError when there is none."""
    found = _pulse_channel(path, extras, meta, meta_path)
    if found is None:
        raise DataError(path, "speed_rpm", "runs.csv gives no speed for this run and meta.json names no tach "
                        "channel")
    channel, ppr, x = found
    return steady_speed(pulse_edges(path, channel, x, fs, ppr), ppr)


def sweep_speed_from_tach(path, extras: dict, time: np.ndarray, fs: float, meta: dict, meta_path):
    """Speed at every sample of a sweep from its tach pulse channel, rad/s, or None without one."""
    found = _pulse_channel(path, extras, meta, meta_path)
    if found is None:
        return None
    channel, ppr, x = found
    edges = pulse_edges(path, channel, x, fs, ppr)
    return sweep_speed(edges, ppr, np.asarray(time, dtype=float) - float(time[0]))
