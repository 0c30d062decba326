"""Diagnosed broadband floors and speed ripple in the FMU (issue 7): the floor's multisine against
Parseval and the floor's PSD, the ripple against the same FMU fed the rippled speed and against
the closed-form Bessel/amplitude sidebands, the native kernel against numpy, fmpy against the
runtime, switches, and bad entries."""
from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy.signal import welch
from scipy.special import jv
from test_fmu import NATIVE_ONLY, assert_native_equals_numpy, kernel, slope, spin_up  # noqa: F401  (kernel: a fixture)

from rwadist import model as model_io
from rwadist.fmu import hosts
from rwadist.fmu import runtime as rt
from rwadist.fmu.build import build_fmu
from rwadist.presets import preset

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")

FLOOR = {"kind": "broadband_floor", "channel": ["Fx", "Tz"], "exponent": 2.5, "omega_ref_rad_s": 200.0,
         "f_Hz": [5.0, 60.0, 140.0, 300.0], "psd_ref": [1.0e-5, 4.0e-5, 4.0e-5, 0.5e-5]}
RIPPLE = {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 10.0, "omega_ref_rad_s": 200.0,
          "speed_exponent": 0.0}


def doc_with(effects, model=None):
    doc = model_io.to_json(model or preset("ithaco-e").to_model())
    doc["effects"] = copy.deepcopy(effects)
    return doc


def runtime(doc, **kw):
    params, lines = rt.model_from_doc(doc)
    return rt.WheelRuntime(params, lines, **rt.effects_from_doc(doc), **kw)


def worst_rel(out, ref):
    """Largest |out − ref| per channel relative to the channel's peak; a channel that is 0 in ``ref``
    must be 0 in ``out`` (then 0 here)."""
    scale = np.max(np.abs(ref), axis=0)
    diff = np.max(np.abs(out - ref), axis=0)
    return np.where(scale > 0, diff / np.where(scale > 0, scale, 1.0), np.where(diff > 0, np.inf, 0.0))


def floor_integral(e, f_max=400.0):
    """∫ psd_ref(f) df of a floor entry, trapezoid on a fine grid (independent of the multisine grid)."""
    f = np.linspace(0.0, f_max, 400_001)
    return float(np.trapezoid(np.interp(f, e["f_Hz"], e["psd_ref"], left=0.0, right=0.0), f))


# ------------------------------------------------------------------ broadband floor

@pytest.mark.parametrize("seed", [None, 5])
def test_floor_mean_square_is_its_integral(seed):
    """Lines off, constant speed: over one period 1/df the floor channel's mean square is
    ∫psd_ref df·(Ω/Ω_ref)^p (Parseval of the multisine; 1e-3 for the grid's rectangle rule, exact
    1e-12 against it), at two speeds; the channels without a floor stay 0."""
    doc = doc_with([FLOOR])
    df = 0.25
    dt = 1e-3
    t = np.arange(int(round(1 / df / dt)) + 1) * dt
    ref = floor_integral(FLOOR)
    f_k = np.arange(1, int(300 / df) + 1) * df
    rect = float(np.sum(np.interp(f_k, FLOOR["f_Hz"], FLOOR["psd_ref"], left=0.0, right=0.0)) * df)
    for w in (200.0, -350.0):
        out = runtime(doc, seed=seed, imbalance=False, harmonics=False, floor_resolution=df).run(t, np.full(t.size, w))
        gain = (abs(w) / 200.0) ** 2.5
        for c in (0, 5):
            ms = float(np.mean(out[1:, c] ** 2))
            assert ms == pytest.approx(rect * gain, rel=1e-12)
            assert ms == pytest.approx(ref * gain, rel=1e-3)
        assert np.all(out[:, 1:5] == 0.0)


