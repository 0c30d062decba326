"""Detector of the open world (issue 33, item 3) on the final model's residual: a line whose ratio to the speed drifts
with the speed (a ``line_property`` of property ``ratio_drift``).

A rolling bearing's cage turns at a fixed fraction of the shaft only while its balls roll without slip; under a
light preload or at high speed they slide, the cage lags, and the cage ratio and the ball-pass over the outer race
(n × the cage's) fall while the inner race's (n − BPFO) rises, by a few per cent over the speed range.  The model's
lines are at constant ratios h: a drifting line is binned into one h or split into two, and the modes' fit bends to
it (trial 30b, wheel A with the cage slipping 5 % at 3000 rpm, three seeds: a mode declared unconstrained each time,
an invented test stand of peak gain 0.27 on one, nothing described on another).

Read on the Welch PSDs the search used: in each run, the peak of the line's channels summed within a window around
h·|Ω|/2π (at most :data:`WINDOW` of h, and under half the way to the model's nearest other line), :data:`MIN_SNR_DB`
over the median of the PSD around it, refined by a parabola through the log powers of the top three bins; its ratio
h_run against the runs' speeds by a Theil-Sen line.  A drift over the speeds of at least :data:`MIN_DRIFT` of h,
the Theil-Sen slope's confidence interval clear of 0 and at least :data:`MIN_BINS` Welch bins at the top speed, in :data:`MIN_RUNS`
runs or more, is described with the ratios read at the lowest and the highest speed.  A line at a whole multiple of the
speed (a ratio within :data:`WHOLE` of one) is locked to the rotor and not read.  A line whose drift of
:data:`MIN_DRIFT` would stay under :data:`MIN_BINS` Welch bins at the top speed (a cage's, h ≈ 0.4) is read on the
whole records instead (:func:`_record_ratios`), its drift then counted in their bins.
"""
from __future__ import annotations

import numpy as np

from ..bearings import BALL_COUNTS, GAMMA_RANGE, RATIO_RANGES
from .describe_lines import log_parabola_offset, sliced
from .unexplained import Unexplained

#: Directions read and their channels (summed).
DIRECTIONS = {"radial_force": ("Fx", "Fy"), "radial_torque": ("Tx", "Ty"), "axial_force": ("Fz",)}
#: Half-width of the window searched around h, as a fraction of h (a cage slips by a few per cent).
WINDOW = 0.08
#: The window stays under this fraction of the distance to the model's nearest other line.
NEIGHBOUR_FRACTION = 0.45
#: Peak over the median PSD around the window (dB), at least.
MIN_SNR_DB = 15.0
#: Bins either side of the window whose PSD median is the floor.
FLOOR_BINS = 20
#: Runs read, at least.
MIN_RUNS = 8
#: Drift of the ratio over the speeds read (fraction of h), at least: clean lines read 0.00 % (trial 30b's wheels).
MIN_DRIFT = 0.01
#: The drift in frequency at the top speed, at least this many Welch bins (what the PSD can tell).
MIN_BINS = 2.0
#: Lines of the model closer than this fraction of h are this line (read in another direction, or split by its drift).
SAME_LINE = 0.02
#: A ratio within this of a whole number is locked to the rotor.
WHOLE = 0.05
#: Points of the h grid a line is read on in the whole records, at most.
MAX_GRID = 400


def _run_ratios(ctx, chans, h0: float, half: float) -> np.ndarray:
    """(run index, rpm, h_run) of the runs where the line's peak stands :data:`MIN_SNR_DB` over its floor, shape
    (n, 3)."""
    df = float(ctx.sp.df)
    P = np.sum([np.asarray(ctx.sp.psd[c], dtype=float) for c in chans], axis=0)
    top = float(ctx.f[-1]) if ctx.sp.f_lim is None else min(float(ctx.sp.f_lim), float(ctx.f[-1]))
    rows = []
    for r in ctx.runs:
        spin = abs(float(ctx.omega[r])) / (2 * np.pi)
        k0, k1 = int(np.ceil((h0 - half) * spin / df)), int(np.floor((h0 + half) * spin / df))
        if k1 - k0 < 4 or k0 < 2 or (h0 + half) * spin >= top or not np.all(np.isfinite(P[r, k0:k1 + 1])):
            continue
        seg = P[r, k0:k1 + 1]
        j = int(np.argmax(seg))
        floor = float(np.median(P[r, max(1, k0 - FLOOR_BINS):k1 + FLOOR_BINS + 1]))
        if not 0 < j < seg.size - 1 or floor <= 0 or seg[j] < floor * 10 ** (MIN_SNR_DB / 10):
            continue
        k = k0 + j + log_parabola_offset(seg[j - 1:j + 2])
        rows.append((float(r), spin * 60.0, k * df / spin))
    return np.asarray(rows, dtype=float).reshape(-1, 3)


