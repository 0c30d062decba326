"""A fixture (test-stand) resonance on every channel, told from the wheel's own suspension modes.

A resonance of the stand lifts the lines of EVERY load direction at one frequency; a wheel mode lifts one
direction (translation the radial forces, rocking the radial torques, axial the axial force).  Taken for a
mode, a stand resonance near one spoils the modes' fit (the radial translation pulled to the stand and
declared unconstrained, the other modes' damping widened).  This module takes the starts proposed from an
empirical fit (:mod:`rwadist.stand_detect`) and fits the extended model with it, the stand's parameters in the modes' least squares
(:func:`fit_extended_beside_stand`, what ``rwadist fit --extended`` and ``rwadist diagnose``'s ``suspension_modes``
run).  The stand's gain is the general single-mode form of :mod:`rwadist.resonance`: a fixture resonance need not
return to 1 above its frequency (the force through a fixture spring falls as 2ζ/r there).
"""
from __future__ import annotations

import numpy as np

from .extended_fit_lsq import joint_cost, noise_weighted_cost
from .resonance import resonance
from .stand_detect import (
    STAND_MIN_LOG_GAIN,
    STAND_WINDOW,
    further_stand_starts,
    is_fixture_resonance,
    local_lift,
    stand_starts,
)

#: Largest relative move of a located mode between the fit beside the modes' own stand and the fit beside every
#: fixture resonance the search named (``rwadist diagnose``'s suspension modes): half the 2 % a mode must be found to.
STAND_SETTLED_MODE = 0.01


def _mode_hz(params) -> dict:
    """Mode frequencies at rest (Hz) of :class:`~rwadist.extended.ExtendedParams`, by the fit's unconstrained names."""
    return {"radial_translation": float(np.sqrt(params.k_r / params.mass) / (2 * np.pi)),
            "rocking": float(np.sqrt(params.k_rock / params.I_rr) / (2 * np.pi)),
            "axial": float(np.sqrt(params.k_z / params.mass) / (2 * np.pi))}


#: Passes of the joint fit from one start at most: each locates the modes (their scans) with the last pass's stand
#: divided out, then fits modes and stand together
JOINT_PASSES = 4
#: The passes have settled when one moves ln f_r by less than this and ln ζ by less than ten times as much
JOINT_SETTLED_LOG_F = 2e-4


def _joint_from(test, fit, start, kwargs, settled_at: list | None = None):
    """The extended fit with the stand fitted jointly with the modes, from the stand ``start``: the modes located
    again with each pass's stand divided out until the stand settles (:data:`JOINT_PASSES` at most); ``kwargs``
    passed on to :func:`rwadist.extended_fit.fit_extended` in every pass.  ``settled_at``: [(stand, fit)] of the joint
    fits of the same data, fit and ``kwargs`` that settled (appended to): a pass that reaches one of those stands ends
    with that fit, as the passes from there would (family wheel 0 with a 20/15/150 mm load-cell offset: four starts
    at 309.8-310.2 Hz, ζ 0.019-0.021, gain 21-82, all at 319.14 Hz, ζ 0.049 after their passes)."""
    from .extended_fit import fit_extended

    stand, settled = tuple(start), False
    for _ in range(JOINT_PASSES):
        # every mode the scans locate stays in the passes' least squares (a mode declared loose there leaves the stand
        # alone to explain its lines, and the stand runs off: ζ to its bound, gain 450); declared in the last fit only
        efit = fit_extended(test, fit, stand=stand, fit_stand=True, declare=False, **kwargs)
        assert efit.stand is not None, "fit_extended with fit_stand=True returns the stand it fitted"
        settled, stand = _one_stand(efit.stand, stand), efit.stand
        reached = next((f for s, f in settled_at or () if _one_stand(stand, s)), None)
        if reached is not None:
            return reached
        if settled:
            break
    out = fit_extended(test, fit, stand=stand, fit_stand=True, **kwargs)
    if settled and settled_at is not None:
        settled_at.append((stand, out))
    return out


def _one_stand(a: tuple, b: tuple) -> bool:
    """True when two passes' stands differ by less than the passes settle to (:data:`JOINT_SETTLED_LOG_F`)."""
    return bool(abs(np.log(a[0] / b[0])) < JOINT_SETTLED_LOG_F and abs(np.log(a[1] / b[1])) < 10 * JOINT_SETTLED_LOG_F)


def _joint_once(memo: dict | None, test, fit, start, kwargs):
    """:func:`_joint_from` of ``test``, ``fit``, ``start``, ``kwargs``, made once per ``memo`` (None: every time): a
    fresh copy of the kept fit each time (its readers add notes and declare modes on it)."""
    if memo is None:
        return _joint_from(test, fit, start, kwargs)
    key = (tuple(float(v) for v in start), repr(sorted(kwargs.items())))
    if key not in memo:
        memo[key] = _joint_from(test, fit, start, kwargs, memo.setdefault(("settled", key[1]), []))
    return memo[key].fresh_copy()