def test_floor_psd_matches_psd_ref():
    """The periodogram of one period (boxcar, 1/df long) of the floor output is psd_ref(f_k)·(Ω/Ω_ref)^p at
    every grid frequency (1e-8 of the peak: one component per bin); a 4-s Hann Welch estimate, as an engineer would
    take it, is within 10 % in 10-Hz bands; the two channels of one floor entry are incoherent."""
    doc = doc_with([FLOOR])
    dt, df = 1e-3, 0.1
    t = np.arange(20001) * dt
    w = 300.0
    out = runtime(doc, seed=2, imbalance=False, harmonics=False, floor_resolution=df).run(t, np.full(t.size, w))
    gain = (w / 200.0) ** 2.5
    f, P = welch(out[1:, 0], fs=1 / dt, window="boxcar", nperseg=10000, noverlap=0, detrend=False)
    expect = np.interp(f, FLOOR["f_Hz"], FLOOR["psd_ref"], left=0.0, right=0.0) * gain
    inner = (f > 0) & (f < 1 / (2 * dt))
    assert np.max(np.abs(P[inner] - expect[inner])) < 1e-8 * np.max(expect)
    f, P = welch(out[1:, 0], fs=1 / dt, nperseg=4096)
    expect = np.interp(f, FLOOR["f_Hz"], FLOOR["psd_ref"], left=0.0, right=0.0) * gain
    worst = 0.0
    for lo in np.arange(10.0, 290.0, 10.0):
        band = (f >= lo) & (f < lo + 10.0)
        worst = max(worst, abs(P[band].mean() / expect[band].mean() - 1))
    assert worst < 0.10, worst
    x, y = out[1:, 0], out[1:, 5]
    assert abs(np.mean(x * y)) < 0.05 * np.sqrt(np.mean(x * x) * np.mean(y * y))
    print(f"\nworst 10-Hz band of a 4-s Hann Welch PSD of the floor vs psd_ref: {worst:.3f}")


@pytest.mark.parametrize("seed", [None, 3])
def test_floors_of_channels_and_entries_are_incoherent(seed):
    """With or without a seed, two channels of one floor entry and two entries with different shapes are
    incoherent: mean Welch coherence over 10-290 Hz below 0.15 for every pair (identical phases would
    give 1), so a 45° mounting adds their powers (spacecraft-frame Fx mean square = the mean of the two
    within 5 %)."""
    from scipy.signal import coherence
    fy = dict(FLOOR, channel="Fy", f_Hz=[5.0, 100.0, 300.0], psd_ref=[2.0e-5, 3.0e-5, 1.0e-5])
    doc = doc_with([FLOOR, fy])
    dt = 1e-3
    t = np.arange(20001) * dt
    c45 = np.sqrt(0.5)
    R = [[c45, -c45, 0.0], [c45, c45, 0.0], [0.0, 0.0, 1.0]]
    W = runtime(doc, seed=seed, imbalance=False, harmonics=False, dcm=R)
    h = dt
    y = np.array([W.step12(200.0, 0.0, h) for _ in range(t.size - 1)])
    x, yy, z = y[:, 0], y[:, 1], y[:, 5]
    for a, b in ((x, z), (x, yy), (yy, z)):
        f, C = coherence(a, b, fs=1 / dt, nperseg=1024)
        band = (f > 10) & (f < 290)
        assert C[band].mean() < 0.15, C[band].mean()
    ms = np.mean(y[:, 6] ** 2)
    assert ms == pytest.approx(0.5 * (np.mean(x**2) + np.mean(yy**2)), rel=0.05)


def test_floor_adds_to_the_lines_and_reaches_the_spacecraft_frame():
    """Floor on = floor off + the floor alone (the lines' phases do not move), on a spin-up with modes;
    the spacecraft-frame outputs are R·F and R·T + r × R·F of the wheel-frame ones."""
    doc = doc_with([FLOOR])
    t, w = spin_up(T=2.0)
    R = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    r = np.array([0.1, 0.2, -0.3])
    kw = dict(seed=7, dcm=R, position=r)

    def run12(W):
        h = t[1] - t[0]
        acc = slope(t, w)
        return np.array([W.step12(w[n], acc[n], h) for n in range(t.size - 1)])

    both = run12(runtime(doc, **kw))
    lines = run12(runtime(doc, broadband_floor=False, **kw))
    floor = run12(runtime(doc, imbalance=False, harmonics=False, **kw))
    assert np.max(np.abs(both - lines - floor)) < 1e-12 * np.max(np.abs(both))
    assert np.any(floor[:, 0] != 0)
    F = both[:, :3] @ R.T
    T = both[:, 3:6] @ R.T + np.cross(r, F)
    assert np.allclose(both[:, 6:], np.hstack([F, T]), rtol=0, atol=1e-12 * np.max(np.abs(both)))


