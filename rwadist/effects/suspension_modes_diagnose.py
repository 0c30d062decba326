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
from functools import reduce

import numpy as np

# the fixture-resonance detection lives beside the extended fit (``rwadist fit --extended`` uses it too)
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.modes_base import wheel_base
from ..diagnose.modes_trend import beside_trend
from ..diagnose.stands import StandGroup
from ..diagnose.state import State
from ..diagnose.whole_fit import fit_of_runs, fit_spectra, whole_data_fit
from ..model import WheelModel
from ..stand_detect import further_stand_starts, stand_starts
from ..stand_resonance import SAME_STAND, fit_extended_beside_stand, fit_extended_beside_structure_mode
from .cross_coupling_diagnose import OFFSET_Z, CrossCoupling


def _recorded_meta(ctx: Context) -> dict:
    """The meta of the context's test with the far noisier sensor family of the load cell
    (:func:`rwadist.extended_fit_lsq.noisy_sensor_directions`) decided once, on every run as recorded (the whole
    data's lines at every speed, :func:`whole_data_fit`), under
    :data:`rwadist.extended_fit_lsq.NOISY_SENSORS_META`: every fit of the modes (on half of the runs, on every run, on
    the torques corrected for a load-cell offset) weighs the same family's measurements by their noise, or none.  On
    the corrected torques T − r × F the force sensors' noise reads in both families, and a decision taken again
    there is not the load cell's (:func:`rwadist.extended_fit_lsq.recorded_noisy_sensors`)."""
    from ..extended_fit_lsq import NOISY_SENSORS_META, noisy_sensor_directions

    key = ("suspension_modes.noisy_sensors",)
    if key not in ctx._memo:
        ctx._memo[key] = noisy_sensor_directions(whole_data_fit(ctx).without_mode_exclusion.lines)
    return dict(ctx.test.meta, **{NOISY_SENSORS_META: ctx._memo[key]})


def _fit_runs(ctx: Context, runs, state: State, stand_start: tuple | None = None, near: dict | None = None,
              structure_start: tuple | None = None, offset_start: CrossCoupling | None = None):
    """(SteadyTest, EmpiricalFit, ExtendedFit, stand, offset) of ``runs``, or None when the runs show no modal
    amplification (or the extended fit fails, or locates no mode); ``stand`` is the fixture resonance (f_r Hz, ζ,
    peak gain, gain above) fitted with the modes, or None; ``offset`` the load-cell offset (a ``cross_coupling``)
    the torques were corrected for before the modes were located (:func:`_beside_offset`), or None.
    ``stand_start``: the stand to start from (a refit on every run starts from the one fitted on half of them), else
    those :func:`rwadist.stand_detect.stand_starts` proposes. ``near``: the modes that fit located, searched
    first (``near`` of :func:`rwadist.extended_fit.fit_extended`), or None.  ``structure_start``: the mode of the
    wheel's structure to start from (direction, f_r Hz, ζ, peak gain: the fit on half the runs had it), or None.
    ``offset_start``: the load-cell offset the fit on half the runs located its modes beside (its ``offset``), or
    None: :func:`_beside_offset` starts from it when the offset estimated beside the modes located on the data as
    they are is not significant.

    A fixture resonance on every channel is fitted with the modes, never into them (:func:`_locate`); the stand
    itself is left to the search (a ``fixed_resonance`` of role test_stand proposed from this fit's stand).  A
    load-cell offset the located modes leave in the torques is taken out before the modes are located
    (:func:`_beside_offset`); then, when no stand is kept, a mode of the wheel's structure on one direction is tried
    beside the modes (on a direction whose mode stays unconstrained while another is located, or on the forces when
    every mode is located:
    :func:`rwadist.stand_resonance.fit_extended_beside_structure_mode`): the fit is then that joint fit (its
    ``stand`` on one direction, ``stand_direction``) and the stand None.  The offset first: the torques read r × F
    of the forces' lines amplified by their translation, which a resonance of the torques alone at that frequency
    also explains (family wheel 4, r_z = −60 mm: a 'structure mode' at 228.5 Hz on the torques, its 227.7 Hz
    translation, pinned the rocking 4.9 % off and the offset's correction was never tried)."""
    from ..data import SteadyTest
    from ..empirical import fit_empirical
    from ..extended_fit import amplification_peaks
    from ..stand_resonance import fixed_across_speeds, modes_beside_moving, stand_of_structure

    runs = [int(r) for r in runs]
    test = SteadyTest([ctx.test.runs[r] for r in runs], _recorded_meta(ctx))
    if runs == [int(r) for r in ctx.runs]:
        fit = whole_data_fit(ctx)      # the refit on every run: the same empirical fit, computed once
    else:
        sp, detections = fit_spectra(ctx, test, runs)
        fit = fit_empirical(sp, detections=detections)
    if not amplification_peaks(fit) and not amplification_peaks(whole_data_fit(ctx)):
        return None
    offset = None
    # what follows depends on the runs and the starts alone, except the offset (read beside ``state``): kept on the
    # context, the search's next step asks the same runs again with its new state and pays only for the offset
    key = ("suspension_modes.located", tuple(runs), stand_start, repr(sorted(near.items())) if near else None,
           structure_start)
    try:
        efit, stand = _memo(ctx, key, lambda: _locate(ctx, test, fit, stand_start, near))
        if len(ctx.channels) == 6:
            # a load-cell offset (T_measured = T + r × F) puts the forces' lines, amplified by the translation mode,
            # into the torques (where they also pass for a fixture resonance lifting every direction at that mode, or
            # for the rocking mode): the modes are located on the torques corrected for it when the data show one
            # (the offset itself is left to the search: a ``cross_coupling`` on the modes' base)
            got = _beside_offset(ctx, state, efit, fit, runs, test, stand_start, near, offset_start)
            if got is not None:
                test, fit, efit, stand, offset = got
        if efit.unconstrained and offset is None:
            # a gain common to every line that changes with speed bends the trend the modes are read from: taken out
            # when the located modes' lines show one and the modes are then located better
            # (:mod:`rwadist.diagnose.modes_trend`)
            trend = _memo(ctx, key + ("trend",), lambda: beside_trend(ctx, test, fit, efit, stand_start, near, _locate))
            if trend is not None:
                test, fit, efit, stand = trend
        if stand is None and len(ctx.channels) > 3 and not efit.locates_no_mode:
            # on an unconstrained mode's direction, or on the forces when every mode is located.  Not when no mode is
            # located: a resonance of one direction's structure hides that direction's mode, and the others' would
            # be located beside it (the ithaco-e data of Masterson's modal model, every mode unlocated: 14 of its 48 s
            # tried it on each direction for nothing)
            def beside_structure(efit=efit):
                structure = fit_extended_beside_structure_mode(test, fit, efit, start=structure_start)
                if structure is not None and not fixed_across_speeds(lambda part: fit_of_runs(ctx, part),
                                                                     ctx.test.speeds, runs, structure):
                    # a resonance moving with speed: the open world describes it, the modes it hid are located
                    # beside it (none: the modes as they were)
                    moved = modes_beside_moving(efit, structure)
                    return (efit if moved is None else moved), None
                if structure is not None and len(ctx.channels) == 6:
                    # found on one direction, it may lift every one: the stand's (too few lines crossed it to
                    # propose it)
                    efit_s, stand_s = stand_of_structure(test, fit, efit, structure)
                    return (efit_s, stand_s) if stand_s is not None else (structure, None)
                return (efit if structure is None else structure), None

            efit, stand = beside_structure() if offset is not None else _memo(ctx, key + ("structure",),
                                                                              beside_structure)
    except ValueError:
        return None
    if efit.locates_no_mode:
        return None                     # no mode located: nothing to name
    return test, fit, efit, stand, offset


