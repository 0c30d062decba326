"""Locate each suspension mode from the measured lines by a profile scan, or say it is not constrained.

The interface load of a rigid rotor on its suspension depends on the mode only through ratios:
radial translation on f_T = sqrt(k/M)/2π and ζ_T (c/M = 2ζω), rocking on f_0 = sqrt(k_θ/I_rr)/2π,
ζ_θ and a = I_zz/I_rr (gyroscopic whirl f± = sqrt((aΩ/2)² + ω0²) ± aΩ/2), axial on f_z, ζ_z.  For a
complex-coordinate load e^{iνt} (ν > 0 with the spin, ν < 0 against it) at wheel speed Ω::

    T(ν) = (ω0² + 2iζω0ν) / (ω0² − ν² + aΩν + 2iζω0ν)      (a = 0 for translation and axial)

A radial line's measured power x² + y² is Ω⁴(P_co|T(+hΩ)|² + P_counter|T(−hΩ)|²): for a given
(f0, ζ, a) the two non-negative forcing powers are solved per line in closed form (:func:`_grid_search`).  Both
whirls therefore enter: co-rotating content meets the forward
whirl, counter-rotating content the backward whirl, over whatever speeds the data cover.  An axial
line has one coefficient.

The scan evaluates the log power residual Σ ln²(model/data) on a grid of (f0, ζ, a) and keeps
the profile over f0 (minimum over ζ, a and the forcing).  A mode is **found** when its profile has
an interior minimum that is sharp: every f0 more than ``tolerance`` away from the best one fits
worse by a log-likelihood ratio of at least ``min_log_lr`` (n/2·ln(SSR/SSR_best), n measurements;
2.0 is about the 95 % level of one parameter, Δχ² = 3.84) -- the data then exclude a frequency
error larger than the tolerance.  The profile uses f0 steps of 1 % (2 % when a is scanned), ζ steps
of a factor 1.6 (2.0) and a-steps of 0.2; the best point is refined to 0.1 % (the least squares that
follows refines it).  Otherwise the data do not
constrain the mode (no line comes near it, only a skirt is seen, or the whirl it shows trades off
against I_zz/I_rr) and the result says so; nothing is invented.

:func:`rwadist.extended_fit.fit_extended` uses the scan only to locate each mode (interior best point,
``min_log_lr = -inf``) and decides "found" from its log-amplitude least squares (standard error of
the frequency), which measured more reliable than this profile on edge-of-range cases.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .extended import IMBALANCE_H_TOL
from .off_law_lines import OFF_LAW_Z
from .schema import MAX_INERTIA_RATIO

#: modes scanned and the measured direction that shows each
MODE_DIRECTION = {"radial_translation": "radial_force", "rocking": "radial_torque", "axial_translation": "axial_force"}


@dataclass
class ModeScan:
    """Result of :func:`scan_mode`.

    mode : "radial_translation" | "rocking" | "axial_translation".
    found : whether the data locate the mode (see the module docstring).
    f0_hz, zeta, inertia_ratio : best grid point (inertia_ratio a = I_zz/I_rr; 0 for translations).
    log_lr_off : n/2·ln(SSR/SSR_best) of the best f0 farther than the tolerance (how sharply the
        data place the mode; ``inf`` never, 0 when a distant f0 fits as well).
    interval_hz : (low, high) f0 range whose profile stays within ``min_log_lr`` of the best.
    reason : why not found ('' when found).
    n : number of measurements used.
    """

    mode: str
    found: bool
    f0_hz: float
    zeta: float
    inertia_ratio: float
    log_lr_off: float
    interval_hz: tuple
    reason: str
    n: int


def transmissibility_sq(nu, omega, f0_hz, zeta, a):
    """|T(ν)|² on a grid: ``nu``, ``omega`` (rows,) rad/s; ``f0_hz``, ``zeta``, ``a`` (grid,) -> (grid, rows), in
    real arithmetic: |T|² = (ω0⁴ + d²)/((ω0² − ν² + aΩν)² + d²) with d = 2ζω0ν (the scan's :func:`_grid_search`
    evaluates the same expression on its product grid)."""
    w0 = 2 * np.pi * np.asarray(f0_hz, float)[:, None]
    z = np.asarray(zeta, float)[:, None]
    a = np.asarray(a, float)[:, None]
    nu = np.asarray(nu, float)[None, :]
    om = np.abs(np.asarray(omega, float))[None, :]
    w02 = w0**2
    d2 = (2 * z * w0 * nu) ** 2
    return (w02**2 + d2) / ((w02 - nu**2 + a * om * nu) ** 2 + d2)


class _Segments:
    """Per-line sums over the last axis (the rows sorted by line: ``starts``, ``counts`` rows each).  In double precision
    segment sums (:func:`numpy.add.reduceat`: each point's sums the same numbers whichever grid holds it); in single
    precision (the screen of :func:`_screened_search`) one matrix product with the rows' line indicator."""

    def __init__(self, starts, counts, dtype, only=None):
        self.starts, self.counts = starts, counts
        # per line +1 (co-rotating forcing only), -1 (counter-rotating only), 0 (both), or None: every line both
        self.only = None if only is None or not np.any(only) else np.asarray(only, int)
        self.indicator = None
        if dtype != np.float64:
            n_rows = int(counts.sum())
            self.indicator = np.zeros((n_rows, starts.size), dtype)
            self.indicator[np.arange(n_rows), np.repeat(np.arange(starts.size), counts.astype(int))] = 1

    def sum(self, x, weights=None):
        """Σ over each line's rows of ``x`` (× ``weights`` per row, or 1), shape x.shape[:-1] + (lines,)."""
        if self.indicator is None:
            return np.add.reduceat(x if weights is None else x * weights, self.starts, axis=-1)
        e = self.indicator if weights is None else (self.indicator * weights[:, None]).astype(self.indicator.dtype)
        return (x.reshape(-1, x.shape[-1]) @ e).reshape(x.shape[:-1] + (e.shape[1],))


class _Trend:
    """Per-row ln|Ω| less its line's mean (``lc``), per line Σ lc² (``lc2``) and the factor e^{Z²/n} (``factor``) of
    :func:`_line_log_ssr`'s off-law option, the rows sorted by line; ``lawful`` (per line, bool): the lines that have
    no such option (the imbalance: :func:`_imbalance_lines`)."""

    def __init__(self, om, starts, counts, lawful):
        lw = np.log(om)
        mean = np.add.reduceat(lw, starts) / counts
        self.lc = lw - np.repeat(mean, counts.astype(int))
        self.lc2 = np.add.reduceat(self.lc**2, starts)
        self.factor = np.exp(OFF_LAW_Z**2 / counts)
        self.lawful = np.asarray(lawful, bool)


def _imbalance_lines(h_line, radial: bool) -> np.ndarray:
    """Per line (its harmonic number ``h_line``), whether it is the imbalance: a radial line within
    :data:`rwadist.extended.IMBALANCE_H_TOL` of h = 1.  Its load is U·Ω² by its physics (a mass off the spin axis),
    so its speed trend through the modes is the information it carries, never a law of its own: with an exponent of
    its own allowed, the rocking whirl of a wheel with I_zz/I_rr > 2 (whose forward whirl the 1x line never crosses:
    its transmissibility 1/(1 + (a − 1)(Ω/ω0)²) is a smooth trend) traded off f0 against a (family wheel 2: 46.3 Hz at
    a = 2.54 for 50 Hz at 2.2) and an amplitude law on the imbalance was invented to make up the trend."""
    return radial & (np.abs(np.asarray(h_line, float) - 1.0) <= IMBALANCE_H_TOL)


def _two(two_parts) -> bool:
    """Whether ``two_parts`` (:func:`_grid_search`) gives a radial line a co- and a counter-rotating part."""
    return True if isinstance(two_parts, np.ndarray) else bool(two_parts)


def _rows_of(two_parts, rows):
    """``two_parts`` (:func:`_grid_search`) of the rows ``rows`` alone (a per-row restriction sliced, a flag as it is)."""
    return two_parts[rows] if isinstance(two_parts, np.ndarray) else two_parts


def _parts(mode: str, sense, ok) -> bool | np.ndarray:
    """:func:`_grid_search`'s ``two_parts`` of ``mode``'s scan: False (the axial mode: one forcing), else the per-row
    restriction ``sense`` of the rows ``ok`` (:func:`scan_mode`) when it restricts any, else True."""
    if mode == "axial_translation":
        return False
    return True if sense is None or not np.any(np.asarray(sense)[ok]) else np.asarray(sense, int)[ok]


def _line_only(two_parts, order, starts):
    """Per line (the rows sorted by ``order``, each line's first at ``starts``) the sense its forcing is restricted
    to (+1 co-rotating, -1 counter-rotating, 0 both), or None when ``two_parts`` is a flag (:class:`_Segments` takes
    a restriction of none as None)."""
    return np.asarray(two_parts, int)[order][starts] if isinstance(two_parts, np.ndarray) else None


def _line_log_ssr(lw, seg, trend=None, scratch=None):
    """Per line (along the last axis, its rows summed by ``seg``, :class:`_Segments`) Σ(lw − mean lw)²: the log least
    squares of the line's rows with its scale free (closed form: the scale is the mean).  With ``trend``
    (:class:`_Trend`), the least of that and the line with an exponent of its own (lw detrended in ln|Ω|, closed form)
    times e^{Z²/n}, the likelihood ratio a trend must earn: one line of another law (an Ω³ amplitude law across the
    band) then weighs in the scan as one such line, not as a mode's skirt (the E wheel's translation placed 7 % low).
    ``scratch``: an array of lw's shape to hold lw² (else a new one)."""
    counts = seg.counts
    s1 = seg.sum(lw)
    s2 = seg.sum(lw * lw if scratch is None else np.multiply(lw, lw, out=scratch))
    ssr = np.maximum(s2 - s1 * s1 / counts, 0.0)
    if trend is None:
        return ssr
    sl = seg.sum(lw, trend.lc)
    free = np.maximum(ssr - np.where(trend.lc2 > 0, sl * sl / np.where(trend.lc2 > 0, trend.lc2, 1.0), 0.0), 0.0)
    return np.where(trend.lawful, ssr, np.minimum(ssr, free * trend.factor))


def _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, chunk=512, dtype=np.float64):
    """SSR of the log power residual (f0_grid.size, zeta_grid.size, a_grid.size) on the grid, each line's forcing
    solved per line: Σ over lines of min over its forcing of Σ_rows ln²(P·|T|²·Ω⁴/power).

    One forcing P (an axial line, or no gyroscopic term: both senses meet the same |T|²): ln P is minus the mean of
    ln u, u = |T|²Ω⁴/power, in closed form.  Two (a radial line through the rocking whirls: P_co through T(+hΩ), P_ct
    through T(−hΩ)): the least of co-rotating only, counter-rotating only, and both at the split the relative-power
    non-negative least squares gives (min Σ(P_co·u + P_ct·v − 1)², 2 variables in closed form), their common scale
    free.  Log rather than relative powers: a mode placed a little off a sharp peak overpredicts some rows tenfold, which
    a relative residual squares (81) where it forgives an underprediction (at most 1), so a coarse grid preferred broad
    modes far from every line (the rocking mode of a wheel at 258 Hz, ζ 0.1, put at 314 Hz, a = 0.42); the least
    squares that follows the scan is in logs too.

    line (rows,) int line index; h, omega (rows,); power (rows,) measured x²+y² (radial) or amp² (axial).
    two_parts : a radial line's forcing has a co- and a counter-rotating part (not restricted by the sense measured at
    the load cell summed over the runs: the whirls amplify one sense more than the other, so a line forced 80 %
    co-rotating reads 95 % co-rotating near the forward whirl, and scanned as co-rotating only it put the family's new
    wheel's rocking mode at 87 Hz, truth 95); or, per row, +1 / -1 where the line's forcing turns one way only
    (co- / counter-rotating: its response turns that way in every run, ``scan_mode``'s ``sense``), 0 both.

    The grid is a product: d² = (2ζω0ν)² depends on (f0, ζ, row) only, ω0² − ν² ± aΩν on (f0, a, row) only, so
    those are computed on their own sub-grids and broadcast; the sums over each line's rows are segment sums of
    the rows sorted by line (:func:`numpy.add.reduceat`).  Chunks of f0 hold about ``chunk``·256 elements per
    term."""
    f0_grid, zeta_grid, a_grid = (np.asarray(x, float) for x in (f0_grid, zeta_grid, a_grid))
    order = np.argsort(line, kind="stable")
    line_s = np.asarray(line)[order]
    starts = np.flatnonzero(np.r_[True, line_s[1:] != line_s[:-1]])
    counts = np.diff(np.r_[starts, line_s.size]).astype(float)          # rows per line
    om = np.abs(np.asarray(omega, float))[order]
    nu = np.asarray(h, float)[order] * om
    scale = om**4 / np.asarray(power, float)[order]                     # model/data per unit forcing power
    nu2 = nu**2
    gyro = (a_grid[:, None] * om[None, :]) * nu[None, :]                 # (A, rows)
    if dtype != np.float64:
        # a line's scale is free: divided by its geometric mean (every SSR the same) its rows stay near 1
        scale = scale / np.exp(np.repeat(np.add.reduceat(np.log(scale), starts) / counts, counts.astype(int)))
        f0_grid, zeta_grid, om, nu, nu2, scale, gyro = (np.asarray(x, dtype) for x in (
            f0_grid, zeta_grid, om, nu, nu2, scale, gyro))
    # no gyroscopic term (translation modes, or a = 0): both senses see the same |T|² and the two parts are one
    same = not np.any(gyro)
    both_senses = _two(two_parts) and not same
    trend = _Trend(om, starts, counts, _imbalance_lines(np.asarray(h, float)[order][starts], _two(two_parts)))
    seg = _Segments(starts, counts, dtype, _line_only(two_parts, order, starts))
    # the screen's logarithms in base 2 (single precision: 40 % faster than the natural logarithm), its SSR times
    # (ln 2)² at the end: every SSR is a sum of squared differences of logs, so the same number to rounding
    log = np.log if dtype == np.float64 else np.log2
    n_z, n_a, n_rows = zeta_grid.size, a_grid.size, om.size
    out = np.empty((f0_grid.size, n_z, n_a))
    bufs = None                     # the two-senses search's arrays, one set for every chunk (the first is the largest)
    step = max(1, chunk * 256 // max(n_rows * n_z * n_a, 1))
    for s in range(0, f0_grid.size, step):
        w0 = 2 * np.pi * f0_grid[s:s + step]                                           # (F,)
        w02 = w0**2
        d2 = ((2 * zeta_grid[None, :] * w0[:, None])[:, :, None] * nu[None, None, :]) ** 2   # (F, Z, rows)
        num = ((w02**2)[:, None, None] + d2) * scale                                  # |T|² numerator × scale
        rest = w02[:, None] - nu2[None, :]                                            # (F, rows)
        lnum = log(num)
        if same:
            lw = (lnum - log(rest[:, None, :] ** 2 + d2))[:, :, None, :]              # (F, Z, 1, rows)
            out[s:s + step] = np.sum(_line_log_ssr(lw, seg, trend), axis=-1)
            continue
        lnum = lnum[:, :, None, :]
        if not both_senses:
            den_u = ((rest[:, None, :] + gyro[None]) ** 2)[:, None] + d2[:, :, None, :]    # (F, Z, A, rows)
            out[s:s + step] = np.sum(_line_log_ssr(lnum - log(den_u), seg, trend), axis=-1)
            continue
        if bufs is None:
            bufs = np.empty((4, w0.size, n_z, n_a, n_rows), num.dtype)
        out[s:s + step] = np.sum(_two_senses_ssr(num[:, :, None, :], lnum, rest[:, None, :], gyro[None],
                                                 d2[:, :, None, :], seg, trend, bufs), axis=-1)
    if log is not np.log:
        out *= LN2_SQUARED
    return out


#: (ln 2)²: the single-precision screen's SSR of base-2 logarithms times this is its SSR of natural logarithms
LN2_SQUARED = math.log(2.0) ** 2


def _two_senses_ssr(num, lnum, rest, gyro, d2, seg, trend, bufs):
    """Per grid point and line, :func:`_grid_search`'s SSR of a radial line forced in both senses: the least of
    co-rotating only (u = num/den_u, den_u = (rest + gyro)² + d2), counter-rotating only (v = num/den_v, den_v =
    (rest − gyro)² + d2) and both at the split of the relative-power non-negative least squares, each with its scale
    free (``num``, ``lnum`` = ln num, ``d2`` (F, Z, 1, rows); ``rest`` (F, 1, rows); ``gyro`` (1, A, rows)).  ``bufs``
    (4, F, Z, A, rows) holds u, v and two more arrays of their size: the numbers of new arrays for each, in four
    arrays reused from chunk to chunk (they stay in cache: the single-precision screen 5-10 % faster)."""
    u, v, lw, tmp = bufs[:, :num.shape[0]]
    np.add(((rest + gyro) ** 2)[:, None], d2, out=u)            # den_u
    np.add(((rest - gyro) ** 2)[:, None], d2, out=v)            # den_v
    double = seg.indicator is None
    if double:                      # double precision: the logs of numerator and denominator, as ever
        ssr_u = _line_log_ssr(np.subtract(lnum, np.log(u, out=lw), out=lw), seg, trend, tmp)
        ssr_v = _line_log_ssr(np.subtract(lnum, np.log(v, out=lw), out=lw), seg, trend, tmp)
    np.divide(num, u, out=u)
    np.divide(num, v, out=v)
    if not double:                  # the screen: the base-2 logs of the ratios (no subtraction broadcast over a)
        ssr_u = _line_log_ssr(np.log2(u, out=lw), seg, trend, tmp)
        ssr_v = _line_log_ssr(np.log2(v, out=lw), seg, trend, tmp)
    ssr = np.minimum(ssr_u, ssr_v)
    su, sv = seg.sum(u), seg.sum(v)
    suu, svv, suv = (seg.sum(np.multiply(a, b, out=tmp)) for a, b in ((u, u), (v, v), (u, v)))
    det = suu * svv - suv**2
    safe = np.where(np.abs(det) > 1e-14 * suu * svv, det, np.nan)
    x = (svv * su - suv * sv) / safe
    y = (suu * sv - suv * su) / safe
    ok = (x > 0) & (y > 0)
    if np.any(ok):
        reps = seg.counts.astype(int)
        np.multiply(np.repeat(np.where(ok, x, 1.0), reps, axis=-1), u, out=lw)
        np.add(lw, np.multiply(np.repeat(np.where(ok, y, 0.0), reps, axis=-1), v, out=tmp), out=lw)   # the mix
        ssr = np.where(ok, np.minimum(ssr, _line_log_ssr((np.log if double else np.log2)(lw, out=lw), seg,
                                                          scratch=tmp)), ssr)
    if seg.only is not None:        # a line forced one way only: that sense's fit alone
        ssr = np.where(seg.only == 1, ssr_u, np.where(seg.only == -1, ssr_v, ssr))
    return ssr


#: points of the single-precision screen evaluated at once by :func:`_points_ssr` (about 2**17 point × row elements per
#: array: its few arrays stay in the core's cache)
POINT_CHUNK_ELEMENTS = 1 << 17
#: :func:`_pruned_screen` evaluates every line first on every this-many-th point of each axis of its grid (through the
#: grid's centre): a 1/9-1/27 share of the points, for a first bound on the least SSR
SAMPLE_STRIDE = 3
#: when more than this share of a grid's points is left after its first line, :func:`_pruned_screen` screens the whole
#: grid instead (a point's line summed point by point costs ~2.5x its share of the product grid's passes)
PRUNE_FALLBACK_SHARE = 0.25
#: grids of fewer points × rows than this are screened whole (:func:`_grid_search`): the pruning's own steps cost more
#: than they save there
PRUNE_MIN_ELEMENTS = 1 << 20
#: after the first line, the points of least partial SSR evaluated on every line too (a tighter bound)
PROMISING_POINTS = 64


class _Rows:
    """The rows of :func:`_grid_search` in single precision, sorted by line, each line's scale divided by its geometric
    mean (the screen's own numbers), and per line its rows' slice with its :class:`_Segments` and :class:`_Trend`."""

    def __init__(self, line, h, omega, power, two_parts):
        order = np.argsort(line, kind="stable")
        line_s = np.asarray(line)[order]
        starts = np.flatnonzero(np.r_[True, line_s[1:] != line_s[:-1]])
        counts = np.diff(np.r_[starts, line_s.size]).astype(float)
        om = np.abs(np.asarray(omega, float))[order]
        nu = np.asarray(h, float)[order] * om
        scale = om**4 / np.asarray(power, float)[order]
        scale = scale / np.exp(np.repeat(np.add.reduceat(np.log(scale), starts) / counts, counts.astype(int)))
        lawful = _imbalance_lines(np.asarray(h, float)[order][starts], _two(two_parts))
        only = _line_only(two_parts, order, starts)
        self.om64, self.nu64 = om, nu
        self.om, self.nu, self.scale = (np.asarray(x, np.float32) for x in (om, nu, scale))
        self.lines = []
        for i, (s, c) in enumerate(zip(starts, counts.astype(int))):
            one_start, one_count = np.array([0]), np.array([float(c)])
            self.lines.append((slice(s, s + c), _Segments(one_start, one_count, np.float32,
                                                          None if only is None else only[i:i + 1]),
                               _Trend(self.om[s:s + c], one_start, one_count, lawful[i:i + 1])))


def _points_ssr(rows: _Rows, k: int, w0, zeta, a, same: bool, both_senses: bool) -> np.ndarray:
    """The single-precision SSR of line ``k`` of ``rows`` (:class:`_Rows`) at the grid points (ω0 rad/s, ζ, a) given
    one by one (``w0``, ``zeta``, ``a``, (P,) float32): :func:`_grid_search`'s terms of that line (the same formulas on
    a list of points instead of a product grid), in natural-log units."""
    part, seg, trend = rows.lines[k]
    om, nu, scale = rows.om[part], rows.nu[part], rows.scale[part]
    nu2 = nu * nu
    out = np.empty(w0.size)
    step = max(1, POINT_CHUNK_ELEMENTS // max(om.size, 1))
    bufs = None
    for s in range(0, w0.size, step):
        w = w0[s:s + step]
        w02 = w * w
        d2 = ((2 * zeta[s:s + step] * w)[:, None] * nu[None, :]) ** 2                # (P, rows)
        num = ((w02 * w02)[:, None] + d2) * scale
        rest = w02[:, None] - nu2[None, :]
        if same:
            ssr = _line_log_ssr(np.log2(num) - np.log2(rest * rest + d2), seg, trend)
        else:
            gyro = (a[s:s + step, None] * om[None, :]) * nu[None, :]
            if not both_senses:
                ssr = _line_log_ssr(np.log2(num) - np.log2((rest + gyro) ** 2 + d2), seg, trend)
            else:
                if bufs is None:
                    bufs = np.empty((4, w.size, 1, 1, om.size), np.float32)
                ssr = _two_senses_ssr(num[:, None, None, :], None, rest[:, None, :], gyro[:, None, :],
                                      d2[:, None, None, :], seg, trend, bufs)
        out[s:s + step] = np.reshape(ssr, (w.size,))
    return out * LN2_SQUARED


def _pruned_screen(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts) -> np.ndarray:
    """The single-precision screen of :func:`_screened_search`: :func:`_grid_search`'s SSR (single precision) at every
    point of the grid that can come within :data:`SCREEN_MARGIN` of the least; at the others a lower bound of it above
    that, the sum of some of its lines' terms.

    Every line's term is ≥ 0, so the sum over some lines bounds a point's SSR from below.  Every line is evaluated on a
    sub-grid (every :data:`SAMPLE_STRIDE`-th point of each axis, through the grid's centre, where a refinement grid
    holds the coarse best point) and at the :data:`PROMISING_POINTS` points of least first-line term: U, their least
    SSR, bounds the grid's least from above.  The lines are then summed one at a time (first the one that rules out
    most of the sub-grid, on the whole grid; the others at the points left), each only at the points whose sum so far
    is within U + SCREEN_MARGIN·(1 + U) (:func:`_screen_bound`): a point beyond it can be neither the least nor within
    the margin of it, which is all :func:`_screened_search` reads of the screen (the f0 it searches again in double
    precision, and its least).  On the mode scans of a 60-speed diagnose the first line leaves 0-10 % of the points (a
    sharp mode rules out most of the grid)."""
    f0_grid, zeta_grid, a_grid = (np.asarray(x, float) for x in (f0_grid, zeta_grid, a_grid))
    shape = (f0_grid.size, zeta_grid.size, a_grid.size)
    line, h, omega, power = (np.asarray(x) for x in (line, h, omega, power))
    n_points = int(np.prod(shape))
    if n_points * line.size < PRUNE_MIN_ELEMENTS:
        return _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, dtype=np.float32)
    rows = _Rows(line, h, omega, power, two_parts)
    n_lines = len(rows.lines)
    order_rows = np.argsort(line, kind="stable")

    def on_grid(k, f, z, a):
        # line k's terms on a product grid: _grid_search's single-precision numbers of that line's rows alone
        r = order_rows[rows.lines[k][0]]
        return _grid_search(line[r], h[r], omega[r], power[r], f, z, a, _rows_of(two_parts, r),
                            dtype=np.float32)[..., None]

    sub = [np.arange((n // 2) % SAMPLE_STRIDE, n, SAMPLE_STRIDE) if n > SAMPLE_STRIDE else np.arange(n) for n in shape]
    at_sub = np.concatenate([on_grid(k, f0_grid[sub[0]], zeta_grid[sub[1]], a_grid[sub[2]])
                             for k in range(n_lines)], axis=-1).reshape(-1, n_lines)      # (sub-grid points, lines)
    bound = _screen_bound(float(np.min(at_sub.sum(axis=1))))
    order = np.argsort(-np.mean(at_sub > bound, axis=0), kind="stable")
    partial = on_grid(order[0], f0_grid, zeta_grid, a_grid).ravel().astype(float)
    # as _grid_search decides them, on the whole grid: no gyroscopic term anywhere, or a line's two senses
    same = not np.any(a_grid[:, None] * rows.om64[None, :] * rows.nu64[None, :])
    both_senses = _two(two_parts) and not same
    fi, zi, ai = np.unravel_index(np.arange(n_points), shape)
    w0 = (2 * np.pi * np.asarray(f0_grid, np.float32))[fi]
    zeta, a = np.asarray(zeta_grid, np.float32)[zi], np.asarray(a_grid, np.float32)[ai]

    def terms(k, idx):
        return _points_ssr(rows, k, w0[idx], zeta[idx], a[idx], same, both_senses)

    if n_lines > 1:
        # the points the first line favours, on every line: a tighter bound than the sub-grid's
        best = np.argsort(partial, kind="stable")[:PROMISING_POINTS]
        bound = min(bound, _screen_bound(float(np.min(partial[best] + sum(terms(k, best) for k in order[1:])))))
    alive = np.flatnonzero(partial <= bound)
    if alive.size > PRUNE_FALLBACK_SHARE * n_points:
        # a flat profile (no sharp mode: most points stay near the least): the point-by-point sums of the other lines
        # would cost more than the product grid's, so the whole grid is screened as it is
        return _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, dtype=np.float32)
    for k in order[1:]:
        partial[alive] += terms(k, alive)
        alive = alive[partial[alive] <= bound]
    return partial.reshape(shape)


def _screen_bound(upper: float) -> float:
    """The largest SSR a point of the screen can have and still be kept (:func:`_screened_search`) when the least SSR
    is at most ``upper``: upper + :data:`SCREEN_MARGIN`·(1 + upper), with 1 % of that margin more for the rounding of
    single-precision sums taken in another order."""
    return upper + 1.01 * SCREEN_MARGIN * (1.0 + abs(upper))


def _window(grid: np.ndarray, centre: float | None, lo: float, hi: float) -> np.ndarray:
    """Indices of the points of ``grid`` (increasing) within [lo, hi]·``centre`` (all of them when ``centre`` is
    None or no point falls there)."""
    if centre is None or not np.isfinite(centre):
        return np.arange(grid.size)
    idx = np.flatnonzero((grid >= lo * centre) & (grid <= hi * centre))
    return idx if idx.size else np.arange(grid.size)


#: The single-precision screen of :func:`_screened_search` keeps every f0 whose least SSR lies within this fraction of
#: (1 + the least SSR) of the least: 70x the largest difference from the double-precision SSR measured near the best
#: points of the benchmark's and the family's scans (1.4e-4 of it)
SCREEN_MARGIN = 1e-2


def _screened_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts):
    """:func:`_grid_search`'s SSR on the grid for a scan that only locates its best point: the whole grid first in
    single precision (each line's scale divided by its geometric mean, the per-line sums one matrix product: about
    half the time), then every f0 whose single-precision least SSR lies within :data:`SCREEN_MARGIN`·(1 + least) of the
    least again in double precision -- the numbers of the double-precision search there, the others the single
    precision's.  The best point is the double-precision search's (the same number: a point's SSR does not depend on
    the grid it is computed in) whenever the two precisions differ by less than half the margin near it; the whole
    grid is searched in double precision when the screen is not finite or its kept points do not come within half
    the margin of its least."""
    approx = _pruned_screen(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts)
    if approx.size and not np.all(np.isfinite(approx)):
        approx = _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, dtype=np.float32)
    if approx.size == 0 or not np.all(np.isfinite(approx)):
        return _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts)
    least = float(approx.min())
    margin = SCREEN_MARGIN * (1.0 + abs(least))
    keep = np.flatnonzero(approx.min(axis=(1, 2)) <= least + margin)
    exact = _grid_search(line, h, omega, power, np.asarray(f0_grid, float)[keep], zeta_grid, a_grid, two_parts)
    if not np.nanmin(exact) <= least + 0.5 * margin:
        return _grid_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts)
    approx[keep] = exact
    return approx


