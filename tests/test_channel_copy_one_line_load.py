"""One line of two channels at one complex ratio, whose other lines the target lacks, is a load of the target's own
direction in a fixed phase to the source's, not a copy of the source (:func:`rwadist.diagnose.channel_copy._pair`).

Session 69's new-user trial (its own generator: a rigid rotor whose line phases stay fixed from run to run, a test
stand at 252 Hz on every channel): Fz's 1× line, the axial imbalance, followed Fy's departure from C·Ω² through the
stand at one ratio (0.096 × Fy, the one-line copy's signature), was read as crosstalk and taken out before the search:
the axial 1× line went to 0.016 of its truth and the axial mode was "not located".  Fy's other lines stood in Fz at
0.0004-0.002 of that ratio: a copy scales every line of its source alike.

Data: the family generator (tests/family_wheel.py, numpy only) on the session-68 trial's wheel A line set with the axial
1× line turning with the imbalance (a fixed phase to it in every run) and a fixture resonance (tests/family_effects.py)
inside the 1× line's range, on three wheels; an instrument's copy of Tx into Tz on the same data is still found."""
import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

#: (translation, rocking, axial Hz, fixture Hz, top speed rpm, sample rate Hz)
WHEELS = [(300.0, 60.0, 380.0, 60.0, 4800.0, 2000.0), (420.0, 70.0, 520.0, 110.0, 9000.0, 4000.0),
          (180.0, 110.0, 260.0, 75.0, 6000.0, 4000.0)]
#: the axial 1× line's phase ahead of the radial imbalance's (rad)
AXIAL_PHASE = 0.7


class _AxialWithImbalance:
    """The axial 1× line turning with the rotor's imbalance: its phase the radial imbalance's plus
    :data:`AXIAL_PHASE` in every run (an axial runout of the imbalanced rotor), its amplitude the wheel's."""

    def components(self, comp, omega, run, rng, wheel):
        imbalance = next(i for i, (d, tag, s) in enumerate(zip(comp.direction, comp.tag, comp.sense))
                         if d == "radial_force" and tag == "imbalance" and s > 0)
        c = comp.c.copy()
        for i, (d, w) in enumerate(zip(comp.direction, comp.w)):
            if d == "axial_force" and abs(w / omega - 1.0) < 1e-9:
                c[i] = abs(c[i]) * np.exp(1j * (np.angle(c[imbalance]) + AXIAL_PHASE))
        return fw.Components(comp.direction, comp.w, comp.sense, c, comp.tag)


def _wheel(row) -> fw.Wheel:
    f_trans, f_rock, f_axial, _, top, rate = row
    return dataclasses.replace(fw.trial_wheel_a(), f_trans=f_trans, f_rock=f_rock, f_axial=f_axial, max_rpm=top,
                               sample_rate=rate)


def _copies(data) -> list:
    from rwadist.api import diagnose_nperseg
    from rwadist.diagnose.channel_copy import find_channel_copies
    from rwadist.diagnose.engine import Context
    from rwadist.spectra import compute_spectra

    test = steady_test(data)
    return find_channel_copies(Context(compute_spectra(test, nperseg=diagnose_nperseg(test)), None, test))


@pytest.mark.parametrize("row", WHEELS)
def test_an_axial_line_in_a_fixed_phase_to_the_imbalance_is_no_copy_and_a_true_copy_still_is(row):
    wheel = _wheel(row)
    effects = [_AxialWithImbalance(), fe.Fixture(row[3], 0.03, 6.0)]
    assert _copies(fw.steady(wheel, noise=0.01, seed=0, effects=effects)) == []
    # an instrument's crosstalk on the same data: every torque line of Tx in Tz (which has none of its own)
    copied = _copies(fw.steady(wheel, noise=0.01, seed=0, effects=effects + [fe.Crosstalk("Tx", "Tz", 0.3)]))
    assert [(c.source, c.target) for c in copied] == [("Tx", "Tz")], copied
    assert copied[0].kappa == pytest.approx(0.3, rel=0.01), copied


def test_the_default_command_keeps_the_axial_line_and_locates_the_axial_mode():
    from rwadist.api import diagnose

    wheel = _wheel(WHEELS[0])
    data = fw.steady(wheel, noise=0.01, seed=1, effects=[_AxialWithImbalance(), fe.Fixture(WHEELS[0][3], 0.03, 6.0)])
    diag = diagnose(steady_test(data))
    assert not [u for u in diag.unexplained if u.signature == "channel_copy"], diag.unexplained
    (modes,) = [e for e in diag.state_after.effects if getattr(e, "kind", "") == "suspension_modes"]
    assert not modes.unconstrained and modes.f0_Hz["axial"] == pytest.approx(wheel.f_axial, rel=0.01), modes
    (axial,) = [x for x in diag.model.harmonics("axial_force") if abs(x.h - 1.0) < 1e-3]
    truth = next(ln.C for ln in wheel.lines if ln.direction == "axial_force" and ln.h == 1.0)
    assert axial.C == pytest.approx(truth, rel=0.05), (axial.C, truth)
