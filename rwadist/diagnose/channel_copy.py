"""A channel that carries a copy of another channel's content (load-cell or amplifier crosstalk, a wiring fault, a
calibration matrix without its off-diagonal term): found in the data before the search, described, and taken out of
the records the fits read (issue 33, item 3).

Left in, a copy is forced into classes: Fz holding 0.2 × Fy's lines shows the radial lines, amplified by the radial
translation mode, in the axial direction too, which the fixture-resonance detection reads as one resonance lifting
every direction (a test stand at the translation mode, which spoilt the wheel's modes).

Signature: at the frequencies of the source channel's lines, the target's whole-record transform is the source's
times one complex constant κ, in every run and for every line the target does not carry itself (a physical pair of
channels shares a line's phase only through the wheel's geometry and its modes, which change with the speed and
from line to line).  Found on each run's Hann-windowed FFT (the same bin of both channels: a copy has the source's
leakage too, so the ratio holds whatever the line's place between bins): points (run, line) of the source standing
:data:`MIN_LINE_DB` over its noise, κ the centre of the densest cluster of their ratios (the point with the most
others within :data:`CLUSTER_TOLERANCE`, then the mean of the points within it, then the least squares of the
target on the source over those points), a copy when the points near κ hold at least :data:`MIN_COPIED_LINES` different lines (ratios h to the speed), each in at
least :data:`MIN_RUN_FRACTION` of the runs where the copy would stand :data:`MIN_COPY_DB` over the target's
noise (its ratio there within :data:`CLUSTER_TOLERANCE` of κ, or within the scatter that noise gives it,
:data:`NOISE_Z`, the tolerance's own at :data:`CLEAR_COPY_DB`: a noisy test's copied lines stand 10-20 dB over the
target's noise), and κ times the source stands over the target's noise.  Pairs of channels of one direction (Fx-Fy, Tx-Ty: a rotating line fixes their phase) are not tried on the lines
(on the floor they are, :func:`_floor_copies`), nor a
torque carrying a force of a load-cell offset's r × F on the lines (the ``cross_coupling`` class;
:data:`LEVER_ARM_PAIRS`: on the floor they are, against their mirror pair, :func:`_floor_copies`), but a radial force
in a radial torque, whose mirror pair tells an offset from a copy on the lines too (:data:`RADIAL_LEVER`,
:func:`_mirror_missing`); a copy
whose target torque that offset's r × F of the forces explains as well is the offset's (:func:`_lever_arm_of_forces`);
and a radial pair reading the other radial pair alike (Tx = κ·Fx with Ty = κ·Fy: a rotating source's force and
moment in phase) is the rotor's own pattern, not a copy.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..units import CHANNEL_DIRECTION, RAD_S_TO_RPM

#: (force, torque) pairs of a load-cell offset's r × F (Tx = r_y·Fz − r_z·Fy, ...): the ``cross_coupling`` class
#: explains a torque carrying such a force on the lines, so those pairs are left to it there (the noise floor tells
#: an instrument's copy from an offset: :func:`_floor_copies`), but for :data:`RADIAL_LEVER`'s
LEVER_ARM_PAIRS = {("Fy", "Tx"), ("Fz", "Tx"), ("Fx", "Ty"), ("Fz", "Ty"), ("Fx", "Tz"), ("Fy", "Tz")}
#: Each lever-arm pair's mirror: the other term of the same component of r in r × F, at the negated ratio
#: (T_y = r_z·F_x with T_x = −r_z·F_y; T_x = r_y·F_z with T_z = −r_y·F_x; T_z = r_x·F_y with T_y = −r_x·F_z)
LEVER_ARM_MIRROR = {("Fx", "Ty"): ("Fy", "Tx"), ("Fy", "Tx"): ("Fx", "Ty"), ("Fz", "Tx"): ("Fx", "Tz"),
                    ("Fx", "Tz"): ("Fz", "Tx"), ("Fz", "Ty"): ("Fy", "Tz"), ("Fy", "Tz"): ("Fz", "Ty")}
#: Each torque's row of a load-cell offset's r × F: (force, sign) of its two terms, the real components of r the
#: unknowns (T_x = r_y·F_z − r_z·F_y, T_y = r_z·F_x − r_x·F_z, T_z = r_x·F_y − r_y·F_x)
TORQUE_ROW = {"Tx": (("Fz", 1.0), ("Fy", -1.0)), "Ty": (("Fx", 1.0), ("Fz", -1.0)),
              "Tz": (("Fy", 1.0), ("Fx", -1.0))}
#: A copy whose target that row explains within this factor of the copy's own median misfit is the offset's
#: (:func:`_lever_arm_of_forces`): two explanations right to the noise differ by the noise's draw (tens of per cent
#: on the medians of a copy's points); a wrong one leaves the structure it misses, of the order of the line itself
LEVER_MISFIT_RATIO = 2.0
#: The other channel of a radial pair.
PARTNER = {"Fx": "Fy", "Fy": "Fx", "Tx": "Ty", "Ty": "Tx"}
#: The lever-arm pairs of a radial force in a radial torque (mirrors of each other): an offset r_z reads in both
#: (T_y = r_z·F_x with T_x = −r_z·F_y), a load cell's or an amplifier's crosstalk in one.  Tried on the lines
#: (:func:`_mirror_missing`): the classic cross-talk of a six-axis cell, a force into a moment, undeclared, left the
#: family's wheel 0 (Ty += 0.08·Fx, Fx's noise under Ty's own) with its rocking mode lost, a counter-rotating part
#: named on the radial torque and no word of a copy
RADIAL_LEVER = {("Fx", "Ty"), ("Fy", "Tx")}
#: ... one channel's copy when the mirror's torque departs from −κ × its force, at the copy's lines and runs where
#: that would stand CLEAR_COPY_DB over the mirror's noise, by more than this share of it (median): an offset's mirror
#: holds it to the wheel's own torque there (which the copy's points, where κ·F dominates, keep small)
MIRROR_MISFIT = 0.5
#: A radial force in a radial torque this close to ±90° (deg) is the partner force's r × F (:func:`_lever_arm_through_partner`).
LEVER_PHASE_DEG = 20.0
#: A source line's power over the noise in its record bin, at least (dB).
MIN_LINE_DB = 25.0
#: Lines per run and channel taken as sources (the strongest).
LINES_PER_RUN = 12
#: Relative distance to κ within which a point belongs to the copy.
CLUSTER_TOLERANCE = 0.15
#: Points of one line: their ratios h to the speed rounded to this step (a record bin is 0.06 in h at 600 rpm and
#: 0.6 Hz bins).
LINE_H_STEP = 0.1
#: Different lines (h, to LINE_H_STEP) the copy must hold, and the fraction of their runs each must hold.
MIN_COPIED_LINES = 2
MIN_RUN_FRACTION = 0.6
#: Runs at least, and at most (spread over the speeds) the copy is looked for in.
MIN_RUNS = 4
MAX_RUNS = 24
#: The copied content's power over the target's noise in those points, at least (dB).
MIN_COPY_DB = 10.0
#: A line's run counts where the copy there would stand this far over the target's noise (dB).
CLEAR_COPY_DB = 20.0
#: Below that, a point is the copy's when its ratio lies within this many of the noise's scatter of κ (the target's
#: noise, a complex Gaussian of power N in the bin, moves X_t/X_s from κ by sqrt(N)/|X_s| rms: within 1.5 of it in
#: 1 − exp(−1.5²) = 90 % of the runs), the scatter of CLUSTER_TOLERANCE at CLEAR_COPY_DB (0.15 × 10^(20/20)): a
#: run counts where the copy would stand MIN_COPY_DB over the target's noise (the tolerance there ±47 % of κ)
NOISE_Z = CLUSTER_TOLERANCE * 10 ** (CLEAR_COPY_DB / 20)
#: One line alone is a copy when κ holds in at least this many of its clear runs (and MIN_SINGLE_FRACTION of them)
#: while the source's line departs from its own law by at least SINGLE_LAW_DB over those runs (:func:`_one_line_copy`)
MIN_SINGLE_RUNS = 8
MIN_SINGLE_FRACTION = 0.8
SINGLE_LAW_DB = 3.0
#: ... and the target follows that departure: the slope of ln|κ| (the run's ratio) on ln(|X_s|/Ω²) over those runs
#: at most this (a copy's ratio is one constant, slope 0; a load of the target's own direction in a fixed phase to the
#: source, through its own modes, follows part of it: family wheel 6's 300-s run-up, Fz's 1× line 2.9 dB over its
#: law through the axial mode at 85 Hz, Fx's 0.8 dB through the translation at 150 Hz, slope −0.7; one continuous
#: record keeps every line's phases, so the two read at one ratio within the cluster's tolerance in every slice)
SINGLE_RATIO_SLOPE = 0.25
#: A copy of several lines holds the source's strongest line too: the target carries there at least this fraction of
#: the copy's amplitude in most runs (:func:`_holds_strongest`; 0.5: the target's own line would have to cancel half of
#: the copy, in phase opposition, in most runs)
STRONGEST_HELD = 0.5


@dataclass(frozen=True)
class ChannelCopy:
    """``target`` carries κ × ``source`` (complex ``kappa``, the target's unit per the source's): the lines it was
    found on (h), the runs (indices), its median power over the target's noise at those points (dB)."""

    source: str
    target: str
    kappa: complex
    lines_h: tuple
    runs: tuple
    level_dB: float
    alternatives: tuple = ()
    #: read on the noise floor (:mod:`~rwadist.diagnose.channel_copy_broadband`): the null-scatter z of its
    #: cross-spectrum (median over the runs), else 0 (read on the lines)
    floor_z: float = 0.0


