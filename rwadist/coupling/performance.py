"""Performance prediction: harmonic lines and broadband floors of several wheels through the coupled
spacecraft, side by side with the three practices of thesis Table 5.1.

Method (frequency domain, exact for steady lines; the same physics as
:func:`rwadist.coupling.assemble.assemble`, checked against it in the tests).  At a line of wheel k at
frequency f, with plant accelerance G(f) and performance map P(f) (per interface load), each
wheel i's inverted component ``f_i = Zc_i a_i + B_i w_i`` mounted by Mt_i, the plant interface
loads u solve::

    (I − Σ_i Mt_iᵀ Zc_i Mt_i G) u = Mt_kᵀ F_k            y = P u

where F_k = B_k w_k are wheel k's hard-mounted line loads, i.e.
:func:`rwadist.extended.steady_lines` — the blocked loads are all the coupled answer needs
besides the wheels' dynamic masses.  Practices: 'i' u = Mt_kᵀ F_k; 'ii' Zc_i replaced by the
rigid mass −M6_i; 'iii' F_k replaced by B_k F_k (measured loads fed as free excitation).

Line phasors: channel = Re(Y e^{i2πft}); lines of one wheel with the same harmonic number (and
the same fixed frequency offset: a diagnosed sideband sits at |hΩ/2π ± f_mod|) are coherent
(their phasors add); lines of different harmonic numbers or offsets and of different wheels are
taken as incoherent (powers add): RMS = sqrt(Σ |Y|²/2).  Each group is evaluated at its own
frequency (plant, wheel dynamic mass and blocked loads alike).

Diagnosed effects that are not lines of the extended model (``rwadist diagnose``, read by
:func:`wheel_spec_from_model` as their elements' actions, :mod:`rwadist.effects.actions`):

* a speed modulation (:class:`rwadist.extended_ripple.Ripple`): the wheel speed is Ω0 + ΔΩ sin 2πf_r t; every line
  becomes lines at its frequency + m·f_r with the complex coefficients of
  :func:`rwadist.extended_ripple.ripple_lines` (phase modulation of the rotor angle, amplitude modulation of
  a(|Ω|)), each evaluated through the wheel's modes and the coupled plant at its own frequency.  The
  coefficients act per line before the lines of one (h, offset) group are summed (they share the ripple);
  the groups are then (h, offset, m).  Neglected: the imbalance's tangential term and the ripple's
  modulation of the gyroscopic dynamics (see ripple_lines).
* a broadband floor (:class:`Floor`): a blocked (hard-mounted) load PSD S_c(f, Ω) on channel c of the
  wheel, incoherent with everything.  Its output PSD is Σ_wheels Σ_c |T_{y,c}(f)|² S_c(f, Ω·speed_scale),
  T the same interface equation with F_k = e_c (:func:`floor_responses`); its mean square adds to the
  lines' in :func:`jitter_vs_speed` and its PSD to :func:`output_psd`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rwadist import extended as ext
from rwadist import extended_ripple as ripple_mod
from rwadist import schema
from rwadist.effects.actions import NoiseFloor, of_effects
from rwadist.schema import ModelError
from rwadist.units import CHANNELS, RAD_S_TO_RPM

from . import geometry, rigid_practice
from .assemble import PRACTICES
from .components import Plant, wheel_rigid_mass_matrix
from .errors import CouplingError, SingularInterfaceError
from .gyro_split import FloorSolver, wheel_split
from .interface import _apply_left, _interface_matrix, _wheel_frf, rigid_wheel_frf  # noqa: F401  (rigid_wheel_frf: public here)
from .line_groups import grouped_lines_blocked

# ----------------------------------------------------------------------------- broadband floors

@dataclass(frozen=True, eq=False)
class Floor:
    """A broadband floor of one load channel of a wheel (a diagnosed noise floor): the blocked
    load PSD S(f, Ω) = interp(f; f_hz, psd_ref; 0 outside)·(|Ω|/omega_ref)^exponent, one-sided, unit²/Hz.

    channel : 0..5 (Fx, Fy, Fz, Tx, Ty, Tz, wheel frame).  f_hz : knots, Hz (>= 0, increasing, >= 2).
    psd_ref : PSD at the knots at Ω = omega_ref, N²/Hz or (N·m)²/Hz (>= 0).  omega_ref : rad/s (> 0).
    exponent : speed exponent p (>= 0)."""

    channel: int
    f_hz: np.ndarray
    psd_ref: np.ndarray
    omega_ref: float
    exponent: float = 0.0

    def __post_init__(self):
        f = np.asarray(self.f_hz, dtype=float).ravel()
        s = np.asarray(self.psd_ref, dtype=float).ravel()
        if self.channel not in range(6):
            raise CouplingError(f"Floor.channel must be 0..5 ({', '.join(CHANNELS)}), got {self.channel!r}")
        if f.size < 2 or not np.all(np.isfinite(f)) or f[0] < 0 or np.any(np.diff(f) <= 0):
            raise CouplingError("Floor.f_hz must be >= 2 finite, non-negative, strictly increasing frequencies")
        if s.shape != f.shape or not np.all(np.isfinite(s)) or np.any(s < 0):
            raise CouplingError(f"Floor.psd_ref must be {f.size} finite values >= 0 (one per knot)")
        if not (math.isfinite(self.omega_ref) and self.omega_ref > 0):
            raise CouplingError(f"Floor.omega_ref must be > 0, got {self.omega_ref!r}")
        if not (math.isfinite(self.exponent) and self.exponent >= 0):
            raise CouplingError(f"Floor.exponent must be finite and >= 0, got {self.exponent!r}")
        object.__setattr__(self, "f_hz", f)
        object.__setattr__(self, "psd_ref", s)

    def psd(self, f_hz, omega) -> np.ndarray:
        """S (n_speeds, n_f) at frequencies ``f_hz`` (Hz) and wheel speeds ``omega`` (rad/s)."""
        return self.gain(omega)[:, None] * self.shape(f_hz)[None, :]

    def shape(self, f_hz) -> np.ndarray:
        """The PSD at omega_ref at frequencies ``f_hz`` (Hz): the knots' piecewise-linear interpolant, 0 outside."""
        return np.interp(np.asarray(f_hz, dtype=float), self.f_hz, self.psd_ref, left=0.0, right=0.0)

    def gain(self, omega) -> np.ndarray:
        """(|Ω|/omega_ref)^exponent (n_speeds,) at wheel speeds ``omega`` (rad/s): S(f, Ω) = gain(Ω)·shape(f)."""
        return (np.abs(np.atleast_1d(np.asarray(omega, dtype=float))) / self.omega_ref) ** self.exponent

    def support(self):
        """(lo, hi) Hz outside which the floor is zero, or None for an all-zero floor."""
        nz = np.nonzero(self.psd_ref > 0)[0]
        if nz.size == 0:
            return None
        return float(self.f_hz[max(nz[0] - 1, 0)]), float(self.f_hz[min(nz[-1] + 1, self.f_hz.size - 1)])


