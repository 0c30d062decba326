"""Practice 'ii' (the plant plus each wheel's rigid mass, thesis Table 5.1) of a modal plant, in closed form.

The practice's interface equation u = (I + M_r·G(f))⁻¹·X, y = P(f)·u (M_r = Σ_i Mt_iᵀ M6_i Mt_i the wheels' rigid
masses at the interface, :mod:`rwadist.coupling.performance`) does not depend on the wheel speed.  For a modal plant
(η̈ + Dη̇ + Kη = Φᵀu, a = Φη̈, y = Φ_p η; D = diag 2ζω, K = diag ω²) it is the mass-loaded structure

    M'·η̈ + D·η̇ + K·η = Φᵀ·X,     M' = I + Φᵀ M_r Φ,     y = Φ_p η.

Its rigid-body modes (ω = 0) make its state matrix defective, so they are split off exactly: with R the rigid
coordinates and F the M'-orthogonal complement of R (F = (I − R·M_RR⁻¹·Rᵀ·M')·E_flex, K·R = D·R = 0), the two parts
decouple (FᵀM'R = 0, FᵀKF = K_ff, FᵀDF = D_ff):

    y = Φ_p R M_RR⁻¹ RᵀΦᵀ X / s²  +  Φ_p F (s² M_FF + s D_ff + K_ff)⁻¹ FᵀΦᵀ X,

and the flexible part, non-defective, is one eigen-decomposition of its state matrix (states [ω·ζ, ζ̇], ω the plant's
flexible frequencies, where the eigenvectors of a lightly damped structure are near-orthogonal):
y_flex = Σ_j c_j (w_j·X)/(s − λ_j).  Every (speed, line) point then costs a few products over the modes
instead of an n_if × n_if interface matrix and its factorisation; one decomposition serves every speed and frequency.
Where the eigenvectors are ill-conditioned (> :data:`EIG_COND`), or the plant too large for one decomposition to pay
(> :data:`MAX_STATES`), :func:`rigid_practice` returns None and the caller keeps the solves.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .components import Plant, reciprocal

#: Eigenvector-matrix condition number (1-norm) above which the closed form is not used (its error grows with it;
#: the mass-loaded modes of a lightly damped structure in M-normalised coordinates stay near 1).
EIG_COND = 1e6
#: Largest number of flexible states (2 × flexible modes) given the closed form: its decomposition costs O(n³) once per
#: sweep (0.1 s CPU at 388 states) and its product per point grows with n, while the interface solve it replaces does
#: not; larger plants keep the solve.
MAX_STATES = 600


@dataclass(frozen=True, eq=False)
class RigidPractice:
    """y = T(s)·X of practice 'ii' (module doc): lam (2n_f,) the flexible poles, rad/s; CV (n_perf, 2n_f) their output
    vectors; WB (2n_f, n_if) their input vectors; rigid (n_perf, n_if) the rigid-body term's coefficient of 1/s²."""

    lam: np.ndarray
    CV: np.ndarray
    WB: np.ndarray
    rigid: np.ndarray

    def outputs(self, f_hz, mounts, loads) -> np.ndarray:
        """The performance outputs (..., n_perf, K) for the blocked loads ``loads`` [(..., 6) per wheel] of K wheels
        mounted by ``mounts`` [Mt (6, n_if) per wheel] (interface loads X = Mtᵀ·F) at frequencies ``f_hz`` (...)
        Hz (> 0): Σ_j (c_j w_jᵀ Mtᵀ)/(s − λ_j) for every wheel in one product over the modes, then each point's
        loads."""
        f = np.asarray(f_hz, dtype=float)
        w = 2 * np.pi * f.reshape(-1)
        r = reciprocal(-self.lam.real[None, :], w[:, None] - self.lam.imag[None, :])   # 1/(s − λ_j)  (N, 2n_f)
        n_perf, n = self.CV.shape
        T = np.concatenate([(self.CV.T[:, :, None] * (self.WB @ Mt.T)[:, None, :]).reshape(n, n_perf * 6) for Mt in mounts],
                           axis=1)                                          # (2n_f, K·n_perf·6)
        Z = (r @ T).reshape(w.size, len(mounts), n_perf, 6)
        Z += np.stack([self.rigid @ Mt.T for Mt in mounts])[None] / (-(w * w))[:, None, None, None]
        F = np.stack([np.asarray(Fk).reshape(-1, 6) for Fk in loads], axis=1)   # (N, K, 6)
        # each point's loads by a batched product (an einsum of the same sum took ~8x as long)
        y = np.swapaxes((Z @ F[..., None])[..., 0], 1, 2)                      # (N, n_perf, K)
        return y.reshape(f.shape + (n_perf, len(mounts)))


