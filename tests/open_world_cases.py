"""Effects no diagnose class describes, added to the independent wheel's data (test helper for issue 33, item 3).

The wheel is tests/independent_wheel.py (the thesis's E wheel through its suspension modes, real coordinates, typed
here, not read from rwadist), generated without noise; each kind below changes the records, then white noise of
``noise`` × the top-speed fundamental of each group is added (as the generator does).  Only numpy and scipy.signal;
nothing of rwadist's diagnose is used.  Kinds (each different from the others and from the wheel family's of
tests/family_effects.py where they share a signature):

=================== =================================================================================
fixed_lines         lines at 60 and 180 Hz (a 60 Hz mains family) and 137 Hz, at every speed, each channel
                    its own phase (differential pickup), 5 × the noise std in amplitude ("weak_fixed_lines":
                    1.5 ×, 26 dB over the noise in a Welch bin of 1024 samples: a stripe a reviewer sees)
channel_copy        Tz carries 0.3 × Tx (a load cell's torque axis cross-sensitive to another; no load-cell
                    offset puts a torque into a torque)
moving_resonance    a resonance on the radial forces (ζ 0.03, peak gain 5) whose frequency falls with speed,
                    f_r = 160 − 0.8·f_spin Hz (a mode softening: preload relaxing; between the rocking and
                    the radial translation modes): run through a real IIR filter per run
broadband_hump      band-limited noise at 95-125 Hz on the torque channels, 10 × the noise's PSD there, the
                    same at every speed
run_change          every third run (in speed order) recorded 3.5 dB stronger in every channel (an amplifier
                    range switched between runs)
partial_line        a co-rotating radial-force line at h = 2.7, C 0.08 (thesis units, as the E wheel's 2×
                    line), in every third run only (from the first, in speed order): a source that comes and goes
wide_hump           noise through a first-order band-pass of 450-1000 Hz on every channel, 12 × the noise's
                    PSD at its centre: a hump a third of the band wide
rattle              a part rattling: impacts at random times (20 per second) ringing at 700 Hz (ζ 0.05) on
                    the radial forces and torques, in every run ("rattle_some_runs": in every third run only,
                    from the second in speed order)
affine_line         a line at 150 Hz + 1.5·f_spin on Fz and Tz (a source at a fixed frequency mixed with a line
                    of the rotor), 5 × the noise std in amplitude
=================== =================================================================================
"""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402

KINDS = ("fixed_lines", "channel_copy", "moving_resonance", "broadband_hump", "run_change")
#: the signature a description of each kind must have (docs/diagnose.md, "Unexplained residual")
SIGNATURE = {"fixed_lines": "fixed_line", "weak_fixed_lines": "fixed_line", "channel_copy": "channel_copy", "moving_resonance": "moving_resonance",
             "broadband_hump": "broadband_hump", "run_change": "run_change", "partial_line": "partial_line",
             "wide_hump": "broadband_hump", "rattle": "broadband_hump", "rattle_some_runs": "broadband_hump",
             "affine_line": "affine_line"}
WIDE_HUMP_HZ = (450.0, 1000.0)
RATTLE = (700.0, 0.05, 20.0)          # ringing frequency (Hz), damping ratio, impacts per second
AFFINE = (150.0, 1.5)                 # offset (Hz), slope (Hz per Hz of spin)
FIXED_HZ = (60.0, 137.0, 180.0)
COPY = ("Tx", "Tz", 0.3)
HUMP_HZ = (95.0, 125.0)
RUN_STEP_DB = 3.5
#: the partial line: (h, C in thesis units), present in the runs i % PARTIAL_EVERY == 0
PARTIAL_LINE = (2.7, 0.08)
PARTIAL_EVERY = 3


def _noise_std(lines) -> dict:
    """White noise std per group at ``noise`` = 1: the top-speed fundamental (set per call below)."""
    return {d: next(c for dd, h, c, _ in lines if dd == d and h == 1.0) for d in ("radial_force", "radial_torque")}


def moving_fr(f_spin):
    """The moving resonance's frequency (Hz) at spin frequency ``f_spin`` (Hz)."""
    return 160.0 - 0.8 * np.asarray(f_spin, float)


def _resonance_filter(f_hz, zeta, gain, fs):
    """(b, a) of H(s) = (s² + 2gζω s + ω²)/(s² + 2ζω s + ω²), bilinear, prewarped at ``f_hz``."""
    wd = 2 * fs * np.tan(np.pi * f_hz / fs)
    return signal.bilinear([1, 2 * gain * zeta * wd, wd * wd], [1, 2 * zeta * wd, wd * wd], fs=fs)


