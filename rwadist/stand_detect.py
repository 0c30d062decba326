"""A fixture (test-stand) resonance proposed from an empirical fit's line gains: where one frequency lifts the lines of
every load direction.

A resonance of the stand lifts the lines of EVERY load direction at one frequency; a wheel mode lifts one direction
(translation the radial forces, rocking the radial torques, axial the axial force).  This module reads that signature
from the lines' log power gains over their hard-mounted law C·Ω² (:func:`stand_starts`, :func:`further_stand_starts`)
and proposes starts (f_r Hz, ζ, peak gain, gain above) for the joint fit of the stand and the modes
(:func:`rwadist.stand_resonance.fit_extended_beside_stand`), which measures the stand or rejects it.
"""
from __future__ import annotations

import numpy as np

from .resonance import general_log_power_gain, peak_of, resonance

#: Smallest local lift (mean over a direction's lines of the ln power gain near one frequency over the same line's
#: gains on both sides, :func:`local_lift`) a fixture resonance must show in EVERY load direction with lines there to
#: be proposed: a power gain of 1.5.  A wheel mode amplifies one direction's lines (translation the radial forces,
#: rocking the radial torques, axial the axial force); only a resonance of the stand lifts them all at one frequency.
STAND_MIN_LOG_GAIN = float(np.log(1.5))


def log_power_gain(e, f_hz) -> np.ndarray:
    """ln|H(f)|² of the fixed resonance ``e`` (its f_r Hz, zeta, peak_gain, gain_above: :func:`rwadist.resonance.resonance`)
    at ``f_hz`` (Hz, any shape), |H|² held at 1e-300 or more: where its magnitude reaches :data:`STAND_MIN_LOG_GAIN` the
    resonance changes a line's power by a factor 1.5 or more, up or down (the stand detection's own threshold)."""
    return np.log(np.maximum(np.abs(resonance(f_hz, e.f_r, e.zeta, e.peak_gain, e.gain_above)) ** 2, 1e-300))


#: Largest damping ratio of a proposed fixture resonance: a fixture resonance is sharp; a "resonance" as wide as
#: the fit allows (ζ → 0.5) is a broad tilt of the line gains (a wheel mode's skirt, model error), not a stand.
STAND_MAX_ZETA = 0.2
#: Smallest damping ratio of a fixture resonance: the fits' lower bound is 0.001 (:func:`fit_on_lines`,
#: :class:`rwadist.resonance.FittedResonance`, :class:`rwadist.effects.fixed_resonance_diagnose.FixedResonance`); a fit that ends there measured no width -- a
#: "resonance" narrower than the lines resolve, one line's misfit at one speed lifted by a gain of 20-40.
STAND_MIN_ZETA = 0.0015
#: Half width of the window (relative to the frequency) in which a line's log gains are averaged (its neighbourhood:
#: 2-5 times as far on both sides, :func:`local_lift`).
STAND_WINDOW = 0.05


def line_log_gains(fit, known: tuple = ()) -> dict:
    """(direction, h) -> (f Hz, y) of every measured line amplitude of an empirical fit: f = h|Ω|/2π and
    y = 2 ln(a / (C·Ω²)), the log power gain over the line's hard-mounted law, less ln|H(f)|² of each fixture
    resonance of ``known`` ((f_r Hz, ζ, peak gain, gain above) each: stands already fitted with the modes)."""
    out: dict[tuple[str, float], tuple[list[np.ndarray], list[np.ndarray]]] = {}
    for x in fit.lines:
        w = np.abs(np.asarray(x.speed, dtype=float))
        a = np.asarray(x.amplitude, dtype=float)
        ok = np.isfinite(a) & (a > 0) & (w > 0)
        if x.C <= 0 or not ok.any():
            continue
        f, y = out.setdefault((x.direction, float(x.h)), ([], []))
        f.append(x.h * w[ok] / (2 * np.pi))
        y.append(2.0 * np.log(a[ok] / (x.C * w[ok] ** 2)))
    got = {d: (np.concatenate(f), np.concatenate(y)) for d, (f, y) in out.items()}
    for k in known:
        got = {d: (f, y - np.log(np.maximum(np.abs(resonance(f, *k)) ** 2, 1e-300))) for d, (f, y) in got.items()}
    return got