def _memo(ctx: Context, key: tuple, compute):
    """``compute()`` kept on the context under ``key`` (its ValueError too): asked again, the same object (never
    changed by its readers: a fit's notes are added to the new fits made from it)."""
    if key not in ctx._memo:
        try:
            ctx._memo[key] = (compute(), None)
        except ValueError as exc:
            ctx._memo[key] = (None, exc)
    value, error = ctx._memo[key]
    if error is not None:
        raise error
    return value


def _locate(ctx: Context, test, fit, stand_start, near=None):
    """(ExtendedFit, stand) of ``test`` (empirical fit ``fit``): the modes fitted jointly with a fixture resonance
    (:func:`rwadist.stand_resonance.fit_extended_beside_stand`, from ``stand_start`` or the stands the fit -- else the
    whole data, :func:`whole_data_fit` -- proposes) when that is confirmed over the fit without one, else the modes
    alone (stand None).  Only with six channels: a stand is told from a mode by lifting the forces AND the torques.
    ``near`` (the modes of an earlier fit beside ``stand_start``, None: without a stand) guides only the fits beside
    that same stand (``near_stand`` of :func:`rwadist.stand_resonance.fit_extended_beside_stand`)."""
    from ..extended_fit import fit_extended

    if len(ctx.channels) <= 3:
        return _or_beside_moving(test, fit, fit_extended(test, fit, near=near), near), None
    axis = _beside_axis_stand(ctx, test, fit, near)
    if axis is not None:
        return axis, axis.stand
    # a fixture resonance the fit runs are too few to show (half of a short speed grid) but every run shows
    source = None if stand_start is not None else (fit if _stand_starts_once(ctx, fit) else whole_data_fit(ctx))
    starts = [stand_start] if source is None else _stand_starts_once(ctx, source)
    further = None if source is None else (lambda: _stand_starts_once(ctx, source, further=True))
    efit = fit_extended_beside_stand(test, fit, starts=starts, further_starts=further, near=near, near_stand=stand_start,
                                     joints=_joints_memo(ctx, test, fit))
    own = ((efit.stand,) if efit.stand is not None else ()) + tuple(efit.more_stands)
    if stand_start is None and (not own or stand_starts(whole_data_fit(ctx), known=own)):
        # every run may show a stand (or another one) these runs do not resolve; ``near`` came from a fit without a
        # stand (stand_start None): no guide to the modes beside one
        held = _beside_whole_data_stand(ctx, test, fit, efit)
        if held is not None:
            efit = held
    efit = _or_beside_moving(test, fit, efit, near)
    return efit, efit.stand


def _or_beside_moving(test, fit, efit, near):
    """``efit``, or when it locates no mode the modes located beside a resonance on every channel moving with speed
    that its lines hold (:func:`rwadist.diagnose.modes_moving.beside_moving`): fitted on its lines, every mode was
    pulled and declared, and no suspension_modes was proposed (the session-69 trial: a resonance at 150 + 0.9·f_spin Hz
    on every channel; the empirical base's mode exclusion then dropped the dynamic imbalance from the model).  A fixed
    resonance fitted with the modes over its track (a 'stand' that locates no mode either: its envelope) is left out:
    the track is read on the fit without one."""
    from ..diagnose.modes_moving import beside_moving
    from ..extended_fit import fit_extended

    if not efit.locates_no_mode:
        return efit
    plain = efit if efit.stand is None and not efit.more_stands else fit_extended(test, fit, near=near)
    moved = beside_moving(test, fit, plain, near)
    return efit if moved is None else moved


