"""``line_property`` (property ``amplitude_law``): a model line whose amplitude departs from C·Ω² as a law Ω^p the
search measured to many standard errors on the held-out runs but did not add, its held-out gain below ``min_gain``
of the misplaced power and of the narrow-line misfit (:func:`rwadist.diagnose.search._narrow_judge` names a law
above it on the narrow lines: trial21's below, now named).

The acceptance rule's ``min_gain`` is a share of the held-out misplaced power of every channel (docs/diagnose.md,
"Acceptance rule"), a power-weighted sum: a law on a weak line (a bearing line 20-40 dB under the imbalance) gains
little of it however well it is measured, and the more so when another misfit holds most of it.  trial21's law
Ω^2.6 on a bearing line h 3.3 (radial force and Fz): the law took the line's residual in its bands from up to 128 and
273 noise standard deviations to within 1-3 (t 187), but those bands held 0.2 % (Fx, Fy) and 4 % (Fz) of their
channels' misplaced power, and the torques' misfit at the rocking whirl crossings held 85 % of all of it: a held-out
gain of 0.03-0.06 % of the misplaced power, and the law appeared nowhere.  Such a law, below ``min_gain`` of the
narrow-line misfit as well, is no noise and no model
imperfection (its exponent is told from 2 by :meth:`AmplitudeLaw.significant` on every run): it is described here,
with its exponent, its standard error and its held-out evidence.
"""
from __future__ import annotations

import numpy as np

from ..extended_fit import UNCONSTRAINED_NAME
from ..mode_scan import MODE_DIRECTION
from .unexplained import Unexplained


def laws_below_gain(ctx, state, judged, k_sigma: float, min_gain: float) -> list:
    """[(hypothesis, law refitted on every run)] of the ``amplitude_law`` hypotheses of ``judged`` (the last search
    step's, judged against ``state``, none taken) that pass the held-out test's significance (t > ``k_sigma``) but not
    its ``min_gain``, and whose law refitted on every run against ``state`` is still told from Ω²
    (:meth:`AmplitudeLaw.significant`); a line with a law in ``state`` is left out, and a line judged twice is taken
    once."""
    out: list[tuple] = []
    for h in judged:
        e = h.effect
        if getattr(e, "kind", "") != "amplitude_law" or not (h.t > k_sigma and h.gain_fraction < min_gain):
            continue
        # a line with a law in the state, or one judged twice in the step (trial26 nonlin: h 3's Ω^5.17 printed twice)
        if (e.direction, round(e.h, 4)) in state.laws or any((x.direction, x.h) == (e.direction, e.h) for _, x in out):
            continue
        refit = e.refit(ctx, state)
        if refit is not e and refit.significant() and _beside_fast_crossings(ctx, state, refit):
            out.append((h, refit))
    return out


def _beside_fast_crossings(ctx, state, law) -> bool:
    """True when ``law`` is still told from Ω² refitted on the runs where its line does not pass a resonance faster
    than the resonance settles (:func:`rwadist.diagnose.sweep_crossing.crossings`, at the state's spin smear or the
    runs' speed track): there the line's level is not its steady response (the lag, the lower peak, the ringing after
    the line has passed), and a law fitted through it reads that as the source's.  True on steady runs."""
    from ..effects.amplitude_law_diagnose import AmplitudeLaw
    from .smear import speed_track
    from .sweep_crossing import crossings

    rate = getattr(state, "smear", None)
    if rate is None and ctx is not None:
        rate = speed_track(ctx, ctx.runs)
    if rate is None or not np.isfinite(rate):
        return True                     # steady runs (or none read): no crossing
    pos = np.arange(ctx.runs.size)
    fast = crossings(ctx, state, np.full(pos.size, law.h), pos, rate)
    if not fast.any():
        return True
    calm = AmplitudeLaw.fit(ctx, state, law.direction, law.h, ctx.runs[~fast])
    return calm is not None and calm.significant()


#: the suspension mode each load direction's lines pass through (its name in ``suspension_modes``' parameters)
_MODE_OF = {direction: UNCONSTRAINED_NAME[mode] for mode, direction in MODE_DIRECTION.items()}


