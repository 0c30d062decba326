"""A mode whose frequency the data pin but whose damping they do not: the damping held and declared, not fitted.

A line crossing a whirl branch between two measured speeds is seen on the skirts of its resonance only: the
skirts place the mode (the side each speed is on, the level far from it) but not the height of the peak, which
lies between the speeds, so any damping below the one that would lift the nearest measured speed fits as well.
The least squares then drifts along that flat valley -- to the fit's floor ζ = 5e-5, where the mode was declared
not located and its frequency reset to a starting value (3x the top line) although it was pinned to 0.3 %, or to an
interior ζ with a standard error of its logarithm of 6-1000 (the damping reported as fitted, from 6.9e-5 to 0.025
on seeds of one wheel whose ζ is 0.015, and a 1/(2ζ) ≈ 7000x peak in the model where lines cross the whirl).

:func:`damping_interval` profiles the weighted least-squares cost over the mode's damping ratio alone (the other
parameters at their best fit) on a log grid from the fit's floor to 0.95: the interval where the cost rises by less
than :data:`PROFILE_RISE` (1.5 standard errors) is what the data allow.  It spans more than :data:`MAX_SPAN` (a
decade) when the data do not measure the damping: :func:`hold_unmeasured_damping` then holds the mode's ζ at its
starting value ``zeta0`` moved into that interval (the value closest to it the data allow), refits the rest with
it, and the mode stays located (its frequency is judged as before) with its damping declared: ``zeta_bounds`` of
the extended fit, ``unconstrained`` of ``rwadist diagnose``'s ``suspension_modes``.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .extended_fit_lsq import MODE_PARAMS, LogAmplitudeProblem, Solution, loose_modes
from .mode_scan import MODE_DIRECTION, QUASI_STATIC_ZETA
from .off_law_lines import free_off_law_lines, lawful_lines

#: the least squares' floor on a damping ratio (:meth:`LogAmplitudeProblem.solve`'s bounds)
ZETA_FLOOR = 5e-5
#: the highest damping ratio profiled (the least squares' ceiling, 0.95 of critical)
ZETA_CEILING = 0.95
#: rise of the profiled cost Σ r²/s² (rows as fitted, each over its direction's residual variance) bounding the
#: interval the data allow: 1.5 standard errors of one parameter, 1.5² -- the tolerance the modes' frequencies are
#: judged with (:func:`rwadist.extended_fit_lsq.loose_modes`)
PROFILE_RISE = 1.5**2
#: an interval of damping ratios wider than this factor (hi/lo) is not a measurement: a decade
MAX_SPAN = 10.0
#: damping ratios profiled per decade
PER_DECADE = 8
#: mode key of the fit -> the name of its damping in ``analytical.unconstrained``
DAMPING_NAME = {"radial_translation": "zeta_radial_translation", "rocking": "zeta_rocking",
                "axial_translation": "zeta_axial"}


def damping_interval(problem: LogAmplitudeProblem, solution: Solution, free_modes: list, mode: str) -> tuple:
    """(lo, hi) damping ratios of ``mode`` (a free mode of ``solution``, the least squares of ``problem``) whose cost
    stays within :data:`PROFILE_RISE` of the least on a log grid from :data:`ZETA_FLOOR` to :data:`ZETA_CEILING`
    (and the fitted ζ itself), the other parameters held at their best fit; each end where the cost crosses that
    level between the last grid point inside and the next (linear in ln ζ), or the grid's end.

    Held, the others cannot trade against the damping, so the interval is the narrowest the data could give: a
    damping declared on it is never declared in vain."""
    i = free_modes.index(mode)
    kn, cn, inertia = MODE_PARAMS[mode]
    theta = np.array(solution.res.x, dtype=float)
    root = 2 * math.sqrt(math.exp(theta[2 * i]) * problem.base[inertia])      # c / ζ
    n = int(round(PER_DECADE * math.log10(ZETA_CEILING / ZETA_FLOOR))) + 1
    grid = np.unique(np.concatenate([np.geomspace(ZETA_FLOOR, ZETA_CEILING, n),
                                     [min(max(math.exp(theta[2 * i + 1]) / root, ZETA_FLOOR), ZETA_CEILING)]]))
    residuals = solution.residuals
    if residuals is None:
        raise ValueError("damping_interval needs the solution's residual function (LogAmplitudeProblem.solve's)")
    s2 = np.maximum(np.asarray(solution.s2_row, dtype=float), 1e-300)
    cost = np.empty(grid.size)
    for k, z in enumerate(grid):
        t = theta.copy()
        t[2 * i + 1] = math.log(z * root)
        r = residuals(t)
        cost[k] = float(np.sum(r**2 / s2))
    level = cost.min() + PROFILE_RISE
    inside = np.flatnonzero(cost <= level)

    def edge(k: int, out: int) -> float:
        # where the cost crosses the level between the grid point inside (k) and its neighbour outside (linear in ln ζ):
        # a grid step is a factor 1.33, and the last point inside alone understates the interval by up to that
        if not 0 <= out < grid.size:
            return float(grid[k])
        t = (level - cost[k]) / (cost[out] - cost[k])
        return float(math.exp(math.log(grid[k]) + t * (math.log(grid[out]) - math.log(grid[k]))))
    return edge(int(inside.min()), int(inside.min()) - 1), edge(int(inside.max()), int(inside.max()) + 1)


def hold_unmeasured_damping(problem: LogAmplitudeProblem, solution: Solution, free_modes: list, zeta0: float,
                            bounds: dict, intervals: dict) -> list:
    """The free modes of ``solution`` (not held yet) whose damping the data do not measure (:func:`damping_interval`
    spans more than :data:`MAX_SPAN`): each is held in ``problem.held_zeta`` at ``zeta0`` moved into its interval
    (its damping coefficient in ``problem.base`` set to match, the start of the next least squares) and its interval
    recorded in ``bounds`` (mode -> (lo, hi)); returned, so that the caller fits again.  ``intervals`` gets the
    interval of every damping profiled (mode -> (lo, hi)): that of a measured damping, at this solution."""
    held = []
    for m in free_modes:
        if m in problem.held_zeta or solution.residuals is None:
            continue
        lo, hi = intervals[m] = damping_interval(problem, solution, free_modes, m)
        if hi / lo <= MAX_SPAN:
            continue
        zeta = min(max(zeta0, lo, 2 * ZETA_FLOOR), hi)
        kn, cn, inertia = MODE_PARAMS[m]
        problem.held_zeta[m] = zeta
        problem.base[cn] = 2 * zeta * math.sqrt(problem.base[kn] * problem.base[inertia])
        bounds[m] = (lo, hi)
        held.append(m)
    return held


def damping_note(mode: str, zeta: float, lo: float, hi: float) -> str:
    """The note of a held damping (:func:`hold_unmeasured_damping`)."""
    return (f"{mode}: DAMPING NOT CONSTRAINED by the data: any ζ in {lo:.2g}-{hi:.2g} fits within 1.5 standard "
            "errors (no measured speed sits on a crossing of a line with this mode's peak; only its skirts are "
            f"seen); held at ζ = {zeta:.3g}, the frequency fitted with it; listed in analytical.unconstrained "
            f"as {DAMPING_NAME[mode]}")


def located_damping(zeta_bounds: dict, intervals: dict, identified: dict, held_zeta: dict, notes: list) -> tuple:
    """(bounds, intervals) of the modes the fit located (``identified``, mode -> bool, after its last declarations):
    the held dampings' (lo, hi) of ``zeta_bounds`` and every profiled damping's of ``intervals`` (a held one's: its
    bounds); the note of each held damping (at its ``held_zeta``, :func:`damping_note`) appended to ``notes``.  A
    mode declared after its damping was held keeps its starting values: its damping is no held value of a fit."""
    bounds = {m: b for m, b in zeta_bounds.items() if identified[m]}
    notes += [damping_note(m, held_zeta[m], *b) for m, b in bounds.items()]
    return bounds, {m: bounds.get(m, b) for m, b in intervals.items() if identified[m]}


def damping_record(zeta_bounds: dict, zeta_interval: dict) -> dict:
    """The model file's ``analytical.fit`` entries of the dampings (``zeta_bounds``, ``zeta_interval``: mode ->
    [lo, hi]), each only when it holds a mode."""
    return ({"zeta_bounds": {m: list(b) for m, b in zeta_bounds.items()}} if zeta_bounds else {}) | \
        ({"zeta_interval": {m: list(b) for m, b in zeta_interval.items()}} if zeta_interval else {})


def fit_modes(problem: LogAmplitudeProblem, free_modes: list, declare: bool, tolerance: float, off_law: list,
              log_w: np.ndarray, declared: Callable[[str, str, tuple | None], None], zeta0: float, zeta_bounds: dict,
              intervals: dict) -> Solution:
    """The least squares with ``free_modes``, lines of another law freed (``off_law``, appended in place; ``log_w``
    ln|Ω| per row: :func:`rwadist.off_law_lines.free_off_law_lines`); with ``declare``, a damping the data do not
    measure is held (at ``zeta0`` moved into what the data allow, its interval put in ``zeta_bounds``, every profiled
    damping's in ``intervals``:
    :func:`rwadist.extended_fit_damping.hold_unmeasured_damping`) and the fit repeated, before each mode it does not
    pin is given to ``declared(mode, why, kept)`` (which resets it in ``problem.base``, or holds it at the stiffness and
    damping ``kept`` of :func:`above_every_line`), dropped from ``free_modes`` and the fit repeated: a mode whose damping runs to the floor while its frequency is pinned is located, its damping
    declared."""
    walks: dict = {}
    risen: list = []            # the modes whose damping was held because only the lines' rise below them shows them
    while True:
        solution, loose = free_off_law_lines(
            lambda lns: problem.solve(free_modes, lns), lambda sol: loose_modes(sol, free_modes, problem.base, tolerance),
            off_law, problem.row_line, log_w, lawful_lines(problem.meas_lines), [x.h for x in problem.meas_lines])
        if declare and hold_unmeasured_damping(problem, solution, free_modes, zeta0, zeta_bounds, intervals):
            continue
        # a mode placed by the rise below it alone, its damping held, is never taken as located: with ζ held its
        # frequency's error no longer counts the trade, and a compromise looked pinned (a ROSS wheel's 334.5 Hz axial
        # mode on a coupled stand: 178.9 Hz "located")
        loose += [(m, f"located at {_f_hz(problem, solution, free_modes, m):.4g} Hz only by the rise of the lines "
                      "below it, its damping held: no line crosses it") for m in risen
                  if declare and m in free_modes and m not in dict(loose)]
        if not loose or not declare:
            return solution
        # each loose mode's fitted stiffness when it lies above every line (at a bound of its window or not), read
        # before any is dropped; kept when it is not at a bound, or at one when it could walk (not the rocking mode)
        rising = {m: above_every_line(problem, solution, free_modes, m) for m, _ in loose}
        kept = {m: None if solution.at_bound[m] and not (m in risen and m != "rocking") else k
                for m, k in rising.items()}
        # below a mode ζ and f0 trade along one valley (a ROSS wheel's axial mode above its lines: 243.9 Hz, ζ 0.58,
        # 334.5 Hz, 0.024 in truth): a loose mode above every line has its damping held, its frequency fitted with it
        below = [m for m, _ in loose if m not in problem.held_zeta and rising[m] is not None]
        for m in below:
            zeta_bounds[m] = (2 * ZETA_FLOOR, QUASI_STATIC_ZETA)
            problem.held_zeta[m] = zeta0
            risen.append(m)
        # such a mode, held, that runs into the ±5 % window around its start: the window moved there, fitted again.
        # Not the rocking mode: its I_zz/I_rr is held at the scan's, and below the whirls the lines do not tell it
        # from f0 (the ROSS wheel's 405.6 Hz, 1.22: scanned 573 Hz, 3.0; walked to 576 Hz, the 1x torque's
        # gyroscopic stiffening 1.5 % at the top speed for ROSS's 0.3 %)
        walk = [m for m, _ in loose if m != "rocking" and m in problem.held_zeta and solution.at_bound[m] == "stiffness"
                and walks.get(m, 0) < MAX_WALKS and rising[m]]
        for m in below + walk:
            walks[m] = walks.get(m, 0) + (m in walk)
            k = rising[m]
            kn, cn, inertia = MODE_PARAMS[m]
            problem.base[kn] = k
            problem.base[cn] = 2 * problem.held_zeta[m] * math.sqrt(k * problem.base[inertia])
        if below or walk:
            continue
        for m, why in loose:
            k = kept[m]
            inertia = problem.base[MODE_PARAMS[m][2]]
            declared(m, why, None if k is None else (k, 2 * problem.held_zeta.get(m, zeta0) * math.sqrt(k * inertia)))
            free_modes.remove(m)


def _f_hz(problem: LogAmplitudeProblem, solution: Solution, free_modes: list, mode: str) -> float:
    """The frequency (Hz) at rest of the free ``mode`` in ``solution``."""
    k = math.exp(float(solution.res.x[2 * free_modes.index(mode)]))
    return math.sqrt(k / problem.base[MODE_PARAMS[mode][2]]) / (2 * np.pi)


def _top_line_hz(problem: LogAmplitudeProblem, mode: str) -> float:
    """The highest frequency (Hz) a measured line of ``mode``'s direction reaches (0 without one)."""
    return max((x.h * float(np.max(np.abs(x.speed))) / (2 * np.pi) for x in problem.meas_lines
                if x.direction == MODE_DIRECTION[mode] and np.size(x.speed)), default=0.0)


#: Times the ±5 % window of a held mode above every line is moved to where its fit ran (:func:`fit_modes`)
MAX_WALKS = 6


def above_every_line(problem: LogAmplitudeProblem, solution: Solution, free_modes: list, mode: str) -> float | None:
    """The stiffness (SI) the least squares ``solution`` put the loose ``mode`` at when that frequency lies above
    every measured line of its direction (the data show only the rise below it, C·Ω²/(1 − r²)), else None.

    Such a mode is declared, but kept where the rise puts it: reset to a starting value far above the band, its rise
    was left to the lines, each then given an exponent of its own and described as a source growing faster than Ω²
    (a ROSS wheel whose 334.5 Hz axial and 405.6 Hz rocking modes lie above its lines, 300-3000 rpm: axial located at
    243.9 Hz ±14.9 %, reset to 924 Hz, and three lines described as 'grows as Ω^2.1-2.2: a bearing defect')."""
    i = free_modes.index(mode)
    top = _top_line_hz(problem, mode)
    return math.exp(float(solution.res.x[2 * i])) if top and _f_hz(problem, solution, free_modes, mode) > top else None
