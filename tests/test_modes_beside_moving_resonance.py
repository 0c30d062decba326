"""The wheel's suspension modes fitted beside a resonance whose frequency moves with speed (issue 33, item 1: the modes
fit robust to what no class explains; the describe stage names the moving resonance).

Data: family wheel 2 of tests/family_wheel.py (generated without rwadist: 15 kg, I_zz/I_rr 2.2, modes 90/50/62 Hz,
300-3000 rpm at 2 kHz, the family matrix's 20 speeds, 4096 samples, noise 3 %) with the family's moving resonance
(tests/family_effects.MovingResonance: on the axial force, f_r = sqrt(f0² + (1.5 f_spin)²), 76 -> 107 Hz, ζ 0.03,
peak gain 5).  Reference: the generator's modes.  Before, the axial mode came out 2.2 % off with a standard error of
0.8 % (a wrong mode kept silently); a fixture "stand" was also confirmed at 88 Hz on one fold of the speeds, which
put the rocking 3.1 % off.
"""
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist.data import SteadyTest, read_steady  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_resonance import _mode_hz, fit_extended_beside_stand  # noqa: E402


def _test(effects, seed=201):
    wheel = fw.family()[2]
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, 20), n_samples=4096, noise=0.03,
                     seed=seed, effects=effects)
    with tempfile.TemporaryDirectory() as tmp:
        return wheel, read_steady(fw.write_steady(data, Path(tmp) / "data", wheel.name))


def _modes(test):
    fit = fit_empirical(compute_spectra(test))
    return fit_extended_beside_stand(test, fit)


@pytest.mark.parametrize("fold", [slice(None), slice(0, None, 2)])
def test_every_mode_is_right_or_declared_beside_a_moving_resonance(fold):
    wheel, test = _test((fe.default_effect("moving_resonance", fw.family()[2]),))
    test = SteadyTest(test.runs[fold], dict(test.meta))
    efit = _modes(test)
    got = _mode_hz(efit.params)
    for m, truth in wheel.modes_hz().items():
        assert m in efit.unconstrained or got[m] == pytest.approx(truth, rel=0.02), (m, got[m], truth)
    assert efit.stand is None                       # a resonance of the axial force alone is no fixture
    assert len(efit.unconstrained) < 3


def test_clean_modes_are_found_not_declared():
    wheel, test = _test(())
    efit = _modes(test)
    got = _mode_hz(efit.params)
    assert not efit.unconstrained and efit.stand is None
    for m, truth in wheel.modes_hz().items():
        assert got[m] == pytest.approx(truth, rel=0.02), m
