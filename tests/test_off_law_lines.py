"""Which lines the extended fit frees past its cap (rwadist/off_law_lines.py), on a least squares with a closed form.

The problem: each measured line's log amplitude residual is δ_j·(ln|Ω| − mean) plus small noise, so freeing line j
(its exponent shift fitted: the rows' projection on their centred ln|Ω|) leaves only the noise.  Four lines: h 2.0 and
h 3.2994 (radial force) trend most and are freed first, up to the cap of 2; then h 3.3003 (radial torque: the same
physical line, its h measured on its own direction) must follow, while h 5.0 must not.
"""
import numpy as np

from rwadist.extended import LAW_H_TOL
from rwadist.off_law_lines import MAX_OFF_LAW_LINES, free_off_law_lines, same_harmonic


def _problem(shifts, n_rows=30, seed=0):
    rng = np.random.default_rng(seed)
    omega = np.linspace(30.0, 300.0, n_rows)
    log_w = np.tile(np.log(omega), len(shifts))
    row_line = np.repeat(np.arange(len(shifts)), n_rows)
    centred = log_w - np.log(omega).mean()
    r = np.asarray(shifts)[row_line] * centred + 1e-3 * rng.standard_normal(row_line.size)

    class Result:
        def __init__(self, fun):
            self.fun = fun

    def fit_with(freed):
        fun = r.copy()
        for j in freed:
            m = row_line == j
            fun[m] -= centred[m] * (centred[m] @ r[m]) / (centred[m] @ centred[m])
        return (Result(fun),)

    return fit_with, row_line, log_w


def test_a_freed_harmonics_other_direction_follows_past_the_cap_within_the_models_tolerance():
    line_h = [2.0, 3.2994, 3.3003, 5.0]
    assert abs(line_h[2] - line_h[1]) < LAW_H_TOL
    assert round(line_h[1], 3) != round(line_h[2], 3)  # the two reads round to different thirds
    fit_with, row_line, log_w = _problem([0.9, 0.6, 0.3, 0.3])
    off_law: list = []
    free_off_law_lines(fit_with, lambda fit: [], off_law, row_line, log_w, (), line_h)
    assert off_law[:MAX_OFF_LAW_LINES] == [0, 1]
    assert sorted(off_law) == [0, 1, 2]


def test_without_line_harmonics_nothing_follows_past_the_cap():
    fit_with, row_line, log_w = _problem([0.9, 0.6, 0.3, 0.3])
    off_law: list = []
    free_off_law_lines(fit_with, lambda fit: [], off_law, row_line, log_w)
    assert off_law == [0, 1]


def test_same_harmonic_is_the_models_tolerance():
    h = [3.3, 3.3 + 0.99 * LAW_H_TOL, 3.3 + 1.01 * LAW_H_TOL]
    assert same_harmonic(1, [0], h) and not same_harmonic(2, [0], h)
    assert same_harmonic(0, [0]) and not same_harmonic(1, [0])


def test_a_follower_past_the_cap_does_not_chain_the_match():
    """h 3.2994 freed up to the cap; 3.3003 follows (within 0.001 of it); 3.3012 is 0.0018 from 3.2994 and must not
    follow through 3.3003."""
    line_h = [2.0, 3.2994, 3.3003, 3.3012]
    fit_with, row_line, log_w = _problem([0.9, 0.6, 0.3, 0.2])
    off_law: list = []
    free_off_law_lines(fit_with, lambda fit: [], off_law, row_line, log_w, (), line_h)
    assert sorted(off_law) == [0, 1, 2]
