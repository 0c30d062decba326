"""Order tracking of a speed that wanders within the runs (issue 33, item 5; trial 16's ``wander`` cells).

A steady run whose rotor speed moves during the record (a speed loop hunting, a drifting set-point: trial 16's 0.3 %
Ornstein-Uhlenbeck wander with a 1 s correlation) smears every line over h·ΔΩ: at h 6 of 5000 rpm a 0.3 % wander is
1.5 Hz, six bins of a 4 s record, and the model, which holds each run at one speed, leaves that smear as residual
(9-55x the clean error).  :mod:`rwadist.speed_runs` detects it (every 1× line wider than a steady tone's in half the
runs or more).  Here it is undone the way a rotating-machinery lab does, by computed order tracking:

* the rotor angle θ(t) is read from the run's own imbalance line, which turns at exactly 1× the rotor on every
  wheel: the strongest 1× line of the run (:func:`rwadist.speed_check.line_reads`) of a radial pair read as x + iy,
  where it is one line turning one way (the axial force where no pair is read: one real channel also holds every
  line's mirror image), is brought to 0 Hz at its measured frequency, low-passed (zero-phase Butterworth of order
  :data:`ORDER`, cut at :data:`CUT_RATIO` of the line's frequency and at most :data:`CUT_MAX_HZ`: below the nearest
  other line of a bearing-like set, the cage near 0.4×, and above the wander's own spectrum), and its unwrapped
  phase added to the line's steady turn;
* a run is resampled only where the angle's swing about a steady turn is :data:`SWING_OVER_NOISE` times what the
  sensor noise alone gives the reading (a slow run's weak 1× line gains nothing from it);
* every channel of the run is resampled at equal steps of θ (a cubic spline of the record, first upsampled
  :data:`UPSAMPLE` x band-limited (the FFT of the record and its mirror image), flat to the Nyquist frequency)
  onto the run's own time base, at the run's mean speed (θ's rise over the record).  Every line at h·θ is then a
  steady tone at h times that mean, as the model takes it;
* what is not tied to the rotor (a fixed resonance, the noise floor, a mains line) is time-warped by the wander,
  i.e. spread by ±0.3 % about its frequency: below a suspension mode's own half-power width (2ζ) at any damping of
  a wheel or a stand (ζ ≥ 0.005), and below a fixed line's bin at a Welch resolution of a few Hz up to ~1 kHz.

The runs' speeds become their mean speeds (the record's ``runs_tracked`` lists each run's mean, the speed's RMS
within it from dθ/dt, the sensor noise's share included, and the angle's noise).  Nothing here runs unless the
wander was detected.

Units: Hz, rad/s, rad, s.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

#: the zero-phase low-pass on the demodulated 1× line: its order ...
ORDER = 4
#: ... its cut as a fraction of the 1× frequency (the nearest other rotor line of a bearing-like set, the cage at
#: ~0.4×, is 0.6× away; the imbalance's counter part 2× away) ...
CUT_RATIO = 0.25
#: ... and at most this (Hz): a wander of a speed loop or a set-point is slower than this
CUT_MAX_HZ = 5.0
#: upsampling before the spline (band-limited): the spline then reads a signal sampled 4x over its band
UPSAMPLE = 4
#: wander's RMS (relative to the mean speed) within a run below which the run is left as recorded
MIN_WANDER_REL = 1.0e-5
#: a run is resampled where the angle's swing about a steady turn is this many times the noise's share of it
SWING_OVER_NOISE = 3.0
#: share of the record at each end left out of the mean speed and the wander (the low-pass's own edges)
EDGE = 0.05
#: a pair's 1× line is read for the angle where this share of its power turns one way (one line, not an ellipse)
ONE_WAY = 0.9


def _middle(n: int) -> slice:
    """The samples of a record of ``n`` less its first and last :data:`EDGE` (the low-pass's own edges)."""
    return slice(int(EDGE * n), n - int(EDGE * n))


def cut_hz(f_line: float) -> float:
    """The low-pass's cut (Hz) for a 1× line at ``f_line`` Hz."""
    return min(CUT_RATIO * abs(float(f_line)), CUT_MAX_HZ)


def rotor_angle(run, channels: tuple, f_line: float, turn: float = 1.0) -> tuple:
    """(θ, noise): θ (rad, (n,)) of the rotor at the run's samples, from its 1× line at ``f_line`` Hz (its measured
    peak) in ``channels`` (a radial pair (x, y) read as x + iy, whose line sits at ``turn`` · ``f_line``, +1 or −1;
    or one channel): brought to 0 Hz, low-passed (module docstring; padded by its own mirror image over four of the
    filter's time constants, so the filter's start and end transients stay outside the record), its phase unwrapped
    and added to 2π·``f_line``·t; θ rises at the rotor's speed.  ``noise`` (rad): the RMS the sensor noise alone
    gives θ, √(B/(df·SNR)): B the low-pass's cut, df the record's bin, SNR the line's power (the low-passed
    phasor's) over the noise in one bin (the median bin of the record's spectrum over ln 2)."""
    from scipy import signal

    fs = float(run.sample_rate)
    n = run.n_samples
    t = np.arange(n) / fs
    w = 2 * np.pi * abs(float(f_line))
    sig = [np.asarray(run.signals[c], dtype=float) for c in channels]
    z = sig[0] - sig[0].mean()
    if len(sig) == 2:
        z = z + 1j * (sig[1] - sig[1].mean())
    else:
        turn = 1.0                      # one real channel: its positive-frequency line
    base = z * np.exp(-1j * turn * w * t)
    cut = cut_hz(f_line)
    sos = signal.butter(ORDER, cut, fs=fs, output="sos")
    pad = min(n - 1, int(np.ceil(4 * fs / cut)))
    # an even extension: the slowly turning phasor continues with its own magnitude (an odd one, 2·x₀ − x, doubles
    # it at the ends where the phase has moved)
    base = (signal.sosfiltfilt(sos, base.real, padtype="even", padlen=pad)
            + 1j * signal.sosfiltfilt(sos, base.imag, padtype="even", padlen=pad))
    spec = np.abs(np.fft.fft(z)) ** 2 / n
    snr = float(np.mean(np.abs(base) ** 2)) * n / max(float(np.median(spec)) / np.log(2.0), 1e-300)
    noise = float(np.sqrt(cut / (fs / n * max(snr, 1e-12))))
    return w * t + turn * np.unwrap(np.angle(base)), noise


def resampled(run, theta: np.ndarray):
    """(run, mean speed rad/s, wander RMS relative): ``run`` with every channel at equal steps of ``theta`` on its own
    time base (module docstring) and its speed the mean over the record (θ's rise end to end; the sign kept).  The
    wander's RMS is read over the record less its first and last :data:`EDGE`."""
    from scipy import signal
    from scipy.interpolate import CubicSpline

    fs = float(run.sample_rate)
    n = run.n_samples
    t = np.arange(n) / fs
    mid = _middle(n)
    # the mean over the whole record (what every Welch segment averages), from the angle's rise end to end: its
    # ends carry the low-pass's edge (~0.05 rad, 1e-5 of a record's turn), a least-squares slope over part of the
    # record the wander's own departure from that mean (~1e-4)
    mean = float(theta[-1] - theta[0]) / float(t[-1] - t[0])
    start = float(theta[0])
    # the times at which the rotor reaches equal steps of angle (θ rises: an inverse by interpolation, continued
    # beyond the record's ends at the mean speed)
    t_ext = np.concatenate([[t[0] - 1.0], t, [t[-1] + 1.0]])
    th_ext = np.concatenate([[theta[0] - mean], theta, [theta[-1] + mean]])
    # (within the record: a spline continued past its ends is a cubic running away)
    t_new = np.clip(np.interp(start + mean * t, th_ext, t_ext), t[0], t[-1])
    t_up = np.arange(n * UPSAMPLE) / (fs * UPSAMPLE)
    signals = {}
    for c, v in run.signals.items():
        x = np.asarray(v, dtype=float)
        # band-limited upsampling of the record and its mirror image (one period without a jump at the ends): flat
        # to the Nyquist frequency, where a polyphase filter's transition band takes 1-3 dB of the top 10 %
        up = signal.resample(np.concatenate([x, x[::-1]]), 2 * n * UPSAMPLE)[: n * UPSAMPLE]
        signals[c] = CubicSpline(t_up, up)(t_new)
    wander = float(np.std(np.gradient(theta, t)[mid]) / mean)
    return replace(run, signals=signals, speed=float(np.sign(run.speed)) * mean), float(mean), wander


def tracked(test, check: dict, reads=None) -> tuple:
    """(test, check): each spinning run with a 1× line read resampled at equal rotor angle (module docstring) when
    :func:`rwadist.speed_runs.own_speeds` found the speed wandering within the runs (``check["runs_speed"]["wander"]``),
    with ``runs_tracked`` added to that record; else the arguments untouched.  ``reads``: a
    :class:`rwadist.speed_check.LineReads` shared with the steps before, or None."""
    from .speed_check import LINES, LineReads

    own = (check or {}).get("runs_speed") or {}
    if not own.get("wander"):
        return test, check
    reads = (reads or LineReads())(test)
    runs, done = list(test.runs), []
    for i, run in enumerate(test.runs):
        # the run's 1x lines read (a pair's where it is one line turning one way), the strongest
        snr = {k: float(r[i, 1]) for k, r in reads.items() if np.isfinite(r[i, 0]) and r[i, 1] > 0
               and (len(LINES[k][0]) == 1 or abs(r[i, 2] - 0.5) >= ONE_WAY - 0.5)}
        if run.speed == 0 or not snr:
            continue
        # a pair first: x + iy holds its 1x line alone near 1x (one channel also holds every line's mirror image)
        pairs = [k for k in snr if len(LINES[k][0]) == 2]
        best = max(pairs or snr, key=lambda k: snr[k])
        turn = 1.0 if len(LINES[best][0]) == 1 or reads[best][i, 2] > 0.5 else -1.0
        f_line = float(reads[best][i, 0])
        theta, noise = rotor_angle(run, LINES[best][0], f_line, turn)
        new, mean, wander = resampled(run, theta)
        # the wander's swing of the angle about a steady turn against what the noise alone gives the reading
        t = np.arange(run.n_samples) / float(run.sample_rate)
        mid = _middle(t.size)
        swing = float(np.std(theta[mid] - np.polyval(np.polyfit(t[mid], theta[mid], 1), t[mid])))
        if wander < MIN_WANDER_REL or swing < SWING_OVER_NOISE * noise:
            continue
        runs[i] = new
        done.append({"run": i, "run_name": run.name or str(i),
                     "given_rpm": round(abs(float(run.speed)) * 30 / np.pi, 6), "mean_rpm": round(mean * 30 / np.pi, 6),
                     "wander_rms_rel": round(wander, 7), "angle_noise_rad": round(noise, 6), "line": LINES[best][1]})
    if not done:
        return test, check
    rms = float(np.median([d["wander_rms_rel"] for d in done]))
    text = (f"{len(done)} runs resampled at equal steps of the rotor's angle, read from each run's own 1x line (order "
            f"tracking): the speed within a run moved by {100 * rms:.2g} % RMS (median), and each run is taken at its "
            "mean speed")
    own = dict(own, runs_tracked=done, wander=dict(own["wander"], action=text))
    return type(test)(runs, dict(test.meta or {}, order_tracked=len(done))), dict(check, runs_speed=own)
