"""Step 3 of the extended fit (:func:`rwadist.extended_fit.fit_extended`): the least squares of log line amplitudes.

The stiffness and damping of each mode left free, the forcing coefficient of each line (a radial line: its co- and
counter-rotating parts), an exponent of its own for a line of another law than C·Ω² (:mod:`rwadist.off_law_lines`) and,
when fitted with the modes, the fixture resonance's parameters (:class:`rwadist.resonance.FittedResonance`) are
adjusted together on every measured line at every speed; standard errors come from the Jacobian.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np
from scipy import optimize

from . import extended as ext
from .extended_fit_power import LinePower, imbalances
from .resonance import FittedResonance
from .stand_every import FittedStands

#: The scatter of a row's log amplitude assumed besides the noise (:meth:`LogAmplitudeProblem.row_weights`): about the
#: unweighted fit's own RMS log residual on the family's data (0.034-0.040 on family wheel 1's load-cell offset cell).
LOG_SCATTER = 0.03
#: A load cell's force sensors are noisier than its torque sensors (or the reverse) when the one family's noise floor
#: against its imbalance line is more than this many times the other's at every speed (:func:`noisy_sensor_directions`)
#: (the family matrix's clean, cross_coupling, sidebands and broadband_floor cells of wheels 1, 5, 6: at most 2.1x
#: at the slowest speed; its lever_arm_noise cells, force sensors 28 dB noisier: 5.1-19x at every speed)
SENSOR_NOISE_EXCESS = 3.0
#: the percentile of the line measurements' noise floors that reads a sensor family's floor (:func:`_family_noise`)
FLOOR_PERCENTILE = 10.0
#: the load directions each sensor family of a six-axis load cell measures
SENSOR_FAMILIES = {"force": ("radial_force", "axial_force"), "torque": ("radial_torque", "axial_torque")}


def _family_noise(meas_lines, radial: str) -> dict:
    """Per speed (rad/s), the noise floor of the sensors measuring ``radial`` against the imbalance they measure: of
    every measurement of every line of that direction at that speed (each channel), the noise amplitude under the line
    (σ_d·d, :attr:`rwadist.empirical.LineFit.noise` times the amplitude) divided by the imbalance line's (h = 1)
    amplitude in the same channel, its :data:`FLOOR_PERCENTILE` th percentile; empty without an h = 1 line.  The low
    percentile reads the floor under the cleanest lines: a neighbouring line's skirt (a sideband) only lifts it."""
    lines = [x for x in meas_lines if x.direction == radial and x.noise is not None]
    h1 = [x for x in lines if abs(x.h - 1.0) < 1e-3]
    if not h1:
        return {}
    ref = {(c, float(w)): float(d) for c, w, d in zip(h1[0].channel, h1[0].speed, h1[0].amplitude) if d > 0}
    per: dict = {}
    for x in lines:
        for c, w, d, n in zip(x.channel, x.speed, x.amplitude, np.asarray(x.noise, dtype=float)):
            if (c, float(w)) in ref and np.isfinite(n) and n > 0:
                per.setdefault(float(w), []).append(float(n) * float(d) / ref[(c, float(w))])
    return {w: float(np.percentile(v, FLOOR_PERCENTILE)) for w, v in per.items()}


def noisy_sensor_directions(meas_lines) -> tuple:
    """The load directions whose sensors are far noisier than the load cell's others: those of the force sensors when
    the radial forces' noise floor against their imbalance line (:func:`_family_noise`) is more than
    :data:`SENSOR_NOISE_EXCESS` times the radial torques' at every speed both are measured at, those of the torque
    sensors in the reverse case, else none (also without an imbalance line in both).

    A six-axis load cell has two sensor families, its force and its moment channels, each with its own noise.  The
    imbalance line is in both (the static and the dynamic imbalance) at the same speeds, so the ratio of the two
    families' noise floors, each against the imbalance it measures, is dimensionless: alike (within a few times) on a
    stand whose noise is alike across its channels, far apart when one family's sensors (their amplifiers, a
    load-cell offset's lever-arm cabling) are noisier.  A sensor's noise does not depend on the speed, so a noisier
    sensor family is noisier at every speed, the slowest included; the rotor's own random loads (a broadband floor on
    the forces, growing as Ω³) and the lines' skirts grow with the speed and lift the ratio at the top speeds only
    (family wheel 1, a broadband floor: 7x at the median speed, 0.14x at the slowest; its force sensors 28 dB
    noisier: 19-23x at every speed).  Only when a family is so much noisier do its measurements weigh less in the
    mode fit (:meth:`LogAmplitudeProblem.row_weights`); a fit of data whose noise is alike across the load cell is
    left as it is."""
    force = _family_noise(meas_lines, SENSOR_FAMILIES["force"][0])
    torque = _family_noise(meas_lines, SENSOR_FAMILIES["torque"][0])
    ratio = np.array([force[w] / torque[w] for w in force if w in torque and torque[w] > 0])
    if not ratio.size:
        return ()
    if ratio.min() > SENSOR_NOISE_EXCESS:
        return SENSOR_FAMILIES["force"]
    if ratio.max() < 1.0 / SENSOR_NOISE_EXCESS:
        return SENSOR_FAMILIES["torque"]
    return ()


