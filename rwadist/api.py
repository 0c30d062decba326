"""The Python way in: read data, fit, diagnose, PSD, Campbell, simulate (re-exported by :mod:`rwadist`).

Every default and every check lives here (the ranges in :data:`rwadist.validate.LIMITS`), and the rules that
decide what a request means -- a datasheet wheel's assumed suspension modes run hard-mounted unless asked
for (:mod:`rwadist.wheel_source`), diagnose's starting base (:func:`rwadist.diagnose.resolve_base`); the
``rwadist`` command line (:mod:`rwadist.cli`) calls these functions and only parses flags and prints, so the
same request gives the same numbers both ways.  A refused value is a :class:`rwadist.ParameterError` naming
the parameter; warnings are :class:`rwadist.RwadistWarning`.  SI units inside, rpm at this edge (parameters
named ``*_rpm``), as the CLI.  The heavy modules (scipy, matplotlib) are imported inside the functions, so
``import rwadist`` stays light.
"""
from __future__ import annotations

import functools
import json
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from . import model as model_io
from .api_psd import psd, write_nastran
from .data import SteadyTest, Sweep
from .errors import DataError, MissingDependencyError, ModelError, ParameterError, RwadistWarning, own_models
from .formats.records import reading_provenance
from .model import WheelModel
from .model import load as _load
from .threads import in_one_blas_thread
from .units import RAD_S_TO_RPM
from .validate import (
    MAX_SAMPLES,
    check_f_lim,
    check_flags,
    check_object,
    check_parameter,
    check_path,
    check_run_lengths,
    check_speeds_rpm,
    check_test_speeds,
    refuse_non_finite_model,
    speed_scale_warning,
    warn_unconstrained,
)

__all__ = ["read", "simulate_test", "simulate_sweep", "fit", "fit_extended", "diagnose", "psd", "write_nastran",
           "campbell", "build_fmu", "WheelModel", "load_model", "save_model"]

def load_model(path) -> WheelModel:
    """The model file (JSON) at ``path``, parsed and validated once; a :class:`rwadist.model.ModelKeyWarning` per
    key or effect kind of the file this version does not read.  :class:`ParameterError` for a ``path`` that is not
    a path; :class:`DataError` / :class:`ModelError` naming the file and field."""
    check_path("path", path, "a model file (JSON)")
    return _load(path)


def save_model(model: WheelModel, path) -> Path:
    """Write ``model`` as a model file (JSON) at ``path``, atomically (a kill leaves the old file or the new one).
    Refused (:class:`DataError` naming ``path``, nothing written): a folder, a path in a folder that cannot be
    written, a path ending in a data format's extension (``.csv``, ``.h5``: a model file is JSON), an existing file
    rwadist did not write (a measurement, someone's notes: never replaced; a model file or an output rwadist wrote
    is); a model :func:`load_model` would refuse (:class:`ModelFileError`)."""
    from .outputs import check_model_file, write_file

    check_object("model", model, WheelModel, "rwadist.fit's .model, or load_model")
    check_path("path", path, "the model file (JSON) to write")
    check_model_file(path, "path")
    doc = model_io.to_json(model)
    model_io.from_json(doc, str(path))        # refused naming the user's path, before anything is written
    text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
    return write_file(path, lambda tmp: Path(tmp).write_text(text), "path")


#: Default FFT length rule of :func:`diagnose`: a power of 2 at most a quarter of the median run length, so
#: every PSD averages several Welch segments (the residual needs noise statistics).
DIAGNOSE_SEGMENTS = 4
#: A sweep whose slices' speeds span less than this fraction is named as one steady run read as a sweep.
STEADY_FILE_SPREAD = 0.02
#: What :func:`read` may take each sweep slice's speed from.
SPEED_SOURCES = ("auto", "tach", "data")
#: Physics of the virtual test stand (:func:`simulate_test`, :func:`simulate_sweep`).
PHYSICS = ("simple", "extended")


def _choice(parameter: str, value, allowed: tuple):
    if value not in allowed:
        raise ParameterError(parameter, f"{value!r}: must be one of {', '.join(map(repr, allowed))}")
    return value


def _as_model(model) -> WheelModel:
    """A WheelModel from a WheelModel or a model-file path."""
    if isinstance(model, WheelModel):       # valid everywhere or nowhere: a model built in code as a file's
        return model_io.validate(model, f"<model {getattr(model, 'name', '')!r}>")
    if isinstance(model, (str, Path)):
        return load_model(model)
    raise ParameterError("model", f"a {type(model).__name__}: expected a WheelModel or a model-file path")


def _model_name(model) -> str:
    return str(model) if isinstance(model, (str, Path)) else getattr(model, "name", "<model>")


def _preset_model(name: str) -> WheelModel:
    """The model of preset ``name`` (a catalogue datasheet wheel's carries ``analytical.modes_assumed``)."""
    from .presets import preset

    return preset(name).to_model()


