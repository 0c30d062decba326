"""The versioned model file: round trip, older/other schema refused by name, bad fields."""
import json

import numpy as np
import pytest

from rwadist import model as model_io
from rwadist.data import DataError
from rwadist.model import Harmonic, WheelModel, line_amplitudes, model_rms


def _model():
    m = WheelModel(name="t", wheel={"mass_kg": 10.6})
    m.empirical["radial_force"] = [Harmonic(1.0, 3.79e-6, 1e-9, 200, 1.0, [[1600.0, 2200.0]]),
                                   Harmonic(2.0, 7.6e-7, None, 0, None, [])]
    m.empirical["axial_force"] = [Harmonic(1.98, 2.57e-6)]
    m.analytical = {"k_r_N_per_m": 2.17e7}
    m.effects = [{"kind": "x-free_exponent", "h": 2.0}]          # an extension's kind: carried through
    return m


def test_round_trip_is_lossless(tmp_path):
    m = _model()
    back = model_io.load(model_io.save(m, tmp_path / "m.json"))
    assert back == m


def test_other_schema_version_is_refused_by_name(tmp_path):
    doc = model_io.to_json(_model())
    doc["schema_version"] = 0
    p = tmp_path / "old.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(DataError) as err:
        model_io.load(p)
    assert err.value.field == "schema_version" and "version 0" in str(err.value) and str(p) in str(err.value)
    doc["schema"] = "something.else"
    p.write_text(json.dumps(doc))
    with pytest.raises(DataError, match="not an rwadist model"):
        model_io.load(p)


@pytest.mark.parametrize("item,field", [({"h": 1.0}, "C"), ({"h": "x", "C": 1.0}, "h"),
                                        ({"h": 1.0, "C": float("nan")}, "C")])
def test_bad_harmonic_names_the_field(tmp_path, item, field):
    doc = model_io.to_json(_model())
    doc["empirical"]["radial_force"] = [item]
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc).replace("NaN", "NaN"))
    with pytest.raises(DataError) as err:
        model_io.load(p)
    assert err.value.field == f"empirical.radial_force[0].{field}"


def test_truncated_json_names_the_line(tmp_path):
    p = tmp_path / "t.json"
    p.write_text(json.dumps(model_io.to_json(_model()), indent=2)[:200])
    with pytest.raises(DataError, match="not valid JSON"):
        model_io.load(p)


def test_line_amplitudes_and_rms_eq_3_19():
    m = _model()
    w = np.array([-100.0, 0.0, 200.0])
    f, a = line_amplitudes(m, "radial_force", w)
    np.testing.assert_allclose(f[:, 1], 2.0 * np.abs(w) / (2 * np.pi))
    np.testing.assert_allclose(a[:, 0], 3.79e-6 * w**2)
    expected = np.sqrt((3.79e-6**2 + 7.6e-7**2) * w**4 / 2)
    np.testing.assert_allclose(model_rms(m, "radial_force", w), expected)
    # f_max drops the h = 2 line above it
    only1 = model_rms(m, "radial_force", w, f_max=1.5 * 200 / (2 * np.pi))
    np.testing.assert_allclose(only1[2], 3.79e-6 * 200**2 / np.sqrt(2))