#: The key of a test's ``meta`` that holds the load directions of its far noisier sensor family, decided once on the
#: data as recorded (:func:`recorded_noisy_sensors`); diagnose sets it before any effect is fitted
NOISY_SENSORS_META = "noisy_sensor_directions"


def recorded_noisy_sensors(test, meas_lines) -> tuple:
    """The load directions of the far noisier sensor family of ``test``: those its ``meta`` holds under
    :data:`NOISY_SENSORS_META` (decided once on the data as recorded), else :func:`noisy_sensor_directions` of
    ``meas_lines``, the lines measured on ``test`` itself.

    Which sensors are noisier is a property of the load cell, not of what has been fitted: the test a fit works on may
    be the recorded data with an effect's correction applied (a load-cell offset's T − r × F moves the force
    sensors' noise into the corrected torques, so both families read noisy there) or a half of the runs, and the
    decision read again on those is not the recording's (the family matrix's lever_arm_noise cell of wheel 5, r_z =
    −60 mm: the forces' floor 5.2-8.0x the torques' at every speed as recorded, 2.9-5.1x on the corrected torques,
    where the force family was not singled out and the axial mode came out 5.4e-4 off, 0.4e-4 with the recording's
    decision).  :func:`rwadist.effects.suspension_modes_diagnose._recorded_meta` decides it once on every recorded run
    and carries it to every fit of the modes."""
    held = getattr(test, "meta", {}).get(NOISY_SENSORS_META)
    return noisy_sensor_directions(meas_lines) if held is None else tuple(held)


#: mode -> (its stiffness, its damping, the inertia they act on): fields of :class:`rwadist.extended.ExtendedParams`
MODE_PARAMS = {"radial_translation": ("k_r", "c_r", "mass"), "rocking": ("k_rock", "c_rock", "I_rr"),
               "axial_translation": ("k_z", "c_z", "mass")}


def _row_variance(res: optimize.OptimizeResult, row_group: np.ndarray) -> np.ndarray:
    """Per row of the least squares, its direction's mean squared residual (``row_group``: per row its direction),
    the degrees of freedom shared out in proportion to the rows (:func:`_covariance`)."""
    r2 = res.fun**2
    scale = res.fun.size / max(res.fun.size - res.x.size, 1)
    groups, inverse = np.unique(row_group, return_inverse=True)
    mean = np.bincount(inverse, weights=r2, minlength=groups.size) / np.maximum(np.bincount(inverse), 1)
    return scale * mean[inverse]


def _covariance(res: optimize.OptimizeResult, row_group: np.ndarray) -> np.ndarray:
    """Covariance of the least squares' parameters ``res.x`` with each load direction's own residual variance
    (``row_group``: per row its direction): (JᵀJ)⁺ Jᵀ S J (JᵀJ)⁺, S = diag of each row's direction's mean squared
    residual (the degrees of freedom shared out in proportion to the rows).  A mode's frequency is measured by its
    own direction's lines: another direction's misfit (a resonance moving with speed on the radial forces, which no
    mode of the model has, 1.3 dB near the translation) is no scatter of the rocking lines, and pooled it widened the
    rocking's standard error past the 2 % of a found mode.  One direction: s²·(JᵀJ)⁺, as before."""
    s2_row = _row_variance(res, row_group)
    inv = np.linalg.pinv(res.jac.T @ res.jac)
    return inv @ (res.jac.T @ (s2_row[:, None] * res.jac)) @ inv


