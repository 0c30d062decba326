"""From a file's channels to ours: names, units, signs, a calibration matrix, the time base.

Without a ``channel_map`` in ``meta.json`` a file channel is taken by name:
an interchange column (``Fx_N`` ... ``Tz_Nm``, SI by its name) or a bare
channel name (``Fx`` ... ``Tz``) whose unit the file states (a TDMS
``unit_string``, a UFF ordinate label or unit exponents).

With a map (see ``docs/formats.md``)::

    "channel_map": {
      "calibration": {"inputs": ["LC1", ..., "LC6"], "matrix": [[...6...], ... 6 rows]},
      "channels": {"LC1": {"channel": "Fy", "unit": "lbf", "sign": -1}, ...}
    }

the calibration matrix is applied first (the six named inputs become
``matrix @ inputs``, in each input's mapped unit), then each mapped channel is
renamed, converted to SI and multiplied by its sign.  File channels the map
does not name are refused, except the tach channels (``speed_rpm`` column,
the ``tach`` pulse channel named in ``meta.json``).
"""
from __future__ import annotations

import math

import numpy as np

from ..units import CHANNEL_COLUMN, CHANNELS, COLUMN_CHANNEL, rad_s_to_rpm, rpm_to_rad_s
from .records import MAX_T0_S, DataError, RawRecord, Run, Sweep, check_loads, check_rate_bound, check_speed_rpm
from .tach import steady_speed_from_tach, sweep_speed_from_tach
from .timebase import check_rate, sample_step

#: Unit spellings -> (kind, factor to SI).  Forces in N, torques in N·m.  Matched without regard to case, so no
#: spelling whose case carries an SI prefix is here ("mN" is a millinewton, "MN" a meganewton: see UNITS_EXACT).
_UNIT_SPELLINGS: tuple[tuple[tuple[str, ...], str, float], ...] = (
        (("N", "newton", "newtons"), "force", 1.0),
        (("kN", "kilonewton"), "force", 1000.0),
        (("lbf", "lb", "lbs", "pound-force"), "force", 4.4482216152605),
        (("N·m", "Nm", "N*m", "N.m", "N m", "N-m", "m·N"), "torque", 1.0),
        (("in·lbf", "in-lbf", "in*lbf", "inlbf", "in.lbf", "in lbf", "lbf·in", "lbf-in", "lbf*in", "lbf.in",
          "lbf in", "in-lb", "lb-in"), "torque", 0.1129848290276167),
        (("ft·lbf", "ft-lbf", "ft*lbf", "ftlbf", "ft.lbf", "ft lbf", "lbf·ft", "lbf-ft", "lbf*ft", "lbf.ft",
          "lbf ft", "ft-lb", "lb-ft"), "torque", 1.3558179483314004),
)
UNITS: dict[str, tuple[str, float]] = {n.lower(): (kind, factor) for names, kind, factor in _UNIT_SPELLINGS
                                       for n in names}
#: Spellings with a milli prefix, matched exactly (their case is their meaning): checked before UNITS.
_MILLI_SPELLINGS: tuple[tuple[tuple[str, ...], str, float], ...] = (
        (("mN", "millinewton"), "force", 1e-3),
        (("mN·m", "mNm", "mN*m", "mN.m", "mN m", "mN-m", "N·mm", "Nmm", "N*mm", "N.mm", "N mm", "N-mm"), "torque", 1e-3),
)
UNITS_EXACT: dict[str, tuple[str, float]] = {n: (kind, factor) for names, kind, factor in _MILLI_SPELLINGS for n in names}
CHANNEL_KIND = {ch: ("force" if ch.startswith("F") else "torque") for ch in CHANNELS}
#: Column of a measured speed in rpm (interchange sweeps).
SPEED_COLUMN = "speed_rpm"
#: Condition number above which a calibration matrix counts as singular.
MAX_CALIBRATION_CONDITION = 1e12


