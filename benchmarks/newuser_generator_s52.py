#!/usr/bin/env python3
"""Independent physics generator of hard-mounted reaction-wheel load-cell tests (numpy only).

Written from the physics alone (not from rwadist's code) for the session-52 new-user trial.

Usage
-----
    python newuser_generator_s52.py --wheel W1 --case clean --seed 1 --out DIR
    python newuser_generator_s52.py --wheel W2 --case pump  --seed 2 --out DIR
    python newuser_generator_s52.py --wheel W1 --case sweep --seed 1 --out DIR   # DIR/sweep.csv, no speed column

    --wheel  W1 | W2 | W3
    --case   clean | aniso | fixtures | pump | step | ty_sign | cogging | tach2 | radps | sweep
    --seed   integer (phases, noise, per-run pump amplitude)
    --runs   number of steady runs (default 30)
    --out    output folder (created); holds runs.csv, run_XXXX.csv, meta.json (sweep: sweep.csv);
             the truth is written beside it as DIR + "_truth.json"

Physics
-------
Rigid rotor (mass m, transverse inertia I_rr, polar I_zz) on a linear suspension inside a housing that is
hard-mounted on a 6-axis load cell (Fx Fy Fz Tx Ty Tz at the bearing centre, z = spin axis, positive spin
about +z).  Steady state at constant speed Omega, every disturbance line a tone at omega = h*Omega:

  radial translation, per axis (k_x may differ from k_y: anisotropic mounting)
      m x'' + c_x x' + k_x x = F_x            cell reads  Fx = k_x x + c_x x'
  rocking, complex angle phi = theta_x + j theta_y, complex moment M = M_x + j M_y (isotropic k_r)
      I_rr phi'' - j I_zz Omega phi' + c_r phi' + k_r phi = M
      cell reads  T = k_r phi + c_r phi'   (Tx = Re T, Ty = Im T)
      a tone M = P e^{j w t} (w > 0: forward, w < 0: backward whirl) gives
      T = P (k_r + j c_r w) / (k_r - I_rr w^2 + I_zz Omega w + j c_r w) e^{j w t}
  axial
      m z'' + c_a z' + k_a z = F_z            cell reads  Fz = k_a z + c_a z'
  Tz: no suspension mode (free spin axis); only what a case puts there (motor cogging) plus sensor noise.

Disturbance lines: amplitude C * Omega^2 at h * Omega.  Static imbalance U_s (h = 1, co-rotating radial force),
dynamic imbalance U_d (h = 1, co-rotating radial torque), 2x, cage (~0.4, co-rotating), ball-pass outer/inner
race (3-5.5) and multiples as planar radial loads (a fixed direction: half co, half counter-rotating) and
axial loads.  Phases random per run.  White sensor noise of 1 % of each channel's RMS over the test
(one fixed floor per channel; Tz takes 1 % of Tx's).

Cases
-----
  clean     baseline
  aniso     k_y = 1.08 k_x (the translation mode splits, ~+3.9 % in y)
  fixtures  test-stand resonance H = (1 + 2j z r)/(1 - r^2 + 2j z r) (base transmissibility) on the force
            channels at f_F and a second one on the torque channels at f_T
  fixF      only the force-channel fixture of 'fixtures';  fixT: only the torque-channel one
  pump      a pump at 1480 rpm in the lab: forces at 24.667 Hz and 49.333 Hz on Fx, Fy, Fz, random phase per
            run, amplitude varying +-25 % run to run
  step      static imbalance U_s x 1.2 for the upper half of the runs (in speed order): a balance mass moved
  ty_sign   Ty recorded with the wrong sign
  cogging   motor cogging torque on Tz only: constant-amplitude lines at 6x and 12x the speed
  tach2     speed column 2x the truth (a 2-pulse/rev tach read as 1 pulse/rev)
  radps     speed column holds rad/s while labelled rpm (x 2*pi/60)
  sweep     one run-up 10 % -> 100 % top speed, linear in time, no speed column (quasi-static: each line's
            response is the steady one at its instantaneous frequency and speed)

Record (2026-12-05, session 52; 62 data sets, seeds 1-2, each diagnosed by the command a user types with no model,
``rwadist diagnose DATA -o REPORT``; main f10986f against the session's tree): clean (modes within 0.04 %, nothing
added), a lab pump (both lines described as fixed lines), Ty recorded with the wrong sign (corrected with a warning)
and run-ups without a speed column (every ratio within 0.02 %, modes within 0.2 %) were right on main.  A speed
column 2x the rotor's (tach2) or in rad/s (radps): main silent, the true 1x named "a subharmonic: a rub", U_s 100x
low, I_zz/I_rr 0.65 for 1.3 (tach2), the modes lost at 586-2614x the clean error (radps); now 12/12 scaled back
(rwadist.speed_check's whole factors), the modes within 0.04 %, I_zz/I_rr within 0.003, the error at the clean level.
The static imbalance 20 % stronger in the upper half of the runs (step): main said nothing (360-1480x the clean
error); now 6/6 described (``line_property`` ``line_step``: x 1.2 between the two middle runs).  Left: two fixtures
at once or a force-only fixture (a stand is fitted on every channel: rocking +27-42 %, errors 515-4467x), a
torque-only fixture named a wheel mode, motor cogging on Tz alone (W1: the suspension modes not fitted), an
anisotropic suspension (the translation declared unconstrained, no split described: its lines past the modes are
planar, their x/y power ratio set by their direction), and a planar line read as a channel's gain (pump W1,
sweeps W1 and W3).
"""
import argparse
import json
import os
import shutil

