"""`rwadist fmu build` and `rwadist fmu check`: the FMU of a model file or preset, packaged (pythonfmu) or native
(C), and its check by an independent host (fmpy: validation and a spin-up), kept out of cli.py."""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from .cli_parser import check_fmu_ramp
from .errors import DataError, MissingDependencyError, ModelError
from .outputs import check_output_file, refuse_input_overwrite, write_file
from .progress import working
from .units import rpm_to_rad_s


def _windows_note() -> str:
    """'' where the native FMU gets its win64 binary, else the note saying how to get one."""
    from rwadist.fmu.native_build import MINGW_HINT, windows_compiler
    return "" if windows_compiler() else f"no Windows binary (mingw-w64 not found): {MINGW_HINT}"


def _build_assembly(args, out: Path) -> int:
    """rwadist fmu build --native --wheels wheels.json -o assembly.ssp"""
    import warnings

    from rwadist.fmu.ssp import build_assembly_ssp
    if out.suffix != ".ssp":
        raise DataError("-o", "value", f"{str(out)!r} must end in .ssp with --wheels (an SSP 1.0 file)")
    if not getattr(args, "native", False):
        raise DataError("--wheels", "value", "the assembly SSP holds native FMUs: add --native")
    if args.fmi_version != 2:
        raise DataError("--fmi-version", "value", "the assembly SSP holds FMI 2.0 FMUs (libcosim, the SSP host, runs "
                        "FMI 2.0): leave --fmi-version at 2")
    refuse_input_overwrite([("-o", out, "file")], [args.wheels, args.model])
    default = args.model or (None if args.preset is None else _preset_source(args.preset))
    with working("rwadist fmu build: compiling one native FMU per wheel model"), warnings.catch_warnings():
        warnings.filterwarnings("ignore", "no Windows binary", RuntimeWarning)    # noted below, once
        notes: list = []
        path = write_file(out, lambda tmp: notes.extend(build_assembly_ssp(
            args.wheels, tmp, name=out.stem, default_model=default, assumed_modes=args.assumed_modes)[1]))
    for note in notes:
        print(f"rwadist: note: {note}")
    if note := _windows_note():
        print(f"rwadist: note: {note}")
    print(f"wrote {path} (SSP 1.0 of the wheels in {args.wheels}: one native FMU component per wheel, driven by the "
          "speed_command component's inputs, rad/s; each wheel's Fx_sc .. Tz_sc are its loads at the spacecraft "
          "reference point, the assembly's are their sum)")
    return 0


def _preset_source(name: str):
    from . import catalogue
    from .presets import preset
    return catalogue.preset_model(name) or preset(name).to_model()


def cmd_fmu_build(args) -> int:
    """The FMU of a model file or preset (:func:`rwadist.build_fmu`), or the SSP of a wheels set."""
    import warnings

    from . import api

    out = check_output_file(args.output)
    if getattr(args, "wheels", None):
        try:
            return _build_assembly(args, out)
        except ModelError as exc:
            if exc.field is not None:
                raise
            raise DataError(args.wheels, "model", str(exc)) from None
    if out.suffix != ".fmu":
        raise DataError("-o", "value", f"{str(out)!r} must end in .fmu")
    fmi_version = getattr(args, "fmi_version", 2)
    refuse_input_overwrite([("-o", out, "file")], [args.model])
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "no Windows binary", RuntimeWarning)    # noted below
        path = api.build_fmu(args.model, out, preset=args.preset, native=getattr(args, "native", False),
                             fmi_version=fmi_version, assumed_modes=args.assumed_modes, progress=True)
    what = f"model {'file ' + args.model if args.model else 'preset ' + (args.preset or 'ithaco-e')}"
    if getattr(args, "native", False):
        from rwadist.fmu.native_build import binary_platforms

        if note := _windows_note():
            print(f"rwadist: note: {note}")
        print(f"wrote {path} ({what}; native FMU, FMI {fmi_version}.0: C only, no Python needed by the host; "
              f"binaries: {', '.join(binary_platforms(path))})")
    else:
        from rwadist.fmu.build import has_native

        print(f"wrote {path} ({what}; native layer: "
              f"{'yes' if has_native(path) else 'no, numpy steps and fmi2Discard on bad input'})")
    return 0