class CouplingModelError(ModelError, CouplingError):
    """A bad model-file entry read by the coupling kit: the schema's one :class:`rwadist.schema.ModelError`
    (same message in every consumer), also a :class:`CouplingError`.

    Raised as a ModelError (``CouplingModelError(source, field, problem)`` or ``CouplingModelError(message)``), it
    keeps the attributes a :class:`rwadist.ParameterError` promises: ``parameter`` None (a file's entry, no
    function parameter to blame) and ``problem`` always a string (the message when no field is named)."""

    problem: str

    def __init__(self, source: object, field: str | None = None, problem: str | None = None):
        super().__init__(source, field, problem)
        self.parameter = None
        self.problem = str(self) if problem is None else problem


def floors_from_effects(effects, source: str = "<model>") -> tuple:
    """The :class:`Floor` s of a model file's ``effects`` list (dicts or typed effects): one per broadband floor its
    elements say the wheel has (:class:`rwadist.effects.actions.NoiseFloor`: one per channel an entry names, a channel
    named twice once).  Read by the schema (:func:`rwadist.schema.parse_effects`): :class:`CouplingModelError` naming
    ``effects[i].<field>`` on a bad entry."""
    actions = of_effects(schema.parse_effects(effects, source, CouplingModelError))
    return tuple(Floor(a.channel, a.f_hz, a.psd_ref, a.omega_ref, a.exponent) for a in actions
                 if isinstance(a, NoiseFloor))


# ----------------------------------------------------------------------------- wheels

@dataclass(frozen=True, eq=False)
class WheelSpec:
    """One wheel on the plant.  params: extended-model parameters; lines: its forcing lines
    (:class:`rwadist.extended.Line`); mount: where it sits; housing mass (kg) and inertia
    (kg·m², about the interface point); speed_scale: this wheel's speed = speed_scale × the
    sweep speed (e.g. −1 for a wheel spinning the other way, 0.9 for a slower one).
    floors: its broadband floors (:class:`Floor`, blocked loads, incoherent); ripple: its speed
    ripple (:class:`rwadist.extended_ripple.Ripple`) or None.  hard_mounted: the suspension is rigid (the rotor
    moves with the housing; a datasheet wheel whose modes are only assumed runs so by default): its blocked
    loads are the lines' free loads (C·Ω², U_s·Ω², U_d·Ω², the radial force with its lever arm ``height``)
    and its dynamic mass the rigid wheel's with the rotor's gyroscopic coupling (:func:`rigid_wheel_frf`)."""

    params: ext.ExtendedParams
    lines: tuple
    mount: geometry.Mount = field(default_factory=geometry.Mount)
    housing_mass: float = 0.0
    housing_inertia: tuple = (0.0, 0.0, 0.0)
    speed_scale: float = 1.0
    name: str = "wheel"
    floors: tuple = ()
    ripple: ripple_mod.Ripple | None = None
    hard_mounted: bool = False

    def __post_init__(self):
        object.__setattr__(self, "lines", tuple(self.lines))
        object.__setattr__(self, "floors", tuple(self.floors))
        if not self.lines:
            raise CouplingError(f"{self.name}: no forcing lines")
        if any(not isinstance(f, Floor) for f in self.floors):
            raise CouplingError(f"{self.name}: floors must be rwadist.coupling.performance.Floor objects")
        if self.ripple is not None and not isinstance(self.ripple, ripple_mod.Ripple):
            raise CouplingError(f"{self.name}: ripple must be a rwadist.extended_ripple.Ripple or None")


def _physical_params(model, p, mass_kg, radius_m, name):
    """``p`` in SI for a model fitted per unit mass and inertia (``analytical.fit.per_unit``: no mass or radius given
    to the fit, M = 1 kg and I_rr = 1 kg·m² are units): with the rotor's ``mass_kg`` and ``radius_m`` (thin-disc
    I_rr, the fitted I_zz/I_rr kept) every stiffness and damping is scaled by its inertia, which leaves the interface
    loads as fitted (they depend only on k/M, c/M, k_θ/I_rr, c_θ/I_rr, I_zz/I_rr) and gives the coupling the rotor's
    true mass.  Coupled as a 1 kg rotor, the line-of-sight jitter was off by +22 % (1800 kg spacecraft) to +148 %
    (150 kg).  ``p`` itself for a model in SI; a :class:`CouplingModelError` for a per-unit one without both."""
    from dataclasses import replace

    per_unit = ((getattr(model, "analytical", None) or {}).get("fit") or {}).get("per_unit")
    if not per_unit:
        if mass_kg is not None or radius_m is not None:
            raise CouplingModelError(f"{name}: mass_kg and radius_m rescale a model fitted per unit mass; this one is "
                                     f"in SI already (mass {p.mass:g} kg): leave them out")
        return p
    if mass_kg is None or radius_m is None:
        raise CouplingModelError(f"{name}: analytical.fit.per_unit: the suspension was fitted per unit mass and "
                                 "inertia (no rotor mass and radius given): coupling to a structure needs the "
                                 "rotor's mass and inertias; pass mass_kg= and radius_m= (thin-disc inertias, the "
                                 "fitted I_zz/I_rr kept), or refit the extended model with the rotor's mass and radius")
    if not (mass_kg > 0 and radius_m > 0 and np.isfinite(mass_kg) and np.isfinite(radius_m)):
        raise CouplingModelError(f"{name}: mass_kg and radius_m must be positive, got {mass_kg!r}, {radius_m!r}")
    _, i_rr = ext.thin_disc(float(mass_kg), float(radius_m))
    m, r = float(mass_kg) / p.mass, i_rr / p.I_rr
    return replace(p, mass=float(mass_kg), I_rr=i_rr, I_zz=p.I_zz * r, k_r=p.k_r * m, c_r=p.c_r * m, k_z=p.k_z * m,
                   c_z=p.c_z * m, k_rock=p.k_rock * r, c_rock=p.c_rock * r)


