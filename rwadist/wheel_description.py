"""The wheel a virtual test measures: :class:`Mode` (a resonance amplifying lines) and :class:`WheelDescription`
(harmonics, modes, the extended rotor), light plain dataclasses apart from the test stand that synthesises records
from them (:mod:`rwadist.teststand`): the presets and every reader of a wheel's description import them without the
signal-processing stack the stand needs.  The physics of both is described in :mod:`rwadist.teststand`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import extended as ext
from .errors import ParameterError
from .model import Harmonic, WheelModel
from .resonance import resonance_response, smallest_peak
from .units import CHANNELS, DIRECTION_CHANNELS, rad_s_to_hz

# --------------------------------------------------------------------------- modes

@dataclass
class Mode:
    """A resonance that amplifies the harmonic lines on some channels.

    name : label, e.g. ``"rocking_backward"``.
    f0_hz : natural frequency at zero wheel speed, Hz (> 0).
    zeta : damping ratio (> 0); the -3 dB width of the peak is about 2ζ·f_mode.
    peak_gain : |gain| at the resonance (r = 1); > 1 amplifies.
    channels : channels it acts on (subset of Fx, Fy, Fz, Tx, Ty, Tz).
    whirl : 0 fixed frequency; +1 forward whirl; -1 backward whirl.
    inertia_ratio : a = I_zz/I_rr of the gyroscopic whirl law (thin disc: 2).
    gain_above : H far above the resonance (1: back to 1 on both sides; 0: a fixture spring's transmissibility,
        :mod:`rwadist.resonance`); peak_gain must then be at least |1 − gain_above|/(2ζ).
    """

    name: str
    f0_hz: float
    zeta: float
    peak_gain: float
    channels: tuple
    whirl: int = 0
    inertia_ratio: float = 2.0
    gain_above: float = 1.0

    def __post_init__(self):
        self.channels = tuple(self.channels)
        bad = [c for c in self.channels if c not in CHANNELS]
        if bad:
            raise ParameterError(f"mode {self.name!r}: unknown channel(s) {bad}; expected some of {list(CHANNELS)}")
        if not (np.isfinite(self.f0_hz) and self.f0_hz > 0):
            raise ParameterError(f"mode {self.name!r}: f0_hz must be > 0, got {self.f0_hz!r}")
        if not (np.isfinite(self.zeta) and self.zeta > 0):
            raise ParameterError(f"mode {self.name!r}: zeta must be > 0, got {self.zeta!r}")
        if not (np.isfinite(self.peak_gain) and self.peak_gain > 0):
            raise ParameterError(f"mode {self.name!r}: peak_gain must be > 0, got {self.peak_gain!r}")
        if self.whirl not in (-1, 0, 1):
            raise ParameterError(f"mode {self.name!r}: whirl must be -1, 0 or +1, got {self.whirl!r}")
        if self.whirl and not self.inertia_ratio >= 0:
            raise ParameterError(f"mode {self.name!r}: inertia_ratio must be >= 0, got {self.inertia_ratio!r}")
        if not np.isfinite(self.gain_above):
            raise ParameterError(f"mode {self.name!r}: gain_above must be a finite number, got {self.gain_above!r}")
        least = smallest_peak(self.zeta, self.gain_above)
        if self.peak_gain < least * (1 - 1e-9):
            raise ParameterError(f"mode {self.name!r}: peak_gain {self.peak_gain!r} is below {least:.6g}, the least a "
                                 f"resonance of zeta {self.zeta!r} reaching gain_above {self.gain_above!r} far above "
                                 "can have (|1 - gain_above|/(2 zeta))")

    def frequency_hz(self, omega):
        """Natural frequency (Hz) at wheel speed ``omega`` (rad/s, sign ignored); vectorised."""
        w = np.abs(np.asarray(omega, dtype=float))
        if self.whirl == 0:
            return np.full_like(w, float(self.f0_hz))
        half = 0.5 * self.inertia_ratio * rad_s_to_hz(w)
        return np.sqrt(half**2 + self.f0_hz**2) + self.whirl * half

    def gain(self, f_hz, omega):
        """Complex gain H(r), r = f_hz / f_mode(omega), of a line at ``f_hz`` (Hz, >= 0) with the
        wheel at ``omega`` (rad/s); ``f_hz`` and ``omega`` broadcast.  |H| = peak_gain at r = 1,
        H -> 1 far from the mode on both sides."""
        return self.response(np.abs(np.asarray(f_hz, dtype=float)) / self.frequency_hz(omega))

    def response(self, r):
        """H(r) at frequency ratio r = f / f_mode (:func:`rwadist.resonance.resonance_response`): (1 − r² + 2j·g·ζ·r) /
        (1 − r² + 2j·ζ·r) when ``gain_above`` is 1."""
        return resonance_response(r, self.zeta, self.peak_gain, self.gain_above)

    def crossing_speed_hz(self, h: float) -> float | None:
        """Wheel speed |Ω|/2π (Hz) at which harmonic ``h`` meets this mode (h·Ω_hz = f_mode), or None.

        Fixed mode: f0/h.  Whirl s = ±1: h·x = sqrt((a x/2)² + f0²) + s·a·x/2  =>  x = f0/sqrt(h(h - s·a)),
        which exists for the forward whirl only when h > a (the forward whirl rises with slope a);
        thesis Eq. 4.84: (ω∓)² = h·k_θ/(h·I_rr ± I_zz), Ω = ω/h.
        """
        if h <= 0:
            return None
        if self.whirl == 0:
            return self.f0_hz / h
        q = h * (h - self.whirl * self.inertia_ratio)
        if q <= 0:
            return None
        return self.f0_hz / np.sqrt(q)

    def to_json(self) -> dict:
        return {"name": self.name, "f0_hz": float(self.f0_hz), "zeta": float(self.zeta),
                "peak_gain": float(self.peak_gain), "channels": list(self.channels), "whirl": int(self.whirl),
                "inertia_ratio": float(self.inertia_ratio), "gain_above": float(self.gain_above)}


# --------------------------------------------------------------------------- wheel

@dataclass
class WheelDescription:
    """The truth a virtual test measures.

    name : wheel label.
    harmonics : direction -> list of (h, C) with C in SI per (rad/s)² (kg·m forces, kg·m² torques).
    modes : wheel structural modes (:class:`Mode`), applied when ``modes=True``.
    test_stand_modes : fixture resonances, applied when ``test_stand=True``.
    max_speed_rpm : speed range of the wheel, rpm (catalogue value).
    mass_kg, radius_m : flywheel mass (kg) and radius (m), if known.
    f_lim_hz : upper limit of uncorrupted data (Hz) when the stand resonates, else None.
    default_speeds_rpm : speeds of the reference steady test, rpm (None: no steady reference test).
    default_sample_rate : sample rate of the reference test, Hz.
    default_n_samples : samples per steady run of the reference test.
    default_sweep : keyword arguments of :func:`simulate_sweep` reproducing the reference sweep, or None.
    notes : free text (source of the numbers).
    extended : :class:`rwadist.extended.ExtendedParams` of the rotor for ``physics="extended"``, or None.
    senses : (direction, h) -> 'co' | 'counter' | 'planar', rotation sense of a radial harmonic in the
        extended physics (missing: 'co').  Keys use the harmonic numbers of ``harmonics``.
    imbalance_phase : fixed angle (rad) of the dynamic imbalance ahead of the static one; a property
        of the rotor (same in every run).
    modes_assumed : the suspension modes of ``extended`` are assumed (a catalogue datasheet wheel), not measured:
        :meth:`to_model` says so (``analytical.modes_assumed``).
    """

    name: str
    harmonics: dict
    modes: list
    test_stand_modes: list = field(default_factory=list)
    max_speed_rpm: float = 6000.0
    mass_kg: float | None = None
    radius_m: float | None = None
    f_lim_hz: float | None = None
    default_speeds_rpm: np.ndarray | None = None
    default_sample_rate: float = 3840.0
    default_n_samples: int = 8192
    default_sweep: dict | None = None
    notes: str = ""
    extended: ext.ExtendedParams | None = None
    senses: dict = field(default_factory=dict)
    imbalance_phase: float = 0.0
    modes_assumed: bool = False

    def __post_init__(self):
        clean = {}
        for d, items in self.harmonics.items():
            if d not in DIRECTION_CHANNELS:
                raise ParameterError(f"wheel {self.name!r}: unknown direction {d!r}; expected {list(DIRECTION_CHANNELS)}")
            pairs = [(float(h), float(C)) for h, C in items]
            for h, C in pairs:
                if not (np.isfinite(h) and h > 0 and np.isfinite(C) and C >= 0):
                    raise ParameterError(f"wheel {self.name!r}: {d}: need h > 0 and C >= 0, got h={h!r}, C={C!r}")
            clean[d] = pairs
        self.harmonics = clean
        senses = {}
        for key, sense in dict(self.senses).items():
            try:
                d, h = key
                h = float(h)
            except (TypeError, ValueError):
                raise ParameterError(f"wheel {self.name!r}: senses key {key!r} must be (direction, h)") from None
            if d not in DIRECTION_CHANNELS:
                raise ParameterError(f"wheel {self.name!r}: senses: unknown direction {d!r}")
            if sense not in ext.SENSES:
                raise ParameterError(f"wheel {self.name!r}: senses[{key!r}] = {sense!r}; expected one of {ext.SENSES}")
            senses[(d, h)] = sense
        self.senses = senses
        if self.extended is not None and not isinstance(self.extended, ext.ExtendedParams):
            raise ParameterError(f"wheel {self.name!r}: extended must be an ExtendedParams, got "
                             f"{type(self.extended).__name__}")
        self.imbalance_phase = float(self.imbalance_phase)
        if not np.isfinite(self.imbalance_phase):
            raise ParameterError(f"wheel {self.name!r}: imbalance_phase must be finite, got {self.imbalance_phase!r}")
        if self.default_speeds_rpm is not None:
            self.default_speeds_rpm = np.asarray(self.default_speeds_rpm, dtype=float)

    def h_and_C(self, direction: str):
        """Arrays (h, C) of a direction, SI (empty when the direction has none)."""
        pairs = self.harmonics.get(direction, [])
        return (np.array([p[0] for p in pairs], dtype=float), np.array([p[1] for p in pairs], dtype=float))

    def fundamental_C(self, direction: str) -> float:
        """C of the harmonic nearest h = 1 in ``direction`` (0 when the direction has none)."""
        h, C = self.h_and_C(direction)
        if h.size == 0:
            return 0.0
        return float(C[np.argmin(np.abs(h - 1.0))])

    def all_modes(self, modes: bool = True, test_stand: bool = True) -> list:
        return (list(self.modes) if modes else []) + (list(self.test_stand_modes) if test_stand else [])

    def truth_json(self) -> dict:
        """Harmonic lists in SI, JSON-ready: direction -> [{"h": .., "C": ..}, ...]."""
        return {d: [{"h": h, "C": C} for h, C in pairs] for d, pairs in self.harmonics.items()}

    def wheel_json(self) -> dict:
        doc = {"name": self.name, "max_speed_rpm": float(self.max_speed_rpm)}
        if self.mass_kg is not None:
            doc["mass_kg"] = float(self.mass_kg)
        if self.radius_m is not None:
            doc["radius_m"] = float(self.radius_m)
        if self.f_lim_hz is not None:
            doc["f_lim_hz"] = float(self.f_lim_hz)
        return doc

    def to_model(self) -> WheelModel:
        """The truth as a :class:`rwadist.model.WheelModel`: harmonics (no simple modes); with
        ``extended`` set also its ``analytical`` section and each radial harmonic's sense."""
        wheel = {k: v for k, v in self.wheel_json().items() if k != "name"}
        empirical: dict[str, list[Harmonic]] = {d: [] for d in DIRECTION_CHANNELS}
        for d, pairs in self.harmonics.items():
            radial = self.extended is not None and d in ("radial_force", "radial_torque")
            empirical[d] = [Harmonic(h=h, C=C, sense=self.senses.get((d, h), "co") if radial else None)
                            for h, C in pairs]
        analytical = ext.params_to_dict(self.extended) if self.extended is not None else None
        if analytical is not None and self.modes_assumed:
            # the coupling notebook's preset(...).to_model() dropped it, and a datasheet wheel ran through guessed modes
            analytical["modes_assumed"] = True
        return WheelModel(name=self.name, wheel=wheel, empirical=empirical, analytical=analytical,
                          provenance={"source": "rwadist.teststand.WheelDescription (simulation truth)",
                                      "notes": self.notes})

    def extended_lines(self) -> list:
        """Lines of the extended physics (phases 0): :func:`rwadist.extended.lines_from_model` of
        the harmonics with the radial h ≈ 1 ones (|h − 1| <= IMBALANCE_H_TOL) replaced by the
        imbalances of ``extended``, senses from ``senses``.  ValueError without ``extended``."""
        if self.extended is None:
            raise ParameterError(f"wheel {self.name!r} has no extended parameters (WheelDescription.extended); "
                             "physics='extended' needs them")
        return ext.lines_from_model(self.to_model(), self.extended, self.senses)

    def crossings(self, direction: str, speeds_rpm, modes: bool = True, test_stand: bool = True) -> list:
        """Where harmonics of ``direction`` meet the modes acting on its channels.

        speeds_rpm : speeds (rpm) whose |range| is searched: [min|s|, max|s|], or [0, max|s|] when the
        speeds change sign.  Returns a list of dicts {h, mode, whirl, speed_rpm, f_hz} sorted by speed,
        speed_rpm >= 0 being the |wheel speed| at which h·|Ω|/2π equals the mode frequency f_hz.
        """
        s = np.asarray(speeds_rpm, dtype=float).ravel()
        if s.size == 0:
            return []
        lo = 0.0 if (s.min() <= 0.0 <= s.max()) else float(np.abs(s).min())
        hi = float(np.abs(s).max())
        chans = set(DIRECTION_CHANNELS[direction])
        h_arr, _ = self.h_and_C(direction)
        out = []
        for mode in self.all_modes(modes, test_stand):
            if not chans & set(mode.channels):
                continue
            for h in h_arr:
                x = mode.crossing_speed_hz(float(h))
                if x is None:
                    continue
                rpm = 60.0 * x
                if lo <= rpm <= hi:
                    out.append({"h": float(h), "mode": mode.name, "whirl": mode.whirl, "speed_rpm": float(rpm),
                                "f_hz": float(h * x)})
        out.sort(key=lambda d: (d["speed_rpm"], d["h"]))
        return out
