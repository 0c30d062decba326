"""The extended fit weighs the measurements of a load cell's far noisier sensor family by the noise under each line
(:func:`rwadist.extended_fit_lsq.noisy_sensor_directions`, :meth:`rwadist.extended_fit_lsq.LogAmplitudeProblem.row_weights`).

A load cell whose force sensors are much noisier than its torque sensors (the family matrix's ``lever_arm_noise``
cell: white noise of std 0.078·C1·Ω_max² on Fx, Fy, Fz, 28 dB over wheel #1's 0.3 % stand noise) measures the
force lines near the noise with a relative error of 10-30 %.  Weighted alike with the lines 60 dB clear of it, they
pulled the 520 Hz translation mode and the 260 Hz axial mode off the generator's (tests/family_wheel.py, its own
physics: the truth here), and diagnose's error after was 12.5x the clean cell's.  Data whose noise is alike across
the load cell are fitted as before: no weights at all.
"""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402

from rwadist.data import Run, SteadyTest  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.extended_fit import fit_extended  # noqa: E402
from rwadist.extended_fit_lsq import NOISY_SENSORS_META, noisy_sensor_directions, recorded_noisy_sensors  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402
from rwadist.stand_resonance import _mode_hz  # noqa: E402

#: the matrix's conditions of wheel #1 (benchmarks/diagnose_family_matrix.py CONDITIONS): speeds, samples, noise
N_SPEEDS, N_SAMPLES, NOISE = 16, 8192, 0.003
#: the extra sensor noise of the matrix's lever_arm_noise cell, fraction of C1·Ω_max² (tests/family_effects.py)
EXTRA_NOISE = 0.078
#: RMS over the seeds of a mode's relative error against the generator's frequency (all rows alike: translation
#: 0.026 %, axial 0.089 % on these seeds)
RMS_TOL = 2e-4


def _test(wheel, seed: int, noisy: str = "") -> SteadyTest:
    """Wheel ``wheel`` at the matrix's conditions, the channels whose name starts with ``noisy`` ("F": the forces,
    "T": the torques, "": none) carrying white noise of std EXTRA_NOISE × the top-speed imbalance load of their
    group besides the stand's."""
    data = fw.steady(wheel, noise=NOISE, seed=seed)
    rng = np.random.default_rng(1000 + seed)
    runs = []
    for i, om in enumerate(data.speeds):
        signals = {}
        for j, c in enumerate(fw.CHANNELS):
            std = data.noise_std[j] / NOISE * EXTRA_NOISE
            extra = std * rng.standard_normal(data.signals.shape[2]) if noisy and c.startswith(noisy) else 0.0
            signals[c] = data.signals[i, j] + extra
        runs.append(Run(speed=float(om), sample_rate=data.sample_rate, t0=0.0, name=f"run_{i:04d}.csv",
                        signals=signals))
    return SteadyTest(runs=runs, meta={})


@pytest.fixture(scope="module")
def wheel():
    return replace(fw.family()[1], n_speeds=N_SPEEDS, n_samples=N_SAMPLES)


@pytest.mark.parametrize("noisy, expected", [("", ()), ("F", ("radial_force", "axial_force")),
                                             ("T", ("radial_torque", "axial_torque"))])
def test_the_noisier_sensor_family_is_told_from_the_imbalance_line(wheel, noisy, expected):
    """Alike noise: no family singled out (the fit stays the plain least squares); 28 dB more on one family: it."""
    fit = fit_empirical(compute_spectra(_test(wheel, 1, noisy)))
    assert noisy_sensor_directions(fit.lines) == expected


def test_a_load_floor_on_the_forces_is_no_noisier_sensor(wheel):
    """The rotor's random loads (the matrix's broadband_floor cell: a floor on the forces growing as Ω³, 15x the
    torques' relative noise under the imbalance line over the speeds) lift the forces' floor at the top speeds, not
    at the slowest: no family is singled out, the fit stays the plain least squares."""
    data = fw.steady(wheel, noise=NOISE, seed=101, effects=[fe.default_effect("broadband_floor", wheel)])
    fit = fit_empirical(compute_spectra(steady_test(data)))
    assert noisy_sensor_directions(fit.lines) == ()


def test_noisy_force_lines_do_not_pull_the_modes(wheel):
    truth = wheel.modes_hz()
    err: dict = {m: [] for m in truth}
    for seed in range(1, 7):
        test = _test(wheel, seed, "F")
        efit = fit_extended(test, fit_empirical(compute_spectra(test)))
        assert not efit.unconstrained
        got = _mode_hz(efit.params)
        for m, f in truth.items():
            err[m].append(got[m] / f - 1)
    rms = {m: float(np.sqrt(np.mean(np.square(e)))) for m, e in err.items()}
    assert all(v < RMS_TOL for v in rms.values()), rms


