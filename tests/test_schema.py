"""The one typed schema of the model file (rwadist/schema.py): every consumer reads through it and
refuses a bad entry with the same error naming the file and the field; shipped files round-trip
byte for byte."""
import copy
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from rwadist import broadband as bb
from rwadist import extended as ext
from rwadist import model as model_io
from rwadist import schema
from rwadist.cli import main
from rwadist.data import DataError
from rwadist.effects.amplitude_law import AmplitudeLaw
from rwadist.effects.broadband_floor import BroadbandFloor
from rwadist.effects.sidebands import Sidebands
from rwadist.effects.speed_ripple import SpeedRipple
from rwadist.extended_ripple import ripple_from_effects

CATALOGUE = sorted((Path(schema.__file__).parent / "catalogue").glob("*.json"))
BASE = CATALOGUE[[p.name for p in CATALOGUE].index("ithaco-e.json")]

LAW = {"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": 2.5,
       "omega_ref_rad_s": 200.0, "channel": ["Fx", "Fy"], "evidence": {"t": 5.0, "passed": True}}
FLOOR = {"kind": "broadband_floor", "channel": ["Fx"], "exponent": 2.0, "omega_ref_rad_s": 200.0,
         "f_Hz": [10.0, 200.0], "psd_ref": [1e-6]}
#: the two bad entries of the issue and the message every consumer must give
BAD = [(LAW, "effects[0].amplitude_ref: missing"),
       (FLOOR, "effects[0].psd_ref: has 1 values for 2 f_Hz knots (one per knot)")]


def base_doc():
    return json.loads(BASE.read_text())


def write(tmp_path, effects):
    doc = base_doc()
    doc["effects"] = effects
    p = tmp_path / "model.json"
    p.write_text(json.dumps(doc, indent=2))
    return p, doc


# ------------------------------------------------------------------ round trip

@pytest.mark.parametrize("path", CATALOGUE, ids=lambda p: p.stem)
def test_catalogue_file_round_trips_byte_for_byte(path, tmp_path):
    m = model_io.load(path)
    assert isinstance(m.analytical, schema.Analytical)
    out = model_io.save(m, tmp_path / path.name)
    assert out.read_bytes() == path.read_bytes()


def test_effects_round_trip_typed_and_equal_to_their_json(tmp_path):
    ok_law = dict(LAW, amplitude_ref=0.01, h=2)                   # an int h stays an int in the file
    rip = {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 0.5, "omega_ref_rad_s": 200.0,
           "law": "text kept"}
    other = {"kind": "x-suspension_modes_from_the_future", "x": [1, 2]}     # an extension: carried, unused
    p, doc = write(tmp_path, [ok_law, dict(FLOOR, psd_ref=[1e-6, 2e-6]), rip, other])
    m = model_io.load(p)
    law, floor, ripple, unknown = m.effects
    assert isinstance(law, AmplitudeLaw) and law.law == (0.01, 200.0, 2.5) and law["h"] == 2
    assert isinstance(floor, BroadbandFloor) and floor.channel_indices == (0,)
    assert isinstance(ripple, SpeedRipple) and ripple.speed_exponent == 0.0 and "speed_exponent" not in ripple
    assert isinstance(unknown, schema.UnknownEffect) and unknown.kind == other["kind"]
    assert m.effects == doc["effects"]                           # effects equal the JSON they came from
    back = model_io.save(m, tmp_path / "back.json")
    assert json.loads(back.read_text()) == doc
    # an effect made in code serialises from its fields
    made = Sidebands(direction="axial_force", h=1.0, f_mod_Hz=3.0, depth=0.1)
    assert made.to_json() == {"kind": "sidebands", "direction": "axial_force", "h": 1.0, "f_mod_Hz": 3.0,
                              "depth": 0.1}
    assert schema.parse_effect(made.to_json()) == made


# ------------------------------------------------------------------ the same error everywhere

