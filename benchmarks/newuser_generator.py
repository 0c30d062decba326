"""Independent reaction-wheel load-cell data generator (numpy only).

Rigid rotor on a linear suspension, hard-mounted on a 6-axis load cell whose
reference point is the rotor's centre (no lever arm).  Complex coordinates:
  radial translation u = x + j y :  m u'' + c u' + k u = F        (F = Fx + j Fy)
  rocking         phi = thx + j thy: I_rr phi'' - j I_zz W phi' + c_r phi' + k_r phi = M
  axial           z:                m z'' + c_a z' + k_a z = Fz
Interface load = suspension load: (k + j c w) * displacement.
A load rotating as e^{j s h W t} (s=+1 co-rotating, -1 counter) at frequency w = s h W.
Forward whirl: I_rr w^2 - I_zz W w - k_r = 0 (w>0 root) grows with speed.

Written in session 43 by a helper trying rwadist as a new user, from the physics alone (nothing of tests/ or of
rwadist imported): a third generator beside tests/family_wheel.py and ROSS.  Usage::

    python benchmarks/newuser_generator.py WHEEL VARIANT [SEED] [OUT_DIR]      # then: rwadist diagnose OUT_DIR/WHEEL_VARIANT
    WHEEL: w1 (4 kg, 180/90/250 Hz, 300-3000 rpm, 2 kHz), w2 (12 kg, 80/50/120 Hz), w3 (2.5 kg, 500/250/600 Hz,
    1000-10000 rpm, 8 kHz), w4 (7 kg, 300/140/400 Hz, 600-6000 rpm); the truth beside it as WHEEL_VARIANT.truth.json.

Record (2026-12-04, rwadist of branch s43 at fb28697-3766879, 62 diagnoses by the command a user types, 3.4-13.2 s each): every mode within
0.35 % but one (0.76 %, flagged); clean 8/8 nothing added; a fixture at 0.5/1.0/1.5x a mode 12/12 named (within
0.05 Hz); a 28 % counter-rotating 1x 8/8; 50 + 150 Hz pickup 8/8 described, nothing invented; Fy += 0.2 Fx 8/8
described.  Failing: a hump wider than ~1/8 of the band, the same in every run (humpconst, 4/4 wheels; w1 own, a
speed-dependent hump at 330 ± 70 Hz) is taken into the noise model and nothing is said ("Nothing" in report.md); impacts
in every third run (w4 own, 400-900 Hz, the waterfall plain) not described; impacts in every run described on w3, w4,
not on w1, w2; a line at 40 Hz + 0.5 f_spin (w3 own) read as a constant-ratio line, two fixed lines 'of the stand' and
a cage slipping 14 %; a line of random strength run to run (w2 own) described as a partial line covering 3-34 % of the
error left.

Record (2026-12-04, session 44, rwadist at e381cc0, the same 62 data sets, 3.1-9.2 s each): the four wide humps
described where they are on every channel (327-572 Hz for 450 ± 50 Hz ...), kurtosis 2.9-3.0, named a fixture or
sensor resonance; the speed-dependent hump (w1 own, both seeds) described on Fx Fy Fz at 207-465 Hz; impacts in every
run described on all four wheels (kurtosis 12-14, named impacts ringing at 350/357/1410/718 Hz); impacts in every third
run (w4 own, both seeds) described in 11 of the 32 runs at 206-1042 Hz, kurtosis 41-46, named impacts ringing at
692-700 Hz; the line at 40 Hz + 0.5 f_spin (w3 own, both seeds) one affine_line on Fz Tz, f0 39.98 Hz, slope
0.5001-0.5002, nothing else; clean, fixtures, counter-rotation, pickup and crosstalk as before.  Left: the line of
random strength (w2 own) is still a partial line.
"""
import json
import os
import sys

import numpy as np

TWO_PI = 2 * np.pi


