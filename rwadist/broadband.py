"""Stochastic broadband disturbance PSD over a wheel-speed distribution (Melody's model).

Thesis §1.3 and Fig. 1-4 block (e): the wheel speed Ω is a random variable with a
density p_Ω; the discrete harmonic lines of the steady model are smeared into a PSD.

Derivation.  At a fixed speed Ω a line i is ``x_c(t) = Re(A_ic(Ω) e^{i(2π f_i t + α_i)})``
in channel c, f_i = h_i|Ω|/2π, α_i uniform and independent between lines (thesis App. B,
Eq. B.12: the autocorrelation of the empirical model is Σ_i C_i²Ω⁴/2 · cos(2π f_i τ), the
cross terms i ≠ j average out).  Its one-sided cross-spectral density between channels a, b
is a line of weight ``σ_ab,i(Ω) = A_ia conj(A_ib) / 2`` at f_i; for a = b the weight is the
variance ``σ_i²(Ω) = |A_i(Ω)|²/2`` (empirical model: C_i²Ω⁴/2).  With Ω random and
independent of the phases, the expected spectrum is the speed average of the lines::

    S_ab(f) = Σ_i ∫ p_Ω(Ω) σ_ab,i(Ω) δ(f − h_i|Ω|/2π) dΩ
            = Σ_i Σ_{Ω: h_i|Ω|/2π = f} σ_ab,i(Ω) p_Ω(Ω) |dΩ/df|,      |dΩ/df| = 2π/h_i,

the inner sum running over both roots Ω = ±2πf/h_i inside the support (bidirectional
operation: a negative speed puts its lines at the same |frequency|, with the radial x/y
phase relation and the extended model's whirl response of the opposite spin).  Parseval:
∫S_aa df = E_Ω[Σ_i σ_i²(Ω)], the speed-averaged mean square.  Melody's empirical model
uses A = C Ω² (no modes); the extended model puts the modal amplification inside the
integral: A_i(Ω) = :func:`rwadist.extended.steady_lines`, which carries |H(f, Ω)|² of the
rotor's speed-dependent whirl modes -- Melody's model cannot.

Evaluation (exact per bin, no speed grid; :mod:`rwadist.broadband_bins`).  The PSD of bin k
(centred on f_k = k·df, width df) is the closed form's mean over the bin, (1/df)∫_bin S(f) df: the
line power of the speeds whose line falls in the bin.  On a branch of constant spin sign a line's
amplitude is fixed channel patterns times scalar functions of |Ω|, so the CSD is a sum of fixed
Hermitian matrices times scalar densities, evaluated as one matrix product; each density's bin
values are exact (a power law C·Ω² on a uniform or histogram law in closed form; otherwise
Gauss–Legendre below the narrowest resonance and the law's scale, relative error < 1e-12).
Σ_k S_k df equals the speed-averaged mean square of the lines inside [0, f_max + df/2] to rounding.
Cost O(n_freq × lines); memory the output and the densities (at most half its size), never a
speeds × frequencies array.  (Until issue 37 the speed support was cut into cells whose power was
spread over their frequency interval: 2000 cells left ~1e-7 of the mean square and ~1e-3 of a
bin; that result converges to this one as 1/cells².)

Coherence.  Within one wheel the channels of a line are coherent (radial x and y 90°
apart from the complex amplitudes; in the extended model a radial force line also gives
the lever-arm torque, and the static and dynamic imbalance lines are one coherent source
at their relative phase).  Different lines of one wheel, and the empirical model's
different directions, have independent random phases (thesis App. B; the virtual test
stand draws them independently too).  Different wheels are independent.  Tied speeds
(:class:`Member` with a ratio) change nothing by themselves -- the PSD depends only on each
wheel's marginal speed law and the line phases are random per wheel -- so cross-wheel terms
appear only with ``phase_lock``: the tied wheels are then identical rotors whose line phases
are equal up to the rotor-angle offset δ (factor e^{i·sign(Ω)·h·δ}, a time shift); their
amplitudes add coherently (in the spacecraft frame) before the outer product, so
cross-wheel terms appear exactly where their lines coincide.

Convention: ``csd[k, a, b] = E[X_a conj(X_b)]`` one-sided (the matrix E[X X^H],
Hermitian positive semidefinite); scipy.signal.csd(x_a, x_b) returns its conjugate.
Units: N²/Hz, N·(N·m)/Hz, (N·m)²/Hz; frequencies Hz; speeds rad/s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import extended as ext
from . import schema
from .data import DataError
from .effects.actions import LineFilter, LineLaw, LineModulation, NoiseFloor, SpeedModulation, of_effects
from .model import WheelModel
from .presets import preset
from .resonance import resonance
from .speed_laws import (  # noqa: F401
    PDF_RTOL,
    Histogram,
    TruncatedNormal,
    Uniform,
    _check_range,
    from_time_profile,
    histogram_from_centres,
    law_from_csv,
    law_from_spec,
    speed_cells,
)
from .units import CHANNELS, RAD_S_TO_RPM

#: Upper-triangle channel pairs (a <= b), 21 of them.
PAIRS = tuple((a, b) for a in range(6) for b in range(a, 6))
_PAIR_A = np.array([p[0] for p in PAIRS])
_PAIR_B = np.array([p[1] for p in PAIRS])
#: Co-rotating radial harmonics with |h − 1| at most this are the imbalances the extended
#: model replaces (one rule for every path: :data:`rwadist.extended.IMBALANCE_H_TOL`).
IMBALANCE_H_TOL = ext.IMBALANCE_H_TOL
_CROSS_UNIT = {(0, 0): "N2", (0, 1): "N2m", (1, 1): "Nm2"}


# =========================================================================== line sources

@dataclass
class WheelLines:
    """The coherent line sources of one wheel, each with its harmonic number.

    kind : 'empirical' (Melody: A = C·Ω², no modes) or 'extended' (closed-form steady response).
    h : (n_sources,) harmonic numbers.  labels : one per source.
    For 'empirical', ``spec`` is a list of (direction, C kg·m or kg·m², mode) with mode one of
    'co', 'counter', 'x', 'y', 'axial'.  For 'extended', ``params`` and ``groups`` (a list of
    lists of :class:`rwadist.extended.Line`, the lines of one group adding coherently).
    """

    kind: str
    h: np.ndarray
    labels: list
    spec: list = field(default_factory=list)
    params: ext.ExtendedParams | None = None
    groups: list = field(default_factory=list)
    name: str = "wheel"
    #: source index -> (amplitude_ref N or N·m, omega_ref rad/s, exponent p): the source's amplitude
    #: goes as amplitude_ref·(|Ω|/omega_ref)^p instead of C·Ω² (a diagnosed ``amplitude_law``)
    laws: dict = field(default_factory=dict)
    #: broadband floors (channel index, f knots Hz, psd_ref unit²/Hz, omega_ref rad/s, exponent p):
    #: S(f, Ω) = psd_ref(f)·(|Ω|/omega_ref)^p, incoherent with everything (a diagnosed ``broadband_floor``)
    floors: list = field(default_factory=list)
    #: wheel-mode resonances (directions, f_r Hz, ζ, peak gain) multiplying the lines of those
    #: directions by H(f) (a diagnosed ``fixed_resonance`` with role ``wheel_mode``)
    resonances: list = field(default_factory=list)
    #: source index -> fixed frequency offset, Hz: the source sits at h|Ω|/2π + offset (a sideband of a
    #: diagnosed ``sidebands`` effect, ±f_mod from its carrier)
    offsets: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.labels)

    def freqs(self, w, idx=None) -> np.ndarray:
        """(n_speeds, n_sel) line frequencies, Hz, at wheel speeds ``w`` (rad/s): |h|Ω|/2π + offset|."""
        idx = np.arange(len(self)) if idx is None else np.asarray(idx)
        off = np.array([self.offsets.get(int(i), 0.0) for i in idx])
        return np.abs(self.h[idx][None, :] * np.abs(np.asarray(w, float))[:, None] / (2 * np.pi) + off[None, :])

    def _source_C(self, i) -> float:
        return self.spec[i][1] if self.kind == "empirical" else self.groups[i][0].C

    def _law_factor(self, w, idx) -> np.ndarray:
        """(n_speeds, n_sel) factor turning C·Ω² into the diagnosed amplitude law (1 without one),
        times the diagnosed wheel-mode resonances of the source's direction."""
        fac = np.ones((w.size, idx.size), dtype=complex)
        for dirs, f_r, zeta, g, *above in self.resonances:
            for j, i in enumerate(idx):
                d = self.spec[int(i)][0] if self.kind == "empirical" else self.groups[int(i)][0].direction
                if d in dirs:
                    H = resonance(self.freqs(w, [i])[:, 0], f_r, zeta, g, *above)
                    fac[:, j] *= np.where(w < 0, np.conj(H), H)   # a real filter at negative frequency
        for j, i in enumerate(idx):
            if int(i) in self.laws:
                a_ref, w_ref, p = self.laws[int(i)]
                C = self._source_C(int(i))
                with np.errstate(divide="ignore", invalid="ignore"):
                    fac[:, j] = np.where(w != 0, a_ref * (np.abs(w) / w_ref) ** p / (C * w**2), 0.0)
        return fac

    def amplitudes(self, omega, idx=None) -> np.ndarray:
        """Complex channel amplitudes (n_speeds, n_sel, 6) at speeds ``omega`` (rad/s, signed) of the
        sources ``idx`` (default all): channel c is Re(A_c e^{i 2π f t}), f = h|Ω|/2π, N or N·m."""
        w = np.atleast_1d(np.asarray(omega, float))
        idx = np.arange(len(self)) if idx is None else np.atleast_1d(idx)
        out = np.zeros((w.size, idx.size, 6), dtype=complex)
        if self.kind == "empirical":
            s = np.where(w < 0, -1.0, 1.0)
            for j, i in enumerate(idx):
                d, C, mode = self.spec[i]
                a = C * w**2
                base = {"radial_force": 0, "radial_torque": 3, "axial_force": 2, "axial_torque": 5}[d]
                if mode == "axial":
                    out[:, j, base] = a
                elif mode == "x":
                    out[:, j, base] = a
                elif mode == "y":
                    out[:, j, base + 1] = a
                else:
                    out[:, j, base] = a
                    out[:, j, base + 1] = (-1j if mode == "co" else 1j) * s * a
            return out * self._law_factor(w, idx)[..., None] if (self.laws or self.resonances) else out
        if self.params is None:
            raise ValueError(f"{self.name}: extended line sources without their ExtendedParams (params)")
        flat, owner = [], []
        for j, i in enumerate(idx):
            for ln in self.groups[i]:
                flat.append(ln)
                owner.append(j)
        _, amp = ext.steady_lines(self.params, flat, w)
        for k, j in enumerate(owner):
            out[:, j, :] += amp[:, k, :]
        return out * self._law_factor(w, idx)[..., None] if (self.laws or self.resonances) else out