def test_floor_seeds_and_phasor_resync():
    """Different seeds give different realisations of the same mean square; the same seed the same
    output; the rotating phasors equal the direct sum Σ a_k cos(ω_k t + φ_k) over 4000 steps (past
    three resynchronisations) to 1e-9 of the peak (the runtime's time is the sum of its steps, ~1e-13 s
    from n·dt after 4000 steps: ω_k·1e-13 at 300 Hz is 2e-10)."""
    doc = doc_with([FLOOR])
    dt = 1e-3
    t = np.arange(4001) * dt
    w = np.full(t.size, 200.0)
    a = runtime(doc, seed=1, imbalance=False, harmonics=False).run(t, w)
    b = runtime(doc, seed=2, imbalance=False, harmonics=False).run(t, w)
    c = runtime(doc, seed=1, imbalance=False, harmonics=False).run(t, w)
    assert np.array_equal(a, c)
    assert np.max(np.abs(a[:, 0] - b[:, 0])) > 0.1 * np.max(np.abs(a[:, 0]))
    W = runtime(doc, seed=1, imbalance=False, harmonics=False)
    A, wk = W.floor_A[:W.floor_starts[1]], W.floor_w[:W.floor_starts[1]]
    direct = (A[None, :] * np.exp(1j * np.outer(t, wk))).real.sum(axis=1)
    assert np.max(np.abs(a[:, 0] - direct)) < 1e-9 * np.max(np.abs(direct))


# ------------------------------------------------------------------ speed ripple

def rippled_speed(t, w, e, theta=0.0):
    """Ω(t) + ΔΩ_ref (|Ω|/Ω_ref)^q sin(2π f_r t + θ)."""
    dw = e["delta_omega_rad_s"] * (np.abs(w) / e["omega_ref_rad_s"]) ** e.get("speed_exponent", 0.0)
    return w + dw * np.sin(2 * np.pi * e["f_ripple_Hz"] * t + theta)


@pytest.mark.parametrize("q", [0.0, 1.0])
def test_ripple_equals_the_fmu_fed_the_rippled_speed(q):
    """With modes, imbalance and every harmonic: the runtime with a diagnosed ripple = the runtime without
    it fed Ω(t) + r(t) with the slope as acceleration, 1e-10 relative (rounding: the runtime's time is the
    sum of its steps, the test's n·dt; spin-up, speed law exponent q;
    with a seed the ripple's phase θ comes from default_rng((seed, 1)))."""
    e = dict(RIPPLE, speed_exponent=q)
    doc = doc_with([e])
    plain = doc_with([])
    t, w = spin_up(T=3.0)
    for seed in (None, 9):
        theta = 0.0 if seed is None else np.random.default_rng((seed, 1)).uniform(0, 2 * np.pi, 1)[0]
        a = runtime(doc, seed=seed).run(t, w)[1:]      # (t0 row: the FMU takes dr/dt there, the host a slope)
        wr = rippled_speed(t, w, e, theta)
        b = runtime(plain, seed=seed).run(t, wr)[1:]
        assert np.all(worst_rel(a, b) < 1e-10), worst_rel(a, b)
        c = runtime(doc, seed=seed, speed_ripple=False).run(t, w)[1:]
        assert np.max(worst_rel(a, c)) > 1e-3          # the ripple does something


def ripple_coefficients_p2(beta, eps, k):
    """|c_k| of (1 + ε sin θ)² e^{−iβ cos θ} = Σ c_k e^{ikθ}: the Fourier coefficients of the
    amplitude, {0: 1 + ε²/2, ±1: ∓iε, ±2: −ε²/4}, convolved with (−i)^n J_n(β)."""
    a = {0: 1 + eps**2 / 2, 1: -1j * eps, -1: 1j * eps, 2: -eps**2 / 4, -2: -eps**2 / 4}
    return np.array([abs(sum(am * (-1j) ** (kk - m) * jv(kk - m, beta) for m, am in a.items())) for kk in k])


