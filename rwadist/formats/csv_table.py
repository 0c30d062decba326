"""The interchange CSV files: one table per run or sweep, ``time_s`` first.

Header ``time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm`` (channels may be absent; a
sweep may add ``speed_rpm``; with a ``channel_map`` in ``meta.json`` the
columns may carry the lab's own names).  Written with 17 significant digits
(lossless for float64); read with the time stamps as printed, however many
digits (:mod:`rwadist.formats.timebase`).
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .records import DataError, RawRecord, read_text

TIME_COLUMN = "time_s"


def read_numeric_csv(path: Path, required_first: str = TIME_COLUMN):
    """Read a numeric CSV with a header; return (column names, 2-D array, shape (n, n_columns)).
    Errors name the line."""
    text = read_text(path)
    header_line, _, body = text.partition("\n")
    header = [h.strip() for h in header_line.strip().split(",")] if header_line.strip() else []
    if not header:
        raise DataError(path, "header", "file is empty (no header line)")
    if header[0] != required_first:
        raise DataError(path, "header", f"first column is {header[0]!r}, expected {required_first!r}")
    seen = set()
    for col in header:
        if col in seen:
            raise DataError(path, col, "column appears twice in the header")
        seen.add(col)
    if not body.strip():
        raise DataError(path, "data", "no data rows after the header")
    try:
        data = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, dtype=float)
    except ValueError:
        data = None
    if data is None or data.shape[1] != len(header):
        _diagnose_rows(path, body, header)
        raise DataError(path, "data", "could not be parsed as numbers")  # pragma: no cover
    return header, data


def _diagnose_rows(path: Path, body: str, header: list):
    """Slow path after a parse failure: find and name the first bad line."""
    n_cols = len(header)
    for lineno, line in enumerate(body.splitlines(), start=2):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) != n_cols:
            raise DataError(path, f"line {lineno}",
                            f"has {len(fields)} fields, header has {n_cols} (truncated file?): {line[:80]!r}")
        for col, value in zip(header, fields):
            try:
                float(value)
            except ValueError:
                raise DataError(path, f"{col} (line {lineno})", f"value {value.strip()!r} is not a number") from None


def _check_finite(path: Path, header, data):
    bad = ~np.isfinite(data)
    if bad.any():
        rows, cols = np.nonzero(bad)
        col = header[cols[0]]
        raise DataError(path, col, f"{bad.sum()} non-finite sample(s) (NaN/inf); first at data row {rows[0] + 1}"
                        f" (line {rows[0] + 2}), value {data[rows[0], cols[0]]:g}")


def read_record(path) -> RawRecord:
    """A CSV table as a :class:`RawRecord` (time stamps from the first column)."""
    path = Path(path)
    header, data = read_numeric_csv(path)
    if len(header) < 2:
        raise DataError(path, "header", "no channel columns; expected some of Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm")
    _check_finite(path, header, data)
    columns = {col: np.ascontiguousarray(data[:, i]) for i, col in enumerate(header) if i > 0}
    return RawRecord(path=path, columns=columns, time=np.ascontiguousarray(data[:, 0]), time_field=TIME_COLUMN,
                     channels_field="header")


def _format_table(columns: list) -> str:
    """Columns (1-D arrays) -> CSV body, 17 significant digits (lossless for float64).

    The text of ``np.savetxt(buf, table, delimiter=",", fmt="%.17g")`` (one row format per line), formatted by
    one ``%`` of the whole table instead of one per row: the same bytes in half the time."""
    table = np.column_stack(columns)
    row = ",".join(["%.17g"] * table.shape[1]) + "\n"
    return (row * table.shape[0]) % tuple(table.ravel().tolist())


def write_table(path, header: list, columns: list) -> Path:
    """Write a CSV table: header names and 1-D columns of equal length."""
    path = Path(path)
    with open(path, "w", newline="") as fh:
        fh.write(",".join(header) + "\n")
        fh.write(_format_table(columns))
    return path
