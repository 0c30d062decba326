"""Lines at a constant ratio of the speed on ONE channel of the radial-force pair that the wheel's translation mode
does not lift: a source outside the wheel (the test stand, the sensor, the electronics), found in the data before
the search, described, and taken out of the records the fits read (docs/diagnose.md, "Unexplained residual").

A radial force of the wheel reaches the load cell through the rotor's translation mode, whatever its form: a load
turning with the rotor or against it, or one fixed in a direction (a planar load, an outer-race defect's) -- the
mode is isotropic and both senses pass the same gain.  So a line of the wheel on one channel of the pair alone (a
planar load along that axis) is still lifted where it crosses the translation mode, as the wheel's other
radial-force lines are.  A line on one channel alone (its partner under the noise in every run) that keeps its
C·Ω² course through the crossing does not pass through the wheel's suspension: it was added at the load cell.

Left in, the empirical base took it as a planar radial-force line (a co- and a counter-rotating part of equal
amplitude, which predicts it on both channels), and the modes' fit carried it through the translation mode: its
runs at the crossing, where the model lifts it ~15x and the data do not, pulled the mode's damping to twice its
value and left the mode declared not located (a new user's trial, W5 with h 2.37 on Fy: ζ 0.064 for 0.03), and the
line's missing lift was described as a ``partial_line`` "absent" from the three runs at the crossing.

The telling signature needs both halves: one channel alone (:func:`_partner_dB`), and no lift where the wheel's
other radial-force lines show one (:func:`lift_followed`: the slope of the line's log level against the log gain
of the translation mode those lines locate, :func:`rwadist.mode_scan.scan_mode`; 1 for a load of the wheel, 0 for
one added at the load cell).  A one-channel line that does not cross a lift the other lines show (a hard-mounted
wheel, a line far from the mode) cannot be told from a planar load of the wheel and is left to the search.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..units import CHANNELS, DIRECTION_CHANNELS, RAD_S_TO_RPM
from .lift_test import MAX_LIFT_FOLLOWED, LiftTest, lift_followed

#: the direction read (the translation mode lifts both senses of a radial force alike; a radial torque's whirls
#: split by sense, and a planar torque line's two parts would need the rocking mode's whirls to be read)
DIRECTION = "radial_force"
#: runs (distinct speeds) the empirical fit measured the line in, at least
MIN_RUNS = 6
#: the partner channel's power at the line's frequency over the carrier's, in the runs the line was measured in:
#: the median at most this (dB) ...
PARTNER_MEDIAN_DB = -20.0
#: ... and in 90 % of those runs at most this (dB: a run where the line is weak reads the partner's noise)
PARTNER_P90_DB = -10.0
#: the imbalance's order is left to the search (a counter_rotation names a one-sided 1x)
IMBALANCE_H_TOL = 1e-3
#: each run's frequency of the line is refined on its record within this many record bins of h·|Ω|/2π, on a grid of
#: REFINE_STEP record bins (:func:`run_frequencies`): the empirical fit's h (4 places) is off by up to a few 1e-4,
#: a quarter turn of phase over a long record, and the tone taken out with it left 10 % of the line in each Welch
#: segment, read again as a line there
REFINE_HALF_BINS = 0.5
REFINE_STEP = 0.05


@dataclass(frozen=True)
class OneChannelLine:
    """A line at ratio ``h`` of the speed on ``channel`` alone of the radial-force pair (``partner`` its other
    channel), not lifted by the translation mode: C (median |A|/Ω²), the runs where it was measured (indices of the
    spectra), the partner's power against it (dB, median and 90th percentile) and the lift test (``lift``) against
    the translation mode the wheel's other radial-force lines locate."""

    h: float
    channel: str
    partner: str
    C: float
    runs: tuple
    partner_dB: float
    partner_p90_dB: float
    lift: LiftTest
    #: complex amplitude (every run of the test) of the line on ``channel``
    amplitudes: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: frequency (Hz) in every run of the test (NaN for a run without a speed)
    f_runs: np.ndarray | None = field(default=None, repr=False, compare=False)


def pair_fit(ctx):
    """The empirical fit of the context's spectra the lines outside the wheel are read on (this module's and
    :mod:`.range_lines`'), or None without the time series, both channels of the radial-force pair or
    :data:`MIN_RUNS` runs (nothing to read: no fit made)."""
    from ..empirical import fit_empirical

    if ctx.test is None or not set(DIRECTION_CHANNELS[DIRECTION]) <= set(ctx.channels) or ctx.runs.size < MIN_RUNS:
        return None
    return fit_empirical(ctx.sp)