def _copy_source(src: WheelLines, i: int, label: str, scale: float = 1.0, law=None, f_off: float = 0.0) -> None:
    """Append a copy of source ``i`` (its own random phase) with its amplitude times ``scale``: an empirical
    source's C and an extended group's lines' C scaled (and the A_ref of its amplitude law, so the law keeps
    its shape), or with the amplitude law ``law`` = (A_ref, omega_ref, p) instead; ``f_off`` (Hz) is added
    to the copy's frequency offset."""
    from dataclasses import replace

    j = len(src)
    src.h = np.append(src.h, src.h[i])
    if src.kind == "empirical":
        d, C, mode = src.spec[i]
        src.spec.append((d, C * scale, mode))
    else:
        src.groups.append([replace(ln, C=ln.C * scale) for ln in src.groups[i]])
    src.labels.append(label)
    if src.offsets.get(i, 0.0) + f_off:
        src.offsets[j] = src.offsets.get(i, 0.0) + f_off
    if law is not None:
        src.laws[j] = law
    elif i in src.laws:
        a_ref, w_ref, p = src.laws[i]
        src.laws[j] = (a_ref * scale, w_ref, p)


def _source_direction(src: WheelLines, i: int) -> str:
    return src.spec[i][0] if src.kind == "empirical" else src.groups[i][0].direction


