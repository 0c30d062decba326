"""Spectra of steady runs (rwadist.spectra) against closed forms: Parseval, the
Hann window's scalloping loss, the one-sided white-noise level 2σ²/fs, chi²
false-alarm rates by Monte-Carlo."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from rwadist.data import DataError, Run, SteadyTest
from rwadist.spectra import (
    compute_spectra,
    cumulative_rms,
    detection_threshold,
    find_lines,
    line_amplitude,
    line_power,
    noise_floor,
    rms,
    welch_dof,
)

FS = 1024.0
NPERSEG = 1024  # df = 1 Hz
DF = FS / NPERSEG


def single(x, fs=FS, channel="Fx", name="r.csv", speed=100.0):
    return SteadyTest([Run(speed=speed, sample_rate=fs, signals={channel: x}, name=name)])


def sine(f0, amplitude, n, fs=FS, phase=0.7):
    return amplitude * np.sin(2 * np.pi * f0 * np.arange(n) / fs + phase)


def hann_scallop(delta):
    """Amplitude response of a Hann window to a sinusoid ``delta`` bins off a bin centre."""
    return np.sinc(delta) / (1.0 - delta**2)


# --------------------------------------------------------------------------- PSD, amplitude, RMS

def test_parseval_noise_plus_sine():
    rng = np.random.default_rng(1)
    n = 2**15
    x = 0.5 * rng.standard_normal(n) + sine(123.4, 2.0, n) + 0.1  # offset removed by the constant detrend
    sp = compute_spectra(single(x), nperseg=NPERSEG)
    mean_square = np.mean((x - x.mean()) ** 2)  # 2.2464
    integral = np.sum(sp.psd["Fx"][0]) * sp.df
    assert integral == pytest.approx(mean_square, rel=0.02)
    assert rms(sp.psd["Fx"][0], sp.f) ** 2 == pytest.approx(integral, rel=1e-12)
    assert sp.f[1] - sp.f[0] == sp.df == DF
    assert sp.n_segments[0] == 1 + (n - NPERSEG) // (NPERSEG // 2)


def test_amplitude_spectrum_reads_bin_centred_sine():
    amp = 1.7
    sp = compute_spectra(single(sine(100 * DF, amp, 2**14)), nperseg=NPERSEG)
    a = sp.amplitude["Fx"][0]
    assert int(np.argmax(a)) == 100
    assert a[100] == pytest.approx(amp, rel=1e-9)
    # the same line measured by its power (Parseval) agrees
    assert line_amplitude(sp.psd["Fx"][0], sp.f, 100 * DF) == pytest.approx(amp, rel=1e-9)


@pytest.mark.parametrize("delta", [0.37, 0.5])
def test_off_bin_sine_line_amplitude_vs_scalloping(delta):
    amp = 0.8
    f0 = (200 + delta) * DF
    sp = compute_spectra(single(sine(f0, amp, 2**14)), nperseg=NPERSEG)
    peak = np.max(sp.amplitude["Fx"][0])
    # the Hann amplitude spectrum reads low by the scalloping loss (8.5 % at 0.37 bin, 15.1 % at half a bin)
    assert peak / amp == pytest.approx(hann_scallop(delta), rel=2e-3)
    assert peak < (0.92 if delta == 0.37 else 0.86) * amp
    # the power under the line does not depend on where it falls
    assert line_amplitude(sp.psd["Fx"][0], sp.f, f0) == pytest.approx(amp, rel=0.01)


def test_line_amplitude_with_noise_and_floor():
    """Noise in the 7 summed bins biases the line power; subtracting the floor removes it."""
    rng = np.random.default_rng(5)
    n, sigma, amp, f0 = 2**16, 1.0, 0.3, 300.37
    x = sigma * rng.standard_normal(n) + sine(f0, amp, n)
    sp = compute_spectra(single(x), nperseg=NPERSEG)
    psd = sp.psd["Fx"][0]
    floor = noise_floor(psd, sp.f, dof=welch_dof(sp.n_segments[0]))
    raw = line_amplitude(psd, sp.f, f0)
    corrected = line_amplitude(psd, sp.f, f0, floor=floor)
    # noise adds ~7 bins x 2σ²/fs x df = 0.0137 to the power 0.045
    assert raw > 1.1 * amp
    assert corrected == pytest.approx(amp, rel=0.05)


def test_cumulative_rms_ends_at_total_and_matches_bands():
    rng = np.random.default_rng(2)
    n = 2**14
    runs = [Run(speed=s, sample_rate=FS, signals={"Tz": 0.01 * rng.standard_normal(n) + sine(50 + s, 0.02, n)},
                name=f"r{s}") for s in (10, 20, 30)]
    sp = compute_spectra(SteadyTest(runs), nperseg=NPERSEG)
    psd, f = sp.psd["Tz"], sp.f
    cum = cumulative_rms(psd, f)
    total = rms(psd, f)
    np.testing.assert_allclose(cum[:, -1], total, rtol=1e-12)
    assert np.all(np.diff(cum, axis=-1) >= 0)
    # a band from the running version: cum²(f2) - cum²(f1 - df) = band²
    i1, i2 = 40, 200
    band = rms(psd, f, f[i1], f[i2])
    np.testing.assert_allclose(cum[:, i2] ** 2 - cum[:, i1 - 1] ** 2, band**2, rtol=1e-10)
    # each band holds its sine (0.02²/2) plus the band's noise, 2σ²/fs per Hz
    expected = 0.02**2 / 2 + 2 * 1e-4 / FS * (f[i2] - f[i1] + DF)
    np.testing.assert_allclose(band**2, expected, rtol=0.05)


# --------------------------------------------------------------------------- noise floor and detection

@pytest.mark.parametrize("n_samples", [NPERSEG, 2**16])  # one segment (dof 2) and 127 Welch averages
def test_noise_floor_estimates_white_noise_level(n_samples):
    rng = np.random.default_rng(3)
    sigma = 0.3
    runs = [Run(speed=float(i), sample_rate=FS, signals={"Fy": sigma * rng.standard_normal(n_samples)})
            for i in range(4)]
    sp = compute_spectra(SteadyTest(runs), nperseg=NPERSEG)
    dof = welch_dof(sp.n_segments[0])
    floor = noise_floor(sp.psd["Fy"], sp.f, dof=dof)
    level = 2 * sigma**2 / FS  # one-sided PSD of white noise
    interior = slice(20, -20)
    assert np.median(floor[:, interior]) / level == pytest.approx(1.0, rel=0.05)
    assert np.mean(floor[:, interior]) / level == pytest.approx(1.0, rel=0.10)
    # without the chi² median correction a single-segment floor would read ln 2 = 0.69 of the level
    if dof == 2.0:
        assert np.median(np.median(sp.psd["Fy"][:, interior], axis=1)) / level == pytest.approx(np.log(2), rel=0.1)


@pytest.mark.parametrize("n_samples, p_false", [(512, 0.1), (512, 0.05), (8192, 0.1)])
def test_detection_threshold_false_alarm_rate(n_samples, p_false):
    """400 pure-noise spectra against the true mean level: the fraction with any bin over the
    threshold is p_false (binomial sd 0.015 at 0.1)."""
    nperseg, n_spectra = 512, 400
    rng = np.random.default_rng(4)
    x = rng.standard_normal((n_spectra, n_samples))
    test = SteadyTest([Run(speed=float(i), sample_rate=FS, signals={"Fz": x[i]}) for i in range(n_spectra)])
    sp = compute_spectra(test, nperseg=nperseg)
    psd = sp.psd["Fz"][:, 1:-1]  # DC and Nyquist are not line candidates
    dof = welch_dof(sp.n_segments[0])
    thr = detection_threshold(dof, psd.shape[1], p_false)
    rate = np.mean(np.any(psd > thr * 2.0 / FS, axis=1))
    sd = np.sqrt(p_false * (1 - p_false) / n_spectra)
    assert abs(rate - p_false) < 3 * sd, (rate, p_false)
    if dof == 2.0:  # exponential bins: closed form
        assert thr == pytest.approx(-np.log(p_false / psd.shape[1]), rel=1e-12)


# noise_floor once padded with the DC and Nyquist bins and read low near both ends (fixed).


def test_noise_floor_unbiased_near_band_edges():
    rng = np.random.default_rng(12)
    x = rng.standard_normal((50, 8192))
    test = SteadyTest([Run(speed=float(i), sample_rate=FS, signals={"Fz": x[i]}) for i in range(50)])
    sp = compute_spectra(test, nperseg=512)
    floor = noise_floor(sp.psd["Fz"], sp.f, dof=welch_dof(sp.n_segments[0]))
    ratio = floor.mean(axis=0) / (2.0 / FS)
    np.testing.assert_allclose(ratio[1:6], 1.0, rtol=0.1)  # now 0.70 ... 0.86
    np.testing.assert_allclose(ratio[-6:-1], 1.0, rtol=0.1)  # now ~0.85 ... 0.74


def test_detection_with_estimated_floor_false_alarm_rate():
    """The pipeline the fitter uses (noise_floor + detection_threshold) on 400 pure-noise spectra of
    15 Welch averages (dof 59)."""
    nperseg, n_spectra, n_samples, p_false = 512, 400, 8192, 0.1
    rng = np.random.default_rng(4)
    x = rng.standard_normal((n_spectra, n_samples))
    test = SteadyTest([Run(speed=float(i), sample_rate=FS, signals={"Fz": x[i]}) for i in range(n_spectra)])
    sp = compute_spectra(test, nperseg=nperseg)
    dof = welch_dof(sp.n_segments[0])
    floor = noise_floor(sp.psd["Fz"], sp.f, dof=dof)
    thr = detection_threshold(dof, len(sp.f) - 2, p_false)
    rate = np.mean(np.any(sp.psd["Fz"][:, 1:-1] > thr * floor[:, 1:-1], axis=1))
    assert rate < 1.5 * p_false, rate


def test_detection_with_estimated_floor_interior():
    """Away from the band edges the estimated floor keeps the stated rate at dof 59 (measured 0.1075)."""
    nperseg, n_spectra, n_samples, p_false = 512, 400, 8192, 0.1
    rng = np.random.default_rng(4)
    x = rng.standard_normal((n_spectra, n_samples))
    test = SteadyTest([Run(speed=float(i), sample_rate=FS, signals={"Fz": x[i]}) for i in range(n_spectra)])
    sp = compute_spectra(test, nperseg=nperseg)
    dof = welch_dof(sp.n_segments[0])
    inner = slice(20, -20)
    floor = noise_floor(sp.psd["Fz"], sp.f, dof=dof)[:, inner]
    psd = sp.psd["Fz"][:, inner]
    thr = detection_threshold(dof, psd.shape[1], p_false)
    rate = np.mean(np.any(psd > thr * floor, axis=1))
    assert abs(rate - p_false) < 0.05, rate


@pytest.mark.parametrize("delta", [0.0, 0.37, 0.5, -0.25])
def test_find_lines_finds_and_refines_sinusoid(delta):
    """A sine whose peak PSD is 20 dB over white noise is found; its frequency refined to 5 % of a bin."""
    n, sigma = 2**15, 1.0
    level = 2 * sigma**2 / FS
    amp = np.sqrt(2 * 100 * level * 1.5 * DF)  # peak PSD of a bin-centred Hann line: (A²/2)/(1.5 df)
    f0 = (200 + delta) * DF
    rng = np.random.default_rng(6)
    sp = compute_spectra(single(sigma * rng.standard_normal(n) + sine(f0, amp, n)), nperseg=NPERSEG)
    psd = sp.psd["Fx"][0]
    dof = welch_dof(sp.n_segments[0])
    floor = noise_floor(psd, sp.f, dof=dof)
    thr = detection_threshold(dof, len(sp.f), 0.01)
    freqs, idx = find_lines(psd, sp.f, floor, thr)
    assert idx.size >= 1
    k = int(np.argmax(psd[idx]))
    assert abs(freqs[k] - f0) < 0.05 * DF
    assert abs(idx[k] - round(200 + delta)) <= 1
    # outside the band nothing is returned
    f_out, i_out = find_lines(psd, sp.f, floor, thr, f_min=250.0, f_max=400.0)
    assert not np.any(np.abs(f_out - f0) < 2 * DF)
    # the detection statistic agrees with the intended SNR (scalloping² × 100)
    assert psd[idx[k]] / level == pytest.approx(100 * hann_scallop(delta) ** 2,
                                                rel=0.3)


def test_welch_dof_limits():
    assert welch_dof(1) == 2.0
    # non-overlapped segments are independent: 2K
    assert welch_dof(10, overlap=0.0) == 20.0
    # 50 % Hann overlap: large-K limit 2K / (1 + 2·0.167²)
    assert welch_dof(10_000) / 20_000 == pytest.approx(1 / (1 + 2 * 0.167**2), rel=1e-3)
    assert stats.chi2.isf(0.01, 2) / 2 == pytest.approx(detection_threshold(1.0, 1, 0.01))


# --------------------------------------------------------------------------- run bookkeeping and errors

def test_run_shorter_than_nperseg_names_run():
    rng = np.random.default_rng(7)
    runs = [Run(10.0, FS, {"Fx": rng.standard_normal(4096)}, name="long.csv"),
            Run(20.0, FS, {"Fx": rng.standard_normal(700)}, name="short_run.csv")]
    with pytest.raises(DataError) as info:
        compute_spectra(SteadyTest(runs), nperseg=1024)
    msg = str(info.value)
    assert "short_run.csv" in msg and "700" in msg and "1024" in msg
    # the default nperseg follows the typical run; a truncated run is named, not silently absorbed
    runs.append(Run(30.0, FS, {"Fx": rng.standard_normal(4096)}, name="long2.csv"))
    with pytest.raises(DataError) as info:
        compute_spectra(SteadyTest(runs))
    assert "short_run.csv" in str(info.value) and "4096" in str(info.value)


def test_different_sample_rates_raise():
    rng = np.random.default_rng(8)
    runs = [Run(10.0, 1000.0, {"Fx": rng.standard_normal(2048)}, name="a.csv"),
            Run(20.0, 1024.0, {"Fx": rng.standard_normal(2048)}, name="b.csv")]
    with pytest.raises(DataError) as info:
        compute_spectra(SteadyTest(runs))
    msg = str(info.value)
    assert "b.csv" in msg and "sample_rate" in msg and "1024" in msg and "1000" in msg


def test_missing_channel_gives_nan_row():
    rng = np.random.default_rng(9)
    n = 4096
    runs = [Run(10.0, FS, {"Fx": rng.standard_normal(n), "Tz": rng.standard_normal(n)}, name="a"),
            Run(20.0, FS, {"Fx": rng.standard_normal(n)}, name="b"),
            Run(30.0, FS, {"Fx": rng.standard_normal(n), "Tz": rng.standard_normal(n)}, name="c")]
    sp = compute_spectra(SteadyTest(runs), nperseg=NPERSEG)
    assert sp.channels == ("Fx", "Tz")
    np.testing.assert_array_equal(sp.available("Tz"), [True, False, True])
    np.testing.assert_array_equal(sp.available("Fx"), [True, True, True])
    assert np.all(np.isnan(sp.psd["Tz"][1])) and np.all(np.isnan(sp.amplitude["Tz"][1]))
    assert np.all(np.isfinite(sp.psd["Tz"][[0, 2]]))
    assert sp.run_names == ["a", "b", "c"]


def test_runs_of_different_lengths_each_get_their_own_psd():
    """Rows of a mixed-length test equal the PSD of each run analysed alone (grouping by length)."""
    rng = np.random.default_rng(10)
    lengths = [4096, 2048, 4096, 3000]
    runs = [Run(float(i), FS, {"Fz": rng.standard_normal(n) * (i + 1)}, name=f"r{i}")
            for i, n in enumerate(lengths)]
    sp = compute_spectra(SteadyTest(runs), nperseg=NPERSEG)
    np.testing.assert_array_equal(sp.n_segments, [7, 3, 7, 4])
    for i, run in enumerate(runs):
        alone = compute_spectra(SteadyTest([run]), nperseg=NPERSEG)
        np.testing.assert_allclose(sp.psd["Fz"][i], alone.psd["Fz"][0], rtol=1e-12)
        assert np.mean(sp.psd["Fz"][i, 10:-10]) == pytest.approx(2 * (i + 1) ** 2 / FS, rel=0.15)


def test_line_power_broadcasts_over_runs():
    n = 2**13
    amps = np.array([0.5, 1.0, 2.0])
    freqs = np.array([100.2, 150.45, 301.0])
    runs = [Run(float(i), FS, {"Fx": sine(f, a, n)}, name=str(i)) for i, (f, a) in enumerate(zip(freqs, amps))]
    sp = compute_spectra(SteadyTest(runs), nperseg=NPERSEG)
    np.testing.assert_allclose(line_amplitude(sp.psd["Fx"], sp.f, freqs), amps, rtol=0.01)
    np.testing.assert_allclose(line_power(sp.psd["Fx"], sp.f, freqs), amps**2 / 2, rtol=0.02)


def test_running_median_equals_scipy_ndimage():
    """spectra.running_median (the noise floor's median, selected from a window stack) gives exactly
    scipy.ndimage.median_filter(mode="mirror") along the last axis: 1-, 2- and 3-D, odd widths, ties,
    a row of NaN (a run without the channel), a NaN or inf among finite values (ndimage's own path)."""
    from scipy import ndimage

    from rwadist.spectra import running_median

    rng = np.random.default_rng(5)
    for shape, n in [((4097,), 31), ((12, 2047), 31), ((3, 4, 515), 85), ((5, 40), 33), ((2, 31), 31), ((6, 200), 3)]:
        x = rng.chisquare(2, size=shape)
        cases = [x, np.round(x, 1)]
        if x.ndim > 1:
            y = x.copy()
            y.reshape(-1, shape[-1])[1] = np.nan
            cases.append(y)
        z = x.copy()
        z.flat[7] = np.nan
        z.flat[11] = np.inf
        cases.append(z)
        for c in cases:
            ref = ndimage.median_filter(c, size=(1,) * (c.ndim - 1) + (n,), mode="mirror")
            got = running_median(c, n)
            assert got.shape == ref.shape and got.dtype == ref.dtype
            assert np.array_equal(got, ref, equal_nan=True)
