"""The ``rwadist`` command line.  rpm and Hz at this edge, SI inside."""
from __future__ import annotations

import argparse
import errno
import json
import os
import sys
import time
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from . import api, catalogue
from . import data as data_io
from . import model as model_io
from .cli_catalogue import cmd_catalogue_list, cmd_catalogue_show, cmd_model_compare  # noqa: F401 (parser)
from .cli_fmu import cmd_fmu_build, cmd_fmu_check  # noqa: F401 (parser)
from .cli_parser import _version, check_fit_flags, check_parsed, check_psd_flags
from .data import DataError
from .errors import ParameterError, RwadistError, UnresolvedLinesWarning
from .outputs import (
    atomic_dataset_dir,
    check_dataset_dir,
    check_model_file,
    check_output_dir,
    check_output_file,
    exit_on_interrupt,
    interrupt_message,
    output_set,
    refuse_input_overwrite,
    refuse_special_base,
)
from .outputs import write_file as _write
from .plot_util import import_matplotlib_for_command, psd_title, save_png
from .progress import working
from .threads import one_blas_thread
from .units import RAD_S_TO_RPM
from .validate import check_grid_size, check_speeds_rpm, check_within_test


def parse_speeds(text: str, n: int | None = None, flag: str = "--speeds-rpm",
                 n_flag: str | None = "--n-speeds") -> np.ndarray:
    """rpm list from 'A,B,C', 'START:STOP:STEP' (stop inclusive) or 'START:STOP' with ``n`` points;
    every speed finite within +-MAX_RPM, at most MAX_SPEEDS of them (:class:`DataError` naming ``flag``).
    ``n_flag``: the command's flag giving ``n``, None when it has none (``fit --cumulative-rpm``: no START:STOP)."""
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if not all(np.isfinite(parts)):
                raise ValueError("every part must be a finite number of rpm")
            if len(parts) == 2:
                if not n:
                    raise ValueError(f"START:STOP needs {n_flag}" if n_flag else
                                     "START:STOP gives no number of speeds: give START:STOP:STEP or A,B,C")
                return check_speeds_rpm(np.linspace(parts[0], parts[1], int(n)), flag)
            if len(parts) != 3:
                raise ValueError("expected START:STOP:STEP or START:STOP")
            if n:
                raise ValueError("START:STOP:STEP gives its own number of speeds: drop --n-speeds, or give START:STOP")
            start, stop, step = parts
            if step <= 0:
                raise ValueError("STEP must be > 0")
            check_speeds_rpm([start, stop], flag)
            check_grid_size(start, stop, step, flag)
            return check_speeds_rpm(np.arange(start, stop + 0.5 * step, step), flag)
        return check_speeds_rpm([float(p) for p in text.split(",") if p.strip()], flag)
    except ValueError as exc:
        if isinstance(exc, DataError):
            raise
        why = str(exc)
        if why.startswith("could not convert"):
            why = "not a number; give speeds in rpm as A,B,C or START:STOP:STEP" + (
                f", or START:STOP with {n_flag}" if n_flag else "")
        raise DataError(flag, "value", f"{text!r}: {why}") from None


# --------------------------------------------------------------------------- simulate-test

def _simulate_sweep(args, out: Path) -> int:
    """``simulate-test --sweep``: one spin-up record (:func:`rwadist.simulate_sweep`)."""
    if args.inject:
        raise DataError("--inject", "--sweep", "injections apply to steady runs; leave out --sweep")
    sweep = api.simulate_sweep(args.preset, args.sweep_start_rpm, 2400.0 if args.sweep_end_rpm is None else
                               args.sweep_end_rpm, duration=args.duration, sample_rate=args.sample_rate,
                               noise=args.noise, modes=not args.no_modes, test_stand=not args.no_test_stand,
                               seed=args.seed, profile=args.profile, tach=not args.no_tach, physics=args.physics,
                               assumed_modes=args.assumed_modes)
    path = _write(out / "sweep.csv", lambda tmp: data_io.write_sweep(sweep, tmp))
    print(f"wrote sweep {path} ({len(sweep.time)} samples, {sweep.sample_rate:g} Hz)")
    return 0


def cmd_simulate(args) -> int:
    """Synthetic load-cell data of a preset wheel (:func:`rwadist.simulate_test`, :func:`rwadist.simulate_sweep`)."""
    out = Path(args.out_dir)
    if args.sweep:
        return _simulate_sweep(args, out)
    if args.n_speeds and not args.speeds_rpm:
        raise DataError("--n-speeds", "value", "needs --speeds-rpm START:STOP")
    speeds = parse_speeds(args.speeds_rpm, args.n_speeds) if args.speeds_rpm else None
    check_dataset_dir(out, "OUT_DIR")      # before the simulation: the folder is replaced whole
    n_runs = len(speeds) if speeds is not None else 20
    with working(f"rwadist simulate-test: simulating {n_runs} runs"):
        test = api.simulate_test(args.preset, speeds, sample_rate=args.sample_rate, n_samples=args.samples,
                                 noise=args.noise, modes=not args.no_modes, test_stand=not args.no_test_stand,
                                 seed=args.seed, physics=args.physics, inject=args.inject,
                                 assumed_modes=args.assumed_modes)
    for e in test.meta.get("injected", []):
        print("injected " + e["kind"] + ": " + ", ".join(f"{k}={v}" for k, v in e.items() if k != "kind"))
    if above := test.meta.get("lines_above_nyquist"):
        lines = sorted({(x["direction"], x["h"]) for x in above})
        named = ", ".join(f"{d} h={h:g}" for d, h in lines[:4]) + (" ..." if len(lines) > 4 else "")
        print(f"note: {len(lines)} of the wheel's lines reach the Nyquist frequency in "
              f"{len({x['speed_rpm'] for x in above})} run(s) and are not recorded there, as an anti-aliasing filter "
              f"would ({named}; meta.json lines_above_nyquist); raise --sample-rate to keep them")
    speeds = np.array([r.speed for r in test.runs]) * RAD_S_TO_RPM
    fs = test.runs[0].sample_rate
    with atomic_dataset_dir(out, "OUT_DIR") as tmp, working(f"writing {len(test.runs)} runs"):
        data_io.write_steady(test, tmp)
    print(f"wrote {len(test.runs)} runs to {out} ({speeds.min():g} to {speeds.max():g} rpm, {fs:g} Hz, "
          f"{args.samples} samples each)")
    return 0


