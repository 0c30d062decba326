"""Detector of the open world (issue 33, item 3) on the final model's residual: a line at one fixed frequency over a
part of the speed range only (a ``fixed_line`` whose runs begin or end at some speed).

The lines at one fixed frequency in every run are found before the search (:mod:`.fixed_lines`) and taken out of
the records the fits read.  A stand's machine that runs during part of the test, or a lightly damped structural
resonance that only the higher (or lower) speeds excite, stands at one frequency in the runs above (or below) some
speed and is absent from the others: that detector, which asks for the whole speed range, passes it over, and no
class takes it (trial13: a 317 Hz tone above 5000 rpm, +10 dB on the waterfall in five channels, described by
nothing).  Found on the final residual as a column of lit bins (:func:`rwadist.diagnose.describe_lines._lit`: the
data over the model beyond a 1e-3 false-alarm level, away from the model's lines) over the runs sorted by speed: lit
in at least :data:`BLOCK_FRACTION` of a block and :data:`MIN_RUNS` of its runs that begins at the lowest speed or
ends at the highest, in at most :data:`OUTSIDE_FRACTION` of the at least :data:`MIN_ABSENT` runs outside it (a line
in every run is the other detector's); narrow (the median data-over-model ratio over the block's runs
:data:`PEAKINESS` times that :data:`SIDE_BINS` bins either side: a hump of noise is nearly as high there); at a
frequency where a line at a constant ratio of the speed would move by :data:`MIN_MOVE_BINS` Welch bins over the
block's speeds (otherwise the two cannot be told apart); away from the model's suspension modes and fixed resonances
(:func:`_at_a_mode`: there it is the mode rung by broadband content); and :data:`MIN_LEVEL_DB` over the model in its
cells.
"""
from __future__ import annotations

import numpy as np

from ..units import RAD_S_TO_RPM
from .describe_lines import sliced
from .unexplained import Unexplained

#: Runs of the block lit at least (a review's tone at 300 Hz over the top five of twenty runs), and of the runs outside it.
MIN_RUNS = 4
MIN_ABSENT = 3
#: ... on a sweep's slices, which smear the lines over bins, the runs of a block at least, its level read in its cells
#: alone (family wheel 5's 60-s run-down from 10000 rpm: a 'fixed line' at 484 Hz over its top four slices, +0.6 dB in
#: its bands, +16 dB at its bin)
SLICED_MIN_RUNS = 6
#: Fraction of the block's runs where the bin (or a neighbour) is lit, at least; of the runs outside, at most.
BLOCK_FRACTION = 0.75
OUTSIDE_FRACTION = 0.25
#: Fraction of the block's runs a channel must be lit in to carry the line.
CHANNEL_FRACTION = 0.5
#: Welch bins a line at a constant ratio of the speed would move over the block's speeds, at least.
MIN_MOVE_BINS = 4.0
#: Narrow: the line's bin over the bins this far either side (median data over model over the block's runs).
SIDE_BINS = 4
PEAKINESS = 4.0
#: Data over model in the line's cells, at least (dB): the level the whole-range detector asks of the median run
#: (:data:`rwadist.diagnose.fixed_lines.MIN_LEVEL`, over the floor).  Family wheel 0's counter_rotation cell held a
#: 95.3 Hz column lit in Fx over the lower speeds at +6.1 dB, which no source made; trial13's tone stood +35 dB.
MIN_LEVEL_DB = 10.0
#: ... or at the line's own bin (the median over the block's runs of the data over the model, mean of its channels,
#: dB): the metric's bands hold the model's lines beside it (a review's tone at 215 Hz in Fz over the top five
#: speeds: +6.0 dB in its bands, +24.4 dB at its bin, described by nothing, and a moving resonance fitted to the lines
#: it lifted).
MIN_PEAK_DB = 15.0
#: A line within this many ζ·f (and two Welch bins) of a suspension mode of the model, or of one of its fixed
#: resonances, in most of its runs is the mode rung by broadband content, not a source of its own (family wheel 0:
#: the rocking mode at rest, 95 Hz, in Fx over the lower speeds, where its whirl branches have not yet split).
MODE_HALF_WIDTHS = 3.0
#: The channels each suspension mode of the extended base moves (the radial modes, translation and rocking, load the
#: radial forces and torques; the axial mode the axial force): a tone on Fz beside the radial translation is no
#: ringing of it (a review's 300 Hz tone in Fz over the top speeds, 76 Hz from a translation fitted at 224.5 Hz with
#: ζ 0.17, was taken for that mode and described by nothing).
MODE_CHANNELS = {"radial_translation": ("Fx", "Fy", "Tx", "Ty"), "rocking_forward": ("Fx", "Fy", "Tx", "Ty"),
                 "rocking_backward": ("Fx", "Fy", "Tx", "Ty"), "axial_translation": ("Fz",)}


