"""Wrong things passed to the Python API get a ParameterError naming the parameter and what it expects, never a raw
TypeError from pathlib (new-user trial 29: ``rwadist.fit(model)``, ``rwadist.read(5)``, ``rwadist.load_model(test)``,
``rwadist.save_model(test, ...)``, ``rwadist.write_nastran(model, ...)``); a binary file read where text goes is
named for what it is (an HDF5 test file given as a model was "a damaged file or another encoding"), and a folder
given as an output file is refused naming it."""
import h5py
import numpy as np
import pytest

import rwadist
from rwadist.presets import preset

MODEL = preset("ithaco-e").to_model()


@pytest.fixture(scope="module")
def test_data():
    return rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 6), n_samples=1024, seed=1)


@pytest.mark.parametrize("call, parameter, expected", [
    (lambda t: rwadist.fit(MODEL), "data", "the test data go first"),
    (lambda t: rwadist.fit(None), "data", "expected the path of test data"),
    (lambda t: rwadist.fit(np.zeros((10, 6))), "data", "a ndarray: expected the path of test data"),
    (lambda t: rwadist.diagnose(MODEL), "data", "a model is passed as model"),
    (lambda t: rwadist.read(5), "path", "a int: expected the path of test data"),
    (lambda t: rwadist.load_model(t), "path", "a SteadyTest: expected the path of a model file"),
    (lambda t: rwadist.save_model(t, "x.json"), "model", "a SteadyTest: expected a WheelModel"),
    (lambda t: rwadist.save_model("wheel.json", "y.json"), "model", "a str: expected a WheelModel"),
    (lambda t: rwadist.write_nastran(MODEL, "x.bdf"), "result", "a WheelModel: expected a BroadbandPSD"),
])
def test_a_wrong_type_names_the_parameter(test_data, tmp_path, monkeypatch, call, parameter, expected):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(rwadist.ParameterError, match=rf"^{parameter}: .*{expected}"):
        call(test_data)
    assert not list(tmp_path.iterdir())         # nothing written


def test_a_folder_given_as_the_output_file_is_refused(tmp_path):
    res = rwadist.psd(MODEL, speed_rpm=(600, 2400), empirical=True, n_freq=201, n_speeds=20)
    (tmp_path / "out").mkdir()
    with pytest.raises(rwadist.DataError, match=r"path: .*is a folder: give the path of a file to write"):
        rwadist.write_nastran(res, tmp_path / "out")
    assert not list((tmp_path / "out").iterdir())


def test_an_hdf5_file_given_as_a_model_is_named_hdf5(tmp_path):
    path = tmp_path / "data.h5"
    with h5py.File(path, "w") as f:
        f["x"] = np.arange(3.0)
    with pytest.raises(rwadist.DataError, match=r"an HDF5 file, not text.*a model file is JSON"):
        rwadist.load_model(path)
    with pytest.raises(rwadist.DataError, match=r"an HDF5 file, not text"):
        rwadist.psd(str(path), speed_rpm=(600, 2400), empirical=True)


@pytest.mark.parametrize("call, parameter", [
    (lambda t: rwadist.fit(t, exclude_modes="no"), "exclude_modes"),
    (lambda t: rwadist.simulate_test("ithaco-e", [600.0, 1200.0], modes="off"), "modes"),
    (lambda t: rwadist.psd(MODEL, empirical=1), "empirical"),
    (lambda t: rwadist.read("x", progress="yes"), "progress"),
])
def test_a_switch_given_as_anything_but_true_or_false_is_refused(test_data, call, parameter):
    """``exclude_modes="no"`` was read as True (a non-empty string), the opposite of what was meant (trial 29)."""
    with pytest.raises(rwadist.ParameterError, match=rf"^{parameter}: .*must be True or False"):
        call(test_data)


def test_a_table_of_speeds_is_refused_not_flattened():
    """``simulate_test(speeds_rpm=[[1000, 2000], [1500, 1800]])`` ran the four speeds in the table's order (trial 29)."""
    with pytest.raises(rwadist.ParameterError, match=r"^speeds_rpm: an array of shape \(2, 2\): give one list"):
        rwadist.simulate_test("ithaco-e", speeds_rpm=np.array([[1000, 2000], [1500, 1800]]))