#: A stand fitted with the modes is kept when it lowers the fit's cost beyond the Bayesian information criterion of
#: its parameters: n·ln(SSR_without / SSR_with) > STAND_PARAMETERS·ln n
STAND_PARAMETERS = 4


def stand_confirmed(joint, plain, stand: tuple | None = None) -> bool:
    """True when the joint fit's stand (``joint``: modes and stand, ``plain``: the modes alone, of one empirical fit) is
    a fixture resonance (:func:`is_fixture_resonance`), explains the lines beyond its parameters' worth (the
    Bayesian information criterion on the log residuals, :data:`STAND_PARAMETERS`) and lifts every direction
    (:func:`lifts_every_direction`).  ``stand``: the stand of ``joint`` judged (default its ``stand``; a second
    fixture: ``plain`` is then the fit beside the others alone)."""
    stand = joint.stand if stand is None else stand
    if stand is None or not is_fixture_resonance(stand[1], stand[2]):
        return False
    n = int(np.sum(np.isfinite(joint.line_residuals[1])))
    c1, c0 = joint_cost(joint), joint_cost(plain)
    return bool(n > STAND_PARAMETERS and c1 > 0 and n * np.log(c0 / c1) > STAND_PARAMETERS * np.log(n)
                and lifts_every_direction(joint, plain, stand))


#: A stand that makes a load direction worse is kept only when the directions it makes better gain this many times
#: what the worse ones lose (:func:`lifts_every_direction`)
STAND_OUTWEIGH = 4.0


def lifts_every_direction(joint, plain, stand: tuple | None = None) -> bool:
    """True when the joint fit's stand explains the lines of two load directions or more and costs the others little:
    over the measurements where its power gain reaches :data:`STAND_MIN_LOG_GAIN` (a factor 1.5, the detection's own
    threshold), a direction is better (worse) when its squared log residuals fall below (rise above) those of the fit
    without a stand by more than its number of such measurements times the joint fit's mean squared residual (its own
    scatter); two directions or more must be lifted and none worse, or, when some are worse, two or more must be
    better and the worse ones lose less than 1/:data:`STAND_OUTWEIGH` of what the better ones gain.

    A fixture resonance lifts every line near it on every channel; a resonance of one direction beside a wheel mode
    of another passed the overall criterion on what it explained there alone (family wheel 2, a resonance moving from
    76 to 107 Hz with speed on the axial force beside the 90 Hz translation: a "stand" at 79-88 Hz lowered the axial
    residuals from 12.2 to 6.1 and raised the radial forces' from 0.005 to 6.0 and the torques' from 0.002 to 2.4,
    and put the rocking mode 3.1 % off): one direction better is no stand.  Not "each direction better": a fit without
    the stand can pull a mode onto it and explain that direction as well (the E wheel with a 180 Hz stand and a
    load-cell offset: the translation at 184.5 Hz, the radial forces' residuals 0.017 against the joint fit's 0.035 over
    15 measurements).  Nor "no direction worse": a stand of finite mass couples with the wheel's mode of a direction
    near it into two resonances the wheel's model divided by one stand cannot hold, while the others move little (ROSS's
    4.2-kg wheel on two 40-kg masses at 230 Hz, tests/data/ross_new_wheel_fixture230.json: the axial 310 Hz and the
    stand's 230 Hz become 210 and 339 Hz; the stand fitted with the modes lowered the radial forces' residuals from 41.6
    to 0.58 and the torques' from 20.2 to 0.36, raised the axial force's from 1.5 to 7.3, and put the radial modes
    within 0.4 % of ROSS's; refused, the modes were lost and two amplitude laws invented in their place)."""
    f1, r1, d1 = (np.asarray(v) for v in joint.line_residuals)
    _, r0, d0 = (np.asarray(v) for v in plain.line_residuals)
    if r1.shape != r0.shape or not np.array_equal(d1, d0):
        return True                     # not the same rows: the overall criterion decides alone
    ok = np.isfinite(r1) & np.isfinite(r0)
    scatter = float(np.mean(r1[ok] ** 2)) if ok.any() else 0.0
    lifted = ok & (np.log(np.abs(resonance(f1, *(joint.stand if stand is None else stand))) ** 2) >= STAND_MIN_LOG_GAIN)
    change, allowance = {}, {}
    for d in np.unique(d1[lifted]):
        rows = lifted & (d1 == d)
        change[d] = float(np.sum(r1[rows] ** 2) - np.sum(r0[rows] ** 2))
        allowance[d] = float(np.sum(rows)) * scatter
    gained = -sum(c for d, c in change.items() if c < -allowance[d])
    lost = sum(c for d, c in change.items() if c > allowance[d])
    better = sum(c < -allowance[d] for d, c in change.items())
    if lost == 0:
        return len(change) >= 2         # none worse: two lifted directions suffice
    return better >= 2 and lost * STAND_OUTWEIGH < gained


#: Relative distance in frequency under which two fixture resonances are one stand (the stand an earlier fit's modes
#: were located beside and a start of this one's, :func:`same_stand`)
SAME_STAND = 0.02


