"""The open world's detectors read a torque corrected for a load-cell offset (T − r × F, a ``cross_coupling``) against
the floor of the data as the state reads them (:func:`rwadist.diagnose.describe.floor_as_read`).

trial13 (an independent generator, a wheel with its load-cell reference 25 mm below the bearing centre, force sensor
noise added after the geometry as on a real stand): the correction moves r × n_F into the torques (+1 dB of floor);
read against the floor estimated on the uncorrected torques, clean data were described with 4-38 ``speed_line``
records at h 0.26-0.81 in Tx Ty that are not in the data, none with the reference at the centre.

Data: a wheel of this file's own (numpy; not rwadist's simulator, not the E wheel): hard mounted, radial force lines
h 1, 2, 3.4 (rotating), axial force h 1, 2, radial torque h 1, 2, axial torque h 1; 30 runs at 1000-7000 rpm, 2 kHz,
8 s; sensor noise white (4 mN on forces, 0.15 mN·m on torques), added after the torques took r × F with
r = (0, 0, 30 mm): the corrected torques' floor is 0.15² + (30·0.004)² = 1.64 × that of the torque sensors (+2.1 dB,
closed form).  The state read is the generator's truth: its lines at their C, the noise the search starts from
(:func:`rwadist.diagnose.engine.initial_state`, the data as given) and the true offset as a ``cross_coupling``.
"""
from __future__ import annotations

import functools

import numpy as np

from rwadist.diagnose.describe import Residual, describe_residual, floor_as_read
from rwadist.diagnose.engine import Context, initial_state
from rwadist.effects.cross_coupling_diagnose import CrossCoupling
from rwadist.formats.records import Run, SteadyTest
from rwadist.model import Harmonic, WheelModel
from rwadist.spectra import compute_spectra

FS, T_RUN, NPERSEG = 2000.0, 8.0, 1024
SPEEDS_RPM = np.linspace(1000.0, 7000.0, 30)
R = np.array([0.0, 0.0, 0.030])
NOISE = {"Fx": 4e-3, "Fy": 4e-3, "Fz": 4e-3, "Tx": 1.5e-4, "Ty": 1.5e-4, "Tz": 1e-4}
#: (direction, h, C) of the wheel's lines: kg·m (forces), kg·m² (torques)
LINES = [("radial_force", 1.0, 2e-6), ("radial_force", 2.0, 1e-7), ("radial_force", 3.4, 5e-8),
         ("axial_force", 1.0, 2e-7), ("axial_force", 2.0, 8e-8),
         ("radial_torque", 1.0, 8e-8), ("radial_torque", 2.0, 5e-9), ("axial_torque", 1.0, 3e-9)]
#: an undeclared counter-rotating radial torque line (a cage-like ratio): h, C kg·m²
EXTRA = (0.37, 4e-9)


def lever_arm_test(lines, r, speeds_rpm, seed: int) -> SteadyTest:
    """Runs (FS, T_RUN) of the wheel ``lines`` ((direction, h, C): a direction ending in "counter" turns against the
    spin) at ``speeds_rpm``, each line of its own random phase in every run, the torques read at a load-cell reference
    ``r`` (m, 3-vector: T + r × F) and the sensors' noise :data:`NOISE` added after the geometry (a real stand); also
    tests/test_cross_coupling_own_weight.py's data."""
    r = np.asarray(r, dtype=float)
    rng = np.random.default_rng(seed)
    n = int(FS * T_RUN)
    t = np.arange(n) / FS
    runs = []
    for i, rpm in enumerate(speeds_rpm):
        om = rpm * np.pi / 30.0
        sig = {c: np.zeros(n) for c in NOISE}
        for d, h, C in lines:
            a = C * om**2
            ph = h * om * t + rng.uniform(0, 2 * np.pi)
            if d.startswith("radial"):
                s = -1.0 if d.endswith("counter") else 1.0
                x, y = a * np.cos(ph), s * a * np.sin(ph)
                sig["Fx" if d == "radial_force" else "Tx"] += x
                sig["Fy" if d == "radial_force" else "Ty"] += y
            else:
                sig["Fz" if d == "axial_force" else "Tz"] += a * np.cos(ph)
        F = np.column_stack([sig[c] for c in ("Fx", "Fy", "Fz")])
        rxF = np.cross(r[None, :], F)
        for j, c in enumerate(("Tx", "Ty", "Tz")):
            sig[c] = sig[c] + rxF[:, j]
        for c, sd in NOISE.items():             # the sensors' noise after the geometry (a real stand)
            sig[c] = sig[c] + sd * rng.standard_normal(n)
        runs.append(Run(speed=om, sample_rate=FS, signals=sig, name=f"run_{i:02d}.csv"))
    return SteadyTest(runs, {"sample_rate_hz": FS})