def wheel_spec_from_model(model, mount=None, *, assumed_modes: bool = False, mass_kg: float | None = None,
                          radius_m: float | None = None, **kw) -> WheelSpec:
    """A WheelSpec from a :class:`rwadist.model.WheelModel` with an analytical section (a fitted
    model file or ``preset(...).to_model()``): lines via :func:`rwadist.extended.lines_from_model`,
    with the diagnosed effects of ``model.effects`` applied as their elements' actions
    (:mod:`rwadist.effects.actions`: amplitude laws, wheel-mode resonances, sidebands on the lines,
    :func:`rwadist.extended.apply_line_effects`), its broadband floors as :attr:`WheelSpec.floors`
    (:func:`floors_from_effects`) and its speed modulation as :attr:`WheelSpec.ripple`
    (:func:`rwadist.extended_ripple.ripple_from_effects`).
    A bad entry raises :class:`CouplingModelError` (a CouplingError) naming ``effects[i].<field>``.

    A wheel whose suspension modes are assumed (``analytical.modes_assumed``: a catalogue datasheet wheel)
    is hard-mounted (:attr:`WheelSpec.hard_mounted`), as its datasheet states, with a RuntimeWarning saying
    so; ``assumed_modes=True`` runs it through the assumed modes, with a RuntimeWarning that the coupled
    results rest on assumed values.

    A model fitted per unit mass and inertia (``rwadist fit --extended`` without --mass/--radius) needs the rotor's
    ``mass_kg`` (kg) and ``radius_m`` (m): :func:`_physical_params`."""
    import warnings

    from rwadist.catalogue import modes_assumed

    effects = schema.parse_effects(getattr(model, "effects", None), "<model>", CouplingModelError)
    name = getattr(model, "name", "wheel")
    p = _physical_params(model, ext.params_from_model(model), mass_kg, radius_m, name)
    if modes_assumed(model):
        if assumed_modes:
            warnings.warn(f"{name}: the suspension modes are ASSUMED (datasheet wheel, analytical.modes_assumed), "
                          "not measured; assumed_modes=True: the coupled results rest on assumed values",
                          RuntimeWarning, stacklevel=2)
        else:
            kw.setdefault("hard_mounted", True)
            warnings.warn(f"{name}: the suspension modes are ASSUMED (datasheet wheel, analytical.modes_assumed); "
                          "the wheel runs hard-mounted (rigid suspension), as its datasheet states; "
                          "assumed_modes=True runs the assumed modes", RuntimeWarning, stacklevel=2)
    try:
        lines = tuple(ext.lines_from_model(model, p))
        ripple = ripple_mod.ripple_from_effects(effects)
    except ValueError as exc:
        raise CouplingError(str(exc)) from exc
    kw.setdefault("floors", floors_from_effects(effects))
    kw.setdefault("ripple", ripple)
    return WheelSpec(p, lines, mount or geometry.Mount(), **kw)


# ----------------------------------------------------------------------------- lines

@dataclass(frozen=True, eq=False)
class LineResponses:
    """Per wheel k: h[k] (J_k,) harmonic numbers (a harmonic repeats for its sideband groups, whose
    frequency offsets are in f_offset[k] (J_k,) Hz: a diagnosed sideband's ±f_mod plus the speed-ripple
    order ripple_order[k] (J_k,) × f_r), f_hz[k] (S, J_k), y[practice][k] (S, J_k, n_perf) complex
    output phasors, loads[k] (S, J_k, 6) coupled loads wheel k exerts (own frame, own lines),
    hard_mounted[k] (S, J_k, 6) the same lines on a rigid mount.  floor: the wheels' broadband floors
    through the same practices (:class:`FloorResponses`), None when no wheel has one."""

    omega: np.ndarray
    perf_names: tuple
    h: list
    f_hz: list
    y: dict
    loads: list
    hard_mounted: list
    f_offset: list = field(default_factory=list)
    ripple_order: list = field(default_factory=list)
    floor: "FloorResponses | None" = None

    def rms(self, practice: str = "coupled") -> np.ndarray:
        """(S, n_perf) RMS of each performance output over all lines of all wheels (floors excluded)."""
        ms = sum(np.sum(np.abs(yk) ** 2, axis=1) / 2.0 for yk in self.y[practice])
        return np.sqrt(ms)

    def total_rms(self, practice: str = "coupled") -> np.ndarray:
        """(S, n_perf) RMS of lines and broadband floors: sqrt(lines' mean square + floors' mean square)
        (incoherent)."""
        ms = self.rms(practice) ** 2
        if self.floor is not None:
            ms = ms + self.floor.ms[practice]
        return np.sqrt(ms)


def _wheel_key(w):
    return (w.params, float(w.housing_mass), tuple(float(x) for x in w.housing_inertia), float(w.speed_scale),
            bool(w.hard_mounted))


class _FrfCache:
    """Wheel FRFs of one speed chunk, shared by identical wheels (same parameters, housing and speed scale:
    the mount does not enter Zc, B) evaluated at the same frequencies."""

    def __init__(self):
        self.f = None
        self.store = {}

    def get(self, w, omega, f):
        if self.f is None or self.f.shape != f.shape or not np.array_equal(self.f, f):
            self.f, self.store = f, {}
        key = _wheel_key(w)
        if key not in self.store:
            self.store[key] = _wheel_frf(w, omega * w.speed_scale, f)
        return self.store[key]