def same_stand(a: tuple | None, b: tuple | None) -> bool:
    """True when the stands ``a`` and ``b`` ((f_r Hz, ...) or None: no stand) are one hypothesis: both None, or both
    given within :data:`SAME_STAND` of each other in frequency."""
    if a is None or b is None:
        return a is None and b is None
    return bool(abs(a[0] / b[0] - 1.0) <= SAME_STAND)


def _four(start) -> tuple:
    """A stand's start as (f_r Hz, ζ, peak gain, gain above): a three-value start returns to 1 far above."""
    return tuple(start) + (() if len(start) == 4 else (1.0,))


def fit_extended_beside_stand(test, fit, stand_start: tuple | None = None, starts: list | None = None,
                              near: dict | None = None, near_stand: tuple | None = None, joints: dict | None = None,
                              further_starts=None, **kwargs):
    """:func:`rwadist.extended_fit.fit_extended` of ``test`` (empirical fit ``fit``; ``kwargs`` passed on) with a
    fixture resonance fitted jointly with the wheel's modes, never into them.

    From each start (``starts``; else ``stand_start``; else :func:`stand_starts` of ``fit``, only with all six
    channels: a stand is told from a mode by lifting the forces AND the torques), the modes are located with the stand
    divided out and fitted with it in one least squares (:class:`rwadist.resonance.FittedResonance`), again until the stand settles
    (:func:`_joint_from`); of the fits :func:`stand_confirmed` over the fit without a stand, the one of least cost is
    kept; none: that one is returned.  The modes' standard errors are then those with the stand free: a mode the data do not
    tell apart from the stand is declared by the fit's own rule (1.5 of them within 2 %).  The stand kept is in
    ``ExtendedFit.stand`` (f_r Hz, ζ, peak gain, gain above) and a note; it is not part of the wheel's model
    (``rwadist diagnose`` names it as a ``fixed_resonance`` of role test_stand).

    ``near`` (``near`` of :func:`rwadist.extended_fit.fit_extended`: where an earlier fit of the same wheel located the
    modes, its scans searching there first) was located beside the stand ``near_stand`` (None: without one).  It is
    given only to the fits beside that same stand (:func:`same_stand`): the fit without a stand when ``near_stand`` is
    None, a joint fit from a start within :data:`SAME_STAND` of it.  Divided out or not, a stand changes where the
    lines put the modes, and a scan started near the modes of the other hypothesis can settle inside that window on a
    point of its own (family wheel 7, a stand at 195 Hz on its 130 Hz rocking mode: the fit runs saw no stand and put
    the rocking at 265 Hz, I_zz/I_rr 2.8; every run's joint fit scanned from there stayed at 247 Hz, 2.8, and the
    rocking was declared; scanned over its whole range, 129.7 Hz, 2.10).

    ``joints``: a dict kept by the caller for this ``test`` and ``fit`` (the same data and empirical fit), holding the
    joint fit from each start already made with the same arguments: asked again (the stands of every run, then the
    refit of the modes on every run, from the same starts), the same fit is not made twice.

    ``further_starts``: a callable returning the starts of a stand at another frequency
    (:func:`rwadist.stand_detect.further_stand_starts`), fitted only when no start of ``starts`` is confirmed; None:
    those of ``fit`` when the starts are its own (``starts`` and ``stand_start`` None), else none."""
    from .extended_fit import fit_extended

    def near_beside(stand):
        return {} if near is None or not same_stand(stand, near_stand) else {"near": near}

    if starts is None:
        channels = {c for r in test.runs for c in r.signals}
        starts = [stand_start] if stand_start is not None else (stand_starts(fit) if len(channels) >= 6 else [])
        if further_starts is None and stand_start is None and len(channels) >= 6:
            further_starts = lambda: further_stand_starts(fit)  # noqa: E731 (asked only when no start is confirmed)
    plain = fit_extended(test, fit, **kwargs, **near_beside(None))
    if not starts:
        return plain
    def confirmed_from(starts_):
        return [j for j in (_joint_once(joints, test, fit, _four(s), {**kwargs, **near_beside(_four(s))})
                            for s in starts_) if stand_confirmed(j, plain)]

    # of the joint fits whose stand is confirmed, the least cost (as a structure mode's: those confirmed, then the
    # best): a start whose fit runs off to no fixture resonance (ζ at its 0.3 bound, a broad tilt of the line gains)
    # can cost less than the stand another start found, and must not hide it.  Family wheel 2's fixture pair (seed
    # 201): from the second start (64.6 Hz, ζ 0.040, gain 7.3) the passes ended at 83.6 Hz ζ 0.30 gain 2.29, cost
    # 10.06, below the 70.07 Hz ζ 0.042 gain 4.05 of the first (10.45), and no stand was kept; which of the two that
    # start reaches turns on the smallest change of the rows (the 300-rpm radial imbalance row scaled by 0.9-1.1:
    # 70.1 Hz at 0.9, 0.95, 1.05, 1.1; 83-87 Hz, ζ 0.3 at 0.8, 1.0, 1.25)
    confirmed = confirmed_from(starts)
    if not confirmed and further_starts is not None:
        # the lines lift at another frequency too: a second fixture, beside which the modes may be located first
        confirmed = confirmed_from(further_starts())
    if not confirmed:
        return plain
    joint = min(confirmed, key=joint_cost)
    joint = beside_more_stands(test, fit, joint, kwargs)
    for i, (f_r, zeta, gain, above) in enumerate((joint.stand,) + joint.more_stands):
        where = "analytical.fit.test_stand" if i == 0 else f"analytical.fit.more_test_stands[{i - 1}]"
        joint.notes.append(f"test stand: a resonance at {f_r:.4g} Hz (ζ {zeta:.3g}, peak gain {gain:.3g}, "
                           f"{above:.3g} of the load far above it) lifts the lines of every channel: a fixture "
                           f"resonance, fitted with the modes and not part of the wheel's model ({where})")
    return joint