def wheel_defs():
    W = {}
    # name: mass, Izz, ratio, f_t, f_r, f_a, zetas, speeds, n_speeds, fs, bearing (n, gamma), Us, Ud
    W["w1"] = dict(m=4.0, Izz=0.015, ratio=1.6, f_t=180.0, f_r=90.0, f_a=250.0,
                   z_t=0.02, z_r=0.015, z_a=0.025, rpm=(300, 3000), n=36, fs=2000.0,
                   balls=8, gamma=0.2, Us=4e-6, Ud=3e-7, seed=11)
    W["w2"] = dict(m=12.0, Izz=0.09, ratio=2.0, f_t=80.0, f_r=50.0, f_a=120.0,
                   z_t=0.015, z_r=0.02, z_a=0.02, rpm=(300, 3000), n=40, fs=2048.0,
                   balls=10, gamma=0.25, Us=1.2e-5, Ud=1.5e-6, seed=22)
    W["w3"] = dict(m=2.5, Izz=0.004, ratio=1.3, f_t=500.0, f_r=250.0, f_a=600.0,
                   z_t=0.025, z_r=0.02, z_a=0.03, rpm=(1000, 10000), n=40, fs=8000.0,
                   balls=7, gamma=0.18, Us=1.5e-6, Ud=6e-8, seed=33)
    W["w4"] = dict(m=7.0, Izz=0.03, ratio=1.8, f_t=300.0, f_r=140.0, f_a=400.0,
                   z_t=0.01, z_r=0.02, z_a=0.015, rpm=(600, 6000), n=32, fs=4096.0,
                   balls=9, gamma=0.22, Us=6e-6, Ud=4e-7, seed=44)
    return W


def lines_of(w):
    """(channel-group, h, C, sense).  group: 'rf' radial force, 'rt' radial torque, 'af' axial force."""
    n, g = w["balls"], w["gamma"]
    cage, bpfo, bpfi = 0.5 * (1 - g), n / 2 * (1 - g), n / 2 * (1 + g)
    Us, Ud = w["Us"], w["Ud"]
    L = [("rf", 1.0, Us, +1), ("rt", 1.0, Ud, +1),
         ("rf", 2.0, 0.10 * Us, +1),
         ("rf", cage, 0.15 * Us, +1),
         ("rf", bpfo, 0.25 * Us, +1), ("rf", bpfi, 0.12 * Us, +1), ("rf", 2 * bpfo, 0.06 * Us, +1),
         ("rt", bpfo, 0.20 * Ud, +1), ("rt", bpfi, 0.10 * Ud, +1),
         ("af", bpfo, 0.20 * Us, 0), ("af", bpfi, 0.15 * Us, 0), ("af", 2 * bpfi, 0.05 * Us, 0)]
    return L, dict(cage=cage, bpfo=bpfo, bpfi=bpfi)


def suspension(w):
    m, Izz = w["m"], w["Izz"]
    Irr = Izz / w["ratio"]
    k_t = m * (TWO_PI * w["f_t"]) ** 2
    c_t = 2 * w["z_t"] * np.sqrt(k_t * m)
    k_r = Irr * (TWO_PI * w["f_r"]) ** 2
    c_r = 2 * w["z_r"] * np.sqrt(k_r * Irr)
    k_a = m * (TWO_PI * w["f_a"]) ** 2
    c_a = 2 * w["z_a"] * np.sqrt(k_a * m)
    return dict(m=m, Izz=Izz, Irr=Irr, k_t=k_t, c_t=c_t, k_r=k_r, c_r=c_r, k_a=k_a, c_a=c_a)


def trans_radial(s, w_sig):
    """interface force per applied force, w_sig signed whirl frequency rad/s."""
    return (s["k_t"] + 1j * s["c_t"] * w_sig) / (s["k_t"] - s["m"] * w_sig ** 2 + 1j * s["c_t"] * w_sig)


