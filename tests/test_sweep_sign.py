"""The direction of a sweep read from its slices' start times (:func:`rwadist.diagnose.smear.sweep_sign`): the sign of
dΩ/dt the suspension modes are driven at in the smear's prediction (:func:`rwadist.diagnose.smear.segment_transfer`,
a mode crossed faster than it settles lags on the way up and leads on the way down).

Session 65's investigation: the first slice of every sweep starts at t = 0.0, which ``t0 or nan`` read as a missing
time, so every sweep was a run-up there; on family wheel 2's 60-s exponential run-down the smear at the track's
acceleration was then refused (error 0.0335; with the sign, α −2.60 rad/s² named, 0.0290)."""
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.smear import sweep_sign  # noqa: E402


@pytest.mark.parametrize("up", [True, False])
def test_a_sweeps_direction_is_read_from_slices_that_start_at_zero(tmp_path, up):
    wheel = fw.family()[2]
    lo, hi = wheel.min_rpm, 0.5 * (wheel.min_rpm + wheel.max_rpm)
    data = fw.sweep(wheel, lo if up else hi, hi if up else lo, 6.0, seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(data, tmp_path / "sweep.csv", tach=True))
    t0 = np.array([r.t0 for r in test.runs])
    assert t0.min() == 0.0 and len(test.runs) >= 3           # the case that was read as no time at all
    ctx = SimpleNamespace(test=test, runs=np.arange(len(test.runs)), omega=np.array([r.speed for r in test.runs]))
    # the generator's own direction, and the sign of the slices' speeds against their start times
    rising = np.polyfit(t0, np.abs(ctx.omega), 1)[0] > 0
    assert rising == up
    assert sweep_sign(ctx) == (1.0 if up else -1.0)