def test_ripple_sidebands_closed_form():
    """Modes off, one co-rotating radial harmonic h = 2 at constant Ω = 200 rad/s, ripple ΔΩ = 10 rad/s at
    4 Hz (β = hΔΩ/2πf_r = 0.80, ε = 0.05): least-squares amplitudes of F = Fx + iFy at hΩ + 2πk f_r,
    k = −4..4, equal C·Ω²·|c_k| of the closed form (1e-5 of the carrier, measured 1.7e-7; the step's
    linear speed is the only approximation)."""
    m = preset("ithaco-e").to_model()
    C = 5.0e-7
    m.empirical = {"radial_force": [model_io.Harmonic(h=2.0, C=C)]}
    doc = doc_with([RIPPLE], m)
    dt = 1e-4
    t = np.arange(40001) * dt
    W0 = 200.0
    out = runtime(doc, seed=3, imbalance=False, modes=False).run(t, np.full(t.size, W0))
    F = out[:, 0] + 1j * out[:, 1]
    k = np.arange(-4, 5)
    wr = 2 * np.pi * RIPPLE["f_ripple_Hz"]
    coef, *_ = np.linalg.lstsq(np.exp(1j * np.outer(t, 2 * W0 + k * wr)), F, rcond=None)
    beta, eps = 2 * RIPPLE["delta_omega_rad_s"] / wr, RIPPLE["delta_omega_rad_s"] / W0
    expect = C * W0**2 * ripple_coefficients_p2(beta, eps, k)
    assert np.max(np.abs(np.abs(coef) - expect)) < 1e-5 * C * W0**2, (np.abs(coef) / expect)
    # the sidebands are asymmetric through the amplitude term (upper ≈ β/2 + ε, lower ≈ β/2 − ε)
    assert abs(coef[5]) > 1.2 * abs(coef[3])
    assert np.sum(np.abs(coef) ** 2) == pytest.approx(C**2 * W0**4 * (1 + 3 * eps**2 + 3 * eps**4 / 8), rel=1e-3)


# ------------------------------------------------------------------ native kernel, fmpy, switches, errors

@NATIVE_ONLY
def test_native_kernel_with_floor_and_ripple_equals_numpy(kernel):  # noqa: F811
    """C kernel = numpy runtime with a floor and a ripple (1e-12), with modes, start_steady and derived
    acceleration."""
    assert kernel is not None
    doc = doc_with([FLOOR, RIPPLE])
    t, w = spin_up(T=2.0)
    h = t[1] - t[0]
    for kw, acc in ((dict(), slope(t, w)), (dict(start_steady=True), [None] * t.size)):
        assert_native_equals_numpy(runtime(doc, seed=4, **kw), runtime(doc, seed=4, kernel=kernel, **kw), w, acc, h, kw)


def test_fmu_with_floor_and_ripple_through_fmpy(tmp_path):
    """Through fmpy (native layer where built): = the numpy runtime to 1e-9 with both effects; with
    speed_ripple and broadband_floor off = the FMU of the model without them; floor_resolution is read."""
    doc = doc_with([FLOOR, RIPPLE])
    path = build_fmu(doc, tmp_path / "floor_ripple.fmu")
    t, w = spin_up(T=1.0)
    inputs = {"wheel_speed": w, "wheel_acceleration": slope(t, w)}
    par = {"use_wheel_acceleration": True, "seed": 6, "floor_resolution": 0.5}
    out = hosts.run_fmpy(path, t, inputs, par)
    ref = runtime(doc, seed=6, floor_resolution=0.5).run(t, w)
    assert np.all(worst_rel(out[:, :6], ref) < 1e-9), worst_rel(out[:, :6], ref)
    off = hosts.run_fmpy(path, t, inputs, dict(par, speed_ripple=False, broadband_floor=False))
    plain = hosts.run_fmpy(build_fmu(doc_with([]), tmp_path / "plain.fmu"), t, inputs, par)
    assert np.array_equal(off, plain)
    assert np.max(worst_rel(out, plain)) > 1e-2


@pytest.mark.parametrize("index, field, value", [
    (0, "channel", "Fw"), (0, "f_Hz", [5.0, 4.0, 140.0, 300.0]), (0, "psd_ref", [1e-5, -1e-5, 1e-5, 1e-5]),
    (0, "psd_ref", [1e-5, 1e-5]), (0, "exponent", float("nan")), (0, "omega_ref_rad_s", 0.0),
    (1, "f_ripple_Hz", 0.0), (1, "delta_omega_rad_s", -1.0), (1, "speed_exponent", -0.5),
    (1, "omega_ref_rad_s", "200")])
