"""Issue 7, item 3 end to end: effects diagnosed from data whose effects nobody declared flow through the
model file into the FMU's time-domain output, checked against the injected truth (not against the
diagnosed numbers): a broadband floor and a wheel-speed ripple."""
from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal
from test_diagnose import C1, FS, SPEEDS, TRUTH, e_data, inject_floor, spectra
from test_diagnose_modulation import RIPPLE, rippled_data
from test_fmu_effects import ripple_coefficients_p2

from rwadist import model as model_io
from rwadist.diagnose import diagnose
from rwadist.fmu import runtime as rt

pytest.importorskip("pythonfmu")


def improved_runtime(d, **kw):
    """The FMU runtime of a diagnosed model, read back from its model-file JSON."""
    doc = json.loads(json.dumps(model_io.to_json(d.model)))
    params, lines = rt.model_from_doc(doc)
    return rt.WheelRuntime(params, lines, **rt.effects_from_doc(doc), **kw)


def test_diagnosed_floor_reaches_the_fmu_output():
    """Floor ∝ Ω³ (2nd-order low-pass at 60 Hz) injected on Fx, Fy, Fz; diagnosed; the FMU of the improved
    model (lines off) at 1500 rpm puts out, on each of those channels, a PSD within 25 % of the injected
    floor's PSD in every 20-Hz band from 10 to 210 Hz (diagnose analyses from 4 bins = 7.5 Hz up), and
    nothing on the torque channels."""
    test = e_data(0)
    wmax = np.abs(SPEEDS).max() * 2 * np.pi / 60
    ref = FLOOR = 0.2 * C1 * wmax**2
    inject_floor(test, ("Fx", "Fy", "Fz"), {c: FLOOR for c in ("Fx", "Fy", "Fz")}, p=3.0, fc=60.0, fs=FS, seed=0)
    d = diagnose(spectra(test), TRUTH)
    assert {e["kind"] for e in d.model.effects} == {"broadband_floor"}
    w0 = 1500 * 2 * np.pi / 60
    dt = 1.0 / FS
    t = np.arange(int(20 * FS) + 1) * dt
    out = improved_runtime(d, seed=2, imbalance=False, harmonics=False, modes=False).run(t, np.full(t.size, w0))
    b, a = signal.butter(2, 60.0, fs=FS)
    f, H = signal.freqz(b, a, worN=8192, fs=FS)
    shape = np.abs(H) ** 2 / np.trapezoid(np.abs(H) ** 2, f)          # unit-variance low-passed noise, 1/Hz
    worst = 0.0
    for c in (0, 1, 2):
        fw, P = signal.welch(out[1:, c], fs=FS, nperseg=2048)
        truth = ref**2 * (w0 / wmax) ** 3 * np.interp(fw, f, shape)
        for lo in np.arange(10.0, 210.0, 20.0):
            band = (fw > lo) & (fw <= lo + 20.0)
            worst = max(worst, abs(P[band].mean() / truth[band].mean() - 1))
    assert worst < 0.25, worst
    assert np.all(out[:, 3:] == 0.0)
    print(f"\nFMU floor of the diagnosed model vs the injected floor, worst 20-Hz band: {worst:.3f}")


