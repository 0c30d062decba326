"""Virtual test stand: line amplitudes, rotation sense, noise, modal gain, whirl crossings, sweeps, presets."""
import json
import time

import numpy as np
import pytest
from scipy import optimize, signal

from rwadist import data
from rwadist.model import line_amplitudes, model_rms
from rwadist.presets import PRESETS, preset
from rwadist.teststand import Mode, WheelDescription, simulate_steady, simulate_sweep

TWO_PI = 2.0 * np.pi
RPM = TWO_PI / 60.0          # rad/s per rpm, written out here instead of taken from rwadist.units


def one_line(direction="radial_force", h=1.0, C=3.79e-6, modes=(), stand=()):
    return WheelDescription("one", {direction: [(h, C)]}, modes=list(modes), test_stand_modes=list(stand))


def fit_lines(x, t, freqs):
    """Linear least squares of x on cos/sin at the given frequencies -> (amplitude, phase) of
    x ≈ Σ A_k cos(2π f_k t + θ_k)."""
    w = TWO_PI * np.asarray(freqs, dtype=float)
    design = np.hstack([np.cos(np.outer(t, w)), np.sin(np.outer(t, w))])
    coef, *_ = np.linalg.lstsq(design, x, rcond=None)
    p, q = coef[: len(w)], coef[len(w):]
    return np.hypot(p, q), np.arctan2(-q, p)


def wrap(a):
    return (np.asarray(a) + np.pi) % TWO_PI - np.pi


# --------------------------------------------------------------------------- steady lines

def test_single_harmonic_amplitude_and_frequency_by_fft_and_nonlinear_fit():
    C_f, C_t = 3.79e-6, 2.0e-6
    wheel = WheelDescription("two", {"radial_force": [(1.0, C_f)], "radial_torque": [(2.5, C_t)]}, modes=[])
    fs, n, rpm = 1024.0, 2048, 1500.0                   # 25 Hz and 62.5 Hz lines sit on 0.5 Hz bins
    run = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0).runs[0]
    omega = rpm * RPM
    for ch, h, C in (("Fx", 1.0, C_f), ("Ty", 2.5, C_t)):
        X = np.fft.rfft(run.signals[ch])
        k = int(np.argmax(np.abs(X)))
        assert k * fs / n == pytest.approx(h * rpm / 60.0, abs=1e-12)
        assert 2.0 * np.abs(X[k]) / n == pytest.approx(C * omega**2, rel=1e-9)

    # off-bin case: non-linear least-squares fit with the frequency free
    h, rpm = 1.37, 1234.0
    wheel = one_line(h=h, C=C_f)
    run = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=1000, noise=0.0).runs[0]
    t = np.arange(1000) / fs
    x = run.signals["Fx"]
    f_true = h * rpm / 60.0

    def resid(p):
        return p[0] * np.cos(TWO_PI * p[1] * t) + p[2] * np.sin(TWO_PI * p[1] * t) - x

    sol = optimize.least_squares(resid, [0.0, f_true * 1.002, 0.0], x_scale=[1e-3, 1.0, 1e-3])
    assert sol.x[1] == pytest.approx(f_true, rel=1e-9)
    assert np.hypot(sol.x[0], sol.x[2]) == pytest.approx(C_f * (rpm * RPM) ** 2, rel=1e-8)


@pytest.mark.parametrize("with_mode", [False, True])
def test_radial_quadrature_and_rotation_sense_flip_with_negative_speed(with_mode):
    h, C, rpm, fs, n = 1.0, 3.79e-6, 1500.0, 1000.0, 2000
    f = h * rpm / 60.0
    # a mode right at the line: complex gain must keep x/y in quadrature for both signs of spin
    modes = [Mode("m", f, 0.05, 4.0, ("Fx", "Fy"))] if with_mode else []
    wheel = one_line(h=h, C=C, modes=modes)
    test = simulate_steady(wheel, [rpm, -rpm], sample_rate=fs, n_samples=n, noise=0.0)
    t = np.arange(n) / fs
    expected_amp = C * (rpm * RPM) ** 2 * (4.0 if with_mode else 1.0)
    for run, sense in zip(test.runs, (+1, -1)):
        ax, px = fit_lines(run.signals["Fx"], t, [f])
        ay, py = fit_lines(run.signals["Fy"], t, [f])
        assert ax[0] == pytest.approx(expected_amp, rel=1e-9)
        assert ay[0] == pytest.approx(expected_amp, rel=1e-9)
        # positive spin: Fy = A sin φ lags Fx by 90°; negative spin: leads by 90°
        assert wrap(py[0] - px[0]) == pytest.approx(-sense * np.pi / 2, abs=1e-9)
        # second method: sign of the angular velocity of the (Fx, Fy) vector
        x, y = run.signals["Fx"], run.signals["Fy"]
        turn = np.mean(x * np.gradient(y) - y * np.gradient(x))
        assert np.sign(turn) == sense
        assert run.speed == pytest.approx(sense * rpm * RPM)


def test_modal_phase_shift_is_that_of_a_real_filter_for_both_spin_directions():
    """A mode on Fx only, off resonance: Fx is shifted by +∠H relative to the un-moded Fy whichever way
    the wheel spins (a real system's phase at positive frequency), in steady runs and in a sweep."""
    h, C, fs, n, rpm = 1.0, 3.79e-6, 1000.0, 2000, 1500.0
    f = h * rpm / 60.0
    m = Mode("m", 1.05 * f, 0.05, 4.0, ("Fx",))
    G = complex(m.gain(f, rpm * RPM))
    assert abs(np.angle(G)) > 0.3
    wheel = one_line(h=h, C=C, modes=[m])
    t = np.arange(n) / fs
    test = simulate_steady(wheel, [rpm, -rpm], sample_rate=fs, n_samples=n, noise=0.0)
    for run, sense in zip(test.runs, (+1, -1)):
        ax, px = fit_lines(run.signals["Fx"], t, [f])
        ay, py = fit_lines(run.signals["Fy"], t, [f])
        assert ax[0] / ay[0] == pytest.approx(abs(G), rel=1e-9)
        assert wrap(px[0] - py[0] - sense * np.pi / 2) == pytest.approx(np.angle(G), abs=1e-9)
    # quasi-steady sweep at constant speed -rpm: same relation as the steady run
    sw = simulate_sweep(wheel, -rpm, -rpm, duration=n / fs, sample_rate=fs, noise=0.0)
    ax, px = fit_lines(sw.signals["Fx"], sw.time, [f])
    ay, py = fit_lines(sw.signals["Fy"], sw.time, [f])
    assert wrap(px[0] - py[0] + np.pi / 2) == pytest.approx(np.angle(G), abs=1e-9)


