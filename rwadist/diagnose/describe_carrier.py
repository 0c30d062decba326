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
the whole records (:func:`_stretch_h`), the two sides of one h one record.
"""
from __future__ import annotations

import numpy as np

from ..units import RAD_S_TO_RPM
from .describe_lines import H_STEP_BINS, MIN_LEVEL_DB, RIDGE_FRACTION, RIDGE_RUNS, _lit, ratio_resolution
from .unexplained import Unexplained

#: Welch bins from the carrier within which a run's sideband bin is not read (the carrier's own leakage)
CARRIER_BINS = 3
#: Largest ratio h searched (a motor's pole pairs times a few harmonics of its electrical frequency)
MAX_H = 12.0


def sideband_lines(ctx, state, carriers, track_shares) -> list:
    """``sideband_line`` records of the residual's lines at f_c ± h·|Ω|/2π around each of ``carriers``
    (:class:`~rwadist.diagnose.fixed_lines.FixedLine`: f_Hz, channels); ``track_shares(chans, f_of_run, runs)`` ->
    (share, level dB) of the cells of a track f_of_run (Hz, one per run of ``runs``) in ``chans``."""
    runs = ctx.runs
    if runs.size < RIDGE_RUNS or not carriers:
        return []
    om = ctx.omega[runs]
    spin = om / (2 * np.pi)
    dh = H_STEP_BINS * ctx.df / float(spin.max())
    h_grid = np.arange(0.25, MAX_H, dh)
    rows = np.arange(runs.size)[None, :]
    lit = {c: _lit(ctx, state, c) for c in ctx.channels}
    out: list[Unexplained] = []
    for ln in carriers:
        chans = [c for c in ln.channels if c in lit]
        if not chans:
            continue
        cands = []
        for side in (-1.0, 1.0):
            f = ln.f_Hz + side * np.outer(h_grid, spin)                                        # (H, R)
            k = np.rint(f / ctx.df).astype(int)
            inb = (k >= ctx.k_lo) & (k <= ctx.k_hi) & (np.abs(f - ln.f_Hz) > CARRIER_BINS * ctx.df)
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
        accepted: list[tuple] = []
        for frac_i, side, (h_a, h_b), on in sorted(cands, key=lambda x: -x[0]):
            h = _stretch_h(ctx, chans, runs[on], h_a, h_b, ln.f_Hz, side)
            if h is None or _shadow(ctx, ln.f_Hz, side, h, runs[on], accepted):
                continue
            accepted.append((side, h, runs[on], frac_i))
        # the two sides of one ratio are one record
        groups: list[list] = []
        for a in accepted:
            g = next((g for g in groups if abs(g[0][1] - a[1]) <= 4 * dh and all(x[0] != a[0] for x in g)), None)
            (g.append(a) if g is not None else groups.append([a]))
        for sides in groups:
            rec = _record(ctx, ln, chans, sides, track_shares)
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
        X = ctx.phasors(runs, f_c + side * np.outer(w, grid))[:, :, cols]
        return np.nanmedian(np.nansum(np.abs(X) ** 2, axis=2), axis=0)

    step = max(ratio_resolution(ctx), 1e-9)
    grid = np.arange(h_a, h_b + 1e-12, step)
    h = float(grid[int(np.argmax(power(grid)))])
    fine = h + np.arange(-4, 5) * 0.25 * step
    p = power(fine)
    j = int(np.argmax(p))
    if not 0 < j < fine.size - 1:
        return None                 # no peak: the stretch is the skirt of something else
    lo, mid, hi = np.log(np.maximum(p[j - 1:j + 2], 1e-300))
    den = lo - 2 * mid + hi
    return float(fine[j] + (0.5 * (lo - hi) / den if den < 0 else 0.0) * 0.25 * step)


def _shadow(ctx, f_c: float, side: float, h: float, runs, accepted) -> bool:
    """Whether the track f_c + side·h·|Ω|/2π lies within 1.5 Welch bins (a lit bin and its neighbour) of a track
    already taken in half of ``runs`` or more: its ridge is that line's, lit where the two tracks are not resolved (a
    line's ridge at the low speeds, where a Welch bin spans a wide range of h)."""
    f = f_c + side * h * ctx.omega[runs] / (2 * np.pi)
    return any(np.mean(np.abs(f - (f_c + s * g * ctx.omega[runs] / (2 * np.pi))) <= 1.5 * ctx.df) >= 0.5
               for s, g, _, _ in accepted)