class Solution(NamedTuple):
    """One least squares of :meth:`LogAmplitudeProblem.solve`.

    res : scipy's result (``res.x`` θ: ln k, ln c of each free mode, ln C of each line, the freed lines' exponent
        shifts, the stand's parameters; ``res.fun`` the log residuals, the axial rows then the radial ones).
    names : the name of each entry of θ.
    rel_se : relative standard error of each entry of θ (the standard error of its logarithm), shape like ``res.x``.
    unpack : θ -> (:class:`~rwadist.extended.ExtendedParams`, fitted lines).
    at_bound : per free mode, the limit its best fit sits at ("stiffness", "damping") or "".
    cov : covariance of θ (:func:`_covariance`), shape (θ, θ); NaN where it could not be computed.
    s2_row : per row its direction's residual variance (:func:`_row_variance`), shape like ``res.fun``.
    residuals : θ -> the rows' residuals as fitted (weighted), the function the least squares minimised, without its
        Jacobian (:meth:`_Residuals.value`: a damping's profile, :func:`rwadist.extended_fit_damping.damping_interval`).
    """

    res: optimize.OptimizeResult
    names: list[str]
    rel_se: np.ndarray
    unpack: Callable[[np.ndarray], tuple[ext.ExtendedParams, list[ext.Line]]]
    at_bound: dict[str, str]
    cov: np.ndarray
    s2_row: np.ndarray
    residuals: Callable[[np.ndarray], np.ndarray] | None = None