def test_bad_floor_or_ripple_entry_is_refused(index, field, value):
    """A bad entry is refused by the FMU build naming effects[i].<field>."""
    effects = copy.deepcopy([FLOOR, RIPPLE])
    effects[index][field] = value
    with pytest.raises(rt.ModelError, match=rf"effects\[{index}\]\.{field}"):
        build_fmu(doc_with(effects), "/nonexistent/x.fmu")


def test_floor_resolution_and_effect_rules():
    """floor_resolution is checked (with or without floors); a floor span needing more than
    FLOOR_MAX_COMPONENTS sinusoids is refused before anything is allocated (a 2e9-Hz span answers at
    once); a floor narrower than the resolution is refused; a channel named twice is one floor (as the
    coupling kit reads it); a second speed_ripple is refused (as the coupling kit)."""
    import time
    doc = doc_with([FLOOR])
    for bad in (0.0, float("nan"), -1.0):
        with pytest.raises(rt.ModelError, match="floor_resolution"):
            runtime(doc, floor_resolution=bad)
        with pytest.raises(rt.ModelError, match="floor_resolution"):
            runtime(doc_with([]), floor_resolution=bad)
    with pytest.raises(rt.ModelError, match="coarser floor_resolution"):
        runtime(doc, floor_resolution=1e-4)
    huge = doc_with([dict(FLOOR, f_Hz=[5.0, 2.0e9], psd_ref=[1e-6, 1e-6])])
    t0 = time.perf_counter()
    with pytest.raises(rt.ModelError, match=r"f_Hz: values must be <= 1e\+06"):    # beyond the schema's range
        runtime(huge)
    wide = doc_with([dict(FLOOR, f_Hz=[5.0, 9.0e5], psd_ref=[1e-6, 1e-6])])       # within it, still too many
    with pytest.raises(rt.ModelError, match="coarser floor_resolution"):
        runtime(wide, floor_resolution=1e-3)
    assert time.perf_counter() - t0 < 1.0
    with pytest.raises(rt.ModelError, match="finer floor_resolution"):
        runtime(doc_with([dict(FLOOR, f_Hz=[10.01, 10.05], psd_ref=[1e-6, 1e-6])]))
    dt = 1e-3
    t = np.arange(int(round(1 / 0.25 / dt)) + 1) * dt
    twice = doc_with([dict(FLOOR, channel=["Fx", "Fx"])])
    out = runtime(twice, seed=1, imbalance=False, harmonics=False, floor_resolution=0.25).run(t, np.full(t.size, 200.0))
    assert np.mean(out[1:, 0] ** 2) == pytest.approx(floor_integral(FLOOR), rel=1e-3)
    with pytest.raises(rt.ModelError, match=r"effects\[1\]\.kind: a second speed_ripple"):
        rt.effects_from_doc(doc_with([RIPPLE, dict(RIPPLE, f_ripple_Hz=9.0)]))


def test_ripple_needs_steps_that_resolve_it():
    """A communication step longer than 1/(20 f_r) is refused with a message naming the ripple (the
    ripple would otherwise be weakened, or vanish at h = 1/(2 f_r)); without the ripple it is taken."""
    doc = doc_with([RIPPLE])                     # 4 Hz: at most 12.5 ms
    runtime(doc, max_step=0.1).step12(200.0, 0.0, 0.0125)
    with pytest.raises(rt.ModelError, match="does not resolve the speed ripple of 4 Hz"):
        runtime(doc, max_step=0.1).step12(200.0, 0.0, 0.02)
    runtime(doc, max_step=0.1, speed_ripple=False).step12(200.0, 0.0, 0.02)


def test_cli_fmu_check_reports_the_fmus_reason(tmp_path, capsys):
    """`rwadist fmu check` of a rippled wheel: fine at 1-ms steps; at 10-ms steps (an 8-Hz ripple needs
    at most 6.25 ms) it fails and prints the FMU's own reason."""
    from rwadist.cli import main
    m = preset("ithaco-e").to_model()
    m.effects = [dict(RIPPLE, f_ripple_Hz=8.0)]
    path = tmp_path / "rippled.fmu"
    assert main(["fmu", "build", str(model_io.save(m, tmp_path / "m.json")), "-o", str(path)]) == 0
    assert main(["fmu", "check", str(path)]) == 0
    capsys.readouterr()
    assert main(["fmu", "check", str(path), "--step-size", "0.01"]) == 1
    assert "does not resolve the speed ripple of 8 Hz" in capsys.readouterr().err


