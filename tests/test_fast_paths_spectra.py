"""compute_spectra's Welch PSD (:func:`rwadist.spectra.welch_psd`: every segment of a block of runs transformed in one
call) against scipy.signal.welch itself, run by run, over segment lengths (even and odd), overlaps and record lengths
that leave a partial segment, one segment alone, and more segments than numpy sums in one pass (8)."""
import numpy as np
import pytest
from scipy import signal

from rwadist.presets import preset
from rwadist.spectra import compute_spectra, welch_psd
from rwadist.teststand import simulate_steady


@pytest.mark.parametrize("n, nperseg, noverlap, window", [
    (8192, 2048, 1024, "hann"), (8192, 8192, 4096, "hann"), (5000, 1024, 512, "hann"), (4097, 511, 255, "hann"),
    (20000, 1000, 300, "hamming"), (3000, 3000, 0, "hann")])
def test_welch_psd_is_scipy_welch(n, nperseg, noverlap, window):
    rng = np.random.default_rng(n + nperseg)
    t = np.arange(n) / 1000.0
    x = 0.3 + rng.standard_normal((5, n)) + 4.0 * np.sin(2 * np.pi * 37.3 * t)[None, :]
    win = signal.get_window(window, nperseg)
    got = welch_psd(x, 1000.0, win, noverlap)
    for row, g in zip(x, got):
        _, ref = signal.welch(row, fs=1000.0, window=win, nperseg=nperseg, noverlap=noverlap, detrend="constant",
                              scaling="density")
        np.testing.assert_allclose(g, ref, rtol=1e-12, atol=0)


def test_compute_spectra_rows_are_scipy_welch_of_each_run():
    from dataclasses import replace

    test = simulate_steady(preset("ithaco-e"), np.linspace(600.0, 3000.0, 5), sample_rate=1000.0, n_samples=4096,
                           noise=0.01, seed=2, test_stand=False)
    test.runs[1] = replace(test.runs[1], signals={k: v[:3500] for k, v in test.runs[1].signals.items()})
    sp = compute_spectra(test, nperseg=1024)
    win = signal.get_window("hann", 1024)
    for i, run in enumerate(test.runs):
        for c in ("Fx", "Tz"):
            _, ref = signal.welch(run.signals[c], fs=1000.0, window=win, nperseg=1024, noverlap=512,
                                  detrend="constant", scaling="density")
            np.testing.assert_allclose(sp.psd[c][i], ref, rtol=1e-12, atol=0)