def generate(kind: str, speeds_rpm, n_samples: int = 4096, sample_rate: float = 3840.0, noise: float = 0.01,
             seed: int = 0):
    """(SteadyTest, truth) of the independent wheel with ``kind`` (one of :data:`KINDS`, or "clean")."""
    from rwadist.data import Run, SteadyTest

    pad = n_samples if kind == "moving_resonance" else 0            # a filter's transient, discarded
    raw, _ = iw.generate(speeds_rpm, sample_rate=sample_rate, n_samples=n_samples + pad, noise=0.0, seed=seed)
    rng = np.random.default_rng([seed, 33])
    w_top = max(abs(r.speed) for r in raw.runs)
    fund = {g: c * iw.C_UNIT * w_top**2 for g, c in zip("FT", _noise_std(iw.E_LINES).values())}
    std = {ch: noise * fund[ch[0]] for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
    t = np.arange(n_samples) / sample_rate
    runs = []
    for i, r in enumerate(raw.runs):
        sig = {ch: np.asarray(x, float) for ch, x in r.signals.items()}
        if kind == "moving_resonance":
            b, a = _resonance_filter(float(moving_fr(abs(r.speed) / (2 * np.pi))), 0.03, 5.0, sample_rate)
            for ch in ("Fx", "Fy"):
                sig[ch] = signal.lfilter(b, a, sig[ch])
        sig = {ch: x[pad:] for ch, x in sig.items()}
        if kind == "channel_copy":
            src, dst, k = COPY
            sig[dst] = sig[dst] + k * sig[src]
        if kind == "partial_line" and i % PARTIAL_EVERY == 0:
            h, c = PARTIAL_LINE
            phase = h * r.speed * np.arange(sig["Fx"].size) / sample_rate + rng.uniform(0, 2 * np.pi)
            amp = c * iw.C_UNIT * r.speed**2
            sig["Fx"] = sig["Fx"] + amp * np.cos(phase)
            sig["Fy"] = sig["Fy"] + amp * np.sin(phase)
        if kind == "run_change" and i % 3 == 1:
            sig = {ch: x * 10 ** (RUN_STEP_DB / 20) for ch, x in sig.items()}
        for ch in sig:
            sig[ch] = sig[ch] + std[ch] * rng.standard_normal(n_samples)
        if kind in ("fixed_lines", "weak_fixed_lines"):
            amp = 5.0 if kind == "fixed_lines" else 1.5
            for ch in sig:
                for f in FIXED_HZ:
                    sig[ch] = sig[ch] + amp * std[ch] * np.cos(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
        if kind == "broadband_hump":
            sos = signal.butter(4, HUMP_HZ, btype="bandpass", fs=sample_rate, output="sos")
            for ch in ("Tx", "Ty", "Tz"):
                sig[ch] = sig[ch] + np.sqrt(10.0) * std[ch] * signal.sosfilt(sos, rng.standard_normal(n_samples))
        if kind == "wide_hump":
            sos = signal.butter(1, WIDE_HUMP_HZ, btype="bandpass", fs=sample_rate, output="sos")
            for ch in sig:
                sig[ch] = sig[ch] + np.sqrt(12.0) * std[ch] * signal.sosfilt(sos, rng.standard_normal(n_samples))
        if kind == "rattle" or (kind == "rattle_some_runs" and i % 3 == 1):
            f_r, zeta, rate = RATTLE
            w = 2 * np.pi * f_r / sample_rate
            ring = ([1.0], [1.0, -2 * np.exp(-zeta * w) * np.cos(w), np.exp(-2 * zeta * w)])   # a decaying sine
            hits = rng.random((4, n_samples)) < rate / sample_rate
            for j, ch in enumerate(("Fx", "Fy", "Tx", "Ty")):
                sig[ch] = sig[ch] + 8.0 * std[ch] * signal.lfilter(*ring, hits[j] * rng.standard_normal(n_samples))
        if kind == "affine_line":
            f0, b = AFFINE
            f_line = f0 + b * abs(r.speed) / (2 * np.pi)
            for ch in ("Fz", "Tz"):
                sig[ch] = sig[ch] + 5.0 * std[ch] * np.cos(2 * np.pi * f_line * t + rng.uniform(0, 2 * np.pi))
        runs.append(Run(speed=r.speed, sample_rate=sample_rate, signals=sig, t0=0.0, name=r.name))
    truth = {"kind": kind, "signature": SIGNATURE.get(kind), "fixed_hz": FIXED_HZ, "copy": COPY,
             "hump_hz": HUMP_HZ, "run_step_db": RUN_STEP_DB, "partial_line": PARTIAL_LINE,
             "partial_runs": [r.name for i, r in enumerate(raw.runs) if i % PARTIAL_EVERY == 0],
             "rattle_rpm": [abs(r.speed) * 30 / np.pi for i, r in enumerate(raw.runs) if i % 3 == 1]}
    return SteadyTest(runs=runs, meta={"generator": "tests/open_world_cases.py"}), truth


def with_runs(test, runs):
    """``test`` with ``runs`` (a helper for tests that change records)."""
    return replace(test, runs=list(runs))