def test_noise_std_per_channel_group():
    wheel = preset("ithaco-e")
    speeds = [500.0, -1000.0, 2000.0]
    kw = dict(sample_rate=3840.0, n_samples=8192, modes=True, seed=7)
    noisy = simulate_steady(wheel, speeds, noise=0.05, **kw)
    clean = simulate_steady(wheel, speeds, noise=0.0, **kw)
    # thesis units: N/rpm² ×1e-7 times rpm² gives N directly (Table 3.4 fundamentals)
    expect_f = 0.05 * 0.4155e-7 * 2000.0**2
    expect_t = 0.05 * 0.2205e-7 * 2000.0**2
    for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"):
        expect = expect_f if ch.startswith("F") else expect_t
        assert noisy.meta["noise_std"][ch] == pytest.approx(expect, rel=1e-9)
        resid = np.concatenate([a.signals[ch] - b.signals[ch] for a, b in zip(noisy.runs, clean.runs)])
        assert abs(resid.mean()) < 4 * expect / np.sqrt(resid.size)
        assert resid.std() == pytest.approx(expect, rel=0.02)      # 24576 samples: σ of the estimate 0.45 %
    assert clean.meta["noise_std"]["Fx"] == 0.0
    # no harmonics on Tz: the clean Tz channel is exactly zero, the noisy one is pure noise
    assert np.all(clean.runs[0].signals["Tz"] == 0.0)


# --------------------------------------------------------------------------- modes

def test_mode_gain_peak_far_field_and_whirl_law():
    m = Mode("m", 100.0, 0.02, 8.0, ("Fx",))
    assert abs(m.gain(100.0, 0.0)) == pytest.approx(8.0, rel=1e-12)
    # far field: |H - 1| ≈ 2(g-1)ζ·r below the mode and 2(g-1)ζ/r above it
    for r in (1e-3, 1e-4, 1e3, 1e4):
        dev = abs(m.gain(100.0 * r, 123.0) - 1.0)
        assert dev == pytest.approx(2 * 7.0 * 0.02 * min(r, 1 / r), rel=1e-3)
    # the maximum of |H| on a fine grid is ≈ peak_gain and sits within ζ of r = 1
    f = np.linspace(50.0, 150.0, 200001)
    mag = np.abs(m.gain(f, 0.0))
    assert mag.max() == pytest.approx(8.0, rel=0.01)
    assert abs(f[np.argmax(mag)] / 100.0 - 1.0) < 0.02
    # half-power width of the resonant part ≈ 2ζ f0 (light damping)
    above = f[mag > 8.0 / np.sqrt(2)]
    assert above.max() - above.min() == pytest.approx(2 * 0.02 * 100.0, rel=0.1)
    # broadcasting
    assert m.gain(np.ones((3, 1)) * 50.0, np.zeros(4)).shape == (3, 4)

    # gyroscopic whirl: f+·f- = f0² and f+ - f- = a·Ω_hz; both -> f0 at rest; sign of Ω ignored
    fwd = Mode("rf", 54.9, 0.03, 6.0, ("Fx",), whirl=+1, inertia_ratio=2.0)
    bwd = Mode("rb", 54.9, 0.03, 6.0, ("Fx",), whirl=-1, inertia_ratio=2.0)
    om = np.array([-300.0, 0.0, 50.0, 250.0])
    fp, fm = fwd.frequency_hz(om), bwd.frequency_hz(om)
    np.testing.assert_allclose(fp * fm, 54.9**2, rtol=1e-12)
    np.testing.assert_allclose(fp - fm, 2.0 * np.abs(om) / TWO_PI, rtol=1e-12, atol=1e-12)
    assert fp[1] == fm[1] == pytest.approx(54.9)
    with pytest.raises(ValueError):
        Mode("bad", 10.0, 0.02, 2.0, ("Fq",))


def test_whirl_crossings_match_thesis_table_3_6_and_a_root_finder():
    wheel = preset("ithaco-e")
    xs = wheel.crossings("radial_force", [0.0, 3850.0])
    by = {(c["h"], c["mode"]): c for c in xs}
    modes = {m.name: m for m in wheel.modes}
    # (h, mode, thesis Table 3.6 range in rpm)
    table = [(1.0, "rocking_backward", (1900, 2000)), (3.0, "rocking_forward", (1800, 2000)),
             (4.0, "rocking_forward", (1150, 1400)), (2.0, "rocking_backward", (800, 1300)),
             (4.42, "rocking_forward", (900, 1100))]
    for h, name, (lo, hi) in table:
        c = by[(h, name)]
        assert lo - 10 <= c["speed_rpm"] <= hi, (h, name, c)      # h=1: 1902, h=4: 1165 rpm
        # independent: root of h·Ω_hz - f_mode(Ω) found numerically
        root = optimize.brentq(lambda w: h * w / TWO_PI - modes[name].frequency_hz(w), 1.0, 600.0, xtol=1e-12)
        assert c["speed_rpm"] == pytest.approx(root / RPM, rel=1e-9)
        assert c["f_hz"] == pytest.approx(modes[name].frequency_hz(root), rel=1e-9)
    assert by[(1.0, "rocking_backward")]["speed_rpm"] == pytest.approx(by[(3.0, "rocking_forward")]["speed_rpm"])
    assert by[(2.0, "rocking_backward")]["speed_rpm"] == pytest.approx(1165, abs=1)
    # h = 1 cannot meet the forward whirl (it rises with slope a = 2 > h)
    assert (1.0, "rocking_forward") not in by
    # Table 3.9: axial h = 1.98 amplified by the 70 Hz axial mode at 2100-2350 rpm
    ax = {(c["h"], c["mode"]): c for c in wheel.crossings("axial_force", [0, 3850])}
    assert 2100 <= ax[(1.98, "axial_translation")]["speed_rpm"] <= 2350
    # range handling: a range not containing the crossing excludes it; a sign-changing range covers 0..max
    assert all(c["speed_rpm"] >= 2000 for c in wheel.crossings("radial_force", [2000, 2400]))
    assert len(wheel.crossings("radial_force", [-3850, 3850])) == len(xs)


