"""One line written twice in a model file is refused, by every consumer (the model is parsed once): a new user's
model with its 1x radial-force entry copied was accepted and counted twice (psd's Fx RMS 0.1033 N for 0.0762).
A line's co- and counter-rotating parts (the same h, senses 'co' and 'counter') are two lines and load."""
import json

import numpy as np
import pytest

import rwadist
from rwadist import cli


@pytest.fixture(scope="module")
def model_doc(tmp_path_factory):
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 8), n_samples=2048, seed=2)
    path = tmp_path_factory.mktemp("m") / "wheel.json"
    rwadist.save_model(rwadist.fit(test).model, path)
    return json.loads(path.read_text())


def _write(tmp_path, doc, name="edited.json"):
    p = tmp_path / name
    p.write_text(json.dumps(doc))
    return p


def test_a_copied_entry_is_refused_naming_both(tmp_path, model_doc):
    doc = json.loads(json.dumps(model_doc))
    rf = doc["empirical"]["radial_force"]
    rf.append(dict(rf[0]))
    p = _write(tmp_path, doc)
    with pytest.raises(rwadist.ModelError) as e:
        rwadist.load_model(p)
    msg = str(e.value)
    assert str(p) in msg and f"empirical.radial_force[{len(rf) - 1}]" in msg and "empirical.radial_force[0]" in msg
    assert "counted twice" in msg


def test_the_command_line_refuses_it_with_exit_2(tmp_path, model_doc, capsys):
    doc = json.loads(json.dumps(model_doc))
    doc["empirical"]["radial_force"].append(dict(doc["empirical"]["radial_force"][0]))
    p = _write(tmp_path, doc)
    out = tmp_path / "p.csv"
    assert cli.main(["psd", str(p), "--speed-rpm", "600:2400", "--empirical", "-o", str(out)]) == 2
    assert "counted twice" in capsys.readouterr().err and not out.exists()


def test_co_and_counter_parts_of_one_h_are_two_lines(tmp_path, model_doc):
    doc = json.loads(json.dumps(model_doc))
    rf = doc["empirical"]["radial_force"]
    first = dict(rf[0])
    rf[0] = dict(first, sense="co", C=0.8 * first["C"])
    rf.append(dict(first, sense="counter", C=0.6 * first["C"]))
    m = rwadist.load_model(_write(tmp_path, doc))
    hs = [(x.h, x.sense) for x in m.harmonics("radial_force")]
    assert (first["h"], "co") in hs and (first["h"], "counter") in hs
