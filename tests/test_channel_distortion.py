"""A radial channel whose signal chain is not linear (rwadist.channel_distortion): an amplifier's distortion on one
channel of a pair, which no diagnose class describes, broke the diagnosis (family wheel 2, 2 % second and third order
on Fx: the suspension modes not fitted, amplitude laws invented on three directions, the error 112x its clean level;
an outside trial's amplifier distortion ended in "nothing" at 37-48x).

The data are the wheel family's (tests/family_wheel.py, numpy only); the distortion is written here, y = x + a2·x²/σ +
a3·x³/σ² on one channel (σ its clean RMS), so the truth is known: the channel and orders found, the law measured, the
clean channel given back (the same seed without the distortion), and the diagnosis of the command a user types."""
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

import rwadist  # noqa: E402
from rwadist import channel_distortion  # noqa: E402
from rwadist.cli import main  # noqa: E402

CHANNEL = dict(zip(fw.CHANNELS, range(6)))


def distorted(data: fw.Steady, channel: str, a2: float, a3: float) -> fw.Steady:
    """``data`` with ``channel`` through y = x + a2·x²/σ + a3·x³/σ² (σ the run's clean RMS of it)."""
    signals = data.signals.copy()
    x = signals[:, CHANNEL[channel], :]
    s = x.std(axis=1, keepdims=True)
    signals[:, CHANNEL[channel], :] = x + a2 * x**2 / s + a3 * x**3 / s**2
    return dataclasses.replace(data, signals=signals)


@pytest.fixture(scope="module")
def wheels():
    return fw.family()


@pytest.mark.parametrize("index", [0, 2, 5, 7])
def test_clean_family_wheels_hold_no_distortion(wheels, index):
    test = family_test.steady_test(fw.steady(wheels[index], seed=1))
    out, records = channel_distortion.corrected(test)
    assert records == [] and out is test


@pytest.mark.parametrize("index, channel, a2, a3", [
    (0, "Fx", 0.02, 0.02),
    (1, "Ty", 0.0, 0.03),           # odd (a symmetric amplifier): no second-order products
    (3, "Fy", 0.02, 0.0),
    (6, "Fx", 0.005, 0.005),
])
def test_a_distorted_channel_is_found_measured_and_undone(wheels, index, channel, a2, a3):
    clean = fw.steady(wheels[index], seed=1)
    test = family_test.steady_test(distorted(clean, channel, a2, a3))
    out, records = channel_distortion.corrected(test)
    assert [r["channel"] for r in records] == [channel], records
    rec = records[0]
    assert rec["lines_at_products"] >= 5 * max(rec["expected_by_chance"], 1.0) and rec["false_alarm"] <= 1e-9
    assert rec["after"]["lines_at_products"] <= 0.1 * rec["lines_at_products"], rec
    for key, truth in (("second_order", a2), ("third_order", a3)):
        if truth:
            assert rec[key] == pytest.approx(truth, rel=0.12), rec
        else:
            assert abs(rec[key]) < 0.1 * max(a2, a3), rec
    # the corrected channel against the clean one (the same seed): the runs put right within 1 % of its RMS, and
    # five times closer than the distorted samples at the median
    fixed = set(rec["run_names"])
    assert len(fixed) >= 0.5 * len(test.runs)
    before, after = [], []
    for i, (run, new) in enumerate(zip(test.runs, out.runs)):
        if new.name not in fixed:
            continue
        x = clean.signals[i, CHANNEL[channel]]
        before.append(np.std(run.signals[channel] - x) / np.std(x))
        after.append(np.std(new.signals[channel] - np.mean(new.signals[channel]) - (x - x.mean())) / np.std(x))
    assert np.median(after) < 0.2 * np.median(before) and max(after) < 0.015, (np.median(after), max(after))
    # the other channels are left as they were
    for run, new in zip(test.runs, out.runs):
        assert all(new.signals[c] is run.signals[c] for c in run.signals if c != channel)


def test_diagnose_puts_the_channel_right_and_finds_the_wheel(wheels, tmp_path, capsys):
    """``rwadist diagnose DATA -o R`` (no model) on family wheel 2 with Fx distorted: before, the modes were not fitted
    and three amplitude laws, a missing harmonic and 12 descriptions came out (error 0.2655, clean 0.0024); now the
    channel is named and corrected and the diagnosis is the clean one's: the wheel's modes within 0.5 %, nothing
    else, the error within 2x its clean level."""
    wheel = wheels[2]
    data = fw.write_steady(distorted(fw.steady(wheel, seed=1), "Fx", 0.02, 0.02), tmp_path / "w2")
    assert main(["diagnose", str(data), "-o", str(tmp_path / "r")]) == 0
    out = capsys.readouterr().out
    assert "Fx's signal chain is not linear" in out and "Fx was corrected in" in out
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    kinds = [e["kind"] for e in summary["effects"]]
    assert kinds == ["suspension_modes"], kinds
    assert not [u for u in summary.get("unexplained", []) if u.get("signature") != "fixed_line"]
    modes = summary["effects"][0]
    truth = wheel.truth()["modes_hz"]
    for key, name in (("radial_translation_Hz", "radial_translation"), ("rocking_Hz", "rocking"),
                      ("axial_Hz", "axial")):
        assert modes[key] == pytest.approx(truth[name], rel=0.005), (key, modes[key], truth)
    records = [r for r in summary["data_quality"] if r["type"] == "distorted"]
    assert [r["channel"] for r in records] == ["Fx"]
    assert summary["error_after"] < 2.0 * 0.0025


def test_fit_puts_the_channel_right_too(wheels):
    """The empirical fit reads the same data step (one validation for every consumer): warned, in the provenance."""
    test = family_test.steady_test(distorted(fw.steady(wheels[3], seed=1), "Fy", 0.02, 0.0))
    with pytest.warns(rwadist.RwadistWarning, match="Fy's signal chain is not linear"):
        fit = rwadist.fit(test)
    assert [r["channel"] for r in fit.model.provenance["data_quality"]] == ["Fy"]


def test_a_channel_left_out_of_every_run_is_as_one_the_test_lacks():
    """A channel invalid in every run (it froze throughout, ``Run.invalid``) kept NaN rows in the spectra, which the
    search read: "Mean of empty slice" on 8 runs, an internal error (SVD did not converge) on 12 runs of 4096 samples.
    It is now left out of the spectra, as a channel the test lacks."""
    import warnings

    from rwadist.spectra import compute_spectra

    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 8), n_samples=2048, seed=1)
    runs = [dataclasses.replace(r, signals=dict(r.signals, Fx=np.zeros_like(r.signals["Fx"]))) for r in test.runs]
    test = type(test)(runs, test.meta)
    assert "Fx" not in compute_spectra(type(test)([dataclasses.replace(r, invalid=frozenset({"Fx"})) for r in runs],
                                                  test.meta)).psd
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        diagnosis = rwadist.diagnose(test)
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], [str(w.message) for w in caught]
    assert [r["channel"] for r in diagnosis.data_quality] == ["Fx"] * len(runs)