def _run_points(run, chans, window: str):
    """(f (P,) Hz, X (P, K) complex, noise (K,)) of one run: the record's Hann FFT of every channel of ``chans`` at
    the peaks of each channel's spectrum standing MIN_LINE_DB over the channel's median (the LINES_PER_RUN
    strongest of each), with the source channel's index (P,)."""
    from scipy import fft as sp_fft

    from ..dft import demeaned_windowed, run_window

    n = run.n_samples
    w, wsum, _ = run_window(window, n)
    x = demeaned_windowed([run.signals[c] for c in chans], w)
    X = 2.0 * sp_fft.rfft(x, axis=-1).T / wsum                            # (F, K)
    P = np.abs(X) ** 2
    noise = np.median(P[2:], axis=0) / np.log(2.0)                          # (K,) exponential median -> mean
    f = np.arange(X.shape[0]) * run.sample_rate / n
    rows, src = [], []
    for j in range(len(chans)):
        p = P[:, j]
        peak = np.flatnonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:]) & (p[1:-1] > noise[j] * 10 ** (MIN_LINE_DB / 10))) + 1
        peak = peak[f[peak] > 4 * run.sample_rate / n]
        peak = peak[np.argsort(-p[peak])][:LINES_PER_RUN]
        rows += list(peak)
        src += [j] * peak.size
    bins = np.asarray(rows, dtype=int)
    return f[bins], X[bins], noise, np.asarray(src, dtype=int)