#: Fixture resonances fitted with the modes at most (:func:`beside_more_stands`)
MAX_STANDS = 3
#: Starts of a further stand tried at most (:func:`stand_starts`' first ones)
MORE_STAND_STARTS = 1


def beside_more_stands(test, fit, joint, kwargs):
    """The joint fit ``joint`` (the modes beside one confirmed stand or more: its ``stand`` and ``more_stands``) with
    each further fixture resonance the lines show beside them fitted too, up to :data:`MAX_STANDS` in all.

    A stand is fitted with the modes one at a time (:func:`_joint_from`), the others divided out and held.  Two
    fixtures on every channel on either side of the translation mode (0.8x and 1.3x its 160 Hz: trial20, 128 and
    208 Hz, ζ 0.03, peak 5): the fit beside the 128 Hz stand alone left the 208 Hz one in the lines, every mode
    unconstrained (cost 24.2), and the search stayed on the empirical base, inventing an amplitude law and a moving
    resonance; beside both, the modes within 0.4 %, cost 1.5.  The further stand's starts are those of the
    lines' gains with the known stands divided out (:func:`stand_starts`' ``known``), the first of them tried
    (:data:`MORE_STAND_STARTS`); fitted with the known ones held, then each known one fitted again with the others
    held (each was fitted while the new one was still in the lines), twice round: of these fits the least cost is
    kept when the new stand is confirmed over the fit without it (:func:`stand_confirmed`: a fixture resonance, worth
    its parameters, lifting every direction).  Trial20 seed 22, every run: the rounds' costs 1.33, 0.53, 0.30, 0.23,
    the stands 127.86 Hz (ζ 0.0298, gain 4.97) and 208.22 Hz (ζ 0.0263, gain 5.11), the modes within 0.1 %.  Then
    every stand is fitted again at once with the modes (:func:`fit_every_stand`)."""
    for _ in range(MAX_STANDS - 1 - len(joint.more_stands)):
        known = (joint.stand,) + tuple(joint.more_stands)
        starts = stand_starts(fit, known=known)[:MORE_STAND_STARTS]
        if not starts:
            break
        got = min((_with_new_stand(test, fit, known, s, kwargs) for s in starts), key=lambda g: joint_cost(g[0]))
        if not stand_confirmed(got[0], joint, got[1]):
            break
        joint = got[0]
    # each found while the others were held: all of them fitted again at once with the modes
    return fit_every_stand(test, fit, joint, kwargs)


def fit_every_stand(test, fit, joint, kwargs: dict):
    """The extended fit of ``test`` (empirical fit ``fit``) with every stand of ``joint`` (its ``stand`` and
    ``more_stands``, found one at a time: :func:`beside_more_stands`) fitted free at once with
    the modes (:class:`rwadist.stand_every.FittedStands`), the modes located again beside each pass's stands until they settle
    (:data:`JOINT_PASSES` at most; the scans searching first where ``joint`` located them),
    or ``joint`` itself when it has one stand or its noise-weighted cost (:func:`noise_weighted_cost`) is not above
    this fit's.  ``kwargs`` passed on to :func:`rwadist.extended_fit.fit_extended`."""
    from .extended_fit import fit_extended

    if joint.stand is None or not joint.more_stands:
        return joint
    stands = (tuple(joint.stand),) + tuple(tuple(k) for k in joint.more_stands)
    extra = {**kwargs, "near": _near_of(joint), "fit_stand": True, "fit_more_stands": True}
    for _ in range(JOINT_PASSES):
        # every located mode kept in the passes' least squares (as :func:`rwadist.stand_resonance._joint_from`)
        efit = fit_extended(test, fit, stand=stands[0], more_stands=stands[1:], declare=False, **extra)
        new = (efit.stand,) + tuple(efit.more_stands)
        settled = all(abs(np.log(a[0] / b[0])) < JOINT_SETTLED_LOG_F and
                      abs(np.log(a[1] / b[1])) < 10 * JOINT_SETTLED_LOG_F for a, b in zip(new, stands))
        stands = new
        if settled:
            break
    every = fit_extended(test, fit, stand=stands[0], more_stands=stands[1:], **extra)
    # each row weighed by its own scatter: a line at the noise floor must not choose between the stands
    return every if noise_weighted_cost(every) < noise_weighted_cost(joint) else joint