def _beside_axis_stand(ctx: Context, test, fit, near):
    """The extended fit of ``test`` (empirical fit ``fit``) beside a fixture resonance that lifts one channel of a
    radial pair (:func:`rwadist.stand_axes.axis_stand` of every run's empirical fit, else of ``fit``), held on its
    channels (:func:`rwadist.stand_axes.fit_beside`), or None.  A fixture on Fy and Tx searched on every channel lost
    the translation and the rocking (family wheels 1, 5 and 6, 0.8x the translation: every mode within 0.1 % beside
    it).  Read on every run first, as a stand on every channel the fit runs do not resolve
    (:func:`_beside_whole_data_stand`): its ratio estimate holds no wheel mode, and half of a speed grid crosses it
    sparsely (family wheel 4, 1.5x its translation, 12 of 24 speeds: 321.8 Hz for 341.5, and the stand judged there
    on the held-out runs failed; every run: 341.6 Hz)."""
    from ..stand_axes import axis_stand, fit_beside

    axis = _axis_stand_whole(ctx)
    if axis is None and fit is not whole_data_fit(ctx):
        key = ("suspension_modes.axis_stand", id(fit))
        if key not in ctx._memo or ctx._memo[key][0] is not fit:
            ctx._memo[key] = (fit, axis_stand(fit))
        axis = ctx._memo[key][1]
    return None if axis is None else fit_beside(test, fit, axis, near=near)


def _axis_stand_whole(ctx: Context):
    """:func:`rwadist.stand_axes.axis_stand` of every run's empirical fit, once per diagnosis."""
    from ..stand_axes import axis_stand

    key = ("suspension_modes.axis_stand_whole",)
    if key not in ctx._memo:
        ctx._memo[key] = axis_stand(whole_data_fit(ctx))
    return ctx._memo[key]


def _joints_memo(ctx: Context, test, fit) -> dict:
    """The joint fits of the modes and a stand made on ``test`` (empirical fit ``fit``), by start
    (:func:`rwadist.stand_resonance.fit_extended_beside_stand`'s ``joints``), kept for the diagnosis: the stands of
    every run (:func:`_whole_data_stands`) and the refit of the modes on every run start from the same stands of the
    same data and fit.  Kept with the fit and the runs they were made of, so a fit of other data is never served."""
    key = ("suspension_modes.joints", id(fit))
    runs = tuple(id(r) for r in test.runs)
    meta = repr(sorted(test.meta.items()))
    kept = ctx._memo.get(key)
    if kept is None or kept[0] is not fit or kept[1] != runs or kept[2] != meta:
        kept = ctx._memo[key] = (fit, runs, meta, test.runs, {})
    return kept[4]


def _stand_starts_once(ctx: Context, fit, further: bool = False) -> list:
    """:func:`rwadist.stand_detect.stand_starts` of the empirical fit ``fit`` (``further``:
    :func:`rwadist.stand_detect.further_stand_starts`), computed once per fit and diagnosis (the whole data's fit is
    asked by the fit on the fit runs, by the whole data's stand and by the refit on every run, which fits the same
    empirical fit)."""
    key = ("suspension_modes.stand_starts", id(fit), further)
    if key not in ctx._memo or ctx._memo[key][0] is not fit:
        ctx._memo[key] = (fit, (further_stand_starts if further else stand_starts)(fit))
    return list(ctx._memo[key][1])


def _beside_whole_data_stand(ctx: Context, test, fit, plain):
    """The extended fit of ``test`` (empirical fit ``fit``) with the fixture resonances fitted jointly with the modes
    on EVERY run (:func:`_whole_data_stands`) divided out at their parameters, held fixed, or None when every run
    shows no stand or the fit runs do not confirm them over ``plain`` (the fit runs' own fit, beside no stand or
    fewer: :func:`rwadist.stand_resonance.stand_confirmed` of a stand every run shows and ``plain`` has not).

    Half of a short speed grid may put no line within the stand's width: the lines near it then tell neither its
    width nor its frequency from a mode's on the same spot (family wheel 0, a fixture at its radial translation's
    310 Hz, 8 of 16 speeds: no line between 290 and 330 Hz; the joint fit ran to ζ 0.001, no fixture resonance,
    and the fit without a stand located no mode).  Every run shows it; held at what they show, the fit runs locate
    the modes (the search then judges them on the held-out runs, as any effect).  Two fixtures (trial20, 128 and
    208 Hz, seed 22): 10 of 20 speeds fitted the 128 Hz stand at 124.0 Hz, ζ 0.019 and ran the 208 Hz one to the
    damping's floor (ζ 0.001, gain 55: no measured width), no mode located; every run fits both within 0.1 %."""
    from ..extended_fit import fit_extended
    from ..stand_resonance import same_stand, stand_confirmed

    whole = _whole_data_stands(ctx)
    own = ((plain.stand,) if plain.stand is not None else ()) + tuple(plain.more_stands)
    if len(whole) <= len(own):
        return None
    held = fit_extended(test, fit, stand=whole[0], more_stands=whole[1:])
    new = next((w for w in whole if not any(same_stand(w, k) for k in own)), None)
    if new is None or not stand_confirmed(held, plain, new):
        return None
    for f_r, zeta, gain, above in whole:
        held.notes.append(f"test stand: a resonance at {f_r:.4g} Hz (ζ {zeta:.3g}, peak gain {gain:.3g}, {above:.3g} of "
                          "the load far above it) lifts the lines of every channel: a fixture resonance, fitted with the "
                          "modes on every run (these runs alone do not resolve it) and divided out here; not part of "
                          "the wheel's model (analytical.fit.test_stand)")
    return held