def find_channel_copies(ctx, test=None) -> list:
    """The :class:`ChannelCopy` of ``test`` (default the context's; the context's runs and speeds), [] without the
    time series."""
    test = ctx.test if test is None else test
    if test is None or ctx.runs.size < MIN_RUNS:
        return []
    chans = tuple(c for c in ctx.channels if all(c in test.runs[r].signals for r in ctx.runs))
    if len(chans) < 2:
        return []
    # a run with a channel that froze (Run.invalid) would make or break a copy's ratio: left out of the detection
    usable = np.array([r for r in ctx.runs if all(test.runs[r].usable(c) for c in chans)], dtype=int)
    if usable.size < MIN_RUNS:
        return []
    # an instrument's copy is in every run: up to MAX_RUNS of them, spread over the speeds, tell
    order = usable[np.argsort(ctx.omega[usable], kind="stable")]
    runs = order[np.unique(np.linspace(0, order.size - 1, min(MAX_RUNS, order.size)).round().astype(int))]
    parts = [_run_points(test.runs[r], chans, ctx.sp.window) for r in runs]
    run_of = np.concatenate([np.full(p[0].size, r) for p, r in zip(parts, runs)])
    f = np.concatenate([p[0] for p in parts])
    X = np.concatenate([p[1] for p in parts])                               # (P, K)
    noise = np.concatenate([np.broadcast_to(p[2], (p[0].size, len(chans))) for p in parts])
    src = np.concatenate([p[3] for p in parts])
    h = np.round(f * 2 * np.pi / np.maximum(ctx.omega[run_of], 1e-12) / LINE_H_STEP) * LINE_H_STEP
    found = []
    for s, cs in enumerate(chans):
        mine = src == s
        if mine.sum() < MIN_RUNS:
            continue
        for t, ct in enumerate(chans):
            lever = (cs, ct) in LEVER_ARM_PAIRS
            if t == s or CHANNEL_DIRECTION[ct] == CHANNEL_DIRECTION[cs] or (lever and (cs, ct) not in RADIAL_LEVER):
                continue
            got = _pair(X[mine, s], X[mine, t], noise[mine, t], run_of[mine], h[mine], cs, ct,
                        ctx.omega[run_of[mine]])
            if got is None:
                continue
            if (_mirror_missing(got, X, src, chans, run_of, h, noise) if lever else
                    not _lever_arm_through_partner(got) and
                    not _lever_arm_of_forces(got, X[mine], chans, run_of[mine], h[mine])):
                found.append(got)
    found += _floor_copies(test, runs, chans, found, X, noise, src, run_of, h)
    # a radial pair carrying the other radial pair's content alike (Tx = κ·Fx and Ty = κ·Fy) is the rotor's own
    # pattern (a force and a moment of one rotating source, in phase; the virtual stand's wheel without modes), not a
    # copy: a cross-sensitive channel reads one other channel, not its pair's partner too
    found = [x for x in found if not any(y.source == PARTNER.get(x.source) and y.target == PARTNER.get(x.target)
                                         for y in found)]
    # one copy per target: its source the pair whose points hold the most lines (Fz = κ·Fy also matches Fx on
    # purely co-rotating lines, at ∓jκ), a copy weaker than what it copies (|κ| < 1: the other way round of a pair
    # is the same copy read backwards)
    out = []
    for ct in dict.fromkeys(x.target for x in found):
        # a crosstalk term is a real gain: of a source and its pair's partner (a co-rotating line's x and y a quarter
        # turn apart: both fit), the one read in phase or in antiphase leads a tie by lines, or a deficit of one (the
        # session-68 trial, Fz += 0.3·Fx on co-rotating lines: "0.307 × Fy at +95.6°", Fy holding one more run)
        cands = sorted((x for x in found if x.target == ct and (abs(x.kappa) < 1.0 or x.floor_z > 0)),
                       key=lambda x: (-(len(x.lines_h) + IN_PHASE_LINES * _in_phase(x.kappa)), -len(x.runs)))
        if cands:
            out.append(replace(cands[0], alternatives=tuple(x.source for x in cands[1:])))
    return out


#: A copy's ratio within this of 0° or 180° (deg) is in phase, as a crosstalk term (a real gain) is ...
IN_PHASE_DEG = 30.0
#: ... and counts this many lines more when the copies of one target are ranked (a source against its partner)
IN_PHASE_LINES = 1


def _in_phase(kappa: complex) -> bool:
    """True when the complex ratio ``kappa`` lies within :data:`IN_PHASE_DEG` of the real axis."""
    return abs(np.sin(np.angle(kappa))) <= np.sin(np.radians(IN_PHASE_DEG))