def trans_rock(s, w_sig, Om):
    return (s["k_r"] + 1j * s["c_r"] * w_sig) / (
        s["k_r"] - s["Irr"] * w_sig ** 2 + s["Izz"] * Om * w_sig + 1j * s["c_r"] * w_sig)


def trans_axial(s, w_pos):
    return (s["k_a"] + 1j * s["c_a"] * w_pos) / (s["k_a"] - s["m"] * w_pos ** 2 + 1j * s["c_a"] * w_pos)


def whirl_Hz(s, Om):
    a, b, c = s["Irr"], -s["Izz"] * Om, -s["k_r"]
    d = np.sqrt(b * b - 4 * a * c)
    return (-b + d) / (2 * a) / TWO_PI, (-b - d) / (2 * a) / TWO_PI  # forward (+), backward (-)


def fixture_gain(f, f0, zeta=0.03):
    r = f / f0
    return 1.0 / (1 - r ** 2 + 2j * zeta * r)


def make(wname, variant, out, n_samples=8192):
    W = wheel_defs()[wname]
    rng = np.random.default_rng(W["seed"] * 100 + hash(variant) % 97)
    rng = np.random.default_rng([W["seed"], sum(map(ord, variant))] + ([SEED] if SEED else []))
    s = suspension(W)
    L, bear = lines_of(W)
    fs = W["fs"]
    t = np.arange(n_samples) / fs
    rpms = np.linspace(*W["rpm"], W["n"])
    truth = dict(wheel=wname, variant=variant, params=W, bearing_ratios=bear,
                 modes=dict(radial_translation_Hz=W["f_t"], rocking_Hz=W["f_r"], axial_Hz=W["f_a"],
                            inertia_ratio=W["ratio"]),
                 lines=[dict(group=g, h=h, C=C, sense=sn) for g, h, C, sn in L], contaminant=None)
    # fixture definition
    if variant == "fixture1x":
        pass
    fix = {"w1": 1.5 * W["f_t"], "w2": 0.5 * W["f_t"], "w3": 1.0 * W["f_r"], "w4": 1.5 * W["f_a"]}[wname]
    if variant == "fixture1x":
        fix = W["f_t"]
        truth["contaminant"] = dict(kind="fixed_resonance(test stand)", f_Hz=fix, zeta=0.03, channels="all", where="1.0 x f_t")
    if variant == "fixture":
        truth["contaminant"] = dict(kind="fixed_resonance(test stand)", f_Hz=fix, zeta=0.03, channels="all",
                                    where={"w1": "1.5 x f_t", "w2": "0.5 x f_t", "w3": "1.0 x f_r", "w4": "1.5 x f_a"}[wname])
    q_counter = 0.28
    if variant == "counter":
        truth["contaminant"] = dict(kind="counter_rotation", fraction=q_counter, on="1x radial force")
    # clean signals first (complex amplitudes per channel)
    sigs = []
    for irun, rpm in enumerate(rpms):
        Om = rpm * TWO_PI / 60
        X = np.zeros((6, n_samples))
        for g, h, C, sn in L:
            A = C * Om ** 2
            wl = h * Om
            ph = rng.uniform(0, TWO_PI)
            if g == "rf":
                loads = [(A, sn)]
                if variant == "counter" and h == 1.0:
                    loads.append((q_counter * A, -1))
                for Aa, ss in loads:
                    T = trans_radial(s, ss * wl)
                    if variant.startswith("fixture"):
                        T = T * fixture_gain(wl / TWO_PI, fix)
                    ph2 = ph if ss == sn else rng.uniform(0, TWO_PI)
                    # u = Aa*T*e^{j(ss*wl*t+ph)} ; Fx=Re u, Fy=Im u
                    u = Aa * T * np.exp(1j * (ss * wl * t + ph2))
                    X[0] += u.real
                    X[1] += u.imag
            elif g == "rt":
                T = trans_rock(s, sn * wl, Om)
                if variant.startswith("fixture"):
                    T = T * fixture_gain(wl / TWO_PI, fix)
                u = A * T * np.exp(1j * (sn * wl * t + ph))
                X[3] += u.real
                X[4] += u.imag
            elif g == "af":
                T = trans_axial(s, wl)
                if variant.startswith("fixture"):
                    T = T * fixture_gain(wl / TWO_PI, fix)
                X[2] += np.abs(A * T) * np.cos(wl * t + ph + np.angle(T))
        sigs.append(X)
    # noise level per channel: 1 % of the channel's largest line (median over runs), from std of the signal
    amp = np.array([[np.sqrt(2) * X[c].std() for c in range(6)] for X in sigs])  # rough peak of largest line
    med = np.median(amp, axis=0)
    med[5] = med[3]  # Tz has no lines: torque-sensor noise like Tx
    sigma = 0.01 * med
    truth["noise_sigma"] = sigma.tolist()
    out_runs = []
    for irun, (rpm, X) in enumerate(zip(rpms, sigs)):
        Om = rpm * TWO_PI / 60
        if variant == "pickup":
            for c in range(6):
                X[c] += 0.05 * med[c] * np.cos(TWO_PI * 50 * t + rng.uniform(0, TWO_PI))
                X[c] += 0.02 * med[c] * np.cos(TWO_PI * 150 * t + rng.uniform(0, TWO_PI))
        if variant == "own":
            own(wname, W, s, X, t, Om, rng, med, irun, truth)
        if variant in ("humpconst", "humpnarrow"):
            f0 = 0.45 * W["fs"] / 2; bw = 0.05 * W["fs"] / 2
            if variant == "humpnarrow":
                bw = 0.015 * W["fs"] / 2
            F = np.fft.rfftfreq(len(t), t[1] - t[0])
            for c in range(6):
                spec = (rng.standard_normal(len(F)) + 1j * rng.standard_normal(len(F))) * np.exp(-0.5 * ((F - f0) / bw) ** 2)
                x = np.fft.irfft(spec, len(t)); X[c] += x / x.std() * 0.04 * med[c if c != 5 else 3]
            truth["contaminant"] = dict(kind=f"broadband hump gaussian {f0:.0f} Hz +-{bw:.0f} Hz, constant rms 4% of median largest line, all channels, all runs")
        if variant == "rattleall":
            n = len(t); imp = np.zeros(n); k = rng.poisson(20 * t[-1]); idx = rng.integers(0, n, k); imp[idx] = rng.normal(0, 1, k)
            tau = np.arange(int(0.02 * W["fs"])) / W["fs"]; fr = 0.35 * W["fs"] / 2
            x = np.convolve(imp, np.exp(-tau / 0.004) * np.sin(TWO_PI * fr * tau))[:n]; x /= x.std() + 1e-30
            for c in (0, 1, 3, 4): X[c] += 0.05 * med[c] * x
            truth["contaminant"] = dict(kind=f"rattle in every run: decaying {fr:.0f} Hz impacts ~20/s on Fx Fy Tx Ty, rms 5% of median largest line")
        X = X + sigma[:, None] * rng.standard_normal(X.shape)
        if variant == "crosstalk":
            X[1] = X[1] + 0.20 * X[0]
        out_runs.append(X)
    if variant == "pickup":
        truth["contaminant"] = dict(kind="fixed lines 50 Hz (5%) + 150 Hz (2%) of channel median largest line, all channels, all runs")
    if variant == "crosstalk":
        truth["contaminant"] = dict(kind="channel_copy: Fy += 0.20*Fx (after noise)")
    write(out, rpms, t, out_runs, truth, fs)


