"""The in-memory test objects every reader fills and every writer takes.

:class:`Run` and :class:`SteadyTest` (one record per steady speed),
:class:`Sweep` (one record through a speed change) and :class:`DataError`
(bad input, naming the file, the field and the value).  Re-exported by
:mod:`rwadist.data`, the public data API.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataError  # noqa: F401  (its home is rwadist.errors; re-exported)
from ..units import CHANNELS


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


def read_text(path) -> str:
    """The UTF-8 text of ``path`` (a leading BOM dropped); DataError naming the file and the byte when it is
    not UTF-8 (a UTF-16 export or a damaged file) or cannot be read."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataError(path, "file", f"cannot be read ({exc.strerror})") from None
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise DataError(path, "encoding", "the file is UTF-16 text; save it as UTF-8 (e.g. 'CSV UTF-8' in a "
                        "spreadsheet, or `iconv -f UTF-16 -t UTF-8`)")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(path, f"byte {exc.start}", f"not UTF-8 text (byte 0x{raw[exc.start]:02x}): a damaged "
                        "file or another encoding; save it as UTF-8") from None


def read_json(path):
    """A JSON document; DataError naming the file (missing) or the line (invalid)."""
    path = Path(path)
    if not path.exists():
        raise DataError(path, "file", "does not exist")
    if path.is_dir():
        raise DataError(path, "file", "is a folder, not a JSON file")
    text = read_text(path)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise DataError(path, f"line {exc.lineno}", f"not valid JSON ({exc.msg})") from None
    except RecursionError:
        raise DataError(path, "structure", "nested too deeply to be a model or metadata file") from None


#: meta.json keys that describe how a lab file is to be read; once read, the data are SI in our channels.
READING_KEYS = ("channel_map", "tach", "unlisted_files")


def reading_provenance(meta) -> dict:
    """What a model fitted to data with test metadata ``meta`` records of how the data were read (its provenance's
    ``reading``): the channel map and tach pulse channel of ``meta.json`` and a sweep's slicing (slice length, speed
    source, slices kept and dropped), those present; {} when none is."""
    meta = dict(meta or {})
    got = {k: meta[k] for k in ("channel_map", "tach", "slicing") if k in meta}
    return {"reading": got} if got else {}


def portable_meta(meta) -> dict:
    """``meta`` without the keys that only describe the source files (channel map, tach pulse channel)."""
    return {k: v for k, v in dict(meta or {}).items() if k not in READING_KEYS}


def json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"cannot serialise {type(obj).__name__}")


@dataclass
class RawRecord:
    """One record as a file stores it, before the channel map and the time check.

    Every reader (CSV, HDF5 sweep, UFF 58, TDMS, MATLAB) fills one of these;
    :mod:`rwadist.formats.channels` turns it into a :class:`Run` or a :class:`Sweep`.

    Attributes
    ----------
    path : the file, named in errors.
    columns : file channel name -> samples, 1-D float64, shape (n,), in the file's units.
    units : file channel name -> unit string as the file gives it ('' when it gives none).
    where : file channel name -> where it sits in the file, for errors (a column, a dataset path).
    time : s, shape (n,), when the file stores a time per sample, else None.
    time_field : name of the time column/dataset, for errors.
    time_position : ``time_position(i)`` names where the step from sample i to i+1 ends.
    sample_rate : Hz, when the file stores a rate or an increment instead of (or besides) time.
    rate_rtol : relative precision of ``sample_rate`` as stored (UFF ASCII: 6 significant digits).
    rate_field : where the rate is stored, for errors.
    t0 : time of the first sample, s, when ``time`` is None.
    channels_field : what errors about the set of channels name (a CSV's ``header``).
    """

    path: Path
    columns: dict
    units: dict = field(default_factory=dict)
    where: dict = field(default_factory=dict)
    time: np.ndarray | None = None
    time_field: str = "time_s"
    time_position: object = None
    sample_rate: float | None = None
    rate_rtol: float = 0.0
    rate_field: str = "sample_rate"
    t0: float = 0.0
    channels_field: str = "channels"

    def locate(self, name: str) -> str:
        """Where channel ``name`` sits in the file (for error messages)."""
        return self.where.get(name, name)