def _at_a_mode(ctx, state, f_hz: float, runs: np.ndarray, chans) -> bool:
    """True when ``f_hz`` lies within :data:`MODE_HALF_WIDTHS` ζ·f (+ 2 bins) of one of the state's suspension modes
    that moves one of ``chans`` (:data:`MODE_CHANNELS`; its whirl frequency at each run's speed) in at least half of
    ``runs``, or of a fixed resonance on ``chans``."""
    from ..extended import damped_modes

    tol = 2.0 * ctx.df
    for f_r, zeta, _, on, *_ in state.resonances:        # (f_r, ζ, g, channels[, gain above])
        if set(on) & set(chans) and abs(f_hz - f_r) <= MODE_HALF_WIDTHS * zeta * f_r + tol:
            return True
    if state.ext is None:
        return False
    for mode, s in damped_modes(state.ext, ctx.omega[runs]).items():
        if not set(MODE_CHANNELS.get(mode, chans)) & set(chans):
            continue
        f_m = np.abs(s.imag) / (2 * np.pi)
        zeta = -s.real / np.maximum(np.abs(s), 1e-300)
        if np.mean(np.abs(f_hz - f_m) <= MODE_HALF_WIDTHS * zeta * f_m + tol) >= 0.5:
            return True
    return False


def _blocks(lit: np.ndarray, min_runs: int = MIN_RUNS) -> tuple:
    """Per bin the best block of ``lit`` (runs sorted by speed × bins): (first run, end run (exclusive), fraction lit
    inside, fraction lit outside), of the blocks that begin at the lowest speed or end at the highest and meet the
    fractions the one with the most runs lit inside or unlit outside; first = end = 0 where none does."""
    R, K = lit.shape
    cs = np.vstack([np.zeros((1, K)), np.cumsum(lit, axis=0)])                  # (R + 1, K): lit runs before run i
    total = cs[-1]
    best = (np.zeros(K, int), np.zeros(K, int), np.zeros(K), np.ones(K))
    agree = np.full(K, -1.0)
    for n in range(min_runs, R - MIN_ABSENT + 1):
        for i0 in (0, R - n):
            lit_in = cs[i0 + n] - cs[i0]
            inside, outside = lit_in / n, (total - lit_in) / (R - n)
            # the block whose runs agree best with lit inside, unlit outside: its edge where the line begins
            score = lit_in + (R - n) - (total - lit_in)
            better = (inside >= BLOCK_FRACTION) & (lit_in >= min_runs) & (outside <= OUTSIDE_FRACTION) & (score > agree)
            agree[better] = score[better]
            best[0][better], best[1][better] = i0, i0 + n
            best[2][better], best[3][better] = inside[better], outside[better]
    return best


