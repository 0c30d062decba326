"""The search's bound (:meth:`rwadist.diagnose.engine.Context.can_pass`): a family skips a fit on channels whose held-out
misplaced power is below ``min_gain`` of all of it, since nothing judged there by the error metric could pass.

Checked two ways on E-wheel data with one strong effect (the h = 4.42 radial-force line growing as Ω^2.5, so the
other directions hold little of the misfit): every hypothesis the families propose unbounded, judged by the search's
own judge, fails wherever the bound says it must; and the diagnosis with the bound finds the same effects, the same
errors and the same model as the diagnosis without it."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
from test_diagnose import TRUTH, W_MID, e_data, inject_line, spectra

from rwadist.diagnose import engine, search
from rwadist.diagnose.effects import EFFECT_CLASSES
from rwadist.diagnose.effects.speed_sidebands import REACH, SpeedSidebands
from rwadist.presets import preset


def _law_data(seed=5):
    h, p = 4.42, 2.5
    C = dict(preset("ithaco-e").harmonics["radial_force"])[h]
    t = e_data(seed, drop=("radial_force", h))
    inject_line(t, "radial_force", h, lambda w: C * W_MID**2 * (w / W_MID) ** p, seed)
    return t


def test_no_hypothesis_the_bound_skips_could_pass():
    t = _law_data()
    sp = spectra(t)
    ctx = engine.Context(sp, test=t)
    state = engine.initial_state(ctx, replace(TRUTH))
    memo: dict = {}
    ctx.step = (state, lambda chans: search._state_errors(ctx, state, ctx.held_runs, chans, memo), 0.05)
    checked = 0
    for cls in EFFECT_CLASSES:
        for e in _unbounded(cls, ctx, state):
            own = getattr(e, "heldout_evidence", None)
            if own is not None and own(ctx, state, ctx.held_runs) is not None:
                continue                          # brings its own evidence: the bound does not apply
            if isinstance(e, SpeedSidebands):
                w = ctx.omega[ctx.held_runs] / (2 * np.pi)
                bound = ctx.can_pass(state, e.channels, ctx.reach_bands((e.h0 - REACH) * w, (e.h0 + REACH) * w))
            else:
                bound = ctx.can_pass(state, e.channels)
            if bound:
                continue
            hyp = search._judge(ctx, state, e, 4.0, 0.05, 1, memo)
            assert not hyp.passed and hyp.gain_fraction < 0.05, (e.kind, hyp.gain_fraction)
            checked += 1
    assert checked >= 3                           # the bound did skip some of the families' hypotheses here


def _unbounded(cls, ctx, state):
    """The family's hypotheses without the bound (no search step under way)."""
    step, ctx.step = ctx.step, None
    try:
        return cls.candidates(ctx, state, ctx.fit_runs)
    finally:
        ctx.step = step


def test_the_bound_changes_no_decision(monkeypatch):
    t = _law_data(seed=6)
    judged = []
    judge = search._judge
    monkeypatch.setattr(search, "_judge", lambda *a, **k: judged.append(1) or judge(*a, **k))
    bounded = search.diagnose(spectra(t), TRUTH, test=t)
    n_bounded = len(judged)
    monkeypatch.setattr(engine.Context, "can_pass", lambda self, state, chans, bands=None: True)
    plain = search.diagnose(spectra(t), TRUTH, test=t)
    assert bounded.model.effects[0]["kind"] == "amplitude_law"
    assert bounded.model.effects == plain.model.effects                 # kinds, parameters and held-out evidence
    assert (bounded.error_before, bounded.error_after) == (plain.error_before, plain.error_after)
    assert bounded.model.empirical == plain.model.empirical
    assert n_bounded < len(judged) - n_bounded                           # the bound skipped hypotheses
