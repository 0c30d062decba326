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

from fmu import hosts, runtime as rt
from fmu.build import build_fmu
from rwadist import model as model_io
from rwadist.presets import preset

from test_fmu import NATIVE_ONLY, kernel, slope, spin_up  # noqa: F401  (kernel: a fixture)

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
        a = runtime(doc, seed=seed).run(t, w)
        wr = rippled_speed(t, w, e, theta)
        b = runtime(plain, seed=seed).run(t, wr)
        assert np.all(worst_rel(a, b) < 1e-10), worst_rel(a, b)
        c = runtime(doc, seed=seed, speed_ripple=False).run(t, w)
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
        a = runtime(doc, seed=4, **kw)
        b = runtime(doc, seed=4, kernel=kernel, **kw)
        assert b.native and not a.native
        ya = np.array([a.step12(w[n], acc[n], h) for n in range(t.size - 1)])
        yb = np.array([b.step12(w[n], acc[n], h) for n in range(t.size - 1)])
        scale = np.max(np.abs(ya), axis=0)
        assert np.all(np.abs(yb - ya) <= 1e-12 * scale), np.max(np.abs(yb - ya), axis=0) / scale


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


def test_floor_resolution_is_checked():
    doc = doc_with([FLOOR])
    with pytest.raises(rt.ModelError, match="floor_resolution"):
        runtime(doc, floor_resolution=0.0)
    with pytest.raises(rt.ModelError, match="coarser floor_resolution"):
        runtime(doc, floor_resolution=1e-4)