def rigid_practice(plant: Plant, M_r: np.ndarray) -> RigidPractice | None:
    """The closed form of practice 'ii' for a modal plant and the wheels' rigid masses ``M_r`` (n_if, n_if) at the
    interface; None for a plant without modal data, with more than :data:`MAX_STATES` flexible states or with
    ill-conditioned modes."""
    if plant.modal is None:
        return None
    wn, zeta, Phi, Phip = (np.asarray(x, dtype=float) for x in plant.modal)
    rig = wn == 0.0
    if 2 * np.count_nonzero(~rig) > MAX_STATES:
        return None
    Mp = np.eye(wn.size) + Phi.T @ M_r @ Phi
    flex = np.nonzero(~rig)[0]
    rid = np.nonzero(rig)[0]
    Fm = np.zeros((wn.size, flex.size))
    Fm[flex, np.arange(flex.size)] = 1.0
    rigid = np.zeros((Phip.shape[0], Phi.shape[0]))
    if rid.size:
        Mrr = Mp[np.ix_(rid, rid)]
        Fm[rid] = -np.linalg.solve(Mrr, Mp[np.ix_(rid, flex)])
        rigid = Phip[:, rid] @ np.linalg.solve(Mrr, Phi[:, rid].T)
    if flex.size == 0:
        return RigidPractice(np.zeros(0, complex), np.zeros((Phip.shape[0], 0), complex),
                             np.zeros((0, Phi.shape[0]), complex), rigid)
    Mff = Fm.T @ Mp @ Fm
    try:
        L = np.linalg.cholesky(0.5 * (Mff + Mff.T))
    except np.linalg.LinAlgError:
        return None
    # states [W·ζ, ζ̇] (W = the plant's own flexible frequencies, K_ff = W²): the state matrix's scale is ω_max, not
    # ω_max², and for a mass loading that leaves M_FF near I its eigenvectors are near-orthogonal ([ζ, ζ̇] makes their
    # condition number ~ ω_max/ω_min, and an eigen-decomposition of M_FF⁻¹K_ff loses the low modes' relative accuracy)
    W = wn[flex]
    n = flex.size
    MinvW = np.linalg.solve(L.T, np.linalg.solve(L, np.diag(W)))
    MinvD = np.linalg.solve(L.T, np.linalg.solve(L, np.diag(2 * zeta[flex] * W)))
    A = np.block([[np.zeros((n, n)), np.diag(W)], [-MinvW, -MinvD]])
    B = np.vstack([np.zeros((n, Phi.shape[0])), np.linalg.solve(L.T, np.linalg.solve(L, Fm.T @ Phi.T))])
    C = np.hstack([(Phip @ Fm) / W, np.zeros((Phip.shape[0], n))])
    lam, V = np.linalg.eig(A)
    if not np.all(np.isfinite(lam)):
        return None
    try:
        Vi = np.linalg.inv(V)
    except np.linalg.LinAlgError:
        return None
    if np.linalg.norm(V, 1) * np.linalg.norm(Vi, 1) > EIG_COND:
        return None
    return RigidPractice(lam, C @ V, Vi @ B, rigid)

