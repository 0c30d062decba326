"""One validation layer for command-line values: finite numbers, ranges, integers, speed lists.

Each check is an argparse ``type`` (a refused value is kept as :class:`Refused`, then
:func:`check_parsed` raises ``--noise: value: 'nan': must be a finite number in [0, 10]``) or a function
raising :class:`DataError` naming the flag, the value and the allowed range.  rpm and Hz at this edge.
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from .formats.records import DataError
from .units import RAD_S_TO_RPM, rpm_to_rad_s

#: highest wheel speed any command accepts, rpm (flight wheels run below ~10 000 rpm)
MAX_RPM = 100_000.0
#: most speeds in a list or grid (a Campbell grid, a simulated test)
MAX_SPEEDS = 100_000
#: most samples of a simulated record (memory: 6 channels x 8 bytes each)
MAX_SAMPLES = 50_000_000


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


def check_number(value, flag: str, lo=None, hi=None, *, lo_open: bool = False, hi_open: bool = False,
                 integer: bool = False, unit: str = ""):
    """``value`` as a float (or int) checked finite and in range; :class:`DataError` naming ``flag``
    otherwise.  ``lo_open``/``hi_open``: the bound itself is excluded."""
    text = value if isinstance(value, str) else repr(value)
    kind = "an integer" if integer else "a finite number"
    allowed = _range_text(lo, hi, lo_open, hi_open) + (f" {unit}" if unit else "")
    if isinstance(value, bool):
        raise DataError(flag, "value", f"{text}: must be {kind} in {allowed}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise DataError(flag, "value", f"{text!r}: must be {kind} in {allowed}") from None
    if not math.isfinite(x):
        raise DataError(flag, "value", f"{text!r}: must be {kind} in {allowed}")
    if integer:
        if x != int(x):
            raise DataError(flag, "value", f"{text!r}: must be {kind} in {allowed}")
        x = int(x)
    if (lo is not None and (x < lo or (lo_open and x == lo))) or (
            hi is not None and (x > hi or (hi_open and x == hi))):
        raise DataError(flag, "value", f"{text}: out of range; allowed {allowed}")
    return x


class Refused:
    """A flag value :func:`number` refused: ``text`` as given and ``why`` (range, type)."""

    def __init__(self, text: str, why: str):
        self.text, self.why = text, why

    def __repr__(self) -> str:
        return repr(self.text)


def number(lo=None, hi=None, *, lo_open: bool = False, hi_open: bool = False, integer: bool = False,
           unit: str = ""):
    """An argparse ``type`` checking a finite number (or an integer) in a range."""
    def parse(text):
        try:
            return check_number(text, "value", lo, hi, lo_open=lo_open, hi_open=hi_open, integer=integer,
                                unit=unit)
        except DataError as exc:       # refused by check_parsed, which knows the flag (exit 2 from main)
            return Refused(text, str(exc).split(": ", 2)[-1])

    parse.__name__ = "integer" if integer else "number"
    parse.rwadist_checked = True
    return parse


def check_parsed(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """After parsing: every flag typed by :func:`number` holds a number (argparse skips the type of some
    values, e.g. ``--noise=--`` gives an empty list); :class:`DataError` naming the flag otherwise."""
    def walk(p):
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):     # only the command that was chosen
                chosen = action.choices.get(getattr(args, action.dest, None) or "")
                if chosen is not None:
                    yield from walk(chosen)
            elif getattr(action.type, "rwadist_checked", False):
                yield action

    for action in walk(parser):
        value = getattr(args, action.dest, None)
        if value is None or value is action.default:
            continue
        flag = max(action.option_strings, key=len) if action.option_strings else action.dest
        if isinstance(value, Refused):
            raise DataError(flag, "value", value.why)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise DataError(flag, "value", f"{value!r}: missing or not a number")


def check_fit_flags(args: argparse.Namespace) -> None:
    """``rwadist fit``: flags it would ignore are refused: --mass, --radius, --height and --preset without
    --extended (they feed the extended fit only), --mass without --radius or the reverse (the fit is then per unit
    mass), and --cumulative-rpm with --no-report (it picks the report's plots)."""
    given = [f for f, v in (("--mass", args.mass), ("--radius", args.radius), ("--height", args.height or None),
                            ("--preset", args.preset)) if v is not None]
    if given and not args.extended:
        raise DataError(given[0], "value", "applies to the extended fit only: add --extended (the plain fit of "
                        "harmonics C·Ω² does not use it)")
    if (args.mass is None) != (args.radius is None):
        raise DataError("--mass" if args.radius is None else "--radius", "value", "needs "
                        f"{'--radius' if args.radius is None else '--mass'} too (the rotor's inertias come from both; "
                        "with neither the fit is per unit mass and inertia)")
    if args.cumulative_rpm and args.no_report:
        raise DataError("--cumulative-rpm", "value", "picks the report's plots: drop it, or drop --no-report")


def check_within_test(speeds_rpm, test, flag: str) -> None:
    """Speeds (rpm) a plot reads from the test's runs (the nearest run to each) must lie within the test's speeds:
    --cumulative-rpm 5000 on a 300-2400 rpm test plotted 2400 rpm under a title of 5000."""
    rpm = np.abs([r.speed for r in test.runs]) * RAD_S_TO_RPM
    lo, hi = float(rpm.min()), float(rpm.max())
    for v in speeds_rpm:
        if not lo - 1e-6 <= abs(v) <= hi + 1e-6:
            raise DataError(flag, "value", f"{v:g} rpm is outside the test's speeds {lo:g}-{hi:g} rpm (the plot "
                            "shows the run nearest each speed): give speeds the test covers")


def check_psd_flags(args: argparse.Namespace) -> None:
    """``rwadist psd``: flags that the chosen output or law would ignore are refused, as is an output whose extension
    names the other format (a NASTRAN deck written as x.csv, CSV as x.bdf)."""
    from pathlib import Path

    nastran = args.format == "nastran"
    if not nastran and (args.nastran_cross or args.nastran_fields != "small"):
        raise DataError("--nastran-cross" if args.nastran_cross else "--nastran-fields", "value",
                        "applies to --format nastran only")
    if args.std_rpm is not None and args.dist != "normal":
        raise DataError("--std-rpm", "value", f"applies to --dist normal only (--dist is {args.dist!r})")
    suffix = Path(args.output).suffix.lower()
    if nastran and suffix == ".csv" or not nastran and suffix in (".bdf", ".dat", ".nas", ".blk"):
        raise DataError("-o", "value", f"{args.output!r}: its extension names the other format than --format "
                        f"{args.format}; give a {'.bdf' if nastran else '.csv'} file")


def check_fmu_ramp(fmu_path, speed_rpm: float, stop_time: float) -> None:
    """``rwadist fmu check``: the check's ramp 0 -> ``speed_rpm`` over ``stop_time`` s must stay within the FMU's
    ``max_acceleration`` (its start value): 6000 rpm over the default 1 s is 628 rad/s², which the FMU refuses (500
    rad/s² by default), and the check then failed (exit 1) as if the FMU were broken."""
    from fmpy import read_model_description

    var = next((v for v in read_model_description(str(fmu_path)).modelVariables if v.name == "max_acceleration"),
               None)
    accel = abs(float(rpm_to_rad_s(speed_rpm))) / stop_time
    if var is not None and var.start is not None and accel > float(var.start):
        raise DataError("--stop-time", "value", f"{stop_time:g} s to {speed_rpm:g} rpm is {accel:.4g} rad/s², above the "
                        f"FMU's max_acceleration of {float(var.start):g} rad/s²: give --stop-time "
                        f"{math.ceil(100 * accel * stop_time / float(var.start)) / 100:g} s or more")


def warn_beyond_rated_speed(model, source, lo_rpm: float, hi_rpm: float, flag: str = "--speed-rpm") -> None:
    """Print (stderr) a warning when a speed range reaches beyond the wheel's rated maximum (``wheel.max_speed_rpm``
    of its model, when it states one): the Ithaco E over 0:10000 rpm (rated 3850) gave Fx RMS 2.19 N without a word."""
    import sys

    top = (getattr(model, "wheel", None) or {}).get("max_speed_rpm")
    if isinstance(top, (int, float)) and top > 0 and max(abs(lo_rpm), abs(hi_rpm)) > top * (1 + 1e-9):
        print(f"WARNING: {flag} {lo_rpm:g}:{hi_rpm:g} rpm reaches beyond the maximum speed of {source}, {top:g} rpm "
              "(its model's wheel.max_speed_rpm): the results extrapolate its lines to speeds it does not run at",
              file=sys.stderr)


def check_f_lim(test, f_lim, flag: str = "--f-lim") -> None:
    """``f_lim`` (Hz, or None) within (0, Nyquist] of every run of ``test``: refused naming the flag (the spectra's
    own check named '<spectra>', which the user never typed)."""
    if f_lim is None:
        return
    nyquist = 0.5 * min(r.sample_rate for r in test.runs)
    if not 0.0 < f_lim <= nyquist:
        raise DataError(flag, "value", f"{f_lim:g} Hz is above the data's Nyquist frequency {nyquist:g} Hz: give a "
                        "limit below it (or leave it out)")


def warn_unconstrained(model, source, use) -> None:
    """Print (stderr) that ``model`` has modes the extended fit could not identify, if it has (``use``: what rests on
    them, e.g. "the PSD")."""
    import sys

    from .extended_fit import unconstrained_warning

    if text := unconstrained_warning(model, str(source), use):
        print(text, file=sys.stderr)


def rpm(lo: float = -MAX_RPM, hi: float = MAX_RPM):
    """An argparse ``type``: a wheel speed in rpm within [lo, hi]."""
    return number(lo, hi, unit="rpm")


def check_speeds_rpm(speeds, flag: str) -> np.ndarray:
    """A speed list (rpm) checked: non-empty, finite, |speed| <= MAX_RPM, at most MAX_SPEEDS entries."""
    s = np.asarray(speeds, dtype=float).ravel()
    if s.size == 0:
        raise DataError(flag, "value", "no speeds: give at least one speed in rpm")
    if s.size > MAX_SPEEDS:
        raise DataError(flag, "value", f"{s.size} speeds: at most {MAX_SPEEDS}; use a coarser step")
    bad = s[~np.isfinite(s) | (np.abs(s) > MAX_RPM)]
    if bad.size:
        raise DataError(flag, "value", f"speed {float(bad[0])!r} rpm: must be finite in [{-MAX_RPM:g}, {MAX_RPM:g}] rpm")
    return s


def check_grid_size(start: float, stop: float, step: float, flag: str) -> None:
    """Refuse a START:STOP:STEP grid of more than MAX_SPEEDS points before it is allocated."""
    n = (stop - start) / step + 1 if step > 0 else math.inf
    if not math.isfinite(n) or n > MAX_SPEEDS:
        raise DataError(flag, "value", f"{_fmt(start)}:{_fmt(stop)}:{_fmt(step)} makes "
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
    tach = meta.get("tach") if isinstance(meta, dict) else None
    ppr = tach.get("pulses_per_rev", 1) if isinstance(tach, dict) else None
    ppr = ppr if isinstance(ppr, int) and not isinstance(ppr, bool) and ppr >= 1 else None

    def near(x, y):
        return abs(x / y - 1.0) <= 0.01

    sub = next((k for k in range(2, 9) if near(top.h, 1.0 / k)), None)
    over = next((k for k in range(2, 9) if near(top.h, k) and ppr is not None and ppr % k == 0), None)
    if sub is not None and ppr is not None:
        hint = (f"the speeds come from the tach channel {tach.get('channel')!r} with meta.json tach.pulses_per_rev = "
                f"{ppr}; {ppr * sub} pulses per revolution would put it at h = 1")
    elif over is not None:
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
