"""Mounting geometry, one home: the DCM check, the lever-arm load transform (and its removal from a test's torques)
and the spin-axis DCM.

Convention (``docs/formats.md``): a mounting is a direction-cosine matrix R (wheel frame ->
spacecraft frame, ``v_sc = R @ v_wheel``) and the interface position r (m, spacecraft frame, from the
reference point the loads are moved to).  Loads move as::

    F_sc = R F_w,      T_sc = R T_w + r × (R F_w)

i.e. the 6×6 :func:`load_transform` [[R, 0], [[r]× R, R]] acting on (Fx, Fy, Fz, Tx, Ty, Tz); a CSD
matrix transforms as T S Tᵀ, and by virtual work the interface accelerations as Tᵀ.

Used by :mod:`rwadist.mounting` (``rwadist psd --wheels``), :mod:`rwadist.coupling.geometry` and, as a
self-contained copy pinned by tests/test_geometry.py, the FMU runtime (``rwadist/fmu/runtime.py``
``rotation_check`` and ``to_spacecraft``).  Each caller raises its own error type with the message
:func:`rotation_problem` gives.
"""
from __future__ import annotations

import numpy as np

#: Tolerance on max |RᵀR − I| and on |det R − 1| of a DCM.  1e-6, not 1e-9: DCMs arrive from JSON
#: files and other tools with 6-7 significant digits (cos 35.26° typed as 0.816497 is 3e-7 off;
#: float32 round-off is ~1e-7), and a non-orthogonality ε changes a transformed load by at most ε
#: relative -- 1e-6 is four orders below the percent-level accuracy of any disturbance model, while a
#: real mistake (a swapped sign, a reflection, a transposed row) is off by O(1).
DCM_TOL = 1e-6


def rotation_problem(dcm, tol: float = DCM_TOL) -> str | None:
    """What makes ``dcm`` not a proper rotation (3×3, finite, RᵀR = I and det R = 1 within ``tol``),
    or None when it is one.  The messages say 'not orthonormal' or 'reflection' (det < 0)."""
    R = np.asarray(dcm, dtype=float)
    if R.shape != (3, 3):
        return f"must be a 3x3 matrix, got shape {R.shape}"
    if not np.all(np.isfinite(R)):
        return f"must be finite, got {R.tolist()!r}"
    orth = float(np.max(np.abs(R.T @ R - np.eye(3))))
    if orth > tol:
        return f"not orthonormal: max |RᵀR − I| = {orth:.3g} > {tol:g}; dcm = {R.tolist()}"
    det = float(np.linalg.det(R))
    if abs(det - 1.0) > tol:
        return f"det = {det:.6g}, not +1 (a reflection, not a rotation)"
    return None


def check_dcm(dcm, tol: float = DCM_TOL) -> np.ndarray:
    """The DCM as a float (3, 3) array; ValueError (:func:`rotation_problem`) unless a proper rotation."""
    problem = rotation_problem(dcm, tol)
    if problem is not None:
        raise ValueError(f"DCM {problem}")
    return np.asarray(dcm, dtype=float)


def skew(r) -> np.ndarray:
    """[r]× (3, 3) such that skew(r) @ v = r × v."""
    x, y, z = np.asarray(r, float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def load_transform(R, r) -> np.ndarray:
    """6×6 [[R, 0], [[r]× R, R]]: wheel-frame (F, T) at the interface -> (F, T) at the reference point,
    spacecraft frame (R (3, 3) DCM, r (3,) m).  Not checked: see :func:`check_dcm`."""
    R = np.asarray(R, float)
    T = np.zeros((6, 6))
    T[:3, :3] = R
    T[3:, 3:] = R
    T[3:, :3] = skew(r) @ R
    return T


def spin_axis_dcm(axis, ref=(0.0, 0.0, 1.0)) -> np.ndarray:
    """A DCM whose third column (wheel z, the spin axis) is ``axis`` normalised; wheel x is the part of
    ``ref`` normal to the axis (or of spacecraft x, then y, when ``ref`` is parallel to it), y = z × x.
    The wheel is axisymmetric, so any x is valid; ``ref`` only fixes which.  ValueError for a zero or
    non-finite axis."""
    z = np.asarray(axis, float)
    n = float(np.linalg.norm(z))
    if z.shape != (3,) or not np.isfinite(n) or n == 0:
        raise ValueError(f"spin axis must be a finite non-zero 3-vector, got {axis!r}")
    z = z / n
    ref = np.asarray(ref, float)
    x = ref - np.dot(ref, z) * z
    if np.linalg.norm(x) < 1e-9:
        x = np.array([1.0, 0.0, 0.0]) - z[0] * z
        if np.linalg.norm(x) < 1e-9:
            x = np.array([0.0, 1.0, 0.0]) - z[1] * z
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def remove_lever_arm(test, height: float):
    """Torques about the rotor centre from torques about the interface, for every run of the steady test ``test``
    (a :class:`rwadist.data.SteadyTest`; a new one is returned): T_rotor = T_int − i·height·F, i.e.
    Tx += height·Fy, Ty −= height·Fx, ``height`` (m) the rotor centre's z above the interface (runs lacking a
    channel are left as they are)."""
    from dataclasses import replace

    runs = []
    for r in test.runs:
        sig = dict(r.signals)
        if all(c in sig for c in ("Fx", "Fy", "Tx", "Ty")):
            sig["Tx"] = sig["Tx"] + height * sig["Fy"]
            sig["Ty"] = sig["Ty"] - height * sig["Fx"]
        runs.append(replace(r, signals=sig))
    return type(test)(runs, dict(test.meta))