def _unlocated_mode(state, law) -> tuple:
    """The cause a rising line (``law``, exponent over 2) has when the mode of its direction is in the model's
    ``suspension_modes`` but not located (``unconstrained``): the rise of the lines below a mode above them, which the
    lines' own rise could not pin (a ROSS wheel's 405.6 Hz rocking mode, I_zz/I_rr 1.22, its torque lines to 246 Hz:
    h 3.08 and 4.92 rose 1.4 and 3.2 dB faster than Ω², read as their sources' laws).  Empty otherwise."""
    mode = _MODE_OF.get(law.direction, "")
    modes = [e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"]
    if law.exponent <= 2.0 or not modes or mode not in modes[-1].unconstrained:
        return ()
    name = mode.replace("_", " ")
    ratio = " and its I_zz/I_rr from the wheel's inertias" if mode == "rocking" else ""
    return (f"the rise of the line below the {name} mode, which the data do not locate (the fit ended at "
            f"{modes[-1].f0_Hz[mode]:.4g} Hz): a suspension mode above the line lifts it as 1/(1 − (f/f0)²); the "
            f"mode's frequency from a tap test{ratio} would place it",)


def describe_laws(res, laws) -> list:
    """The ``line_property`` records (property ``amplitude_law``) of ``laws`` (:func:`laws_below_gain`), each with
    its share of the misplaced power left measured on ``res`` (the final model's
    :class:`~rwadist.diagnose.describe.Residual` on the data as given: the line's band in each run where it is
    measured, in its channels) and its level the change of the line's power against C·Ω² from the lowest speed where
    it is measured to the highest, 20·(p − 2)·log10(Ω_hi/Ω_lo) dB."""
    from .measure import measure_run_powers

    ctx = res.ctx
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    out = []
    for hyp, law in laws:
        _, w, _, _ = measure_run_powers(ctx, res.state, law.direction, law.h, ctx.runs, skip=law.h)
        if w.size < 2:
            continue
        runs = [int(r) for r in ctx.runs if np.any(np.isclose(ctx.omega[r], w))]
        chans = [c for c in law.channels if c in res.e]
        cells = {}
        for c in chans:
            m = res.mask(c)
            for r in runs:
                m[pos[r], res.band_of(law.h * ctx.omega[r] / (2 * np.pi))] = True
            cells[c] = m
        share, _ = res.measure(cells)
        lo, hi = float(w.min()), float(w.max())
        change = 20.0 * (law.exponent - 2.0) * np.log10(hi / lo)
        rpm = (lo * 60.0 / (2 * np.pi), hi * 60.0 / (2 * np.pi))
        z = (law.exponent - 2.0) / law.exponent_stderr
        out.append(Unexplained(
            signature="line_property", channels=tuple(chans), speed_rpm=rpm,
            f_Hz=(law.h * rpm[0] / 60.0, law.h * rpm[1] / 60.0), level_dB=float(change), share=float(share),
            n_runs=len(runs), h=float(law.h),
            parameters={"property": "amplitude_law", "direction": law.direction, "h": float(law.h),
                        "exponent": float(law.exponent), "exponent_stderr": float(law.exponent_stderr),
                        "amplitude_ref": float(law.amplitude_ref), "omega_ref_rad_s": float(law.omega_ref),
                        "heldout_t": float(hyp.t), "heldout_gain_fraction": float(hyp.gain_fraction)},
            causes=_unlocated_mode(res.state, law) + (
                    f"the line's source grows as Ω^{law.exponent:.3f} ± {law.exponent_stderr:.2g} "
                    f"({z:.0f} standard errors from the model's Ω²), not as an imbalance: a bearing defect's impacts, "
                    f"a drive ripple that follows the motor current; an amplitude_law measured at t {hyp.t:.0f} on "
                    f"the held-out runs, its held-out gain {100.0 * hyp.gain_fraction:.2g} % of the misplaced power "
                    "(below min_gain: the line is weak beside what else is misplaced)",),
            would_tell="the line at a few speeds away from the modes' crossings (its level against Ω² there), or "
                       "diagnose with a lower --min-gain to add the law"))
    return out