def _setup(plant: Plant, wheels, practices, omega):
    """Checks; (speeds (S,), mount selectors Mt_i, −Σ Mt_iᵀ M6_i Mt_i)."""
    if plant.kind != "accelerance":
        raise CouplingError("line and floor responses need a plant in accelerance form (modal or StateSpace)")
    for p in practices:
        if p not in PRACTICES:
            raise CouplingError(f"unknown practice {p!r}; use {PRACTICES}")
    om = np.atleast_1d(np.asarray(omega, dtype=float))
    if om.size == 0:
        raise CouplingError("no speeds: give at least one wheel speed (rad/s)")
    if not np.all(np.isfinite(om)):
        raise CouplingError("speeds must be finite")
    n_if = plant.n_interface
    Mts = [geometry.selector(w.mount, 6, n_if) for w in wheels]
    M6s = [wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia) for w in wheels]
    Zm = -sum(Mt.T @ M6 @ Mt for Mt, M6 in zip(Mts, M6s))
    if "ii" in practices:
        L = np.eye(n_if) - Zm @ plant.frf(np.array([1e6]))[0][0]
        if np.linalg.cond(L) > 1e12:
            raise SingularInterfaceError("practice 'ii' interface matrix is singular")
    return om, Mts, Zm


def _line_group(plant, wheels, Mts, practices, o, fe, ks, lines, cache, rigid_form=None, loads: bool = True) -> list:
    """[(coupled loads (S, J, 6) or None, {practice: outputs (S, J, n_perf)})] of wheels ``ks``, whose lines all sit
    at the frequencies ``fe`` (S, J) Hz at speeds ``o``: the plant, the wheels' dynamic masses and the interface
    matrix once, each practice's solve with every wheel's right-hand side at once; practice 'ii' from
    ``rigid_form`` (:class:`rwadist.coupling.rigid_practice.RigidPractice`) when given.  Without ``loads`` (only the
    outputs wanted) and with fewer outputs than right-hand sides, the adjoint: y = (P·Lc⁻¹)·X with P·Lc⁻¹ from one
    solve with Lcᵀ and the n_perf columns of Pᵀ (the same numbers to rounding, fewer triangular solves)."""
    G, P = plant.frf(fe)
    parts, Bs = [], {}
    for i, wi in enumerate(wheels):
        Zc, Bw = cache.get(wi, o, fe)
        parts.append((Mts[i], Zc))
        if i in ks:
            Bs[i] = (Zc, Bw)
    rhs = np.concatenate([Mts[k].T @ lines[k][1][..., None] for k in ks], axis=-1)          # (S, J, n_if, |ks|)
    Lc = _interface_matrix(G, parts)                                                        # coupled interface
    n = len(ks)
    X = {"coupled": rhs}
    if "iii" in practices:
        X["iii"] = np.concatenate([Mts[k].T @ (Bs[k][1] @ lines[k][1][..., None]) for k in ks], axis=-1)
    Y = {}
    if not loads and P.shape[-2] < n * len(X):        # outputs only: P·Lc⁻¹ once, then each practice's loads
        PL = np.swapaxes(np.linalg.solve(np.swapaxes(Lc, -1, -2), np.swapaxes(P, -1, -2)), -1, -2)
        Y = {p: PL @ x for p, x in X.items()}
        u = {}
    else:                                # one factorisation of Lc for both practices
        both = np.linalg.solve(Lc, np.concatenate(list(X.values()), axis=-1))
        u = {p: both[..., i * n:(i + 1) * n] for i, p in enumerate(X)}
    u["i"] = rhs
    if "ii" in practices and rigid_form is None:    # I − Zm·G, wheel by wheel on its node's rows (Zm = −Σ Mtᵀ M6 Mt)
        rigid = [(Mt, -wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia))
                 for Mt, w in zip(Mts, wheels)]
        u["ii"] = np.linalg.solve(_interface_matrix(G, rigid), rhs)
    # every wheel's outputs and interface accelerations in one product per practice (columns = wheels)
    Y.update({p: P @ u[p] for p in practices if p in u and p not in Y})                      # (S, J, n_perf, |ks|)
    if "ii" in practices and rigid_form is not None:
        Y["ii"] = rigid_form.outputs(fe, [Mts[k] for k in ks], [lines[k][1] for k in ks])
    acc = G @ u["coupled"] if loads else None                                               # (S, J, n_if, |ks|)
    out = []
    for j, k in enumerate(ks):
        live = (lines[k][0] > 0)[..., None]
        load = None
        if acc is not None:
            a_k = _apply_left(Mts[k], acc[..., j])[..., None]                              # its mount's (S, J, 6, 1)
            load = np.where(live, lines[k][1] + (Bs[k][0] @ a_k)[..., 0], 0)
        out.append((load, {p: np.where(live, Y[p][..., j], 0) for p in practices}))
    return out


#: Most (speed, line group) points :func:`line_responses` evaluates at once (their n_if × n_if work arrays, 1500 × 24 × 24
#: complex = 14 MB each, stay small enough to reuse memory: 7-10 % less CPU than 3000 on bench_coupling).
LINE_POINTS = 1500


def line_responses(plant: Plant, wheels, omega, practices=PRACTICES, chunk: int = 250,
                   floor_f_hz=None) -> LineResponses:
    """Steady line responses of the performance outputs for every wheel and practice at sweep
    speeds ``omega`` (rad/s, (S,)).  Processes ``chunk`` speeds at a time (fewer when that makes more than
    :data:`LINE_POINTS` line points).  A wheel with a speed
    ripple gets its sideband orders m = −K..K, K = :func:`rwadist.extended_ripple.ripple_order` over all the
    speeds (so every chunk has the same groups).  When a wheel has broadband floors, their responses
    are computed too (:func:`floor_responses` on ``floor_f_hz``, default :func:`floor_grid`) and kept
    in :attr:`LineResponses.floor`.

    Cost: one coupled interface solve (n_if × n_if) per (speed, line group) point, each at its own frequency (the
    plant, the wheels' dynamic masses and the interface matrix change with it); a ripple's 2K + 1 orders multiply
    the points, and its sidebands at f + m·f_r meet no other point's frequency, so the time grows with them
    (bench_coupling: K = 6, 13.0× the plain sweep's points; at a ripple frequency that is no multiple of the speed
    grid's step they share no frequency: 7 of its 143 000 points coincide).  Per point: the plant's modal sum
    (:meth:`Plant.frf`, over G's upper triangle), the interface matrix and one LU.  Practice 'ii' (speed-free) of a
    modal plant is the mass-loaded structure's closed form (:mod:`rwadist.coupling.rigid_practice`: one
    eigen-decomposition, then a product over its modes per point) instead of a second interface solve."""
    return _line_sweep(plant, wheels, omega, practices, chunk, floor_f_hz, loads=True)


