"""Test data in memory and on disk: the public data API (layouts in ``docs/formats.md``).

Two kinds of measurement:

* :class:`SteadyTest` -- one run per steady wheel speed.  On disk: a directory
  with ``runs.csv`` (columns ``file,speed_rpm``), one file per run and an
  optional ``meta.json``.  A run file is picked by its extension: the
  interchange CSV (header ``time_s,Fx_N,Fy_N,Fz_N,Tx_Nm,Ty_Nm,Tz_Nm``, channels
  may be absent), UFF 58 (``.uff``/``.unv``), TDMS (``.tdms``, ``.tdms:GROUP``)
  or MATLAB (``.mat``, v5 or v7.3); see :mod:`rwadist.formats`.
* :class:`Sweep` -- one long record through a speed change (spin-up,
  run-down), optionally with a ``speed_rpm`` tach column or a tach pulse
  channel, in any of those formats; its ``meta.json`` is the sidecar
  ``NAME.meta.json``.

``meta.json`` may map the lab's channel names, units, signs and a 6x6
calibration matrix to ours (:mod:`rwadist.formats.channels`) and name a tach
pulse channel (:mod:`rwadist.formats.tach`).  Time stamps are read as
instruments print them (:mod:`rwadist.formats.timebase`).

Documented handling of awkward but legal input:

* runs are sorted by speed on reading (stable, so file order breaks ties);
* duplicate speeds are kept as separate runs -- each is an independent
  measurement (a saturated spin-up gives many runs at its top speed);
* negative speeds (wheel spinning about -z) keep their sign; spectra and the
  empirical fit use |Omega|;
* zero speed is kept: it is the noise run of a test, not used by the fit;
* a channel absent from a run is recorded as absent, never filled in.

Everything else that is wrong -- NaN samples, a truncated line, an unknown
column (wrong units), non-uniform time (beyond the rounding of its printed
digits), a duplicated file entry, runs at different sample rates, an empty
directory -- raises :class:`DataError` naming the file, the field and the value.
"""
from __future__ import annotations

import csv
import io
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from .formats import registry
from .formats.channels import SPEED_COLUMN, to_run, to_sweep
from .formats.csv_table import TIME_COLUMN
from .formats.meta import check_f_lim_meta, check_meta
from .formats.records import (
    DataError,
    RawRecord,
    Run,
    SteadyTest,
    Sweep,
    check_speed_rpm,
    json_default,
    json_text,
    portable_meta,
    read_json,
    read_text,
)
from .formats.timebase import sample_step
from .outputs import MANIFEST, WRITER, WRITER_KEY
from .progress import tqdm
from .units import CHANNEL_COLUMN, CHANNELS, COLUMN_CHANNEL, rad_s_to_rpm, rpm_to_rad_s  # noqa: F401 (re-exported)

__all__ = ["DataError", "Run", "SteadyTest", "Sweep", "RawRecord", "read_json", "read_run", "read_steady",
           "read_sweep", "read_data", "write_run", "write_steady", "write_sweep", "sample_step",
           "RUNS_FILE", "META_FILE", "TIME_COLUMN", "TACH_COLUMN"]

RUNS_FILE = "runs.csv"
META_FILE = "meta.json"
TACH_COLUMN = SPEED_COLUMN
_json_default = json_default  # the name the writers of other modules used


def uniform_step(path, field_name: str, time: np.ndarray, position=lambda i: f"line {i + 3}") -> float:
    """The sampling step (s) of a time column, as :func:`rwadist.formats.timebase.sample_step`."""
    return sample_step(path, field_name, time, position=position)


# --------------------------------------------------------------------------- reading

def _read_meta(path: Path) -> dict:
    """A test's meta.json (or a sweep's sidecar), {} when absent; checks the keys the readers use."""
    if not path.exists():
        return {}
    meta = check_meta(read_json(path), path)
    # who wrote the folder is the folder's, not the test's (write_steady sets it again): the test's meta round-trips
    meta.pop(WRITER_KEY, None)
    return meta


def read_run(path, speed: float | None, sample_rate: float | None = None, meta: dict | None = None,
             meta_path=META_FILE) -> Run:
    """Read one run file of any supported format.

    Parameters
    ----------
    path : the file (``.csv``, ``.uff``/``.unv``, ``.tdms`` or ``.tdms:GROUP``, ``.mat``).
    speed : rad/s, or None to take it from the tach pulse channel named in ``meta``.
    sample_rate : Hz, if declared elsewhere (overrides ``meta['sample_rate_hz']``).
    meta : the test's meta.json (channel map, tach); ``meta_path`` names it in errors.
    """
    meta = dict(meta or {})
    if sample_rate is not None:
        meta["sample_rate_hz"] = sample_rate
    record = registry.read_record(path, meta)
    return to_run(record, speed, meta, meta_path, name=Path(str(path)).name)


