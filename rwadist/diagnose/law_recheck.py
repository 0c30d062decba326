"""An amplitude law taken before the base changed, judged again on the new base (docs/diagnose.md, "Amplitude laws
judged again").

The search is greedy: an effect taken in one iteration is judged against the state of that iteration.  An amplitude
law read on the empirical base (every line C·Ω², hard mounted) measures a line's level against speed, and on a wheel
whose suspension modes are not yet in that level carries the modes' transfer: the imbalance's 1x force through a
180 Hz translation mode reads Ω^2.09 over 200-4000 rpm although the source is exactly U·Ω² (trial25 height_s1, a load
cell 50 mm below the rotor: the modes' refit alone raised the error, so the law passed first; the modes and the
load-cell offset came in the next two iterations and the law stayed in model.json, moving `rwadist psd` by +12 % /
-14 % at the ends of the speed range while diagnose's own error was 1.3x clean).  Once the wheel's modes or a
load-cell offset are taken (the base the lines are read through changes), such a law is refitted and judged again on
the final state, by the rule that took it; it is taken back when the new base explains it."""

from __future__ import annotations

from .state import State

#: Effects that change what a line's level is read through: the wheel's suspension modes (the extended base) and a
#: load-cell offset (r × F adds the forces' lines to the torques)
BASE_KINDS = ("suspension_modes", "cross_coupling")


def _without(state: State, effect) -> State:
    """``state`` with ``effect`` left out of its effects (the others, and the base, as they are)."""
    out = state.copy()
    out.effects = [e for e in state.effects if e is not effect]
    return out


def recheck_laws(ctx, state: State, hyps: list, k_sigma: float, min_gain: float, evidence) -> State:
    """``state`` with every amplitude law taken before a later passing effect of :data:`BASE_KINDS` judged again,
    and taken back when it fails; the hypotheses of those taken back get ``passed`` False and ``taken_back`` (the
    reason, reported in the console, report.md and summary.json).

    The law is refitted on every run against the final state without it (:meth:`AmplitudeLaw.refit`): an exponent
    the new base brings back to 2 within its standard errors (:meth:`AmplitudeLaw.significant`, the rule that
    proposes a law) is no law of the source.  Else it is judged on the held-out runs as the search judges it
    (``evidence``: :func:`rwadist.diagnose.search._evidence`, the final state without the law against with it): it
    stays when t > ``k_sigma`` and it takes at least ``min_gain`` of the held-out misplaced power, or of the held-out
    narrow-line misfit (the search's second rule for a law, :func:`rwadist.diagnose.search._narrow_judge`).
    A law taken after the base changed was judged on that base already and is left alone."""
    taken = [h for h in hyps if h.passed]
    changed = [h.iteration for h in taken if getattr(h.effect, "kind", "") in BASE_KINDS]
    for h in taken:
        law = h.effect
        if getattr(law, "kind", "") != "amplitude_law" or not any(i > h.iteration for i in changed):
            continue
        without = _without(state, law)
        refit = law.refit(ctx, without)
        if refit is law:
            # the fit on the new base failed (too few runs measured): nothing confirms the law there
            why = "the line could not be measured again through the new base"
        elif not refit.significant():
            why = (f"refitted through the {_base_text(hyps, h)} its exponent is {refit.exponent:.4f} "
                   f"± {refit.exponent_stderr:.2g}, not told from 2")
        else:
            chans = [c for c in law.channels if c in ctx.channels]
            gain, frac, t, _ = evidence(ctx, without, state, ctx.held_runs, chans, None, own_beats=True)
            c0 = ctx.contrast_error(without, ctx.held_runs)
            narrow = (c0 - ctx.contrast_error(state, ctx.held_runs)) / c0 if c0 > 0 else 0.0
            if t > k_sigma and max(frac, narrow) >= min_gain:
                continue
            why = (f"beside the {_base_text(hyps, h)} its held-out gain is {100 * frac:.2g} % of the misplaced power "
                   f"({100 * narrow:.2g} % of the narrow-line misfit), t {t:.3g}")
        state = without
        h.passed, h.taken_back = False, why
    return state


def _base_text(hyps: list, law_hyp) -> str:
    """The effects of :data:`BASE_KINDS` taken after ``law_hyp``, in words."""
    words = {"suspension_modes": "wheel's suspension modes", "cross_coupling": "load-cell offset"}
    kinds = [h.effect.kind for h in hyps if h.passed and h.iteration > law_hyp.iteration
             and getattr(h.effect, "kind", "") in BASE_KINDS]
    return " and ".join(dict.fromkeys(words[k] for k in kinds))
