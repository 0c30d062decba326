"""A floor law of several channels (:class:`rwadist.effects.broadband_floor_diagnose.FloorGroup`) is ONE hypothesis, its
parts each their own entry of the model file and their own row of the hypotheses (``Hypothesis.group``): one effect
for the search's standing (:func:`rwadist.diagnose.describe.search_standing`), its gain counted once in hypotheses.csv
(:func:`rwadist.diagnose.report.hypotheses_csv`), and taken back whole when one part was fitted to content no class
explains (:func:`rwadist.diagnose.describe.finish`).  Checked on hypotheses built as the search builds them (one
passed hypothesis, copied per part, ``rwadist.diagnose.search._search``)."""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.diagnose import describe
from rwadist.diagnose.report import hypotheses_csv
from rwadist.diagnose.search import Hypothesis


@dataclass(eq=False)
class _Part:
    """An effect of one channel: applied, it is appended to the state (a tuple of effects)."""

    kind: str
    channel: str

    @property
    def channels(self):
        return (self.channel,)

    def params(self) -> dict:
        return {"channel": self.channel, "exponent": 3.0}

    def apply(self, state):
        return state + (self,)


def _group_hypotheses(gain=0.12, fraction=0.3, t=9.0):
    """Hypotheses as the search leaves them: a single-channel amplitude law (iteration 1), then a floor group of Fx,
    Fy, Fz taken at iteration 2 (one passed hypothesis, copied for each part but the last), and a failed rival."""
    law = Hypothesis(_Part("amplitude_law", "Fx"), 0.05, 0.2, 6.0, True, 1)
    parts = tuple(_Part("broadband_floor", c) for c in ("Fx", "Fy", "Fz"))
    group = SimpleNamespace(parts=parts, channels=("Fx", "Fy", "Fz"), kind="broadband_floor")
    best = Hypothesis(parts[-1], gain, fraction, t, True, 2, group=group)
    rival = Hypothesis(_Part("fixed_resonance", "Tx"), 0.01, 0.02, 1.0, False, 2)
    return [law, *[replace(best, effect=e) for e in parts[:-1]], best, rival], parts


def test_a_floor_group_counts_as_one_effect_in_the_search_standing():
    """Two effects added (an amplitude law, one floor law of three channels): standing (modes located, -2), not -4."""
    hyps, parts = _group_hypotheses()
    modes = SimpleNamespace(kind="suspension_modes", unconstrained=("rocking",))
    diag = SimpleNamespace(hypotheses=hyps, state_after=SimpleNamespace(effects=[modes, *parts]))
    assert describe.search_standing(diag) == (2, -2)
    # a search that added one floor group ranks with one that added one amplitude law, above one with two laws
    one = SimpleNamespace(hypotheses=hyps[1:4], state_after=diag.state_after)
    two = SimpleNamespace(hypotheses=[hyps[0], replace(hyps[0])], state_after=diag.state_after)
    assert describe.search_standing(one) == (2, -1) > describe.search_standing(two)


def test_hypotheses_csv_writes_a_group_gain_once_so_the_column_sums():
    hyps, _ = _group_hypotheses(gain=0.12, fraction=0.3)
    rows = list(csv.DictReader(io.StringIO(hypotheses_csv(hyps))))
    assert [r["channels"] for r in rows] == ["Fx", "Fx", "Fy", "Fz", "Tx"]
    passed = [r for r in rows if r["passed"] == "true"]
    # what the passed hypotheses gained: the law's 0.05 and the group's 0.12, each once
    assert sum(float(r["heldout_gain"] or 0) for r in passed) == pytest.approx(0.05 + 0.12)
    assert sum(float(r["heldout_gain_fraction"] or 0) for r in passed) == pytest.approx(0.2 + 0.3)
    floors = [r for r in rows if r["kind"] == "broadband_floor"]
    assert [r["heldout_gain"] for r in floors] == ["0.12", "", ""]
    assert all("part_of=Fx Fy Fz" in r["parameters"] for r in floors)
    assert all(r["t"] == "9" for r in floors)          # each part with the judgement of the whole
    assert "part_of" not in rows[0]["parameters"] and rows[0]["heldout_gain"] == "0.05"


def test_a_group_is_taken_back_whole_when_one_part_was_fitted_to_unexplained_content(monkeypatch):
    """:func:`describe.forced_effects` finds the gain of Fz's part alone in the cells of a described hump: the group
    of Fx, Fy, Fz (one exponent fitted over every part, passed on their summed evidence) is taken back whole; the
    amplitude law, fitted to nothing described, stays; the model is rebuilt from the state without the group."""
    hyps, parts = _group_hypotheses()
    law = hyps[0].effect
    diag = SimpleNamespace(hypotheses=hyps, state_before=(), state_after=(law, *parts), error_before=1.0,
                           error_after=0.1)
    diag.state_after = SimpleNamespace(effects=diag.state_after)
    raw = SimpleNamespace(contrast_error=lambda state: 0.0)
    opened = SimpleNamespace(ctx=raw, raw=raw)
    hump = SimpleNamespace(signature="broadband_hump", h=None)
    monkeypatch.setattr(describe, "_described", lambda *a, **k: ([hump], None))
    monkeypatch.setattr(describe, "forced_effects", lambda *a, **k: [(parts[2], "broadband_hump")])
    monkeypatch.setattr(describe, "line_causes", lambda *a, **k: [])
    rebuilt = []
    describe.finish(diag, opened, rebuild=lambda state, hs: rebuilt.append(state) or "model")
    assert rebuilt == [(law,)] and diag.model == "model"
    by_channel = {h.effect.channel: h for h in hyps if h.effect.kind == "broadband_floor"}
    assert all(not h.passed and h.forced_by == "broadband_hump" for h in by_channel.values())
    assert hyps[0].passed and hyps[0].forced_by is None
    assert not np.any([h.passed for h in hyps[1:]])


def test_a_semicolon_inside_a_value_does_not_split_its_pair():
    """hypotheses.csv separates key=value pairs by ';' (docs/formats.md); a speed ripple's law text held one, which
    split its pair in two (docs29 review)."""
    law = Hypothesis(_Part("amplitude_law", "Fx"), 0.05, 0.2, 6.0, True, 1)
    law.effect.params = lambda: {"law": "a; b", "h": 2.0}
    (row,) = list(csv.DictReader(io.StringIO(hypotheses_csv([law]))))
    assert row["parameters"].split(";") == ["law=a  b", "h=2"]