def _whole_data_stands(ctx: Context) -> tuple:
    """The fixture resonances ((f_r Hz, ζ, peak gain, gain above) each) fitted jointly with the modes on every run
    (:func:`rwadist.stand_resonance.fit_extended_beside_stand` of the whole data's empirical fit,
    :func:`whole_data_fit`: its ``stand`` and ``more_stands``) when that fit confirms any, else (); computed once per
    diagnosis."""
    from ..data import SteadyTest

    key = ("suspension_modes.whole_data_stand",)
    if key not in ctx._memo:
        ctx._memo[key] = ()
        whole_fit = whole_data_fit(ctx)
        starts = _stand_starts_once(ctx, whole_fit)
        if starts:
            test = SteadyTest([ctx.test.runs[int(r)] for r in ctx.runs], _recorded_meta(ctx))
            try:
                efit = fit_extended_beside_stand(test, whole_fit, starts=starts,
                                                 further_starts=lambda: _stand_starts_once(ctx, whole_fit, True),
                                                 joints=_joints_memo(ctx, test, whole_fit))
            except ValueError:
                efit = None
            if efit is not None and efit.stand is not None:
                ctx._memo[key] = tuple(tuple(float(v) for v in k) for k in (efit.stand,) + tuple(efit.more_stands))
    return ctx._memo[key]


#: rounds of :func:`_beside_offset`: the offset estimated beside the modes the last round located
OFFSET_ROUNDS = 3


def _beside_offset(ctx: Context, state: State, efit, fit, runs, test, stand_start, near=None, offset_start=None):
    """(test, fit, efit, stand, offset) of the modes located (:func:`_locate`) on the torques of ``test`` corrected for
    a load-cell offset r (``offset``, a :class:`CrossCoupling`; r in m: the ``cross_coupling`` fit of ``runs`` on ``state`` with the modes of ``efit``, the
    extended fit of ``test`` whose empirical fit is ``fit``: its torque lines, the wheel's own, weigh the equations
    at their frequencies down; T − r × F), or None when the offset is not significant
    (:meth:`CrossCoupling.significant`: no component of r stands 4 standard errors from 0) or the corrected data's
    modes are not better than those of ``efit``.

    Better: more modes located; or as many, and the corrected data's modes with the offset read as measured
    (T − r × F, as the search reads a ``cross_coupling``) explain ``runs`` better than ``efit``'s modes on the data as
    they are, by more than :data:`OFFSET_Z` noise standard errors of the drop in misplaced power (the search's own
    rule, :func:`rwadist.diagnose.search._evidence`).  A located mode may be a wrong one: the offset moves the
    forces' lines, amplified by the translation mode, into the torques, where the rocking fit takes them (family
    wheel 3, r_z = −60 mm, translation 230 Hz, rocking 70 Hz: every mode located, the rocking at 221 Hz on the
    uncorrected torques).

    The offset's estimate weighs each line by the torque the modes predict there, so modes pulled by the offset
    bias it: r is estimated again beside the modes the corrected data gave, up to :data:`OFFSET_ROUNDS` times, until
    a round is better, then while each round locates as many modes and explains the runs no worse than the last, until
    r moves by less than its standard errors: a later round is the same offset measured beside modes it no longer
    pulls (family wheel 2, r_z = −60 mm, the refit on every run: r_z −63.19 then −61.93 mm, the search's
    ``cross_coupling`` −61.92 ± 1.27; the second round, no better by 4 standard errors (t 0.6) nor worse, was dropped
    while a round had to be better, and the torque lines fitted beside −63.19 left the error 2.0x the clean cell's,
    now 1.1x; family wheel 6, r_z = −60 mm, rocking 110 Hz
    beside the 150 Hz translation: r_z −58.0 mm beside the rocking the offset pulled to 138 Hz left the rocking 2 %
    off and 3.5 dB misfit; the second round, beside 112 Hz, locates it; family wheel 3: r_z −54.4 mm beside the
    221 Hz rocking, the rocking found at 69.7 Hz, ζ 0.0248 for 0.0205).  A note of the fit says the offset was
    removed.

    ``offset_start`` (the offset the fit on half the runs located its modes beside, or None) is the first round's
    estimate when the offset estimated beside the modes located on the data as they are is not significant: that
    estimate weighs each line by the torque those modes predict there, and a rocking mode the offset pulled onto the
    translation mode predicts the torque of r × F at the strong force lines near it, which takes the weight off the
    equations that tell r (trial15's wheel, r_z 20 mm, translation 480 Hz, rocking 70 Hz; seed 7: on the fit runs
    17.8 ± 3.2 mm, corrected and every mode located, r_z 20.0 mm; on every run, beside the rocking put at 484.6 Hz,
    5.95 ± 6.39 mm, not significant, and the refit kept the rocking at 484.6 Hz, error 31x the clean cell's).  The
    refit on every run is the same effect measured on twice the runs (as its stand and modes start from the fit
    runs' own); the offset is then re-weighed on every run from it, and the modes it gives must still explain the
    runs better than those located without it."""
    n_located = 3 - len(efit.unconstrained)
    runs = np.asarray(runs, dtype=int)
    modes_fit, modes_efit = fit, efit
    best, best_state, previous = None, None, None
    for _ in range(OFFSET_ROUNDS):
        with_modes = _modes_state(ctx, state, modes_efit, modes_fit, runs.size)
        if best_state is None:
            best_state = with_modes                 # efit's modes on the data as they are
        cc = CrossCoupling.fit(ctx, with_modes, runs)
        if (cc is None or not cc.significant()) and previous is None and offset_start is not None:
            cc = offset_start               # the fit runs' offset (the refit on every run starts from it)
        if cc is None or not cc.significant():
            break
        # the offset taken out weighed by the wheel's own torque, not by the torque as measured (which holds r × F)
        cc = cc.own_weighted(ctx, with_modes, runs)
        test_c, fit_c, efit_c, stand_c = _located_corrected(ctx, test, np.asarray(cc.r, dtype=float), stand_start,
                                                            near)
        k = 3 - len(efit_c.unconstrained)
        if k == 0:
            break
        corrected = cc.apply(_modes_state(ctx, state, efit_c, fit_c, runs.size))
        got = (test_c, fit_c, efit_c, stand_c, cc)
        if k > n_located or (k == n_located and _better(ctx, best_state, corrected, runs)):
            best, best_state, n_located = got, corrected, k
        elif best is not None and k == n_located and not _better(ctx, corrected, best_state, runs):
            # the offset measured again beside modes its correction no longer pulls: the same hypothesis, closer to
            # its fixed point, kept unless it explains the runs worse
            best, best_state = got, corrected
        elif best is not None:
            break                           # the offset estimated again beside the kept modes is worse
        if previous is not None and np.all(np.abs(cc.r - previous.r) <= previous.r_stderr):
            break                           # the offset no longer moves beyond its standard errors
        previous = cc
        modes_fit, modes_efit = fit_c, efit_c
    return None if best is None else _noted(best)


