"""An amplitude law taken before the wheel's modes or a load-cell offset is judged again on that base
(:mod:`rwadist.diagnose.law_recheck`; trial25 height_s1: an Ω^2.09 law on the imbalance taken in iteration 1, the
modes and r_z 50 mm after it, the law left in model.json).

Data: tests/family_wheel.py's wheel 3 (7 kg, I_zz/I_rr 1.8, modes 230/70/120 Hz; not the E wheel), its load cell's
reference 50 mm below the bearing centre (family_effects.CrossCoupling), 16 speeds.  Truth from the generator: the
imbalance's radial force is exactly U_s·Ω² (its Line has no law), and in the second case the BPFO line grows as Ω³.
The early iteration is made as the search made it: the law fitted on the empirical base (every line C·Ω², no modes),
where the modes' transfer reads as a law; then judged again on the diagnosed base (modes and offset).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose import search  # noqa: E402
from rwadist.diagnose.law_recheck import recheck_laws  # noqa: E402
from rwadist.effects.amplitude_law_diagnose import AmplitudeLaw  # noqa: E402

R_Z = 0.05


def _diagnosed(effects, tmp_path):
    wheel = fw.family()[3]
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, 16), n_samples=4096, noise=0.01,
                     seed=3, effects=[fe.CrossCoupling(r=(0.0, 0.0, R_Z)), *effects])
    diag = api.diagnose(str(fw.write_steady(data, tmp_path / "data", wheel.name)))
    kinds = [h.effect.kind for h in diag.hypotheses if h.passed]
    # the premise: the wheel's modes and the offset are named, as on trial25's height seeds
    assert "suspension_modes" in kinds and "cross_coupling" in kinds
    offset = next(h.effect for h in diag.hypotheses if h.passed and h.effect.kind == "cross_coupling")
    assert abs(offset.r[2] - R_Z) < 0.002
    return wheel, data, diag


def _early(diag, direction, h):
    """The law as iteration 1 read it: fitted on the empirical base (the search's starting state) on the fit runs,
    taken in iteration 1 with the diagnosed effects after it (iterations 2 and 3)."""
    # at the line's h as the empirical fit measured it
    h = min((hm.h for hm in diag.state_before.model.harmonics(direction)), key=lambda x: abs(x - h))
    law = AmplitudeLaw.fit(diag.ctx, diag.state_before, direction, h, diag.ctx.fit_runs)
    # a law the search named on that line after the modes is left out: the early one stands for it
    same = [e for e in diag.state_after.effects
            if e.kind == "amplitude_law" and (e.direction, round(e.h, 4)) == (direction, round(h, 4))]
    hyps = [search.Hypothesis(law, 0.1, 0.1, 100.0, True, 1)]
    for k, hyp in enumerate(h_ for h_ in diag.hypotheses if h_.passed and h_.effect not in same):
        hyps.append(search.Hypothesis(hyp.effect, hyp.gain, hyp.gain_fraction, hyp.t, True, 2 + k))
    state = diag.state_after.copy()
    state.effects = [e for e in state.effects if e not in same] + [law]
    return law, hyps, state


@pytest.mark.slow
def test_an_imbalance_law_read_before_the_modes_is_taken_back(tmp_path):
    wheel, _, diag = _diagnosed([], tmp_path)
    imbalance = next(ln for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "imbalance")
    assert imbalance.h == 1.0 and imbalance.exponent == 2.0              # the truth: U_s·Ω², no law
    law, hyps, state = _early(diag, "radial_force", 1.0)
    # the premise: read through no modes, the imbalance's U_s·Ω² through the 230 Hz translation is a 'law'
    assert law is not None and law.significant() and abs(law.exponent - 2.0) > 0.02
    out = recheck_laws(diag.ctx, state, hyps, 4.0, 0.05, search._evidence)
    assert law not in out.effects
    assert not hyps[0].passed
    assert "not told from 2" in hyps[0].taken_back or "held-out gain" in hyps[0].taken_back
    # the other effects are left as they were
    assert [e for e in out.effects] == [e for e in state.effects if e is not law]


@pytest.mark.slow
def test_a_true_law_taken_before_the_modes_is_kept(tmp_path):
    """The Ω³ law the search named on the BPFO line (after the modes), put in iteration 1 before them: kept."""
    wheel = fw.family()[3]
    bpfo = next(ln for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "BPFO")
    _, _, diag = _diagnosed([fe.AmplitudeLaw(direction="radial_force", h=bpfo.h, exponent=3.0)], tmp_path)
    named = [h for h in diag.hypotheses if h.passed and h.effect.kind == "amplitude_law"]
    assert len(named) == 1 and abs(named[0].effect.h - bpfo.h) < 0.01 and abs(named[0].effect.exponent - 3) < 0.05
    law = named[0].effect
    hyps = [search.Hypothesis(law, 0.1, 0.1, 100.0, True, 1)]
    hyps += [search.Hypothesis(h.effect, h.gain, h.gain_fraction, h.t, True, 2 + k)
             for k, h in enumerate(h_ for h_ in diag.hypotheses if h_.passed and h_.effect is not law)]
    out = recheck_laws(diag.ctx, diag.state_after, hyps, 4.0, 0.05, search._evidence)
    assert law in out.effects and hyps[0].passed and hyps[0].taken_back is None
