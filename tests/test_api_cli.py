"""The Python API and the command line give the same numbers for the same request (issue 34): one test per
command, each running the command a user types (``rwadist.cli.main``) beside the API call it stands for, and
the refusals the same on both sides (a ParameterError naming the parameter, exit 2 naming its flag)."""
from __future__ import annotations

import json
import re
import zipfile

import numpy as np
import pytest
from cli_run import run

import rwadist
from rwadist import catalogue, psd_files
from rwadist import model as model_io
from rwadist.cli import main

HR16 = "honeywell-hr16-75"
SPEEDS = "600:2400"
N_SPEEDS = 8



@pytest.fixture(scope="module")
def steady(tmp_path_factory):
    """A small steady test written by the command line, and the API's simulation of the same request."""
    path = tmp_path_factory.mktemp("steady") / "e"
    assert main(["simulate-test", str(path), "--preset", "ithaco-e", "--speeds-rpm", SPEEDS, "--n-speeds",
                 str(N_SPEEDS), "--samples", "2048", "--sample-rate", "1920", "--seed", "4"]) == 0
    test = rwadist.simulate_test("ithaco-e", np.linspace(600, 2400, N_SPEEDS), n_samples=2048, sample_rate=1920.0,
                                 seed=4)
    return path, test


def test_simulate_test(steady):
    path, test = steady
    written = rwadist.read(path)
    assert [r.speed for r in written.runs] == pytest.approx([r.speed for r in test.runs], rel=1e-12)
    for a, b in zip(written.runs, test.runs):
        assert a.channels == b.channels and a.sample_rate == b.sample_rate
        for ch in a.channels:
            np.testing.assert_allclose(a.signals[ch], b.signals[ch], rtol=1e-12, atol=1e-15)


def test_simulate_sweep(tmp_path, capsys):
    code, _, _ = run(capsys, "simulate-test", tmp_path / "s", "--preset", "ithaco-e", "--sweep", "--sweep-end-rpm",
                     "1200", "--duration", "4", "--sample-rate", "960", "--seed", "2")
    assert code == 0
    from rwadist.data import read_data

    written = read_data(tmp_path / "s" / "sweep.csv")
    sweep = rwadist.simulate_sweep("ithaco-e", 0.0, 1200.0, duration=4.0, sample_rate=960.0, seed=2)
    np.testing.assert_allclose(written.time, sweep.time, rtol=0, atol=1e-12)
    for ch in sweep.signals:
        np.testing.assert_allclose(written.signals[ch], sweep.signals[ch], rtol=1e-12, atol=1e-15)


def test_simulate_refusals_are_the_same(tmp_path, capsys):
    """A datasheet wheel's assumed modes: extended physics refused on both sides unless asked for."""
    with pytest.raises(rwadist.ParameterError) as err:
        rwadist.simulate_test(HR16, [3000.0], n_samples=256, physics="extended")
    assert err.value.parameter == "physics" and "assumed" in str(err.value)
    code, _, text = run(capsys, "simulate-test", tmp_path / "x", "--preset", HR16, "--speeds-rpm", "3000",
                        "--samples", "256", "--physics", "extended")
    assert code == 2 and "--physics: value: 'extended'" in text and "--assumed-modes" in text
    with pytest.warns(rwadist.RwadistWarning, match="ASSUMED"):
        test = rwadist.simulate_test(HR16, [3000.0], n_samples=256, physics="extended", assumed_modes=True)
    assert "ASSUMED" in test.meta["modes_assumed"]


def _model_numbers(model) -> dict:
    doc = model_io.to_json(model)
    return {k: doc.get(k) for k in ("empirical", "analytical", "effects")}


def test_fit(steady, tmp_path, capsys):
    path, _ = steady
    code, _, _ = run(capsys, "fit", path, "-o", tmp_path / "m.json", "--no-report", "--presence", "0.4")
    assert code == 0
    fitted = rwadist.fit(path, presence=0.4)
    assert _model_numbers(rwadist.load_model(tmp_path / "m.json")) == _model_numbers(fitted.model)
    assert sum(len(v) for v in fitted.model.empirical.values()) > 3


