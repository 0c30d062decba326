"""What a described moving resonance reaches beyond its own track (:mod:`rwadist.diagnose.describe_structure`): the
lines it lifts, which hold the residual's content where its wide bands do not; the lines its antiresonance takes down,
which are no source that stops; the rise below it, which an amplitude law was fitted to.

The session-67 new-user trial's structure mode stiffening 294-490 Hz with speed (a mode holding 40 % of the rotor's
mass in the load path of Fx, Fy, Fz; a 4.5-kg wheel) was fitted on its track but said nowhere: its bands held less
than an average patch of the residual, its antiresonance's notch was described as a line that stops ("a rub or a
loose part"), and on one seed its rise below was added as an amplitude law.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..units import DIRECTION_CHANNELS
from .describe_structure import _resonance_db

#: A moving track whose bands hold less than an average patch of the residual is still described when they hold at least
#: this fraction of one (:func:`rwadist.diagnose.describe.holds_content`) ...
TRACK_SHARE_FLOOR = 0.25
#: ... and the cells of the lines it lifts (their band in their run) hold at least this many times their own fraction
LIFTED_CONTENT_FACTOR = 3.0


def lifted_hold(u, res, total: int) -> bool:
    """Whether the cells of the points a ``moving_resonance`` record lifts (``lifted_rpm``, ``lifted_Hz``: each line's
    band in its run, in the record's channels) hold :data:`LIFTED_CONTENT_FACTOR` times their own fraction of the
    waterfall's cells' share of the misplaced power left.

    A track's bands (±3ζ about it in every run) are wide, and where little else of a run's spectrum is misplaced they
    hold less than an average patch even when the lines the track lifts are the residual's clearest content: the
    session-67 trial's resonance stiffening 294-490 Hz on Fx, Fy, Fz of a 4.5-kg wheel (ζ 0.03) held 0.77 % of what was
    left on 1.43 % of the cells, its lifted lines 0.98 % on 0.098 %, and nothing was said of it (the lines in its
    antiresonance were described as a source stopping).  A track through lines the model matches (family wheel 7's
    speed sidebands read against their carrier) lifts nothing the residual holds there."""
    ctx = res.ctx
    rpm = np.abs(ctx.omega[ctx.runs]) * 60.0 / (2 * np.pi)
    p = u.parameters
    rows = [int(np.argmin(np.abs(rpm - abs(x)))) for x in p.get("lifted_rpm", ())]
    cells = {}
    for c in u.channels:
        if c in res.e:
            m = res.mask(c)
            for row, f in zip(rows, p.get("lifted_Hz", ())):
                m[row, res.band_of(f)] = True
            cells[c] = m
    n = sum(int(np.sum(m)) for m in cells.values())
    return n > 0 and res.measure(cells)[0] >= LIFTED_CONTENT_FACTOR * n / total


def _shape_db(track, h: float, spin) -> np.ndarray:
    """20·log10 |H| of the ``moving_resonance`` record ``track``'s fitted shape (``zeta``, ``peak_gain``,
    ``gain_far_above``) on its track at the line of ratio ``h`` at spin frequencies ``spin`` (Hz, |Ω|/2π; the track
    extended straight past its own speeds); NaN where the track is at or below 0 Hz or its speeds span nothing."""
    p = track.parameters
    s_lo, s_hi = abs(track.speed_rpm[0]) / 60.0, abs(track.speed_rpm[1]) / 60.0
    spin = np.asarray(spin, dtype=float)
    if not s_hi > s_lo:
        return np.full(spin.shape, np.nan)
    f_r = p["f_at_lowest_speed_Hz"] + (p["f_at_highest_speed_Hz"] - p["f_at_lowest_speed_Hz"]) * (spin - s_lo) / (s_hi - s_lo)
    db = _resonance_db(h * spin, np.maximum(f_r, 1e-300), float(p["zeta"]), float(p["peak_gain"]),
                       float(p["gain_far_above"]))
    return np.where(f_r > 0, db, np.nan)


#: A ``partial_line`` is a described moving resonance's notch when the resonance's fitted shape takes the line down by
#: this much (dB, median over the runs it is absent from) ...
NOTCH_DB = 6.0
#: ... and changes it by no more than this (dB, median) in the runs it is present in
NOTCH_PRESENT_DB = 3.0


def without_notched_lines(records: list) -> list:
    """``records`` without the ``partial_line`` records that a described ``moving_resonance`` of one of their channels
    takes down: its fitted shape (``zeta``, ``peak_gain``, ``gain_far_above``) on its track, evaluated at the line's
    frequency, lowers the line by :data:`NOTCH_DB` or more (median) in the runs it reads as absent and by at most
    :data:`NOTCH_PRESENT_DB` in the runs it is present in, those runs within the track's speeds.  The line is then
    the resonance's antiresonance passing it (a mode holding a share of the rotor's mass: 1 − μr²/(r² − 1) above it),
    not a source that stops; the resonance's record lists it (``notched_lines``).  The session-67 trial's resonance
    stiffening 294-490 Hz (μ 0.4) on a 4.5-kg wheel took its h 7.524 line 9-16 dB down above 4100 rpm, and that was
    described as "a source that starts or stops at one speed: a rub or a loose part"."""
    tracks = [u for u in records if u.signature == "moving_resonance" and "gain_far_above" in (u.parameters or {})]
    if not tracks:
        return records
    notched: dict = {}
    kept = []
    for u in records:
        m, down = next(((t, d) for t in tracks if u.signature == "partial_line" and set(u.channels) & set(t.channels)
                        and (d := _notch_db(u, t)) is not None), (None, None))
        if m is None:
            kept.append(u)
        else:
            notched.setdefault(id(m), []).append({"h": float(u.parameters["h"]), "speed_rpm": list(u.speed_rpm),
                                                  "absent_rpm": list(u.parameters["absent_rpm"]), "shape_dB": down})
    return [replace(u, parameters=dict(u.parameters) | {"notched_lines": notched[id(u)]}) if id(u) in notched else u
            for u in kept]


def _notch_db(line, track) -> float | None:
    """The median change (dB) the ``moving_resonance`` record ``track``'s shape makes to the ``partial_line`` record
    ``line`` in the runs it is absent from, when that is a notch (:func:`without_notched_lines`), else None."""
    q = line.parameters
    s_lo, s_hi = track.speed_rpm[0] / 60.0, track.speed_rpm[1] / 60.0
    absent = np.abs(np.asarray(q.get("absent_rpm", []), float)) / 60.0
    present = np.abs(np.asarray(q.get("present_rpm", []), float)) / 60.0
    inside = (absent >= s_lo - 1e-9) & (absent <= s_hi + 1e-9)
    if absent.size == 0 or inside.mean() < 2.0 / 3.0:
        return None
    h = float(q["h"])
    down = float(np.median(_shape_db(track, h, absent[inside])))
    up = float(np.median(_shape_db(track, h, present))) if present.size else 0.0
    return down if down <= -NOTCH_DB and abs(up) <= NOTCH_PRESENT_DB else None


#: An amplitude law is a described moving resonance's skirt when the resonance's shape changes its line, from the
#: track's lowest speed to its highest, by at least this share of what the law changes it by against Ω² (same sign)
SKIRT_SHARE = 1.0 / 3.0


def on_a_moving_skirt(effect, found) -> str | None:
    """"moving_resonance" when ``effect`` is an ``amplitude_law`` of a line on a channel of a described moving
    resonance whose fitted shape (``zeta``, ``peak_gain``, ``gain_far_above`` on its track) lifts or lowers that line
    across the track's speeds by :data:`SKIRT_SHARE` or more of what the law's exponent does there (20·(p − 2)·log10 of
    the speeds' ratio, dB), in the same sense: the law was fitted to the rise below the resonance.  The session-67
    trial's mode stiffening 294-490 Hz (μ 0.4) lifts the h 2 line below it 0.7 dB at 6000 rpm; an Ω^2.06 law (1.1 dB
    over 774-5987 rpm) was added on one of two seeds.  A source's own law (Ω^2.5: 9 dB over a 7.7x speed span) is far
    more than a skirt."""
    if getattr(effect, "kind", "") != "amplitude_law":
        return None
    chans = set(DIRECTION_CHANNELS.get(effect.direction, ()))
    for u in found:
        p = u.parameters or {}
        if u.signature != "moving_resonance" or not chans & set(u.channels) or "gain_far_above" not in p:
            continue
        s_lo, s_hi = abs(u.speed_rpm[0]) / 60.0, abs(u.speed_rpm[1]) / 60.0
        if not s_hi > s_lo > 0:
            continue
        shape = _shape_db(u, effect.h, np.array([s_lo, s_hi]))
        law = 20.0 * (effect.exponent - 2.0) * np.log10(s_hi / s_lo)
        change = float(shape[1] - shape[0])
        if law != 0 and change * law > 0 and abs(change) >= SKIRT_SHARE * abs(law):
            return u.signature
    return None


def with_track_causes(records: list) -> list:
    """``records`` with a first cause added to each ``line_property`` of an amplitude law (``exponent``) on a line
    whose change a described ``moving_resonance`` of one of its channels makes: its fitted shape on its track changes
    the line from the record's lowest speed to its highest by at least :data:`SKIRT_SHARE` of what the law's exponent
    does against Ω² (dB), in the same sense.  The session-67 trial's structure mode stiffening 294-490 Hz lifted the
    h 5.238 line through its crossing at ~5300 rpm (+5.9 dB of the law's 16) and h 3.762 below it (+3.8 of 4.7), and
    both were said to grow as Ω^2.75 and Ω^2.22: "a bearing defect's impacts"."""
    tracks = [u for u in records if u.signature == "moving_resonance" and "gain_far_above" in (u.parameters or {})]
    if not tracks:
        return records
    out = []
    for u in records:
        p = u.parameters or {}
        track, change = None, None
        if u.signature == "line_property" and p.get("property") == "amplitude_law" and u.h is not None:
            track, change = next(((t, c) for t in tracks if set(u.channels) & set(t.channels) and
                                  (c := _track_change(t, float(u.h), u.speed_rpm, float(p.get("exponent", 2.0))))
                                  is not None), (None, None))
        if track is None:
            out.append(u)
            continue
        lo, hi = track.f_Hz
        out.append(replace(u, causes=(f"the moving resonance described on {' '.join(track.channels)} ({lo:.4g}-{hi:.4g} "
                                      f"Hz): its shape on its track reads as a change of this line by {change:+.1f} dB from "
                                      f"{u.speed_rpm[0]:.0f} to {u.speed_rpm[1]:.0f} rpm, not its source",) + u.causes))
    return out


def _track_change(track, h: float, speed_rpm: tuple, exponent: float) -> float | None:
    """The change (dB) the ``moving_resonance`` record ``track``'s shape makes to the line at ratio ``h`` over
    ``speed_rpm`` (its track extended straight past its own speeds), read as a law reads it: the slope of the shape's dB
    on log10 of the speed at 24 speeds across the range, times the range's decades.  Returned when that slope is at
    least :data:`SKIRT_SHARE` of the law's own, 20·(``exponent`` − 2) dB per decade, in the same sense; else None."""
    lo, hi = (abs(float(x)) / 60.0 for x in speed_rpm)
    if not hi > lo > 0 or exponent == 2.0:
        return None
    spin = np.geomspace(lo, hi, 24)
    shape = _shape_db(track, h, spin)
    if not np.all(np.isfinite(shape)):
        return None
    slope = float(np.polyfit(np.log10(spin), shape, 1)[0])
    law = 20.0 * (exponent - 2.0)
    if slope * law > 0 and abs(slope) >= SKIRT_SHARE * abs(law):
        return slope * float(np.log10(hi / lo))
    return None
