"""An amplitude law measured to many standard errors but below ``min_gain`` is described, not dropped (trial21).

trial21's 11-kg wheel with Ω^2.6 on its bearing line h 3.3: the search fitted the law exactly (2.604 ± 0.005 radial
force, 2.592 ± 0.003 Fz, held-out t 187) and rejected it, its held-out gain 0.03-0.06 % of the misplaced power
(``min_gain`` 5 %), and the law appeared nowhere.  ``min_gain`` is a share of a power-weighted sum over every channel:
a law on a weak line gains little of it however well measured.  Such a law is now described (``unexplained``,
``line_property`` of property ``amplitude_law``, rwadist/diagnose/describe_law.py) when the search does not add it.

Data: family wheel 3 (tests/family_wheel.py, numpy only, the family matrix's test conditions: 20 speeds 600-6000
rpm, 8192 samples, noise 0.01) with its weak axial 3x line (0.1 × the imbalance's coefficient at generation) growing
as Ω^2.2 instead of Ω², equal at the mid speed; diagnosed with no model as the CLI does.  Truth: the generator's
exponent.  Control: the same wheel and seed with the line at Ω² (exponent 2.0): no law, named or described.

Such a law is now named when it takes ``min_gain`` of the held-out narrow-line misfit (every band alike, the
reviewer's view of the waterfall: rwadist.diagnose.search._narrow_judge): this wheel's Ω^2.2 law took 3 % of the
misplaced power and 57 % of the narrow-line misfit, and was only described before.
"""
import functools
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import diagnose_family_matrix as dfm  # noqa: E402
import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.effects.amplitude_law_diagnose import AmplitudeLaw  # noqa: E402

WHEEL = 3


@functools.lru_cache(maxsize=None)
def _diagnosed(exponent: float):
    wheel = dfm.wheels()[WHEEL]
    line = next(x for x in wheel.lines if x.direction == "axial_force" and x.name == "3x")
    law = fe.AmplitudeLaw(direction="axial_force", h=line.h, exponent=exponent)
    data = fw.steady(wheel, noise=dfm.CONDITIONS[WHEEL][2], seed=1 + 100 * WHEEL, effects=[law])
    return line, api.diagnose(steady_test(data))


def _laws(d, h):
    named = [e for e in d.summary()["effects"]
             if e["kind"] == "amplitude_law" and e["direction"] == "axial_force" and abs(e["h"] - h) < 1e-3]
    described = [u for u in d.unexplained if u.signature == "line_property"
                 and u.parameters.get("property") == "amplitude_law"]
    return named, described


@pytest.mark.slow
def test_a_law_on_a_weak_line_below_min_gain_is_described_with_its_exponent():
    line, d = _diagnosed(2.2)
    named, described = _laws(d, line.h)
    # named (its held-out gain reached min_gain) or described: not nowhere
    assert named or described
    for e in named:
        assert e["exponent"] == pytest.approx(2.2, abs=0.02)
    for u in described:
        p = u.parameters
        assert (p["direction"], p["h"]) == ("axial_force", pytest.approx(line.h, abs=1e-3))
        # the generator's exponent, to 0.02 (the fit's standard error is 0.004) and told from 2 by its own error
        assert p["exponent"] == pytest.approx(2.2, abs=0.02)
        assert (p["exponent"] - 2.0) / p["exponent_stderr"] > 4.0
        assert p["heldout_t"] > 4.0 and p["heldout_gain_fraction"] < 0.05
        # the level is the law's own change of power against Ω² over the speeds it was measured at
        lo, hi = u.speed_rpm
        assert u.level_dB == pytest.approx(20 * (2.2 - 2.0) * np.log10(hi / lo), abs=0.15)
        assert u.channels == ("Fz",)


@pytest.mark.slow
def test_a_line_at_omega_squared_gets_no_law_named_or_described():
    line, d = _diagnosed(2.0)
    assert _laws(d, line.h) == ([], [])
    assert not any(u.parameters.get("property") == "amplitude_law" for u in d.unexplained)


@pytest.mark.slow
def test_a_law_on_a_weak_line_is_named_on_its_share_of_the_narrow_line_misfit(monkeypatch):
    line, d = _diagnosed(2.2)
    named, described = _laws(d, line.h)
    assert len(named) == 1 and described == []
    e = named[0]
    # the generator's exponent, and the model's C·Ω² at the mid speed as generated (equal there)
    assert e["exponent"] == pytest.approx(2.2, abs=0.02)
    ev = e["evidence"]
    # taken on the narrow-line rule: its power share is below min_gain (0.05), its narrow-line share above it
    assert ev["passed"] and ev["t"] > 4.0
    assert ev["heldout_gain_fraction"] < 0.05 <= ev["heldout_narrow_gain_fraction"]
    # the model with it misplaces less of the data than the diagnosis of the same data without the narrow-line rule
    # (which only describes the law)
    monkeypatch.setattr(AmplitudeLaw, "judged_on_narrow_lines", False)
    wheel = dfm.wheels()[WHEEL]
    law = fe.AmplitudeLaw(direction="axial_force", h=line.h, exponent=2.2)
    data = fw.steady(wheel, noise=dfm.CONDITIONS[WHEEL][2], seed=1 + 100 * WHEEL, effects=[law])
    without = api.diagnose(steady_test(data))
    assert _laws(without, line.h)[0] == [] and len(_laws(without, line.h)[1]) == 1
    assert d.summary()["error_after"] < without.summary()["error_after"]