def find_one_channel_lines(ctx, fit=None) -> list:
    """The :class:`OneChannelLine` of the context's data (its empirical fit ``fit``, fitted here when None); [] without
    the time series or both channels of the pair."""
    from ..empirical import fit_empirical

    cx, cy = DIRECTION_CHANNELS[DIRECTION]
    if ctx.test is None or not {cx, cy} <= set(ctx.channels) or ctx.runs.size < MIN_RUNS:
        return []
    fit = fit_empirical(ctx.sp) if fit is None else fit
    cands = []
    # every line the data show, at every speed (the base's modal exclusion may leave a line out for too few runs
    # outside its modal ranges: it is still a line of one channel or not)
    for ln in fit.without_mode_exclusion.lines:
        if ln.direction != DIRECTION or abs(ln.h - 1.0) <= IMBALANCE_H_TOL:
            continue
        chans = set(np.asarray(ln.channel).tolist())
        if len(chans) != 1 or np.unique(ln.speed).size < MIN_RUNS:
            continue
        cands.append((ln, chans.pop()))
    if not cands:
        return []
    mode = translation_mode(fit, [ln for ln, _ in cands])
    if mode is None:
        return []
    out = []
    for ln, c in cands:
        got = _judge(ctx, ln, c, cy if c == cx else cx, mode)
        if got is not None:
            out.append(got)
    return out


def translation_mode(fit, leave_out) -> tuple | None:
    """(f0 Hz, ζ) of the radial translation mode the fit's radial-force lines measured on both channels locate (every
    speed: :attr:`rwadist.empirical.EmpiricalFit.without_mode_exclusion`), ``leave_out``'s h left out; None when the
    scan does not find it (a hard-mounted wheel, no line near the mode: no lift to test a line against)."""
    from ..extended_fit import _radial_power
    from ..mode_scan import scan_mode

    skip = [x.h for x in leave_out]
    lines = [x for x in fit.without_mode_exclusion.lines if x.direction == DIRECTION
             and len(set(np.asarray(x.channel).tolist())) == 2 and all(abs(x.h - h) > 2e-3 for h in skip)]
    if len(lines) < 2:
        return None
    li, sp, pw, _, _ = _radial_power(lines)
    if li.size < 8:
        return None
    h = np.array([x.h for x in lines])[li]
    scan = scan_mode("radial_translation", li, h, sp, pw)
    if not scan.found:
        return None
    return float(scan.f0_hz), float(scan.zeta)


def _judge(ctx, ln, c: str, partner: str, mode: tuple) -> OneChannelLine | None:
    """The line ``ln`` of the empirical fit measured on channel ``c`` alone as a :class:`OneChannelLine` when its
    ``partner`` stays under it in every run (:data:`PARTNER_MEDIAN_DB`, :data:`PARTNER_P90_DB`) and it does not follow
    the lift of the translation mode ``mode`` (f0 Hz, ζ) at its runs (:data:`MAX_LIFT_FOLLOWED`), else None."""
    from .fixed_lines import run_amplitudes

    w_all = np.abs(np.asarray(ctx.sp.speed, dtype=float))
    f_runs = np.where(w_all > 0, ln.h * w_all / (2 * np.pi), np.nan)
    # every run it was measured in, those the fit's modal exclusion set aside too (a lifted line's crossing)
    measured = np.isin(w_all, np.unique(np.abs(ln.speed)))
    rows = np.intersect1d(np.flatnonzero(measured), ctx.runs)
    if rows.size < MIN_RUNS:
        return None
    # each run's whole-record phasor at the line's frequency (the partner's: its noise there when it holds none)
    X = ctx.phasors(rows, f_runs[rows][:, None])[:, 0, :]
    a_c, a_o = np.abs(X[:, CHANNELS.index(c)]), np.abs(X[:, CHANNELS.index(partner)])
    ok = np.isfinite(a_c) & np.isfinite(a_o) & (a_c > 0)
    rows, a_c, a_o = rows[ok], a_c[ok], a_o[ok]
    if rows.size < MIN_RUNS:
        return None
    ratio_dB = 20 * np.log10(np.maximum(a_o, 1e-300) / a_c)
    med, p90 = float(np.median(ratio_dB)), float(np.percentile(ratio_dB, 90))
    if not (med <= PARTNER_MEDIAN_DB and p90 <= PARTNER_P90_DB):
        return None
    w = w_all[rows]
    got = lift_followed(a_c, w, ln.h, mode)
    if got is None or got[0] > MAX_LIFT_FOLLOWED:
        return None
    # the amplitude subtracted in each run: the tone fitted on the whole record beside any line passing it (NaN where
    # a line inside its main lobe is not told apart: that run is left as it is), at the run's own frequency of it
    f_runs = run_frequencies(ctx, c, f_runs)
    A = run_amplitudes(ctx, f_runs, (c,))[:, 0]
    h = float(np.median(f_runs[rows] * 2 * np.pi / w))     # the ratio the runs' own frequencies give
    return OneChannelLine(h=h, channel=c, partner=partner, C=float(np.median(a_c / w**2)),
                          runs=tuple(int(r) for r in rows), partner_dB=med, partner_p90_dB=p90,
                          lift=LiftTest.of(mode, got, h), amplitudes=A, f_runs=f_runs)