@dataclass
class LogAmplitudeProblem:
    """What the least squares fits, fixed across its repetitions (a mode declared not constrained is reset in
    ``base`` and left out of the next).

    base : the :class:`~rwadist.extended.ExtendedParams` fields at the start (SI).
    lines : the forcing lines at their starting coefficients (a radial line: a co- and a counter-rotating part).
    power : the model's line power at every measured row (:class:`rwadist.extended_fit_power.LinePower`).
    log_data : the rows' measured log amplitudes, shape (rows,) (with ``joint``: the start stand multiplied back).
    joint : the fixture resonance (or resonances, :class:`rwadist.stand_every.FittedStands`) fitted with the modes, or None.
    row_line, centred_log_w : per row its measured line and centred ln|Ω| (:func:`rwadist.off_law_lines.line_regressors`).
    meas_lines : the measured lines (LineFit list), named by the exponents freed.
    progress : scipy's iteration printout.
    row_noise : per row, the standard deviation of its log amplitude the noise makes (dimensionless), or None.
    scatter : the scatter of a row's log amplitude assumed besides the noise (dimensionless; :meth:`row_weights`).
    noisy : the load directions whose sensors are far noisier than the others' (:func:`noisy_sensor_directions`):
        only their rows are weighted by their noise.
    held_zeta : mode -> the damping ratio it is held at (its damping the data do not constrain,
        :mod:`rwadist.extended_fit_damping`): its damping coefficient follows its stiffness, c = 2ζ·sqrt(k·inertia),
        and its ln c entry of θ is inert.
    """

    base: dict
    lines: list
    power: LinePower
    log_data: np.ndarray
    joint: FittedResonance | FittedStands | None
    row_line: np.ndarray
    centred_log_w: np.ndarray
    meas_lines: list
    progress: bool = False
    row_noise: np.ndarray | None = None
    scatter: float = 0.0
    noisy: tuple = ()
    held_zeta: dict = field(default_factory=dict)

    def row_weights(self) -> np.ndarray | None:
        """Per row, the weight of its log residual, or None (every row alike, the plain least squares): None unless
        some load directions' sensors are far noisier than the others' (``noisy``); then a row of such a direction
        weighs 1/sqrt(1 + (σ_row/s)²), σ_row the standard deviation of its log amplitude the noise makes
        (``row_noise``), s the scatter of a row assumed besides the noise (``scatter``, :data:`LOG_SCATTER`), and
        every other row 1.

        A row's log amplitude scatters by sqrt(σ_row² + s²) about the model: weighed alike, a line measured at
        10-30 % of a noisy sensor's floor pulls a mode as much as one measured 60 dB clear of it.  Force sensors
        28 dB noisier than the torque sensors (family wheel 1, a load-cell offset) moved its 520 Hz translation to
        519.815 Hz (clean 520.011) and left 12.5x the clean error; on wheel 5 the force lines' misfit hid the
        corrected torques' noise.  Rows of a quiet family keep weight 1, and data whose noise is alike across the
        load cell are fitted as before, bit for bit."""
        if self.row_noise is None or not self.scatter > 0 or not self.noisy:
            return None
        dirs = sorted({x.direction for x in self.meas_lines})
        on = np.isin(np.asarray(dirs, dtype=object)[self.row_directions()], list(self.noisy))
        sigma = np.where(on, np.asarray(self.row_noise, dtype=float), 0.0)
        return 1.0 / np.sqrt(1.0 + (sigma / self.scatter) ** 2)

    def solve(self, free_modes: list[str], off_law: Sequence[int] = ()) -> Solution:
        """Log-amplitude least squares with the stiffness and damping of ``free_modes`` free, and an exponent of
        their own for the measured lines ``off_law`` (indices into ``meas_lines``,
        :func:`rwadist.off_law_lines.off_law_line`)."""
        base, lines, joint = self.base, self.lines, self.joint
        names = [p for m in free_modes for p in MODE_PARAMS[m][:2]] + \
                [f"C[{ln.direction},{ln.h:g},{ln.sense}]" for ln in lines] + \
                [f"p-2[{self.meas_lines[j].direction},{self.meas_lines[j].h:g}]" for j in off_law] + \
                (list(joint.NAMES) if joint is not None else [])
        x0 = np.concatenate([np.log([base[n] for m in free_modes for n in MODE_PARAMS[m][:2]]),
                             np.log([ln.C for ln in lines]), np.zeros(len(off_law))]
                            + ([joint.x0] if joint is not None else []))
        n_mode = 2 * len(free_modes)
        n_c = len(lines)
        residuals = _Residuals(self, free_modes, [np.where(self.row_line == j, self.centred_log_w, 0.0)
                                                  for j in off_law])
        # bounds keep the search physical: stiffness within ±10 % of the scan's (frequency ±5 %),
        # damping ratio in [5e-5, 0.95], line coefficients within 1000x (down to 1e-4 of the line
        # for the sense parts, which may vanish)
        lo, hi = [], []
        for m in free_modes:
            kn, cn, inertia = MODE_PARAMS[m]
            crit = 2 * math.sqrt(base[kn] * base[inertia])
            lo += [math.log(base[kn] / 1.1), math.log(1e-4 * crit / 2)]
            hi += [math.log(base[kn] * 1.1), math.log(0.95 * crit * 2)]
        lo += list(x0[n_mode:n_mode + n_c] - math.log(1e4)) + [-3.0] * len(off_law) + \
            (list(joint.lower) if joint is not None else [])
        hi += list(x0[n_mode:n_mode + n_c] + math.log(1e3)) + [3.0] * len(off_law) + \
            (list(joint.upper) if joint is not None else [])
        res = optimize.least_squares(residuals.residuals, x0, jac=residuals.jacobian,
                                     bounds=(lo, hi), method="trf", x_scale="jac", max_nfev=400,
                                     verbose=2 if self.progress else 0)
        try:
            cov = _covariance(res, self.row_directions())
        except np.linalg.LinAlgError:
            cov = np.full((res.x.size, res.x.size), np.nan)
        rel_se = np.sqrt(np.clip(np.diag(cov), 0, None))
        s2_row = _row_variance(res, self.row_directions())      # of the rows as fitted (weighted), as res.jac is
        if residuals.weights is not None:
            # the log residuals themselves for what reads them after the fit (a mode's misfit in dB, the off-law lines)
            res.fun = res.fun / residuals.weights
        # a limit is what the fit allowed, not what the data say: stiffness at ±10 %, damping at its floor ζ = 5e-5 (a
        # stand beside a load-cell offset was taken for the translation so, -19 %)
        at_bound = {m: ("stiffness" if min(res.x[2 * i] - lo[2 * i], hi[2 * i] - res.x[2 * i]) < 0.01 else
                        "damping" if res.x[2 * i + 1] - lo[2 * i + 1] < 0.01 else "")
                    for i, m in enumerate(free_modes)}
        modes = list(free_modes)        # as solved (the caller's list loses the modes it declares next)
        if self.held_zeta:
            # a held damping is no limit the fit ran into
            at_bound = {m: ("" if m in self.held_zeta and why == "damping" else why) for m, why in at_bound.items()}
        return Solution(res, names, rel_se, lambda theta: self.unpack(modes, theta), at_bound, cov, s2_row,
                        residuals.value)

    def row_directions(self) -> np.ndarray:
        """Per least-squares row, the index of its measured line's load direction (radial force, radial torque,
        axial force), shape (rows,)."""
        dirs = sorted({x.direction for x in self.meas_lines})
        of_line = np.array([dirs.index(x.direction) for x in self.meas_lines], dtype=int)
        return of_line[np.asarray(self.row_line, dtype=int)]

    def unpack(self, free_modes: list[str], theta: np.ndarray) -> tuple[ext.ExtendedParams, list[ext.Line]]:
        """(parameters, fitted lines) of θ of the least squares with ``free_modes`` free."""
        vals = dict(self.base)
        k = 0
        for m in free_modes:
            kn, cn, inertia = MODE_PARAMS[m]
            vals[kn] = math.exp(theta[k])
            # damping stays below critical (the model refuses overdamped modes); a held damping ratio follows k
            vals[cn] = (2 * self.held_zeta[m] * math.sqrt(vals[kn] * vals[inertia]) if m in self.held_zeta else
                        min(math.exp(theta[k + 1]), 1.9 * math.sqrt(vals[kn] * vals[inertia])))
            k += 2
        n_mode, n_c = 2 * len(free_modes), len(self.lines)
        C = np.exp(theta[n_mode:n_mode + n_c])
        lns = [replace(ln, C=float(c)) for ln, c in zip(self.lines, C)]
        return ext.ExtendedParams(**(vals | imbalances(lns))), lns


