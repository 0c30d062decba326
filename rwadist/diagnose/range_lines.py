"""Lines at a constant ratio of the speed on the radial-force pair, present over one band of speeds and absent
outside it, that the wheel's translation mode does not lift: a source outside the wheel switched on or off by the
speed, found in the data before the search, described, and taken out of the records the fits read (docs/diagnose.md,
"Unexplained residual").

A radial force of the wheel reaches the load cell through the rotor's translation mode and is lifted where its line
crosses that mode, as the wheel's other radial-force lines are (:mod:`.one_channel_lines`).  A line that stands well
over the noise in one band of speeds, is at the noise in the runs outside it where its C·Ω² would stand as far over
the noise (a sharp start or stop in speed), and keeps its C·Ω² course through the crossing inside that band was added
at the load cell: a part of the test stand or the electronics that a speed brings on or off.

Left in, the empirical base took it as a planar radial-force line of the wheel and the modes' fit carried it through
the translation mode: its runs at the crossing, where the model lifts it and the data do not, held > 95 % of the
misfit near the mode (a new user's trial, h 2.73 at 1500-3000 rpm on wheel B: 5.6 dB RMS on its 4 rows there, the
mode's misfit 2.7 dB), so the mode's damping went to +71 % (+42 % on wheel A) and the mode was declared not located;
the line's missing runs were described as a ``partial_line`` of the wheel, "interleaved" on wheel A.

Both halves of the signature are needed: the band (:func:`_band`), and no lift where the wheel's other radial-force
lines show one (:func:`.lift_test.lift_followed`).  A wheel's own line that starts or stops at a speed is
lifted at the crossing and stays the search's (``partial_line``); a band that does not cross the lift the other lines
show cannot be told from one and is left to the search too.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..units import CHANNELS, DIRECTION_CHANNELS, RAD_S_TO_RPM
from .lift_test import MAX_LIFT_FOLLOWED, LiftTest, lift_followed
from .one_channel_lines import IMBALANCE_H_TOL, MIN_RUNS, run_frequencies, translation_mode

#: the direction read (the translation mode lifts both senses of a radial force alike)
DIRECTION = "radial_force"
#: runs outside the band that read the line absent, at least (a line that fades into the noise at low speed has none:
#: its C·Ω² is at the noise there too)
MIN_ABSENT_RUNS = 3
#: the line's power over the noise in its band's runs (dB, median), at least: a line that stands out where present
PRESENT_OVER_NOISE_DB = 20.0
#: the share of the band's runs where the line stands over :data:`ABSENT_OVER_NOISE_DB`, at least: one band holding it
#: throughout (a line that comes and goes from run to run is the search's ``partial_line``)
MIN_PRESENT_SHARE = 0.9
#: a run outside the band reads the line absent where the band's C·Ω² would stand this far over the noise (dB) ...
EXPECTED_OVER_NOISE_DB = 20.0
#: ... and its power at h·Ω is within this of the noise (dB; the 90th percentile of those runs: a sharp on/off, not a
#: line that fades)
ABSENT_OVER_NOISE_DB = 6.0
#: the noise at a line's frequency in a run: the median power of the whole record's transform at these offsets from
#: it (record bins: clear of the line's main lobe, near enough to share its noise)
NOISE_OFFSETS = np.r_[-9:-3, 4:10].astype(float)


@dataclass(frozen=True)
class RangeLine:
    """A line at ratio ``h`` of the speed on the radial-force pair, present in the runs ``runs`` (indices of the
    spectra; ``rpm`` their speed range) and absent from ``absent`` (their speeds ``absent_rpm``), not lifted by the
    translation mode the wheel's other radial-force lines locate (``lift``): C (median amplitude/Ω² where present, the
    amplitude √(|A_x|² + |A_y|²) on the pair), the power over the noise (dB) where present (median), where absent
    (90th percentile) and what C·Ω² would give there (median)."""

    h: float
    channels: tuple
    C: float
    runs: tuple
    absent_rpm: tuple
    present_dB: float
    absent_dB: float
    expected_dB: float
    lift: LiftTest
    #: complex amplitude (every run of the test, NaN outside ``runs``) of the line on each of ``channels``
    amplitudes: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: frequency (Hz) in every run of the test (NaN outside ``runs``)
    f_runs: np.ndarray | None = field(default=None, repr=False, compare=False)


def find_range_lines(ctx, fit, leave_out=()) -> list:
    """The :class:`RangeLine` of the context's data (``fit``: its empirical fit), the lines of ``leave_out`` (taken out
    already: a one-channel line's) left out; [] without the time series or both channels of the pair."""
    pair = DIRECTION_CHANNELS[DIRECTION]
    if ctx.test is None or not set(pair) <= set(ctx.channels) or ctx.runs.size < MIN_RUNS + MIN_ABSENT_RUNS:
        return []
    skip = [x.h for x in leave_out]
    cands = [ln for ln in fit.without_mode_exclusion.lines if ln.direction == DIRECTION
             and abs(ln.h - 1.0) > IMBALANCE_H_TOL and len(set(np.asarray(ln.channel).tolist())) == 2
             and np.unique(ln.speed).size >= MIN_RUNS and all(abs(ln.h - h) > 2e-3 for h in skip)]
    out: list = []
    for ln in cands:
        band = _band(ctx, ln, pair)
        if band is None:
            continue
        mode = translation_mode(fit, list(leave_out) + [ln])
        got = None if mode is None else _judge(ctx, ln, pair, band, mode)
        if got is not None:
            out.append(got)
    return out


