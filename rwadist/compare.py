"""Model validation: the empirical model against the data it came from
(thesis §3.1.4, ``comp_model.m``, Eqs. 3.12-3.19).

Pure functions, no I/O.  Wheel speeds ``omega`` in rad/s (the model uses
|Ω|), spectral frequencies in Hz, PSDs one-sided in unit²/Hz.

The model of one channel of a direction at speed Ω is a sum of harmonics at
h_i·|Ω|/2π Hz (Eq. 3.12) with amplitudes C_i·Ω² (Eq. 3.13); its one-sided PSD is
a comb of impulses carrying the variances C_i²Ω⁴/2 (Eq. 3.18), and its RMS is
the square root of their sum (Eqs. 3.15, 3.19).  Comparisons with data are
band-limited alike: the data integrated over [0, f_max] and only the model
lines at or below f_max, with f_max no higher than the spectra's band limit.
"""
from __future__ import annotations

import numpy as np

from .model import line_amplitudes, model_rms
from .spectra import rms
from .units import CHANNEL_DIRECTION, CHANNEL_UNIT, DIRECTION_CHANNELS, rad_s_to_rpm


def _band_top(spectra, f_max: float | None) -> float:
    """Upper band edge, Hz: min(f_max, band limit of the spectra)."""
    top = float(spectra.band_limit)
    return top if f_max is None else min(float(f_max), top)


def data_rms(spectra, channel: str, f_max: float | None = None) -> np.ndarray:
    """RMS (N or N·m) of each run of ``channel`` over [0, min(f_max, band_limit)] Hz.

    sqrt of the integrated PSD (thesis ``intrms.m``); NaN for runs lacking the channel.
    """
    return rms(spectra.psd[channel], spectra.f, 0.0, _band_top(spectra, f_max))


def model_rms_vs_speed(model, direction: str, omega, f_max: float | None = None) -> np.ndarray:
    """Model RMS (N or N·m) of one channel of ``direction`` at each speed ``omega`` (rad/s),
    thesis Eq. 3.19, counting lines at or below ``f_max`` Hz (all lines if None)."""
    return model_rms(model, direction, omega, f_max)


def model_psd_lines(model, direction: str, omega):
    """The model's line spectrum (thesis Eq. 3.18) at speeds ``omega`` (rad/s).

    Returns (f, var), each (n_speeds, n_harmonics): line frequencies h·|Ω|/2π in Hz
    and line variances C²Ω⁴/2 in unit² (the area each line carries in a PSD).
    """
    f, a = line_amplitudes(model, direction, omega)
    return f, a**2 / 2.0


def model_cumulative_rms(model, direction: str, omega, f) -> np.ndarray:
    """The model's cumulative RMS (a staircase, unit) on the ascending frequency grid ``f`` (Hz).

    Value at f_k is sqrt(sum of line variances with line frequency <= f_k).
    ``omega`` scalar gives shape (n_f,); an array gives (n_speeds, n_f).
    """
    scalar = np.ndim(omega) == 0
    f = np.asarray(f, dtype=float)
    f_line, var = model_psd_lines(model, direction, omega)          # (n_s, n_h)
    n_s, n_h = f_line.shape
    # first grid index at which each line is counted (f_k >= f_line); len(f) = never
    first = np.searchsorted(f, f_line, side="left")
    steps = np.zeros((n_s, len(f) + 1))
    rows = np.broadcast_to(np.arange(n_s)[:, None], (n_s, n_h))
    np.add.at(steps, (rows, first), var)
    out = np.sqrt(np.cumsum(steps[:, :-1], axis=-1))
    return out[0] if scalar else out


def model_psd_on_grid(model, direction: str, omega, f) -> np.ndarray:
    """The model's line spectrum as a PSD (unit²/Hz) on the uniform grid ``f`` (Hz).

    Each line's variance C²Ω⁴/2 is divided by the bin width and put in the bin
    nearest its frequency (lines sharing a bin add), so sum(S)·df equals the
    model variance of Eq. 3.15 counting the lines that fall on the grid (within
    half a bin of its ends).  ``omega`` scalar gives (n_f,); an array (n_speeds, n_f).
    """
    scalar = np.ndim(omega) == 0
    f = np.asarray(f, dtype=float)
    df = f[1] - f[0]
    f_line, var = model_psd_lines(model, direction, omega)
    n_s, n_h = f_line.shape
    idx = np.rint((f_line - f[0]) / df).astype(int)
    on = (idx >= 0) & (idx < len(f))
    out = np.zeros((n_s, len(f)))
    rows = np.broadcast_to(np.arange(n_s)[:, None], (n_s, n_h))
    np.add.at(out, (rows[on], idx[on]), var[on] / df)
    return out[0] if scalar else out


def channel_rms_column(channel: str) -> str:
    """CSV column of a channel's data RMS, e.g. ``data_Fx_rms_N``."""
    return f"data_{channel}_rms_{CHANNEL_UNIT[channel]}"


def direction_rms_column(direction: str) -> str:
    """CSV column of a direction's model RMS, e.g. ``model_radial_force_rms_N``."""
    unit = CHANNEL_UNIT[DIRECTION_CHANNELS[direction][0]]
    return f"model_{direction}_rms_{unit}"


def rms_table(fit, f_max: float | None = None) -> dict:
    """RMS of data and model at every run's speed, band-limited alike (thesis σ_data, σ_mod).

    Returns an ordered dict of equal-length columns::

        speed_rpm                      run speed (signed, as measured)
        data_<ch>_rms_<unit>           data RMS per channel over [0, f_top]
        model_<direction>_rms_<unit>   model RMS (one channel of the direction), lines <= f_top
        ratio_<ch>                     model/data for the channel's direction (NaN where data is 0 or absent)

    with f_top = min(f_max, band limit).  A direction's model column appears when
    one of its channels is in the data.
    """
    sp = fit.spectra
    top = _band_top(sp, f_max)
    omega = np.asarray(sp.speed, dtype=float)
    table = {"speed_rpm": rad_s_to_rpm(omega)}
    channels = tuple(sp.channels)
    data = {ch: data_rms(sp, ch, top) for ch in channels}
    for ch in channels:
        table[channel_rms_column(ch)] = data[ch]
    directions = [d for d in DIRECTION_CHANNELS if any(ch in channels for ch in DIRECTION_CHANNELS[d])]
    model = {d: model_rms_vs_speed(fit.model, d, omega, top) for d in directions}
    for d in directions:
        table[direction_rms_column(d)] = model[d]
    for ch in channels:
        m, x = model[CHANNEL_DIRECTION[ch]], data[ch]
        with np.errstate(divide="ignore", invalid="ignore"):
            table[f"ratio_{ch}"] = np.where(x > 0, m / x, np.nan)
    return table
