"""A torque reading a load-cell offset's r × F is the offset's, not a copy of another torque.

An offset r puts r × F into every torque (T_x = r_y·F_z − r_z·F_y, T_y = r_z·F_x − r_x·F_z, T_z = r_x·F_y − r_y·F_x).
With r_z large and a lateral part, T_y ≈ r_z·F_x and T_z = r_x·F_y − r_y·F_x on the lines only the radial forces
carry; on a co-rotating line F_y = ∓j·F_x, so T_z is T_y (or T_x) times one complex constant on every such line: a
"copy" to :func:`rwadist.diagnose.channel_copy.find_channel_copies`, which took it out of the records before the
search and with it the equations that tell r's lateral part (trial16's wheel, r = (4, −3, 30) mm: T_z "reads
0.167 × T_y", r fitted (0.04, −0.03, 30.02) mm and the axial mode's 400 Hz, r_x·F_z in the radial torques, named a
'wheel mode'; 8.6x the clean cell's error).

Here family wheels (tests/family_wheel.py, generated without rwadist's physics) on a load cell with
r = (20, 15, 150) mm: no copy is found (on 906dfd9 a T_z copy of T_x in each of wheels 0, 1 and 4); the same wheels
with an instrument's crosstalk T_z += 0.3·T_x and no offset: the copy is still found, at κ 0.3.  The user's
command on wheel 0 (modes 310 / 95 / 140 Hz): r within 0.1 mm and every mode located, nothing else named or
described (906dfd9: r (0.06, 0.18, 149.98) mm, the rocking not located, an amplitude law named, the copy and a
moving resonance described, error 28x).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.api import diagnose  # noqa: E402
from rwadist.diagnose.channel_copy import find_channel_copies  # noqa: E402
from rwadist.diagnose.engine import Context  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402

#: a load-cell reference 150 mm below the rotor centre and 25 mm off its axis (m)
OFFSET_M = (0.020, 0.015, 0.150)


def _copies(index: int, effect) -> list:
    wheel = fw.family()[index]
    data = fw.steady(wheel, noise=0.01, seed=index, effects=[effect])
    test = steady_test(data)
    return find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))


@pytest.mark.parametrize("index", [0, 1, 4])
def test_a_lateral_and_vertical_offset_is_no_torque_copy(index):
    copies = _copies(index, fe.CrossCoupling(OFFSET_M))
    assert [(c.source, c.target) for c in copies] == []


@pytest.mark.parametrize("index", [0, 1, 4])
def test_an_instruments_torque_crosstalk_is_still_a_copy(index):
    copies = _copies(index, fe.Crosstalk("Tx", "Tz", 0.3))
    got = [(c.source, c.target) for c in copies]
    assert got == [("Tx", "Tz")]
    assert abs(copies[0].kappa) == pytest.approx(0.3, rel=0.01)
    assert abs(np.angle(copies[0].kappa)) < 0.01


@pytest.mark.slow
def test_the_offset_is_found_whole_by_the_users_command(tmp_path):
    wheel = fw.family()[0]
    data = fw.steady(wheel, noise=0.01, seed=0, effects=[fe.CrossCoupling(OFFSET_M)])
    d = diagnose(fw.write_steady(data, tmp_path / "data", wheel.name))
    kinds = [e["kind"] for e in d.summary()["effects"]]
    assert kinds == ["suspension_modes", "cross_coupling"]
    modes, cc = d.summary()["effects"]
    assert not modes["unconstrained"]
    assert modes["rocking_Hz"] == pytest.approx(wheel.f_rock, rel=0.02)
    assert cc["r_m"] == pytest.approx(list(OFFSET_M), abs=1e-4)
    assert [u.signature for u in d.unexplained] == []
