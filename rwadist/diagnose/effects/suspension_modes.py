"""``suspension_modes``: the wheel's own suspension modes (radial translation, rocking forward and backward
whirl, axial translation), fitted from the data with the extended fit and made the base of the search.

Data of a real wheel show modal amplification: lines grow and shrink as they cross the rotor's modes.
On the empirical (hard-mounted, C·Ω²) base that looks like foreign effects (fixed resonances, amplitude
laws); it is the wheel itself.  This family proposes, when the search started from the empirical base and
the empirical fit of the fit runs shows amplification (:func:`rwadist.extended_fit.amplification_peaks`),
the extended model fitted to those runs (:func:`rwadist.extended_fit.fit_extended`, per unit mass and
inertia: the interface loads depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr and I_zz/I_rr).  Applied, it
switches the state to the extended base (every line through the fitted modes); the search judges it on
the held-out runs like any effect and carries on from it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..engine import Context
from ..state import State
from .base import register, schema_entry

#: Smallest mean log power gain (ln of measured / C·Ω² line power) a fixture resonance must show near one
#: frequency in EVERY load direction to be divided out before the modes are located: a power gain of 1.5.  A
#: wheel mode amplifies one direction's lines (translation the radial forces, rocking the radial torques,
#: axial the axial force); only a resonance of the stand lifts them all at one frequency.
STAND_MIN_LOG_GAIN = float(np.log(1.5))
#: Largest damping ratio of a proposed fixture resonance: a fixture resonance is sharp; a "resonance" as wide as
#: the fit allows (ζ → 0.5) is a broad tilt of the line gains (a wheel mode's skirt, model error), not a stand.
STAND_MAX_ZETA = 0.2
#: Rounds of (stand on the modes' base, modes with that stand divided out) at most.
STAND_ROUNDS = 4
#: Half width of the window (relative to the frequency) in which a direction's log gains are averaged.
STAND_WINDOW = 0.05


def _line_log_gains(fit, by_line: bool = False) -> dict:
    """direction (or (direction, h) when ``by_line``) -> (f Hz, y) of every measured line amplitude of an
    empirical fit: f = h|Ω|/2π and y = 2 ln(a / (C·Ω²)), the log power gain over the line's hard-mounted law."""
    out = {}
    for x in fit.lines:
        w = np.abs(np.asarray(x.speed, dtype=float))
        a = np.asarray(x.amplitude, dtype=float)
        ok = np.isfinite(a) & (a > 0) & (w > 0)
        if x.C <= 0 or not ok.any():
            continue
        f, y = out.setdefault((x.direction, float(x.h)) if by_line else x.direction, ([], []))
        f.append(x.h * w[ok] / (2 * np.pi))
        y.append(2.0 * np.log(a[ok] / (x.C * w[ok] ** 2)))
    return {d: (np.concatenate(f), np.concatenate(y)) for d, (f, y) in out.items()}


def _window_means(f, y, grid, min_points):
    """Mean of y over the points within ±STAND_WINDOW of each grid frequency; NaN where fewer than
    ``min_points``."""
    inside = np.abs(f[None, :] / grid[:, None] - 1.0) <= STAND_WINDOW
    cnt = inside.sum(1)
    return np.where(cnt >= min_points, (inside * y[None, :]).sum(1) / np.maximum(cnt, 1), np.nan)


