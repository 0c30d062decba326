"""A model whose analytical.unconstrained lists modes: psd, campbell, fmu build and diagnose say so (stderr), once,
naming the file and the modes; a model without the list (or with it empty) gives no warning."""
import pytest

from rwadist import model as model_io
from rwadist.cli import main
from rwadist.extended_fit import unconstrained_warning
from rwadist.presets import preset


@pytest.fixture()
def model_file(tmp_path):
    m = preset("ithaco-e").to_model()
    m.analytical["unconstrained"] = ["rocking"]
    return model_io.save(m, tmp_path / "m.json")


def test_warning_text_names_modes_and_file():
    m = preset("ithaco-e").to_model()
    assert unconstrained_warning(m, "x.json", "the PSD") is None
    m.analytical["unconstrained"] = []
    assert unconstrained_warning(m, "x.json", "the PSD") is None
    m.analytical["unconstrained"] = ["rocking", "axial"]
    text = unconstrained_warning(m, "x.json", "the PSD")
    assert "x.json" in text and "'rocking'" in text and "'axial'" in text and "starting values" in text


def test_held_damping_warns_as_a_held_value_not_a_lost_mode(tmp_path):
    """A located mode whose damping the data do not measure (zeta_rocking, rwadist.extended_fit_damping): the warning
    says the damping is held inside the data's bounds, not that the mode was not identified; the file round-trips."""
    m = preset("ithaco-e").to_model()
    m.analytical["unconstrained"] = ["zeta_rocking"]
    text = unconstrained_warning(m, "x.json", "the PSD")
    assert "damping of rocking is held" in text and "could not identify" not in text
    m.analytical["unconstrained"] = ["axial", "zeta_rocking"]
    text = unconstrained_warning(m, "x.json", "the PSD")
    assert "could not identify this mode" in text and "damping of rocking is held" in text
    back = model_io.load(model_io.save(m, tmp_path / "m.json"))
    assert list(back.analytical["unconstrained"]) == ["axial", "zeta_rocking"]


def test_psd_warns(model_file, tmp_path, capsys):
    assert main(["psd", str(model_file), "--speed-rpm", "500:1500", "--n-freq", "200", "--n-speeds", "20",
                 "-o", str(tmp_path / "p.csv")]) == 0
    err = capsys.readouterr().err
    assert err.count("analytical.unconstrained") == 1 and "the PSD" in err


def test_fmu_build_warns(model_file, tmp_path, capsys):
    pytest.importorskip("pythonfmu")
    assert main(["fmu", "build", str(model_file), "-o", str(tmp_path / "w.fmu")]) == 0
    err = capsys.readouterr().err
    assert err.count("analytical.unconstrained") == 1 and "the FMU" in err


def test_diagnose_warns(model_file, tmp_path, capsys):
    data = tmp_path / "d"
    assert main(["simulate-test", str(data), "--preset", "ithaco-e", "--speeds-rpm", "600:2400", "--n-speeds", "6",
                 "--samples", "2048", "--sample-rate", "1920"]) == 0
    main(["diagnose", str(data), "-o", str(tmp_path / "r"), "--model", str(model_file)])
    err = capsys.readouterr().err
    assert err.count("analytical.unconstrained") == 1 and "diagnose" in err


def test_campbell_warns(model_file, tmp_path, capsys):
    """The Campbell diagram draws the modes the model file holds: one it lists as unconstrained is its starting value
    (an all-unconstrained fitted model printed an empty crossing table and nothing else)."""
    assert main(["campbell", str(model_file), "--speeds-rpm", "0:3000:500", "-o", str(tmp_path / "c.csv")]) == 0
    err = capsys.readouterr().err
    assert err.count("analytical.unconstrained") == 1 and "the Campbell diagram" in err
