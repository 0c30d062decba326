"""rwadist.diagnose, modulation effects: sidebands (amplitude modulation of one line at a fixed frequency)
and speed ripple (every line phase- and amplitude-modulated by a periodic wheel-speed ripple).

Data: the E-wheel data of tests/test_diagnose.py (preset "ithaco-e", simple physics, modes off, 40 speeds
600-2400 rpm, 4096 samples at 1920 Hz, Welch nperseg 1024, noise 0.01), the effect injected into the time
series and declared nowhere; the starting model is the preset's (the truth without the effect).
"""
from __future__ import annotations

import numpy as np
import pytest
from test_diagnose import FS, SPEEDS, TRUTH, N, e_data, kinds, spectra

from rwadist.diagnose import diagnose, ripple_sideband_powers
from rwadist.presets import preset
from rwadist.teststand import simulate_steady
from rwadist.units import DIRECTION_CHANNELS

#: Sidebands injected: carrier h = 2 of the radial force, f_mod 7 Hz, depth 0.4.
SB = {"direction": "radial_force", "h": 2.0, "f_mod": 7.0, "depth": 0.4}
#: Speed ripple injected: 8 Hz, ΔΩ = 3 rad/s (29 rpm; 4.8 % of the speed at 600 rpm, 1.2 % at 2400 rpm).
RIPPLE = {"f_ripple": 8.0, "delta_omega": 3.0}


def inject_sidebands(seed, direction="radial_force", h=2.0, f_mod=7.0, depth=0.4):
    """E-wheel data whose line (direction, h) is amplitude modulated: C·Ω²·(1 + m·cos(2π f_mod t + φ_m)) on the
    vector turning at h|Ω| (x = Re, y = Im), carrier phase and φ_m random per run."""
    test = e_data(seed, drop=(direction, h))
    C = dict(preset("ithaco-e").harmonics[direction])[h]
    chans = DIRECTION_CHANNELS[direction]
    rng = np.random.default_rng(seed + 2000)
    for r in test.runs:
        t = np.arange(r.n_samples) / r.sample_rate
        w = abs(r.speed)
        env = 1.0 + depth * np.cos(2 * np.pi * f_mod * t + rng.uniform(0, 2 * np.pi))
        z = C * w**2 * env * np.exp(1j * (h * w * t + rng.uniform(0, 2 * np.pi)))
        r.signals[chans[0]] += z.real
        if len(chans) > 1:
            r.signals[chans[1]] += z.imag
    return test


def rippled_data(seed, f_ripple=8.0, delta_omega=3.0, tangential=False):
    """E-wheel data at a rippled speed Ω(t) = Ω0 + ΔΩ sin(2π f_r t + φ_r): every line of the preset is
    C·Ω(t)²·exp(±j(h·ψ(t) + α)) (− for the preset's counter-rotating harmonics), ψ = ∫Ω dt in closed form
    (as the stand's sweeps: amplitude at the instantaneous speed, phase h·ψ); the sensor noise is that of e_data(seed) exactly (noisy minus noise-free run).
    ``tangential``: the imbalances (h = 1 of the radial force and torque) also push along the rim, C·(Ω² − jΩ̇)
    (−m·d²(e·e^{jψ})/dt² = m·e·(ψ̇² − jψ̈)·e^{jψ}), Ω̇ = ΔΩ·2πf_r·cos(2πf_r t + φ_r) in the time domain."""
    w = preset("ithaco-e")
    noisy = e_data(seed)
    clean = simulate_steady(w, SPEEDS, sample_rate=FS, n_samples=N, modes=False, noise=0.0, seed=seed)
    rng = np.random.default_rng(seed + 3000)
    for r, c in zip(noisy.runs, clean.runs):
        t = np.arange(r.n_samples) / r.sample_rate
        w0 = abs(r.speed)
        ph = rng.uniform(0, 2 * np.pi)
        th = 2 * np.pi * f_ripple * t + ph
        omega = w0 + delta_omega * np.sin(th)
        omega_dot = delta_omega * 2 * np.pi * f_ripple * np.cos(th)
        psi = w0 * t - delta_omega / (2 * np.pi * f_ripple) * (np.cos(th) - np.cos(ph))
        for ch in r.signals:
            r.signals[ch] = r.signals[ch] - c.signals[ch]                 # the noise alone
        for d, chans in DIRECTION_CHANNELS.items():
            for h, C in w.harmonics.get(d, []):
                sign = -1.0 if w.senses.get((d, h)) == "counter" else 1.0      # a counter-rotating line: e^{-ihψ}
                push = 1j * sign * omega_dot if tangential and h == 1.0 and d in ("radial_force", "radial_torque") \
                    else 0.0
                z = C * (omega**2 - push) * np.exp(1j * sign * (h * psi + rng.uniform(0, 2 * np.pi)))
                r.signals[chans[0]] += z.real
                if len(chans) > 1:
                    r.signals[chans[1]] += z.imag
    return noisy


