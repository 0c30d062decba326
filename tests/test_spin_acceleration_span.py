"""One acceleration for a sweep whose own is far from constant (``spin_acceleration``'s ``alpha_slowest_rad_s2`` and
``alpha_fastest_rad_s2``, :func:`rwadist.diagnose.smear.track_span`).

The smear is predicted at one α, the median of the slices' dΩ/dt.  A motor's run at full voltage against its
back-EMF is exponential (tests/family_wheel.py ``profile="exp"``): its dΩ/dt falls ~50x from the start to the end
(family wheel 2's 60-s run-down: α −2.60 rad/s² named for slices from −0.385 to −17.6), and nothing said that one α
was a compromise.  Now the slowest and fastest rates between slices are in the model and the text says so when they
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
from rwadist.diagnose.smear import speed_track, track_span  # noqa: E402
from rwadist.effects.spin_acceleration import SpinAcceleration  # noqa: E402


@pytest.mark.parametrize("profile", ["exp", "linear"])
def test_the_span_is_the_generators_slowest_and_fastest_rate_between_slices(tmp_path, profile):
    """The rate between two slices next in time is the generator's dΩ/dt at their boundary (the difference of two
    slice means over their spacing: exact for a linear ramp, to second order in the slice length otherwise), within
    3 %; the exponential run-down's spread is its e^{−t/τ} over the slices, the linear one's none."""
    wheel = fw.family()[2]
    duration = 8.0
    data = fw.sweep(wheel, wheel.max_rpm, wheel.min_rpm, duration, seed=4, profile=profile)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(data, tmp_path / "sweep.csv", tach=True))
    runs = np.arange(len(test.runs))
    ctx = SimpleNamespace(test=test, runs=runs, omega=np.array([r.speed for r in test.runs]))
    t0 = np.sort([r.t0 for r in test.runs])
    truth = fw.speed_profile(t0[1:], wheel.max_rpm, wheel.min_rpm, duration, profile)[2]
    slowest, fastest = track_span(ctx, runs)
    assert slowest == pytest.approx(truth[np.argmin(np.abs(truth))], rel=0.03)
    assert fastest == pytest.approx(truth[np.argmax(np.abs(truth))], rel=0.03)
    assert abs(slowest) <= abs(speed_track(ctx, runs)) <= abs(fastest) and slowest < 0 and fastest < 0
    spread = abs(fastest / slowest)
    assert (spread > 4.0) if profile == "exp" else (spread < 1.05)


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