def _test(extra: bool, seed: int = 13) -> SteadyTest:
    return lever_arm_test(LINES + ([("radial_torque_counter", *EXTRA)] if extra else []), R, SPEEDS_RPM, seed)


@functools.lru_cache(maxsize=None)
def _truth(extra: bool):
    """(context, the truth as the state the search ends on) of the data with or without the undeclared line."""
    test = _test(extra)
    ctx = Context(compute_spectra(test, nperseg=NPERSEG), test=test)
    model = WheelModel(name="offset13")
    for d, h, C in LINES:
        model.empirical[d].append(Harmonic(h=h, C=C))
    state = CrossCoupling(R.copy(), np.full(3, 1e-5)).apply(initial_state(ctx, model))
    return ctx, state


def _speed_lines(extra: bool) -> list:
    ctx, state = _truth(extra)
    return [u for u in describe_residual(Residual.of(ctx, state)) if u.signature == "speed_line"]


def test_the_corrected_torques_floor_is_the_transfer_of_the_force_noise():
    """The floor the detectors read for Tx and Ty is the corrected data's: over the state's (the torque sensors'
    alone) by 10·log10(1 + (r_z·σ_F/σ_T)²) = 2.15 dB (closed form) within 0.3 dB in the median over the band; Tz,
    which r = (0, 0, r_z) leaves alone, within 0.3 dB of 0."""
    ctx, state = _truth(False)
    read = floor_as_read(ctx, state)
    band = (ctx.f >= ctx.k_lo * ctx.df) & (ctx.f <= ctx.k_hi * ctx.df)
    want = 10 * np.log10(1 + (R[2] * NOISE["Fx"] / NOISE["Tx"]) ** 2)
    for c, expect in (("Tx", want), ("Ty", want), ("Tz", 0.0)):
        rise = float(np.median(10 * np.log10(np.asarray(read.noise[c])[band] / np.asarray(state.noise[c])[band])))
        assert abs(rise - expect) <= 0.3, (c, rise, expect)


def test_clean_data_under_a_load_cell_offset_describe_no_speed_line():
    """The truth of clean data, read corrected: no ``speed_line`` (trial13: 4-38 of them, all in Tx Ty)."""
    found = _speed_lines(False)
    assert found == [], [(u.h, u.f_Hz, u.speed_rpm, u.level_dB) for u in found]


def test_a_true_undeclared_torque_line_under_an_offset_is_still_described():
    """A counter-rotating radial torque line at h 0.37 no model line has: described once, in Tx Ty, at its ratio
    (within the ratio's resolution, one bin of the whole record at the top speed: 0.0171 for 8-s runs to 7000 rpm),
    counter-rotating (share > 0.9), and nothing else is described as a speed line."""
    found = _speed_lines(True)
    assert len(found) == 1, [u.text() for u in found]
    (u,) = found
    assert set(u.channels) == {"Tx", "Ty"}
    assert abs(u.h - EXTRA[0]) <= 1.0 / T_RUN * 60.0 / SPEEDS_RPM.max()
    assert u.parameters["counter_fraction"] > 0.9