def _record_ratios(ctx, chans, h0: float, half: float) -> tuple:
    """(rows, df) as :func:`_run_ratios`' rows, read on the whole records (:meth:`Context.phasors`) where the Welch bins
    cannot tell a drift of :data:`MIN_DRIFT` (a cage's line at h ≈ 0.4: 1 % of 20 Hz is a fifth of a 1 Hz Welch bin),
    ``df`` the records' resolution (Hz): in each run the power Σ|X|² of ``chans`` on a grid of h over the window (half a
    record bin apart at the top speed), its peak :data:`MIN_SNR_DB` over the grid's median (at the low speeds the
    window lies within the line's own lobe, and its median is no floor: those runs are not read), refined by a
    parabola through the log powers of the top three points."""
    runs = np.asarray(ctx.runs)
    df = float(np.median([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs]))
    spin = np.abs(ctx.omega[runs]) / (2 * np.pi)
    n = int(min(np.ceil(2 * half * spin.max() / (0.5 * df)) + 1, MAX_GRID))
    grid = h0 + np.linspace(-half, half, n)
    top = float(ctx.f[-1]) if ctx.sp.f_lim is None else min(float(ctx.sp.f_lim), float(ctx.f[-1]))
    ok = (h0 + half) * spin < top
    if n < 5 or not ok.any():
        return np.empty((0, 3)), df
    runs, spin = runs[ok], spin[ok]
    X = ctx.transforms(runs, np.outer(spin, grid), chans)
    P = np.sum(np.abs(X) ** 2, axis=2)                                          # (runs, grid)
    j = np.argmax(P, axis=1)
    floor = np.median(P, axis=1)
    rows = []
    for i, r in enumerate(runs):
        if not 0 < j[i] < n - 1 or not np.all(np.isfinite(P[i])) or P[i, j[i]] < floor[i] * 10 ** (MIN_SNR_DB / 10):
            continue
        h = grid[j[i]] + log_parabola_offset(P[i, j[i] - 1:j[i] + 2]) * (grid[1] - grid[0])
        rows.append((float(r), spin[i] * 60.0, float(h)))
    return np.asarray(rows, dtype=float).reshape(-1, 3), df


def _read(ctx, chans, h0: float, every, spin_top: float):
    """(rows, slope interval (lo, hi), h at the lowest speed, h at the highest) of the line near ``h0`` in ``chans``
    when its ratio to the speed drifts (module docstring), else None; ``every``: the model's lines (ratios), whose
    nearest other one bounds the window."""
    # another line of the model is one more than SAME_LINE of h away (closer: this line read in another direction,
    # or split in two by the drift itself: 4.733 and 4.758 in trial 30b's axial force)
    gap = min((abs(h - h0) for h in every if abs(h - h0) > SAME_LINE * h0), default=np.inf)
    half = min(WINDOW * h0, NEIGHBOUR_FRACTION * gap)
    df = float(ctx.sp.df)
    if MIN_DRIFT * h0 * spin_top < MIN_BINS * df and ctx.test is not None:
        rows, df = _record_ratios(ctx, chans, h0, half)
    else:
        rows = _run_ratios(ctx, chans, h0, half)
    got = drift_of(rows, h0, df)
    return None if got is None else (rows,) + got


def drift_of(rows: np.ndarray, h0: float, df: float):
    """(slope interval (lo, hi), h at the lowest speed, h at the highest) of the readings ``rows`` ((run, rpm, h_run),
    shape (n, 3)) of the line near ``h0`` when its ratio drifts by :data:`MIN_DRIFT` of h0 and :data:`MIN_BINS` bins of
    ``df`` (Hz) at the top speed, else None.

    The ratios read at the lowest and the highest speed say how far it drifts (a slip grows as Ω², no straight line);
    the Theil-Sen line through every reading says whether it drifts at all: its slope's interval clear of 0, and its
    own drift over the speeds at least half :data:`MIN_DRIFT`, the chord of a slip growing as Ω² that a line through it
    follows.  A line at one ratio whose last two or three readings fall on something else (trial 33: h 3.27 read in a
    broadband hump at 260-340 Hz at the top speeds, 3.33-3.41, the other 21 readings 3.2700 ± 0.0003) is no drift."""
    from scipy.stats import theilslopes

    if rows.shape[0] < MIN_RUNS:
        return None
    rpm, h = rows[:, 1], rows[:, 2]
    slope, icpt, lo, hi = theilslopes(h, rpm)
    h_lo, h_hi = float(h[np.argmin(rpm)]), float(h[np.argmax(rpm)])
    if abs(h_hi - h_lo) / h0 < MIN_DRIFT or lo * hi <= 0 or abs(h_hi - h_lo) * rpm.max() / 60.0 < MIN_BINS * df \
            or abs(slope) * float(np.ptp(rpm)) / h0 < 0.5 * MIN_DRIFT:
        return None
    return (float(lo), float(hi)), h_lo, h_hi