def test_modal_gain_appears_in_steady_data_at_the_crossing():
    wheel = preset("ithaco-e")
    c = [x for x in wheel.crossings("radial_torque", [0, 3000]) if x["h"] == 1.0][0]
    rpm = c["speed_rpm"]
    fs, n = 3840.0, 8192
    kw = dict(sample_rate=fs, n_samples=n, noise=0.0, seed=3)
    on = simulate_steady(wheel, [rpm, -rpm], modes=True, **kw)
    off = simulate_steady(wheel, [rpm, -rpm], modes=False, **kw)
    t = np.arange(n) / fs
    h, C = wheel.h_and_C("radial_torque")
    freqs = h * rpm / 60.0
    omega = rpm * RPM
    expected = C * omega**2
    gain = np.ones(len(h), dtype=complex)
    for m in wheel.modes:
        if "Tx" in m.channels:
            gain *= m.gain(freqs, omega)
    for r_on, r_off in zip(on.runs, off.runs):
        a_on, _ = fit_lines(r_on.signals["Tx"], t, freqs)
        a_off, _ = fit_lines(r_off.signals["Tx"], t, freqs)
        np.testing.assert_allclose(a_off, expected, rtol=1e-8)
        np.testing.assert_allclose(a_on, expected * np.abs(gain), rtol=1e-8)
    assert np.abs(gain[0]) == pytest.approx(6.0, rel=0.02)        # the rocking peak gain
    # Fz is not touched by the rocking modes (only by the axial mode)
    rocking_only = WheelDescription("r", wheel.harmonics, [m for m in wheel.modes if m.name.startswith("rocking")])
    r_on = simulate_steady(rocking_only, [rpm], modes=True, **kw).runs[0]
    np.testing.assert_array_equal(r_on.signals["Fz"], off.runs[0].signals["Fz"])
    assert not np.array_equal(r_on.signals["Tx"], off.runs[0].signals["Tx"])


def test_test_stand_resonance_switch_and_anti_aliasing():
    stand = [Mode("stand", 300.0, 0.02, 20.0, ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))]
    wheel = WheelDescription("s", {"axial_force": [(6.0, 1e-6)], "radial_force": [(12.0, 1e-6)]}, modes=[],
                             test_stand_modes=stand)
    fs, n, rpm = 1000.0, 1000, 3000.0       # axial line at 300 Hz; radial line at 600 Hz > Nyquist
    t = np.arange(n) / fs
    on = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0, test_stand=True).runs[0]
    off = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0, test_stand=False).runs[0]
    a_on, _ = fit_lines(on.signals["Fz"], t, [300.0])
    a_off, _ = fit_lines(off.signals["Fz"], t, [300.0])
    assert a_on[0] / a_off[0] == pytest.approx(20.0, rel=1e-9)
    # the 600 Hz radial line would alias to 400 Hz: an ideal anti-aliasing filter removes it
    assert np.all(on.signals["Fx"] == 0.0)
    test = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0)
    assert test.meta["lines_above_nyquist"] == [{"speed_rpm": 3000.0, "direction": "radial_force", "h": 12.0}]


# --------------------------------------------------------------------------- sweeps

