"""LabVIEW TDMS files (NI acquisition systems), via npTDMS.

Convention: one group per run (a run file holds one group, or names the group
to read as ``file.tdms:Group`` in ``runs.csv``); a sweep is one group.  The
channels are named ``Fx Fy Fz Tx Ty Tz`` (their unit in the NI property
``unit_string``) or like the interchange columns (``Fx_N`` ... ``Tz_Nm``), or
anything a ``channel_map`` in ``meta.json`` maps.  The time base is the NI
waveform properties ``wf_increment`` (s per sample) and ``wf_start_offset``
(s), stored as doubles: a channel without them is refused, as are channels
whose increments differ.  A ``speed_rpm`` channel or the tach channel of
``meta.json`` carries the speed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..units import CHANNEL_COLUMN
from .records import DataError, RawRecord

GROUP_SEPARATOR = ":"


def split_group(path) -> tuple:
    """``'run.tdms:Group'`` -> (Path('run.tdms'), 'Group'); no selector -> (path, None)."""
    text = str(path)
    head, sep, group = text.rpartition(GROUP_SEPARATOR)
    if sep and head.lower().endswith(".tdms"):
        return Path(head), group
    return Path(text), None


def read_record(path, group_name: str | None = None) -> RawRecord:
    """One group of a TDMS file as a :class:`RawRecord`."""
    from nptdms import TdmsFile

    path = Path(path)
    if not path.exists():
        raise DataError(path, "file", "does not exist")
    try:
        tdms = TdmsFile.read(str(path))
    except Exception as exc:  # npTDMS raises ValueError, struct.error, EOFError on a broken file
        raise DataError(path, "file", f"is not a readable TDMS file (truncated or corrupt?): {exc}") from None
    groups = tdms.groups()
    names = [g.name for g in groups]
    if group_name is None:
        if len(groups) != 1:
            raise DataError(path, "groups", f"holds {len(groups)} groups {names}; a run or sweep file holds one, "
                            "or name it in runs.csv as FILE.tdms:GROUP")
        group = groups[0]
    elif group_name in names:
        group = tdms[group_name]
    else:
        raise DataError(path, f"group {group_name!r}", f"not in the file (groups: {names})")
    gname = group.name
    columns, units, where = {}, {}, {}
    increments, offsets = [], []
    for channel in group.channels():
        loc = f"/{gname}/{channel.name}"
        props = channel.properties
        if "wf_increment" not in props:
            raise DataError(path, loc, "has no NI waveform property wf_increment (the sample step, s); write the "
                            "channel as a waveform, or add wf_increment and wf_start_offset")
        x = np.asarray(channel[:], dtype=float)
        bad = ~np.isfinite(x)
        if bad.any():
            i = int(np.argmax(bad))
            raise DataError(path, loc, f"non-finite sample at index {i}, value {float(x[i])!r}")
        columns[channel.name] = np.ascontiguousarray(x)
        units[channel.name] = str(props.get("unit_string", "") or "")
        where[channel.name] = loc
        increments.append((_property(path, loc, props, "wf_increment"), loc))
        offsets.append((_property(path, loc, props, "wf_start_offset", 0.0), loc))
    if not columns:
        raise DataError(path, f"/{gname}", "holds no channels; expected some of Fx..Tz or "
                        + ",".join(CHANNEL_COLUMN.values()))
    lengths = {n: len(x) for n, x in columns.items()}
    if len(set(lengths.values())) > 1:
        raise DataError(path, f"/{gname}", f"channels differ in length: {lengths}")
    inc, first_loc = increments[0]
    for other, loc in increments[1:]:
        if other != inc:
            raise DataError(path, f"{loc}/wf_increment", f"{other!r} s differs from {first_loc}'s {inc!r} s "
                            "(mixed sample rates in one record)")
    if not (np.isfinite(inc) and inc > 0):
        raise DataError(path, f"{first_loc}/wf_increment", f"{inc!r} s is not a positive step")
    t0, t0_loc = offsets[0]
    for other, loc in offsets:
        if not np.isfinite(other):
            raise DataError(path, f"{loc}/wf_start_offset", f"{other!r} s: the start time must be a finite number")
        if other != t0:
            raise DataError(path, f"{loc}/wf_start_offset", f"{other!r} s differs from {t0_loc}'s {t0!r} s (channels "
                            "that start at different times are not one record)")
    return RawRecord(path=path, columns=columns, units=units, where=where, sample_rate=1.0 / inc,
                     rate_field=f"{first_loc}/wf_increment ({inc!r} s)", t0=t0, channels_field=f"/{gname}",
                     t0_field=f"{t0_loc}/wf_start_offset")


def _property(path, loc, props, key, default=None) -> float:
    """A channel's numeric waveform property ``key`` (``default`` when absent); :class:`DataError` naming it when
    it is no number."""
    v = props.get(key, default)
    try:
        return float(v)
    except (TypeError, ValueError):
        raise DataError(path, f"{loc}/{key}", f"{v!r} is not a number") from None


def write(path, signals: dict, sample_rate: float, t0: float = 0.0, group: str = "run",
          extra: dict | None = None) -> Path:
    """Write channels (SI, named Fx..Tz with unit_string) as one TDMS group of waveforms."""
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    path = Path(path)
    objects = [RootObject(), GroupObject(group)]
    wf = {"wf_increment": 1.0 / sample_rate, "wf_start_offset": float(t0), "wf_samples": 0}
    for ch, y in signals.items():
        unit = "N" if ch.startswith("F") else "N·m"
        objects.append(ChannelObject(group, ch, np.asarray(y, dtype=np.float64), properties=dict(wf, unit_string=unit)))
    for name, y in (extra or {}).items():
        objects.append(ChannelObject(group, name, np.asarray(y, dtype=np.float64), properties=dict(wf)))
    with TdmsWriter(str(path)) as writer:
        writer.write_segment(objects)
    return path