# --------------------------------------------------------------------------- fit

def load_steady(path, args):
    """A steady test from a directory, a sweep CSV (sliced) or HDF5 (:func:`rwadist.read`)."""
    return api.read(path, slice_samples=args.slice_samples, speed_source=args.speed_source, progress=True, log=print)


def run_fit(test, args, name: str, progress: bool = True):
    return api.fit(test, f_lim=args.f_lim, nperseg=args.nperseg, presence=args.presence, epsilon=args.epsilon,
                   exclude_modes=not args.no_mode_exclusion, name=name, progress=progress)


def cmd_fit(args) -> int:
    from .report import write_report

    check_model_file(args.output)
    if args.no_report and args.report:
        raise DataError("--no-report", "--report", f"{args.report}: give one of the two (--no-report writes the model file "
                        "only)")
    report_dir: Path | None = None
    beside = Path(args.output).with_suffix("").parent / (Path(args.output).stem + "_report")   # the default report
    if not args.no_report:
        report_dir = Path(args.report) if args.report else beside
        if not args.report:
            refuse_special_base(args.output, "-o", f"its report folder {report_dir.name}",
                                "give --report DIR or --no-report")
        elif report_dir.resolve() == Path(args.output).resolve():   # the fit ran, then the two writes collided
            raise DataError("--report", "value", f"{args.report}: the same path as -o (the model file); the report "
                            f"is a folder of its own: give another, e.g. --report "
                            f"{beside}")
        check_output_dir(report_dir, "--report")
    check_fit_flags(args)
    if args.extended:
        api.extended_options(args.mass, args.radius, args.height, args.preset)    # refused before the data are read
    refuse_input_overwrite([("-o", args.output, "file")] + ([("--report", report_dir, "dir")] if report_dir else []),
                           [args.data])
    t0 = time.perf_counter()
    test = load_steady(args.data, args)
    if args.cumulative_rpm and report_dir is not None:
        check_within_test(parse_speeds(args.cumulative_rpm, flag="--cumulative-rpm", n_flag=None), test, "cumulative_rpm")
    with warnings.catch_warnings():
        if args.extended:       # the extended fit measures the lines the empirical one could not tell apart
            warnings.filterwarnings("ignore", category=UnresolvedLinesWarning)
        fit = run_fit(test, args, name=Path(args.data).name)
    fit.model.provenance["data"] = str(args.data)
    model = fit.model
    efit = None
    if args.extended:
        efit, model = run_extended_fit(test, fit, args)
    cum = parse_speeds(args.cumulative_rpm, flag="--cumulative-rpm", n_flag=None) if args.cumulative_rpm else None
    files = []
    with output_set() as outs:      # the model and its report replace the old ones together, once both are complete
        if report_dir is not None:
            tmp_dir = outs.folder(report_dir)
            files = write_report(fit, tmp_dir, cumulative_speeds_rpm=cum, progress=True)
            if efit is not None:
                from .report_extended import write_extended_report

                with working("writing the extended report"):
                    files += write_extended_report(efit, fit, tmp_dir, model=model, report_files=files)
        model_io.save(model, outs.file(args.output))
    n = sum(len(v) for v in fit.model.empirical.values())
    idle = fit.model.provenance.get("runs_not_fitted", {}).get("runs", [])
    print(f"fitted {n} harmonics from {len(test.runs) - len(idle)} runs in {time.perf_counter() - t0:.1f} s")
    if idle:
        print(f"note: {len(idle)} run(s) at zero speed not fitted (noise runs): {', '.join(idle[:5])}"
              f"{' ...' if len(idle) > 5 else ''} (the model's provenance.runs_not_fitted)")
    if efit is not None:
        print(f"extended model: {sum(len(v) for v in model.empirical.values())} forcing lines through the fitted "
              "modes (every line the data show, modally amplified or not)")
    modal = [f"{b.direction} h={b.h:.4g}" for b in fit.modally_left_out]
    if modal and efit is None:
        print(f"WARNING: {len(modal)} harmonic(s) the data show were left out of the model because their lines are "
              f"modally amplified at nearly every speed ({', '.join(modal[:6])}{' and more' if modal[6:] else ''}"
              f"{'; bins.csv in the report gives the reasons' if report_dir else ''}): C·Ω² does not describe them; "
              "fit the wheel's modes with --extended, or keep them with --no-mode-exclusion", file=sys.stderr)
    print(f"model:  {args.output}")
    print(f"report: {report_dir} ({len(files)} files)" if report_dir is not None else "report: none (--no-report)")
    if report_dir is None and beside.is_dir():
        print(f"note: {beside} is the report of an earlier fit and does not describe this model (rerun without "
              "--no-report to replace it, or remove it)", file=sys.stderr)
    if n == 0:
        # a script that goes on to psd, fmu or diagnose with this model would compute zeros: exit 1, as a failed check
        print(f"ERROR: the model is empty: no harmonic was found in {args.data} (the warning above says where to "
              f"look); {args.output} is written for inspection only", file=sys.stderr)
        return 1
    return 0