def _assert_same(exc, path, tail):
    assert isinstance(exc, schema.ModelError)
    assert str(exc) == f"{path}: {tail}"
    assert exc.field == tail.split(":")[0]


@pytest.mark.parametrize("entry, tail", BAD, ids=["law_without_amplitude_ref", "floor_2_knots_1_psd"])
def test_model_load_refuses(tmp_path, entry, tail):
    p, _ = write(tmp_path, [entry])
    with pytest.raises(DataError) as info:
        model_io.load(p)
    _assert_same(info.value, p, tail)


@pytest.mark.parametrize("entry, tail", BAD, ids=["law_without_amplitude_ref", "floor_2_knots_1_psd"])
def test_psd_refuses(tmp_path, entry, tail, capsys):
    """``rwadist psd`` (the CLI) and rwadist.broadband (a model built in code) give the same message."""
    p, doc = write(tmp_path, [entry])
    assert main(["psd", str(p), "--speed-rpm", "1000:2000", "-o", str(tmp_path / "psd.csv")]) == 2
    assert capsys.readouterr().err.strip() == f"rwadist: error: {p}: {tail}"
    m = model_io.load(BASE)
    m.effects = [entry]
    for build in (bb.empirical_lines, bb.extended_lines_from_model):
        with pytest.raises(schema.ModelError) as info:
            build(m)
        _assert_same(info.value, "<model>", tail)


@pytest.mark.parametrize("entry, tail", BAD, ids=["law_without_amplitude_ref", "floor_2_knots_1_psd"])
def test_extended_kit_refuses(entry, tail):
    m = model_io.load(BASE)
    m.effects = [entry]
    for read in (lambda: ext.lines_from_model(m, ext.params_from_model(m)), lambda: ext.line_effects(m.effects),
                 lambda: ripple_from_effects(m.effects)):
        with pytest.raises(schema.ModelError) as info:
            read()
        _assert_same(info.value, "<model>", tail)


@pytest.mark.parametrize("entry, tail", BAD, ids=["law_without_amplitude_ref", "floor_2_knots_1_psd"])
def test_fmu_build_and_runtime_refuse(tmp_path, entry, tail, capsys):
    pytest.importorskip("pythonfmu")
    from rwadist.fmu import runtime as rt
    from rwadist.fmu.build import build_fmu

    p, doc = write(tmp_path, [entry])
    with pytest.raises(rt.ModelError) as info:
        build_fmu(p, tmp_path / "x.fmu")
    _assert_same(info.value, p, tail)
    with pytest.raises(rt.ModelError) as info:
        rt.effects_from_doc(doc, str(p))
    _assert_same(info.value, p, tail)
    assert main(["fmu", "build", str(p), "-o", str(tmp_path / "y.fmu")]) == 2
    assert capsys.readouterr().err.strip() == f"rwadist: error: {p}: {tail}"


@pytest.mark.parametrize("entry, tail", BAD, ids=["law_without_amplitude_ref", "floor_2_knots_1_psd"])
def test_coupling_refuses(entry, tail):
    pytest.importorskip("control")
    from rwadist.coupling import performance as cp
    from rwadist.coupling.errors import CouplingError

    m = model_io.load(BASE)
    m.effects = [entry]
    with pytest.raises(CouplingError) as info:
        cp.wheel_spec_from_model(m)
    _assert_same(info.value, "<model>", tail)
    with pytest.raises(CouplingError) as info:
        cp.floors_from_effects([entry], "w.json")
    _assert_same(info.value, "w.json", tail)


# ------------------------------------------------------------------ strict types

HARM = {"h": 1.0, "C": 1e-6}