def _modes_state(ctx: Context, state: State, efit, fit, n_runs: int) -> State:
    """``state`` on the modes of ``efit`` (empirical fit ``fit``, ``n_runs`` runs) with the stands they were located
    beside, as the search names them: :func:`_beside_offset`'s offset read beside the modes alone took a stand's lift
    of the torques, torque that state lacks, for r × F (docs/diagnose.md, trial21's fixture, no offset)."""
    modes = SuspensionModes.from_fit(efit, fit, n_runs, efit.stand if efit.stand_direction is None else None)
    return reduce(lambda s, e: e.apply(s), modes.stand_effects(ctx.channels), modes.apply(state))


def _located_corrected(ctx: Context, test, r: np.ndarray, stand_start, near) -> tuple:
    """(test, fit, efit, stand) of :func:`_locate` on ``test`` with the torques corrected for the load-cell offset
    ``r`` (m): T − r × F in every run."""
    from dataclasses import replace

    from ..data import SteadyTest
    from ..diagnose.constants import TORQUE_CHANNELS
    from ..empirical import fit_empirical
    from ..spectra import compute_spectra

    corrected = []
    for run in test.runs:
        F = np.column_stack([run.signals[k] for k in ("Fx", "Fy", "Fz")])
        T = np.cross(r[None, :], F)
        corrected.append(replace(run, signals={**run.signals, **{k: run.signals[k] - T[:, j]
                                                                 for j, k in enumerate(TORQUE_CHANNELS)
                                                                 if k in run.signals}}))
    test_c = SteadyTest(corrected, dict(test.meta))
    fit_c = fit_empirical(compute_spectra(test_c, window=ctx.sp.window, f_lim=ctx.sp.f_lim))
    efit_c, stand_c = _locate(ctx, test_c, fit_c, stand_start, near)
    return test_c, fit_c, efit_c, stand_c


def _better(ctx: Context, state: State, other: State, runs: np.ndarray) -> bool:
    """Whether ``other`` explains ``runs`` better than ``state``: its drop in misplaced power over every channel more
    than :data:`OFFSET_Z` of its noise standard errors (:func:`rwadist.diagnose.search._evidence`)."""
    from ..diagnose.search import _evidence

    gain, _, t, _ = _evidence(ctx, state, other, runs, [c for c in ctx.channels], None)
    return bool(gain > 0 and t > OFFSET_Z)