def read_steady(directory, progress: bool = False) -> SteadyTest:
    """Read a steady-state test directory (``runs.csv`` + one file per run, any supported format);
    ``progress`` shows a bar over the runs.  ``speed_rpm`` may be empty when meta.json names a tach channel."""
    directory = Path(directory)
    if not directory.is_dir():
        raise DataError(directory, "directory", "does not exist or is not a directory")
    runs_path = directory / RUNS_FILE
    if not runs_path.exists():
        content = sorted(p.name for p in directory.iterdir())
        what = "is empty" if not content else f"has no {RUNS_FILE} (found {content[:5]})"
        sweeps = [n for n in content if "sweep" in n.lower() and not n.lower().endswith(".json")]
        hint = f"; for a spin-up/run-down record give the file itself, e.g. {directory / sweeps[0]}" if sweeps else ""
        raise DataError(directory, RUNS_FILE, f"directory {what}; a steady-state test needs {RUNS_FILE} "
                        f"with columns file,speed_rpm{hint}")
    meta_path = directory / META_FILE
    meta = _read_meta(meta_path)
    with io.StringIO(read_text(runs_path), newline="") as fh:
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
    runs: list[Run] = []
    files_seen: dict[str, int] = {}     # file -> line of runs.csv naming it
    for lineno, row in tqdm(rows, desc="reading runs", unit="run", disable=not progress, leave=False):
        fname, speed_text = row.get("file", ""), row.get("speed_rpm", "")
        if not fname:
            raise DataError(runs_path, f"file (line {lineno})", "empty file name")
        if fname in files_seen:
            raise DataError(runs_path, f"file (line {lineno})",
                            f"{fname!r} is listed twice (first at line {files_seen[fname]})")
        files_seen[fname] = lineno
        if speed_text == "" and "tach" in meta:
            speed = None  # from the tach pulse channel
        else:
            try:
                rpm = float(speed_text)
            except ValueError:
                raise DataError(runs_path, f"speed_rpm (line {lineno})", f"{speed_text!r} is not a number") from None
            check_speed_rpm(runs_path, f"speed_rpm (line {lineno})", rpm)
            speed = float(rpm_to_rad_s(rpm))
        file_name = fname.rsplit(":", 1)[0] if ".tdms:" in fname.lower() else fname
        if not (directory / file_name).is_file():
            raise DataError(runs_path, f"file (line {lineno})", f"{file_name!r} does not exist in {directory}")
        runs.append(read_run(directory / fname, speed, meta=meta, meta_path=meta_path))
        if runs[-1].sample_rate != runs[0].sample_rate:
            raise DataError(directory / fname, "sample rate", f"{runs[-1].sample_rate!r} Hz differs from "
                            f"{runs[0].name}'s {runs[0].sample_rate!r} Hz (mixed sample rates across runs); "
                            "one test holds one sample rate: resample the runs to one rate (or split them into "
                            "one test per rate)")
    files_read = {f.rsplit(":", 1)[0] if ".tdms:" in f.lower() else f for f in files_seen}
    # rwadist's own record of the files it wrote in the folder (outputs.MANIFEST) is no run left out
    listed = files_read | {RUNS_FILE, META_FILE, MANIFEST}
    unlisted = sorted(p.name for p in directory.iterdir() if p.is_file() and p.name not in listed)
    if unlisted:
        # kept in meta so nothing goes unnoticed; the CLI prints it
        meta = dict(meta, unlisted_files=unlisted)
    check_f_lim_meta(meta, runs[0].sample_rate, meta_path)
    # runs.csv's rows are the order the runs were recorded: kept on each run before the sort by speed
    return SteadyTest([replace(r, recorded=i) for i, r in enumerate(runs)], meta).sorted()