@pytest.mark.parametrize("item, field, words", [
    ({"h": True, "C": 1e-6}, "h", "finite number"),                    # a boolean is not a number
    (dict(HARM, presence=1.5), "presence", "<= 1"),
    (dict(HARM, C_stderr=-1e-9), "C_stderr", ">= 0"),
    (dict(HARM, n_points=3.0), "n_points", "integer"),
    (dict(HARM, n_points=-1), "n_points", "integer >= 0"),
    (dict(HARM, excluded_rpm=[[2000.0, 1000.0]]), "excluded_rpm[0]", "lo <= hi"),
    (dict(HARM, excluded_rpm=[1000.0, 2000.0]), "excluded_rpm[0]", "pair"),
    (dict(HARM, excluded_rpm="1000-2000"), "excluded_rpm", "list"),
    (dict(HARM, sense="sideways"), "sense", "not one of"),
])
def test_bad_harmonic_field_is_named(item, field, words):
    doc = base_doc()
    doc["empirical"]["axial_force"] = [item]
    with pytest.raises(schema.ModelError, match=words) as info:
        model_io.from_json(doc, "w.json")
    assert info.value.field == f"empirical.axial_force[0].{field}"


OK_SB = {"kind": "sidebands", "direction": "axial_force", "h": 1.0, "f_mod_Hz": 3.0, "depth": 0.1}


@pytest.mark.parametrize("entry, field", [
    (dict(OK_SB, f_mod_Hz=0.0), "f_mod_Hz"), (dict(OK_SB, depth=False), "depth"), (dict(OK_SB, h="1"), "h"),
    (dict(OK_SB, n_points=2.5), "n_points"), (dict(FLOOR, f_Hz=[10.0, 5.0], psd_ref=[1.0, 1.0]), "f_Hz"),
    (dict(FLOOR, f_Hz=[10.0], psd_ref=[1.0]), "f_Hz"), (dict(FLOOR, psd_ref=[1.0, -1.0]), "psd_ref"),
    (dict(FLOOR, channel="Fq"), "channel"), (dict(FLOOR, channel=[]), "channel"),
    ({"kind": "fixed_resonance", "f_Hz": 50.0, "zeta": 0.01, "peak_gain": 3.0, "role": "wheel_mode",
      "directions": "sideways"}, "directions"),
    ({"kind": "counter_rotation", "direction": "radial_force", "h": 2.0, "counter_fraction": 1.2}, "counter_fraction"),
    ({"kind": "cross_coupling", "r_m": [0.0, 0.01]}, "r_m"),
    ({"kind": "spin_acceleration", "alpha_rad_s2": float("inf")}, "alpha_rad_s2"),
    ({"kind": 3}, "kind"), ({"h": 1.0}, "kind"),
])
def test_bad_effect_field_is_named(entry, field):
    with pytest.raises(schema.ModelError) as info:
        schema.parse_effects([OK_SB, entry], "w.json")
    assert info.value.field == f"effects[1].{field}"


def test_analytical_optional_fields():
    doc = base_doc()
    doc["analytical"] = dict(doc["analytical"], modes_assumed=True, unconstrained=["rocking"])
    m = model_io.from_json(doc)
    assert m.analytical.modes_assumed is True and m.analytical.unconstrained == ("rocking",)
    assert model_io.to_json(m)["analytical"] == doc["analytical"]
    for key, bad in (("modes_assumed", 1), ("unconstrained", "rocking"), ("unconstrained", ["wobble"]),
                     ("k_r_N_per_m", True), ("k_z_N_per_m", -1.0)):
        d = copy.deepcopy(doc)
        d["analytical"][key] = bad
        with pytest.raises(DataError) as info:
            model_io.from_json(d, "w.json")
        assert info.value.field in (f"analytical.{key}", "analytical"), info.value
    assert model_io.from_json(base_doc()).analytical.modes_assumed is None    # absent: old behaviour


