"""Which reader and writer handle a file: picked by its extension (``.tdms:GROUP`` selects a group).

Formats (the names ``rwadist convert --format`` takes):

========== ============ ==================================================
name       extension    library
========== ============ ==================================================
csv        .csv         numpy (the interchange format)
uff        .uff .unv    pyuff, ASCII dataset 58
uff-binary .uff .unv    pyuff, binary dataset 58
tdms       .tdms        npTDMS
mat        .mat         scipy.io (MATLAB v5)
mat73      .mat         h5py (MATLAB v7.3)
========== ============ ==================================================

HDF5 (``.h5``, ``.hdf5``) holds a whole test and lives in :mod:`rwadist.hdf5`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..units import CHANNEL_COLUMN, rad_s_to_rpm
from . import csv_table, matlab, tdms, uff
from .channels import SPEED_COLUMN
from .records import DataError, RawRecord

RUN_FORMATS = ("csv", "uff", "uff-binary", "tdms", "mat", "mat73")
EXTENSION = {"csv": ".csv", "uff": ".uff", "uff-binary": ".uff", "tdms": ".tdms", "mat": ".mat", "mat73": ".mat"}
READ_EXTENSIONS = {".csv": "csv", ".uff": "uff", ".unv": "uff", ".tdms": "tdms", ".mat": "mat"}


def reader_of(path) -> str:
    """The reader ('csv', 'uff', 'tdms', 'mat') of a run or sweep file, by extension."""
    file, _ = tdms.split_group(path)
    suffix = Path(file).suffix.lower()
    if suffix not in READ_EXTENSIONS:
        raise DataError(path, "file", f"extension {suffix or '(none)'!r} is not a known format; use one of "
                        f"{sorted(READ_EXTENSIONS)} (or .h5 for a whole test)")
    return READ_EXTENSIONS[suffix]


def read_record(path, meta: dict | None = None) -> RawRecord:
    """A run or sweep file of any supported format as a :class:`RawRecord`."""
    kind = reader_of(path)
    if kind == "csv":
        return csv_table.read_record(path)
    if kind == "uff":
        tach = (meta or {}).get("tach")
        names = {SPEED_COLUMN} | ({tach["channel"]} if isinstance(tach, dict) and "channel" in tach else set())
        return uff.read_record(path, tach_names=names)
    if kind == "tdms":
        file, group = tdms.split_group(path)
        return tdms.read_record(file, group)
    return matlab.read_record(path)


def write_record(path, fmt: str, signals: dict, sample_rate: float, t0: float = 0.0,
                 speed_rad_s: np.ndarray | None = None) -> Path:
    """Write one run or sweep (channels SI, optional per-sample speed) in format ``fmt``."""
    path = Path(path)
    n = len(next(iter(signals.values())))
    extra = {} if speed_rad_s is None else {SPEED_COLUMN: rad_s_to_rpm(speed_rad_s)}
    if fmt == "csv":
        header = ["time_s"] + [CHANNEL_COLUMN[c] for c in signals] + list(extra)
        time = t0 + np.arange(n) / sample_rate
        return csv_table.write_table(path, header, [time] + list(signals.values()) + list(extra.values()))
    if fmt in ("uff", "uff-binary"):
        return uff.write(path, signals, sample_rate, t0, binary=fmt == "uff-binary", extra=extra)
    if fmt == "tdms":
        return tdms.write(path, signals, sample_rate, t0, extra=extra)
    if fmt in ("mat", "mat73"):
        columns = {"sample_rate_hz": sample_rate, "t0_s": t0}
        columns.update({CHANNEL_COLUMN[c]: x for c, x in signals.items()})
        columns.update(extra)
        return matlab.write(path, columns, v73=fmt == "mat73")
    raise ParameterError("format", f"{fmt!r} is not one of {list(RUN_FORMATS)}")