def apply_effects(src: WheelLines, model: WheelModel) -> WheelLines:
    """Attach a model file's diagnosed effects (``rwadist diagnose``) to its sources, as the generic actions their
    elements say they are (:mod:`rwadist.effects.actions`; an effect that is a measurement artefact or a record --
    a test stand's resonance, a load-cell offset, a missing harmonic already among the harmonics -- has none):

    * a line law (an amplitude law) rescales the matching harmonic (same direction, |Δh| < 1e-3), a noise floor
      adds its floor to its channel, a line filter (a wheel mode) amplifies its directions' lines;
    * then (so a carrier's amplitude law carries over to its sidebands) a line modulation (depth m, f_mod): the
      matching sources get two copies of amplitude m/2 each, with their own random phases (lines at different
      frequencies: no cross-spectrum with the carrier) and the carrier's channel pattern (an amplitude-modulated
      rotating vector still rotates), at h|Ω|/2π ± f_mod (:attr:`WheelLines.offsets`; a lower sideband below 0 Hz
      folds to |f|).  The added mean square m²/2 of the carrier's is exact (Parseval);
    * then a speed modulation (ΔΩ(|Ω|) = delta_omega·(|Ω|/omega_ref)^q at f): the phase modulation only moves each
      line's power to f_i + k·f (Σ_k J_k(β)² = 1), a redistribution over a few f that a PSD over a speed law does not
      resolve: nothing is moved.  The amplitude modulation of an empirical line C·Ω(t)² raises its mean square by the
      factor E_θ[(1 + ε sin θ)⁴] = 1 + 3ε² + 3ε⁴/8, ε = ΔΩ/|Ω|; that is added exactly, as two sources per line with
      amplitude laws √3·C·ΔΩ·|Ω| (exponent 1 + q) and √(3/8)·C·ΔΩ² (exponent 2q).  Sources with an amplitude law or
      of the extended model (not ∝ Ω²) get no amplitude term (it is O(ε²): 3·10⁻⁴ at ε = 1 %).

    The effects are read by the schema (:func:`rwadist.schema.parse_effects`; typed already when the
    model came from a file): :class:`rwadist.schema.ModelError` naming ``effects[i].<field>`` on a bad
    entry, as every other consumer."""
    for a in of_effects(schema.parse_effects(model.effects)):
        n0 = len(src)
        if isinstance(a, LineLaw):
            for i in range(len(src)):
                if _source_direction(src, i) == a.direction and abs(src.h[i] - a.h) < 1e-3:
                    src.laws[i] = a.law
        elif isinstance(a, NoiseFloor):
            src.floors.append((a.channel, a.f_hz, a.psd_ref, a.omega_ref, a.exponent))
        elif isinstance(a, LineFilter):
            src.resonances.append((list(a.directions), *a.resonance))
        elif isinstance(a, LineModulation):
            m, f_m = a.depth, a.f_mod_hz
            for i in range(n0):
                if _source_direction(src, i) == a.direction and abs(src.h[i] - a.h) < 1e-3:
                    for sgn in (1.0, -1.0):
                        _copy_source(src, i, f"{src.labels[i]} sideband {sgn * f_m:+g} Hz", 0.5 * m, f_off=sgn * f_m)
        elif isinstance(a, SpeedModulation) and src.kind == "empirical":
            dw, w_ref, q = a.delta_omega, a.omega_ref, a.exponent
            for i in range(n0):
                if i in src.laws:
                    continue
                C = src.spec[i][1]
                _copy_source(src, i, f"{src.labels[i]} speed-ripple AM (eps^2)", law=(np.sqrt(3.0) * C * dw * w_ref,
                                                                                       w_ref, 1.0 + q))
                _copy_source(src, i, f"{src.labels[i]} speed-ripple AM (eps^4)", law=(np.sqrt(3.0 / 8.0) * C * dw**2,
                                                                                       w_ref, 2.0 * q))
    return src


