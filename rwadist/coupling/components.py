"""Components as state-space systems (python-control) with force inputs and acceleration outputs.

Two kinds, following the thesis's component modelling (Masterson 1999 §5.2):

* **Attached components** (wheel, rigid mass, spring-mass, isolated wheel) are written in
  the form the thesis reaches after step (iii), "invert the force input and acceleration output
  of one attachment point": inputs are the interface **accelerations** ``a`` (n) and the
  component's free, unconstrained excitation ``w`` (m); outputs are the **loads the component
  exerts on the structure it is bolted to**, ``f`` (n)::

      f = Zc(s) a + B(s) w

  ``B(s)`` is the hard-mounted (blocked, a = 0) transmission: ``B w`` is exactly what a rigid
  test stand measures.  ``−Zc(s)`` is the component's dynamic mass at the interface.  (The
  thesis's F_l is the load *on* the component, f = −F_l.)
* **Plants** (spacecraft) keep the free-free form of step (ii): inputs are the loads applied at
  their interface DOFs, outputs the interface accelerations followed by named performance
  outputs.  A plant may also be a rigid body given by its mass matrix (impedance form).

Units SI: m/s², rad/s², N, N·m, kg, kg·m².  Frequencies in Hz at the API, rad/s inside.

Wheel (6 axes, wheel frame, loads at the interface point, channel order Fx, Fy, Fz, Tx, Ty, Tz;
accelerations ax, ay, az, αx, αy, αz).  The rotor of :class:`rwadist.extended.ExtendedParams`
(mass M, inertias I_rr, I_zz, suspension k_r/c_r radial, k_rock/c_rock rocking, k_z/c_z axial,
rotor centre at ``height`` h above the interface) sits on a rigid housing (optional mass m_h
and inertia J_h about the interface point).  States: rotor displacement relative to the housing
point at the rotor centre (q_x, q_y, q_z), relative rocking angles (r_x, r_y), their rates, and
the housing's angular rates ω_hx, ω_hy (the gyroscopic torque needs the rotor's *absolute*
angular rate).  With g = I_zz Ω / I_rr::

    q̈x = −(ax + h αy) − (k_r qx + c_r q̇x)/M + wFx/M
    q̈y = −(ay − h αx) − (k_r qy + c_r q̇y)/M + wFy/M
    q̈z = −az − (k_z qz + c_z q̇z)/M + wFz/M
    r̈x = −αx − g (ṙy + ω_hy) + (wTx − k_rock rx − c_rock ṙx)/I_rr
    r̈y = −αy + g (ṙx + ω_hx) + (wTy − k_rock ry − c_rock ṙy)/I_rr
    ω̇_hx = αx,  ω̇_hy = αy

(the real form of extended.py's I_rr ψ̈ + (c_rock − i I_zz Ω) ψ̇ + k_rock ψ = T applied to the
absolute angle ψ = ψ_h + r).  Loads on the mount::

    Fx = k_r qx + c_r q̇x − m_h ax        (y, z likewise)
    Tx = k_rock rx + c_rock ṙx − h Fy_s − J_hx αx,   Ty = k_rock ry + c_rock ṙy + h Fx_s − J_hy αy
    Tz = wTz − J_hz αz

With a = 0 this is extended.py's steady state exactly (test).  The rotor is free in spin (the
motor is torque-commanded; its commanded torque is not a disturbance), so I_zz does not load
the z rotation; axial-torque lines (wTz) pass straight to the mount as in extended.py.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import control
import numpy as np

from rwadist import extended as ext

from .errors import CouplingError, UnstablePlantError

ACCEL_NAMES = ("ax", "ay", "az", "alpha_x", "alpha_y", "alpha_z")
LOAD_NAMES = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")
#: Plants whose poles have real part above this × max(1, |λ|max) are unstable.
STABILITY_TOL = 1e-9


# ----------------------------------------------------------------------------- helpers

def reciprocal(re, im) -> np.ndarray:
    """1/(re + j·im) for real arrays ``re``, ``im`` (broadcast together), as (re − j·im)/(re² + im²) in real
    arithmetic written into the result's real and imaginary parts: the same values to ~1 ulp as numpy's complex
    division (Smith's algorithm, ~2x the time), which the coupled sweeps make at every point and mode (the plant's
    modal responses, practice 'ii''s closed form).  For the moduli they meet (1e-150 .. 1e150) the sum of squares
    neither overflows nor underflows."""
    re, im = np.broadcast_arrays(np.asarray(re, dtype=float), np.asarray(im, dtype=float))
    den = im * im
    den += re * re
    out = np.empty(re.shape, dtype=complex)
    np.divide(re, den, out=out.real)
    np.divide(im, den, out=out.imag)
    np.negative(out.imag, out=out.imag)
    return out


def ss_frf(A, B, C, D, s):
    """Frequency response C (sI − A)⁻¹ B + D at complex points ``s``, batched.

    A (..., n, n), B (..., n, m), C (p, n) or (..., p, n), D (p, m) or (..., p, m); s (...).
    Returns (..., p, m) complex.  Broadcasts leading axes (e.g. speeds × frequencies)."""
    A = np.asarray(A)
    s = np.asarray(s, dtype=complex)
    n = A.shape[-1]
    if n == 0:
        return np.broadcast_to(np.asarray(D, dtype=complex), s.shape + np.shape(D)[-2:]).copy()
    M = s[..., None, None] * np.eye(n) - A
    X = np.linalg.solve(M, np.broadcast_to(B, M.shape[:-2] + np.shape(B)[-2:]))
    return np.asarray(C) @ X + np.asarray(D)


def frf(sys, f_hz) -> np.ndarray:
    """Frequency response (n_out, n_in, F) of a python-control StateSpace at f_hz (Hz), accurate
    to near rounding: the state matrix is balanced and the solve of (sI − A) X = B gets one step
    of iterative refinement with the residual in extended precision.  (Plain LU, as in
    ``sys(s)``, loses up to ~1e-8 relative on badly scaled realisations such as a 1800 kg / 6 kg
    spring-mass chain.)"""
    from scipy.linalg import matrix_balance
    A, B, C, D = (np.asarray(x, dtype=float) for x in (sys.A, sys.B, sys.C, sys.D))
    s = 2j * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
    n = A.shape[0]
    if n == 0:
        return np.repeat(D[:, :, None].astype(complex), s.size, axis=2)
    A, T = matrix_balance(A, permute=False, separate=False)
    B, C = np.linalg.solve(T, B), C @ T
    M = s[:, None, None] * np.eye(n) - A
    X = np.linalg.solve(M, np.broadcast_to(B, (s.size,) + B.shape))
    R = B.astype(np.clongdouble) - M.astype(np.clongdouble) @ X.astype(np.clongdouble)
    X = X + np.linalg.solve(M, R.astype(complex))
    H = (C.astype(np.longdouble) @ X.astype(np.clongdouble)).astype(complex) + D
    return np.moveaxis(H, 0, -1)


def _named(prefix, names):
    return [f"{prefix}{n}" for n in names]


# ----------------------------------------------------------------------------- components

@dataclass(frozen=True, eq=False)
class Component:
    """An attached component: ``sys`` has inputs [a (n_interface), w (n_free)] and outputs the
    loads f (n_interface) it exerts on its mount (see module docstring).

    rigid_mass : (n_interface × n_interface) mass matrix of the component taken as one rigid
    body at its interface point (what the common practice, Table 5.1 plant (ii), adds to the
    spacecraft model), kg / kg·m / kg·m².
    """

    sys: control.StateSpace
    n_interface: int
    n_free: int
    rigid_mass: np.ndarray
    name: str = "component"

    def __post_init__(self):
        if self.sys.ninputs != self.n_interface + self.n_free or self.sys.noutputs != self.n_interface:
            raise CouplingError(f"{self.name}: sys must have {self.n_interface}+{self.n_free} inputs and "
                                f"{self.n_interface} outputs, has {self.sys.ninputs} and {self.sys.noutputs}")
        rm = np.asarray(self.rigid_mass, dtype=float)
        if rm.shape != (self.n_interface, self.n_interface):
            raise CouplingError(f"{self.name}: rigid_mass must be {self.n_interface}×{self.n_interface}")

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(A, B, C, D) of ``sys`` as arrays."""
        return (np.asarray(self.sys.A), np.asarray(self.sys.B), np.asarray(self.sys.C), np.asarray(self.sys.D))

    def frf(self, f_hz):
        """(Zc, B) at frequencies f_hz (Hz): Zc (F, n, n) loads per interface acceleration,
        B (F, n, m) hard-mounted loads per free excitation."""
        H = ss_frf(*self.matrices(), 2j * np.pi * np.asarray(f_hz, dtype=float))
        return H[..., :self.n_interface], H[..., self.n_interface:]

    def hard_mounted(self) -> control.StateSpace:
        """Free excitation w -> loads on a rigid (a = 0) mount: the test-stand measurement."""
        n = self.n_interface
        return control.ss(self.sys.A, np.asarray(self.sys.B)[:, n:], self.sys.C, np.asarray(self.sys.D)[:, n:])


def _component(A, B, C, D, n, m, rigid_mass, name, free_names=None, iface_names=None):
    iface_names = iface_names or [f"{i}" for i in range(n)]
    free_names = free_names or [f"{i}" for i in range(m)]
    sys = control.ss(A, B, C, D, inputs=_named("a_", iface_names) + _named("w_", free_names),
                     outputs=_named("f_", iface_names), name=name)
    return Component(sys, n, m, np.atleast_2d(np.asarray(rigid_mass, dtype=float)), name)


def rigid_mass(m, name: str = "rigid_mass") -> Component:
    """A rigid component: scalar mass (1 DOF) or a mass matrix.  Free excitation acts on it
    directly, so f = −M a + w (thesis disturbance model 1, Eq. 5.43).  m may be 0."""
    M = np.atleast_2d(np.asarray(m, dtype=float))
    n = M.shape[0]
    if M.shape != (n, n) or not np.all(np.isfinite(M)):
        raise CouplingError(f"mass must be a finite scalar or square matrix, got {m!r}")
    if np.any(np.linalg.eigvalsh(0.5 * (M + M.T)) < -1e-12 * max(1.0, np.abs(M).max())):
        raise CouplingError("mass matrix must be positive semi-definite")
    return _component(np.zeros((0, 0)), np.zeros((0, 2 * n)), np.zeros((n, 0)),
                      np.hstack([-M, np.eye(n)]), n, n, M, name)


def spring_mass(m: float, k: float, c: float = 0.0, name: str = "spring_mass") -> Component:
    """1-DOF wheel with internal compliance (thesis case #2, Eq. 5.58): mass m (kg) on a spring k
    (N/m) and damper c (N·s/m) to the interface; the free force w acts on the mass.
    f = (k + cs)(w − m a)/(m s² + c s + k)."""
    if not (m > 0 and k > 0 and c >= 0):
        raise CouplingError(f"spring_mass needs m > 0, k > 0, c >= 0, got m={m!r}, k={k!r}, c={c!r}")
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    B = np.array([[0.0, 0.0], [-1.0, 1.0 / m]])
    C = np.array([[k, c]])
    D = np.zeros((1, 2))
    return _component(A, B, C, D, 1, 1, [[m]], name)


def wheel_rigid_mass_matrix(p: ext.ExtendedParams, housing_mass: float = 0.0,
                            housing_inertia=(0.0, 0.0, 0.0)) -> np.ndarray:
    """6×6 mass matrix of the whole wheel as one rigid body about its interface point (rotor at
    (0, 0, height), free in spin so no I_zz on the z rotation; housing at the interface point)."""
    h = p.height
    rt = np.array([[0.0, -h, 0.0], [h, 0.0, 0.0], [0.0, 0.0, 0.0]])
    Mm = np.zeros((6, 6))
    Mm[:3, :3] = p.mass * np.eye(3)
    Mm[:3, 3:] = -p.mass * rt
    Mm[3:, :3] = p.mass * rt
    Mm[3:, 3:] = np.diag([p.I_rr, p.I_rr, 0.0]) - p.mass * rt @ rt
    Mm[:3, :3] += housing_mass * np.eye(3)
    Mm[3:, 3:] += np.diag(np.asarray(housing_inertia, dtype=float))
    return Mm


def wheel_matrices(p: ext.ExtendedParams, omega, housing_mass: float = 0.0,
                   housing_inertia=(0.0, 0.0, 0.0)):
    """(A, B, C, D) of the flexible wheel at speeds ``omega`` (rad/s, signed; scalar or array).

    A (..., 12, 12) (only the gyroscopic entries depend on Ω), B (12, 12), C (6, 12), D (6, 12);
    inputs [a (6), w (6)], outputs f (6).  See the module docstring for the equations."""
    w = np.asarray(omega, dtype=float)
    if not np.all(np.isfinite(w)):
        raise CouplingError("wheel speed omega must be finite")
    mh = float(housing_mass)
    Jh = np.asarray(housing_inertia, dtype=float)
    if mh < 0 or Jh.shape != (3,) or np.any(Jh < 0):
        raise CouplingError("housing_mass must be >= 0 and housing_inertia three values >= 0")
    M, Ir, h = p.mass, p.I_rr, p.height
    A = np.zeros(w.shape + (12, 12))
    # x = [qx qy qz rx ry | q̇x q̇y q̇z ṙx ṙy | ωhx ωhy]
    for i in range(5):
        A[..., i, 5 + i] = 1.0
    for i, (k, c) in enumerate(((p.k_r, p.c_r), (p.k_r, p.c_r), (p.k_z, p.c_z))):
        A[..., 5 + i, i] = -k / M
        A[..., 5 + i, 5 + i] = -c / M
    for i in (3, 4):
        A[..., 5 + i, i] = -p.k_rock / Ir
        A[..., 5 + i, 5 + i] = -p.c_rock / Ir
    g = p.I_zz * w / Ir
    A[..., 8, 9] = -g
    A[..., 8, 11] = -g
    A[..., 9, 8] = g
    A[..., 9, 10] = g
    B = np.zeros((12, 12))
    # accelerations (inputs 0..5)
    B[5, 0], B[5, 4] = -1.0, -h
    B[6, 1], B[6, 3] = -1.0, h
    B[7, 2] = -1.0
    B[8, 3] = -1.0
    B[9, 4] = -1.0
    B[10, 3] = 1.0
    B[11, 4] = 1.0
    # free loads (inputs 6..11): wFx wFy wFz wTx wTy wTz
    B[5, 6] = B[6, 7] = B[7, 8] = 1.0 / M
    B[8, 9] = B[9, 10] = 1.0 / Ir
    C = np.zeros((6, 12))
    C[0, 0], C[0, 5] = p.k_r, p.c_r
    C[1, 1], C[1, 6] = p.k_r, p.c_r
    C[2, 2], C[2, 7] = p.k_z, p.c_z
    C[3, 3], C[3, 8] = p.k_rock, p.c_rock
    C[4, 4], C[4, 9] = p.k_rock, p.c_rock
    C[3, :] -= h * C[1, :]
    C[4, :] += h * C[0, :]
    D = np.zeros((6, 12))
    D[:3, :3] = -mh * np.eye(3)
    D[3:6, 3:6] = -np.diag(Jh)
    D[5, 11] = 1.0
    return A, B, C, D


def rigid_wheel_matrices(p: ext.ExtendedParams, omega, housing_mass: float = 0.0,
                         housing_inertia=(0.0, 0.0, 0.0), gyroscopic: bool = True):
    """(A, B, C, D) of the wheel with zero compliance (rotor rigidly on the housing).

    f = −M6 a + [wF; wT + h ẑ × wF] + gyroscopic torque −I_zz Ω ẑ × ... (states ω_hx, ω_hy):
    Tx −= I_zz Ω ω_hy, Ty += I_zz Ω ω_hx.  ``gyroscopic=False`` drops the spin (mass only)."""
    Mm = wheel_rigid_mass_matrix(p, housing_mass, housing_inertia)
    h = p.height
    Wmap = np.eye(6)
    Wmap[3, 1] = -h
    Wmap[4, 0] = h
    D = np.hstack([-Mm, Wmap])
    w = float(omega)
    if not gyroscopic or w == 0.0:
        return np.zeros((0, 0)), np.zeros((0, 12)), np.zeros((6, 0)), D
    A = np.zeros((2, 2))
    B = np.zeros((2, 12))
    B[0, 3] = B[1, 4] = 1.0
    Hs = p.I_zz * w
    C = np.zeros((6, 2))
    C[3, 1] = -Hs
    C[4, 0] = Hs
    return A, B, C, D


def wheel(p: ext.ExtendedParams, omega: float, housing_mass: float = 0.0,
          housing_inertia=(0.0, 0.0, 0.0), rigid: bool = False, gyroscopic: bool = True,
          name: str = "wheel") -> Component:
    """The wheel at constant speed ``omega`` (rad/s, signed) as a 6-axis :class:`Component`.

    rigid=True: zero internal compliance (thesis disturbance model 1); ``gyroscopic`` applies to
    the rigid wheel only (the flexible one always has its gyroscopics)."""
    if rigid:
        A, B, C, D = rigid_wheel_matrices(p, omega, housing_mass, housing_inertia, gyroscopic)
    else:
        A, B, C, D = wheel_matrices(p, float(omega), housing_mass, housing_inertia)
    return _component(A, B, C, D, 6, 6, wheel_rigid_mass_matrix(p, housing_mass, housing_inertia), name,
                      free_names=list(LOAD_NAMES), iface_names=list(LOAD_NAMES))


def with_isolator(comp: Component, k, c=0.0, name: str | None = None) -> Component:
    """``comp`` on a massless spring-damper isolator per interface axis (k N/m or N·m/rad, c
    N·s/m or N·m·s/rad; scalars or one value per axis).

    States added: isolator stroke δ = x_component − x_mount and its rate.  The massless isolator
    node needs ``comp``'s interface feedthrough (its local mass, −D_a) to be invertible: a
    component with no mass at its interface cannot sit on a spring (SingularInterfaceError)."""
    from .errors import SingularInterfaceError
    n, m = comp.n_interface, comp.n_free
    kv = np.broadcast_to(np.asarray(k, dtype=float), (n,))
    cv = np.broadcast_to(np.asarray(c, dtype=float), (n,))
    if np.any(kv <= 0) or np.any(cv < 0) or not np.all(np.isfinite(kv)) or not np.all(np.isfinite(cv)):
        raise CouplingError("isolator needs k > 0 and c >= 0 per axis")
    A, B, C, D = comp.matrices()
    Ba, Bw, Da, Dw = B[:, :n], B[:, n:], D[:, :n], D[:, n:]
    Mloc = -Da
    if np.linalg.svd(Mloc, compute_uv=False).min() <= 1e-12 * max(1.0, np.abs(Mloc).max()):
        raise SingularInterfaceError(f"{comp.name}: no mass at its interface (feedthrough singular); "
                                     "a massless interface cannot sit on an isolator spring - add housing mass")
    K, Cd = np.diag(kv), np.diag(cv)
    # component load on the isolator node: fc = C x + Da a_b + Dw w, with a_b = a_mount + δ̈;
    # massless node: fc = K δ + Cd δ̇  ->  δ̈ = Da⁻¹ (K δ + Cd δ̇ − C x − Dw w) − a_mount
    Dinv = np.linalg.inv(Da)
    nx = A.shape[0]
    # full state [x, δ, δ̇]; a_b = Da⁻¹(K δ + Cd δ̇ − C x − Dw w)
    ab_x = np.hstack([-Dinv @ C, Dinv @ K, Dinv @ Cd])
    ab_w = -Dinv @ Dw
    An = np.zeros((nx + 2 * n, nx + 2 * n))
    An[:nx, :nx] = A
    An[:nx, :] += Ba @ ab_x
    An[nx:nx + n, nx + n:] = np.eye(n)
    An[nx + n:, :] = ab_x
    Bn = np.zeros((nx + 2 * n, n + m))
    Bn[:nx, n:] = Bw + Ba @ ab_w
    Bn[nx + n:, :n] = -np.eye(n)
    Bn[nx + n:, n:] = ab_w
    Cn = np.hstack([np.zeros((n, nx)), K, Cd])
    Dn = np.zeros((n, n + m))
    sysn = control.ss(An, Bn, Cn, Dn, inputs=comp.sys.input_labels, outputs=comp.sys.output_labels,
                      name=name or f"{comp.name}_isolated")
    return Component(sysn, n, m, comp.rigid_mass, name or f"{comp.name}_isolated")


# ----------------------------------------------------------------------------- free excitation

def free_lines(p: ext.ExtendedParams, lines, omega):
    """The free, unconstrained excitation of each line at constant speeds (the loads acting on
    the rotor before the suspension filters them): (f_hz (S, L), W (S, L, 6) complex phasors in
    the wheel component's w order wFx, wFy, wFz, wTx, wTy, wTz; channel = Re(W e^{i2πft})).

    Same line algebra as :func:`rwadist.extended.steady_lines` with the transmissibility
    replaced by 1 and no lever arm (the lever arm is in the component's geometry): the line
    frequency is |hΩ/2π + f_offset| (h|Ω|/2π for a harmonic; a sideband has a fixed offset) and a
    line's diagnosed wheel-mode resonances multiply each component by H at its whirl rate
    (:class:`rwadist.extended.Line`; quasi-static, exact for these steady lines)."""
    w = np.atleast_1d(np.asarray(omega, dtype=float))[:, None]
    lines = list(lines)
    W = np.zeros((w.shape[0], len(lines), 6), dtype=complex)
    f_hz = np.zeros((w.shape[0], len(lines)))
    col = {"radial_force": (0, 1), "radial_torque": (3, 4), "axial_force": (2,), "axial_torque": (5,)}
    for j, ln in enumerate(lines):
        wj = w[:, 0]
        f_hz[:, j] = ln.frequency(wj)
        for sigma, coef in ln.components():
            nu = ln.nu(sigma, wj)
            resp = coef * ln.amplitude(wj) + 0j
            if ln.resonances:
                resp = resp * ln.gain(nu)
            pos = nu >= 0
            a_re = np.where(pos, resp, np.conj(resp))
            a_im = np.where(pos, -1j * resp, 1j * np.conj(resp))
            cols = col[ln.direction]
            W[:, j, cols[0]] += a_re
            if len(cols) == 2:
                W[:, j, cols[1]] += a_im
    return f_hz, W


# ----------------------------------------------------------------------------- plants

@dataclass(frozen=True, eq=False)
class Plant:
    """A spacecraft plant.

    kind 'accelerance': ``sys`` inputs = loads at the n_interface DOFs, outputs = [interface
    accelerations (n_interface), performance outputs (n_perf)].  kind 'rigid': a rigid body with
    interface mass matrix ``mass`` (may be singular: only the assembled total must not be) and
    performance outputs ``perf_matrix @ a`` (acceleration-type).  ``modal`` holds
    (ω rad/s, ζ, Φ_interface (n_if × n_modes), Φ_perf (n_perf × n_modes)) when built from modal
    data, for the exact modal-sum frequency response.
    """

    kind: str
    n_interface: int
    perf_names: tuple
    sys: control.StateSpace | None = None
    mass: np.ndarray | None = None
    perf_matrix: np.ndarray | None = None
    modal: tuple | None = None
    name: str = "plant"
    _eig: tuple | None = field(default=None, repr=False)

    @property
    def n_perf(self) -> int:
        return len(self.perf_names)

    def state_space(self) -> control.StateSpace:
        """``sys``, the state-space model of an accelerance plant; CouplingError for a plant without one (a rigid
        plant: its mass matrix)."""
        if self.sys is None:
            raise CouplingError(f"{self.name}: a {self.kind} plant has no state-space model")
        return self.sys

    def frf(self, f_hz):
        """(G, P) at frequencies f_hz (Hz, any shape ...): G (..., n_if, n_if) interface
        accelerance, P (..., n_perf, n_if) performance outputs per interface load."""
        f = np.asarray(f_hz, dtype=float)
        n = self.n_interface
        if self.kind == "rigid":
            raise CouplingError("a rigid (mass-matrix) plant has no accelerance form; use assemble()")
        if self.modal is not None:
            wn, zeta, Phi, Phip = self.modal
            om = 2 * np.pi * f[..., None]
            hdisp = reciprocal(wn**2 - om**2, 2 * zeta * wn * om)     # (..., n_modes)
            # Σ_m φ_m φ_mᵀ h_m(f) for every frequency at once: the modal responses (complex) times the modes'
            # outer products (real), one real matrix product over all frequencies' real and imaginary parts
            # stacked (BLAS), not a complex n×n_modes×n product per frequency; G is symmetric, so only its upper
            # triangle's n(n+1)/2 entries are summed and each is copied to its mirror (G exactly symmetric) by one
            # gather of contiguous complex entries (two gathers into G's strided real and imaginary parts took ~1.4x
            # as long for 1500 frequencies, products included); P likewise (n_perf × n entries, no mirror)
            m = wn.size
            iu, ju = np.triu_indices(n)
            KG = np.ascontiguousarray(np.einsum("im,jm->mij", Phi, Phi)[:, iu, ju])
            mirror = np.zeros((n, n), dtype=np.intp)
            mirror[iu, ju] = mirror[ju, iu] = np.arange(iu.size)
            KP = np.einsum("im,jm->mij", Phip, Phi).reshape(m, -1)
            ha = (-(om**2) * hdisp).reshape(-1, m)
            hd = hdisp.reshape(-1, m)
            k = ha.shape[0]
            R = np.concatenate([ha.real, ha.imag]) @ KG                  # (2k, n(n+1)/2): real parts, then imaginary
            Gu = np.empty((k, iu.size), dtype=complex)
            Gu.real, Gu.imag = R[:k], R[k:]
            G = np.take(Gu, mirror.ravel(), axis=1)
            RP = np.concatenate([hd.real, hd.imag]) @ KP
            P = np.empty((k, KP.shape[1]), dtype=complex)
            P.real, P.imag = RP[:k], RP[k:]
            P = P.reshape(f.shape + (Phip.shape[0], n))
            return G.reshape(f.shape + (n, n)), P
        sys = self.state_space()
        A, B, C, D = (np.asarray(x) for x in (sys.A, sys.B, sys.C, sys.D))
        s = 2j * np.pi * f
        if self._eig is not None:
            lam, CV, VinvB = self._eig
            H = (CV * (1.0 / (s[..., None] - lam))[..., None, :]) @ VinvB + D
        else:
            H = ss_frf(A, B, C, D, s)
        return H[..., :n, :], H[..., n:, :]


def _check_stable(A, name):
    if A.shape[0] == 0:
        return
    lam = np.linalg.eigvals(A)
    scale = max(1.0, float(np.abs(lam).max()))
    bad = lam.real > STABILITY_TOL * scale
    if bad.any():
        worst = lam[np.argmax(lam.real)]
        raise UnstablePlantError(f"{name}: unstable, pole at {worst:.6g} 1/s (real part > 0); "
                                 "a disturbance analysis needs a stable (or marginally stable) plant")


def _eig_cache(A, B, C):
    if A.shape[0] == 0:
        return None
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) > 1e8:
        return None
    return lam, C @ V, np.linalg.solve(V, B)