def local_lift(f, y, grid, min_points):
    """Mean of y over the points within ±STAND_WINDOW of each grid frequency less the mean of y over its points 2-5 ×
    STAND_WINDOW below and above it (the mean of the two sides' means; one side where the line's points end on the
    other: a line whose top speed puts it on the stand's flank); NaN where fewer than ``min_points`` points lie within
    ±STAND_WINDOW (one where the line's points are that sparse) or none on either side."""
    rel = f[None, :] / grid[:, None] - 1.0
    inner = np.abs(rel) <= STAND_WINDOW
    below = (rel < -2 * STAND_WINDOW) & (rel >= -5 * STAND_WINDOW)
    above = (rel > 2 * STAND_WINDOW) & (rel <= 5 * STAND_WINDOW)
    n_in, n_lo, n_hi = inner.sum(1), below.sum(1), above.sum(1)
    need = min(min_points, max(1, int(np.ceil(f.size / 20))))
    with np.errstate(invalid="ignore", divide="ignore"):
        side = np.where((n_lo > 0) & (n_hi > 0), 0.5 * ((below @ y) / n_lo + (above @ y) / n_hi),
                        np.where(n_lo > 0, (below @ y) / n_lo, (above @ y) / n_hi))
        lift = (inner @ y) / n_in - side
    return np.where((n_in >= need) & ((n_lo > 0) | (n_hi > 0)), lift, np.nan)


def is_fixture_resonance(zeta: float, peak_gain: float) -> bool:
    """True when a resonance of damping ratio ``zeta`` and peak gain ``peak_gain`` (|H| at f_r) can be a fixture's:
    at most :data:`STAND_MAX_ZETA` wide (broader is a tilt of the line gains: a wheel mode's skirt, an amplitude
    law's growth, model error), at least :data:`STAND_MIN_ZETA` (narrower is no measured width) and lifting the lines
    by at least 1 + :data:`STAND_MIN_LOG_GAIN`/2.  The one rule of the stand's detection (:func:`stand_starts`)
    and of the stand fitted with the modes (:func:`stand_confirmed`)."""
    return bool(STAND_MIN_ZETA <= zeta <= STAND_MAX_ZETA and peak_gain >= 1.0 + STAND_MIN_LOG_GAIN / 2)


#: Frequencies at which a fixture resonance is proposed at most (:func:`_stand_frequencies`): the best and, for the
#: fits that confirm no stand there, one more (:func:`further_stand_starts`)
STAND_FREQUENCIES = 2
#: Relative distance between two proposed frequencies at least (as :func:`rwadist.stand_resonance.structure_mode_starts`)
STAND_FREQUENCY_APART = 0.1