def empirical_lines(model: WheelModel) -> WheelLines:
    """Melody's model of a :class:`~rwadist.model.WheelModel`: every harmonic of every direction is a
    source with its own random phase.  Radial harmonics turn with the rotor: x and y 90° apart,
    co-rotating unless the harmonic's ``sense`` is 'counter'; a 'planar' harmonic has no defined x/y
    phase relation in this model and becomes two independent sources (x and y), each C·Ω² -- so every
    radial channel carries C²Ω⁴/2, as the fit measured it."""
    h, labels, spec = [], [], []
    for d in ("radial_force", "radial_torque", "axial_force", "axial_torque"):
        for hm in model.harmonics(d):
            if d.startswith("axial"):
                modes = ["axial"]
            elif hm.sense == "planar":
                modes = ["x", "y"]
            else:
                modes = ["counter" if hm.sense == "counter" else "co"]
            for m in modes:
                h.append(float(hm.h))
                labels.append(f"{d} h={hm.h:g}" + ("" if m in ("co", "axial") else f" ({m})"))
                spec.append((d, float(hm.C), m))
    return apply_effects(WheelLines("empirical", np.array(h, float), labels, spec=spec, name=model.name), model)


def extended_lines(params: ext.ExtendedParams, lines) -> WheelLines:
    """Sources of the extended model: the imbalance lines form one coherent source (they sit on the
    same rotor at their relative ``phase``), every other :class:`~rwadist.extended.Line` is its own."""
    imb = [ln for ln in lines if ln.imbalance]
    others = [ln for ln in lines if not ln.imbalance]
    groups = ([imb] if imb else []) + [[ln] for ln in others]
    labels = (["imbalance h=1"] if imb else []) + [f"{ln.direction} h={ln.h:g} ({ln.sense})" for ln in others]
    h = np.array([g[0].h for g in groups], float)
    return WheelLines("extended", h, labels, params=params, groups=groups)


