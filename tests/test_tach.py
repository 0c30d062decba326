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


def test_tach_channel_under_another_name_is_named_as_such(tmp_path):
    # meta.json names the pulse channel "tach", the file calls it "TACH1": the unknown column is named, and so is
    # the tach channel the file lacks (before: only "unknown column")
    d = write_steady_with_tach(tmp_path / "t", 1)
    meta = json.loads((d / "meta.json").read_text())
    meta["tach"]["channel"] = "TACH1"
    (d / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match=r"r0\.csv: tach: unknown column; allowed: .*meta\.json tach\.channel "
                                        r"'TACH1' is not in the file either: if this channel is the tach pulse, name it "
                                        r"there \(file channels: \['Fx_N', 'tach'\]\)"):
        read_steady(d)


@pytest.mark.parametrize("factor", [2, 3])
def test_a_tach_read_with_too_few_pulses_per_rev_is_flagged(tmp_path, factor):
    # a wheel whose tach gives 2 (3) pulses per revolution, read as 1: every speed is 2 (3) times the wheel's and the
    # imbalance fits at h = 1/2 (1/3); the warning names the setting and the value that puts it back at h = 1.  The
    # loads are the E wheel's (Masterson Table 3.4: its imbalance is the strongest radial line), simulated by the
    # stand, the pulses written at the true speed.  The same data read with the right setting: no warning.
    from dataclasses import replace

    from rwadist.api import fit
    from rwadist.data import SteadyTest
    from rwadist.presets import preset
    from rwadist.teststand import simulate_steady
    from rwadist.validate import speed_scale_warning

    sim = simulate_steady(preset("ithaco-e"), np.linspace(600, 2400, 10), sample_rate=2048.0, n_samples=8192,
                          modes=False, noise=0.01, seed=4)
    meta = {"tach": {"channel": "tach", "pulses_per_rev": 1}}
    wrong = SteadyTest([replace(r, speed=r.speed * factor) for r in sim.runs], meta)
    text = speed_scale_warning(fit(wrong), meta)
    assert text is not None and f"h = {1 / factor:.4g} of the speeds given" in text, text
    assert f"tach.pulses_per_rev = 1; {factor} pulses per revolution would put it at h = 1" in text, text
    assert speed_scale_warning(fit(sim), {"tach": {"channel": "tach", "pulses_per_rev": factor}}) is None
    # too many pulses per revolution given (6 for a 6/factor-pulse tach): the imbalance at h = factor
    slow = SteadyTest([replace(r, speed=r.speed / factor) for r in sim.runs], {})
    text = speed_scale_warning(fit(slow), {"tach": {"channel": "tach", "pulses_per_rev": 6}})
    assert text is not None and f"pulses_per_rev = 6; {6 // factor} would put it at h = 1" in text, text
    # the thesis's B wheel: its strongest radial line is h = 8.83, its imbalance 0.61 of it: no warning
    b = simulate_steady(preset("ithaco-b"), np.linspace(600, 3400, 10), sample_rate=1000.0, n_samples=8192,
                        modes=False, noise=0.01, seed=4)
    assert speed_scale_warning(fit(b), None) is None