def _band(ctx, ln, pair: tuple) -> tuple | None:
    """(present rows, their amplitudes, absent rows, present dB, absent dB, expected dB) of the line ``ln`` when it
    stands :data:`PRESENT_OVER_NOISE_DB` over the noise in one band of speeds (the runs between the slowest and the
    fastest it was measured in) and reads at the noise (:data:`ABSENT_OVER_NOISE_DB`) in at least
    :data:`MIN_ABSENT_RUNS` runs outside it where the band's C·Ω² would stand :data:`EXPECTED_OVER_NOISE_DB` over it,
    in every such run, while the band's runs hold it (:data:`MIN_PRESENT_SHARE`); else None."""
    w_all = np.abs(np.asarray(ctx.sp.speed, dtype=float))
    measured = np.abs(np.asarray(ln.speed, dtype=float))
    rows = ctx.runs
    w = w_all[rows]
    inside = (w >= measured.min() * (1 - 1e-9)) & (w <= measured.max() * (1 + 1e-9))
    if inside.sum() < MIN_RUNS or (~inside).sum() < MIN_ABSENT_RUNS:
        return None
    rec = np.array([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in rows])
    f = ln.h * w / (2 * np.pi)
    grid = np.column_stack([f, f[:, None] + NOISE_OFFSETS[None, :] * rec[:, None]])
    X = ctx.phasors(rows, grid)[..., [CHANNELS.index(c) for c in pair]]
    p = np.sum(np.abs(X) ** 2, axis=2)
    noise = np.median(p[:, 1:], axis=1)
    ok = np.isfinite(p[:, 0]) & np.isfinite(noise) & (noise > 0)
    snr = np.where(ok, p[:, 0] / np.where(ok, noise, 1.0), np.nan)
    a = np.sqrt(p[:, 0])
    present = inside & ok
    if present.sum() < MIN_RUNS:
        return None
    C = float(np.median(a[present] / w[present] ** 2))
    expected = (C * w**2) ** 2 / np.where(ok, noise, np.inf)
    absent = ~inside & ok & (expected >= 10 ** (EXPECTED_OVER_NOISE_DB / 10))
    if absent.sum() < MIN_ABSENT_RUNS:
        return None
    present_dB = float(10 * np.log10(np.median(snr[present])))
    absent_dB = float(10 * np.log10(max(np.percentile(snr[absent], 90), 1e-300)))
    held = float(np.mean(snr[present] > 10 ** (ABSENT_OVER_NOISE_DB / 10)))
    if present_dB < PRESENT_OVER_NOISE_DB or absent_dB > ABSENT_OVER_NOISE_DB or held < MIN_PRESENT_SHARE:
        return None
    return (rows[present], a[present], rows[absent], present_dB, absent_dB,
            float(10 * np.log10(np.median(expected[absent]))))


