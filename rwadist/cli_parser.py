"""The ``rwadist`` command line's argument parser: every command, flag and default.

The commands themselves live in :mod:`rwadist.cli`.  A flag that gives an API parameter is checked at parse
time against that parameter's range, decided once in :data:`rwadist.validate.LIMITS` (:func:`limited`; a refused
value names the flag, the value and the allowed range); flags the chosen command would ignore are refused here
too (:func:`check_fit_flags`, :func:`check_psd_flags`)."""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from .effects import elements
from .errors import DataError, ParameterError
from .units import rpm_to_rad_s
from .validate import LIMITS, MAX_RPM, MAX_SPEEDS, check_number

#: one help text for fit and diagnose: the slice rule of rwadist.sweep (docs/cli.md says the same)
_SLICE_SAMPLES_HELP = ("sweep slice length, samples (default: the longest power of two up to 8192 over which the "
                       "speed changes by at most 5 %% (median over the slices) and, with the speed from the data, "
                       "the highest line sweeps at most 2 bins of a quarter-slice Welch segment in every slice)")


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("rwadist")
    except Exception:   # not installed as a distribution (a bare source tree)
        from . import __version__

        return __version__


class Refused:
    """A flag value :func:`number` refused: ``text`` as given and ``why`` (range, type)."""

    def __init__(self, text: str, why: str):
        self.text, self.why = text, why

    def __repr__(self) -> str:
        return repr(self.text)


class CheckedNumber:
    """An argparse ``type`` checking a finite number (or an integer) in a range (:func:`number`): the value, or a
    :class:`Refused` that :func:`check_parsed` reports naming the flag."""

    #: marks the flags check_parsed looks at
    rwadist_checked = True

    def __init__(self, lo=None, hi=None, *, lo_open: bool = False, hi_open: bool = False, integer: bool = False,
                 unit: str = "", why: str = ""):
        self.lo, self.hi, self.lo_open, self.hi_open = lo, hi, lo_open, hi_open
        self.integer, self.unit, self.why = integer, unit, why
        self.__name__ = "integer" if integer else "number"      # argparse names the type by it

    def __call__(self, text):
        try:
            return check_number(text, "value", self.lo, self.hi, lo_open=self.lo_open, hi_open=self.hi_open,
                                integer=self.integer, unit=self.unit, why=self.why)
        except ParameterError as exc:       # refused by check_parsed, which knows the flag (exit 2 from main)
            return Refused(text, exc.problem)


def number(lo=None, hi=None, *, lo_open: bool = False, hi_open: bool = False, integer: bool = False,
           unit: str = "", why: str = "") -> CheckedNumber:
    """An argparse ``type`` checking a finite number (or an integer) in a range (``why``: the bound's reason)."""
    return CheckedNumber(lo, hi, lo_open=lo_open, hi_open=hi_open, integer=integer, unit=unit, why=why)


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
    --extended (they feed the extended fit only) and --cumulative-rpm with --no-report (it picks the report's
    plots).  The values themselves are :func:`rwadist.api.extended_options`'s to judge."""
    given = [f for f, v in (("--mass", args.mass), ("--radius", args.radius), ("--height", args.height or None),
                            ("--preset", args.preset)) if v is not None]
    if given and not args.extended:
        raise DataError(given[0], "value", "applies to the extended fit only: add --extended (the plain fit of "
                        "harmonics C·Ω² does not use it)")
    if args.cumulative_rpm and args.no_report:
        raise DataError("--cumulative-rpm", "value", "picks the report's plots: drop it, or drop --no-report")


def check_psd_flags(args: argparse.Namespace) -> None:
    """``rwadist psd``: flags that the chosen output would ignore are refused, as is an output whose extension
    names the other format (a NASTRAN deck written as x.csv, CSV as x.bdf)."""
    nastran = args.format == "nastran"
    given = [f for f, on in (("--nastran-cross", args.nastran_cross), ("--nastran-auto-only", args.nastran_auto_only),
                             ("--nastran-fields", args.nastran_fields != "small")) if on]
    if not nastran and given:
        raise DataError(given[0], "value", "applies to --format nastran only")
    if args.nastran_cross and args.nastran_auto_only:
        raise DataError("--nastran-auto-only", "value", "contradicts --nastran-cross: give one")
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


def rpm(lo: float = -MAX_RPM, hi: float = MAX_RPM):
    """An argparse ``type``: a wheel speed in rpm within [lo, hi]."""
    return number(lo, hi, unit="rpm")