def plant_from_statespace(sys, n_interface: int, perf_names=None, name: str = "plant") -> Plant:
    """A plant from a python-control StateSpace (continuous): inputs = loads at ``n_interface``
    interface DOFs, outputs = those DOFs' accelerations then performance outputs."""
    if not isinstance(sys, control.StateSpace):
        sys = control.ss(sys)
    if not sys.isctime():
        raise CouplingError("plant must be a continuous-time system")
    if sys.ninputs != n_interface or sys.noutputs < n_interface:
        raise CouplingError(f"plant sys has {sys.ninputs} inputs / {sys.noutputs} outputs; expected "
                            f"{n_interface} inputs and at least {n_interface} outputs")
    n_perf = sys.noutputs - n_interface
    perf_names = tuple(perf_names) if perf_names is not None else tuple(f"y{i}" for i in range(n_perf))
    if len(perf_names) != n_perf:
        raise CouplingError(f"{len(perf_names)} perf_names for {n_perf} performance outputs")
    A = np.asarray(sys.A)
    _check_stable(A, name)
    return Plant("accelerance", n_interface, perf_names, sys=sys, name=name,
                 _eig=_eig_cache(A, np.asarray(sys.B), np.asarray(sys.C)))


def modal_plant(freq_hz, zeta, phi_interface, phi_perf=None, perf_names=None, name: str = "plant") -> Plant:
    """A plant from mass-normalised modal data.

    freq_hz (n_modes,) natural frequencies, Hz (0 for rigid-body modes); zeta (scalar or
    n_modes) modal damping ratios; phi_interface (n_if × n_modes) mode shapes at the interface
    DOFs; phi_perf (n_perf × n_modes) the performance outputs' modal coefficients
    (displacement-type, e.g. rad of line of sight per unit modal coordinate).

    Modal coordinates η: η̈ + 2ζω η̇ + ω² η = Φ_ifᵀ F; interface acceleration a = Φ_if η̈;
    performance y = Φ_perf η.  StateSpace x = [η, η̇]."""
    fn = np.asarray(freq_hz, dtype=float).ravel()
    nm = fn.size
    z = np.broadcast_to(np.asarray(zeta, dtype=float), (nm,)).copy()
    Phi = np.atleast_2d(np.asarray(phi_interface, dtype=float))
    if Phi.shape[1] != nm:
        raise CouplingError(f"phi_interface must be n_interface × {nm} (one column per mode), got {Phi.shape}")
    Phip = np.zeros((0, nm)) if phi_perf is None else np.atleast_2d(np.asarray(phi_perf, dtype=float))
    if Phip.shape[1] != nm:
        raise CouplingError(f"phi_perf must be n_perf × {nm}, got {Phip.shape}")
    if np.any(fn < 0) or np.any(z < 0) or not (np.all(np.isfinite(fn)) and np.all(np.isfinite(z))):
        raise CouplingError("modal frequencies and damping ratios must be finite and >= 0")
    wn = 2 * np.pi * fn
    n_if, n_perf = Phi.shape[0], Phip.shape[0]
    A = np.block([[np.zeros((nm, nm)), np.eye(nm)], [-np.diag(wn**2), -np.diag(2 * z * wn)]])
    B = np.vstack([np.zeros((nm, n_if)), Phi.T])
    Ca = Phi @ np.hstack([-np.diag(wn**2), -np.diag(2 * z * wn)])
    C = np.vstack([Ca, np.hstack([Phip, np.zeros((n_perf, nm))])])
    D = np.vstack([Phi @ Phi.T, np.zeros((n_perf, n_if))])
    perf_names = tuple(perf_names) if perf_names is not None else tuple(f"y{i}" for i in range(n_perf))
    if len(perf_names) != n_perf:
        raise CouplingError(f"{len(perf_names)} perf_names for {n_perf} performance outputs")
    sys = control.ss(A, B, C, D, name=name)
    return Plant("accelerance", n_if, perf_names, sys=sys, modal=(wn, z, Phi, Phip), name=name)