def read(path, *, slice_samples: int | None = None, speed_source: str = "auto", progress: bool = False,
         log=None) -> SteadyTest:
    """Read test data as a steady test: a run directory, a sweep CSV (cut into quasi-steady slices) or HDF5.

    Parameters
    ----------
    path : str or pathlib.Path
        A steady-test directory (``runs.csv`` + one CSV per run), a sweep CSV, or a ``.h5`` file.
    slice_samples : int or None
        Samples per quasi-steady slice of a sweep; None (default): the longest power of two up to 8192 over
        which the speed changes by at most 5 % (:func:`rwadist.sweep.slice_sweep`).
    speed_source : {"auto", "tach", "data"}
        Speed of each sweep slice: the tach column, estimated from the data, or the tach when present.
    progress : bool
        Print reading progress.
    log : callable or None
        Called with one line of text for each note (slicing done, files not listed); None: silent.

    Returns
    -------
    SteadyTest
        Runs of load-cell signals (N, N·m) at their speeds (rad/s, signed) and sample rates (Hz).

    Raises
    ------
    DataError
        A file that cannot be read as test data (naming the file and the field).
    ParameterError
        ``slice_samples`` or ``speed_source`` out of range.
    """
    from . import data as data_io

    check_path("path", path, "test data (a run folder, a sweep CSV or a .h5 file)")
    check_flags(progress=progress)
    check_parameter("slice_samples", slice_samples)
    _choice("speed_source", speed_source, SPEED_SOURCES)
    obj = data_io.read_data(path, progress=progress)
    if isinstance(obj, Sweep):
        from .sweep import slice_sweep, speed_note

        test, _ = slice_sweep(obj, slice_samples=slice_samples, speed_source=speed_source)
        if log is not None:
            log(speed_note(test.meta["slicing"]))
            rpm = np.abs(np.asarray(test.speeds, dtype=float)) * RAD_S_TO_RPM
            if rpm.size >= 2 and rpm.min() > 0 and rpm.max() / rpm.min() - 1.0 < STEADY_FILE_SPREAD:
                # one steady run's file read as a sweep (new-user trial 29): fitted, but not what was meant
                log(f"note: the speed hardly changes over {path} ({rpm.min():.6g}-{rpm.max():.6g} rpm): one steady "
                    "run? Its slices are fitted as runs at one speed; a steady test is a folder of runs with their "
                    "speeds in runs.csv (docs/formats.md)")
        return test
    names = obj.meta.get("unlisted_files")
    if names and log is not None:
        log(f"note: {len(names)} file(s) in {path} not listed in runs.csv, not read: {', '.join(names[:5])}"
            + (" ..." if len(names) > 5 else ""))
    return obj


def _as_test(data, **read_options) -> SteadyTest:
    if isinstance(data, SteadyTest):
        return data
    if isinstance(data, WheelModel):
        raise ParameterError("data", "a WheelModel: the test data go first (a SteadyTest from read or simulate_test, "
                             "or a data path); a model is passed as model")
    check_path("data", data, "test data (a run folder, a sweep CSV or a .h5 file), or a SteadyTest")
    return read(data, **read_options)


def _stand_wheel(preset: str, physics: str, assumed_modes: bool) -> tuple:
    """(WheelDescription, assumed-modes note or None) of a preset simulated with ``physics``: a catalogue wheel
    whose suspension modes are assumed runs hard-mounted (simple physics, its default) unless ``assumed_modes``
    asks to simulate through them (the note then goes into the data's meta and a warning)."""
    from . import catalogue
    from .presets import preset as get_preset

    _choice("physics", physics, PHYSICS)
    wheel = get_preset(preset)
    m = catalogue.preset_model(preset)
    if physics != "extended" or m is None or not catalogue.modes_assumed(m):
        return wheel, None
    if not assumed_modes:
        raise ParameterError("physics", f"'extended': {preset}: its suspension modes are assumed (datasheet wheel), "
                             "not measured; it runs hard-mounted by default (`physics` 'simple'), or give "
                             "`assumed_modes` to simulate through the assumed modes")
    note = catalogue.ASSUMED_MODES_NOTE.format(name=preset)
    warnings.warn(RwadistWarning(note), stacklevel=3)
    return wheel, note