def test_diagnosed_ripple_reaches_the_fmu_output():
    """Speed rippled ±3 rad/s at 8 Hz in the data; diagnosed; the FMU of the improved model (modes off, fed the
    constant mean speed) puts the ripple's sidebands on the radial-force lines: the first-order sideband
    amplitudes of every harmonic h = 2 … 5.57 (h = 2 counter-rotating: at −2Ω + k·2πf_r) at 1500 rpm,
    relative to their carrier, are within 8 % of the closed form of the injected ripple (Bessel phase
    modulation with the amplitude term, p = 2; the diagnosed ΔΩ is ~3 % low).  Not h = 1: there the FMU
    also has the imbalance's tangential force −iU·dΩ/dt, of relative size ΔΩ·2πf_r/Ω² = 0.6 %, comparable
    to its small lower sideband (β/2 − ε ≈ 1 %), which the synthetic data leave out."""
    d = diagnose(spectra(rippled_data(0, **RIPPLE)), TRUTH)
    assert [e["kind"] for e in d.model.effects] == ["speed_ripple"]
    w0 = 1500 * 2 * np.pi / 60
    dt = 1e-4
    t = np.arange(20001) * dt
    out = improved_runtime(d, seed=1, modes=False).run(t, np.full(t.size, w0))
    F = out[:, 0] + 1j * out[:, 1]
    wr = 2 * np.pi * RIPPLE["f_ripple"]
    hs = [(h.h, -1.0 if h.sense == "counter" else 1.0) for h in TRUTH.harmonics("radial_force")]
    k = np.arange(-2, 3)
    freqs = np.array([s * h * w0 + kk * wr for h, s in hs for kk in k])
    coef, *_ = np.linalg.lstsq(np.exp(1j * np.outer(t, freqs)), F, rcond=None)
    coef = np.abs(coef).reshape(len(hs), k.size)
    worst = 0.0
    for i, (h, s) in enumerate(hs):
        if h == 1.0:
            continue
        c = ripple_coefficients_p2(s * h * RIPPLE["delta_omega"] / wr, RIPPLE["delta_omega"] / w0, k)
        for j in (1, 3):                                  # k = −1, +1
            got, want = coef[i, j] / coef[i, 2], c[j] / c[2]
            worst = max(worst, abs(got / want - 1))
    assert worst < 0.08, worst
    print(f"\nFMU ripple sidebands of the diagnosed model vs the injected ripple's closed form, worst: {worst:.3f}")


def test_diagnosed_floor_reaches_the_coupling_kit():
    """The same diagnosed floor read by ``coupling.wheel_spec_from_model``: the blocked-load PSD of each
    floored channel at 1500 rpm is within 25 % of the injected floor's in every 20-Hz band from 10 to 210 Hz;
    carried through a spacecraft (practice 'i', the blocked load on the bus), the line-of-sight mean square
    over 10-300 Hz is within 25 % of that of the injected floor through the same transfer."""
    from rwadist import coupling as cp

    test = e_data(1)
    wmax = np.abs(SPEEDS).max() * 2 * np.pi / 60
    ref = 0.2 * C1 * wmax**2
    inject_floor(test, ("Fx", "Fy", "Fz"), {c: ref for c in ("Fx", "Fy", "Fz")}, p=3.0, fc=60.0, fs=FS, seed=1)
    d = diagnose(spectra(test), TRUTH)
    improved = model_io.from_json(json.loads(json.dumps(model_io.to_json(d.model))))     # via the model file
    spec = cp.wheel_spec_from_model(improved, mount=cp.Mount(0, np.eye(3), (0.3, 0.2, 0.1)))
    assert sorted(fl.channel for fl in spec.floors) == [0, 1, 2]
    w0 = 1500 * 2 * np.pi / 60
    b, a = signal.butter(2, 60.0, fs=FS)
    f_f, H = signal.freqz(b, a, worN=8192, fs=FS)
    shape = np.abs(H) ** 2 / np.trapezoid(np.abs(H) ** 2, f_f)

    def truth(f):
        return ref**2 * (w0 / wmax) ** 3 * np.interp(f, f_f, shape)

    f = np.linspace(10.0, 210.0, 2001)
    worst = 0.0
    for c in (0, 1, 2):
        S = sum(fl.psd(f, np.array([w0]))[0] for fl in spec.floors if fl.channel == c)
        for lo in np.arange(10.0, 210.0, 20.0):
            band = (f >= lo) & (f < lo + 20.0)
            worst = max(worst, abs(S[band].mean() / truth(f[band]).mean() - 1))
    assert worst < 0.25, worst
    plant = cp.example_spacecraft()
    fg = np.geomspace(10.0, 300.0, 4000)
    fr = cp.floor_responses(plant, [spec], [w0], practices=("i",), f_hz=fg)
    G, P = plant.frf(fg)
    Mt = cp.geometry.selector(spec.mount, 6, plant.n_interface)
    T = P @ Mt.T[:, :3]                                 # wheel Fx, Fy, Fz (with their lever arm) -> LOS
    ms_truth = np.trapezoid(np.sum(np.abs(T) ** 2, axis=2) * truth(fg)[:, None], fg, axis=0)
    ratio = fr.ms["i"][0] / ms_truth
    assert np.all(np.abs(ratio - 1) < 0.25), ratio
    print(f"\ncoupling: diagnosed floor vs injected, worst 20-Hz band {worst:.3f}; LOS mean square ratio {ratio}")