def spring_mass_plant(m: float, k: float, c: float = 0.0, name: str = "spacecraft") -> Plant:
    """Thesis component #1 with its left end constrained (a_l1 = 0, Eq. 5.50): mass m on a spring
    k (and damper c) to ground, loaded at the mass.  Outputs [a (interface), F_l1, a_r1]:
    F_l1 = −(k x + c ẋ) is the load the ground applies (thesis sign), a_r1 the mass's
    acceleration."""
    if not (m > 0 and k >= 0 and c >= 0):
        raise CouplingError("spring_mass_plant needs m > 0, k >= 0, c >= 0")
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    B = np.array([[0.0], [1.0 / m]])
    C = np.array([[-k / m, -c / m], [-k, -c], [-k / m, -c / m]])
    D = np.array([[1.0 / m], [0.0], [1.0 / m]])
    sys = control.ss(A, B, C, D, inputs=["F"], outputs=["a", "F_l1", "a_r1"], name=name)
    return plant_from_statespace(sys, 1, ("F_l1", "a_r1"), name=name)


def rigid_plant(mass, perf_matrix=None, perf_names=None, name: str = "rigid_plant") -> Plant:
    """A rigid plant given by its interface mass matrix (may be singular, e.g. zero); performance
    outputs perf_matrix @ a (acceleration-type)."""
    M = np.atleast_2d(np.asarray(mass, dtype=float))
    n = M.shape[0]
    if M.shape != (n, n):
        raise CouplingError("rigid plant mass must be square")
    Pm = np.zeros((0, n)) if perf_matrix is None else np.atleast_2d(np.asarray(perf_matrix, dtype=float))
    if Pm.shape[1] != n:
        raise CouplingError(f"perf_matrix must have {n} columns")
    names = tuple(perf_names) if perf_names is not None else tuple(f"y{i}" for i in range(Pm.shape[0]))
    return Plant("rigid", n, names, mass=M, perf_matrix=Pm, name=name)