def _drifts(ctx, model) -> list:
    """(direction, channels, h, rows, slope interval (lo, hi), h at the lowest speed, h at the highest) of every line of
    ``model`` whose ratio to the speed drifts on ``ctx``'s Welch PSDs (module docstring); ``rows`` of
    :func:`_run_ratios`.  Kept on the context by the model's lines: the search asks it at every step."""
    if sliced(ctx):  # family wheel 0, a 30-s run-up: a phantom drift
        return []
    lines = {d: sorted({float(x.h) for x in model.harmonics(d)}) for d in DIRECTIONS}
    key = ("ratio_drift", tuple((d, tuple(v)) for d, v in lines.items()))
    memo = getattr(ctx, "_memo", None)
    if memo is not None and key in memo:
        return memo[key]
    every = sorted({h for v in lines.values() for h in v})
    spin_top = float(np.max(np.abs(ctx.omega[ctx.runs]))) / (2 * np.pi)
    out = []
    for d, chans in DIRECTIONS.items():
        chans = tuple(c for c in chans if c in ctx.channels and c in ctx.sp.psd)
        if not chans:
            continue
        said: list[float] = []
        for h0 in lines[d]:
            # a line split in two by its drift is one line: read once
            if h0 < 0.2 or abs(h0 - round(h0)) < WHOLE or any(abs(h0 - x) <= SAME_LINE * h0 for x in said):
                continue
            got = _read(ctx, chans, h0, every, spin_top)
            if got is not None:
                said.append(h0)
                out.append((d, chans, h0) + got)
    if memo is not None:
        memo[key] = out
    return out


def drifting_speed_lines(ctx, state, records: list) -> tuple:
    """(``records`` without the ``speed_line`` records whose ratio drifts with the speed, the (direction, channels, h,
    rows, interval, h_lo, h_hi) readings of those, as :func:`_drifts`'): a line of no model whose ratio drifts is
    caught as a ridge at one h over part of the speeds, or two (trial 31 wheel D, twice the outer race's ball pass
    slipping 4 %: 'speed lines' at h 6.795 over 400-3304 rpm and 6.747 over 400-3646 rpm, named 15-16 and 16-ball
    bearings, never tied to the drift).  Lines of one direction within :data:`SAME_LINE` of a drifting one are it."""
    if sliced(ctx):
        return records, []
    every = sorted({float(x.h) for d in DIRECTIONS for x in state.model.harmonics(d)})
    spin_top = float(np.max(np.abs(ctx.omega[ctx.runs]))) / (2 * np.pi)
    kept: list = []
    found: list = []
    for u in records:
        d = (u.parameters or {}).get("direction") if u.signature == "speed_line" else None
        if d not in DIRECTIONS or u.h is None or abs(u.h - round(u.h)) < WHOLE:
            kept.append(u)
            continue
        if any(x[0] == d and abs(u.h - x[2]) <= SAME_LINE * x[2] for x in found):
            continue                        # the drifting line read already, caught as another ridge
        chans = tuple(c for c in DIRECTIONS[d] if c in ctx.channels and c in ctx.sp.psd)
        got = _read(ctx, chans, float(u.h), every, spin_top) if chans else None
        if got is None:
            kept.append(u)
        else:
            found.append((d, chans, float(u.h)) + got)
    kept = [u for u in kept if not (u.signature == "speed_line" and any(
        x[0] == (u.parameters or {}).get("direction") and abs(u.h - x[2]) <= SAME_LINE * x[2] for x in found))]
    return kept, found


def drifting(ctx, model) -> set:
    """(direction, h) of the lines of ``model`` whose ratio drifts with the speed (:func:`_drifts`), with every
    line of the model within :data:`SAME_LINE` of one (the same line split in two by its drift)."""
    out = set()
    for d, _, h0, *_ in _drifts(ctx, model):
        out |= {(d, float(x.h)) for x in model.harmonics(d) if abs(float(x.h) - h0) <= SAME_LINE * h0}
    return out


