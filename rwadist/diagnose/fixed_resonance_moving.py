"""A proposed fixed resonance that moves with the speed: the runs its speed split reads, the resonances in its reach.

:func:`rwadist.effects.fixed_resonance_diagnose.speed_split` reads a proposed ``fixed_resonance`` on the slower and the
faster half of the runs and refuses it when the two halves want centres apart.  A half whose lines all lie under the
resonance's reach cannot place a centre (:func:`straddles`), and the split told nothing: the resonance was kept.  A
resonance far above the slower runs' lines is reached only by the faster runs' highest orders, and one moving with the
speed there was added as a fixed one (the session-68 new-user trial: a structure resonance falling 512 -> 400 Hz over
200-4200 rpm on every channel of a 12-kg wheel, its lines reaching 400-500 Hz only above ~2400 rpm, was named a 'test
stand' at 421.5 Hz: the slower half of the runs, 200-2200 rpm, held no point within its reach).  The runs that reach it
(:func:`runs_in_reach`: their lines span its peak) are then split instead: theirs are the only lines that place its
centre.  Refused so on every channel, the same resonance is proposed on one direction's lines, which may cross it in a
few runs only (that trial's radial torques: h 6.69 alone, a 'wheel mode' at 399 Hz): it is not proposed within the
moving one's reach (:func:`in_moving_reach`).
"""
from __future__ import annotations

import numpy as np

#: Fewest points a half of the runs gives, and fewest the two give together, for the split to place two centres
HALF_MIN_POINTS, SPLIT_MIN_POINTS = 3, 8
#: A resonance reaches this many of its half-power half-widths ζ about its centre (relatively): the bands ±3ζ a
#: ``moving_resonance``'s track holds (rwadist.diagnose.describe); a line there lies on its peak
REACH_WIDTHS = 3.0


def straddles(e, f: np.ndarray) -> bool:
    """Whether lines at ``f`` (Hz) place the centre of the resonance ``e``: some below it and some above it where it
    changes their power by 1.5x or more.  A half of the runs whose lines reach only one skirt cannot (the new-user
    trial of session 54: a fixture at 800 Hz crossed only by the lines of the runs above 5450 rpm, the slower half's
    skirt put its centre 11 % from the faster half's, ζ 0.0045, and the fixture was refused as moving with the speed)."""
    from ..stand_detect import STAND_MIN_LOG_GAIN, log_power_gain

    near = f[np.abs(log_power_gain(e, f)) >= STAND_MIN_LOG_GAIN]
    return bool(np.any(near < e.f_r) and np.any(near > e.f_r))


def runs_in_reach(e, f: np.ndarray, h: np.ndarray, runs: np.ndarray, spin_hz: np.ndarray) -> np.ndarray:
    """The runs of ``runs`` whose lines do not all lie on one side of the peak of the resonance ``e``.

    Parameters
    ----------
    e : FixedResonance
        The proposed resonance (its ``f_r`` Hz and ``zeta``).
    f : numpy.ndarray
        Each line point's frequency (Hz) on ``runs``.
    h : numpy.ndarray
        Each point's line's ratio to the speed (f = h·f_spin): its run is the one of spin f/h.
    runs : numpy.ndarray
        The runs the points were read on (positions).
    spin_hz : numpy.ndarray
        Each of ``runs``' spin frequency |Ω|/2π (Hz).

    Returns
    -------
    numpy.ndarray
        The runs (in ``runs``' order) with a line point at f_r·(1 − :data:`REACH_WIDTHS`·ζ) or above and one at
        f_r·(1 + :data:`REACH_WIDTHS`·ζ) or below: the peak lies within their lines' span.  A run whose lines all lie
        under it reads its skirt alone (changed by 1.5x or more far below f_r: from 0.65 f_r under a mode holding 30 %
        of the load), and a half of such runs places no centre.
    """
    if f.size == 0:
        return runs[:0]
    of_run = np.argmin(np.abs(np.log(f / h)[:, None] - np.log(np.maximum(spin_hz, 1e-300))[None, :]), axis=1)
    lo, hi = e.f_r * (1 - REACH_WIDTHS * e.zeta), e.f_r * (1 + REACH_WIDTHS * e.zeta)
    f_top = np.full(runs.size, -np.inf)
    f_bottom = np.full(runs.size, np.inf)
    np.maximum.at(f_top, of_run, f)
    np.minimum.at(f_bottom, of_run, f)
    return runs[(f_top >= lo) & (f_bottom <= hi)]