def _line_sweep(plant: Plant, wheels, omega, practices, chunk: int, floor_f_hz, loads: bool) -> LineResponses:
    """:func:`line_responses`; without ``loads`` the coupled loads are not computed (:attr:`LineResponses.loads`
    empty) and the outputs come from the adjoint solve where it is cheaper (:func:`_line_group`)."""
    wheels = list(wheels)
    om, Mts, Zm = _setup(plant, wheels, practices, omega)
    # practice 'ii' does not depend on the speed: for a modal plant, one closed form for every point
    rigid_form = rigid_practice.rigid_practice(plant, -Zm) if "ii" in practices else None
    # wheels that differ only in their mount (a wheel set of one type) have the same lines in their own frame:
    # their sideband orders and grouped blocked loads are computed once
    line_key = [(w.params, tuple(map(id, w.lines)), w.ripple, float(w.speed_scale), bool(w.hard_mounted))
                for w in wheels]
    orders_of: dict = {}
    for w, key in zip(wheels, line_key):
        if key not in orders_of:
            orders_of[key] = 0 if w.ripple is None else ripple_mod.ripple_order(w.lines, om * w.speed_scale, w.ripple)
    kmax = [orders_of[key] for key in line_key]
    # at most ~LINE_POINTS (speed, line) points at once: a speed ripple's sidebands multiply the lines, and work
    # arrays of n_if x n_if per point beyond the caches cost more than the arithmetic
    groups_max = max(len({(ln.h, ln.f_offset) for ln in w.lines}) * (2 * k + 1) for w, k in zip(wheels, kmax))
    chunk = max(1, min(int(chunk), LINE_POINTS // max(groups_max, 1)))
    nw = len(wheels)
    # each wheel type's grouped lines at every speed at once (a ripple's chunks have few speeds, and its per-line
    # FFTs per chunk were Python-bound); (h, offset, order, f (S, J), blocked loads (S, J, 6)) per line key
    grouped: dict = {}
    for k, wk in enumerate(wheels):
        if line_key[k] not in grouped:
            grouped[line_key[k]] = grouped_lines_blocked(wk, om * wk.speed_scale, kmax[k])
    hs, offs, orders, fs, hms = ([grouped[key][i] for key in line_key] for i in range(5))
    # per wheel, the chunks' arrays: interface loads, outputs
    load_parts: list[list[np.ndarray]] = [[] for _ in range(nw)]
    y_parts: dict[str, list[list[np.ndarray]]] = {p: [[] for _ in range(nw)] for p in practices}
    for i0 in range(0, om.size, chunk):
        o = om[i0:i0 + chunk]
        cache = _FrfCache()
        lines = []
        for k in range(nw):
            f, Fk = fs[k][i0:i0 + chunk], hms[k][i0:i0 + chunk]
            lines.append((f, Fk, np.where(f > 0, f, 1.0)))
        # wheels whose lines sit at the same frequencies (equal wheels) share the plant, the interface matrix and
        # its factorisation: one solve with all their right-hand sides
        groups: list = []
        for k, (_, _, fe) in enumerate(lines):
            same = [g for g in groups if g[0].shape == fe.shape and np.array_equal(g[0], fe)]
            if same:
                same[0][1].append(k)
            else:
                groups.append((fe, [k]))
        for fe, ks in groups:
            for k, (ld, y) in zip(ks, _line_group(plant, wheels, Mts, practices, o, fe, ks, lines, cache,
                                                  rigid_form, loads)):
                if ld is not None:
                    load_parts[k].append(ld)
                for p in practices:
                    y_parts[p][k].append(y[p])
    fs, hms = ([x if line_key.index(key) == k else x.copy() for k, (x, key) in enumerate(zip(lst, line_key))]
               for lst in (fs, hms))                                  # each wheel its own arrays
    coupled_loads = [np.concatenate(x) for x in load_parts] if loads else []
    ys = {p: [np.concatenate(x) for x in v] for p, v in y_parts.items()}
    floor = None
    if any(w.floors for w in wheels):
        floor = floor_responses(plant, wheels, om, practices, f_hz=floor_f_hz, rigid_form=rigid_form)
    return LineResponses(om, plant.perf_names, hs, fs, ys, coupled_loads, hms, offs, orders, floor)


# ----------------------------------------------------------------------------- floors through the plant

@dataclass(frozen=True, eq=False)
class FloorResponses:
    """Broadband floors through the coupled plant: f_hz (F,) grid, Hz; psd[practice] (S, F, n_perf)
    one-sided PSD of the performance outputs (unit²/Hz) at each sweep speed; ms[practice] (S, n_perf)
    its integral over f_hz (trapezoid, i.e. the exact integral of the PSD's piecewise-linear interpolant)."""

    omega: np.ndarray
    perf_names: tuple
    f_hz: np.ndarray
    psd: dict
    ms: dict

    def rms(self, practice: str = "coupled") -> np.ndarray:
        return np.sqrt(self.ms[practice])


def _trapz(y, x, axis=-1):
    """Trapezoid integral of ``y`` over ``x`` (F,) along ``axis``: one product with the rule's weights
    (Δx_{j-1} + Δx_j)/2, no temporaries of y's size."""
    dx = np.diff(x)
    w = np.zeros(x.size)
    w[:-1] += 0.5 * dx
    w[1:] += 0.5 * dx
    return np.tensordot(y, w, axes=([axis], [0]))


def _floor_band(wheels):
    sup = [fl.support() for w in wheels for fl in w.floors]
    sup = [s for s in sup if s is not None]
    if not sup:
        return None
    lo, hi = min(s[0] for s in sup), max(s[1] for s in sup)
    if lo <= 0:
        raise CouplingError("a broadband floor reaches 0 Hz: pass f_hz explicitly (a free-free plant's response, "
                            "and a gyroscopic precession pole near 0 Hz, make the low end the analyst's choice)")
    return lo, hi


#: Largest number of speeds at which :func:`floor_grid` computes the coupled poles.
GRID_SPEEDS = 16


def _modal_poles(plant: Plant) -> np.ndarray:
    """The poles (rad/s) of a modal plant's under-damped modes in closed form, λ = ω(−ζ ± j√(1 − ζ²)) (its state
    matrix is block-diagonal in the modes: the eigenvalues its decomposition gives, to rounding, without the O(n³)
    decomposition); the rigid and the critically or over-damped modes have real poles, which
    :func:`_pole_damping` leaves out."""
    wn, zeta = (np.asarray(x, dtype=float) for x in (plant.modal or ())[:2])
    osc = (wn > 0) & (zeta < 1)
    w, z = wn[osc], zeta[osc]
    lam = w * (-z + 1j * np.sqrt(1 - z * z))
    return np.concatenate([lam, lam.conj()])


def _pole_damping(plant: Plant, wheels, omega, rigid_form=None):
    """(f Hz, ζ) of the oscillatory poles that shape the floor responses: the plant's ('i'; a modal plant's in
    closed form, :func:`_modal_poles`), the plant with the wheels as rigid masses ('ii'; the poles of ``rigid_form``,
    practice 'ii''s closed form :class:`rwadist.coupling.rigid_practice.RigidPractice` of these wheels, when the
    caller has it: the mass-loaded structure's flexible modes, its rigid modes having no oscillatory pole), the
    coupled system at up to GRID_SPEEDS of the speeds (evenly picked; 'coupled', 'iii') and every wheel's blocked
    rotor modes at all the speeds ('iii')."""
    from .assemble import Attachment, assemble
    from .components import rigid_mass, wheel

    lams = [_modal_poles(plant) if plant.modal is not None else np.linalg.eigvals(np.asarray(plant.state_space().A))]
    rig = [Attachment(rigid_mass(wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia)), w.mount)
           for w in wheels]
    lams.append(rigid_form.lam if rigid_form is not None else np.linalg.eigvals(np.asarray(assemble(plant, rig).sys.A)))
    om = np.unique(np.atleast_1d(omega))
    pick = om[np.unique(np.linspace(0, om.size - 1, min(om.size, GRID_SPEEDS)).round().astype(int))]
    for o in pick:
        atts = [Attachment(rigid_mass(wheel_rigid_mass_matrix(w.params, w.housing_mass, w.housing_inertia))
                           if w.hard_mounted else wheel(w.params, o * w.speed_scale, w.housing_mass, w.housing_inertia),
                           w.mount) for w in wheels]
        lams.append(np.linalg.eigvals(np.asarray(assemble(plant, atts).sys.A)))
    for w in wheels:
        if not w.hard_mounted:          # a rigid suspension has no rotor modes
            lams += [np.ravel(s) for s in ext.damped_modes(w.params, om * w.speed_scale).values()]
    lam = np.concatenate(lams)
    lam = lam[np.abs(lam.imag) > 1e-9 * np.abs(lam)]
    return np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)