def run_extended_fit(test, fit, args):
    """The extended model fitted on top of the empirical fit; mass and radius from the options or a preset."""
    mass, radius, _ = api.extended_options(args.mass, args.radius, args.height, args.preset)
    if mass is None:
        print("fitting the extended model per unit mass and inertia (no --mass/--radius: the interface loads "
              f"depend only on k/M, c/M, k_theta/I_rr, c_theta/I_rr, I_zz/I_rr; height = {args.height:g} m) ...",
              flush=True)
    else:
        print(f"fitting the extended model (M = {mass:g} kg, R = {radius:g} m, height = {args.height:g} m) ...",
              flush=True)
    efit, model = api.fit_extended(test, fit, mass=args.mass, radius=args.radius, height=args.height,
                                   preset=args.preset)
    p = efit.params
    if efit.per_unit:
        print("  (stiffness and damping below are per kg of rotor mass / per kg·m² of transverse inertia)")
    print(f"  radial translation {p.omega_r / (2 * np.pi):7.2f} Hz  zeta {efit.zeta['radial_translation']:.3f}"
          f"  (k_r {p.k_r:.4g} N/m)")
    print(f"  rocking at rest    {p.omega_rock / (2 * np.pi):7.2f} Hz  zeta {efit.zeta['rocking']:.3f}"
          f"  (k_rock {p.k_rock:.4g} N·m/rad)")
    print(f"  axial translation  {p.omega_z / (2 * np.pi):7.2f} Hz  zeta {efit.zeta['axial_translation']:.3f}"
          f"  (k_z {p.k_z:.4g} N/m)")
    # an imbalance is read through its mode's transfer (translation: U_s, rocking: U_d): through a starting value it
    # rests on that value (the demo's simple-physics data, every mode unconstrained: U_d 1.05e-09 for 2e-06)
    loose = [u for u, m in (("U_s", "radial_translation"), ("U_d", "rocking")) if m in efit.unconstrained]
    print(f"  U_s {p.U_s:.4g} kg·m, U_d {p.U_d:.4g} kg·m²" + (f"  ({' and '.join(loose)} read through a mode the data "
                                                             "do not constrain: it rests on that mode's starting value)"
                                                             if loose else ""))
    for mode, db in efit.residual_db.items():
        print(f"  residual near {mode}: {db:.2f} dB RMS"
              + ("  (a linear model does not match this resonance well)" if db > 2.0 else ""))
    for note in efit.notes:
        print(f"  note: {note}")
    if efit.unconstrained:
        print(f"  UNCONSTRAINED by the data (starting values, or values not told apart from a test stand: see the "
              f"notes; listed in the model file): {', '.join(efit.unconstrained)}")
    return efit, model


# --------------------------------------------------------------------------- model show

def cmd_model_show(args) -> int:
    m = model_io.load(args.model)
    rows = [(d, h) for d in model_io.DIRECTIONS for h in m.harmonics(d)]
    if args.format == "json":
        print(json.dumps(model_io.to_json(m), indent=2))
        return 0
    from .effects_text import model_table, shown_sense

    if args.format == "csv":
        print("direction,h,C_SI,C_stderr_SI,sense")
        for d, h in rows:
            se = "" if h.C_stderr is None else repr(float(h.C_stderr))
            print(f"{d},{h.h!r},{h.C!r},{se},{shown_sense(d, h)}")
        return 0

    print("\n".join(model_table(m)))
    return 0


# --------------------------------------------------------------------------- demo