def _floor_copies(test, runs, chans, found, X, noise, src, run_of, h) -> list:
    """The :class:`ChannelCopy` read on the noise floor (:func:`~rwadist.diagnose.channel_copy_broadband.
    find_broadband_copies`) of the targets the lines gave none: every pair of two directions, a force in a torque
    (:data:`LEVER_ARM_PAIRS`) too unless its mirror pair (:data:`LEVER_ARM_MIRROR`, the same component of a load-cell
    offset's r) reads −κ or cannot be read (:func:`~rwadist.diagnose.channel_copy_broadband.offset_mirror`: an
    offset's r × F, left to ``cross_coupling``); of a pair read both ways, when both its channels are radial (with a
    partner recorded), the way whose removal leaves their lines round (:func:`_round_after`; with one radial channel
    the forward way leaves it as it was whatever κ, and the noise chose: a reviewer's Fz += 0.1·Fx on the floor was
    read backwards on 6 seeds of 10), else the
    way whose removal takes the more of the target's power at the source's lines (the copied lines leave the target;
    read backwards, the source's own lines stay -- unless the target has lines of its own at the source's: a new
    user's Ty += 0.15·Fx on a wheel whose torque lines share the force lines' h, 22 % of Ty's power at Fx's points,
    took 0.781 of it forward and 0.774 backward, and the random phases read it backwards, "Fx reads 5.72 × Ty", on 2
    seeds of 9).  ``X``, ``noise``, ``src``, ``run_of``, ``h``: the lines' points of :func:`find_channel_copies`.

    On the lines a copy of a force in a torque at a real κ is an offset's r × F to the last digit (trial24's
    T_z += 0.02·F_x: r_y = −20 mm explains T_z as well, :func:`_lever_arm_of_forces`); the floor tells them apart: an
    offset moves loads, a copy carries the source's sensor noise too, and a lever-arm correction's (T − r × F of the
    measured forces) moves both of r's terms."""
    from .channel_copy_broadband import RADIAL_PAIR_WAYS, find_broadband_copies

    # nor a copy the lines found read backwards: the target's floor carries the source's noise κ times, so the source
    # reads it back at ~κ* on the floor (trial 33, Fz += 0.1·Fx: "Fx = 0.0972 × Fz" beside it); one pair, one copy
    skip = {(x.source, x.target) for x in found} | {(a, x.target) for x in found for a in chans} | \
        {(x.target, x.source) for x in found if abs(x.kappa) < 1.0}
    got = find_broadband_copies(test, runs, chans, CLUSTER_TOLERANCE, skip, mirror=LEVER_ARM_MIRROR)
    gain = {}
    for g in got:
        s, t = chans.index(g[0]), chans.index(g[1])
        mine = src == s
        Xs, Xt = X[mine, s], X[mine, t]
        if g[:2] in RADIAL_PAIR_WAYS:
            # a radial pair's two ways are one Gaussian pair of floors read backwards, and take alike of the lines; the
            # lines tell: the copy removed the right way leaves them as a rotating load has them, x and y of one
            # amplitude (trial 30, Fy += 0.2·Fx: median |ln| of the ratio 0 that way, 0.04 the other)
            gain[g[:2]] = -_out_of_round(Xs, Xt - g[2] * Xs)
            continue
        rounded = _round_after(X, chans, (src == s) | (src == t), g[0], g[1], g[2]) \
            if g[0] in PARTNER and g[1] in PARTNER else None
        if rounded is not None:
            gain[g[:2]] = -rounded
            continue
        total = float(np.sum(np.abs(Xt) ** 2))
        gain[g[:2]] = 1.0 - float(np.sum(np.abs(Xt - g[2] * Xs) ** 2)) / total if total > 0 else 0.0
    out = []
    for g in got:
        back = (g[1], g[0])
        if back in gain and gain[back] > gain[g[:2]]:
            continue
        s, t = chans.index(g[0]), chans.index(g[1])
        mine = (src == s) & np.isin(run_of, g[3])
        over = np.abs(g[2] * X[mine, s]) ** 2 / np.maximum(noise[mine, t], 1e-300)
        heard = over >= 10 ** (MIN_COPY_DB / 10)
        lines = [float(v) for v in np.unique(h[mine][heard]) if np.unique(run_of[mine][heard & (h[mine] == v)]).size
                 >= MIN_RUNS]
        level = float(10 * np.log10(np.median(over))) if over.size else float("nan")
        kappa = _on_the_lines(g[2], g[4], len(g[3]), X[mine, s], X[mine, t], noise[mine, t])
        out.append(ChannelCopy(g[0], g[1], kappa, tuple(lines), g[3], level, floor_z=g[4]))
    return out


def _on_the_lines(kappa: complex, z: float, n_runs: int, X_s: np.ndarray, X_t: np.ndarray,
                  noise_t: np.ndarray) -> complex:
    """κ of a copy read on the floor, read again on the source's lines that agree with it: the floor's κ is known to
    ~|κ|/(z·√runs) (z ~ 55 a run: 0.5° off over 24 runs, session 60's trial Tz += 0.03·Fx, whose 0.9 % left behind
    was fitted as Tz lines of the wheel), a line standing :data:`CLEAR_COPY_DB` over the target's noise to far
    better.  Points whose ratio lies within three of the floor's σ and of the point's own noise scatter are the
    copy's (a target's own line at the source's ratio lies off it); their least squares, weighted by the source's
    power, when :data:`MIN_RUNS` or more, else the floor's κ."""
    with np.errstate(divide="ignore", invalid="ignore"):
        k = X_t / X_s
        scatter = np.sqrt(noise_t) / np.abs(X_s)
    strong = np.abs(kappa * X_s) ** 2 >= 10 ** (CLEAR_COPY_DB / 10) * noise_t
    sigma = abs(kappa) / (max(z, 1.0) * np.sqrt(max(n_runs, 1)))
    agree = strong & np.isfinite(k) & (np.abs(k - kappa) <= 3.0 * (sigma + scatter))
    return _copy_ratio(X_s, X_t, agree) if agree.sum() >= MIN_RUNS else kappa


