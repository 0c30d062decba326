"""A fixed line is listed on the channels that carry it, not on those the wheel's lines cross it in.

A new user's 9-kg wheel (session 63) with 50/150/250 Hz mains pickup on Fz and Tz only: the 50 Hz line was listed "in
Fx Fy Fz Tx Ty Tz".  With its strong radial lines from 500 to 10000 rpm crossing 50 Hz, 4.9-Hz Welch bins and a lit
threshold 4.3 dB over the floor, the radial channels had a bin within one of 50 Hz lit in 88-93 % of the runs,
4-7 dB over the floor in the median over the runs, where Fz and Tz stood 32-33 dB.  A channel carries the line when its
whole-record amplitude there is steady from run to run, as a source at one frequency is (within 1.5x of its median in
60 % of the runs that read it); the wheel's lines passing give it amplitudes of every size.  A channel absent from
some runs is judged on those that have it.

Data made here with numpy, after the user's wheel: 40 steady runs over 500-10000 rpm (10 kHz, 8192 samples), radial
force and torque lines at h 0.4, 1, 2, 3.6 and 5.4 (C·Ω², co-rotating, a phase of their own per run), axial lines at
h 3.6 and 5.4, white noise 1 % of each channel's top-speed RMS, and the mains family on Fz and Tz."""
import importlib

import numpy as np

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.engine import Context
from rwadist.spectra import compute_spectra

fixed_lines = importlib.import_module("rwadist.diagnose.fixed_lines")
FS, N = 10000.0, 8192
#: the Welch segment ``rwadist diagnose`` reads these runs with (4.9-Hz bins, 14 degrees of freedom a bin)
NPERSEG = 2048
#: (h, C force kg·m, C torque kg·m²) of the radial lines
RADIAL = ((0.4, 4e-7, 6e-8), (1.0, 3e-6, 6e-7), (2.0, 6e-7, 1e-7), (3.6, 3e-7, 5e-8), (5.4, 2e-7, 3e-8))
AXIAL = ((3.6, 2e-7), (5.4, 1.5e-7))


def _with_mains(seed: int) -> SteadyTest:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    speeds = np.linspace(500.0, 10000.0, 40) * 2 * np.pi / 60
    clean = []
    for om in speeds:
        sig = {c: np.zeros(N) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        for h, c_force, c_torque in RADIAL:
            for (cx, cy), c in ((("Fx", "Fy"), c_force), (("Tx", "Ty"), c_torque)):
                ph = rng.uniform(0, 2 * np.pi)
                sig[cx] += c * om**2 * np.cos(h * om * t + ph)
                sig[cy] += c * om**2 * np.sin(h * om * t + ph)
        for h, c in AXIAL:
            sig["Fz"] += c * om**2 * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
            sig["Tz"] += 0.05 * c * om**2 * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
        clean.append(sig)
    std = {c: 0.01 * np.std(clean[-1][c]) for c in clean[-1]}
    runs = []
    for om, sig in zip(speeds, clean):
        for c in sig:
            sig[c] = sig[c] + std[c] * rng.standard_normal(N)
        for k, (f, a) in enumerate(((50.0, 30.0), (150.0, 10.0), (250.0, 6.0))):
            for c in ("Fz", "Tz"):
                sig[c] += a * std[c] * np.cos(2 * np.pi * f * t + 0.7 * k)
        runs.append(Run(float(om), FS, sig, name=f"r{om * 60 / 2 / np.pi:.0f}.csv"))
    return SteadyTest(runs)


def test_mains_pickup_on_the_axial_channels_is_listed_on_them_alone():
    test = _with_mains(63)
    ctx = Context(compute_spectra(test, nperseg=NPERSEG), test=test)
    found = {round(x.f_Hz): x.channels for x in fixed_lines.find_fixed_lines(ctx)}
    assert found.get(50) == ("Fz", "Tz"), found
    assert all(chans == ("Fz", "Tz") for chans in found.values()), found


def test_a_channel_absent_from_some_runs_keeps_its_fixed_line():
    """Tz left out of every other run: the pickup is still listed on Tz (its steadiness is read on the runs that have
    it; counted over every run, the absent ones as unsteady, Tz fell under 60 % and lost the line: a reviewer's case)."""
    from dataclasses import replace

    test = _with_mains(63)
    test = SteadyTest([replace(r, signals={c: v for c, v in r.signals.items() if not (c == "Tz" and i % 2)})
                       for i, r in enumerate(test.runs)])
    ctx = Context(compute_spectra(test, nperseg=NPERSEG), test=test)
    found = {round(x.f_Hz): x.channels for x in fixed_lines.find_fixed_lines(ctx)}
    assert found.get(50) == ("Fz", "Tz"), found


def test_the_line_says_how_far_a_fixed_line_stands_over_the_noise():
    """A fixed line taken out of the data before the search reads ~0 dB over the model in its bins; its line says too
    how far it stands over the noise floor (the new user's 50 Hz pickup, 33 dB, read "+0.1 dB over the model")."""
    from rwadist.diagnose.unexplained import Unexplained

    u = Unexplained(signature="fixed_line", channels=("Fz", "Tz"), speed_rpm=(500.0, 10000.0), f_Hz=(50.0, 50.0),
                    level_dB=0.09, share=0.005, n_runs=40, parameters={"f_Hz": 50.0, "level_over_floor_dB": 33.08,
                                                                       "removed_before_the_search": True})
    assert "+0.1 dB over the model in its bins (median), +33.1 dB over the noise floor at its own bins (taken out of " \
           "the data before the search)" in u.text(), u.text()