def cmd_demo(args) -> int:
    """simulate (E-wheel preset, modes on) -> write -> read -> fit -> model + report, vs the truth."""
    from .presets import preset
    from .report import write_report
    from .teststand import simulate_steady

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise DataError("--out", "value", f"{str(out)!r} is a file, not a folder: give a folder for the demo's outputs")
    if (out / "runs.csv").is_file():        # a lab's runs: the demo's data and model would sit beside them
        raise DataError("--out", "folder", f"{str(out)!r} holds a steady-test dataset (runs.csv); the demo writes "
                        "its own data.h5, model.json and report/ there: give a new folder")
    check_output_dir(out / "report", "--out")       # its report folder is replaced whole
    wheel = preset("ithaco-e")
    speeds = np.linspace(300.0, 2400.0, args.n_speeds)
    print(f"1/4 virtual test stand: {wheel.name}, {len(speeds)} speeds 300-2400 rpm, 3840 Hz, 8192 samples, "
          "noise 1 %, wheel modes on")
    with working(f"simulating {len(speeds)} runs"):
        test = simulate_steady(wheel, speeds, sample_rate=3840.0, n_samples=8192, noise=0.01, modes=True,
                               seed=args.seed)
    from .hdf5 import read_hdf5, write_hdf5

    data_path, model_path = out / "data.h5", out / "model.json"
    with output_set() as outs:      # data, model and report: swapped in together once all are complete
        data_tmp = outs.file(data_path, "--out")
        write_hdf5(test, data_tmp, compression="gzip", precision="float32")
        print(f"2/4 the test as HDF5: {data_path} ({data_tmp.stat().st_size / 1e6:.1f} MB; float32 samples, "
              "gzip; `rwadist convert` writes any other format)")
        stored = read_hdf5(data_tmp)        # the fit reads what the file holds (float32 samples)
        print("3/4 fitting the empirical model")
        ns = argparse.Namespace(f_lim=None, nperseg=None, presence=0.25, epsilon=0.02, no_mode_exclusion=False)
        fit = run_fit(stored, ns, name="demo: " + wheel.name)
        fit.model.provenance["data"] = str(data_path)
        model_io.save(fit.model, outs.file(model_path, "--out"))
        files = write_report(fit, outs.folder(out / "report"), progress=True)
    print(f"4/4 wrote data {data_path}, model {model_path}, report {out / 'report'} ({len(files)} files)\n")
    truth = wheel.to_model()
    print(f"{'direction':<14} {'h fit':>7} {'h true':>7} {'C fit':>11} {'C true':>11} {'err':>7}  excluded rpm")
    for d in model_io.DIRECTIONS:
        th, tc = truth.h_and_C(d)
        for hm in fit.model.harmonics(d):
            k = int(np.argmin(np.abs(th - hm.h))) if th.size else -1
            if k >= 0 and abs(th[k] - hm.h) < 0.05:
                err = f"{100 * (hm.C / tc[k] - 1):+6.1f}%"
                tru_h, tru_c = f"{th[k]:7.2f}", f"{tc[k]:11.3e}"
            else:
                err, tru_h, tru_c = "  extra", "      -", "          -"
            ex = " ".join(f"{lo:.0f}-{hi:.0f}" for lo, hi in hm.excluded_rpm)
            print(f"{d:<14} {hm.h:7.3f} {tru_h} {hm.C:11.3e} {tru_c} {err}  {ex}")
    return 0


# --------------------------------------------------------------------------- convert

def cmd_convert(args) -> int:
    """Read test data in any supported format and write it in another (see docs/formats.md)."""
    from .formats.registry import EXTENSION, READ_EXTENSIONS
    from .hdf5 import write_hdf5

    src, dst = Path(args.src), Path(args.output)
    if str(args.output).strip() == "":
        raise DataError("-o", "value", "empty: give the file or folder to write")
    refuse_input_overwrite([("-o", dst, "file")], [src])
    if dst.is_dir():
        check_dataset_dir(dst, "-o")           # before reading: a folder that would be refused after it
    obj = data_io.read_data(src, progress=True)
    if dst.suffix.lower() in (".h5", ".hdf5"):
        check_output_file(dst)
        _write(dst, lambda tmp: write_hdf5(obj, tmp, compression="gzip", precision=args.precision))
        print(f"wrote {dst} (HDF5, {args.precision}, gzip; {dst.stat().st_size / 1e6:.2f} MB)")
        return 0
    if args.precision != "float64":
        raise DataError("--precision", "value", f"{args.precision!r} applies to HDF5 output only")
    if isinstance(obj, data_io.SteadyTest):
        fmt = args.format or "csv"
        if dst.suffix.lower() in READ_EXTENSIONS:
            raise DataError(dst, "-o", f"a steady test is a directory (runs.csv + one {fmt} file per run) or an "
                            f".h5 file, not a {dst.suffix} file")
        check_output_dir(dst)
        refuse_input_overwrite([("-o", dst, "dir")], [src])      # the folder is replaced whole
        with atomic_dataset_dir(dst) as tmp:
            data_io.write_steady(obj, tmp, fmt)
        print(f"wrote {len(obj.runs)} runs to {dst} ({fmt}, runs.csv, meta.json)")
        return 0
    fmt = args.format
    if fmt is None:
        if dst.suffix.lower() not in READ_EXTENSIONS:
            raise DataError(dst, "-o", f"extension {dst.suffix!r} does not name a format; use one of "
                            f"{sorted(READ_EXTENSIONS)} or .h5, or give --format")
        fmt = READ_EXTENSIONS[dst.suffix.lower()]
    if dst.suffix.lower() != EXTENSION[fmt]:
        raise DataError(dst, "-o", f"a {fmt} sweep file must end in {EXTENSION[fmt]}")
    check_output_file(dst)
    refuse_special_base(dst, "-o", f"its metadata {dst.with_suffix('.meta.json').name}")
    with output_set() as outs:      # the sweep and its metadata sidecar replace the old pair together
        tmp = outs.file(dst)
        data_io.write_sweep(obj, tmp, fmt, with_meta=True)
        meta_tmp = tmp.with_suffix(".meta.json")
        if meta_tmp.exists():
            os.replace(meta_tmp, outs.file(dst.with_suffix(".meta.json")))
        else:       # an older sidecar would describe another sweep
            outs.remove(dst.with_suffix(".meta.json"))
    print(f"wrote sweep {dst} ({fmt}, {len(obj.time)} samples)")
    return 0