def _mirror_missing(copy: ChannelCopy, X: np.ndarray, src: np.ndarray, chans: tuple, run_of: np.ndarray,
                    h: np.ndarray, noise: np.ndarray) -> bool:
    """Whether ``copy`` (a radial force in a radial torque, :data:`RADIAL_LEVER`) lacks its mirror
    (:data:`LEVER_ARM_MIRROR`): at the mirror
    force's points of the copy's lines and runs where −κ × that force would stand :data:`CLEAR_COPY_DB` over the
    mirror torque's noise (in :data:`MIN_RUNS` runs at least), the median of |X_mirror torque + κ·X_mirror force −
    r·X_Fz| (r real, least squares: an offset's lateral term) over |κ·X_mirror force| exceeds :data:`MIRROR_MISFIT`.  ``X`` (P, K), ``src``, ``run_of``, ``h``, ``noise`` (P, K): the
    lines' points of :func:`find_channel_copies`."""
    ms, mt = LEVER_ARM_MIRROR[(copy.source, copy.target)]
    if ms not in chans or mt not in chans:
        return False
    s, t = chans.index(ms), chans.index(mt)
    sel = (src == s) & np.isin(h, copy.lines_h) & np.isin(run_of, copy.runs)
    pred = -copy.kappa * X[sel, s]
    heard = np.abs(pred) ** 2 >= 10 ** (CLEAR_COPY_DB / 10) * noise[sel, t]
    if np.unique(run_of[sel][heard]).size < MIN_RUNS:
        return False
    left = X[sel, t][heard] - pred[heard]
    other = next(f for f, _ in TORQUE_ROW[mt] if f != ms)
    if other in chans:
        # the mirror torque's other term of r × F, an offset's lateral part times the axial force (T_x = r_y·F_z −
        # r_z·F_y): r real, fitted by least squares, taken off too
        fz = X[sel, chans.index(other)][heard]
        A, b = np.concatenate([fz.real, fz.imag]), np.concatenate([left.real, left.imag])
        left = left - (float(A @ b / (A @ A)) if A @ A > 0 else 0.0) * fz
    return float(np.median(np.abs(left) / np.abs(pred[heard]))) > MIRROR_MISFIT


def _round_after(X: np.ndarray, chans, points: np.ndarray, source: str, target: str, kappa: complex) -> float | None:
    """How far from round (:func:`_out_of_round`, summed) the radial channels of a copy's pair leave the lines at
    ``points`` (both channels' line points, so that both ways of a pair are judged on one set) once ``kappa`` ×
    ``source`` is taken off ``target``; None when neither channel is radial with its partner recorded.  A rotor's
    radial lines are rotating loads, x and y of one amplitude: the copy removed the right way leaves them so, read
    backwards it leaves the copy in one channel and puts the other's own lines into the source."""
    s = chans.index(source)
    total, n = 0.0, 0
    for c in (source, target):
        partner = PARTNER.get(c)
        if partner is None or partner not in chans:
            continue
        x = X[points, chans.index(c)] - (kappa * X[points, s] if c == target else 0.0)
        total += _out_of_round(X[points, chans.index(partner)], x)
        n += 1
    return total if n else None


def _out_of_round(a: np.ndarray, b: np.ndarray) -> float:
    """Median over the line points of |ln(|b|/|a|)|: 0 for the two channels of a radial pair carrying a rotating load
    (x and y of one amplitude); ``a``, ``b``: their transforms at the points (P,)."""
    ok = (np.abs(a) > 0) & (np.abs(b) > 0)
    return float(np.median(np.abs(np.log(np.abs(b[ok]) / np.abs(a[ok]))))) if ok.any() else float("inf")


def _lever_arm_through_partner(copy: ChannelCopy) -> bool:
    """A radial force read in a radial torque at ±90° (within :data:`LEVER_PHASE_DEG`): on a rotating line the
    partner force is that force turned by 90° (F_y = ∓j·F_x), so a load-cell offset's r × F (T_y = r_z·F_x, a
    :data:`LEVER_ARM_PAIRS` pair) reads as T_y = ∓j·r_z·F_y -- the ``cross_coupling`` / ``lever_arm_noise`` classes'
    to name, not an instrument's copy (a cross-sensitive channel reads another in phase)."""
    partner = PARTNER.get(copy.source)
    if partner is None or (partner, copy.target) not in LEVER_ARM_PAIRS:
        return False
    return abs(abs(np.degrees(np.angle(copy.kappa))) - 90.0) <= LEVER_PHASE_DEG