def _with_new_stand(test, fit, known: tuple, start: tuple, kwargs) -> tuple:
    """(the fit of least cost, its new stand) of the modes beside the stands ``known`` and a new one from ``start``:
    each stand fitted in turn with the others held (the new one, then each known one, twice round), the scans of each
    fit after the first searching first where the best fit so far located the modes (``near``).  A stand fitted free
    beside a mode whose whirl passes it can leave that mode declared (trial20 seed 21: the 208 Hz stand free, the
    rocking's forward whirl reaching 190 Hz at the top speed: rocking unconstrained, cost 11.0; the 128 Hz stand free
    beside it held: every mode within 0.4 %, cost 1.5): the fit of least cost is kept, not the last."""
    stands = [tuple(start) + (() if len(start) == 4 else (1.0,))] + [tuple(k) for k in known]
    fits: list = []
    for i in 2 * list(range(len(stands))):
        held = tuple(k for j, k in enumerate(stands) if j != i)
        extra: dict = {"more_stands": held}
        if fits:
            best = min(fits, key=lambda g: joint_cost(g[0]))[0]
            extra["near"] = _near_of(best)
        efit = _joint_from(test, fit, stands[i], {**kwargs, **extra})
        stands[i] = efit.stand
        fits.append((efit, stands[0]))
    return min(fits, key=lambda g: joint_cost(g[0]))


def _near_of(efit) -> dict:
    """``near`` of :func:`rwadist.extended_fit.fit_extended`: the modes ``efit`` located (its scans search there
    first), the rocking mode's I_zz/I_rr with it."""
    from .extended_fit import MODE_KEY

    hz = _mode_hz(efit.params)
    out = {MODE_KEY[m]: {"near_hz": f} for m, f in hz.items() if m not in efit.unconstrained}
    if "rocking" in out:
        out["rocking"]["near_a"] = float(efit.params.inertia_ratio)
    return out


# --------------------------------------------------------------------------- a mode of the wheel's structure
#: The load direction each of the extended fit's modes shows (its ``unconstrained`` names)
MODE_DIRECTION = {"radial_translation": "radial_force", "rocking": "radial_torque", "axial": "axial_force"}
#: Parameters of a structure mode fitted with the modes (f_r, ζ, γ and β, the gain far above it:
#: :data:`rwadist.resonance.PATH_MODE_MAX_ABOVE`), for the information criterion
STRUCTURE_PARAMETERS = 4
#: Lifts of one direction's residuals tried as a structure mode's start, at most (the strongest first)
STRUCTURE_STARTS = 2
#: The directions a structure mode is looked for on when the fit without it locates every mode: the forces.  The
#: torques read r × F of the forces too (a load-cell offset, ``cross_coupling``; ``lever_arm_noise``): the forces' lines
#: amplified by their translation stand out of the torques' model there as a resonance of the torques alone would
#: (family wheels 0 and 1 with an offset: a 'structure mode' on the torques at 310.3 / 516.6 Hz, their translations at
#: 310.0 / 520.0 Hz), and only a mode it pins tells them apart; the forces carry no torque.
LOCATED_STRUCTURE_DIRECTIONS = ("axial_force", "radial_force")


def structure_mode_starts(efit, direction: str) -> list:
    """Starts (f_r Hz, ζ, peak gain) of a resonance of ``direction``'s lines alone, from the extended fit ``efit``'s log
    residuals there (:attr:`ExtendedFit.line_residuals`): the frequencies where their local lift over their
    neighbourhood (:func:`local_lift` of the log power residuals) is greatest and at least
    :data:`STAND_MIN_LOG_GAIN`, :data:`STRUCTURE_STARTS` at most, 10 % apart; ζ 0.03 and the lift's gain.

    A wheel's suspension mode is one resonance per direction; a second one on the same lines (a mode of the housing
    or of the rotor's own structure) is what the extended model lacks, and its lines stand above the model there."""
    f, r, d = (np.asarray(v) for v in efit.line_residuals)
    ok = (d == direction) & np.isfinite(r) & (f > 0)
    f, y = f[ok], 2.0 * r[ok]
    if f.size < 8 or f.max() <= f.min() * (1 + 2 * STAND_WINDOW):
        return []
    grid = np.exp(np.arange(np.log(f.min()), np.log(f.max()), 0.005))
    lift = local_lift(f, y, grid, 2)
    out: list[tuple] = []
    for i in np.argsort(-np.where(np.isfinite(lift), lift, -np.inf)):
        if not lift[i] >= STAND_MIN_LOG_GAIN or len(out) == STRUCTURE_STARTS:
            break
        if all(abs(grid[i] / s[0] - 1) > 0.1 for s in out):
            out.append((float(grid[i]), 0.03, float(np.clip(np.exp(lift[i] / 2), 1.25, 50.0))))
    return out


