"""The test metadata (``meta.json``, a sweep's sidecar, an HDF5 file's ``meta``): every key a reader uses, checked
when the file is read (docs/formats.md section 2)."""
from __future__ import annotations

import math

from .records import MAX_PULSES_PER_REV, MAX_SAMPLE_RATE_HZ, DataError
from .tach import tach_settings


def check_meta(meta, path, where: str = "") -> dict:
    """The test metadata ``meta`` (a ``meta.json``, a sweep's sidecar or an HDF5 file's ``meta``) with every key the
    kit reads checked: ``sample_rate_hz`` (finite, in (0, 1e7] Hz), ``f_lim_hz`` (null or finite > 0 Hz) and
    ``tach`` (a channel name and 1 <= ``pulses_per_rev`` <= 100000, an integer); :class:`DataError` naming ``path`` and
    the key (after ``where``, e.g. "meta.") otherwise.  The tach is checked whether or not the speeds come from it: a
    model fitted to the data records it (its provenance).  Returns ``meta``."""
    if not isinstance(meta, dict):
        raise DataError(path, where.rstrip(".") or "document", "must be a JSON object")
    for key, top in (("sample_rate_hz", MAX_SAMPLE_RATE_HZ), ("f_lim_hz", None)):
        v = meta.get(key)
        if v is None and key == "f_lim_hz":
            continue
        if key in meta and not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                                and v > 0 and (top is None or v <= top)):
            raise DataError(path, where + key, f"{v!r}: must be a finite number of Hz > 0"
                            + (f" and <= {top:g}" if top else ""))
    settings = tach_settings(meta, path)
    if settings is not None and settings[1] > MAX_PULSES_PER_REV:
        raise DataError(path, where + "tach.pulses_per_rev", f"{settings[1]!r}: at most {MAX_PULSES_PER_REV} pulses "
                        "per revolution")
    return meta


def check_f_lim_meta(meta, sample_rate: float, path, where: str = "") -> None:
    """``f_lim_hz`` of the metadata (when set) at or below the Nyquist frequency of data sampled at ``sample_rate``
    Hz: :class:`DataError` naming ``path`` and the key otherwise (the fit read it as the band limit and refused it
    naming no file)."""
    v = meta.get("f_lim_hz") if isinstance(meta, dict) else None
    if v is not None and v > 0.5 * sample_rate:
        raise DataError(path, where + "f_lim_hz", f"{v:g} Hz is above the data's Nyquist frequency "
                        f"{0.5 * sample_rate:g} Hz: give the limit of good data below it, or remove the key")