def _lever_arm_of_forces(copy: ChannelCopy, X: np.ndarray, chans: tuple, runs, h) -> bool:
    """Whether the copy's target, a torque, reads a load-cell offset's r × F of the forces (its row of r × F with real
    r, :data:`TORQUE_ROW`: T_x = r_y·F_z − r_z·F_y, T_y = r_z·F_x − r_x·F_z, T_z = r_x·F_y − r_y·F_x, fitted by least
    squares) within :data:`LEVER_MISFIT_RATIO` of how closely it reads κ × the source, at the copy's points: the
    source's lines ``copy.lines_h`` in ``copy.runs`` whose ratio lies within :data:`CLUSTER_TOLERANCE` of κ (``X``
    (P, K) the transforms of ``chans`` at the source's points, their ``runs`` and line ratios ``h``); the median
    relative misfit |X_t − fit|/|X_t| of the two explanations compared.

    An offset puts r × F into every torque: where one term dominates a torque (T_y ≈ r_z·F_x with r_z large), another
    torque's r × F (T_z = r_x·F_y − r_y·F_x, the same rotating force lines) is that torque times one complex constant
    on every co-rotating line (F_y = ∓j·F_x), a copy to the cluster of ratios; taken out before the search it took
    the very equations that tell the offset's lateral part (trial16's wheel, r = (4, −3, 30) mm: T_z read as
    0.167 × T_y, r then fitted (0.04, −0.03, 30.02) mm, and r_x·F_z in T_y, the axial mode's 400 Hz, named a
    'wheel mode' on the radial torque).  The forces' pairs of a torque are left to the ``cross_coupling`` class
    (:data:`LEVER_ARM_PAIRS`); a copy the target's lever-arm forces explain as well is theirs too.  A cross-sensitive
    torque (T_z = κ·T_x of the wheel's own moment) is not: the wheel's own torque lines and its forces' have
    amplitudes and phases of their own from line to line and, through the modes, from speed to speed, which no one r
    maps onto each other.  Measured (median relative misfits, lever arm / copy, over the torque pairs tried):
    trial16's offset, offset@2 and offD (r_z 30 mm and a lateral part), 0.006-0.019 / 0.009-0.018, both at the noise
    (ratio 0.34-1.26); the open world's torque crosstalk (T_z += 0.3·T_x, family wheels 0-7), 0.18-1.0 / 0.003-0.019
    (ratio 17-330)."""
    if copy.target not in TORQUE_ROW:
        return False
    rows = TORQUE_ROW[copy.target]
    if not all(f in chans for f, _ in rows):
        return False
    s, t = chans.index(copy.source), chans.index(copy.target)
    sel = np.isin(h, copy.lines_h) & np.isin(runs, copy.runs)
    Xs, Xt = X[sel, s], X[sel, t]
    with np.errstate(divide="ignore", invalid="ignore"):
        sel2 = np.isfinite(Xt / Xs) & (np.abs(Xt / Xs - copy.kappa) <= CLUSTER_TOLERANCE * abs(copy.kappa))
    idx = np.flatnonzero(sel)[sel2]
    if idx.size < MIN_RUNS:
        return False
    Xt = X[idx, t]
    scale = np.maximum(np.abs(Xt), 1e-300)
    A = np.column_stack([sign * X[idx, chans.index(f)] / scale for f, sign in rows])     # (P, 2) complex
    b = Xt / scale
    coef, *_ = np.linalg.lstsq(np.vstack([A.real, A.imag]), np.concatenate([b.real, b.imag]), rcond=None)
    lever = float(np.median(np.abs(b - A @ coef)))
    own = float(np.median(np.abs(Xt - copy.kappa * X[idx, s]) / scale))
    return lever <= LEVER_MISFIT_RATIO * own


def _one_line_copy(X_s, X_t, omega, runs, h, near, strong) -> list:
    """[h] of the one line whose κ holds in at least :data:`MIN_SINGLE_RUNS` runs where the copy stands clear
    (``strong``), :data:`MIN_SINGLE_FRACTION` of them, while the source's line there departs from C·Ω² by at least
    :data:`SINGLE_LAW_DB` (its |X|/Ω² over those runs, max over min) and the target follows it (the ratio's slope on
    the source's law at most :data:`SINGLE_RATIO_SLOPE`), the line the source's strongest where the copy would stand
    clear, else [].

    One line at one complex ratio in every run can be the wheel's own geometry (an axial runout turning with the
    imbalance: the two loads in a fixed phase, both ∝ Ω² below their modes); but a target following the source's own
    departure from its law -- the source's modes shaping it, which the target's direction does not share -- at one
    gain and phase is a copy of that channel (family wheel 2: Tz = 0.3·Tx; Tx's imbalance line, attenuated from 0.96
    to 0.45 of C·Ω² by its rocking whirl, the one torque line that stands clear)."""
    # a copy scales every line of the source alike: the line it is read on must be the source's strongest where the
    # copy would stand clear (family wheel 2's 300-s run-up: Fz at 0.63 × Fy on the ball-pass line h 4.57, both
    # above their modes, while Fy's imbalance line, 14 dB stronger, stood in Fz at another ratio: two loads of one
    # rotor, not a copy)
    levels = {float(v): float(np.median(np.abs(X_s[(h == v) & strong]))) for v in np.unique(h[strong])}
    if not levels:
        return []
    strongest = max(levels, key=lambda v: levels[v])
    sel = (h == strongest) & strong
    hit = sel & near
    n_runs = np.unique(runs[sel]).size
    if not hit.any() or n_runs < MIN_SINGLE_RUNS or \
            np.unique(runs[hit]).size < max(MIN_SINGLE_FRACTION * n_runs, MIN_SINGLE_RUNS):
        return []
    law = np.abs(X_s[hit]) / np.maximum(np.abs(omega[hit]), 1e-12) ** 2
    if 20 * np.log10(law.max() / law.min()) < SINGLE_LAW_DB:
        return []
    slope = np.polyfit(np.log(law), np.log(np.abs(X_t[hit] / X_s[hit])), 1)[0]
    return [float(strongest)] if abs(slope) <= SINGLE_RATIO_SLOPE else []