#: Damping ratio below which a pole inside the floor band counts as undamped (infinite mean square).
MIN_FLOOR_ZETA = 1e-4


def floor_grid(plant: Plant, wheels, omega, points_per_halfwidth: float = 2.0, per_decade: int = 100,
               max_points: int = 200_000, rigid_form=None) -> np.ndarray:
    """Default frequency grid (Hz) for :func:`floor_responses`.

    Band: from the lowest to the highest frequency where any wheel's floor is non-zero (a band starting at
    0 Hz is refused: a free-free plant's response diverges there, so the low end needs an explicit f_hz).  Spacing:
    geometric, Δf/f = ζ_min/``points_per_halfwidth`` (and at least ``per_decade`` points per decade),
    ζ_min the smallest damping ratio of the oscillatory poles near the band (lo/2 .. 2·hi) of every system
    the practices solve -- the plant alone, the plant with rigid wheel masses, the coupled assembly
    (:func:`rwadist.coupling.assemble.assemble`, at up to GRID_SPEEDS of the speeds) -- and of the wheels' blocked
    rotor modes at all the speeds (:func:`rwadist.extended.damped_modes`).  (The coupled poles are needed:
    mass loading lowers a mode's damping ratio, ζ_c ≈ ζ·f_c/f, below its constituents'.)  A resonance of
    half-power half-width ζf then gets ``points_per_halfwidth`` points per half-width.  The mean square is
    the trapezoid rule on this grid (the exact integral of the piecewise-linear PSD); its error falls as the
    square of the spacing: measured 1.6e-5 for a single oscillator of ζ = 0.05 (vs G/(4kc)) and 2e-6 on a
    coupled 8-mode plant with two wheels (vs a grid 4× finer) at the default 2 points per half-width (tests).
    Every floor knot inside the band is a grid point (the floors are piecewise linear between knots).
    CouplingError when a pole near the band has ζ < 1e-4 (infinite or unresolvable mean square) or the
    grid would exceed ``max_points``.  ``rigid_form``: practice 'ii''s closed form for these wheels when the caller
    has it (:func:`rwadist.coupling.rigid_practice.rigid_practice`), whose poles are then not recomputed."""
    wheels = list(wheels)
    band = _floor_band(wheels)
    if band is None:
        raise CouplingError("no wheel has a non-zero broadband floor")
    lo, hi = band
    f, zeta = _pole_damping(plant, wheels, omega, rigid_form)
    near = (f >= lo / 2) & (f <= 2 * hi)
    zmin = float(np.min(zeta[near])) if near.any() else 1.0
    if zmin < MIN_FLOOR_ZETA:
        j = np.nonzero(near)[0][np.argmin(zeta[near])]
        raise CouplingError(f"a pole at {f[j]:.6g} Hz near the floor band {lo:.6g}-{hi:.6g} Hz has damping ratio "
                            f"{zeta[j]:.3g} < {MIN_FLOOR_ZETA:g}: the floor's mean square is infinite or unresolvable")
    ratio = min(1.0 + min(zmin, 1.0) / points_per_halfwidth, 10.0 ** (1.0 / per_decade))
    n = int(np.ceil(np.log(hi / lo) / np.log(ratio))) + 1
    if n > max_points:
        raise CouplingError(f"floor grid would need {n} points ({lo:.6g}-{hi:.6g} Hz, ζ_min {zmin:.3g}); "
                            "pass f_hz")
    knots = np.concatenate([fl.f_hz for w in wheels for fl in w.floors])
    knots = knots[(knots >= lo) & (knots <= hi)]
    return np.unique(np.concatenate([np.geomspace(lo, hi, max(n, 2)), knots]))


