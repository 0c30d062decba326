"""The extended fit's forcing lines, measured-line powers and their derivatives
(:func:`rwadist.extended_fit.fit_extended`)."""
from __future__ import annotations

import math
from dataclasses import asdict, replace

import numpy as np

from . import extended as ext
from .errors import DataError
from .units import CHANNELS

CHANNEL_INDEX = {c: i for i, c in enumerate(CHANNELS)}
RADIAL = ("radial_force", "radial_torque")

#: direction -> (mode, stiffness, damping, inertia, gyroscopic inertia or None) of the subsystem it loads
_SUBSYSTEM = {"radial_force": ("radial_translation", "k_r", "c_r", "mass", None),
              "radial_torque": ("rocking", "k_rock", "c_rock", "I_rr", "I_zz"),
              "axial_force": ("axial_translation", "k_z", "c_z", "mass", None)}
_SUB_MODES = tuple(v[0] for v in _SUBSYSTEM.values())


class LinePower:
    """Measured-line powers of the least squares' forcing lines, vectorised, with analytic derivatives.

    Rows: first the non-radial measurements (one line, one channel: power |A|² of
    :func:`rwadist.extended.steady_lines` in that channel), then the radial ones (the x² + y² power of the
    co- and counter-rotating parts of one measured line, Σ_parts 2|T(ν)|²C²Ω⁴).  Exactly the model of
    :func:`rwadist.extended.steady_lines` for lines without law, offset or resonance, at ``height`` 0 (the
    fit removes the lever arm first), one component each ("co" or "counter"): a component of load C·Ω² at
    whirl rate ν = ±hΩ meets T(ν) = (k + icν)/(k − mν² + I_zz Ω ν + icν) of its direction's subsystem.
    Written out so that the least squares costs one vectorised evaluation per point and its Jacobian none
    (the finite-difference Jacobian of the per-line model cost one evaluation per parameter).

    lines : the fit's :class:`rwadist.extended.Line` list.  omega_ax, ax_line, ax_channel : (n_ax,) speed
    (rad/s), line index and channel index of each non-radial measurement.  omega_rad, rad_parts : (n_rad,)
    speed and (n_rad, 2) line indices of the two parts of each radial measurement.
    """

    def __init__(self, lines, omega_ax, ax_line, ax_channel, omega_rad, rad_parts):
        for ln in lines:
            if ln.law is not None or ln.f_offset != 0.0 or ln.resonances or ln.sense not in ("co", "counter"):
                raise ValueError(f"LinePower: line {ln} is not a plain co- or counter-rotating harmonic")
        own = {"axial_force": CHANNEL_INDEX["Fz"], "axial_torque": CHANNEL_INDEX["Tz"]}
        n_ax, n_rad = len(ax_line), len(rad_parts)
        ax_line, rad_parts = np.asarray(ax_line, int), np.asarray(rad_parts, int).reshape(-1, 2)
        self.n_rows = n_ax + n_rad
        self.row = np.concatenate([np.arange(n_ax), np.repeat(np.arange(n_ax, n_ax + n_rad), 2)])
        self.line = np.concatenate([ax_line, rad_parts.ravel()])
        omega = np.concatenate([np.asarray(omega_ax, float), np.repeat(np.asarray(omega_rad, float), 2)])
        weight = np.concatenate([[1.0 if own.get(lines[j].direction) == c else 0.0
                                  for j, c in zip(ax_line, np.asarray(ax_channel, int))], np.full(2 * n_rad, 2.0)])
        sigma = np.array([1.0 if (ln.sense == "co" or ln.direction not in RADIAL) else -1.0 for ln in lines])
        h = np.array([ln.h for ln in lines])
        self.omega = omega
        self.nu = sigma[self.line] * h[self.line] * omega
        self.scale = weight * omega**4                     # |load|² per C² and the channels the term reaches
        mode_of = np.array([_SUB_MODES.index(_SUBSYSTEM[ln.direction][0]) if ln.direction in _SUBSYSTEM else -1
                            for ln in lines], int)
        self.sub = mode_of[self.line]
        self.n_lines = len(lines)
        # each subsystem's terms, and each term's cell of d_C (row, line), fixed for every evaluation of the fit
        self.masks = [self.sub == i for i in range(len(_SUB_MODES))]
        self.cell = self.row * self.n_lines + self.line

    def _gains(self, vals: dict, derivatives: bool = True) -> tuple:
        """(|T|², ∂ ln|T|²/∂ ln k, ∂ ln|T|²/∂ ln c) of every term (n_terms,) at parameters ``vals``: the derivatives zero
        when ``derivatives`` is False."""
        t2 = np.ones(self.nu.size)
        dlk = np.zeros(self.nu.size)
        dlc = np.zeros(self.nu.size)
        for i, (mode, kn, cn, mn, gn) in enumerate(_SUBSYSTEM.values()):
            m = self.masks[i]
            if not m.any():
                continue
            k, c, mass = vals[kn], vals[cn], vals[mn]
            gyro = vals[gn] if gn else 0.0
            nu, om = self.nu[m], self.omega[m]
            cnu2 = (c * nu) ** 2
            num = k * k + cnu2
            re = k - mass * nu**2 + gyro * om * nu
            den = re**2 + cnu2
            t2[m] = num / den
            if derivatives:
                dlk[m] = 2.0 * k * (k / num - re / den)        # ∂ ln|T|² / ∂ ln k
                dlc[m] = 2.0 * cnu2 * (1.0 / num - 1.0 / den)  # ∂ ln|T|² / ∂ ln c
        return t2, dlk, dlc

    def line_powers(self, vals: dict) -> np.ndarray:
        """(n_lines,) each forcing line's response power per unit C², summed over its rows (Σ |T|²·Ω⁴ and the channels
        it reaches) at parameters ``vals``."""
        return np.bincount(self.line, self._gains(vals, False)[0] * self.scale, minlength=self.n_lines)

    def log_residuals(self, vals: dict, log_C: np.ndarray, log_data: np.ndarray, derivatives: bool = True):
        """(r, d_mode, d_C) at parameters ``vals`` (:class:`~rwadist.extended.ExtendedParams` fields) and line
        coefficients exp(``log_C``): r = log_data − ½ ln(model power) (n_rows,); d_mode[mode] = (∂r/∂ln k,
        ∂r/∂ln c) of each subsystem (n_rows,) each; d_C = ∂r/∂ln C (n_rows, n_lines).  ``derivatives`` False: (r,
        None, None), r the same numbers (a damping's profile evaluates the residuals alone, ~25 points a mode)."""
        t2, dlk, dlc = self._gains(vals, derivatives)
        p_term = t2 * np.exp(2.0 * log_C[self.line]) * self.scale
        p_row = np.bincount(self.row, p_term, minlength=self.n_rows)
        live = p_row > 1e-300
        r = log_data - 0.5 * np.log(np.maximum(p_row, 1e-300))
        if not derivatives:
            return r, None, None
        share = np.where(live[self.row], p_term / np.where(live, p_row, 1.0)[self.row], 0.0)
        d_mode = {}
        for i, mode in enumerate(_SUB_MODES):
            m = self.masks[i]
            d_mode[mode] = (-0.5 * np.bincount(self.row[m], (share * dlk)[m], minlength=self.n_rows),
                            -0.5 * np.bincount(self.row[m], (share * dlc)[m], minlength=self.n_rows))
        # Σ over the terms of each (row, line) cell in their order, from 0: the numbers of np.add.at, in one pass
        d_C = np.bincount(self.cell, -share, minlength=self.n_rows * self.n_lines).reshape(self.n_rows, self.n_lines)
        return r, d_mode, d_C