def _stand_frequencies(fit, min_points: int = 2, known: tuple = ()):
    """(the frequencies (Hz, best first), the lines' log gains by line) where a fixture resonance lifts every
    direction in ``fit``, or None when there is none: :data:`STAND_FREQUENCIES` at most, each
    :data:`STAND_FREQUENCY_APART` from the others; ``known``: stands already fitted, divided out of the gains
    (:func:`line_log_gains`) and not proposed again (no f within :data:`STAND_WINDOW` of one).

    The signature of a stand resonance is one frequency at which the lines of every load direction are lifted (a
    wheel mode lifts one direction only).  Score of a frequency f: the smallest, over the directions with lines
    there, of the mean over the direction's lines of each line's local lift at f (:func:`local_lift`: its log
    power gains within ±:data:`STAND_WINDOW` of f over its own gains on both sides, at least ``min_points`` of them
    where the line's points are that dense); the f where the score is best, when it reaches :data:`STAND_MIN_LOG_GAIN`
    in two directions or more, then the next best so far from it.
    """
    # every line the data show, at every speed (a line lifted by the stand at most of its speeds is dropped from the
    # fit with modal exclusion: the E wheel's radial-force lines near a 180 Hz stand at 300-2400 rpm)
    by_line = line_log_gains(getattr(fit, "without_mode_exclusion", fit), known)
    if len({d for d, _ in by_line}) < 2:
        return None
    f_all = np.concatenate([f for f, _ in by_line.values()])
    lo, hi = float(np.min(f_all)), float(np.max(f_all))
    if hi <= lo * (1 + 2 * STAND_WINDOW):
        return None
    grid = np.exp(np.arange(np.log(lo), np.log(hi), 0.005))                     # 0.5 % steps
    # each line's lift at f over its own gains on both sides of f: the offset of its C·Ω² law and a wheel mode's
    # broad skirt (the new wheel's three modes lift each direction over most of the band) cancel; the mean over a
    # direction's lines; the smallest over the directions with lines measured there, where two directions or more
    # have them: a direction with no line measured near f (on a short record the empirical fit resolves fewer lines:
    # 2048 samples kept no radial-force line within 5 % of a 180 Hz stand) neither lifts nor rules out f
    dirs = sorted({d for d, _ in by_line})
    total, count = np.zeros((len(dirs), grid.size)), np.zeros((len(dirs), grid.size))
    for (d, _h), (f, y) in by_line.items():
        c = local_lift(f, y, grid, min_points)
        ok = np.isfinite(c)
        total[dirs.index(d)] += np.where(ok, c, 0.0)
        count[dirs.index(d)] += ok
    seen = count > 0
    means = total / np.maximum(count, 1)
    score = np.where(seen.sum(0) >= 2, np.min(np.where(seen, means, np.inf), axis=0), -np.inf)
    for k in known:
        score[np.abs(grid / k[0] - 1.0) <= STAND_WINDOW] = -np.inf
    found: list[float] = []
    for i in np.argsort(-score, kind="stable"):
        if not score[i] >= STAND_MIN_LOG_GAIN or len(found) == STAND_FREQUENCIES:
            break
        if all(abs(grid[i] / f - 1) > STAND_FREQUENCY_APART for f in found):
            found.append(float(grid[i]))
    return (found, by_line) if found else None


def _stand_frequency(fit, min_points: int = 2, known: tuple = ()):
    """(f Hz, the lines' log gains by line) of the best frequency of :func:`_stand_frequencies`, or None."""
    got = _stand_frequencies(fit, min_points, known)
    return None if got is None else (got[0][0], got[1])


def stand_resonance_start(fit, min_points: int = 2):
    """(f_r Hz, ζ, peak gain, gain above) of a fixture resonance seen in the empirical fit ``fit``, or None: the first
    of :func:`stand_starts`."""
    starts = stand_starts(fit, min_points)
    return starts[0] if starts else None


def stand_starts(fit, min_points: int = 2, known: tuple = ()) -> list:
    """Starts (f_r Hz, ζ, peak gain, gain above) of the fixture resonance seen in the empirical fit ``fit``: none when
    :func:`_stand_frequency` sees none; else the resonance fitted on every direction's lines (:func:`fit_on_lines`),
    then the one of each direction alone that is a fixture resonance within ±5 % of it, weakest first.  A wheel mode
    beside the stand lifts its own direction's lines by the mode times the stand (the axial mode at 140 Hz beside a
    stand at 142 Hz: the pooled fit 138.6 Hz, gain 12.6 for a stand of gain 5), so the direction lifted least is the
    stand's best start where a mode sits on one direction.  ``known``: stands already fitted with the modes, divided
    out of the line gains first (:func:`line_log_gains`): the starts of another stand beside them."""
    found = _stand_frequency(fit, min_points, tuple(known))
    if found is None:
        return []
    f_s, by_line = found
    pooled = fit_on_lines(by_line, f_s)
    out = [] if pooled is None else [pooled]
    dirs = sorted({d for d, _ in by_line})
    own = [fit_on_lines({k: v for k, v in by_line.items() if k[0] == d}, f_s) for d in dirs]
    ref = f_s if pooled is None else pooled[0]
    own = sorted((o for o in own if o is not None and abs(o[0] / ref - 1) <= 0.05), key=lambda o: o[2])
    for o in own:
        if not any(abs(o[0] / q[0] - 1) < 0.005 and abs(np.log(o[2] / q[2])) < 0.05 for q in out):
            out.append(o)
    return out