import numpy as np

TWO_PI = 2.0 * np.pi

# ----------------------------------------------------------------------------- wheels
WHEELS = {
    # rocking < axial < translation, 6000 rpm, 5 kHz
    "W1": dict(m=2.5, I_zz=0.0060, ratio=1.8, f_trans=420.0, f_rock=160.0, f_axial=260.0,
               z_trans=0.02, z_rock=0.015, z_axial=0.025, top_rpm=6000.0, fs=5000.0, n=8192,
               U_s=8e-7, U_d=3e-8, cage=0.392, bpo=3.61, bpi=5.39,
               fix_F=(340.0, 0.05), fix_T=(210.0, 0.06)),
    # axial < translation < rocking, 3000 rpm, 2 kHz
    "W2": dict(m=12.0, I_zz=0.120, ratio=1.3, f_trans=75.0, f_rock=130.0, f_axial=55.0,
               z_trans=0.03, z_rock=0.02, z_axial=0.03, top_rpm=3000.0, fs=2000.0, n=8192,
               U_s=6e-6, U_d=4e-7, cage=0.415, bpo=4.12, bpi=5.88,
               fix_F=(105.0, 0.05), fix_T=(190.0, 0.05)),
    # rocking < translation < axial, 10000 rpm, 10 kHz
    "W3": dict(m=5.0, I_zz=0.020, ratio=2.1, f_trans=330.0, f_rock=240.0, f_axial=580.0,
               z_trans=0.02, z_rock=0.02, z_axial=0.015, top_rpm=10000.0, fs=10000.0, n=16384,
               U_s=1.5e-6, U_d=6e-8, cage=0.381, bpo=3.23, bpi=4.77,
               fix_F=(450.0, 0.05), fix_T=(290.0, 0.05)),
}

PUMP_RPM = 1480.0


def wheel_params(name, case):
    w = dict(WHEELS[name])
    m = w["m"]
    I_rr = w["I_zz"] / w["ratio"]
    wt = TWO_PI * w["f_trans"]
    k = m * wt ** 2
    p = dict(name=name, m=m, I_zz=w["I_zz"], I_rr=I_rr)
    p["k_x"] = k
    p["k_y"] = k * (1.08 if case == "aniso" else 1.0)
    p["c_x"] = 2 * w["z_trans"] * np.sqrt(p["k_x"] * m)
    p["c_y"] = 2 * w["z_trans"] * np.sqrt(p["k_y"] * m)
    p["k_r"] = I_rr * (TWO_PI * w["f_rock"]) ** 2
    p["c_r"] = 2 * w["z_rock"] * np.sqrt(p["k_r"] * I_rr)
    p["k_a"] = m * (TWO_PI * w["f_axial"]) ** 2
    p["c_a"] = 2 * w["z_axial"] * np.sqrt(p["k_a"] * m)
    Us, Ud = w["U_s"], w["U_d"]
    # lines: (direction, h, C, sense) ; sense co | planar (planar: fixed direction angle)
    lines = [
        ("radial_force", 1.0, Us, "co"),
        ("radial_force", 2.0, 0.08 * Us, "planar"),
        ("radial_force", w["cage"], 0.05 * Us, "co"),
        ("radial_force", w["bpo"], 0.03 * Us, "planar"),
        ("radial_force", w["bpi"], 0.05 * Us, "planar"),
        ("radial_force", 2 * w["bpi"], 0.015 * Us, "planar"),
        ("radial_torque", 1.0, Ud, "co"),
        ("radial_torque", 2.0, 0.05 * Ud, "planar"),
        ("radial_torque", w["bpi"], 0.04 * Ud, "planar"),
        ("axial_force", 1.0, 0.10 * Us, None),
        ("axial_force", w["bpo"], 0.08 * Us, None),
        ("axial_force", 2 * w["bpo"], 0.03 * Us, None),
        ("axial_force", w["bpi"], 0.03 * Us, None),
    ]
    return w, p, lines