def _windowed_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, near_hz, near_a,
                     search=None):
    """:func:`_grid_search` on the whole product grid, or -- with ``near_hz`` (and ``near_a`` for the rocking
    mode's I_zz/I_rr) -- first on the grid's points within ×/÷ :data:`NEAR_SPAN` of ``near_hz`` (and
    ±:data:`NEAR_A_SPAN` of ``near_a``), the others NaN: kept when the best point lies inside that window (a point of
    the same grid, so the same best point as the whole grid's whenever the whole grid's best lies there), the whole
    grid searched when it lies on an edge the whole grid goes beyond (the data's best lies outside the window).
    ``search``: the grid search (default :func:`_grid_search`; :func:`_screened_search` for a locate-only scan)."""
    search = search or _grid_search
    fi = _window(f0_grid, near_hz, 1.0 / NEAR_SPAN, NEAR_SPAN)
    ai = np.arange(a_grid.size) if near_a is None or a_grid.size == 1 else \
        np.flatnonzero(np.abs(a_grid - near_a) <= NEAR_A_SPAN + 1e-9)
    if ai.size == 0:
        ai = np.arange(a_grid.size)
    if fi.size == f0_grid.size and ai.size == a_grid.size:
        return search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts)
    return _part_first(search, (line, h, omega, power), f0_grid, zeta_grid, a_grid, two_parts, fi, ai)