def test_a_new_kind_is_one_small_class():
    """Registering a kind is a class with its checked fields; the registry does the rest."""
    @dataclass(frozen=True, eq=False, kw_only=True)
    class Wobble(schema.Effect):
        KIND: ClassVar[str] = "test_wobble"
        h: float = field(metadata=schema.check(schema.number(gt=0)))

    schema.register(Wobble)
    try:
        e, = schema.parse_effects([{"kind": "test_wobble", "h": 2.0, "note": "x"}])
        assert isinstance(e, Wobble) and e.h == 2.0 and e.to_json()["note"] == "x"
        with pytest.raises(schema.ModelError, match=r"effects\[0\]\.h: must be a finite number > 0"):
            schema.parse_effects([{"kind": "test_wobble", "h": np.nan}])
        with pytest.raises(ValueError, match="registered twice"):
            schema.register(Wobble)
    finally:
        del schema.EFFECT_KINDS["test_wobble"]


# ------------------------------------------------------------------ JSON Schema (docs/model.schema.json)

ROOT = Path(__file__).resolve().parents[1]
EVERY_KIND = [
    {"kind": "missing_harmonic", "direction": "axial_force", "h": 3.1, "C": 1e-8, "channel": ["Fz"]},
    dict(LAW, amplitude_ref=0.01, exponent_stderr=None),
    dict(FLOOR, psd_ref=[1e-6, 2e-6], psd_law="text", unit="N^2/Hz"),
    {"kind": "fixed_resonance", "f_Hz": 50.0, "zeta": 0.02, "peak_gain": 3.0, "role": "test_stand",
     "directions": ["radial_force"], "n_points": 12},
    {"kind": "cross_coupling", "r_m": [0.0, 0.01, -0.02], "r_stderr_m": [1e-4, 1e-4, 1e-4], "n_points": 30},
    dict(OK_SB, n_points=8),
    {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 0.5, "omega_ref_rad_s": 200.0,
     "speed_exponent": 1.0},
    {"kind": "counter_rotation", "direction": "radial_force", "h": 2.0, "counter_fraction": 0.3,
     "counter_fraction_stderr": 0.01, "counter_fraction_phase": -1.2, "n_points": 9},
    {"kind": "spin_acceleration", "alpha_rad_s2": 2.0, "alpha_track_rad_s2": None, "role": "measurement"},
    {"kind": "suspension_modes", "radial_translation_Hz": 227.0, "rocking_Hz": 55.0, "axial_Hz": 70.0,
     "zeta_radial_translation": 0.17, "zeta_rocking": 0.04, "zeta_axial": 0.05, "inertia_ratio": 2.0,
     "unconstrained": ["axial"], "per_unit": True, "n_runs": 60, "channel": ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"]},
    {"kind": "speed_sidebands", "direction": "radial_force", "h": 1.0, "h_lower": 0.94, "h_upper": 1.06,
     "C_lower": 1.0e-7, "C_upper": 1.1e-7, "n_points": 12, "per_rev": 0.06, "ratio_lower": 0.2},
    {"kind": "lever_arm_noise", "r_m": [0.0, 0.0, -0.06], "noise_transfer": 1.01, "noise_transfer_stderr": 0.005,
     "n_points": 40, "floor_rise_dB": {"Tx": 2.5, "Ty": 2.5}, "role": "measurement"},
]


@pytest.fixture(scope="module")
def validator():
    jsonschema = pytest.importorskip("jsonschema")
    doc = json.loads((ROOT / "docs" / "model.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(doc)
    return jsonschema.Draft202012Validator(doc)


def test_json_schema_is_generated_from_the_typed_schema():
    from rwadist.schema_json import json_schema
    assert set(schema.EFFECT_KINDS) == {e["kind"] for e in EVERY_KIND}      # every kind is exercised below
    assert json.loads((ROOT / "docs" / "model.schema.json").read_text()) == json_schema(), \
        "docs/model.schema.json is stale: python -m rwadist.schema_json docs/model.schema.json"


def test_every_shipped_model_file_validates(validator):
    shipped = CATALOGUE + sorted((ROOT / "examples").rglob("*.json"))
    assert len(shipped) >= 12
    for path in shipped:
        doc = json.loads(path.read_text())
        assert not list(validator.iter_errors(doc)), path
        model_io.from_json(doc, str(path))
    doc = base_doc()
    doc["effects"] = EVERY_KIND
    assert not list(validator.iter_errors(doc))
    assert [type(e).KIND for e in model_io.from_json(doc).effects] == [e["kind"] for e in EVERY_KIND]


def _mutate(path, value):
    doc = base_doc()
    doc["effects"] = copy.deepcopy(EVERY_KIND)
    target = doc
    for key in path[:-1]:
        target = target[key]
    if value is KeyError:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return doc


@pytest.mark.parametrize("path, value", [
    (("effects", 1, "amplitude_ref"), KeyError), (("effects", 1, "h"), True), (("effects", 2, "channel"), "Fq"),
    (("effects", 2, "psd_ref"), [1e-6, -1.0]), (("effects", 3, "role"), "fixture"),
    (("effects", 4, "r_m"), [0.0, 0.01]), (("effects", 5, "f_mod_Hz"), 0.0), (("effects", 6, "f_ripple_Hz"), "4"),
    (("effects", 7, "counter_fraction"), 1.5), (("effects", 5, "n_points"), -3),
    (("empirical", "radial_force", 0, "presence"), 2.0), (("empirical", "radial_force", 0, "C"), KeyError),
    (("analytical", "k_r_N_per_m"), -1.0), (("analytical", "modes_assumed"), "yes"),
    (("analytical", "unconstrained"), ["wobble"]), (("schema_version",), 2),
])
def test_mutated_documents_are_refused_by_both(validator, path, value):
    doc = _mutate(path, value)
    assert list(validator.iter_errors(doc)), path
    with pytest.raises(schema.ModelError):
        model_io.from_json(doc, "m.json")


def test_fmu_runtime_reads_through_its_own_copy_without_rwadist(tmp_path):
    """Inside a built FMU the runtime imports the shipped schema copy and the shipped effect elements (rwadist
    blocked from import), reads every kind and refuses the bad entry with the same message."""
    pytest.importorskip("pythonfmu")
    import subprocess
    import sys
    import zipfile

    from rwadist.fmu.build import build_fmu

    fmu = build_fmu(BASE, tmp_path / "w.fmu", native=False)
    zipfile.ZipFile(fmu).extractall(tmp_path / "x")
    res = tmp_path / "x" / "resources"
    p, _ = write(tmp_path, [LAW])
    code = f"""
import importlib.util, json, sys
sys.modules["rwadist"] = None                      # any 'import rwadist' fails
spec = importlib.util.spec_from_file_location("fmu_rt", {str(res / "rwadist_fmu_runtime.py")!r})
rt = importlib.util.module_from_spec(spec); spec.loader.exec_module(rt)
assert rt._schema.__file__ == {str(res / "rwadist_model_schema.py")!r}, rt._schema.__file__
# every element the schema copy reads is a shipped copy (rwadist/effects/<kind>.py)
kinds = rt._schema.EFFECT_KINDS
assert all(sys.modules[c.__module__].__file__.startswith({str(res / "rwadist_model_effects")!r}) for c in kinds.values())
print(json.dumps(sorted(kinds)))
doc = json.load(open({str(p)!r}))
try:
    rt.effects_from_doc(doc, {str(p)!r})
except rt.ModelError as exc:
    print(exc)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    kinds, message = out.stdout.strip().splitlines()
    assert json.loads(kinds) == sorted(schema.EFFECT_KINDS)
    assert message == f"{p}: effects[0].amplitude_ref: missing"
    # the shipped elements are rwadist's, byte for byte
    from rwadist import effects

    shipped = sorted((res / "rwadist_model_effects").iterdir())
    assert [f.name for f in shipped] == sorted(f.name for f in effects.shipped_files())
    for f in effects.shipped_files():
        assert (res / "rwadist_model_effects" / f.name).read_bytes() == f.read_bytes(), f.name
    from rwadist import units

    assert (res / "rwadist_model_units.py").read_bytes() == Path(units.__file__).read_bytes()