def example_spacecraft(total_mass: float = 1800.0, first_mode_hz: float = 10.0, payload_fraction: float = 1 / 3,
                       zeta: float = 0.005, bus_size: float = 2.0, payload_length: float = 3.0) -> Plant:
    """A free-free spacecraft of ``total_mass`` kg whose first flexible mode is ``first_mode_hz``
    (thesis Fig. 5-9: 1800 kg, 10 Hz): a rigid bus (uniform cube of side ``bus_size``) and a
    rigid payload (slender cylinder of length ``payload_length`` along +z, radius 0.4 m, centre
    at (0, 0, bus_size/2 + length/2)) joined at the bus top face by a 6-axis elastic joint.

    Interface: one node, the bus centre (6 DOFs); wheels go on it with :class:`~rwadist.coupling.geometry.Mount`
    lever arms.  Performance outputs: line of sight 'LOS_x', 'LOS_y' = the payload's rotation
    about x and y, rad.  The joint's stiffnesses (translation k_t, rotation k_r with
    k_r = k_t·(length/2)²) are scaled so that the lowest flexible mode is exactly first_mode_hz;
    12 modes (6 rigid, 6 flexible), modal damping ``zeta`` on the flexible ones."""
    from scipy import linalg
    mb, mp = total_mass * (1 - payload_fraction), total_mass * payload_fraction
    a, L, R = bus_size, payload_length, 0.4
    Jb = mb * a * a / 6.0
    Jp_t = mp * (3 * R * R + L * L) / 12.0
    Jp_z = 0.5 * mp * R * R

    def rb(m, J, r):  # 6×6 mass matrix of a body at offset r from its node, about the node
        rt = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        Mm = np.zeros((6, 6))
        Mm[:3, :3] = m * np.eye(3)
        Mm[:3, 3:] = -m * rt
        Mm[3:, :3] = m * rt
        Mm[3:, 3:] = np.diag(J) - m * rt @ rt
        return Mm

    # DOFs: bus node (bus centre) 0..5, payload node (payload centre) 6..11
    M = np.zeros((12, 12))
    M[:6, :6] = rb(mb, (Jb, Jb, Jb), (0, 0, 0))
    M[6:, 6:] = rb(mp, (Jp_t, Jp_t, Jp_z), (0, 0, 0))
    zj = a / 2  # joint at the bus top face

    def kin(r):  # displacement of a point at offset r from a node: u = [I, −r̃] q
        rt = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        Tm = np.zeros((6, 6))
        Tm[:3, :3] = np.eye(3)
        Tm[:3, 3:] = -rt
        Tm[3:, 3:] = np.eye(3)
        return Tm

    Tb = kin((0, 0, zj))
    Tp = kin((0, 0, -L / 2))
    Jm = np.hstack([-Tb, Tp])                       # joint relative motion (6 × 12)

    def stiffness(kt):
        Kj = np.diag([kt, kt, kt, kt * (L / 2) ** 2, kt * (L / 2) ** 2, kt * (L / 2) ** 2])
        return Jm.T @ Kj @ Jm

    def first_flex(kt):
        ev = linalg.eigh(stiffness(kt), M, eigvals_only=True)
        return np.sqrt(max(ev[6], 0.0)) / (2 * np.pi)

    kt0 = 1e6
    kt = kt0 * (first_mode_hz / first_flex(kt0)) ** 2
    K = stiffness(kt)
    ev, V = linalg.eigh(K, M)
    ev = np.where(np.arange(12) < 6, 0.0, ev)
    fn = np.sqrt(np.maximum(ev, 0.0)) / (2 * np.pi)
    z = np.where(np.arange(12) < 6, 0.0, zeta)
    Phi_if = V[:6, :]
    Phi_perf = V[9:11, :]                            # payload θx, θy
    return modal_plant(fn, z, Phi_if, Phi_perf, ("LOS_x", "LOS_y"), name="spacecraft")


def random_modal_plant(n_modes: int = 200, n_nodes: int = 4, n_perf: int = 2, f_range=(1.0, 1000.0),
                       zeta: float = 0.01, seed: int = 0) -> Plant:
    """A synthetic free-free plant for benchmarks: 6 rigid-body modes plus n_modes − 6 flexible
    modes log-spaced over ``f_range`` Hz, random mass-normalised shapes at n_nodes 6-DOF nodes."""
    rng = np.random.default_rng(seed)
    nf = n_modes - 6
    fn = np.concatenate([np.zeros(6), np.geomspace(f_range[0], f_range[1], nf)])
    z = np.concatenate([np.zeros(6), np.full(nf, zeta)])
    Phi = rng.normal(scale=0.05, size=(6 * n_nodes, n_modes))
    Phip = rng.normal(scale=1e-3, size=(n_perf, n_modes))
    return modal_plant(fn, z, Phi, Phip, tuple(f"y{i}" for i in range(n_perf)), name="random_plant")
