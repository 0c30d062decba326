"""One element per effect kind (rwadist/effects/, issue 34): every kind is one module that owns everything about it,
the shipped part imports numpy and the schema only, and no other module of the package names a kind."""
from __future__ import annotations

import ast
import copy
import importlib
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rwadist import effects, schema

ROOT = Path(__file__).resolve().parents[1]
EFFECTS = ROOT / "rwadist" / "effects"


def _imports(path: Path) -> set:
    """Top names a module imports (``numpy``, ``dataclasses``, ...); a relative import as ``.`` + its module."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            out.add("." * node.level + (node.module or "") if node.level else (node.module or "").split(".")[0])
    return out


def test_every_registered_kind_is_an_element_module_of_its_own():
    """Each built-in kind is registered by the module rwadist/effects/<kind>.py, one kind per module."""
    builtin = {k: c for k, c in schema.EFFECT_KINDS.items() if c.__module__.startswith("rwadist.effects.")}
    assert len(builtin) == 12
    for kind, cls in builtin.items():
        assert cls.__module__ == f"rwadist.effects.{kind}", (kind, cls.__module__)
    assert set(builtin) <= set(effects.element_module_names())


def test_shipped_element_files_import_numpy_and_the_schema_only():
    """The files the pythonfmu FMU ships (the elements and this package's __init__) run on a host with Python and
    numpy alone: no scipy, no rwadist module but the schema and the units (read as the sibling package's
    ``..schema``, ``..units``)."""
    stdlib = set(sys.stdlib_module_names)
    files = effects.shipped_files()
    assert {f.name for f in files} >= {"__init__.py", "speed_ripple.py"}
    for f in files:
        for name in _imports(f):
            ok = name in stdlib or name in ("numpy", "..schema", "..units") or (name.startswith(".") and
                                                                                 not name.startswith(".."))
            assert ok, (f.name, name)


# ------------------------------------------------------------------ a toy kind registered from one file

@pytest.fixture
def toy():
    """The toy kind of tests/toy_effect.py, registered by importing that one file, unregistered after the test."""
    from rwadist.diagnose.effects import REGISTRY

    sys.modules.pop("toy_effect", None)
    mod = importlib.import_module("toy_effect")
    try:
        yield mod
    finally:
        schema.EFFECT_KINDS.pop(mod.KIND, None)
        REGISTRY.pop(mod.KIND, None)
        sys.modules.pop("toy_effect", None)


def _scaled(model, direction, h, gain):
    """``model`` with the line (direction, h)'s coefficient times ``gain`` (the toy's effect said another way)."""
    out = copy.deepcopy(model)
    out.empirical[direction] = [replace(x, C=x.C * gain) if abs(x.h - h) < 1e-9 else x for x in out.empirical[direction]]
    return out


def test_a_toy_kind_from_one_file_runs_through_stand_diagnose_file_text_psd_and_fmus(toy, tmp_path):
    """tests/toy_effect.py registers a kind (element and diagnose family) and nothing else is edited: the virtual
    stand injects it, ``rwadist.diagnose`` names and fits it from the model without it, the model file types it and
    writes it back byte for byte, the console shows its line, and the PSD, the FMU runtime and the native C FMU
    apply it -- each equal to the same model with that line's coefficient scaled by the fitted gain (a second way
    to the same loads); the pythonfmu FMU, which reads model files with the shipped elements alone, refuses it by
    name."""
    import rwadist
    from rwadist import model as model_io
    from rwadist.effects_text import describe_effect
    from rwadist.fmu import runtime as rt
    from rwadist.inject import parse, simulate_with_injections
    from rwadist.presets import preset

    wheel = preset("ithaco-e")
    truth = wheel.to_model()
    c2 = next(x.C for x in truth.empirical["radial_force"] if x.h == 2.0)
    test = simulate_with_injections(wheel, [parse(f"{toy.KIND}:h=2,gain=2")], np.linspace(600.0, 2400.0, 24),
                                    sample_rate=1920.0, n_samples=4096, modes=False, seed=11, noise=0.01)
    assert test.meta["injected"] == [{"kind": toy.KIND, "direction": "radial_force", "h": 2.0, "gain": 2.0}]

    diagnosis = rwadist.diagnose(test, truth)
    kinds = [e["kind"] for e in diagnosis.model.effects]
    assert kinds[0] == toy.KIND, kinds
    entry = diagnosis.model.effects[0]
    gain = entry["amplitude_ref"] / (c2 * entry["omega_ref_rad_s"] ** 2)
    assert gain == pytest.approx(2.0, rel=0.02)

    path = model_io.save(diagnosis.model, tmp_path / "m.json")
    back = model_io.load(path)
    assert isinstance(back.effects[0], toy.ToyLineGain) and back.effects[0] == entry
    assert model_io.save(back, tmp_path / "b.json").read_bytes() == path.read_bytes()
    assert describe_effect(entry) == (f"toy line gain: radial force, h 2, amplitude {entry['amplitude_ref']:.3g} at "
                                      f"{entry['omega_ref_rad_s'] * 30 / np.pi:.0f} rpm")

    with_toy = copy.deepcopy(truth)
    with_toy.effects = [dict(entry)]
    scaled = _scaled(truth, "radial_force", 2.0, gain)
    for empirical in (True, False):
        a = rwadist.psd(with_toy, (600.0, 2400.0), empirical=empirical, n_freq=801, n_speeds=100)
        b = rwadist.psd(scaled, (600.0, 2400.0), empirical=empirical, n_freq=801, n_speeds=100)
        assert np.allclose(a.psd, b.psd, rtol=1e-9, atol=1e-12 * b.psd.max())
        assert not np.allclose(a.psd, rwadist.psd(truth, (600.0, 2400.0), empirical=empirical, n_freq=801,
                                                    n_speeds=100).psd, rtol=1e-3)

    doc, doc_scaled = model_io.to_json(with_toy), model_io.to_json(scaled)
    t = np.arange(2001) * 1e-3
    speed = 150.0 + 40.0 * np.sin(2 * np.pi * 0.5 * t)
    runs = []
    for d in (doc, doc_scaled):
        params, lines = rt.model_from_doc(d)
        runs.append(rt.WheelRuntime(params, lines, seed=3, modes=True, **rt.effects_from_doc(d)).run(t, speed))
    assert np.allclose(runs[0], runs[1], rtol=0, atol=1e-9 * np.abs(runs[1]).max())
    from rwadist.fmu.build import native_supported

    if native_supported():
        pytest.importorskip("fmpy")
        from fmpy import simulate_fmu

        from rwadist.fmu.native_build import build_native_fmu

        sig = np.array(list(zip(t, speed)), dtype=[("time", float), ("wheel_speed", float)])
        outs = []
        for name, d in (("toy", doc), ("scaled", doc_scaled)):
            res = simulate_fmu(str(build_native_fmu(d, tmp_path / f"{name}.fmu", tag=name)), start_time=0.0,
                               stop_time=2.0, step_size=1e-3, input=sig, start_values={"seed": 3},
                               output=["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"])
            outs.append(np.column_stack([res[c] for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")]))
        assert np.abs(outs[1]).max() > 0
        assert np.allclose(outs[0], outs[1], rtol=0, atol=1e-9 * np.abs(outs[1]).max())

    from rwadist.fmu.build import build_fmu

    with pytest.raises(rt.ModelError, match=f"effects\\[0\\].kind: {toy.KIND!r} .*native"):
        build_fmu(with_toy, tmp_path / "p.fmu", native=False)
