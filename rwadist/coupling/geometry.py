"""Mounting geometry: where a 6-axis component sits on a plant's interface nodes.

Convention (``docs/formats.md``): a mounting is a direction-cosine matrix ``dcm``
(wheel frame -> spacecraft frame, so ``v_sc = dcm @ v_wheel``) plus the interface
position ``position`` (m, spacecraft frame) relative to the reference point of the plant
node it is bolted to.  Moving a load from the interface point to the node adds r × F to
the torque.

Load transform (wheel-frame loads at the interface point -> node loads, spacecraft frame)::

    T = [[R, 0], [r̃ R, R]]          F_node = R F_w,  T_node = R T_w + r × (R F_w)

and, by virtual work, the kinematic transform is its transpose: the interface's linear and
angular acceleration in the wheel frame is ``a_w = T^T a_node`` (a + α × r rotated back).

The DCM check (one tolerance), the lever-arm transform and the spin-axis DCM have one home,
:mod:`rwadist.geometry`; this module adds the plant-node placement (:class:`Mount`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rwadist import geometry
from rwadist.geometry import DCM_TOL, skew  # noqa: F401  (re-exported: their home is rwadist.geometry)

from .errors import InterfaceMismatchError, NotARotationError


def check_dcm(dcm, tol: float = DCM_TOL) -> np.ndarray:
    """The DCM as a float (3, 3) array; NotARotationError unless a proper rotation
    (:func:`rwadist.geometry.rotation_problem`, tolerance :data:`rwadist.geometry.DCM_TOL`)."""
    problem = geometry.rotation_problem(dcm, tol)
    if problem is not None:
        raise NotARotationError(f"DCM {problem}")
    return np.asarray(dcm, dtype=float)


def rotation(axis: str, angle: float) -> np.ndarray:
    """DCM of a right-handed rotation by ``angle`` (rad) about 'x', 'y' or 'z'."""
    c, s = np.cos(angle), np.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    if axis == "z":
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")


def spin_axis_dcm(axis) -> np.ndarray:
    """A DCM taking the wheel's z (spin) axis onto the unit vector ``axis`` (spacecraft frame);
    the wheel x axis is chosen perpendicular to it (any choice: the wheel is axisymmetric) along
    helper × axis, helper = spacecraft x (or y when the axis is within 26° of x):
    :func:`rwadist.geometry.spin_axis_dcm` with that reference."""
    z = np.asarray(axis, dtype=float)
    n = np.linalg.norm(z)
    if z.shape != (3,) or not np.isfinite(n) or n == 0:
        raise ValueError(f"spin axis must be a finite non-zero vector, got {axis!r}")
    helper = np.array([1.0, 0, 0]) if abs(z[0] / n) < 0.9 else np.array([0, 1.0, 0])
    return geometry.spin_axis_dcm(z, np.cross(helper, z / n))


def load_transform(dcm, position) -> np.ndarray:
    """6×6 T mapping wheel-frame loads at the interface point to node loads (see module doc)."""
    R = check_dcm(dcm)
    r = np.asarray(position, dtype=float)
    if r.shape != (3,) or not np.all(np.isfinite(r)):
        raise ValueError(f"position must be 3 finite numbers (m), got {position!r}")
    # the same transform the broadband PSD uses for the spacecraft frame
    return geometry.load_transform(R, r)


@dataclass(frozen=True)
class Mount:
    """Where a 6-axis component is bolted: plant interface node ``node`` (0-based; node k owns
    plant interface DOFs 6k..6k+5 in the order x, y, z, θx, θy, θz), DCM wheel -> spacecraft,
    interface position (m) relative to the node's reference point, spacecraft frame."""

    node: int = 0
    dcm: np.ndarray = field(default_factory=lambda: np.eye(3))
    position: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        check_dcm(self.dcm)
        if not isinstance(self.node, (int, np.integer)) or self.node < 0:
            raise ValueError(f"Mount.node must be an integer >= 0, got {self.node!r}")

    def selector(self, n_component: int, n_interface: int) -> np.ndarray:
        """Mt (n_component × n_interface): component interface accelerations = Mt @ plant
        interface accelerations; plant interface loads += Mtᵀ @ component loads."""
        if n_component != 6:
            raise InterfaceMismatchError(f"a Mount places a 6-axis component; this component has "
                                         f"{n_component} interface DOFs (attach it with mount=None)")
        if n_interface % 6:
            raise InterfaceMismatchError(f"a Mount needs a plant whose interface is 6-DOF nodes; the plant "
                                         f"has {n_interface} interface DOFs, not a multiple of 6")
        if 6 * (self.node + 1) > n_interface:
            raise InterfaceMismatchError(f"Mount.node = {self.node} but the plant has only "
                                         f"{n_interface // 6} interface node(s)")
        E = np.zeros((6, n_interface))
        E[:, 6 * self.node:6 * self.node + 6] = np.eye(6)
        return load_transform(self.dcm, self.position).T @ E


def selector(mount, n_component: int, n_interface: int) -> np.ndarray:
    """Mt for ``mount`` (a :class:`Mount`) or, for ``mount=None``, the identity when the component
    and plant interfaces have the same size (InterfaceMismatchError otherwise)."""
    if mount is None:
        if n_component != n_interface:
            raise InterfaceMismatchError(f"component has {n_component} interface DOFs, plant has "
                                         f"{n_interface}; give a Mount (6-axis) or matching sizes")
        return np.eye(n_interface)
    return mount.selector(n_component, n_interface)
