"""Detector of the open world (issue 33, item 3) on the final model's residual: lines at a fixed line's frequency
plus or minus a constant ratio of the speed (a ``sideband_line``), the fixed line's modulation by the rotation.

A fixed line of the wheel's electronics (an inverter's switching frequency, a PWM carrier) is modulated by the
motor's electrical frequency, a multiple of the speed: its sidebands sit at f = f_c ± h·|Ω|/2π.  They are neither at
one fixed frequency nor at a constant ratio of the speed, so neither the fixed lines found before the search
(:mod:`.fixed_lines`) nor a ``speed_line`` holds them, and a new user's inverter at 400 Hz had its ±spin sidebands
(0.35 of it) passed over in silence (trial15, finding 8).  Found as a ridge of lit bins (:func:`.describe_lines._lit`)
along f = f_c ± h·|Ω|/2π in the fixed line's channels, for each fixed line f_c found: an h lit in at least
:data:`~.describe_lines.RIDGE_FRACTION` of the runs where that track lies in the band and more than
:data:`CARRIER_BINS` Welch bins from the carrier, :data:`~.describe_lines.RIDGE_RUNS` runs at least, its ratio read on
the whole records (:func:`_stretch_h`), the two sides of one h one record.  A lower side whose f_c − h·|Ω|/2π falls below 0 Hz is at its absolute value (a
real signal's line at −f is at f): the track folds at 0 Hz (review16, a 50 Hz carrier's −1·f_spin side above
3000 rpm, left in the records, made a phantom moving resonance).

As the fixed lines themselves, sidebands that stand out of the data before any model are found before the search
(:func:`find_sidebands`, on the Welch PSDs over each run's block floor) and taken out of the records it reads
(:func:`rwadist.diagnose.fixed_lines.remove_fixed_lines`, each run's own whole-record phasor at its frequency): left
in, the search forced them into a class (the open-world benchmark's wheel 7, 1000-10000 rpm, an inverter at 1020 Hz
with ±4·f_spin sidebands sweeping 353-1687 Hz through the wheel's lines: an amplitude law added).  What the search's
residual still holds along a carrier's tracks is read after it (:func:`sideband_lines`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..units import RAD_S_TO_RPM
from .describe_lines import (
    H_STEP_BINS,
    MIN_LEVEL_DB,
    RIDGE_FRACTION,
    RIDGE_RUNS,
    _lit,
    log_parabola_offset,
    ratio_resolution,
)
from .unexplained import Unexplained

#: Welch bins from the carrier within which a run's sideband bin is not read (the carrier's own leakage)
CARRIER_BINS = 3
#: A side read on the residual without its pair stands this much over the block floor in its own bin (dB, the
#: median over its lit runs in its best channel): noise reads 0 ± 1 dB there
SIDE_ALONE_DB = 3.0
#: Largest ratio h searched (a motor's pole pairs times a few harmonics of its electrical frequency)
MAX_H = 12.0


@dataclass(frozen=True)
class Sideband:
    """One side of a fixed line's modulation found before the search: the line at f_c + side·h·|Ω|/2π.

    f_Hz : the carrier's frequency, Hz.  side : −1 or +1.  h : the ratio to the speed.  channels : the carrier's.
    runs : the runs (indices of the test) where it is lit.  level_dB : its median PSD over the block floor in its bin
    over those runs, dB.  lit_fraction : the share of the in-band runs where it is lit.  f_runs : its frequency in every run of the test (Hz; NaN where it is not taken out: a run
    not read, within :data:`CARRIER_BINS` of the carrier, out of the band).  amplitudes : its complex amplitude
    (every run of the test, the channels; :func:`rwadist.diagnose.fixed_lines.run_amplitudes`)."""

    f_Hz: float
    side: float
    h: float
    channels: tuple
    runs: tuple
    level_dB: float
    lit_fraction: float
    f_runs: np.ndarray = field(repr=False, compare=False)
    amplitudes: np.ndarray = field(repr=False, compare=False)


def _tracks(ctx, f_c: float, chans, lit: dict, known=()) -> list:
    """The sidebands of the carrier ``f_c`` in ``chans``: [(side, h, lit runs, lit fraction)], strongest ridge first.
    ``lit``: channel -> bool (runs of the context, bins) of the lit bins; ``known``: tracks already taken [(side, h,
    runs, fraction)] (their shadows are no candidates; not returned)."""
    runs = ctx.runs
    spin = ctx.omega[runs] / (2 * np.pi)
    dh = H_STEP_BINS * ctx.df / float(spin.max())
    h_grid = np.arange(0.25, MAX_H, dh)
    rows = np.arange(runs.size)[None, :]
    cands = []
    for side in (-1.0, 1.0):
        f = np.abs(f_c + side * np.outer(h_grid, spin))                                       # (H, R)
        k = np.rint(f / ctx.df).astype(int)
        inb = (k >= ctx.k_lo) & (k <= ctx.k_hi) & (np.abs(f - f_c) > CARRIER_BINS * ctx.df)
        hit = np.zeros(k.shape, bool)
        for c in chans:
            hit |= lit[c][rows, np.clip(k, 0, ctx.f.size - 1)]
        n_in = inb.sum(1)
        frac = np.where(n_in >= RIDGE_RUNS, (hit & inb).sum(1) / np.maximum(n_in, 1), 0.0)
        # a strong line lights its Welch bin's neighbours over a range of h (a plateau of frac): each stretch of
        # h over the ridge level is one candidate, its line found on the whole records over the stretch
        over = np.r_[False, frac >= RIDGE_FRACTION, False]
        edges = np.flatnonzero(np.diff(over.astype(int)))
        for a, b in zip(edges[::2], edges[1::2]):
            i = a + int(np.argmax(frac[a:b]))
            cands.append((float(frac[i]), side, (float(h_grid[a]), float(h_grid[b - 1])), hit[i] & inb[i]))
    accepted: list[tuple] = list(known)
    for frac_i, side, (h_a, h_b), on in sorted(cands, key=lambda x: -x[0]):
        h = _stretch_h(ctx, chans, runs[on], h_a, h_b, f_c, side)
        if h is None or _shadow(ctx, f_c, side, h, runs[on], accepted):
            continue
        accepted.append((side, h, runs[on], frac_i))
    return accepted[len(known):]


def _pairs(tracks, dh: float) -> list:
    """``tracks`` [(side, h, ...)] grouped: the two sides of one ratio (within 4 grid steps ``dh``) one group."""
    groups: list[list] = []
    for a in tracks:
        g = next((g for g in groups if abs(g[0][1] - a[1]) <= 4 * dh and all(x[0] != a[0] for x in g)), None)
        (g.append(a) if g is not None else groups.append([a]))
    return groups


def find_sidebands(ctx, fixed) -> list:
    """The :class:`Sideband` of the fixed lines ``fixed`` (:class:`~rwadist.diagnose.fixed_lines.FixedLine`) in the
    context's data as given, before any model: bins lit over each run's block floor (those of
    :func:`rwadist.diagnose.fixed_lines.find_fixed_lines`) along the carrier's tracks (:func:`_tracks`), kept when
    both sides of one ratio are found and each stands out and is steady (:func:`_measured_side`: a source of its own,
    not wheel lines met on the way), with its amplitude in every run.  A single side is left to the residual's
    reading after the search (:func:`sideband_lines`)."""
    from .fixed_lines import _lit as floor_lit

    runs = ctx.runs
    if runs.size < RIDGE_RUNS or not fixed or ctx.test is None:
        return []
    lit = {}
    for c in ctx.channels:
        ok = np.isfinite(ctx.sp.psd[c][runs, 0])
        m = np.zeros((runs.size, ctx.f.size), bool)
        if ok.any():
            m[ok] = floor_lit(ctx.sp.psd[c][runs[ok]], ctx.floor[c][runs[ok]], ctx.dof)
        lit[c] = m
    dh = H_STEP_BINS * ctx.df / float(ctx.omega[runs].max() / (2 * np.pi))
    out = []
    for ln in fixed:
        chans = [c for c in ln.channels if c in lit]
        for pair in _pairs(_tracks(ctx, ln.f_Hz, chans, lit), dh) if chans else []:
            # a modulation makes both sides; one side alone over the floor, before any model, may be the wheel's
            # own lines lighting the track (a 50-250 Hz pickup among a wheel's dense low lines: 14 such "sidebands")
            got = [_measured_side(ctx, ln.f_Hz, chans, side, h, on_runs, frac) for side, h, on_runs, frac in pair]
            if len(got) == 2 and all(x is not None for x in got):
                out += got
    return out


def _measured_side(ctx, f_c: float, chans, side: float, h: float, on_runs, frac: float) -> Sideband | None:
    """The :class:`Sideband` f_c + side·h·|Ω|/2π lit in ``on_runs``, or None when its median over those runs stands
    less than :data:`~rwadist.diagnose.fixed_lines.MIN_LEVEL` over the block floor or its amplitude is not steady
    from run to run as a fixed line's (:data:`~rwadist.diagnose.fixed_lines.STEADY_FRACTION` of the runs it is read
    in within :data:`~rwadist.diagnose.fixed_lines.STEADY_RATIO` of the median, in some channel)."""
    from .fixed_lines import MIN_LEVEL, STEADY_FRACTION, STEADY_RATIO, run_amplitudes

    runs = ctx.runs
    f_runs = np.full(len(ctx.test.runs), np.nan)
    f = np.abs(f_c + side * h * ctx.omega[runs] / (2 * np.pi))
    k = np.rint(f / ctx.df).astype(int)
    ok = (k >= ctx.k_lo) & (k <= ctx.k_hi) & (np.abs(f - f_c) > CARRIER_BINS * ctx.df)
    f_runs[runs[ok]] = f[ok]
    level = _level_over_floor(ctx, f_c, chans, side, h, on_runs)
    if not level >= 10 * np.log10(MIN_LEVEL):
        return None
    A = run_amplitudes(ctx, f_runs, chans)
    mag = np.abs(A[runs[ok]])
    read = np.isfinite(mag)
    if not read.any():
        return None             # no run's tone fitted (a wheel line in every window): no source of its own
    med = np.array([np.median(mag[read[:, j], j]) if read[:, j].any() else np.nan for j in range(len(chans))])
    # over every run it is taken out in (a run whose tone was not fitted counts as not steady), as a fixed line's
    within = np.mean((mag <= STEADY_RATIO * med) & (mag >= med / STEADY_RATIO), axis=0)
    if not np.any(within >= STEADY_FRACTION):
        return None
    return Sideband(float(f_c), float(side), float(h), tuple(chans), tuple(int(r) for r in on_runs), level,
                    float(frac), f_runs, A)


def _level_over_floor(ctx, f_c: float, chans, side: float, h: float, on_runs) -> float:
    """The side f_c + side·h·|Ω|/2π's PSD over the block floor in its own Welch bin, dB: the median over ``on_runs``
    (indices of the test), the largest over ``chans``."""
    f = np.abs(f_c + side * h * ctx.omega[np.asarray(on_runs, int)] / (2 * np.pi))
    k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)
    ratio = np.stack([ctx.sp.psd[c][on_runs, k] / np.maximum(ctx.floor[c][on_runs, k], 1e-300) for c in chans])
    return float(np.max(np.nanmedian(10 * np.log10(np.maximum(ratio, 1e-30)), axis=1)))


def measure_track(res, chans, f_hz, runs) -> tuple:
    """(share, level dB) of ``res`` (a :class:`~rwadist.diagnose.describe.Residual`) over the cells of a track: in each
    run of ``runs`` (indices of the test) the band of its frequency ``f_hz`` (Hz, one per run), in ``chans``."""
    pos = {int(r): i for i, r in enumerate(res.ctx.runs)}
    cells = {}
    for c in chans:
        if c in res.e:
            m = res.mask(c)
            m[[pos[int(r)] for r in runs], res.band_of(f_hz)] = True
            cells[c] = m
    return res.measure(cells)


def describe_sidebands(res, sidebands) -> list:
    """``sideband_line`` records of the sidebands found before the search (:func:`find_sidebands`), the two sides of
    one ratio one record, each with its share and level on ``res`` (the final model's residual on the data as given:
    the cells of its band in each run where it is lit)."""
    ctx = res.ctx
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    if not sidebands:
        return []

    def track_shares(chans, f, runs):
        return measure_track(res, chans, f, runs)

    dh = H_STEP_BINS * ctx.df / float(ctx.omega[ctx.runs].max() / (2 * np.pi))
    out = []
    for f_c in dict.fromkeys(sb.f_Hz for sb in sidebands):
        mine = [sb for sb in sidebands if sb.f_Hz == f_c]
        tracks = [(sb.side, sb.h, np.array([r for r in sb.runs if r in pos], int), sb.lit_fraction) for sb in mine]
        for sides in _pairs(tracks, dh):
            rec = _record(ctx, f_c, list(mine[0].channels), sides, track_shares, removed=True, min_level=None)
            if rec is not None:
                out.append(rec)
    return out


def sideband_lines(ctx, state, carriers, track_shares, known=()) -> list:
    """``sideband_line`` records of the residual's lines at f_c ± h·|Ω|/2π around each of ``carriers``
    (:class:`~rwadist.diagnose.fixed_lines.FixedLine`: f_Hz, channels); ``track_shares(chans, f_of_run, runs)`` ->
    (share, level dB) of the cells of a track f_of_run (Hz, one per run of ``runs``) in ``chans``; ``known``: the
    :class:`Sideband` taken out before the search (their tracks not described again)."""
    runs = ctx.runs
    if runs.size < RIDGE_RUNS or not carriers:
        return []
    dh = H_STEP_BINS * ctx.df / float(ctx.omega[runs].max() / (2 * np.pi))
    lit = {c: _lit(ctx, state, c) for c in ctx.channels}
    out: list[Unexplained] = []
    for ln in carriers:
        chans = [c for c in ln.channels if c in lit]
        if not chans:
            continue
        taken = [(sb.side, sb.h, np.array([r for r in sb.runs if r in set(runs.tolist())], int), 1.0)
                 for sb in known if sb.f_Hz == ln.f_Hz]
        for sides in _pairs(_tracks(ctx, ln.f_Hz, chans, lit, taken), dh):
            if len(sides) == 1 and not _level_over_floor(ctx, ln.f_Hz, chans, *sides[0][:3]) >= SIDE_ALONE_DB:
                # a side alone stands out of the data in its own bin (its track is lit where the data pass the model
                # in the bin or a neighbour, in any of the carrier's channels: trial 30b wheel C, the pickup at 120 Hz
                # and 'a side at -0.281x the speed' whose bins sat at -0.3 dB over the floor, the best channel's median)
                continue
            rec = _record(ctx, ln.f_Hz, chans, sides, track_shares)
            if rec is not None:
                out.append(rec)
    return out


def _stretch_h(ctx, chans, runs, h_a: float, h_b: float, f_c: float, side: float) -> float | None:
    """The ratio of the line a stretch [h_a, h_b] of a ridge holds: the maximum over h of the median over ``runs`` of
    Σ|X|² over ``chans`` at f_c + side·h·|Ω|/2π (whole-run transforms), on a grid of one record bin at the runs' top
    speed (a Hann window's main lobe is four wide) over the stretch, then of a quarter bin about it, refined by a
    parabola through the top three points (in log power); None when the power peaks at the quarter-bin grid's edge (no
    line in the stretch: the skirt of another).  The median, not the sum: a track that meets a strong
    line of the wheel in one run (a sideband 400 + 1.02x the speed on a bearing line 3.69x it at the top speed)
    is not pulled onto it."""
    from ..units import CHANNELS

    runs = np.asarray(runs)
    if ctx.test is None or runs.size < 3:
        return None
    w = ctx.omega[runs] / (2 * np.pi)
    cols = [CHANNELS.index(c) for c in chans]

    def power(grid):
        X = ctx.phasors(runs, np.abs(f_c + side * np.outer(w, grid)))[:, :, cols]
        return np.nanmedian(np.nansum(np.abs(X) ** 2, axis=2), axis=0)

    step = max(ratio_resolution(ctx), 1e-9)
    grid = np.arange(h_a, h_b + 1e-12, step)
    h = float(grid[int(np.argmax(power(grid)))])
    fine = h + np.arange(-4, 5) * 0.25 * step
    p = power(fine)
    j = int(np.argmax(p))
    if not 0 < j < fine.size - 1:
        return None                 # no peak: the stretch is the skirt of something else
    return float(fine[j] + log_parabola_offset(p[j - 1:j + 2]) * 0.25 * step)


def _shadow(ctx, f_c: float, side: float, h: float, runs, accepted) -> bool:
    """Whether the track f_c + side·h·|Ω|/2π lies within 1.5 Welch bins (a lit bin and its neighbour) of a track
    already taken in half of ``runs`` or more: its ridge is that line's, lit where the two tracks are not resolved (a
    line's ridge at the low speeds, where a Welch bin spans a wide range of h)."""
    f = np.abs(f_c + side * h * ctx.omega[runs] / (2 * np.pi))
    return any(np.mean(np.abs(f - np.abs(f_c + s * g * ctx.omega[runs] / (2 * np.pi))) <= 1.5 * ctx.df) >= 0.5
               for s, g, _, _ in accepted)


