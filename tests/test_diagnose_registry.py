"""The effect families of rwadist.diagnose behind one protocol and one registry (issue 13)."""
import ast
import json
from pathlib import Path

import numpy as np

from rwadist import model as model_io
from rwadist.diagnose import REGISTRY, Effect, family_classes
from rwadist.effects.missing_harmonic_diagnose import MissingHarmonic
from rwadist.effects.speed_ripple_diagnose import SpeedRipple
from rwadist.presets import preset

PACKAGE = Path(__file__).resolve().parents[1] / "rwadist" / "diagnose"


def test_registry_holds_every_family_once_in_the_search_order():
    # the order the search has always asked for candidates (its ranking is a stable sort: ties keep it)
    EFFECT_CLASSES = family_classes()
    assert [c.__name__ for c in EFFECT_CLASSES] == [
        "MissingHarmonic", "SpeedSidebands", "AmplitudeLaw", "BroadbandFloor", "FixedResonance", "CrossCoupling",
        "LeverArmNoise", "Sidebands",
        "SpeedRipple", "CounterRotation", "SpinAcceleration", "SuspensionModes"]
    kinds = [c.__dataclass_fields__["kind"].default for c in EFFECT_CLASSES]
    assert len(set(kinds)) == len(kinds) and set(REGISTRY) == set(kinds)
    assert [c.order for c in EFFECT_CLASSES] == sorted(c.order for c in EFFECT_CLASSES)
    for cls in EFFECT_CLASSES:
        for name in ("candidates", "fit", "apply", "refit", "params", "to_schema"):
            assert callable(getattr(cls, name, None)), (cls.__name__, name)


def test_one_module_per_family_and_no_dispatch_on_concrete_classes():
    """Every family module (``rwadist/effects/<kind>_diagnose.py``, beside its kind's element) registers exactly one
    class of its kind; the search names no concrete family."""
    EFFECT_CLASSES = family_classes()
    mods = sorted(p.stem for p in (PACKAGE.parent / "effects").glob("*_diagnose.py"))
    assert len(mods) == len(EFFECT_CLASSES)
    assert sorted(c.__module__.rsplit(".", 1)[1] for c in EFFECT_CLASSES) == mods
    assert all(c.__module__ == f"rwadist.effects.{c.kind}_diagnose" for c in EFFECT_CLASSES)
    names = {c.__name__ for c in EFFECT_CLASSES}
    tree = ast.parse((PACKAGE / "search.py").read_text())
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} | \
           {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
    assert not names & used
    assert not any(isinstance(n, ast.Call) and getattr(n.func, "id", "") == "isinstance" for n in ast.walk(tree))


def test_to_schema_is_the_model_file_entry_and_survives_the_file():
    e = MissingHarmonic("radial_force", 0.51234, 2.5e-7, 17)
    assert isinstance(e, Effect)
    entry = e.to_schema()
    assert entry == {"kind": "missing_harmonic", "direction": "radial_force", "h": 0.5123, "C": 2.5e-7,
                     "channel": ["Fx", "Fy"]}
    r = SpeedRipple(delta_omega=3.0, f_ripple=8.0, omega_ref=150.0, exponent=1.0)
    assert r.to_schema()["kind"] == "speed_ripple" and r.to_schema()["ripple_frac_at_ref"] == 3.0 / 150.0
    model = preset("ithaco-e").to_model()
    model.effects = [entry, r.to_schema()]
    back = model_io.from_json(json.loads(json.dumps(model_io.to_json(model))))
    assert back.effects == model.effects
    assert np.isfinite(back.effects[1]["delta_omega_rad_s"])