@in_one_blas_thread
def simulate_test(preset: str = "ithaco-e", speeds_rpm=None, *, sample_rate: float | None = None,
                  n_samples: int = 8192, noise: float = 0.01, modes: bool = True, test_stand: bool = True,
                  seed: int = 0, physics: str = "simple", inject=(), assumed_modes: bool = False) -> SteadyTest:
    """Steady runs of a preset wheel on the virtual test stand.

    Parameters
    ----------
    preset : str
        Wheel preset, e.g. ``"ithaco-e"``, ``"ithaco-b"`` (:func:`rwadist.presets.names`).
    speeds_rpm : array_like of float, shape (n_runs,), or None
        Wheel speeds, rpm (signed: negative spins about −z), one run each.  Default: the preset's
        reference test, else 120 speeds from 300 to 2400 rpm.
    sample_rate : float or None
        Hz; default the preset's reference test (3840 Hz).
    n_samples : int
        Samples per run (64 or more; at most 5e7 samples over all runs).
    noise : float
        Sensor noise standard deviation as a fraction of the top-speed fundamental amplitude.
    modes, test_stand : bool
        Switch the wheel's structural modes / the test stand's resonances on or off.
    seed : int
        Random seed (phases, noise).
    physics : {"simple", "extended"}
        Simple resonances, or the preset's extended rotor model.
    inject : sequence of str or dict
        Known effects to add, ``"KIND:PARAM=VALUE,..."`` or parsed dicts (:mod:`rwadist.inject`);
        recorded in ``meta["injected"]``.
    assumed_modes : bool
        Allow ``physics="extended"`` on a catalogue wheel whose suspension modes are assumed (datasheet);
        the data's ``meta["modes_assumed"]`` then says so.  Without it such a wheel is refused with
        extended physics: it runs hard-mounted, as its datasheet states.

    Returns
    -------
    SteadyTest
        Forces (N) and torques (N·m) per run; ``meta["f_lim_hz"]`` (Hz) set when the stand resonates.

    Raises
    ------
    ParameterError
        A value out of range (naming it), an unknown preset, extended physics on assumed modes.
    """
    from .teststand import simulate_steady

    check_flags(modes=modes, test_stand=test_stand, assumed_modes=assumed_modes)
    for name, value in (("sample_rate", sample_rate), ("n_samples", n_samples), ("noise", noise), ("seed", seed)):
        check_parameter(name, value)
    wheel, assumed_note = _stand_wheel(preset, physics, assumed_modes)
    if speeds_rpm is None:
        default = getattr(wheel, "default_speeds_rpm", None)
        speeds_rpm = np.linspace(300.0, 2400.0, 120) if default is None else np.asarray(default, float)
    speeds_rpm = check_speeds_rpm(speeds_rpm, "speeds_rpm")
    if speeds_rpm.size * n_samples > MAX_SAMPLES:
        raise ParameterError("n_samples", f"{n_samples} samples x {speeds_rpm.size} runs: at most {MAX_SAMPLES:.3g} "
                             "samples in all; use fewer speeds or samples")
    fs = sample_rate or getattr(wheel, "default_sample_rate", None) or 3840.0
    if inject:
        from .inject import parse, simulate_with_injections

        specs = [parse(x) if isinstance(x, str) else dict(x) for x in inject]
        test = simulate_with_injections(wheel, specs, speeds_rpm, physics=physics, seed=seed, sample_rate=fs,
                                        n_samples=n_samples, noise=noise, modes=modes, test_stand=test_stand)
    else:
        test = simulate_steady(wheel, speeds_rpm, sample_rate=fs, n_samples=n_samples, noise=noise,
                               modes=modes, test_stand=test_stand, seed=seed, physics=physics)
    if wheel.f_lim_hz is not None and test_stand:
        # the test engineer's record of where the fixture corrupts the data; `fit` uses it
        test.meta["f_lim_hz"] = wheel.f_lim_hz
    if assumed_note:
        test.meta["modes_assumed"] = assumed_note
    return test


@in_one_blas_thread
def simulate_sweep(preset: str = "ithaco-e", start_rpm: float = 0.0, end_rpm: float = 2400.0, *,
                   duration: float = 390.0, sample_rate: float | None = None, noise: float = 0.01,
                   modes: bool = True, test_stand: bool = True, seed: int = 0, profile: str = "linear",
                   tach: bool = True, physics: str = "simple", assumed_modes: bool = False) -> Sweep:
    """One record of a preset wheel through a speed change (spin-up or run-down) on the virtual test stand.

    Parameters
    ----------
    preset : str
        Wheel preset (:func:`rwadist.presets.names`).
    start_rpm, end_rpm : float
        Speeds at the start and the end of the record, rpm (signed; different).
    duration : float
        Record length, s (64 samples or more, at most 5e7).
    sample_rate : float or None
        Hz; default 3840 Hz.
    noise, modes, test_stand, seed, physics, assumed_modes
        As :func:`simulate_test`.
    profile : {"linear", "exp"}
        Speed against time.
    tach : bool
        Record the speed (the ``speed_rpm`` tach column).

    Returns
    -------
    Sweep
        Time (s), forces (N) and torques (N·m), the tach (rad/s) when recorded.
    """
    from .teststand import simulate_sweep as stand_sweep

    check_flags(modes=modes, test_stand=test_stand, tach=tach, assumed_modes=assumed_modes)
    for name, value in (("sample_rate", sample_rate), ("noise", noise), ("seed", seed)):
        check_parameter(name, value)
    _choice("profile", profile, ("linear", "exp"))
    check_speeds_rpm([start_rpm, end_rpm], "end_rpm")
    if end_rpm == start_rpm:
        raise ParameterError("end_rpm", f"{end_rpm:g}: equals `start_rpm`; a sweep needs two different speeds")
    fs = sample_rate or 3840.0
    n = duration * fs if np.isfinite(duration) and duration > 0 else -1.0
    if not 64 <= n <= MAX_SAMPLES:
        raise ParameterError("duration", f"{duration:g} s at {fs:g} Hz is {max(n, 0):.3g} samples: a sweep needs 64 to "
                             f"{MAX_SAMPLES:.3g}; {'lengthen' if n < 64 else 'shorten'} `duration`")
    wheel, assumed_note = _stand_wheel(preset, physics, assumed_modes)
    sweep = stand_sweep(wheel, rpm_start=start_rpm, rpm_end=end_rpm, duration=duration, sample_rate=fs, noise=noise,
                        modes=modes, test_stand=test_stand, seed=seed, profile=profile, tach=tach, physics=physics)
    if assumed_note:
        sweep.meta["modes_assumed"] = assumed_note
    return sweep