def _record(ctx, ln, chans, sides, track_shares) -> Unexplained | None:
    """The record of one carrier's sideband pair (or single side) ``sides`` [(side ±1, h, lit runs, lit fraction)],
    None when it stands less than :data:`~.describe_lines.MIN_LEVEL_DB` over the model."""
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    share, levels, f_all, rpm_all, n_runs = 0.0, [], [], [], set()
    for side, h, lit_runs, _ in sides:
        f = ln.f_Hz + side * h * ctx.omega[lit_runs] / (2 * np.pi)
        s, level = track_shares(chans, f, lit_runs)
        share += s
        levels.append(level)
        f_all += list(f)
        rpm_all += list(ctx.omega[lit_runs] * RAD_S_TO_RPM)
        n_runs |= {pos[int(r)] for r in lit_runs}
    if not np.nanmax(levels) >= MIN_LEVEL_DB:
        return None
    h = float(np.mean([x[1] for x in sides]))
    signs = "±" if len(sides) == 2 else ("−" if sides[0][0] < 0 else "+")
    return Unexplained(
        signature="sideband_line", channels=tuple(chans), speed_rpm=(float(min(rpm_all)), float(max(rpm_all))),
        f_Hz=(float(min(f_all)), float(max(f_all))), level_dB=float(np.nanmax(levels)), share=share,
        n_runs=len(n_runs), h=h,
        parameters={"carrier_Hz": float(ln.f_Hz), "h": h, "sides": [int(x[0]) for x in sorted(sides, key=lambda x: x[0])],
                    "lit_fraction": float(max(x[3] for x in sides))},
        causes=(f"the fixed line at {ln.f_Hz:.5g} Hz modulated by the rotation ({signs}{h:.3g}x the speed): an "
                "inverter's or a PWM drive's switching frequency modulated by the motor's electrical frequency (h = "
                "the motor's pole pairs, or a multiple), or pickup modulated once per revolution (an eccentric rotor "
                "in the motor's field)",),
        would_tell="runs with the drive's switching frequency changed move the carrier and these lines together; "
                   "runs coasting with the drive off show neither; the motor's pole-pair count names h")


#: Welch bins either side of a sideband's track that its lit bins reach: a Hann window's main lobe (2) and the lit
#: bin's neighbour (1)
TRACK_REACH_BINS = 3


def on_a_sideband(ctx, u, sidebands) -> bool:
    """Whether the ``fixed_line`` record ``u`` (a line at one frequency over part of the speeds,
    :func:`.describe_fixed.fixed_lines_in_part`) lies within :data:`TRACK_REACH_BINS` Welch bins of a track of one of
    ``sidebands`` (``sideband_line`` records) in half of the runs of its speed range or more: those bins were lit by
    the sideband sweeping past slowly (family wheel 4, 300-3000 rpm: an inverter's f_c + f_spin, 24 dB over the model,
    read as four 'fixed lines' over part of the speeds at 611-687 Hz)."""
    rpm = ctx.omega[ctx.runs] * RAD_S_TO_RPM
    inside = (rpm >= u.speed_rpm[0] - 1e-6) & (rpm <= u.speed_rpm[1] + 1e-6)
    if not inside.any():
        return False
    spin = rpm[inside] / 60.0
    for sb in sidebands:
        p = sb.parameters
        for side in p.get("sides", []):
            f = p["carrier_Hz"] + side * p["h"] * spin
            if np.mean(np.abs(f - u.f_Hz[0]) <= TRACK_REACH_BINS * ctx.df) >= 0.5:
                return True
    return False

