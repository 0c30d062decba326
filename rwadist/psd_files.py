"""Files and plots of the broadband PSD: CSV (auto and cross spectra, envelopes, the envelope's worst line amplitudes),
HDF5, a figure.
Part of :mod:`rwadist.broadband`, which re-exports these names."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from .broadband import _CROSS_UNIT, PAIRS, BroadbandPSD, Envelope
from .text_table import write_csv, write_rows
from .units import CHANNEL_UNIT, CHANNELS, PSD_COLUMN


def write_psd_csv(res: BroadbandPSD, path) -> Path:
    """Auto-spectra: columns f_Hz, Fx_N2_per_Hz, ..., Tz_Nm2_per_Hz (docs/formats.md)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = np.column_stack([res.f, res.psd])
    header = ",".join(["f_Hz"] + [PSD_COLUMN[c] for c in CHANNELS])
    return write_csv(path, header, data, 10)


def cross_columns() -> list:
    """Column names of the cross-spectra file: '<a>_<b>_re_<unit>_per_Hz', '<a>_<b>_im_...' for a < b."""
    cols = []
    for a, b in PAIRS:
        if a == b:
            continue
        unit = _CROSS_UNIT[(a // 3, b // 3)]
        for part in ("re", "im"):
            cols.append(f"{CHANNELS[a]}_{CHANNELS[b]}_{part}_{unit}_per_Hz")
    return cols


def write_cross_csv(res: BroadbandPSD, path) -> Path:
    """Cross-spectra csd[a, b] (a < b) as real and imaginary columns; csd[b, a] is the conjugate."""
    off = [(a, b) for a, b in PAIRS if a != b]
    data = np.empty((res.f.size, 1 + 2 * len(off)))
    data[:, 0] = res.f
    # csd[:, a, b]'s real and imaginary parts are the doubles 2·(6a + b) and 2·(6a + b) + 1 of a row: one gather,
    # no complex temporaries
    parts = [2 * (6 * a + b) + part for a, b in off for part in (0, 1)]
    rows = np.ascontiguousarray(res.csd, dtype=complex).reshape(res.f.size, 36).view(np.float64)
    np.take(rows, parts, axis=1, out=data[:, 1:], mode="clip")     # 'clip': written straight into out
    return write_csv(path, ",".join(["f_Hz"] + cross_columns()), data, 10)


def read_psd_csv(path) -> tuple:
    """(f, {channel: psd}) from a PSD table."""
    with open(path, newline="") as fh:
        header = next(csv.reader(fh))
    arr = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    inv = {v: k for k, v in PSD_COLUMN.items()}
    return arr[:, 0], {inv[h]: arr[:, i] for i, h in enumerate(header) if h in inv}


def write_hdf5(res: BroadbandPSD, path, group: str = "psd") -> Path:
    """A new HDF5 file ``path`` with one group: datasets f_Hz (n), psd (n, 6) and csd (n, 6, 6) complex; attrs
    channels, frame."""
    from .hdf5 import file_in_memory

    path = Path(path)
    with file_in_memory(path) as fh:       # a full disk: one OSError, never HDF5's crash
        g = fh.create_group(group)
        g.create_dataset("f_Hz", data=res.f)
        g.create_dataset("psd", data=res.psd)
        g.create_dataset("csd", data=res.csd, compression="gzip")
        g.attrs["channels"] = ",".join(CHANNELS)
        g.attrs["frame"] = res.frame
        g.attrs["convention"] = "csd[k,a,b] = E[X_a conj(X_b)], one-sided, unit^2/Hz"
    return path


#: a plotted curve keeps at most this many buckets across the visible band (a panel is ~500 px wide): each holds the
#: smallest and the largest value of its frequencies, so every peak and notch is drawn
PLOT_BUCKETS = 2000


def _peaks_kept(f: np.ndarray, y: np.ndarray, visible_hz: float):
    """(f, y) reduced to two points per bucket of width ``visible_hz``/PLOT_BUCKETS (first frequency with the
    bucket's minimum, last with its maximum; NaN, a zero on a log axis, ignored unless the bucket has nothing
    else); unchanged when there are not many more points than that.  Drawing 1e5 points per curve took ~1 s."""
    with np.errstate(over="ignore"):
        wanted = PLOT_BUCKETS * float(np.float64(f[-1] - f[0]) / max(visible_hz, 1e-300))
    n_buckets = int(f.size // 4 if not wanted < f.size // 4 else math.ceil(wanted))
    if n_buckets < PLOT_BUCKETS // 2 or f.size <= 4 * n_buckets:
        return f, y
    start = np.unique(np.linspace(0, f.size, n_buckets + 1).astype(np.int64)[:-1])
    end = np.append(start[1:], f.size) - 1
    x = np.column_stack([f[start], f[end]]).ravel()
    with np.errstate(invalid="ignore"):
        v = np.column_stack([np.fmin.reduceat(y, start), np.fmax.reduceat(y, start)]).ravel()
    return x, v


def plot_psd(res: BroadbandPSD, title: str = ""):
    """Figure (Agg canvas, no pyplot): PSDs (top, log scale) and cumulative RMS (bottom).

    The frequency axis ends where the PSD content ends (``plot_util.content_top``), the log
    axis spans 80 dB below the peak, all-zero channels are left out (named in the panel's
    title) and identical channels share one legend entry (``Fx = Fy``).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .plot_util import content_top, group_identical, is_empty, log_axis, log_floor

    fig = Figure(figsize=(10, 8), layout="tight")   # laid out when drawn: save_png's draw caches serve the layout too
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.add_subplot(2, 2, 1), fig.add_subplot(2, 2, 2)
    ax3, ax4 = fig.add_subplot(2, 2, 3), fig.add_subplot(2, 2, 4)
    psd, cum, f = res.psd, res.cumulative_rms(), res.f
    shown = [c for c in range(len(CHANNELS)) if not is_empty(psd[:, c])]
    f_top = content_top(f, psd[:, shown]) if shown else float(f[-1])
    groups = [(range(0, 3), ax1, ax3, "N"), (range(3, 6), ax2, ax4, "N·m")]
    for chans, ax_p, ax_c, unit in groups:
        live = [c for c in chans if c in shown]
        empty = [CHANNELS[c] for c in chans if c not in shown]
        if live:
            log_axis(ax_p)
        for c, label in group_identical(psd[:, live], [CHANNELS[k] for k in live]) if live else []:
            k = live[c]
            ax_p.plot(*_peaks_kept(f, np.where(psd[:, k] > 0, psd[:, k], np.nan), f_top), lw=0.8, label=label)
            ax_c.plot(*_peaks_kept(f, cum[:, k], f_top), lw=1.0, label=label)
        if live:
            lo = log_floor(psd[:, live])
            if lo is not None:
                ax_p.set_ylim(bottom=lo)
            ax_p.legend(fontsize=8)
            ax_c.legend(fontsize=8)
        if not live:                       # a whole group of zeros: no empty panels
            ax_p.set_visible(False)
            ax_c.set_visible(False)
        elif empty:
            ax_p.set_title(f"zero, not shown: {', '.join(empty)}", fontsize=9)
        ax_p.set_ylabel(f"PSD ({unit}²/Hz)" if unit == "N" else f"PSD (({unit})²/Hz)")
        ax_c.set_ylabel(f"cumulative RMS ({unit})")
    for ax in (ax1, ax2, ax3, ax4):
        ax.set_xlabel("frequency (Hz)")
        ax.set_xlim(0.0, f_top)
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or f"broadband disturbance PSD ({res.frame} frame)")
    return fig


def write_envelope_csv(env: Envelope, path) -> Path:
    """The worst-case line envelope: columns f_Hz, then per channel its peak amplitude ``<ch>_N`` or ``<ch>_Nm``
    (N or N·m) of the strongest line at that frequency (docs/formats.md); 8 significant digits."""
    cols = ["f_Hz"] + [f"{c}_{CHANNEL_UNIT[c]}" for c in CHANNELS]
    return write_csv(path, ",".join(cols), np.column_stack([env.f, env.amplitude]), 8)


def envelope_harmonics_columns() -> list:
    """Columns of the envelope's table per line: ``wheel``, ``source``, ``h``, then per channel <ch> (unit <unit>:
    N or Nm) ``<ch>_max_<unit>``, ``<ch>_speed_rpm``, ``<ch>_f_Hz``."""
    cols = ["wheel", "source", "h"]
    for c in CHANNELS:
        cols += [f"{c}_max_{CHANNEL_UNIT[c]}", f"{c}_speed_rpm", f"{c}_f_Hz"]
    return cols


def wheel_names(res: BroadbandPSD) -> list:
    """The name of each wheel of :func:`rwadist.psd`'s result ``res``, in the order of the envelope's ``wheel`` index:
    a set's names (``meta["speed_laws"]``), or the one wheel's (``meta["wheel"]``)."""
    one = res.meta.get("wheel") or (res.meta.get("source") or {}).get("name") or ""
    return [str(name) if name is not None else str(one) for name, _ in res.meta.get("speed_laws", [(None, "")])]


def write_envelope_harmonics_csv(env: Envelope, path, names=None) -> Path:
    """The envelope's table (:attr:`rwadist.broadband.Envelope.table`) as CSV, one row per line of each wheel, in the
    order of the wheels and of their lines: the wheel (``names[i]``, default its index), the line's label and harmonic
    number h, then per channel the line's largest peak amplitude over the wheel's speeds (N or N·m, in the envelope's
    frame), the signed speed (rpm) and the line's frequency (Hz) where it occurs; a channel the line does not reach
    has amplitude 0 and its speed and frequency empty.  8 significant digits (:func:`rwadist.text_table.cell`).

    Parameters
    ----------
    env : rwadist.broadband.Envelope
        The envelope, with its table.
    path : str or pathlib.Path
        The CSV file to write.
    names : list of str or None
        The wheels' names by index (:func:`wheel_names`); None: the indices.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    rows: dict = {}
    for r in env.table:
        key = (r["wheel"], r["line"])
        row = rows.setdefault(key, {"wheel": names[r["wheel"]] if names is not None else r["wheel"],
                                    "source": r["source"], "h": r["h"]}
                              | {f"{c}_max_{CHANNEL_UNIT[c]}": 0.0 for c in CHANNELS})
        c = r["channel"]
        row |= {f"{c}_max_{CHANNEL_UNIT[c]}": r["max_amplitude"], f"{c}_speed_rpm": r["speed_rpm"],
                f"{c}_f_Hz": r["f_Hz"]}
    cols = envelope_harmonics_columns()
    return write_rows(path, cols, ([row.get(c) for c in cols] for row in rows.values()), digits=8)