class _Residuals:
    """The log residuals of a :class:`LogAmplitudeProblem` and their analytic Jacobian at θ, computed once per point
    (scipy asks for the residuals and then the Jacobian at the same point); ``off_rows``: the regressor of each freed
    exponent."""

    def __init__(self, problem: LogAmplitudeProblem, free_modes: list[str], off_rows: list[np.ndarray]):
        self.problem, self.free_modes, self.off_rows = problem, free_modes, off_rows
        self.weights = problem.row_weights()
        self.key: bytes | None = None
        self.r = np.empty(0)
        self.J = np.empty((0, 0))

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        self._at(theta)
        return self.r

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        self._at(theta)
        return self.J

    def value(self, theta: np.ndarray) -> np.ndarray:
        """:meth:`residuals` at θ without the Jacobian (the same numbers: the same operations in the same order), the
        cache left as it is: what a damping's profile (:func:`rwadist.extended_fit_damping.damping_interval`) reads at
        each of its ~25 points."""
        p = self.problem
        n_mode, n_c, n_off = 2 * len(self.free_modes), len(p.lines), len(self.off_rows)
        vals, _ = self._vals(theta)
        log_data = p.log_data if p.joint is None else \
            p.log_data - 0.5 * p.joint.log_gain(theta[n_mode + n_c + n_off:])[0]
        r = p.power.log_residuals(vals, theta[n_mode:n_mode + n_c], log_data, derivatives=False)[0]
        for i, L in enumerate(self.off_rows):
            r = r - theta[n_mode + n_c + i] * L
        return r * self.weights if self.weights is not None else r

    def _vals(self, theta: np.ndarray) -> tuple:
        """(the :class:`~rwadist.extended.ExtendedParams` fields at θ, per free mode whether its damping is clamped)."""
        p = self.problem
        vals = dict(p.base)
        clamped = {}
        for i, m in enumerate(self.free_modes):
            kn, cn, inertia = MODE_PARAMS[m]
            vals[kn] = math.exp(theta[2 * i])
            crit = 1.9 * math.sqrt(vals[kn] * vals[inertia])
            if m in p.held_zeta:
                # held: c = 2ζ·sqrt(k·inertia) follows k as a clamped damping does (d ln c / d ln k = 1/2)
                clamped[m] = True
                vals[cn] = 2 * p.held_zeta[m] * math.sqrt(vals[kn] * vals[inertia])
                continue
            clamped[m] = math.exp(theta[2 * i + 1]) > crit
            vals[cn] = min(math.exp(theta[2 * i + 1]), crit)
        return vals, clamped

    def _at(self, theta: np.ndarray) -> None:
        key = theta.tobytes()
        if self.key == key:
            return
        p, free_modes = self.problem, self.free_modes
        n_mode, n_c, n_off = 2 * len(free_modes), len(p.lines), len(self.off_rows)
        vals, clamped = self._vals(theta)
        if p.joint is None:
            r, d_mode, d_C = p.power.log_residuals(vals, theta[n_mode:n_mode + n_c], p.log_data)
            J = np.zeros((r.size, theta.size))
        else:
            # the stand divided out at its own parameters: r = ln data − ln|H| − ½ ln P
            y_s, dy_s = p.joint.log_gain(theta[n_mode + n_c + n_off:])
            r, d_mode, d_C = p.power.log_residuals(vals, theta[n_mode:n_mode + n_c], p.log_data - 0.5 * y_s)
            J = np.zeros((r.size, theta.size))
            J[:, n_mode + n_c + n_off:] = -0.5 * dy_s
        for i, L in enumerate(self.off_rows):      # a freed line's own growth (|Ω|/Ω_line)^δ
            r = r - theta[n_mode + n_c + i] * L
            J[:, n_mode + n_c + i] = -L
        for i, m in enumerate(free_modes):
            dk, dc = d_mode[m]
            # a clamped damping follows the stiffness (c = 1.9·sqrt(k·inertia): d ln c / d ln k = 1/2)
            J[:, 2 * i] = dk + 0.5 * dc if clamped[m] else dk
            J[:, 2 * i + 1] = 0.0 if clamped[m] else dc
        J[:, n_mode:n_mode + n_c] = d_C
        if self.weights is not None:
            r, J = r * self.weights, J * self.weights[:, None]
        self.key, self.r, self.J = key, r, J