def forcing_lines(meas_lines: list, senses_xy: dict) -> tuple[list[ext.Line], np.ndarray]:
    """(forcing lines at their start, per forcing line its measured line): an axial line one coefficient, a radial
    line a co- and a counter-rotating part started from the x/y-phase split (floored so both can grow)."""
    lines, owner = [], []
    for j, x in enumerate(meas_lines):
        if x.direction in RADIAL:
            fr = senses_xy.get((x.direction, float(x.h)), ("co", 1.0))[1]
            c_co, c_ct = x.C * max(math.sqrt(fr), 0.03), x.C * max(math.sqrt(1 - fr), 0.03)
            imb = abs(x.h - 1.0) <= ext.IMBALANCE_H_TOL
            lines.append(ext.Line(x.direction, 1.0 if imb else float(x.h), float(c_co), "co", imbalance=imb))
            lines.append(ext.Line(x.direction, float(x.h), float(c_ct), "counter"))
            owner += [j, j]
        else:
            lines.append(ext.Line(x.direction, float(x.h), float(x.C), "co"))
            owner.append(j)
    if not lines:
        raise DataError("empirical fit", "harmonics", "none: nothing to fit the extended model to (lower `presence`)")
    return lines, np.array(owner)


def rows_of_lines(owner: np.ndarray, la: np.ndarray, lr: np.ndarray) -> tuple[dict, np.ndarray, np.ndarray]:
    """(measured line -> its forcing lines, per axial row its forcing line, per radial row its two parts) of the
    forcing lines' measured lines ``owner`` and the rows' measured lines ``la`` (axial), ``lr`` (radial)."""
    line_of: dict[int, list[int]] = {}
    for k, j in enumerate(owner):
        line_of.setdefault(int(j), []).append(k)
    ax_line = np.array([line_of[int(j)][0] for j in la], dtype=int)
    rad_parts = np.array([line_of[int(j)] for j in lr], dtype=int).reshape(-1, 2) if lr.size else np.zeros((0, 2), int)
    return line_of, ax_line, rad_parts


