"""The automatic empirical fit against data whose truth is known.

The data here are generated directly with numpy (independent of the virtual
test stand): rotating radial lines Fx = A cos φ, Fy = A sin φ, A = C·Ω².
"""
import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.empirical import FitSettings, _cluster_stderr, fit_empirical, line_C, modal_exclusion
from rwadist.spectra import compute_spectra
from rwadist.units import rpm_to_rad_s

FS = 1024.0


def peaking_gain(f, f_mode, zeta=0.02, gain=5.0):
    """Unit gain far from f_mode, `gain` at it (a lightly participating mode)."""
    r = f / f_mode
    return (1 - r**2 + 2j * gain * zeta * r) / (1 - r**2 + 2j * zeta * r)


def make_test(harmonics, speeds_rpm, n=4096, noise=1e-3, seed=0, mode=None, extra=None, ripple=None):
    """Steady runs of the radial force channels. harmonics: [(h, C_SI)].

    mode: (f_mode_hz, zeta, gain) amplifies lines near f_mode.
    extra: (f_hz, amplitude) a fixed-frequency sinusoid in every run (test-stand resonance).
    ripple: (f_r Hz, ΔΩ rad/s) the speed Ω(t) = Ω0 + ΔΩ sin(2π f_r t + φ): every line's phase h·ψ(t),
        ψ = Ω0 t − (ΔΩ/2πf_r) cos(2π f_r t + φ) (amplitude C·Ω0²: phase modulation alone), so each line carries
        sidebands at ± k·f_r Hz of amplitude J_k(β)·C·Ω0², β = h·ΔΩ/(2π f_r).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    runs = []
    for rpm in speeds_rpm:
        w = float(rpm_to_rad_s(rpm))
        fx = noise * rng.standard_normal(n)
        fy = noise * rng.standard_normal(n)
        psi = abs(w) * t
        if ripple is not None:
            f_r, delta_omega = ripple
            psi = psi - delta_omega / (2 * np.pi * f_r) * np.cos(2 * np.pi * f_r * t + rng.uniform(0, 2 * np.pi))
        for h, C in harmonics:
            a = C * w**2 * np.ones(1, complex)
            if mode is not None:
                a = a * peaking_gain(h * abs(w) / (2 * np.pi), *mode)
            phi = h * psi + rng.uniform(0, 2 * np.pi)
            fx += np.abs(a) * np.cos(phi + np.angle(a))
            fy += np.sign(w) * np.abs(a) * np.sin(phi + np.angle(a))
        if extra is not None:
            fx += extra[1] * np.sin(2 * np.pi * extra[0] * t)
            fy += extra[1] * np.cos(2 * np.pi * extra[0] * t)
        runs.append(Run(w, FS, {"Fx": fx, "Fy": fy}, name=f"r{rpm:g}.csv"))
    return SteadyTest(runs).sorted()


TRUTH = [(0.5, 1.0e-6), (1.0, 4.0e-6), (2.0, 1.0e-6), (2.73, 0.6e-6), (4.4, 0.8e-6)]
SPEEDS = np.linspace(600, 3000, 25)


def _match(fit, direction="radial_force"):
    return {round(x.h, 2): x for x in fit.lines if x.direction == direction}


def test_finds_integer_non_integer_and_subharmonics():
    fit = fit_empirical(compute_spectra(make_test(TRUTH, SPEEDS)))
    got = [x for x in fit.lines if x.direction == "radial_force"]
    assert len(got) == len(TRUTH)
    for (h, C), x in zip(TRUTH, sorted(got, key=lambda x: x.h)):
        assert abs(x.h - h) < 0.01
        assert x.C == pytest.approx(C, rel=0.02)
        assert x.C_stderr > 0 and x.C_stderr < 0.02 * C
        assert x.presence > 0.9


def test_pure_noise_gives_no_harmonic():
    fit = fit_empirical(compute_spectra(make_test([], SPEEDS, noise=1e-2, seed=3)))
    assert fit.lines == []


def test_band_limit_counts_possible_speeds_as_table_3_2():
    """A line above f_lim at high speed is neither counted possible nor measured there;
    a strong fixed-frequency resonance above f_lim creates no harmonic."""
    f_lim = 150.0
    test = make_test(TRUTH, SPEEDS, extra=(300.0, 0.5))
    fit = fit_empirical(compute_spectra(test, f_lim=f_lim))
    lines = _match(fit)
    speed_hz = np.abs(test.speeds) / (2 * np.pi)
    for h in (2.73, 4.4):
        x = lines[h]
        # N_poss: spectra (2 channels per run) where h·Ω is inside (f_min, f_lim]
        expected_poss = 2 * int(np.sum(x.h * speed_hz <= f_lim))
        assert x.n_possible == expected_poss
        assert np.all(x.h * x.speed / (2 * np.pi) <= f_lim)
    assert all(abs(x.h * SPEEDS.max() / 60 - 300) > 5 for x in fit.lines)
    assert len(fit.lines) == len(TRUTH)


def test_modal_amplification_is_excluded_automatically():
    """One harmonic crosses a mode mid-range: the excluded range brackets the crossing
    speed, C comes back unbiased, the all-points C (thesis C-bar) is biased high."""
    h, C, f_mode = 3.0, 1.0e-6, 120.0
    speeds = np.linspace(600, 3000, 61)
    crossing_rpm = f_mode / h * 60
    test = make_test([(1.0, 4.0e-6), (h, C)], speeds, mode=(f_mode, 0.02, 6.0))
    fit = fit_empirical(compute_spectra(test))
    x = _match(fit)[3.0]
    assert x.excluded_rpm, "no range excluded"
    lo, hi = min(r[0] for r in x.excluded_rpm), max(r[1] for r in x.excluded_rpm)
    assert lo < crossing_rpm < hi
    assert x.C == pytest.approx(C, rel=0.03)
    assert x.C_all > 1.05 * C
    # the same data without exclusion is biased: the exclusion did the work
    raw = _match(fit_empirical(compute_spectra(test), FitSettings(exclude_modes=False)))[3.0]
    assert abs(raw.C / C - 1) > abs(x.C / C - 1)



def test_fit_without_exclusion_reuses_the_identification_with_the_same_numbers():
    """:attr:`EmpiricalFit.without_mode_exclusion` takes the fit's own identification and measurements: its lines,
    harmonics and bins are those of a fit of its own with exclude_modes=False (a second, independent computation);
    the excluded fit's bins are untouched by it (a line dropped as modal there is kept without exclusion)."""
    import dataclasses

    h, C, f_mode = 3.0, 1.0e-6, 120.0
    test = make_test([(1.0, 4.0e-6), (h, C), (4.4, 0.8e-6)], np.linspace(600, 3000, 61), mode=(f_mode, 0.02, 6.0))
    sp = compute_spectra(test)
    fit = fit_empirical(sp)
    bins_before = [dataclasses.astuple(b) for b in fit.bins]
    reused = fit.without_mode_exclusion
    fresh = fit_empirical(sp, FitSettings(exclude_modes=False))
    assert reused.model.empirical == fresh.model.empirical
    assert [dataclasses.astuple(b) for b in reused.bins] == [dataclasses.astuple(b) for b in fresh.bins]
    for a, b in zip(reused.lines, fresh.lines, strict=True):
        assert (a.h, a.C, a.C_stderr, a.C_all) == (b.h, b.C, b.C_stderr, b.C_all)
        assert np.array_equal(a.used, b.used) and np.array_equal(a.amplitude, b.amplitude)
    assert not any(np.any(~x.used) for x in reused.lines)
    assert any(np.any(~x.used) for x in fit.lines)            # the excluded fit did exclude a range
    assert [dataclasses.astuple(b) for b in fit.bins] == bins_before

