"""A force copied into a torque of a load-cell offset's r × F pair (Tz += κ·Fx, Tx += κ·Fz, ...), read on the noise
floor (:func:`rwadist.diagnose.channel_copy._floor_copies`).

trial24: Tz += 0.02·Fx (Fx's sensor noise too) on a 2.4-kg wheel whose Tz has no line of its own.  The pair
(Fx, Tz) is one term of an offset's r × F (T_z = r_x·F_y − r_y·F_x), never tried on the floor, and on the lines
r_y = −20 mm explains Tz to the last digit (a real κ): no copy found, Fx's five lines added to the model as
axial-torque harmonics and an Ω^2.06 law invented on them (land 8f6440e, 3 of 3 seeds).  An offset moves the loads,
not the sensors' noise, and a lever-arm correction of noisy forces moves both terms of r's component (T_z = −r_y·F_x
with T_x = r_y·F_z): a copy is a floor coherence whose mirror pair could be read and is not there.

Here family wheels (tests/family_wheel.py, generated without rwadist's physics) with the copy applied to the records
(lines and sensor noise), κ such that the copy's noise is half the target's own: found at κ within 1 % and in phase.
Controls: the offset's two terms on the same records (no copy); a motor ripple on Tz (lines of its own, at h 1 and
6, random phase per run): no copy, and with the copy the ripple stays in Tz once the copy is taken out (its amplitude
within 2 % of the injected one).  The user's command describes the copy and adds nothing in Tz.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.api import diagnose  # noqa: E402
from rwadist.diagnose.channel_copy import find_channel_copies, remove_channel_copies  # noqa: E402
from rwadist.diagnose.engine import Context  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402

CH = {c: i for i, c in enumerate(fw.CHANNELS)}
#: motor ripple on Tz: (h, amplitude over Tz's noise std at the top speed; ∝ Ω²)
RIPPLE = ((1.0, 30.0), (6.0, 10.0))


def _data(index: int, source: str = "Fx", target: str = "Tz", copy: bool = True, offset: bool = False,
          ripple: bool = False):
    """(wheel, data, κ, ripple amplitudes (runs, lines)) of family wheel ``index``: ``target`` += κ·``source`` on
    the records (κ = half the target's noise std over the source's), or (``offset``) both terms of a load-cell
    offset's r × F of the noisy forces with T_z = −r_y·F_x, T_x = r_y·F_z (r_y = −κ); ``ripple``: :data:`RIPPLE` on
    Tz."""
    wheel = fw.family()[index]
    data = fw.steady(wheel, noise=0.01, seed=index)
    kappa = 0.5 * float(data.noise_std[CH[target]] / data.noise_std[CH[source]])
    fx, fz = data.signals[:, CH["Fx"]].copy(), data.signals[:, CH["Fz"]].copy()
    src = data.signals[:, CH[source]].copy()
    amps = np.zeros((len(data.speeds), len(RIPPLE)))
    if ripple:
        rng = np.random.default_rng([index, 24])
        t = np.arange(data.signals.shape[-1]) / data.sample_rate
        top = float(np.max(data.speeds))
        for i, om in enumerate(data.speeds):
            for j, (h, level) in enumerate(RIPPLE):
                amps[i, j] = level * data.noise_std[CH["Tz"]] * (om / top) ** 2
                data.signals[i, CH["Tz"]] += amps[i, j] * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
    if offset:
        data.signals[:, CH["Tz"]] += kappa * fx
        data.signals[:, CH["Tx"]] -= kappa * fz
    elif copy:
        data.signals[:, CH[target]] += kappa * src
    return wheel, data, kappa, amps


def _copies(data) -> tuple:
    test = steady_test(data)
    return test, find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))


@pytest.mark.parametrize("index,source,target", [(1, "Fx", "Tz"), (4, "Fx", "Tz"), (1, "Fz", "Tx"),
                                                 (4, "Fy", "Tz")])
def test_a_force_copied_into_a_torque_of_an_offset_pair_is_found(index, source, target):
    _, data, kappa, _ = _data(index, source, target)
    _, copies = _copies(data)
    assert [(c.source, c.target) for c in copies] == [(source, target)]
    assert abs(copies[0].kappa) == pytest.approx(kappa, rel=0.01)
    assert abs(np.angle(copies[0].kappa)) < 0.01


@pytest.mark.parametrize("index", [1, 4])
def test_both_terms_of_an_offsets_component_are_no_copy(index):
    _, data, _, _ = _data(index, offset=True)
    _, copies = _copies(data)
    # neither way round: a torque read in a force (Tz -> Fx at 1/κ) is the same offset read backwards
    assert [(c.source, c.target) for c in copies] == []


def _line_amplitude(x, omega_h, fs):
    """Amplitude of the sinusoid at ``omega_h`` (rad/s) in ``x`` by least squares (cos, sin and a constant)."""
    t = np.arange(x.size) / fs
    A = np.column_stack([np.cos(omega_h * t), np.sin(omega_h * t), np.ones_like(t)])
    c = np.linalg.lstsq(A, x, rcond=None)[0]
    return float(np.hypot(c[0], c[1]))


@pytest.mark.parametrize("index", [1, 4])
def test_the_axial_torques_own_lines_are_no_copy_and_stay_when_the_copy_is_taken_out(index):
    _, data, _, _ = _data(index, copy=False, ripple=True)
    assert _copies(data)[1] == []
    _, data, kappa, amps = _data(index, ripple=True)
    test, copies = _copies(data)
    assert [(c.source, c.target) for c in copies] == [("Fx", "Tz")]
    assert abs(copies[0].kappa) == pytest.approx(kappa, rel=0.01)
    clean = remove_channel_copies(test, copies)
    for i in (len(data.speeds) // 2, len(data.speeds) - 1):
        om = float(data.speeds[i])
        for j, (h, _) in enumerate(RIPPLE):
            got = _line_amplitude(np.asarray(clean.runs[i].signals["Tz"]), h * om, data.sample_rate)
            assert got == pytest.approx(amps[i, j], rel=0.02)


def test_the_users_command_describes_the_copy_and_adds_nothing_in_the_axial_torque(tmp_path):
    wheel, data, kappa, _ = _data(1)
    d = diagnose(fw.write_steady(data, tmp_path / "data", wheel.name))
    effects = d.summary()["effects"]
    assert [e["kind"] for e in effects] == ["suspension_modes"]
    modes = effects[0]
    assert not modes["unconstrained"]
    assert modes["rocking_Hz"] == pytest.approx(wheel.f_rock, rel=0.02)
    copy = [u for u in d.unexplained if u.signature == "channel_copy"]
    assert len(copy) == 1 and copy[0].parameters["source"] == "Fx" and copy[0].channels == ("Tz",)
    assert copy[0].parameters["gain"] == pytest.approx(kappa, rel=0.01)