# --------------------------------------------------------------------------- campbell

def cmd_campbell(args) -> int:
    """Campbell table (CSV) + plot (PNG next to it) of a model file's or preset's extended parameters;
    prints the harmonic/mode crossing speeds."""
    from .campbell import plot_campbell, write_campbell_csv

    out = check_output_file(args.output)
    refuse_input_overwrite([("-o", out, "file"), ("-o", out.with_suffix(".png"), "file")], [args.model])
    refuse_special_base(out, "-o", f"its plot {out.with_suffix('.png').name}")
    speeds = parse_speeds(args.speeds_rpm, args.n_speeds)
    table, rows = api.campbell(args.model, speeds, preset=args.preset)
    params, lines, source = api.extended_source(args.model, preset=args.preset, needed_for="the Campbell diagram")
    png_path, csv_path = out.with_suffix(".png"), out
    with output_set() as outs:      # the table and its plot replace the old pair together
        save_png(plot_campbell(params, speeds, lines), outs.file(png_path), dpi=120)
        write_campbell_csv(table, outs.file(csv_path))
    print(f"Campbell table of {source}: {csv_path} ({len(speeds)} speeds), plot: {png_path}")
    print(f"{'h':>6} {'direction':<14} {'sense':<8} {'mode':<19} {'speed_rpm':>10} {'f_Hz':>8}  excites")
    for r in rows:
        print(f"{r['h']:6g} {r['direction']:<14} {r['sense']:<8} {r['mode']:<19} {r['speed_rpm']:10.2f} "
              f"{r['f_Hz']:8.2f}  {'yes' if r['excited'] else 'no'}")
    return 0


# --------------------------------------------------------------------------- diagnose

def _print_base_lines(base_lines) -> None:
    """Console lines of the lines a diagnosis completed into a base fitted from the data (its summary's
    ``base_lines``), each with the model lines measured apart from it."""
    for e in base_lines:
        print(f"  = {e['direction']} h = {e['h']:g}, C = {e['C']:.3g}: a line of the data the fitted base did not hold "
              "(unresolved by the modes' fit, or left out as amplified at nearly every speed before a test stand was "
              "named), added to it (no model to miss it from)")
        for m in e.get("measured_apart", ()):
            part = f" ({m['sense']}-rotating part)" if m.get("sense") in ("co", "counter") else ""
            print(f"    beside it h = {m['h_before']:g}{part}, C = {m['C_before']:.3g} was the two lines' blend on the Welch "
                  f"grid: measured apart on the whole-run DFT, h = {m['h']:g}, C = {m['C']:.3g}")