def unit_factor(unit: str, channel: str, path, where: str) -> float:
    """SI factor of ``unit`` for our ``channel`` (N or N·m); DataError naming the channel otherwise."""
    exact = str(unit).strip()
    key = exact.lower()
    if exact not in UNITS_EXACT and key not in UNITS:
        raise DataError(path, where, f"unit {unit!r} is not known; use one of N, mN, kN, lbf (forces), "
                        "N·m, mN·m, in·lbf, ft·lbf (torques)")
    kind, factor = UNITS_EXACT[exact] if exact in UNITS_EXACT else UNITS[key]
    if kind != CHANNEL_KIND[channel]:
        raise DataError(path, where, f"unit {unit!r} is a {kind} unit, but channel {channel} is a "
                        f"{CHANNEL_KIND[channel]}")
    return factor


def _known_unit(unit: str) -> bool:
    """``unit`` is a spelling :func:`unit_factor` knows."""
    return bool(unit) and (unit in UNITS_EXACT or unit.lower() in UNITS)


def _tach_names(meta: dict) -> set:
    tach = meta.get("tach") if isinstance(meta, dict) else None
    names = {SPEED_COLUMN}
    if isinstance(tach, dict) and isinstance(tach.get("channel"), str):
        names.add(tach["channel"])
    return names


def _tach_hint(record: RawRecord, meta: dict, meta_path) -> str:
    """The end of an unknown-channel error when ``meta`` names a tach pulse channel the file does not have (the
    unknown channel is then likely the tach under another name), else ''."""
    tach = meta.get("tach") if isinstance(meta, dict) else None
    name = tach.get("channel") if isinstance(tach, dict) else None
    if isinstance(name, str) and name not in record.columns:
        return (f"; {meta_path} tach.channel {name!r} is not in the file either: if this channel is the tach pulse, "
                f"name it there (file channels: {sorted(record.columns)})")
    return ""


def _calibrate(record: RawRecord, cal, meta_path) -> dict:
    """Apply the 6x6 calibration matrix to its input channels; returns the new columns."""
    if not isinstance(cal, dict) or "matrix" not in cal or "inputs" not in cal:
        raise DataError(meta_path, "channel_map.calibration", "must be an object with 'inputs' (6 file "
                        "channel names) and 'matrix' (6x6, rows = calibrated inputs)")
    inputs = cal["inputs"]
    try:
        matrix = np.array(cal["matrix"], dtype=float)
    except (TypeError, ValueError):
        raise DataError(meta_path, "channel_map.calibration.matrix", "is not a numeric 6x6 array") from None
    if matrix.shape != (6, 6) or not np.isfinite(matrix).all():
        raise DataError(meta_path, "channel_map.calibration.matrix", f"shape {matrix.shape}, expected 6x6 finite")
    if not (isinstance(inputs, list) and len(inputs) == 6 and all(isinstance(n, str) for n in inputs)):
        raise DataError(meta_path, "channel_map.calibration.inputs", f"{inputs!r}: expected 6 channel names")
    cond = np.linalg.cond(matrix)
    if not cond < MAX_CALIBRATION_CONDITION:
        raise DataError(meta_path, "channel_map.calibration.matrix", f"is singular (condition number "
                        f"{cond:.3g}); a load-cell calibration must be invertible: check the matrix")
    missing = [n for n in inputs if n not in record.columns]
    if missing:
        raise DataError(record.path, f"channel {missing[0]}", f"named in meta.json channel_map.calibration."
                        f"inputs, not in the file (file channels: {sorted(record.columns)})")
    raw = np.vstack([record.columns[n] for n in inputs])
    calibrated = matrix @ raw
    columns = dict(record.columns)
    columns.update({n: np.ascontiguousarray(calibrated[k]) for k, n in enumerate(inputs)})
    return columns