def _f_lim(test: SteadyTest, f_lim):
    """The upper limit of good data, Hz: the one given (checked below the data's Nyquist frequency), else the
    test's record (meta ``f_lim_hz``)."""
    check_f_lim(test, f_lim)
    return test.meta.get("f_lim_hz") if f_lim is None else f_lim


@in_one_blas_thread
def fit(data, *, f_lim: float | None = None, nperseg: int | None = None, presence: float = 0.25,
        epsilon: float = 0.02, exclude_modes: bool = True, name: str | None = None, progress: bool = False):
    """Fit the empirical model (harmonics C·Ω², thesis ch. 3) to steady test data.

    Parameters
    ----------
    data : SteadyTest, str or pathlib.Path
        The test, or a path :func:`read` takes.
    f_lim : float or None
        Upper limit of good data, Hz (a test-stand resonance above it; at most the Nyquist frequency);
        default the test's record.
    nperseg : int or None
        FFT length, samples (62 to 2**24: the noise floor takes medians of blocks of 32 frequency bins); default
        the largest power of 2 in a run.
    presence : float
        Bin presence threshold P0, a fraction in (0, 1].
    epsilon : float
        Binning tolerance on the harmonic number h, dimensionless, in (0, 0.5].
    exclude_modes : bool
        Leave modally amplified speeds out of each harmonic's C.
    name : str or None
        Name written into the model; default the data's path name.
    progress : bool
        Print progress.

    Returns
    -------
    rwadist.empirical.EmpiricalFit
        ``.model`` is the :class:`WheelModel` (C in kg·m for forces, kg·m² for torques, per (rad/s)²:
        amplitude C·Ω² in N or N·m); ``.spectra`` the Welch PSDs it was fitted on.

    Raises
    ------
    ParameterError
        A value out of range, naming the parameter (``presence=2.0``, ``f_lim`` above the Nyquist frequency).
    DataError
        Data that cannot be read or fitted; a fit that diverged (a non-finite C).

    Warns
    -----
    RwadistWarning
        The strongest radial line sits where speeds given k times the wheel's would put the imbalance; a sweep's
        speed from the data whose 1x line tied with another (the scale unsure: ``rwadist diagnose`` tests it); a
        radial channel reads its partner's lines by a unit factor (:func:`rwadist.fit_warnings.unit_mixup_warning`:
        one of them in lbf, kgf, in·lbf, ...); no harmonic passed the presence threshold (the model is empty).
    """
    from . import channel_distortion, chirp, data_quality, fit_warnings, speed_whirl
    from .empirical import FitSettings, fit_empirical
    from .line_senses import with_senses
    from .spectra import _default_nperseg, compute_spectra

    check_flags(exclude_modes=exclude_modes, progress=progress)
    for parameter, value in (("f_lim", f_lim), ("nperseg", nperseg), ("presence", presence), ("epsilon", epsilon)):
        check_parameter(parameter, value)
    test = _as_test(data)
    if name is None:
        name = Path(data).name if isinstance(data, (str, Path)) else "fitted wheel"
    # a channel that froze in a run (a DAQ or amplifier dropout) is marked invalid in that run (Run.invalid): its
    # spectra are left out (docs/diagnose.md, "Data quality": what still reads its samples)
    test, frozen = data_quality.screen(test)
    if frozen:
        warnings.warn(RwadistWarning("; ".join(data_quality.quality_lines([s.to_json() for s in frozen]))),
                      stacklevel=2)
    test, distorted = channel_distortion.corrected(test)     # a radial channel's distortion undone (as diagnose)
    for rec in distorted:
        warnings.warn(RwadistWarning(channel_distortion.summary_line(rec, "the fit")), stacklevel=2)
    check_run_lengths(test, nperseg or _default_nperseg(int(np.median([r.n_samples for r in test.runs]))))
    spectra = compute_spectra(test, nperseg=nperseg, f_lim=_f_lim(test, f_lim))
    settings = FitSettings(presence_min=presence, epsilon=epsilon, exclude_modes=exclude_modes)
    # a sweep's slices, read in one segment each: every line's amplitudes corrected for its chirp (as the extended fit)
    result = chirp.unsmeared_fit(test, fit_empirical(spectra, settings, name=name, progress=progress))
    result.model = with_senses(result, test, ("co", "counter"))      # not 'planar' (the FMU's load along x)
    refuse_non_finite_model(result.model, "fit")
    result.model.provenance.update(reading_provenance(getattr(test, "meta", None)))
    if frozen or distorted:
        result.model.provenance["data_quality"] = [s.to_json() for s in frozen] + distorted
    result.model.provenance.update(model_io.stamp(data if isinstance(data, (str, Path)) else test))
    if text := speed_scale_warning(result, test.meta):
        warnings.warn(RwadistWarning(text.removeprefix("WARNING: ")), stacklevel=2)
    # a sweep's 1x line a tie; a channel in another unit; a radial pair missing a channel; lines not measured apart
    for said in ([RwadistWarning(t) for t in (speed_whirl.fit_tie_warning(test),) if t]
                 + fit_warnings.model_warnings(spectra, result, test)):
        warnings.warn(said, stacklevel=2)
    if not any(result.model.empirical.values()):
        warnings.warn(RwadistWarning(fit_warnings.empty_model_advice(test, settings, presence)), stacklevel=2)
    return result


