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
from rwadist.diagnose.effects import family_classes
from rwadist.effects.speed_sidebands_diagnose import REACH, SpeedSidebands
from rwadist.effects.spin_acceleration_diagnose import SpinAcceleration
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
    for cls in family_classes():
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


def test_record_lines_beside_a_skipped_welch_line_are_still_dropped(monkeypatch):
    """A line h = 0.5 (below the Welch band at the slow runs, in it at the fast ones) is found by both routes; the
    record route's is not proposed beside the Welch route's.  Skipping the Welch route (nothing there could pass)
    must leave the record route's proposals as they were: the Welch line still tells the record line apart."""
    from rwadist.effects.missing_harmonic_diagnose import MissingHarmonic

    t = e_data(8)
    inject_line(t, "radial_force", 0.5, lambda w: 0.5 * TRUTH.empirical["radial_force"][0].C * w**2, 8)
    ctx = engine.Context(spectra(t), test=t)
    state = engine.initial_state(ctx, replace(TRUTH))
    every = MissingHarmonic.candidates(ctx, state, ctx.fit_runs)
    assert any(not e.record and abs(e.h - 0.5) < 0.01 for e in every)         # the Welch route found it
    ctx2 = engine.Context(spectra(t), test=t)
    state2 = engine.initial_state(ctx2, replace(TRUTH))
    ctx2.step = (state2, None, 0.05)
    monkeypatch.setattr(engine.Context, "can_pass", lambda self, state, chans, bands=None: self.step is None)
    skipped = MissingHarmonic.candidates(ctx2, state2, ctx2.fit_runs)
    assert not any(not e.record for e in skipped)                             # the Welch route skipped
    assert [(e.direction, e.h, e.C) for e in skipped] == [(e.direction, e.h, e.C) for e in every if e.record]


def test_the_bound_leaves_out_runs_without_the_channel():
    """A held-out run lacking a channel (a NaN row of its PSD) adds nothing to the bound, as it adds nothing to the
    judge: with it, the bound over bands is still the bound without bands when every band is asked."""
    t = _law_data(seed=7)
    sp = spectra(t)
    sp.psd["Fy"] = sp.psd["Fy"].copy()
    ctx = engine.Context(sp, test=t)
    sp.psd["Fy"][ctx.held_runs[0]] = np.nan
    state = engine.initial_state(ctx, replace(TRUTH))
    memo: dict = {}
    ctx.step = (state, lambda chans: search._state_errors(ctx, state, ctx.held_runs, chans, memo), 0.05)
    every_band = np.ones((ctx.held_runs.size, ctx.n_bands), bool)
    assert ctx.can_pass(state, ["Fx", "Fy"])
    assert ctx.can_pass(state, ["Fx", "Fy"], every_band)


def test_held_out_predictions_under_a_smear_are_their_own():
    """Under a spin smear the lines' spreading depends on the runs asked together (the longest run sets the smear's
    points): a prediction on the held-out runs is computed for them, never read from every run's."""
    t = _law_data(seed=9)
    longest = int(engine.Context(spectra(t), test=t).fit_runs[0])
    run = t.runs[longest]                                      # one fit run twice as long as the others
    run.signals.update({c: np.concatenate([x, x]) for c, x in run.signals.items()})
    ctx = engine.Context(spectra(t), test=t)
    assert longest in ctx.fit_runs and ctx.run_durations(ctx.runs).max() > ctx.run_durations(ctx.held_runs).max()
    direct = engine.initial_state(ctx, replace(TRUTH)).plus(SpinAcceleration(100.0))
    first = ctx.predict(direct, "Fx", ctx.held_runs).copy()
    after = engine.initial_state(ctx, replace(TRUTH)).plus(SpinAcceleration(100.0))
    ctx.predict(after, "Fx", ctx.runs)                        # every run first, as after an accepted refit
    assert np.array_equal(ctx.predict(after, "Fx", ctx.held_runs), first)


def test_reuse_tells_apart_what_a_fit_reads_beside_the_prediction():
    """A channel without lines predicts the same on the empirical and the extended base, but a line fitted there is
    divided by the base's modal gain; a counter-rotating split leaves a radial force's prediction as it was but
    rewrites the harmonics: either way a family's fit is made again, not read back."""
    t = _law_data(seed=10)
    ctx = engine.Context(spectra(t), test=t)
    base = engine.initial_state(ctx, replace(TRUTH))
    calls = []
    ctx.reuse("x", base, ["Fx"], ctx.fit_runs, lambda: calls.append(1) or [])
    ctx.reuse("x", base, ["Fx"], ctx.fit_runs, lambda: calls.append(1) or [])
    assert len(calls) == 1                                    # read back
    other = base.copy()
    other.ext = preset("ithaco-e").extended                   # another base, the same lines of Fx read as before?
    other._cache = {}
    ctx.reuse("x", other, ["Fx"], ctx.fit_runs, lambda: calls.append(1) or [])
    assert len(calls) == 2
    split = base.copy()
    h1 = split.model.empirical["radial_force"][0]
    split.model.empirical["radial_force"][0] = replace(h1, sense="counter")
    ctx.reuse("x", split, ["Fx"], ctx.fit_runs, lambda: calls.append(1) or [])
    assert len(calls) == 3