def map_channels(record: RawRecord, meta: dict, meta_path="meta.json") -> tuple:
    """Our channels (SI) and the tach columns of a record.

    Returns
    -------
    signals : dict channel -> samples, N or N·m, shape (n,), in convention order.
    extras : dict file channel name -> samples for the tach channels present (unconverted).
    """
    cmap = meta.get("channel_map") if isinstance(meta, dict) else None
    tach_names = _tach_names(meta)
    signals, extras = {}, {}
    if cmap is None:
        for name, x in record.columns.items():
            if name in tach_names:
                extras[name] = x
            elif name in COLUMN_CHANNEL:
                signals[COLUMN_CHANNEL[name]] = x
            elif name in CHANNELS:
                unit = record.units.get(name, "")
                if not unit:
                    raise DataError(record.path, record.locate(name), "no unit stored for this channel; state "
                                    "it in meta.json channel_map (see docs/formats.md)")
                signals[name] = x * unit_factor(unit, name, record.path, record.locate(name))
            else:
                hint = ""
                stem = name.split("_")[0]
                if stem in CHANNEL_COLUMN:
                    hint = (f" (expected {CHANNEL_COLUMN[stem]!r}: values must be SI, N or N·m; or map it "
                            "in meta.json channel_map)")
                allowed = sorted(set(COLUMN_CHANNEL) | tach_names)
                raise DataError(record.path, record.locate(name), f"unknown column{hint}; allowed: {allowed}"
                                + _tach_hint(record, meta, meta_path))
    else:
        if not isinstance(cmap, dict) or not isinstance(cmap.get("channels"), dict):
            raise DataError(meta_path, "channel_map", "must be an object with 'channels' "
                            "(file channel -> {channel, unit, sign})")
        columns = _calibrate(record, cmap["calibration"], meta_path) if "calibration" in cmap else record.columns
        calibrated = set(cmap["calibration"]["inputs"]) if "calibration" in cmap else set()
        entries = cmap["channels"]
        for name, x in columns.items():
            if name in tach_names and name not in entries:
                extras[name] = x
                continue
            if name not in entries:
                raise DataError(record.path, record.locate(name), f"file channel {name!r} is not in meta.json "
                                f"channel_map.channels (mapped: {sorted(entries)})" + _tach_hint(record, meta, meta_path))
            entry = entries[name]
            field = f"channel_map.channels.{name}"
            if not isinstance(entry, dict) or entry.get("channel") not in CHANNELS:
                raise DataError(meta_path, field, f"{entry!r}: needs 'channel' one of {list(CHANNELS)}")
            ch = entry["channel"]
            if ch in signals:
                raise DataError(meta_path, field, f"channel {ch} is mapped from two file channels")
            sign = entry.get("sign", 1)
            if sign not in (1, -1):
                raise DataError(meta_path, f"{field}.sign", f"{sign!r}: must be 1 or -1")
            # the unit the file states for the channel (a TDMS unit_string, a UFF label), unless the calibration
            # made the channel (its raw inputs' unit is not the calibrated one's)
            stated = "" if name in calibrated else str(record.units.get(name, "") or "").strip()
            if "unit" not in entry and not _known_unit(stated):
                raise DataError(meta_path, f"{field}.unit", "missing (N, kN, lbf, N·m, in·lbf, ft·lbf)"
                                + (f"; the file states {stated!r}, not a unit known here" if stated else ""))
            unit = entry.get("unit", stated)
            factor = unit_factor(unit, ch, meta_path, f"{field}.unit (file channel {name!r})")
            if _known_unit(stated):
                # a map unit that contradicts the file's own would scale the channel silently (lbf over N: 4.45x)
                file_factor = unit_factor(stated, ch, record.path, record.locate(name))
                if not math.isclose(file_factor, factor, rel_tol=1e-12):
                    raise DataError(meta_path, f"{field}.unit", f"{unit!r} (x{factor:.6g} to SI) contradicts the unit "
                                    f"the file states for channel {name!r}, {stated!r} (x{file_factor:.6g}) at "
                                    f"{record.path}: {record.locate(name)}; give the file's unit, or leave 'unit' "
                                    "out to take it")
            signals[ch] = x * (sign * factor)
        for name in entries:
            if name not in columns:
                raise DataError(record.path, f"channel {name}", f"named in meta.json channel_map.channels, not "
                                f"in the file (file channels: {sorted(columns)})")
    if not signals:
        raise DataError(record.path, record.channels_field, "no channel columns; expected some of "
                        + ",".join(CHANNEL_COLUMN.values()))
    lengths = {len(x) for x in signals.values()} | {len(x) for x in extras.values()}
    if len(lengths) > 1:
        raise DataError(record.path, "channels", f"channels differ in length: "
                        f"{ {n: len(x) for n, x in record.columns.items()} }")
    return {ch: np.ascontiguousarray(signals[ch], dtype=float) for ch in CHANNELS if ch in signals}, extras