def _judge(ctx, ln, pair: tuple, band: tuple, mode: tuple) -> RangeLine | None:
    """The line ``ln`` present in the band ``band`` (:func:`_band`) as a :class:`RangeLine` when it does not follow
    the lift of the translation mode ``mode`` (f0 Hz, ζ) at its runs (:data:`MAX_LIFT_FOLLOWED`), else None."""
    from .fixed_lines import run_amplitudes

    rows, a, absent, present_dB, absent_dB, expected_dB = band
    w_all = np.abs(np.asarray(ctx.sp.speed, dtype=float))
    got = lift_followed(a, w_all[rows], ln.h, mode)
    if got is None or got[0] > MAX_LIFT_FOLLOWED:
        return None
    # the amplitude subtracted in each run of the band (and no other): the tone fitted on the whole record, at the
    # run's own frequency of it (:func:`.one_channel_lines.run_frequencies`, on the channel holding more of it)
    f_runs = np.full(w_all.size, np.nan)
    f_runs[rows] = ln.h * w_all[rows] / (2 * np.pi)
    X = ctx.phasors(rows, f_runs[rows][:, None])[:, 0, :]
    c = max(pair, key=lambda ch: float(np.nansum(np.abs(X[:, CHANNELS.index(ch)]) ** 2)))
    f_runs = run_frequencies(ctx, c, f_runs)
    h = float(np.median(f_runs[rows] * 2 * np.pi / w_all[rows]))
    return RangeLine(h=h, channels=tuple(pair), C=float(np.median(a / w_all[rows] ** 2)),
                     runs=tuple(int(r) for r in rows),
                     absent_rpm=tuple(float(x) for x in np.sort(w_all[absent]) * RAD_S_TO_RPM),
                     present_dB=present_dB, absent_dB=absent_dB, expected_dB=expected_dB,
                     lift=LiftTest.of(mode, got, h), amplitudes=run_amplitudes(ctx, f_runs, pair), f_runs=f_runs)


def range_line_tones(lines) -> list:
    """The tones (channel, frequency Hz per run, complex amplitude per run) of ``lines`` to take out of the records
    (:func:`.fixed_lines.subtract_tones`): each line on each channel of its pair, in the runs of its band."""
    return [(c, ln.f_runs, ln.amplitudes[:, j]) for ln in lines for j, c in enumerate(ln.channels)]


def range_line_shares(res, lines) -> dict:
    """Line index -> (share, level dB) of each line on the data as given: its band on both channels in its runs."""
    pos = {int(r): i for i, r in enumerate(res.ctx.runs)}
    out = {}
    for i, ln in enumerate(lines):
        cells = {}
        for c in (c for c in ln.channels if c in res.e):
            m = res.mask(c)
            for r in (r for r in ln.runs if r in pos):
                m[pos[r], int(res.band_of(ln.f_runs[r]))] = True
            cells[c] = m
        if cells:
            out[i] = res.measure(cells)
    return out


def describe_range_lines(ctx, lines, shares: dict) -> list:
    """``speed_line`` records (:class:`~rwadist.diagnose.unexplained.Unexplained`) of ``lines``, one per line, on its
    pair; ``shares``: line index -> (share, level dB) on the data as given."""
    from .unexplained import Unexplained

    out = []
    for i, ln in enumerate(lines):
        runs = list(ln.runs)
        rpm = ctx.omega[runs] * RAD_S_TO_RPM
        f = ln.f_runs[runs]
        share, level = shares.get(i, (math.nan, math.nan))
        lo, hi = float(rpm.min()), float(rpm.max())
        below = [x for x in ln.absent_rpm if x < lo]
        above = [x for x in ln.absent_rpm if x > hi]
        out.append(Unexplained(
            signature="speed_line", channels=ln.channels, speed_rpm=(lo, hi), f_Hz=(float(f.min()), float(f.max())),
            level_dB=level, share=share, n_runs=len(runs), h=ln.h,
            parameters={"direction": DIRECTION, "h": ln.h, "C": ln.C, "present_rpm": [lo, hi],
                        "starts_between_rpm": [max(below), lo] if below else None,
                        "stops_between_rpm": [hi, min(above)] if above else None,
                        "absent_rpm": list(ln.absent_rpm), "present_over_noise_dB": ln.present_dB,
                        "absent_over_noise_dB": ln.absent_dB, "expected_over_noise_dB": ln.expected_dB,
                        **ln.lift.parameters(), "removed_before_the_search": True},
            causes=("a source outside the wheel, added at the load cell, that a speed switches on or off: a part of "
                    "the test stand driven at the wheel's speed that touches, or comes loose, over a band of speeds, "
                    "or electrical pickup synchronous with the spin from a drive that changes its commutation or "
                    "switching scheme at a speed",
                    "not a load of the wheel that starts or stops at a speed: that passes through the translation "
                    "mode and is lifted at the crossing as the wheel's other radial-force lines are"),
            would_tell="runs repeated across the speeds where it starts and stops with the load cell turned 90° about "
                       "the spin axis, or the drive's electronics supplied and grounded apart from the load cell's "
                       "(a source at the cell or in its chain changes; a load of the wheel does not)"))
    return out