#: a radial line whose co/counter split the line power does not see within a factor e (the standard error of
#: ln(C_co/C_counter), :func:`rwadist.extended_fit_lsq.power_sum_stderr`, at least this) has it from the x/y phase
SPLIT_UNSEEN = 1.0


def imbalances(lines: list) -> dict:
    """{"U_s": C, "U_d": C} of the imbalance lines among ``lines`` (radial force, radial torque; 0.0 without one): the
    :class:`~rwadist.extended.ExtendedParams` values their C stands for."""
    return {u: next((ln.C for ln in lines if ln.imbalance and ln.direction == d), 0.0)
            for u, d in (("U_s", "radial_force"), ("U_d", "radial_torque"))}


def split_from_phase(params, meas_lines: list, fitted_lines: list, line_of: dict, sums: dict, senses_xy: dict) -> tuple:
    """(params, lines, standard errors): ``fitted_lines`` (and the imbalances U_s, U_d of ``params``) with the co- and
    counter-rotating parts of each radial line whose split the line power does not see (``sums``:
    :func:`rwadist.extended_fit_lsq.power_sum_stderr` by (direction, h) of its measured line; its split's standard
    error at least :data:`SPLIT_UNSEEN`) shared as its x/y phase shares them (``senses_xy``' co_fraction,
    :func:`rwadist.line_senses.line_senses`), their summed power kept; each such part's relative standard error
    ({"C[direction,h,sense]": value}) that of the summed amplitude, the split being the phase's.

    Where both senses pass the same gain (a radial force through the translation mode, any line far from the whirl
    modes) the least squares fix the parts' summed power and leave the split where rounding takes it: family wheel 1's
    planar h 5.67 force line (co fraction 0.5, x/y phase 0.4999) ended at 0.500 or 0.470 as numpy's AVX2 or AVX-512
    kernels rounded, and the second made a ``counter_rotation`` of the x/y phase's 0.4999; the E wheel's
    co-rotating torque imbalance, 8 speeds whose rocking no whirl pins, ended counter-rotating, its part's error
    1100 %.  There the response turns as the load does, and its x/y phase measures the split."""
    out, stderr = list(fitted_lines), dict[str, float]()
    for j, x in enumerate(meas_lines):
        key = (x.direction, float(x.h))
        if x.direction not in RADIAL or key not in sums or sums[key][3] < SPLIT_UNSEEN or key not in senses_xy:
            continue
        k_co, k_ct = line_of[j]
        total = out[k_co].C ** 2 + out[k_ct].C ** 2
        co = min(max(float(senses_xy[key][1]), 0.0), 1.0)
        out[k_co] = replace(out[k_co], C=math.sqrt(co * total))
        out[k_ct] = replace(out[k_ct], C=math.sqrt((1.0 - co) * total))
        stderr |= {f"C[{ln.direction},{ln.h:g},{ln.sense}]": float(sums[key][0]) for ln in (out[k_co], out[k_ct])}
    return replace(params, **imbalances(out)), out, stderr


