"""The broadband PSD of the Python API (:func:`rwadist.psd`): one wheel in its own frame, or several wheels in the
spacecraft frame, and the NASTRAN cards of either (:func:`rwadist.write_nastran`).

Every default and check of ``rwadist psd`` is decided here: the speed range and law, the assumed-modes rule of
each wheel (:mod:`rwadist.wheel_source`), the default top frequency, the refusal of a non-finite result, the
warnings (speeds beyond the wheel's rating, modes the data did not constrain).  The command line calls
:func:`psd` and writes what it returns.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .errors import ParameterError
from .threads import in_one_blas_thread
from .validate import (
    check_flags,
    check_object,
    check_parameter,
    check_path,
    check_speed_range,
    refuse_non_finite_psd,
    warn_beyond_rated_speed,
    warn_unconstrained,
)


def default_fmax(pairs) -> float:
    """Default top frequency of :func:`psd`, Hz: 1.2 × the highest line frequency over the speed laws.

    ``pairs`` : [(WheelLines, speed law)], the law's support in rad/s.  :class:`ParameterError` (``fmax``) when
    there is no line to place the band by."""
    try:
        top = max(float(lines.h.max()) * max(abs(law.support[0]), abs(law.support[1])) for lines, law in pairs)
    except ValueError:          # no line at all
        raise ParameterError("fmax", "no default: the wheels have no harmonic lines to place the band by (check "
                             "the model's harmonics)") from None
    return 1.2 * top / (2 * math.pi)


def _one_wheel(source, law, fmax, n_freq: int, n_speeds: int, progress: bool):
    """The wheel-frame PSD of one :class:`rwadist.wheel_source.WheelSource` and its line sources."""
    from .broadband import broadband_psd

    if fmax is None:
        if not len(source.lines):
            raise ParameterError("model", f"{source.name}: no harmonic lines: nothing to compute a PSD of")
        fmax = default_fmax([(source.lines, law)])
    res = broadband_psd(source.lines, law, fmax, n_freq, n_speeds, progress=progress)
    return res, [(source.lines, None)], law.support


def _wheel_set(wheels, default, law, empirical: bool, assumed_modes: bool, fmax, n_freq: int, n_speeds: int,
               progress: bool):
    """The spacecraft-frame CSD of a set of wheels (:func:`rwadist.mounting.load_wheels`; ``meta`` names those whose
    assumed modes were run hard-mounted or used), its line sources and each wheel's speed support (rad/s)."""
    from .mounting import load_wheels, spacecraft_csd
    from .speed_laws import law_text

    ws = load_wheels(wheels, (lambda: default.lines) if default is not None else None, law, empirical,
                     assumed_modes=assumed_modes)
    if fmax is None:
        fmax = default_fmax([(w.lines, w.law or ws[w.tie.to].law) for w in ws])
    res = spacecraft_csd(ws, fmax, n_freq, n_speeds, progress=progress)
    res.meta["hard_mounted_wheels"] = [w.name for w in ws if w.meta.get("modes_assumed") == "hard-mounted"]
    res.meta["on_assumed_modes"] = [f"{w.name} ({w.model_ref})" for w in ws
                                    if w.meta.get("modes_assumed") == "assumed modes used"]
    res.meta["speed_laws"] = [(w.name, law_text(w.law) if w.law is not None else
                               f"tied to {ws[w.tie.to].name} ×{w.tie.ratio:g}") for w in ws]
    return res, [(w.lines, w.mounting) for w in ws], [_own_support(ws, i) for i in range(len(ws))]


def _own_support(ws: list, i: int) -> tuple:
    """(lo, hi) rad/s wheel ``i`` of the set ``ws`` runs over: its speed law's support, or for a tied wheel that
    of the wheel its ties lead to, times the ties' ratios (±1; the chain ends: mounting refuses cycles)."""
    ratio = 1.0
    while ws[i].law is None:
        ratio *= ws[i].tie.ratio
        i = ws[i].tie.to
    lo, hi = (ratio * v for v in ws[i].law.support)
    return (min(lo, hi), max(lo, hi))


def _set_envelope(sources: list, supports: list, f: np.ndarray):
    """The worst-case line envelope of a set of wheels, each over its own speeds (``supports``, rad/s): the largest
    of the wheels' own envelopes at each frequency, the table of each with its wheel's index."""
    from .broadband import Envelope, line_envelope

    own = [line_envelope([src], sup, f) for src, sup in zip(sources, supports)]
    table = [dict(row, wheel=i) for i, e in enumerate(own) for row in e.table]
    return Envelope(f=own[0].f, amplitude=np.max([e.amplitude for e in own], axis=0), table=table)


