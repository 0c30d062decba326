"""A timing skew between the two channels of a radial pair is described as such (rwadist.diagnose.describe_skew;
trial26: Fy 0.8 ms late became a counter_rotation q 0.054 on the imbalance and opposite-sense parts on every
radial-force line, the error figure below the clean level, and nothing was said).

The skew is made as a DAQ makes it: the family generator's Fy record moved k samples later (its first k samples
held), nothing else changed; the truth is τ = k / sample rate.  A line of one sense then reads its x/y phase off a
quarter turn by 2πfτ (closed form, the module's docstring), whatever its amplitude or the modes it passes."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api, channel_timing  # noqa: E402
from rwadist.diagnose.describe_skew import fit_skew  # noqa: E402


def _late(index: int, k: int, channel: str = "Fy"):
    """(the test of family wheel ``index`` with ``channel`` k samples late, τ s)."""
    test = family_test.steady_test(fw.steady(fw.family()[index], seed=4, noise=0.01))
    for run in test.runs:
        if k:
            x = run.signals[channel]
            late = x.copy()
            late[k:] = x[:-k]
            run.signals[channel] = late
    return test, k / test.runs[0].sample_rate


@pytest.fixture
def described_only(monkeypatch):
    """The skews described and left in the data (rwadist.channel_timing undoes none)."""
    monkeypatch.setattr(channel_timing, "MIN_T", np.inf)


def _skews(index: int, k: int, channel: str = "Fy"):
    """(channel_skew records of `api.diagnose` on family wheel ``index`` with ``channel`` k samples late, τ s)."""
    test, tau = _late(index, k, channel)
    diag = api.diagnose(test)
    return [u for u in diag.unexplained if u.parameters.get("property") == "channel_skew"], tau


@pytest.mark.parametrize("index, k", [(3, 3), (7, 6)])
def test_a_channel_recorded_late_is_described_with_its_delay(index, k, described_only):
    """Family wheels 3 (4 kHz, 600-6000 rpm, Fy 0.75 ms late) and 7 (6 kHz, 1000-10000 rpm, 1 ms: beyond a quarter
    turn at the higher lines, read modulo a half turn): Fy named late, τ within 0.5 %, on the radial forces only."""
    (u,), tau = _skews(index, k)
    p = u.parameters
    assert (p["late"], p["early"]) == ("Fy", "Fx") and u.channels == ("Fx", "Fy")
    assert p["tau_s"] == pytest.approx(tau, rel=0.005)
    top = u.f_Hz[1]
    assert p["other_sense_share_at_highest"] == pytest.approx(np.sin(np.pi * top * tau) ** 2, rel=0.01)
    assert f"Fy sampled or filtered {1e3 * tau:.3g} ms after Fx" in u.text()


def test_clean_records_and_a_late_torque_channel(described_only):
    """Wheel 3's records as generated: no skew.  Its Tx one sample late (0.25 ms): the torques' pair, Tx named."""
    assert _skews(3, 0)[0] == []
    (u,), tau = _skews(3, 1, "Tx")
    assert (u.parameters["late"], u.channels) == ("Tx", ("Tx", "Ty"))
    assert u.parameters["tau_s"] == pytest.approx(tau, rel=0.01)


def test_the_fit_reads_the_delay_modulo_a_half_turn_and_not_from_ellipses():
    """fit_skew on cells of the closed form (lines 20-600 Hz, τ 0.9 ms: up to 194° of phase, read modulo 180°, with
    0.5° of noise) returns τ; on phases with no course in f (an ellipse's, uniform in ±90°) it explains nothing."""
    rng = np.random.default_rng(1)
    f = rng.uniform(20.0, 600.0, 80)
    d = (-2 * np.pi * f * 0.9e-3 + np.radians(0.5) * rng.standard_normal(f.size) + np.pi / 2) % np.pi - np.pi / 2
    fit = fit_skew(f, d)
    assert fit["tau_s"] == pytest.approx(0.9e-3, rel=1e-3) and fit["explained"] > 0.99
    assert fit_skew(f, rng.uniform(-np.pi / 2, np.pi / 2, f.size))["explained"] < 0.8


@pytest.mark.parametrize("index, k", [(3, 3), (7, 6)])
def test_a_late_channel_beyond_doubt_is_moved_back_and_diagnosed_again(index, k):
    """The skews above read beyond doubt (rwadist.channel_timing): Fy moved τ earlier in every run, the data diagnosed
    again; data_quality holds the ``late_channel`` record (τ within 0.5 %), no skew is left to describe, and the
    model's radial-force lines keep the senses the generator gave them (the new-user trial nuN: Fy 0.3 ms late had
    counter-rotating parts of 57-67 % on every radial-force line and a true counter_rotation missed)."""
    test, tau = _late(index, k)
    diag = api.diagnose(test)
    (rec,) = [r for r in diag.data_quality if r.get("type") == "late_channel"]
    assert (rec["channel"], rec["reference"]) == ("Fy", "Fx") and rec["tau_s"] == pytest.approx(tau, rel=0.005)
    assert not [u for u in diag.unexplained if u.parameters.get("property") == "channel_skew"]
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes"]
    clean = api.diagnose(_late(index, 0)[0])
    senses = {(round(x.h, 2), x.sense) for x in diag.model.harmonics("radial_force")}
    assert senses == {(round(x.h, 2), x.sense) for x in clean.model.harmonics("radial_force")}


def test_moved_earlier_is_a_delay_undone():
    """A tone delayed by τ (a fraction of a sample) and moved back: the tone again, to 1e-9 away from the ends."""
    fs, n, tau = 1000.0, 4096, 0.37e-3
    t = np.arange(n) / fs
    x = np.sin(2 * np.pi * 31.25 * (t - tau))               # a whole number of cycles: no wrap at the ends
    np.testing.assert_allclose(channel_timing.moved_earlier(x, tau, fs), np.sin(2 * np.pi * 31.25 * t), atol=1e-9)


@pytest.mark.parametrize("late", [0, 3])
def test_a_counter_rotation_beside_a_late_channel_is_read_as_without_it(late):
    """nuN: Fy 0.3 ms late beside a counter-rotating 20 % of the imbalance (q 0.0385): the counter rotation was missed
    on one seed and read 0.0595 on the other.  Family wheel 3 with a counter-rotating q 0.1 of its imbalance, Fy 3
    samples late or not: the same q within 2 %, the late channel moved back."""
    from family_effects import CounterRotation

    test = family_test.steady_test(fw.steady(fw.family()[3], seed=4, noise=0.01,
                                             effects=[CounterRotation(fraction=0.1)]))
    for run in test.runs:
        if late:
            y = run.signals["Fy"].copy()
            y[late:] = run.signals["Fy"][:-late]
            run.signals["Fy"] = y
    diag = api.diagnose(test)
    (cr,) = [e for e in diag.model.effects if e["kind"] == "counter_rotation"]
    assert cr["counter_fraction"] == pytest.approx(0.1, rel=0.02)
    assert len([r for r in diag.data_quality if r.get("type") == "late_channel"]) == (1 if late else 0)
