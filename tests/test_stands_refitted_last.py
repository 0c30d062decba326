"""A test-stand resonance named before a load-cell offset is refitted beside it
(:func:`rwadist.effects.fixed_resonance_diagnose.stands_refitted_last`), checked against the generator's stand.

Data: a hard-mounted wheel of this file's own (numpy; the lines of tests/test_cross_coupling_own_weight.py, each of its
own random phase in every run, the sensors' noise of tests/test_describe_offset_floor.py) on a fixture whose transfer is tests/family_effects.py's ``peak_resonance`` (150 Hz,
ζ 0.03, peak gain 5, every channel), the torques read at a reference 30 mm below the bearing centre (T + r × F after
the fixture, as tests/family_wheel.py mixes them), the sensors' noise added last.  The state holds the generator's
own lines (the torques at the bearing centre, as the wheel's modes predict them in the search), then the stand
fitted on it (the torques still holding r × F, which it reads as a gain of its own), then the offset fitted beside
that stand: the order the search names them in.  Truth: the generator's f, ζ, peak gain; the same fit without the
offset in the data reads 150.007 Hz, ζ 0.0300."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from family_effects import peak_resonance  # noqa: E402
from test_describe_offset_floor import NOISE  # noqa: E402

from rwadist.data import Run, SteadyTest  # noqa: E402
from rwadist.diagnose.engine import Context, initial_state  # noqa: E402
from rwadist.effects.cross_coupling_diagnose import CrossCoupling  # noqa: E402
from rwadist.effects.fixed_resonance_diagnose import FixedResonance, stands_refitted_last  # noqa: E402
from rwadist.model import Harmonic, WheelModel  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402

FS, T_RUN, NPERSEG = 2000.0, 4.0, 1024
SPEEDS_RPM = np.linspace(1000.0, 7000.0, 16)
F_FIX, ZETA_FIX, GAIN_FIX = 150.0, 0.03, 5.0
R_Z = 0.030
#: (direction, h, C) of the wheel's lines: kg·m (forces), kg·m² (torques); a radial torque line comparable with r × F
LINES = [("radial_force", 1.0, 2e-6), ("radial_force", 2.0, 1e-7), ("radial_force", 3.4, 5e-8),
         ("radial_force", 0.4, 4e-8), ("axial_force", 1.0, 2e-7), ("axial_force", 2.0, 8e-8),
         ("radial_torque", 1.0, 4e-8), ("radial_torque", 2.0, 6e-9), ("radial_torque", 3.4, 3e-9),
         ("axial_torque", 1.0, 3e-9)]


def _test(r_z: float, seed: int = 3) -> SteadyTest:
    rng = np.random.default_rng(seed)
    n = int(FS * T_RUN)
    t = np.arange(n) / FS
    runs = []
    for i, rpm in enumerate(SPEEDS_RPM):
        om = rpm * np.pi / 30.0
        sig = {c: np.zeros(n) for c in NOISE}
        for d, h, C in LINES:
            a = C * om**2 * peak_resonance(h * om / (2 * np.pi), F_FIX, ZETA_FIX, GAIN_FIX)
            z = a * np.exp(1j * (h * om * t + rng.uniform(0, 2 * np.pi)))
            if d.startswith("radial"):
                sig["Fx" if d == "radial_force" else "Tx"] += z.real
                sig["Fy" if d == "radial_force" else "Ty"] += z.imag           # co-rotating: y lags x by 90°
            else:
                sig["Fz" if d == "axial_force" else "Tz"] += z.real
        F = np.column_stack([sig[c] for c in ("Fx", "Fy", "Fz")])
        rxF = np.cross(np.array([0.0, 0.0, r_z])[None, :], F)
        for j, c in enumerate(("Tx", "Ty", "Tz")):
            sig[c] = sig[c] + rxF[:, j]
        for c, sd in NOISE.items():
            sig[c] = sig[c] + sd * rng.standard_normal(n)
        runs.append(Run(speed=om, sample_rate=FS, signals=sig, name=f"run_{i:02d}.csv"))
    return SteadyTest(runs, {"sample_rate_hz": FS})


def _stand_on(r_z: float):
    """(context, state: the generator's lines with the stand fitted on them, the stand) of the data at ``r_z``."""
    test = _test(r_z)
    ctx = Context(compute_spectra(test, nperseg=NPERSEG), test=test)
    model = WheelModel(name="hard")
    for d, h, C in LINES:
        model.empirical[d].append(Harmonic(h=h, C=C))
    state = initial_state(ctx, model)
    stand = FixedResonance.fit(ctx, state, tuple(ctx.channels), ctx.runs, 1.03 * F_FIX, "test_stand")
    return ctx, stand.apply(state), stand


def _named_in_order(r_z: float):
    """(context, state: the generator's lines, the stand fitted on them, the offset fitted beside the stand)."""
    ctx, state, stand = _stand_on(r_z)
    offset = CrossCoupling.fit(ctx, state, ctx.runs)
    return ctx, offset.apply(state), stand, offset


def test_a_stand_named_before_the_offset_is_refitted_to_the_generators(monkeypatch):
    from rwadist.diagnose import stand_levels

    # the stand fitted with one weight for every line (its fit before the lines' own scatter weighed them,
    # rwadist.diagnose.stand_levels._scatter_weights): the premise, a stand that took part of r × F for itself
    monkeypatch.setattr(stand_levels, "_scatter_weights", lambda res, inverse, w, w_sum: w)
    ctx, state, before, offset = _named_in_order(R_Z)
    monkeypatch.undo()
    assert offset.r[2] == pytest.approx(R_Z, abs=5e-4)
    # named before the offset, the stand took part of r × F for itself (150.7 Hz, ζ 0.036, gain 4.3)
    assert abs(before.f_r / F_FIX - 1) > 0.003 and abs(before.zeta / ZETA_FIX - 1) > 0.1
    out = stands_refitted_last(ctx, state)
    (after,) = [e for e in out.effects if isinstance(e, FixedResonance)]
    assert after is not before and [type(e) for e in out.effects] == [type(e) for e in state.effects]
    # refitted beside the offset: the generator's stand (150.012 Hz, ζ 0.0301, gain 4.99)
    assert after.f_r == pytest.approx(F_FIX, rel=5e-4)
    assert after.zeta == pytest.approx(ZETA_FIX, rel=0.03)
    assert after.peak_gain == pytest.approx(GAIN_FIX, rel=0.03)
    assert ctx.error(out) < 0.1 * ctx.error(state)


def test_without_an_offset_the_state_is_left_as_it_is():
    """No ``cross_coupling`` in the state (the stand alone, on data without an offset): nothing to refit beside."""
    ctx, state, stand = _stand_on(0.0)
    assert stand.f_r == pytest.approx(F_FIX, rel=5e-4) and stand.zeta == pytest.approx(ZETA_FIX, rel=0.03)
    assert stands_refitted_last(ctx, state) is state


def test_weighed_by_their_scatter_the_lines_read_the_stand_before_the_offset():
    """The torques' lines r × F carries scatter about a stand fitted without the offset far more than the forces' do;
    weighed by their own scatter the stand is the generator's before the offset is named (150.006 Hz, ζ 0.0302)."""
    _, _, before, _ = _named_in_order(R_Z)
    assert before.f_r == pytest.approx(F_FIX, rel=3e-4)
    assert before.zeta == pytest.approx(ZETA_FIX, rel=0.03)
    assert before.peak_gain == pytest.approx(GAIN_FIX, rel=0.03)
