"""A fixture resonance on a table whose load-cell reference sits off the bearing centre (a lever arm r_z), diagnosed
with no model on the user's command path (:func:`rwadist.api.diagnose`), checked against the generator's own truth
(tests/family_wheel.py, numpy only).

The case (benchmarks/diagnose_family_matrix.py, cell ``fixture_offset`` of family wheel 7): a fixture at 195 Hz
(1.5x the 130 Hz rocking mode; ζ 0.03, peak gain 5, every channel) and r = (0, 0, 20) mm, 16 speeds of 8192 samples,
noise 3 %.  The wheel's modes are located on the torques corrected for the offset (T − r × F), and the search names
the stand before the offset: the stand fitted on diagnose's own lines then read the torques with r × F still in
them against the modes' corrected torque lines, and took part of r × F for itself (195.36 Hz, gain above 1.0099).
Kept after the offset was named, it misplaced 2.2 % of the forces' line power and 1.5 % of the torques' against the
generator's noise-free lines (the clean wheel's diagnosis: 0.6 % and 0.4 %), and the error after was 6.0x the clean
cell's.  A stand named before the offset is now refitted beside it at the end of the search
(:func:`rwadist.effects.fixed_resonance_diagnose.stands_refitted_last`): 195.61 Hz, gain above 1.0006, 0.9 % and
0.4 % misplaced (the same fixture without the offset: 195.59 Hz, 1.0007, 0.9 % and 0.35 %); the error after 1.9x the
clean cell's.
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

F_FIX, ZETA_FIX, GAIN_FIX = 195.0, 0.03, 5.0
R_Z = 0.02                      # m
#: misplaced line power against the generator's noise-free lines, forces and torques each (clean wheel: 0.6 %, 0.4 %)
MISPLACED_MAX = 0.0125
GROUPS = {"forces": ("Fx", "Fy", "Fz"), "torques": ("Tx", "Ty", "Tz")}


@pytest.fixture(scope="module")
def case():
    wheel = fw.family()[7]
    data = fw.steady(wheel, speeds_rpm=np.linspace(wheel.min_rpm, wheel.max_rpm, 16), n_samples=8192, noise=0.03,
                     seed=701, effects=(fe.Fixture(f_hz=F_FIX, zeta=ZETA_FIX, gain=GAIN_FIX),
                                        fe.CrossCoupling(r=(0.0, 0.0, R_Z))))
    return wheel, data, api.diagnose(steady_test(data))


def _misplaced(d, data) -> dict:
    """Per group of channels: Σ over runs and line frequencies of |P_model − P_true| / Σ P_true, P the line's power
    (amplitude²/2) summed over the group's channels; P_true from the generator's complex amplitudes at the load cell
    (its components at one frequency added), the torques as the diagnosis reads them (T − r × F, its own r); P_model
    the diagnosis's lines through its modes and resonances.  A radial pair summed over x and y: the cross term of a
    line's co and counter parts cancels there."""
    ctx, st = d.ctx, d.state_after
    r = np.zeros(3) if st.load_cell_offset is None else np.asarray(st.load_cell_offset, dtype=float)
    mis, tot = dict.fromkeys(GROUPS, 0.0), dict.fromkeys(GROUPS, 0.0)
    for run in ctx.runs:
        comp, A = data.components[run]
        A = A.copy()
        A[:, 3:] -= np.cross(r[None, :], A[:, :3])
        f_true = comp.w / (2 * np.pi)
        freqs = np.unique(f_true)
        for g, chans in GROUPS.items():
            model: dict[float, float] = {}
            for c in chans:
                for h, _law, amp, _ in ctx.channel_lines(st, c, np.array([run])):
                    f = h * ctx.omega[run] / (2 * np.pi)
                    k = float(freqs[np.argmin(np.abs(freqs - f))])
                    key = k if abs(k - f) < 1e-3 * f else f
                    model[key] = model.get(key, 0.0) + float(amp[0] * ctx.gain(st, c, np.array([f]))[0]) ** 2 / 2
            true = {float(f): sum(abs(A[f_true == f, fw.CHANNELS.index(c)].sum()) ** 2 / 2 for c in chans)
                    for f in freqs}
            for f in set(model) | set(true):
                mis[g] += abs(model.get(f, 0.0) - true.get(f, 0.0))
                tot[g] += true.get(f, 0.0)
    return {g: mis[g] / tot[g] for g in GROUPS}


@pytest.mark.slow
def test_stand_and_lever_arm_named_against_the_generators_truth(case):
    wheel, data, d = case
    effects = d.model.effects
    assert [e["kind"] for e in effects] == ["suspension_modes", "fixed_resonance", "cross_coupling"], effects
    modes, stand, offset = effects
    for name, truth in wheel.modes_hz().items():
        assert modes[f"{name}_Hz"] == pytest.approx(truth, rel=0.02), (name, modes[f"{name}_Hz"])
    assert stand["role"] == "test_stand"
    assert stand["f_Hz"] == pytest.approx(F_FIX, rel=0.01)
    assert stand["zeta"] == pytest.approx(ZETA_FIX, rel=0.1) and stand["peak_gain"] == pytest.approx(GAIN_FIX, rel=0.1)
    # the fixture's gain returns to 1 far above it (family_effects.peak_resonance): the stand fitted before the offset
    # was named took r × F for a gain above it of 1.0099
    assert abs(stand["gain_above"] - 1.0) < 0.005, stand
    # the lever arm's moment in closed form: a radial force line of the wheel's (no torque of its own) reads in the
    # torques as r × F alone; the diagnosed r applied to the generator's forces gives the generator's torques
    r = np.asarray(offset["r_m"], dtype=float)
    assert abs(r[2] - R_Z) < 1e-3 and np.all(np.abs(r[:2]) < 1e-3), r
    for comp, A in data.components:
        force = [j for j in range(len(comp.w)) if comp.direction[j] == "radial_force"
                 and not np.any((comp.w == comp.w[j]) & (comp.direction != "radial_force"))]
        moment = np.cross(r[None, :], A[force, :3])
        np.testing.assert_allclose(np.abs(moment[:, :2]), np.abs(A[force, 3:5]), rtol=0.03)


@pytest.mark.slow
def test_line_power_near_the_truth_with_the_stand_beside_the_offset(case):
    _, data, d = case
    got = _misplaced(d, data)
    assert got["forces"] < MISPLACED_MAX and got["torques"] < MISPLACED_MAX, got
