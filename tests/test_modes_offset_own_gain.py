"""The wheel's modes judged with the load-cell offset they were located beside must add a gain of their own
(review14 finding 1; :func:`rwadist.diagnose.search._judge_with_offset`).

The offset's correction T − r × F has a gain of its own on data read at a reference below the bearing centre.
Judged as a pair against the state with neither, that gain counted for the modes, so modes that add nothing passed
whenever the offset alone would.  The pair is now judged against the better of the state and the state with the
offset alone.

Closed form: modes that change nothing, beside the true offset, gain exactly 0 over the state with that offset.
Data: tests/test_describe_offset_floor.py's numpy wheel (hard mounted, r_z 30 mm, sensor noise after the geometry),
its true lines as the state; and, on the default path, tests/standmodes_wheel.py's bearing wheel hard mounted (its
modes at 100 kHz, far above every line) on a fixture resonance, read with r_z 30 mm: no suspension modes.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import standmodes_wheel as sw  # noqa: E402
import test_describe_offset_floor as lever  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose import search  # noqa: E402
from rwadist.diagnose.engine import initial_state  # noqa: E402
from rwadist.effects.cross_coupling_diagnose import CrossCoupling  # noqa: E402
from rwadist.model import Harmonic, WheelModel  # noqa: E402


class _NoModes:
    """'Modes' that change nothing: what a wrong mode fit adds at most beside an offset that explains the data."""

    kind = "suspension_modes"

    def apply(self, state):
        return state


def _true_state():
    ctx, _ = lever._truth(False)
    model = WheelModel(name="offset15")
    for d, h, C in lever.LINES:
        model.empirical[d].append(Harmonic(h=h, C=C))
    return ctx, initial_state(ctx, model)


def test_modes_that_add_nothing_beside_a_passing_offset_do_not_pass():
    ctx, state = _true_state()
    offset = CrossCoupling(lever.R.copy(), np.full(3, 1e-5))
    runs, chans = ctx.held_runs, list(ctx.channels)
    # the offset alone passes the search's rule on these data (the premise: its gain is there to be taken)
    _, frac, t, _ = search._evidence(ctx, state, offset.apply(state), runs, chans, None)
    assert t > 4.0 and frac >= 0.05
    hyp = search._judge_with_offset(ctx, state, _NoModes(), offset, runs, chans, 4.0, 0.05, 1)
    assert not hyp.passed
    assert hyp.gain == pytest.approx(0.0, abs=1e-12)


@pytest.mark.slow
def test_a_hard_mounted_wheel_on_a_fixture_with_a_30_mm_lever_arm_names_no_modes():
    r_z = 0.030
    hard = sw.bearing_wheel(name="hard", f_trans=1e5, f_rock=1e5, f_axial=1e5)
    test, _ = sw.generate(hard, np.linspace(600.0, 6000.0, 24), sample_rate=5000.0, n_samples=4096, noise=0.01,
                          seed=11, fixtures=((300.0, 0.03, 4.0),))
    for run in test.runs:
        fx, fy = run.signals["Fx"], run.signals["Fy"]
        run.signals["Tx"] = run.signals["Tx"] - r_z * fy
        run.signals["Ty"] = run.signals["Ty"] + r_z * fx
    kinds = [e["kind"] for e in api.diagnose(test).summary()["effects"]]
    assert "suspension_modes" not in kinds
    assert "fixed_resonance" in kinds


def _diag(*kinds_beside):
    """A stand-in Diagnosis: hypotheses taken, each (effect kind, kind of the effect it was judged beside or None)."""
    from types import SimpleNamespace as NS

    return NS(hypotheses=[NS(passed=True, effect=NS(kind=k), beside=None if b is None else NS(kind=b))
                          for k, b in kinds_beside])


@pytest.mark.parametrize("first, calls", [
    # the modes taken on the pair's evidence, no offset named after them: searched again without the pair path
    ([("suspension_modes", "cross_coupling")], [True, False]),
    # the offset named too: the pair's evidence stands
    ([("suspension_modes", "cross_coupling"), ("cross_coupling", None)], [True]),
    # modes taken alone: nothing to re-check
    ([("suspension_modes", None), ("amplitude_law", None)], [True]),
])
def test_modes_taken_on_an_offsets_evidence_without_it_are_searched_again(monkeypatch, first, calls):
    """review15 S5: the re-run path (search._search) had no test.  A search that kept modes judged with a load-cell
    offset it did not name is searched again with offset_pair False, and that search's result is the answer (the
    first's modes stood on evidence its own model does not hold); any other search runs once."""
    seen, second = [], _diag(("suspension_modes", None))

    def fake(*args, offset_pair=True, **kwargs):
        seen.append(offset_pair)
        return _diag(*first) if offset_pair else second

    monkeypatch.setattr(search, "_search_once", fake)
    out = search._search("args")
    assert seen == calls
    assert (out is second) == (calls == [True, False])
