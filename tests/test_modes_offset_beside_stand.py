"""A fixture resonance beside the radial translation and NO load-cell offset: the modes are not located on torques
"corrected" for an offset, checked against the generator's own truth (tests/trial21_wheel.py, an independent
generator, numpy only).

trial21's 11-kg wheel (translation 75 Hz, rocking 45 Hz at rest, axial 190 Hz) with a fixture at 67.5 Hz (ζ 0.03,
peak gain 5) on every channel, seed 22.  The modes and the stand were located right (67.71 Hz ζ 0.031 gain 4.91 on
the fit runs; 67.47 Hz ζ 0.0297 gain 5.02 and the modes within 0.02 % on every run), then a load-cell offset was
estimated beside the modes WITHOUT the stand (:func:`rwadist.effects.suspension_modes_diagnose._beside_offset`):
the stand's lift of the torque lines was torque the state did not predict, r_z read −2.03 ± 0.41 mm on the fit
runs (−1.45 ± 0.24 mm on every run), "significant", and the modes located on the torques it corrected (translation
74.57 Hz, −0.57 %; rocking 45.27 Hz, +0.61 %; the stand 67.99 Hz ζ 0.0397 gain 4.06 in that fit) explained the runs
"better" than the true ones by the same omission.  The error after was 8.5x the clean seed-21 cell's.  Estimated
beside the modes AND the stand they were fitted with, r_z reads −0.18 ± 0.62 mm (−0.49 ± 0.37 mm): nothing is
corrected, and the modes are those located on the data as they are.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import trial21_wheel as tw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.data import Run, SteadyTest  # noqa: E402


@pytest.fixture(scope="module")
def diagnosis():
    speeds, signals, fs = tw.steady(seed=22, fixture=True)
    runs = [Run(speed=float(om), sample_rate=fs, t0=0.0, name=f"run_{i:04d}.csv",
                signals={c: signals[i, j] for j, c in enumerate(tw.CHANNELS)}) for i, om in enumerate(speeds)]
    return api.diagnose(SteadyTest(runs=runs, meta={}))


@pytest.mark.slow
def test_modes_beside_a_stand_are_not_located_on_torques_corrected_for_no_offset(diagnosis):
    d = diagnosis
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds[0] == "suspension_modes" and "cross_coupling" not in kinds, kinds
    modes = d.model.effects[0]
    assert not modes.get("unconstrained"), modes.get("unconstrained")
    # the generator's modes (the located ones: translation +0.02 %, rocking +0.32 %, axial −0.01 %; the clean wheel's
    # seed 22 reads the rocking +0.41 %, the fixture's seeds 21, 23, 24 every mode within 0.32 %)
    for name, truth, rel in (("radial_translation", tw.F_TR, 0.002), ("rocking", tw.F_RK, 0.005),
                             ("axial", tw.F_AX, 0.002)):
        assert modes[f"{name}_Hz"] == pytest.approx(truth, rel=rel), (name, modes[f"{name}_Hz"], truth)
    assert modes["inertia_ratio"] == pytest.approx(tw.I_ZZ / tw.I_RR, rel=0.01)
    stands = [e for e in d.model.effects if e["kind"] == "fixed_resonance" and e["role"] == "test_stand"]
    assert len(stands) == 1, kinds
    assert stands[0]["f_Hz"] == pytest.approx(tw.FIX_F, rel=0.005)
    assert stands[0]["zeta"] == pytest.approx(tw.FIX_Z, rel=0.1)
    assert stands[0]["peak_gain"] == pytest.approx(tw.FIX_P, rel=0.05)
