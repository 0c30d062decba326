"""Tach pulse channel as the speed source (issue 15): steady runs and a 0 -> 2400 rpm sweep within 0.05 % of
the truth with 1 and 60 pulses per revolution; a missing pulse and a double trigger are refused and named.
The pulse trains are sampled TTL levels with instantaneous edges (the worst case for edge timing) and noise."""
from __future__ import annotations

import json

import numpy as np
import pytest

from rwadist.data import DataError, read_steady, read_sweep
from rwadist.units import rpm_to_rad_s

FS = 25600.0  # a DAQ rate that resolves 60 pulses/rev at 2400 rpm (2.4 kHz pulse rate)
N = 32768
SPEEDS_RPM = (307.3, 1234.5, 2399.1)  # periods not a whole number of samples: edge timing errors differ


def ttl(angle: np.ndarray, ppr: int, seed=0) -> np.ndarray:
    """A 0/5 V pulse train, 50 % duty, ``ppr`` pulses per revolution of ``angle`` (rad), 20 mV noise."""
    level = 5.0 * ((angle * ppr / (2 * np.pi)) % 1.0 < 0.5)
    return level + 0.02 * np.random.default_rng(seed).standard_normal(len(angle))


def write_steady_with_tach(d, ppr, edit=None):
    d.mkdir()
    lines = ["file,speed_rpm"]
    t = np.arange(N) / FS
    for i, rpm in enumerate(SPEEDS_RPM):
        omega = float(rpm_to_rad_s(rpm))
        angle = 0.7 + omega * t
        pulse = ttl(angle, ppr, seed=i)
        if edit is not None and i == 1:
            edit(pulse)
        fx = 0.3 * np.sin(angle) + 0.01 * np.random.default_rng(10 + i).standard_normal(N)
        np.savetxt(d / f"r{i}.csv", np.column_stack([t, fx, pulse]), delimiter=",", fmt="%.10g",
                   header="time_s,Fx_N,tach", comments="")
        lines.append(f"r{i}.csv,")  # no speed: the tach gives it
    (d / "runs.csv").write_text("\n".join(lines) + "\n")
    (d / "meta.json").write_text(json.dumps({"sample_rate_hz": FS, "tach": {"channel": "tach",
                                                                               "pulses_per_rev": ppr}}))
    return d


@pytest.mark.parametrize("ppr", [1, 60])
def test_steady_speed_from_tach(tmp_path, ppr):
    test = read_steady(write_steady_with_tach(tmp_path / "t", ppr))
    truth = rpm_to_rad_s(SPEEDS_RPM)
    err = np.abs(test.speeds / truth - 1)
    assert err.max() < 5e-4, err
    assert test.runs[0].channels == ("Fx",)  # the tach channel is not a load channel


def _drop_pulse(pulse):
    """Remove the 5th pulse (its samples go low): a missing pulse."""
    rising = np.flatnonzero((pulse[1:] > 2.5) & (pulse[:-1] <= 2.5)) + 1
    falling = np.flatnonzero((pulse[1:] <= 2.5) & (pulse[:-1] > 2.5)) + 1
    a = rising[4]
    pulse[a: falling[falling > a][0]] = 0.0


def _glitch(pulse):
    """A 3-sample spike in the middle of a low period: a double trigger."""
    falling = np.flatnonzero((pulse[1:] <= 2.5) & (pulse[:-1] > 2.5)) + 1
    rising = np.flatnonzero((pulse[1:] > 2.5) & (pulse[:-1] <= 2.5)) + 1
    a = falling[6]
    b = rising[rising > a][0]
    mid = (a + b) // 2
    pulse[mid: mid + 3] = 5.0


@pytest.mark.parametrize("ppr", [1, 60])
@pytest.mark.parametrize("edit, what", [(_drop_pulse, "missing pulse"), (_glitch, "double trigger")])
def test_missing_pulse_and_double_trigger_are_named(tmp_path, ppr, edit, what):
    d = write_steady_with_tach(tmp_path / "t", ppr, edit=edit)
    with pytest.raises(DataError) as info:
        read_steady(d)
    msg = str(info.value)
    assert str(d / "r1.csv") in msg and "channel tach" in msg and what in msg and "t = " in msg, msg


@pytest.mark.parametrize("ppr", [1, 60])
def test_sweep_speed_from_tach(tmp_path, ppr, stand_sweep):
    sweep = stand_sweep("ithaco-e", rpm_start=0.0, rpm_end=2400.0, duration=20.0, sample_rate=FS, seed=2, tach=True)
    truth = sweep.tach
    angle = np.concatenate([[0.0], np.cumsum(0.5 * (truth[1:] + truth[:-1]) / FS)])
    path = tmp_path / "sweep.csv"
    np.savetxt(path, np.column_stack([sweep.time, sweep.signals["Fx"], ttl(angle, ppr)]), delimiter=",",
               fmt="%.10g", header="time_s,Fx_N,tach", comments="")
    (tmp_path / "sweep.meta.json").write_text(json.dumps({"tach": {"channel": "tach", "pulses_per_rev": ppr}}))
    back = read_sweep(path)
    moving = truth >= rpm_to_rad_s(60.0)  # from the first second of the spin-up on
    err = np.abs(back.tach[moving] / truth[moving] - 1)
    assert err.max() < 5e-4, err.max()