def extended_lines_from_model(model: WheelModel, source="<model>") -> WheelLines:
    """Extended sources of a model file: ``analytical`` parameters; the co-rotating radial
    harmonics within :data:`IMBALANCE_H_TOL` of h = 1 are replaced by the imbalances U_s, U_d
    (:func:`rwadist.extended.lines_from_model`, as the virtual stand does); the imbalance phases
    are those of :func:`rwadist.extended.imbalance_lines` (0, 0)."""
    params = ext.params_from_model(model, source)
    src = extended_lines(params, ext.lines_from_model(model, params, effects=False))   # apply_effects adds laws
    src.name = model.name
    return apply_effects(src, model)


def preset_lines(name: str, empirical: bool = False) -> WheelLines:
    """Sources of a virtual-stand preset (:func:`rwadist.presets.preset`): empirical from its
    harmonics, or extended from its ``extended_lines()`` with the dynamic imbalance at the preset's
    ``imbalance_phase`` ahead of the static one."""
    wheel = preset(name)
    if empirical:
        src = empirical_lines(wheel.to_model())
    else:
        if wheel.extended is None:
            raise DataError(name, "extended", "this preset has no extended parameters; use the empirical model "
                            "(`empirical`)")
        lines = [ext.Line(ln.direction, ln.h, ln.C, ln.sense,
                          wheel.imbalance_phase if (ln.imbalance and ln.direction == "radial_torque") else ln.phase,
                          ln.angle, ln.imbalance) for ln in wheel.extended_lines()]
        src = extended_lines(wheel.extended, lines)
    src.name = wheel.name
    return src


# =========================================================================== result

