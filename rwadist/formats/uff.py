"""Universal File Format dataset 58 (function at nodal DOF), ASCII and binary, via pyuff.

Convention (Simcenter Testlab, m+p, Brüel & Kjær exports): one dataset per
channel, function type 1 (time response); the channel is the response
direction (1 X, 2 Y, 3 Z force; 4 X, 5 Y, 6 Z rotation = torque; a negative
direction is the opposite sign); the sample step is the abscissa increment,
which the format stores with six significant digits (``%13.5e``), so the
sample rate it gives is rounded: it is accepted to that precision, and the
rate of ``meta.json`` (or of the other runs) is used when it agrees.  Units
come from the ordinate units label (``N``, ``lbf``, ``N·m``, ``in·lbf`` ...)
or, when the label is empty, from the unit exponents (force 1 = N; force 1
and length 1 = N·m).  A sweep is one file of such datasets; a dataset whose
response direction is 0 and whose first ID line is ``speed_rpm`` or the tach
channel of ``meta.json`` carries the speed.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..units import CHANNEL_UNIT, CHANNELS
from .records import DataError, RawRecord

#: UFF function types by number, for error messages.
FUNCTION_TYPES = {0: "general or unknown", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
                  4: "frequency response function", 5: "transmissibility", 6: "coherence",
                  7: "auto correlation", 8: "cross correlation", 9: "power spectral density",
                  10: "energy spectral density", 11: "probability density function", 12: "spectrum",
                  13: "cumulative frequency distribution", 14: "peaks valley", 15: "stress/cycles",
                  16: "strain/cycles", 17: "orbit", 18: "mode indicator function", 19: "force pattern",
                  20: "partial power", 21: "partial coherence", 22: "eigenvalue", 23: "eigenvector",
                  24: "shock response spectrum", 25: "finite impulse response filter",
                  26: "multiple coherence", 27: "order function"}
#: Relative precision of the abscissa increment as pyuff and the format write it (6 significant digits).
INCREMENT_RTOL = 5e-6
SI_LABEL = {"N": "N", "Nm": "N·m"}
#: Specific data types pyuff requires: abscissa time (17), ordinate force (13), denominator and z unknown (0).
_SPEC_TYPES = {"abscissa_spec_data_type": 17, "ordinate_spec_data_type": 13, "orddenom_spec_data_type": 0,
               "z_axis_spec_data_type": 0}


def _unit(dset: dict) -> str:
    label = str(dset.get("ordinate_axis_units_lab", "") or "").strip()
    if label and label.upper() != "NONE":
        return label
    length, force = int(dset.get("ordinate_len_unit_exp", 0)), int(dset.get("ordinate_force_unit_exp", 0))
    return {(0, 1): "N", (1, 1): "N·m"}.get((length, force), f"unit exponents length {length}, force {force}")


def _read_sets(path: Path) -> list:
    import pyuff

    if not path.exists():
        raise DataError(path, "file", "does not exist")
    with open(path, "rb") as fh:
        fh.seek(0, 2)
        fh.seek(max(0, fh.tell() - 64))
        tail = fh.read().rstrip()
    if not tail.endswith(b"-1") or tail[-3:-2] not in (b" ", b"\n", b"\r", b""):
        raise DataError(path, "file", "is truncated: it does not end with the UFF dataset delimiter line '-1' "
                        "(an interrupted export?); export it again")
    try:
        uff = pyuff.UFF(str(path))
        types = list(uff.get_set_types())
        sets = uff.read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions, IndexErrors, ValueErrors on a broken file
        raise DataError(path, "file", f"is not a readable UFF file (truncated or corrupt?): {exc}") from None
    if isinstance(sets, dict):
        sets = [sets]
    if not types:
        raise DataError(path, "file", "holds no UFF datasets")
    return list(zip(types, sets))


def read_record(path, tach_names=()) -> RawRecord:
    """A UFF file of dataset-58 time responses as a :class:`RawRecord` (channels named Fx..Tz)."""
    path = Path(path)
    columns: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    where: dict[str, str] = {}
    increments: list[tuple[float | None, str]] = []     # (abscissa increment s, None: uneven; dataset)
    starts: list[float | np.ndarray] = []               # abscissa start s, or every sample's time when uneven
    lengths: list[tuple[int, str]] = []
    for index, (set_type, dset) in enumerate(_read_sets(path)):
        loc = f"dataset {index + 1}"
        if int(set_type) != 58:
            continue  # units (164), geometry (15) ... are not channels
        ftype = int(dset.get("func_type", -1))
        if ftype != 1:
            raise DataError(path, loc, f"function type {ftype} ({FUNCTION_TYPES.get(ftype, 'unknown')}), "
                            "expected 1 (time response): export time histories, not spectra or FRFs")
        data = np.asarray(dset.get("data", []))
        n_stated = int(dset.get("num_pts", len(data)))
        if len(data) != n_stated:
            raise DataError(path, loc, f"holds {len(data)} samples, its header states {n_stated} (truncated?)")
        if np.iscomplexobj(data):
            raise DataError(path, loc, "holds complex ordinates; a time response is real")
        direction = int(dset.get("rsp_dir", 0))
        name = str(dset.get("id1", "")).strip()
        if direction == 0 and name in tach_names:
            key, sign = name, 1.0
        elif 1 <= abs(direction) <= 6:
            key, sign = CHANNELS[abs(direction) - 1], (1.0 if direction > 0 else -1.0)
        else:
            raise DataError(path, loc, f"response direction {direction} is not 1..6 (X, Y, Z, X/Y/Z rotation)")
        if key in columns:
            raise DataError(path, loc, f"second dataset for channel {key} (first at {where[key]})")
        x = np.asarray(data, dtype=float) * sign
        bad = ~np.isfinite(x)
        if bad.any():
            i = int(np.argmax(bad))
            raise DataError(path, f"{loc} ({key})", f"non-finite sample at index {i}, value {float(x[i])!r}")
        columns[key], where[key] = np.ascontiguousarray(x), f"{loc} ({key})"
        units[key] = _unit(dset) if key in CHANNELS else ""
        lengths.append((len(x), loc))
        if int(dset.get("abscissa_spacing", 1)) == 1:
            increments.append((float(dset["abscissa_inc"]), loc))
            starts.append(float(dset.get("abscissa_min", 0.0)))
        else:
            increments.append((None, loc))
            starts.append(np.asarray(dset["x"], dtype=float))
    if not columns:
        raise DataError(path, "file", "holds no dataset 58 (function at nodal DOF)")
    if len({n for n, _ in lengths}) > 1:
        raise DataError(path, lengths[-1][1], f"channels differ in length: {[n for n, _ in lengths]}")
    first_inc, first_loc = increments[0]
    for inc, loc in increments[1:]:
        if inc is None or first_inc is None:
            mixed = (inc is None) != (first_inc is None)
        else:
            mixed = abs(inc - first_inc) > 2 * INCREMENT_RTOL * first_inc
        if mixed:
            raise DataError(path, loc, f"abscissa increment {inc!r} s differs from {first_loc}'s {first_inc!r} s "
                            "(mixed sample rates in one record)")
    if first_inc is None:  # uneven abscissa: the time of every sample is stored
        return RawRecord(path=path, columns=columns, units=units, where=where, time=np.asarray(starts[0]),
                         time_field=f"{first_loc} abscissa", time_position=lambda i: f"sample {i + 1}")
    if not first_inc > 0:
        raise DataError(path, f"{first_loc} abscissa increment", f"{first_inc!r} s is not positive")
    return RawRecord(path=path, columns=columns, units=units, where=where, sample_rate=1.0 / first_inc,
                     rate_rtol=INCREMENT_RTOL, rate_field=f"{first_loc} abscissa increment ({first_inc!r} s)",
                     t0=float(starts[0]))


def write(path, signals: dict, sample_rate: float, t0: float = 0.0, binary: bool = False,
          extra: dict | None = None) -> Path:
    """Write channels (SI) as dataset-58 time responses; ``extra`` name -> samples as direction-0 datasets."""
    import pyuff

    path = Path(path)
    if path.exists():
        path.unlink()
    n = len(next(iter(signals.values())))
    x = t0 + np.arange(n) / sample_rate
    sets = []
    for ch, y in signals.items():
        sets.append(pyuff.prepare_58(
            binary=int(binary), func_type=1, rsp_node=1, rsp_dir=CHANNELS.index(ch) + 1, ref_node=0, ref_dir=0,
            id1=ch, data=np.asarray(y, dtype=float), x=x, abscissa_spacing=1, abscissa_min=t0,
            abscissa_inc=1.0 / sample_rate, ordinate_axis_units_lab=SI_LABEL[CHANNEL_UNIT[ch]],
            abscissa_axis_units_lab="s", **_SPEC_TYPES))
    for name, y in (extra or {}).items():
        sets.append(pyuff.prepare_58(
            binary=int(binary), func_type=1, rsp_node=1, rsp_dir=0, ref_node=0, ref_dir=0, id1=name,
            data=np.asarray(y, dtype=float), x=x, abscissa_spacing=1, abscissa_min=t0,
            abscissa_inc=1.0 / sample_rate, abscissa_axis_units_lab="s", **_SPEC_TYPES))
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    return path
