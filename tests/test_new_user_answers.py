"""What a new user met (2026-11-28 trial in a fresh clone), each answered: a misspelt model-file key is named, not
read as absent; a model without suspension modes given to diagnose on modal data says its harmonics were replaced
and lists the data's lines it lacks; errors say what to do (a broken time column, --base extended without modes, a
sweep folder given as a test folder, speeds that are no numbers); the report says when the base became the fitted
modes; a floor's PSD carries its unit; an offset has no signed zero."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from rwadist import model as model_io
from rwadist.cli import main
from rwadist.data import DataError, write_steady
from rwadist.effects_text import describe_effect
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.teststand import simulate_steady


def test_misspelt_model_keys_are_refused_with_the_likely_key(tmp_path, capsys):
    """A misspelt key was read as absent ('empirial': a model without harmonics, `psd` and `fmu build` exit 0 with an
    imbalance-only PSD and an FMU without harmonics), first silently, then with a warning: now each is an error naming
    the key and the one it most likely meant (issue 36), in every consumer alike."""
    m = preset("ithaco-e").to_model()
    good = model_io.save(m, tmp_path / "good.json")
    assert main(["model", "show", str(good)]) == 0
    assert "warning" not in capsys.readouterr().err            # a file rwadist wrote: nothing unread
    base = json.loads(good.read_text())
    cases = {"empirial": ("empirial", "'empirical'"),
             "k_r": ("analytical.k_r_N_per_mm", "'k_r_N_per_m'"),
             "kind": ("effects[0].kind", "'fixed_resonance'"),
             "C": ("empirical.radial_force[0].C_stdev", "'C_stderr'"),
             "wheel": ("wheel.max_sped_rpm", "'max_speed_rpm'")}
    for what, (field, likely) in cases.items():
        doc = json.loads(json.dumps(base))
        if what == "empirial":
            doc["empirial"] = doc.pop("empirical")
        elif what == "k_r":
            doc["analytical"]["k_r_N_per_mm"] = doc["analytical"].pop("k_r_N_per_m")
        elif what == "kind":
            doc["effects"] = [{"kind": "fixed_resonence", "f_Hz": 150.0}]
        elif what == "C":
            doc["empirical"]["radial_force"][0]["C_stdev"] = 1e-8
        else:
            doc["wheel"]["max_sped_rpm"] = 3000.0
        bad = tmp_path / f"bad_{what}.json"
        bad.write_text(json.dumps(doc))
        with pytest.raises(model_io.ModelFileError, match=re.escape(f"{field}: ")):
            model_io.load(bad)
        for argv in (["model", "show", str(bad)],
                     ["psd", str(bad), "--speed-rpm", "600:2400", "--empirical", "--n-freq", "201", "-o",
                      str(tmp_path / "p.csv")]):
            assert main(argv) == 2
            err = capsys.readouterr().err.strip().splitlines()[-1]
            assert f"{bad}: {field}: " in err and likely in err, err
        assert not (tmp_path / "p.csv").exists()


@pytest.fixture(scope="module")
def modal(tmp_path_factory):
    """E-wheel data with the wheel's modes (the extended physics): a clean test and one with a line at h = 0.5."""
    d = tmp_path_factory.mktemp("modal")
    w = preset("ithaco-e")
    speeds = np.linspace(300.0, 3000.0, 24)
    clean = simulate_steady(w, speeds, physics="extended", sample_rate=3840.0, n_samples=4096, noise=0.01, seed=1)
    inj = simulate_with_injections(w, [parse("missing_harmonic:direction=radial_force,h=0.5,fraction=0.5")], speeds,
                                   physics="extended", seed=2, sample_rate=3840.0, n_samples=4096, noise=0.01)
    return write_steady(clean, d / "clean"), write_steady(inj, d / "inj")


def test_a_model_without_modes_given_on_modal_data_says_what_replaced_it(modal, tmp_path, capsys):
    clean, inj = modal
    emp = tmp_path / "emp.json"
    assert main(["fit", str(clean), "-o", str(emp), "--no-report"]) == 0
    capsys.readouterr()
    assert main(["diagnose", str(inj), "--model", str(emp), "-o", str(tmp_path / "rep")]) == 0
    out = capsys.readouterr().out
    assert "empirical -> extended" in out and f"note: {emp} has no suspension modes" in out
    assert re.search(r"  - radial_force h = 0\.500\d*( \(co-rotating part\))?, C = ", out)   # the injected line
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    lacks = summary["lines_missing_from_given_model"]
    assert any(x["direction"] == "radial_force" and abs(x["h"] - 0.5) < 0.01 for x in lacks)
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "-> extended (through the wheel's suspension modes fitted from the data)" in md
    assert "## The given model's harmonics" in md


def test_diagnose_base_extended_without_modes_says_what_to_give(modal, tmp_path, capsys):
    clean, _ = modal
    emp = model_io.save(preset("ithaco-e").to_model(), tmp_path / "m.json")
    doc = json.loads(emp.read_text())
    doc.pop("analytical")
    emp.write_text(json.dumps(doc))
    assert main(["diagnose", str(clean), "--model", str(emp), "--base", "extended", "-o", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert f"{emp}: --base: extended needs a model with the wheel's suspension modes" in err
    assert "rwadist fit --extended" in err and "rwadist.extended" not in err


def test_a_broken_time_column_says_what_to_do(tmp_path):
    from rwadist.data import read_steady

    fs = 3840.0
    t = np.arange(2048) / fs
    x = np.random.default_rng(0).standard_normal((2048, 2))
    keep = np.ones(t.size, bool)
    keep[700] = False
    d = tmp_path / "d"
    d.mkdir()
    np.savetxt(d / "r.csv", np.column_stack([t, x])[keep], delimiter=",", header="time_s,Fx_N,Fy_N", comments="",
               fmt=["%.6f", "%.17g", "%.17g"])
    (d / "runs.csv").write_text("file,speed_rpm\nr.csv,1000\n")
    with pytest.raises(DataError, match="export the run again without the loss"):
        read_steady(d)


def test_a_sweep_folder_given_as_a_test_names_the_sweep_file(tmp_path):
    from rwadist.data import read_steady

    d = tmp_path / "sw"
    d.mkdir()
    (d / "sweep.csv").write_text("time_s,Fx_N\n0,0\n")
    with pytest.raises(DataError, match=r"give the file itself, e\.g\. .*sw/sweep\.csv"):
        read_steady(d)


def test_speeds_that_are_no_numbers_say_the_forms(capsys):
    assert main(["simulate-test", "--preset", "ithaco-e", "x", "--speeds-rpm", "abc"]) == 2
    err = capsys.readouterr().err
    assert "'abc': not a number; give speeds in rpm as A,B,C or START:STOP:STEP" in err
    assert "could not convert" not in err


def test_floor_unit_and_offset_without_signed_zero():
    floor = {"kind": "broadband_floor", "channel": ["Tx"], "exponent": 3.0, "omega_ref_rad_s": 100.0,
             "f_Hz": [10.0, 100.0], "psd_ref": [1e-9, 2e-9]}
    assert "(N·m)²/Hz" in describe_effect(floor) and "unit²/Hz" not in describe_effect(floor)
    assert "N²/Hz" in describe_effect({**floor, "channel": ["Fx"]})
    offset = {"kind": "cross_coupling", "r_m": [1e-6, -2e-5, -0.06], "r_stderr_m": [1e-5, 1e-5, 1e-4]}
    text = describe_effect(offset)
    assert "r = (0.0, 0.0, -60.0)" in text and "-0.0" not in text