def test_sweep_phase_is_the_integral_of_speed_linear_and_exp():
    h, C, fs, T = 2.0, 3.79e-6, 4000.0, 4.0
    wheel = one_line(h=h, C=C)
    w0, w1 = 600.0 * RPM, 1800.0 * RPM
    for profile in ("linear", "exp"):
        sw = simulate_sweep(wheel, 600.0, 1800.0, duration=T, sample_rate=fs, noise=0.0, modes=False,
                            profile=profile, seed=1)
        t = sw.time
        if profile == "linear":
            omega = w0 + (w1 - w0) * t / T
            psi = w0 * t + 0.5 * (w1 - w0) * t**2 / T
        else:
            tau = T / 5.0
            omega = w1 + (w0 - w1) * np.exp(-t / tau)
            psi = w1 * t + (w0 - w1) * tau * (1.0 - np.exp(-t / tau))
        np.testing.assert_allclose(sw.tach, omega, rtol=1e-12)
        z = sw.signals["Fx"] + 1j * sw.signals["Fy"]
        np.testing.assert_allclose(np.abs(z), C * omega**2, rtol=1e-9)
        # phase of the rotating vector = h·∫Ω dt + α (closed-form integral), to micro-radians
        err = wrap(np.unwrap(np.angle(z)) - h * psi)
        assert np.ptp(err) < 1e-4
        # second method: instantaneous frequency of the analytic signal of Fx alone
        # (averaged over 0.1 s; Ω(t)·t instead of ∫Ω dt would read 66 % high at mid-sweep)
        inst = np.diff(np.unwrap(np.angle(signal.hilbert(sw.signals["Fx"])))) * fs / TWO_PI
        f_true = h * 0.5 * (omega[1:] + omega[:-1]) / TWO_PI
        box = np.ones(400) / 400
        ratio = np.convolve(inst, box, "valid") / np.convolve(f_true, box, "valid")
        mid = slice(len(ratio) // 10, 9 * len(ratio) // 10)
        assert np.max(np.abs(ratio[mid] - 1.0)) < 3e-3
        # third: zero crossings of Fx count 2 per cycle of h·ψ
        n_cross = np.count_nonzero(np.diff(np.signbit(sw.signals["Fx"])))
        assert abs(n_cross - 2 * h * psi[-1] / TWO_PI) <= 2
    assert simulate_sweep(wheel, 0, 100, duration=0.5, sample_rate=200.0, tach=False).tach is None


def test_sweep_modal_gain_quasi_steady_and_reversal_through_zero():
    m = Mode("m", 20.0, 0.05, 5.0, ("Fx", "Fy"))
    h, C, fs, T = 1.0, 1e-5, 1000.0, 20.0
    wheel = one_line(h=h, C=C, modes=[m])
    sw = simulate_sweep(wheel, -2400.0, 2400.0, duration=T, sample_rate=fs, noise=0.0, seed=5)
    omega = sw.tach
    z = sw.signals["Fx"] + 1j * sw.signals["Fy"]
    expected = C * omega**2 * np.abs(m.gain(h * np.abs(omega) / TWO_PI, omega))
    np.testing.assert_allclose(np.abs(z), expected, rtol=1e-9, atol=1e-15)
    # the line passes the 20 Hz mode at ±1200 rpm, amplified by the peak gain there
    near = np.abs(np.abs(omega) / RPM - 1200.0) < 5.0
    assert np.max(np.abs(z[near]) / (C * omega[near] ** 2)) == pytest.approx(5.0, rel=0.01)
    # the vector turns clockwise while Ω < 0 and counter-clockwise while Ω > 0
    dphi = np.diff(np.unwrap(np.angle(z)))
    wmid = 0.5 * (omega[1:] + omega[:-1])
    fast = np.abs(wmid) > 100 * RPM
    assert np.all(np.sign(dphi[fast]) == np.sign(wmid[fast]))
    # continuous through zero speed: near Ω = 0 no step is larger than the rotation h|Ω|dt of the
    # vector plus its change of length
    slow = np.abs(wmid) < 300 * RPM
    step = np.abs(np.diff(z))[slow]
    mag = np.maximum(np.abs(z[1:]), np.abs(z[:-1]))[slow]
    bound = mag * h * np.abs(wmid[slow]) / fs * 1.01 + np.abs(np.diff(np.abs(z)))[slow] + 1e-18
    assert np.all(step <= bound)
    assert np.count_nonzero(slow) > 1000


# --------------------------------------------------------------------------- reproducibility, format

def test_seeded_reproducibility_and_independent_phases():
    wheel = preset("ithaco-e")
    a = simulate_steady(wheel, [1000.0, 1000.0], n_samples=1024, seed=11)
    b = simulate_steady(wheel, [1000.0, 1000.0], n_samples=1024, seed=11)
    c = simulate_steady(wheel, [1000.0, 1000.0], n_samples=1024, seed=12)
    for ra, rb, rc in zip(a.runs, b.runs, c.runs):
        for ch in ra.signals:
            np.testing.assert_array_equal(ra.signals[ch], rb.signals[ch])
            assert not np.allclose(ra.signals[ch], rc.signals[ch])
    # two runs at the same speed: same line amplitudes, different phases
    t = np.arange(1024) / 3840.0
    f = 1000.0 / 60.0 * wheel.h_and_C("axial_force")[0]
    clean = simulate_steady(wheel, [1000.0, 1000.0], n_samples=1024, seed=11, noise=0.0, modes=False)
    (a0, p0), (a1, p1) = (fit_lines(r.signals["Fz"], t, f) for r in clean.runs)
    np.testing.assert_allclose(a0, a1, rtol=1e-6)
    assert np.all(np.abs(wrap(p0 - p1)) > 1e-3)
    s1 = simulate_sweep(wheel, 0, 1000, duration=1.0, sample_rate=1000.0, seed=4)
    s2 = simulate_sweep(wheel, 0, 1000, duration=1.0, sample_rate=1000.0, seed=4)
    for ch in s1.signals:
        np.testing.assert_array_equal(s1.signals[ch], s2.signals[ch])


def test_presets_convert_thesis_units_and_list_names():
    e, b = preset("ithaco-e"), preset("ithaco-b")
    h1, C1 = e.harmonics["radial_force"][0]
    assert h1 == 1.0
    assert C1 == pytest.approx(0.4155e-7 * (60.0 / TWO_PI) ** 2, rel=1e-12)
    assert C1 == pytest.approx(3.79e-6, rel=1e-3)
    assert C1 == pytest.approx(0.38e-5, rel=0.01)        # Table 4.2: U_s = 0.38 g·cm
    assert b.harmonics["radial_force"][-1] == pytest.approx((10.25, 0.3183e-7 * (60.0 / TWO_PI) ** 2))
    counts = {d: len(v) for d, v in e.harmonics.items()}
    assert counts == {"radial_force": 7, "radial_torque": 6, "axial_force": 5}
    counts = {d: len(v) for d, v in b.harmonics.items()}
    assert counts == {"radial_force": 13, "radial_torque": 11, "axial_force": 4}
    assert (e.mass_kg, e.radius_m, e.max_speed_rpm) == (10.6, 0.1965, 3850.0)
    assert (b.mass_kg, b.radius_m, b.max_speed_rpm, b.f_lim_hz) == (5.9, 0.1275, 5100.0, 200.0)
    assert {m.f0_hz for m in b.test_stand_modes} == {300.0, 460.0} and e.test_stand_modes == []
    np.testing.assert_allclose(b.default_speeds_rpm, np.arange(500, 3401, 100))
    assert b.default_sample_rate == 1000.0
    with pytest.raises(ValueError, match="ithaco-b.*ithaco-e"):
        preset("ithaco-z")
    e.harmonics["radial_force"].clear()                   # a fresh copy: PRESETS untouched
    assert len(PRESETS["ithaco-e"].harmonics["radial_force"]) == 7


def test_to_model_matches_simulated_rms_parseval():
    wheel = preset("ithaco-e")
    model = wheel.to_model()
    rpm = 1200.0
    f, a = line_amplitudes(model, "radial_force", rpm * RPM)
    h, C = wheel.h_and_C("radial_force")
    np.testing.assert_allclose(f[0], h * rpm / 60.0)
    np.testing.assert_allclose(a[0], C * (rpm * RPM) ** 2)
    run = simulate_steady(wheel, [rpm], n_samples=3840 * 8, noise=0.0, modes=False).runs[0]
    for ch, d in (("Fx", "radial_force"), ("Ty", "radial_torque"), ("Fz", "axial_force")):
        rms = np.sqrt(np.mean(run.signals[ch] ** 2))
        assert rms == pytest.approx(float(model_rms(model, d, rpm * RPM)[0]), rel=0.01)


def test_steady_round_trip_through_interchange_format(tmp_path):
    wheel = preset("ithaco-b")
    test = simulate_steady(wheel, [0.0, 500.0, -800.0], sample_rate=1000.0, n_samples=64, seed=2)
    data.write_steady(test, tmp_path / "b")
    back = data.read_steady(tmp_path / "b")
    np.testing.assert_allclose(back.speeds, [-800 * RPM, 0.0, 500 * RPM], rtol=1e-12)
    orig = {r.name: r for r in test.runs}
    for r in back.runs:
        for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"):
            np.testing.assert_array_equal(r.signals[ch], orig[r.name].signals[ch])
    meta = json.loads((tmp_path / "b" / "meta.json").read_text())
    assert meta["sample_rate_hz"] == 1000.0 and meta["wheel"]["name"] == "ithaco-b"
    assert meta["seed"] == 2 and meta["modes"] is True
    assert meta["truth"]["radial_force"][0]["C"] == pytest.approx(wheel.harmonics["radial_force"][0][1])


def test_steady_120_runs_shape():
    """The default E test: 120 runs of 8192 samples on the six channels (its speed lives in
    benchmarks/bench_teststand.py, not in a timed unit test)."""
    wheel = preset("ithaco-e")
    test = simulate_steady(wheel, wheel.default_speeds_rpm, sample_rate=3840.0, n_samples=8192)
    assert len(test.runs) == 120 and test.runs[0].n_samples == 8192 and test.channels == data.CHANNELS


@pytest.mark.slow
def test_full_e_wheel_spin_up_slice_matches_truth():
    """390 s at 3840 Hz (1.5 M samples): the last 8192-point slice (saturated speed, thesis §2.2.2)
    carries each radial-force line at C·Ω²·|gain|."""
    wheel = preset("ithaco-e")
    sw = simulate_sweep(wheel, **wheel.default_sweep, noise=0.01, seed=0)
    assert len(sw.time) == 390 * 3840
    sl = slice(-8192, None)
    omega = sw.tach[sl]
    w = float(np.mean(omega))
    assert np.ptp(omega) / w < 1e-3                        # quasi-steady at the end of the spin-up
    # phase of a quasi-steady slice: demodulate with the tach-integrated phase, fit line amplitudes
    h, C = wheel.h_and_C("radial_force")
    t = sw.time[sl] - sw.time[sl][0]
    amps, _ = fit_lines(sw.signals["Fx"][sl], t, h * w / TWO_PI)
    gain = np.ones(len(h), dtype=complex)
    for m in wheel.modes:
        if "Fx" in m.channels:
            gain *= m.gain(h * w / TWO_PI, w)
    expected = C * w**2 * np.abs(gain)
    np.testing.assert_allclose(amps, expected, rtol=0.02, atol=3 * sw.meta["noise_std"]["Fx"] / np.sqrt(4096))


# --------------------------------------------------------------------------- extended physics (issue 3)

from dataclasses import asdict, replace  # noqa: E402

from rwadist import extended as ex  # noqa: E402
from rwadist.cli import main as cli_main  # noqa: E402
from rwadist.extended_time import simulate_time  # noqa: E402
from rwadist.units import THESIS_C_TO_SI  # noqa: E402


def fit_complex(x, t, freqs):
    """Least-squares complex amplitudes a_k of x ≈ Re Σ a_k e^{i2πf_k t} (second method to the closed form)."""
    w = TWO_PI * np.asarray(freqs, dtype=float)
    design = np.hstack([np.cos(np.outer(t, w)), np.sin(np.outer(t, w))])
    coef, *_ = np.linalg.lstsq(design, x, rcond=None)
    return coef[: len(w)] - 1j * coef[len(w):]


def whirl_fit(z, t, freqs):
    """Least-squares (forward, backward) content of the complex signal z = X + iY:
    z ≈ Σ a_k e^{+i2πf_k t} + b_k e^{−i2πf_k t}; returns (a, b)."""
    w = TWO_PI * np.asarray(freqs, dtype=float)
    design = np.hstack([np.exp(1j * np.outer(t, w)), np.exp(-1j * np.outer(t, w))])
    coef, *_ = np.linalg.lstsq(design, z, rcond=None)
    return coef[: len(w)], coef[len(w):]


def test_extended_steady_equals_closed_form_by_least_squares():
    """Every line of every channel: least-squares sinusoid fit at the known frequency = steady_lines amplitude
    times one unit phase factor per line (the run's random phase), the same on all the line's channels."""
    wheel = preset("ithaco-e")
    p = wheel.extended
    lines = wheel.extended_lines()
    fs, n = 3840.0, 4096
    t = np.arange(n) / fs
    speeds = [900.0, -1500.0, 1907.0]                  # 1907 rpm: h = 3 on the forward whirl
    test = simulate_steady(wheel, speeds, sample_rate=fs, n_samples=n, noise=0.0, seed=5, physics="extended")
    assert test.meta["physics"] == "extended"
    assert ex.params_from_dict(test.meta["extended"]) == p
    for run, rpm in zip(test.runs, speeds):
        f, A0 = ex.steady_lines(p, lines, [rpm * RPM])          # phases 0
        f, A0 = f[0], A0[0]
        fitted = np.zeros_like(A0)
        for ci, ch in enumerate(data.CHANNELS):
            used = np.nonzero(np.abs(A0[:, ci]) > 0)[0]
            if used.size == 0:
                assert np.abs(run.signals[ch]).max() == 0.0
                continue
            fu, inv = np.unique(np.round(f[used], 9), return_inverse=True)
            assert fu.size == used.size                           # no two lines at one frequency per channel
            fitted[used, ci] = fit_complex(run.signals[ch], t, f[used])
        for j, ln in enumerate(lines):
            on = np.abs(A0[j]) > 1e-6 * np.abs(A0[j]).max()
            ratio = fitted[j, on] / A0[j, on]
            np.testing.assert_allclose(np.abs(ratio), 1.0, rtol=1e-7, err_msg=f"{ln} at {rpm} rpm")
            np.testing.assert_allclose(ratio, ratio[0], rtol=1e-7, err_msg=f"{ln} at {rpm} rpm")
    # and the modes are really there: h = 3 (co) radial torque at its forward-whirl crossing is amplified
    j3 = [j for j, ln in enumerate(lines) if ln.direction == "radial_torque" and ln.h == 3.0][0]
    _, A = ex.steady_lines(p, lines, [1907.0 * RPM])
    assert abs(A[0, j3, 3]) > 3 * lines[j3].C * (1907.0 * RPM) ** 2


def test_extended_imbalance_torque_force_ratio_is_a_wheel_property():
    """Static and dynamic imbalance share one random phase per run plus the fixed imbalance_phase: the 1×
    Tx/Fx ratio is the same in every run at a speed (and equals the closed form), while Fx's phase is not."""
    wheel = preset("ithaco-e")
    p = wheel.extended
    fs, n = 3840.0, 3840
    t = np.arange(n) / fs
    for rpm in (1200.0, -1800.0):
        test = simulate_steady(wheel, [rpm] * 4, sample_rate=fs, n_samples=n, noise=0.0, seed=9, physics="extended")
        lines = wheel.extended_lines()
        f_all, _ = ex.steady_lines(p, lines, [rpm * RPM])
        fr = np.unique(np.round(f_all[0], 9))            # every frequency in the record, for a clean fit
        k1 = int(np.argmin(np.abs(fr - abs(rpm) / 60.0)))
        fx = [fit_complex(r.signals["Fx"], t, fr)[k1] for r in test.runs]
        tx = [fit_complex(r.signals["Tx"], t, fr)[k1] for r in test.runs]
        ratio = np.array(tx) / np.array(fx)
        # closed form with static at 0 and dynamic at imbalance_phase
        _, A = ex.steady_lines(p, ex.imbalance_lines(p, 0.0, wheel.imbalance_phase), [rpm * RPM])
        expected = A[0, 1, 3] / A[0, 0, 0]
        np.testing.assert_allclose(ratio, expected, rtol=1e-7)
        assert np.ptp(np.angle(fx)) > 0.1                 # the shared phase itself is random per run
    # a different imbalance_phase changes the ratio by exactly that angle
    other = replace(wheel, imbalance_phase=wheel.imbalance_phase + 0.5)
    r0 = simulate_steady(wheel, [1200.0], sample_rate=fs, n_samples=n, noise=0.0, seed=9, physics="extended").runs[0]
    r1 = simulate_steady(other, [1200.0], sample_rate=fs, n_samples=n, noise=0.0, seed=9, physics="extended").runs[0]
    f_all, _ = ex.steady_lines(p, wheel.extended_lines(), [1200.0 * RPM])
    fr = np.unique(np.round(f_all[0], 9))
    k1 = int(np.argmin(np.abs(fr - 20.0)))
    q0 = fit_complex(r0.signals["Tx"], t, fr)[k1] / fit_complex(r0.signals["Fx"], t, fr)[k1]
    q1 = fit_complex(r1.signals["Tx"], t, fr)[k1] / fit_complex(r1.signals["Fx"], t, fr)[k1]
    assert wrap(np.angle(q1 / q0)) == pytest.approx(0.5, abs=1e-7)


@pytest.mark.parametrize("rpm", [1165.0, -1165.0])
def test_extended_counter_rotating_h2_is_backward_content(rpm):
    """E wheel h = 2 is counter-rotating: its radial force and torque are X − iY content (whirl against the
    spin) for Ω > 0 and X + iY for Ω < 0; the co-rotating h = 3 the opposite.  At 1165 rpm the h = 2 torque
    sits on the backward whirl and is amplified."""
    wheel = preset("ithaco-e")
    fs, n = 3840.0, 4096
    t = np.arange(n) / fs
    run = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0, seed=1, physics="extended").runs[0]
    f_all, _ = ex.steady_lines(wheel.extended, wheel.extended_lines(), [rpm * RPM])
    fr = np.unique(np.round(f_all[0], 9))
    spin = np.sign(rpm)
    for chx, chy, d in (("Fx", "Fy", "radial_force"), ("Tx", "Ty", "radial_torque")):
        fwd, bwd = whirl_fit(run.signals[chx] + 1j * run.signals[chy], t, fr)
        plus, minus = (fwd, bwd) if spin > 0 else (bwd, fwd)     # plus: rotating with the spin
        k2 = int(np.argmin(np.abs(fr - 2 * abs(rpm) / 60.0)))
        k3 = int(np.argmin(np.abs(fr - 3 * abs(rpm) / 60.0)))
        C2 = dict(wheel.harmonics[d])[2.0]
        assert abs(minus[k2]) > 0.5 * C2 * (rpm * RPM) ** 2 and abs(plus[k2]) < 1e-9 * abs(minus[k2]), d
        assert abs(plus[k3]) > 0 and abs(minus[k3]) < 1e-9 * abs(plus[k3]), d
        if d == "radial_torque":
            assert abs(minus[k2]) > 3 * C2 * (rpm * RPM) ** 2     # backward-whirl amplification