def _record(ctx, f_c: float, chans, sides, track_shares, removed: bool = False,
            min_level: float | None = MIN_LEVEL_DB) -> Unexplained | None:
    """The record of the carrier ``f_c``'s sideband pair (or single side) ``sides`` [(side ±1, h, lit runs, lit
    fraction)], None when it stands less than ``min_level`` dB over the model (a residual's; None for those taken out
    before the search: they stood out of the data already).  ``removed``: taken out of the records the search read."""
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    share, levels, f_all, rpm_all, n_runs = 0.0, [], [], [], set()
    for side, h, lit_runs, _ in sides:
        f = np.abs(f_c + side * h * ctx.omega[lit_runs] / (2 * np.pi))
        s, level = track_shares(chans, f, lit_runs)
        share += s
        levels.append(level)
        f_all += list(f)
        rpm_all += list(ctx.omega[lit_runs] * RAD_S_TO_RPM)
        n_runs |= {pos[int(r)] for r in lit_runs}
    finite = [x for x in levels if np.isfinite(x)]
    level = max(finite) if finite else float("nan")
    if min_level is not None and not level >= min_level:
        return None
    h = float(np.mean([x[1] for x in sides]))
    signs = "±" if len(sides) == 2 else ("−" if sides[0][0] < 0 else "+")
    return Unexplained(
        signature="sideband_line", channels=tuple(chans), speed_rpm=(float(min(rpm_all)), float(max(rpm_all))),
        f_Hz=(float(min(f_all)), float(max(f_all))), level_dB=float(level), share=share,
        n_runs=len(n_runs), h=h,
        parameters={"carrier_Hz": float(f_c), "h": h, "sides": [int(x[0]) for x in sorted(sides, key=lambda x: x[0])],
                    "lit_fraction": float(max(x[3] for x in sides)), "removed_before_the_search": removed},
        causes=(f"the fixed line at {f_c:.5g} Hz modulated by the rotation ({signs}{h:.3g}x the speed): an "
                "inverter's or a PWM drive's switching frequency modulated by the motor's electrical frequency (h = "
                "the motor's pole pairs, or a multiple), or pickup modulated once per revolution (an eccentric rotor "
                "in the motor's field)",),
        would_tell="runs with the drive's switching frequency changed move the carrier and these lines together; "
                   "runs coasting with the drive off show neither; the motor's pole-pair count names h")