@dataclass
class BroadbandPSD:
    """One-sided cross-spectral density matrix on a uniform frequency grid.

    f : (n,) Hz, f[k] = k·df.  csd : (n, 6, 6) complex, csd[k, a, b] = E[X_a conj(X_b)] per Hz
    (channels Fx, Fy, Fz, Tx, Ty, Tz; N²/Hz, N·N·m/Hz, (N·m)²/Hz).  frame : 'wheel' or 'spacecraft'.
    meta : description (laws, wheels, model kind).
    """

    f: np.ndarray
    csd: np.ndarray
    frame: str = "wheel"
    meta: dict = field(default_factory=dict)

    @property
    def df(self) -> float:
        return float(self.f[1] - self.f[0])

    @property
    def psd(self) -> np.ndarray:
        """Auto-spectra (n, 6), real."""
        return np.real(np.einsum("kaa->ka", self.csd))

    def mean_square(self) -> np.ndarray:
        """∫S df per channel (rectangle rule on the bins: exact for the binned power)."""
        return self.psd.sum(axis=0) * self.df

    def rms(self) -> np.ndarray:
        return np.sqrt(self.mean_square())

    def cumulative_rms(self) -> np.ndarray:
        """(n, 6): sqrt of the power up to and including each bin (thesis Eq. 2.13)."""
        return np.sqrt(np.cumsum(self.psd, axis=0) * self.df)


def _transform_of(mounting):
    if mounting is None:
        return np.eye(6)
    T = getattr(mounting, "transform", mounting)
    T = np.asarray(T, float)
    if T.shape != (6, 6):
        raise ValueError(f"mounting transform must be 6x6, got {T.shape}")
    return T


@dataclass
class Member:
    """One wheel of a coherent group: its sources, 6×6 transform to the output frame (None: wheel
    frame), speed ratio to the group's speed (±1; −1 = spinning the other way), and rotor-angle
    offset ``phase_offset`` (rad) to the group's rotor angle (used only under phase lock)."""

    lines: WheelLines
    transform: object = None
    ratio: float = 1.0
    phase_offset: float = 0.0


def _freq_grid(f_max, n_freq):
    if not (math.isfinite(f_max) and f_max > 0):
        raise DataError("frequency grid", "fmax", f"must be > 0 Hz, got {f_max!r}")
    n_freq = int(n_freq)
    if n_freq < 2:
        raise DataError("frequency grid", "n_freq", f"must be >= 2, got {n_freq}")
    return np.linspace(0.0, f_max, n_freq)


def _check_fmax(groups, f_max):
    h_min = min(float(m.lines.h.min()) for members, law in groups for m in members if len(m.lines))
    w_max = max(max(abs(law.support[0]), abs(law.support[1])) for _, law in groups)
    f_first = h_min * w_max / (2 * np.pi)
    if f_max < f_first:
        raise DataError("frequency grid", "fmax", f"{f_max:g} Hz is below the first harmonic's highest "
                        f"frequency ({f_first:g} Hz: h = {h_min:g} at {w_max * RAD_S_TO_RPM:g} rpm); "
                        "the PSD would miss lines -- raise `fmax`")


def csd_groups(groups, f_max: float, n_freq: int = 20001, n_speeds: int | None = None, progress: bool = False,
               frame: str = "wheel", check_fmax: bool = True) -> BroadbandPSD:
    """The CSD of independent groups of coherent wheels: Melody's closed form integrated exactly over each
    frequency bin (:mod:`rwadist.broadband_bins`), no speed grid.

    groups : list of (members, law): ``members`` a list of :class:`Member` sharing one speed
        (each at ratio·Ω) and, when more than one, phase-locked (amplitudes add before the outer
        product); ``law`` the group's speed law (rad/s).
    f_max : top of the grid, Hz; n_freq : grid points (0 .. f_max).
    n_speeds : not used (every speed law has a density, integrated exactly); accepted so that callers written
        for the speed-cell method keep working.
    Raises DataError when f_max is below the top frequency of the lowest harmonic (``check_fmax``).
    """
    from .broadband_bins import closed_form_csd

    f = _freq_grid(f_max, n_freq)
    if check_fmax:
        _check_fmax(groups, f_max)
    for members, _ in groups:
        n_src = len(members[0].lines)
        if len(members) > 1 and any(len(m.lines) != n_src or not np.allclose(m.lines.h, members[0].lines.h)
                                    or m.lines.offsets != members[0].lines.offsets for m in members):
            raise DataError("wheels", "tie", "phase-locked wheels must use the same wheel model (same lines)")
    return BroadbandPSD(f=f, csd=closed_form_csd(groups, f, _transform_of, progress), frame=frame)