def structure_confirmed(joint, plain) -> bool:
    """True when the joint fit's structure mode (``joint``, its ``stand`` on one direction) beside the modes is a
    resonance (:func:`is_fixture_resonance`: a measured width and a lift), explains the lines beyond its parameters'
    worth (the Bayesian information criterion on the log residuals, :data:`STRUCTURE_PARAMETERS`) and pins more of the
    wheel's modes than the fit without it (``plain``): what the model lacked is found, the mode it pulled is located.
    When ``plain`` located every mode, a structure mode on a force direction
    (:data:`LOCATED_STRUCTURE_DIRECTIONS`) that leaves every mode located passes on the first two rules."""
    if joint.stand is None or not is_fixture_resonance(joint.stand[1], joint.stand[2]):
        return False
    n = int(np.sum(np.isfinite(joint.line_residuals[1])))
    c1, c0 = joint_cost(joint), joint_cost(plain)
    pins = len(joint.unconstrained) < len(plain.unconstrained) or (
        not plain.unconstrained and not joint.unconstrained and joint.stand_direction in LOCATED_STRUCTURE_DIRECTIONS)
    return bool(n > STRUCTURE_PARAMETERS and c1 > 0 and n * np.log(c0 / c1) > STRUCTURE_PARAMETERS * np.log(n)
                and pins and lifts_two_lines(joint, plain))


def lifts_two_lines(joint, plain) -> bool:
    """True when the structure mode of ``joint`` explains two lines or more (distinct h) better than ``plain`` where it
    lifts them by :data:`STAND_MIN_LOG_GAIN` (squared log residuals lower by over their rows × the joint fit's mean), or
    the fits' rows differ.  One line's run-to-run scatter is no resonance (family wheel 3's cage line and a line 0.003
    beside it beat within one record bin: a 'wheel mode' at 12.2 Hz, ζ 0.033, gain 1.6 was named on that line alone)."""
    f1, r1, d1 = (np.asarray(v) for v in joint.line_residuals)
    _, r0, d0 = (np.asarray(v) for v in plain.line_residuals)
    h = np.asarray(getattr(joint, "line_h", np.empty(0)), dtype=float)
    if r1.shape != r0.shape or h.shape != r1.shape or not np.array_equal(d1, d0):
        return True
    ok = np.isfinite(r1) & np.isfinite(r0)
    scatter = float(np.mean(r1[ok] ** 2)) if ok.any() else 0.0
    lifted = ok & (np.log(np.abs(resonance(f1, *joint.stand)) ** 2) >= STAND_MIN_LOG_GAIN)
    return sum(np.sum(r1[m] ** 2 - r0[m] ** 2) < -np.sum(m) * scatter for m in (lifted & (h == x) for x in np.unique(
        h[lifted]))) >= 2


def structure_mode_refused(test, fit, direction: str, stand: tuple) -> tuple:
    """(evidence, f_r Hz) of ``test`` (empirical fit ``fit``) against a mode of the wheel's structure on ``direction``
    at ``stand`` (f_r Hz, ζ, peak gain[, gain above]): the structure mode fitted again from it, jointly with the suspension modes,
    and its Bayesian information criterion over the fit with ``stand`` held, n·ln(SSR_held / SSR_free) −
    :data:`STRUCTURE_PARAMETERS`·ln n (> 0: these data want a resonance of their own), and the frequency they want.
    Raises ValueError when an extended fit fails."""
    from .extended_fit import fit_extended

    start = tuple(stand[:4]) + (() if len(stand) >= 4 else (1.0,))
    held = fit_extended(test, fit, stand=start, stand_direction=direction)
    free = _joint_from(test, fit, start, {"stand_direction": direction})
    n = int(np.sum(np.isfinite(free.line_residuals[1])))
    c0, c1 = joint_cost(held), joint_cost(free)
    if free.stand is None or n <= STRUCTURE_PARAMETERS or c1 <= 0 or c0 <= 0:
        return -np.inf, float(stand[0])
    return float(n * np.log(c0 / c1) - STRUCTURE_PARAMETERS * np.log(n)), float(free.stand[0])


#: A structure mode is a fixed-frequency resonance: when the slower and the faster half of the runs each want a
#: resonance of their own (:func:`structure_mode_refused`), their two frequencies must lie
#: within its own relative half-width ζ, and within this at least, for it to stay one fixed resonance
STRUCTURE_SPEED_SPLIT_TOL = 0.03
#: ... each half holding this many runs at least (fewer: the split tells nothing, the mode is kept)
STRUCTURE_SPLIT_MIN_RUNS = 5


