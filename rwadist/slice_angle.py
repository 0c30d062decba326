"""A sweep slice's mean speed from the rotor's angle, read on the imbalance's line (the speed from the data).

The imbalance turns at exactly 1x the rotor, so its line's phase over a slice is the rotor's angle, and the angle's
rise over the slice is the slice's mean speed -- what a tach column's mean over the slice gives.  The peaks of a
slice's lines (:func:`rwadist.sweep.estimate_speed_track`'s first reading) do not give that mean on a sweep: each line's
amplitude grows across a run-up's slice, and its peak lies where it spends its power.  :func:`angle_speeds` reads the
angle where it reads better than the peaks, as :mod:`rwadist.order_tracking` reads it within a steady run.

Units: Hz, Hz/s, rad, s.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import butter, sosfiltfilt

from .data import Sweep
from .order_tracking import ORDER, _middle, cut_hz
from .units import RADIAL_PAIRS

#: A slice's speed read from its 1x line's angle (:func:`angle_speeds`) is taken where its standard error is at most
#: the peak estimate's, or at most this share of the speed: below it no peak of a slice reads the slice's mean speed
#: as well
ANGLE_SE_REL = 1.0e-4
#: ... or at most the peak's error counted with its chirp's bias, (ΔΩ/Ω)²/PEAK_CHIRP_BIAS of the speed (ΔΩ the speed's
#: change across the slice: the session-69 trial's run-up read 0.30 % high at ΔΩ/Ω 0.25, 0.11 % at 0.14, 0.041 % at
#: 0.084: (ΔΩ/Ω)² over 17-21)
PEAK_CHIRP_BIAS = 20.0
#: the low-pass on the dechirped 1x line cuts at this share of the distance to the nearest other line of the speed
#: scale (:func:`angle_speeds`) ...
ANGLE_CUT_SHARE = 0.5
#: ... and at no fewer than this many cycles over the slice (the angle's slope must stay measurable; sidebands nearer
#: the 1x than that are not resolved within one slice, and their wobble on the angle counts in its error)
ANGLE_MIN_CYCLES = 4.0
#: the angle is read on a slice over which the low-pass's cut turns this many cycles at least: its response (~1/cut
#: either way) short beside the slice (trial23's 30-s run-up, 2048-sample slices: at 336 rpm, 0.67 cycles, the angle
#: read 0.23 % high, the peaks 0.07 %)
ANGLE_SETTLE_CYCLES = 1.5
#: a line under the low-pass is fitted as its beat with the 1x (:func:`_angle_slope`) where the beat turns this many
#: cycles over the slice: fewer, it cannot be told from the slope and the parabola (nearer that, the slope's standard
#: error counts what the beat takes of it, and the peak estimate is kept where it is no better)
ANGLE_BEAT_CYCLES = 1.0


def _slice_angle(x: np.ndarray, y: np.ndarray, fs: float, f0: float, rate: float, turn: float, cut: float) -> tuple:
    """(θ rad (n,), noise rad): the rotor's angle over one slice from the 1x line of the radial pair ``x``, ``y``
    read as x + iy (at ``turn`` · f: +1 or −1), brought to 0 Hz along the straight track f0 + rate·(t − t_c) (Hz,
    Hz/s; t_c the slice's centre) and low-passed at ``cut`` Hz (zero-phase, :data:`rwadist.order_tracking.ORDER`
    poles, padded by its own mirror image as :func:`rwadist.order_tracking.rotor_angle` does); its unwrapped phase
    added back.  ``noise``: the RMS the sensor noise alone gives θ (rotor_angle's reading)."""
    n = x.size
    t = np.arange(n) / fs
    track = 2.0 * np.pi * (f0 * t + 0.5 * rate * (t - t[-1] / 2.0) ** 2)
    z = (x - x.mean()) + 1j * (y - y.mean())
    base = z * np.exp(-1j * turn * track)
    sos = butter(ORDER, cut, fs=fs, output="sos")
    pad = min(n - 1, int(np.ceil(4 * fs / cut)))
    base = (sosfiltfilt(sos, base.real, padtype="even", padlen=pad)
            + 1j * sosfiltfilt(sos, base.imag, padtype="even", padlen=pad))
    spec = np.abs(np.fft.fft(z)) ** 2 / n
    snr = float(np.mean(np.abs(base) ** 2)) * n / max(float(np.median(spec)) / np.log(2.0), 1e-300)
    noise = float(np.sqrt(cut / (fs / n * max(snr, 1e-12))))
    return track + turn * np.unwrap(np.angle(base)), noise


def _angle_slope(t: np.ndarray, theta: np.ndarray, f0: float, rate: float, near: np.ndarray,
                 beats: np.ndarray) -> tuple:
    """(slope rad/s, RMS rad about the fit, the slope's variance over a straight line's alone: the beats' share of
    it) of the straight line through the angle ``theta`` at ``t`` (symmetric about the slice's centre), fitted with a
    parabola and with the wobble of each other line of the pattern under the low-pass whose beat turns
    :data:`ANGLE_BEAT_CYCLES` over the slice (``near``, their distances |h − 1| ``beats``; ``f0`` Hz and ``rate``
    Hz/s the track, as :func:`_slice_angle`): a line at h beside the 1x beats with it at (h − 1) times the rotor's
    angle, a sinusoid of known frequency on θ (the session-69 trial's speed sidebands at 0.95 and 1.05 pass the
    low-pass; fitted as a slope alone they read 1733 rpm 0.035 % high, with their beat 0.015 %)."""
    tc = 0.5 * (t[0] + t[-1])
    x = t - tc
    turn = 2.0 * np.pi * (f0 * x + 0.5 * rate * x**2)
    cols = [np.ones_like(x), x, x**2]
    for d in beats[near]:
        cols += [np.cos(d * turn), np.sin(d * turn)]
    A = np.stack(cols, axis=1)
    coef, *_ = np.linalg.lstsq(A, theta, rcond=None)
    # the slope's variance against a straight line's alone (1 when no beat is fitted: the parabola is orthogonal to it)
    inflation = float(np.linalg.pinv(A.T @ A)[1, 1] * np.sum(x**2))
    return float(coef[1]), float(np.std(theta - A @ coef)), inflation


def angle_speeds(sweep: Sweep, starts, slice_samples: int, f0: np.ndarray, sigma: np.ndarray, sign: np.ndarray,
                  rate: np.ndarray, ratios) -> tuple:
    """(f0, σ) Hz per slice: the slice's mean speed read from the rotor's angle where it can be, else the peak
    estimate ``f0`` (σ its standard error) as given.

    The imbalance turns at exactly 1x the rotor: its line in a radial pair read as x + iy (:func:`_slice_angle`,
    brought to 0 Hz along the speed track -- ``f0`` and the track's ``rate``, Hz/s -- turning the way ``sign`` says,
    and low-passed below the nearest other line of the speed scale's ``ratios``, :data:`ANGLE_CUT_SHARE` of its
    distance, at most :func:`rwadist.order_tracking.cut_hz`) gives the rotor's angle θ(t) over the slice, and the
    slope of a straight line through θ over the slice less its ends (symmetric about its centre: a quadratic θ, a
    speed changing linearly, gives its mean exactly) is the slice's mean speed, as a tach column's mean over the slice
    is.  The peaks of a slice's lines do not read that mean on a sweep: each line's peak lies where the line spends its
    power, and its amplitude C·Ω² grows across the slice, so the peaks read high by ~(ΔΩ/Ω)²/20 of the speed (ΔΩ its
    change across the slice) -- a new user's 60-s run-up 500 -> 9000 rpm without a speed column read 0.30 % high at
    572 rpm and 0.041 % at 1733 rpm, where the 3.62 line crossed the rocking whirl at its peak: read that far up, the
    line's peak (pulled to the whirl by 0.57 Hz) fell outside its harmonic's tolerance, the one row on the whirl's
    peak was lost and its damping, 0.015, read "not constrained, 5e-05-0.0072" (with the tach, 0.016).  Read on the
    angle: within 0.021 % of the tach in every slice (RMS 0.0035 %).

    Read where the slice has a finite speed (off-track and silent slices stay as they are), a radial pair is
    recorded and the low-pass settles within the slice (:data:`ANGLE_SETTLE_CYCLES`).  Its standard error: the angle's scatter (the sensor noise's share or, when larger, θ's RMS about a
    parabola through it: sidebands within the cut wobble it), correlated over 1/(2·cut), through the slope of a
    straight line; taken where it is at most the peak estimate's error (σ and its chirp's bias,
    :data:`PEAK_CHIRP_BIAS`) or :data:`ANGLE_SE_REL` of the speed."""
    pair = next(((x, y) for x, y in RADIAL_PAIRS if x in sweep.signals and y in sweep.signals), None)
    if pair is None:
        return f0, sigma
    fs = float(sweep.sample_rate)
    t = np.arange(slice_samples) / fs
    mid = _middle(slice_samples)
    span = float(t[mid][-1] - t[mid][0])
    others = np.abs(np.asarray(ratios, dtype=float) - 1.0)
    others = others[others > 1e-3]
    nearest = float(others.min()) if others.size else 1.0
    beats = np.unique(np.round(others, 4))
    f0, sigma = f0.copy(), sigma.copy()
    for i in np.flatnonzero(np.isfinite(f0) & (f0 > 0) & np.isfinite(sigma) & np.isfinite(rate)):
        cut = min(cut_hz(f0[i]), max(ANGLE_CUT_SHARE * nearest * f0[i], ANGLE_MIN_CYCLES / span))
        if cut * span < ANGLE_SETTLE_CYCLES:
            continue
        a, b = int(starts[i]), int(starts[i]) + slice_samples
        theta, noise = _slice_angle(np.asarray(sweep.signals[pair[0]][a:b], dtype=float),
                                    np.asarray(sweep.signals[pair[1]][a:b], dtype=float), fs, float(f0[i]),
                                    float(rate[i]), float(sign[i]), cut)
        near = (beats * f0[i] <= cut) & (beats * f0[i] * span >= ANGLE_BEAT_CYCLES)
        slope, wobble, inflation = _angle_slope(t[mid], theta[mid], float(f0[i]), float(rate[i]), near, beats)
        se = max(noise, wobble) * np.sqrt(12.0 * inflation / max(2.0 * cut * span, 2.0)) / span / (2.0 * np.pi)
        f_new = slope / (2.0 * np.pi)
        # the peak estimate's error: its standard error and the high reading its chirp gives it
        change = abs(rate[i]) * slice_samples / fs / f0[i]
        peak_error = float(np.hypot(sigma[i], f0[i] * change**2 / PEAK_CHIRP_BIAS))
        if np.isfinite(f_new) and f_new > 0 and np.isfinite(se) and se <= max(peak_error, ANGLE_SE_REL * f_new):
            f0[i], sigma[i] = f_new, se
    return f0, sigma
