"""Lines of another law than C·Ω² in the extended fit's least squares (:func:`rwadist.extended_fit.fit_extended`).

A load on one harmonic that grows as |Ω|^p, p ≠ 2 (an amplitude law), sent through the wheel's suspension modes,
is a line the extended model (C·Ω² through the modes) cannot follow: in the log-amplitude least squares its
systematic misfit drags the modes it overlaps (the radial translation to the ±5 % limit, where the fit declares it
not constrained) while every other line places them.  Before declaring a mode, the fit frees the exponent of the
line that trends most in ln|Ω| (:func:`off_law_line`) and keeps that when it pins more modes.
"""
from __future__ import annotations

import math

import numpy as np

from .extended import IMBALANCE_H_TOL, LAW_H_TOL

#: Lines of a law other than C·Ω² whose exponent the least squares may free before a mode is declared not
#: constrained (:func:`off_law_line`): one such line (an amplitude law, a foreign load) is what drags a mode to the
#: ±5 % limit while every other line places it.  Beyond it, only the other directions' lines of a harmonic already
#: freed: a law of a line's source (a bearing defect's impacts) is the law of that harmonic in every direction it
#: loads -- radial force, radial torque, axial force, each a measured line of the fit -- and one of them left C·Ω²
#: drags the mode it crosses (trial21's Ω^2.6 on h 3.3: radial force and Fz freed, the radial torque's crossing of
#: the forward whirl at 1064 rpm pulled the rocking damping to 0.0545, truth 0.02).  A third harmonic is not freed:
#: family wheel 0's axial resonance stiffening with speed lifts its h 3.08 lines, and a third freed harmonic (4.92)
#: left the axial mode to be declared instead of fitted beside that resonance.
MAX_OFF_LAW_LINES = 2
#: A line is off its C·Ω² law when the trend of its log residual in ln|Ω| (its exponent shift) lies at least this
#: many standard errors from 0 ...
OFF_LAW_Z = 4.0
#: ... and is at least this large (the accuracy asked of a fitted exponent, as diagnose's ``amplitude_law``).
OFF_LAW_MIN_SHIFT = 0.05


def off_law_line(r: np.ndarray, row_line: np.ndarray, log_w: np.ndarray, skip) -> int | None:
    """The measured line whose log residuals ``r`` (one per row; ``row_line`` its line, ``log_w`` ln|Ω|) trend
    most in ln|Ω| -- the line least like C·Ω² through the fitted modes -- or None when no line (outside ``skip``)
    has a trend of at least :data:`OFF_LAW_MIN_SHIFT` and :data:`OFF_LAW_Z` standard errors.  Ranked by the RMS
    of the trend itself (|b|·std ln|Ω|): the misfit an exponent of its own would take away."""
    best, best_rms = None, 0.0
    for j in np.unique(row_line):
        m = row_line == j
        if int(j) in skip or m.sum() < 5:
            continue
        L = log_w[m] - log_w[m].mean()
        sxx = float(L @ L)
        if sxx <= 0:
            continue
        b = float(L @ r[m]) / sxx
        e = r[m] - r[m].mean() - b * L
        se = math.sqrt(float(e @ e) / max(int(m.sum()) - 2, 1) / sxx)
        trend_rms = abs(b) * math.sqrt(sxx / m.sum())
        if abs(b) >= OFF_LAW_MIN_SHIFT and abs(b) >= OFF_LAW_Z * se and trend_rms > best_rms:
            best, best_rms = int(j), trend_rms
    return best


def line_regressors(ax_line: np.ndarray, rad_line: np.ndarray, ax_omega: np.ndarray, rad_omega: np.ndarray):
    """(row_line, log_w, centred) per least-squares row (the axial rows, then the radial ones): the measured line
    (index), ln|Ω| and ln|Ω| less its mean over that line's rows, the regressor L of a freed exponent (residual
    r −= δ·L: amplitude ∝ C·Ω²·(|Ω|/Ω_line)^δ, δ = p − 2, uncorrelated with the line's C).  Arrays (n_rows,)."""
    row_line = np.concatenate([ax_line, rad_line]).astype(int)
    log_w = np.log(np.maximum(np.abs(np.concatenate([ax_omega, rad_omega])), 1e-300))
    centred = log_w.copy()
    for j in np.unique(row_line):
        centred[row_line == j] -= log_w[row_line == j].mean()
    return row_line, log_w, centred


