"""HDF5 storage of test data, on top of the CSV interchange format.

One file holds either a :class:`~rwadist.data.SteadyTest` or a
:class:`~rwadist.data.Sweep`, losslessly (float64 samples, exact sample rate,
t0, speeds and ``meta``), which the CSV layout cannot always do (a sweep CSV
has no place for ``meta`` or the exact sample rate).

Layout (format ``"rwadist.test"``, version 1)::

    /                      attrs: format="rwadist.test", format_version=1,
                                  kind="steady" | "sweep", meta=<JSON object string>
    steady:
    /runs/run_0000         group per run; attrs speed_rad_s (signed), speed_rpm,
                           sample_rate_hz, t0 (s), name (source file name)
    /runs/run_0000/Fx_N    one 1-D float64 dataset per channel present, named
    /runs/run_0000/Tx_Nm   by its interchange column (N or N·m); absent
                           channels have no dataset
    sweep:
    /time_s                1-D float64, s
    /Fx_N ... /Tz_Nm       channels present
    /speed_rad_s           optional tach, rad/s
                           root attrs also carry sample_rate_hz

Runs are returned sorted by speed (stable), as :func:`rwadist.data.read_steady`
does.  Every problem found on reading raises :class:`~rwadist.data.DataError`
naming the file and the field (attribute or dataset path).
"""
from __future__ import annotations

import json
import math
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np

from .formats.meta import check_f_lim_meta, check_meta
from .formats.records import (
    DataError,
    Run,
    SteadyTest,
    Sweep,
    check_loads,
    check_rate_bound,
    check_speed_rpm,
    json_text,
    portable_meta,
)
from .formats.timebase import sample_step
from .units import CHANNEL_COLUMN, CHANNELS, COLUMN_CHANNEL, rad_s_to_rpm

FORMAT = "rwadist.test"
FORMAT_VERSION = 1
RUNS_GROUP = "runs"
TIME_DATASET = "time_s"
TACH_DATASET = "speed_rad_s"


# --------------------------------------------------------------------------- writing

@contextmanager
def file_in_memory(path, header: bytes = b""):
    """Yield a new HDF5 file (``h5py.File``) built in memory; when the block ends it is written to ``path`` in one
    plain write (``header``, a user block of 512·2^k bytes, first), never when the block raises.

    HDF5 writing its own file on a full disk printed a traceback from each h5py destructor and then crashed the
    process (exit 139), leaving a part file; in memory, a full disk is one ``OSError`` from the final write
    (the command's one-line error, its temporary removed).  Memory: the file's size (compressed), once."""
    import uuid

    fh = h5py.File(f"rwadist-{uuid.uuid4().hex}.h5", "w", driver="core", backing_store=False)
    try:
        yield fh
        fh.flush()
        image = fh.id.get_file_image()
    finally:
        fh.close()
    with open(path, "wb") as out:
        out.write(header)
        out.write(image)


def _float_dataset(group, name, values, compression, dtype=np.float64):
    data = np.ascontiguousarray(values, dtype=dtype)
    if data.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {data.shape}")
    kw = {"compression": compression, "shuffle": True} if compression and data.size else {}
    group.create_dataset(name, data=data, **kw)