@in_one_blas_thread
def psd(model=None, speed_rpm=(0.0, 3000.0), *, preset: str | None = None, wheels=None, dist: str = "uniform",
        std_rpm: float | None = None, empirical: bool = False, assumed_modes: bool = False,
        fmax: float | None = None, n_freq: int = 20001, n_speeds: int = 2000, envelope: bool = False,
        progress: bool = False):
    """Broadband disturbance PSD over a wheel-speed distribution: one wheel (wheel frame), or several wheels
    mounted on a spacecraft (6×6 CSD at the spacecraft's reference point).

    Parameters
    ----------
    model, preset : WheelModel, model-file path or None; str or None
        The wheel's model (or model file), or a wheel preset; with ``wheels``, the model of wheels naming none.
    speed_rpm : (float, float)
        MIN, MAX speed, rpm (negative = spinning about −z); with ``wheels``, for wheels without ``speed``.
    wheels : str, pathlib.Path, list of dict or None
        Several wheels in the spacecraft frame: a wheels.json file, or its content -- a list of wheel
        objects ``{"name", "model" or "preset", "dcm" and "position_m" (m) or "mounting": {"preset":
        "pyramid-4", "index": i}, "speed" or "tie"}`` (docs/formats.md; paths relative to the working folder).
    dist : str
        "uniform", "normal" (centred, truncated to the range) or a CSV file (histogram, density or time
        profile of the speed).
    std_rpm : float or None
        Standard deviation of the normal law, rpm (only with ``dist="normal"``); default range/6.
    empirical : bool
        Melody's model from the harmonics alone (hard mounted), else the extended model (modal amplification
        inside the speed integral).
    assumed_modes : bool
        Run a wheel whose suspension modes are assumed (a catalogue datasheet wheel) through those modes;
        without it such a wheel runs hard-mounted, as its datasheet states.
    fmax, n_freq, n_speeds : float or None, int, int
        Top frequency, Hz (default 1.2 × the highest line frequency, :func:`default_fmax`); frequency points
        from 0 to ``fmax`` (2 to 200 001); speed cells of the law (2 to 20 000).
    envelope : bool
        Also compute the worst-case line envelope (``meta["envelope"]``, a :class:`rwadist.broadband.Envelope`).
    progress : bool
        Print progress.

    Returns
    -------
    rwadist.broadband.BroadbandPSD
        ``.f`` frequencies (n_freq,), Hz; ``.csd`` (n_freq, 6, 6) and ``.psd`` auto-spectra (n_freq, 6) in
        N²/Hz, N·N·m/Hz and (N·m)²/Hz of Fx, Fy, Fz, Tx, Ty, Tz; ``.rms()`` (6,) in N and N·m; ``.frame``
        "wheel" or "spacecraft".  ``meta``: ``model`` ("empirical" or "extended"), ``source`` (the one wheel's
        or the default wheel's name, modes_assumed, hard_mounted; or None), ``hard_mounted_wheels`` and
        ``on_assumed_modes`` (names), ``speed_rpm``, ``fmax_hz``, ``speed_laws`` ([(wheel name or None, the
        law in words)]: each wheel's own law, or its tie).

    Raises
    ------
    ParameterError
        A value out of range (naming it): an empty speed range, ``std_rpm`` without the normal law, no model.
    DataError, ModelError
        A wheels file, model file or speed file that cannot be used (naming the file and field); a result
        with non-finite values.

    Warns
    -----
    RwadistWarning
        Speeds beyond the wheel's rated maximum; modes the extended fit could not identify.
    """
    from .broadband import line_envelope

    check_flags(empirical=empirical, assumed_modes=assumed_modes, envelope=envelope, progress=progress)
    law, (lo_rpm, hi_rpm) = _speed_law(speed_rpm, dist, std_rpm, fmax, n_freq, n_speeds)
    source = None               # the one wheel, or the set's default wheel
    if wheels is None or model is not None or preset:
        source = _default_source(model, preset, empirical, assumed_modes, lo_rpm, hi_rpm)
    meta = {"source": None if source is None else {"name": source.name, "modes_assumed": source.modes_assumed,
                                                   "hard_mounted": source.hard_mounted},
            "on_assumed_modes": [source.name] if source is not None and source.on_assumed_modes else [],
            "hard_mounted_wheels": []}
    if wheels is None:
        from .speed_laws import law_text

        res, sources, support = _one_wheel(source, law, fmax, n_freq, n_speeds, progress)
        res.meta["speed_laws"] = [(None, law_text(law))]
    else:
        res, sources, support = _wheel_set(wheels, source, law, empirical, assumed_modes, fmax, n_freq, n_speeds,
                                           progress)
        meta["on_assumed_modes"] += res.meta.pop("on_assumed_modes")
        meta["hard_mounted_wheels"] = res.meta.pop("hard_mounted_wheels")
    refuse_non_finite_psd(res, source.name if source is not None and wheels is None
                          else str(wheels) if isinstance(wheels, (str, Path)) else "wheels")
    hard = empirical or (source is not None and source.hard_mounted)
    res.meta.update(meta, model="empirical" if hard else "extended", speed_rpm=(lo_rpm, hi_rpm),
                    fmax_hz=float(res.f[-1]))
    if envelope:
        # a wheel of a set only over its own speeds: over the set's whole range, a wheel run slower than the others
        # was enveloped at speeds it never reaches
        res.meta["envelope"] = (line_envelope(sources, support, res.f) if wheels is None
                                else _set_envelope(sources, support, res.f))
    return res