#: Two readings are one line's track when, in the runs both read (at least MIN_COMMON), their frequencies lie within
#: this many Welch bins of each other in SAME_TRACK_SHARE of those runs or more
TRACK_BINS = 0.5
MIN_COMMON = 3
SAME_TRACK_SHARE = 0.8


def _same_track(a: np.ndarray, b: np.ndarray, df: float) -> bool:
    """Whether readings ``a`` and ``b`` ((run, rpm, h_run) rows) follow one track: :data:`TRACK_BINS` of ``df`` Hz
    apart in :data:`SAME_TRACK_SHARE` of the runs both read."""
    common, ia, ib = np.intersect1d(a[:, 0], b[:, 0], return_indices=True)
    if common.size < MIN_COMMON:
        return False
    gap = np.abs(a[ia, 2] - b[ib, 2]) * a[ia, 1] / 60.0
    return float(np.mean(gap <= TRACK_BINS * df)) >= SAME_TRACK_SHARE


def joined_tracks(readings: list, df: float) -> list:
    """The drift readings (:func:`_drifts`' tuples) grouped by the track they follow (:func:`_same_track`), each group
    led by its reading of the most runs: one drifting line read from two of the model's lines (split by its drift
    more than :data:`SAME_LINE` apart: the new-user trial nuM's h 1.55 -> 1.85, in the model at 1.688 and 1.75, was
    four records, two per direction, over overlapping speeds) or in two directions is one line."""
    groups: list[list] = []
    for x in sorted(readings, key=lambda x: -x[3].shape[0]):
        group = next((g for g in groups if any(_same_track(y[3], x[3], df) for y in g)), None)
        if group is None:
            groups.append([x])
        else:
            group.append(x)
    return groups


def _cause(way: str, h_lo: float, h_hi: float, drift: float, rpm: np.ndarray) -> str:
    """The bearing cause of a drifting line, worded for the way its ratio goes and where it sits
    (:data:`rwadist.bearings.RATIO_RANGES`): a slipping cage lowers its own ratio (½(1 ∓ γ), γ = (d/D)·cos α, the
    inner or the outer race turning) and the ball pass over the still race, n × it, and raises the ball pass over the
    turning race, n × (1 − it), over :func:`_turning_pass_min` with :data:`rwadist.bearings.BALL_COUNTS` balls; a
    cage's ratio rises only as γ changes: its contact angle moving with the speed."""
    span = f"from {h_lo:.4g} to {h_hi:.4g} ({100 * drift:+.1f} %) over {rpm.min():.0f}-{rpm.max():.0f} rpm"
    if way == "falls":
        return (f"a rolling bearing's cage slipping more as the speed grows: the line's ratio falls {span}, as the "
                "cage's ratio and the still race's ball pass (n × the cage's) fall together by one slip")
    lo, hi = min(h_lo, h_hi), max(h_lo, h_hi)
    for key, (a, b, _) in RATIO_RANGES.items():
        if a <= lo and hi <= b:
            race = "inner" if key == "FTF" else "outer"
            return (f"the cage of a ball bearing whose {race} race turns, its contact angle moving with the speed (the "
                    f"balls' centrifugal load on an angular-contact pair, or a preload changing as the bearing warms): "
                    f"the line's ratio rises {span}; a slipping cage would lower it")
    if lo >= _turning_pass_min():
        return (f"a rolling bearing's ball pass over its turning race (the inner-race ball pass BPFI = n − BPFO when "
                f"the inner race turns) as its cage slips more with the speed: the line's ratio rises {span}, while the "
                "cage's own line and the still race's ball pass would fall by the same slip")
    return (f"a line of the wheel whose ratio rises {span}: off every cage's range and under any ball pass over a "
            f"turning race (h ≥ {_turning_pass_min():.2f} with {BALL_COUNTS[0]} balls or more), so no bearing slip")


def _turning_pass_min() -> float:
    """The least ratio of a ball pass over a bearing's turning race: (n/2)(1 − γ) with the fewest balls and the
    largest γ of :mod:`rwadist.bearings` (the outer race turning; the inner race's, (n/2)(1 + γ), lies higher)."""
    return 0.5 * BALL_COUNTS[0] * (1.0 - GAMMA_RANGE[1])