def _floor_terms(wheels, cols, f, omega):
    """The floors as separable terms S_t(f, Ω) = gain_t(Ω)·shape_t(f) (:meth:`Floor.psd`): gains (S, T) at the
    sweep speeds ``omega`` (each wheel's speed scale applied), shapes (T, F) on ``f`` Hz, and each term's column
    in ``cols`` [(wheel, channel)] (T,)."""
    gains, shapes, col = [], [], []
    for j, (k, c) in enumerate(cols):
        for fl in wheels[k].floors:
            if fl.channel == c:
                gains.append(fl.gain(omega * wheels[k].speed_scale))
                shapes.append(fl.shape(f))
                col.append(j)
    return np.stack(gains, axis=1), np.stack(shapes), np.array(col)


def _speed_free_psd(A, gains, shapes, col) -> np.ndarray:
    """Σ_n A[f, p, n]·S_n(f, Ω) (S, F, n_perf) for a response A (F, n_perf, N) that does not depend on the speed,
    the floors as :func:`_floor_terms`: one (S, T) × (T, F·n_perf) product."""
    W = A[:, :, col] * shapes.T[:, None, :]                                  # (F, n_perf, T)
    return (gains @ np.moveaxis(W, -1, 0).reshape(col.size, -1)).reshape(gains.shape[0], A.shape[0], A.shape[1])


def floor_responses(plant: Plant, wheels, omega, practices=PRACTICES, f_hz=None,
                    chunk_points: int = 20000, rigid_form=None) -> FloorResponses:
    """The wheels' broadband floors through the plant for each practice at sweep speeds ``omega`` (rad/s).

    A floor is a blocked load PSD S_c(f, Ω) on channel c of wheel k (:class:`Floor`, Ω = sweep speed ×
    speed_scale), incoherent with everything else, so the output PSD is
    Σ_k Σ_c |T_{y,kc}(f)|² S_kc(f, Ω), with T the response to a unit blocked load e_c of wheel k through
    the practice's interface equation, as :func:`line_responses` for a line: coupled
    u = solve(I − Σ_i Mt_iᵀ Zc_i Mt_i G, Mt_kᵀ e_c); 'i' u = Mt_kᵀ e_c; 'ii' Zc_i → −M6_i (rigid wheels);
    'iii' Mt_kᵀ B_k e_c in the coupled solve; y = P u.  Several floors on one channel add.

    f_hz : frequency grid, Hz (increasing, > 0; default :func:`floor_grid`, which resolves the lightly
    damped plant and wheel modes).  chunk_points : speeds × frequencies evaluated at once (memory).  rigid_form :
    practice 'ii''s closed form for these wheels, when the caller has it (passed to :func:`floor_grid`).
    Returns :class:`FloorResponses` (mean square = trapezoid over f_hz)."""
    wheels = list(wheels)
    practices = tuple(practices)
    om, Mts, Zm = _setup(plant, wheels, practices, omega)
    n_if = plant.n_interface
    cols = [(k, c) for k, w in enumerate(wheels) for c in sorted({fl.channel for fl in w.floors})]
    if not cols:
        raise CouplingError("no wheel has a broadband floor")
    if f_hz is None:
        f = floor_grid(plant, wheels, om, rigid_form=rigid_form)
    else:
        f = np.asarray(f_hz, dtype=float).ravel()
        if f.size < 2 or not np.all(np.isfinite(f)) or f[0] <= 0 or np.any(np.diff(f) <= 0):
            raise CouplingError("f_hz must be >= 2 finite, positive, strictly increasing frequencies")
    R = np.stack([Mts[k].T[:, c] for k, c in cols], axis=1)                 # (n_if, N) unit blocked loads
    gains, shapes, col = _floor_terms(wheels, cols, f, om)
    # S_n(f, Ω) = Σ_{t on column n} gain_t(Ω)·shape_t(f): each chunk's (speeds, frequencies, columns) in one product
    H = np.zeros((col.size, f.size, len(cols)))
    H[np.arange(col.size), :, col] = shapes
    psd = {p: np.zeros((om.size, f.size, plant.n_perf)) for p in practices}
    dyn = [p for p in ("coupled", "iii") if p in practices]
    eye = np.eye(n_if)
    fstep = max(1, min(f.size, int(chunk_points)))
    for j0 in range(0, f.size, fstep):               # frequency chunks: the n_if × n_if work arrays stay bounded
        fs = slice(j0, j0 + fstep)
        fc = f[fs]
        G, P = plant.frf(fc)
        if not (np.all(np.isfinite(G)) and np.all(np.isfinite(P))):
            raise CouplingError(f"the plant's response is not finite on the floor grid ({f[0]:.6g}-{f[-1]:.6g} Hz)")
        # 'i' and 'ii' do not depend on the speed: Σ_t gain_t(Ω)·(|T_{y,n_t}(f)|²·shape_t(f)), one product
        if "i" in practices:
            psd["i"][:, fs] = _speed_free_psd(np.abs(P @ R) ** 2, gains, shapes[:, fs], col)
        if "ii" in practices:
            Y = P @ np.linalg.solve(eye - Zm @ G, np.broadcast_to(R, (fc.size,) + R.shape))
            psd["ii"][:, fs] = _speed_free_psd(np.abs(Y) ** 2, gains, shapes[:, fs], col)
        if not dyn:
            continue
        # the wheels' speeds enter only through their rank-2 gyroscopic terms: one factorisation per frequency
        # (coupling.gyro_split), then a 2w x 2w solve per speed and frequency
        splits: dict = {}
        for w in wheels:
            key = _wheel_key(w)[:3] + (bool(w.hard_mounted),)
            if key not in splits:
                splits[key] = wheel_split(w, fc)
        solver = FloorSolver(G, P, Mts, [splits[_wheel_key(w)[:3] + (bool(w.hard_mounted),)] for w in wheels], R,
                             cols)
        step = max(1, int(chunk_points) // fc.size)
        Hc = H[:, fs].reshape(col.size, -1)
        for i0 in range(0, om.size, step):
            o = om[i0:i0 + step]
            Sc = (gains[i0:i0 + o.size] @ Hc).reshape(o.size, fc.size, len(cols), 1)
            for p, Y in solver.responses(o, [w.speed_scale for w in wheels], dyn).items():
                psd[p][i0:i0 + o.size, fs] = ((Y.real ** 2 + Y.imag ** 2) @ Sc)[..., 0]
    psd = {p: psd[p] for p in practices}
    ms = {p: _trapz(v, f, axis=1) for p, v in psd.items()}
    return FloorResponses(om, plant.perf_names, f, psd, ms)


# ----------------------------------------------------------------------------- jitter and PSD

@dataclass(frozen=True, eq=False)
class JitterResult:
    """RMS of each performance output vs sweep speed for each practice (lines and, when the wheels have
    any, broadband floors), and the relative error (rms_practice − rms_coupled)/rms_coupled (nan where the
    coupled RMS is 0)."""

    omega: np.ndarray
    perf_names: tuple
    rms: dict
    rel_error: dict

    @property
    def speed_rpm(self):
        return self.omega * RAD_S_TO_RPM

    def worst(self, practice: str = "ii", output=None) -> tuple:
        """(largest |relative error|, signed error there, speed rpm) of ``practice`` for output
        name ``output`` (None: the root-sum-square of all outputs)."""
        if output is None:
            rp = np.sqrt(np.sum(self.rms[practice] ** 2, axis=1))
            rc = np.sqrt(np.sum(self.rms["coupled"] ** 2, axis=1))
        else:
            j = self.perf_names.index(output)
            rp, rc = self.rms[practice][:, j], self.rms["coupled"][:, j]
        with np.errstate(invalid="ignore", divide="ignore"):
            e = np.where(rc > 0, (rp - rc) / rc, np.nan)
        i = int(np.nanargmax(np.abs(e)))
        return float(abs(e[i])), float(e[i]), float(self.speed_rpm[i])


def jitter_vs_speed(plant: Plant, wheels, omega, practices=PRACTICES, chunk: int = 250,
                    floor_f_hz=None) -> JitterResult:
    """RMS of the named performance outputs vs wheel speed for each practice (see module doc): the lines'
    mean square plus, when wheels have broadband floors, the floors' mean square (incoherent, added in
    quadrature: :meth:`LineResponses.total_rms`; ``floor_f_hz`` as in :func:`floor_responses`).  Without
    floors the lines alone, as before.  Only the outputs are computed (not the coupled loads of
    :func:`line_responses`): the coupled and 'iii' outputs of wheels sharing their line frequencies come from P·Lc⁻¹
    (one solve with Lcᵀ and Pᵀ's n_perf columns) instead of Lc⁻¹ times every wheel's loads (tests: equal to
    python-control's state-space assembly at every line and sideband)."""
    practices = tuple(practices)
    if "coupled" not in practices:
        practices = ("coupled",) + practices
    lr = _line_sweep(plant, wheels, omega, practices, chunk, floor_f_hz, loads=False)     # the outputs only
    rms = {p: lr.total_rms(p) for p in practices}
    rc = rms["coupled"]
    with np.errstate(invalid="ignore", divide="ignore"):
        err = {p: np.where(rc > 0, (rms[p] - rc) / rc, np.nan) for p in practices}
    return JitterResult(lr.omega, lr.perf_names, rms, err)


def _cumint_piecewise_linear(x, y, xq):
    """∫_{x0}^{xq} of the piecewise-linear interpolant of y (F, n) on x (F,) (zero outside [x0, x_end]),
    exactly, at points xq (Q,): (Q, n)."""
    C = np.concatenate([np.zeros((1,) + y.shape[1:]), np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x)[:, None], 0)])
    xc = np.clip(xq, x[0], x[-1])
    i = np.clip(np.searchsorted(x, xc, side="right") - 1, 0, x.size - 2)
    d = (xc - x[i])[:, None]
    dx = (x[i + 1] - x[i])[:, None]
    return C[i] + y[i] * d + (y[i + 1] - y[i]) * d * d / (2 * dx)


