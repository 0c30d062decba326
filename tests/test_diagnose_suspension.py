"""``rwadist diagnose`` without a model names the wheel's own suspension modes first (issue 14, item 3).

The truth is typed from the thesis (tests/independent_wheel.py: Tables 3.4/4.2, axial 70 Hz), not read
from rwadist: radial translation sqrt(k/M), rocking sqrt(k d²/I_rr) at rest.  Data: the project's virtual
stand with the extended physics (modes on, 300-3000 rpm: the span on which the extended fit once lost
the rocking mode), the independent generator, and ROSS's bearing reactions (tests/ross_dataset.py).
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402
import ross_dataset as rd  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist import model as model_io  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.teststand import simulate_steady  # noqa: E402

SPEEDS = np.linspace(300.0, 3000.0, 30)


def _modes_only(d, truth, tol=0.02):
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds == ["suspension_modes"], kinds
    e = d.model.effects[0]
    assert e["radial_translation_Hz"] == pytest.approx(truth["radial_translation"], rel=tol)
    assert e["rocking_Hz"] == pytest.approx(truth["rocking"], rel=tol)
    assert e["axial_Hz"] == pytest.approx(truth["axial"], rel=tol)
    # the improved model is on the extended base and carries the fitted analytical section
    assert d.state_after.base == "extended" and d.model.analytical
    assert d.model.provenance["diagnose"]["base"] == "extended"
    # summary.json says the base moved (it said "empirical" alone: an independent trial read the final model as one)
    assert (d.summary()["base"], d.summary()["base_after"]) == ("empirical", "extended")
    assert d.error_after < 0.1 * d.error_before
    return e


def test_virtual_stand_extended_physics_only_the_suspension_modes(tmp_path):
    w = preset("ithaco-e")
    test = simulate_steady(w, SPEEDS, sample_rate=3840.0, n_samples=8192, noise=0.01, seed=3,
                           physics="extended", test_stand=False)
    d = api.diagnose(test)
    e = _modes_only(d, iw.TRUTH_HZ)
    # the whirls at the top speed: closed form of the fitted parameters against the thesis numbers
    w_top = SPEEDS[-1] * np.pi / 30
    half = 0.5 * (iw.I_ZZ / iw.I_RR) * w_top / (2 * np.pi)
    f_fwd = np.sqrt(half**2 + iw.TRUTH_HZ["rocking"] ** 2) + half
    assert e["inertia_ratio"] == pytest.approx(iw.I_ZZ / iw.I_RR, rel=0.02)
    from rwadist.effects.suspension_modes_diagnose import SuspensionModes
    fitted = d.state_after.effects[0]
    assert isinstance(fitted, SuspensionModes)
    assert fitted.whirl_Hz(w_top)["rocking_forward"] == pytest.approx(f_fwd, rel=0.02)
    # the model file round-trips through the typed schema, suspension_modes entry included
    path = tmp_path / "model.json"
    model_io.save(d.model, path)
    back = model_io.load(path)
    assert [x["kind"] for x in back.effects] == ["suspension_modes"]
    assert json.loads(path.read_text())["analytical"]["unconstrained"] == []


def test_independent_generator_only_the_suspension_modes():
    test, truth = iw.generate(SPEEDS, n_samples=8192, seed=1)
    _modes_only(api.diagnose(test), truth)


@pytest.mark.slow
def test_ross_data_nothing_beyond_the_suspension_modes():
    d = api.diagnose(rd.ross_test())
    assert [e["kind"] for e in d.model.effects] == ["suspension_modes"]


def test_modes_off_record_and_explicit_empirical_base_keep_the_empirical_base():
    """No base switch when the test says the modes were off, or when the caller asks for the empirical base."""
    w = preset("ithaco-e")
    test = simulate_steady(w, np.linspace(600, 2400, 12), sample_rate=1920.0, n_samples=4096, noise=0.01,
                           seed=2, modes=False, test_stand=False)
    d = api.diagnose(test)
    assert d.state_after.base == "empirical"
    assert "suspension_modes" not in [e["kind"] for e in d.model.effects]
