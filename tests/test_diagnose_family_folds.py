"""The wheel's suspension modes on clean data of a short speed grid, diagnosed with no model (issue 33: 0 effects
added to clean data on every wheel), on a wheel of the family generated without rwadist's physics
(tests/family_wheel.py, seed 2 of the family: the same design table, other dampings, inertias and lines).

The case that failed: family wheel 3 of seed 2, 16 speeds of 4096 samples.  The search fits on every other speed;
those 8 speeds miss the rocking mode's peak and leave it unconstrained, and the modes so fitted predicted the held-out
runs worse than the empirical base (no suspension_modes; two missing harmonics and an amplitude law named on clean
data).  The split of the speeds is arbitrary: the modes are also fitted on the held-out half and judged on the fit
half (rwadist.diagnose.search._other_folds), which locates all three.  Wheel 0 of seed 2: the fit half ran the
translation's damping to the fit's floor and located no mode (two fixed resonances, an amplitude law and a missing
harmonic named); the other fold locates the modes, and a wheel-mode "resonance" of gain 0.02 at 489 Hz patching one
radial-force line was then named: a wheel mode amplifies (a dip is no wheel mode, only a test stand's gain may fall).
Checked against the generator's truth: only ``suspension_modes``, every mode within 2 %.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist import api  # noqa: E402


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 3])
def test_clean_wheel_whose_fit_half_misses_a_mode_gets_its_modes_and_nothing_else(index):
    wheel = fw.family(seed=2)[index]
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, 16), n_samples=4096, noise=0.01,
                     seed=7)
    d = api.diagnose(steady_test(data))
    assert [e["kind"] for e in d.model.effects] == ["suspension_modes"], [e["kind"] for e in d.model.effects]
    modes = d.model.effects[0]
    for name, truth in wheel.modes_hz().items():
        assert modes[f"{name}_Hz"] == pytest.approx(truth, rel=0.02), (name, modes[f"{name}_Hz"], truth)