def test_negative_zero_and_duplicate_speeds():
    """Negative speeds fit by |Ω|; the zero-speed noise run is skipped; duplicate speeds count twice."""
    speeds = np.concatenate([-SPEEDS[::2], [0.0], SPEEDS[1::2], [SPEEDS[-1]]])
    fit = fit_empirical(compute_spectra(make_test(TRUTH, speeds)))
    x = _match(fit)[1.0]
    assert x.C == pytest.approx(4.0e-6, rel=0.02)
    assert np.all(x.speed > 0)
    assert fit.model.provenance["n_runs"] == len(speeds) - 1


def test_line_C_and_its_standard_error_closed_form():
    """Eq. 3.10 on exact data returns C; the sandwich SE equals the OLS SE when the
    residuals are homoscedastic in the Ω² regressor (checked by Monte Carlo)."""
    rng = np.random.default_rng(5)
    w = np.linspace(50, 300, 40)
    assert line_C(2.5e-6 * w**2, w) == pytest.approx(2.5e-6, rel=1e-12)
    estimates, ses = [], []
    for _ in range(2000):
        d = 2.5e-6 * w**2 + 1e-3 * rng.standard_normal(w.size)
        c = line_C(d, w)
        estimates.append(c)
        ses.append(_cluster_stderr(d, w, np.arange(w.size), c))
    true_sd = 1e-3 / np.sqrt(np.sum(w**4))   # closed form of the OLS slope's sd
    assert np.std(estimates) == pytest.approx(true_sd, rel=0.05)
    assert np.median(ses) == pytest.approx(true_sd, rel=0.1)