#: a radial line's part under this share of the line's load power is dropped (:func:`fitted_senses`)
KEPT_PART = 0.01
#: a radial line's fitted part of one sense is contradicted by its x/y phase when the response share the fit gives it
#: exceeds this many times the measured share (which holds the noise's: an upper bound) ...
SENSE_FACTOR = 2.0
#: ... on a line whose response turns one way in every run, all but this share of its power at most
PURE_SENSE = 0.01


def split_to_senses(params, meas_lines: list, fitted_lines: list, line_of: dict, powers: np.ndarray,
                    senses_xy: dict) -> tuple:
    """(params, lines, keys): ``fitted_lines`` (and the imbalances of ``params``) with each radial line whose fitted
    part of one sense its x/y phase contradicts made a line of the other sense alone, and the (direction, h) of those
    lines.

    The x/y phase measures the response's co-rotating share directly (``senses_xy``' co_fraction,
    :func:`rwadist.line_senses.line_senses`, summed over the runs).  The parts fitted to the line power predict it:
    the minority sense's share q = C_m²·P_m / (C_co²·P_co + C_counter²·P_counter), with P a part's response power per
    unit C² (``powers``: :meth:`LinePower.line_powers` at the fitted modes).  Where the response turns one way in every
    run (``senses_xy``' every_run "co" or "counter") and all but m <= :data:`PURE_SENSE` of its power, and q exceeds
    :data:`SENSE_FACTOR` times m, the data hold no such response of the other sense, and the split is model error
    absorbed.  A co-rotating line: a fast sweep's top torque line crossing the forward whirl within one slice, a peak
    smeared in the slice, fitted as a counter part of 24-38 % of C that the x/y phase put at 0.1 % of the line's power,
    in 5 of 12 sweeps of three wheels; another's 0.36 % against the phase's 0.089 %.  A counter-rotating one: session
    62's trial (a 7.5-kg wheel, I_zz/I_rr 1.55, rocking 88 Hz), its cage torque line h 0.41 fitted with a co part of
    29 % of C, 1.5 % of the response, where the phase put 3e-6: at 4500 rpm the model turned 4e-3 N·m with the spin
    that the data held at 2e-5.  There the line is of the one sense alone, its response's summed power P kept
    (C² = P/P_sense): a share m that small is the noise's, and, divided by a far smaller gain of the other whirl,
    would still make a part of 13 % of C (a family wheel's co line crossing the forward whirl in a 40 s run-up).
    Not on a line that turns both ways: there the measured share is weighted by what lifts the runs (a fixture
    resonance, divided out of the fitted rows), and a line of 20 % counter-rotating load, its phase's share 0.078 and
    the fit's 0.245, lost family wheel 6's fixture at 1.25x its rocking mode."""
    out, changed = list(fitted_lines), []
    for j, x in enumerate(meas_lines):
        key = (x.direction, float(x.h))
        if x.direction not in RADIAL or key not in senses_xy or senses_xy[key][2] not in ("co", "counter"):
            continue
        k_co, k_ct = line_of[j]
        co_share = min(max(float(senses_xy[key][1]), 0.0), 1.0)
        k_own, k_other, m = (k_co, k_ct, 1.0 - co_share) if senses_xy[key][2] == "co" else (k_ct, k_co, co_share)
        if out[k_other].imbalance:
            continue    # an imbalance turns with the spin: read against it in every run, the speed's sign is in doubt
        p_own, p_other = out[k_own].C ** 2 * powers[k_own], out[k_other].C ** 2 * powers[k_other]
        total = p_own + p_other
        if not total > 0.0 or powers[k_own] <= 0.0 or m > PURE_SENSE or p_other / total <= SENSE_FACTOR * m:
            continue
        if out[k_other].C ** 2 < KEPT_PART * (out[k_own].C ** 2 + out[k_other].C ** 2):
            continue    # a part the model does not keep (:func:`fitted_senses`): nothing to correct
        # the response turns one way in every run, all but m of it: what turns the other way is noise
        out[k_own] = replace(out[k_own], C=math.sqrt(total / powers[k_own]))
        out[k_other] = replace(out[k_other], C=0.0)
        changed.append(key)
    return replace(params, **imbalances(out)), out, changed


