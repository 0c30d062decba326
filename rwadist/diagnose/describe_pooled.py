"""A resonance moving with the speed on the lines of several directions at once: one track fitted on every direction's
line ratios pooled (a ``moving_resonance`` record over every channel whose lines it lifts).

:func:`.describe_structure.moving_resonance` fits one direction's lines at a time.  A structure under the load cell
(or a resonance of the load path every channel reads) lifts the lines of every direction, and on a wheel whose
directions hold a few lines each, each direction's lines cross it once or twice: no direction reads its slope.  The
session-68 new-user trial's resonance falling 512 -> 400 Hz over 200-4200 rpm on all six channels of a 12-kg wheel
(μ 0.3, ζ 0.03): the radial torques' track F 5.0 (15 needed), the axial force's −1.6, the axial torque's F 31 but
slope +0.65 for −1.68 and 0.08 % of what was left; nothing was described, and the lines' rise below it was added as
amplitude laws (h 4.31 Ω^2.2 on Fz and on Tx, Ty; on the 6-kg wheel, 300-6000 rpm, the radial force's h 2 Ω^2.07 and
the axial force's h 3.62 Ω^2.27).  Pooled (each line of each direction its own offset), the lines place one track:
F 1632, 0.16 of the best fixed resonance's misfit, 491 -> 406 Hz; on the 6-kg wheel F 3958, 506 -> 404 Hz.

The pooled track is judged as a direction's (:func:`.describe_structure._moving_fit`: the F statistic, the misfit
ratios, a move over the speeds wider than its half-power width) and must lift the lines of
:data:`POOL_MIN_DIRECTIONS` directions (one direction's track is that direction's fit's to describe); it is not the
fitted rocking whirl when it lifts radial lines alone.  Its record takes the place of the single directions' records
on its track (:func:`moving_resonances`): they are its pieces.
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS
from . import describe_structure as structure
from .describe_mode_drift import same_track
from .describe_structure import MOVING_GATE_DB, MOVING_PEAK_DB, LineRatios
from .describe_whirl import whirl_note
from .unexplained import Unexplained

#: The pooled track describes a resonance of this many directions at least (the directions whose lines it lifts): a
#: track lifting one direction's lines is that direction's own fit's (:func:`.describe_structure.moving_resonance`)
POOL_MIN_DIRECTIONS = 2
#: ... and is fitted beside single directions' records that describe every lifted direction when they are this many:
#: one resonance of the whole load path read on each (the session-69 trial, every channel: four records).  Two are
#: left as they are (tests/test_moving_structure_mode.py: a mode in the path of Fx, Fy and Fz, its Fx Fy record's
#: antiresonance and the line laws it explains read on that direction's own track)
POOL_SAID_DIRECTIONS = 3
#: The ``direction`` parameter of a pooled record (its ``directions``: the directions whose lines it lifts)
POOLED = "pooled"
#: The radial directions, whose lines alone the rocking mode's whirl lifts (:func:`.describe_whirl.whirl_note`)
RADIAL = frozenset(("radial_force", "radial_torque"))
#: A single direction's track is a piece of the pooled one when both its ends lie within this many of the pooled
#: track's half-power half-widths ζ of it (relatively): the bands ±3ζ a track's cells hold (:func:`.describe.cells_of`)
SAME_TRACK_WIDTHS = 3.0
#: ... or when at least this fraction of the points it lifts are lifted by the pooled one (a track of their own)
PIECE_FRACTION = 2.0 / 3.0
#: Two lifted points are the same line in the same run when their speeds and frequencies agree to this (log): the
#: records' lifted points are the lines' own readings, equal where they are one reading
SAME_POINT = 1e-6


def pooled_ratios(ratios: list) -> tuple[LineRatios, np.ndarray] | None:
    """The :class:`~.describe_structure.LineRatios` of every direction pooled (direction :data:`POOLED`; each
    direction's lines numbered on, so that each keeps its own offset) and each point's direction (an array of
    names); None with fewer than :data:`POOL_MIN_DIRECTIONS` directions holding points."""
    held = [r for r in ratios if r.q.size]
    if len(held) < POOL_MIN_DIRECTIONS:
        return None
    first = np.cumsum([0] + [int(r.line.max()) + 1 for r in held[:-1]])
    cat = {k: np.concatenate([getattr(r, k) for r in held]) for k in ("q", "f", "run", "spin", "h", "w")}
    line = np.concatenate([r.line + o for r, o in zip(held, first)])
    of = np.concatenate([np.full(r.q.size, r.direction, dtype=object) for r in held])
    return LineRatios(POOLED, line=line, **cat), of


def _lifted_directions(r: LineRatios, of: np.ndarray, track: tuple) -> list:
    """The directions (in :data:`~rwadist.units.DIRECTION_CHANNELS`' order) with a point the fitted ``track`` (f0,
    slope, ζ, gain, gain above) changes as the data read it (:func:`_changed`): the lines it lifts or notches."""
    return [d for d in DIRECTION_CHANNELS if np.any(_changed(r, track) & (of == d))]


def _changed(r: LineRatios, track: tuple) -> np.ndarray:
    """The points of ``r`` that the fitted ``track`` (f0, slope, ζ, gain, gain above) changes by
    :data:`~.describe_structure.MOVING_PEAK_DB` or more and that the data read changed as much, in the same sense: the
    lines it lifts by much (the lift a direction's lines must show for a resonance to be looked for), and those its
    antiresonance takes down.  A skirt's 2 dB far below the track is read by the fit, not said to be its reach."""
    g = structure._track_db(r, *track)
    return (np.abs(g) >= MOVING_PEAK_DB) & (np.abs(r.q) >= MOVING_PEAK_DB) & (g * r.q > 0)


def _read_span(r: LineRatios, changed: np.ndarray) -> tuple[float, float]:
    """(lowest, highest) spin (Hz) of the longest stretch of consecutive runs of ``r`` (by speed) each holding a point
    of ``changed`` (the points the track changes: :func:`_changed`): the speeds its lines read it at.  Below them the
    track is its slope carried on, read by no line, and its bands there hold the noise alone (the session-68 trial's
    wheel B, 200-4200 rpm, whose lines reach 400-500 Hz above ~2300 rpm only; a track's record is described where its
    bands hold their share of what is left, :func:`.describe.holds_content`); a run read apart from the stretch (one
    line lifted in it, the runs above it reading none) does not stretch it."""
    spin = np.unique(r.spin)
    hit = np.isin(spin, r.spin[changed])
    best, start, out = 0, 0, (float(spin[hit][0]), float(spin[hit][0]))
    for k in range(spin.size + 1):
        if k < spin.size and hit[k]:
            continue
        if k - start > best:
            best, out = k - start, (float(spin[start]), float(spin[k - 1]))
        start = k + 1
    return out


def pooled_moving_resonance(ctx, state, ratios: list, shares) -> list:
    """The ``moving_resonance`` record of one track fitted on every direction's line ratios pooled, or none.

    Parameters
    ----------
    ctx : Context
        The diagnosis (its channels).
    state : State
        The final model (its ``suspension_modes``, for the whirl and the modes the track crosses).
    ratios : list
        The :class:`~.describe_structure.LineRatios` of each direction (steady lines resolved from their neighbours,
        as :func:`.describe_structure.moving_resonance` reads them).
    shares : callable
        ``shares(chans, track, zeta)`` -> (share of the misplaced power, level dB) of the track's cells.

    Returns
    -------
    list
        One record (``direction`` :data:`POOLED`, ``directions`` the directions whose lines it lifts, its channels
        theirs) when the pooled points pass a direction's gates (:data:`~.describe_structure.MOVING_PEAK_DB` in one
        run, :data:`~.describe_structure.MOVING_GATE_DB` in two), the track pays as a direction's does
        (:func:`.describe_structure._moving_fit`), lifts the lines of :data:`POOL_MIN_DIRECTIONS` directions and is
        not the fitted rocking whirl; else none.
    """
    pooled = pooled_ratios(ratios)
    if pooled is None:
        return []
    r, of = pooled
    if r.q.size < 8 or not np.any(r.q >= MOVING_PEAK_DB) or np.unique(r.run[r.q >= MOVING_GATE_DB]).size < 2:
        return []
    got = structure._moving_fit(r)
    if got is None:
        return []
    (sse_m, f0, b, zeta, gain, above), misfit_ratio, f_stat, companion = got
    dirs = _lifted_directions(r, of, (f0, b, zeta, gain, above))
    if len(dirs) < POOL_MIN_DIRECTIONS:
        return []
    mid = 0.5 * (r.spin.min() + r.spin.max())
    s_lo, s_hi = _read_span(r, _changed(r, (f0, b, zeta, gain, above)) & np.isin(of, dirs))
    f_low, f_high = f0 + b * (s_lo - mid), f0 + b * (s_hi - mid)
    modes = next((e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"), None)
    if set(dirs) <= RADIAL:
        whirl, explained = whirl_note("radial_torque", b, modes, s_lo, s_hi, f_low, f_high)
        if explained:
            return []
    else:
        whirl = "no gyroscopic whirl moves a resonance of the axial lines (the whirl splits the rocking mode only)"
    return [_record(ctx, r, of, dirs, got, (s_lo, s_hi, modes, whirl, shares))]


def _record(ctx, r: LineRatios, of: np.ndarray, dirs: list, got: tuple, context: tuple) -> Unexplained:
    """The pooled track ``got`` (:func:`.describe_structure._moving_fit`) of the points ``r`` (``of``: each one's
    direction) as a ``moving_resonance`` record over the channels of ``dirs``; ``context``: (its lowest and highest
    speeds, Hz of spin, the fitted ``suspension_modes`` or None, the whirl's words, ``shares``)."""
    (sse_m, f0, b, zeta, gain, above), misfit_ratio, f_stat, companion = got
    s_lo, s_hi, modes, whirl, shares = context
    mid = 0.5 * (r.spin.min() + r.spin.max())
    f_low, f_high = f0 + b * (s_lo - mid), f0 + b * (s_hi - mid)
    chans = tuple(c for d in dirs for c in DIRECTION_CHANNELS[d] if c in ctx.channels)
    track = lambda spin: f0 + b * (spin - mid)                                                      # noqa: E731
    share, level = shares(chans, track, zeta)
    beside: dict = {} if companion is None else {"beside_fixed_resonance_Hz": float(companion[1]),
                                                 "beside_fixed_resonance_peak_gain": float(companion[4])}
    crossed = next((c for d in dirs if (c := structure._crossed_mode(d, modes, track, s_lo, s_hi, (zeta, gain, above)))),
                   None)
    if crossed:
        beside["crosses_fitted_mode"] = crossed
    on = np.isin(of, dirs) & (r.spin >= s_lo) & (r.spin <= s_hi)
    mine = LineRatios(POOLED, **{k: getattr(r, k)[on] for k in ("q", "f", "run", "spin", "line", "h", "w")})
    return Unexplained(
        signature="moving_resonance", channels=chans, speed_rpm=(s_lo * 60.0, s_hi * 60.0),
        f_Hz=(float(min(f_low, f_high)), float(max(f_low, f_high))), level_dB=level, share=share,
        n_runs=int(np.unique(mine.run).size),
        parameters={"direction": POOLED, "directions": list(dirs), "f_at_lowest_speed_Hz": float(f_low),
                    "f_at_highest_speed_Hz": float(f_high), "slope_Hz_per_Hz_of_spin": float(b),
                    "largest_line_lift_dB": float(np.max(mine.q)), **structure._lifted(mine),
                    "zeta": float(zeta), "peak_gain": float(gain), **structure._shape_words(zeta, gain, above),
                    "fixed_resonance_misfit_ratio": float(misfit_ratio), "f_statistic": float(f_stat),
                    "whirl": whirl, **beside},
        causes=("a resonance of the structure every direction's load passes through (the load cell's mount, a test "
                "stand's or the housing's), its stiffness changing with the speed or the test",)
        + structure._moving_causes(b, "stiffening" if b > 0 else "softening", float(track(mid)), float(mid)),
        would_tell=structure._crossing_words(crossed) + "a slow run-up recorded with its speed tracks the resonance "
                   "continuously; a tap test of the wheel on its mount, and of the mount alone, at rest")


def _on_track(u: Unexplained, pooled: Unexplained) -> bool:
    """Whether the single direction's ``moving_resonance`` record ``u`` is a piece of the ``pooled`` one: its channels
    among the pooled record's, and both its ends within :data:`SAME_TRACK_WIDTHS` half-power half-widths of the pooled
    track at its own speeds, or :data:`PIECE_FRACTION` of the points it lifts lifted by the pooled one (the same line
    in the same run: one direction's lines crossing the resonance read as a track of their own beside a fixed one; the
    session-68 trial's 6-kg wheel, seed 2: "175 -> 376 Hz" on Fz through the axial lines the pooled track lifts)."""
    p, q = u.parameters, pooled.parameters
    if not set(u.channels) <= set(pooled.channels) or "f_at_lowest_speed_Hz" not in p:
        return False
    s_lo, s_hi = pooled.speed_rpm[0] / 60.0, pooled.speed_rpm[1] / 60.0
    f_lo, f_hi = q["f_at_lowest_speed_Hz"], q["f_at_highest_speed_Hz"]
    spin = np.array(u.speed_rpm, float) / 60.0
    f_pool = f_lo + (f_hi - f_lo) * (spin - s_lo) / max(s_hi - s_lo, 1e-12)
    ends = np.array([p["f_at_lowest_speed_Hz"], p["f_at_highest_speed_Hz"]], float)
    if np.all(np.abs(np.log(ends / np.maximum(f_pool, 1e-12))) <= SAME_TRACK_WIDTHS * q["zeta"]):
        return True
    mine = np.array([p.get("lifted_rpm", []), p.get("lifted_Hz", [])], float).T
    theirs = np.array([q.get("lifted_rpm", []), q.get("lifted_Hz", [])], float).T
    if mine.size == 0 or theirs.size == 0:
        return False
    same = np.all(np.abs(np.log(mine[:, None, :] / theirs[None, :, :])) <= SAME_POINT, axis=2).any(axis=1)
    return bool(same.mean() >= PIECE_FRACTION)


def moving_resonances(ctx, state, ratios: list, shares, holds, drifting: list) -> list:
    """The ``moving_resonance`` records of the lines' resonances moving with the speed.

    Parameters
    ----------
    ctx, state
        The diagnosis and its final model.
    ratios : list
        The :class:`~.describe_structure.LineRatios` of each direction (steady lines resolved from their neighbours).
    shares : callable
        ``shares(chans, track, zeta)`` -> (share of the misplaced power, level dB) of a track's cells.
    holds : callable
        ``holds(record)``: whether the record's cells hold content (:func:`.describe.holds_content`).
    drifting : list
        The records of the model's own modes moving (:func:`.describe_mode_drift.drifting_modes`): a track on a
        drifting mode's direction reaching it is that mode's rise (:func:`.describe_mode_drift.same_track`).

    Returns
    -------
    list
        Each direction's records (:func:`.describe_structure.moving_resonance`) that hold content and are no drifting
        mode's rise; when they leave a direction with lines lifted by :data:`~.describe_structure.MOVING_GATE_DB`
        undescribed, or describe :data:`POOL_SAID_DIRECTIONS` directions or more (one resonance every direction reads
        is described on each: the session-69 trial's 150 + 0.9·f_spin Hz on every channel, four records on Fx Fy, Tx
        Ty, Fz and Tz), the pooled one (:func:`pooled_moving_resonance`) too, which takes
        the place of the single directions' records on its track (:func:`_on_track`: its pieces).
    """
    def keep(u) -> bool:
        return holds(u) and not any(same_track(u, v) for v in drifting)

    single = [u for u in structure.moving_resonance(ctx, state, ratios, shares) if keep(u)]
    said = {u.parameters.get("direction") for u in single}
    if len(said) < POOL_SAID_DIRECTIONS and all(r.direction in said or not np.any(r.q >= MOVING_GATE_DB) for r in ratios):
        return single
    pooled = [u for u in pooled_moving_resonance(ctx, state, ratios, shares) if keep(u)]
    return [u for u in single if not any(_on_track(u, p) for p in pooled)] + pooled