def record_rate(record: RawRecord, declared_rate, declared_by="meta.json sample_rate_hz") -> tuple:
    """(sample rate Hz, t0 s) of a record, checked against a declared rate."""
    if record.time is not None:
        if record.sample_rate is not None:  # the file stores both: its rate is checked like a declared one
            if declared_rate is None:
                declared_rate, declared_by = record.sample_rate, record.rate_field
            else:
                declared_rate = check_rate(record.path, record.rate_field, record.sample_rate, record.rate_rtol,
                                           declared_rate, declared_by)
        step = sample_step(record.path, record.time_field, record.time, declared_rate, declared_by,
                           position=record.time_position)
        return 1.0 / step, float(record.time[0])
    if record.sample_rate is None:
        raise DataError(record.path, record.time_field, "neither time stamps nor a sample rate stored")
    if not math.isfinite(record.t0) or abs(record.t0) > MAX_T0_S:
        raise DataError(record.path, record.t0_field or "t0", f"start time {record.t0!r} s: must be finite within "
                        f"+-{MAX_T0_S:g} s")
    return check_rate(record.path, record.rate_field, record.sample_rate, record.rate_rtol, declared_rate,
                      declared_by), float(record.t0)


def to_run(record: RawRecord, speed, meta: dict, meta_path="meta.json", name: str = "") -> Run:
    """A :class:`Run` from a record: ``speed`` rad/s, or None to take it from the tach channel."""
    signals, extras = map_channels(record, meta, meta_path)
    check_loads(record.path, signals)
    fs, t0 = record_rate(record, meta.get("sample_rate_hz") if isinstance(meta, dict) else None)
    check_rate_bound(record.path, record.time_field if record.time is not None else record.rate_field, fs)
    if speed is None:
        speed = steady_speed_from_tach(record.path, extras, fs, meta, meta_path)
        check_speed_rpm(record.path, "speed from the tach channel", rad_s_to_rpm(speed))
    return Run(speed=float(speed), sample_rate=fs, signals=signals, t0=t0, name=name or record.path.name)


def to_sweep(record: RawRecord, meta: dict, meta_path="meta.json", declared_rate=None) -> Sweep:
    """A :class:`Sweep` from a record (tach from a ``speed_rpm`` column or a pulse channel)."""
    signals, extras = map_channels(record, meta, meta_path)
    check_loads(record.path, signals)
    if declared_rate is None and isinstance(meta, dict):
        declared_rate = meta.get("sample_rate_hz")
    fs, t0 = record_rate(record, declared_rate)
    check_rate_bound(record.path, record.time_field if record.time is not None else record.rate_field, fs)
    n = len(next(iter(signals.values())))
    time = record.time if record.time is not None else t0 + np.arange(n) / fs
    tach = None
    if SPEED_COLUMN in extras:
        check_speed_rpm(record.path, record.where.get(SPEED_COLUMN, SPEED_COLUMN), extras[SPEED_COLUMN])
        tach = rpm_to_rad_s(extras[SPEED_COLUMN])
    else:
        tach = sweep_speed_from_tach(record.path, extras, time, fs, meta, meta_path)
        if tach is not None:
            check_speed_rpm(record.path, "speed from the tach channel", rad_s_to_rpm(tach))
    return Sweep(time=np.asarray(time, dtype=float), signals=signals, sample_rate=fs, tach=tach,
                 meta=dict(meta) if isinstance(meta, dict) else {})