def resplit_note(direction: str, h: float, co_fraction: float) -> str:
    """The model file's note on a radial line whose fitted co/counter split its x/y phase contradicted
    (:func:`split_to_senses`)."""
    own, other = ("co", "counter") if co_fraction >= 0.5 else ("counter", "co")
    share = 1.0 - co_fraction if own == "co" else co_fraction
    return (f"{direction} h={h:.4g}: the co/counter split fitted to the line power put a {other}-rotating response "
            f"in the data that the x/y phase does not show ({100 * share:.2g} % of the line's power "
            f"turns {'against' if own == 'co' else 'with'} the spin): the split is the phase's, the line's power kept "
            f"(a misfit near a whirl mode, e.g. a line crossing it within one slice of a fast sweep, is not taken for a "
            f"{other}-rotating load)")


def phase_splits(params, meas_lines: list, fitted_lines: list, line_of: dict, sums: dict, senses_xy: dict,
                 power: "LinePower", notes: list) -> tuple:
    """(params, lines, standard errors) of :func:`split_from_phase` then :func:`split_to_senses` (the forcing lines'
    response powers per unit C² from ``power`` at the fitted modes); a note of each line split again appended to
    ``notes``."""
    params, lines, stderr = split_from_phase(params, meas_lines, fitted_lines, line_of, sums, senses_xy)
    powers = power.line_powers(asdict(params))
    params, lines, resplit = split_to_senses(params, meas_lines, lines, line_of, powers, senses_xy)
    notes += [resplit_note(d, h, senses_xy[(d, h)][1]) for d, h in resplit]
    return params, lines, stderr


def fitted_senses(meas_lines: list, fitted_lines: list, line_of: dict) -> tuple[dict, list]:
    """(senses, kept lines): the rotation sense of each radial line from its fitted forcing, (direction, h) ->
    (sense, co-rotating fraction of its power); negligible parts (< 1 % of the line's power) dropped."""
    senses, kept_lines = {}, []
    for j, x in enumerate(meas_lines):
        parts = [fitted_lines[k] for k in line_of[j]]
        if x.direction not in RADIAL:
            kept_lines += parts
            continue
        p_co, p_ct = parts[0].C ** 2, parts[1].C ** 2
        fr = p_co / (p_co + p_ct)
        sense = "co" if fr >= 0.99 else ("counter" if fr <= 0.01 else "co+counter")
        senses[(x.direction, float(x.h))] = (sense, float(fr))
        kept_lines += [ln for ln, pw in zip(parts, (p_co, p_ct)) if pw >= KEPT_PART * (p_co + p_ct) or ln.imbalance]
    return senses, kept_lines
