#!/usr/bin/env python3
"""Independent physics generator (numpy only): a rigid rotor on a linear suspension, hard-mounted on a 6-axis load cell
at the rotor's centre; four wheels, cases of contamination a lab records.

Written in session 51 by a helper trying rwadist as a new user, from the physics alone (nothing of rwadist, its tests
or its other generators read or imported): a fourth generator beside tests/family_wheel.py, ROSS and
benchmarks/newuser_generator.py.  Radial translation m u'' + c u' + k u = F, rocking I_rr φ'' − j I_zz Ω φ' + c_r φ'
+ k_r φ = M, axial m z'' + c_a z' + k_a z = Fz; the cell reads the suspension's reaction (k + jωc)·displacement; lines
C·Ω² (imbalances at h 1, bearing-like 0.41 / 3.63 / 5.37 / 7.26), white noise 1 % of each channel's median run RMS.

usage: newuser_generator_s51.py WHEEL CASE OUTDIR [--seed N]      # then: rwadist diagnose OUTDIR -o REPORT
  WHEEL: W1 (5 kg, I_zz/I_rr 1.6, 150/80/250 Hz, 600-6000 rpm, 4 kHz), W2 (12 kg, 2.0, 300/60/120 Hz, 300-3000 rpm,
  2.5 kHz), W3 (3 kg, 1.25, 450/200/580 Hz, 1000-10000 rpm, 8 kHz), W4 (8 kg, 1.85, 520/330/90 Hz, 500-6000 rpm, 5 kHz)
  CASE: clean | fixture | fixture_counter | onechan_res | tx_res | gain_step | nonlinear | hump | speed_offset | am |
        mains | clip | clip_adc         (the truth beside OUTDIR as OUTDIR.truth.json)

Record (2026-12-05, session 51; 96 data sets, seeds 1-3, each diagnosed by the command a user types with no model;
main 91b937a against the session's tree): suspension modes within 0.12 % or declared in every case but the
nonlinear ones (both trees).  Fixture (8/8), fixture + 25 % counter-rotation (8/8), mains (4/4), ADC clipping and
amplitude modulation as before.  A resonance of ONE channel (Fy, or Tx; ζ 0.03, gain 5): main named a wheel mode on
both channels of the pair in 10 of 16 (gain 3.6, its model 3.6x on the untouched channel), read a channel skew in 2
and said nothing in 4; now 16/16 described (``line_property`` ``channel_resonance``, f_r within 0.3 %, ζ 0.03, gain
4.99-5) and no wheel mode.  Runs from the median speed up 1.5 % faster than their column: main left 1-4 runs each
unmoved (their axial 1x read pulled off), 25-250x the clean error, nothing said; now every such run moved, errors at
the clean level in 8/8.  False humps: main described a hump on clean W3 (a line 95 dB over the floor on the 580 Hz
axial mode: its Welch skirt past the model's kernel, both seeds) and in 16 cases of other kinds (13 of them W3's);
now none but in the clipping cases (3, was 2).  A hump
growing as Ω⁶: main "excited by the surroundings at every speed"; now "rung by the wheel's own broadband loads",
|Ω|^5.9-6.2.  Left: a quadratic channel nonlinearity loses the axial mode (W3 names a 532 Hz wheel mode on 3/3
seeds; its sum and difference lines are now named combinations of 3.63 and 0.41); an Fx gain step is described but a
law stays on W3; clipping before the noise gives phantom fixed lines; on W4 a Tx resonance also reads as a x1.11 gain
step; the growing hump's fixed line at 127.6 Hz on W1.
"""
import json
import os
import sys

import numpy as np

TWO_PI = 2 * np.pi

WHEELS = {
    # mass kg, I_rr kg m^2, ratio I_zz/I_rr, modes Hz (translation, rocking at 0 rpm, axial), zetas, top rpm, fs
    "W1": dict(m=5.0, I_rr=0.010, ratio=1.6, f_t=150.0, f_rock=80.0, f_a=250.0,
               z_t=0.03, z_rock=0.02, z_a=0.03, top_rpm=6000, min_rpm=600, n=40, fs=4000.0,
               U_s=4e-6, U_d=2.5e-7),
    "W2": dict(m=12.0, I_rr=0.060, ratio=2.0, f_t=300.0, f_rock=60.0, f_a=120.0,
               z_t=0.02, z_rock=0.03, z_a=0.02, top_rpm=3000, min_rpm=300, n=36, fs=2500.0,
               U_s=1.2e-5, U_d=1.5e-6),
    "W3": dict(m=3.0, I_rr=0.004, ratio=1.25, f_t=450.0, f_rock=200.0, f_a=580.0,
               z_t=0.04, z_rock=0.03, z_a=0.025, top_rpm=10000, min_rpm=1000, n=45, fs=8000.0,
               U_s=2e-6, U_d=8e-8),
    "W4": dict(m=8.0, I_rr=0.020, ratio=1.85, f_t=520.0, f_rock=330.0, f_a=90.0,
               z_t=0.025, z_rock=0.02, z_a=0.03, top_rpm=6000, min_rpm=500, n=50, fs=5000.0,
               U_s=6e-6, U_d=4e-7),
}