def cmd_diagnose(args) -> int:
    """Fit (or take) a model, find what it leaves in the residual, add the effects that pass, report."""
    from .diagnose import write_report

    if args.preset and args.model:
        raise DataError("diagnose", "--model/--preset", "give a model file or --preset, not both")
    check_output_dir(args.output)
    refuse_input_overwrite([("-o", args.output, "dir")], [args.data, args.model])
    from .bearings import parse_bearing

    bearings = None if not args.bearing else tuple(parse_bearing(b, "--bearing", f"bearing {i + 1}")
                                                   for i, b in enumerate(args.bearing))
    t0 = time.perf_counter()
    test = load_steady(args.data, args)
    # a starting model whose suspension modes are assumed (datasheet wheel) is hard-mounted unless
    # --base extended asks for its assumed modes explicitly: the rule is resolve_base's (api.diagnose)
    assumed = catalogue.source_modes_assumed(args.model, args.preset)
    if assumed and args.base == "auto":
        print(f"note: {args.model or args.preset}: suspension modes are assumed (datasheet wheel); the starting "
              "prediction is hard-mounted (C*omega^2), modes the data show are fitted from them; --base extended "
              "uses the assumed modes")
    try:
        with working("rwadist diagnose: searching the residual for effects"):
            diag = api.diagnose(test, args.model, preset=args.preset, base=args.base, nperseg=args.nperseg,
                                f_lim=args.f_lim, k_sigma=args.k_sigma, min_gain=args.min_gain, bearings=bearings,
                                source=args.data)
    except ParameterError as exc:
        if exc.parameter != "base":
            raise
        raise DataError(args.model or "diagnose", "--base", "extended needs a model with the wheel's suspension "
                        "modes (an analytical section): give one made by `rwadist fit --extended`, or a --preset, "
                        "or leave --base at auto") from None
    with output_set() as outs, working("writing the diagnose report"):
        tmp_dir = outs.folder(args.output)
        files = [Path(args.output) / Path(f).name for f in write_report(diag, tmp_dir)]
        if assumed and diag.state_before.base == "extended":
            from .catalogue import write_assumed_note
            files.append(write_assumed_note(Path(args.output) / "ASSUMED_MODES.txt", [args.model or args.preset],
                                            files, with_flags, write_to=tmp_dir / "ASSUMED_MODES.txt"))
    base = diag.state_before.base
    if diag.state_after.base != base:
        base += f" -> {diag.state_after.base} (the wheel's suspension modes fitted from the data)"
    lo, hi = diag.band_Hz
    print(f"diagnosed {len(test.runs)} runs over {lo:.3g}-{hi:.4g} Hz in {time.perf_counter() - t0:.1f} s, "
          f"{diag.iterations} iteration(s), {base} base")
    summary = diag.summary()
    status = summary["suspension_modes_status"]
    if status and status["status"] != "no_amplification":
        print(f"  ! suspension modes: {status['text']}")
    if diag.data_quality:
        from .data_quality import quality_lines

        for line in quality_lines(diag.data_quality):
            print(f"  ! {line}")
    if diag.speed.get("source") in ("data", "scaled") or any(diag.speed.get(k) for k in ("runs_off", "runs_doubtful",
                                                                                           "runs_speed")):
        from .speed_whirl import speed_lines

        # how the speed was obtained was said when the sweep was read; the whirl's test (and any warning) follows;
        # a steady test's speed column scaled, or a run of it corrected, by its 1x lines is said here in full
        lines = speed_lines(diag.speed)
        for line in lines if diag.speed["source"] != "data" else lines[1:]:
            print(f"  {line}")
    from .effects_text import diagnose_lines

    print("\n".join(diagnose_lines(summary["effects"])) or "  no effect added (none passed the held-out test)")
    _print_base_lines(summary["base_lines"])
    missing = summary["lines_missing_from_given_model"]
    if diag.model_given and diag.state_after.base != diag.state_before.base:
        print(f"  note: {args.model or args.preset} has no suspension modes the data could be read through (none, or "
              "assumed ones): its harmonics were replaced by those fitted with the wheel's modes from the data"
              + ("; lines of the data it lacks:" if missing else "; it lacks none of the data's lines"))
        for e in missing:
            part = f" ({e['sense']}-rotating part)" if e.get("sense") in ("co", "counter") else ""
            print(f"  - {e['direction']} h = {e['h']:g}{part}, C = {e['C']:.3g}")
    for h in diag.hypotheses:
        if getattr(h, "forced_by", None):
            print(f"  - {h.effect.kind} taken back: the search fitted it to the {h.forced_by} described below")
        elif getattr(h, "taken_back", None):
            print(f"  - {h.effect.kind} (iteration {h.iteration}) taken back: {h.taken_back}")
    for u in diag.unexplained:
        print(f"  ? {u.text()}")
    same: dict = {}                 # one console line for the directions whose line at one h has the same causes
    for lc in diag.line_causes:
        same.setdefault((f"{lc['h']:.4g}", tuple(lc["causes"])), []).append(lc["direction"])
    for (h_text, causes), directions in same.items():
        more = f" (+{len(causes) - 1} more in report.md)" if len(causes) > 1 else ""
        print(f"  ~ {', '.join(directions)} h = {h_text}: could be {causes[0]}{more}")
    print(f"unexplained fraction of the data's power (speed x frequency): {diag.error_before:.4g} -> "
          f"{diag.error_after:.4g} (definition: report.md)")
    print(f"band-by-band misfit, every band alike (narrow lines count as on the waterfall): "
          f"{diag.contrast_error_before:.4g} -> {diag.contrast_error_after:.4g}")
    if any(u.signature not in ("partial_line", "run_change") for u in diag.unexplained):
        print("  (the content described above with ? is in no model: it counts in both figures)")
    print(f"report: {args.output} ({len(files)} files; improved model: {Path(args.output) / 'model.json'})")
    return 0


# --------------------------------------------------------------------------- psd

def _speed_range_flag(text: str) -> tuple:
    """(MIN, MAX) rpm of ``--speed-rpm MIN:MAX`` (the range itself is checked by :func:`rwadist.psd`)."""
    if not text:
        raise DataError("--speed-rpm", "value", "missing MIN:MAX (rpm)")
    try:
        lo_rpm, hi_rpm = (float(x) for x in text.split(":"))
    except ValueError:
        raise DataError("--speed-rpm", "value", f"{text!r}: expected MIN:MAX in rpm") from None
    return lo_rpm, hi_rpm


def _psd_kind(res, args) -> str:
    """What the PSD rests on, for the console and the plot; notes where assumed modes ran hard-mounted."""
    source = res.meta["source"]
    if source and source["modes_assumed"] and source["hard_mounted"] and not args.empirical:
        print(f"note: {args.model or args.preset}: suspension modes are assumed (datasheet wheel); running it "
              "hard-mounted (Melody's model of its lines); --assumed-modes uses the assumed modes")
    if res.meta["hard_mounted_wheels"]:
        print(f"note: {args.wheels}: wheels {', '.join(res.meta['hard_mounted_wheels'])} have assumed suspension modes "
              "(datasheet wheels); running them hard-mounted (Melody's model of their lines); --assumed-modes uses "
              "the assumed modes")
    kind = "empirical (Melody)" if res.meta["model"] == "empirical" else "extended (modal amplification)"
    return kind + (" on ASSUMED modes" if res.meta["on_assumed_modes"] else "")


#: the files ``rwadist psd -o X.csv`` writes beside X.csv, named X + each of these
PSD_COMPANIONS = ("_cross.csv", "_cross.h5", "_envelope.csv", "_envelope_harmonics.csv", ".png", "_ASSUMED_MODES.txt")