def test_extended_sweep_is_simulate_time_and_matches_steady_at_constant_speed():
    wheel = preset("ithaco-e")
    p = wheel.extended
    fs, dur = 3840.0, 3.0
    sw = simulate_sweep(wheel, 300.0, 1500.0, duration=dur, sample_rate=fs, noise=0.0, seed=3, physics="extended")
    assert sw.meta["physics"] == "extended" and ex.params_from_dict(sw.meta["extended"]) == p
    # the documented phase rule: β (static), β + imbalance_phase (dynamic), uniform for the others in order
    lines = wheel.extended_lines()
    rng = np.random.default_rng(np.random.SeedSequence(3).spawn(2)[0])
    beta = rng.uniform(0, TWO_PI)
    others = list(rng.uniform(0, TWO_PI, size=len(lines) - 2))
    phases = [beta, beta + wheel.imbalance_phase] + others
    assert [ln.imbalance for ln in lines[:2]] == [True, True]
    ref = simulate_time(p, lines, sw.time, sw.tach, phases=phases, start="steady")
    for i, ch in enumerate(data.CHANNELS):
        np.testing.assert_allclose(sw.signals[ch], ref[:, i], rtol=0, atol=1e-12 * np.abs(ref).max())
    # constant speed: time-domain sweep (started in steady state) = closed-form steady run with the same seed
    n = 4096
    sw_c = simulate_sweep(wheel, 1300.0, 1300.0, duration=n / fs, sample_rate=fs, noise=0.01, seed=8,
                          physics="extended")
    st = simulate_steady(wheel, [1300.0], sample_rate=fs, n_samples=n, noise=0.01, seed=8, physics="extended")
    for ch in data.CHANNELS:
        scale = np.abs(st.runs[0].signals[ch]).max()
        np.testing.assert_allclose(sw_c.signals[ch], st.runs[0].signals[ch], rtol=0, atol=1e-6 * scale + 1e-300)