def test_fmu_ripple_equals_the_coupling_kits_sidebands():
    """Two independent implementations: the FMU's time-domain ripple (the rotor's speed rippled step by step,
    modes on, steady start) and rwadist.extended_ripple.ripple_lines (closed-form sideband coefficients through the
    rotor's modes, used by the coupling kit) agree on every line's sidebands in Fx, Fy, Fz to 1e-4 of the
    channel's largest line, at +1700 and −2000 rpm, with counter-rotating lines and a speed law q = 0.5.
    (Tx, Ty are left out: ripple_lines neglects the ripple's modulation of the gyroscopic rocking, 8-12 % of
    the largest Tx/Ty line here, at sidebands near the rocking whirl.)"""
    from dataclasses import replace

    from rwadist import extended as ext
    from rwadist.extended_ripple import ripple_from_effects, ripple_lines
    m = preset("ithaco-e").to_model()
    rip_e = dict(RIPPLE, f_ripple_Hz=2.3, delta_omega_rad_s=3.0, speed_exponent=0.5)
    m.effects = [rip_e]
    doc = doc_with([rip_e], m)
    pe = ext.params_from_model(m)
    lines = [ln for ln in ext.lines_from_model(m, pe) if not ln.imbalance]   # imbalance: tangential term
    rip = ripple_from_effects(m.effects)
    h, T = 5e-4, 24.0
    t = np.arange(int(T / h) + 1) * h
    sel = t >= 8.0                             # the start transient of the modes decays
    for rpm in (1700.0, -2000.0):
        om = rpm * 2 * np.pi / 60
        # the FMU's rotor angle is 0 at t0; ripple_lines' mean angle is: shift each line's phase by hΔΩ/(2πf_r)
        d = float(rip.delta(om)) / (2 * np.pi * rip.f_hz)
        shifted = [replace(ln, phase=ln.phase + ln.h * d) for ln in lines]
        _, f, A = ripple_lines(pe, shifted, [om], rip)
        f, A = f[0].ravel(), A[0].reshape(-1, 6)
        fu, idx = np.unique(np.round(f, 9), return_inverse=True)
        pred = np.zeros((fu.size, 6), complex)
        np.add.at(pred, idx, A)
        keep = np.abs(pred).max(1) > 1e-6 * np.abs(pred).max()
        fu, pred = fu[keep], pred[keep]
        out = runtime(doc, imbalance=False, start_steady=True).run(t, np.full(t.size, om))
        E = np.exp(2j * np.pi * fu[None, :] * t[sel, None])
        coef = np.linalg.lstsq(np.hstack([E.real, -E.imag]), out[sel], rcond=None)[0]
        fit = coef[:fu.size] + 1j * coef[fu.size:]
        err = np.abs(fit - pred)[:, :5].max(0) / np.abs(pred)[:, :5].max(0)    # (Tz: no line of this model)
        assert np.all(err[:3] < 1e-4), (rpm, err)
        print(f"\n{rpm} rpm: {fu.size} line frequencies, FMU vs ripple_lines per channel {np.array2string(err, precision=1)}")


def test_a_wheel_mode_keeping_load_above_is_refused_saying_what_to_do():
    """A wheel_mode resonance with gain_above < 1 (diagnose writes it for a mode holding a share of the load; the FMU's
    filter returns to 1 above): the build is refused naming the resonance and the way on (trial26's rattle model,
    where `rwadist psd` runs); the same resonance returning to 1 above is taken."""
    mode = {"kind": "fixed_resonance", "f_Hz": 404.0, "zeta": 0.1, "peak_gain": 5.8, "role": "wheel_mode",
            "directions": ["axial_force"]}
    with pytest.raises(rt.ModelError, match=r"404 Hz keeps gain_above 0.6.*remove that effect from a copy"):
        build_fmu(doc_with([dict(mode, gain_above=0.6)]), "/nonexistent/x.fmu")
    assert rt.effects_from_doc(doc_with([mode]))["resonances"] == [(("axial_force",), 404.0, 0.1, 5.8)]