def stand_resonance_start(fit, min_points: int = 2):
    """(f_r Hz, ζ, peak gain) of a fixture resonance seen in the empirical fit ``fit``, or None.

    The signature of a stand resonance is one frequency at which the lines of every load direction are
    amplified over their C·Ω² law (a wheel mode lifts one direction only).  Score of a frequency f: the
    smallest, over the directions with lines, of the mean log power gain of that direction's measurements
    within ±:data:`STAND_WINDOW` of f (at least ``min_points`` of them), and over every single line (direction,
    h) with ``min_points`` measurements there (a fixture lifts every harmonic at f alike); a stand resonance is proposed at
    the best score when it reaches :data:`STAND_MIN_LOG_GAIN` in two directions or more.  ζ and the peak
    gain: robust (soft-L1) least squares of ln|H|² (:func:`rwadist.resonance.resonance`) on every direction's
    log gains within ±25 % of f pooled, f_r free within ±10 %; refused when ζ > :data:`STAND_MAX_ZETA` (a broad
    tilt, not a resonance) or the peak gain is below 1 + :data:`STAND_MIN_LOG_GAIN`/2.  A stand detected so is
    refined by the same fit with a smooth trend a + b·ln f of each direction's own (a wheel mode's skirt beside
    the stand pulls the pooled fit: 185 Hz, ζ 0.06-0.09, gain 7-13 for a 180 or 150 Hz, ζ 0.03, gain 5 stand
    beside the radial translation mode), and refused again by the same rules.  A start only: the search refits
    it beside the modes.
    """
    from scipy.optimize import least_squares

    from ...resonance import resonance

    pts = {d: fy for d, fy in _line_log_gains(fit).items() if fy[0].size >= 2 * min_points}
    if len(pts) < 2:
        return None
    f_all = np.concatenate([fy[0] for fy in pts.values()])
    lo, hi = float(np.min(f_all)), float(np.max(f_all))
    if hi <= lo * (1 + 2 * STAND_WINDOW):
        return None
    grid = np.exp(np.arange(np.log(lo), np.log(hi), 0.005))                     # 0.5 % steps
    score = np.full(grid.size, np.inf)
    for f, y in pts.values():
        score = np.minimum(score, np.nan_to_num(_window_means(f, y, grid, min_points), nan=-np.inf))
    # a fixture amplifies every line at f, whatever its harmonic: a line (direction, h) with points near f
    # that is not lifted there rules f out (an amplitude law lifts one harmonic at the top speeds only)
    for (d, _h), (f, y) in _line_log_gains(fit, by_line=True).items():
        if d in pts:
            score = np.fmin(score, np.where(np.isnan(m := _window_means(f, y, grid, min_points)), np.inf, m))
    i = int(np.argmax(score))
    if not score[i] >= STAND_MIN_LOG_GAIN:
        return None
    f_s = float(grid[i])
    f, y, which = [], [], []
    for j, (fd, yd) in enumerate(pts.values()):
        near = np.abs(fd / f_s - 1.0) <= 0.25
        f.append(fd[near])
        y.append(yd[near])
        which.append(np.full(int(near.sum()), j))
    f, y, which = np.concatenate(f), np.concatenate(y), np.concatenate(which)
    n_dir = len(pts)
    lf = np.log(f / f_s)
    lb3, ub3 = np.log([0.9 * f_s, 1e-3, 1.1]), np.log([1.1 * f_s, 0.5, 200.0])
    g0 = float(np.clip(np.exp(np.max(y) / 2.0), 1.2, 100.0))

    def pooled(x):
        return y - np.log(np.abs(resonance(f, np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2)

    # detection: one resonance on every direction's points pooled (cheap); refused as below, nothing more is tried
    det = min((least_squares(pooled, np.clip(np.log([f_s, z0, g0]), lb3 + 1e-9, ub3 - 1e-9), loss="soft_l1",
                             f_scale=0.5, bounds=(lb3, ub3)) for z0 in (0.01, 0.03, 0.1)), key=lambda sol: sol.cost)
    _, zeta_det, gain_det = (float(v) for v in np.exp(det.x))
    if zeta_det > STAND_MAX_ZETA or gain_det < 1.0 + STAND_MIN_LOG_GAIN / 2:
        return None

    def res(x):
        # the fixture's resonance, common to every direction, on a smooth trend of each direction's own (a + b·ln f:
        # the skirt of a wheel mode beside the stand -- the radial translation lifting the radial forces, the axial
        # mode below it lowering the axial force -- is one direction's, not the fixture's)
        trend = x[3 + 2 * which] + x[4 + 2 * which] * lf
        return y - trend - np.log(np.abs(resonance(f, np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2)

    rows = np.arange(f.size)

    def jac(x):
        # analytic: ln|H|² = ln(b² + g²q²) − ln(b² + q²), b = 1 − r², q = 2ζr, r = f/f_r, parameters in logs
        r = f / np.exp(x[0])
        b, q, g = 1.0 - r * r, 2.0 * np.exp(x[1]) * r, np.exp(x[2])
        A, B = b * b + (g * q) ** 2, b * b + q * q
        J = np.zeros((f.size, x.size))
        J[:, 0] = -((4 * b * r * r - 2 * (g * q) ** 2) / A - (4 * b * r * r - 2 * q * q) / B)
        J[:, 1] = -(2 * (g * q) ** 2 / A - 2 * q * q / B)
        J[:, 2] = -(2 * (g * q) ** 2 / A)
        J[rows, 3 + 2 * which] = -1.0
        J[rows, 4 + 2 * which] = -lf
        return J

    # refinement of a detected stand: the same resonance on each direction's own trend
    lb = np.concatenate([lb3, np.full(2 * n_dir, -np.inf)])
    ub = np.concatenate([ub3, np.full(2 * n_dir, np.inf)])
    best = None
    for z0 in (0.01, 0.03, 0.1):
        x0 = np.concatenate([np.clip(np.log([f_s, z0, g0]), lb[:3] + 1e-9, ub[:3] - 1e-9), np.zeros(2 * n_dir)])
        sol = least_squares(res, x0, jac=jac, loss="soft_l1", f_scale=0.5, bounds=(lb, ub))
        if best is None or sol.cost < best.cost:
            best = sol
    f_r, zeta, gain = (float(v) for v in np.exp(best.x[:3]))
    if zeta > STAND_MAX_ZETA or gain < 1.0 + STAND_MIN_LOG_GAIN / 2:
        return None
    return f_r, zeta, gain


def _fit_runs(ctx: Context, runs, state: State, stand_start: tuple | None = None):
    """(SteadyTest, EmpiricalFit, ExtendedFit, stand) of ``runs``, or None when the runs show no modal
    amplification (or the extended fit fails); ``stand`` is the fixture resonance (f_r Hz, ζ, peak gain)
    divided out of the lines, or None.  ``stand_start``: the stand to start from (a refit on every run
    starts from the one fitted on half of them), else the one :func:`stand_resonance_start` proposes.

    A fixture resonance on every channel is fitted beside the modes, never into them: when the empirical
    fit shows lines of every direction amplified at one frequency (:func:`stand_resonance_start`), that
    resonance is divided out of the measured lines before the modes are located (``stand`` of
    :func:`rwadist.extended_fit.fit_extended`; a fixture resonance taken for a mode spoils every mode).
    After the extended fit, a ``fixed_resonance`` common to all channels (role test_stand) is fitted on
    that base; when it is a resonance (:data:`MIN_PEAK_GAIN`), the extended fit is repeated with it divided
    out (up to :data:`STAND_ROUNDS` rounds, until the stand settles); when it is not while one was divided
    out, the stand was not confirmed and the fit is repeated without it.  The stand resonance itself is left
    to the search (a clear residual of the extended base: a ``fixed_resonance`` effect)."""
    from ...data import SteadyTest
    from ...empirical import fit_empirical
    from ...extended_fit import amplification_peaks, fit_extended
    from ...spectra import compute_spectra

    runs = [int(r) for r in runs]
    test = SteadyTest([ctx.test.runs[r] for r in runs], dict(ctx.test.meta))
    # the fit's own resolution (the longest segment, as ``rwadist fit``): close lines (h = 5.37, 5.57 of the
    # E wheel) that diagnose's shorter Welch segments cannot separate are resolved here
    sp = compute_spectra(test, window=ctx.sp.window, f_lim=ctx.sp.f_lim)
    fit = fit_empirical(sp)
    if not amplification_peaks(fit):
        return None
    stand = None if len(ctx.channels) <= 3 else (stand_start or stand_resonance_start(fit))
    try:
        efit = fit_extended(test, fit, stand=stand)
        if stand is not None and len(efit.unconstrained) == 3:
            # the fixture resonance divided out locates no mode at all (a start pulled by a wheel mode beside it:
            # its frequency, width and gain off): the modes are located without it, and the stand is fitted on
            # their base below, as when none was proposed
            efit_plain = fit_extended(test, fit)
            if len(efit_plain.unconstrained) < 3:
                efit, stand = efit_plain, None
        for _ in range(STAND_ROUNDS):
            if len(efit.unconstrained) == 3 or len(ctx.channels) <= 3:
                break
            from ..effects.fixed_resonance import MIN_PEAK_GAIN, FixedResonance

            # the stand on the modes' base: the lines are predicted without it, so this is the whole stand
            st = SuspensionModes.from_fit(efit, fit, len(runs)).apply(state)
            new = FixedResonance.fit(ctx, st, ctx.channels, np.asarray(runs), None if stand is None else stand[0],
                                     role="test_stand")
            if new is None or abs(np.log(new.peak_gain)) < np.log(MIN_PEAK_GAIN):
                if stand is not None:           # the stand divided out is not confirmed: the fit without it
                    efit = fit_extended(test, fit)
                    stand = None
                break
            new = (new.f_r, new.zeta, new.peak_gain)
            settled = (stand is not None and abs(new[0] / stand[0] - 1) < 0.002
                       and abs(np.log(new[2] / stand[2])) < 0.02)
            stand = new
            efit = fit_extended(test, fit, stand=stand)
            if settled:
                break
    except ValueError:
        return None
    if len(efit.unconstrained) == 3:
        return None                     # no mode located: nothing to name
    return test, fit, efit, stand


@register(order=100)
@dataclass
class SuspensionModes:
    """The rotor's suspension modes fitted per unit mass (M = 1 kg) and transverse inertia (I_rr = 1 kg·m²).

    model : the extended model (:func:`rwadist.extended_fit.to_model`: harmonics = forcing lines, with the
        ``analytical`` section).  f0_Hz : mode frequencies at rest, Hz ("radial_translation", "rocking",
        "axial"); zeta : damping ratios; inertia_ratio : I_zz/I_rr; unconstrained : modes the data do not
        locate (starting values, as in ``analytical.unconstrained``); n_runs : runs fitted; stand : the fixture
        resonance (f_r Hz, ζ, peak gain) divided out of the lines for the fit, or None (the search names it
        as a ``fixed_resonance`` of its own; not part of this effect's parameters).
    """

    model: object = field(repr=False)
    f0_Hz: dict
    zeta: dict
    inertia_ratio: float
    unconstrained: tuple
    n_runs: int
    stand: tuple | None = None
    kind: str = "suspension_modes"
    #: the search takes a passing suspension_modes before any other effect: the wheel's own modes first
    first = True

    @property
    def channels(self) -> tuple:
        return ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")

    @staticmethod
    def from_fit(efit, fit, n_runs: int, stand: tuple | None = None) -> "SuspensionModes":
        from ...extended_fit import to_model

        p = efit.params
        f0 = {"radial_translation": float(p.omega_r / (2 * np.pi)), "rocking": float(p.omega_rock / (2 * np.pi)),
              "axial": float(np.sqrt(p.k_z / p.mass) / (2 * np.pi))}
        zeta = {"radial_translation": float(p.zeta_r), "rocking": float(p.zeta_rock), "axial": float(p.zeta_z)}
        return SuspensionModes(to_model(efit, fit), f0, zeta, float(p.inertia_ratio), tuple(efit.unconstrained),
                               n_runs, stand)

    def apply(self, state: State) -> State:
        import copy

        from ...extended import params_from_model

        s = state.copy()
        s.model = copy.deepcopy(self.model)
        s.model.effects = list(state.model.effects)
        s.ext = params_from_model(s.model, "suspension_modes")
        s.laws = {}
        s._cache = {}
        s.effects.append(self)
        return s

    def refit(self, ctx: Context, state: State) -> "SuspensionModes":
        """Refitted on every run (``ctx.runs``), starting from this fit's stand resonance; itself when that fit
        fails."""
        return SuspensionModes.fit(ctx, state, ctx.runs, self.stand) or self

    def whirl_Hz(self, omega_rad_s: float) -> dict:
        """Whirl frequencies (Hz) at wheel speed ``omega_rad_s``: translation, rocking forward/backward, axial."""
        half = 0.5 * self.inertia_ratio * abs(omega_rad_s) / (2 * np.pi)
        root = np.sqrt(half**2 + self.f0_Hz["rocking"] ** 2)
        return {"radial_translation": self.f0_Hz["radial_translation"], "rocking_forward": float(root + half),
                "rocking_backward": float(root - half), "axial": self.f0_Hz["axial"]}

    def params(self) -> dict:
        return {"radial_translation_Hz": self.f0_Hz["radial_translation"], "rocking_Hz": self.f0_Hz["rocking"],
                "axial_Hz": self.f0_Hz["axial"], "zeta_radial_translation": self.zeta["radial_translation"],
                "zeta_rocking": self.zeta["rocking"], "zeta_axial": self.zeta["axial"],
                "inertia_ratio": self.inertia_ratio, "unconstrained": list(self.unconstrained) or None,
                "per_unit": True, "n_runs": self.n_runs,
                "whirl": "rocking forward/backward f = sqrt((a·f_spin/2)^2 + rocking_Hz^2) ± a·f_spin/2, "
                         "a = inertia_ratio; the model's analytical section holds the fitted parameters"}

    def to_schema(self) -> dict:
        return schema_entry(self)

    @staticmethod
    def fit(ctx: Context, state: State, runs, stand_start: tuple | None = None) -> "SuspensionModes | None":
        """The modes fitted on ``runs`` (per unit mass and inertia), or None when those runs show no modal
        amplification or no mode can be located; ``stand_start``: see :func:`_fit_runs`."""
        got = _fit_runs(ctx, runs, state, stand_start)
        return None if got is None else SuspensionModes.from_fit(got[2], got[1], len(runs), got[3])

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """The extended fit of ``runs`` when the search may change its base (``ctx.base_switch``), the state
        is on the empirical base, the time series are known and the runs show modal amplification."""
        if state.ext is not None or ctx.test is None or not getattr(ctx, "base_switch", False):
            return []
        if any(e.kind == "suspension_modes" for e in state.effects):
            return []
        e = SuspensionModes.fit(ctx, state, runs)
        return [] if e is None else [e]