def output_psd(lr: LineResponses, practice: str, weights, f_edges):
    """One-sided PSD (unit²/Hz) of the performance outputs when the wheel speed is spread over
    the sweep speeds with probability ``weights`` (S,, summing to 1): each line's mean-square
    |Y|²/2 × weight is put in the frequency bin (``f_edges`` Hz) it falls in and divided by the
    bin width; the broadband floors' PSD (:attr:`LineResponses.floor`), weighted over the speeds likewise,
    is integrated exactly over each bin (its piecewise-linear interpolant on the floor grid) and divided by
    the bin width.  Its integral is the speed-averaged mean square inside the edges,
    Σ_s weight_s · (lines' mean square + floors' mean square), i.e. Σ_s weight_s · total_rms_s² when the
    edges span every line and the floor grid.  Returns (f_centres, psd (n_bins, n_perf))."""
    edges = np.asarray(f_edges, dtype=float)
    wts = np.asarray(weights, dtype=float)
    if wts.shape != lr.omega.shape or np.any(wts < 0):
        raise CouplingError("weights must be >= 0, one per sweep speed")
    nb = edges.size - 1
    psd = np.zeros((nb, len(lr.perf_names)))
    for fk, yk in zip(lr.f_hz, lr.y[practice]):
        idx = np.searchsorted(edges, fk, side="right") - 1
        ok = (idx >= 0) & (idx < nb)
        power = np.abs(yk) ** 2 / 2.0 * wts[:, None, None]
        for j in range(psd.shape[1]):
            psd[:, j] += np.bincount(idx[ok], weights=power[..., j][ok], minlength=nb)
    if lr.floor is not None:
        fl = np.einsum("s,sfp->fp", wts, lr.floor.psd[practice])
        psd += np.diff(_cumint_piecewise_linear(lr.floor.f_hz, fl, edges), axis=0)
    return 0.5 * (edges[1:] + edges[:-1]), psd / np.diff(edges)[:, None]