def loose_modes(solution: Solution, free_modes: list[str], base: dict, tolerance: float) -> list[tuple[str, str]]:
    """(mode, why) of each free mode the least squares does not pin: found means its frequency pinned (1.5 standard
    errors of f = sqrt(k/m)/2π, half k's relative error, within ``tolerance``) away from the bounds."""
    res, rel_se, at_bound = solution.res, solution.rel_se, solution.at_bound
    loose = []
    for i, m in enumerate(free_modes):
        se_f = 0.5 * float(rel_se[2 * i])
        if at_bound[m] or not (1.5 * se_f <= tolerance):
            f_fit = math.sqrt(math.exp(res.x[2 * i]) / base[MODE_PARAMS[m][2]]) / (2 * np.pi)
            loose.append((m, {"stiffness": "the best fit sits at the ±5 % limit around the scan's frequency",
                              "damping": f"located at {f_fit:.4g} Hz but its damping runs to the fit's floor (ζ = "
                              "5e-05): the data show no damped peak there (a resonance of the test stand?)"}.get(
                at_bound[m], f"located at {f_fit:.4g} Hz but only to ±{100 * 1.5 * se_f:.1f} % (1.5 standard "
                             f"errors), not {100 * tolerance:g} %")))
    return loose


def power_sum_stderr(solution: Solution, pairs: dict) -> dict:
    """Per radial line fitted with a co- and a counter-rotating part (``pairs``: (direction, h) -> the parts' indices
    among the least squares' forcing lines, co first): {(direction, h): (the relative standard error of the parts'
    summed amplitude sqrt(C_co² + C_counter²), that of each part, the standard error of ln(C_co/C_counter) with
    the other parameters held)}.

    The rows are each line's x-plus-y power, abs(C_co·H_co)² + abs(C_counter·H_counter)²: where both senses pass
    the same gain (a radial force through the translation mode, any line far from the whirl modes) the rows fix
    the sum and not the split, whose column of the Jacobian then vanishes (trial11: parts' errors of 612 and 1477,
    or, with the pseudo-inverse, small ones that mean nothing).  With g = (C_co², C_counter²)/P the sum's
    d ln sqrt(P) = g·(d ln C_co, d ln C_counter): var = g·Σ·g.  The split moves along v = (g_counter, −g_co),
    which keeps P and changes ln(C_co/C_counter) one for one: var = vᵀJᵀSJv/(vᵀJᵀJv)² (J and S the rows' Jacobian
    and variances as fitted: weighted when a far noisier sensor family is, :meth:`LogAmplitudeProblem.row_weights`);
    infinite when the rows do not see it.  Held the other parameters, this is the least the split's error can be: a
    note said on it is never said in vain, though a split measured only through a free mode's gain may go unsaid."""
    first = next(i for i, n in enumerate(solution.names) if n.startswith("C["))     # θ: the modes, then the lines
    out = {}
    for key, (k_co, k_ct) in pairs.items():
        ij = [first + k_co, first + k_ct]
        c2 = np.exp(2.0 * solution.res.x[ij])
        g = c2 / np.sum(c2)
        var = float(g @ solution.cov[np.ix_(ij, ij)] @ g)
        jv = solution.res.jac[:, ij] @ np.array([g[1], -g[0]])
        seen = float(jv @ jv)
        split = math.sqrt(float(jv**2 @ solution.s2_row)) / seen if seen > 0.0 else math.inf
        out[key] = (math.sqrt(max(var, 0.0)) if np.isfinite(var) else math.nan,
                    float(solution.rel_se[ij[0]]), float(solution.rel_se[ij[1]]), split)
    return out