def read_sweep(path, sample_rate: float | None = None) -> Sweep:
    """Read a sweep file of any supported format (time, channels, optional tach).

    Its ``meta.json`` is the sidecar ``NAME.meta.json`` beside it (channel map, tach, sample rate).
    """
    path = Path(path)
    file = Path(str(path).rsplit(":", 1)[0]) if ".tdms:" in str(path).lower() else path
    if file.is_dir():
        raise DataError(path, "file", "is a directory; a sweep is one file")
    if not file.exists():
        raise DataError(path, "file", "does not exist")
    meta_path = file.with_suffix(".meta.json")
    meta = _read_meta(meta_path)
    record = registry.read_record(path, meta)
    sweep = to_sweep(record, meta, meta_path, declared_rate=sample_rate)
    check_f_lim_meta(meta, sweep.sample_rate, meta_path)
    return sweep


def read_data(path, progress: bool = False):
    """A directory is a steady-state test, a file a sweep (``.h5`` files: HDF5, either)."""
    path = Path(path)
    if path.is_dir():
        return read_steady(path, progress=progress)
    if path.suffix.lower() in (".h5", ".hdf5"):
        from .hdf5 import read_hdf5  # h5py only when a file needs it: every command imports this module

        obj = read_hdf5(path)
    else:
        obj = read_sweep(path)
    if isinstance(obj, Sweep) and not obj.name:
        obj.name = str(path)            # a sweep's messages name its file (they said <sweep>)
    return obj


# --------------------------------------------------------------------------- writing

def write_run(path, run: Run, fmt: str = "csv") -> Path:
    """Write one run in format ``fmt`` (see :mod:`rwadist.formats.registry`)."""
    return registry.write_record(path, fmt, {c: run.signals[c] for c in run.channels}, run.sample_rate, run.t0)


def write_steady(test: SteadyTest, directory, fmt: str = "csv") -> Path:
    """Write a steady-state test: ``runs.csv`` (its rows in the order the runs were recorded where that is known,
    :attr:`Run.recorded`, else in the test's order), ``meta.json`` and one ``fmt`` file per run. Returns the
    directory."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rates = {r.sample_rate for r in test.runs}
    meta = portable_meta(test.meta)
    # the writer, so that this folder may be replaced by rwadist's next dataset there (outputs.check_dataset_dir);
    # a folder without it (a lab's runs) never is
    meta[WRITER_KEY] = WRITER
    if len(rates) == 1:
        meta["sample_rate_hz"] = rates.pop()
    else:
        meta.pop("sample_rate_hz", None)
    ext = registry.EXTENSION[fmt]
    names, taken = [], {RUNS_FILE, META_FILE}
    for i, run in enumerate(test.runs):
        name = str(Path(run.name).with_suffix(ext)) if run.name else f"run_{i:04d}{ext}"
        k = i
        while name in taken:  # never overwrite another run or the index files
            name = f"run_{k:04d}{ext}"
            k += 1
        taken.add(name)
        names.append(name)
        write_run(directory / name, run, fmt)
    # the rows in the order the runs were recorded where it is known (Run.recorded: read back so)
    rows = sorted(zip(names, test.runs), key=lambda x: x[1].recorded if x[1].recorded >= 0 else len(names))
    with open(directory / RUNS_FILE, "w", newline="") as fh:
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(["file", "speed_rpm"])
        for name, run in rows:
            writer.writerow([name, repr(float(rad_s_to_rpm(run.speed)))])
    (directory / META_FILE).write_text(json_text(meta, indent=2) + os.linesep)
    return directory


def write_sweep(sweep: Sweep, path, fmt: str | None = None, with_meta: bool = False) -> Path:
    """Write a sweep (with the ``speed_rpm`` channel when a tach signal exists); ``fmt`` from the extension
    when None.  ``with_meta``: a non-empty ``meta`` goes to the sidecar ``NAME.meta.json``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fmt = fmt or registry.reader_of(path)
    if fmt == "csv" and not np.array_equal(sweep.time, sweep.time[0] + np.arange(len(sweep.time)) / sweep.sample_rate):
        header = [TIME_COLUMN] + [registry.CHANNEL_COLUMN[c] for c in sweep.channels]
        cols = [sweep.time] + [sweep.signals[c] for c in sweep.channels]
        if sweep.tach is not None:
            header.append(TACH_COLUMN)
            cols.append(rad_s_to_rpm(sweep.tach))
        from .formats.csv_table import write_table
        write_table(path, header, cols)
    else:
        registry.write_record(path, fmt, {c: sweep.signals[c] for c in sweep.channels}, sweep.sample_rate,
                              float(sweep.time[0]), sweep.tach)
    meta = dict(portable_meta(sweep.meta), sample_rate_hz=float(sweep.sample_rate))
    if with_meta:
        path.with_suffix(".meta.json").write_text(json_text(meta, indent=2) + os.linesep)
    return path
