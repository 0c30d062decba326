"""A broadband floor under the lines of a short record (issue 14: the matrix's 2048-sample cells missed it).

At 2048 samples and 3840 Hz diagnose's Welch bins are 7.5 Hz wide; with ±LINE_HALF bins masked around each line,
no bin between 26 and 266 Hz is left at the top speeds, where a floor low-passed at 60 Hz lives.  The floor is
measured there on each run's whole-record spectrum, between the lines
(:func:`rwadist.effects.broadband_floor_diagnose.record_offline_bands`).  Checked against closed forms: the
white sensor noise's PSD 2σ²/fs under strong lines, and the injected floor's PSD (a 2nd-order Butterworth
low-pass of white noise of known RMS, :mod:`rwadist.inject`).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from rwadist import api
from rwadist.diagnose.constants import BAND_BINS
from rwadist.effects.broadband_floor_diagnose import record_offline_bands
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset

FS = 3840.0
N_SAMPLES = 2048
SPEC = "broadband_floor:channels=Fz,level=0.05,exponent=3,fc_hz=60"


@pytest.fixture(scope="module")
def floored():
    """(test, diagnosis) of E-wheel data (modes on, 30 speeds over 300-3000 rpm, 2048 samples) with a floor on Fz,
    diagnosed from the preset's model (its modes and lines: what this run adds to the wheel's model)."""
    wheel = preset("ithaco-e")
    test = simulate_with_injections(wheel, [parse(SPEC)], np.linspace(300.0, 3000.0, 30), physics="extended",
                                    seed=21, sample_rate=FS, n_samples=N_SAMPLES, noise=0.01, test_stand=True)
    return test, api.diagnose(test, wheel.to_model())


def _floor_psd(f_hz, omega, omega_max):
    """One-sided PSD (N²/Hz) of the injected floor at speed ``omega``: white noise of RMS level·C₁·Ω_max²·(Ω/Ω_max)^1.5
    through the 2nd-order Butterworth low-pass at fc (its |H|² normalised by its noise bandwidth up to fs/2)."""
    s = parse(SPEC)
    b, a = signal.butter(2, s["fc_hz"], fs=FS)
    rms = s["level"] * preset("ithaco-e").fundamental_C("radial_force") * omega_max**2 * (omega / omega_max) ** 1.5
    f_all = np.linspace(0.0, FS / 2, 20001)
    bandwidth = np.trapezoid(np.abs(signal.freqz(b, a, worN=f_all, fs=FS)[1]) ** 2, f_all)
    return rms**2 * np.abs(signal.freqz(b, a, worN=np.atleast_1d(f_hz), fs=FS)[1]) ** 2 / bandwidth


def test_whole_record_bands_read_the_white_noise_under_strong_lines(floored):
    """On Tx (no floor: the wheel's torque lines and white sensor noise), every band between the lines reads the
    noise's PSD 2σ²/fs: the lines' leakage, tens of dB above the noise, is taken off with their own phasors."""
    test, d = floored
    ctx = d.ctx
    runs = np.asarray(ctx.runs)
    need = np.ones((runs.size, ctx.n_bands), bool)
    y, cnt, df_rec = record_offline_bands(ctx, d.state_before, "Tx", runs, need)
    assert np.allclose(df_rec, FS / N_SAMPLES)
    white = 2.0 * test.meta["noise_std"]["Tx"] ** 2 / FS
    used = cnt >= 8
    assert used.mean() > 0.9
    # each run's band mean of n exponential bins scatters by 1/sqrt(n); the mean over runs and bands is tight
    assert float(np.sum(y * cnt) / np.sum(cnt)) == pytest.approx(white, rel=0.05)
    assert np.median(y[used] / white) == pytest.approx(1.0, rel=0.1)
    # without the lines' leakage taken off, the bands next to the strongest lines would read far above the noise
    assert np.percentile(y[used] / white, 99) < 2.0


def test_floor_under_the_lines_of_a_short_record_found(floored):
    test, d = floored
    floors = [e for e in d.model.effects if e["kind"] == "broadband_floor"]
    assert [e["channel"] for e in floors] in ([["Fz"]], ["Fz"])
    assert floors[0]["exponent"] == pytest.approx(3.0, abs=0.5)
    assert not [e for e in d.model.effects if e["kind"] != "broadband_floor"]
    # the fitted floor at the reference speed, band by band where it lives (the error metric's 60-Hz bands centred at
    # 56, 116 and 176 Hz, all under the lines at the top speeds), against the injected floor's PSD averaged over each
    # band: within 30 % (it was 1-11 % of it before the whole-record bands)
    e = next(x for x in d.state_after.effects if x.kind == "broadband_floor")
    omegas = np.array([abs(r.speed) for r in test.runs])
    half = 0.5 * BAND_BINS * d.ctx.df
    for f_c, psd in zip(e.knots_f[1:4], e.knots_psd[1:4]):
        truth = _floor_psd(np.linspace(f_c - half, f_c + half, 201), e.omega_ref, omegas.max()).mean()
        assert psd / truth == pytest.approx(1.0, rel=0.3), f_c