@pytest.mark.parametrize("presence", [2.0, -1.0, 0.0, float("nan")])
def test_fit_refuses_a_presence_outside_its_range(steady, tmp_path, capsys, presence):
    """presence=2.0 returned a model without harmonics and -1 was taken, where --presence 2 was refused."""
    path, test = steady
    with pytest.raises(rwadist.ParameterError) as err:
        rwadist.fit(test, presence=presence)
    assert err.value.parameter == "presence" and str(err.value).startswith("presence: ") and "(0, 1]" in str(err.value)
    code, _, text = run(capsys, "fit", path, "-o", tmp_path / "m.json", "--no-report", "--presence", str(presence))
    assert code == 2 and "--presence: value:" in text and "(0, 1]" in text


def test_fit_extended(steady, tmp_path, capsys):
    path, _ = steady
    code, out, _ = run(capsys, "fit", path, "-o", tmp_path / "m.json", "--no-report", "--extended", "--mass", "10.6",
                       "--radius", "0.2")
    assert code == 0 and "radial translation" in out
    _, model = rwadist.fit_extended(path, rwadist.fit(path), mass=10.6, radius=0.2)
    assert _model_numbers(rwadist.load_model(tmp_path / "m.json")) == _model_numbers(model)
    with pytest.raises(rwadist.ParameterError, match="radius"):
        rwadist.fit_extended(path, mass=10.6)
    code, _, text = run(capsys, "fit", path, "-o", tmp_path / "m2.json", "--extended", "--mass", "10.6")
    assert code == 2 and "--mass: value: needs --radius too" in text


def test_model_show_and_compare(steady, tmp_path, capsys):
    path, _ = steady
    model = rwadist.fit(path).model
    file = rwadist.save_model(model, tmp_path / "m.json")
    code, out, _ = run(capsys, "model", "show", file, "--format", "json")
    assert code == 0 and json.loads(out) == model_io.to_json(rwadist.load_model(file))
    code, out, _ = run(capsys, "model", "show", file, "--format", "csv")
    rows = [line.split(",") for line in out.strip().splitlines()[1:]]
    want = [(d, h.h, h.C, "" if d.startswith("axial") else (h.sense or "co"))
            for d in model_io.DIRECTIONS for h in model.harmonics(d)]
    assert [(d, float(h), float(c), sense) for d, h, c, _, sense in rows] == want
    code, out, _ = run(capsys, "model", "compare", file, "--preset", "ithaco-e")
    res = catalogue.compare(rwadist.load_model(file), catalogue.load("ithaco-e"))
    printed = re.findall(r"^(\w+_\w+) +([\d.]+) +([\d.e+-]+) +([\d.]+) +([\d.e+-]+)", out, flags=re.M)
    matched = [(d, f"{hf:.3f}", f"{cf:.3e}", f"{hr:.3f}", f"{cr:.3e}") for d, hf, cf, hr, cr in res["harmonics"]
               if hf is not None and hr is not None]
    assert code in (0, 1) and printed == matched and matched


def test_campbell(tmp_path, capsys):
    code, out, _ = run(capsys, "campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:250", "-o",
                       tmp_path / "c.csv")
    assert code == 0
    table, rows = rwadist.campbell(preset="ithaco-e", speeds_rpm=np.arange(0.0, 3001.0, 250.0))
    lines = (tmp_path / "c.csv").read_text().splitlines()
    assert lines[0].split(",") == list(table)
    written = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    np.testing.assert_array_equal(written, np.column_stack([table[c] for c in table]))     # repr: exact
    printed = re.findall(r"^ *([\d.]+) (\w+) +(\w+) +(\w+) +([\d.]+) +([\d.]+)", out, flags=re.M)
    assert printed == [(f"{r['h']:g}", r["direction"], r["sense"], r["mode"], f"{r['speed_rpm']:.2f}",
                        f"{r['f_Hz']:.2f}") for r in rows] and rows
    code, _, text = run(capsys, "campbell", "--preset", "ithaco-e", "--speeds-rpm", "1000,-1000", "-o",
                        tmp_path / "c2.csv")
    assert code == 2 and "--speeds-rpm: value: gives one speed" in text
    with pytest.raises(rwadist.ParameterError, match="speeds_rpm: gives one speed"):
        rwadist.campbell(preset="ithaco-e", speeds_rpm=[1000.0, -1000.0])


