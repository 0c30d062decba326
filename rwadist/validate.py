"""The library's checks of values given to it: finite numbers in their ranges, speed lists, frequency limits.

Every numeric parameter of the API has its allowed range once, in :data:`LIMITS`; the functions of
:mod:`rwadist.api` check their arguments against it (:func:`check_parameter`) and the command line's parser
builds its flags' checks from it (:mod:`rwadist.cli_parser`), so a value refused on one side is refused on
the other.  A refused value is a :class:`rwadist.ParameterError` naming the parameter, the value and the
allowed range (``presence: 2.0: out of range; allowed (0, 1]``); the command line names the flag instead.
rpm and Hz at this edge.
"""
from __future__ import annotations

import math
import os
import warnings
from typing import TypedDict

import numpy as np

from .errors import DataError, ParameterError, RwadistWarning
from .units import RAD_S_TO_RPM

#: highest wheel speed any command accepts, rpm (flight wheels run below ~10 000 rpm)
MAX_RPM = 100_000.0
#: most speeds in a list or grid (a Campbell grid, a simulated test)
MAX_SPEEDS = 100_000
#: most samples of a simulated record (memory: 6 channels x 8 bytes each)
MAX_SAMPLES = 50_000_000

#: The allowed range of every numeric parameter of the API, by name: the keyword arguments of
#: :func:`check_number` (``lo``/``hi`` bounds, ``lo_open``/``hi_open`` bound excluded, ``integer``, ``unit``,
#: ``why``: the reason for a bound, said when a value is out of range).
class Limit(TypedDict, total=False):
    """The keyword arguments of :func:`check_number` that give a parameter's range."""

    lo: float
    hi: float
    lo_open: bool
    hi_open: bool
    integer: bool
    unit: str
    why: str


LIMITS: dict[str, Limit] = {
    "f_lim": dict(lo=0, hi=1e6, lo_open=True, unit="Hz"),
    # the fit's noise floor takes medians of blocks of 32 frequency bins (rwadist.empirical.block_floor) and
    # nperseg samples give nperseg // 2 + 1 bins: 16 gave 9 (a fit crashed, then found no line; diagnose crashed)
    "nperseg": dict(lo=62, hi=2**24, integer=True,
                    why="the noise floor is the median of blocks of 32 frequency bins, and nperseg samples give "
                        "nperseg/2 + 1 bins: 62 is the smallest usable"),
    "presence": dict(lo=0, hi=1, lo_open=True),
    "epsilon": dict(lo=0, hi=0.5, lo_open=True),
    "slice_samples": dict(lo=64, hi=2**24, integer=True),
    "mass": dict(lo=0, hi=1e4, lo_open=True, unit="kg"),
    "radius": dict(lo=0, hi=10, lo_open=True, unit="m"),
    "height": dict(lo=-10, hi=10, unit="m"),
    "k_sigma": dict(lo=0, hi=100, lo_open=True),
    "min_gain": dict(lo=0, hi=1, lo_open=True, hi_open=True),
    "std_rpm": dict(lo=0, hi=MAX_RPM, lo_open=True, unit="rpm"),
    "fmax": dict(lo=0, hi=1e6, lo_open=True, unit="Hz"),
    "n_freq": dict(lo=2, hi=200_001, integer=True),
    "n_speeds": dict(lo=2, hi=20_000, integer=True),       # speed cells of the PSD's law
    "sample_rate": dict(lo=0, hi=1e6, lo_open=True, unit="Hz"),
    "n_samples": dict(lo=64, hi=MAX_SAMPLES, integer=True),
    "noise": dict(lo=0, hi=10),
    "seed": dict(lo=0, hi=2**32 - 1, integer=True),
}


def _fmt(x) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _range_text(lo, hi, lo_open: bool, hi_open: bool) -> str:
    if lo is not None and hi is not None:
        return f"{'(' if lo_open else '['}{_fmt(lo)}, {_fmt(hi)}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {_fmt(lo)}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {_fmt(hi)}"
    return "any finite value"