def limited(parameter: str):
    """The argparse ``type`` of the flag giving the API parameter ``parameter``: its range in
    :data:`rwadist.validate.LIMITS`."""
    return number(**LIMITS[parameter])


def _add_fit_options(p):
    p.add_argument("--f-lim", type=limited("f_lim"), default=None, help="upper limit of good data, Hz (test-stand resonance)")
    p.add_argument("--nperseg", type=limited("nperseg"), default=None, help="FFT length (default: largest power of 2 in a run)")
    p.add_argument("--presence", type=limited("presence"), default=0.25, help="bin presence threshold P0, fraction (default 0.25)")
    p.add_argument("--epsilon", type=limited("epsilon"), default=0.02, help="binning tolerance on h (default 0.02)")
    p.add_argument("--no-mode-exclusion", action="store_true", help="keep modally amplified speeds in the fit")
    p.add_argument("--slice-samples", type=limited("slice_samples"), default=None,
                   help=_SLICE_SAMPLES_HELP)
    p.add_argument("--speed-source", choices=("auto", "tach", "data"), default="auto",
                   help="speed of sweep slices: tach column, estimated from data, or auto")
    p.add_argument("--extended", action="store_true",
                   help="also fit the extended model (modes, damping, imbalances) into the model file")
    p.add_argument("--mass", type=limited("mass"), default=None,
                   help="rotor mass, kg (extended fit; without --mass/--radius the fit is per unit mass/inertia)")
    p.add_argument("--radius", type=limited("radius"), default=None, help="rotor radius, m (extended fit; thin-disc inertias)")
    p.add_argument("--height", type=limited("height"), default=0.0,
                   help="lever arm from the rotor centre to the torque reference point, m (default 0)")
    p.add_argument("--preset", default=None, help="take mass and radius (and unseen modes) from a wheel preset")


class _Parser(argparse.ArgumentParser):
    """argparse's parser, its refusal of a flag whose value starts with '-' (a negative speed range: argparse
    takes ``-3000:-600`` for a flag) saying how to give it."""

    def error(self, message: str):
        if message.endswith("expected one argument"):
            flag = message.split("argument ", 1)[-1].split(":", 1)[0].split("/")[-1]
            message += f" (a value that starts with '-' goes after '=': {flag}=-VALUE)"
        super().error(message)


def build_parser(cli) -> argparse.ArgumentParser:
    """The argument parser; ``cli`` is the :mod:`rwadist.cli` module, whose ``cmd_*`` functions run the
    commands (passed in, not imported: the parser stays a leaf of the import graph)."""
    p = _Parser(prog="rwadist", description="Reaction wheel disturbance models from test data.")
    p.add_argument("--version", action="version", version=f"rwadist {_version()}")
    sub = p.add_subparsers(dest="command", required=True)
    # the commands in the order ``rwadist --help`` lists them
    for add_command in (_add_simulate_test, _add_fit, _add_model_tools, _add_catalogue, _add_demo, _add_convert,
                        _add_campbell, _add_psd, _add_diagnose, _add_fmu):
        add_command(sub, cli)
    return p


def _add_simulate_test(sub, cli) -> None:
    """``rwadist simulate-test``: the virtual test stand."""
    s = sub.add_parser("simulate-test", help="virtual test stand: synthetic load-cell data in the interchange format")
    s.add_argument("out_dir")
    s.add_argument("--preset", required=True, help="wheel preset, e.g. ithaco-e, ithaco-b")
    s.add_argument("--speeds-rpm", help="'A,B,C', 'START:STOP:STEP' or 'START:STOP' with --n-speeds")
    s.add_argument("--n-speeds", type=number(1, MAX_SPEEDS, integer=True), default=None)
    s.add_argument("--sample-rate", type=limited("sample_rate"), default=None, help="Hz (default: the preset's test)")
    s.add_argument("--samples", type=limited("n_samples"), default=8192, help="samples per steady run")
    s.add_argument("--noise", type=limited("noise"), default=0.01, help="sensor noise std as a fraction of the top-speed fundamental")
    s.add_argument("--no-modes", action="store_true", help="switch the wheel's structural modes off")
    s.add_argument("--no-test-stand", action="store_true", help="switch test-stand resonances off")
    s.add_argument("--seed", type=limited("seed"), default=0)
    s.add_argument("--sweep", action="store_true", help="one spin-up record instead of steady runs")
    s.add_argument("--sweep-start-rpm", type=rpm(), default=0.0)
    s.add_argument("--sweep-end-rpm", type=rpm(), default=None)
    s.add_argument("--duration", type=number(0, 1e5, lo_open=True, unit="s"), default=390.0, help="sweep duration, s")
    s.add_argument("--profile", choices=("linear", "exp"), default="linear")
    s.add_argument("--no-tach", action="store_true", help="sweep without the speed_rpm tach column")
    s.add_argument("--physics", choices=("simple", "extended"), default="simple",
                   help="simple resonances (default) or the extended rotor model of the preset")
    s.add_argument("--assumed-modes", action="store_true",
                   help="allow --physics extended on a catalogue wheel whose suspension modes are assumed "
                        "(the data's metadata then says so)")
    s.add_argument("--inject", action="append", default=[], metavar="KIND:PARAM=VALUE,...",
                   help="add a known effect to try diagnose on (repeatable; recorded in meta.json 'injected'): "
                        + ", ".join(c.KIND for c in elements() if c.INJECT is not None)
                        + " (parameters: see rwadist/effects/KIND.py)")
    s.set_defaults(func=cli.cmd_simulate)