PSD_SIZE = ("--n-freq", "401", "--n-speeds", "100")


def _same_file(written, result, writer, tmp_path):
    """``written`` (by the command line) byte for byte what ``writer`` makes of the API's ``result``."""
    mine = writer(result, tmp_path / ("api_" + written.name))
    assert written.read_bytes() == mine.read_bytes()


@pytest.mark.parametrize("assumed", [False, True])
def test_psd_of_the_datasheet_wheel(tmp_path, capsys, assumed):
    """The HR16-75 (assumed suspension modes) over 0-6000 rpm: hard-mounted by default on both sides, through its
    assumed modes on request on both sides; the CLI's table is the API's, byte for byte."""
    out = tmp_path / "p.csv"
    code, text, _ = run(capsys, "psd", "--preset", HR16, "--speed-rpm", "0:6000", *PSD_SIZE, "-o", out,
                        *(["--assumed-modes"] if assumed else []))
    assert code == 0
    res = rwadist.psd(preset=HR16, speed_rpm=(0, 6000), n_freq=401, n_speeds=100, assumed_modes=assumed)
    assert res.meta["model"] == ("extended" if assumed else "empirical")
    _same_file(out, res, psd_files.write_psd_csv, tmp_path)
    _same_file(tmp_path / "p_cross.csv", res, psd_files.write_cross_csv, tmp_path)
    rms = re.search(r"RMS: Fx ([\d.e+-]+) N, Fy [\d.e+-]+ N, Fz [\d.e+-]+ N, Tx ([\d.e+-]+) N·m", text)
    assert rms.groups() == (f"{res.rms()[0]:.4g}", f"{res.rms()[3]:.4g}")
    # hard-mounted, every line is C·Ω² with its own random phase: a radial channel's mean square is Σ C² E[Ω⁴]/2 over
    # the uniform law, E[Ω⁴] = Ω_max⁴/5 from 0 (closed form); every line lies below the default fmax
    if not assumed:
        model = catalogue.load(HR16)
        w4 = (6000 * 2 * np.pi / 60) ** 4 / 5
        for ch, d in ((0, "radial_force"), (3, "radial_torque")):
            want = sum(h.C**2 for h in model.harmonics(d)) * w4 / 2
            assert res.mean_square()[ch] == pytest.approx(want, rel=1e-3)


def test_psd_of_a_wheel_set_and_its_nastran_cards(tmp_path, capsys):
    """``--wheels`` and ``wheels=``: one spacecraft-frame CSD; the NASTRAN deck the same file either way."""
    pytest.importorskip("pyNastran")
    wheels = [{"name": "A", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 0}},
              {"name": "B", "preset": HR16, "mounting": {"preset": "pyramid-4", "index": 1},
               "speed": {"dist": "uniform", "min_rpm": 1000, "max_rpm": 5000}}]
    wj = tmp_path / "wheels.json"
    wj.write_text(json.dumps({"wheels": wheels}))
    out = tmp_path / "set.bdf"
    code, text, _ = run(capsys, "psd", "--wheels", wj, "--speed-rpm", "300:2400", *PSD_SIZE, "--format", "nastran",
                        "--nastran-cross", "-o", out)
    assert code == 0 and "wheels B have assumed suspension modes" in text
    res = rwadist.psd(wheels=wj, speed_rpm=(300, 2400), n_freq=401, n_speeds=100)
    assert res.frame == "spacecraft" and res.meta["hard_mounted_wheels"] == ["B"]
    _same_file(out, res, lambda r, p: (rwadist.write_nastran(r, p, cross=True), p)[1], tmp_path)
    _same_file(tmp_path / "set_cross.csv", res, psd_files.write_cross_csv, tmp_path)
    # the same set given as Python objects
    inline = rwadist.psd(wheels=wheels, speed_rpm=(300, 2400), n_freq=401, n_speeds=100)
    np.testing.assert_array_equal(inline.csd, res.csd)


