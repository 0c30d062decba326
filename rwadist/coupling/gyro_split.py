"""The coupled floor responses at many speeds on one frequency grid, with one factorisation per frequency.

A wheel's speed enters its dynamic mass only through the rotor's gyroscopic coupling, a rank-2 term:
A(Ω) = A0 + g·E·N (g = I_zz·Ω/I_rr; E = the two rocking-rate states' columns, N their gyroscopic rows, see
:func:`rwadist.coupling.components.wheel_matrices`), so by Woodbury, with R0 = (sI − A0)⁻¹::

    Zc(s, Ω) = Zc0(s) + a(s)·K(s, Ω)·b(s),     K = g·(I − g·Q(s))⁻¹,   a = C R0 E,  b = N R0 B_a,  Q = N R0 E

(B_a the acceleration inputs; the free-load transmissibility likewise, B = B0 + a·K·b_w).  A hard-mounted wheel's
gyroscopic torque is Ω·I_zz/s on its two rocking DOFs (:func:`rwadist.coupling.performance.rigid_wheel_frf`): the same form,
a = b^T = [e_Tx, e_Ty], K = (Ω·I_zz/s)·[[0, −1], [1, 0]].

The coupled interface matrix is then Lc = L0(f) − U·K·V, U = [Mt_iᵀ a_i] (n_if × 2w), V = [b_i Mt_i G] (2w × n_if),
K block-diagonal in the wheels, and every output needed, P·Lc⁻¹·X, is

    P·Lc⁻¹·X = P·L0⁻¹·X + (P L0⁻¹ U)·K·(I − Y·K)⁻¹·(V L0⁻¹ X),     Y = V L0⁻¹ U   (2w × 2w)

so L0 is factorised once per frequency and each (speed, frequency) point costs a 2w × 2w solve instead of an
n_if × n_if one (w wheels; the same numbers to rounding: tests against the direct solves and against the assembled
state-space system).

The speed ω of the sweep enters K linearly in every wheel, K_i = ω·Γ_i·(I − ω·Q_i·Γ_i)⁻¹ (flexible: Γ_i = the
inertia ratio × speed scale, a scalar; hard-mounted: Γ_i = I_zz·scale/s·[[0, −1], [1, 0]], Q_i = 0), so with
H = Γ·(Q + Y) (2w × 2w, one per frequency; Γ, Q block-diagonal)::

    K·(I − Y·K)⁻¹ = ω·(I − ω·H)⁻¹·Γ = Σ_k ω/(1 − ω·λ_k) · v_k·u_kᵀ·Γ,     H = Σ_k λ_k v_k u_kᵀ (eigenvectors)

and every speed costs a sum over the 2w eigenvalues (:meth:`FloorSolver.responses`); frequencies whose eigenvector
matrix is ill-conditioned (> :data:`EIG_COND`) keep the 2w × 2w solve per speed.
"""
from __future__ import annotations

import numpy as np

from .components import wheel_matrices
from .interface import _interface_matrix, rigid_wheel_frf


def _gyro_vectors():
    """E (12, 2), N (2, 12) with A(Ω) − A(0) = g·E·N in :func:`rwadist.coupling.components.wheel_matrices` (states 8, 9 the
    rotor's rocking rates, 10, 11 the housing's rates)."""
    E = np.zeros((12, 2))
    E[8, 0] = E[9, 1] = 1.0
    N = np.zeros((2, 12))
    N[0, 9] = N[0, 11] = -1.0          # A[8, 9] = A[8, 11] = −g
    N[1, 8] = N[1, 10] = 1.0           # A[9, 8] = A[9, 10] = +g
    return E, N


def wheel_split(spec, f: np.ndarray) -> dict:
    """The speed-free parts of one wheel's FRF on the grid ``f`` (F,) Hz: Zc0, B0 (F, 6, 6), a (F, 6, 2), b, bw
    (F, 2, 6), Q (F, 2, 2) and the kind ('flexible' or 'rigid') for :func:`gyro_gain`."""
    s = 2j * np.pi * np.asarray(f, dtype=float)
    p = spec.params
    if spec.hard_mounted:
        Zc0, B = rigid_wheel_frf(p, np.zeros(1), f[None, :], spec.housing_mass, spec.housing_inertia)
        e = np.zeros((6, 2))
        e[3, 0] = e[4, 1] = 1.0
        F = s.size
        return {"kind": "rigid", "s": s, "I_zz": p.I_zz, "Zc0": Zc0[0], "B0": np.broadcast_to(B, (F, 6, 6)),
                "a": np.broadcast_to(e, (F, 6, 2)), "b": np.broadcast_to(e.T, (F, 2, 6)),
                "bw": np.zeros((F, 2, 6)), "Q": np.zeros((F, 2, 2))}
    A0, Bm, C, D = wheel_matrices(p, 0.0, spec.housing_mass, spec.housing_inertia)
    E, N = _gyro_vectors()
    M = s[:, None, None] * np.eye(12) - A0
    X = np.linalg.solve(M, np.broadcast_to(np.concatenate([Bm, E], axis=1), (s.size, 12, 14)))   # R0 [B | E]
    return {"kind": "flexible", "s": s, "ratio": p.I_zz / p.I_rr,
            "Zc0": C @ X[..., :6] + D[:, :6], "B0": C @ X[..., 6:12] + D[:, 6:12], "a": C @ X[..., 12:],
            "b": N @ X[..., :6], "bw": N @ X[..., 6:12], "Q": N @ X[..., 12:]}


