"""A carrier measured beside its weak speed sidebands (rwadist.line_overlap), checked against the generator's
amplitudes and against scipy's Welch PSD of a sinusoid."""
import numpy as np
import pytest
from scipy import signal

from rwadist.data import Run, SteadyTest
from rwadist.empirical import fit_empirical
from rwadist.line_overlap import window_share
from rwadist.spectra import compute_spectra

FS, N = 1000.0, 6000
RPM = np.linspace(300.0, 3000.0, 20)
C1, SIDE, DH = 2e-5, 0.2, 0.06


def _test(seed: int) -> SteadyTest:
    """A radial carrier at h 1 (C1 N/(rad/s)²) with speed sidebands at 1 ± DH of SIDE times its amplitude, and noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    runs = []
    for i, rpm in enumerate(RPM):
        om = rpm * 2 * np.pi / 60
        sig = {c: 2e-4 * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        for h, a in ((1.0, C1 * om ** 2), (1 - DH, SIDE * C1 * om ** 2), (1 + DH, SIDE * C1 * om ** 2)):
            ph = rng.uniform(0, 2 * np.pi)
            sig["Fx"] += a * np.cos(h * om * t + ph)
            sig["Fy"] += a * np.sin(h * om * t + ph)
        runs.append(Run(speed=om, sample_rate=FS, t0=0.0, name=f"run_{i:04d}.csv", signals=sig))
    return SteadyTest(runs=runs, meta={})


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_carrier_is_measured_where_its_weak_sidebands_share_its_bins(seed):
    sp = compute_spectra(_test(seed))
    fit = fit_empirical(sp)
    lf = {round(x.h, 2): x for x in fit.lines if x.direction == "radial_force"}
    carrier = lf[1.0]
    # the sidebands are apart from the carrier by DH·f_rot: within its 2L+1 bins at the low speeds
    apart_bins = DH * RPM / 60 / sp.df
    speeds = np.unique(np.rint(carrier.speed * 60 / (2 * np.pi)))
    shared = RPM[apart_bins < 2 * 3 + 1]
    assert shared.size >= 8
    measured_shared = [r for r in shared if np.any(np.abs(speeds - r) < 1)]
    # every speed at which the sidebands are clear of the carrier's main lobe (2.5 bins) keeps its measurement
    assert all(np.any(np.abs(speeds - r) < 1) for r in RPM[apart_bins >= 2.5])
    assert speeds.size >= 18
    assert len(measured_shared) >= shared.size - 2
    assert carrier.C == pytest.approx(C1, rel=0.01)
    # the amplitudes read where the sidebands share the bins are the carrier's alone, within 1 % or the measurement's
    # own stated error where that is larger (the lines beat within the one Welch segment, by their phases); a run whose
    # sidebands are inside the carrier's main lobe (2 bins) is left out
    rpm_of = carrier.speed * 60 / (2 * np.pi)
    apart = DH * rpm_of / 60 / sp.df
    truth = C1 * carrier.speed ** 2
    assert apart.min() >= 2.0
    assert (apart < 7).sum() >= 10
    shared_ = apart < 7
    error = np.abs(carrier.amplitude / truth - 1)[shared_]
    assert np.all(error <= np.maximum(0.01, carrier.noise[shared_]))
    assert np.median(error) <= 0.005
    assert carrier.noise[shared_].max() <= 0.05

def test_the_window_share_is_scipys_welch_of_a_sinusoid_and_sums_to_one():
    fs, n = 1000.0, 1024
    df = fs / n
    t = np.arange(16 * n) / fs
    for offset in (0.0, 0.3, 1.7, 2.5, 4.2):
        k0 = 100
        x = np.sqrt(2.0) * np.cos(2 * np.pi * (k0 + offset) * df * t)          # unit power
        _, p = signal.welch(x, fs, window="hann", nperseg=n, noverlap=n // 2, detrend=False)
        for half in (1, 3):
            measured = p[k0 - half:k0 + half + 1].sum() * df
            assert window_share("hann", n, offset, half) == pytest.approx(measured, abs=2e-3)
    # Parseval: the shares of every bin of the spectrum add up to the whole power
    assert window_share("hann", n, 0.37, 20) == pytest.approx(1.0, abs=1e-6)
