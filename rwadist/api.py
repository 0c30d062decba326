"""The Python way in: read data, fit, diagnose, PSD, Campbell, simulate (re-exported by :mod:`rwadist`).

Every default lives here; the ``rwadist`` command line (:mod:`rwadist.cli`) calls these functions and
only parses flags and prints.  SI units inside, rpm at this edge (parameters named ``*_rpm``), as the
CLI.  The heavy modules (scipy, matplotlib) are imported inside the functions, so ``import rwadist``
stays light.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .data import DataError, SteadyTest, Sweep
from .formats.records import reading_provenance
from .model import WheelModel
from .model import load as load_model
from .model import save as save_model

__all__ = ["read", "simulate_test", "fit", "fit_extended", "diagnose", "psd", "campbell", "WheelModel",
           "load_model", "save_model"]

#: Default FFT length rule of :func:`diagnose`: a power of 2 at most a quarter of the median run length, so
#: every PSD averages several Welch segments (the residual needs noise statistics).
DIAGNOSE_SEGMENTS = 4


def _as_model(model, what: str) -> WheelModel:
    """A WheelModel from a WheelModel or a model-file path."""
    if isinstance(model, WheelModel):
        return model
    if isinstance(model, (str, Path)):
        return load_model(model)
    raise DataError(what, "model", f"expected a WheelModel or a model-file path, got {type(model).__name__}")


def _preset_model(name: str) -> WheelModel:
    from .presets import preset

    try:
        return preset(name).to_model()
    except (KeyError, ValueError) as exc:
        raise DataError("--preset", "name", str(exc)) from None


def read(path, *, slice_samples: int = 8192, speed_source: str = "auto", progress: bool = False,
         log=None) -> SteadyTest:
    """Read test data as a steady test: a run directory, a sweep CSV (cut into quasi-steady slices) or HDF5.

    Parameters
    ----------
    path : str or pathlib.Path
        A steady-test directory (``runs.csv`` + one CSV per run), a sweep CSV, or a ``.h5`` file.
    slice_samples : int
        Samples per quasi-steady slice of a sweep (default 8192).
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
    """
    from . import data as data_io

    obj = data_io.read_data(path, progress=progress)
    if isinstance(obj, Sweep):
        from .sweep import slice_sweep

        test, _ = slice_sweep(obj, slice_samples=slice_samples, speed_source=speed_source)
        if log is not None:
            log(f"sliced sweep into {len(test.runs)} quasi-steady runs (speed from {speed_source})")
        return test
    names = obj.meta.get("unlisted_files")
    if names and log is not None:
        log(f"note: {len(names)} file(s) in {path} not listed in runs.csv, not read: {', '.join(names[:5])}"
            + (" ..." if len(names) > 5 else ""))
    return obj


def _as_test(data, **read_options) -> SteadyTest:
    return data if isinstance(data, SteadyTest) else read(data, **read_options)


def simulate_test(preset: str = "ithaco-e", speeds_rpm=None, *, sample_rate: float | None = None,
                  n_samples: int = 8192, noise: float = 0.01, modes: bool = True, test_stand: bool = True,
                  seed: int = 0, physics: str = "simple", inject=()) -> SteadyTest:
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
        Samples per run.
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

    Returns
    -------
    SteadyTest
        Forces (N) and torques (N·m) per run; ``meta["f_lim_hz"]`` (Hz) set when the stand resonates.
    """
    from .presets import preset as get_preset
    from .teststand import simulate_steady

    wheel = get_preset(preset)
    if speeds_rpm is None:
        default = getattr(wheel, "default_speeds_rpm", None)
        speeds_rpm = np.linspace(300.0, 2400.0, 120) if default is None else np.asarray(default, float)
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
    return test


def _f_lim(test: SteadyTest, f_lim):
    """The upper limit of good data, Hz: the one given, else the test's record (meta ``f_lim_hz``)."""
    return test.meta.get("f_lim_hz") if f_lim is None else f_lim


def fit(data, *, f_lim: float | None = None, nperseg: int | None = None, presence: float = 0.25,
        epsilon: float = 0.02, exclude_modes: bool = True, name: str | None = None, progress: bool = False):
    """Fit the empirical model (harmonics C·Ω², thesis ch. 3) to steady test data.

    Parameters
    ----------
    data : SteadyTest, str or pathlib.Path
        The test, or a path :func:`read` takes.
    f_lim : float or None
        Upper limit of good data, Hz (a test-stand resonance above it); default the test's record.
    nperseg : int or None
        FFT length, samples; default the largest power of 2 in a run.
    presence : float
        Bin presence threshold P0, a fraction (0..1).
    epsilon : float
        Binning tolerance on the harmonic number h, dimensionless.
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
    """
    from .empirical import FitSettings, fit_empirical
    from .spectra import compute_spectra

    test = _as_test(data)
    if name is None:
        name = Path(data).name if isinstance(data, (str, Path)) else "fitted wheel"
    spectra = compute_spectra(test, nperseg=nperseg, f_lim=_f_lim(test, f_lim))
    settings = FitSettings(presence_min=presence, epsilon=epsilon, exclude_modes=exclude_modes)
    result = fit_empirical(spectra, settings, name=name, progress=progress)
    result.model.provenance.update(reading_provenance(getattr(test, "meta", None)))
    return result


