"""A fixture resonance on top of a wheel mode, diagnosed with no model (issue 33, Build item 1), on wheels of the
family generated without rwadist's physics (tests/family_wheel.py).

The case that failed: family wheel 0 (the issue's new wheel, modes 310/95/140 Hz) with a fixture at its radial
translation's own 310 Hz (ζ 0.03, peak gain 5, every channel), 16 speeds of 4096 samples.  The search fits the modes
on every other speed: 8 speeds put no line between 290 and 330 Hz, so those runs tell the stand from the mode on the
same spot by neither width nor frequency (the joint fit ran to ζ 0.001, no fixture resonance; without a stand no
mode was located) and diagnose named nothing.  Every run shows the stand; held at what they show, the fit runs
locate the modes.  Checked against the generator's truth: every mode within 2 % (or declared unconstrained), the
stand named as a test-stand resonance within 2 % of its frequency, nothing else added.

Family wheel 3 with a fixture at 1.25x its radial translation (288 Hz): the stand's held-out evidence summed over the
channels was diluted by the radial forces' imprecisely measured strong lines (t 3.97 < 4, while the torques alone gave
20 and the axial force 69) and the search named a wheel-mode resonance of the torques at the stand's frequency
instead.  A test-stand resonance is also read per load direction (rwadist.diagnose.search._by_direction_t).

Family wheel 0 with a fixture at 0.75x its radial translation (232 Hz): the fit half's translation damping (ζ 0.0088;
truth 0.021, the held-out half 0.021) put a line of the held-out top speed on a peak 1.7x too high, the modes were
refused and an amplitude law and two missing harmonics named; the modes fitted on the other half and judged on the
fit half are taken (rwadist.diagnose.search._other_folds).

Family wheel 5 with a fixture on its 600 Hz translation: the stand passed the held-out test but the radial forces'
own resonance gained a little more (0.93 against 0.87 of the misfit), and two wheel-mode resonances were named
instead; a passing stand is taken before a one-direction resonance at its frequency.  Family wheel 6 with a fixture at
1.25x its translation (188 Hz): after the stand, a wheel-mode candidate on the axial force at 88 Hz refitted on every
run to a peak gain of 1.003 was added; a refit must still be a resonance its family proposes.  With a fixture at 1.5x
its rocking mode (165 Hz): an axial 'wheel mode' at 89.7 Hz whose damping ended on the fit's floor (ζ 0.001: no
measured width) was added.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist import api  # noqa: E402


def _diagnosis(index, mode, factor, n_speeds=16, n_samples=4096, seed=1):
    wheel = fw.family()[index]
    f_fix = factor * wheel.modes_hz()[mode]
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, n_speeds), n_samples=n_samples,
                     noise=0.01, seed=seed, effects=(fe.Fixture(f_hz=f_fix),))
    return wheel, f_fix, api.diagnose(steady_test(data))


@pytest.mark.slow
@pytest.mark.parametrize("index, mode, factor", [(0, "radial_translation", 0.75), (0, "radial_translation", 1.0),
                                               (3, "radial_translation", 1.0), (3, "radial_translation", 1.25),
                                               (5, "radial_translation", 1.0), (6, "radial_translation", 1.25),
                                               (6, "rocking", 1.5)])
def test_fixture_near_a_mode_is_named_beside_the_modes_and_nothing_else(index, mode, factor):
    wheel, f_fix, d = _diagnosis(index, mode, factor)
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds[:1] == ["suspension_modes"], kinds
    modes = d.model.effects[0]
    for name, truth in wheel.modes_hz().items():
        assert name in (modes.get("unconstrained") or []) or modes[f"{name}_Hz"] == pytest.approx(truth, rel=0.02), \
            (name, modes[f"{name}_Hz"], truth)
    others = [e for e in d.model.effects[1:]]
    assert len(others) == 1 and others[0]["kind"] == "fixed_resonance" and others[0]["role"] == "test_stand", kinds
    assert others[0]["f_Hz"] == pytest.approx(f_fix, rel=0.02)
