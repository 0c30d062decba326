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

from rwadist import api  # noqa: E402
from rwadist.diagnose.describe_skew import fit_skew  # noqa: E402


def _skews(index: int, k: int, channel: str = "Fy"):
    """(channel_skew records of `api.diagnose` on family wheel ``index`` with ``channel`` k samples late, τ s)."""
    test = family_test.steady_test(fw.steady(fw.family()[index], seed=4, noise=0.01))
    for run in test.runs:
        if k:
            x = run.signals[channel]
            late = x.copy()
            late[k:] = x[:-k]
            run.signals[channel] = late
    diag = api.diagnose(test)
    found = [u for u in diag.unexplained if u.parameters.get("property") == "channel_skew"]
    return found, k / test.runs[0].sample_rate


@pytest.mark.parametrize("index, k", [(3, 3), (7, 6)])
def test_a_channel_recorded_late_is_described_with_its_delay(index, k):
    """Family wheels 3 (4 kHz, 600-6000 rpm, Fy 0.75 ms late) and 7 (6 kHz, 1000-10000 rpm, 1 ms: beyond a quarter
    turn at the higher lines, read modulo a half turn): Fy named late, τ within 0.5 %, on the radial forces only."""
    (u,), tau = _skews(index, k)
    p = u.parameters
    assert (p["late"], p["early"]) == ("Fy", "Fx") and u.channels == ("Fx", "Fy")
    assert p["tau_s"] == pytest.approx(tau, rel=0.005)
    top = u.f_Hz[1]
    assert p["other_sense_share_at_highest"] == pytest.approx(np.sin(np.pi * top * tau) ** 2, rel=0.01)
    assert f"Fy sampled or filtered {1e3 * tau:.3g} ms after Fx" in u.text()


def test_clean_records_and_a_late_torque_channel():
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
