"""Spectra of steady-state runs: Welch PSDs, amplitude spectra, RMS, peaks.

Conventions (``docs/formats.md``): PSDs are one-sided, unit²/Hz, Welch
with a Hann window; their integral over frequency is the mean square.
Amplitude spectra read the peak amplitude of a sinusoid centred on a bin
(``sqrt(2 * power spectrum)``); between bins a Hann window reads up to 15 %
low, which is why line amplitudes are measured by :func:`line_amplitude`
(the power under the line, window-independent by Parseval) instead.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage, signal, stats

from .data import DataError, SteadyTest
from .units import CHANNELS


@dataclass
class Spectra:
    """PSDs and amplitude spectra of every run and channel (the waterfall).

    f : frequencies, Hz (n_f).
    speed : wheel speed of each run, rad/s (n_runs).
    psd : channel -> (n_runs, n_f) one-sided PSD, unit²/Hz; a row of NaN where
        the run lacks the channel.
    amplitude : channel -> (n_runs, n_f) amplitude spectrum, unit.
    sample_rate : Hz.  nperseg : FFT length.  n_segments : Welch averages per run.
    window : window name.  f_lim : upper limit of good data, Hz (None: Nyquist).
    run_names : source file of each run.
    """

    f: np.ndarray
    speed: np.ndarray
    psd: dict
    amplitude: dict
    sample_rate: float
    nperseg: int
    n_segments: np.ndarray
    window: str = "hann"
    f_lim: float | None = None
    run_names: list = field(default_factory=list)

    @property
    def df(self) -> float:
        """Frequency resolution, Hz."""
        return self.sample_rate / self.nperseg

    @property
    def channels(self) -> tuple:
        return tuple(ch for ch in CHANNELS if ch in self.psd)

    @property
    def band_limit(self) -> float:
        """Upper limit of usable data, Hz: f_lim, or Nyquist."""
        return float(self.f_lim) if self.f_lim is not None else self.sample_rate / 2.0

    def available(self, channel: str) -> np.ndarray:
        """Boolean per run: the run has this channel."""
        return np.isfinite(self.psd[channel][:, 0])


def _default_nperseg(n_min: int) -> int:
    return int(2 ** np.floor(np.log2(n_min)))


def compute_spectra(test: SteadyTest, nperseg: int | None = None, overlap: float = 0.5,
                    window: str = "hann", f_lim: float | None = None, channels=None) -> Spectra:
    """Welch PSDs and amplitude spectra of every run of ``test``.

    Parameters
    ----------
    nperseg : FFT segment length; default the largest power of two that fits
        in the typical (median-length) run -- one segment, the finest resolution,
        as the thesis did for the E wheel.  A run shorter than that is an error
        naming the run, not a reason to coarsen every spectrum.
    overlap : fraction of segment overlap.
    f_lim : upper frequency limit of good data, Hz (e.g. below a test-stand
        resonance); stored, applied by the fit.
    """
    if not test.runs:
        raise DataError("<test>", "runs", "no runs to analyse")
    rates = np.array([r.sample_rate for r in test.runs])
    if np.any(np.abs(rates - rates[0]) > 1e-9 * rates[0]):
        i = int(np.argmax(np.abs(rates - rates[0])))
        raise DataError(test.runs[i].name, "sample_rate", f"{rates[i]!r} Hz differs from the first run's "
                        f"{rates[0]!r} Hz; resample to one rate first")
    fs = float(rates[0])
    lengths = np.array([r.n_samples for r in test.runs])
    if nperseg is None:
        nperseg = _default_nperseg(int(np.median(lengths)))
    short = np.nonzero(lengths < nperseg)[0]
    if short.size:
        r = test.runs[short[0]]
        raise DataError(r.name or f"run {short[0]}", "samples",
                        f"{r.n_samples} samples, shorter than one FFT segment ({nperseg}); drop the run or record longer "
                        "runs")
    if f_lim is not None and not (0 < f_lim <= fs / 2):
        raise DataError("<spectra>", "f_lim", f"{f_lim!r} Hz is outside (0, Nyquist={fs / 2:g}]")
    # a channel left out of every run (Run.invalid in each: a dropout, a distorted signal chain) is as one the test
    # lacks: its rows would be NaN in every run, which no step reads
    channels = (tuple(channels) if channels is not None else
                tuple(ch for ch in test.channels if any(r.usable(ch) for r in test.runs)))
    noverlap = int(round(overlap * nperseg))
    win = signal.get_window(window, nperseg)
    # density -> "spectrum" (power of a sinusoid) scaling, as scipy defines both.
    to_power = fs * np.sum(win**2) / np.sum(win) ** 2
    n_f = nperseg // 2 + 1
    f = np.fft.rfftfreq(nperseg, 1.0 / fs)
    psd = {ch: np.full((len(test.runs), n_f), np.nan) for ch in channels}
    step = nperseg - noverlap
    n_segments = 1 + (lengths - nperseg) // step
    for n in np.unique(lengths):
        idx = np.nonzero(lengths == n)[0]
        for ch in channels:
            # a channel that froze in a run (Run.invalid, rwadist.data_quality) is left out of it, as an absent one
            have = [i for i in idx if ch in test.runs[i].signals and ch not in test.runs[i].invalid]
            if not have:
                continue
            block = np.stack([test.runs[i].signals[ch] for i in have])
            psd[ch][have] = welch_psd(block, fs, win, noverlap)
    amplitude = {ch: np.sqrt(2.0 * psd[ch] * to_power) for ch in channels}
    return Spectra(f=f, speed=test.speeds, psd=psd, amplitude=amplitude, sample_rate=fs,
                   nperseg=nperseg, n_segments=n_segments, window=window, f_lim=f_lim,
                   run_names=[r.name for r in test.runs])


#: samples (rows × segments × segment length) of the detrended segments :func:`welch_psd` holds at once (64 MB)
WELCH_BLOCK = 1 << 23


def welch_psd(x: np.ndarray, fs: float, win: np.ndarray, noverlap: int) -> np.ndarray:
    """Welch PSD (one-sided, density, unit²/Hz) of the rows of ``x`` (R, n): the numbers of
    ``scipy.signal.welch(x, fs, window=win, nperseg=win.size, noverlap=noverlap, detrend="constant",
    scaling="density")``, computed the way that function does (:class:`scipy.signal.ShortTimeFFT` with the same
    window scaling, each segment's mean taken off, the squared magnitude doubled off DC and Nyquist, the mean over
    segments in the same memory order) but with every segment of a block of rows transformed in one call instead of
    one segment position at a time.

    Parameters
    ----------
    x : numpy.ndarray
        (R, n) real records, n ≥ ``win.size``.
    fs : float
        Sample rate, Hz.
    win : numpy.ndarray
        (nperseg,) window.
    noverlap : int
        Samples shared by consecutive segments, < nperseg.

    Returns
    -------
    numpy.ndarray
        (R, nperseg // 2 + 1) PSD.
    """
    from scipy import fft as sp_fft

    x = np.asarray(x, dtype=float)
    nperseg = win.size
    hop = nperseg - noverlap
    sft = signal.ShortTimeFFT(win, hop, fs, fft_mode="onesided", mfft=nperseg, scale_to="psd", phase_shift=None)
    w = sft.win.conj()
    n_seg = (x.shape[-1] - noverlap) // hop
    out = np.empty((x.shape[0], nperseg // 2 + 1))
    step = max(1, WELCH_BLOCK // (n_seg * nperseg))
    for s in range(0, x.shape[0], step):
        seg = np.lib.stride_tricks.sliding_window_view(x[s:s + step], nperseg, axis=-1)[:, ::hop][:, :n_seg]
        S = sp_fft.rfft((seg - np.mean(seg, -1, keepdims=True)) * w, n=nperseg, axis=-1)     # (r, P, F)
        if 1 < n_seg < 8:
            # the mean over fewer than 8 segments as numpy sums them, one after the other from the first, as whole-array
            # adds over the segment axis where it lies (no copy of the powers with it last); doubling is exact, so
            # before the sum or after it is the same number
            P = S[:, 0].real ** 2 + S[:, 0].imag ** 2
            for k in range(1, n_seg):
                P += S[:, k].real ** 2 + S[:, k].imag ** 2
            P[..., 1:-1 if nperseg % 2 == 0 else None] *= 2
            out[s:s + step] = P / n_seg
            continue
        P = np.ascontiguousarray(np.moveaxis(S.real**2 + S.imag**2, 1, -1))                # (r, F, P) as scipy
        P[..., 1:-1 if nperseg % 2 == 0 else None, :] *= 2
        out[s:s + step] = P.mean(axis=-1) if n_seg > 1 else P[..., 0]
    return out


# --------------------------------------------------------------------------- RMS

def band_mask(f: np.ndarray, f_min: float = 0.0, f_max: float | None = None) -> np.ndarray:
    f_max = np.inf if f_max is None else f_max
    return (f >= f_min) & (f <= f_max)


def rms(psd: np.ndarray, f: np.ndarray, f_min: float = 0.0, f_max: float | None = None) -> np.ndarray:
    """RMS over a band from a PSD (last axis frequency): sqrt(sum S df)."""
    df = f[1] - f[0]
    m = band_mask(f, f_min, f_max)
    return np.sqrt(np.sum(psd[..., m], axis=-1) * df)


def cumulative_rms(psd: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Running RMS from 0 Hz up (thesis Eq. 2.13); last value is the total RMS."""
    df = f[1] - f[0]
    return np.sqrt(np.cumsum(psd, axis=-1) * df)


# --------------------------------------------------------------------------- lines and peaks

def noise_floor(psd: np.ndarray, f: np.ndarray, dof: float = 2.0, width_hz: float = 10.0,
                min_bins: int = 31) -> np.ndarray:
    """Local mean noise level of a PSD (last axis), unit²/Hz.

    A running median over ``width_hz`` ignores the narrow lines; a Welch PSD of
    noise is mean·chi²(dof)/dof, so dividing the median by median(chi²)/dof
    turns it into the mean.
    """
    df = f[1] - f[0]
    n = max(min_bins, int(round(width_hz / df)) | 1)
    # DC (detrended) and Nyquist (not doubled) bins are not noise-like: take the
    # median over the interior with mirrored edges and copy it to the end bins.
    inner = running_median(psd[..., 1:-1], n)
    med = np.concatenate([inner[..., :1], inner, inner[..., -1:]], axis=-1)
    return med * (max(dof, 2.0) / stats.chi2.median(max(dof, 2.0)))


def running_median(x: np.ndarray, n: int, mode: str = "mirror") -> np.ndarray:
    """Running median of width ``n`` along the last axis of ``x``; the values of
    ``scipy.ndimage.median_filter(x, size=(1, .., 1, n), mode=mode)`` (``"mirror"``: edges mirrored about the end
    sample; ``"nearest"``: the end sample repeated).

    ndimage filters a 1-D array with its own running rank filter (O(n_f·log n)), an n-D one by selecting from every
    window again (O(n_f·n)): the rows are filtered one at a time, the same numbers 2.5-15x faster at the widths used
    here (a (60, 4097) array at n = 61: 11 ms against 165 ms).  An array with NaN or inf next to finite values in a
    row goes through ndimage as it is (NaN has no place in a rank's order, and ndimage's 1-D and n-D paths order it
    differently); a row of NaN alone gives NaN in both.

    Parameters
    ----------
    x : numpy.ndarray
        Any shape (..., n_f); filtered along the last axis.
    n : int
        Window width in samples.
    mode : str
        ndimage's edge mode.

    Returns
    -------
    numpy.ndarray
        The running median, shape of ``x``.
    """
    x = np.asarray(x)
    if x.ndim == 0:
        return ndimage.median_filter(x, size=n, mode=mode)
    rows = x.reshape(-1, x.shape[-1])
    if x.dtype.kind != "f" or not np.all(np.isfinite(rows).all(axis=1) | np.isnan(rows).all(axis=1)):
        return ndimage.median_filter(x, size=(1,) * (x.ndim - 1) + (n,), mode=mode)
    out = np.empty(rows.shape, dtype=x.dtype)
    for i, row in enumerate(rows):                   # one 1-D filter a row (module docstring): n_rows calls
        ndimage.median_filter(row, size=n, mode=mode, output=out[i])
    return out.reshape(x.shape)


def detection_threshold(dof: float, n_bins: int, p_false: float = 0.01) -> float:
    """Factor over the local mean noise PSD that noise alone exceeds with
    probability ``p_false`` somewhere in ``n_bins`` bins.

    A Welch PSD of Gaussian noise with ``dof`` degrees of freedom is the mean
    times chi²(dof)/dof.
    """
    dof = max(float(dof), 2.0)
    per_bin = p_false / max(n_bins, 1)
    return float(stats.chi2.isf(per_bin, dof) / dof)


def welch_dof(n_segments: int, overlap: float = 0.5) -> float:
    """Equivalent degrees of freedom of a Hann Welch estimate (Percival & Walden,
    50 % overlap correlation 0.167)."""
    k = max(int(n_segments), 1)
    if k == 1:
        return 2.0
    rho = 0.167 if overlap > 0 else 0.0
    return 2.0 * k / (1.0 + 2.0 * rho**2 * (k - 1) / k)


def find_lines(psd_row: np.ndarray, f: np.ndarray, floor_row: np.ndarray, threshold: float,
               f_max: float | None = None, f_min: float = 0.0):
    """Significant narrow peaks of one PSD: (frequency Hz refined, peak index).

    A local maximum counts when it exceeds ``threshold`` times the local mean
    noise floor.  Its frequency is refined by a Gaussian (log-parabolic) fit through
    the three bins around it, which for a Hann window is accurate to a few
    percent of a bin.
    """
    m = band_mask(f, f_min, f_max)
    height = np.where(m, threshold * floor_row, np.inf)
    idx, _ = signal.find_peaks(psd_row, height=height)
    idx = idx[(idx > 0) & (idx < len(f) - 1)]
    if idx.size == 0:
        return np.empty(0), idx
    lo, mid, hi = (np.log(np.maximum(psd_row[idx + k], 1e-300)) for k in (-1, 0, 1))
    denom = lo - 2 * mid + hi
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(denom < 0, 0.5 * (lo - hi) / denom, 0.0)
    delta = np.clip(delta, -0.5, 0.5)
    df = f[1] - f[0]
    return f[idx] + delta * df, idx


def line_power(psd: np.ndarray, f: np.ndarray, f_line, half_width_bins: int = 3,
               floor: np.ndarray | None = None) -> np.ndarray:
    """Mean-square power of a spectral line, unit², summed over the bins within
    ``half_width_bins`` of ``f_line`` (the Hann main lobe is ±2 bins), less the
    noise floor in those bins.

    ``psd`` (..., n_f) and ``f_line`` broadcast over the leading axes.  By
    Parseval the result does not depend on where the line falls between bins.
    A sinusoid of amplitude A has power A²/2.
    """
    df = f[1] - f[0]
    f_line = np.asarray(f_line, dtype=float)
    centre = np.rint(f_line / df).astype(int)
    offsets = np.arange(-half_width_bins, half_width_bins + 1)
    bins = np.clip(centre[..., None] + offsets, 0, len(f) - 1)
    lead = psd.shape[:-1]
    bins_b = np.broadcast_to(bins, lead + (len(offsets),)) if bins.ndim == 1 and lead else bins
    p = np.take_along_axis(psd, bins_b, axis=-1)
    total = np.sum(p, axis=-1) * df
    if floor is not None:
        fl = np.take_along_axis(floor, bins_b, axis=-1)
        total = total - np.sum(fl, axis=-1) * df
    return np.maximum(total, 0.0)


def line_amplitude(psd, f, f_line, half_width_bins: int = 3, floor=None):
    """Amplitude (unit) of the sinusoid at ``f_line``: sqrt(2 × line power)."""
    return np.sqrt(2.0 * line_power(psd, f, f_line, half_width_bins, floor))
