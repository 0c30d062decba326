"""MATLAB ``.mat`` files: v5 (scipy.io) and v7.3 (HDF5, via h5py).

Convention: one file per run or sweep, holding column (or row) vectors named
like the interchange columns (``time_s``, ``Fx_N`` ... ``Tz_Nm``, a sweep's
``speed_rpm``), or named by a ``channel_map`` in ``meta.json``; instead of
``time_s`` a scalar ``sample_rate_hz`` (and optionally ``t0_s``) may give the
time base.  A 2-D matrix is refused (which dimension is time cannot be
known); so are vectors of different lengths.  v7.3 files are HDF5 with a
MATLAB header; MATLAB stores them transposed, which does not matter for
vectors.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .records import DataError, RawRecord

TIME = "time_s"
RATE = "sample_rate_hz"
T0 = "t0_s"
#: MATLAB's v7.3 files are HDF5 files with this 512-byte header block.
V73_HEADER = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu Jan  1 00:00:00 1970 HDF5 schema 1.00 ."


def _variables(path: Path) -> tuple:
    """(name -> array, version string) of the numeric variables of a .mat file."""
    import h5py

    if not path.exists():
        raise DataError(path, "file", "does not exist")
    if h5py.is_hdf5(path):
        out = {}
        try:
            with h5py.File(path, "r") as fh:
                for name, obj in fh.items():
                    if name.startswith("#"):        # MATLAB's own (#refs#, #subsystem#)
                        continue
                    if not isinstance(obj, h5py.Dataset):
                        raise DataError(path, f"variable {name}", "is a MATLAB struct or cell array (an HDF5 group), "
                                        "not a numeric vector: store each channel as a vector of its own")
                    out[name] = np.asarray(obj[()])
        except OSError as exc:
            raise DataError(path, "file", f"cannot be read as MATLAB v7.3 (HDF5): {exc}") from None
        return out, "v7.3"
    from scipy.io import loadmat

    try:
        raw = loadmat(str(path))
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError on a broken file
        raise DataError(path, "file", f"is not a readable MATLAB v5 file (truncated or corrupt?): {exc}") from None
    return {k: v for k, v in raw.items() if not k.startswith("__")}, "v5"


def _vector(path, name, value) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype.kind not in "fiu":
        raise DataError(path, f"variable {name}", f"class {a.dtype} is not numeric")
    if a.ndim > 2 or (a.ndim == 2 and min(a.shape) > 1):
        raise DataError(path, f"variable {name}", f"is a {'x'.join(map(str, a.shape))} matrix: its orientation "
                        "(which dimension is time) is unknown; store one vector per channel (time_s, Fx_N ...)")
    x = np.ascontiguousarray(a.reshape(-1), dtype=float)
    bad = ~np.isfinite(x)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataError(path, f"variable {name}", f"non-finite sample at index {i}, value {float(x[i])!r}")
    return x


def read_record(path) -> RawRecord:
    """A .mat file (v5 or v7.3) as a :class:`RawRecord`."""
    path = Path(path)
    variables, version = _variables(path)
    rate = t0 = time = None
    columns, where = {}, {}
    for name, value in variables.items():
        if name in (RATE, T0):
            a = np.asarray(value, dtype=float).reshape(-1) if np.asarray(value).dtype.kind in "fiu" else None
            if a is None or a.size != 1 or not np.isfinite(a[0]):
                raise DataError(path, f"variable {name}", f"must be one finite number, got {value!r}")
            if name == RATE:
                rate = float(a[0])
            else:
                t0 = float(a[0])
            continue
        x = _vector(path, name, value)
        if name == TIME:
            time = x
        else:
            columns[name], where[name] = x, f"variable {name}"
    if not columns:
        raise DataError(path, "variables", f"no channel vectors ({version} file; found {sorted(variables)})")
    lengths = {n: len(x) for n, x in columns.items()}
    if time is not None:
        lengths[TIME] = len(time)
    if len(set(lengths.values())) > 1:
        raise DataError(path, "variables", f"vectors differ in length: {lengths}")
    if time is None and rate is None:
        raise DataError(path, TIME, f"neither a {TIME} vector nor a {RATE} scalar ({version} file)")
    return RawRecord(path=path, columns=columns, where=where, time=time, time_field=f"variable {TIME}",
                     time_position=lambda i: f"index {i + 1}", sample_rate=rate,
                     rate_field=f"variable {RATE}", t0=t0 if t0 is not None else 0.0, channels_field="variables")


def write(path, columns: dict, v73: bool = False) -> Path:
    """Write named 1-D vectors (and scalars) as a .mat file: v5 by scipy.io, v7.3 by h5py."""
    path = Path(path)
    if not v73:
        from scipy.io import savemat

        savemat(str(path), {k: (np.asarray(v, dtype=float).reshape(-1, 1) if np.ndim(v) else float(v))
                            for k, v in columns.items()})
        return path
    from ..hdf5 import file_in_memory

    # MATLAB's 128-byte header in a 512-byte user block before the HDF5 superblock (found there by HDF5)
    header = (V73_HEADER.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM").ljust(512, b"\x00")
    with file_in_memory(path, header) as fh:
        for name, value in columns.items():
            data = np.asarray(value, dtype=np.float64)
            ds = fh.create_dataset(name, data=data.reshape(1, -1) if data.ndim else data.reshape(1, 1))
            ds.attrs["MATLAB_class"] = np.bytes_("double")
    return path
