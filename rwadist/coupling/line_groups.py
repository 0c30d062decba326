"""A wheel's hard-mounted line phasors grouped by (h, frequency offset, ripple order): the blocked loads the coupled
line sweep (:mod:`rwadist.coupling.performance`) solves for, built in blocks of speeds to bound their work arrays."""
from __future__ import annotations

import numpy as np

from rwadist import extended as ext
from rwadist import extended_ripple as ripple_mod


def _grouped_lines(spec, omega, k_max: int = 0):
    """Hard-mounted line phasors of ``spec`` (a :class:`rwadist.coupling.performance.WheelSpec`) summed over lines with
    equal h and frequency offset (and, with a speed ripple, the ripple order m, the complex ripple coefficient applied
    per line first) at speeds ``omega`` (S,) rad/s, orders up to ``k_max``:
    (h (J,), f_offset (J,) Hz incl. m·f_r, m (J,), f (S, J) Hz, F (S, J, 6))."""
    S = np.size(omega)
    if spec.ripple is None:
        m = np.zeros(1, dtype=int)
        f_all, amp = ext.steady_lines(spec.params, spec.lines, omega, rigid=spec.hard_mounted)
        f_all, amp = f_all[:, :, None], amp[:, :, None, :]
    else:
        m, f_all, amp = ripple_mod.ripple_lines(spec.params, spec.lines, omega, spec.ripple, k_max, rigid=spec.hard_mounted)
    L, M = len(spec.lines), m.size
    keys = np.array([(ln.h, ln.f_offset, mm) for ln in spec.lines for mm in m], dtype=float)
    ku, first, inv = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inv = np.ravel(inv)
    ind = np.zeros((ku.shape[0], keys.shape[0]))
    ind[inv, np.arange(keys.shape[0])] = 1.0
    A2 = np.moveaxis(amp.reshape(S, L * M, 6), 1, 0).reshape(L * M, S * 6)
    F = np.moveaxis((ind @ A2.real + 1j * (ind @ A2.imag)).reshape(-1, S, 6), 0, 1)
    fr = 0.0 if spec.ripple is None else spec.ripple.f_hz
    return (ku[:, 0], ku[:, 1] + ku[:, 2] * fr, ku[:, 2].astype(int), f_all.reshape(S, L * M)[:, first], F)


#: Most (speed, line, ripple order) points :func:`_grouped_lines` takes at once (work arrays ~5x their loads: ~100 MB)
GROUPED_POINTS = 200_000


def grouped_lines_blocked(spec, omega, k_max: int = 0):
    """:func:`_grouped_lines` over blocks of at most :data:`GROUPED_POINTS` // (lines x orders) speeds, joined along
    the speeds (each speed's phasors are its own: the same values as in one block)."""
    omega = np.atleast_1d(omega)
    per_speed = max(len(spec.lines) * (2 * k_max + 1 if spec.ripple is not None else 1), 1)
    block = max(1, GROUPED_POINTS // per_speed)
    if omega.size <= block:
        return _grouped_lines(spec, omega, k_max)
    h, off, m, f0, F0 = _grouped_lines(spec, omega[:block], k_max)
    f, F = np.empty((omega.size,) + f0.shape[1:]), np.empty((omega.size,) + F0.shape[1:], dtype=F0.dtype)
    f[:block], F[:block] = f0, F0
    for i0 in range(block, omega.size, block):
        f[i0:i0 + block], F[i0:i0 + block] = _grouped_lines(spec, omega[i0:i0 + block], k_max)[3:]
    return h, off, m, f, F
