"""A copy inside one radial pair (Fy += κ·Fx, Ty += κ·Tx: one bridge of the load cell reading its partner, a
calibration matrix without that off-diagonal term), read on the real part of the pair's noise-floor cross-spectrum.

Trial 30 (an independent generator, a 300/110/170 Hz wheel to 6000 rpm): Fy += 0.2·Fx (Fx's noise too) was passed
over in silence on three seeds ("Nothing ... stands above the noise"), the error after 3.5-4.7× clean: the pair was
never tried (a rotating line fixes its phase), and on the floor the lines' skirts read at ±90° bent the band's lowest
part.  A crosstalk is a real gain; the pair's own coherence is in quadrature.  Which channel carries the copy is read
on the lines: removed from the right one, x and y are left of one amplitude, as a rotating load has them.

Here family wheels (tests/family_wheel.py, generated without rwadist's physics) with the copy applied to the records
(lines and sensor noise): the copy, its way round and its gain (within 0.01) are found; the clean records of every
family wheel hold none; the user's command describes it and locates the modes.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.api import diagnose  # noqa: E402
from rwadist.diagnose.channel_copy import find_channel_copies  # noqa: E402
from rwadist.diagnose.engine import Context  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402


def _data(index: int, source: str | None = None, target: str | None = None, kappa: float = 0.0):
    wheel = fw.family()[index]
    data = fw.steady(wheel, noise=0.01, seed=index)
    if source is not None:
        s, t = fw.CHANNELS.index(source), fw.CHANNELS.index(target)
        data.signals[:, t] += kappa * data.signals[:, s].copy()
    return wheel, data


def _copies(data) -> list:
    test = steady_test(data)
    return find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))


@pytest.mark.parametrize("index, source, target, kappa", [(1, "Fx", "Fy", 0.2), (4, "Fy", "Fx", 0.15),
                                                          (2, "Tx", "Ty", 0.1), (6, "Fx", "Fy", -0.1)])
def test_a_copy_inside_a_radial_pair_is_found_its_way_round(index, source, target, kappa):
    _, data = _data(index, source, target, kappa)
    copies = _copies(data)
    assert [(c.source, c.target) for c in copies] == [(source, target)]
    # within 0.01: the clean pair's own in-phase floor coherence (the lines' skirts) reads up to 0.009 on these wheels
    assert copies[0].kappa.real == pytest.approx(kappa, abs=0.01)
    assert copies[0].kappa.imag == 0.0          # read on the real part: a crosstalk is a gain
    assert copies[0].floor_z > 8


@pytest.mark.parametrize("index", range(8))
def test_clean_records_hold_no_copy_in_a_pair(index):
    _, data = _data(index)
    assert [(c.source, c.target) for c in _copies(data)] == []


def test_the_users_command_describes_the_pairs_copy_and_locates_the_modes(tmp_path):
    wheel, data = _data(1, "Fx", "Fy", 0.2)
    d = diagnose(fw.write_steady(data, tmp_path / "data", wheel.name))
    modes = [e for e in d.summary()["effects"] if e["kind"] == "suspension_modes"]
    assert [e["kind"] for e in d.summary()["effects"]] == ["suspension_modes"] and not modes[0]["unconstrained"]
    for key, truth in (("radial_translation_Hz", wheel.f_trans), ("rocking_Hz", wheel.f_rock),
                       ("axial_Hz", wheel.f_axial)):
        assert modes[0][key] == pytest.approx(truth, rel=0.02)
    (copy,) = [u for u in d.unexplained if u.signature == "channel_copy"]
    assert copy.parameters["source"] == "Fx" and copy.channels == ("Fy",)
    assert copy.parameters["gain"] == pytest.approx(0.2, rel=0.02)
    assert "nan" not in copy.text()