def write_hdf5(obj, path, *, compression: str | None = None, precision: str = "float64") -> Path:
    """Write a :class:`SteadyTest` or :class:`Sweep` to an HDF5 file. Returns the path.

    ``compression``: an h5py filter name (e.g. ``"gzip"``), lossless; None stores raw.
    ``precision``: ``"float64"`` (lossless, the default) or ``"float32"`` for the load channels
    (a 24-bit mantissa: the resolution of a 24-bit acquisition system, half the size on disk);
    time, tach and every attribute stay float64.
    """
    if precision not in ("float64", "float32"):
        raise ValueError(f"precision {precision!r} is neither 'float64' nor 'float32'")
    sample_dtype = np.dtype(precision)
    path = Path(path)
    if isinstance(obj, SteadyTest):
        kind = "steady"
    elif isinstance(obj, Sweep):
        kind = "sweep"
    else:
        raise TypeError(f"write_hdf5 takes a SteadyTest or a Sweep, not {type(obj).__name__}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with file_in_memory(path) as fh:
        fh.attrs["format"] = FORMAT
        fh.attrs["format_version"] = FORMAT_VERSION
        fh.attrs["kind"] = kind
        fh.attrs["meta"] = json_text(portable_meta(obj.meta))
        if kind == "steady":
            runs = fh.create_group(RUNS_GROUP)
            width = max(4, len(str(len(obj.runs))))
            for i, run in enumerate(obj.runs):
                g = runs.create_group(f"run_{i:0{width}d}")
                g.attrs["speed_rad_s"] = float(run.speed)
                g.attrs["speed_rpm"] = float(rad_s_to_rpm(run.speed))
                g.attrs["sample_rate_hz"] = float(run.sample_rate)
                g.attrs["t0"] = float(run.t0)
                g.attrs["name"] = str(run.name)
                for ch in run.channels:
                    _float_dataset(g, CHANNEL_COLUMN[ch], run.signals[ch], compression, sample_dtype)
        else:
            fh.attrs["sample_rate_hz"] = float(obj.sample_rate)
            _float_dataset(fh, TIME_DATASET, obj.time, compression)
            for ch in obj.channels:
                _float_dataset(fh, CHANNEL_COLUMN[ch], obj.signals[ch], compression, sample_dtype)
            if obj.tach is not None:
                _float_dataset(fh, TACH_DATASET, obj.tach, compression)
    return path


# --------------------------------------------------------------------------- reading

def _attr(path, obj, name, where=""):
    field = f"{where}/{name}" if where else name
    if name not in obj.attrs:
        raise DataError(path, field, "attribute missing")
    value = obj.attrs[name]
    if isinstance(value, bytes):
        value = value.decode("utf-8")
    return value, field


def _str_attr(path, obj, name, where=""):
    value, field = _attr(path, obj, name, where)
    if not isinstance(value, str):
        raise DataError(path, field, f"must be a string, got {value!r}")
    return value


def _float_attr(path, obj, name, where="", positive=False):
    value, field = _attr(path, obj, name, where)
    try:
        x = float(np.asarray(value).item())
    except (TypeError, ValueError):
        raise DataError(path, field, f"must be a number, got {value!r}") from None
    if not math.isfinite(x) or (positive and not x > 0):
        raise DataError(path, field, f"must be a {'positive ' if positive else ''}finite number, got {x!r}")
    return x


def _samples(path, group, name) -> np.ndarray:
    """A 1-D, real, finite dataset as float64."""
    field = f"{group.name.rstrip('/')}/{name}"
    obj = group.get(name)
    if obj is None:
        raise DataError(path, field, "dataset missing")
    if not isinstance(obj, h5py.Dataset):
        raise DataError(path, field, "is a group, expected a dataset")
    if obj.dtype.kind not in "fiu":
        raise DataError(path, field, f"dtype {obj.dtype} is not a real number type")
    if obj.ndim != 1:
        raise DataError(path, field, f"shape {obj.shape}, expected 1-D")
    data = np.asarray(obj[()], dtype=np.float64)
    bad = ~np.isfinite(data)
    if bad.any():
        i = int(np.argmax(bad))
        raise DataError(path, field, f"{int(bad.sum())} non-finite sample(s) (NaN/inf); first at index {i}, "
                        f"value {data[i]!r}")
    return data


def _channels(path, group, skip=()) -> dict:
    """Channel datasets of a group (named by interchange column) -> {channel: samples}."""
    signals = {}
    for name in group:
        if name in skip:
            continue
        if name not in COLUMN_CHANNEL:
            hint = ""
            stem = name.split("_")[0]
            if stem in CHANNEL_COLUMN:
                hint = f" (expected {CHANNEL_COLUMN[stem]!r}: values must be SI, N or N·m)"
            raise DataError(path, f"{group.name.rstrip('/')}/{name}",
                            f"unknown dataset{hint}; allowed: {sorted(COLUMN_CHANNEL) + list(skip)}")
        signals[COLUMN_CHANNEL[name]] = _samples(path, group, name)
    where = group.name.rstrip("/") or "/"
    if not signals:
        raise DataError(path, where, "no channel datasets; expected some of " + ",".join(CHANNEL_COLUMN.values()))
    lengths = {ch: len(v) for ch, v in signals.items()}
    if len(set(lengths.values())) > 1:
        raise DataError(path, where, f"channel datasets differ in length: "
                        f"{ {CHANNEL_COLUMN[c]: n for c, n in lengths.items()} }")
    if next(iter(lengths.values())) < 1:
        raise DataError(path, where, "channel datasets are empty")
    return {ch: signals[ch] for ch in CHANNELS if ch in signals}


def _check_time(path, time: np.ndarray, fs: float, stored_dtype=np.float64):
    field = f"/{TIME_DATASET}"
    stored_rtol = float(np.finfo(stored_dtype).eps) if np.dtype(stored_dtype).kind == "f" else 0.0
    sample_step(path, field, time, fs, declared_by="attribute sample_rate_hz",
                position=lambda i: f"index {i + 1}", stored_rtol=stored_rtol if stored_rtol > 1e-15 else 0.0)


def _read_run(path, group) -> Run:
    where = group.name
    speed = _float_attr(path, group, "speed_rad_s", where)
    if "speed_rpm" in group.attrs:
        rpm = _float_attr(path, group, "speed_rpm", where)
        if abs(float(rad_s_to_rpm(speed)) - rpm) > 1e-9 * max(abs(rpm), 1.0):
            raise DataError(path, f"{where}/speed_rpm", f"{rpm!r} rpm disagrees with speed_rad_s {speed!r} "
                            f"({float(rad_s_to_rpm(speed))!r} rpm)")
    fs = _float_attr(path, group, "sample_rate_hz", where, positive=True)
    check_speed_rpm(path, f"{where}/speed_rad_s", rad_s_to_rpm(speed))
    check_rate_bound(path, f"{where}/sample_rate_hz", fs)
    t0 = _float_attr(path, group, "t0", where) if "t0" in group.attrs else 0.0
    name = _str_attr(path, group, "name", where) if "name" in group.attrs else group.name.rsplit("/", 1)[-1]
    signals = _channels(path, group)
    check_loads(path, signals, {c: f"{where}/{CHANNEL_COLUMN[c]}" for c in signals})
    return Run(speed=speed, sample_rate=fs, signals=signals, t0=t0, name=name)


def _read_steady(path, fh) -> list[Run]:
    """The runs of a steady test's file, in the order of their group names."""
    runs_group = fh.get(RUNS_GROUP)
    if runs_group is None or not isinstance(runs_group, h5py.Group):
        raise DataError(path, f"/{RUNS_GROUP}", "group missing; a steady test keeps one group per run there")
    names = sorted(runs_group)
    if not names:
        raise DataError(path, f"/{RUNS_GROUP}", "no runs")
    runs: list[Run] = []
    for name in names:
        g = runs_group[name]
        if not isinstance(g, h5py.Group):
            raise DataError(path, g.name, "is a dataset, expected a run group")
        runs.append(_read_run(path, g))
    return runs


def _read_sweep(path, fh) -> tuple[np.ndarray, dict[str, np.ndarray], float, np.ndarray | None]:
    """(time s, channel -> SI samples, sample rate Hz, tach speed rad/s or None) of a sweep's file, checked."""
    fs = _float_attr(path, fh, "sample_rate_hz", positive=True)
    check_rate_bound(path, "sample_rate_hz", fs)
    time = _samples(path, fh, TIME_DATASET)
    signals = _channels(path, fh, skip=(TIME_DATASET, TACH_DATASET))
    check_loads(path, signals, {c: f"/{CHANNEL_COLUMN[c]}" for c in signals})
    n = len(time)
    for ch, x in signals.items():
        if len(x) != n:
            raise DataError(path, f"/{CHANNEL_COLUMN[ch]}", f"{len(x)} samples, {TIME_DATASET} has {n}")
    _check_time(path, time, fs, fh[TIME_DATASET].dtype)
    tach = None
    if TACH_DATASET in fh:
        tach = _samples(path, fh, TACH_DATASET)
        check_speed_rpm(path, f"/{TACH_DATASET}", rad_s_to_rpm(tach))
        if len(tach) != n:
            raise DataError(path, f"/{TACH_DATASET}", f"{len(tach)} samples, {TIME_DATASET} has {n}")
    return time, signals, fs, tach


def read_hdf5(path) -> SteadyTest | Sweep:
    """Read a file written by :func:`write_hdf5`: a :class:`SteadyTest` or a :class:`Sweep`."""
    path = Path(path)
    if not path.exists():
        raise DataError(path, "file", "does not exist")
    if not h5py.is_hdf5(path):
        raise DataError(path, "file", "is not an HDF5 file")
    try:
        fh = h5py.File(path, "r")
    except OSError as exc:
        raise DataError(path, "file", f"cannot be opened ({exc})") from exc
    with fh:
        try:
            return _read_open(path, fh)
        except DataError:
            raise
        except (KeyError, OSError, RuntimeError, ValueError, TypeError) as exc:
            # h5py raises these on a damaged file (bad object headers, dangling links, flipped bytes)
            raise DataError(path, "file", f"damaged HDF5 file: {str(exc)[:160]}; re-export it or "
                            "`rwadist convert` the original data again") from None


def _read_open(path, fh) -> SteadyTest | Sweep:
    """The test in the open HDF5 file ``fh`` (see :func:`read_hdf5`)."""
    fmt = _str_attr(path, fh, "format")
    if fmt != FORMAT:
        raise DataError(path, "format", f"{fmt!r} is not {FORMAT!r}")
    version, _ = _attr(path, fh, "format_version")
    try:
        version_int = int(np.asarray(version).item())
        ok = version_int == np.asarray(version).item()
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise DataError(path, "format_version", f"{version!r} is not an integer version")
    if version_int != FORMAT_VERSION:
        raise DataError(path, "format_version", f"version {version_int} is not supported "
                        f"(this reader knows version {FORMAT_VERSION})")
    kind = _str_attr(path, fh, "kind")
    meta = {}
    if "meta" in fh.attrs:
        text = _str_attr(path, fh, "meta")
        try:
            meta = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DataError(path, "meta", f"not valid JSON ({exc.msg})") from exc
        check_meta(meta, path, "meta.")
    if kind == "steady":
        runs = _read_steady(path, fh)
        check_f_lim_meta(meta, runs[0].sample_rate, path, "meta.")
        return SteadyTest(runs, meta).sorted()
    if kind == "sweep":
        time, signals, fs, tach = _read_sweep(path, fh)
        check_f_lim_meta(meta, fs, path, "meta.")
        return Sweep(time=time, signals=signals, sample_rate=fs, tach=tach, meta=meta)
    raise DataError(path, "kind", f"{kind!r} is neither 'steady' nor 'sweep'")
