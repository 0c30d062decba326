"""The coupled interface equation's pieces shared by the line and floor responses (:mod:`rwadist.coupling.performance`,
:mod:`rwadist.coupling.gyro_split`): a wheel's dynamic mass (flexible and hard-mounted), the congruences of constant
selectors, and I − Σ_i Mt_iᵀ Zc_i Mt_i G."""
from __future__ import annotations

import numpy as np

from rwadist import extended as ext

from .components import wheel_matrices, wheel_rigid_mass_matrix


def rigid_wheel_frf(p: ext.ExtendedParams, omega, f, housing_mass: float = 0.0, housing_inertia=(0.0, 0.0, 0.0)):
    """(Zc, B) of a hard-mounted (rigid-suspension) wheel at speeds omega (S,) rad/s and frequencies f (S, J)
    Hz: Zc (S, J, 6, 6), B (6, 6).  The limit of :func:`rwadist.coupling.components.wheel_matrices` as the suspension
    stiffnesses grow without bound (test): the rotor moves with the housing, so
    f = −M6 a + (gyroscopic) + B w with M6 the rigid wheel's mass matrix
    (:func:`rwadist.coupling.components.wheel_rigid_mass_matrix`), the rotor's angular momentum I_zz·Ω giving
    Tx = −I_zz Ω ω_y, Ty = +I_zz Ω ω_x (ω = α/s, s = i2πf), and B passing the free loads with the radial
    force's lever arm h (Tx −= h·wFy, Ty += h·wFx)."""
    om = np.asarray(omega, dtype=float)
    s = 2j * np.pi * np.asarray(f, dtype=float)
    M6 = wheel_rigid_mass_matrix(p, housing_mass, housing_inertia)
    Zc = np.broadcast_to(-M6, s.shape + (6, 6)).astype(complex)
    gyro = p.I_zz * om.reshape(om.shape + (1,) * (s.ndim - om.ndim)) / s
    Zc[..., 3, 4] -= gyro
    Zc[..., 4, 3] += gyro
    B = np.eye(6)
    B[3, 1], B[4, 0] = -p.height, p.height
    return Zc, B


#: Eigenvector-matrix condition number above which the wheel FRF falls back to direct solves.
_EIG_COND = 1e8


def _wheel_frf(spec, omega, f):
    """(Zc, B) of a flexible wheel at speeds omega (S,) and frequencies f (S, J): (S, J, 6, 6) each.

    Modal form per speed, H(s) = C V (s − Λ)⁻¹ V⁻¹ B + D (one 12×12 eigen-decomposition per speed, then a
    product per frequency; cond(V) ≈ 1.5e3 for the wheel's state scaling, so ~1e-12 relative); direct
    solves of (sI − A) X = B at speeds where V is ill-conditioned (> 1e8).  A hard-mounted wheel:
    :func:`rigid_wheel_frf`."""
    if spec.hard_mounted:
        Zc, B = rigid_wheel_frf(spec.params, omega, f, spec.housing_mass, spec.housing_inertia)
        return Zc, np.broadcast_to(B, Zc.shape)
    A, B, C, D = wheel_matrices(spec.params, omega, spec.housing_mass, spec.housing_inertia)
    s = 2j * np.pi * np.asarray(f, dtype=float)
    lam, V = np.linalg.eig(A)                                           # (S, 12), (S, 12, 12)
    ok = np.linalg.cond(V) < _EIG_COND
    H = np.empty(s.shape + (6, 12), dtype=complex)
    if ok.any():
        CV = (C @ V[ok])[:, None]                                       # (s, 1, 6, 12)
        VB = np.linalg.solve(V[ok], np.broadcast_to(B, (int(ok.sum()),) + B.shape))[:, None]
        r = 1.0 / (s[ok][..., None] - lam[ok][:, None, :])              # (s, J, 12)
        H[ok] = (CV * r[..., None, :]) @ VB + D
    if not ok.all():
        bad = ~ok
        M = s[bad][..., None, None] * np.eye(12) - A[bad][:, None]
        X = np.linalg.solve(M, np.broadcast_to(B, M.shape[:-2] + B.shape))
        H[bad] = C @ X + D
    return H[..., :6], H[..., 6:]


def _congruence(T, Z) -> np.ndarray:
    """Tᵀ Z T for a constant real T (6, 6) and stacked complex Z (..., 6, 6), as one matrix product over all
    of them: (TᵀZT)_cd = Σ_ab T_ac Z_ab T_bd, i.e. vec(Z) times kron(T, T) (real and imaginary parts apart)."""
    K = np.kron(T, T)
    Zf = np.ascontiguousarray(Z).reshape(-1, K.shape[0])
    return (Zf.real @ K + 1j * (Zf.imag @ K)).reshape(Z.shape[:-2] + (T.shape[1], T.shape[1]))


def _apply_left(M, x) -> np.ndarray:
    """M @ x[..., :] for a constant real M (a, b) and stacked complex vectors x (..., b): one matrix product."""
    xf = np.ascontiguousarray(x).reshape(-1, M.shape[1])
    return (xf.real @ M.T + 1j * (xf.imag @ M.T)).reshape(x.shape[:-1] + (M.shape[0],))


def _interface_matrix(G, parts) -> np.ndarray:
    """The coupled interface matrix I − Σ_i Mt_iᵀ Zc_i Mt_i G for plant accelerances G (..., n, n) and wheels
    ``parts`` = [(Mt_i (6, n) mount selector, Zc_i (..., 6, 6) dynamic mass)], broadcast together.  Each
    wheel touches only the interface DOFs its selector reaches (its non-zero columns: one node's six), so
    its term is Tᵀ Zc T·G[those rows] with T the selector's non-zero block -- a 6×6 and a 6×n product per
    point instead of n×n ones."""
    n = G.shape[-1]
    L = None
    reach = [np.nonzero(np.any(Mt != 0, axis=0))[0] for Mt, _ in parts]
    # when the wheels' nodes are distinct blocks covering every interface DOF, every row is written in place below
    # and L needs no zeroing (a pass over n × n per point)
    tiling = np.sort(np.concatenate(reach)) if reach else np.zeros(0, dtype=int)
    shapes = [np.broadcast_shapes(Z.shape[:-2], G.shape[:-2]) for _, Z in parts]
    covers = tiling.size == n and np.array_equal(tiling, np.arange(n)) and len(set(shapes)) == 1 \
        and all(r.size and np.all(np.diff(r) == 1) for r in reach)
    written = np.zeros(n, dtype=bool)                                # rows holding a term (the rest are still 0)
    for (Mt, Z), reached in zip(parts, reach):
        T = Mt[:, reached]
        ZT = _congruence(T, Z)
        shape = np.broadcast_shapes(ZT.shape[:-2], G.shape[:-2])
        if L is None:
            L = (np.empty if covers else np.zeros)(shape + (n, n), dtype=complex)
        if reached.size and np.all(np.diff(reached) == 1) and not written[reached].any() and L.shape[:-2] == shape:
            # a node's DOFs no wheel reached before: −ZT·G written in place (no term in its rows yet; negating the
            # 6 × 6 factor is exact and cheaper than negating the 6 × n product)
            cols = slice(int(reached[0]), int(reached[-1]) + 1)
            np.matmul(-ZT, G[..., cols, :], out=L[..., cols, :])
        else:
            L[..., reached, :] -= ZT @ G[..., reached, :]
        written[reached] = True
    if L is None:
        L = np.zeros(G.shape, dtype=complex)
    L.reshape(L.shape[:-2] + (n * n,))[..., :: n + 1] += 1.0      # the diagonal, in place
    return L
