"""What the description takes back of the search's model (:func:`rwadist.diagnose.describe.finish`): an effect fitted
to content no class explains, the other parts of its group, and an effect left acting on a line only a taken-back
effect had put in the model (docs/diagnose.md, "Unexplained residual")."""
from __future__ import annotations

from .state import State


def on_a_moving_track(effect, found) -> str | None:
    """"moving_resonance" when ``effect`` is a fixed resonance (the ``fixed_resonance`` class) on a channel of a
    described moving resonance, at a frequency its track passes: one frame of the moving resonance, fitted as fixed."""
    f_r, chans = getattr(effect, "f_r", None), set(getattr(effect, "channels", ()) or ())
    if f_r is None:
        return None
    for u in found:
        if u.signature == "moving_resonance" and chans & set(u.channels) and u.f_Hz[0] <= f_r <= u.f_Hz[1]:
            return u.signature
    return None


def without(start: State, effects, e) -> State | None:
    """``start`` with every effect of ``effects`` but ``e`` applied in their order, or None when one of them cannot be
    applied without ``e`` (a ``counter_rotation`` splits the sense of a line that an effect before it made or left
    free: it raises on a state without that line): ``e`` is then not taken back alone (family wheel 7, a 60-s run-up
    without a speed column: the search ended with an internal error)."""
    state = start
    for other in effects:
        if other is not e:
            try:
                state = other.apply(state)
            except (TypeError, ValueError):
                return None
    return state


def with_groups(hypotheses, gone: dict) -> dict:
    """``gone`` (id of an effect taken back -> the signature it was fitted to) with every other part of an effect of
    several parts one of whose parts it holds (``Hypothesis.group``: a floor law of several channels), under that
    part's signature.

    A group stands or falls together: its parts share one exponent, fitted over every part's bands at once, and it
    passed as one hypothesis on their summed held-out evidence.  A part fitted to content no class explains put that
    content into the shared exponent and into the evidence the others passed on; without a new fit and judgement of
    the other channels alone (the search's, not the description's), they stand on nothing of their own."""
    sig: dict = {}
    for h in hypotheses:
        g = getattr(h, "group", None)
        if g is not None and id(h.effect) in gone:
            sig.setdefault(id(g), gone[id(h.effect)])
    out = dict(gone)
    for h in hypotheses:
        g = getattr(h, "group", None)
        if g is not None and id(g) in sig:
            out.setdefault(id(h.effect), sig[id(g)])
    return out



def on_a_line_gone(effect, state: State) -> bool:
    """Whether ``effect`` changes one line of the model (an amplitude law: ``own_beats``, its ``direction`` and ``h``)
    that ``state`` does not hold: a line a taken-back effect had added (a missing harmonic the search fitted to a
    broadband hump: its amplitude law stayed in the model on no line, and the model's error did not move)."""
    d, h = getattr(effect, "direction", None), getattr(effect, "h", None)
    if not getattr(effect, "own_beats", False) or d is None or h is None:
        return False
    return not any(abs(x.h - h) < 1e-3 for x in state.model.harmonics(d))


def without_taken_back(start: State, effects, gone: dict) -> tuple:
    """(gone, state): ``start`` with the effects of ``effects`` applied in their order but those of ``gone`` (id ->
    the signature each was fitted to), and ``gone`` with every effect that then acts on a line no longer there
    (:func:`on_a_line_gone`), under the signature of the effect that had added that line (of the first taken back
    when none of them names it)."""
    out = dict(gone)
    of_line = {(e.direction, round(float(e.h), 3)): gone[id(e)] for e in effects
               if id(e) in gone and hasattr(e, "direction") and hasattr(e, "h")}
    state = start
    for e in effects:
        if id(e) in out:
            continue
        if on_a_line_gone(e, state):
            out[id(e)] = of_line.get((e.direction, round(float(e.h), 3)), next(iter(gone.values())))
            continue
        state = e.apply(state)
    return out, state