def ratio_drift(ctx, state, shares, more=()) -> list:
    """``line_property`` records (``ratio_drift``) of the model's lines (``state.model``) whose ratio to the speed
    drifts with it (module docstring), and of the readings ``more`` (:func:`drifting_speed_lines`: lines of no
    model), one per track (:func:`joined_tracks`: its directions' channels together, ``model_h`` the model's lines
    it was read from); ``shares(chans, h, runs)`` -> (share, level dB) of a line's cells."""
    from ..units import CHANNELS

    out: list[Unexplained] = []
    for group in joined_tracks(list(_drifts(ctx, state.model)) + list(more), float(ctx.sp.df)):
        d, _, h0, rows, (lo, hi), _, _ = group[0]
        seen = set(rows[:, 0])
        for x in group[1:]:                     # the runs only the others read
            extra = x[3][[r not in seen for r in x[3][:, 0]]]
            rows = np.vstack([rows, extra])
            seen |= set(extra[:, 0])
        chans = tuple(c for c in CHANNELS if any(c in x[1] for x in group))
        directions = list(dict.fromkeys(x[0] for x in group))
        rpm, h = rows[:, 1], rows[:, 2]
        h_lo, h_hi = float(h[np.argmin(rpm)]), float(h[np.argmax(rpm)])
        drift = (h_hi - h_lo) / h0
        read = rows[:, 0].astype(int)
        order = np.argsort(rpm)
        share, level = shares(chans, h0, np.unique(read))
        way = "falls" if drift < 0 else "rises"
        joined = {} if len(group) == 1 else {"directions": directions,
                                              "model_h": sorted({float(x[2]) for x in group})}
        out.append(Unexplained(
            signature="line_property", channels=chans, speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(h_lo * rpm.min() / 60.0), float(h_hi * rpm.max() / 60.0)), level_dB=level, share=share,
            n_runs=int(np.unique(read).size), h=h0,
            parameters={"property": "ratio_drift", "direction": d, "h": h0, "h_at_lowest_speed": h_lo,
                        "h_at_highest_speed": h_hi, "drift_percent": float(100 * drift),
                        "readings_rpm": [float(x) for x in rpm[order]],
                        "readings_h": [float(x) for x in h[order]],
                        "drift_interval_percent": [float(100 * lo * np.ptp(rpm) / h0),
                                                   float(100 * hi * np.ptp(rpm) / h0)], **joined},
            causes=(_cause(way, h_lo, h_hi, drift, rpm),
                    "a line of a source not locked to the rotor (a pump, a fan, another machine) whose frequency "
                    "grows with the wheel's speed but not in proportion"),
            would_tell="the bearing's preload or lubrication changed (slip shrinks with preload); the cage's own "
                       "line, at h ≈ 0.4, drifting by the same fraction as the ball-pass lines names the bearing"))
    return out


def beside_drifts(records: list, drifts: list) -> list:
    """``records`` without the ``partial_line`` and ``blended_lines`` records of a line of ``drifts`` (a
    ``ratio_drift`` record's h within :data:`SAME_LINE` of it, on one of its channels), then ``drifts``: the data's
    line moves off the model's fixed ratio as the speed grows, and read there it is 'absent' from the top speeds
    (trial 30b wheel A, h 3.255 on the radial torques: 'stops between 2435 and 2589 rpm' beside its drift of -4.9 %)
    or, spread over the Welch window's bins as the record's finer ones are not, 'two or more lines' (session 60's
    trial: a cage line drifting 0.3755 -> 0.39, +2 dB in its window on Fx Fy and on Tx Ty)."""
    def drifting(u) -> bool:
        # every model line a joined record was read from (``model_h``), not its lead's alone
        read_fixed = u.signature == "partial_line" or (u.signature == "line_property" and
                                                        u.parameters.get("property") == "blended_lines")
        return read_fixed and u.h is not None and any(
            abs(u.h - h) <= SAME_LINE * h and set(u.channels) & set(x.channels)
            for x in drifts for h in (x.parameters.get("model_h") or [x.h]))

    return [u for u in records if not drifting(u)] + list(drifts)


def with_drifts(ctx, state, records: list, shares) -> list:
    """``records`` (the residual's descriptions) with the lines whose ratio drifts with the speed described as such:
    those of the model (:func:`ratio_drift`) and the ``speed_line`` records that drift (:func:`drifting_speed_lines`,
    replaced), without a drifting line's fixed-ratio reading as a ``partial_line`` (:func:`beside_drifts`)."""
    kept, more = drifting_speed_lines(ctx, state, records)
    return beside_drifts(kept, ratio_drift(ctx, state, shares, more))