# --------------------------------------------------------------------------- ripple line powers

def test_ripple_sideband_powers_are_bessel_and_conserve_power():
    """Pure phase modulation: |c_k|² = J_k(β)² (scipy.special.jv, a second method) and Σ_k = 1 (Parseval);
    with the amplitude term (1 + ε sin θ)^2 the total is the closed form 1 + 3ε² + 3ε⁴/8."""
    from scipy.special import jv

    beta = np.array([0.05, 0.4, 1.7, 6.0])
    k, P = ripple_sideband_powers(beta, np.zeros(4), 2.0)
    assert np.allclose(P, jv(k[None, :], beta[:, None]) ** 2, atol=1e-12)
    assert np.allclose(P.sum(1), 1.0, atol=1e-12)
    eps = np.array([0.01, 0.05, 0.2, 0.5])
    _, P = ripple_sideband_powers(beta, eps, 2.0)
    assert np.allclose(P.sum(1), 1 + 3 * eps**2 + 3 * eps**4 / 8, rtol=1e-10)
    # first order, small β and ε: upper/lower sideband amplitudes ε ± β/2 (AM and PM in phase, derived by hand)
    _, P = ripple_sideband_powers(0.02, 0.004, 2.0)
    i0 = P.size // 2
    assert np.sqrt(P[i0 + 1]) == pytest.approx(2 * 0.004 / 2 + 0.01, rel=0.01)
    assert np.sqrt(P[i0 - 1]) == pytest.approx(0.01 - 0.004, rel=0.02)


def test_ripple_prediction_matches_welch_of_a_rippled_line():
    """Context.predict of one line under a speed ripple is the Welch PSD of the synthesised rippled line
    (independent synthesis: cumulative phase h·ψ(t) sampled, scipy Welch) to a few per cent where it matters."""
    from rwadist.diagnose import Context, State
    from rwadist.effects.speed_ripple_diagnose import SpeedRipple
    from rwadist.model import Harmonic, WheelModel

    test = e_data(0, speeds=np.array([1500.0]))
    run = test.runs[0]
    t = np.arange(run.n_samples) / run.sample_rate
    w0, h, C, dw, fr = abs(run.speed), 4.42, 1e-6, 6.0, 8.0
    th = 2 * np.pi * fr * t
    z = C * (w0 + dw * np.sin(th)) ** 2 * np.exp(1j * h * (w0 * t - dw / (2 * np.pi * fr) * np.cos(th)))
    for c in run.signals:
        run.signals[c] = np.zeros(run.n_samples)
    run.signals["Fx"] = z.real
    sp = spectra(test)
    ctx = Context(sp, channels=["Fx"])
    m = WheelModel(name="one")
    m.empirical["radial_force"] = [Harmonic(h, C)]
    st = SpeedRipple(dw, fr, w0).apply(State(m, {"Fx": np.zeros(sp.f.size)}))
    pred = ctx.predict(st, "Fx", np.array([0]))[0]
    f0 = h * w0 / (2 * np.pi)
    for kk in (-2, -1, 0, 1, 2):
        k = int(round((f0 + kk * fr) / sp.df))
        band = slice(k - 2, k + 3)
        assert pred[band].sum() == pytest.approx(sp.psd["Fx"][0, band].sum(), rel=0.05)
    assert pred.sum() == pytest.approx(sp.psd["Fx"][0].sum(), rel=0.01)


# --------------------------------------------------------------------------- acceptance

