"""rwadist.diagnose, issue 14 item 4(c): the noise the lever-arm correction moves into the torques (modes on).

A load cell whose reference sits r below the wheel measures T + r × F; its sensors add their noise after that
geometry.  Correcting T' = T − r × F (``cross_coupling``) then puts the force sensors' noise into the
torques, T' = T + n_T − r × n_F, and the corrected torque floor sits above the first noise estimate.
``lever_arm_noise`` fits the transfer κ of Σ r_k² S_Fj (1 by that physics) and gives the diagnosis the
corrected channels' floor; without it, broadband floors (wheel loads!) were patched onto Tx and Ty.

Data: the E wheel (preset "ithaco-e"), extended physics with its suspension modes ON, 20 speeds 300-3000 rpm,
8192 samples at 1920 Hz, Welch nperseg 2048; ``rwadist.inject`` ``cross_coupling:r_z=-0.06,force_noise=0.078``
(what ``simulate-test --inject`` writes): the offset acts on the noise-free forces, then the force sensors carry
white noise of std sqrt(0.01² + 0.078²)·C1_F·Ω_max² and the torque sensors 0.01·C1_T·Ω_max², so that
r_z²σ_F²/σ_T² puts the corrected Tx, Ty floors 2.5 dB up (the issue's case).
Tolerances: r_z within 1 mm, κ within 10 % of 1, the floor rise within 0.3 dB of the closed form
10·log10(1 + r_z²σ_F²/σ_T²), no broadband floor added.  Controls: the same offset with the noise already in the
measured torque (noise before the geometry: no transfer) adds cross_coupling only; clean data add nothing.
"""
from __future__ import annotations

import numpy as np
import pytest

from rwadist import inject
from rwadist.diagnose import diagnose
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady
from rwadist.units import rpm_to_rad_s

E = preset("ithaco-e")
TRUTH = E.to_model()
SPEEDS = np.linspace(300.0, 3000.0, 20)
KW = dict(sample_rate=1920.0, n_samples=8192, noise=0.01, physics="extended")
R_Z, FORCE_NOISE = -0.06, 0.078
SPEC = f"cross_coupling:r_z={R_Z},force_noise={FORCE_NOISE}"


#: sensor noise variances of the generator (N², N²m²): the stand's 1 % and the injected force noise
S_F2 = (0.01**2 + FORCE_NOISE**2) * (E.fundamental_C("radial_force") * rpm_to_rad_s(SPEEDS.max()) ** 2) ** 2
S_T2 = (0.01 * E.fundamental_C("radial_torque") * rpm_to_rad_s(SPEEDS.max()) ** 2) ** 2


def expected_rise_db():
    """10·log10(1 + r_z²σ_F²/σ_T²) of Tx and Ty (Tx' noise gains r_z²·n_Fy, Ty' r_z²·n_Fx)."""
    return 10 * np.log10(1 + R_Z**2 * S_F2 / S_T2)


def run(test):
    return diagnose(compute_spectra(test, nperseg=2048), TRUTH, test=test, base="extended")


def test_the_case_is_the_issues_2_5_db():
    assert expected_rise_db() == pytest.approx(2.5, abs=0.1)


@pytest.mark.parametrize("seed", [0, 1])
def test_lever_arm_noise_found(seed):
    d = run(simulate_with_injections(E, [parse(SPEC)], SPEEDS, seed=seed, **KW))
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds == ["cross_coupling", "lever_arm_noise"]
    cc, ln = d.model.effects
    assert cc["r_m"][2] == pytest.approx(R_Z, abs=1e-3)
    assert ln["noise_transfer"] == pytest.approx(1.0, rel=0.10)
    rise = expected_rise_db()
    for c in ("Tx", "Ty"):
        assert ln["floor_rise_dB"][c] == pytest.approx(rise, abs=0.3)
    assert abs(ln["floor_rise_dB"]["Tz"]) < 0.1          # r_x = r_y = 0: no transfer into Tz
    # the diagnosis's floor of the corrected torques against the closed form: white noise of variance
    # σ_T² + r_z²σ_F² has the one-sided PSD 2(σ_T² + r_z²σ_F²)/f_s
    ctx = d.ctx
    band = slice(ctx.k_lo, ctx.k_hi + 1)
    truth = 2 * (S_T2 + R_Z**2 * S_F2) / KW["sample_rate"]
    level = {c: 10 * np.log10(np.mean(d.state_after.noise[c][band]) / truth) for c in ("Tx", "Ty")}
    assert all(abs(v) < 0.3 for v in level.values())
    print(f"seed {seed}: r_z {cc['r_m'][2]:.5f} kappa {ln['noise_transfer']:.3f} +- {ln['noise_transfer_stderr']:.3f} "
          f"rise Tx {ln['floor_rise_dB']['Tx']:.2f} Ty {ln['floor_rise_dB']['Ty']:.2f} dB (closed form {rise:.2f}); "
          f"floor - closed form: Tx {level['Tx']:+.2f} Ty {level['Ty']:+.2f} dB")


def test_noise_already_in_the_measured_torque_gets_no_transfer():
    """The offset applied to the noisy forces (the sensors' noise before the geometry): the correction removes
    r × n_F with the lines, the corrected floor is n_T, κ ≈ 0: cross_coupling alone."""
    test = simulate_steady(E, SPEEDS, seed=2, **KW)
    rng = np.random.default_rng(7)
    std = FORCE_NOISE * E.fundamental_C("radial_force") * rpm_to_rad_s(SPEEDS.max()) ** 2
    for r in test.runs:
        for c in ("Fx", "Fy", "Fz"):
            r.signals[c] = r.signals[c] + rng.normal(0.0, std, r.n_samples)
    inject.apply(test, E, [parse(f"cross_coupling:r_z={R_Z}")], seed=2)       # clean=None: r × noisy F
    d = run(test)
    assert [e["kind"] for e in d.model.effects] == ["cross_coupling"]


def test_clean_modal_data_add_nothing():
    d = run(simulate_with_injections(E, [], SPEEDS, seed=3, **KW))
    assert d.model.effects == []