def _offset_removed(test: SteadyTest, r) -> SteadyTest:
    """``test`` with its torques corrected for the load-cell offset ``r`` (m), T − r × F (as diagnose fits the modes on
    the corrected torques, rwadist.effects.suspension_modes_diagnose._located_corrected), keeping its meta."""
    runs = []
    for run in test.runs:
        F = np.column_stack([run.signals[k] for k in ("Fx", "Fy", "Fz")])
        T = np.cross(np.asarray(r, dtype=float)[None, :], F)
        runs.append(replace(run, signals={**run.signals, **{k: run.signals[k] - T[:, j]
                                                            for j, k in enumerate(("Tx", "Ty", "Tz"))}}))
    return SteadyTest(runs=runs, meta=dict(test.meta))


def test_the_recordings_noisier_family_is_carried_to_the_corrected_torques():
    """The family matrix's lever_arm_noise cell of wheel 5 (its conditions: 16 speeds, 16384 samples, noise 0.01, seed
    501; a load-cell offset r_z = −60 mm, force sensors noisier).  As recorded, the forces' floor is 5.2-8.0x the
    torques' at every speed: the force family is the noisier.  On the torques corrected for the offset the force
    sensors' noise reads in both families (2.9-5.1x) and decided there alone no family is singled out: the modes'
    fit weighs every row alike and the axial mode comes out 5.4e-4 off the generator's.  With the recording's decision
    in the test's meta (as diagnose carries it) the same corrected data weigh the force rows by their noise: the
    translation and axial modes within 1e-4 of the generator's (0.4e-4 both).  The rocking (0.37 % low here, 0.3 % in
    the clean cell too) is not what the weights move."""
    wheel = replace(fw.family()[5], n_speeds=16, n_samples=16384)
    offset = fe.default_effect("lever_arm_noise", wheel)
    data = fw.steady(wheel, noise=0.01, seed=501, effects=[offset])
    recorded = steady_test(data)
    forces = ("radial_force", "axial_force")
    assert noisy_sensor_directions(fit_empirical(compute_spectra(recorded)).without_mode_exclusion.lines) == forces
    corrected = _offset_removed(recorded, offset.params["r"])
    fit_c = fit_empirical(compute_spectra(corrected))
    assert noisy_sensor_directions(fit_c.without_mode_exclusion.lines) == ()
    carried = SteadyTest(runs=corrected.runs, meta={NOISY_SENSORS_META: forces})
    assert recorded_noisy_sensors(carried, fit_c.lines) == forces
    truth = wheel.modes_hz()
    own, held = (_mode_hz(fit_extended(t, fit_c).params) for t in (corrected, carried))
    assert abs(own["axial"] / truth["axial"] - 1) > 3e-4           # decided on the corrected data alone
    for m in ("radial_translation", "axial"):
        assert abs(held[m] / truth[m] - 1) < 1e-4, (m, held[m], truth[m])


def test_a_lever_arm_taken_out_leaves_the_recordings_decision(wheel, monkeypatch):
    """``fit_extended(height=h)`` (``rwadist fit --height``) takes T − h × F out before it measures the lines, which
    puts the force sensors' noise in the torques too: with h = 0.1 m the corrected data no longer single out the force
    family (their floor 2.6-3.5x the torques', under SENSOR_NOISE_EXCESS), though the recording's forces are 28 dB
    noisier (5-9x).  The mode fit weighs by the recording's decision (review13: on 8930074 it read the corrected lines
    and weighed nothing)."""
    import rwadist.extended_fit as efm
    from rwadist.geometry import remove_lever_arm

    test = _test(wheel, 1, "F")
    fit = fit_empirical(compute_spectra(test))
    assert noisy_sensor_directions(fit.without_mode_exclusion.lines) == ("radial_force", "axial_force")
    sp = fit.spectra
    corrected = fit_empirical(compute_spectra(remove_lever_arm(test, 0.1), nperseg=sp.nperseg, f_lim=sp.f_lim,
                                              window=sp.window), fit.fit_settings)
    assert noisy_sensor_directions(corrected.without_mode_exclusion.lines) == ()       # the premise
    seen = []
    problem = efm.LogAmplitudeProblem

    def spy(*args, **kwargs):
        made = problem(*args, **kwargs)
        seen.append(tuple(made.noisy))
        return made

    monkeypatch.setattr(efm, "LogAmplitudeProblem", spy)
    fit_extended(test, fit, height=0.1)
    assert seen == [("radial_force", "axial_force")]