def gyro_gain(split: dict, omega: np.ndarray) -> np.ndarray:
    """K (S, F, 2, 2) of a wheel at its speeds ``omega`` (S,) rad/s on the split's grid: Zc = Zc0 + a·K·b."""
    om = np.asarray(omega, dtype=float)[:, None]
    if split["kind"] == "rigid":
        k = split["I_zz"] * om / split["s"][None, :]                       # (S, F)
        K = np.zeros(k.shape + (2, 2), dtype=complex)
        K[..., 0, 1], K[..., 1, 0] = -k, k
        return K
    g = (split["ratio"] * om)[..., None, None]                             # (S, 1, 1, 1)
    Q = split["Q"][None]
    IgQ = np.eye(2) - g * Q                                                # (S, F, 2, 2)
    det = IgQ[..., 0, 0] * IgQ[..., 1, 1] - IgQ[..., 0, 1] * IgQ[..., 1, 0]
    inv = np.empty_like(IgQ)
    inv[..., 0, 0], inv[..., 1, 1] = IgQ[..., 1, 1], IgQ[..., 0, 0]
    inv[..., 0, 1], inv[..., 1, 0] = -IgQ[..., 0, 1], -IgQ[..., 1, 0]
    return g * inv / det[..., None, None]


def gyro_rate(split: dict, scale: float) -> np.ndarray:
    """Γ (F, 2, 2) of a wheel whose speed is ``scale`` × the sweep's speed ω: K = ω·Γ·(I − ω·Q·Γ)⁻¹
    (:func:`gyro_gain` at ω·scale)."""
    F = split["s"].size
    if split["kind"] == "rigid":
        k = split["I_zz"] * scale / split["s"]
        out = np.zeros((F, 2, 2), dtype=complex)
        out[:, 0, 1], out[:, 1, 0] = -k, k
        return out
    return np.broadcast_to(split["ratio"] * scale * np.eye(2), (F, 2, 2)).astype(complex)


#: Eigenvector-matrix condition number above which :meth:`FloorSolver.responses` solves per speed at a frequency.
EIG_COND = 1e6