def test_a_line_whose_channel_amplitude_changes_from_run_to_run_is_read_at_its_power():
    """A straight load along an angle that changes from run to run (a planar line) and a line of both senses with
    their own phases: each channel's amplitude scatters from run to run, x² + y² of a run does not (closed form:
    A² for the straight load, 2(a₊² + a₋²) for the two senses), so the model's C (C²Ω⁴/2 a channel) is A/√2 and
    sqrt(a₊² + a₋²).  Eq. 3.10's mean amplitude reads them 10 % low (E|cos α| = 2/π against its RMS 1/√2)."""
    rng = np.random.default_rng(3)
    t = np.arange(4096) / FS
    A, a_co, a_ct = 3.0e-6, 1.6e-6, 1.2e-6
    runs = []
    for rpm in np.linspace(600, 3000, 25):
        w = float(rpm_to_rad_s(rpm))
        fx, fy = 1e-3 * rng.standard_normal((2, t.size))
        alpha, p1, p2, p3 = rng.uniform(0, 2 * np.pi, 4)
        straight = A * w**2 * np.cos(w * t + p1)                       # h = 1 along alpha
        fx, fy = fx + straight * np.cos(alpha), fy + straight * np.sin(alpha)
        phi = 2.0 * w * t                                               # h = 2: a co and a counter part
        fx = fx + a_co * w**2 * np.cos(phi + p2) + a_ct * w**2 * np.cos(phi + p3)
        fy = fy + a_co * w**2 * np.sin(phi + p2) - a_ct * w**2 * np.sin(phi + p3)
        runs.append(Run(w, FS, {"Fx": fx, "Fy": fy}, name=f"r{rpm:g}.csv"))
    fit = fit_empirical(compute_spectra(SteadyTest(runs).sorted()))
    got = _match(fit)
    assert got[1.0].C == pytest.approx(A / np.sqrt(2), rel=0.01)
    assert got[2.0].C == pytest.approx(np.hypot(a_co, a_ct), rel=0.01)
    line = next(ln for ln in fit.lines if abs(ln.h - 1.0) < 0.01)
    d, w = line.amplitude[line.used], line.speed[line.used]
    assert np.sum(d * w**2) / np.sum(w**4) < 0.95 * A / np.sqrt(2)       # what Eq. 3.10 read


def test_reported_stderr_matches_spread_over_seeds():
    """The standard error the fit reports predicts the scatter of C over noise seeds."""
    speeds = np.linspace(600, 3000, 15)
    truth = [(1.0, 4.0e-6), (2.0, 0.4e-6)]
    cs, ses = [], []
    for seed in range(12):
        fit = fit_empirical(compute_spectra(make_test(truth, speeds, noise=2e-2, seed=seed, n=2048)))
        x = _match(fit)[2.0]
        cs.append(x.C)
        ses.append(x.C_stderr)
    ratio = np.std(cs, ddof=1) / np.median(ses)
    assert 0.5 < ratio < 2.0, ratio


def test_modal_exclusion_grows_a_contiguous_range():
    w = np.linspace(60, 300, 50)
    d = 1e-6 * w**2
    bump = np.exp(-0.5 * ((w - 200) / 8) ** 2)
    d = d * (1 + 0.8 * bump)
    ex = modal_exclusion(d, w, np.arange(w.size), np.full(w.size, 1e-3), FitSettings())
    assert ex[np.argmin(np.abs(w - 200))]
    # contiguous: no gaps inside the flagged set
    idx = np.nonzero(ex)[0]
    assert np.all(np.diff(idx) == 1)
    # every point amplified by more than amp_min (3 %) is out, nothing amplified < 1 % is
    assert np.all(ex[0.8 * bump > 0.03])
    assert not np.any(ex[0.8 * bump < 0.01])


def test_sidebands_at_a_fixed_offset_are_no_harmonics():
    """A 4-Hz speed ripple (ΔΩ 5 rad/s: β = 0.2·h) puts sidebands at ± 4 and 8 Hz beside every line; near the top
    speed their h ± 4/f_rot gather and passed the presence test (11 extra lines).  Only the true harmonics are kept,
    each C the carrier's, C·J_0(β) (Bessel, scipy), within 1 %; the sidebands' bins say why they are not."""
    from scipy.special import jv

    f_r, dw = 4.0, 5.0
    fit = fit_empirical(compute_spectra(make_test(TRUTH, SPEEDS, ripple=(f_r, dw))))
    got = sorted((x.h, x.C) for x in fit.lines if x.direction == "radial_force")
    assert [round(h, 2) for h, _ in got] == [h for h, _ in TRUTH]
    for (h, C), (_, C_fit) in zip(TRUTH, got):
        assert C_fit == pytest.approx(C * jv(0, h * dw / (2 * np.pi * f_r)), rel=0.01)
    assert sum("fixed offset" in b.reason for b in fit.bins) >= 8
