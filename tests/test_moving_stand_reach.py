"""A resonance reached only by the faster runs' lines is split on the runs that reach it (the session-68 trial).

The trial's own numpy generator: a 12-kg wheel over 200-4200 rpm (36 runs) whose structure under the load cell has a
resonance falling 512 -> 400 Hz with the speed on every channel, H = 1 + μr²/(1 − r² + 2jζr), μ 0.3, ζ 0.03.  Its
lines reach 400-500 Hz only above ~2400 rpm: the slower half of the runs (200-2200 rpm) held no line within its reach,
:func:`rwadist.effects.fixed_resonance_diagnose.speed_split` told nothing and a 'test stand' at 421.5 Hz on every
channel was added, I_zz/I_rr 3 % off; on wheel A (300-6000 rpm) 'wheel modes' at 399 and 413 Hz on one direction.
Now the runs that reach it are split (:func:`rwadist.diagnose.fixed_resonance_moving.split_halves`): the stand is refused
as moving, and so is one direction's resonance in its reach (:func:`rwadist.diagnose.fixed_resonance_moving.in_moving_reach`);
a stand as high that does not move is kept.  Refused, it is described as one ``moving_resonance`` on every direction's
lines pooled (:mod:`rwadist.diagnose.describe_pooled`; no direction's lines read its slope alone), and the amplitude
laws fitted to its rise are taken back (before: h 4.31 Ω^2.2 on Fz and Tx, Ty; h 2 Ω^2.07 and h 3.62 Ω^2.27 on wheel A).

Data: tests/structure_mode_wheel.py (its transfer functions and phasors, not rwadist's physics): 24 steady speeds over
400-6000 rpm, a structure resonance on all six channels falling 560 -> 440 Hz (its lines reach it above ~3500 rpm);
and log power gains written here from the same shape for the split itself.
"""
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from structure_mode_wheel import write_runs  # noqa: E402

import rwadist.effects.fixed_resonance_diagnose as frd  # noqa: E402
from rwadist.diagnose.fixed_resonance_moving import in_moving_reach  # noqa: E402
from rwadist.effects.fixed_resonance_diagnose import FixedResonance  # noqa: E402

#: the trial's wheel B: its lines (h) and speeds, the resonance's ends, mass share and damping
HS = (0.385, 1.0, 2.0, 4.31, 6.69, 8.62)
RPM = np.linspace(200.0, 4200.0, 36)
ENDS, MU, ZETA = (512.0, 400.0), 0.3, 0.03


def _shape(f, f_s):
    """1 + μr²/(1 − r² + 2jζr), r = f/f_s: a mode holding a share μ of the load, written here."""
    r = f / f_s
    return 1.0 + MU * r**2 / (1.0 - r**2 + 2j * ZETA * r)


def _points(track, rng):
    """A fake (ctx, points of the runs asked) of the lines h·f_spin through ``_shape`` on ``track(rpm)`` Hz, 0.05 of
    scatter on each log power gain; with the lines (their ids and (direction, h)) when asked."""
    omega = RPM / 60.0 * 2 * np.pi
    ctx = SimpleNamespace(runs=np.arange(RPM.size), omega=omega, channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"),
                          df=0.61, k_lo=7, k_hi=2040)
    noise = rng.normal(0.0, 0.05, (RPM.size, len(HS)))

    def points(ctx_, state, chans, runs, with_lines=False):
        runs = np.asarray(runs)
        f = np.asarray(HS)[None, :] * (omega[runs] / (2 * np.pi))[:, None]
        y = np.log(np.abs(_shape(f, track(RPM[runs])[:, None])) ** 2) + noise[runs]
        ids = np.broadcast_to(np.arange(len(HS)), f.shape).ravel()
        out = (f.ravel(), y.ravel(), np.ones(f.size), np.full(f.size, "axial_torque"))
        return out + (ids, [("axial_torque", h) for h in HS], np.ones(f.size)) if with_lines else out
    return ctx, points


def _falling(rpm):
    return ENDS[0] + (rpm - RPM[0]) / (RPM[-1] - RPM[0]) * (ENDS[1] - ENDS[0])