def free_off_law_lines(fit_with, loose_of, off_law: list, row_line: np.ndarray, log_w: np.ndarray,
                       lawful: tuple = (), line_h=None):
    """(fit, loose) of the least squares ``fit_with(off_law)`` (a tuple whose first item is the scipy result) with
    ``loose_of(fit)`` its modes not pinned; while fewer than :data:`MAX_OFF_LAW_LINES` lines are freed, the line
    :func:`off_law_line` picks (never one of ``lawful``: the imbalances, whose U·Ω² is their physics,
    :func:`lawful_lines`) is freed when that pins more modes, or as many and explains the lines better by more than
    its one parameter (:func:`_explains_more`; ``off_law`` is appended in place).  Once :data:`MAX_OFF_LAW_LINES`
    lines are freed, only the other directions' lines of a harmonic already freed may follow (``line_h``: each
    measured line's h; None: none may).

    Is one line of another law (an amplitude law on one harmonic, Ω³ where the model says Ω²) dragging the modes off
    while the other lines place them?  Before a located mode is declared not constrained, and also when every mode is
    pinned: a bearing line of the new wheel growing as Ω^2.6 across its translation mode (310 Hz at 6000 rpm) left the
    mode 1 % low, found, and the search then named the law at Ω^2.54 with a resonance invented beside it.  That line then informs
    the modes only through its shape across them; it stays C·Ω² in the model, said in the notes
    (:func:`off_law_note`), for ``rwadist diagnose`` to name its law."""
    fit = fit_with(off_law)
    loose = loose_of(fit)
    n_lines = int(row_line.max()) + 1 if row_line.size else 0
    while True:
        skip = list(off_law) + list(lawful)
        if len(off_law) >= MAX_OFF_LAW_LINES:
            # the harmonics are those of the lines freed up to the cap (a match never chains from a follower)
            skip += [k for k in range(n_lines) if not same_harmonic(k, off_law[:MAX_OFF_LAW_LINES], line_h)]
        j = off_law_line(fit[0].fun, row_line, log_w, skip)
        if j is None:
            break
        trial = fit_with(off_law + [j])
        trial_loose = loose_of(trial)
        if len(trial_loose) > len(loose) or (len(trial_loose) == len(loose)
                                             and not _explains_more(fit[0].fun, trial[0].fun)):
            break
        off_law.append(j)
        fit, loose = trial, trial_loose
    return fit, loose


def same_harmonic(k: int, freed: list, line_h=None) -> bool:
    """True when measured line ``k`` is one of the ``freed`` lines' harmonics: its h (``line_h``, one per measured
    line) within :data:`rwadist.extended.LAW_H_TOL` of a freed line's, the tolerance within which the model takes two
    directions' lines for one harmonic (each direction's h is measured on its own, so 3.2994 and 3.3003 are one line;
    rounding both to 3 decimals had called them two).  Without ``line_h`` only the freed lines themselves."""
    if line_h is None:
        return k in freed
    return any(abs(float(line_h[k]) - float(line_h[j])) < LAW_H_TOL for j in freed)


def lawful_lines(meas_lines: list) -> tuple:
    """Indices of the measured lines (``direction``, ``h``) whose law is known: the imbalances (a radial line within
    :data:`rwadist.extended.IMBALANCE_H_TOL` of h = 1, a mass off the spin axis: U·Ω²).  Their trend in speed is what
    the modes make of them, so it is never freed: freed, the imbalance of a wheel with I_zz/I_rr > 2 (its forward
    whirl never crossed by the 1x line, whose transmissibility is then a smooth trend in speed) no longer told the
    rocking f0 from I_zz/I_rr, and an amplitude law was invented on it (family wheel 2)."""
    return tuple(j for j, x in enumerate(meas_lines)
                 if x.direction in ("radial_force", "radial_torque") and abs(x.h - 1.0) <= IMBALANCE_H_TOL)


def _explains_more(r0: np.ndarray, r1: np.ndarray) -> bool:
    """True when the log residuals ``r1`` of the least squares with one more line's exponent free leave less than
    those ``r0`` without it by the likelihood ratio of a trend :data:`OFF_LAW_Z` standard errors from 0:
    n·ln(SSR0/SSR1) >= OFF_LAW_Z²."""
    s0, s1 = float(np.sum(r0**2)), float(np.sum(r1**2))
    return bool(s1 > 0 and r0.size * np.log(s0 / s1) >= OFF_LAW_Z**2)


#: A freed exponent that changes its line by less than this over the line's measured speeds (dB) is no law worth
#: naming: the fit freed it for the modes' sake, and the note says it stays within this of C·Ω²
OFF_LAW_NOTE_DB = 1.0


def off_law_note(line, shift: float, stderr: float) -> str:
    """The fit's note on a freed line (an empirical line: ``direction``, ``h``, ``speed`` rad/s (n,)) of exponent
    2 + ``shift`` (± ``stderr``).  A shift that moves the line by less than :data:`OFF_LAW_NOTE_DB` over its speeds
    is said to be within that of C·Ω², not a law: an exponent of 1.99 ± 0.002 over 8:1 in speed (0.2 dB) is
    significant to the least squares and nothing to a reader (trial 29, a wheel without modes fitted extended)."""
    speed = np.abs(np.asarray(getattr(line, "speed", ()), dtype=float))
    speed = speed[speed > 0]
    span_db = abs(shift) * 20 * np.log10(speed.max() / speed.min()) if speed.size else np.inf
    head = f"{line.direction} h={line.h:.4g}: "
    if span_db < OFF_LAW_NOTE_DB:
        return (head + f"its exponent was left free in the fit so that it does not pull the modes off (|Ω|^{2 + shift:.3g}"
                f" ±{stderr:.2g}); over its speeds that is within {span_db:.1g} dB of C·Ω², as the model keeps it")
    return (head + f"its amplitude grows as |Ω|^{2 + shift:.3g} (±{stderr:.2g}), not as "
            "C·Ω² through the modes: its exponent was left free in the fit so that it does not pull the modes off; "
            "the model keeps the line as C·Ω² (a law the wheel's modes do not explain: `rwadist diagnose` names it)")