def split_note(direction: str, h: float, rel_sum: float, split: float) -> str:
    """The model file's note on a radial line whose co/counter split the line power leaves open
    (:func:`power_sum_stderr`'s ``split`` over 1: the amplitude ratio not known within a factor e; ``rel_sum`` its
    summed amplitude's relative standard error): the split is the x/y phase's,
    :func:`rwadist.extended_fit_power.split_from_phase`."""
    return (f"{direction} h={h:.4g}: the line power does not separate its co- and counter-rotating parts (both senses "
            f"pass the same gain here; standard error of ln(C_co/C_counter) "
            f"{'unbounded' if split > 1e3 else f'{split:.3g}'}): the split is the x/y phase's (analytical.fit.senses; "
            f"rwadist diagnose's counter_rotation measures it), and each part's standard error is that of the summed "
            f"amplitude sqrt(C_co² + C_counter²), known to {100 * rel_sum:.2g} % "
            f"(rel_stderr C[{direction},{h:g},co+counter])")


def joint_cost(efit) -> float:
    """Sum of squared log residuals of an extended fit (:attr:`ExtendedFit.line_residuals`): its least squares'
    cost, every fit of one empirical fit measured on the same rows."""
    r = np.asarray(efit.line_residuals[1], dtype=float)
    return float(np.sum(r[np.isfinite(r)] ** 2))


def noise_weighted_cost(efit) -> float:
    """Σ r²/(s² + σ²) over the rows of an extended fit (:attr:`rwadist.extended_fit.ExtendedFit.line_residuals` r,
    ``line_noise`` σ): each log residual over the scatter its row has about a right model, the noise under the line
    (σ, the standard deviation of its log amplitude) and the scatter assumed besides it (s,
    :data:`LOG_SCATTER`, 0.03) -- twice the negative log likelihood of the rows, up to a
    constant.  The plain cost (:func:`joint_cost`) weighs every row alike, so one line measured at the noise floor
    can outweigh all the rest: on family wheel 2's fixture pair (stands 70.93 and
    115.71 Hz, ζ 0.03, gain 5) the stands fitted at once (70.998 Hz ζ 0.0305 gain 4.97; 115.66 Hz ζ 0.0302 gain
    4.96) cost 0.299 against 0.175 for those fitted one at a time (70.31 Hz ζ 0.0224 gain 6.03; 115.96 Hz ζ 0.0295
    gain 4.76), and 0.138 of the difference was one row: the axial 2xBPFO line at 197.2 Hz, its log amplitude's
    noise σ 0.37 (the rows' median 0.028), residual +0.379 against +0.074.  Weighed by their scatter the rows cost
    37.6 against 56.9, and the stands fitted at once left the error after 2.96x the clean cell's instead of 8.3x.
    Rows whose noise was not measured (σ 0) weigh 1/s² each; rows whose residual or noise is not a number (a line
    not measured at that speed) are left out, as the plain cost leaves them."""
    r = np.asarray(efit.line_residuals[1], dtype=float)
    sigma = np.asarray(getattr(efit, "line_noise", np.empty(0)), dtype=float)
    if sigma.shape != r.shape:
        sigma = np.zeros_like(r)
    ok = np.isfinite(r) & np.isfinite(sigma)
    return float(np.sum(r[ok] ** 2 / (LOG_SCATTER**2 + sigma[ok] ** 2)))