def _noted(got: tuple) -> tuple:
    """``got`` of :func:`_beside_offset`, its extended fit noting the offset removed."""
    got[2].notes.append("load-cell offset: r = (%s) mm removed from the torques (T − r × F) before the modes were "
                        "located; not part of the wheel's model (diagnose names it as cross_coupling)"
                        % ", ".join(f"{1000 * v:.1f}" for v in got[4].r))
    return got


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

    model: WheelModel = field(repr=False)
    f0_Hz: dict
    zeta: dict
    inertia_ratio: float
    unconstrained: tuple
    n_runs: int
    stand: tuple | None = None
    #: the speed-sideband pairs :func:`wheel_base` left out of the base, (direction, h0, h_lower, h_upper, C_lower,
    #: C_upper, number of measurements) each
    sideband_pairs: tuple = field(default=(), repr=False)
    kind: str = "suspension_modes"
    #: the stand of the fit on the fit runs this effect was refitted from (:meth:`refit`), or None: what a
    #: ``fixed_resonance`` proposed from the modes' stand is judged with on the held-out runs
    stand_fit_runs: tuple | None = field(default=None, repr=False)
    #: the search takes a passing suspension_modes before any other effect: the wheel's own modes first
    first = True
    #: the runs this fit is judged on when it was fitted on the held-out runs (:meth:`other_fold`), else None
    judge_runs: tuple | None = field(default=None, repr=False)
    #: a mode of the wheel's structure on one direction fitted with the modes and divided out of that direction's lines
    #: for the fit (direction, f_r Hz, ζ, peak gain), or None: named by the search as a ``fixed_resonance`` of role
    #: wheel_mode (:meth:`stand_effect`), not part of this effect's parameters
    structure: tuple | None = None
    #: the structure mode of the fit on the fit runs this effect was refitted from, or None (as ``stand_fit_runs``)
    structure_fit_runs: tuple | None = field(default=None, repr=False)
    #: the channels ``stand`` acts on when not every one (a fixture that sways along one axis,
    #: :func:`_beside_axis_stand`), or None
    stand_on: tuple | None = None
    #: further fixture resonances fitted with the modes beside ``stand`` (each (f_r Hz, ζ, peak gain, gain above):
    #: :func:`rwadist.stand_resonance.beside_more_stands`), named by the search as ``fixed_resonance`` effects too
    more_stands: tuple = ()
    #: the further stands of the fit on the fit runs this effect was refitted from (as ``stand_fit_runs``)
    more_stands_fit_runs: tuple = field(default=(), repr=False)
    #: the load-cell offset (a :class:`CrossCoupling`) the torques were corrected for before the modes were located,
    #: or None: what the modes are judged with when they do not pass alone (:meth:`offset_effect`); named by the search
    #: as a ``cross_coupling`` of its own, not part of this effect's parameters
    offset: CrossCoupling | None = field(default=None, repr=False, compare=False)
    #: per located mode ("radial_translation", "rocking", "axial") whose damping the data do not measure, the damping
    #: ratios (lo, hi) they allow: its ζ is held, not fitted (:mod:`rwadist.extended_fit_damping`), listed in the
    #: effect's ``unconstrained`` as zeta_<mode>
    zeta_bounds: dict = field(default_factory=dict)
    #: per located mode whose damping was profiled, the damping ratios (lo, hi) the data allow (a measured damping's
    #: interval; a held one's is its ``zeta_bounds``)
    zeta_interval: dict = field(default_factory=dict)

    @property
    def channels(self) -> tuple:
        return ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")

    @staticmethod
    def from_fit(efit, fit, n_runs: int, stand: tuple | None = None) -> "SuspensionModes":
        from ..extended_fit import to_model

        p = efit.params
        f0 = {"radial_translation": float(p.omega_r / (2 * np.pi)), "rocking": float(p.omega_rock / (2 * np.pi)),
              "axial": float(np.sqrt(p.k_z / p.mass) / (2 * np.pi))}
        zeta = {"radial_translation": float(p.zeta_r), "rocking": float(p.zeta_rock), "axial": float(p.zeta_z)}
        base, pairs = wheel_base(to_model(efit, fit))
        structure = None if efit.stand_direction is None or efit.stand is None else \
            (efit.stand_direction,) + tuple(float(v) for v in efit.stand[:4])
        def named(d):
            return {("axial" if m == "axial_translation" else m): tuple(float(v) for v in b) for m, b in d.items()}

        more = () if stand is None else tuple(tuple(float(v) for v in k) for k in efit.more_stands)
        bounds = named(efit.zeta_bounds)
        # a held damping is held inside its bounds (rwadist.extended_fit_damping.hold_unmeasured_damping), at a bound
        # when the start lies beyond it: read back from its damping coefficient it may pass that bound by a rounding
        # (family wheel 7, seed 701: 0.01418914241710545 for 0.014189142417105447)
        zeta = {m: min(max(z, bounds[m][0]), bounds[m][1]) if m in bounds else z for m, z in zeta.items()}
        return SuspensionModes(base, f0, zeta, float(p.inertia_ratio), tuple(efit.unconstrained), n_runs, stand,
                               stand_on=efit.stand_on if stand is not None else None, sideband_pairs=pairs,
                               structure=structure, zeta_bounds=bounds,
                               zeta_interval=named(efit.zeta_interval), more_stands=more)

    def apply(self, state: State) -> State:
        import copy

        from ..extended import params_from_model

        s = state.plus(self)
        s.model = copy.deepcopy(self.model)
        s.model.effects = list(state.model.effects)
        s.ext = params_from_model(s.model, "suspension_modes")
        return s

    def contribute(self, parts) -> None:
        parts.laws.clear()              # the laws fitted on the other base do not carry over

    def refit(self, ctx: Context, state: State) -> "SuspensionModes":
        """Refitted on every run (``ctx.runs``), starting from this fit's stand resonance and load-cell offset, each
        mode it located searched first near it (:meth:`near`); itself when that fit fails."""
        from dataclasses import replace

        return replace(SuspensionModes.fit(ctx, state, ctx.runs, self.stand, self.near(), self.structure,
                                           self.offset) or self,
                       stand_fit_runs=self.stand if self.judge_runs is None else None, judge_runs=None,
                       more_stands_fit_runs=self.more_stands if self.judge_runs is None else (),
                       structure_fit_runs=self.structure if self.judge_runs is None else None)

    def other_fold(self, ctx: Context, state: State) -> "SuspensionModes | None":
        """The modes fitted on the held-out runs, judged on the fit runs (``judge_runs``): the search's other fold
        when this fit did not pass (:func:`rwadist.diagnose.search._other_folds`), or None; one fit per state."""
        return _held_out_fold(ctx, state)

    def near(self) -> dict:
        """``near`` of :func:`rwadist.extended_fit.fit_extended`: the modes this fit located (not those left
        unconstrained), with the rocking mode's I_zz/I_rr.  The refit on every run is the same effect measured on
        twice the runs: its scans start where this one's ended (a scan of the rocking mode over its whole grid of
        f0, ζ and I_zz/I_rr is most of an extended fit's cost), and search the whole range when the best point
        lies on the window's edge."""
        from ..extended_fit import UNCONSTRAINED_NAME

        out = {mode: {"near_hz": self.f0_Hz[name]} for mode, name in UNCONSTRAINED_NAME.items()
               if name not in self.unconstrained}
        if "rocking" in out:
            out["rocking"]["near_a"] = self.inertia_ratio
        return out

    def stand_effect(self, channels):
        """The fixture resonance fitted jointly with these modes (``stand``) as the test-stand effect on ``channels``
        (a :class:`~rwadist.effects.fixed_resonance_diagnose.FixedResonance`) the search names after them, or None:
        what the modes are judged beside when they do not pass alone (:func:`rwadist.diagnose.search._judge_beside_stand`);
        without a stand, the mode of the wheel's structure fitted with them (``structure``) as a wheel-mode resonance."""
        from .fixed_resonance_diagnose import FixedResonance

        if self.stand is None and self.structure is not None:
            return FixedResonance.of_structure(self.structure_fit_runs or self.structure, channels, self.structure)
        if self.stand is None:
            return None
        one = FixedResonance.of_stand(self.stand, self._stand_channels(channels), self.stand)
        return one if not self.more_stands else StandGroup((one,) + tuple(
            FixedResonance.of_stand(k, channels, k) for k in self.more_stands))

    def stand_effects(self, channels) -> list:
        """Each fixture resonance fitted with these modes (``stand``, then ``more_stands``) as a test-stand
        ``fixed_resonance`` on ``channels``, as judged on the held-out runs (the fit runs' stand of that frequency when
        this is a refit, :func:`rwadist.stand_resonance.same_stand`), refitted as this fit has it."""
        from ..stand_resonance import same_stand
        from .fixed_resonance_diagnose import FixedResonance

        if self.stand is None:
            return []
        # matched by frequency: the refit on every run may hold the fit runs' stands in another order (family wheel 1's
        # fixtures at 422 and 651 Hz: 650 then 422 on the fit runs, 422 then 651 on every run, and the 650 Hz stand
        # was proposed twice)
        held = ([self.stand_fit_runs] if self.stand_fit_runs else []) + list(self.more_stands_fit_runs)
        first = next((h for h in held if same_stand(h, self.stand)), self.stand_fit_runs or self.stand)
        return [FixedResonance.of_stand(first, self._stand_channels(channels), self.stand)] + [
            FixedResonance.of_stand(next((h for h in held if same_stand(h, k)), k), channels, k)
            for k in self.more_stands]

    def _stand_channels(self, channels) -> tuple:
        """The channels of ``channels`` ``stand`` acts on (:attr:`stand_on`, else every one)."""
        return tuple(channels) if self.stand_on is None else tuple(c for c in channels if c in self.stand_on)

    def offset_effect(self) -> CrossCoupling | None:
        """The load-cell offset the modes were located beside (``offset``), or None: what the modes are judged with
        when they do not pass alone (:func:`rwadist.diagnose.search._judge_with_offset`).  The modes alone predict the
        torques at the bearing centre, while the data read T + r × F: r × F carries the forces' lines through the
        translation mode into the torques, where the empirical base fits every line freely (tests/standmodes_wheel's
        new wheel, r_z = 30 mm: the modes located beside the offset within 0.1 %, r_z 30.0 mm, rejected in every
        iteration, and a 'wheel mode' at 305 Hz and an amplitude law named instead)."""
        return self.offset

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
                "inertia_ratio": self.inertia_ratio,
                "unconstrained": list(self.unconstrained) + [f"zeta_{m}" for m in self.zeta_bounds] or None,
                "zeta_bounds": {m: list(b) for m, b in self.zeta_bounds.items()} or None,
                "zeta_interval": {m: list(b) for m, b in self.zeta_interval.items()} or None,
                "per_unit": True, "n_runs": self.n_runs,
                "whirl": "rocking forward/backward f = sqrt((a·f_spin/2)^2 + rocking_Hz^2) ± a·f_spin/2, "
                         "a = inertia_ratio; the model's analytical section holds the fitted parameters"}

    def to_schema(self) -> dict:
        return schema_entry(self)

    @staticmethod
    def fit(ctx: Context, state: State, runs, stand_start: tuple | None = None,
            near: dict | None = None, structure_start: tuple | None = None,
            offset_start: CrossCoupling | None = None) -> "SuspensionModes | None":
        """The modes fitted on ``runs`` (per unit mass and inertia), or None when those runs show no modal
        amplification or no mode can be located; ``stand_start``, ``near``, ``structure_start``, ``offset_start``:
        see :func:`_fit_runs`."""
        from dataclasses import replace

        got = _fit_runs(ctx, runs, state, stand_start, near, structure_start, offset_start)
        return None if got is None else replace(SuspensionModes.from_fit(got[2], got[1], len(runs), got[3]),
                                                offset=got[4])

    @staticmethod
    def finish(ctx: Context, state: State) -> State:
        """The search's last state with the modes the fixtures named after them could have pulled declared
        (:func:`declare_beside_fixtures`)."""
        return declare_beside_fixtures(ctx, state)

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """The extended fit of ``runs`` when the search may change its base (``ctx.base_switch``), the state
        is on the empirical base, the time series are known and the runs show modal amplification."""
        if state.ext is not None or ctx.test is None or not getattr(ctx, "base_switch", False):
            return []
        if any(e.kind == "suspension_modes" for e in state.effects):
            return []
        e = SuspensionModes.fit(ctx, state, runs)
        if e is None:
            # half of a short speed grid can miss a sharp mode's peak (its damping runs to the fit's floor and no mode
            # is located) while the other half holds it: the other fold, judged on these runs
            e = _held_out_fold(ctx, state)
        return [] if e is None or one_fixed_resonance(e) else [e]


