"""Speed sweeps (spin-up, run-down) cut into quasi-steady slices (thesis §2.2.2).

The E-wheel test of the thesis was one 390 s record at 3840 Hz through a
spin-up; it was cut into 8192-sample slices (2.133 s), each treated as a steady
run at the slice's mean speed.  The thesis took the frequency of the largest
peak of each slice as the wheel speed.  That fails whenever a structural mode
lifts another line above the 1× line, and a harmonic comb (1, 2, 3, 4 × f0)
fails on a wheel whose strongest lines are bearing lines near the integers
(a ball-pass line at 3.08 read as 3×: every h 2.6 % low).  So the speed is
found from physics alone, assuming no line set:

1. **Spectra.**  Each slice (a 2-D array of slices, one FFT call) gets a
   Hann periodogram zero-padded ``PAD`` times.  Each channel's PSD is
   divided by one number, its median noise floor in that slice
   (:func:`rwadist.spectra.noise_floor`), and the channels are averaged (P),
   so no channel dominates by its unit; the same average of the local floors
   is F, and ``R = P / F`` is a signal-to-noise ratio, 1 in pure noise.  A
   slice whose largest R does not pass the largest that white noise reaches
   on the same grid (calibrated on generated noise, fixed seed) shows no line
   (the wheel near rest): ``speed = nan``.
2. **Shape and scale** (:mod:`rwadist.speed_scale`).  Every line sits at a
   fixed ratio of the speed, so the line pattern moves rigidly in ln f: the
   slices registered against each other and against their common template
   give ln|Ω| up to one constant.  The template's peaks are the wheel's lines;
   the 1× line is the imbalance -- one rotation sense in the radial force and
   the same in the radial torque (the static and dynamic imbalances turn with
   the rotor), with the most integer multiples among the lines (itself
   included; a count, never a summed strength, which saturates and flipped
   with the sweep's duration), the lowest of a tie (not a cage of a stronger
   tied line: :func:`rwadist.speed_scale.imbalance_line`), the others kept for the
   gyroscopic whirl's test (:mod:`rwadist.speed_whirl`); every other line
   keeps its ratio h_i to it.
3. **Refinement.**  The lines near h_i·f0 are found and their frequencies
   refined with :func:`rwadist.spectra.find_lines` on P (log-parabolic
   interpolation on the zero-padded spectrum; P has no frequency-dependent
   normalisation, so the peak is not shifted).  The lines vote for f0 (f_i/h_i);
   the largest agreeing set is kept (a line pulled by a mode it is crossing is
   outvoted) and f0 is their weighted least-squares fit of f_i = h_i·f0, weights
   1/σ_i², σ_i ≈ 0.4·df/sqrt(n_channels·SNR_i).  Then each slice is fused with
   the leave-one-out quadratic prediction of its neighbours (inverse-variance
   mean, model error estimated from the data, outliers excluded), so slices
   whose lines are near the noise borrow from the smooth speed track while
   precise slices keep their own value.  How the speed was obtained and how
   well the lines agree with it (RMS of f_i/(h_i·f0) − 1) go to the test's
   ``meta["slicing"]["speed_scale"]``.
4. **Mean speed.**  The imbalance turns at exactly 1× the rotor: each slice's
   speed is the rise of the 1× line's angle over it (the radial pair as x + iy
   brought to 0 Hz along the track and low-passed;
   :func:`rwadist.slice_angle.angle_speeds`), its
   mean speed as a tach's mean is, where that reads better than the peaks --
   which read a run-up's slices high by ~(ΔΩ/Ω)²/20, as every line's amplitude
   grows across the slice.
5. **Sign.**  A spectrum sees only |Ω|.  For positive spin a rotating radial
   vector is Fx = A cos φ, Fy = A sin φ (counter-clockwise about +z), so Fy
   lags Fx by 90° and the cross-spectrum conj(X)·Y at the 1× line has phase
   -90°.  The sign of the speed is minus the sign of Im(conj(X)·Y), from the
   (Fx, Fy) pair, else (Tx, Ty); without either pair the speed is |Ω|.

Units: SI inside (rad/s for wheel speed, Hz for frequencies); rpm only in the
``rpm_range`` / ``min_speed_rpm`` arguments and in ``meta``.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import fft as sfft
from scipy import signal

from . import speed_scale as scale
from .data import TACH_COLUMN, DataError, Run, SteadyTest, Sweep
from .errors import RwadistError
from .slice_angle import angle_speeds
from .spectra import find_lines, noise_floor
from .units import RADIAL_PAIRS, rad_s_to_rpm, rpm_to_rad_s

#: Zero-padding factor of the slice periodograms (sub-bin sampling of the comb and the peaks).
PAD = 4
#: Slices of white noise used to calibrate the "no line" level of R (fixed seed: deterministic).
NOISE_CAL_SLICES = 48
NOISE_CAL_SEED = 20240611
#: Weight cap (SNR ratio) of one line in the least-squares refinement.
WEIGHT_CAP = 1.0e4
#: Relative tolerance within which two harmonic lines count as agreeing on f0 (0.05 %).
AGREE_REL = 5.0e-4
#: Neighbours (slices either side) of the continuity fusion of the speed track.
FUSE_HALF_WIDTH = 4
#: Automatic slice length: powers of two from AUTO_SLICE_MAX down to AUTO_SLICE_MIN samples ...
AUTO_SLICE_MAX = 8192
AUTO_SLICE_MIN = 1024
#: ... the longest over which the speed changes by at most this share of itself (median over the slices) ...
AUTO_SLICE_CHANGE = 0.05
#: ... and over whose Welch segments (a slice read in SEGMENTS_READ of them, ``rwadist.api.DIAGNOSE_SEGMENTS``) the
#: highest line of the speed scale sweeps by at most CHIRP_BINS of the segment's bins, in every slice: a line is
#: read in a window of ±LINE_HALF = 3 bins (:mod:`rwadist.diagnose.constants`) around its mean frequency, a Hann
#: main lobe is ±2 bins wide, so a chirp of c bins (±c/2) stays within the window for c <= 2(3 − 2) = 2.
SEGMENTS_READ = 4
CHIRP_BINS = 2.0
#: Default drop level: fraction of the largest |speed| found.
MIN_SPEED_FRACTION = 0.05
RADIAL = ("Fx", "Fy", "Tx", "Ty")


@dataclass
class SliceInfo:
    """One quasi-steady slice of a sweep.

    start, stop : sample indices into the sweep (stop exclusive).
    speed : wheel speed assigned to the slice, rad/s (signed when the tach or
        the x/y phase tells the sense; nan when no line was found in the data).
    speed_source : "tach" or "data".
    speed_spread : rad/s.  Tach: max - min of the tach over the slice.  Data:
        hypot(2·σ, ΔΩ), σ the standard error of the estimate and ΔΩ the change
        of the estimated speed track across the slice length.
    confidence : 0..1.  Tach: 1.  Data: comb-score margin of the chosen speed
        over the best candidate more than 5 % away, relative to its score.
    speed_stderr : rad/s, standard error of the slice's mean speed (0 for the tach;
        for data, from the scatter of the harmonic lines and the track fusion).
    """

    start: int
    stop: int
    speed: float
    speed_source: str
    speed_spread: float
    confidence: float
    speed_stderr: float = 0.0


# --------------------------------------------------------------------------- slicing

def _sweep_name(sweep: Sweep) -> str:
    if sweep.name:
        return sweep.name
    return str(sweep.meta.get("file", sweep.meta.get("source", "<sweep>"))) if sweep.meta else "<sweep>"


def _n_samples(sweep: Sweep) -> int:
    if not sweep.signals:
        raise DataError(_sweep_name(sweep), "signals", "the sweep has no channels")
    return len(next(iter(sweep.signals.values())))


def _slice_starts(sweep: Sweep, slice_samples: int, hop: int | None) -> tuple:
    """Start indices of the slices, and the hop (samples)."""
    slice_samples = int(slice_samples)
    if slice_samples < 16:
        raise ValueError(f"slice_samples must be >= 16, got {slice_samples!r}")
    hop = slice_samples if hop is None else int(hop)
    if hop < 1:
        raise ValueError(f"hop must be >= 1 sample, got {hop!r}")
    n = _n_samples(sweep)
    if n < slice_samples:
        raise DataError(_sweep_name(sweep), "samples",
                        f"{n} samples, shorter than one slice (slice_samples={slice_samples}); "
                        "pass a smaller slice_samples")
    return np.arange(0, n - slice_samples + 1, hop), hop


def _slices(x: np.ndarray, starts: np.ndarray, slice_samples: int) -> np.ndarray:
    """(n_slices, slice_samples) view of x."""
    view = np.lib.stride_tricks.sliding_window_view(np.asarray(x, dtype=float), slice_samples)
    return view[starts]


# --------------------------------------------------------------------------- speed from data

def _estimation_channels(sweep: Sweep, channels) -> tuple:
    if channels is not None:
        chans = tuple(channels)
        missing = [c for c in chans if c not in sweep.signals]
        if missing:
            raise DataError(_sweep_name(sweep), missing[0], f"channel not in the sweep (has {sweep.channels})")
        return chans
    chans = tuple(c for c in RADIAL if c in sweep.signals)
    return chans if chans else sweep.channels


def _snr_spectra(sweep: Sweep, starts, slice_samples: int, channels) -> tuple:
    """Zero-padded slice periodograms of ``channels``, combined without letting units dominate.

    Returns (f_pad Hz, P, F, df native Hz), P and F of shape (n_slices, n_f_pad):
    P = mean over channels of PSD_ch / m_ch, m_ch the slice's median noise floor of the channel
    (one number per channel and slice, so line shapes and peak positions are untouched), and
    F = the same combination of the local noise floors (:func:`rwadist.spectra.noise_floor`,
    linearly interpolated onto the padded grid).  P / F is a signal-to-noise ratio, 1 in noise.
    """
    fs = float(sweep.sample_rate)
    nfft = PAD * slice_samples
    win = signal.get_window("hann", slice_samples)
    scale = 2.0 / (fs * np.sum(win**2))
    f_pad = np.fft.rfftfreq(nfft, 1.0 / fs)
    f_nat = f_pad[::PAD]
    pos = np.arange(len(f_pad)) / PAD
    j0 = np.minimum(np.floor(pos).astype(int), len(f_nat) - 2)
    w = pos - j0
    P = np.zeros((len(starts), len(f_pad)))
    F = np.zeros_like(P)
    tiny = np.finfo(float).tiny
    for ch in channels:
        block = _slices(sweep.signals[ch], starts, slice_samples)
        block = (block - block.mean(axis=1, keepdims=True)) * win
        p = np.abs(sfft.rfft(block, n=nfft, axis=1)) ** 2 * scale
        floor = noise_floor(p[:, ::PAD], f_nat, dof=2.0)
        m = np.maximum(np.median(floor, axis=1, keepdims=True), tiny)
        P += p / m
        F += (floor[:, j0] * (1.0 - w) + floor[:, j0 + 1] * w) / m
    n = max(len(channels), 1)
    return f_pad, P / n, np.maximum(F / n, tiny), fs / slice_samples


def _noise_line_level(n_channels: int, slice_samples: int, fs: float) -> float:
    """Largest R = P/F that white noise reaches in ``NOISE_CAL_SLICES`` slices of the same length and number of
    channels (about its 98th percentile per slice): a slice whose largest R is below it shows no line."""
    rng = np.random.default_rng(NOISE_CAL_SEED)
    n = NOISE_CAL_SLICES * slice_samples
    names = tuple(f"noise{i}" for i in range(max(n_channels, 1)))
    fake = Sweep(time=np.arange(n) / fs, signals={c: rng.standard_normal(n) for c in names}, sample_rate=fs)
    starts = np.arange(NOISE_CAL_SLICES) * slice_samples
    f_pad, P, F, _ = _snr_spectra(fake, starts, slice_samples, names)
    return float(np.max(P[:, 1:-1] / F[:, 1:-1]))


def _refine(P_row, F_row, f_pad, f0: float, harmonics, df: float, threshold: float, n_channels: int = 1) -> tuple:
    """Weighted LS of f_h = h·f0 over the lines found near h·f0 (P_row, F_row from :func:`_snr_spectra`).

    Lines are found and their frequencies refined by :func:`rwadist.spectra.find_lines` on P_row
    (no frequency-dependent normalisation, so the log-parabolic peak is unbiased) against F_row.
    Returns (f0 Hz, standard error Hz, number of lines used, their f/(h·f0) − 1); f0 and its error nan
    when no line is found.
    """
    h_arr = np.asarray(harmonics, dtype=float)
    tol = max(df, 0.01 * f0)
    lo = max(h_arr.min() * f0 - tol - 2 * df, 0.0)
    hi = h_arr.max() * f0 + tol + 2 * df
    f_lines, idx = find_lines(P_row, f_pad, F_row, threshold, f_max=hi, f_min=lo)
    h_found, f_found, snr_found = [], [], []      # each harmonic found: h, its line's frequency (Hz) and SNR
    for h in h_arr:
        if f_lines.size == 0:
            break
        d = np.abs(f_lines - h * f0)
        i = int(np.argmin(d))
        if d[i] <= tol:
            h_found.append(h)
            f_found.append(f_lines[i])
            snr_found.append(P_row[idx[i]] / F_row[idx[i]])
    if not h_found:
        return float("nan"), float("nan"), 0, np.empty(0)
    hs, fk, snr = np.array(h_found), np.array(f_found), np.array(snr_found)
    # Cramér-Rao-like scatter of a line frequency: about 0.4·df/sqrt(SNR) (Hann, one segment), the
    # SNR of the channel average being n_channels times that of one channel
    sig = 0.4 * df / np.sqrt(n_channels * np.minimum(snr, WEIGHT_CAP))
    # Consensus: each line's f/h is a vote for f0; two lines agree within 3 combined σ plus
    # AGREE_REL (relative).  The kept set is the one agreeing with the line of largest support
    # (number of agreeing lines, then their SNR): a line pulled by a mode it crosses, or a noise peak
    # near a high harmonic (h² leverage), cannot set f0 against the others.
    r, sr = fk / hs, sig / hs
    agree = np.abs(r[:, None] - r[None, :]) <= 3.0 * np.hypot(sr[:, None], sr[None, :]) + AGREE_REL * r[:, None]
    support = agree.sum(axis=1) + (agree * np.minimum(snr, WEIGHT_CAP)[None, :]).sum(axis=1) / (
        2.0 * len(hs) * WEIGHT_CAP)
    keep = agree[int(np.argmax(support))]
    w = keep / sig**2
    f_est = np.sum(w * hs * fk) / np.sum(w * hs**2)
    stderr = 1.0 / np.sqrt(np.sum(w * hs**2))
    n_used = int(keep.sum())
    if n_used > 1:
        resid = (fk - hs * f_est)[keep]
        chi2 = np.sum(w[keep] * resid**2) / (n_used - 1)
        stderr *= np.sqrt(max(chi2, 1.0))
    return float(f_est), float(stderr), n_used, (fk / (hs * f_est) - 1.0)[keep]


def _predict_from_neighbours(f0, sigma, usable, half_width: int) -> tuple:
    """Leave-one-out prediction of every slice from a weighted quadratic (in slice index) through
    the ``usable`` slices within ``half_width`` either side.  Returns (prediction, its variance), Hz."""
    n = len(f0)
    pred = np.full(n, np.nan)
    pvar = np.full(n, np.nan)
    use = np.nonzero(usable)[0]
    for i in np.nonzero(np.isfinite(f0))[0]:
        j = use[(np.abs(use - i) <= half_width) & (use != i)]
        if len(j) < 4 or not (j.min() < i < j.max()) and len(j) < 6:
            continue
        x = (j - i).astype(float)
        A = np.stack([np.ones_like(x), x, x * x], axis=1)
        w = 1.0 / sigma[j] ** 2
        cov = np.linalg.inv(A.T @ (A * w[:, None]))
        pred[i], pvar[i] = (cov @ (A.T @ (w * f0[j])))[0], cov[0, 0]
    return pred, pvar


#: A slice's speed more than this share off the track its neighbours predict (and 4 combined standard errors) is a
#: line of another ratio taken for 1x there, not the rotor's speed (the rotor cannot jump so between two slices): the
#: session-55 trial's 4.5 kg wheel swept 500 -> 7500 rpm in 90 s without a speed column read its cage line (h 0.41) as
#: 1x in two slices at ~500 rpm (1244 and 1299 rpm), and those two slices' jumps set the slice-length rule's chirp
#: (50 bins at 8192 samples): 2048-sample slices were cut, the band started at 54.7 Hz, counter-rotating torque
#: lines and an Ω^2.06 law were fitted
OFF_TRACK_REL = 0.2


def _fuse_track(f0: np.ndarray, sigma: np.ndarray, half_width: int = FUSE_HALF_WIDTH) -> tuple:
    """Combine each slice's estimate with the prediction of its neighbours (continuity).

    For every slice with an estimate, a quadratic in slice index is fitted by weighted least squares
    (weights 1/σ²) to the estimates of the detected neighbours within ``half_width`` slices, the
    slice itself left out (an extrapolation needs 6 neighbours); its value at the slice is the
    prediction p (variance v).  Slices more than 4 combined σ from their prediction are not used
    as neighbours in a second pass (a mis-picked line must not bend the track of the others).  The
    model error m of the prediction is estimated from the data (robust method of moments on the
    residuals, relative to f0), and each slice's value becomes the inverse-variance mean of its
    own estimate (σ²) and p (v + m²f0²); an outlier keeps its own value.  Precise slices keep
    their value; noisy ones (the wheel slow, its lines near the noise) borrow from the track.  A slice off the
    track (:func:`_off_track`) gets σ = ∞: a mis-picked line, no speed.
    Returns (f0, σ) fused, Hz.
    """
    off = _off_track(f0, half_width)
    good = np.isfinite(f0) & np.isfinite(sigma) & (sigma > 0) & ~off
    pred, pvar = _predict_from_neighbours(f0, sigma, good, half_width)
    have = np.isfinite(pred)
    outlier = np.zeros(len(f0), dtype=bool)
    outlier[have] = np.abs(f0[have] - pred[have]) > 4.0 * np.sqrt(sigma[have] ** 2 + pvar[have])
    if outlier.any():
        pred, pvar = _predict_from_neighbours(f0, sigma, good & ~outlier, half_width)
        have = np.isfinite(pred)
    if have.sum() < 3:
        return f0, np.where(off, np.inf, sigma)
    r = f0[have] - pred[have]
    excess = (r**2 - sigma[have] ** 2 - pvar[have]) / f0[have] ** 2
    m_rel2 = max(float(np.median(excess[~outlier[have]])) if (~outlier[have]).any() else 0.0, 0.0)
    vp = pvar[have] + m_rel2 * f0[have] ** 2
    ok = np.abs(r) <= 4.0 * np.sqrt(sigma[have] ** 2 + vp)
    w_own, w_pred = 1.0 / sigma[have] ** 2, np.where(ok, 1.0 / vp, 0.0)
    out_f, out_s = f0.copy(), sigma.copy()
    out_f[have] = (w_own * f0[have] + w_pred * pred[have]) / (w_own + w_pred)
    out_s[have] = 1.0 / np.sqrt(w_own + w_pred)
    # far off the track: another line taken for 1x in that slice; its speed is not known (the slice is dropped as
    # uncertain, :func:`slice_sweep`, and no slice-length rule reads it)
    out_s[off] = np.inf
    return out_f, out_s


def _off_track(f0: np.ndarray, half_width: int) -> np.ndarray:
    """Bool per slice: its estimate ``f0`` (Hz) lies more than :data:`OFF_TRACK_REL` off the Theil-Sen line through
    its neighbours' within ``half_width`` slices (twice as far on the one side at an end of the sweep, where the
    slowest slices are: 4 neighbours at least).  Robust to a neighbour off the track too (the trial's two first
    slices both read the cage as 1x), which the weighted quadratic of :func:`_predict_from_neighbours`, fitted
    through them, is not."""
    from scipy.stats import theilslopes

    found = np.isfinite(f0) & (f0 > 0)
    off = np.zeros(f0.size, bool)
    for _ in range(2):
        # the second pass reads each slice against the neighbours the first found on the track: two slices off it
        # beside a third leave its Theil-Sen line with a third of its points wrong
        idx = np.flatnonzero(found & ~off)
        new = np.zeros(f0.size, bool)
        for i in np.flatnonzero(found):
            j = idx[(np.abs(idx - i) <= half_width) & (idx != i)]
            if j.size and not (j.min() < i < j.max()):
                j = idx[(np.abs(idx - i) <= 2 * half_width) & (idx != i)]
            if j.size < 4:
                continue
            slope, icpt = theilslopes(f0[j], j)[:2]
            p = icpt + slope * i
            new[i] = bool(p > 0 and abs(f0[i] / p - 1.0) > OFF_TRACK_REL)
        off = new
    return off


def _rotation_sign(sweep: Sweep, starts, slice_samples: int, f1: np.ndarray) -> np.ndarray:
    """+1 / -1 per slice from the phase of Y against X at the 1× line (f1 Hz); +1 if no x/y pair."""
    pair = next(((x, y) for x, y in RADIAL_PAIRS if x in sweep.signals and y in sweep.signals), None)
    sign = np.ones(len(starts))
    ok = np.isfinite(f1) & (f1 > 0)
    if pair is None or not ok.any():
        return sign
    fs = float(sweep.sample_rate)
    win = signal.get_window("hann", slice_samples)
    n = np.arange(slice_samples)
    st = starts[ok]
    phasor = np.exp(-2j * np.pi * np.outer(f1[ok] / fs, n)) * win        # (n_ok, N)
    X, Y = (np.sum(_slices(sweep.signals[c], st, slice_samples) * phasor, axis=1) for c in pair)
    im = np.imag(np.conj(X) * Y)
    sign[ok] = np.where(im > 0, -1.0, 1.0)
    return sign


def estimate_speeds(sweep: Sweep, slice_samples: int = 8192, hop: int | None = None, channels=None,
                    rpm_range=None) -> list:
    """Wheel speed of every slice of ``sweep`` from the data alone (the tach is ignored).

    slice_samples : samples per slice; hop : samples between slice starts (default slice_samples).
    channels : channels whose lines are followed (default the radial ones present, Fx Fy Tx Ty, with Fz;
        else all); the rotation senses are read from the Fx/Fy and Tx/Ty pairs present.
    rpm_range : (lo, hi) |speed| range, rpm: a 1× line whose speed track falls outside it is not taken.
    Returns one :class:`SliceInfo` per slice in time order; speed rad/s (signed by the x/y phase),
    nan where the slice shows no line above its noise (confidence 0).  How the speed scale was found:
    :func:`estimate_speed_track`.
    """
    return estimate_speed_track(sweep, slice_samples, hop, channels, rpm_range)[0]


def _track_channels(sweep: Sweep, channels) -> tuple:
    if channels is not None:
        return _estimation_channels(sweep, channels)
    chans = tuple(c for c in RADIAL + ("Fz",) if c in sweep.signals)
    return chans if chans else sweep.channels


def _complex_spectra(sweep: Sweep, starts, slice_samples: int) -> dict:
    """Zero-padded (``PAD``) Hann-windowed complex spectra of the slices of each radial channel present."""
    win = signal.get_window("hann", slice_samples)
    out = {}
    for c in RADIAL:
        if c in sweep.signals:
            block = _slices(sweep.signals[c], starts, slice_samples)
            out[c] = sfft.rfft((block - block.mean(axis=1, keepdims=True)) * win, n=PAD * slice_samples, axis=1)
    return out


#: a template line found in fewer slices than :data:`rwadist.speed_scale.PRESENCE` asks is sought again at the order its
#: own finds give when it was found in this many slices at least (:func:`_found_again`)
FOUND_AGAIN_MIN = 3


def _found_again(P, F, f_pad, f_lines, f_meas, orders0, keep, threshold: float, df: float, f_lo: float, f_hi: float):
    """``f_meas`` (n_slices, n_lines) Hz (the template's lines, at orders ``orders0``) with each line not kept
    (``keep`` False) but found in :data:`FOUND_AGAIN_MIN` slices or more measured again where its own finds put it:
    at the median over those slices of its frequency over the slice's scale (the kept lines' frequencies over their
    orders, :func:`rwadist.speed_scale.line_orders`), times each slice's scale.

    The template's peak is read on the slices' clipped, smeared log content; a line's peak there can lie off the line
    by more than the 1.5 native bins :func:`rwadist.speed_scale.measured_lines` looks within at the fast slices (the
    session-69 trial's 60-s run-up 500 -> 9000 rpm: the 1x peak 1.7 % high, the 3.62 line's 0.7 %, found below 3450
    rpm only, in 27 of 58 slices, and left out of the ratios though the wheel has it in every direction)."""
    redo = ~keep & (np.sum(np.isfinite(f_meas), axis=0) >= FOUND_AGAIN_MIN)
    if not keep.any() or not redo.any():
        return f_meas
    import warnings

    orders = scale.line_orders(f_meas[:, keep], orders0[keep])
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)                   # slices or lines without a find: nan
        c = np.nanmedian(f_meas[:, keep] / orders[None, :], axis=1)
        own = np.nanmedian(f_meas[:, redo] / c[:, None], axis=0)
    guess = np.where(np.isfinite(c)[:, None], own[None, :] * c[:, None], f_lines[:, redo])
    guess = np.where(np.isfinite(f_lines[:, redo]) & (guess >= f_lo) & (guess <= f_hi), guess, np.nan)
    out = f_meas.copy()
    out[:, redo] = scale.measured_lines(P, F, f_pad, guess, threshold, df)
    return out


def _scale_lines(sweep, starts, slice_samples, f_pad, P, F, df, active, rpm_range, threshold) -> tuple:
    """The line pattern's relative track and the 1× line (:mod:`rwadist.speed_scale`): (rough rotor frequency
    per slice Hz (nan where inactive), ratios of the lines found, SpeedScale without agreement)."""
    fs = float(sweep.sample_rate)
    f_lo, f_hi = 2.0 * df, 0.98 * fs / 2.0
    u, L = scale.log_content(P / F, f_pad, f_lo, f_hi)
    shifts = scale.relative_track(L, u, active)
    o, T = scale.template(L, shifts, u)
    o_lines, strength = scale.template_lines(o, T)
    if o_lines.size == 0:
        return np.full(len(starts), np.nan), np.array([1.0]), None
    f_lines = np.exp(o_lines[None, :] + shifts[:, None])
    f_lines = np.where((f_lines >= f_lo) & (f_lines <= f_hi), f_lines, np.nan)
    f_meas = scale.measured_lines(P, F, f_pad, f_lines, threshold, df)
    # a line of the wheel is found where the pattern puts it in most slices; a bump of the template left by
    # content at a fixed frequency crossing it is not
    keep = np.sum(np.isfinite(f_meas), axis=0) >= scale.PRESENCE * np.sum(np.isfinite(f_lines), axis=0)
    f_meas = _found_again(P, F, f_pad, f_lines, f_meas, np.exp(o_lines), keep, threshold, df, f_lo, f_hi)
    keep = np.sum(np.isfinite(f_meas), axis=0) >= scale.PRESENCE * np.sum(np.isfinite(f_lines), axis=0)
    if not keep.any():
        return np.full(len(starts), np.nan), np.array([1.0]), None
    o_lines, strength, f_lines, f_meas = o_lines[keep], strength[keep], f_lines[:, keep], f_meas[:, keep]
    orders = scale.line_orders(f_meas, np.exp(o_lines))
    f_lines = np.where(np.isfinite(f_meas), f_meas, f_lines)
    senses = scale.pair_senses(_complex_spectra(sweep, starts, slice_samples), f_pad, PAD, f_lines)
    if rpm_range is not None:
        lo, hi = sorted(abs(float(v)) / 60.0 for v in rpm_range)
        med = np.nanmedian(np.exp(shifts))
        inside = (orders * med >= lo) & (orders * med <= hi)
        strength = np.where(inside, strength, 0.0)
    best, sense, evidence, reason = scale.imbalance_line(orders, strength, senses)
    ratios = orders / orders[best]
    f1 = np.exp(shifts) * orders[best]
    order = np.argsort(ratios)
    share = [senses[k][0][order] if k in senses else np.full(ratios.size, np.nan) for k in ("F", "T")]
    spd = scale.SpeedScale(method=f"speed from the data: {reason}; {ratios.size} lines, each at its own ratio",
                           ratios=tuple(ratios[order]), one_x=evidence, sense=sense, n_lines=int(ratios.size),
                           senses=tuple(zip(*share)))
    return f1, ratios, spd


def estimate_speed_track(sweep: Sweep, slice_samples: int = 8192, hop: int | None = None, channels=None,
                         rpm_range=None) -> tuple:
    """(:func:`estimate_speeds`'s infos, :class:`rwadist.speed_scale.SpeedScale` or None when no line was found):
    the speed of every slice from the data alone, and how it was obtained (module docstring, steps 1-3)."""
    starts, hop = _slice_starts(sweep, slice_samples, hop)
    chans = _track_channels(sweep, channels)
    fs = float(sweep.sample_rate)
    f_pad, P, F, df = _snr_spectra(sweep, starts, slice_samples, chans)
    active = (P / F)[:, PAD:-PAD].max(axis=1) > _noise_line_level(len(chans), slice_samples, fs)
    n_s = len(starts)
    f0 = np.full(n_s, np.nan)
    sigma = np.full(n_s, np.nan)
    conf = np.zeros(n_s)
    spd = None
    if active.any():
        threshold = 1.0 + 4.0 / np.sqrt(len(chans))    # ~ 4 sigma of a noise-normalised averaged PSD bin
        f1, ratios, spd = _scale_lines(sweep, starts, slice_samples, f_pad, P, F, df, active, rpm_range, threshold)
        resid = []
        for s in np.flatnonzero(active & np.isfinite(f1)):
            f0[s], sigma[s], n_used, r = _refine(P[s], F[s], f_pad, f1[s], ratios, df, threshold, len(chans))
            in_band = np.sum((ratios * f1[s] >= 2 * df) & (ratios * f1[s] <= 0.98 * fs / 2))
            conf[s] = n_used / max(int(in_band), 1)
            resid.append(r)
        if spd is not None:
            allr = np.concatenate(resid) if resid else np.empty(0)
            spd = replace(spd, agreement=float(np.sqrt(np.mean(allr**2))) if allr.size else float("nan"))
    f0, sigma = _fuse_track(f0, sigma)
    sign = _rotation_sign(sweep, starts, slice_samples, f0)
    omega = sign * 2.0 * np.pi * f0
    if spd is not None and np.isfinite(omega).any():
        spd = replace(spd, sense=float(np.sign(np.nanmedian(omega)) or 1.0))
    # change of the speed track across one slice (finite differences over detected neighbours)
    grad = np.full(n_s, np.nan)
    good = np.isfinite(f0)
    if good.sum() >= 2:
        idx = np.nonzero(good)[0]
        grad[idx] = np.abs(np.gradient(2.0 * np.pi * f0[idx], idx))
    drift = np.nan_to_num(grad) * (slice_samples / hop)
    # the track's rate (Hz/s, signed: |f| rising or falling) over each slice, for reading the 1x line's angle
    rate = np.full(n_s, np.nan)
    if good.sum() >= 2:
        rate[idx] = np.gradient(f0[idx], idx) * fs / hop
    f0, sigma = angle_speeds(sweep, starts, slice_samples, f0, sigma, sign, rate,
                              ratios if spd is not None else ())
    omega = sign * 2.0 * np.pi * f0
    spread = np.hypot(2.0 * 2.0 * np.pi * sigma, drift)
    infos = [SliceInfo(start=int(st), stop=int(st + slice_samples), speed=float(omega[i]), speed_source="data",
                       speed_spread=float(spread[i]), confidence=float(np.clip(conf[i], 0.0, 1.0)),
                       speed_stderr=float(2.0 * np.pi * sigma[i]))
             for i, st in enumerate(starts)]
    return infos, spd


# --------------------------------------------------------------------------- slicing into a steady test

def speed_note(slicing: dict) -> str:
    """One line for the console: how the slices' speeds were obtained (``test.meta["slicing"]``), and for a speed
    from the data, which line is 1× and how well the lines agree with it."""
    n = slicing.get("n_kept", 0)
    if slicing.get("speed_source") != "data":
        return f"sliced sweep into {n} quasi-steady runs (speed from the tach column)"
    sc = slicing.get("speed_scale") or {}
    agree = sc.get("agreement_rel_rms")
    text = f"sliced sweep into {n} quasi-steady runs; {sc.get('method', 'speed from the data')}"
    if agree is not None:
        text += (f"; ratios {', '.join(f'{h:.4g}' for h in sc.get('ratios', []))}; the lines agree with the speed "
                 f"to {100 * agree:.3f} % RMS")
    return text


def _tach_infos(sweep: Sweep, starts, slice_samples: int) -> list:
    if sweep.tach is None:
        raise DataError(_sweep_name(sweep), TACH_COLUMN,
                        "`speed_source` tach, but the sweep has no tach column: give `speed_source` data (the speed "
                        "estimated from the lines) or auto")
    tach = np.asarray(sweep.tach, dtype=float)
    if len(tach) != _n_samples(sweep):
        raise DataError(_sweep_name(sweep), TACH_COLUMN,
                        f"{len(tach)} tach samples for {_n_samples(sweep)} data samples")
    block = _slices(tach, starts, slice_samples)
    mean, spread = block.mean(axis=1), block.max(axis=1) - block.min(axis=1)
    return [SliceInfo(int(st), int(st + slice_samples), float(mean[i]), "tach", float(spread[i]), 1.0)
            for i, st in enumerate(starts)]


def _slice_chirp(infos: list, fs: float, h_max: float) -> float:
    """Largest over the slices with a speed of the sweep, in bins, of the line h_max across one of the
    :data:`SEGMENTS_READ` Welch segments of a slice: h_max·|dΩ/dt|·L²/(2π), L = T/SEGMENTS_READ seconds (the line
    moves h_max·|dΩ/dt|·L/(2π) Hz over the segment, its bin is 1/L Hz); dΩ/dt from the slices' speeds against
    their centre times (rad/s²), the slices with a known speed (a finite standard error: :func:`_fuse_track`).  0 with
    fewer than 3 such slices."""
    t = np.array([0.5 * (i.start + i.stop) / fs for i in infos])
    w = np.array([i.speed for i in infos])
    ok = np.isfinite(w) & (w != 0) & np.isfinite([i.speed_stderr for i in infos])
    if ok.sum() < 3 or not np.isfinite(h_max):
        return 0.0
    seg = (infos[0].stop - infos[0].start) / fs / SEGMENTS_READ
    return float(np.max(h_max * np.abs(np.gradient(w[ok], t[ok])) * seg**2 / (2 * np.pi)))


def _slice_change(infos: list, fs: float) -> float:
    """Median over the slices with a speed of |dΩ/dt|·T/|Ω|: the share by which the speed changes across one
    slice of T seconds (dΩ/dt from the slices' speeds against their centre times)."""
    t = np.array([0.5 * (i.start + i.stop) / fs for i in infos])
    w = np.array([i.speed for i in infos])
    ok = np.isfinite(w) & (w != 0) & np.isfinite([i.speed_stderr for i in infos])
    if ok.sum() < 3:
        return 0.0
    rate = np.abs(np.gradient(w[ok], t[ok]))
    return float(np.median(rate * (infos[0].stop - infos[0].start) / fs / np.abs(w[ok])))


def _speed_infos(sweep, slice_samples, hop, source, channels) -> tuple:
    """(slice starts, hop, infos, SpeedScale or None) at one slice length."""
    starts, hop = _slice_starts(sweep, slice_samples, hop)
    if source == "tach":
        return starts, hop, _tach_infos(sweep, starts, slice_samples), None
    infos, spd = estimate_speed_track(sweep, slice_samples, hop, channels=channels)
    return starts, hop, infos, spd


def _tach_line_reach(sweep, slice_samples: int, channels) -> float:
    """The highest line ratio h of a sweep read with its tach: the speed scale's lines (:func:`estimate_speed_track`
    at ``slice_samples``: the data's own lines, read as they are with no speed given), or nan when it finds none.
    A tach gives the speed, not how far up the lines reach, and the chirp of the highest line bounds the slice as
    without it (:func:`_auto_slices`): a new user's 40-s run-up 300 -> 6000 rpm, fastest at its start, was cut into
    8192-sample slices with its tach (0.9 % median change) and into 2048 without it; with the tach the rocking mode
    came out 3.5 % low, a spin acceleration and a line were invented, and the error was 48 times the same data's
    without it."""
    try:
        spd = estimate_speed_track(sweep, slice_samples, None, channels=channels)[1]
    except RwadistError:
        return float("nan")
    return max(spd.ratios) if spd is not None and spd.ratios else float("nan")


def _auto_slices(sweep, source, channels) -> tuple:
    """The longest power-of-two slice (AUTO_SLICE_MAX down to AUTO_SLICE_MIN samples, and at most an eighth of
    the record) over which the speed changes by at most AUTO_SLICE_CHANGE of itself (median over the slices) and
    over whose Welch segments the highest line of the speed scale (with a tach: :func:`_tach_line_reach`) sweeps by at most
    CHIRP_BINS bins in every slice (:func:`_slice_chirp`: a median over the slices does not see the fast part of a
    motor's exponential run-up, which spends most of its time near the top speed; family wheel 2, 300 -> 3000 rpm
    in 300 s, e^(−t/75 s): 0.8 % change at 8192 samples, but h 9.14 swept 5.6 bins per segment in the first slices,
    and the rocking mode came out 12 % low): (slice_samples, starts, hop, infos, SpeedScale, rule text)."""
    n_total = _n_samples(sweep)
    fs = float(sweep.sample_rate)
    n = int(min(AUTO_SLICE_MAX, max(2 ** int(np.floor(np.log2(max(n_total // 8, 1)))), AUTO_SLICE_MIN)))
    tried = []
    reach = _tach_line_reach(sweep, n, channels) if source == "tach" else float("nan")
    while True:
        starts, hop, infos, spd = _speed_infos(sweep, n, None, source, channels)
        change = _slice_change(infos, fs)
        h_max = max(spd.ratios) if spd is not None and spd.ratios else reach
        chirp = _slice_chirp(infos, fs, h_max)
        tried.append(f"{n} samples: {100 * change:.1f} %" + (f", chirp {chirp:.2f} bins" if np.isfinite(h_max) else ""))
        if (change <= AUTO_SLICE_CHANGE and chirp <= CHIRP_BINS) or n // 2 < AUTO_SLICE_MIN:
            rule = (f"auto: the longest slice (<= {AUTO_SLICE_MAX} samples) over which the speed changes by <= "
                    f"{100 * AUTO_SLICE_CHANGE:g} % (median over the slices) and the highest line sweeps <= "
                    f"{CHIRP_BINS:g} bins of a 1/{SEGMENTS_READ}-slice segment (every slice); " + "; ".join(tried))
            return n, starts, hop, infos, spd, rule
        n //= 2


def slice_sweep(sweep: Sweep, slice_samples: int | None = None, hop: int | None = None, speed_source: str = "auto",
                min_speed_rpm: float | None = None, channels=None, max_speed_error: float = 0.005) -> tuple:
    """Cut ``sweep`` into quasi-steady slices: a :class:`SteadyTest` plus one :class:`SliceInfo` per run.

    slice_samples, hop : samples per slice and between slice starts (default hop = slice_samples,
        non-overlapping, as the thesis).  slice_samples None (default): the longest power of two up to
        8192 samples (the thesis's) over which the speed changes by at most 5 % of itself (median over the
        slices): a fast sweep's lines are smeared over a long slice and their peaks pulled (a 30-s run-up
        300 -> 3000 rpm at 3840 Hz in 8192-sample slices put h = 3 at 3.04, with the tach too); also short
        enough that the highest line sweeps at most CHIRP_BINS bins of a quarter-slice Welch segment in every
        slice (:func:`_auto_slices`; with the speed from the data or from the tach alike).
    speed_source : "auto" (tach if the sweep has one, else data), "tach" (mean of the tach over
        the slice; DataError naming ``speed_rpm`` without one) or "data" (:func:`estimate_speeds`).
    min_speed_rpm : slices with |speed| below this (rpm) are dropped; default 5 % of the largest
        |speed| found.  Slices where the data show no line (speed nan) are dropped too.
    channels : channels used to estimate the speed from data (default radial); the runs always
        carry every channel of the sweep.
    max_speed_error : relative; a slice whose speed comes from data is dropped when three
        standard errors of its speed exceed this fraction of it (default 0.5 %: at the
        lowest speeds the lines are too close to the noise to place the speed better).
    Each kept slice becomes a :class:`Run` named ``slice_NNNN.csv`` (NNNN its index in time order),
    t0 = time of its first sample, speed rad/s.  Runs are sorted by speed (:meth:`SteadyTest.sorted`)
    and the returned infos are in the same order.  ``test.meta`` carries the sweep's meta plus
    ``"slicing"``: slice length, hop, source, counts and the minimum speed used.
    """
    if speed_source not in ("auto", "tach", "data"):
        raise ValueError(f"speed_source must be 'auto', 'tach' or 'data', got {speed_source!r}")
    source = ("tach" if sweep.tach is not None else "data") if speed_source == "auto" else speed_source
    if source == "tach" and sweep.tach is None:
        raise DataError(_sweep_name(sweep), TACH_COLUMN,
                        "`speed_source` tach, but the sweep has no tach column: give `speed_source` data (the speed "
                        "estimated from the lines) or auto")
    if slice_samples is None:
        slice_samples, starts, hop, infos, spd, rule = _auto_slices(sweep, source, channels)
    else:
        starts, hop, infos, spd = _speed_infos(sweep, slice_samples, hop, source, channels)
        rule = "given"
    speeds = np.array([i.speed for i in infos])
    found = np.isfinite(speeds)
    if min_speed_rpm is None:
        top = float(np.abs(speeds[found]).max()) if found.any() else 0.0
        min_speed = MIN_SPEED_FRACTION * top
    else:
        min_speed = float(rpm_to_rad_s(abs(float(min_speed_rpm))))
    fast = found & (np.abs(np.where(found, speeds, 0.0)) >= min_speed)
    stderr = np.array([i.speed_stderr for i in infos])
    with np.errstate(invalid="ignore", divide="ignore"):
        certain = ~(3.0 * stderr > max_speed_error * np.abs(speeds))
    keep = fast & certain
    fs = float(sweep.sample_rate)
    time = np.asarray(sweep.time, dtype=float)
    runs = []
    kept = np.nonzero(keep)[0]
    for i in kept:
        a, b = infos[i].start, infos[i].stop
        runs.append(Run(speed=float(speeds[i]), sample_rate=fs,
                        signals={ch: np.array(sweep.signals[ch][a:b]) for ch in sweep.channels},
                        t0=float(time[a]), name=f"slice_{i:04d}.csv"))
    meta = {k: v for k, v in (sweep.meta or {}).items()}
    meta["slicing"] = {
        "slice_samples": int(slice_samples),
        "slice_rule": rule,
        "hop_samples": int(hop),
        "slice_duration_s": slice_samples / fs,
        "speed_source": source,
        "n_slices": int(len(infos)),
        "n_kept": int(len(kept)),
        "n_dropped": int(len(infos) - len(kept)),
        "n_dropped_no_line": int((~found).sum()),
        "n_dropped_slow": int((found & ~fast).sum()),
        "n_dropped_uncertain": int((fast & ~certain).sum()),
        "max_speed_error": float(max_speed_error),
        "min_speed_rpm": float(rad_s_to_rpm(min_speed)),
        "min_speed_rule": ("given" if min_speed_rpm is not None
                           else f"{MIN_SPEED_FRACTION:g} x largest |speed| found"),
        "dropped_slices": [int(i) for i in np.nonzero(~keep)[0]],
    }
    if source == "data":
        meta["slicing"]["speed_scale"] = (spd.to_meta() if spd is not None else
                                          {"method": "speed from the data: no line above the noise in any slice"})
    order = np.argsort(speeds[kept], kind="stable")
    # how far the speed moves within each kept slice (in the runs' order): a line is smeared over h × that, which no
    # finer feature of the slice's spectrum (a sideband closer to its carrier) can be told from
    meta["slicing"]["speed_spread_rpm"] = [float(rad_s_to_rpm(infos[kept[k]].speed_spread)) for k in order]
    test = SteadyTest([runs[k] for k in order], meta)
    return test, [infos[kept[k]] for k in order]