#: Welch bins either side of a sideband's track that its lit bins reach: a Hann window's main lobe (2) and the lit
#: bin's neighbour (1)
TRACK_REACH_BINS = 3


def sideband_tracks(records=(), sidebands=()) -> list:
    """(f_c, side, h) of every track of ``records`` (``sideband_line`` records) and ``sidebands``
    (:class:`Sideband`)."""
    return ([(r.parameters["carrier_Hz"], side, r.parameters["h"]) for r in records for side in r.parameters["sides"]]
            + [(sb.f_Hz, sb.side, sb.h) for sb in sidebands])


def on_a_sideband(ctx, u, tracks) -> bool:
    """Whether the ``fixed_line`` record ``u`` (a line at one frequency over part of the speeds,
    :func:`.describe_fixed.fixed_lines_in_part`) lies within :data:`TRACK_REACH_BINS` Welch bins of one of ``tracks``
    ((f_c, side, h): :func:`sideband_tracks`) in half of the runs of its speed range or more: those bins were lit by
    the sideband sweeping past slowly (family wheel 4, 300-3000 rpm: an inverter's f_c + f_spin, 24 dB over the model,
    read as four 'fixed lines' over part of the speeds at 611-687 Hz)."""
    rpm = ctx.omega[ctx.runs] * RAD_S_TO_RPM
    inside = (rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6)
    if not inside.any():
        return False
    spin = rpm[inside] / 60.0
    return any(np.mean(np.abs(np.abs(f_c + side * h * spin) - u.f_Hz[0]) <= TRACK_REACH_BINS * ctx.df) >= 0.5
               for f_c, side, h in tracks)