def further_stand_starts(fit, min_points: int = 2, known: tuple = ()) -> list:
    """Starts (f_r Hz, ζ, peak gain, gain above) of a fixture resonance at the frequencies of :func:`_stand_frequencies`
    after the best (each the resonance fitted on every direction's lines there, :func:`fit_on_lines`): tried by the
    joint fit with the modes only when no start of :func:`stand_starts` is confirmed.

    Two fixtures lift the lines at two frequencies; the one scored best is not always the one the modes can be fitted
    beside.  A 12-kg wheel (translation 110 Hz, rocking 45 Hz, axial 160 Hz) on fixtures at 80 and 270 Hz: only the
    h 6.6 lines reach 270 Hz, in two directions, and scored it 2.89 against the 80 Hz stand's 2.80 in all four; beside
    the 270 Hz stand alone the 80 Hz one, between the rocking and the translation, left every mode unconstrained (cost
    293), and no stand was kept; beside the 80 Hz one the modes were located within 0.02 % and the 270 Hz stand then
    found beside it (:func:`rwadist.stand_resonance.beside_more_stands`), cost 0.25."""
    got = _stand_frequencies(fit, min_points, tuple(known))
    if got is None:
        return []
    frequencies, by_line = got
    starts = (fit_on_lines(by_line, f_s) for f_s in frequencies[1:])
    return [s for s in starts if s is not None]


#: Window (factors of f_r) of the line gains a fixture resonance is fitted on: wide enough to see where the gain
#: ends above the resonance (a transmissibility's |H| crosses 1 at sqrt(2)·f_r)
GENERAL_WINDOW = (0.5, 2.0)
#: Damping ratio a start is given when the lines alone do not resolve the stand's width (:func:`fit_on_lines`): the
#: smallest of that fit's own starting values; the joint fit with the modes measures it
UNRESOLVED_START_ZETA = 0.01
#: Evaluations of one start's least squares at most (:func:`fit_on_lines`).  The starts converge in 15-300; one that
#: does not crawls along the width's floor where the lines do not resolve the peak (family wheel 2 clean, its 90 Hz
#: translation seen as a stand: 1700 evaluations, 1.2 s, each to ζ 0.0023, gain 8.9; stopped at 200: ζ 0.0028, gain 8.3).
#: What it proposes is a start: the joint fit with the modes measures the stand or rejects it.
START_MAX_NFEV = 200


