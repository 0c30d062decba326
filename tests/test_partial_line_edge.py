"""A line present in a stretch of runs only is one description, not also a step at its edge
(rwadist.diagnose.describe_line_step.with_line_steps).

The new-user trial nuN's intermittent rub (a forward-whirling radial-force line at h 0.5 in the 11 runs 4029-6743 rpm
of 36) was described as a ``partial_line`` present in exactly those runs, and again as a ``line_step``, "changed by
x 0.003 between 6743 and 7557 rpm", a second share of the same content.  Here family wheels with such a line added
to the records (numpy: a 0.5x line, 0.3 x the imbalance's force, in the middle third of the speeds)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


@pytest.mark.parametrize("index", [3, 6])
def test_a_line_in_a_stretch_of_runs_is_one_partial_line(index):
    wheel = fw.family()[index]
    test = family_test.steady_test(fw.steady(wheel, seed=1, noise=0.01))
    speeds = np.array([abs(r.speed) for r in test.runs])
    lo, hi = np.quantile(speeds, [1 / 3, 2 / 3])
    imbalance = next(x for x in wheel.lines if x.direction == "radial_force" and x.h == 1.0)
    rng = np.random.default_rng(5)
    lit = []
    for i, run in enumerate(test.runs):
        if lo <= abs(run.speed) <= hi:
            t = np.arange(run.n_samples) / run.sample_rate
            a, ph = 0.3 * imbalance.C * run.speed ** 2, rng.uniform(0, 2 * np.pi)
            run.signals["Fx"] = run.signals["Fx"] + a * np.cos(0.5 * run.speed * t + ph)
            run.signals["Fy"] = run.signals["Fy"] + a * np.sin(0.5 * run.speed * t + ph)
            lit.append(run.speed * 30 / np.pi)
    diag = api.diagnose(test)
    about = [u for u in diag.unexplained if u.h is not None and abs(u.h - 0.5) < 0.01
             or abs(u.parameters.get("h", 0.0) - 0.5) < 0.01]
    assert [u.signature for u in about] == ["partial_line"]
    assert about[0].parameters["present_rpm"] == pytest.approx(sorted(lit))
