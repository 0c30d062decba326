"""The line kernel the diagnose engine predicts a line's Welch PSD with (issue 14: the true model's error on
modes-on data).

Independent reference: scipy.signal.welch of a sinusoid, the PSD :meth:`Context.psd_at` predicts for a line.
Read at the nearest of its table's 1/64-bin points (before), a line's flank was off by 1-2 % and a line beside a
band edge sent ~0.4 % of its peak bin's power to the wrong band: on modes-on data of the bench's sideband case
that was 80 % of the error left with the true sidebands added (bench_diagnose.py --modes-on).
"""
import numpy as np
import pytest
from scipy import signal

from rwadist.diagnose import Context
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady


@pytest.mark.parametrize("nperseg,fs,offset", [(512, 1000.0, 0.3 + 1 / 200), (2048, 3840.0, 0.47),
                                               (256, 500.0, 0.011), (1024, 1920.0, -0.5 + 1 / 300)])
def test_predicted_line_psd_is_the_welch_psd_of_the_line(nperseg, fs, offset):
    """A unit-variance sinusoid between bins: the engine's PSD in every bin within ±12 of it equals scipy's Welch
    PSD of that sinusoid (Hann, 50 % overlap, whole segments) to 1e-6 of the peak, and to 1e-4 relative in the
    bins the floor fit reads (4..12 bins off); the ``bins`` route gives the same numbers as the whole grid."""
    test = simulate_steady(preset("ithaco-e"), [1000.0], sample_rate=fs, n_samples=4 * nperseg, modes=False,
                           noise=0.01, seed=0)
    ctx = Context(compute_spectra(test, nperseg=nperseg))
    k_line = 40
    f0 = (k_line + offset) * ctx.df
    t = np.arange(16 * nperseg) / fs
    x = np.sqrt(2.0) * np.cos(2 * np.pi * f0 * t + 0.7)                  # variance 1
    _, want = signal.welch(x, fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2, detrend=False)
    got = ctx.psd_at(np.array([f0]), np.array([1.0]))[0]
    k = np.arange(k_line - 12, k_line + 13)
    assert np.max(np.abs(got[k] - want[k])) < 1e-6 * want.max()
    flank = np.concatenate([np.arange(k_line - 12, k_line - 3), np.arange(k_line + 5, k_line + 13)])
    # the sinusoid's negative-frequency image leaks into the Welch estimate too (cross term, ~1e-9 of the peak
    # here, 40 bins away): allowed for in the absolute term
    assert np.allclose(got[flank], want[flank], rtol=1e-4, atol=1e-9 * want.max())
    at_bins = ctx.psd_at(np.array([f0]), np.array([1.0]), bins=k[None, :])[0]
    assert np.allclose(at_bins, got[k], rtol=1e-12, atol=0.0)


def test_kernel_sums_to_the_line_power():
    """Parseval: Σ_k K(k − δ)·Δf = 1 for a line anywhere between bins (the kernel's reach holds all but the
    Hann window's far sidelobes, < 1e-6 of the power beyond ±16 bins)."""
    test = simulate_steady(preset("ithaco-e"), [1000.0], sample_rate=1000.0, n_samples=2048, modes=False,
                           noise=0.01, seed=0)
    ctx = Context(compute_spectra(test, nperseg=512))
    for frac in np.linspace(0.0, 0.99, 12):
        f0 = (60 + frac) * ctx.df
        assert abs(ctx.psd_at(np.array([f0]), np.array([1.0]))[0].sum() * ctx.df - 1.0) < 1e-6