def broadband_psd(lines: WheelLines, law, f_max: float, n_freq: int = 20001, n_speeds: int = 2000,
                  mounting=None, progress: bool = False) -> BroadbandPSD:
    """Broadband CSD of one wheel with speed law ``law`` (rad/s); in the wheel frame, or in the
    spacecraft frame through ``mounting`` (an object with a 6×6 ``transform``, e.g.
    :class:`rwadist.mounting.Mounting`)."""
    out = csd_groups([([Member(lines, mounting)], law)], f_max, n_freq, n_speeds, progress,
                     frame="wheel" if mounting is None else "spacecraft")
    out.meta.update({"model": lines.kind, "wheel": lines.name, "law": repr(law)})
    return out


def expected_mean_square(lines: WheelLines, law, f_max: float | None = None, n_speeds: int = 4000) -> np.ndarray:
    """E_Ω[Σ_i |A_ic(Ω)|²/2] per channel (wheel frame) by Gauss–Legendre quadrature per cell
    (lines above ``f_max`` Hz excluded): the Parseval target of :func:`broadband_psd`."""
    lo_e, hi_e, _, _ = speed_cells(law, n_speeds)
    x, wq = np.polynomial.legendre.leggauss(4)
    total = np.zeros(6)
    for xi, wi in zip(x, wq):
        w = 0.5 * (lo_e + hi_e) + 0.5 * (hi_e - lo_e) * xi
        A = lines.amplitudes(w)
        p2 = np.abs(A) ** 2 / 2
        if f_max is not None:
            p2 = p2 * (lines.freqs(w) <= f_max)[..., None]
        total += np.einsum("s,sc->c", 0.5 * (hi_e - lo_e) * wi * law.pdf(w), p2.sum(axis=1))
    return total


# =========================================================================== envelope

@dataclass
class Envelope:
    """Worst-case line spectrum: ``amplitude[k, c]`` is the largest peak amplitude (N or N·m) of any
    line that can sit at f[k] for some speed in the range; ``table`` lists per source and channel the
    largest amplitude over the range and the speed (rpm) and frequency (Hz) where it occurs: dicts of ``wheel`` (index),
    ``line`` (index in its wheel's lines), ``source`` (its label), ``h``, ``channel``, ``max_amplitude`` (N or N·m),
    ``speed_rpm`` (signed) and ``f_Hz``, a channel the line does not reach left out
    (:func:`rwadist.psd_files.write_envelope_harmonics_csv` writes it)."""

    f: np.ndarray
    amplitude: np.ndarray
    table: list