def extended_options(mass: float | None = None, radius: float | None = None, height: float = 0.0,
                     preset: str | None = None) -> tuple:
    """(mass kg, radius m, starting ExtendedParams or None) of an extended fit: those given, the rest the preset's.

    Both None: the fit is per unit mass and inertia.  :class:`ParameterError` for a value out of range, or one of
    mass and radius without the other (the rotor's inertias come from both)."""
    for parameter, value in (("mass", mass), ("radius", radius), ("height", height)):
        check_parameter(parameter, value)
    start = None
    if preset:
        from .presets import preset as get_preset

        wheel = get_preset(preset)
        mass = mass if mass is not None else wheel.mass_kg
        radius = radius if radius is not None else wheel.radius_m
        start = getattr(wheel, "extended", None)
    if (mass is None) != (radius is None):
        given, missing = ("mass", "radius") if radius is None else ("radius", "mass")
        raise ParameterError(given, f"needs `{missing}` too (the rotor's inertias come from both; with neither the fit "
                             "is per unit mass and inertia)")
    return mass, radius, start


@in_one_blas_thread
def fit_extended(data, empirical=None, *, mass: float | None = None, radius: float | None = None,
                 height: float = 0.0, preset: str | None = None, progress: bool = False):
    """Fit the extended model (suspension modes, damping, imbalances) on top of the empirical fit.

    Parameters
    ----------
    data : SteadyTest, str or pathlib.Path
        The test, or a path :func:`read` takes (a sweep's speed from the data: warns when the whirl contradicts it).
    empirical : rwadist.empirical.EmpiricalFit or None
        Its empirical fit; default :func:`fit` of ``data`` with default settings.
    mass : float or None
        Rotor mass, kg; default the preset's.  Without mass and radius: per unit mass and inertia (the loads
        depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr and I_zz/I_rr).
    radius : float or None
        Rotor radius, m (thin-disc inertias); default the preset's.  Give both or neither.
    height : float
        Lever arm from the rotor centre to the torque reference point, m.
    preset : str or None
        Wheel preset giving mass, radius and the starting values of modes the data do not show.
    progress : bool
        Print progress.

    Returns
    -------
    efit : rwadist.extended_fit.ExtendedFit
        Fitted parameters (stiffness N/m and N·m/rad, damping ratios, imbalances kg·m and kg·m²).
    model : WheelModel
        The model file's content: the empirical harmonics as forcing lines plus the analytical section.

    Raises
    ------
    ParameterError
        mass, radius or height out of range, or one of mass and radius without the other.
    """
    from . import speed_whirl
    from .extended_fit import to_model
    from .stand_axes import axis_stand, fit_beside
    from .stand_resonance import fit_extended_beside_stand

    check_flags(progress=progress)
    mass, radius, start = extended_options(mass, radius, height, preset)
    test = _as_test(data)
    if empirical is None:
        empirical = fit(test)
    # a fixture lifting every channel is fitted with the wheel's modes, never into them (a mode not told apart from it is
    # declared by the joint fit's standard errors); one lifting one channel of each radial pair: rwadist.stand_axes
    options = dict(mass=mass, radius=radius, height=height, start=start, progress=progress)
    axis = axis_stand(empirical)
    efit = None if axis is None else fit_beside(test, empirical, axis, **options)
    if efit is None:
        efit = fit_extended_beside_stand(test, empirical, **options)
    model = to_model(efit, empirical)
    refuse_non_finite_model(model, "fit")
    model.provenance.update(model_io.stamp(data if isinstance(data, (str, Path)) else test))
    speed_whirl.warn_whirl_against_scale(test, efit)
    return efit, model