def _part_first(search, data: tuple, f_grid, z_grid, a_grid, two_parts, fi, ai) -> np.ndarray:
    """``search(*data, f, ζ, a, two_parts)`` first on the part of the grid at f0 indices ``fi`` and I_zz/I_rr indices
    ``ai`` (every ζ), the other points NaN: kept when the part's best point lies inside it (a point of the same grid,
    so the whole grid's best whenever that lies in the part); the whole grid searched when the part's best lies on an
    edge the whole grid goes beyond, or the part holds no finite cost."""
    sub = search(*data, f_grid[fi], z_grid, a_grid[ai], two_parts)
    if np.all(np.isnan(sub)):
        return search(*data, f_grid, z_grid, a_grid, two_parts)
    i, _, k = np.unravel_index(np.nanargmin(sub), sub.shape)
    on_edge = ((i == 0 and fi[0] > 0) or (i == fi.size - 1 and fi[-1] < f_grid.size - 1)
               or (k == 0 and ai[0] > 0) or (k == ai.size - 1 and ai[-1] < a_grid.size - 1))
    if on_edge:
        return search(*data, f_grid, z_grid, a_grid, two_parts)
    out = np.full((f_grid.size, z_grid.size, a_grid.size), np.nan)
    out[np.ix_(fi, np.arange(z_grid.size), ai)] = sub
    return out