def _add_fit(sub, cli) -> None:
    """``rwadist fit``: the empirical (or extended) fit of test data."""
    f = sub.add_parser("fit", help="fit the empirical model to test data; writes the model file and a report")
    f.add_argument("data", help="steady-state directory, sweep CSV, or .h5")
    f.add_argument("-o", "--output", required=True, help="model file to write (JSON)")
    f.add_argument("--report", help="report directory (default: <model>_report)")
    f.add_argument("--no-report", action="store_true",
                   help="write the model file only, no report (batch fits: the report's plots take most of a small fit's time)")
    f.add_argument("--cumulative-rpm", help="speeds of the cumulative-RMS plots, e.g. '600,1500,2400' "
                   "(default: lowest, middle, top)")
    _add_fit_options(f)
    f.set_defaults(func=cli.cmd_fit)


def _add_model_tools(sub, cli) -> None:
    """``rwadist model show`` and ``rwadist model compare``."""
    m = sub.add_parser("model", help="model file tools")
    msub = m.add_subparsers(dest="model_command", required=True)
    ms = msub.add_parser("show", help="print a model's harmonics")
    ms.add_argument("model")
    ms.add_argument("--format", choices=("table", "csv", "json"), default="table")
    ms.set_defaults(func=cli.cmd_model_show)
    mc = msub.add_parser("compare", help="a fitted model next to a catalogue wheel (exit 1 if an imbalance "
                         "exceeds the datasheet limit)")
    mc.add_argument("model")
    mc.add_argument("--preset", required=True, help="catalogue wheel, e.g. ithaco-e")
    mc.set_defaults(func=cli.cmd_model_compare)


def _add_catalogue(sub, cli) -> None:
    """``rwadist catalogue list`` and ``rwadist catalogue show``."""
    cat = sub.add_parser("catalogue", help="catalogue of real wheels (presets for every command)")
    csub = cat.add_subparsers(dest="catalogue_command", required=True)
    cl = csub.add_parser("list", help="the catalogue wheels with their sources")
    cl.set_defaults(func=cli.cmd_catalogue_list)
    cs = csub.add_parser("show", help="one catalogue wheel: source, what was measured, harmonics, parameters")
    cs.add_argument("name")
    cs.set_defaults(func=cli.cmd_catalogue_show)


def _add_demo(sub, cli) -> None:
    """``rwadist demo``: simulate, fit and report on the example wheel."""
    d = sub.add_parser("demo", help="simulate -> fit -> report on the bundled example wheel")
    d.add_argument("--out", default="demo_out", help="output directory (default demo_out)")
    d.add_argument("--n-speeds", type=number(2, 10_000, integer=True), default=120)
    d.add_argument("--seed", type=number(0, 2**32 - 1, integer=True), default=0)
    d.set_defaults(func=cli.cmd_demo)


def _add_convert(sub, cli) -> None:
    """``rwadist convert``: test data between formats."""
    cv = sub.add_parser("convert", help="convert test data between formats: CSV interchange, HDF5, UFF 58, TDMS, "
                        "MATLAB (docs/formats.md)")
    cv.add_argument("src", help="a steady-test directory (runs.csv), a sweep file or an .h5 file")
    cv.add_argument("-o", "--output", required=True, help="an .h5 file, a directory (steady test) or a sweep file")
    cv.add_argument("--format", choices=["csv", "uff", "uff-binary", "tdms", "mat", "mat73"], default=None,
                    help="run/sweep file format (default: csv for a directory, else from the extension)")
    cv.add_argument("--precision", choices=["float64", "float32"], default="float64",
                    help="HDF5 sample precision (default float64, lossless)")
    cv.set_defaults(func=cli.cmd_convert)