def _lacks_other_lines(X_s, X_t, kappa: complex, runs, h, heard, line: float) -> bool:
    """Whether the target lacks another of the source's lines that a copy of the source would put in it: a line other
    than ``line`` heard at κ over the target's noise (``heard``: :data:`MIN_COPY_DB`) in at least :data:`MIN_RUNS`
    runs, where the target carries under :data:`STRONGEST_HELD` of κ·X_s (the median over those runs).

    A copy scales every line of the source alike; one line of two channels at one complex ratio whose other lines the
    target lacks is a load of the target's own direction in a fixed phase to the source's (a new user's rotor, its
    phases fixed from run to run, with a test stand at 252 Hz on every channel: Fz's 1× line, the axial imbalance,
    followed Fy's departure from C·Ω² through the stand at 0.096 × Fy, read as a copy and taken out, while Fy's
    other lines stood in Fz far under 0.096 of them)."""
    for hv in np.unique(h[heard]):
        sel = (h == hv) & heard
        if hv == line or np.unique(runs[sel]).size < MIN_RUNS:
            continue
        if np.median(np.abs(X_t[sel]) / np.maximum(np.abs(kappa * X_s[sel]), 1e-300)) < STRONGEST_HELD:
            return True
    return False


def _holds_strongest(X_s, X_t, kappa: complex, runs, h, strong) -> bool:
    """Whether the target holds, at the source's strongest line where a copy would stand clear (``strong``), at least
    :data:`STRONGEST_HELD` of the copy κ·X_s there (the median over those runs of |X_t|/|κ·X_s|).

    A copy scales every component of the source alike: the target's own line at that ratio adds to it with a phase of
    its own, and cancels it in one run, not in most.  Lines of one ratio family standing in two channels at one
    complex ratio are also a real force along a fixed direction (an outer-race impact train on a housing, Fz = 0.7·Fx
    on the ball-pass multiples: trial13's impacts cell), which leaves the source's other lines where they are: there
    Fx's imbalance line stood in Fz at 0.07 of 0.7·Fx (the median over 24 runs), and taking 0.7·Fx out of
    Fz put the radial lines, amplified by the radial translation, into the axial direction (axial 1x C x12)."""
    levels = {float(v): float(np.median(np.abs(X_s[(h == v) & strong]))) for v in np.unique(h[strong])}
    if not levels:
        return True
    sel = (h == max(levels, key=lambda v: levels[v])) & strong
    if np.unique(runs[sel]).size < MIN_RUNS:
        return True                     # too few runs to tell
    return bool(np.median(np.abs(X_t[sel]) / np.maximum(np.abs(kappa * X_s[sel]), 1e-300)) >= STRONGEST_HELD)


def _copy_ratio(X_s: np.ndarray, X_t: np.ndarray, sel: np.ndarray) -> complex:
    """κ of the least squares of the target's bins ``X_t`` on the source's ``X_s`` (complex, same shape) over the
    points ``sel`` (bool): Σ X_t·conj(X_s) / Σ |X_s|², each point weighted by the source line's power."""
    return complex(np.sum(X_t[sel] * np.conj(X_s[sel])) / np.sum(np.abs(X_s[sel]) ** 2))


def _pair(X_s, X_t, noise_t, runs, h, cs: str, ct: str, omega) -> ChannelCopy | None:
    """The copy of channel ``cs`` in ``ct`` from the source's points: their transforms ``X_s``, ``X_t``, the target's
    noise there, their runs, line ratios ``h`` and speeds ``omega`` (rad/s); or None."""
    k = X_t / X_s
    ok = np.isfinite(k) & (np.abs(k) > 0)
    if ok.sum() < MIN_RUNS:
        return None
    # the densest cluster of ratios: the point with the most others within the tolerance (a copy's share of the
    # points may be small: the target's own lines at the source's ratios scatter), then its mean, three times
    kk = k[ok]
    support = np.sum(np.abs(kk[:, None] - kk[None, :]) <= CLUSTER_TOLERANCE * np.abs(kk)[:, None], axis=1)
    kappa = complex(kk[int(np.argmax(support))])
    for _ in range(3):
        near = ok & (np.abs(k - kappa) <= CLUSTER_TOLERANCE * max(abs(kappa), 1e-300))
        if near.sum() < MIN_RUNS:
            return None
        kappa = complex(np.mean(k[near]))
    if abs(kappa) == 0:
        return None
    near = ok & (np.abs(k - kappa) <= CLUSTER_TOLERANCE * abs(kappa))
    # κ to the precision the strongest lines give (a copy 80 dB over the noise needs it to 1e-4 to be taken out): the
    # least squares of X_t on X_s over the copy's points, weighted by the lines' power (the ratio's own mean is pulled
    # by the weak lines, whose source carries noise the copy does not)
    kappa = _copy_ratio(X_s, X_t, near)
    # where the copy would stand clear of the target's noise (CLEAR_COPY_DB) its ratio is the copy's to the cluster's
    # tolerance (the strongest line, the one-line copy read there); a line counts in the runs where it would stand
    # MIN_COPY_DB over it, its ratio within the tolerance or within the scatter that noise gives it (NOISE_Z): a
    # noisy test's copied lines stand 10-20 dB over the target's noise (family wheel 2, noise 0.03, 300-3000 rpm:
    # Fz = 0.2·Fy on the cage line h 0.42 over 11 runs, 20 dB in 3, its ratios 0.83-1.19 of κ; on the inner-race
    # line h 6.43 over 7 runs, 20 dB in 1), where the cluster's ±15 % is the noise's own draw
    strong = np.abs(kappa * X_s) ** 2 >= 10 ** (CLEAR_COPY_DB / 10) * noise_t
    heard = np.abs(kappa * X_s) ** 2 >= 10 ** (MIN_COPY_DB / 10) * noise_t
    with np.errstate(divide="ignore", invalid="ignore"):
        fits = near | (ok & heard & ~strong & (np.abs(k - kappa) <= NOISE_Z * np.sqrt(noise_t) / np.abs(X_s)))
    lines = []
    for hv in np.unique(h[fits]):
        sel = (h == hv) & heard
        n_runs = np.unique(runs[sel]).size
        if n_runs >= MIN_RUNS and np.unique(runs[sel & fits]).size >= MIN_RUN_FRACTION * n_runs:
            lines.append(float(hv))
    if len(lines) < MIN_COPIED_LINES:
        lines = _one_line_copy(X_s, X_t, omega, runs, h, near, strong)
        if not lines or _lacks_other_lines(X_s, X_t, kappa, runs, h, heard, lines[0]):
            return None
    elif not _holds_strongest(X_s, X_t, kappa, runs, h, strong):
        return None
    keep = fits & np.isin(h, lines)
    # κ again from the copy's cleanest lines: a line the target also carries itself (a ratio the two directions share)
    # scatters about κ from run to run, one it only copies does not; within the wide cluster such lines pulled κ
    # 10 % off in phase, which left the copy's strongest lines 20 dB down, still over the noise
    spread = {}
    for hv in lines:
        sel = keep & strong & (h == hv)
        if sel.sum() >= 3:
            k_line = np.sum(X_t[sel] * np.conj(X_s[sel])) / np.sum(np.abs(X_s[sel]) ** 2)
            spread[hv] = float(np.median(np.abs(k[sel] - k_line)) / abs(k_line))
    if spread:
        best = min(spread.values())
        clean = [hv for hv, sp in spread.items() if sp <= max(2.0 * best, 1e-3)]
        sel = keep & strong & np.isin(h, clean)
        kappa = _copy_ratio(X_s, X_t, sel)
    else:
        # no line with 3 runs clear of the noise (every copied point 10-20 dB over it): the least squares over all
        # the copy's points, the strict cluster's few alone left κ 5-10 % off
        kappa = _copy_ratio(X_s, X_t, keep)
    level = 10 * np.log10(np.median(np.abs(kappa * X_s[keep]) ** 2 / np.maximum(noise_t[keep], 1e-300)))
    if level < MIN_COPY_DB:
        return None
    return ChannelCopy(cs, ct, kappa, tuple(lines), tuple(sorted(set(int(r) for r in runs[keep]))), float(level))