#: Largest I_zz/I_rr the rocking scan tries.  A rigid rotor about its centre of mass has I_zz <= 2 I_rr, but the
#: ratio the whirls show is an effective one (a flexible rotor or rim, rocking coupled with other motion, a test
#: generator outside that bound): measured wheels and the family's (I_zz/I_rr up to 2.2) go beyond 2, and a scan
#: capped there moved their rocking mode 3-4 % to make up the whirl (family wheels 2 and 7) and left the rest to an
#: invented amplitude law.  The model's own bound (:data:`rwadist.schema.MAX_INERTIA_RATIO`).
A_MAX = MAX_INERTIA_RATIO
#: Least I_zz/I_rr the rocking scan's refinement reaches
A_MIN = 0.02
#: I_zz/I_rr grid of the rocking scan when the ratio is unknown (steps of 0.2; 2.0 on the grid)
A_GRID = np.round(np.arange(0.2, A_MAX + 1e-9, 0.2), 10)
#: Half-width (a factor) of the f0 window a scan with ``near_hz`` searches first (:func:`scan_mode`)
NEAR_SPAN = 1.25
#: Half-width of the I_zz/I_rr window a rocking scan with ``near_a`` searches first
NEAR_A_SPAN = 0.4


def _at_the_end(f_best: float, f0_grid: np.ndarray) -> str:
    """Why a mode whose best fit ``f_best`` (Hz) lies at an end of the scanned ``f0_grid`` (Hz) is not located; the
    refinement around the grid's last points may step past them, which is said so (trial 29: "909.7 Hz of
    1.25-882.8 Hz" quoted a value outside the range it named)."""
    end = "bottom" if f_best <= f0_grid[2] * 1.001 else "top"
    where = "at" if f0_grid[0] <= f_best <= f0_grid[-1] else "past"
    return (f"the best fit puts it {where} the {end} of the scanned range {f0_grid[0]:.4g}-{f0_grid[-1]:.4g} Hz, "
            f"at {f_best:.4g} Hz: no line comes near it")