def _write_psd(res, out: Path, args, title: str) -> tuple:
    """The PSD's files, swapped in as ONE set (a kill never leaves a new table beside old cross-spectra): the table
    (CSV or NASTRAN), the cross-spectra, the line envelope and its worst amplitude per line, the plot and, on assumed
    modes, the note; an older companion this run does not write is removed with the set.  Returns (envelope, its
    table per line, png)."""
    from . import psd_files
    from .nastran import left_out_text

    stem = out.with_suffix("")
    sibling = {s: stem.parent / (stem.name + s) for s in PSD_COMPANIONS}
    cross_path = {"csv": sibling["_cross.csv"], "h5": sibling["_cross.h5"]}
    with output_set() as outs:
        note = sibling["_ASSUMED_MODES.txt"]
        if res.meta["on_assumed_modes"]:
            from .catalogue import write_assumed_note

            write_assumed_note(note, res.meta["on_assumed_modes"], [out, sibling["_cross.csv"], sibling["_envelope.csv"],
                               sibling["_envelope_harmonics.csv"], sibling[".png"]], with_flags, write_to=outs.file(note))
        else:
            outs.remove(note)
        if args.format == "nastran":
            auto_only = args.nastran_auto_only
            tables = api.write_nastran(res, outs.file(out), fields=args.nastran_fields, cross=not auto_only)
            wrote = (f"wrote NASTRAN deck {out} ({len(tables)} TABRND1 tables, {args.nastran_fields} field, "
                     + ("AUTO-SPECTRA ONLY: " + left_out_text(res) if auto_only else
                        "auto- and cross-spectra: the full 6x6") + ")")
        else:
            psd_files.write_psd_csv(res, outs.file(out))
            wrote = f"wrote PSD table {out}"
        for fmt, path in cross_path.items():        # one cross-spectra file, or none: an older one is removed
            if args.cross != fmt:
                outs.remove(path)
        if args.cross == "csv":
            psd_files.write_cross_csv(res, outs.file(cross_path["csv"]))
        elif args.cross == "h5":
            psd_files.write_hdf5(res, outs.file(cross_path["h5"]), "csd")
        psd_files.write_envelope_csv(res.meta["envelope"], outs.file(sibling["_envelope.csv"]))
        psd_files.write_envelope_harmonics_csv(res.meta["envelope"], outs.file(sibling["_envelope_harmonics.csv"]),
                                               psd_files.wheel_names(res))
        with working("drawing the PSD plot"):
            import_matplotlib_for_command()
            save_png(psd_files.plot_psd(res, title), outs.file(sibling[".png"]), dpi=110)
    print(wrote)
    if args.cross in cross_path:
        print(f"cross-spectra: {cross_path[args.cross]}" + (" (group /csd)" if args.cross == "h5" else ""))
    return sibling["_envelope.csv"], sibling["_envelope_harmonics.csv"], sibling[".png"]


def cmd_psd(args) -> int:
    """Broadband PSD over a speed distribution (Melody's model, or the extended model with the modal
    amplification inside the speed integral); one wheel or a wheels.json set in the spacecraft frame
    (:func:`rwadist.psd`)."""
    if args.preset and args.model:
        raise DataError("psd", "model/--preset", "give a model file or --preset, not both")
    args.output = args.output or ("psd.bdf" if args.format == "nastran" else "psd.csv")
    check_psd_flags(args)
    lo_rpm, hi_rpm = _speed_range_flag(args.speed_rpm)
    out = check_output_file(args.output)
    refuse_special_base(out, "-o", "its companions (_envelope.csv, _envelope_harmonics.csv, .png)")
    stem = out.with_suffix("")
    written = [out] + [stem.parent / (stem.name + s) for s in PSD_COMPANIONS]
    refuse_input_overwrite([("-o", p, "file") for p in written],
                           [args.model, args.wheels, args.dist if Path(args.dist).suffix else None])
    t0 = time.perf_counter()
    res = api.psd(args.model, (lo_rpm, hi_rpm), preset=args.preset, wheels=args.wheels, dist=args.dist,
                  std_rpm=args.std_rpm, empirical=args.empirical, assumed_modes=args.assumed_modes, fmax=args.fmax,
                  n_freq=args.n_freq, n_speeds=args.n_speeds, envelope=True, progress=True)
    kind = _psd_kind(res, args)
    p_env, p_lines, png = _write_psd(res, out, args, psd_title(kind, res))
    rms = res.rms()
    print(f"{kind}, {res.frame} frame, {res.f.size} frequencies to {res.meta['fmax_hz']:g} Hz, "
          f"{time.perf_counter() - t0:.1f} s")
    print("RMS: " + ", ".join(f"{c} {v:.4g} {'N' if c[0] == 'F' else 'N·m'}"
                              for c, v in zip(("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"), rms)))
    print(f"worst-case line envelope: {p_env}; its worst amplitude per line: {p_lines}; plots: {png}")
    return 0


# --------------------------------------------------------------------------- main