def fit_extended(data, empirical=None, *, mass: float | None = None, radius: float | None = None,
                 height: float = 0.0, preset: str | None = None, progress: bool = False):
    """Fit the extended model (suspension modes, damping, imbalances) on top of the empirical fit.

    Parameters
    ----------
    data : SteadyTest, str or pathlib.Path
        The test, or a path :func:`read` takes.
    empirical : rwadist.empirical.EmpiricalFit or None
        Its empirical fit; default :func:`fit` of ``data`` with default settings.
    mass : float or None
        Rotor mass, kg; default the preset's.  Without mass or radius the fit is per unit mass and
        inertia (the interface loads depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr and I_zz/I_rr).
    radius : float or None
        Rotor radius, m (thin-disc inertias); default the preset's.
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
    """
    from .extended_fit import to_model
    from .stand_resonance import declare_coupled_modes, fit_extended_beside_stand

    test = _as_test(data)
    if empirical is None:
        empirical = fit(test)
    start = None
    if preset:
        from .presets import preset as get_preset

        wheel = get_preset(preset)
        mass = mass if mass is not None else wheel.mass_kg
        radius = radius if radius is not None else wheel.radius_m
        start = getattr(wheel, "extended", None)
    for flag, value in (("--mass", mass), ("--radius", radius)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise DataError(flag, "value", f"{value!r}: must be a positive number (kg / m)")
    if mass is None or radius is None:
        # per unit mass and inertia: the interface loads depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr, I_zz/I_rr
        mass = radius = None
    # a fixture resonance lifting every channel is fitted beside the wheel's modes, never into them
    efit = fit_extended_beside_stand(test, empirical, mass=mass, radius=radius, height=height, start=start,
                                     progress=progress)
    declare_coupled_modes(efit)          # a mode the stand dragged along, not told apart from it: said
    return efit, to_model(efit, empirical)


def diagnose_nperseg(test: SteadyTest) -> int:
    """Default FFT length of :func:`diagnose`, samples: the largest power of 2 at most 1/4 of the median run."""
    n = int(np.median([r.n_samples for r in test.runs]))
    return int(2 ** np.floor(np.log2(max(n // DIAGNOSE_SEGMENTS, 16))))


def diagnose(data, model=None, *, preset: str | None = None, base: str = "auto", nperseg: int | None = None,
             f_lim: float | None = None, k_sigma: float = 4.0, min_gain: float = 0.05):
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
        on from them (:func:`rwadist.diagnose.search.fits_modes_from_data`).
    nperseg : int or None
        FFT length, samples; default :func:`diagnose_nperseg`.
    f_lim : float or None
        Upper limit of good data, Hz; default the test's record.
    k_sigma : float
        Held-out gain needed, in noise standard errors.
    min_gain : float
        Held-out gain needed, fraction of the unexplained power (0..1).

    Returns
    -------
    rwadist.diagnose.Diagnosis
        ``.model`` the improved :class:`WheelModel` (effects added), ``.summary()`` the metric before and
        after and every hypothesis; :func:`rwadist.diagnose.write_report` writes it out.
    """
    from .diagnose import diagnose as _diagnose
    from .spectra import compute_spectra

    if preset and model is not None:
        raise DataError("diagnose", "--model/--preset", "give a model file or --preset, not both")
    test = _as_test(data)
    if model is not None:
        model = _as_model(model, "diagnose")
    elif preset:
        model = _preset_model(preset)
        from .catalogue import source_modes_assumed

        if model.analytical and source_modes_assumed(None, preset):
            # a datasheet wheel of the catalogue: its modes are assumed, which resolve_base reads from the model
            model.analytical = {**dict(model.analytical), "modes_assumed": True}
    spectra = compute_spectra(test, nperseg=nperseg or diagnose_nperseg(test), f_lim=_f_lim(test, f_lim))
    diagnosis = _diagnose(spectra, model, k_sigma=k_sigma, min_gain=min_gain, test=test, base=base)
    reading = reading_provenance(getattr(test, "meta", None))
    if reading:
        diagnosis.model.provenance = dict(diagnosis.model.provenance, diagnose=dict(
            diagnosis.model.provenance.get("diagnose", {}), **reading))
    return diagnosis


def wheel_lines(model=None, *, preset: str | None = None, empirical: bool = False):
    """The disturbance sources of one wheel for :func:`psd`: from a model (file) or a preset.

    Returns a :class:`rwadist.broadband.WheelLines` (harmonic numbers h, coefficients C in SI per (rad/s)²,
    load directions); ``empirical``: Melody's hard-mounted lines, else the extended model's.
    """
    from . import broadband as bb

    if preset and model is not None:
        raise DataError("psd", "model/--preset", "give a model file or --preset, not both")
    if preset:
        try:
            return bb.preset_lines(preset, empirical)
        except ValueError as exc:
            raise DataError("--preset", "name", str(exc)) from None
    if model is None:
        raise DataError("psd", "model", "give a model file or --preset NAME")
    source = str(model) if isinstance(model, (str, Path)) else getattr(model, "name", "<model>")
    m = _as_model(model, "psd")
    return bb.empirical_lines(m) if empirical else bb.extended_lines_from_model(m, source)


def default_fmax(pairs) -> float:
    """Default top frequency of :func:`psd`, Hz: 1.2 × the highest line frequency over the speed laws.

    ``pairs`` : [(WheelLines, speed law)], the law's support in rad/s."""
    top = max(float(lines.h.max()) * max(abs(law.support[0]), abs(law.support[1])) for lines, law in pairs)
    return 1.2 * top / (2 * np.pi)


def psd(model=None, speed_rpm=(0.0, 3000.0), *, preset: str | None = None, dist: str = "uniform",
        std_rpm: float | None = None, empirical: bool = False, fmax: float | None = None, n_freq: int = 20001,
        n_speeds: int = 2000, progress: bool = False):
    """Broadband disturbance PSD of one wheel over a wheel-speed distribution (wheel frame).

    Parameters
    ----------
    model : WheelModel, str, pathlib.Path or None
        The wheel's model (or model file); or give ``preset``.
    speed_rpm : (float, float)
        MIN, MAX speed, rpm (negative = spinning about −z).
    preset : str or None
        Wheel preset instead of a model.
    dist : str
        "uniform", "normal" (centred, truncated to the range) or a CSV file (histogram, density or time
        profile of the speed).
    std_rpm : float or None
        Standard deviation of the normal law, rpm; default range/6.
    empirical : bool
        Melody's model from the harmonics alone (hard mounted), else the extended model (modal amplification
        inside the speed integral).
    fmax : float or None
        Top frequency, Hz; default :func:`default_fmax`.
    n_freq : int
        Frequency points from 0 to ``fmax``.
    n_speeds : int
        Speed cells of the law.
    progress : bool
        Print progress.

    Returns
    -------
    rwadist.broadband.BroadbandPSD
        ``.f`` frequencies (n_freq,), Hz; ``.psd`` auto-spectra (n_freq, 6) in N²/Hz and (N·m)²/Hz of
        Fx, Fy, Fz, Tx, Ty, Tz; ``.rms()`` (6,) in N and N·m.
    """
    from . import broadband as bb

    lo_rpm, hi_rpm = (float(x) for x in speed_rpm)
    law = bb.law_from_spec(dist, lo_rpm, hi_rpm, std_rpm)
    lines = wheel_lines(model, preset=preset, empirical=empirical)
    if fmax is None:
        fmax = default_fmax([(lines, law)])
    return bb.broadband_psd(lines, law, fmax, n_freq, n_speeds, progress=progress)


def extended_source(model=None, *, preset: str | None = None) -> tuple:
    """(ExtendedParams, lines, description) of a model (file) with an analytical section, or of a preset."""
    from . import extended

    if preset:
        from .presets import preset as get_preset

        wheel = get_preset(preset)
        if wheel.extended is None:
            raise DataError(preset, "extended", "this preset has no extended (analytical) parameters")
        return wheel.extended, wheel.extended_lines(), f"preset {wheel.name}"
    if model is None:
        raise DataError("campbell", "model", "give a model file or --preset NAME")
    source = str(model) if isinstance(model, (str, Path)) else getattr(model, "name", "<model>")
    m = _as_model(model, "campbell")
    params = extended.params_from_model(m, source)
    return params, extended.lines_from_model(m, params), source


def campbell(model=None, speeds_rpm=None, *, preset: str | None = None) -> tuple:
    """Campbell diagram of the extended model: mode frequencies against speed, and the crossings.

    Parameters
    ----------
    model : WheelModel, str, pathlib.Path or None
        Model (file) with an analytical section; or give ``preset``.
    speeds_rpm : array_like of float, shape (n,), or None
        Wheel speeds, rpm; default 0 to 3000 rpm in steps of 100.
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
    """
    from .campbell import campbell_crossings, campbell_table

    params, lines, _ = extended_source(model, preset=preset)
    speeds = np.arange(0.0, 3000.0 + 50.0, 100.0) if speeds_rpm is None else np.asarray(speeds_rpm, float)
    return campbell_table(params, speeds), campbell_crossings(params, speeds, lines)