def test_extended_fixture_resonance_and_anti_aliasing_b_wheel():
    """B wheel: fixture resonances multiply each steady line by H(f); the sweep applies the same real filter
    (FFT) so at constant speed it equals the steady run away from the record ends; lines at or above
    Nyquist are not recorded in either."""
    wheel = preset("ithaco-b")
    fs, n, rpm = 1000.0, 8000, 2000.0
    t = np.arange(n) / fs
    on = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0, seed=2, physics="extended")
    off = simulate_steady(wheel, [rpm], sample_rate=fs, n_samples=n, noise=0.0, seed=2, test_stand=False,
                          physics="extended")
    f_all, _ = ex.steady_lines(wheel.extended, wheel.extended_lines(), [rpm * RPM])
    fr = np.unique(np.round(f_all[0], 9))
    a_on = fit_complex(on.runs[0].signals["Fx"], t, fr)
    a_off = fit_complex(off.runs[0].signals["Fx"], t, fr)
    H = np.ones(fr.size, dtype=complex)
    for f0 in (300.0, 460.0):                          # H(r) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r), g 10, ζ 0.01
        r = fr / f0
        H *= (1 - r**2 + 2j * 10 * 0.01 * r) / (1 - r**2 + 2j * 0.01 * r)
    big = np.abs(a_off) > 1e-6 * np.abs(a_off).max()
    np.testing.assert_allclose(a_on[big], (H * a_off)[big], rtol=1e-7)
    sw = simulate_sweep(wheel, rpm, rpm, duration=n / fs, sample_rate=fs, noise=0.0, seed=2, physics="extended")
    # away from the circular ends; the FFT filter of a non-periodic record leaves a ~1e-4 residue near
    # Nyquist (H is complex there), so 1e-3 of the peak -- the fixture itself changes the signal by O(1)
    mid = slice(n // 4, 3 * n // 4)
    for ch in ("Fx", "Ty", "Fz"):
        ref = on.runs[0].signals[ch]
        np.testing.assert_allclose(sw.signals[ch][mid], ref[mid], rtol=0, atol=1e-3 * np.abs(ref).max())
        assert np.abs(off.runs[0].signals[ch] - ref).max() > 0.05 * np.abs(ref).max()   # >> the 1e-3 bound
    # anti-aliasing: at 3400 rpm h = 8.83, 9.54, 10.25 (>= 500 Hz) are absent, h = 8.09 (458.4 Hz) present
    hi = simulate_steady(wheel, [3400.0], sample_rate=fs, n_samples=n, noise=0.0, seed=2, test_stand=False,
                         physics="extended")
    dropped = {(d["direction"], d["h"]) for d in hi.meta["lines_above_nyquist"]}
    assert dropped == {("radial_force", 8.83), ("radial_force", 9.54), ("radial_force", 10.25)}
    f_hi, _ = ex.steady_lines(wheel.extended, wheel.extended_lines(), [3400.0 * RPM])
    kept = np.unique(np.round(f_hi[0][f_hi[0] < 500.0], 9))
    alias = 1000.0 - 9.54 * 3400 / 60                  # where h = 9.54 would alias (459.4 Hz)
    a = fit_complex(hi.runs[0].signals["Fx"], t, np.append(kept, alias))
    C954 = dict(wheel.harmonics["radial_force"])[9.54]
    assert abs(a[-1]) < 1e-9 * C954 * (3400 * RPM) ** 2
    assert abs(a[np.argmin(np.abs(kept - 8.09 * 3400 / 60))]) > 0.1 * C954 * (3400 * RPM) ** 2


def test_physics_switch_default_and_bad_input():
    wheel = preset("ithaco-e")
    a = simulate_steady(wheel, [800.0, 1600.0], n_samples=512, seed=4)
    b = simulate_steady(wheel, [800.0, 1600.0], n_samples=512, seed=4, physics="simple")
    c = simulate_steady(wheel, [800.0, 1600.0], n_samples=512, seed=4, physics="extended")
    for ra, rb, rc in zip(a.runs, b.runs, c.runs):
        np.testing.assert_array_equal(ra.signals["Tx"], rb.signals["Tx"])
        assert not np.allclose(ra.signals["Tx"], rc.signals["Tx"])
    assert a.meta["physics"] == "simple" and c.meta["physics"] == "extended"
    with pytest.raises(ValueError, match="physics"):
        simulate_steady(wheel, [800.0], physics="rotordynamic")
    with pytest.raises(ValueError, match="modes=False"):
        simulate_steady(wheel, [800.0], modes=False, physics="extended")
    with pytest.raises(ValueError, match="extended"):
        simulate_sweep(one_line(), 0, 100, duration=0.1, physics="extended")
    with pytest.raises(ValueError, match="senses"):
        WheelDescription("x", {"radial_force": [(2.0, 1e-7)]}, [], senses={("radial_force", 2.0): "sideways"})


def test_presets_extended_parameters():
    e, b = preset("ithaco-e"), preset("ithaco-b")
    assert asdict(e.extended) == {**asdict(ex.from_table_4_2()), "height": 0.0}
    assert e.senses[("radial_force", 2.0)] == "counter" == e.senses[("radial_torque", 2.0)]
    assert {e.senses[(d, h)] for d in ("radial_force", "radial_torque") for h in (3.0, 4.0, 4.42)} == {"co"}
    pb = b.extended
    assert pb.mass == 5.9 and pb.I_zz == pytest.approx(0.5 * 5.9 * 0.1275**2) and pb.height == 0.0
    for omega, f in ((pb.omega_r, 200.0), (pb.omega_rock, 85.0), (pb.omega_z, 65.0)):   # Table 2.3
        assert omega / TWO_PI == pytest.approx(f, rel=1e-12)
    pe = e.extended
    for z in ("zeta_r", "zeta_rock", "zeta_z"):
        assert getattr(pb, z) == pytest.approx(getattr(pe, z), rel=1e-12)
    # Table 3.3's h = 0.99 coefficients, N/rpm² ×1e-7 -> kg·m with (60/2π)²
    assert pb.U_s == pytest.approx(0.2134e-7 * (60 / TWO_PI) ** 2, rel=1e-12)
    assert pb.U_d == pytest.approx(0.0630 * THESIS_C_TO_SI, rel=1e-12)
    # the 0.99 lines are the imbalances (no double count), the rest carry over
    lines = b.extended_lines()
    assert [ln.h for ln in lines if ln.direction == "radial_force" and not ln.imbalance][0] == 1.99
    assert sum(ln.imbalance for ln in lines) == 2
    assert len(lines) == sum(len(v) for v in b.harmonics.values())
    # the truth model carries the analytical section and senses
    m = e.to_model()
    assert ex.params_from_model(m) == pe
    assert {hm.h: hm.sense for hm in m.harmonics("radial_torque")}[2.0] == "counter"


def test_cli_simulate_test_physics_extended(tmp_path, capsys):
    out = tmp_path / "e"
    assert cli_main(["simulate-test", str(out), "--preset", "ithaco-e", "--physics", "extended",
                     "--speeds-rpm", "600,1200", "--samples", "512", "--noise", "0"]) == 0
    back = data.read_steady(out)
    meta = json.loads((out / "meta.json").read_text())
    assert meta["physics"] == "extended" and ex.params_from_dict(meta["extended"]) == preset("ithaco-e").extended
    ref = simulate_steady(preset("ithaco-e"), [600.0, 1200.0], n_samples=512, noise=0.0, seed=0, physics="extended")
    for r, q in zip(back.runs, ref.runs):
        np.testing.assert_allclose(r.signals["Tx"], q.signals["Tx"], rtol=1e-12, atol=1e-15)
    assert cli_main(["simulate-test", str(tmp_path / "x"), "--preset", "ithaco-e", "--physics", "extended",
                     "--no-modes", "--speeds-rpm", "600"]) == 2
    assert "modes=False" in capsys.readouterr().err


@pytest.mark.slow
def test_full_e_wheel_extended_spin_up():
    """390 s, 3840 Hz extended spin-up of the E wheel: the last slice's 1× force equals the closed form at
    the (saturated) speed, and the backward-whirl crossing of h = 2 shows in the torque."""
    wheel = preset("ithaco-e")
    t0 = time.perf_counter()
    sw = simulate_sweep(wheel, **wheel.default_sweep, noise=0.0, seed=0, physics="extended")
    print(f"\nextended 390 s sweep: {time.perf_counter() - t0:.1f} s")
    sl = slice(-8192, None)
    w = float(np.mean(sw.tach[sl]))
    t = sw.time[sl] - sw.time[sl][0]
    _, A = ex.steady_lines(wheel.extended, ex.imbalance_lines(wheel.extended), [w])
    amp = fit_complex(sw.signals["Fx"][sl], t, [w / TWO_PI])
    assert abs(amp[0]) == pytest.approx(abs(A[0, 0, 0]), rel=2e-3)
