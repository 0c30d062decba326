"""One acceleration for a sweep whose own is far from constant (``spin_acceleration``'s ``alpha_slowest_rad_s2`` and
``alpha_fastest_rad_s2``, :func:`rwadist.diagnose.smear.track_span`).

The smear is predicted at one α, the median of the slices' dΩ/dt.  A motor's run at full voltage against its
back-EMF is exponential (tests/family_wheel.py ``profile="exp"``): its dΩ/dt falls ~50x from the start to the end
(family wheel 2's 60-s run-down: α −2.60 rad/s² named for slices from −0.477 to −14.5 over eighths of the sweep),
and nothing said that one α was a compromise.  Now the slowest and fastest rates between slices are in the model and the text says so when they
spread over a factor 2."""
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.smear import SPAN_WINDOW, speed_track, track_span  # noqa: E402
from rwadist.effects.spin_acceleration import SpinAcceleration  # noqa: E402


@pytest.mark.parametrize("profile", ["exp", "linear"])
def test_the_span_is_the_generators_slowest_and_fastest_rate(tmp_path, profile):
    """Over windows of an eighth of the slices (:data:`rwadist.diagnose.smear.SPAN_WINDOW`), the rate of the slices'
    speeds is the generator's mean dΩ/dt between the windows' slice centres, (Ω(c_j) − Ω(c_i))/(c_j − c_i) of its
    closed-form profile, within 3 %; the exponential run-down's spread is its e^{−t/τ} over the sweep, the linear one's
    none."""
    wheel = fw.family()[2]
    duration = 8.0
    data = fw.sweep(wheel, wheel.max_rpm, wheel.min_rpm, duration, seed=4, profile=profile)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(data, tmp_path / "sweep.csv", tach=True))
    runs = np.arange(len(test.runs))
    ctx = SimpleNamespace(test=test, runs=runs, omega=np.array([r.speed for r in test.runs]))
    order = np.argsort([r.t0 for r in test.runs])
    centre = np.array([test.runs[i].t0 + 0.5 * test.runs[i].n_samples / test.runs[i].sample_rate for i in order])
    m = max(1, int(round(SPAN_WINDOW * centre.size)))
    om = fw.speed_profile(centre, wheel.max_rpm, wheel.min_rpm, duration, profile)[0]
    truth = (om[m:] - om[:-m]) / (centre[m:] - centre[:-m])
    slowest, fastest = track_span(ctx, runs)
    assert slowest == pytest.approx(truth[np.argmin(np.abs(truth))], rel=0.03)
    assert fastest == pytest.approx(truth[np.argmax(np.abs(truth))], rel=0.03)
    assert slowest < 0 and fastest < 0 and abs(slowest) <= abs(speed_track(ctx, runs)) <= abs(fastest)
    spread = abs(fastest / slowest)
    assert (spread > 4.0) if profile == "exp" else (spread < 1.05)


def test_a_ramp_read_with_noisy_speeds_has_no_spread():
    """A constant 1 rad/s² ramp cut into 300 slices 2 s apart, each slice's speed read to 1e-3 (Gaussian): the rates of
    slices next in time scatter by ~0.3 rad/s², their extremes over 2x apart; over an eighth of the slices the span
    stays within 10 % of the ramp and the text says nothing."""
    rng = np.random.default_rng(7)
    t0 = 2.0 * np.arange(300)
    omega = (100.0 + 1.0 * t0) * (1 + 1e-3 * rng.standard_normal(t0.size))
    runs = [SimpleNamespace(t0=float(t)) for t in t0]
    ctx = SimpleNamespace(test=SimpleNamespace(runs=runs), runs=np.arange(t0.size), omega=omega)
    next_rates = np.diff(omega) / np.diff(t0)
    assert np.max(np.abs(next_rates)) > 2 * np.min(np.abs(next_rates))      # what min/max of neighbours would say
    slowest, fastest = track_span(ctx, ctx.runs)
    assert 0.9 < slowest <= fastest < 1.1
    entry = {"alpha_rad_s2": 1.0, "alpha_slowest_rad_s2": slowest, "alpha_fastest_rad_s2": fastest}
    assert "one α for slices" not in SpinAcceleration.describe(entry)
    # a sweep that dwells (rate 0) or turns back (rates of both signs) is no spread of one acceleration
    assert "one α for slices" not in SpinAcceleration.describe(entry | {"alpha_slowest_rad_s2": 0.0})
    assert "one α for slices" not in SpinAcceleration.describe(entry | {"alpha_slowest_rad_s2": -0.3,
                                                                        "alpha_fastest_rad_s2": 5.0})


def test_the_text_says_one_alpha_is_a_compromise_only_when_the_rates_spread():
    entry = {"alpha_rad_s2": -6.38, "alpha_track_rad_s2": -6.38, "alpha_residual_rad_s2": -5.9,
             "alpha_slowest_rad_s2": -2.1, "alpha_fastest_rad_s2": -19.8}
    text = SpinAcceleration.describe(entry)
    assert "(a run-down)" in text and "one α for slices whose dΩ/dt runs from −2.1 to −19.8 rad/s²" in text.replace("-", "−")
    steady_ramp = entry | {"alpha_slowest_rad_s2": -6.1, "alpha_fastest_rad_s2": -6.6}
    assert "one α for slices" not in SpinAcceleration.describe(steady_ramp)
    # a model written before the fields existed reads as before
    old = {k: v for k, v in entry.items() if k not in ("alpha_slowest_rad_s2", "alpha_fastest_rad_s2")}
    assert "one α for slices" not in SpinAcceleration.describe(old)