def fixed_lines_in_part(ctx, state, shares) -> list:
    """``fixed_line`` records of the residual's lines at one fixed frequency over the runs above or below some speed
    (``shares(chans, f_hz, runs)`` -> (share of the misplaced power, level dB) of the line's cells)."""
    from .describe_lines import _lit

    runs = ctx.runs
    if runs.size < MIN_RUNS + MIN_ABSENT:
        return []
    order = np.argsort(ctx.omega[runs], kind="stable")
    om = ctx.omega[runs][order]
    lits = {c: _lit(ctx, state, c)[order] for c in ctx.channels}
    lit = np.zeros_like(next(iter(lits.values())))
    for x in lits.values():
        lit |= x
    # a sweep's slices smear the lines over bins: there a block of SLICED_MIN_RUNS, its level in its cells
    swept = sliced(ctx)
    first, end, inside, _ = _blocks(lit, SLICED_MIN_RUNS if swept else MIN_RUNS)
    k = np.arange(lit.shape[1])
    length = end - first
    cand = (length > 0) & (k >= ctx.k_lo + SIDE_BINS) & (k <= ctx.k_hi - SIDE_BINS)
    # a constant-h line through f moves f·(1 − Ω_lo/Ω_hi) over the block's speeds
    lo = om[np.clip(first, 0, om.size - 1)]
    hi = om[np.clip(end - 1, 0, om.size - 1)]
    cand &= k * (1.0 - lo / np.maximum(hi, 1e-12)) >= MIN_MOVE_BINS
    out: list[Unexplained] = []
    taken: list[int] = []
    for k0 in np.flatnonzero(cand)[np.lexsort((-inside[cand], -length[cand]))]:
        k0 = int(k0)
        if any(abs(k0 - t) <= SIDE_BINS for t in taken):
            continue
        block = runs[order[first[k0]:end[k0]]]
        chans = [c for c in ctx.channels if lits[c][first[k0]:end[k0], k0].mean() >= CHANNEL_FRACTION]
        ratio = {c: np.nanmedian(ctx.data(state, c, block)[block][:, k0 - SIDE_BINS:k0 + SIDE_BINS + 1]
                                 / np.maximum(ctx.predict(state, c, block)[:, k0 - SIDE_BINS:k0 + SIDE_BINS + 1],
                                              1e-300), axis=0) for c in chans}
        chans = [c for c in chans if ratio[c][SIDE_BINS] >= PEAKINESS * max(ratio[c][0], ratio[c][-1])]
        if not chans:
            continue
        taken.append(k0)
        # its frequency: the peak of the block's median data PSD (summed over its channels) within 2 bins (a lit bin
        # may be the line's neighbour), a parabola through the log of the top three
        d = np.sum([np.nanmedian(ctx.data(state, c, block)[block][:, k0 - 3:k0 + 4], axis=0) for c in chans], axis=0)
        kp = int(np.argmax(d[1:-1])) + 1
        a, b, c3 = np.log(np.maximum(d[kp - 1:kp + 2], 1e-300))
        den = a - 2 * b + c3
        f_hz = (k0 - 3 + kp + (0.5 * (a - c3) / den if den < 0 else 0.0)) * ctx.df
        if _at_a_mode(ctx, state, f_hz, block, chans):
            continue
        share, level = shares(chans, f_hz, block)
        peak_db = 10 * np.log10(max(float(np.mean([ratio[c][SIDE_BINS] for c in chans])), 1e-300))
        if not (level >= MIN_LEVEL_DB or (peak_db >= MIN_PEAK_DB and not swept)):
            continue
        rpm = ctx.omega[block] * RAD_S_TO_RPM
        upper = first[k0] > 0
        where = f"from {rpm.min():.0f} rpm up" if upper else f"up to {rpm.max():.0f} rpm"
        out.append(Unexplained(
            signature="fixed_line", channels=tuple(chans), speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f_hz), float(f_hz)), level_dB=level, share=share, n_runs=int(block.size),
            parameters={"f_Hz": float(f_hz), "removed_before_the_search": False, "present": where,
                        "peak_over_model_dB": float(peak_db),
                        "lit_fraction": float(inside[k0]), "absent_runs": int(runs.size - block.size)},
            causes=(f"a machine of the stand or near it that runs {where} only (a pump, a fan, a compressor)",
                    "a lightly damped structural resonance of the stand or the wheel that the speeds "
                    f"{'above' if upper else 'below'} excite (its frequency stays while the speed changes)"),
            would_tell="runs repeated at one speed inside and outside that range, and a run with the wheel still and "
                       "the stand's machines on: a machine's line comes and goes with the machine, a resonance with "
                       "the excitation; a tap test of the stand gives its resonances"))
    return out
