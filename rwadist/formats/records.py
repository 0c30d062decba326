"""The in-memory test objects every reader fills and every writer takes.

:class:`Run` and :class:`SteadyTest` (one record per steady speed),
:class:`Sweep` (one record through a speed change) and :class:`DataError`
(bad input, naming the file, the field and the value).  Re-exported by
:mod:`rwadist.data`, the public data API.
"""
from __future__ import annotations

import json
import math
from collections.abc import Callable
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
    invalid : channels whose samples hold a stretch that is no measurement (a dropout found by
        :func:`rwadist.data_quality.screen`): their spectra are left out of this run (as for an absent channel).
    recorded : the run's position in the order the runs were recorded (a steady test's ``runs.csv`` rows, read so
        before the runs are sorted by speed); -1 when not known.  Read only to tell a change between runs in time
        (:mod:`rwadist.diagnose.describe_line_step`, :mod:`rwadist.diagnose.run_order`).
    """

    speed: float
    sample_rate: float
    signals: dict
    t0: float = 0.0
    name: str = ""
    invalid: frozenset = frozenset()
    recorded: int = -1

    @property
    def n_samples(self) -> int:
        return len(next(iter(self.signals.values()))) if self.signals else 0

    @property
    def channels(self) -> tuple:
        return tuple(ch for ch in CHANNELS if ch in self.signals)

    def usable(self, channel: str) -> bool:
        """The run holds ``channel`` and it did not freeze (not in ``invalid``)."""
        return channel in self.signals and channel not in self.invalid


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
    name : the file it was read from ("" when made in memory), for messages.
    """

    time: np.ndarray
    signals: dict
    sample_rate: float
    tach: np.ndarray | None = None
    meta: dict = field(default_factory=dict)
    name: str = ""

    @property
    def channels(self) -> tuple:
        return tuple(ch for ch in CHANNELS if ch in self.signals)


#: the first bytes of binary files a user may give where text goes, and what each is
BINARY_SIGNATURES = {b"\x89HDF\r\n\x1a\n": "an HDF5 file", b"MATLAB 5.0 MAT-file": "a MATLAB .mat file",
                     b"TDSm": "a TDMS file", b"PK\x03\x04": "a zip archive (an FMU, a spreadsheet)"}


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
    kind = next((k for sig, k in BINARY_SIGNATURES.items() if raw.startswith(sig)), None)
    if kind is not None:
        raise DataError(path, "file", f"{kind}, not text: this file is read where a text file is expected (a model "
                        "file is JSON; test data go to read, fit or diagnose)")
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


#: highest wheel speed a test may record, rpm (as the command line's and the model file's: flight wheels run below
#: ~10 000 rpm): a speed beyond is a unit slip or a corrupted file
MAX_RPM = 100_000.0
#: largest load sample a test may record after its channel map, N or N·m (a load cell under a wheel reads below
#: ~1e3): a sample beyond is a corrupted file or a unit slip, whose square would overflow the spectra
MAX_LOAD = 1e9
#: largest start time of a record, s (a year: a time stamp in s since an epoch is converted to the record's own)
MAX_T0_S = 3.2e7
#: highest sample rate a test's metadata may declare, Hz (load-cell systems sample at most ~100 kHz)
MAX_SAMPLE_RATE_HZ = 1e7
#: most tach pulses per revolution (an optical encoder has at most a few thousand)
MAX_PULSES_PER_REV = 100_000


def check_speed_rpm(path, field: str, rpm) -> None:
    """Speeds (rpm, a number or an array) finite and within +-:data:`MAX_RPM`; :class:`DataError` naming ``path``,
    ``field`` and the first bad value (with its index for an array)."""
    a = np.atleast_1d(np.asarray(rpm, dtype=float))
    bad = ~np.isfinite(a) | (np.abs(a) > MAX_RPM)
    if bad.any():
        i = int(np.argmax(bad))
        where = f" at index {i}" if a.size > 1 else ""
        raise DataError(path, field, f"speed {float(a[i])!r} rpm{where}: must be finite within +-{MAX_RPM:g} rpm "
                        "(a unit slip? speeds are in rpm)")


def check_rate_bound(path, field: str, rate: float) -> None:
    """A sample rate (Hz) at most :data:`MAX_SAMPLE_RATE_HZ`; :class:`DataError` naming ``path`` and ``field``."""
    if not rate <= MAX_SAMPLE_RATE_HZ:
        raise DataError(path, field, f"{rate!r} Hz: at most {MAX_SAMPLE_RATE_HZ:g} Hz (a unit slip? Hz, not kHz)")


def check_loads(path, signals: dict, where: dict | None = None) -> None:
    """Load samples (SI, after the channel map) within +-:data:`MAX_LOAD`: :class:`DataError` naming ``path``, the
    channel (where the file keeps it) and the first bad sample -- never a run dropped later because its spectrum
    overflowed."""
    for ch, x in signals.items():
        a = np.asarray(x)
        if a.size and float(np.max(np.abs(a))) > MAX_LOAD:
            i = int(np.argmax(np.abs(a) > MAX_LOAD))
            loc = (where or {}).get(ch, f"channel {ch}")
            raise DataError(path, loc, f"sample {float(a[i])!r} at index {i} is beyond any load a wheel test "
                            f"records (|x| <= {MAX_LOAD:g} N or N·m): a corrupted file or a unit slip")


def portable_meta(meta) -> dict:
    """``meta`` without the keys that only describe the source files (channel map, tach pulse channel)."""
    return {k: v for k, v in dict(meta or {}).items() if k not in READING_KEYS}


def json_text(doc, **kw) -> str:
    """``doc`` as valid JSON text: numpy values as Python numbers, every non-finite number (NaN is no JSON) as null --
    the free-form places of metadata carry what a lab wrote; the keys a reader uses are refused when not finite."""
    def safe(x):
        if isinstance(x, dict):
            return {k: safe(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [safe(v) for v in x]
        if isinstance(x, np.ndarray):
            return safe(x.tolist())
        if isinstance(x, np.generic):
            x = x.item()
        return None if isinstance(x, float) and not math.isfinite(x) else x
    return json.dumps(safe(doc), allow_nan=False, default=json_default, **kw)


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
    t0_field : where ``t0`` is stored, for errors.
    """

    path: Path
    columns: dict
    units: dict = field(default_factory=dict)
    where: dict = field(default_factory=dict)
    time: np.ndarray | None = None
    time_field: str = "time_s"
    time_position: Callable[[int], str] | None = None
    sample_rate: float | None = None
    rate_rtol: float = 0.0
    rate_field: str = "sample_rate"
    t0: float = 0.0
    channels_field: str = "channels"
    t0_field: str = "t0"

    def locate(self, name: str) -> str:
        """Where channel ``name`` sits in the file (for error messages)."""
        return self.where.get(name, name)