def diagnose_nperseg(test: SteadyTest) -> int:
    """Default FFT length of :func:`diagnose`, samples: the largest power of 2 at most 1/4 of the median run, at
    least 64 (the smallest power of 2 the ``nperseg`` limit allows, :data:`rwadist.validate.LIMITS`)."""
    n = int(np.median([r.n_samples for r in test.runs]))
    return int(2 ** np.floor(np.log2(max(n // DIAGNOSE_SEGMENTS, 64))))


def _diagnose_model(model, preset: str | None, base: str):
    """The starting model of :func:`diagnose` (None: the data's empirical fit) and the base it asks for, checked."""
    from .diagnose import BASES

    _choice("base", base, BASES)
    if preset and model is not None:
        raise ParameterError("preset", f"{preset!r} given beside a model: give a model or a preset, not both")
    if model is not None:
        name, model = _model_name(model), _as_model(model)
        warn_unconstrained(model, name, "diagnose's extended base")
    elif preset:
        model = _preset_model(preset)
    if base == "extended" and not getattr(model, "analytical", None):
        raise ParameterError("base", "'extended' needs a model with the wheel's suspension modes (an analytical "
                             "section, as the extended fit writes), or a `preset`; or leave `base` at 'auto'")
    return model


def _one_x_checks(test) -> tuple:
    """(test, speed check record, polarity record or None) of :func:`diagnose`'s steps before the search, each read
    from the imbalance's 1x lines (the lines of one test read once: :class:`rwadist.speed_check.LineReads`)."""
    from . import channel_polarity, order_tracking, speed_check, speed_runs

    # a steady test's speed column checked against its 1x lines, scaled when they all sit at one ratio
    test, checked = speed_check.checked(test, reads := speed_check.LineReads(), confirm=speed_runs.confirmed_off)
    # a radial pair whose 1x line reads mirrored against the other pair's: one channel's sign flipped back; both
    # pairs mirrored: every speed negated (before the runs' own speeds: those read the 1x lines' senses)
    test, polarity = channel_polarity.checked(test, reads)
    if polarity is not None:
        warnings.warn(RwadistWarning(channel_polarity.polarity_lines(polarity)[0]), stacklevel=3)
    # each run's own mean speed from its 1x lines, taken where it is off the column beyond its own uncertainty
    test, checked = speed_runs.own_speeds(test, checked, reads)
    # a speed that wanders within the runs: each run resampled at equal steps of the rotor's angle (order tracking)
    test, checked = order_tracking.tracked(test, checked, reads)
    return test, checked, polarity


@in_one_blas_thread
def diagnose(data, model=None, *, preset: str | None = None, base: str = "auto", nperseg: int | None = None,
             f_lim: float | None = None, k_sigma: float = 4.0, min_gain: float = 0.05, bearings=None,
             source=None):
    """Find what a model leaves out of test data, name the effects, add those that pass a held-out test.

    Parameters
    ----------
    data : SteadyTest, str or pathlib.Path
        The test, or a path :func:`read` takes.
    model : WheelModel, str, pathlib.Path or None
        Model to start from; default the empirical fit of the data.
    preset : str or None
        Start from a preset's model instead (not with ``model``).
    base : {"auto", "empirical", "extended"}
        Line prediction: C·Ω² hard mounted, or through the suspension modes of the model's analytical
        section; "auto" (:func:`rwadist.diagnose.resolve_base`, the one rule of the library and the CLI):
        extended when the model has an analytical section whose modes are not assumed (a catalogue
        datasheet wheel's are) and the data's record does not say the wheel's modes were off; otherwise
        empirical, and the search may name the wheel's ``suspension_modes`` fitted from the data and carry
        on from them (:func:`rwadist.diagnose.bases.fits_modes_from_data`).
    nperseg : int or None
        FFT length, samples; default :func:`diagnose_nperseg`.
    f_lim : float or None
        Upper limit of good data, Hz; default the test's record.
    k_sigma : float
        Held-out gain needed, in noise standard errors, in (0, 100].
    min_gain : float
        Held-out gain needed, fraction of the unexplained power, in (0, 1).
    bearings : sequence or None
        The wheel's bearings (:class:`rwadist.bearings.Bearing`, or their descriptions as the model file's
        ``wheel.bearings`` objects or ``--bearing`` texts): their cage, ball-pass and ball-spin ratios are named as
        candidate causes of lines; None: those of the model's ``wheel`` section, if any.
    source : str, pathlib.Path or None
        What the data's errors and warnings name when ``data`` is a test read from a file (its path); default
        ``data`` itself when a path, else "the test".

    Returns
    -------
    rwadist.diagnose.Diagnosis
        ``.model`` the improved :class:`WheelModel` (effects added), ``.summary()`` the metric before and
        after and every hypothesis; :func:`rwadist.diagnose.write_report` writes it out.

    Raises
    ------
    ParameterError
        A value out of range; a model and a preset; base "extended" without the wheel's modes.
    DataError
        Runs at fewer than 2 distinct speeds (:func:`rwadist.validate.check_test_speeds`).
    """
    from . import channel_distortion, channel_timing, data_quality, speed_whirl
    from .diagnose import diagnose as _diagnose
    from .spectra import compute_spectra

    for parameter, value in (("nperseg", nperseg), ("f_lim", f_lim), ("k_sigma", k_sigma), ("min_gain", min_gain)):
        check_parameter(parameter, value)
    model = _diagnose_model(model, preset, base)
    if bearings is not None:
        from .bearings import Bearing, parse_bearing

        bearings = tuple(b if isinstance(b, Bearing) else parse_bearing(b, "diagnose", f"bearings[{i}]")
                         for i, b in enumerate(bearings))
    test = _as_test(data)
    # a channel that froze in a run (a DAQ or amplifier dropout) is marked invalid in that run (Run.invalid): its
    # spectra are left out (docs/diagnose.md, "Data quality": what still reads its samples)
    test, frozen = data_quality.screen(test)
    if frozen:
        warnings.warn(RwadistWarning(data_quality.summary_line([s.to_json() for s in frozen])), stacklevel=2)
    # a radial channel whose signal chain distorts (lines of its own at sums and differences of its lines, which its
    # partner lacks) is put right before the search (docs/diagnose.md, "Data quality")
    test, distorted = channel_distortion.corrected(test)
    for rec in distorted:
        warnings.warn(RwadistWarning(channel_distortion.summary_line(rec, "the diagnosis")), stacklevel=2)
    # too few speeds to fit and judge on: refused (one), or warned of (fewer than the data's own fit needs)
    check_test_speeds(test, source or (data if isinstance(data, (str, Path)) else "the test"),
                      model_given=model is not None or preset is not None)
    check_f_lim(test, f_lim)            # before the search starts, not after it
    test, checked, polarity = _one_x_checks(test)
    check_run_lengths(test, nperseg or diagnose_nperseg(test))

    def run(test, base_check):
        spectra = compute_spectra(test, nperseg=nperseg or diagnose_nperseg(test), f_lim=_f_lim(test, f_lim))
        with own_models("the diagnosis"):       # a model given was checked above
            return _diagnose(spectra, model, k_sigma=k_sigma, min_gain=min_gain, test=test, base=base,
                             bearings=bearings, base_check=base_check)

    # a speed from the data is tested by the wheel's gyroscopic whirl (the data diagnosed again on the scale it
    # supports, kept: not judged again); a radial channel recorded late (read on the records at the model's lines)
    # moved back and the data diagnosed again; how the speed was obtained, and what was put right, are reported
    test, diagnosis, late = channel_timing.in_time(speed_whirl.settle(test, run), lambda t: (t, run(t, None)))
    for rec in late:
        warnings.warn(RwadistWarning(channel_timing.summary_line(rec)), stacklevel=2)
    diagnosis.speed = speed_whirl.speed_record(getattr(test, "meta", None), checked)
    put_right = distorted + late + ([polarity] if polarity is not None else [])
    diagnosis.data_quality = [s.to_json() for s in frozen] + put_right
    return _with_provenance(diagnosis, test, put_right, data)


def _with_provenance(diagnosis, test, put_right: list, data):
    """``diagnosis`` with its model's provenance: the data quality records of what was put right before the model was
    fitted (``put_right``), how the data were read and the data's stamp."""
    if put_right:     # the model was fitted to the data with those channels put right
        diagnosis.model.provenance = dict(diagnosis.model.provenance, data_quality=put_right)
    reading = reading_provenance(getattr(test, "meta", None))
    if reading:
        diagnosis.model.provenance = dict(diagnosis.model.provenance, diagnose=dict(
            diagnosis.model.provenance.get("diagnose", {}), **reading))
    diagnosis.model.provenance = dict(diagnosis.model.provenance,
                                      **model_io.stamp(data if isinstance(data, (str, Path)) else test))
    return diagnosis


def extended_source(model=None, *, preset: str | None = None, needed_for: str | None = None) -> tuple:
    """(ExtendedParams, lines, description) of a model (file) with an analytical section, or of a preset;
    ``needed_for``: what asks for them, said when the model has none (:func:`rwadist.extended.params_from_dict`)."""
    from . import extended

    if preset and model is not None:
        raise ParameterError("preset", f"{preset!r} given beside a model: give a model or a preset, not both")
    if preset:
        from .presets import preset as get_preset

        wheel = get_preset(preset)
        if wheel.extended is None:
            raise DataError(preset, "extended", "this preset has no extended (analytical) parameters")
        return wheel.extended, wheel.extended_lines(), f"preset {wheel.name}"
    if model is None:
        raise ParameterError("model", "missing: give a model (a WheelModel or a model-file path) or a preset")
    source = _model_name(model)
    m = _as_model(model)
    params = extended.params_from_model(m, source, needed_for)
    return params, extended.lines_from_model(m, params), source


@in_one_blas_thread
def campbell(model=None, speeds_rpm=None, *, preset: str | None = None) -> tuple:
    """Campbell diagram of the extended model: mode frequencies against speed, and the crossings.

    Parameters
    ----------
    model : WheelModel, str, pathlib.Path or None
        Model (file) with an analytical section; or give ``preset``.
    speeds_rpm : array_like of float, shape (n,), or None
        Wheel speeds, rpm, spanning a range of |speed|; default 0 to 3000 rpm in steps of 100.
    preset : str or None
        Wheel preset instead of a model.

    Returns
    -------
    table : dict
        ``speed_rpm`` (n,) and one column (n,) per mode in Hz: radial_translation_Hz, rocking_forward_Hz,
        rocking_backward_Hz, axial_translation_Hz.
    crossings : list of dict
        Each harmonic/mode crossing: ``h``, ``direction``, ``sense``, ``mode``, ``speed_rpm``, ``f_Hz``,
        ``excited``, sorted by speed.

    Raises
    ------
    ParameterError
        Speeds that are not a range of finite speeds within ±1e5 rpm; a model and a preset, or neither.
    DataError
        A model without an analytical section, or whose modes come out non-finite.
    """
    from .campbell import campbell_crossings, campbell_table

    params, lines, source = extended_source(model, preset=preset, needed_for="the Campbell diagram")
    if model is not None:
        warn_unconstrained(_as_model(model), source, "the Campbell diagram")
    speeds = np.arange(0.0, 3000.0 + 50.0, 100.0) if speeds_rpm is None else check_speeds_rpm(speeds_rpm,
                                                                                                 "speeds_rpm")
    if np.ptp(np.abs(speeds)) == 0:
        raise ParameterError("speeds_rpm", f"gives one speed ({float(speeds[0]):g} rpm); a Campbell diagram needs "
                             "a range, e.g. 0 to 3000 rpm in steps of 100")
    table = campbell_table(params, speeds)
    bad = [k for k, v in table.items() if not np.all(np.isfinite(np.asarray(v, dtype=float)))]
    if bad:
        raise DataError(source, "campbell", f"non-finite frequencies in {', '.join(bad)}: the model's analytical "
                        "parameters are out of range; check them (`rwadist model show`)")
    return table, campbell_crossings(params, speeds, lines)


def build_fmu(model=None, path="wheel.fmu", *, preset: str | None = None, native: bool = False,
              fmi_version: int = 2, assumed_modes: bool = False, progress: bool = False) -> Path:
    """Build the FMI 2.0 co-simulation FMU of a wheel model, written atomically to ``path``.

    Parameters
    ----------
    model : WheelModel, str, pathlib.Path or None
        The model (file): empirical, extended or diagnosed; or give ``preset`` (default ``"ithaco-e"``).
    path : str or pathlib.Path
        The ``.fmu`` file to write.
    preset : str or None
        Wheel preset instead of a model: its catalogue entry, else its virtual-stand model.
    native : bool
        A pure-C FMU (no Python on the host; sources included) instead of pythonfmu's.
    fmi_version : {2, 3}
        FMI 2.0, or FMI 3.0 (the native FMU only).
    assumed_modes : bool
        A wheel with assumed (datasheet) suspension modes runs them by default (the FMU's ``modes`` start
        value); without it such a wheel is hard-mounted by default.
    progress : bool
        An elapsed-time line on stderr while the FMU is built.

    Returns
    -------
    pathlib.Path
        The FMU written.

    Raises
    ------
    ParameterError
        A path not ending in .fmu; a model and a preset; FMI 3.0 without ``native``.
    ModelError
        A model the FMU cannot run (naming the file and field, or the model).
    MissingDependencyError
        pythonfmu (the ``fmu`` extra) not installed.
    """
    from . import catalogue
    from .outputs import write_file
    from .presets import preset as get_preset
    from .progress import working

    check_flags(native=native, assumed_modes=assumed_modes, progress=progress)
    if Path(path).suffix != ".fmu":
        raise ParameterError("path", f"{str(path)!r} must end in .fmu")
    if preset and model is not None:
        raise ParameterError("preset", f"{preset!r} given beside a model: give a model or a preset, not both")
    _choice("fmi_version", fmi_version, (2, 3))
    if fmi_version != 2 and not native:
        raise ParameterError("fmi_version", f"{fmi_version}: the pythonfmu FMU is FMI 2.0 only; add `native` for the "
                             "FMI 3.0 FMU")
    if model is not None:
        source, name = (model if isinstance(model, (str, Path)) else _as_model(model)), _model_name(model)
        warn_unconstrained(_as_model(model), name, "the FMU")
    else:
        name = preset or "ithaco-e"
        source = catalogue.preset_model(name) or get_preset(name).to_model()
    build: Callable[..., Path]      # (model, output, assumed_modes=) -> the FMU written
    if native:
        from rwadist.fmu.native_build import build_native_fmu

        build = functools.partial(build_native_fmu, fmi_version=fmi_version)
    else:
        import importlib.util

        if importlib.util.find_spec("pythonfmu") is None:
            raise MissingDependencyError("pythonfmu", "building an FMU", "fmu")
        from rwadist.fmu.build import build_fmu as build
    try:
        with working("compiling the native FMU" if native else "packaging the FMU", enabled=progress):
            return write_file(path, lambda tmp: build(source, tmp, assumed_modes=assumed_modes))
    except ModelError as exc:
        if exc.field is not None:       # a bad model-file field: the schema's message names file and field
            raise
        raise DataError(name, "model", str(exc)) from None
