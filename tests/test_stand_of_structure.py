"""A fixture resonance that the empirical fit's lines are too sparse to propose, found by the modes' fit on one
direction, is named the test stand it is when it lifts every direction (:func:`rwadist.stand_resonance.stand_of_structure`).

An outside trial's wheel (trial24 W1: 2.4 kg, I_zz/I_rr 2.1, translation 480 Hz, rocking 150 Hz, axial 560 Hz; few
lines: radial force 1, 0.41, 3.6, 5.4, 7.2, radial torque 1, 0.41, 3.6, axial force 3.6; 16 speeds 1000-10000 rpm at
10 kHz) on a fixture at 225 Hz (ζ 0.03, gain 5, every channel), between its rocking and translation modes, made
here by the tests' own generator (tests/family_wheel.py, numpy only).  Each line passes within ±6 % of the fixture
at one speed at most: the stand's detection saw no fixture, the modes' fit found the resonance on the radial
forces alone, and diagnose named a wheel mode at 225.4-226.1 Hz there on 3 of 3 seeds (the stand's peak carried into
the flight model), the error after 0.023-0.026, 10-46x the same seed's clean data.  Truth: the generator's fixture and
modes.  Seed 1 goes through the stand held at the radial forces' resonance (every channel's joint fit runs ζ to its
floor), seed 3 through the joint fit.
"""
import functools
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist import api  # noqa: E402

FIXTURE_HZ = 225.0
L = fw.Line
WHEEL = fw.Wheel(
    name="trial24-w1", mass=2.4, I_zz=0.0044, I_rr=0.0021, f_trans=480.0, f_rock=150.0, f_axial=560.0,
    zeta_trans=0.015, zeta_rock=0.02, zeta_axial=0.02,
    lines=(L("radial_force", 1.0, 1.5e-6, 1.0, "imbalance"), L("radial_force", 0.41, 2e-7, 1.0, "cage"),
           L("radial_force", 3.6, 1.5e-7, 0.0, "BPFO"), L("radial_force", 5.4, 1e-7, 1.0, "BPFI"),
           L("radial_force", 7.2, 6e-8, 1.0, "2xBPFO"), L("radial_torque", 1.0, 8e-8, 1.0, "imbalance"),
           L("radial_torque", 0.41, 1e-8, 1.0, "cage"), L("radial_torque", 3.6, 1.2e-8, 0.0, "BPFO"),
           L("axial_force", 3.6, 8e-8, 1.0, "BPFO")),
    min_rpm=1000.0, max_rpm=10000.0, sample_rate=10000.0, n_samples=16384, n_speeds=16)


@functools.lru_cache(maxsize=None)
def _summary(seed: int, fixture: bool) -> dict:
    data = fw.steady(WHEEL, noise=0.015, seed=seed, effects=[fe.Fixture(FIXTURE_HZ)] if fixture else [])
    return api.diagnose(steady_test(data)).summary()


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 3])
def test_a_sparse_fixture_between_the_modes_is_named_a_test_stand(seed):
    s = _summary(seed, True)
    res = [e for e in s["effects"] if e["kind"] == "fixed_resonance"]
    print(seed, [(e["role"], e["f_Hz"], e["zeta"], e["peak_gain"]) for e in res], s["error_after"])
    assert [e["role"] for e in res] == ["test_stand"]
    stand = res[0]
    assert stand["f_Hz"] == pytest.approx(FIXTURE_HZ, rel=0.01)
    assert set(stand["channel"]) == {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"}
    # the fixture's lift where the lines pass it (ζ·gain: the sparse speeds measure the flank, not the width)
    assert stand["zeta"] * stand["peak_gain"] == pytest.approx(0.03 * 5.0, rel=0.25)
    modes = next(e for e in s["effects"] if e["kind"] == "suspension_modes")
    for name, f_true in WHEEL.modes_hz().items():
        f = modes[f"{name}_Hz"]
        assert f == pytest.approx(f_true, rel=0.02) or name in (modes.get("unconstrained") or []), (name, f)
    # the model explains the data as the clean data's model does its own (before: 10-46x).  Seed 1 read 4.85x until the
    # rocking scan read the torque lines' senses (rwadist.extended_fit.one_sense_rows), then 5.9x: its clean run's
    # error fell 0.00054 -> 0.00047 (rocking 149.98 -> 149.90 Hz, truth 150), the fixture's rose 0.00263 -> 0.00279 with
    # the modes and the stand the same to 5 digits
    assert s["error_after"] < 6.0 * _summary(seed, False)["error_after"]