@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sidebands_found(seed):
    """Radial-force fundamental amplitude modulated at 7 Hz, depth 0.4: named ``sidebands`` (not missing
    harmonics, not a speed ripple), f_mod within 2 %, depth within 15 %, error cut at least 3×."""
    test = inject_sidebands(seed, h=1.0)
    d = diagnose(spectra(test), TRUTH)
    assert kinds(d) == ["sidebands"]
    e = d.model.effects[0]
    assert e["direction"] == "radial_force" and e["h"] == pytest.approx(1.0)
    assert e["f_mod_Hz"] == pytest.approx(7.0, rel=0.02)
    assert e["depth"] == pytest.approx(0.4, rel=0.15)
    assert d.error_before > 3 * d.error_after


def test_sidebands_of_a_weak_line_found():
    """The h = 2 radial-force line (a fifth of the fundamental) modulated alike: named and fitted as well; its
    sidebands carry so little power that the clean data's own error floor (~6.5e-4) caps the cut at ~2.2×."""
    test = inject_sidebands(0, h=2.0)
    d = diagnose(spectra(test), TRUTH)
    assert kinds(d) == ["sidebands"]
    e = d.model.effects[0]
    assert e["h"] == pytest.approx(2.0)
    assert e["f_mod_Hz"] == pytest.approx(7.0, rel=0.02)
    assert e["depth"] == pytest.approx(0.4, rel=0.15)
    assert d.error_before > 2 * d.error_after


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_speed_ripple_found(seed):
    """Wheel speed rippled ±3 rad/s at 8 Hz: named ``speed_ripple`` (one effect for every line, not per-line
    sidebands), the fixed-size law (q = 0) preferred to the fixed fraction, f_ripple within 2 %, ΔΩ within
    15 %, error cut at least 3×."""
    test = rippled_data(seed, **RIPPLE)
    d = diagnose(spectra(test), TRUTH)
    assert kinds(d) == ["speed_ripple"]
    e = d.model.effects[0]
    assert e["f_ripple_Hz"] == pytest.approx(RIPPLE["f_ripple"], rel=0.02)
    assert e["delta_omega_rad_s"] == pytest.approx(RIPPLE["delta_omega"], rel=0.15)
    assert e["speed_exponent"] == 0.0
    assert d.error_before > 3 * d.error_after


def test_speed_ripple_inside_the_welch_kernel_found_on_the_whole_record():
    """A ripple 1.5 Welch bins from its lines (2.8 Hz at 1.875-Hz bins; 6 bins of the whole record), the imbalances'
    tangential force included in the time series: the Welch grid starts at 2.5 bins and the error metric's bands
    sum the sidebands with their carrier, so only the whole record shows it.  Named ``speed_ripple`` alone, q = 0,
    f_ripple within 1 %, ΔΩ within 10 % of the truth."""
    test = rippled_data(5, f_ripple=2.8, delta_omega=3.0, tangential=True)
    d = diagnose(spectra(test), TRUTH, test=test)
    assert kinds(d) == ["speed_ripple"]
    e = d.model.effects[0]
    assert e["f_ripple_Hz"] == pytest.approx(2.8, rel=0.01)
    assert e["delta_omega_rad_s"] == pytest.approx(3.0, rel=0.10)
    assert e["speed_exponent"] == 0.0


def test_ripple_sidebands_of_an_imbalance_bessel_and_first_order():
    """The ripple's coefficients with the imbalance's tangential term −jτ cos θ: at ε = 0 the closed form
    (−j)^k (J_k(β) + τ J_k'(β)) (Bessel, scipy); with every term the first sidebands (ε ± (β + τ)/2)² to first order."""
    from scipy.special import jv, jvp

    from rwadist.effects.speed_ripple_diagnose import sideband_fractions
    from rwadist.extended_ripple import ripple_coefficients

    for beta, tau in ((0.7, 0.3), (2.4, -0.5), (0.05, 0.0)):
        k, c = ripple_coefficients(beta, 0.0, 2.0, k_max=10, tau=tau)
        assert c == pytest.approx((-1j) ** k * (jv(k, beta) + tau * jvp(k, beta)), abs=1e-13)
    dw, w, f_r, h = 0.3, 60.0, 2.8, 1.0
    beta, eps, tau = h * dw / (2 * np.pi * f_r), dw / w, dw * 2 * np.pi * f_r / w**2
    lo, up, _ = sideband_fractions(h, dw, w, f_r, 2.0, True)
    assert up == pytest.approx((eps + (beta + tau) / 2) ** 2, rel=0.02)
    assert lo == pytest.approx((eps - (beta + tau) / 2) ** 2, rel=0.05)
    lo0, up0, _ = sideband_fractions(h, dw, w, f_r, 2.0, False)
    assert up0 == pytest.approx((eps + beta / 2) ** 2, rel=0.02)