def own(wname, W, s, X, t, Om, rng, med, irun, truth):
    fspin = Om / TWO_PI
    if wname == "w1":
        # broadband hump: band-limited noise centred 330 Hz, Q ~ 5, amplitude grows with speed^2, radial forces + Fz
        f0, bw = 330.0, 70.0
        n = len(t)
        F = np.fft.rfftfreq(n, t[1] - t[0])
        for c in (0, 1, 2):
            spec = (rng.standard_normal(len(F)) + 1j * rng.standard_normal(len(F))) * np.exp(-0.5 * ((F - f0) / bw) ** 2)
            x = np.fft.irfft(spec, n)
            x = x / x.std() * 0.04 * med[c] * (fspin / 50.0) ** 2
            X[c] += x
        truth["contaminant"] = dict(kind="broadband hump (gaussian band 330 Hz +-70 Hz) on Fx Fy Fz, rms 4% of median largest line x (f_spin/50Hz)^2")
    elif wname == "w2":
        # a line at h=2.3 on radial force (co-rotating) whose amplitude varies randomly run to run (lognormal sigma 8 dB)
        h = 2.3
        A = 0.15 * W["Us"] * Om ** 2 * 10 ** (rng.normal(0, 8) / 20)
        u = A * trans_radial(s, h * Om) * np.exp(1j * (h * Om * t + rng.uniform(0, TWO_PI)))
        X[0] += u.real
        X[1] += u.imag
        truth["contaminant"] = dict(kind="line h=2.3 radial force co-rotating, C=0.15*Us with lognormal run-to-run amplitude sigma 8 dB")
    elif wname == "w3":
        # an affine track: f = 40 Hz + 0.5 f_spin on Fz and Tz (e.g. a drive beat), constant amplitude
        f = 40.0 + 0.5 * fspin
        for c in (2, 5):
            X[c] += 0.1 * med[c if c != 5 else 3] * np.cos(TWO_PI * f * t + rng.uniform(0, TWO_PI))
        truth["contaminant"] = dict(kind="affine line f = 40 Hz + 0.5*f_spin on Fz and Tz, constant amplitude 10% of median largest line (Tz: of Tx)")
    elif wname == "w4":
        # intermittent rattle: in every 3rd run, decaying 700 Hz impacts (random times, ~20/s) on all radial force+torque channels
        if irun % 3 == 1:
            n = len(t)
            imp = np.zeros(n)
            k = rng.poisson(20 * t[-1])
            idx = rng.integers(0, n, k)
            imp[idx] = rng.normal(0, 1, k)
            tau = np.arange(int(0.02 * 4096)) / 4096
            kern = np.exp(-tau / 0.004) * np.sin(TWO_PI * 700 * tau)
            x = np.convolve(imp, kern)[:n]
            x /= x.std() + 1e-30
            for c in (0, 1, 3, 4):
                X[c] += 0.05 * med[c] * x
        truth["contaminant"] = dict(kind="intermittent rattle: every 3rd run (irun%3==1) decaying 700 Hz impacts on Fx Fy Tx Ty, rms 5% of median largest line")


def write(out, rpms, t, runs, truth, fs):
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "runs.csv"), "w") as f:
        f.write("file,speed_rpm\n")
        for i, rpm in enumerate(rpms):
            f.write(f"run_{i:04d}.csv,{rpm:.6f}\n")
    for i, X in enumerate(runs):
        M = np.column_stack([t] + [X[c] for c in range(6)])
        np.savetxt(os.path.join(out, f"run_{i:04d}.csv"), M, fmt="%.10g", delimiter=",",
                   header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm", comments="")
    with open(os.path.join(os.path.dirname(out.rstrip("/")), os.path.basename(out.rstrip("/")) + ".truth.json"), "w") as f:
        json.dump(truth, f, indent=1, default=float)


SEED = 0
if __name__ == "__main__":
    wname, variant = sys.argv[1], sys.argv[2]
    SEED = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    out_dir = sys.argv[4] if len(sys.argv) > 4 else "newuser_data"
    suffix = f"_s{SEED}" if SEED else ""
    make(wname, variant, os.path.join(out_dir, f"{wname}_{variant}{suffix}"))