# ----------------------------------------------------------------------------- transfer functions
def trans_gain(p, axis, w):
    k, c = p["k_" + axis], p["c_" + axis]
    return (k + 1j * c * w) / (k - p["m"] * w ** 2 + 1j * c * w)


def axial_gain(p, w):
    return (p["k_a"] + 1j * p["c_a"] * w) / (p["k_a"] - p["m"] * w ** 2 + 1j * p["c_a"] * w)


def rock_gain(p, w_signed, Om):
    kr, cr = p["k_r"], p["c_r"]
    return (kr + 1j * cr * w_signed) / (kr - p["I_rr"] * w_signed ** 2 + p["I_zz"] * Om * w_signed
                                        + 1j * cr * w_signed)


def fixture_gain(f, f0, zeta):
    r = f / f0
    return (1 + 2j * zeta * r) / (1 - r ** 2 + 2j * zeta * r)


def whirl_hz(p, Om):
    """Rocking forward/backward whirl frequencies (Hz, positive) at spin Om (rad/s)."""
    a, b, c = p["I_rr"], p["I_zz"] * Om, p["k_r"]
    disc = np.sqrt(b * b + 4 * a * c)
    return (b + disc) / (2 * a) / TWO_PI, (-b + disc) / (2 * a) / TWO_PI


# ----------------------------------------------------------------------------- synthesis
def synth(p, lines, Om_t, theta_t, rng, case, w, run_Us_factor=1.0, phases=None, gF=None, gT=None):
    """Channels (6, N) for speed history Om_t (rad/s, array) and shaft angle theta_t (rad).

    Quasi-static: for a sweep the gains are evaluated at the instantaneous speed; for a steady run Om_t is
    constant and this is the exact steady state.  gF, gT: optional fixture gains g(f_Hz) (complex) of the force
    and torque channels, applied to each tone (a real channel's e^{+jwt} part times g, e^{-jwt} part times conj g)."""
    one = lambda f: 1.0 + 0j
    gF = gF or one
    gT = gT or one
    N = len(theta_t)
    out = np.zeros((6, N))
    for i, (d, h, C, sense) in enumerate(lines):
        if phases is None:
            ph = rng.uniform(0, TWO_PI)
            ang = rng.uniform(0, np.pi)
        else:
            ph, ang = phases[i]
        scale = run_Us_factor if (d == "radial_force" and h == 1.0) else 1.0
        A = scale * C * Om_t ** 2
        wline = h * Om_t
        arg = h * theta_t + ph
        if d == "radial_force":
            if sense == "co":
                # F = A e^{j arg}: Fx = A cos, Fy = A sin
                Fxp, Fyp = A * np.exp(1j * arg), A * np.exp(1j * (arg - np.pi / 2))
            else:
                Fxp, Fyp = A * np.cos(ang) * np.exp(1j * arg), A * np.sin(ang) * np.exp(1j * arg)
            g = gF(wline / TWO_PI)
            out[0] += np.real(g * Fxp * trans_gain(p, "x", wline))
            out[1] += np.real(g * Fyp * trans_gain(p, "y", wline))
        elif d == "radial_torque":
            if sense == "co":
                P = A * np.exp(1j * arg)          # forward component
                Q = 0.0 * A
            else:
                Mx = A * np.cos(ang) * np.exp(1j * arg)
                My = A * np.sin(ang) * np.exp(1j * arg)
                # m(t) = Re(Mx e) + j Re(My e) = (Mx + j My)/2 e + (conj(Mx) + j conj(My))/2 conj(e)
                P = (Mx + 1j * My) / 2
                Q = (np.conj(Mx) + 1j * np.conj(My)) / 2
            g = gT(wline / TWO_PI)
            T = g * P * rock_gain(p, wline, Om_t) + np.conj(g) * Q * rock_gain(p, -wline, Om_t)
            out[3] += np.real(T)
            out[4] += np.imag(T)
        elif d == "axial_force":
            out[2] += np.real(gF(wline / TWO_PI) * A * np.exp(1j * arg) * axial_gain(p, wline))
    return out