# --------------------------------------------------------------------------- rwadist psd

def _psd_model(effects):
    from rwadist.model import Harmonic, WheelModel

    m = WheelModel(name="t")
    m.empirical["radial_force"] = [Harmonic(2.0, 1.0e-6, sense="co"), Harmonic(3.0, 0.5e-6, sense="co")]
    m.effects = effects
    return m


def _quad_mean(fn, law):
    from scipy import integrate

    return integrate.quad(lambda w: fn(w) * law.pdf(w), law.lo, law.hi, limit=200)[0]


def test_psd_sidebands_add_their_power():
    """Sidebands of depth m on the h = 2 line add m²/2 of that line's speed-averaged mean square (Parseval,
    against quadrature), to the Fx and Fy of that line only."""
    from rwadist.broadband import Uniform, broadband_psd, empirical_lines
    from rwadist.units import rpm_to_rad_s

    law = Uniform(float(rpm_to_rad_s(600.0)), float(rpm_to_rad_s(3000.0)))
    sb = {"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 7.0, "depth": 0.4}
    kw = dict(f_max=200.0, n_freq=20001, n_speeds=4000)
    with_sb = broadband_psd(empirical_lines(_psd_model([sb])), law, **kw)
    plain = broadband_psd(empirical_lines(_psd_model([])), law, **kw)
    df = plain.f[1] - plain.f[0]
    added = (with_sb.psd - plain.psd).sum(0) * df
    line = _quad_mean(lambda w: (1.0e-6 * w**2) ** 2 / 2, law)
    assert added[0] == pytest.approx(0.4**2 / 2 * line, rel=5e-3)
    assert added[1] == pytest.approx(0.4**2 / 2 * line, rel=5e-3)
    assert np.allclose(added[2:], 0.0, atol=1e-6 * line)


def test_psd_speed_ripple_conserves_phase_power_adds_amplitude_term():
    """A speed ripple's phase modulation moves no power; its amplitude modulation multiplies each C·Ω² line's
    mean square by the Parseval sum of :func:`ripple_sideband_powers` (a second method, FFT over the ripple
    period) - checked against quadrature over the speed law, with a large ripple so the term shows."""
    from rwadist.broadband import Uniform, broadband_psd, empirical_lines
    from rwadist.units import rpm_to_rad_s

    law = Uniform(float(rpm_to_rad_s(600.0)), float(rpm_to_rad_s(3000.0)))
    dw, w_ref, fr = 15.0, 150.0, 8.0
    kw = dict(f_max=200.0, n_freq=20001, n_speeds=4000)
    for q in (0.0, 1.0):
        rip = {"kind": "speed_ripple", "f_ripple_Hz": fr, "delta_omega_rad_s": dw, "omega_ref_rad_s": w_ref,
               "speed_exponent": q}
        res = broadband_psd(empirical_lines(_psd_model([rip])), law, **kw)
        ms = res.psd.sum(0) * (res.f[1] - res.f[0])

        def line_ms(w):
            d = dw * (abs(w) / w_ref) ** q
            tot = 0.0
            for h, C in ((2.0, 1.0e-6), (3.0, 0.5e-6)):
                _, P = ripple_sideband_powers(h * d / (2 * np.pi * fr), d / abs(w), 2.0)
                tot += (C * w**2) ** 2 / 2 * P.sum()
            return tot

        expected = _quad_mean(line_ms, law)
        assert ms[0] == pytest.approx(expected, rel=5e-3)
        plain = _quad_mean(lambda w: ((1e-6 * w**2) ** 2 + (0.5e-6 * w**2) ** 2) / 2, law)
        assert expected / plain - 1 > 0.005           # the amplitude term is visible at this ripple