def _add_campbell(sub, cli) -> None:
    """``rwadist campbell``: the extended model's Campbell table and plot."""
    c = sub.add_parser("campbell", help="Campbell table and plot of the extended model; prints crossing speeds")
    src = c.add_mutually_exclusive_group(required=True)
    src.add_argument("model", nargs="?", help="model file (JSON) with an analytical section")
    src.add_argument("--preset", help="wheel preset instead of a model file, e.g. ithaco-e")
    c.add_argument("--speeds-rpm", default="0:3000:100", help="'START:STOP:STEP', 'A,B,C' or 'START:STOP' "
                   "with --n-speeds (default 0:3000:100)")
    c.add_argument("--n-speeds", type=number(2, MAX_SPEEDS, integer=True), default=None)
    c.add_argument("-o", "--output", default="campbell.csv", help="CSV to write; the plot goes next to it (.png)")
    c.set_defaults(func=cli.cmd_campbell)


def _add_psd(sub, cli) -> None:
    """``rwadist psd``: the broadband PSD over a wheel-speed distribution."""
    q = sub.add_parser("psd", help="broadband disturbance PSD over a wheel-speed distribution (Melody's model / "
                       "extended model), optionally several wheels in the spacecraft frame")
    q.add_argument("model", nargs="?", help="model file (JSON)")
    q.add_argument("--preset", help="wheel preset instead of a model file, e.g. ithaco-e")
    q.add_argument("--speed-rpm", required=True, help="MIN:MAX speed range, rpm (negative = spinning about -z)")
    q.add_argument("--dist", default="uniform", help="uniform | normal | FILE.csv (speed_rpm,weight histogram, "
                   "speed_rpm,pdf_per_rpm density, or time_s,speed_rpm profile)")
    q.add_argument("--std-rpm", type=limited("std_rpm"), default=None, help="std of the normal law, rpm (default range/6)")
    q.add_argument("--wheels", help="wheels.json: several wheels with mountings (spacecraft-frame 6x6 CSD)")
    q.add_argument("--fmax", type=limited("fmax"), default=None, help="top frequency, Hz (default 1.2 x highest line)")
    q.add_argument("--n-freq", type=limited("n_freq"), default=20001, help="frequency points 0..fmax (default 20001)")
    q.add_argument("--n-speeds", type=limited("n_speeds"), default=2000, help="speed cells of the law (default 2000)")
    q.add_argument("--empirical", action="store_true", help="Melody's model from the harmonics alone, no modes")
    q.add_argument("--assumed-modes", action="store_true",
                   help="run a wheel with assumed (datasheet) suspension modes through them (default: hard-mounted); "
                        "the outputs then carry a note that they rest on assumed values")
    q.add_argument("--format", choices=("csv", "nastran"), default="csv")
    q.add_argument("--nastran-fields", choices=("small", "free"), default="small")
    q.add_argument("--nastran-cross", action="store_true",
                   help="RANDPS/TABRND1 of the cross-spectra too (the default; kept for scripts that give it)")
    q.add_argument("--nastran-auto-only", action="store_true",
                   help="leave the cross-spectra out of the deck (auto-spectra only); the console and the deck name "
                        "the coherence each pair left out carries")
    q.add_argument("--cross", choices=("csv", "h5", "none"), default="csv",
                   help="cross-spectra next to the output: <out>_cross.csv (default) or <out>_cross.h5")
    q.add_argument("-o", "--output", default=None,
                   help="output file (CSV or NASTRAN bulk data; default psd.csv, or psd.bdf with --format nastran)")
    q.set_defaults(func=cli.cmd_psd)


