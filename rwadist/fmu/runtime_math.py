"""Closed-form helpers and the native kernel's interface of the FMU runtime (part of
:mod:`rwadist.fmu.runtime`; numpy only, no rwadist, no other module of the runtime).

Copied verbatim into the FMU's ``resources/`` (as ``rwadist_fmu_runtime_math.py``).  Here: the stable roots of a
mode's characteristic polynomial (:func:`quad_roots`), the wheel → spacecraft frame change (:func:`to_spacecraft`,
:func:`frame12`), and the memory layout and loader of the C step kernel ``rwadist_kernel_step``
(:data:`KERNEL_PARAMS`, :func:`load_kernel`).
"""
from __future__ import annotations

import cmath
import ctypes

import numpy as np


def quad_roots(m, c, k):
    """Both roots of m λ² + c λ + k = 0 (c complex), the stable form of rwadist.extended."""
    c = complex(c)
    disc = cmath.sqrt(c * c - 4 * m * k)
    sgn = 1.0 if (c.conjugate() * disc).real >= 0 else -1.0
    q = -0.5 * (c + sgn * disc)
    return q / m, k / q


def to_spacecraft(out, R, r):
    """Spacecraft-frame loads (…, 6) of wheel-frame loads ``out`` (…, 6): F_sc = R F,
    T_sc = R T + r × F_sc (R wheel → spacecraft DCM, r interface position in m)."""
    out = np.asarray(out, dtype=float)
    F = out[..., :3] @ np.asarray(R).T
    T = out[..., 3:] @ np.asarray(R).T + np.cross(np.asarray(r, dtype=float), F)
    return np.concatenate([F, T], axis=-1)


# ------------------------------------------------------------------ native kernel

#: cfg layout of ``rwadist_kernel_step`` (rwadist/fmu/native/rwadist_fmu_native.c): parameter order,
#: offsets of the fixed poles, mounting, and the per-component block (σh, direction, coef·C,
#: −i·coef·C·[imbalance], coef·A_ref, Ω_ref, p of an amplitude law, ω_off (rad/s, sidebands),
#: number of resonances, cfg index of its resonance entries), then the resonance table
#: (KERNEL_RES doubles per entry: 2π f_r, 2·g·ζ, 2·ζ).  State: [0] φ, [1] time since t0, then the
#: complex states.  The C file repeats it; tests/test_fmu.py checks both agree by running.
KERNEL_PARAMS = ("mass", "c_r", "k_r", "I_rr", "c_rock", "k_rock", "I_zz", "c_z", "k_z", "height")
KERNEL_COMP = 32
KERNEL_STRIDE = 13
KERNEL_RES = 3

def load_kernel(path):
    """``rwadist_kernel_step`` of the native library at ``path`` as a ctypes function, or None
    when the file is missing or is not the rwadist native library (then numpy steps)."""
    try:
        lib = ctypes.CDLL(str(path))
        fn = lib.rwadist_kernel_step
    except (OSError, AttributeError):
        return None
    fn.restype = None
    fn.argtypes = [ctypes.c_void_p] * 3 + [ctypes.c_double] * 4
    return fn


def frame12(o, R, r):
    """[wheel-frame 6] + [spacecraft-frame 6] as a list of floats (R 3×3 nested, r 3)."""
    f0, f1, f2, t0, t1, t2 = o.tolist() if isinstance(o, np.ndarray) else (float(v) for v in o)
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    rx, ry, rz = r
    fx = r00 * f0 + r01 * f1 + r02 * f2
    fy = r10 * f0 + r11 * f1 + r12 * f2
    fz = r20 * f0 + r21 * f1 + r22 * f2
    return [f0, f1, f2, t0, t1, t2, fx, fy, fz,
            r00 * t0 + r01 * t1 + r02 * t2 + ry * fz - rz * fy,
            r10 * t0 + r11 * t1 + r12 * t2 + rz * fx - rx * fz,
            r20 * t0 + r21 * t1 + r22 * t2 + rx * fy - ry * fx]