def run_frequencies(ctx, c: str, f_runs: np.ndarray) -> np.ndarray:
    """Each run's frequency of a line near ``f_runs`` (Hz, every run of the test; NaN kept) on channel ``c``: the
    maximum of |X|² of the whole record over ±:data:`REFINE_HALF_BINS` record bins, a parabola through its logarithm's
    top three points; the nominal one where the maximum lies on the grid's edge."""
    from .describe_lines import log_parabola_offset

    out = np.array(f_runs, dtype=float)
    rows = np.flatnonzero(np.isfinite(out))
    if rows.size == 0:
        return out
    rec = np.array([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in rows])
    steps = np.arange(-REFINE_HALF_BINS, REFINE_HALF_BINS + 0.5 * REFINE_STEP, REFINE_STEP)
    grid = out[rows][:, None] + steps[None, :] * rec[:, None]
    p = np.abs(ctx.transforms(rows, grid, (c,))[..., 0]) ** 2
    for i, r in enumerate(rows):
        j = int(np.nanargmax(p[i])) if np.isfinite(p[i]).any() else -1
        if 0 < j < steps.size - 1:
            out[r] = grid[i, j] + log_parabola_offset(p[i, j - 1:j + 2]) * REFINE_STEP * rec[i]
    return out


def one_channel_tones(lines) -> list:
    """The tones (channel, frequency Hz per run, complex amplitude per run) of ``lines`` to take out of the records
    (:func:`.fixed_lines.subtract_tones`): each line on its channel in every run where its amplitude was read."""
    return [(ln.channel, ln.f_runs, ln.amplitudes) for ln in lines]


def one_channel_line_shares(res, lines) -> dict:
    """Line index -> (share, level dB) of each line on the data as given: its band in the runs it was measured in,
    on its channel."""
    pos = {int(r): i for i, r in enumerate(res.ctx.runs)}
    out = {}
    for i, ln in enumerate(lines):
        if ln.channel not in res.e:
            continue
        m = res.mask(ln.channel)
        for r in ln.runs:
            if r in pos:
                m[pos[r], int(res.band_of(ln.f_runs[r]))] = True
        out[i] = res.measure({ln.channel: m})
    return out


def describe_one_channel_lines(ctx, lines, shares: dict) -> list:
    """``speed_line`` records (:class:`~rwadist.diagnose.unexplained.Unexplained`) of ``lines``, one per line, on its
    channel alone; ``shares``: line index -> (share, level dB) on the data as given."""
    from .unexplained import Unexplained

    out = []
    for i, ln in enumerate(lines):
        runs = list(ln.runs)
        rpm = ctx.omega[runs] * RAD_S_TO_RPM
        f = ln.f_runs[runs]
        share, level = shares.get(i, (math.nan, math.nan))
        out.append(Unexplained(
            signature="speed_line", channels=(ln.channel,), speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=level, share=share, n_runs=len(runs), h=ln.h,
            parameters={"direction": DIRECTION, "h": ln.h, "one_channel": ln.channel, "partner": ln.partner,
                        "C": ln.C, "partner_dB": ln.partner_dB, "partner_p90_dB": ln.partner_p90_dB,
                        **ln.lift.parameters(), "removed_before_the_search": True},
            causes=(f"a source outside the wheel, added at the load cell: a part of the test stand driven at the "
                    f"wheel's speed, the {ln.channel} sensor's own chain, or electrical pickup synchronous with the "
                    "spin (the drive's commutation, a tach or encoder signal)",
                    "not a load of the wheel: a planar load (an outer-race defect's) also reads on one channel, but "
                    "passes through the translation mode and is lifted at the crossing as the other lines are"),
            would_tell=f"runs with the load cell turned 90° about the spin axis (a load of the wheel keeps its "
                       f"direction at the wheel; a sensor's or cable's stays on {ln.channel}), or with the "
                       f"{ln.channel} channel's cable and amplifier swapped with {ln.partner}'s"))
    return out