def remove_channel_copies(test, copies):
    """A copy of ``test`` with each target less κ × its source: x_t − Re(κ·(x_s + j·H[x_s])) (H the Hilbert
    transform: a complex κ is a gain and a phase of the source's every component).  New arrays; the input is not
    changed."""
    from scipy.signal import hilbert

    from ..data import SteadyTest

    runs = []
    for run in test.runs:
        sig = dict(run.signals)
        for cp in copies:
            if run.usable(cp.source) and run.usable(cp.target):
                xs = np.asarray(run.signals[cp.source], dtype=float)
                analytic = hilbert(xs - xs.mean()) + xs.mean()
                sig[cp.target] = sig[cp.target] - np.real(cp.kappa * analytic)
        runs.append(replace(run, signals=sig))
    return SteadyTest(runs, dict(test.meta))


def describe_channel_copies(ctx, copies, shares: dict) -> list:
    """:class:`~rwadist.diagnose.unexplained.Unexplained` records (signature ``channel_copy``) of ``copies``;
    ``shares``: index -> (share, level dB) on the data as given."""
    from .unexplained import Unexplained

    out = []
    for i, cp in enumerate(copies):
        speeds = ctx.omega[list(cp.runs)] * RAD_S_TO_RPM
        f = np.array([h * ctx.omega[r] / (2 * np.pi) for h in cp.lines_h for r in cp.runs])
        if f.size == 0:                 # read on the noise floor alone: every frequency of the spectra
            f = np.asarray(ctx.sp.f, dtype=float)[[1, -1]]
        share, level = shares.get(i, (float("nan"), cp.level_dB))
        gain, phase = abs(cp.kappa), float(np.degrees(np.angle(cp.kappa)))
        # the other sources' lines fit a copy as well, each at its own phase (Fy's a quarter turn from Fx's on a
        # co-rotating line): a crosstalk term is mostly in phase, which the phase of the one named tells
        alt = (f" (or {' or '.join(cp.alternatives)}: the lines fit a copy of either, each at its own phase; "
               f"{cp.source}'s is {phase:+.1f}°)" if cp.alternatives else "")
        out.append(Unexplained(
            signature="channel_copy", channels=(cp.target,), speed_rpm=(float(speeds.min()), float(speeds.max())),
            f_Hz=(float(f.min()), float(f.max())), level_dB=level, share=share, n_runs=len(cp.runs),
            parameters={"source": cp.source, "target": cp.target, "gain": gain, "phase_deg": phase,
                        "lines_h": list(cp.lines_h), "copy_over_noise_dB": cp.level_dB,
                        "other_sources": list(cp.alternatives), "removed_before_the_search": True,
                        "read_on": "noise floor" if cp.floor_z > 0 else "lines", "floor_z": cp.floor_z},
            causes=(f"crosstalk: {cp.target} reads {gain:.3g} × {cp.source}{alt} (the load cell's {cp.target} bridge or "
                    f"its amplifier picking up {cp.source}, a calibration matrix missing that off-diagonal term, "
                    "or a wiring fault)",),
            would_tell=f"a calibration check loading {cp.source} alone (a known force or moment along it) shows "
                       f"{cp.target} respond by {gain:.3g}; swapping the two channels' amplifiers tells the cell from "
                       "the electronics"))
    return out