def _speed_law(speed_rpm, dist: str, std_rpm, fmax, n_freq, n_speeds) -> tuple:
    """(law in rad/s, (MIN, MAX) rpm) of :func:`psd`'s request, its sizes checked."""
    from .broadband import law_from_spec

    for parameter, value in (("std_rpm", std_rpm), ("fmax", fmax), ("n_freq", n_freq), ("n_speeds", n_speeds)):
        check_parameter(parameter, value)
    if std_rpm is not None and dist != "normal":
        raise ParameterError("std_rpm", f"{std_rpm:g}: applies to `dist` 'normal' only (`dist` is {dist!r})")
    lo_rpm, hi_rpm = check_speed_range(speed_rpm)
    return law_from_spec(dist, lo_rpm, hi_rpm, std_rpm, "dist"), (lo_rpm, hi_rpm)


def _default_source(model, preset, empirical: bool, assumed_modes: bool, lo_rpm: float, hi_rpm: float):
    """The one wheel (or the set's default wheel) of :func:`psd`, with the warnings about what its PSD rests on."""
    from .wheel_source import wheel_source

    source = wheel_source(model, preset=preset, empirical=empirical, assumed_modes=assumed_modes)
    warn_beyond_rated_speed(source.model, source.name, lo_rpm, hi_rpm)
    if not source.hard_mounted:
        warn_unconstrained(source.model, source.name, "the PSD")
    return source


def write_nastran(result, path, *, fields: str = "small", cross: bool = True) -> dict:
    """Write a PSD's RANDPS/TABRND1 bulk-data entries (NASTRAN random analysis), atomically, to ``path``.

    Parameters
    ----------
    result : rwadist.broadband.BroadbandPSD
        What :func:`psd` returns (wheel or spacecraft frame).
    path : str or pathlib.Path
        The bulk-data file to write (e.g. ``psd.bdf``).
    fields : {"small", "free"}
        Small (8-character) or free field format.
    cross : bool
        The cross-spectra too (real and imaginary RANDPS entries): the full 6×6 matrix (default).  False: the
        auto-spectra only, and the deck's header names each pair left out with the largest coherence it carries.

    Returns
    -------
    dict
        {table id: (channel j, channel k, "auto" | "re" | "im")} of the TABRND1 tables written; subcase of
        channel Fx, Fy, Fz, Tx, Ty, Tz = 1 … 6; units Hz and N²/Hz, N·N·m/Hz, (N·m)²/Hz.
    """
    from .broadband import BroadbandPSD
    from .nastran import write_deck
    from .outputs import write_file

    check_flags(cross=cross)
    check_object("result", result, BroadbandPSD, "what rwadist.psd returns")
    check_path("path", path, "the bulk-data file to write")
    if fields not in ("small", "free"):
        raise ParameterError("fields", f"{fields!r}: must be 'small' or 'free'")
    tables: dict = {}
    write_file(path, lambda tmp: tables.update(write_deck(result, tmp, fmt=fields, cross=cross)), "path")
    return tables