def fixed_across_speeds(test_and_fit, speeds, runs, joint) -> bool:
    """Whether the structure mode of ``joint`` (its ``stand`` on ``stand_direction``) stays at one frequency across
    the speeds.  On the slower and on the faster half of ``runs``, the structure mode is fitted again from it (jointly
    with the suspension modes) and set against the fit holding it
    (:func:`structure_mode_refused`: the Bayesian information criterion of its four
    parameters); it moves with the speed when BOTH halves want a resonance of their own and their two frequencies are
    more than the resonance's relative half-width ζ (or :data:`STRUCTURE_SPEED_SPLIT_TOL`) apart.  A mode whose
    frequency falls or rises with speed (a rotor mode softening, a drive resonance following the speed) also lifts
    the lines of one direction, and one fixed resonance fitted to it sits between its ends (family wheel 0, a radial
    resonance softening 248 -> 149 Hz over the speeds: a 'wheel mode' at 198 Hz; the halves want 202 and 188 Hz, each
    beyond its criterion by 75 and 194): it is no wheel mode, and the open world describes it (``moving_resonance``).
    A fixed one fitted on half its speeds may run off (family wheel 5: 538 Hz on the slower half for a 490-Hz mode)
    but that half does not want it (criterion -29).  Halves too short, or fits that fail, tell nothing: kept.
    ``test_and_fit(runs)``: (SteadyTest, EmpiricalFit) of those runs (positions); ``speeds``: every run's, rad/s
    (``rwadist diagnose``'s suspension modes)."""
    runs = np.asarray([int(r) for r in runs])
    half = runs.size // 2
    if half < STRUCTURE_SPLIT_MIN_RUNS:
        return True
    spin = np.abs(np.asarray(speeds, dtype=float)[runs])
    order = np.argsort(spin, kind="stable")
    got = []
    for part in (np.sort(runs[order[:half]]), np.sort(runs[order[-half:]])):
        try:
            test, fit = test_and_fit(part)
            got.append(structure_mode_refused(test, fit, joint.stand_direction, tuple(joint.stand[:4])))
        except ValueError:
            return True
    moved = abs(float(np.log(got[1][1] / got[0][1])))
    moving = got[0][0] > 0 and got[1][0] > 0 and moved > max(joint.stand[1], STRUCTURE_SPEED_SPLIT_TOL)
    return not moving


def fit_extended_beside_structure_mode(test, fit, plain, start: tuple | None = None, **kwargs):
    """The extended fit of ``test`` (empirical fit ``fit``) with a mode of the wheel's structure on one direction fitted
    jointly with the suspension modes (:func:`rwadist.extended_fit.fit_extended`'s ``stand_direction``), or None.

    Tried when ``plain`` (the fit without it, and without a stand) leaves a mode unconstrained: from each lift of that
    mode's direction's residuals (:func:`structure_mode_starts`), or from ``start`` ((direction, f_r Hz, ζ, peak gain):
    an earlier fit's); the fit of least cost kept when :func:`structure_confirmed`.  A fixed-frequency resonance on
    the radial forces alone beside the radial translation (family wheels: a housing mode between two modes) is not
    a second translation: the translation is the spring the rotor's force passes through (its transmissibility falls
    above it), the structure mode passes β = 1 − μ of it above its frequency (μ >= 0 its participation:
    :data:`rwadist.resonance.PATH_MODE_MAX_ABOVE`), and the wheel's modes are fitted beside it instead of being pulled
    onto it or declared.  Of the fits the lines do not tell apart, the one of least participation is kept
    (:func:`least_participation`)."""
    if start is not None:
        tries = [(start[0], tuple(start[1:]))]
    else:
        dirs = sorted({MODE_DIRECTION[m] for m in plain.unconstrained if m in MODE_DIRECTION}) \
            if plain.unconstrained else list(LOCATED_STRUCTURE_DIRECTIONS)
        tries = [(d, s) for d in dirs for s in structure_mode_starts(plain, d)]
    fits = []
    for d, s in tries:
        try:
            fits.append(_joint_from(test, fit, _four(s), {**kwargs, "stand_direction": d}))
        except ValueError:
            continue
    fits = [j for j in fits if structure_confirmed(j, plain)]
    if not fits:
        return None
    joint = least_participation(fits)
    f_r, zeta, gain, above = joint.stand
    joint.notes.append(f"structure mode: a resonance at {f_r:.4g} Hz (ζ {zeta:.3g}, peak gain {gain:.3g}, {above:.3g} "
                       f"of the load far above it) on the {joint.stand_direction} lines alone, fitted with the "
                       "suspension modes: a mode of the wheel's "
                       "structure the extended model lacks (analytical.fit.structure_mode; `rwadist diagnose` names it "
                       "a fixed_resonance of role wheel_mode)")
    return joint


