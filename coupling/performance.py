"""Performance prediction: harmonic lines of several wheels through the coupled spacecraft,
side by side with the three practices of thesis Table 5.1.

Method (frequency domain, exact for steady lines; the same physics as
:func:`coupling.assemble.assemble`, checked against it in the tests).  At a line of wheel k at
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
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rwadist import extended as ext
from rwadist.units import RAD_S_TO_RPM

from . import geometry
from .assemble import PRACTICES
from .components import Plant, wheel_matrices, wheel_rigid_mass_matrix
from .errors import CouplingError, SingularInterfaceError


@dataclass(frozen=True, eq=False)
class WheelSpec:
    """One wheel on the plant.  params: extended-model parameters; lines: its forcing lines
    (:class:`rwadist.extended.Line`); mount: where it sits; housing mass (kg) and inertia
    (kg·m², about the interface point); speed_scale: this wheel's speed = speed_scale × the
    sweep speed (e.g. −1 for a wheel spinning the other way, 0.9 for a slower one)."""

    params: ext.ExtendedParams
    lines: tuple
    mount: geometry.Mount = field(default_factory=geometry.Mount)
    housing_mass: float = 0.0
    housing_inertia: tuple = (0.0, 0.0, 0.0)
    speed_scale: float = 1.0
    name: str = "wheel"

    def __post_init__(self):
        object.__setattr__(self, "lines", tuple(self.lines))
        if not self.lines:
            raise CouplingError(f"{self.name}: no forcing lines")


def wheel_spec_from_model(model, mount=None, **kw) -> WheelSpec:
    """A WheelSpec from a :class:`rwadist.model.WheelModel` with an analytical section (a fitted
    model file or ``preset(...).to_model()``): lines via :func:`rwadist.extended.lines_from_model`,
    with the diagnosed effects of ``model.effects`` applied (``rwadist diagnose``; amplitude laws,
    wheel-mode resonances, sidebands: :func:`rwadist.extended.apply_line_effects`)."""
    p = ext.params_from_model(model)
    return WheelSpec(p, tuple(ext.lines_from_model(model, p)), mount or geometry.Mount(), **kw)


@dataclass(frozen=True, eq=False)
class LineResponses:
    """Per wheel k: h[k] (J_k,) harmonic numbers (a harmonic repeats for its sideband groups, whose
    frequency offsets are in f_offset[k] (J_k,) Hz), f_hz[k] (S, J_k), y[practice][k] (S, J_k, n_perf)
    complex output phasors, loads[k] (S, J_k, 6) coupled loads wheel k exerts (own frame, own
    lines), hard_mounted[k] (S, J_k, 6) the same lines on a rigid mount."""

    omega: np.ndarray
    perf_names: tuple
    h: list
    f_hz: list
    y: dict
    loads: list
    hard_mounted: list
    f_offset: list = field(default_factory=list)

    def rms(self, practice: str = "coupled") -> np.ndarray:
        """(S, n_perf) RMS of each performance output over all lines of all wheels."""
        ms = sum(np.sum(np.abs(yk) ** 2, axis=1) / 2.0 for yk in self.y[practice])
        return np.sqrt(ms)


def _grouped_lines(spec: WheelSpec, omega):
    """Hard-mounted line phasors summed over lines with equal h and frequency offset:
    (h (J,), f_offset (J,) Hz, f (S, J) Hz, F (S, J, 6))."""
    keys = np.array([(ln.h, ln.f_offset) for ln in spec.lines], dtype=float)
    ku, first, inv = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inv = np.ravel(inv)
    f_all, amp = ext.steady_lines(spec.params, spec.lines, omega)
    ind = np.zeros((ku.shape[0], keys.shape[0]))
    ind[inv, np.arange(keys.shape[0])] = 1.0
    return ku[:, 0], ku[:, 1], f_all[:, first], np.einsum("jl,slc->sjc", ind, amp)


def _wheel_frf(spec, omega, f):
    """(Zc, B) of a flexible wheel at speeds omega (S,) and frequencies f (S, J): (S, J, 6, 6) each."""
    A, B, C, D = wheel_matrices(spec.params, omega, spec.housing_mass, spec.housing_inertia)
    s = 2j * np.pi * f
    M = s[..., None, None] * np.eye(12) - A[:, None]
    X = np.linalg.solve(M, np.broadcast_to(B, M.shape[:-2] + B.shape))
    H = C @ X + D
    return H[..., :6], H[..., 6:]


def line_responses(plant: Plant, wheels, omega, practices=PRACTICES, chunk: int = 250) -> LineResponses:
    """Steady line responses of the performance outputs for every wheel and practice at sweep
    speeds ``omega`` (rad/s, (S,)).  Processes ``chunk`` speeds at a time."""
    wheels = list(wheels)
    if plant.kind != "accelerance":
        raise CouplingError("line_responses needs a plant in accelerance form (modal or StateSpace)")
    for p in practices:
        if p not in PRACTICES:
            raise CouplingError(f"unknown practice {p!r}; use {PRACTICES}")
    om = np.atleast_1d(np.asarray(omega, dtype=float))
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
    hs, offs, fs, hms, loads = [], [], [], [], []
    ys = {p: [] for p in practices}
    eye = np.eye(n_if)
    for k, wk in enumerate(wheels):
        parts = {p: [] for p in practices}
        lk, fk_all, Fk_all = [], [], []
        for i0 in range(0, om.size, chunk):
            o = om[i0:i0 + chunk]
            ok = o * wk.speed_scale
            hk, offk, f, Fk = _grouped_lines(wk, ok)
            live = f > 0
            fe = np.where(live, f, 1.0)
            G, P = plant.frf(fe)
            Zsum = np.zeros(fe.shape + (n_if, n_if), dtype=complex)
            Bk = None
            for i, wi in enumerate(wheels):
                Zc, Bw = _wheel_frf(wi, o * wi.speed_scale, fe)
                Zsum += Mts[i].T @ Zc @ Mts[i]
                if i == k:
                    Zck, Bk = Zc, Bw
            rhs = (Mts[k].T @ Fk[..., None])                     # (S, J, n_if, 1)
            Lc = eye - Zsum @ G                                   # coupled interface equation
            uc = np.linalg.solve(Lc, rhs)
            lk.append(np.where(live[..., None], (Fk[..., None] + Zck @ (Mts[k] @ (G @ uc)))[..., 0], 0))
            for p in practices:
                if p == "coupled":
                    u = uc
                elif p == "i":
                    u = rhs
                elif p == "ii":
                    u = np.linalg.solve(eye - Zm @ G, rhs)
                else:
                    u = np.linalg.solve(Lc, Mts[k].T @ (Bk @ Fk[..., None]))
                parts[p].append(np.where(live[..., None], (P @ u)[..., 0], 0))
            fk_all.append(f)
            Fk_all.append(Fk)
        hs.append(hk)
        offs.append(offk)
        fs.append(np.concatenate(fk_all))
        hms.append(np.concatenate(Fk_all))
        loads.append(np.concatenate(lk))
        for p in practices:
            ys[p].append(np.concatenate(parts[p]))
    return LineResponses(om, plant.perf_names, hs, fs, ys, loads, hms, offs)


@dataclass(frozen=True, eq=False)
class JitterResult:
    """RMS of each performance output vs sweep speed for each practice, and the relative error
    (rms_practice − rms_coupled)/rms_coupled (nan where the coupled RMS is 0)."""

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


def jitter_vs_speed(plant: Plant, wheels, omega, practices=PRACTICES, chunk: int = 250) -> JitterResult:
    """RMS of the named performance outputs vs wheel speed for each practice (see module doc)."""
    practices = tuple(practices)
    if "coupled" not in practices:
        practices = ("coupled",) + practices
    lr = line_responses(plant, wheels, omega, practices, chunk)
    rms = {p: lr.rms(p) for p in practices}
    rc = rms["coupled"]
    with np.errstate(invalid="ignore", divide="ignore"):
        err = {p: np.where(rc > 0, (rms[p] - rc) / rc, np.nan) for p in practices}
    return JitterResult(lr.omega, lr.perf_names, rms, err)


def output_psd(lr: LineResponses, practice: str, weights, f_edges):
    """One-sided PSD (unit²/Hz) of the performance outputs when the wheel speed is spread over
    the sweep speeds with probability ``weights`` (S,, summing to 1): each line's mean-square
    |Y|²/2 × weight is put in the frequency bin (``f_edges`` Hz) it falls in and divided by the
    bin width.  Its integral is the speed-averaged mean square (Σ_s weight_s · rms_s²).
    Returns (f_centres, psd (n_bins, n_perf))."""
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
    return 0.5 * (edges[1:] + edges[:-1]), psd / np.diff(edges)[:, None]