def _competitor(line, h, omega, power, grids, ssr, io, f_step, f_best, tolerance, two_parts, at_grid) -> float:
    """The SSR of the best competitor farther than ``tolerance`` from ``f_best``, at f0 grid index ``io`` (``grids``:
    the scan's f0, ζ and a grids; ``ssr`` its grid of SSRs; ``at_grid`` the profile's SSR there), given the same
    refinement as the best point (a coarse ζ grid would make it look worse than it is and the mode look pinned when
    it is not)."""
    f0_grid, zeta_grid, a_grid = grids
    jo, ko = np.unravel_index(np.nanargmin(ssr[io]), ssr[io].shape)
    f_o = f0_grid[io] * np.exp(np.arange(-f_step, f_step + 0.0001, 0.002))
    f_o = f_o[np.abs(np.log(f_o / f_best)) > math.log1p(tolerance)]
    z_o = zeta_grid[jo] * np.exp(np.linspace(-0.5, 0.5, 11) * (1 if a_grid.size == 1 else 1.5))
    a_o = a_grid if a_grid.size == 1 else np.unique(np.clip(a_grid[ko] + np.linspace(-0.2, 0.2, 21), 0.02, A_MAX))
    return min(float(np.nanmin(_grid_search(line, h, omega, power, f_o, z_o, a_o, two_parts))), at_grid)


