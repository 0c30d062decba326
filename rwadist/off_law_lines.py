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

#: Lines of a law other than C·Ω² whose exponent the least squares may free before a mode is declared not
#: constrained (:func:`off_law_line`): one such line (an amplitude law, a foreign load) is what drags a mode to the
#: ±5 % limit while every other line places it.
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
