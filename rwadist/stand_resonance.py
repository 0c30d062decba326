"""A fixture (test-stand) resonance on every channel, told from the wheel's own suspension modes.

A resonance of the stand lifts the lines of EVERY load direction at one frequency; a wheel mode lifts one
direction (translation the radial forces, rocking the radial torques, axial the axial force).  Taken for a
mode, a stand resonance near one spoils the modes' fit (the radial translation pulled to the stand and
declared unconstrained, the other modes' damping widened).  This module detects one from an empirical fit
(:func:`stand_resonance_start`), refines it on the residual of an extended fit that divided it out
(:func:`stand_on_modes`), and fits the extended model beside it (:func:`fit_extended_beside_stand`, what
``rwadist fit --extended`` runs); ``rwadist diagnose``'s ``suspension_modes`` uses the same detection.
"""
from __future__ import annotations

import numpy as np

#: Smallest mean log power gain (ln of measured / C·Ω² line power) a fixture resonance must show near one
#: frequency in EVERY load direction to be divided out before the modes are located: a power gain of 1.5.  A
#: wheel mode amplifies one direction's lines (translation the radial forces, rocking the radial torques,
#: axial the axial force); only a resonance of the stand lifts them all at one frequency.
STAND_MIN_LOG_GAIN = float(np.log(1.5))
#: Largest damping ratio of a proposed fixture resonance: a fixture resonance is sharp; a "resonance" as wide as
#: the fit allows (ζ → 0.5) is a broad tilt of the line gains (a wheel mode's skirt, model error), not a stand.
STAND_MAX_ZETA = 0.2
#: Smallest damping ratio of a fixture resonance: the fits' lower bound is 0.001 (:func:`_log_bounds_and_gain_start`,
#: :class:`rwadist.effects.fixed_resonance_diagnose.FixedResonance`); a fit that ends there measured no width -- a
#: "resonance" narrower than the lines resolve, one line's misfit at one speed lifted by a gain of 20-40.
STAND_MIN_ZETA = 0.0015
#: Rounds of (stand on the modes' base, modes with that stand divided out) at most.
STAND_ROUNDS = 4
#: Rounds of (stand on the modes' residual, modes with that stand divided out) at most in the reference fit
#: (:func:`fit_extended_beside_stand`, ``rwadist fit --extended``).  The two are coupled (a stand a little too weak or
#: too sharp is made up by the radial translation's mode moving towards it), so this alternation converges
#: geometrically, each round removing only ~1/3 of what is left: 4 rounds left the 180 Hz, ζ 0.03, gain 5 stand of
#: the robustness matrix 2 % weak and the translation 0.6 % low (1-3 % misfit of the lines above the stand).
REFERENCE_STAND_ROUNDS = 25
#: The reference fit's stand has settled when a round moves ln f_r by less than this ...
REFERENCE_SETTLED_LOG_F = 2e-4
#: ... and ln ζ and ln(peak gain) by less than this: with the alternation's ratio of ~2/3 per round the stand is then
#: within ~0.2 % of where the rounds converge, and the translation within ~0.1 %.
REFERENCE_SETTLED_LOG_SHAPE = 1e-3
#: Largest relative move of a located mode in the last round of the stand's refit (stand on the modes' residual,
#: modes with that stand divided out) for the mode to count as told apart from the stand: half the 2 % a mode must
#: be found to.  A mode still moving more is coupled to the stand beyond what its standard error (stand fixed) says.
STAND_SETTLED_MODE = 0.01
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


def _log_bounds_and_gain_start(f0: float, y: np.ndarray):
    """Bounds of ln(f_r, ζ, g) for a fixture resonance near ``f0`` (Hz: ±10 %, ζ 0.001-0.5, g 1.1-200) and the
    start gain from the largest log power gain in ``y``."""
    lb, ub = np.log([0.9 * f0, 1e-3, 1.1]), np.log([1.1 * f0, 0.5, 200.0])
    return lb, ub, float(np.clip(np.exp(np.max(y) / 2.0), 1.2, 100.0))