#: The largest damping ratio a mode above every line is scanned with (:func:`scan_mode`'s ``zeta_max``): below a mode
#: the lines show only its rise, along which f0 and ζ trade (a ROSS wheel's axial mode at 334.5 Hz, ζ 0.024, its lines
#: to 154 Hz: 237.5 Hz at a large ζ, then declared and its rise described as two lines' laws), and a suspension mode's
#: damping is well under it
QUASI_STATIC_ZETA = 0.15


#: Times the rocking scan's refinement window is moved along the whirl's valley at most (:func:`_follow_valley`)
MAX_VALLEY_STEPS = 12


def _follow_valley(data: tuple, grids: tuple, at: tuple, best: float, offsets: tuple, f_edge: bool) -> tuple:
    """(SSR, (f0 Hz, ζ, I_zz/I_rr)) of the rocking scan's refinement followed along the whirl's valley: while the best
    point of the window searched (``grids``: its f0, ζ and a grids; ``at``: the best point's indices, SSR ``best``)
    lies on the window's I_zz/I_rr edge inside the scan's range (or, with ``f_edge``, on its f0 edge), the window is
    recentred on it (``offsets``: ln f0, ln ζ and a about the centre) and searched again, as long as the SSR falls.

    Where the lines cross one whirl only (co-rotating lines through the forward whirl: one torque line crossing it),
    the data fix the crossing, f0²/(h² − h·a), and f0 and a trade along a long, shallow valley that a window of ±0.2
    in a does not span: trial C (f0 260 Hz, I_zz/I_rr 1.25, a 5.1x torque line) was refined from a coarse 0.8 to
    1.019 on the window's edge, 267.6 Hz (+2.9 %), at an SSR 1.7x that of the truth's."""
    line, h, omega, power, two_parts = data
    (f_grid, z_grid, a_grid), (i, j, k) = grids, at
    f_off, z_off, a_off = offsets
    point = (float(f_grid[i]), float(z_grid[j]), float(a_grid[k]))
    z_lo, z_hi = float(z_grid.min()), float(z_grid.max())     # the valley runs in f0 and a: ζ stays in its window
    for _ in range(MAX_VALLEY_STEPS):
        a_edge = (k == 0 and a_grid[0] > A_MIN + 1e-9) or (k == a_grid.size - 1 and a_grid[-1] < A_MAX - 1e-9)
        if not (a_edge or (f_edge and i in (0, f_grid.size - 1))):
            break
        f_grid, z_grid = point[0] * np.exp(f_off), np.unique(np.clip(point[1] * np.exp(z_off), z_lo, z_hi))
        a_grid = np.unique(np.clip(np.round(point[2] + a_off, 9), A_MIN, A_MAX))
        ssr = _screened_search(line, h, omega, power, f_grid, z_grid, a_grid, two_parts)
        i, j, k = np.unravel_index(np.nanargmin(ssr), ssr.shape)
        if not float(ssr[i, j, k]) < best:
            break
        best, point = float(ssr[i, j, k]), (float(f_grid[i]), float(z_grid[j]), float(a_grid[k]))
    return best, point