def stand_of_structure(test, fit, plain, structure) -> tuple:
    """(extended fit, its stand) of ``test`` (empirical fit ``fit``, six channels) with the resonance ``structure``
    found on one direction (its ``stand``, :func:`fit_extended_beside_structure_mode`) fitted again from it as a
    fixture resonance on every channel jointly with the modes, when that is a stand (:func:`stand_confirmed` over
    ``plain``, the fit without either: it lifts every direction) and explains the lines at least as well as the
    structure mode with the same four parameters; else (``plain``, None).

    A fixture resonance lifts every line near it; the stand's detection (:func:`stand_starts`) reads that lift on the
    empirical fit's lines, and a sparse speed grid leaves too few lines near it: trial24's 2.4-kg wheel (16 speeds
    1000-10000 rpm, a fixture at 225 Hz, ζ 0.03, gain 5, between its 150-Hz rocking and 480-Hz translation) put one
    point of each line within ±6 % of it, the pooled fit had no measured width, no stand was proposed, and the modes'
    fit found it on the radial forces alone (225.1 Hz, ζ 0.029, gain 5.09: named a wheel mode, the stand's peak
    carried into the flight model, the axial force and the torques left 21-23 % off at 4000 rpm).  Fitted on every
    channel, the few lines near it may leave its width unresolved (ζ at the fit's floor, no fixture resonance by
    :func:`is_fixture_resonance`) where the one direction's resolved it: the stand is then held at that direction's
    resonance on every channel and judged so."""
    from .extended_fit import fit_extended

    start = tuple(structure.stand[:4])
    try:
        joint = _joint_from(test, fit, start, {})
        if joint.stand is None or not stand_confirmed(joint, plain):
            # every channel's few lines near it may not resolve its width (ζ run to the fit's floor, the peak to
            # 100 and more) where one direction's did: held at that direction's resonance on every channel
            joint = fit_extended(test, fit, stand=start)
    except ValueError:
        return plain, None
    if joint.stand is None or not stand_confirmed(joint, plain) or joint_cost(joint) > joint_cost(structure):
        return plain, None
    f_r, zeta, gain, above = joint.stand
    joint.notes.append(f"test stand: a resonance at {f_r:.4g} Hz (ζ {zeta:.3g}, peak gain {gain:.3g}, {above:.3g} of "
                       "the load far above it) lifts the lines of every channel: a fixture resonance, found on one "
                       "direction's lines and fitted with the modes on every channel; not part of the wheel's model "
                       "(analytical.fit.test_stand)")
    return joint, joint.stand


def least_participation(fits: list):
    """Of the joint fits ``fits`` (each with a structure mode on one direction, its ``stand`` (f_r Hz, ζ, peak gain,
    β)), the one of least cost, or of the fits whose cost is within one parameter's worth of it (n·ln of their cost
    ratio below ln n, the information criterion's price of one parameter: the lines do not tell them apart) the one
    whose structure mode has the least participation μ = 1 − β (:data:`rwadist.resonance.PATH_MODE_MAX_ABOVE`).

    The radial force lines pass the translation's transmissibility T(f) (the whole load drives it: μ = 1, no zero)
    and the structure mode H(f) (a zero at f_s/sqrt(β)): their product's magnitude has two resonances and one
    antiresonance f_a, which each assignment of the two resonances reproduces up to the numerators' damping terms
    (a few 0.1 % of power) -- the structure mode at the lower resonance f_1 with β = (f_1/f_a)², or at the upper f_2
    with β = (f_2/f_a)² (trial16's housing: 340 Hz, β 0.70, the translation 260 Hz; or 260 Hz, β 0.41, the
    'translation' 340 Hz; costs 0.05 % apart).  A structure mode is what the wheel's model lacks beside its
    suspension; the least of it that explains the lines is the one nearest its antiresonance, the lightest mode of
    the path (the suspension is the one the whole load passes)."""
    best = min(fits, key=joint_cost)
    n = int(np.sum(np.isfinite(best.line_residuals[1])))
    c0 = joint_cost(best)
    tied = [j for j in fits if n * np.log(joint_cost(j) / c0) < np.log(max(n, 2))]
    return min(tied, key=lambda j: (abs(1.0 - j.stand[3]), joint_cost(j)))


def modes_beside_moving(plain, joint):
    """The suspension modes ``joint`` located beside a resonance on one direction that moves with speed (its
    ``stand``, refused as a structure mode: no fixed resonance), without that resonance, or None when they pin no
    mode ``plain`` (the fit without it) left unconstrained, or leave unconstrained one ``plain`` located.

    The lines such a resonance lifts are no wheel mode's: fitted without it, the mode of that direction is pulled and
    widened by them, or declared unconstrained (family wheel 6, an axial resonance stiffening 117.5 -> 139 Hz over
    the speeds beside its 85-Hz axial mode: the axial mode 86.4 Hz, ζ 0.019 for 0.0126, unconstrained, and the lines
    it misfits held the residual the moving track's cells should).  A fixed resonance fitted over its track (there
    131 Hz, ζ 0.068: its envelope) takes those lines out of the modes' fit as it is
    refused (axial 85.02 Hz, ζ 0.014); the modes are that fit's and the resonance stays out of the wheel's model: it
    moves, and the open world describes it (``moving_resonance``, :mod:`rwadist.diagnose.describe_structure`)."""
    from dataclasses import replace

    if not set(joint.unconstrained) < set(plain.unconstrained):
        return None
    f_r, zeta, gain, *_ = joint.stand
    notes = [n for n in joint.notes if not n.startswith("structure mode:")]
    notes.append(f"modes located beside a resonance moving with speed on the {joint.stand_direction} lines (fitted as "
                 f"fixed over its track: {f_r:.4g} Hz, ζ {zeta:.3g}, peak gain {gain:.3g}), which is not the wheel's "
                 "model: `rwadist diagnose` describes it (moving_resonance)")
    return replace(joint, stand=None, stand_direction=None, notes=notes)