def _add_diagnose(sub, cli) -> None:
    """``rwadist diagnose``: the effects a model lacks against test data."""
    dg = sub.add_parser("diagnose", help="residual of a model against test data; finds, adds and reports the "
                        "effects the model lacks (missing harmonics, amplitude laws, broadband floors, resonances, "
                        "coupling, sidebands, speed ripple, counter rotation)")
    dg.add_argument("data", help="steady-test directory, sweep CSV or HDF5")
    dsrc = dg.add_mutually_exclusive_group()
    dsrc.add_argument("--model", help="model file to start from (default: the empirical fit of the data)")
    dsrc.add_argument("--preset", help="start from a wheel preset's model, e.g. ithaco-e")
    dg.add_argument("-o", "--output", required=True, help="report directory")
    dg.add_argument("--nperseg", type=limited("nperseg"), default=None, help="FFT length (default: power of 2 <= run length/4)")
    dg.add_argument("--f-lim", type=limited("f_lim"), default=None, help="upper limit of good data, Hz")
    dg.add_argument("--k-sigma", type=limited("k_sigma"), default=4.0, help="held-out gain needed, noise standard errors (4)")
    dg.add_argument("--min-gain", type=limited("min_gain"), default=0.05,
                    help="held-out gain needed, fraction of the unexplained power (0.05)")
    dg.add_argument("--base", choices=("auto", "empirical", "extended"), default="auto",
                    help="starting prediction of the lines: 'empirical' C*omega^2 hard mounted, 'extended' through "
                         "the rotor's suspension modes of the model's analytical section (forward/backward whirl, "
                         "rotation sense); auto (default): extended when the model (--model/--preset) has an "
                         "analytical section and the data's meta.json does not say modes: false")
    dg.add_argument("--slice-samples", type=limited("slice_samples"), default=None,
                    help=_SLICE_SAMPLES_HELP)
    dg.add_argument("--speed-source", choices=("auto", "tach", "data"), default="auto",
                    help="speed of sweep slices: tach column, estimated from data, or auto")
    dg.add_argument("--bearing", action="append", default=None, metavar="KEY=VALUE,...",
                    help="a bearing of the wheel, e.g. balls=9,ball_diameter_m=0.00794,pitch_diameter_m=0.03904"
                         "[,contact_angle_deg=15][,name=front][,rotating_race=inner|outer]: its cage, ball-pass and "
                         "ball-spin ratios are named as causes of lines (repeat for each bearing; replaces the model "
                         "file's wheel.bearings)")
    dg.set_defaults(func=cli.cmd_diagnose)


def _add_fmu(sub, cli) -> None:
    """``rwadist fmu build`` and ``rwadist fmu check``."""
    fm = sub.add_parser("fmu", help="FMI 2.0/3.0 co-simulation FMU of the extended model, SSP of an assembly "
                        "(build, check)")
    fsub = fm.add_subparsers(dest="fmu_command", required=True)
    fb = fsub.add_parser("build", help="build the FMU from a model file or a preset (default: ithaco-e)")
    fsrc = fb.add_mutually_exclusive_group()
    fsrc.add_argument("model", nargs="?", help="model file (JSON): empirical, extended or diagnosed")
    fsrc.add_argument("--preset", help="wheel preset instead of a model file, e.g. ithaco-e")
    fb.add_argument("-o", "--output", default="wheel.fmu", help="FMU to write (default wheel.fmu)")
    fb.add_argument("--native", action="store_true",
                    help="write a pure-C FMU (no Python on the host; sources/ included) instead of pythonfmu's")
    fb.add_argument("--assumed-modes", action="store_true",
                    help="a wheel with assumed (datasheet) suspension modes runs them by default (modes = true); "
                         "without it such a wheel is hard-mounted by default")
    fb.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                    help="FMI version of the --native FMU: 2 (default) or 3 (FMI 3.0 co-simulation)")
    fb.add_argument("--wheels", metavar="WHEELS_JSON",
                    help="with --native: an SSP 1.0 file of the assembly in this wheels.json (the file of rwadist psd "
                         "--wheels), one wheel FMU per wheel with its mounting and speed law; -o must end in .ssp")
    fb.set_defaults(func=cli.cmd_fmu_build)
    fc = fsub.add_parser("check", help="fmpy validation and a short spin-up simulation of an FMU")
    fc.add_argument("fmu")
    fc.add_argument("--stop-time", type=number(0, 1e5, lo_open=True, unit="s"), default=1.0, help="s (default 1)")
    fc.add_argument("--step-size", type=number(0, 1e3, lo_open=True, unit="s"), default=1e-3, help="communication step, s (default 1e-3)")
    fc.add_argument("--speed-rpm", type=rpm(), default=1500.0, help="end speed of the ramp from 0 (default 1500)")
    fc.set_defaults(func=cli.cmd_fmu_check)