def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command (:mod:`rwadist.cli_parser`)."""
    from .cli_parser import build_parser as _build

    return _build(sys.modules[__name__])


#: API parameters given on the command line under another name than ``--`` + the name with ``-`` for ``_``
PARAMETER_FLAGS = {"n_samples": "--samples", "exclude_modes": "--no-mode-exclusion", "model": "MODEL",
                   "data": "DATA", "path": "-o", "fields": "--nastran-fields", "cross": "--nastran-cross",
                   "start_rpm": "--sweep-start-rpm", "end_rpm": "--sweep-end-rpm", "modes": "--no-modes",
                   "test_stand": "--no-test-stand", "tach": "--no-tach"}


#: per command, API parameters given by a positional argument there (``catalogue show NAME``)
COMMAND_FLAGS = {"catalogue show": {"preset": "NAME"}}


def flag_of(parameter: str, command: str = "") -> str:
    """The command-line flag that gives the API's ``parameter`` (``speed_rpm`` -> ``--speed-rpm``) in ``command``."""
    named = COMMAND_FLAGS.get(command, {}).get(parameter) or PARAMETER_FLAGS.get(parameter)
    return named or "--" + parameter.replace("_", "-")


def with_flags(text: str, command: str = "") -> str:
    """A library message with the parameters it names in backquotes (```radius```) named by their flags."""
    import re

    return re.sub(r"`([a-z][a-z0-9_]*)`", lambda m: flag_of(m.group(1), command), text)


def user_message(exc: RwadistError, command: str = "") -> str:
    """The one-line message of a library error as the command line says it: a :class:`ParameterError` names the
    flag of its parameter (``--presence: value: 2.0: ...``) and of those it mentions, every other error its file and
    field as raised."""
    if isinstance(exc, ParameterError) and exc.parameter is not None:
        return f"{flag_of(exc.parameter, command)}: value: {with_flags(exc.problem, command)}"
    return with_flags(str(exc), command)


def _command_name(args) -> str:
    """'fit', 'fmu build', ... of parsed ``args``, for messages."""
    words = [args.command]
    for sub in ("model_command", "catalogue_command", "fmu_command"):
        if getattr(args, sub, None):
            words.append(getattr(args, sub))
    return " ".join(words)


def _write_crash_log(command: str) -> Path | None:
    """Write the current exception's traceback to a file in the temp folder; its path (None if impossible)."""
    import tempfile
    import traceback

    try:
        fd, name = tempfile.mkstemp(prefix="rwadist-crash-", suffix=".txt")
        with os.fdopen(fd, "w") as fh:
            fh.write(f"rwadist {_version()} {command}: {' '.join(sys.argv)}\n")
            traceback.print_exc(file=fh)
        return Path(name)
    except OSError:
        return None


@contextmanager
def _library_warnings():
    """The library's warnings (:class:`rwadist.RwadistWarning`) each printed once as one line on stderr, with the
    parameters they name given by their flags, not in Python's warning format: ``WARNING: --speed-rpm 0:10000 rpm
    reaches ...``; a model file's unread keys (:class:`rwadist.model.ModelKeyWarning`) as ``rwadist: warning: ...``."""
    from .errors import RwadistWarning
    from .model import ModelKeyWarning

    seen: set = set()
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, RwadistWarning):
            shown(message, category, filename, lineno, file, line)
            return
        parameter = getattr(message, "parameter", None)
        text = with_flags(message.text if parameter else str(message))
        text = (f"rwadist: warning: {text}" if issubclass(category, ModelKeyWarning) else
                f"WARNING: {flag_of(parameter) + ' ' if parameter else ''}{text}")
        if text not in seen:
            seen.add(text)
            from tqdm import tqdm

            tqdm.write(text, file=sys.stderr)       # on its own line, below a running progress line

    with warnings.catch_warnings():
        warnings.simplefilter("always", RwadistWarning)
        warnings.showwarning = show
        yield


def main(argv=None) -> int:
    """Run one command; every failure ends in a one-line message: exit 2 for bad input, 130 on Ctrl-C (at any
    moment: :func:`rwadist.outputs.exit_on_interrupt`), 3 for an internal error (its traceback goes to a file named in
    the message, never to the user)."""
    state = {"command": ""}
    with exit_on_interrupt(lambda: state["command"]):
        return _run(argv, state)


def _run(argv, state: dict) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except KeyboardInterrupt:       # raised, not signalled (the handler ends the process itself)
        print(interrupt_message(""), file=sys.stderr)
        return 130
    command = state["command"] = _command_name(args)
    try:
        check_parsed(parser, args)
        with one_blas_thread(), _library_warnings():
            return args.func(args)
    except KeyboardInterrupt:
        print(interrupt_message(command), file=sys.stderr)
        return 130
    except RwadistError as exc:     # bad input, said by the library: a parameter is named by its flag here
        print(f"rwadist: error: {user_message(exc, command)}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"rwadist {command}: error: not enough memory for these settings; reduce the sizes given "
              "(--n-freq, --n-speeds, --samples, --duration)", file=sys.stderr)
        return 2
    except BrokenPipeError:     # the reader of our output went away (`| head`): nothing more to say
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:
        where = exc.filename if exc.filename is not None else ""
        why = exc.strerror or str(exc)
        if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            why += "; nothing written (the old outputs are kept): free some space or write elsewhere"
        print(f"rwadist {command}: error: {where}{': ' if where else ''}{why}", file=sys.stderr)
        return 2
    except Exception as exc:    # last resort: no traceback reaches the user
        log = _write_crash_log(command)
        print(f"rwadist {command}: internal error ({type(exc).__name__}: {str(exc)[:200]}); "
              f"{'full traceback in ' + str(log) if log else 'no traceback file could be written'}; "
              "please report it", file=sys.stderr)
        return 3


if __name__ == "__main__":
    sys.exit(main())