def test_a_resonance_above_the_slower_runs_lines_is_split_on_the_runs_that_reach_it(monkeypatch):
    """The falling resonance: the slower half of every run reaches it nowhere (before: no split, the stand kept); on the
    runs that reach it the slower half wants a higher centre than the faster, beyond ζ: refused.  The same shape held
    at 456 Hz: the halves agree within 0.5 %, kept."""
    proposed = FixedResonance(421.5, 0.034, 4.2, ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"), "test_stand", gain_above=0.72)
    ctx, points = _points(_falling, np.random.default_rng(24))
    monkeypatch.setattr(frd, "_line_gain_points", points)
    slow = points(ctx, None, (), np.arange(RPM.size // 2))[0]
    assert slow.max() < 0.85 * proposed.f_r                              # every line of the slower half under it
    split = frd.speed_split(ctx, None, proposed)
    assert split is not None and split["f_slow_Hz"] > split["f_fast_Hz"]
    assert split["evidence"] > 0 and split["moved"] > max(split["zeta"], frd.SPLIT_MIN_MOVE)
    assert ENDS[1] * (1 - ZETA) <= split["f_fast_Hz"] < split["f_slow_Hz"] <= _falling(RPM[RPM.size // 2]), split
    assert frd.moves_with_speed(ctx, None, proposed)

    ctx, points = _points(lambda rpm: np.full(np.shape(rpm), 456.0), np.random.default_rng(24))
    monkeypatch.setattr(frd, "_line_gain_points", points)
    fixed = FixedResonance(456.0, 0.03, 5.0, proposed.channels, "test_stand", gain_above=0.7)
    split = frd.speed_split(ctx, None, fixed)
    assert split is not None
    assert split["f_slow_Hz"] == pytest.approx(456.0, rel=0.005) and split["f_fast_Hz"] == pytest.approx(456.0, rel=0.005)
    assert not frd.moves_with_speed(ctx, None, fixed)


def test_a_resonance_of_one_direction_in_a_moving_ones_reach_is_refused():
    """A 'wheel mode' on the radial torques at 399 Hz beside the every-channel resonance refused as moving (433 Hz on
    the slower runs that reach it, 414 Hz on the faster, ζ 0.028) lies in its reach; one at 300 Hz does not, nor is a
    resonance refused for a moving one of fewer channels (a stand beside a moving resonance of one direction)."""
    stand = FixedResonance(417.8, 0.031, 4.8, ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"), "test_stand")
    moving = [(stand, {"f_slow_Hz": 433.3, "f_fast_Hz": 413.9, "zeta": 0.0294})]
    assert in_moving_reach(FixedResonance(399.0, 0.03, 5.0, ("Tx", "Ty"), "wheel_mode"), moving)
    assert not in_moving_reach(FixedResonance(300.0, 0.03, 5.0, ("Tx", "Ty"), "wheel_mode"), moving)
    one = [(FixedResonance(417.8, 0.031, 4.8, ("Tx", "Ty"), "wheel_mode"), moving[0][1])]
    assert not in_moving_reach(FixedResonance(410.0, 0.03, 5.0, ("Fx", "Fy"), "wheel_mode"), one)
    assert not in_moving_reach(FixedResonance(420.0, 0.03, 5.0, stand.channels, "test_stand"), one)
    assert not in_moving_reach(stand, moving)


#: the generator's structure resonance on every channel, falling 560 -> 440 Hz over 400-6000 rpm (a stand's shape)
SPEEDS = np.linspace(400.0, 6000.0, 24)
FALLING = dict(f0=560.0 + 120.0 * 400.0 / 5600.0, slope=-120.0 / 5600.0, zeta=0.03, mu=0.3,
               channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))


def _truth_hz(rpm):
    return FALLING["f0"] + FALLING["slope"] * rpm


def test_a_structure_resonance_falling_with_speed_is_no_fixed_resonance(tmp_path):
    """The generator's wheel with the falling resonance on every channel: no ``fixed_resonance`` is added (before: a
    'test stand' at 465 Hz on every channel, the slower half of the runs under its reach; with the stand refused
    alone, a 'wheel mode' at 444 Hz on the radial torques), and the wheel's modes where they were (within 1 %).  It is
    described as one ``moving_resonance`` on the lines of every direction pooled
    (:func:`rwadist.diagnose.describe_pooled.pooled_moving_resonance`: no direction's lines read its slope alone), its
    track falling within 5 % of the truth over the speeds its lines read it at, and the rise below it is no
    ``amplitude_law`` (before: the radial force's h 2 as Ω^2.06, the resonance described nowhere)."""
    from rwadist import api

    got = api.diagnose(api.read(write_runs(tmp_path / "runs", SPEEDS, 3, FALLING)))
    kinds = [(e["kind"], round(e.get("f_Hz", 0.0), 1)) for e in got.model.effects]
    assert not [k for k in kinds if k[0] == "fixed_resonance"], kinds
    assert not [k for k in kinds if k[0] == "amplitude_law"], kinds
    tracks = [u for u in got.unexplained if u.signature == "moving_resonance"]
    assert len(tracks) == 1, [(u.channels, u.f_Hz) for u in tracks]
    p = tracks[0].parameters
    assert p["slope_Hz_per_Hz_of_spin"] < 0 and p["direction"] == "pooled"
    assert {"Fx", "Fy", "Fz"} <= set(tracks[0].channels)
    lo, hi = tracks[0].speed_rpm
    assert hi == pytest.approx(SPEEDS[-1]) and hi - lo >= 0.2 * (SPEEDS[-1] - SPEEDS[0])
    assert p["f_at_lowest_speed_Hz"] == pytest.approx(_truth_hz(lo), rel=0.05)
    assert p["f_at_highest_speed_Hz"] == pytest.approx(_truth_hz(hi), rel=0.05)
    modes = next(e for e in got.model.effects if e["kind"] == "suspension_modes")
    assert modes["radial_translation_Hz"] == pytest.approx(180.0, rel=0.01)
    assert modes["rocking_Hz"] == pytest.approx(95.0, rel=0.01)
    assert modes["axial_Hz"] == pytest.approx(260.0, rel=0.01)