def _refine_ratio(data: tuple, grids: tuple, at: tuple, best: float, f_step: float) -> tuple:
    """(SSR, (f0 Hz, ζ, I_zz/I_rr)) of the rocking scan's refinement when I_zz/I_rr is scanned: the fine window
    (``grids``, its best point at indices ``at``, SSR ``best``) followed along the whirl's valley, then a to 0.001
    about its best point, followed again (:func:`_follow_valley`)."""
    best, (f_best, z_best, a_best) = _follow_valley(
        data, grids, at, best, (np.arange(-2 * f_step - 0.01, 2 * f_step + 0.0101, 0.001),
                                np.linspace(-0.75, 0.75, 11), np.linspace(-0.2, 0.2, 21)), f_edge=False)
    # I_zz/I_rr is not refined later (the extended fit frees k and c only), and one step of 0.02 moves a whirl
    # branch by up to 1 % of the spin frequency at the mode: 0.5 % of the forward whirl at 9000 rpm, enough to
    # under-predict a line passing near it by 16 % (trial15: an invented amplitude law on clean data).  The
    # neighbourhood of the best point once more, a to 0.001 (f0 and ζ move with it along the whirl's valley)
    offsets = (np.arange(-0.003, 0.00301, 0.0005), np.linspace(-0.1, 0.1, 5), np.arange(-0.02, 0.02001, 0.001))
    f_2, z_2 = f_best * np.exp(offsets[0]), z_best * np.exp(offsets[1])
    a_2 = np.unique(np.clip(np.round(a_best + offsets[2], 9), A_MIN, A_MAX))
    line, h, omega, power, two_parts = data
    fine_2 = _screened_search(line, h, omega, power, f_2, z_2, a_2, two_parts)
    gi, gj, gk = np.unravel_index(np.nanargmin(fine_2), fine_2.shape)
    if float(fine_2[gi, gj, gk]) < best:
        return _follow_valley(data, (f_2, z_2, a_2), (gi, gj, gk), float(fine_2[gi, gj, gk]), offsets, f_edge=True)
    return best, (f_best, z_best, a_best)