#: The least I_zz/I_rr of a wheel's rotor (a disc is 2, a rim-weighted one up to ~2.2; 0.5 is a cylinder ~1.7x as
#: long as it is wide): below it the rocking whirl barely moves with the speed (:func:`one_fixed_resonance`)
MIN_WHEEL_INERTIA_RATIO = 0.5
#: ... and the located modes lie within this factor of one another
ONE_RESONANCE_SPREAD = 1.05


def one_fixed_resonance(e: SuspensionModes) -> bool:
    """Whether the suspension modes ``e`` are one fixed resonance on every channel, not a wheel's: two or more modes
    located within :data:`ONE_RESONANCE_SPREAD` of one frequency and a rotor whose whirl does not move with the speed
    (I_zz/I_rr below :data:`MIN_WHEEL_INERTIA_RATIO`).  That is a fixture's signature (issue 33: the stand is the one
    resonance whose frequency does not move with speed and that lifts every line near it on all channels), and the
    test-stand resonance fitted with the lines' levels takes it (:mod:`rwadist.diagnose.stand_levels`).  A
    wheel with no suspension modes on a 180-Hz fixture (the W7 trial wheel, ζ 0.03): translation, rocking and axial at
    179.9, 179.6 and 179.9 Hz with I_zz/I_rr 0.02 were named its suspension modes, and the fixture went into the flight
    PSD (axial RMS 3.8x the hard-mounted one)."""
    located = [f for m, f in e.f0_Hz.items() if m not in e.unconstrained]
    return bool(len(located) >= 2 and max(located) <= ONE_RESONANCE_SPREAD * min(located)
                and e.inertia_ratio < MIN_WHEEL_INERTIA_RATIO)


