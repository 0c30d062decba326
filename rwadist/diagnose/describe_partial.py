"""``partial_line``: a line of the final model present in some runs and absent from others (issue 33, item 3).

A line the base fitted from the data over every run holds at the strength of the runs where it is present; in the
runs where it is absent the model puts it far over the data (a blue stripe of the residual waterfall at h·Ω/2π on
those runs only).  No class explains a line that comes and goes with the run: it is described.  Read on the
lines' measured-over-predicted ratios per direction (:func:`.describe_structure.line_ratios` with the absent
runs kept), in the runs where the model's line stands :data:`~.describe_structure.ABSENT_SNR_DB` over the noise:
absent where the data hold :data:`ABSENT_DB` or less of it (in a run where the line is resolved from the
direction's other lines, :func:`others_in_window`), present within :data:`PRESENT_DB` of it.
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS
from .constants import LINE_HALF
from .unexplained import Unexplained

#: A run whose measured line power is this far under the model's (dB) or further does not hold the line ...
ABSENT_DB = -10.0
#: ... one within this of the model's (dB) holds it.
PRESENT_DB = 3.0
#: Described when at least this many runs (and this fraction of the runs read) lack the line, and as many hold it.
PARTIAL_MIN_RUNS = 3
PARTIAL_MIN_FRACTION = 0.2
#: A run reads a line absent only where the other lines of its direction predict at most this much power in the
#: line's window, relative to the line's own there (0 dB: the line is the larger part of it).  Read against
#: stronger neighbours, their misfit and their beat with the line within a Welch segment are read as its power: family
#: wheel 2's speed sidebands at h 0.94 and 1.06, 0.8-1.5 bins from their carrier (0.06·Ω/2π at 1579-3000 rpm), had
#: their carrier's +14 dB in their windows and read absent in 3 of 10 runs (a partial_line was described, and the
#: true speed_sidebands effect taken back as fitted to it: wheels 1, 2 and 6 at 5.9x, 11.3x, 1.3x the clean error);
#: the E wheel's 3× read absent at +1.3/+1.8 dB where a partial 2.7× beside it was absent; the partial 2.7× itself,
#: at -1 to -9 dB beside the 3×, read right.
OTHERS_IN_WINDOW_MAX = 1.0
#: A line whose runs read neither absent nor present in at least this fraction of its runs, its measured-over-model
#: ratio scattering by at least SCATTER_DB from run to run (:func:`_scatter`), is a line whose strength is not locked to
#: the speed rather than one that comes and goes (the new-user generator's h = 2.3 of a lognormal strength, 8 dB from
#: run to run: -21 to +17 dB, 18 of 35 runs between); described so even where no run reads absent.
SCATTER_BETWEEN_FRACTION = 1.0 / 3.0
SCATTER_DB = 4.0


def others_in_window(ctx, state, direction: str, h: float, runs: np.ndarray) -> np.ndarray:
    """Per run of ``runs`` (indices of the context's runs): the power the other lines of the direction's model
    predict in the window line h is measured in (±LINE_HALF bins about its nearest bin, as
    :meth:`Context.measure_lines` reads it), over the power line h predicts there, summed over the direction's
    channels: the lines the effects added (a speed sideband's, a sideband's) and the resonance gains included, the
    floors not; inf where line h predicts nothing there."""
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
    k0 = np.rint(h * ctx.omega[runs] / (2 * np.pi) / ctx.df).astype(int)
    k = np.clip(k0[:, None] + np.arange(-LINE_HALF, LINE_HALF + 1), 0, ctx.f.size - 1)
    rows = np.arange(runs.size)[:, None]
    own, lines = np.zeros(runs.size), np.zeros(runs.size)
    for c in chans:
        own += ctx._predict(state, c, runs, None, h, bins=k).sum(1)
        lines += (ctx.predict(state, c, runs)[rows, k] - ctx.floor_psd(state, c, runs)[rows, k]).sum(1)
    return np.where(own > 0, np.maximum(lines - own, 0.0) / np.where(own > 0, own, 1.0), np.inf)


def _scatter(q: np.ndarray, rpm: np.ndarray, w: np.ndarray) -> tuple:
    """(spread dB, whether it scatters, the readings dB) of a line's measured-over-model ratios ``q`` (dB) at ``rpm``:
    read no further under the model than the noise allows (``w``: the line's SNR), the robust spread of each run's
    reading about its neighbours' median by speed (:func:`rwadist.line_scatter.spread`: a mode's smooth gain, or a run
    or two where one lifts it, do not count); it scatters at :data:`SCATTER_DB`, with :data:`SCATTER_BETWEEN_FRACTION`
    of the runs neither absent nor present."""
    from ..line_scatter import spread

    read = np.maximum(q, -10 * np.log10(w))
    order = np.argsort(rpm, kind="stable")
    s = spread(read[order])
    between = (read > ABSENT_DB) & (np.abs(read) > PRESENT_DB)
    return s, bool(s >= SCATTER_DB and np.mean(between) >= SCATTER_BETWEEN_FRACTION), read


def _candidates(ctx, state, ratios: list) -> list:
    """Per line of each direction whose ratios hold :data:`PARTIAL_MIN_RUNS` present runs: (direction, channels, h,
    run positions, rpm, frequencies, q dB, SNR, absent mask, present mask, resolved mask).  A run is absent, and its
    reading counts for the line's scatter, only where the line is resolved from the direction's other lines
    (:func:`others_in_window` at most :data:`OTHERS_IN_WINDOW_MAX`: a speed sideband beside its carrier read -39 to +7
    dB, the carrier's misfit and beat, and was described as a line of scattering strength)."""
    out = []
    for r in ratios:
        chans = [c for c in DIRECTION_CHANNELS[r.direction] if c in ctx.channels]
        for ln in np.unique(r.line):
            m = np.flatnonzero(r.line == ln)
            q, rpm = r.q[m], r.spin[m] * 60.0
            absent, present = q <= ABSENT_DB, np.abs(q) <= PRESENT_DB
            resolved = np.ones(q.size, bool)
            if absent.any() or _scatter(q, rpm, r.w[m])[1]:
                # a run reads the line's own power only where it is resolved from the direction's other lines
                resolved = others_in_window(ctx, state, r.direction, float(r.h[m[0]]),
                                            ctx.runs[r.run[m]]) <= OTHERS_IN_WINDOW_MAX
                absent &= resolved
            if (absent.any() or _scatter(q[resolved], rpm[resolved], r.w[m][resolved])[1]) and \
                    present.sum() >= PARTIAL_MIN_RUNS:
                out.append((r.direction, chans, float(r.h[m[0]]), r.run[m], rpm, r.f[m], q, r.w[m], absent, present,
                            resolved))
    return out


def partial_lines(ctx, state, ratios: list, of_line) -> list:
    """The ``partial_line`` records of the lines' ratios ``ratios`` (:func:`.describe_structure.line_ratios` of
    ``state`` with ``absent=True``: positions in the context's runs); ``of_line(chans, h, runs)`` -> (share, level
    dB) of the line's cells in those runs (indices of the records).  The runs the line is absent from and present
    in, their speeds (rpm), whether they interleave (a line that comes and goes) or part at one speed (a line that
    starts or stops).

    A line is read against the model's other lines (:meth:`Context.measure_lines`): a run counts as absent only
    where the line is resolved from them (:func:`others_in_window`; a speed sideband read its carrier's misfit as its
    own power, and read absent, where not).  And where a partial line is absent, its model's skirt over-predicts the window of a neighbour within a line window (2·LINE_HALF + 1 bins), which
    then reads absent too (the E wheel's 3× beside a partial 2.7×).  So the lines are taken by their share, largest
    first, and a line's absent runs inside such a described line's window in a run it is absent from do not count."""
    out = []
    names = ctx.sp.run_names
    reach = (2 * LINE_HALF + 1) * ctx.df
    scored = []
    for cand in _candidates(ctx, state, ratios):
        direction, chans, h, pos, rpm, f, q, w, absent, present, _ = cand
        share, _ = of_line(chans, h, ctx.runs[pos[absent | present]])
        scored.append((share, cand))
    taken: list = []                            # (direction, h, absent run positions) of the lines described
    scattering: list = []                       # (direction, h) of the scattering lines described
    for share, (direction, chans, h, pos, rpm, f, q, w, absent, present, resolved) in sorted(scored,
                                                                                          key=lambda x: -x[0]):
        shadow = np.zeros(absent.shape, bool)
        for d, h_other, gone in taken:
            if d == direction:
                shadow |= np.isin(pos, gone) & (np.abs(h - h_other) * rpm / 60.0 <= reach)
        absent = absent & ~shadow
        scatter, scatters, _ = _scatter(q[resolved], rpm[resolved], w[resolved])
        read = np.maximum(q, -10 * np.log10(w))
        few = absent.sum() < max(PARTIAL_MIN_RUNS, PARTIAL_MIN_FRACTION * (absent | present).sum())
        # a neighbour of a scattering line described, within a line window of it, reads its leakage as its own scatter
        near_scattering = any(d == direction and abs(h - h_other) * float(np.median(rpm)) / 60.0 <= reach
                              for d, h_other in scattering)
        if few and (not scatters or near_scattering):
            continue
        if scatters:
            scattering.append((direction, h))
        taken.append((direction, h, pos[absent]))
        runs = ctx.runs[pos]
        a_rpm, p_rpm = np.sort(rpm[absent]), np.sort(rpm[present])
        # interleaved: the runs holding the line and those lacking it alternate in speed, but for one band of runs
        # holding it with none on either side (a line that starts and stops: trial wheel A's h 2.73 on Fz, present at
        # 2054-3954 rpm alone, read "the two interleaved")
        held = present[absent | present][np.argsort(rpm[absent | present], kind="stable")]
        switches = int(np.count_nonzero(np.diff(held.astype(int))))
        interleaved = bool(a_rpm.size and (switches > 2 or (switches == 2 and held[0])))
        # how far under the model the absent runs are, no further than their noise allows (w: the line's SNR, capped
        # at 1e4 by line_ratios: 40 dB)
        depth = float(np.median(read[absent])) if absent.any() else float(np.min(read))
        both = absent | present

        def run_names(sel):
            return [names[int(x)] if int(x) < len(names) else str(int(x)) for x in runs[sel]]

        out.append(Unexplained(
            signature="partial_line", channels=tuple(chans),
            speed_rpm=(float(rpm[both].min()), float(rpm[both].max())),
            f_Hz=(float(f[both].min()), float(f[both].max())), level_dB=depth, share=share,
            n_runs=int(absent.sum()), h=h,
            parameters={"direction": direction, "h": h, "runs_absent": run_names(absent),
                        "runs_present": run_names(present), "absent_rpm": [float(x) for x in a_rpm],
                        "present_rpm": [float(x) for x in p_rpm], "interleaved": interleaved,
                        "present_dB": float(np.median(q[present])),
                        **({"scatter_dB": scatter, "read_dB": [float(read[resolved].min()), float(read[resolved].max())],
                            "runs_between": int(np.sum(~both))} if scatters else {})},
            causes=((f"a source whose strength is not locked to the speed: from run to run it scatters by {scatter:.0f} "
                     "dB (rms) about the model's law, weakest where it reads absent (a bearing defect's impacts, a "
                     "lubricant film that forms and breaks, a rub that bears harder or lighter)" if scatters else
                     "an intermittent source: a cage's unstable whirl, a rub, a loose part that settles and comes "
                     "loose again" if interleaved else
                     "a source that starts or stops at one speed: a rub or a loose part that a speed or its heating "
                     "brings on, a cage whose motion changes regime"),
                    "the runs recorded in two sessions with a part changed between them (a bearing, a balance "
                    "weight, a preload)"),
            would_tell="runs repeated at the speeds where it is absent and where it is present (a steady source "
                       "repeats; an intermittent one does not), in the order they were recorded"))
    return out