class FloorSolver:
    """P·Lc⁻¹·X of the coupled interface equation at any speeds on one frequency chunk (see the module doc):
    ``setup`` once per chunk (one solve with L0ᵀ per frequency), then :meth:`coupled` and :meth:`iii` per speeds."""

    def __init__(self, G, P, Mts, splits, loads, cols):
        """G (F, n, n), P (F, n_perf, n) the plant on the chunk; Mts the wheels' mount selectors (6, n); splits
        their :func:`wheel_split` on the chunk; loads R (n, N) the unit blocked loads; cols [(wheel, channel)]."""
        nw = len(Mts)
        L0 = _interface_matrix(G, [(Mt, sp["Zc0"]) for Mt, sp in zip(Mts, splits)])     # (F, n, n)
        U = np.concatenate([np.einsum("ji,fjk->fik", Mt, sp["a"]) for Mt, sp in zip(Mts, splits)], axis=-1)
        V = np.concatenate([sp["b"] @ (Mt @ G) for Mt, sp in zip(Mts, splits)], axis=-2)  # (F, 2w, n)
        rhs = np.concatenate([np.swapaxes(P, -1, -2), np.swapaxes(V, -1, -2)], axis=-1)
        QPV = np.swapaxes(np.linalg.solve(np.swapaxes(L0, -1, -2), rhs), -1, -2)      # [P; V]·L0⁻¹
        n_perf = P.shape[-2]
        QP, QV = QPV[..., :n_perf, :], QPV[..., n_perf:, :]
        self.splits, self.nw = splits, nw
        self.A1, self.Y = QP @ U, QV @ U                                   # (F, n_perf, 2w), (F, 2w, 2w)
        self.PR, self.VR = QP @ loads, QV @ loads                          # (F, n_perf, N), (F, 2w, N)
        # 'iii': the blocked loads through each wheel's free-load transmissibility, B = B0 + a·K·bw
        R3 = np.stack([np.einsum("jn,fj->fn", Mts[k], splits[k]["B0"][..., :, c]) for k, c in cols], axis=-1)
        self.PR3, self.VR3 = QP @ R3, QV @ R3
        self._modal: tuple | None = None                                     # responses()'s terms, per scales
        self.W = np.zeros((G.shape[0], 2 * nw, len(cols)), dtype=complex)  # bw's column c in wheel k's rows
        for j, (k, c) in enumerate(cols):
            self.W[:, 2 * k:2 * k + 2, j] = splits[k]["bw"][..., :, c]

    def gains(self, omegas) -> np.ndarray:
        """K (S, F, 2w, 2w), block-diagonal, at the wheels' speeds ``omegas`` [(S,) per wheel]."""
        Ks = [gyro_gain(sp, om) for sp, om in zip(self.splits, omegas)]
        K = np.zeros(Ks[0].shape[:2] + (2 * self.nw, 2 * self.nw), dtype=complex)
        for i, Ki in enumerate(Ks):
            K[..., 2 * i:2 * i + 2, 2 * i:2 * i + 2] = Ki
        return K

    def solve(self, K, practices) -> dict:
        """{practice: P·Lc⁻¹·X (S, F, n_perf, N)} for 'coupled' (X the blocked loads) and 'iii' (X through each
        wheel's transmissibility)."""
        out = {}
        Mm = np.eye(2 * self.nw) - self.Y[None] @ K                      # I − Y·K  (S, F, 2w, 2w)
        AK = self.A1[None] @ K
        n = self.VR.shape[-1]
        rhs = []
        if "coupled" in practices:
            rhs.append(np.broadcast_to(self.VR, Mm.shape[:2] + self.VR.shape[1:]))
        if "iii" in practices:
            KW = K @ self.W[None]
            rhs.append(self.VR3[None] + self.Y[None] @ KW)
        z = np.linalg.solve(Mm, np.concatenate(rhs, axis=-1))          # one factorisation for both practices
        if "coupled" in practices:
            out["coupled"] = self.PR[None] + AK @ z[..., :n]
        if "iii" in practices:
            out["iii"] = self.PR3[None] + self.A1[None] @ KW + AK @ z[..., -n:]
        return out

    def responses(self, omega, scales, practices) -> dict:
        """{practice: P·Lc⁻¹·X (S, F, n_perf, N)} at the sweep's speeds ``omega`` (S,) rad/s, wheel i at
        ``scales[i]`` × omega, for 'coupled' and 'iii': :meth:`solve`'s numbers from one eigen-decomposition of
        H = Γ·(Q + Y) per frequency (module doc; computed on the first call and kept for the same scales), the
        2w × 2w solves kept where its eigenvectors are ill-conditioned."""
        om = np.asarray(omega, dtype=float)
        key = (tuple(float(sc) for sc in scales), tuple(practices))
        if self._modal is None or self._modal[0] != key:
            self._modal = (key, self._modal_terms(scales, practices))
        lam, terms, bad = self._modal[1]
        phi = om[None, :, None] / (1.0 - om[None, :, None] * lam[:, None, :])   # (F, S, 2w)
        out = {}
        for p, (T, base, shape) in terms.items():
            Y = (phi @ T).reshape((lam.shape[0], om.size) + shape)
            Y += base[:, None]
            out[p] = np.moveaxis(Y, 1, 0)
        if bad.size:
            sub = self._at(bad)
            direct = sub.solve(sub.gains([om * sc for sc in scales]), practices)
            for p in practices:
                out[p][:, bad] = direct[p]
        return out

    def _modal_terms(self, scales, practices) -> tuple:
        """(λ (F, 2w), {practice: (Σ_k terms (F, 2w, n_perf·N), P·L0⁻¹·X (F, n_perf, N), (n_perf, N))}, frequencies
        to solve per speed) of :meth:`responses`."""
        nw, F = self.nw, self.Y.shape[0]
        Gam = np.zeros((F, 2 * nw, 2 * nw), dtype=complex)
        Qb = np.zeros_like(Gam)
        for i, (sp, sc) in enumerate(zip(self.splits, scales)):
            Gam[:, 2 * i:2 * i + 2, 2 * i:2 * i + 2] = gyro_rate(sp, sc)
            Qb[:, 2 * i:2 * i + 2, 2 * i:2 * i + 2] = sp["Q"]
        lam, V = np.linalg.eig(Gam @ (Qb + self.Y))
        ok = np.linalg.cond(V) < EIG_COND
        Vi = np.linalg.inv(np.where(ok[:, None, None], V, np.eye(2 * nw)))
        alpha = self.A1 @ V                                                # (F, n_perf, 2w)
        terms = {}
        for p in practices:
            X, base = (self.VR, self.PR) if p == "coupled" else (self.VR3 + self.W, self.PR3)
            beta = Vi @ (Gam @ X)                                          # (F, 2w, N)
            T = alpha[:, :, :, None] * beta[:, None, :, :]                 # (F, n_perf, 2w, N)
            shape = (T.shape[1], T.shape[3])
            terms[p] = (np.moveaxis(T, 2, 1).reshape(F, 2 * nw, -1), base, shape)
        return lam, terms, np.nonzero(~ok)[0]

    def _at(self, idx) -> "FloorSolver":
        """This solver on the frequencies ``idx`` only."""
        sub = object.__new__(FloorSolver)
        sub.nw, sub._modal = self.nw, None
        sub.splits = [{k: (v[idx] if isinstance(v, np.ndarray) and v.ndim and v.shape[0] == self.Y.shape[0] else v)
                       for k, v in sp.items()} for sp in self.splits]
        for name in ("A1", "Y", "PR", "VR", "PR3", "VR3", "W"):
            setattr(sub, name, getattr(self, name)[idx])
        return sub
