"""Test data in memory and the interchange format on disk (``shared/CONVENTIONS.md``).

Two kinds of measurement:

* :class:`SteadyTest` -- one run per steady wheel speed.  On disk: a directory
  with ``runs.csv`` (columns ``file,speed_rpm``), one CSV per run with header
  ``time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm`` (channels may be absent) and an
  optional ``meta.json``.
* :class:`Sweep` -- one long record through a speed change (spin-up,
  run-down), optionally with a ``speed_rpm`` tach column.

Documented handling of awkward but legal input:

* runs are sorted by speed on reading (stable, so file order breaks ties);
* duplicate speeds are kept as separate runs -- each is an independent
  measurement (a saturated spin-up gives many runs at its top speed);
* negative speeds (wheel spinning about -z) keep their sign; spectra and the
  empirical fit use |Omega|;
* zero speed is kept: it is the noise run of a test, not used by the fit;
* a channel absent from a run is recorded as absent, never filled in.

Everything else that is wrong -- NaN samples, a truncated line, an unknown
column (wrong units), non-uniform time, a duplicated file entry, an empty
directory -- raises :class:`DataError` naming the file, the field and the value.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from .units import CHANNEL_COLUMN, CHANNELS, COLUMN_CHANNEL, rad_s_to_rpm, rpm_to_rad_s

RUNS_FILE = "runs.csv"
META_FILE = "meta.json"
TIME_COLUMN = "time_s"
TACH_COLUMN = "speed_rpm"
#: Relative tolerance on sample spacing before a time column counts as non-uniform.
UNIFORM_TIME_RTOL = 1e-6


class DataError(ValueError):
    """Bad input data; the message names the file, the field and the value."""

    def __init__(self, file, field_name, message):
        self.file = str(file)
        self.field = field_name
        super().__init__(f"{file}: {field_name}: {message}")


@dataclass
class Run:
    """One steady-speed record.

    Attributes
    ----------
    speed : wheel speed, rad/s (signed).
    sample_rate : Hz.
    signals : channel name -> samples (N or N·m); absent channels are absent keys.
    t0 : time of the first sample, s.
    name : file name of the run in the interchange format.
    """

    speed: float
    sample_rate: float
    signals: dict
    t0: float = 0.0
    name: str = ""

    @property
    def n_samples(self) -> int:
        return len(next(iter(self.signals.values()))) if self.signals else 0

    @property
    def channels(self) -> tuple:
        return tuple(ch for ch in CHANNELS if ch in self.signals)


@dataclass
class SteadyTest:
    """Runs at steady wheel speeds, sorted by speed. ``meta`` is free-form (``meta.json``)."""

    runs: list
    meta: dict = field(default_factory=dict)

    @property
    def speeds(self) -> np.ndarray:
        """Wheel speeds of the runs, rad/s."""
        return np.array([r.speed for r in self.runs], dtype=float)

    @property
    def channels(self) -> tuple:
        """Channels present in at least one run, in convention order."""
        present = {ch for r in self.runs for ch in r.signals}
        return tuple(ch for ch in CHANNELS if ch in present)

    def sorted(self) -> "SteadyTest":
        order = np.argsort(self.speeds, kind="stable")
        return SteadyTest([self.runs[i] for i in order], dict(self.meta))


@dataclass
class Sweep:
    """A continuous record through a speed change.

    time : s; signals : channel -> samples (SI); sample_rate : Hz;
    tach : measured wheel speed per sample, rad/s, or None when not recorded.
    """

    time: np.ndarray
    signals: dict
    sample_rate: float
    tach: np.ndarray | None = None
    meta: dict = field(default_factory=dict)

    @property
    def channels(self) -> tuple:
        return tuple(ch for ch in CHANNELS if ch in self.signals)


# --------------------------------------------------------------------------- reading

def _read_numeric_csv(path: Path, allowed: set, required_first: str):
    """Read a numeric CSV with a header; return (columns, 2-D array). Errors name the line."""
    try:
        with open(path, "r", newline="", encoding="utf-8-sig") as fh:
            header_line = fh.readline()
            body = fh.read()
    except OSError as exc:
        raise DataError(path, "file", f"cannot be read ({exc.strerror})") from exc
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
        if col not in allowed:
            hint = ""
            stem = col.split("_")[0]
            if stem in CHANNEL_COLUMN:
                hint = f" (expected {CHANNEL_COLUMN[stem]!r}: values must be SI, N or N·m)"
            raise DataError(path, col, f"unknown column{hint}; allowed: {sorted(allowed)}")
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


def uniform_step(path, field_name: str, time: np.ndarray, position=lambda i: f"line {i + 3}") -> float:
    """The sampling step (s) of a time column, DataError unless it increases uniformly.
    ``position(i)`` names where step i sits in the file (a CSV line, an HDF5 index)."""
    if len(time) < 2:
        raise DataError(path, field_name, f"only {len(time)} sample(s); need at least 2")
    dt = np.diff(time)
    step = float(np.median(dt))
    if not step > 0:
        raise DataError(path, field_name, f"time does not increase (median step {step:.9g} s)")
    dev = np.abs(dt - step)
    if dev.max() > UNIFORM_TIME_RTOL * step + 1e-12 * np.abs(time).max():
        i = int(np.argmax(dev))
        raise DataError(path, field_name, f"sampling is not uniform: step {dt[i]:.9g} s at {position(i)}, "
                        f"median step {step:.9g} s")
    return step


def _sample_rate(path: Path, time: np.ndarray, declared: float | None) -> float:
    step = uniform_step(path, TIME_COLUMN, time)
    fs = 1.0 / step
    if declared is not None:
        if abs(fs - declared) > 1e-6 * declared:
            raise DataError(path, TIME_COLUMN, f"sample rate from time column {fs:.9g} Hz disagrees with "
                            f"meta.json sample_rate_hz {declared!r}")
        fs = float(declared)
    return fs


def read_json(path):
    """A JSON document; DataError naming the file (missing) or the line (invalid)."""
    path = Path(path)
    if not path.exists():
        raise DataError(path, "file", "does not exist")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise DataError(path, f"line {exc.lineno}", f"not valid JSON ({exc.msg})") from None


def _read_meta(directory: Path) -> dict:
    path = directory / META_FILE
    if not path.exists():
        return {}
    meta = read_json(path)
    if not isinstance(meta, dict):
        raise DataError(path, "document", "must be a JSON object")
    fs = meta.get("sample_rate_hz")
    if fs is not None and not (isinstance(fs, (int, float)) and fs > 0 and math.isfinite(fs)):
        raise DataError(path, "sample_rate_hz", f"must be a positive number, got {fs!r}")
    return meta


def read_run(path, speed: float, sample_rate: float | None = None) -> Run:
    """Read one run CSV. ``speed`` in rad/s; ``sample_rate`` (Hz) if declared elsewhere."""
    path = Path(path)
    allowed = {TIME_COLUMN} | set(COLUMN_CHANNEL)
    header, data = _read_numeric_csv(path, allowed, TIME_COLUMN)
    if len(header) < 2:
        raise DataError(path, "header", "no channel columns; expected some of " + ",".join(CHANNEL_COLUMN.values()))
    _check_finite(path, header, data)
    time = data[:, 0]
    fs = _sample_rate(path, time, sample_rate)
    signals = {COLUMN_CHANNEL[col]: np.ascontiguousarray(data[:, i]) for i, col in enumerate(header) if i > 0}
    return Run(speed=float(speed), sample_rate=fs, signals=signals, t0=float(time[0]), name=path.name)


def read_steady(directory, progress: bool = False) -> SteadyTest:
    """Read a steady-state test directory (``runs.csv`` + one CSV per run);
    ``progress`` shows a bar over the runs."""
    directory = Path(directory)
    if not directory.is_dir():
        raise DataError(directory, "directory", "does not exist or is not a directory")
    runs_path = directory / RUNS_FILE
    if not runs_path.exists():
        content = sorted(p.name for p in directory.iterdir())
        what = "is empty" if not content else f"has no {RUNS_FILE} (found {content[:5]})"
        raise DataError(directory, RUNS_FILE, f"directory {what}; a steady-state test needs {RUNS_FILE} "
                        "with columns file,speed_rpm")
    meta = _read_meta(directory)
    with open(runs_path, newline="", encoding="utf-8-sig") as fh:
        reader = csv.DictReader(fh)
        if reader.fieldnames is None:
            raise DataError(runs_path, "header", "file is empty")
        cols = [c.strip() for c in reader.fieldnames]
        for need in ("file", "speed_rpm"):
            if need not in cols:
                raise DataError(runs_path, need, f"column missing; header is {cols}")
        rows = []
        for row in reader:
            if None in row:  # more fields than the header: '1,000' would otherwise read as 1 rpm
                last = reader.fieldnames[-1]
                text = ",".join([row.get(last) or ""] + list(row[None]))
                raise DataError(runs_path, f"{last.strip()} (line {reader.line_num})",
                                f"value {text!r} is not a number: the row has {len(cols) + len(row[None])} "
                                f"fields, the header {len(cols)} (thousands separator?)")
            rows.append((reader.line_num, {k.strip(): (v or "").strip() for k, v in row.items()}))
    if not rows:
        raise DataError(runs_path, "rows", "no runs listed")
    runs, files_seen = [], {}
    for lineno, row in tqdm(rows, desc="reading runs", unit="run", disable=not progress, leave=False):
        fname, speed_text = row.get("file", ""), row.get("speed_rpm", "")
        if not fname:
            raise DataError(runs_path, f"file (line {lineno})", "empty file name")
        if fname in files_seen:
            raise DataError(runs_path, f"file (line {lineno})",
                            f"{fname!r} is listed twice (first at line {files_seen[fname]})")
        files_seen[fname] = lineno
        try:
            rpm = float(speed_text)
        except ValueError:
            raise DataError(runs_path, f"speed_rpm (line {lineno})", f"{speed_text!r} is not a number") from None
        if not math.isfinite(rpm):
            raise DataError(runs_path, f"speed_rpm (line {lineno})", f"{speed_text!r} is not finite")
        run_path = directory / fname
        if not run_path.exists():
            raise DataError(runs_path, f"file (line {lineno})", f"{fname!r} does not exist in {directory}")
        runs.append(read_run(run_path, float(rpm_to_rad_s(rpm)), meta.get("sample_rate_hz")))
    listed = set(files_seen) | {RUNS_FILE, META_FILE}
    unlisted = sorted(p.name for p in directory.iterdir() if p.is_file() and p.name not in listed)
    if unlisted:
        # kept in meta so nothing goes unnoticed; the CLI prints it
        meta = dict(meta, unlisted_files=unlisted)
    return SteadyTest(runs, meta).sorted()


def read_sweep(path, sample_rate: float | None = None) -> Sweep:
    """Read a sweep CSV (time, channels, optional ``speed_rpm`` tach column)."""
    path = Path(path)
    if path.is_dir():
        raise DataError(path, "file", "is a directory; a sweep is one CSV file")
    if not path.exists():
        raise DataError(path, "file", "does not exist")
    allowed = {TIME_COLUMN, TACH_COLUMN} | set(COLUMN_CHANNEL)
    header, data = _read_numeric_csv(path, allowed, TIME_COLUMN)
    if not any(c in COLUMN_CHANNEL for c in header):
        raise DataError(path, "header", "no channel columns")
    _check_finite(path, header, data)
    time = data[:, 0]
    fs = _sample_rate(path, time, sample_rate)
    signals = {COLUMN_CHANNEL[c]: np.ascontiguousarray(data[:, i]) for i, c in enumerate(header) if c in COLUMN_CHANNEL}
    tach = None
    if TACH_COLUMN in header:
        tach = rpm_to_rad_s(data[:, header.index(TACH_COLUMN)])
    return Sweep(time=time, signals=signals, sample_rate=fs, tach=tach)


def read_data(path, progress: bool = False):
    """A directory is a steady-state test, a file a sweep (``.h5`` files: HDF5)."""
    path = Path(path)
    if path.is_dir():
        return read_steady(path, progress=progress)
    if path.suffix.lower() in (".h5", ".hdf5"):
        from .hdf5 import read_hdf5
        return read_hdf5(path)
    return read_sweep(path)


# --------------------------------------------------------------------------- writing

def _format_table(columns: list) -> str:
    """Columns (1-D arrays) -> CSV body, 17 significant digits (lossless for float64)."""
    table = np.column_stack(columns)
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", fmt="%.17g")
    return buf.getvalue()


def write_run(path, run: Run) -> None:
    chans = run.channels
    time = run.t0 + np.arange(run.n_samples) / run.sample_rate
    header = ",".join([TIME_COLUMN] + [CHANNEL_COLUMN[c] for c in chans])
    with open(path, "w", newline="") as fh:
        fh.write(header + "\n")
        fh.write(_format_table([time] + [run.signals[c] for c in chans]))


def write_steady(test: SteadyTest, directory) -> Path:
    """Write a steady-state test in the interchange format. Returns the directory."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rates = {r.sample_rate for r in test.runs}
    meta = dict(test.meta)
    if len(rates) == 1:
        meta["sample_rate_hz"] = rates.pop()
    else:
        meta.pop("sample_rate_hz", None)
    names, taken = [], {RUNS_FILE, META_FILE}
    for i, run in enumerate(test.runs):
        name = run.name or f"run_{i:04d}.csv"
        k = i
        while name in taken:  # never overwrite another run or the index files
            name = f"run_{k:04d}.csv"
            k += 1
        taken.add(name)
        names.append(name)
        write_run(directory / name, run)
    with open(directory / RUNS_FILE, "w", newline="") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(["file", "speed_rpm"])
        for name, run in zip(names, test.runs):
            writer.writerow([name, repr(float(rad_s_to_rpm(run.speed)))])
    (directory / META_FILE).write_text(json.dumps(meta, indent=2, default=_json_default) + os.linesep)
    return directory


def write_sweep(sweep: Sweep, path) -> Path:
    """Write a sweep CSV (with the ``speed_rpm`` column when a tach signal exists)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    chans = sweep.channels
    cols = [TIME_COLUMN] + [CHANNEL_COLUMN[c] for c in chans]
    arrays = [sweep.time] + [sweep.signals[c] for c in chans]
    if sweep.tach is not None:
        cols.append(TACH_COLUMN)
        arrays.append(rad_s_to_rpm(sweep.tach))
    with open(path, "w", newline="") as fh:
        fh.write(",".join(cols) + "\n")
        fh.write(_format_table(arrays))
    return path


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"cannot serialise {type(obj).__name__}")
