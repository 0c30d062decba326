"""The axial mode located beside a resonance that moves with speed on the axial force, and the resonance described
(issue 33, "open world": a resonance whose frequency changes with speed in a way the gyroscopic whirl does not
explain; the axial mode has no whirl, its frequency is the same at every speed).

Data: a wheel of this test's own (tests/family_wheel.make_wheel, not one of the family's eight: 10 kg, I_zz/I_rr 1.5,
modes 160/115/80 Hz, 300-3000 rpm at 2.5 kHz, 16 speeds of 4096 samples, noise 0.3 %) with the family's moving
resonance (tests/family_effects.MovingResonance) on the axial force, f_r = sqrt(f0² + (1.5 f_spin)²) with f0 midway
between the axial mode and the highest mode (120 Hz: 120 -> 141 Hz over the speeds), ζ 0.03, peak gain 5.
Reference: the generator's modes and its f_r at the lowest and highest speed.  Before, the axial mode was fitted
with the lines the resonance lifts (pulled and widened, declared unconstrained), the structure mode the modes were
located beside was refused as moving and its modes dropped with it, the misfit of the axial mode held the residual
and nothing was described.
"""
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.data import read_steady  # noqa: E402
from rwadist.stand_resonance import modes_beside_moving  # noqa: E402

#: (wheel, speeds, samples per run, noise, data seed): this test's own wheel, and family wheel 6 at the family
#: matrix's conditions (its axial mode at 85 Hz under a resonance stiffening 117.5 -> 139 Hz: nothing was described)
CASES = {"own": (lambda: fw.make_wheel(9, 10.0, 1.5, 0.15, (160.0, 115.0, 80.0), 3000.0, 2500.0, 11, 0.2, 15.0),
                 16, 4096, 0.003, 7),
         "family6": (lambda: fw.family()[6], 20, 4096, 0.003, 601)}


@pytest.fixture(scope="module", params=sorted(CASES))
def diagnosed(request):
    make, n_speeds, n_samples, noise, seed = CASES[request.param]
    wheel = make()
    # the family's rule (tests/family_effects.default_effect): f0 midway between the axial mode and the highest mode
    effect = fe.MovingResonance(f0_hz=0.5 * (wheel.f_axial + max(wheel.modes_hz().values())), stiffening=1.5)
    speeds = np.linspace(wheel.min_rpm, wheel.max_rpm, n_speeds)
    data = fw.steady(wheel, speeds_rpm=speeds, n_samples=n_samples, noise=noise, seed=seed, effects=(effect,))
    with tempfile.TemporaryDirectory() as tmp:
        test = read_steady(fw.write_steady(data, Path(tmp) / "data", wheel.name))
    truth_track = effect.f_r(np.array([speeds[0], speeds[-1]]) * np.pi / 30.0)
    return wheel, truth_track, api.diagnose(test)


def test_axial_mode_located_beside_the_moving_resonance(diagnosed):
    wheel, _, diag = diagnosed
    assert [e.kind for e in diag.effects] == ["suspension_modes"]          # no class added for the resonance
    modes = diag.effects[0]
    assert "axial" not in modes.unconstrained
    for m, truth in wheel.modes_hz().items():
        assert modes.f0_Hz[m] == pytest.approx(truth, rel=0.02), (m, modes.f0_Hz[m], truth)
    # the resonance is no wheel mode of the model (it moves): no structure mode kept beside the modes
    assert modes.structure is None


def test_moving_resonance_described_on_the_axial_force(diagnosed):
    _, truth_track, diag = diagnosed
    moving = [u for u in diag.unexplained if u.signature == "moving_resonance"]
    assert len(moving) == 1
    p = moving[0].parameters
    assert p["direction"] == "axial_force"
    # a linear track through a stiffening f_r = sqrt(f0² + (1.5 f_spin)²): its ends within 5 % of the truth's, rising
    assert p["f_at_lowest_speed_Hz"] == pytest.approx(truth_track[0], rel=0.05)
    assert p["f_at_highest_speed_Hz"] == pytest.approx(truth_track[1], rel=0.05)
    assert p["slope_Hz_per_Hz_of_spin"] > 0


def test_modes_beside_moving_only_when_they_pin_a_hidden_mode():
    from dataclasses import dataclass, field

    @dataclass
    class Fit:
        unconstrained: tuple
        stand: tuple | None = (130.0, 0.07, 3.5, 1.0)
        stand_direction: str | None = "axial_force"
        notes: list = field(default_factory=lambda: ["structure mode: a resonance at 130 Hz"])

    got = modes_beside_moving(Fit(("axial",)), Fit(()))
    assert got is not None and got.stand is None and got.stand_direction is None
    assert not any(n.startswith("structure mode:") for n in got.notes)
    assert modes_beside_moving(Fit(()), Fit(())) is None                       # nothing hidden: the plain modes stand
    assert modes_beside_moving(Fit(("axial",)), Fit(("axial",))) is None         # pins nothing more
    assert modes_beside_moving(Fit(("axial",)), Fit(("rocking",))) is None       # loses a located mode