def _halves_of(ctx, e, points, runs: np.ndarray, min_runs: int) -> list | None:
    """(f, y, w) of ``points`` on the slower and on the faster half of ``runs``, or None (:func:`split_halves`)."""
    half = runs.size // 2
    if half < min_runs:
        return None
    order = np.argsort(np.abs(ctx.omega[runs]), kind="stable")
    parts = [points(np.sort(runs[o]))[:3] for o in (order[:half], order[-half:])]
    if min(p[0].size for p in parts) < HALF_MIN_POINTS or sum(p[0].size for p in parts) < SPLIT_MIN_POINTS:
        return None
    return parts if all(straddles(e, p[0]) for p in parts) else None


def split_halves(ctx, e, points, min_runs: int) -> list | None:
    """The line points of the slower and of the faster half of the runs that place the centre of ``e``.

    Parameters
    ----------
    ctx : Context
        The diagnosis (its ``runs`` and ``omega``, rad/s).
    e : FixedResonance
        The proposed resonance.
    points : callable
        ``points(runs, with_lines=False)``: the line points of ``e``'s channels on ``runs``
        (:func:`rwadist.effects.fixed_resonance_diagnose._line_gain_points`: f Hz, y, w, direction, and with the
        lines each point's line id, the lines (direction, h) and its predicted power).
    min_runs : int
        Fewest runs a half holds.

    Returns
    -------
    list or None
        [(f, y, w) of the slower half, (f, y, w) of the faster half]: the halves of every run, else the halves of
        :func:`runs_in_reach` (a half whose lines all lie under the resonance's reach places no centre); None when
        neither pair holds :data:`HALF_MIN_POINTS` points on each half, :data:`SPLIT_MIN_POINTS` on both, lines on
        both sides of the centre on each (:func:`straddles`), and ``min_runs`` runs on each.
    """
    runs = np.asarray(ctx.runs)
    parts = _halves_of(ctx, e, points, runs, min_runs)
    if parts is not None or runs.size // 2 < min_runs:
        return parts
    f, _, _, _, ids, keys, _ = points(runs, with_lines=True)
    if f.size == 0:
        return None
    h = np.array([keys[i][1] for i in ids], dtype=float)
    reached = runs_in_reach(e, f, h, runs, np.abs(ctx.omega[runs]) / (2 * np.pi))
    return _halves_of(ctx, e, points, reached, min_runs)


def in_moving_reach(e, moving) -> bool:
    """Whether the proposed resonance ``e`` lies within the reach of one refused as moving with the speed.

    Parameters
    ----------
    e : FixedResonance
        The proposed resonance (its ``f_r`` Hz and ``channels``).
    moving : list
        (resonance, split) of each resonance refused as moving: the split's ``f_slow_Hz``, ``f_fast_Hz`` and
        ``zeta`` (:func:`rwadist.effects.fixed_resonance_diagnose.speed_split`).

    Returns
    -------
    bool
        True when a refused one holds every channel of ``e`` and more (a resonance of every channel refused as
        moving, ``e`` one direction's) and ``e``'s centre lies between its two halves' centres, widened by
        :data:`REACH_WIDTHS` × ζ on either side: one direction's lines crossing the moving resonance in a few runs,
        which place one centre only.  A resonance of as many channels is judged by its own split: a fixture on every
        channel is not refused for a moving resonance of one direction beside it.
    """
    for m, s in moving:
        if not set(e.channels) < set(m.channels):
            continue                    # a resonance of fewer channels than the moving one's (a stand is no direction's)
        lo, hi = sorted((s["f_slow_Hz"], s["f_fast_Hz"]))
        widen = REACH_WIDTHS * s["zeta"]
        if lo * (1 - widen) <= e.f_r <= hi * (1 + widen):
            return True
    return False