def run_signal(p, lines, w, case, Om, rng, n, fs, Us_factor=1.0):
    t = np.arange(n) / fs
    theta = Om * t + rng.uniform(0, TWO_PI)
    Om_t = np.full(n, Om)
    gF = gT = None
    if case in ("fixtures", "fixF"):
        gF = lambda f: fixture_gain(f, *w["fix_F"])
    if case in ("fixtures", "fixT"):
        gT = lambda f: fixture_gain(f, *w["fix_T"])
    ch = synth(p, lines, Om_t, theta, rng, case, w, Us_factor, gF=gF, gT=gT)
    if case == "cogging":
        t6 = rng.uniform(0, TWO_PI)
        t12 = rng.uniform(0, TWO_PI)
        ch[5] += w["cog6"] * np.cos(6 * theta + t6) + w["cog12"] * np.cos(12 * theta + t12)
    if case == "pump":
        fp = PUMP_RPM / 60.0
        amp = w["pump_amp"] * rng.uniform(0.75, 1.25)
        ph1 = rng.uniform(0, TWO_PI)
        ph2 = rng.uniform(0, TWO_PI)
        for c, share in zip((0, 1, 2), (1.0, 0.7, 0.5)):
            ch[c] += share * amp * np.cos(TWO_PI * fp * t + ph1 + 0.9 * c)
            ch[c] += share * 0.5 * amp * np.cos(TWO_PI * 2 * fp * t + ph2 + 1.3 * c)
    return t, ch


