"""Detector of the open world (issue 33, item 3) on the final model's residual: a gain of the measurement chain that
depends on the line's FREQUENCY, the same on every channel whatever the speed (a ``line_property`` of property
``frequency_response``): a data-acquisition anti-alias low-pass, an amplifier's bandwidth, a load cell's own
high-pass.

The model's lines follow C·Ω² (or a law, or the suspension modes' transfer) with one C per line, so a gain common to
the chain that is the same at every frequency goes into the C's unseen.  A gain that falls with frequency does not: a
line of h 9.8 swept from 65 to 820 Hz through a 4-pole Butterworth at 600 Hz loses 12 dB over its runs, the h 3 line
of the same test 0.3 dB; the fit takes a mean into each C and bends the modes' damping towards the rest (an independent
trial, session 39: the C of the 9.8 lines 25-27 % low, the rocking mode's ζ 0.018 for 0.025, error 4-15x clean), and
the search named an amplitude law on one line or nothing.  :mod:`rwadist.diagnose.describe_trend` reads the same
lines' ratios and leaves a gain of the frequency to this detector (its ``FILTER_RSS_RATIO``).

The lines read are :func:`rwadist.diagnose.describe_trend.read_lines`' (every direction, pairs' powers summed, the lines
standing 10 dB over the noise in 6 runs or more over 40 % of the speed range, a line's own law put back).  Their
ratios 10·log10(P/P̂) are fitted with each line's own offset and one common gain of the frequency G(f), a
Butterworth-like magnitude (low-pass −10·log10(1 + (f/f_c)^2n), high-pass −10·log10(1 + (f_c/f)^2n)) over a grid of
corners and orders (:data:`ORDERS`); the best is described when

- it explains the lines' ratios far better than their offsets alone: the residual falls below :data:`MAX_RSS_SHARE`
  of theirs and by more than its two parameters' worth (the Bayesian information criterion),
- and far better than one common slope against the speed or its logarithm (a gain trend, a common Ω^p law:
  :data:`MAX_RSS_SHARE` of the lesser residual), its corner inside the grid (at an end the magnitude is a power of f),
- it changes the lines by :data:`MIN_CHANGE_DB` or more over the frequencies read,
- and the lines it moves (:data:`LINE_CHANGE_DB` or more over their own runs) are :data:`MIN_LINES` or more, of two
  harmonic numbers or more (on lines of one h a gain of the frequency is one of the speed: a bearing line's own
  amplitude law on every direction), in :data:`MIN_DIRECTIONS` load directions or more, each of those fitting better
  with it than without, and fewer than half as many lines it would move that fit worse with it (they contradict it).
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS
from .describe_trend import pooled_slope, read_lines
from .line_offsets import line_indicator, offset_free_sse, per_line_sse
from .unexplained import Unexplained

#: Filter orders tried (poles of a Butterworth-like magnitude)
ORDERS = (1, 2, 3, 4, 6, 8)
#: Corners tried: this many, log-spaced from a fifth of the lowest line frequency read to five times the highest
N_CORNERS = 121
#: ... then this many around the best of them, over one step of that grid on either side
N_FINE = 41
#: The filter's residual at most this share of that of the lines' offsets alone, and of one slope against the speed
MAX_RSS_SHARE = 0.5
#: The filter's change of the lines' power over the frequencies read at least (dB): 1 dB is 12 % in amplitude, about
#: five times the worst line C error of the family's clean fits
MIN_CHANGE_DB = 1.0
#: A line counts as moved by the filter when its gain changes by this much over its own runs (dB)
LINE_CHANGE_DB = 0.5
#: Lines moved, at least ...
MIN_LINES = 3
#: ... in this many load directions or more (a gain of the chain acts on every channel)
MIN_DIRECTIONS = 2
#: Parameters the filter adds (corner, order): the information criterion's penalty is this times ln(points)
FILTER_PARAMETERS = 2


def _gain_db(f: np.ndarray, corners: np.ndarray, order: int, low: bool) -> np.ndarray:
    """Power gain (dB) of the Butterworth-like magnitude at ``f`` (N,) Hz for each corner ``corners`` (K,) Hz, (K, N)."""
    x = f[None, :] / corners[:, None] if low else corners[:, None] / f[None, :]
    return -10.0 * np.log10(1.0 + x ** (2 * order))


def frequency_response(ctx, state, shares) -> list:
    """A ``line_property`` record (property ``frequency_response``) when the model's lines in every direction depart
    from it by one gain of their frequency (module docstring), else []; ``state`` read as recorded
    (:func:`rwadist.diagnose.describe_gain.as_recorded`), ``shares(chans, hs, runs)`` -> (share of the misplaced power,
    level dB) of the lines' cells."""
    runs = ctx.runs
    read = [x for x in read_lines(ctx, state, runs) if np.all(x[4] > 0) and np.all(np.isfinite(x[5]))]
    if len(read) < MIN_LINES:
        return []
    f = np.concatenate([x[4] for x in read])
    db = np.concatenate([x[5] for x in read])
    line = np.repeat(np.arange(len(read)), [x[4].size for x in read])
    onehot, count = line_indicator(line)
    rss0 = float(offset_free_sse(db[None, :], onehot, count)[0])
    if not rss0 > 0:
        return []
    # one common slope against the speed, and one against its logarithm (a common Ω^p law)
    rss_speed = min(pooled_slope([x[3] / 1000.0 for x in read], [x[5] for x in read])[1],
                    pooled_slope([np.log(x[3]) for x in read], [x[5] for x in read])[1])
    corners = np.geomspace(0.2 * f.min(), 5.0 * f.max(), N_CORNERS)
    best = (np.inf, 0.0, 0, True)
    for low in (True, False):
        for order in ORDERS:
            sse = offset_free_sse(db[None, :] - _gain_db(f, corners, order, low), onehot, count)
            i = int(np.argmin(sse))
            if sse[i] < best[0]:
                best = (float(sse[i]), float(corners[i]), order, low)
    rss_f, corner, order, low = best
    if not corners[0] < corner < corners[-1]:
        return []       # at the grid's end the magnitude is a power of f: one common Ω^p law, not a corner (review)
    # the corner to a fraction of a per cent: a finer grid over the coarse one's step on either side of the best
    step = float(corners[1] / corners[0])
    fine = corner * np.geomspace(1.0 / step, step, N_FINE)
    sse = offset_free_sse(db[None, :] - _gain_db(f, fine, order, low), onehot, count)
    i = int(np.argmin(sse))
    if sse[i] < rss_f:
        rss_f, corner = float(sse[i]), float(fine[i])
    n = f.size
    if not (rss_f < MAX_RSS_SHARE * rss0 and rss_f < MAX_RSS_SHARE * rss_speed
            and n * np.log(rss0 / max(rss_f, 1e-300)) > FILTER_PARAMETERS * np.log(n)):
        return []
    g = _gain_db(f, np.array([corner]), order, low)[0]
    change = float(g.max() - g.min())
    if change < MIN_CHANGE_DB:
        return []
    # the lines it moves, each fitted better with it than by its own offset alone; those it would move that fit worse
    # with it contradict it (a chain filter bends every channel's lines at a frequency: review, the radial force and
    # torque bent alike by one mode's misfit while the axial lines at the same frequencies stay flat)
    starts = np.r_[0, np.cumsum(count[:-1])].astype(int)          # the lines' points lie one line after the other
    reach = np.maximum.reduceat(g, starts) - np.minimum.reduceat(g, starts) >= LINE_CHANGE_DB
    better = per_line_sse(db - g, onehot, count) < per_line_sse(db, onehot, count)
    moved = [x for x, r, b in zip(read, reach, better) if r and b]
    against = int(np.sum(reach & ~better))
    directions = sorted({x[0] for x in moved})
    if 2 * against >= len(moved) or len(moved) < MIN_LINES or len(directions) < MIN_DIRECTIONS \
            or len({x[1] for x in moved}) < 2:
        return []       # lines of one h alone: a gain of their frequency is one of the speed (their source's law)
    chans = tuple(c for c in ctx.channels if any(c in DIRECTION_CHANNELS[d] for d in directions))
    read_h = sorted({x[1] for x in moved})
    used = np.unique(np.concatenate([x[2] for x in moved]))
    share, _ = shares(chans, read_h, used)
    f_moved = np.concatenate([x[4] for x in moved])
    rpm = np.concatenate([x[3] for x in moved])
    kind = "low-pass" if low else "high-pass"
    where = "above" if low else "below"
    edge = float(f_moved.max() if low else f_moved.min())
    loss = -float(_gain_db(np.array([edge]), np.array([corner]), order, low)[0, 0])
    # 10·log10(1 + x^(2n)) = 1 dB at x = (10^0.1 − 1)^(1/2n): f_c/2 for one pole, 0.85·f_c for four
    x_1db = (10.0 ** 0.1 - 1.0) ** (1.0 / (2 * order))
    f_1db = corner * x_1db if low else corner / x_1db
    return [Unexplained(
        signature="line_property", channels=chans, speed_rpm=(float(rpm.min()), float(rpm.max())),
        f_Hz=(float(f_moved.min()), float(f_moved.max())), level_dB=-loss, share=share, n_runs=int(used.size),
        parameters={"property": "frequency_response", "shape": kind, "corner_Hz": corner, "order": order,
                    "loss_dB_at_edge": loss, "edge_Hz": edge, "change_dB": change,
                    "lines_moved": len(moved), "lines_read": len(read), "directions": directions,
                    "read_h": read_h, "rss_offsets_dB2": rss0, "rss_filter_dB2": rss_f,
                    "rss_speed_dB2": rss_speed},
        causes=(f"a {kind} gain of the whole measurement chain: the lines' power falls {loss:.1f} dB by {edge:.4g} Hz "
                f"(a {order}-pole magnitude, corner {corner:.4g} Hz, fits the lines' ratios), the same at the same "
                f"frequency in every direction ({', '.join(directions)}) whatever the speed: "
                + ("the data acquisition's anti-alias filter, or the load-cell amplifier's bandwidth" if low else
                   "a charge amplifier's or an AC-coupled input's high-pass")
                + f"; the model's lines {where} {f_1db:.4g} Hz (where it takes 1 dB) are read low (their C's take "
                  "the mean loss) and the suspension modes' damping near them bends to it",),
        would_tell="the data acquisition's filter settings (type, corner, order) and the amplifier's bandwidth; the "
                   "same test recorded with the filter off or at a higher sample rate; a calibration of the chain with "
                   "a shaker at known frequencies")]