def scan_mode(mode: str, line, h, omega, power, inertia_ratio: float | None = None, tolerance: float = 0.02,
              min_log_lr: float = 2.0, near_hz: float | None = None, near_a: float | None = None,
              zeta_max: float = 0.6, sense=None) -> ModeScan:
    """Profile scan of one mode (see the module docstring).

    line : (n,) int, index of the line each measurement belongs to.  h : (n,) harmonic number.
    omega : (n,) wheel speed, rad/s.  power : (n,) measured x² + y² (radial, N² or N²m²) or the
    squared axial amplitude.  inertia_ratio : I_zz/I_rr for rocking when known (mass and radius
    given); None scans it over [0.2, :data:`A_MAX`].  tolerance : relative f0 error the data must exclude.
    min_log_lr : see the module docstring; ``-inf`` (a locate-only scan, as the extended fit asks) skips the
    distant competitor's refinement (``log_lr_off`` is then NaN: nothing compares with it).
    near_hz, near_a : where an earlier fit of the same wheel located the mode (Hz) and its I_zz/I_rr (the refit of
    ``rwadist diagnose``'s suspension modes on every run, from the fit on half of them), or None: the coarse grid
    is searched within ×/÷ :data:`NEAR_SPAN` (and ±:data:`NEAR_A_SPAN`) of it first and over its whole range only
    when the best point lies on that window's edge; the result is the whole grid's whenever its best point lies
    inside the window.  ``interval_hz`` and ``log_lr_off`` are then those of the profile inside the window.
    zeta_max : the largest damping ratio scanned (:data:`QUASI_STATIC_ZETA` for a mode above every line).
    sense : (n,) +1 / -1 where the measurement's radial line is forced co- / counter-rotating only (its response turns
    that way in every run: :func:`rwadist.extended_fit.one_sense_rows`), 0 where both parts are free; None: all free.
    """
    line, h, omega, power = (np.asarray(x) for x in (line, h, omega, power))
    ok = (power > 0) & np.isfinite(power) & (np.abs(omega) > 0)
    line, h, omega, power = line[ok], h[ok].astype(float), omega[ok].astype(float), power[ok].astype(float)
    n = int(line.size)
    if n < 8:
        return ModeScan(mode, False, math.nan, math.nan, math.nan, 0.0, (math.nan, math.nan),
                        f"only {n} measurements of the {MODE_DIRECTION[mode]} lines", n)
    _, line = np.unique(line, return_inverse=True)
    f_line = h * np.abs(omega) / (2 * np.pi)
    rocking = mode == "rocking"
    two_parts = _parts(mode, sense, ok)
    f_lo, f_hi = 0.25 * f_line.min(), 4.0 * f_line.max()
    if rocking:
        # the backward whirl of a mode at f0 falls to ~f0²/(a·f_spin): f0 may sit above every line
        f_hi = 4.0 * f_line.max()
    if not rocking:
        a_grid = np.array([0.0])
    elif inertia_ratio is not None:
        a_grid = np.array([float(inertia_ratio)])
    else:
        a_grid = A_GRID
    # a third axis (a unknown) costs 10x: coarser f0 and ζ steps there, the refinement recovers them
    f_step = 0.01 if a_grid.size == 1 else 0.02
    f0_grid = np.exp(np.arange(math.log(f_lo), math.log(f_hi), f_step))
    zeta_grid = np.exp(np.linspace(math.log(0.002), math.log(zeta_max), 13 if a_grid.size == 1 else 9))
    # a locate-only scan reads its grid's best point alone: screened in single precision first
    ssr = _windowed_search(line, h, omega, power, f0_grid, zeta_grid, a_grid, two_parts, near_hz,
                           near_a if rocking and inertia_ratio is None else None,
                           _screened_search if min_log_lr == -math.inf else _grid_search)
    i, j, k = np.unravel_index(np.nanargmin(ssr), ssr.shape)
    # refine around the best point: f0 to 0.1 %, ζ and a finer
    f_fine = f0_grid[i] * np.exp(np.arange(-2 * f_step - 0.01, 2 * f_step + 0.0101, 0.001))
    z_fine = zeta_grid[j] * np.exp(np.linspace(-0.5, 0.5, 11) * (1 if a_grid.size == 1 else 1.5))
    a_fine = a_grid if a_grid.size == 1 else np.unique(np.clip(a_grid[k] + np.linspace(-0.2, 0.2, 21), A_MIN, A_MAX))
    # screened in single precision, its best the double-precision grid's; whole (a part first: a false local minimum)
    fine = _screened_search(line, h, omega, power, f_fine, z_fine, a_fine, two_parts)
    fi, fj, fk = np.unravel_index(np.nanargmin(fine), fine.shape)
    best = float(fine[fi, fj, fk])
    f_best, z_best, a_best = float(f_fine[fi]), float(z_fine[fj]), float(a_fine[fk])
    if a_fine.size > 1:
        best, (f_best, z_best, a_best) = _refine_ratio((line, h, omega, power, two_parts), (f_fine, z_fine, a_fine),
                                                       (fi, fj, fk), best, f_step)
    if z_best > QUASI_STATIC_ZETA and zeta_max > QUASI_STATIC_ZETA and f_best > float(f_line.max()):
        return scan_mode(mode, line, h, omega, power, inertia_ratio, tolerance, min_log_lr, near_hz, near_a,
                         zeta_max=QUASI_STATIC_ZETA, sense=two_parts if isinstance(two_parts, np.ndarray) else None)
    profile = np.full(f0_grid.size, np.nan)
    scanned = ~np.all(np.isnan(ssr), axis=(1, 2))     # every f0 but those a windowed search left out
    profile[scanned] = np.nanmin(ssr[scanned], axis=(1, 2))
    log_lr = 0.5 * n * np.log(np.maximum(profile, 1e-300) / max(best, 1e-300))
    off = np.abs(np.log(f0_grid / f_best)) > math.log1p(tolerance)
    log_lr_off = math.inf
    off &= np.isfinite(log_lr)          # the grid points a windowed search left out
    if min_log_lr == -math.inf:
        log_lr_off = math.nan           # a locate-only scan: no competitor is weighed
    elif off.any():
        io = np.nonzero(off)[0][np.argmin(log_lr[off])]
        ssr_o = _competitor(line, h, omega, power, (f0_grid, zeta_grid, a_grid), ssr, io, f_step, f_best, tolerance,
                            two_parts, float(profile[io]))
        log_lr_off = float(0.5 * n * np.log(max(ssr_o, 1e-300) / max(best, 1e-300)))
    inside = np.nonzero(log_lr < max(min_log_lr, 2.0))[0]
    interval = (float(f0_grid[inside.min()]), float(f0_grid[inside.max()])) if inside.size else (f_best, f_best)
    reason = ""
    if f_best <= f0_grid[2] * 1.001 or f_best >= f0_grid[-3] * 0.999:
        reason = _at_the_end(f_best, f0_grid)
    elif log_lr_off < min_log_lr:
        far = f0_grid[io]
        reason = (f"the data fit a mode at {far:.4g} Hz almost as well as at {f_best:.4g} Hz "
                  f"(log-likelihood ratio {log_lr_off:.1f} < {min_log_lr:g}): its frequency is not pinned to "
                  f"{100 * tolerance:g} % (f0 within {interval[0]:.4g}-{interval[1]:.4g} Hz)")
    return ModeScan(mode, not reason, f_best, z_best, a_best if rocking else 0.0, log_lr_off, interval, reason, n)
