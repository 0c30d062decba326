"""Detector of the open world (issue 33, item 3) on the final model's residual: a model line whose Welch window holds
more than the line itself (a ``line_property`` of property ``blended_lines``): two or more lines closer than the
Welch segments resolve, measured as one.

The base measures a line on the Welch PSDs, whose window (±LINE_HALF bins of the segment length) takes in every line
within it: two lines 0.025 apart in h (a cage line beside a bearing line, a line whose co- and counter-rotating parts
run at slightly different ratios) are 1.25 Hz apart at 3000 rpm, inside one window of 1.9 Hz bins, and the base fits
one line of their summed power between them (family wheel with h 0.40 and 0.425 of equal C: one line at h 0.405 of
C +6 % over either's quadratic sum's share, nothing said).  The PSD it predicts is right; its h and C are a blend.  The
whole record is four times finer and reads the line at its own frequency alone: a line alone in its window reads the
same amplitude on both (:func:`rwadist.effects.missing_harmonic_diagnose.window_ratios`: 0.99-1.00 on clean data), a
blend more on the Welch window (2.6-5.5 dB for the pair above).  Where the search could split the blend (the record
resolves the two lines in enough runs: a ``missing_harmonic`` of route ``close``) the model holds both and its lines
read 1 again; where it could not, the blend is described here, read as the search reads it
(:func:`rwadist.effects.missing_harmonic_diagnose.hidden_in_window`) on the faster half of the runs where the line
stands :data:`MIN_SNR_DB` over the record's noise, on :data:`MIN_POINTS` readings or more.
"""
from __future__ import annotations

import numpy as np

from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .constants import LINE_HALF, TORQUE_CHANNELS
from .unexplained import Unexplained

#: The line's whole-record power over the record's white noise, at least (dB), in a run that is read: a line near the
#: noise reads the noise of its Welch window as its own power.
MIN_SNR_DB = 20.0
#: The power the model's other lines predict in the line's window, over the line's own there, at most in a run that is
#: read (:func:`rwadist.diagnose.describe_partial.others_in_window`)
OTHERS_MAX = 0.1
#: Readings (channel × run) at least: three (the search's own floor for trying a split) let the few top-speed runs of a
#: broadband floor's noise or a lever arm's read as a blend (family wheel 7: +1.5 and +0.3 dB on 3 points each)
MIN_POINTS = 6


def blended_lines(ctx, state, of_line) -> list:
    """``line_property`` records (property ``blended_lines``) of the final model's lines that hide another line in
    their Welch window (module docstring); ``of_line(chans, h, runs)`` -> (share, level dB) of a line's cells."""
    from ..effects.missing_harmonic_diagnose import _steady, hidden_in_window, record_noise
    from .describe_partial import others_in_window
    from .measure import record_dfts
    from .record_residual import RECORD_SEP_BINS

    if not _steady(ctx, state) or (ctx.test.meta or {}).get("slicing") is not None:
        return []                       # a sweep's slice holds each line as a chirp, on its record as on its Welch PSD
    runs = np.asarray(ctx.runs)
    w_hz = ctx.omega[runs] / (2 * np.pi)
    fast = runs[w_hz >= np.median(w_hz)]
    if not fast.size:
        return []
    w_top = float(np.max(ctx.omega[fast])) / (2 * np.pi)
    df_rec = max(ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in fast)
    # per channel, every line at once: Welch (:meth:`Context.measure_lines`) and whole-record amplitudes, SNR
    read_of: dict = {}
    for c in ctx.channels:
        if state.load_cell_offset is not None and c in TORQUE_CHANNELS:
            continue                    # the state reads T − r × F on the Welch PSDs, the records hold T
        rows = fast[np.array([ctx.test.runs[r].usable(c) for r in fast], bool)]
        # a line with modulation sidebands holds them in its window (its own prediction): not read
        lines = ctx.channel_lines(state, c, rows) if rows.size else []
        idx = [j for j, x in enumerate(lines) if len(state.line_components(c, x[0])) == 1]
        hs = [lines[j][0] for j in idx]
        if hs:
            f = np.outer(ctx.omega[rows] / (2 * np.pi), hs)                                  # (R, L)
            record = np.abs(record_dfts(ctx, rows, c, f))
            with np.errstate(divide="ignore", invalid="ignore"):
                q = ctx.measure_lines(state, c, rows).T[:, idx] / record
                snr = record**2 / record_noise(ctx, state, c, rows, f)
            read_of[c] = (rows, hs, q, snr)
    out = []
    for direction, chans_all in DIRECTION_CHANNELS.items():
        chans = [c for c in chans_all if c in read_of]
        for h in sorted({x.h for x in state.model.harmonics(direction)}):
            ratio, used, read = [], [], set()
            # a run whose window of the line holds other model lines reads their misfit as the line's own (a speed
            # sideband 0.06 from its carrier, family wheel 6: +2.3 dB)
            clear = fast[others_in_window(ctx, state, direction, h, fast) <= OTHERS_MAX] if chans else fast
            for c in chans:
                rows, hs, q_all, snr_all = read_of[c]
                j = next((j for j, x in enumerate(hs) if abs(x - h) < 1e-9), None)
                if j is None:
                    continue
                q, snr = q_all[:, j], snr_all[:, j]
                keep = np.isfinite(q) & (snr >= 10 ** (MIN_SNR_DB / 10)) & np.isin(rows, clear)
                ratio.append(q[keep])
                used.append(rows[keep])
                if keep.any():
                    read.add(c)
            r = np.concatenate(ratio) if ratio else np.empty(0)
            if r.size < MIN_POINTS or not hidden_in_window(r):
                continue
            rows = np.unique(np.concatenate(used))
            rpm = ctx.omega[rows] * RAD_S_TO_RPM
            level = float(20 * np.log10(np.median(r)))
            share, _ = of_line(sorted(read), h, rows)
            window_h = (LINE_HALF + 0.5) * float(ctx.df) / w_top
            resolved_h = RECORD_SEP_BINS * df_rec / w_top
            T = 1.0 / df_rec
            out.append(Unexplained(
                signature="line_property", channels=tuple(c for c in chans if c in read),
                speed_rpm=(float(rpm.min()), float(rpm.max())),
                f_Hz=(float(h * rpm.min() / 60.0), float(h * rpm.max() / 60.0)), level_dB=level, share=share,
                n_runs=int(rows.size), h=float(h),
                parameters={"property": "blended_lines", "direction": direction,
                            "window_over_record_dB": [round(float(x), 2) for x in np.percentile(20 * np.log10(r),
                                                                                                 (25, 50, 75))],
                            "points": int(r.size), "window_h": window_h, "record_resolution_h": resolved_h,
                            "record_s": T},
                causes=(f"two or more lines within ±{window_h:.3g} of h = {h:.4g} (the Welch window at "
                        f"{w_top * 60:.0f} rpm), measured as one line of their summed power: a bearing line beside "
                        "another (a cage line, a ball-pass line and a harmonic of the speed), or a line whose co- and "
                        "counter-rotating parts run at slightly different ratios.  The model's PSD holds their power; "
                        "its h and C are a blend of theirs",),
                would_tell=(f"longer records at the top speeds: {T:.3g} s records resolve lines {resolved_h:.3g} apart "
                            f"in h at {w_top * 60:.0f} rpm (2 record bins), ten times longer ones lines ten times "
                            "closer; or runs at higher speed")))
    return out