def fit_on_lines(by_line: dict, f_s: float):
    """(f_r Hz, ζ, peak gain, gain above) of the fixture resonance near ``f_s`` fitted to the lines' log power gains
    ``by_line`` ((direction, h) -> (f Hz, y)) within :data:`GENERAL_WINDOW` of f_s, or None when it is no fixture
    resonance (:func:`is_fixture_resonance`).

    Robust (soft-L1) least squares of y = a_line + b_direction·ln(f/f_s) + ln|H(f)|², H the general single-mode gain
    (:mod:`rwadist.resonance`, f_r within ±10 % of f_s): each line's own offset a (its C·Ω² law was fitted on speeds
    that the fixture lifts or lowers, so its gains are offset by its own amount), each direction's own tilt b (a
    wheel mode's skirt beside the stand is one direction's), the resonance common to all.  Started from H → 1 above
    (β = 1) and from a transmissibility (β = 0, γ = 1), ζ ∈ {0.01, 0.03, 0.1}; the best kept."""
    from scipy.optimize import least_squares

    fs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    lines: list[np.ndarray] = []
    whichs: list[np.ndarray] = []
    dirs = sorted({d for d, _ in by_line})
    for j, ((d, _h), (fd, yd)) in enumerate(by_line.items()):
        near = (fd >= GENERAL_WINDOW[0] * f_s) & (fd <= GENERAL_WINDOW[1] * f_s)
        fs.append(fd[near])
        ys.append(yd[near])
        lines.append(np.full(int(near.sum()), j))
        whichs.append(np.full(int(near.sum()), dirs.index(d)))
    f, y, line, which = (np.concatenate(v) for v in (fs, ys, lines, whichs))
    if f.size < 8:
        return None
    _, line = np.unique(line, return_inverse=True)
    n_line, n_dir = int(line.max()) + 1, len(dirs)
    lf = np.log(f / f_s)
    rows = np.arange(f.size)

    last: dict = {}

    def res_jac(x):
        # scipy asks the residuals, then the Jacobian at the same point: both made once (a copy of each handed out:
        # the robust loss scales what it is given in place)
        key = x.tobytes()
        if last.get("x") != key:
            lg, d = general_log_power_gain(f, float(np.exp(x[0])), float(np.exp(x[1])), float(x[2]), float(x[3]))
            J = np.zeros((f.size, x.size))
            J[:, :4] = -d
            J[rows, 4 + line] = -1.0
            J[rows, 4 + n_line + which] = -lf
            last.update(x=key, r=y - x[4 + line] - x[4 + n_line + which] * lf - lg, J=J)
        return last["r"].copy(), last["J"].copy()

    n_free = n_line + n_dir
    lb = np.concatenate([[np.log(0.9 * f_s), np.log(1e-3), 0.0, -1.0], np.full(n_free, -np.inf)])
    ub = np.concatenate([[np.log(1.1 * f_s), np.log(0.3), 200.0, 3.0], np.full(n_free, np.inf)])
    # each line's offset started at its median gain outside ±10 % of f_s (where a sharp resonance lifts little)
    off = np.array([np.median(y[(line == k) & (np.abs(lf) > 0.1)]) if np.any((line == k) & (np.abs(lf) > 0.1))
                    else np.median(y[line == k]) for k in range(n_line)])
    near = np.abs(lf) <= 0.05
    g0 = float(np.clip(np.exp(np.max(y[near] - off[line[near]]) / 2.0) if near.any() else 3.0, 1.2, 100.0))
    sols = []
    for zeta in (0.01, 0.03, 0.1):
        for gamma, beta in ((g0, 1.0), (1.0, 0.0)):
            x0 = np.concatenate([[np.log(f_s), np.log(zeta), gamma, beta], off, np.zeros(n_dir)])
            sols.append(least_squares(lambda x: res_jac(x)[0], x0, jac=lambda x: res_jac(x)[1], loss="soft_l1",
                                      f_scale=0.5, bounds=(lb, ub), max_nfev=START_MAX_NFEV))
    best = min(sols, key=lambda sol: sol.cost)      # the first of the lowest cost
    zeta = float(np.exp(best.x[1]))
    out = (float(np.exp(best.x[0])), zeta, peak_of(zeta, float(best.x[2]), float(best.x[3])), float(best.x[3]))
    if zeta < STAND_MIN_ZETA and out[2] > 1.0:
        # the width runs to the fit's floor: the lines cross the stand too sparsely to resolve it (family wheel 7,
        # 16 speeds to 10000 rpm, each line one point within ±5 % of a 200 Hz stand on its axial mode: ζ 0.001, gain
        # 200), and measure only the lift off its peak, ζ·g.  That start, at a width the fit can leave, is proposed:
        # the joint fit with the modes measures the width (200.2 Hz, ζ 0.031, gain 4.9 there) or rejects the stand
        # (:func:`stand_confirmed`)
        out = (out[0], UNRESOLVED_START_ZETA, max(out[2] * zeta / UNRESOLVED_START_ZETA, 1.0), out[3])
    return out if is_fixture_resonance(out[1], out[2]) else None