# bearing-like lines: (direction, h, C as a fraction of U_s (force) or U_d (torque)); C*Omega^2, co-rotating
BEARING = [
    ("radial_force", 0.41, 0.15), ("radial_force", 3.63, 0.20), ("radial_force", 5.37, 0.10),
    ("radial_force", 7.26, 0.06),
    ("radial_torque", 3.63, 0.25), ("radial_torque", 5.37, 0.15),
    ("axial_force", 0.41, 0.10), ("axial_force", 3.63, 0.30), ("axial_force", 7.26, 0.12),
]


def resonance(fr, zeta, g):
    """H(f) = (1 - r^2 + 2j g zeta r)/(1 - r^2 + 2j zeta r); signed f -> conjugate symmetry."""
    def H(f):
        f = np.asarray(f, float)
        r = np.abs(f) / fr
        h = (1 - r**2 + 2j * g * zeta * r) / (1 - r**2 + 2j * zeta * r)
        return np.where(f < 0, np.conj(h), h)
    return H


def main():
    wheel, case, out = sys.argv[1], sys.argv[2], sys.argv[3]
    seed = int(sys.argv[sys.argv.index("--seed") + 1]) if "--seed" in sys.argv else 1
    rng = np.random.default_rng(seed)
    P = dict(WHEELS[wheel])
    m, I_rr = P["m"], P["I_rr"]
    I_zz = P["ratio"] * I_rr
    k = m * (TWO_PI * P["f_t"]) ** 2
    c = 2 * P["z_t"] * np.sqrt(k * m)
    kr = I_rr * (TWO_PI * P["f_rock"]) ** 2
    cr = 2 * P["z_rock"] * np.sqrt(kr * I_rr)
    ka = m * (TWO_PI * P["f_a"]) ** 2
    ca = 2 * P["z_a"] * np.sqrt(ka * m)
    fs, N = P["fs"], 8192
    t = np.arange(N) / fs
    speeds = np.linspace(P["min_rpm"], P["top_rpm"], P["n"])

    lines = [dict(direction="radial_force", h=1.0, C=P["U_s"], sense="co", what="static imbalance"),
             dict(direction="radial_torque", h=1.0, C=P["U_d"], sense="co", what="dynamic imbalance")]
    for d, h, frac in BEARING:
        base = P["U_d"] if d == "radial_torque" else P["U_s"]
        lines.append(dict(direction=d, h=h, C=frac * base, sense="co" if d != "axial_force" else None,
                          what="bearing-like"))
    effects = []
    fix = None
    if case in ("fixture", "fixture_counter"):
        mult = {"W1": 1.5, "W2": 0.5, "W3": 1.0, "W4": 0.5}[wheel]
        which = {"W1": "f_t", "W2": "f_a", "W3": "f_rock", "W4": "f_t"}[wheel]
        f_fix = mult * P[which]
        fix = resonance(f_fix, 0.03, 5.0)
        effects.append(dict(kind="test_stand_resonance", f_Hz=f_fix, zeta=0.03, peak_gain=5.0,
                            channels="all", note=f"{mult} x {which}"))
    if case == "fixture_counter":
        lines.append(dict(direction="radial_force", h=1.0, C=0.25 * P["U_s"], sense="counter",
                          what="25% counter-rotating part of the radial-force fundamental"))
        effects.append(dict(kind="counter_rotation", direction="radial_force", h=1.0, fraction=0.25))
    chan_filter = {}
    if case == "tx_res":
        f_s = {"W1": 230.0, "W2": 150.0, "W3": 500.0, "W4": 380.0}[wheel]
        chan_filter["Tx"] = resonance(f_s, 0.03, 5.0)
        effects.append(dict(kind="own:single_channel_sensor_resonance", channel="Tx", f_Hz=f_s,
                            zeta=0.03, peak_gain=5.0,
                            signature="Tx lines (only Tx) amplified near f_Hz at every speed; Ty untouched"))
    if case == "speed_offset":
        effects.append(dict(kind="own:speed_label_error", factor=1.015,
                            signature="runs from the median speed up ran 1.5 % faster than runs.csv says "
                                      "(every line of those runs at h*1.015 of the labelled speed)"))
    if case == "onechan_res":
        f_s = {"W1": 200.0, "W2": 180.0, "W3": 700.0, "W4": 260.0}[wheel]
        chan_filter["Fy"] = resonance(f_s, 0.03, 5.0)
        effects.append(dict(kind="own:single_channel_sensor_resonance", channel="Fy", f_Hz=f_s,
                            zeta=0.03, peak_gain=5.0,
                            signature="Fy lines (only Fy) amplified near f_Hz at every speed; Fx untouched"))
    phases = {id(L): rng.uniform(0, TWO_PI) for L in lines}

    def Tt(w):
        return (k + 1j * w * c) / (k - m * w**2 + 1j * w * c)

    def Tr(w, W):
        return (kr + 1j * w * cr) / (kr - I_rr * w**2 + I_zz * W * w + 1j * w * cr)

    def Ta(w):
        return (ka + 1j * w * ca) / (ka - m * w**2 + 1j * w * ca)

    sig = []
    for rpm in speeds:
        W = rpm * TWO_PI / 60
        if case == "speed_offset" and rpm >= np.median(speeds):
            W *= 1.015
        ch = {n: np.zeros(N) for n in ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"]}
        for L in lines:
            F = L["C"] * W**2
            ph = phases[id(L)]
            if L["direction"] == "axial_force":
                w = L["h"] * W
                A = F * Ta(w) * np.exp(1j * ph)
                if fix: A = A * fix(w / TWO_PI)
                if "Fz" in chan_filter: A = A * chan_filter["Fz"](w / TWO_PI)
                ch["Fz"] += np.real(A * np.exp(1j * w * t))
                continue
            s = 1 if L["sense"] == "co" else -1
            w = s * L["h"] * W
            if L["direction"] == "radial_force":
                A = F * Tt(w) * np.exp(1j * ph); cx, cy = "Fx", "Fy"
            else:
                A = F * Tr(w, W) * np.exp(1j * ph); cx, cy = "Tx", "Ty"
            if fix: A = A * fix(w / TWO_PI)
            z = np.exp(1j * w * t)
            if case == "am" and L["what"] == "static imbalance":
                z = z * (1 + 0.3 * np.sin(TWO_PI * 2.0 * t))
            Ax = A * chan_filter[cx](w / TWO_PI) if cx in chan_filter else A
            Ay = A * chan_filter[cy](w / TWO_PI) if cy in chan_filter else A
            ch[cx] += np.real(Ax * z)
            ch[cy] += np.imag(Ay * z)
        sig.append(ch)

    # own effects acting on the measured signal
    if case == "gain_step":
        g = 1.5
        half = speeds >= np.median(speeds)
        for i in np.where(half)[0]:
            sig[i]["Fx"] *= g
        effects.append(dict(kind="own:channel_gain_step", channel="Fx", gain=g,
                            from_rpm=float(speeds[half].min()),
                            signature="Fx alone reads 1.5x (3.5 dB) in every run from from_rpm up "
                                      "(amplifier range switched halfway through a test recorded in speed order)"))
    if case == "nonlinear":
        # quadratic load-cell nonlinearity on Fz: Fz_meas = Fz + beta Fz^2
        ref = max(np.max(np.abs(s["Fz"])) for s in sig)
        beta = 0.15 / ref
        for s in sig:
            s["Fz"] = s["Fz"] + beta * s["Fz"] ** 2
        effects.append(dict(kind="own:quadratic_channel_nonlinearity", channel="Fz", beta_per_N=beta,
                            signature="Fz only: lines at sums/differences/doubles of the Fz lines' h "
                                      "(0.82, 3.22, 4.04, 6.85, 7.26+.., 7.26, 7.67, 10.89, 11.3, 14.52, 3.63 "
                                      "double 7.26 coincides with a real line) growing as Omega^4; 15% at top speed"))
    if case == "hump":
        f0 = {"W1": 120.0, "W2": 200.0, "W3": 300.0, "W4": 200.0}[wheel]
        bw = 0.1 * f0
        ref = np.median([np.std(s["Fx"]) for s in sig])
        for i, rpm in enumerate(speeds):
            amp = 0.3 * ref * (rpm / P["top_rpm"]) ** 3
            for cn in ("Fx", "Fy", "Fz"):
                x = rng.standard_normal(N)
                X = np.fft.rfft(x)
                f = np.fft.rfftfreq(N, 1 / fs)
                X *= np.exp(-0.5 * ((f - f0) / bw) ** 2)
                y = np.fft.irfft(X, N)
                sig[i][cn] += amp * y / np.std(y)
        effects.append(dict(kind="own:speed_dependent_broadband_hump", channels=["Fx", "Fy", "Fz"], f0_Hz=f0,
                            sigma_Hz=bw, rms_law="0.3*median Fx rms*(rpm/top)^3",
                            signature="Gaussian-shaped noise hump at fixed f0 growing with speed on the forces"))

    if case == "am":
        effects.append(dict(kind="own:amplitude_modulated_line", direction="radial_force", h=1.0, f_mod_Hz=2.0,
                            depth=0.3, signature="static imbalance line modulated 1+0.3 sin(2 pi 2Hz t): sidebands at 1x +/- 2 Hz"))
    if case == "mains":
        for cn in ("Fz", "Ty"):
            ref = np.median([np.std(s[cn]) for s in sig])
            for n_, a in ((1, 0.05), (2, 0.02), (3, 0.03), (5, 0.015)):
                ph = rng.uniform(0, TWO_PI)
                for s in sig:
                    s[cn] += a * ref * np.sqrt(2) * np.cos(TWO_PI * 50 * n_ * t + ph)
        effects.append(dict(kind="own:mains_pickup", channels=["Fz", "Ty"], f_Hz=[50, 100, 150, 250],
                            signature="fixed lines at 50 Hz multiples in Fz and Ty in every run"))
    if case in ("clip", "clip_adc"):
        lim = 0.5 * max(np.max(np.abs(s["Fy"])) for s in sig)
        nclip = 0
        for s in sig:
            if np.max(np.abs(s["Fy"])) > lim: nclip += 1
            if case == "clip":
                s["Fy"] = np.clip(s["Fy"], -lim, lim)
        effects.append(dict(kind="own:clipping", channel="Fy", limit=lim, runs_clipped=nclip,
                            signature="Fy clipped at +/- limit in the loudest runs (case clip: before the sensor noise, an amplifier stage; clip_adc: after it, the ADC)"))
    # sensor noise: white, 1 % of each channel's median run RMS (torques share one level for Tz)
    names = ["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"]
    rms = {n: np.median([np.std(s[n]) for s in sig]) for n in names}
    rms["Tz"] = rms["Tx"]
    noise = {n: 0.01 * rms[n] for n in names}
    os.makedirs(out, exist_ok=True)
    rows = ["file,speed_rpm"]
    for i, (rpm, s) in enumerate(zip(speeds, sig)):
        fn = f"run_{i:04d}.csv"
        data = np.column_stack([t] + [s[n] + noise[n] * rng.standard_normal(N) for n in names])
        if case == "clip_adc":  # the ADC clips the measured (noisy) Fy at +/- lim
            data[:, 2] = np.clip(data[:, 2], -lim, lim)
        np.savetxt(os.path.join(out, fn), data, delimiter=",", fmt="%.10g",
                   header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm", comments="")
        rows.append(f"{fn},{rpm:.6f}")
    open(os.path.join(out, "runs.csv"), "w").write("\n".join(rows) + "\n")
    json.dump({"sample_rate_hz": fs}, open(os.path.join(out, "meta.json"), "w"))
    truth = dict(wheel=wheel, case=case, seed=seed, mass_kg=m, I_rr=I_rr, I_zz=I_zz, ratio=P["ratio"],
                 modes_Hz=dict(translation=P["f_t"], rocking_at_0rpm=P["f_rock"], axial=P["f_a"]),
                 zeta=dict(translation=P["z_t"], rocking=P["z_rock"], axial=P["z_a"]),
                 k_r=k, k_rock=kr, k_z=ka, c_r=c, c_rock=cr, c_z=ca,
                 speeds_rpm=[float(x) for x in speeds], fs=fs, N=N, noise=noise,
                 lines=[{kk: v for kk, v in L.items()} for L in lines], effects=effects,
                 command=" ".join(sys.argv))
    json.dump(truth, open(out.rstrip("/") + ".truth.json", "w"), indent=1)


if __name__ == "__main__":
    main()