def line_envelope(wheels, speed_range, f: np.ndarray, n_speeds: int = 4000) -> Envelope:
    """Worst-case envelope of the lines of ``wheels`` = [(WheelLines, transform or None), ...] over
    ``speed_range`` = (lo, hi) rad/s (signed), on the frequency grid ``f`` (Hz).

    Each source's amplitude is evaluated on a fine speed grid (per sign branch) and interpolated in
    frequency onto ``f``; the envelope is the maximum over sources, branches and wheels (a single
    wheel's line, not a sum)."""
    lo, hi = float(speed_range[0]), float(speed_range[1])
    _check_range("envelope speed range", lo, hi)
    f = np.asarray(f, float)
    if np.any(np.diff(f) < 0):                   # the line ranges are searched on an ascending grid
        order = np.argsort(f, kind="stable")
        env_sorted = line_envelope(wheels, speed_range, f[order], n_speeds)
        env_sorted.amplitude[order] = env_sorted.amplitude.copy()
        return Envelope(f=f, amplitude=env_sorted.amplitude, table=env_sorted.table)
    env = np.zeros((f.size, 6))
    table = []
    branches = []
    if hi > 0:
        branches.append(np.linspace(max(lo, 0.0), hi, n_speeds))
    if lo < 0:
        branches.append(np.linspace(min(hi, 0.0), lo, n_speeds))
    for wi, (lines, mounting) in enumerate(wheels):
        T = _transform_of(mounting)
        best = np.zeros((len(lines), 6))
        best_w = np.zeros((len(lines), 6))
        first = None
        for w in branches:
            A = np.abs(lines.amplitudes(w) @ T.T)                      # (S, L, 6)
            fw = lines.freqs(w)                                        # (S, L), increasing in S
            A_lines = np.ascontiguousarray(A.transpose(1, 0, 2))       # (L, S, 6): rows gathered per line
            # a line the other sign of speed puts at the same frequencies with the same amplitudes (bit for bit:
            # Melody's lines, whose amplitudes at -Ω are the conjugates of those at Ω) adds nothing to the envelope
            drawn = np.ones(len(lines), bool) if first is None else ~(
                np.all(fw == first[0], axis=0) & np.all(A == first[1], axis=(0, 2)))
            first = (fw, A) if first is None else first
            for i in np.flatnonzero(drawn).tolist():
                if not fw[-1, i] > fw[0, i]:
                    continue
                a, b = np.searchsorted(f, fw[0, i], side="left"), np.searchsorted(f, fw[-1, i], side="right")
                if b > a:
                    np.maximum(env[a:b], _interp_columns(f[a:b], fw[:, i], A_lines[i]), out=env[a:b])
            k = np.argmax(A, axis=0)                                   # (L, 6): speed of each line's peak
            val = np.take_along_axis(A, k[None], axis=0)[0]
            upd = val > best
            best = np.where(upd, val, best)
            best_w = np.where(upd, w[k], best_w)
        for i in range(len(lines)):
            for c, ch in enumerate(CHANNELS):
                if best[i, c] > 0:
                    table.append({"wheel": wi, "line": i, "source": lines.labels[i], "h": float(lines.h[i]),
                                  "channel": ch, "max_amplitude": float(best[i, c]),
                                  "speed_rpm": float(best_w[i, c] * RAD_S_TO_RPM),
                                  "f_Hz": float(lines.freqs([best_w[i, c]], [i])[0, 0])})
    return Envelope(f=f, amplitude=env, table=table)


def _interp_columns(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """np.interp(x, xp, fp[:, c]) of every column c at once (numpy's formula, its slopes computed once per interval:
    the same numbers); ``x`` ascending inside [xp[0], xp[-1]].  A non-increasing ``xp`` (a line folded below 0 Hz by
    an offset) goes to np.interp itself."""
    if np.any(np.diff(xp) <= 0):
        return np.stack([np.interp(x, xp, fp[:, c]) for c in range(fp.shape[1])], axis=1)
    # interval of each x (xp[j] <= x < xp[j + 1]) by merging the two sorted grids: j + 1 counts the xp <= x
    starts = np.bincount(np.searchsorted(x, xp[1:-1], side="left"), minlength=x.size + 1)[:x.size]
    j = np.cumsum(starts)
    slope = np.diff(fp, axis=0)
    slope /= np.diff(xp)[:, None]
    out = np.take(slope, j, axis=0)                     # np.take: rows gathered faster than by fancy indexing
    out *= (x - np.take(xp, j))[:, None]
    out += np.take(fp, j, axis=0)
    out[x.size - np.count_nonzero(x == xp[-1]):] = fp[-1]     # x at the grid's end (the last ones: x ascending)
    return out
