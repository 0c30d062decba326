"""Fit the extended (analytical) wheel model to test data, starting from the empirical fit.

Thesis §4.3 fitted the analytical model by hand and only for the fundamental,
and could not match both the height and the width of a resonance.  Here every
harmonic takes part and the fit is a least-squares problem:

1. **Rotation sense** of every radial line from the x/y phase in the time
   series: a line rotating with the spin has its power in X + iY (X, Y the
   complex spectra of the x and y channels at +f), a counter-rotating one in
   X − iY (for Ω < 0 the two swap).  Only counter-rotating content can excite
   backward whirl (the thesis's "pole-zero cancellation").
2. **Mode frequencies** by a profile scan (:mod:`rwadist.mode_scan`) over every measured line
   at every speed: radial-force lines place the radial translation mode, radial-torque lines the
   rocking mode through BOTH whirls (co-rotating content meets the forward whirl, counter-rotating
   the backward one, f± = sqrt((aΩ/2)² + f0²) ± aΩ/2, a = I_zz/I_rr), axial-force lines the axial
   mode.  The scan also gives the damping start and, without mass and radius, a.  A mode whose
   scan has an interior best point is *located*; it is *found* when the least squares below pins
   its frequency (1.5 standard errors within ``tolerance``, 2 %, off the ±5 % limit, damping off its floor
   ζ = 5e-5); otherwise it is declared not constrained and the least squares repeated without it,
   unless one line of another law than C·Ω² drags it off (:mod:`rwadist.off_law_lines`).
3. **Least squares** of log amplitude over every measured line at every speed
   (amplified or not): stiffnesses, damping of each mode and the forcing
   coefficient of each line (U_s and U_d are the h = 1 radial force and torque
   lines) are adjusted together, so height *and* width of each resonance are
   matched where a linear model can match them; the residual near each mode
   says where it cannot.  Every row weighs alike, unless one sensor family of
   the load cell (its forces or its torques) is far noisier than the other
   (:func:`rwadist.extended_fit_lsq.noisy_sensor_directions`, decided once on the data as
   recorded: :func:`rwadist.extended_fit_lsq.recorded_noisy_sensors`): then a row of that
   family weighs 1/sqrt(1 + (σ_noise/s)²), σ_noise its log amplitude's error from
   the noise under the line, s the scatter assumed besides it
   (:meth:`rwadist.extended_fit_lsq.LogAmplitudeProblem.row_weights`).
   Standard errors come from the Jacobian.

A mode the data do not constrain keeps its starting value and is said to be so: a note, and
``unconstrained`` (``analytical.unconstrained`` in the model file), never silently.  Mass and
radius come from the datasheet (thin-disc inertias, docs/formats.md) or are left out (a per-unit
fit: the interface loads depend only on the ratios); ``height`` (lever arm from the radial
force to the reported torque) is geometry, given, default 0 (torques about the
rotor centre).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from . import extended as ext
from .data import SteadyTest
from .empirical import EmpiricalFit, FitSettings, block_floor, fit_empirical
from .extended_fit_close import with_close_lines
from .extended_fit_damping import DAMPING_NAME, damping_record, fit_modes, located_damping
from .extended_fit_lsq import (
    LOG_SCATTER,
    MODE_PARAMS,
    LogAmplitudeProblem,
    power_sum_stderr,
    recorded_noisy_sensors,
    split_note,
)
from .extended_fit_power import (
    CHANNEL_INDEX,
    RADIAL,
    SPLIT_UNSEEN,
    LinePower,
    fitted_senses,
    forcing_lines,
    phase_splits,
    rows_of_lines,
)
from .geometry import remove_lever_arm
from .line_senses import ONE_SENSE, ONE_SENSE_RUNS, _line_senses_once, line_senses, one_sense_rows  # noqa: F401
from .mode_scan import MODE_DIRECTION, scan_mode
from .model import Harmonic
from .off_law_lines import line_regressors, off_law_note
from .resonance import resonance, resonance_response
from .spectra import compute_spectra, welch_dof
from .stand_every import log_data as _log_data
from .units import DIRECTION_CHANNELS, RAD_S_TO_RPM

#: RMS log-amplitude misfit (dB) of the measurements near a mode beyond which the linear model misses the data there
#: (:func:`_residuals_near_modes`: said in the notes), and a located mode's frequency is declared not constrained: its
#: standard error assumes the model right, and a resonance the model lacks beside the mode pulls it (family wheels
#: 2, 4, 7 with a resonance moving with speed on the axial force: 1.1-1.9 dB, the axial mode 2.2 % off with a standard
#: error of 0.8 %); clean and fixture cells of the wheel family leave at most 0.25 dB
MISFIT_DB = 1.0
#: mode key of the fit -> its name in the model file's ``analytical.unconstrained``
UNCONSTRAINED_NAME = {"radial_translation": "radial_translation", "rocking": "rocking", "axial_translation": "axial"}
#: ... and back: a name of ``analytical.unconstrained`` -> the fit's mode key (``identified``, ``scans``)
MODE_KEY = {name: key for key, name in UNCONSTRAINED_NAME.items()}


def declare_mode(efit, name: str, note: str) -> None:
    """Declare the located mode ``name`` (as in ``analytical.unconstrained``: "radial_translation", "rocking",
    "axial") of the extended fit ``efit`` not constrained by the data: listed in ``efit.unconstrained`` (every consumer
    warns), no longer ``identified``, ``note`` added to its notes; its fitted value is kept."""
    efit.unconstrained.append(name)
    efit.identified[MODE_KEY[name]] = False
    efit.notes.append(note)


@dataclass
class ExtendedFit:
    """Result of :func:`fit_extended`.

    params : fitted :class:`~rwadist.extended.ExtendedParams`.
    lines : forcing lines (direction, h, C, sense) of the fitted model.
    zeta : damping ratio per mode ("radial_translation", "rocking", "axial_translation").
    rel_stderr : relative standard error per fitted parameter (k_r, c_r, ... and line C's).
    identified : per mode, whether the data locate it (:func:`rwadist.mode_scan.scan_mode`).
    peaks : the amplification peaks that located the modes (dicts).
    senses : (direction, h) -> (sense, fraction of power co-rotating).
    rms : model-vs-data RMS comparison (see :func:`rms_comparison`).
    residual_db : per mode, RMS log-amplitude residual (dB) of the measurements near it.
    notes : what could not be fitted and why.
    measured : the line measurements the least squares used (LineFit list, every speed).
    unconstrained : modes the data do not constrain ("radial_translation", "rocking", "axial"):
        their values are starting values, or for a mode not told apart from a test stand its fitted value
        (written to ``analytical.unconstrained``).
    scans : per mode, the :class:`~rwadist.mode_scan.ModeScan` that located it or said why not.
    per_unit : True when mass/radius were not given (M = 1 kg, I_rr = 1 kg·m²).
    stand : the fixture resonance (f_r Hz, ζ, peak gain[, gain above]) divided out of every line, or None: the start
        given, or the stand fitted with the modes (``fit_stand``).
    stand_direction : None, or the load direction ``stand`` acts on alone: then a mode of the wheel's structure, not a
        fixture (:func:`fit_extended`'s ``stand_direction``).
    line_residuals : (f Hz, r, direction) of every measurement the least squares used: f = h|Ω|/2π the line's
        frequency and r = ln(measured / model amplitude) (radial lines: of sqrt(x² + y²)), the stand divided out (and
        a line whose exponent the fit freed, :func:`rwadist.off_law_lines.off_law_line`, taken with its own growth);
        direction its load direction ("axial_force", "radial_force", "radial_torque").
    line_noise : per row of ``line_residuals``, the standard deviation of its log amplitude the noise under the line
        makes (dimensionless; 0 where not measured; :attr:`rwadist.empirical.LineFit.noise`).
    line_h : per row of ``line_residuals``, the ratio h of its line to the speed.
    zeta_bounds : per located mode whose damping the data do not measure, (lo, hi) the damping ratios they allow; its
        ζ is held (:mod:`rwadist.extended_fit_damping`), written as zeta_<mode> to ``analytical.unconstrained``.
    zeta_interval : per located mode whose damping was profiled, (lo, hi) the damping ratios the data allow (a held
        one's: its ``zeta_bounds``); in ``analytical.fit.zeta_interval``.
    """

    params: ext.ExtendedParams
    lines: list
    zeta: dict
    rel_stderr: dict
    identified: dict
    peaks: list
    senses: dict
    rms: dict = field(default_factory=dict)
    residual_db: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    measured: list = field(default_factory=list)
    unconstrained: list = field(default_factory=list)
    scans: dict = field(default_factory=dict)
    per_unit: bool = False
    stand: tuple | None = None
    line_residuals: tuple = (np.empty(0), np.empty(0), np.empty(0, dtype=str))
    stand_direction: str | None = None
    zeta_bounds: dict = field(default_factory=dict)
    zeta_interval: dict = field(default_factory=dict)
    more_stands: tuple = ()         # further fixture resonances divided out of every line, held (``more_stands``)
    stand_on: tuple | None = None   # the channels ``stand`` acts on when not every one (``stand_on``)
    line_noise: np.ndarray = field(default_factory=lambda: np.empty(0))     # per row of line_residuals, σ_noise
    line_h: np.ndarray = field(default_factory=lambda: np.empty(0))         # per row of line_residuals, its line's h

    def parts_of(self, direction: str, h: float) -> list:
        """The model lines (co- and counter-rotating parts) of the measured harmonic (direction, h)."""
        tol = ext.IMBALANCE_H_TOL if abs(h - 1.0) <= ext.IMBALANCE_H_TOL else 1e-6
        return [ln for ln in self.lines if ln.direction == direction and abs(ln.h - h) <= tol]

    @property
    def locates_no_mode(self) -> bool:
        """True when every suspension mode is declared unconstrained: the data locate none of them."""
        return set(UNCONSTRAINED_NAME.values()) <= set(self.unconstrained)

    def fresh_copy(self) -> "ExtendedFit":
        """A copy whose lists and dicts are its own (notes, declared modes, ...: what a reader adds to); the arrays
        and line fits, which no reader changes, shared."""
        import copy
        from dataclasses import fields

        out = copy.copy(self)
        for f in fields(self):
            if isinstance(v := getattr(self, f.name), (list, dict)):
                setattr(out, f.name, type(v)(v))
        return out


# --------------------------------------------------------------------------- 1. senses

# --------------------------------------------------------------------------- 2. mode frequencies

def amplification_peaks(fit: EmpiricalFit, min_gain: float = 1.25) -> list:
    """The largest amplification (measured / C·Ω²) inside each excluded speed range of each line."""
    peaks = []
    for x in fit.lines:
        if not x.excluded_rpm:
            continue
        rpm = x.speed * RAD_S_TO_RPM
        ratio = x.amplitude / (x.C * x.speed**2)
        for lo, hi in x.excluded_rpm:
            m = (rpm >= lo - 1e-9) & (rpm <= hi + 1e-9)
            if not m.any():
                continue
            k = np.nonzero(m)[0][np.argmax(ratio[m])]
            if ratio[k] < min_gain:
                continue
            # a maximum at an end of the measured speeds is a skirt, not a peak: a bound only
            edge = bool(rpm[k] >= rpm.max() - 1e-9 or rpm[k] <= rpm.min() + 1e-9)
            peaks.append({"direction": x.direction, "h": x.h, "speed_rad_s": float(x.speed[k]),
                          "speed_rpm": float(rpm[k]), "f_hz": float(x.h * x.speed[k] / (2 * np.pi)),
                          "gain": float(ratio[k]), "at_range_edge": edge})
    return peaks


def mode_frequencies(peaks: list, senses: dict, inertia_ratio: float) -> dict:
    """Starting mode frequencies (Hz at rest) from amplification peaks; None where none seen."""
    out: dict[str, float | None] = {"radial_translation": None, "rocking": None, "axial_translation": None}
    trans = [p["f_hz"] for p in peaks if p["direction"] == "radial_force" and not p["at_range_edge"]]
    trans = trans or [p["f_hz"] for p in peaks if p["direction"] == "radial_force"]
    if trans:
        out["radial_translation"] = float(np.median(trans))
    axial = [p["f_hz"] for p in peaks if p["direction"] == "axial_force"]
    if axial:
        out["axial_translation"] = float(np.median(axial))
    cands = []
    for p in peaks:
        if p["direction"] != "radial_torque":
            continue
        sense = senses.get(("radial_torque", float(p["h"])), ("co", 1.0))[0]
        w_hz = p["speed_rad_s"] / (2 * np.pi)
        for s, name in ((1, "co"), (-1, "counter")):
            if sense in (name, "planar"):
                f0sq = p["f_hz"] ** 2 - s * inertia_ratio * w_hz * p["f_hz"]
                if f0sq > 0:
                    cands.append(math.sqrt(f0sq))
    if cands:
        out["rocking"] = float(np.median(cands))
    return out


# --------------------------------------------------------------------------- 3. least squares

def _axial_measurements(fit: EmpiricalFit):
    """Flat arrays of every measured amplitude of the axial lines: line index (position in ``fit.lines``), speed,
    channel index, amplitude, and the standard deviation of its logarithm the noise makes (its relative amplitude
    error, :attr:`rwadist.empirical.LineFit.noise`; 0 where not measured)."""
    li, sp, ch, amp, nz = [], [], [], [], []
    for j, x in enumerate(fit.lines):
        li.append(np.full(x.speed.size, j))
        sp.append(x.speed)
        ch.append(np.array([CHANNEL_INDEX[c] for c in x.channel]))
        amp.append(x.amplitude)
        nz.append(np.zeros(x.speed.size) if x.noise is None else np.asarray(x.noise, dtype=float))
    la, sa, ca, aa, na = (np.concatenate(a) for a in (li, sp, ch, amp, nz))
    keep = np.array([fit.lines[j].direction not in RADIAL for j in la], bool)
    return la[keep], sa[keep], ca[keep], aa[keep], na[keep]


def _radial_power(meas_lines, read_speeds: dict | None = None):
    """Per radial line and run, the measured x and y amplitudes combined: d_x² + d_y² (only runs
    where both are measured; a channel measured twice at one speed counts by its first measurement).  A line never
    measured on both channels at one speed is read on the one it was measured on, at every speed: √2·d² where the
    other channel was read (``read_speeds``: channel -> the speeds, rad/s, of the runs that have it; None: every
    channel at every speed) and did not show the line, whose x² + y² then lies between d² and 2d² (log noise the
    measurement's and that factor's, uniform); 2d² where it was not read (a load turning in the plane, as most do).
    Returns (line index, speed, power, direction, log noise) arrays, each line's speeds in increasing order; log
    noise: the standard deviation of ½ ln(d_x² + d_y²) the noise makes, sqrt(d_x⁴ s_x² + d_y⁴ s_y²)/(d_x² + d_y²) of
    the relative amplitude errors s (:attr:`rwadist.empirical.LineFit.noise`; 0 where not measured).

    Without those rows such a line's coefficients were free in the least squares and went where rounding took them
    (family wheel 2's run-up with its tach: the planar 2xBSF line, at each speed on the channel it leant to, at
    100-150x its level as OpenBLAS's kernels rounded; its modes lost on the held-out runs, on one CI machine)."""
    li, sp, pw, dr, nz = [], [], [], [], []
    for j, x in enumerate(meas_lines):
        if x.direction not in RADIAL:
            continue
        cx, cy = DIRECTION_CHANNELS[x.direction]
        chan = np.asarray(x.channel)
        on_x, on_y = chan == cx, chan == cy
        # each speed's first measurement on each channel (np.unique's first occurrences), paired on the speeds both have
        wx, ix = np.unique(x.speed[on_x], return_index=True)
        wy, iy = np.unique(x.speed[on_y], return_index=True)
        both, kx, ky = np.intersect1d(wx, wy, assume_unique=True, return_indices=True)
        noise = np.zeros(x.speed.size) if x.noise is None else np.asarray(x.noise, dtype=float)
        if both.size:
            dx, dy = x.amplitude[on_x][ix[kx]], x.amplitude[on_y][iy[ky]]
            sx, sy = noise[on_x][ix[kx]], noise[on_y][iy[ky]]
            p = dx**2 + dy**2
            log_noise = np.sqrt((dx**2 * sx) ** 2 + (dy**2 * sy) ** 2) / np.maximum(p, 1e-300)
        else:
            both, first = np.unique(x.speed, return_index=True)
            other = np.where(chan[first] == cx, cy, cx)
            read = np.ones(both.size, bool) if read_speeds is None else \
                np.array([np.isin(abs(w), read_speeds.get(str(c), ())) for w, c in zip(both, other)], bool)
            p = np.where(read, math.sqrt(2.0), 2.0) * x.amplitude[first] ** 2
            log_noise = np.sqrt(noise[first] ** 2 + np.where(read, ONE_CHANNEL_LOG_SPREAD ** 2, 0.0))
        li.append(np.full(both.size, j))
        sp.append(both)
        pw.append(p)
        dr.append(np.full(both.size, x.direction))
        nz.append(log_noise)
    if not li:
        return np.array([], int), np.array([]), np.array([]), np.array([]), np.array([])
    return (np.concatenate(li).astype(int), np.concatenate(sp), np.concatenate(pw), np.concatenate(dr),
            np.concatenate(nz))


#: The standard deviation of ½ ln(x² + y²) about ln(2^¼·d) when x² + y² lies uniformly in ln between d² and 2d²
#: (:func:`_radial_power`: a line measured on one channel of its pair, the other read and under the noise)
ONE_CHANNEL_LOG_SPREAD = math.log(2.0) / 4.0 / math.sqrt(3.0)


def _read_speeds(spectra) -> dict:
    """Channel -> the |speeds| (rad/s) of the runs of ``spectra`` that have it
    (:meth:`rwadist.spectra.Spectra.available`)."""
    speed = np.abs(np.asarray(spectra.speed, dtype=float))
    return {c: speed[spectra.available(c)] for c in spectra.channels}


def _scan_all(meas_lines, radial, la, sa, aa, inertia_ratio, tolerance, near=None, senses_xy=None):
    """Profile scan (:mod:`rwadist.mode_scan`) of each mode on the measured lines (``radial``: their
    :func:`_radial_power`; ``near``: :func:`fit_extended`).  The axial mode on the axial-force lines alone: the
    spin-axis torque's lines pass through no mode (:mod:`rwadist.extended`), and scanned with them a flat Tz line up to
    the mode held it off when one force line alone reached it (trial 11's 300-s run-up without the 7.2 lines: h 3.6 of
    Tz to 268 Hz beside h 3.6 of Fz through the 260-Hz mode; the scan put it at 293 Hz, ζ 0.06, the least squares at
    its ±5 % limit, and the Fz line's rise went to an invented amplitude law).  ``senses_xy``: :func:`line_senses`
    of the measured lines, whose every-run senses restrict the rocking scan's forcing (:func:`one_sense_rows`)."""
    lr, sr, pr, dr, _ = radial
    h_of = np.array([x.h for x in meas_lines]) if meas_lines else np.zeros(0)
    scans = {}
    for mode, direction in MODE_DIRECTION.items():
        if direction == "axial_force":
            m = np.array([meas_lines[int(j)].direction == direction for j in la], dtype=bool)
            line, omega, power = la[m], sa[m], aa[m] ** 2
        else:
            m = dr == direction
            line, omega, power = lr[m], sr[m], pr[m]
        sense = one_sense_rows(meas_lines, line, senses_xy) if mode == "rocking" and senses_xy else None
        scans[mode] = scan_mode(mode, line, h_of[line] if line.size else np.zeros(0), omega, power,
                                inertia_ratio=inertia_ratio if mode == "rocking" else None, tolerance=tolerance,
                                min_log_lr=-math.inf, sense=sense, **(near or {}).get(mode, {}))
    return scans


def _measured_lines(test: SteadyTest, fit: EmpiricalFit, height: float, stands: list, stand_direction: str | None = None,
                    stand_on: tuple | None = None, fit_stand: bool = False, moving: tuple | None = None):
    """(test, empirical fit, measured lines, x/y senses) the extended fit works on: the lever-arm torque ``height`` × F
    removed from the test and its fit (:func:`rwadist.geometry.remove_lever_arm`); every line the data show, with
    every measurement (the empirical fit without modal exclusion: with it, lines that are amplified or attenuated at
    most speeds are dropped; close lines measured together on the records); the fixture resonances ``stands`` divided
    out of their amplitudes (the first only out of the lines of ``stand_direction``, or of the measurements on the
    channels ``stand_on``, when given: held, not with ``fit_stand``, ValueError), and the resonance ``moving`` (f0 Hz,
    slope Hz per Hz of spin, ζ, peak gain, gain above: at f0 + slope·|Ω|/2π in each run) out of every line's."""
    if stand_on is not None and fit_stand:
        raise ValueError("a stand on some channels is held (measured on the x/y ratios, rwadist.stand_axes), not fitted")
    if height:
        sp0 = fit.spectra
        test = remove_lever_arm(test, height)
        spectra = compute_spectra(test, nperseg=sp0.nperseg, f_lim=sp0.f_lim, window=sp0.window)
        fit = fit_empirical(spectra, fit.fit_settings)
    meas = _unsmeared_once(test, with_close_lines(test, fit.without_mode_exclusion),
                           len(fit.without_mode_exclusion.lines))
    radial_on = None if stand_on is None else tuple(c for c in stand_on if c in ("Fx", "Fy", "Tx", "Ty"))
    senses_xy = _line_senses_once(test, meas, (tuple(stands[0]), radial_on) if radial_on else None)
    if stands:
        def fixture_gain(x):
            f = x.h * np.abs(x.speed) / (2 * np.pi)
            acting = [s for i, s in enumerate(stands) if i > 0 or stand_direction in (None, x.direction)]
            gains = [np.abs(resonance(f, *s)) for s in acting]
            if stand_on is not None and acting and acting[0] is stands[0]:
                gains[0] = np.where(np.isin(x.channel, stand_on), gains[0], 1.0)
            return np.prod(gains, axis=0) if acting else np.ones_like(f)

        meas = replace(meas, lines=[replace(x, amplitude=x.amplitude / fixture_gain(x)) for x in meas.lines])
    if moving is not None:
        f0, slope, *shape = moving
        spin = [np.abs(x.speed) / (2 * np.pi) for x in meas.lines]
        meas = replace(meas, lines=[replace(x, amplitude=x.amplitude / np.abs(resonance_response(
            x.h * s / np.maximum(f0 + slope * s, 1e-6), *shape))) for x, s in zip(meas.lines, spin)])
    return test, fit, meas, senses_xy


def _unsmeared_once(test: SteadyTest, meas: EmpiricalFit, n_window: int) -> EmpiricalFit:
    """``meas`` with its first ``n_window`` lines' amplitudes corrected for their chirp across the fit's segment on a
    test cut from a sweep (:func:`rwadist.chirp.unsmeared_lines`), else ``meas`` itself; kept on ``meas`` per test."""
    from .chirp import unsmeared_lines

    kept = meas.__dict__.get("_unsmeared")
    if kept is None or kept[0] is not test:
        lines = unsmeared_lines(test, meas, n_window)
        kept = (test, meas if lines is None else replace(meas, lines=lines))
        meas.__dict__["_unsmeared"] = kept
    return kept[1]


def _inertias(mass: float | None, radius: float | None, rocking_scan, notes: list) -> tuple[float, float, float]:
    """(M kg, I_rr kg·m², I_zz kg·m²): the thin disc of the datasheet's mass and radius, or per unit (M = 1 kg,
    I_rr = 1 kg·m², I_zz/I_rr from the rocking whirls when its scan found them, else 2; said in ``notes``)."""
    if mass is not None and radius is not None:
        I_zz, I_rr = ext.thin_disc(mass, radius)
        return mass, I_rr, I_zz
    a_fit = rocking_scan.inertia_ratio if rocking_scan.found else 2.0
    notes.append("mass/radius not given: parameters are per unit mass (M = 1 kg) and per unit transverse "
                 f"inertia (I_rr = 1 kg·m²); I_zz/I_rr = {a_fit:.3f} "
                 + ("fitted from the whirls" if rocking_scan.found else "ASSUMED (thin disc): the rocking "
                    "whirls do not constrain it"))
    return 1.0, 1.0, float(a_fit)


def _ratio_words(notes: list, identified: dict) -> list:
    """``notes`` with I_zz/I_rr "fitted from the whirls" (:func:`_inertias`) said as the rocking scan's when the fit then
    declared the rocking mode not constrained: the ratio rests on a mode the fit did not confirm (a new user's
    hard-mounted wheel, no mode in band: "I_zz/I_rr = 3.000 fitted from the whirls", the scan's bound)."""
    if identified.get("rocking", True):
        return notes
    return [n.replace("fitted from the whirls", "from the rocking scan, but the rocking mode is NOT CONSTRAINED: the "
                      "whirls do not fix it") for n in notes]


@dataclass
class _ModeStarts:
    """The modes' starting point.  Per mode the frequency its scan found (``f_modes``, Hz at rest; None: not found)
    and whether the data identify it; a mode without a frequency is NOT CONSTRAINED (said in ``notes``): its
    stiffness from ``start`` in a physical fit, else at 3x the top line frequency ``f_top`` Hz, its damping ratio
    ``zeta0``."""

    scans: dict
    start: ext.ExtendedParams | None
    physical: bool
    f_top: float
    zeta0: float
    notes: list
    f_modes: dict = field(init=False)
    identified: dict = field(init=False)

    def __post_init__(self) -> None:
        self.f_modes = {m: (sc.f0_hz if sc.found else None) for m, sc in self.scans.items()}
        self.identified = {m: self.f_modes[m] is not None for m in MODE_PARAMS}

    def stiffness(self, mode: str, inertia: float, attr: str) -> float:
        """The starting stiffness of ``mode`` (``attr`` of ExtendedParams), N/m or N·m/rad."""
        f = self.f_modes[mode]
        if f is not None:
            return inertia * (2 * np.pi * f) ** 2
        if self.start is not None and self.physical:
            k = getattr(self.start, attr)
        else:
            k = inertia * (2 * np.pi * 3 * self.f_top) ** 2
        f_start = math.sqrt(k / inertia) / (2 * np.pi)
        self.notes.append(f"{mode}: NOT CONSTRAINED by the data ({self.scans[mode].reason}); its {f_start:.4g} Hz is "
                          "a starting value, listed in analytical.unconstrained")
        return k

    def params(self, mass: float, I_rr: float, I_zz: float) -> dict:
        """The ExtendedParams fields at the start (SI): each mode's stiffness and damping (the scan's damping ratio
        when identified, else ``zeta0``), no forcing yet."""
        k_r = self.stiffness("radial_translation", mass, "k_r")
        k_rock = self.stiffness("rocking", I_rr, "k_rock")
        k_z = self.stiffness("axial_translation", mass, "k_z")
        base = dict(mass=mass, I_zz=I_zz, I_rr=I_rr, k_r=k_r, k_rock=k_rock, k_z=k_z, height=0.0, U_s=0.0, U_d=0.0)
        for m, (kn, cn, inertia) in MODE_PARAMS.items():
            zeta = self.scans[m].zeta if self.identified[m] else self.zeta0
            base[cn] = 2 * zeta * math.sqrt(base[kn] * base[inertia])
        return base

    def declare(self, base: dict, mode: str, why: str, kept: tuple | None = None) -> None:
        """``mode`` not pinned by the least squares: NOT CONSTRAINED (``why``), back to its start in ``base``, or held
        at the stiffness and damping ``kept`` where it was located (above every line of its direction:
        :func:`rwadist.extended_fit_damping.above_every_line`); else its damping ratio ``zeta0``."""
        self.scans[mode].reason = why
        self.scans[mode].found = False
        self.identified[mode] = False
        self.f_modes[mode] = None
        kn, cn, inertia = MODE_PARAMS[mode]
        if kept is None:
            base[kn] = self.stiffness(mode, base[inertia], kn)
            base[cn] = 2 * self.zeta0 * math.sqrt(base[kn] * base[inertia])
        else:
            base[kn], base[cn] = kept
            self.notes.append(f"{mode}: NOT CONSTRAINED by the data ({why}); above every line of its direction (the "
                              "lines show the rise below it, not the mode): its fitted value is kept, listed in "
                              "analytical.unconstrained")


def _residuals_near_modes(params: ext.ExtendedParams, lines: list, ax_line: np.ndarray, rad_parts: np.ndarray,
                          sa: np.ndarray, sr: np.ndarray, dr: np.ndarray, r: np.ndarray,
                          notes: list) -> tuple[dict[str, float], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(per mode the RMS log residual (dB) of the measurements within ±10 % of its frequency at their speed, (f Hz, r)
    of every row: :attr:`ExtendedFit.line_residuals`) of the least squares' residuals ``r`` (the axial rows: forcing
    line ``ax_line``, speed ``sa`` rad/s; then the radial rows: parts ``rad_parts``, speed ``sr``, direction ``dr``);
    over 1 dB said in ``notes``."""
    f_ax = np.array([lines[k].h for k in ax_line]) * np.abs(sa) / (2 * np.pi)
    f_rd = np.array([lines[k].h for k in rad_parts[:, 0]]) * np.abs(sr) / (2 * np.pi) if sr.size else np.empty(0)
    r_ax, r_rad = r[:sa.size], r[sa.size:]
    on_fz = np.array([lines[k].direction == "axial_force" for k in ax_line], bool)
    resid_db = {}
    for m, keys, use_rad, dirs in (("radial_translation", ("radial_translation",), True, ("radial_force",)),
                                   ("rocking", ("rocking_forward", "rocking_backward"), True, ("radial_torque",)),
                                   ("axial_translation", ("axial_translation",), False, ("axial_force",))):
        if use_rad:
            fm = ext.whirl_frequencies(params, sr)
            near = np.zeros(sr.size, bool)
            for key in keys:
                near |= np.abs(f_rd / fm[key] - 1) < 0.1
            near &= np.isin(dr, dirs)
            rr = r_rad[near]
        else:       # the axial force's rows: the axial torque has no mode (its lines pass through, hard-mounted)
            fm = ext.whirl_frequencies(params, sa)
            rr = r_ax[(np.abs(f_ax / fm[keys[0]] - 1) < 0.1) & on_fz]
        if rr.size:
            resid_db[m] = float(20 / np.log(10) * np.sqrt(np.mean(rr**2)))
            if resid_db[m] > MISFIT_DB:
                notes.append(f"{m}: the linear model misses the data near this mode by {resid_db[m]:.1f} dB RMS "
                             "(a fixture resonance inside the band -- set f_lim --, nonlinear damping, or a "
                             "mode the model lacks)")
    return resid_db, (np.concatenate([f_ax, f_rd]), np.concatenate([r_ax, r_rad]),
                      np.concatenate([np.full(f_ax.size, "axial_force"), np.asarray(dr, dtype=str)]))


def fit_extended(test: SteadyTest, fit: EmpiricalFit, mass: float | None = None, radius: float | None = None,
                 height: float = 0.0, start: ext.ExtendedParams | None = None, zeta0: float = 0.02,
                 progress: bool = False, tolerance: float = 0.02, stand: tuple | None = None,
                 more_stands: tuple = (), near: dict | None = None, fit_stand: bool = False,
                 declare: bool = True, stand_direction: str | None = None, fit_more_stands: bool = False,
                 stand_on: tuple | None = None, moving: tuple | None = None) -> ExtendedFit:
    """Fit the extended model to a steady test whose empirical fit is ``fit``.

    mass (kg), radius (m): datasheet values (thin-disc inertias, I_zz/I_rr = 2).  Either may be None: the interface
    loads depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr and I_zz/I_rr, so the fit is then per unit mass and per unit
    transverse inertia (M = 1 kg, I_rr = 1 kg·m², I_zz = the fitted ratio; stated in the notes) and I_zz/I_rr is fitted
    from the two whirls.  height (m): z of the rotor centre above the point the torques are measured about (the
    interface), as in :class:`rwadist.extended.ExtendedParams`; the lever-arm torque height × F is removed from the data
    before the fit and put back in the model.  start: parameters for modes the data do not constrain (default: modes at
    3x the top line frequency, ζ = zeta0).  tolerance: relative frequency error the data must exclude for a mode to
    count as found (:func:`scan_mode`).
    stand: (f_r Hz, ζ, peak gain[, gain above]) of a fixture resonance acting on every channel (``rwadist diagnose``'s
    ``fixed_resonance`` of role test_stand; :func:`rwadist.resonance.resonance`), or None: every measured line amplitude
    is divided by its |H| before the modes are located and fitted, so that the fixture's amplification is not taken for
    the wheel's.  more_stands: further fixture resonances (each (f_r Hz, ζ, peak gain[, gain above]), on every channel)
    divided out the same way and held (``ExtendedFit.more_stands``).  near: mode -> ``near_hz``/``near_a`` of
    :func:`rwadist.mode_scan.scan_mode` (where an earlier fit of the same wheel located it), or None.  fit_stand: the
    modes are located with ``stand`` divided out, and its parameters (f_r, ζ, the numerator's damping and the gain
    above, :class:`rwadist.resonance.FittedResonance`) are fitted in the modes' least squares, from it: the modes'
    standard errors are those with the stand free (what the stand could take of their lines is counted).  declare: False
    keeps every located mode in the least squares, however loose (the joint fit's passes, whose next scans start from
    the stand it fits: a mode dropped there leaves its lines to the stand alone).  stand_direction: ``stand`` is a mode
    of the wheel's structure on that load direction only (``rwadist diagnose``'s ``fixed_resonance`` of role
    wheel_mode), divided out of that direction's lines alone, H → 1 far above it (β = 1).  fit_more_stands: with
    ``fit_stand``, ``more_stands`` fitted in its least squares too (:mod:`rwadist.stand_every`).  stand_on: the channels
    a held ``stand`` acts on when not every one (:mod:`rwadist.stand_axes`); not with ``fit_stand``.  moving: held.

    Each mode is located by a profile scan over its frequency, damping (and I_zz/I_rr) on every measured line at every
    speed, both whirls included (:mod:`rwadist.mode_scan`); a mode the data do not pin down keeps its starting value,
    is named in ``unconstrained`` and in the notes.  Each radial line gets two forcing coefficients, one rotating with
    the spin and one against it, fitted to the x-plus-y line power (which does not depend on their relative phase): the
    rotation sense is read from the forcing, not from the response (a mode amplifies one sense more than the other, so
    the response alone would mislabel a planar load).
    """
    physical = mass is not None and radius is not None
    notes: list[str] = []
    # the load cell's noisier sensor family read on the data as recorded, before the lever arm comes out (T − h × F puts
    # the force sensors' noise in the torques: wheel 1's forces 28 dB noisier, 5-9x the torques' floor, 2.6-3.5x less h)
    noisy = recorded_noisy_sensors(test, fit.without_mode_exclusion.lines) if height else None
    test, fit, meas, senses_xy = _measured_lines(test, fit, height, ([] if stand is None else [stand]) + list(more_stands),
                                                 None if stand is None else stand_direction, stand_on, fit_stand, moving)
    peaks = amplification_peaks(fit)
    la, sa, ca, aa, na = _axial_measurements(meas)
    lr, sr, pr, dr, nr = radial = _radial_power(meas.lines, _read_speeds(meas.spectra))
    scans = _scan_all(meas.lines, radial, la, sa, aa, 2.0 if physical else None, tolerance, near, senses_xy)
    mass_kg, I_rr, I_zz = _inertias(mass, radius, scans["rocking"], notes)
    starts = _ModeStarts(scans, start, physical, max((x.h * x.speed.max() / (2 * np.pi) for x in meas.lines),
                                                     default=100.0), zeta0, notes)
    base = starts.params(mass_kg, I_rr, I_zz)
    lines, owner = forcing_lines(meas.lines, senses_xy)
    line_of, ax_line, rad_parts = rows_of_lines(owner, la, lr)
    log_data, joint = _log_data(meas.lines, la, sa, aa, lr, sr, pr, stand if fit_stand else None, stand_direction,
                                tuple(more_stands) if fit_stand and fit_more_stands else ())
    row_line, log_w, centred_log_w = line_regressors(la, lr, sa, sr)     # per row: its line, ln|Ω|, centred
    problem = LogAmplitudeProblem(base, lines, LinePower(lines, sa, ax_line, ca, sr, rad_parts), log_data, joint,
                                  row_line, centred_log_w, meas.lines, progress, np.concatenate([na, nr]), LOG_SCATTER,
                                  recorded_noisy_sensors(test, meas.lines) if noisy is None else noisy)
    off_law: list[int] = []     # lines given an exponent of their own before a mode is declared (appended in place)
    zeta_bounds: dict = {}      # mode -> (lo, hi): a damping the data do not measure, held (filled in place)
    intervals: dict = {}        # mode -> (lo, hi): every damping's interval at the last fit that profiled it
    solution = fit_modes(problem, [m for m in MODE_PARAMS if starts.identified[m]], declare, tolerance, off_law,
                          log_w, lambda m, why, kept: starts.declare(base, m, why, kept), zeta0, zeta_bounds, intervals)
    res, names, rel_se, unpack = solution.res, solution.names, solution.rel_se, solution.unpack
    params, fitted_lines = unpack(res.x)
    sums = power_sum_stderr(solution, {(x.direction, float(x.h)): tuple(line_of[j])
                                       for j, x in enumerate(meas.lines) if x.direction in RADIAL})
    params, fitted_lines, split_se = phase_splits(params, meas.lines, fitted_lines, line_of, sums, senses_xy, problem.power, notes)
    n_x = res.x.size - (len(joint.NAMES) if joint is not None else 0)
    notes += [off_law_note(meas.lines[j], res.x[n_x + i - len(off_law)], rel_se[n_x + i - len(off_law)])
              for i, j in enumerate(off_law)]
    if joint is not None:
        stand, more_stands = joint.stand(res.x[n_x:]), joint.more(res.x[n_x:], more_stands)
    params = replace(params, height=float(height))
    senses, kept_lines = fitted_senses(meas.lines, fitted_lines, line_of)
    notes += [split_note(d, h, se[0], se[3]) for (d, h), se in sums.items() if se[3] >= SPLIT_UNSEEN and senses[(d, h)][0] == "co+counter"]
    resid_db, line_residuals = _residuals_near_modes(params, lines, ax_line, rad_parts, sa, sr, dr, res.fun, notes)
    for m in (m for m in MODE_PARAMS if declare and starts.identified[m] and resid_db.get(m, 0.0) > MISFIT_DB):
        starts.identified[m] = False
        notes.append(f"{m}: NOT CONSTRAINED: located at {_mode_hz_of(params, m):.4g} Hz, but the model misses the data "
                     f"near it by {resid_db[m]:.1f} dB RMS (more than {MISFIT_DB:g} dB: something the model lacks "
                     "acts there, and pulls the mode); its fitted value is kept, listed in analytical.unconstrained")
    zeta_bounds, intervals = located_damping(zeta_bounds, intervals, starts.identified, problem.held_zeta, notes)
    return ExtendedFit(params=params, lines=kept_lines,
                       zeta={"radial_translation": params.zeta_r, "rocking": params.zeta_rock,
                             "axial_translation": params.zeta_z},
                       rel_stderr={n: float(v) for n, v in zip(names, rel_se)} | split_se
                       | {f"C[{d},{h:g},co+counter]": se[0] for (d, h), se in sums.items()}, identified=starts.identified,
                       peaks=peaks, senses=senses, residual_db=resid_db, notes=_ratio_words(notes, starts.identified), measured=meas.lines,
                       unconstrained=[UNCONSTRAINED_NAME[m] for m in MODE_PARAMS if not starts.identified[m]], scans=scans,
                       per_unit=not physical, stand=None if stand is None else tuple(float(v) for v in stand),
                       line_residuals=line_residuals, stand_direction=None if stand is None else stand_direction,
                       zeta_bounds=zeta_bounds, zeta_interval=intervals, line_noise=np.concatenate([na, nr]),
                       line_h=_rows_h(lines, ax_line, rad_parts, sr),
                       more_stands=tuple(tuple(float(v) for v in k) for k in more_stands),
                       stand_on=None if stand is None or stand_on is None else tuple(stand_on))


def _rows_h(lines: list, ax_line: np.ndarray, rad_parts: np.ndarray, sr: np.ndarray) -> np.ndarray:
    """h of the line of every row of :attr:`ExtendedFit.line_residuals` (the axial rows, then the radial ones)."""
    return np.array([lines[k].h for k in ax_line] + ([lines[k].h for k in rad_parts[:, 0]] if sr.size else []), float)


def _mode_hz_of(params: ext.ExtendedParams, mode: str) -> float:
    """Frequency at rest (Hz) of ``mode`` (a key of MODE_PARAMS) of ``params``."""
    kn, _, inertia = MODE_PARAMS[mode]
    return float(np.sqrt(getattr(params, kn) / getattr(params, inertia)) / (2 * np.pi))


# --------------------------------------------------------------------------- 4. comparison

def rms_comparison(efit: ExtendedFit, fit: EmpiricalFit) -> dict:
    """RMS vs speed of data, empirical model and extended model, per direction (``runs``: its spinning runs with the
    direction's first channel, indices of the spectra; ``speed_rpm``: their |speed|), and the error of each model
    where modes are excited (speeds inside any excluded range of that direction).

    Data RMS is over (0, band limit] with the noise floor's mean square removed, so what
    is compared is the harmonic content.  Error = RMS over those speeds of
    (model − data) / data.
    """
    from .model import model_rms

    sp = fit.spectra
    f, df = sp.f, sp.df
    band = (f > 0) & (f <= sp.band_limit)
    dof = welch_dof(int(np.min(sp.n_segments)))
    speed = np.abs(sp.speed)
    rpm = speed * RAD_S_TO_RPM
    ext_rms = ext.steady_rms(efit.params, efit.lines, sp.speed, f_max=sp.band_limit)
    out = {}
    for d in ("radial_force", "radial_torque", "axial_force"):
        c = DIRECTION_CHANNELS[d][0]
        if c not in sp.psd:
            continue
        ok = sp.available(c) & (speed > 0)
        psd = sp.psd[c][ok]
        floor = block_floor(psd, dof=dof)
        data = np.sqrt(np.maximum(np.sum(psd[:, band], axis=1) - np.sum(floor[:, band], axis=1), 0) * df)
        emp = model_rms(fit.model, d, sp.speed[ok], f_max=sp.band_limit)
        exm = ext_rms[ok, CHANNEL_INDEX[c]]
        ranges = [r for x in fit.lines if x.direction == d for r in x.excluded_rpm]
        in_modes = np.zeros(ok.sum(), bool)
        for lo, hi in ranges:
            in_modes |= (rpm[ok] >= lo) & (rpm[ok] <= hi)
        def err(model):
            m = in_modes & (data > 0)
            return float(np.sqrt(np.mean(((model[m] - data[m]) / data[m]) ** 2))) if m.any() else float("nan")
        out[d] = {"speed_rpm": rpm[ok], "data": data, "empirical": emp, "extended": exm, "in_modes": in_modes,
                  "error_empirical": err(emp), "error_extended": err(exm), "runs": np.flatnonzero(ok)}
    return out


def unresolved_spans(fit: EmpiricalFit) -> list:
    """Spans of h, per direction, where the empirical fit ``fit`` detected lines it could not measure apart:
    candidate harmonics present in enough runs but dropped because no measurement was resolved from the other
    lines (a close pair, h = 5.37 and 5.57 of the E wheel, on a short record: the fit's (2·line_half_width + 1)-bin
    power windows overlap at every speed).  Candidates closer than that window at the top speed are one span;
    each span is widened by the fit's tolerance ε on h.  Returns [{"direction", "h_min", "h_max"}]: the model
    file's ``analytical.fit.unresolved_lines``, which ``rwadist diagnose`` reads (a line found there is the
    wheel's own content the model's fit could not measure, not an effect)."""
    eps = float(fit.settings.get("epsilon", FitSettings.epsilon))
    half = int(fit.settings.get("line_half_width", FitSettings.line_half_width))
    sp = fit.spectra
    f_spin = float(np.max(np.abs(sp.speed))) / (2 * np.pi) if np.size(sp.speed) else 0.0
    close = max(eps, (2 * half + 1) * sp.df / f_spin) if f_spin > 0 else eps
    out = []
    for d in sorted({b.direction for b in fit.bins}):
        hs = sorted(b.h for b in fit.bins if b.direction == d and not b.kept
                    and b.reason.startswith("no measurement resolved"))
        spans: list[list[float]] = []      # [h_min, h_max] of each run of close lost lines
        for h in hs:
            if spans and h - spans[-1][1] < close:
                spans[-1][1] = h
            else:
                spans.append([h, h])
        out += [{"direction": d, "h_min": float(lo - eps), "h_max": float(hi + eps)} for lo, hi in spans]
    return out


def to_model(efit: ExtendedFit, fit: EmpiricalFit):
    """A model file for the extended fit: the analytical section, and as harmonics the fitted
    forcing lines (each radial one split into its co- and counter-rotating parts where both carry
    power), which is what :func:`rwadist.extended.lines_from_model` reads back.  The forcing
    coefficient equals the hard-mounted amplitude C·Ω² wherever the suspension is rigid."""
    from copy import deepcopy

    model = deepcopy(fit.model)
    se = efit.rel_stderr

    def n_points(ln) -> int:
        """Measurements of the line the least squares fitted ``ln`` to (an imbalance's h is 1 exactly)."""
        near = [x for x in efit.measured if x.direction == ln.direction and abs(x.h - ln.h) <= ext.IMBALANCE_H_TOL]
        return int(min(near, key=lambda x: abs(x.h - ln.h)).speed.size) if near else 0

    for d in model.empirical:
        model.empirical[d] = [
            Harmonic(h=round(ln.h, 4), C=ln.C, C_stderr=ln.C * se.get(f"C[{ln.direction},{ln.h:g},{ln.sense}]", np.nan),
                     sense=ln.sense if d in RADIAL else None, n_points=n_points(ln))
            for ln in efit.lines if ln.direction == d]
    analytical = ext.params_to_dict(efit.params)
    analytical["fit"] = {"zeta": efit.zeta, "identified": efit.identified,
                         "rel_stderr": efit.rel_stderr, "residual_db_near_mode": efit.residual_db,
                         "senses": {f"{d} h={h:.4g}": {"sense": s_, "co_fraction": fr}
                                    for (d, h), (s_, fr) in efit.senses.items()}, "notes": efit.notes}
    analytical["unconstrained"] = list(efit.unconstrained) + [DAMPING_NAME[m] for m in efit.zeta_bounds]
    analytical["fit"] |= damping_record(efit.zeta_bounds, efit.zeta_interval)
    unresolved = unresolved_spans(fit)
    if unresolved:
        analytical["fit"]["unresolved_lines"] = unresolved
    if efit.stand is not None:
        # the fixture's resonance is not the wheel's: kept out of its model, recorded for the user (a mode of the wheel's
        # structure on one direction is the wheel's: ``rwadist diagnose`` names it as a fixed_resonance of its model)
        key = "test_stand" if efit.stand_direction is None else "structure_mode"
        analytical["fit"][key] = dict(stand_record(efit.stand),
                                      **({} if efit.stand_direction is None else {"direction": efit.stand_direction}),
                                      **({} if efit.stand_on is None else {"channels": list(efit.stand_on)}))
        if efit.more_stands:    # the further fixture resonances fitted with it (two fixtures on one stand)
            analytical["fit"]["more_test_stands"] = [stand_record(k) for k in efit.more_stands]
    if efit.per_unit:
        analytical["fit"]["per_unit"] = ("mass and radius not given: mass_kg = 1 and I_rr = 1 are units, the "
                                         "stiffnesses and damping are per unit mass / transverse inertia")
    model.analytical = analytical
    model.provenance = dict(model.provenance, extended_fit="rwadist fit --extended: harmonics are the fitted "
                            "forcing lines of the extended model")
    return model


def stand_record(stand: tuple) -> dict:
    """A fitted stand (f_r Hz, ζ, peak gain[, gain above]) as the model file records it."""
    f_r, zeta, gain, *above = stand
    return {"f_Hz": f_r, "zeta": zeta, "peak_gain": gain, "gain_above": above[0] if above else 1.0}


def unconstrained_warning(model, source: str, use: str) -> str | None:
    """The warning a command prints when it uses ``model`` whose ``analytical.unconstrained`` lists modes
    (the extended fit could not identify them: their values are starting values, or values the fit could not tell
    apart from a test-stand resonance, as its notes say) or held dampings (zeta_<mode>: located modes whose damping is
    held inside the bounds the data allow, :mod:`rwadist.extended_fit_damping`); None otherwise.

    source : where the model came from (file name), for the message.  use : what the command does with it.
    """
    analytical = getattr(model, "analytical", None) or {}
    listed = analytical.get("unconstrained") or []
    if not listed:
        return None
    modes = [m for m in listed if m not in DAMPING_NAME.values()]
    held = [m[len("zeta_"):] for m in listed if m not in modes]
    text = [f"the extended fit could not identify {'this mode' if len(modes) == 1 else 'these modes'} from the test "
            f"data; {use} uses {'its' if len(modes) == 1 else 'their'} starting values or values not told apart from "
            "a test stand (see the model's analytical.fit.notes; measure a speed range whose lines cross the mode, or "
            "give the mode from another source)"] if modes else []
    # a held damping: the mode is located, its ζ a value inside what the data allow (no speed on a crossing's peak)
    text += [f"the damping of {', '.join(held)} is held inside the bounds the data allow (analytical.fit.zeta_bounds), "
             f"not measured: no speed sits on a line's crossing of that mode, and {use} uses the held value"] if held else []
    return f"warning: {source}: analytical.unconstrained = {list(listed)}: " + "; ".join(text)