def _held_out_fold(ctx: Context, state: State) -> "SuspensionModes | None":
    """:class:`SuspensionModes` fitted on the held-out runs, to be judged on the fit runs (``judge_runs``), or None;
    kept on the context for ``state``."""
    from dataclasses import replace

    key = ("suspension_modes.held_out_fold", id(state))
    if key not in ctx._memo or ctx._memo[key][0] is not state:
        e = SuspensionModes.fit(ctx, state, ctx.held_runs)
        ctx._memo[key] = (state, None if e is None else replace(e, judge_runs=tuple(int(r) for r in ctx.fit_runs)))
    return ctx._memo[key][1]


def declare_beside_fixtures(ctx: Context, state: State) -> State:
    """``state`` with the wheel's modes declared that the fixture resonances named after them could have pulled.

    The modes are fitted beside one fixture resonance (their ``stand``).  When the search then names other
    test-stand resonances on every channel (two fixtures at 150 and 180 Hz: the modes' fit divided out one
    resonance between them, and the search named both), the modes are fitted again on every run with all of them
    divided out, from the same data and empirical fit as with the modes' stand alone; a located mode that moves more
    than :data:`rwadist.stand_resonance.STAND_SETTLED_MODE` between the two is not told apart from those fixtures by
    these data (corner-high cell: the radial translation 2.4 % low, nothing said).  It is declared: listed in
    ``unconstrained`` (the effect's and ``analytical.unconstrained``: every consumer warns) with a note giving both
    values.  The state's
    predictions are unchanged (the declaration is the model's metadata); the state is returned as is when nothing
    moves or no other fixture was named."""
    import copy
    from dataclasses import replace

    from ..data import SteadyTest
    from ..extended_fit import MODE_KEY, fit_extended
    from ..stand_resonance import STAND_SETTLED_MODE, _mode_hz

    modes = next((e for e in state.effects if e.kind == "suspension_modes"), None)
    if modes is None or ctx.test is None or len(ctx.channels) < 6:
        return state
    own = modes.stand
    mine = ((own,) if own is not None else ()) + tuple(modes.more_stands)
    others = [(e.f_r, e.zeta, e.peak_gain, e.gain_above) for e in state.effects
              if e.kind == "fixed_resonance" and e.role == "test_stand" and len(e.channels) == 6
              and all(abs(e.f_r / k[0] - 1) > SAME_STAND for k in mine)]
    if not others:
        return state
    test, fit = fit_of_runs(ctx, ctx.runs)
    test = SteadyTest(test.runs, _recorded_meta(ctx))
    try:
        one = fit_extended(test, fit, stand=own, more_stands=tuple(modes.more_stands), stand_on=modes.stand_on)
        every = fit_extended(test, fit, stand=own, more_stands=tuple(modes.more_stands) + tuple(others),
                             stand_on=modes.stand_on)
    except ValueError:
        return state
    f_one, f_every = _mode_hz(one.params), _mode_hz(every.params)
    moved = [m for m in ("radial_translation", "rocking", "axial") if m not in modes.unconstrained
             and m not in one.unconstrained and abs(f_every[m] / f_one[m] - 1) > STAND_SETTLED_MODE]
    if not moved:
        return state
    named = ", ".join(f"{s[0]:.4g} Hz" for s in others)
    notes = [f"{m}: NOT CONSTRAINED beside the fixture resonances the search named ({named}, besides the modes' own "
             f"stand): with them divided out too it moves from {f_one[m]:.4g} to {f_every[m]:.4g} Hz (more than "
             f"{100 * STAND_SETTLED_MODE:g} %); listed in analytical.unconstrained" for m in moved]
    new = replace(modes, model=copy.deepcopy(modes.model), unconstrained=tuple(modes.unconstrained) + tuple(moved))
    out = state.copy()
    out.effects = [new if e is modes else e for e in state.effects]
    for model in (new.model, out.model):
        analytical = getattr(model, "analytical", None)
        if not analytical:
            continue
        analytical["unconstrained"] = list(analytical.get("unconstrained") or []) + moved
        fit_doc = analytical.setdefault("fit", {})
        fit_doc["notes"] = list(fit_doc.get("notes") or []) + notes
        ident = fit_doc.get("identified")
        if isinstance(ident, dict):
            for m in moved:
                ident[MODE_KEY[m]] = False
    return out