@pytest.fixture(scope="module")
def hr16_data(tmp_path_factory):
    data = tmp_path_factory.mktemp("hr16") / "t"
    assert main(["simulate-test", str(data), "--preset", HR16, "--speeds-rpm", "2000,4000,6000",
                 "--samples", "2048"]) == 0
    return data


@pytest.mark.parametrize("given", ["preset", "model file"])
def test_diagnose_of_the_datasheet_wheel(hr16_data, tmp_path, capsys, given):
    """diagnose from the HR16-75 (its preset, or its catalogue model file) on its hard-mounted data: the same
    hard-mounted starting base (its assumed modes not used), effects, errors and model either way."""
    start = {"preset": HR16} if given == "preset" else {"model": str(catalogue.path(HR16))}
    flag = ["--preset", HR16] if given == "preset" else ["--model", start.get("model")]
    code, out, _ = run(capsys, "diagnose", hr16_data, *flag, "-o", tmp_path / "r")
    assert code == 0
    diag = rwadist.diagnose(hr16_data, **start)
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert diag.state_before.base == "empirical" and "empirical" in out
    assert f"{diag.error_before:.4g} -> {diag.error_after:.4g}" in out
    assert [e["kind"] for e in summary["effects"]] == [e["kind"] for e in diag.summary()["effects"]]
    assert _model_numbers(rwadist.load_model(tmp_path / "r" / "model.json")) == _model_numbers(diag.model)


def test_fmu_build(tmp_path, capsys):
    """The datasheet wheel's FMU: the same model inside and the same start values (hard-mounted) either way."""
    pytest.importorskip("pythonfmu")
    code, _, _ = run(capsys, "fmu", "build", "--preset", HR16, "-o", tmp_path / "cli.fmu")
    assert code == 0
    rwadist.build_fmu(preset=HR16, path=tmp_path / "api.fmu")

    def inside(path):
        with zipfile.ZipFile(path) as z:
            names = sorted(n for n in z.namelist() if n.endswith(".json"))
            xml = z.read("modelDescription.xml").decode()
            return {n.split("/")[-1]: json.loads(z.read(n)) for n in names}, re.findall(
                r'name="(\w+)"[^>]*?>\s*<Real[^>]*start="([^"]+)"', xml)

    assert inside(tmp_path / "cli.fmu") == inside(tmp_path / "api.fmu")


def test_convert(steady, tmp_path, capsys):
    path, test = steady
    code, _, _ = run(capsys, "convert", path, "-o", tmp_path / "t.h5")
    assert code == 0
    back = rwadist.read(tmp_path / "t.h5")
    for a, b in zip(back.runs, rwadist.read(path).runs):
        assert a.speed == b.speed and all(np.array_equal(a.signals[c], b.signals[c]) for c in a.channels)


def test_catalogue(capsys):
    code, out, _ = run(capsys, "catalogue", "list")
    assert code == 0 and [line.split()[0] for line in out.splitlines()[1:]] == catalogue.names()
    code, out, _ = run(capsys, "catalogue", "show", HR16)
    model = catalogue.load(HR16)
    assert code == 0 and all(f"{h.C:12.4e}" in out for d in model_io.DIRECTIONS for h in model.harmonics(d))
    code, _, text = run(capsys, "catalogue", "show", "no-such-wheel")
    assert code == 2 and "NAME: value: 'no-such-wheel'" in text