def is_fixture_resonance(zeta: float, peak_gain: float) -> bool:
    """True when a resonance of damping ratio ``zeta`` and peak gain ``peak_gain`` (|H| at f_r) can be a fixture's:
    at most :data:`STAND_MAX_ZETA` wide (broader is a tilt of the line gains: a wheel mode's skirt, an amplitude
    law's growth, model error), at least :data:`STAND_MIN_ZETA` (narrower is no measured width) and lifting the lines
    by at least 1 + :data:`STAND_MIN_LOG_GAIN`/2.  The one rule of
    the stand's detection (:func:`stand_resonance_start`), of its refit on the modes' residual
    (:func:`stand_on_modes`) and of ``rwadist diagnose``'s ``suspension_modes`` rounds."""
    return bool(STAND_MIN_ZETA <= zeta <= STAND_MAX_ZETA and peak_gain >= 1.0 + STAND_MIN_LOG_GAIN / 2)


def _one_resonance(f: np.ndarray, y: np.ndarray, f0: float):
    """(f_r Hz, ζ, g) of one resonance fitted to the log power gains ``y`` at ``f`` (Hz) near ``f0``: robust
    (soft-L1) least squares of ln|H|², parameters in logs, best of the starts ζ ∈ {0.01, 0.03, 0.1}; None when it
    is broader than STAND_MAX_ZETA or lifts less than half of STAND_MIN_LOG_GAIN."""
    from scipy.optimize import least_squares

    from .resonance import resonance

    lb, ub, g0 = _log_bounds_and_gain_start(f0, y)

    def res(x):
        return y - np.log(np.abs(resonance(f, np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2)

    best = min((least_squares(res, np.clip(np.log([f0, z0, g0]), lb + 1e-9, ub - 1e-9), loss="soft_l1",
                              f_scale=0.5, bounds=(lb, ub)) for z0 in (0.01, 0.03, 0.1)), key=lambda sol: sol.cost)
    f_r, zeta, gain = (float(v) for v in np.exp(best.x))
    return (f_r, zeta, gain) if is_fixture_resonance(zeta, gain) else None


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

    from .resonance import resonance

    pts = {d: fy for d, fy in _line_log_gains(fit).items() if fy[0].size >= 2 * min_points}
    if len(pts) < 2:
        return None
    f_all = np.concatenate([fy[0] for fy in pts.values()])
    lo, hi = float(np.min(f_all)), float(np.max(f_all))
    if hi <= lo * (1 + 2 * STAND_WINDOW):
        return None
    grid = np.exp(np.arange(np.log(lo), np.log(hi), 0.005))                     # 0.5 % steps
    # the smallest over the directions with measurements near f, where two directions or more have them: a
    # direction with no line measured there (on a short record the empirical fit resolves fewer lines: 2048
    # samples kept no radial-force line within 5 % of a 180 Hz stand) neither lifts nor rules out f
    means = np.array([_window_means(f, y, grid, min_points) for f, y in pts.values()])
    seen = np.isfinite(means)
    score = np.where(seen.sum(0) >= 2, np.min(np.where(seen, means, np.inf), axis=0), -np.inf)
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
    lb3, ub3, g0 = _log_bounds_and_gain_start(f_s, y)
    # detection: one resonance on every direction's points pooled (cheap); refused as below, nothing more is tried
    if _one_resonance(f, y, f_s) is None:
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
    return (f_r, zeta, gain) if is_fixture_resonance(zeta, gain) else None


def stand_on_modes(efit, near_hz: float):
    """(f_r Hz, ζ, peak gain) of the fixture resonance left on the residual of the extended fit ``efit``, or None.

    The residual r = ln(measured / model amplitude) of every line measurement (:attr:`ExtendedFit.line_residuals`,
    the stand ``efit.stand`` divided out) plus ln|H| of that stand is what a resonance common to every channel
    must explain once the wheel's modes are modelled.  Fit as the detection of :func:`stand_resonance_start`
    (robust soft-L1 least squares of ln|H|² on the points within ±25 % of ``near_hz``, f_r free within ±10 %);
    refused by the same rules (ζ > :data:`STAND_MAX_ZETA`: a broad tilt of the modes' misfit; peak gain below
    1 + :data:`STAND_MIN_LOG_GAIN`/2)."""

    from .resonance import resonance

    f, r = (np.asarray(v, dtype=float) for v in efit.line_residuals)
    near = np.isfinite(r) & (f > 0) & (np.abs(f / near_hz - 1.0) <= 0.25)
    if near.sum() < 6:
        return None
    f = f[near]
    y = 2.0 * r[near]
    if efit.stand is not None:
        y = y + 2.0 * np.log(np.abs(resonance(f, *efit.stand)))
    return _one_resonance(f, y, near_hz)


def _mode_hz(params) -> dict:
    """Mode frequencies at rest (Hz) of :class:`~rwadist.extended.ExtendedParams`, by the fit's unconstrained names."""
    return {"radial_translation": float(np.sqrt(params.k_r / params.mass) / (2 * np.pi)),
            "rocking": float(np.sqrt(params.k_rock / params.I_rr) / (2 * np.pi)),
            "axial": float(np.sqrt(params.k_z / params.mass) / (2 * np.pi))}


def declare_unsettled_modes(before, after) -> list:
    """Declare in ``after`` (an :class:`~rwadist.extended_fit.ExtendedFit`, the last round of the stand's refit) the
    located modes that moved more than :data:`STAND_SETTLED_MODE` from ``before`` (the round before): the stand and
    the mode are not told apart by these data (a mode beside the stand creeps with each round while the stand has
    settled), so the mode's frequency is not known to the 2 % its standard error claims.  Each is added to
    ``after.unconstrained`` (``analytical.unconstrained``: every consumer warns) with a note giving both values, its
    value kept as the last round's.  Returns the names declared."""
    from .extended_fit import declare_mode

    f0, f1 = _mode_hz(before.params), _mode_hz(after.params)
    out = []
    for m in ("radial_translation", "rocking", "axial"):
        if m in after.unconstrained or m in before.unconstrained or abs(f1[m] / f0[m] - 1) <= STAND_SETTLED_MODE:
            continue
        declare_mode(after, m, f"{m}: NOT CONSTRAINED beside the test stand: it moved from {f0[m]:.4g} to "
                     f"{f1[m]:.4g} Hz in the last round of the stand's refit (more than {100 * STAND_SETTLED_MODE:g} %): "
                     "the stand and this mode are not told apart by these data; listed in analytical.unconstrained")
        out.append(m)
    return out


#: Moves of a mode over the last rounds of the stand's refit whose ratios measure the rounds' rate (3 ratios) ...
COUPLED_MOVES = 4
#: ... when they agree to within this (a geometric drift: the alternation's own rate, not noise)
COUPLED_RATIO_SPREAD = 0.1
#: Standard errors a mode's frequency must be found to within the fit's tolerance (as
#: :func:`rwadist.extended_fit.fit_extended` decides "found": 1.5 standard errors)
FOUND_STDERR_FACTOR = 1.5


def _keeps_rate(moves: np.ndarray, max_ratio: float):
    """True where successive ``moves`` (along axis 0: a drift's steps, one column per quantity) keep one rate: every
    ratio of a move to the one before in (0, ``max_ratio``) -- so every move of one sign -- and the ratios within
    :data:`COUPLED_RATIO_SPREAD` of each other.  The geometric-drift rule of :func:`coupled_stderr` (a mode dragged
    by the stand) and of :func:`_aitken_step` (rounds converging to a limit)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = moves[1:] / moves[:-1]
        return np.all((ratios > 0) & (ratios < max_ratio), axis=0) & (np.ptp(ratios, axis=0) <= COUPLED_RATIO_SPREAD)


def coupled_stderr(modes: list, rel_stderr: dict, total: dict | None = None) -> dict:
    """Standard errors of the located modes' frequencies with the stand free, from the stand's refit rounds.

    The rounds alternate two least squares, the modes with the stand fixed and the stand with the modes fixed.  On a
    (locally) quadratic joint problem such block-coordinate rounds converge geometrically at the rate ρ = κ², κ the
    largest canonical correlation between the two blocks, and a parameter's marginal variance is at most 1/(1 − ρ)
    times its variance with the other block fixed (the Schur complement; equal for a parameter along the coupled
    direction).  A mode whose frequency drifts geometrically over the last :data:`COUPLED_MOVES` rounds (one sign,
    ratios in (0, 1) within :data:`COUPLED_RATIO_SPREAD` of each other), and by more than its standard error over all
    the rounds, is taken as dragged by the stand, and gets that bound.  The bound is conservative for a mode only weakly coupled:
    the stand of a reference fit that divided out one resonance where there were two (150 and 180 Hz, 2048 samples)
    dragged all three modes along at ρ 0.93, and all three are declared (the translation 18 % low, rocking and axial
    within 0.2 %).

    modes : list of dict
        :func:`_mode_hz` after each round (Hz by mode name), first to last.
    rel_stderr : dict
        :attr:`ExtendedFit.rel_stderr` of the last round (relative standard errors of k_r, k_rock, k_z, stand fixed).
    total : dict, optional
        mode name -> its whole drift over the rounds, ln(f_last / f_first), for the drift rule when ``modes`` are only
        the rounds before a jump to their limit (:func:`fit_extended_beside_stand`); default: ln(f_last / f_first)
        of ``modes``.

    Returns
    -------
    dict
        mode name -> (ρ, relative standard error of f with the stand fixed, its bound with the stand free) for the
        modes the stand dragged; the others are left out."""
    out = {}
    if len(modes) < COUPLED_MOVES + 1:
        return out
    for m, key in (("radial_translation", "k_r"), ("rocking", "k_rock"), ("axial", "k_z")):
        lf = np.log([h[m] for h in modes])
        d = np.diff(lf)[-COUPLED_MOVES:]
        if not _keeps_rate(d, 1.0):
            continue
        ratios = d[1:] / d[:-1]
        se_fixed = 0.5 * float(rel_stderr.get(key, np.nan))      # of f = sqrt(k/m)/2π: half of k's
        drift = lf[-1] - lf[0] if total is None else total[m]
        if not (np.isfinite(se_fixed) and abs(drift) > se_fixed):
            continue
        rho = float(np.mean(ratios))
        out[m] = (rho, se_fixed, se_fixed / float(np.sqrt(1.0 - rho)))
    return out


def declare_coupled_modes(efit, tolerance: float = 0.02) -> list:
    """Declare in ``efit`` the located modes the stand's refit rounds dragged along (``efit.coupled``,
    :func:`coupled_stderr`) whose frequency, the stand's uncertainty counted, is not shown to be known to
    ``tolerance``: :data:`FOUND_STDERR_FACTOR` of its standard-error bound with the stand free exceed it (the fit's
    own rule for "found", :func:`rwadist.extended_fit.fit_extended`).  Each is added to ``efit.unconstrained``
    (``analytical.unconstrained``: every consumer warns) with a note, its fitted value kept.  Returns the names
    declared.  Called on the fit a caller keeps (``rwadist fit --extended``, :func:`rwadist.api.fit_extended`; the
    ``suspension_modes`` of ``rwadist diagnose`` once it has decided which modes it located), not inside the rounds:
    a declared mode is still located.

    On a 2048-sample record through a 180 Hz stand with noisy force sensors (the robustness matrix, samples=2048+stand,
    lever_arm_noise): ρ 0.91, the radial translation ±0.9 % with the stand fixed and up to ±3.1 % with it free (one
    standard error), 221.3 Hz, 2.8 % low; nothing was said before."""
    from .extended_fit import declare_mode

    out = []
    k = FOUND_STDERR_FACTOR
    for m, (rho, se_fixed, se_free) in efit.coupled.items():
        if m in efit.unconstrained or k * se_free <= tolerance:
            continue
        declare_mode(efit, m, f"{m}: NOT CONSTRAINED beside the test stand: located at "
                     f"{_mode_hz(efit.params)[m]:.4g} Hz, to ±{100 * k * se_fixed:.1f} % ({k:g} standard errors) with "
                     f"the stand fixed but up to ±{100 * k * se_free:.1f} % with it free (the stand's refit rounds "
                     f"dragged it along at a ratio of {rho:.2f} a round): the stand and this mode are not told apart "
                     f"to {100 * tolerance:g} % by these data; listed in analytical.unconstrained")
        out.append(m)
    return out


def fit_extended_beside_stand(test, fit, stand_start: tuple | None = None, **kwargs):
    """:func:`rwadist.extended_fit.fit_extended` of ``test`` (empirical fit ``fit``; ``kwargs`` passed on) with a
    fixture resonance fitted beside the wheel's modes, never into them.

    When the empirical fit shows the lines of every load direction lifted at one frequency
    (:func:`stand_resonance_start`; only with all six channels: a stand is told from a mode by lifting the
    forces AND the torques), that resonance is divided out of every line before the modes are located, then
    refitted on the residual of the modes' fit (:func:`stand_on_modes`) and the modes refitted with it, until it
    settles (a round moves ln f_r less than :data:`REFERENCE_SETTLED_LOG_F`, ln ζ and ln g less than
    :data:`REFERENCE_SETTLED_LOG_SHAPE`) or :data:`REFERENCE_STAND_ROUNDS` rounds: the stand and the radial
    translation's mode are coupled, so a loosely settled stand leaves the mode pulled towards it.  Once the stand
    has moved :data:`COUPLED_MOVES` times at one rate the rounds jump to their limit (:func:`_aitken_step`, kept when
    :func:`_checked_limit` confirms it) and go on from there.  It is dropped (the plain fit
    returned) when the residual confirms no resonance there, or when the fit with it locates fewer modes than
    the fit without it.  The modes the rounds dragged along are recorded in ``ExtendedFit.coupled`` with their
    standard errors (:func:`coupled_stderr`), for the caller to declare (:func:`declare_coupled_modes`).  The stand
    kept is in ``ExtendedFit.stand`` and a note; it is not part of the wheel's model (``rwadist diagnose`` names it
    as a ``fixed_resonance`` of role test_stand).  ``stand_start``: the (f_r Hz, ζ, peak gain) to start the rounds
    from instead of :func:`stand_resonance_start`'s (the caller has
    checked that every channel is there)."""
    from .extended_fit import fit_extended

    channels = {c for r in test.runs for c in r.signals}
    stand = stand_start or (stand_resonance_start(fit) if len(channels) >= 6 else None)
    if stand is None:
        return fit_extended(test, fit, **kwargs)
    plain = fit_extended(test, fit, **kwargs)
    efit = fit_extended(test, fit, stand=stand, **kwargs)
    history = [stand]                             # the stand of each round, since the start or the last jump
    modes = [_mode_hz(efit.params)]               # the located modes after each round, likewise
    first = modes[0]
    drift = None                                  # the modes of the rounds before the first jump
    refusals, refused_at = 0, 0                   # limits refused by their check; the round of the last
    for k in range(REFERENCE_STAND_ROUNDS):
        new = stand_on_modes(efit, stand[0])
        if new is None:
            return plain                          # not confirmed on the modes' base: no stand
        step = np.abs(np.log(np.asarray(new) / np.asarray(stand)))
        settled = step[0] < REFERENCE_SETTLED_LOG_F and max(step[1], step[2]) < REFERENCE_SETTLED_LOG_SHAPE
        stand = new
        history.append(stand)
        efit = fit_extended(test, fit, stand=stand, **kwargs)
        modes.append(_mode_hz(efit.params))
        if settled:
            break
        # a limit is asked for while rounds are left (the last one's is _extrapolated_rounds'), at most twice in vain,
        # and not again before as many new rounds as it needs
        ask = k < REFERENCE_STAND_ROUNDS - 1 and refusals < 2 and len(history) > refused_at + COUPLED_MOVES
        aitken = _aitken_step(history, COUPLED_MOVES) if ask else None
        jump = None if aitken is None else _checked_limit(test, fit, aitken[0], history, kwargs)
        if aitken is not None and jump is None:
            refusals, refused_at = refusals + 1, len(history) - 1
        if jump is not None:
            # the rounds converge geometrically: on to their limit (the 25 rounds a ratio of 0.9 a round needs to
            # settle become about 10 fits), and the rounds go on from there; each mode's rate of drift is read from the
            # rounds before the jump (coupled_stderr)
            drift = modes if drift is None else drift
            efit, stand = jump, aitken[0]
            history, modes, refused_at = [stand], [_mode_hz(efit.params)], 0
    else:
        efit, stand = _extrapolated_rounds(test, fit, efit, history, kwargs)
    if len(efit.unconstrained) > len(plain.unconstrained):
        return plain
    last = _mode_hz(efit.params)
    efit.coupled = coupled_stderr(modes, efit.rel_stderr) if drift is None else \
        coupled_stderr(drift, efit.rel_stderr, total={m: float(np.log(last[m] / first[m])) for m in first})
    efit.notes.append(f"test stand: a resonance at {stand[0]:.4g} Hz (ζ {stand[1]:.3g}, peak gain {stand[2]:.3g}) "
                      "lifts the lines of every channel: a fixture resonance, divided out of the lines before the "
                      "modes were fitted and not part of the wheel's model (analytical.fit.test_stand)")
    return efit


#: Largest ratio of two successive rounds' moves of the stand for :func:`_extrapolated_rounds` to take the rounds as
#: converging geometrically (at 0.98 the limit lies 49 last moves away: not a measured convergence)
EXTRAPOLATE_MAX_RATIO = 0.98


def _extrapolated_rounds(test, fit, efit, history, kwargs):
    """(ExtendedFit, stand) after :data:`REFERENCE_STAND_ROUNDS` rounds that did not settle (``history``: the stands
    since the last jump to a limit, if any): the rounds' limit
    (:func:`_aitken_step` of the last three stands) when a fit with that stand divided out is closer to a fixed point
    of the rounds (:func:`_checked_limit`), else ``efit`` and the last stand.

    The stand and the radial translation are coupled: when the stand's start is well below its gain, each round
    removes only a small part of what is left (a ratio of ~0.9 per round on a 2048-sample record: after 25 rounds the
    gain 4.88 of 5, the translation 1.8 % low and still moving 0.1 % a round)."""
    stand = history[-1]
    step = _aitken_step(history)
    efit_limit = None if step is None else _checked_limit(test, fit, step[0], history, kwargs)
    if efit_limit is None:
        return efit, stand
    limit, ratio = step
    efit_limit.notes.append(f"test stand: the refit rounds had not settled after {REFERENCE_STAND_ROUNDS} (stand "
                            f"{stand[0]:.4g} Hz, ζ {stand[1]:.3g}, gain {stand[2]:.3g}, moving by a ratio up to "
                            f"{ratio:.2f} a round): their limit (Aitken Δ²) taken")
    return efit_limit, limit


def _aitken_step(history, geometric_moves: int = 2):
    """The limit of the stand's refit rounds by Aitken's Δ² of their last three stands, or None when the rounds do not
    converge geometrically.

    Each of ln f_r, ln ζ, ln g still moving in the last round (beyond the settle steps
    :data:`REFERENCE_SETTLED_LOG_F`, :data:`REFERENCE_SETTLED_LOG_SHAPE`) must move at a ratio in (0,
    :data:`EXTRAPOLATE_MAX_RATIO`) of the round before, and with ``geometric_moves`` > 2 so must each of its last
    ``geometric_moves`` moves, the ratios within :data:`COUPLED_RATIO_SPREAD` of each other: a rate the rounds keep,
    not noise (the test of :func:`coupled_stderr`).  A component not moving is kept at its last value.

    Parameters
    ----------
    history : list of tuple
        The stand (f_r Hz, ζ, peak gain) of each round, first to last.
    geometric_moves : int
        Moves the rate is read over (2: the last ratio only, the end-of-rounds use).

    Returns
    -------
    tuple or None
        ((f_r Hz, ζ, peak gain) of the limit, the largest of the moving components' last ratios), or None.
    """
    moves = max(geometric_moves, 2)
    if len(history) < moves + 1:
        return None
    x = np.log(np.asarray(history[-(moves + 1):], dtype=float))
    d = np.diff(x, axis=0)
    d1, d2 = d[-2], d[-1]
    moving = np.abs(d2) >= np.array([REFERENCE_SETTLED_LOG_F] + 2 * [REFERENCE_SETTLED_LOG_SHAPE])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(moving, d2 / d1, 0.0)
    if not moving.any() or np.any(moving & ~((ratio > 0) & (ratio < EXTRAPOLATE_MAX_RATIO))):
        return None
    if moves > 2 and np.any(moving & ~_keeps_rate(d, EXTRAPOLATE_MAX_RATIO)):
        return None
    return tuple(float(v) for v in np.exp(x[-1] + d2 * ratio / (1 - ratio))), float(np.max(ratio))


def _checked_limit(test, fit, limit, history, kwargs):
    """The extended fit of ``test`` (empirical fit ``fit``, ``kwargs`` passed on) with the stand ``limit`` (f_r Hz, ζ,
    peak gain; :func:`_aitken_step` of the rounds ``history``) divided out, or None when the stand that fit leaves on
    the residual (:func:`stand_on_modes`) is no closer to ``limit`` than the last round's stand was to the one before
    (in the largest of ln f_r, ln ζ, ln g): the limit is then no closer to a fixed point of the rounds."""
    from .extended_fit import fit_extended

    efit_limit = fit_extended(test, fit, stand=limit, **kwargs)
    check = stand_on_modes(efit_limit, limit[0])
    last = np.abs(np.log(np.asarray(history[-1], dtype=float) / np.asarray(history[-2], dtype=float)))
    if check is None or np.max(np.abs(np.log(np.asarray(check) / np.asarray(limit)))) >= np.max(last):
        return None
    return efit_limit