def _check_fmu_archive(path) -> None:
    """Refuse a file that is not a complete FMU archive (a zip holding modelDescription.xml)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as z:
            names = set(z.namelist())
            broken = z.testzip()
    except (zipfile.BadZipFile, OSError, EOFError, ValueError) as exc:
        raise DataError(path, "FMU", f"not an FMU archive (a zip file): {exc}; give the .fmu written by "
                        "`rwadist fmu build`") from None
    if "modelDescription.xml" not in names:
        raise DataError(path, "FMU", "the archive has no modelDescription.xml: not an FMU")
    if broken is not None:
        raise DataError(path, "FMU", f"damaged archive (member {broken!r} fails its checksum); rebuild it")


def cmd_fmu_check(args) -> int:
    try:
        from fmpy import simulate_fmu
        from fmpy.validation import validate_fmu
    except ImportError:
        raise MissingDependencyError("fmpy", "checking an FMU", "fmu") from None
    if not Path(args.fmu).is_file():
        raise DataError(args.fmu, "file", "does not exist")
    _check_fmu_archive(args.fmu)
    if not 1 <= (n_steps := args.stop_time / args.step_size) <= 1e7:
        raise DataError("--step-size", "value", f"{args.step_size:g} s over --stop-time {args.stop_time:g} s makes "
                        f"{n_steps:.3g} steps: allowed 1 to 1e7 steps")
    try:
        problems = validate_fmu(args.fmu)
        # the ramp ends at the last whole step (as simulated below), not at --stop-time
        check_fmu_ramp(args.fmu, args.speed_rpm, round(args.stop_time / args.step_size) * args.step_size)
    except DataError:
        raise
    except Exception as exc:    # fmpy raises assorted errors on a damaged archive or XML
        raise DataError(args.fmu, "FMU", f"cannot be read by fmpy ({type(exc).__name__}: {str(exc)[:160]}); "
                        "rebuild it with `rwadist fmu build`") from None
    for prob in problems:
        print(f"validation: {prob}")
    print(f"fmpy validation: {len(problems)} problem(s)")
    try:
        import zipfile

        from rwadist.fmu.build import has_native
        from rwadist.fmu.native_build import C_SOURCES
        if any(n.endswith(tuple(C_SOURCES.values())) for n in zipfile.ZipFile(args.fmu).namelist()):
            print("native FMU: C only, no Python needed by the host")
        else:
            print(f"native layer (fmi2Error on bad input, C step kernel): {'yes' if has_native(args.fmu) else 'no'}")
    except Exception:   # informational only; validation above already judged the file
        pass
    w_end = float(rpm_to_rad_s(args.speed_rpm))
    n = int(round(args.stop_time / args.step_size))
    t = np.linspace(0.0, n * args.step_size, n + 1)
    # every input gets its signal (fmpy warns of a missing one): the speed ramp and its slope
    sig = np.zeros(t.size, dtype=[("time", float), ("wheel_speed", float), ("wheel_acceleration", float)])
    sig["time"], sig["wheel_speed"], sig["wheel_acceleration"] = t, w_end * t / t[-1], w_end / t[-1]
    errors = []

    def fmu_log(*args):     # FMI 2.0: (component, instance, status, category, message); FMI 3.0: (env, status, ...)
        status, message = args[-3], args[-1]
        if status >= 3:       # fmi2Error and worse: the FMU says why it refused
            errors.append(message.decode(errors="replace") if isinstance(message, bytes) else str(message))

    t0 = time.perf_counter()
    try:
        res = simulate_fmu(args.fmu, stop_time=float(t[-1]), step_size=args.step_size, input=sig,
                           output_interval=args.step_size, logger=fmu_log, debug_logging=True)
    except Exception as exc:   # fmpy raises FMICallException on a refused step; the FMU logged why
        why = f"; the FMU says: {errors[-1]}" if errors else ""
        print(f"rwadist: error: FMU check failed: the simulation stopped: {exc}{why}", file=sys.stderr)
        return 1
    wall = time.perf_counter() - t0
    if len(res) < t.size:
        print(f"rwadist: error: FMU check failed: the simulation stopped after {len(res)} of {t.size} samples",
              file=sys.stderr)
        return 1
    names = [c for c in res.dtype.names if c != "time"]
    finite = all(np.all(np.isfinite(res[c])) for c in names)
    print(f"simulated 0 -> {args.speed_rpm:g} rpm over {t[-1]:g} s at {args.step_size:g} s steps in {wall:.2f} s "
          f"wall ({len(res)} samples)")
    print("\n".join(f"  {c:<6} max |.| = {np.max(np.abs(res[c])):.4g}" for c in names))
    if problems or not finite:
        print("rwadist: error: FMU check failed" + ("" if finite else " (non-finite outputs)"), file=sys.stderr)
        return 1
    return 0