def write_run(path, t, ch):
    data = np.column_stack([t, ch.T])
    np.savetxt(path, data, delimiter=",", fmt="%.10g",
               header="time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm", comments="")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--wheel", required=True, choices=sorted(WHEELS))
    ap.add_argument("--case", default="clean",
                    choices=["clean", "aniso", "fixtures", "fixF", "fixT", "pump", "step", "ty_sign", "cogging", "tach2",
                             "radps", "sweep"])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--sweep-seconds", type=float, default=40.0)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()

    w, p, lines = wheel_params(a.wheel, a.case)
    rng = np.random.default_rng(1000 * a.seed + int(a.wheel[1]))
    fs, n = w["fs"], w["n"]
    top = w["top_rpm"]
    Om_top = top * TWO_PI / 60
    w["cog6"] = 0.3 * w["U_d"] * Om_top ** 2          # constant cogging torque (N m)
    w["cog12"] = 0.1 * w["U_d"] * Om_top ** 2
    w["pump_amp"] = 0.05 * w["U_s"] * Om_top ** 2     # pump 1x force (N)

    if os.path.exists(a.out):
        shutil.rmtree(a.out)
    os.makedirs(a.out)

    truth = dict(generator="newuser_generator_s52.py", wheel=a.wheel, case=a.case, seed=a.seed,
                 sample_rate_hz=fs, samples_per_run=n,
                 mass_kg=p["m"], I_zz=p["I_zz"], I_rr=p["I_rr"], inertia_ratio=w["ratio"],
                 modes_Hz=dict(radial_translation_x=np.sqrt(p["k_x"] / p["m"]) / TWO_PI,
                               radial_translation_y=np.sqrt(p["k_y"] / p["m"]) / TWO_PI,
                               rocking_at_rest=w["f_rock"], axial=w["f_axial"]),
                 zeta=dict(translation=w["z_trans"], rocking=w["z_rock"], axial=w["z_axial"]),
                 lines=[dict(direction=d, h=h, C_SI=C, sense=s) for d, h, C, s in lines],
                 noise="white, 1 % of each channel's RMS over the test (Tz: 1 % of Tx's)",
                 effects=[])
    if a.case == "aniso":
        truth["effects"].append(dict(kind="anisotropic_suspension", k_y_over_k_x=1.08))
    if a.case in ("fixtures", "fixF"):
        truth["effects"].append(dict(kind="fixture_resonance", channels=["Fx", "Fy", "Fz"],
                                     f_Hz=w["fix_F"][0], zeta=w["fix_F"][1],
                                     form="(1+2jzr)/(1-r^2+2jzr)",
                                     peak_gain=float(abs(fixture_gain(w["fix_F"][0], *w["fix_F"])))))
    if a.case in ("fixtures", "fixT"):
        truth["effects"].append(dict(kind="fixture_resonance", channels=["Tx", "Ty", "Tz"],
                                     f_Hz=w["fix_T"][0], zeta=w["fix_T"][1],
                                     form="(1+2jzr)/(1-r^2+2jzr)",
                                     peak_gain=float(abs(fixture_gain(w["fix_T"][0], *w["fix_T"])))))
    if a.case == "pump":
        truth["effects"].append(dict(kind="lab_pump", rpm=PUMP_RPM, f_Hz=[PUMP_RPM / 60, 2 * PUMP_RPM / 60],
                                     amp_1x_N_Fx=w["pump_amp"], amp_2x_N_Fx=0.5 * w["pump_amp"],
                                     channel_shares={"Fx": 1.0, "Fy": 0.7, "Fz": 0.5},
                                     per_run_amplitude="uniform 0.75-1.25", phase="random per run"))
    if a.case == "step":
        truth["effects"].append(dict(kind="imbalance_step", U_s_factor=1.2, applies_to="upper half of runs"))
    if a.case == "ty_sign":
        truth["effects"].append(dict(kind="wiring", channel="Ty", sign=-1))
    if a.case == "cogging":
        truth["effects"].append(dict(kind="motor_cogging", channel="Tz", h=[6, 12],
                                     amp_Nm=[w["cog6"], w["cog12"]], law="constant amplitude (Omega^0)"))
    speed_factor = {"tach2": 2.0, "radps": TWO_PI / 60}.get(a.case, 1.0)
    if speed_factor != 1.0:
        truth["effects"].append(dict(kind="speed_column_scale", factor=speed_factor))

    if a.case == "sweep":
        T = a.sweep_seconds
        N = int(round(T * fs))
        t = np.arange(N) / fs
        rpm = top * (0.1 + 0.9 * t / T)
        Om_t = rpm * TWO_PI / 60
        theta = np.cumsum(Om_t) / fs
        ch = synth(p, lines, Om_t, theta, rng, a.case, w)
        sig = np.sqrt(np.mean(ch ** 2, axis=1))
        sig[5] = sig[3]
        ch += 0.01 * sig[:, None] * rng.standard_normal(ch.shape)
        path = os.path.join(a.out, "sweep.csv")
        write_run(path, t, ch)
        truth["sweep"] = dict(file="sweep.csv", rpm_start=rpm[0], rpm_end=rpm[-1], seconds=T,
                              speed_column=False, law="linear in time")
    else:
        rpms = np.linspace(0.1 * top, top, a.runs)
        truth["speeds_rpm_true"] = rpms.tolist()
        sigs = []
        for i, r in enumerate(rpms):
            Om = r * TWO_PI / 60
            Usf = 1.2 if (a.case == "step" and i >= a.runs // 2) else 1.0
            t, ch = run_signal(p, lines, w, a.case, Om, rng, n, fs, Usf)
            sigs.append(ch)
        allch = np.concatenate(sigs, axis=1)
        sig = np.sqrt(np.mean(allch ** 2, axis=1))
        sig[5] = sig[3]
        truth["noise_sigma"] = dict(zip(["Fx", "Fy", "Fz", "Tx", "Ty", "Tz"], (0.01 * sig).tolist()))
        with open(os.path.join(a.out, "runs.csv"), "w") as f:
            f.write("file,speed_rpm\n")
            for i, (r, ch) in enumerate(zip(rpms, sigs)):
                ch = ch + 0.01 * sig[:, None] * rng.standard_normal(ch.shape)
                if a.case == "ty_sign":
                    ch[4] = -ch[4]
                t = np.arange(n) / fs
                name = f"run_{i:04d}.csv"
                write_run(os.path.join(a.out, name), t, ch)
                f.write(f"{name},{r * speed_factor:.6f}\n")
        with open(os.path.join(a.out, "meta.json"), "w") as f:
            json.dump(dict(sample_rate_hz=fs, wheel=dict(name=f"newuser-{a.wheel}", mass_kg=p["m"]),
                           notes="newuser_generator_s52.py"), f, indent=1)
    # whirl table for reference
    sp = np.linspace(0, top, 6)
    truth["rocking_whirl_Hz"] = [dict(rpm=s, forward=whirl_hz(p, s * TWO_PI / 60)[0],
                                      backward=whirl_hz(p, s * TWO_PI / 60)[1]) for s in sp]
    with open(a.out.rstrip("/") + "_truth.json", "w") as f:
        json.dump(truth, f, indent=1, default=float)


if __name__ == "__main__":
    main()