def check_number(value, parameter: str, lo=None, hi=None, *, lo_open: bool = False, hi_open: bool = False,
                 integer: bool = False, unit: str = "", why: str = ""):
    """``value`` as a float (or int) checked finite and in range; :class:`ParameterError` naming ``parameter``
    otherwise.  ``lo_open``/``hi_open``: the bound itself is excluded; ``why``: the bound's reason, said when
    ``value`` is out of range."""
    text = value if isinstance(value, str) else repr(value)
    kind = "an integer" if integer else "a finite number"
    allowed = _range_text(lo, hi, lo_open, hi_open) + (f" {unit}" if unit else "")
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(parameter, f"{text}: must be {kind} in {allowed}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(parameter, f"{value!r}: must be {kind} in {allowed}") from None
    if not math.isfinite(x):
        raise ParameterError(parameter, f"{value!r}: must be {kind} in {allowed}")
    if integer:
        if x != int(x):
            raise ParameterError(parameter, f"{value!r}: must be {kind} in {allowed}")
        x = int(x)
    if (lo is not None and (x < lo or (lo_open and x == lo))) or (
            hi is not None and (x > hi or (hi_open and x == hi))):
        raise ParameterError(parameter, f"{text}: out of range; allowed {allowed}" + (f" ({why})" if why else ""))
    return x


#: The API parameters whose default is None (the function decides: the data's record, a default FFT length, per
#: unit mass ...): None passes for them only; for any other, None is refused by name, not met later as a TypeError
NONE_IS_DEFAULT = frozenset({"f_lim", "nperseg", "mass", "radius", "std_rpm", "fmax", "sample_rate", "slice_samples"})


def check_path(name: str, value, what: str) -> None:
    """:class:`ParameterError` naming ``name`` unless ``value`` is a path (str or os.PathLike); ``what``: what the
    path must lead to (the message's advice, e.g. 'a model file (JSON)')."""
    if not isinstance(value, (str, os.PathLike)):
        raise ParameterError(name, f"a {type(value).__name__}: expected the path of {what}")


def check_flags(**flags) -> None:
    """:class:`ParameterError` naming the first of ``flags`` (name=value) that is not a bool (``"no"`` is a truthy
    string: read as True, it would do the opposite of what was meant)."""
    for name, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            raise ParameterError(name, f"{value!r}: must be True or False")


def check_object(name: str, value, cls: type, what: str) -> None:
    """:class:`ParameterError` naming ``name`` unless ``value`` is a ``cls``; ``what``: where one comes from."""
    if not isinstance(value, cls):
        raise ParameterError(name, f"a {type(value).__name__}: expected a {cls.__name__} ({what})")


def check_parameter(name: str, value):
    """``value`` of the API parameter ``name`` checked against :data:`LIMITS` (None passes as None for the
    parameters of :data:`NONE_IS_DEFAULT`); :class:`ParameterError` naming ``name`` otherwise."""
    if value is None and name not in NONE_IS_DEFAULT:
        lim = LIMITS[name]
        allowed = _range_text(lim.get("lo"), lim.get("hi"), lim.get("lo_open", False), lim.get("hi_open", False))
        raise ParameterError(name, f"None: must be a number in {allowed}")
    if isinstance(value, (str, bytes)):     # the API takes numbers ('3' passed check_number, then broke a sum)
        lim = LIMITS[name]
        allowed = _range_text(lim.get("lo"), lim.get("hi"), lim.get("lo_open", False), lim.get("hi_open", False))
        raise ParameterError(name, f"{value!r}: a string; must be a number in {allowed}")
    return None if value is None else check_number(value, name, **LIMITS[name])


def check_within_test(speeds_rpm, test, parameter: str) -> None:
    """Speeds (rpm) a plot reads from the test's runs (the nearest run to each) must lie within the test's speeds:
    --cumulative-rpm 5000 on a 300-2400 rpm test plotted 2400 rpm under a title of 5000."""
    rpm = np.abs([r.speed for r in test.runs]) * RAD_S_TO_RPM
    lo, hi = float(rpm.min()), float(rpm.max())
    for v in speeds_rpm:
        if not lo - 1e-6 <= abs(v) <= hi + 1e-6:
            raise ParameterError(parameter, f"{v:g} rpm is outside the test's speeds {lo:g}-{hi:g} rpm (the plot "
                                 "shows the run nearest each speed): give speeds the test covers")


def warn_beyond_rated_speed(model, source, lo_rpm: float, hi_rpm: float, parameter: str = "speed_rpm") -> None:
    """A :class:`RwadistWarning` when a speed range reaches beyond the wheel's rated maximum (``wheel.max_speed_rpm``
    of its model, when it states one): the Ithaco E over 0:10000 rpm (rated 3850) gave Fx RMS 2.19 N without a word."""
    top = (getattr(model, "wheel", None) or {}).get("max_speed_rpm")
    if isinstance(top, (int, float)) and top > 0 and max(abs(lo_rpm), abs(hi_rpm)) > top * (1 + 1e-9):
        warnings.warn(RwadistWarning(f"{lo_rpm:g}:{hi_rpm:g} rpm reaches beyond the maximum speed of {source}, "
                                     f"{top:g} rpm (its model's wheel.max_speed_rpm): the results extrapolate its "
                                     "lines to speeds it does not run at", parameter), stacklevel=3)


def check_f_lim(test, f_lim, parameter: str = "f_lim") -> None:
    """``f_lim`` (Hz, or None) within (0, Nyquist] of every run of ``test``: refused naming the parameter (the
    spectra's own check named '<spectra>', which the user never typed)."""
    if f_lim is None:
        return
    nyquist = 0.5 * min(r.sample_rate for r in test.runs)
    if not 0.0 < f_lim <= nyquist:
        raise ParameterError(parameter, f"{f_lim:g} Hz is above the data's Nyquist frequency {nyquist:g} Hz: give "
                             "a limit below it (or leave it out)")


def check_test_speeds(test, source, model_given: bool = False) -> None:
    """Refuse, or warn about, a test too narrow in speed to diagnose (``source``: the data's path, named).

    A :class:`DataError` when the runs of ``test`` hold fewer than 2 distinct speeds (a speed within 0.1 % of the top
    one of a speed already counted is the same; speeds not finite are left out): the search fits on every other speed
    and judges on the rest.  A sweep whose slices all share one speed is said to be one steady run recorded as one
    file.  A :class:`RwadistWarning` when, without a model given, they hold fewer than the empirical fit's
    ``min_points`` (:class:`rwadist.empirical.FitSettings`): that fit leaves out every line measured at fewer speeds."""
    from .empirical import FitSettings  # diagnose's own import; the one place the count is decided

    need = FitSettings.min_points
    speeds = np.abs(np.array([r.speed for r in test.runs], dtype=float))
    speeds = speeds[np.isfinite(speeds)]
    top = float(speeds.max()) if speeds.size else 0.0
    kept: list = []
    for x in np.sort(speeds):       # each new speed counted against the last one kept (a slow sweep's slices count)
        if not kept or x - kept[-1] > 1e-3 * top:
            kept.append(float(x))
    distinct = np.array(kept)
    rpm = ", ".join(f"{x * RAD_S_TO_RPM:.0f}" for x in distinct)
    if distinct.size >= 2:
        if distinct.size < need and not model_given:
            warnings.warn(RwadistWarning(
                f"{source}: runs at {distinct.size} distinct speeds ({rpm} rpm): the data's empirical fit keeps a "
                f"line measured at {need} speeds at least, so the starting model holds few lines or none; "
                "give the test's runs over its speed range (or a model file)"), stacklevel=3)
        return
    held = (f"runs at 1 distinct speed ({rpm} rpm)" if distinct.size else
            "no run with a finite speed (every speed is NaN or infinite)")
    msg = (f"{held}: diagnose needs runs at 2 speeds at least (it fits on "
           f"every other speed and judges on the rest; the data's own fit needs {need}); give the test's "
           "runs over its speed range")
    if (getattr(test, "meta", None) or {}).get("slicing") is not None and speeds.size:
        change = 100.0 * float(speeds.max() - speeds.min()) / max(top, 1e-300)
        msg += (f". This file was read as a sweep, but its speed changes by {change:.2g} % over the record: one "
                "steady run recorded as one file; put it with the test's other runs in a steady-test folder "
                "(runs.csv and one file per run, docs/formats.md)")
    raise DataError(source, "speed_rpm", msg)


def warn_unconstrained(model, source, use) -> None:
    """A :class:`RwadistWarning` that ``model`` has modes the extended fit could not identify, if it has (``use``:
    what rests on them, e.g. "the PSD")."""
    from .extended_fit import unconstrained_warning

    if text := unconstrained_warning(model, str(source), use):
        warnings.warn(RwadistWarning(text.removeprefix("warning: ")), stacklevel=3)


def check_speeds_rpm(speeds, parameter: str) -> np.ndarray:
    """A speed list (rpm) checked: non-empty, finite, |speed| <= MAX_RPM, at most MAX_SPEEDS entries."""
    items = np.asarray(speeds, dtype=object).ravel() if not isinstance(speeds, np.ndarray) else speeds.ravel()
    if isinstance(speeds, (str, bytes)) or any(isinstance(x, (str, bytes, bool, np.bool_)) for x in items):
        raise ParameterError(parameter, f"{speeds!r}: not a list of numbers (rpm)")
    try:
        s = np.asarray(speeds, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(parameter, f"{speeds!r}: not a list of numbers (rpm)") from None
    if s.ndim > 1:              # a table flattened would run speeds nobody listed in that order
        raise ParameterError(parameter, f"an array of shape {s.shape}: give one list of speeds (rpm)")
    s = s.ravel()
    if s.size == 0:
        raise ParameterError(parameter, "no speeds: give at least one speed in rpm")
    if s.size > MAX_SPEEDS:
        raise ParameterError(parameter, f"{s.size} speeds: at most {MAX_SPEEDS}; use a coarser step")
    bad = s[~np.isfinite(s) | (np.abs(s) > MAX_RPM)]
    if bad.size:
        raise ParameterError(parameter, f"speed {float(bad[0])!r} rpm: must be finite in [{-MAX_RPM:g}, "
                             f"{MAX_RPM:g}] rpm")
    return s


def check_speed_range(speed_rpm, parameter: str = "speed_rpm") -> tuple:
    """(MIN, MAX) rpm of a speed range: two finite speeds within +-MAX_RPM, MIN below MAX."""
    try:
        lo, hi = (float(x) for x in speed_rpm)
    except (TypeError, ValueError):
        raise ParameterError(parameter, f"{speed_rpm!r}: expected (MIN, MAX) in rpm") from None
    check_speeds_rpm([lo, hi], parameter)
    if not lo < hi:
        raise ParameterError(parameter, f"{lo:g}:{hi:g}: empty or inverted speed range; MIN must be below MAX (rpm; "
                             "a negative range, e.g. -2400:-600, spins about -z)")
    return lo, hi


def check_grid_size(start: float, stop: float, step: float, parameter: str) -> None:
    """Refuse a START:STOP:STEP grid of more than MAX_SPEEDS points before it is allocated."""
    n = (stop - start) / step + 1 if step > 0 else math.inf
    if not math.isfinite(n) or n > MAX_SPEEDS:
        raise ParameterError(parameter, f"{_fmt(start)}:{_fmt(stop)}:{_fmt(step)} makes "
                             f"{'too many' if not math.isfinite(n) else int(n)} speeds: at most {MAX_SPEEDS}; "
                             "use a larger step")


def refuse_non_finite_psd(res, source) -> None:
    """A PSD with NaN or infinite values is an error, never a result."""
    bad = ~np.isfinite(res.psd)
    if bad.any():
        rows = int(bad.any(axis=1).sum())
        raise DataError(source, "psd", f"{rows} of {res.f.size} frequencies give non-finite PSD values (a "
                        "coefficient or parameter of the model overflows); nothing written: check the model's "
                        "values with `rwadist model show`")


def refuse_non_finite_model(model, source) -> None:
    """A fitted model with a non-finite coefficient is an error, never a result."""
    for d in model.empirical:
        for h in model.harmonics(d):
            if not (np.isfinite(h.h) and np.isfinite(h.C)):
                raise DataError(source, d, f"harmonic h={h.h!r} has C={h.C!r}: the fit diverged; nothing written")


def speed_scale_warning(fit, meta: dict | None = None) -> str | None:
    """A warning (text) when the empirical ``fit``'s lines sit where speeds given k times the wheel's put them, or None.

    A reaction wheel's strongest radial-force line is nearly always its static imbalance, once per revolution
    (Masterson's E wheel; not the thesis's B wheel, whose lines near h = 8-10 are stronger).  Speeds scaled by a
    factor k move every line to h/k and the fit is self-consistent at the wrong h.  Flagged when the strongest
    radial-force line (largest C) is where such a scaling puts the imbalance and no line at h = 1 has 0.3 of its C
    (the E wheel's h = 2, which a 2-pulse tach read as 1 moves to h = 1: 0.20 of it): at h = 1/k, k = 2 … 8 (a tach
    with k times the ``pulses_per_rev`` given), at h = k with a ``pulses_per_rev`` k times too many, or at
    h = 60/2π = 9.55 (a runs.csv speed_rpm column holding rad/s).  ``meta``: the test's meta.json (its ``tach``)."""
    lines = [ln for ln in fit.lines if ln.direction == "radial_force" and np.isfinite(ln.C) and ln.C > 0]
    if not lines:
        return None
    top = max(lines, key=lambda ln: ln.C)
    at_one = max((ln.C for ln in lines if abs(ln.h - 1.0) <= 0.02), default=0.0)
    if abs(top.h - 1.0) <= 0.02 or at_one >= 0.3 * top.C:
        return None
    tach_meta = meta.get("tach") if isinstance(meta, dict) else None
    tach: dict = tach_meta if isinstance(tach_meta, dict) else {}
    ppr = tach.get("pulses_per_rev", 1) if isinstance(tach_meta, dict) else None
    ppr = ppr if isinstance(ppr, int) and not isinstance(ppr, bool) and ppr >= 1 else None

    def near(x, y):
        return abs(x / y - 1.0) <= 0.01

    sub = next((k for k in range(2, 9) if near(top.h, 1.0 / k)), None)
    over = next((k for k in range(2, 9) if near(top.h, k) and ppr is not None and ppr % k == 0), None)
    if sub is not None and ppr is not None:
        hint = (f"the speeds come from the tach channel {tach.get('channel')!r} with meta.json tach.pulses_per_rev = "
                f"{ppr}; {ppr * sub} pulses per revolution would put it at h = 1")
    elif over is not None and ppr is not None:         # over is only found with ppr given
        hint = (f"the speeds come from the tach channel {tach.get('channel')!r} with meta.json tach.pulses_per_rev = "
                f"{ppr}; {ppr // over} would put it at h = 1")
    elif sub is not None:
        hint = f"check the speeds given (runs.csv speed_rpm, rpm): they may be {sub} times the wheel's"
    elif near(top.h, 60.0 / (2 * np.pi)):
        hint = "runs.csv speed_rpm may hold rad/s: in rpm the imbalance would be at h = 1"
    else:
        return None
    return (f"WARNING: the strongest radial-force line is at h = {top.h:.4g} of the speeds given, not at h = 1 (a "
            f"wheel's imbalance, nearly always its strongest radial line), and no line at h = 1 comes near it: "
            f"{hint}.  If this wheel's imbalance is not its strongest line, ignore this")


def check_run_lengths(test, nperseg: int) -> None:
    """DataError naming the first run of ``test`` shorter than one FFT segment of ``nperseg`` samples, with advice it
    can follow: a run with fewer samples than the smallest ``nperseg`` allowed (:data:`LIMITS`) is told to record
    longer runs, not to pass a smaller ``nperseg`` (which that range would refuse)."""
    for i, run in enumerate(test.runs):
        if run.n_samples >= nperseg:
            continue
        smallest = int(LIMITS["nperseg"]["lo"])
        advice = (f"record at least {smallest} samples a run (the fewest a spectrum can use) or drop the run"
                  if run.n_samples < smallest else
                  f"pass `nperseg` between {smallest} and {run.n_samples}, or drop the run")
        raise DataError(run.name or f"run {i}", "samples",
                        f"{run.n_samples} samples, shorter than one FFT segment ({nperseg}); {advice}")
