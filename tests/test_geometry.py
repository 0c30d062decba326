"""One home for the mounting geometry (rwadist/geometry.py): one DCM tolerance for psd, coupling and
the FMU runtime (whose self-contained copies are pinned here), one lever-arm transform, one spin-axis
builder."""
import numpy as np
import pytest

from rwadist import geometry, mounting
from rwadist.data import DataError


def _rot(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _off(R, eps):
    """R with its RᵀR − I of size ~eps (a symmetric stretch)."""
    return R @ (np.eye(3) + eps * np.diag([1.0, 0.0, 0.0]))


def test_one_tolerance_for_every_consumer():
    """A DCM 1e-7 off (as typed with 7 digits) passes psd mountings, coupling and the FMU runtime alike;
    1e-5 off fails all three (before: coupling refused at 1e-9, the others at 1e-6)."""
    cp = pytest.importorskip("rwadist.coupling")
    from rwadist.fmu import runtime as rt

    R = _rot(np.random.default_rng(1))
    for eps, ok in ((1e-7, True), (1e-5, False)):
        bad = _off(R, eps)
        results = []
        for make, err in ((lambda: mounting.Mounting(bad), DataError),
                          (lambda: cp.Mount(0, bad), cp.NotARotationError),
                          (lambda: rt.rotation_check(bad), rt.ModelError),
                          (lambda: geometry.check_dcm(bad), ValueError)):
            try:
                make()
                results.append(True)
            except err as exc:
                assert "orthonormal" in str(exc) or "not a proper rotation" in str(exc)
                results.append(False)
        assert results == [ok] * 4, (eps, results)


def test_runtime_copy_matches_the_home():
    """The FMU runtime's self-contained rotation check and spacecraft transform equal rwadist.geometry's."""
    import inspect

    from rwadist.fmu import runtime as rt

    assert inspect.signature(rt.rotation_check).parameters["tol"].default == geometry.DCM_TOL
    rng = np.random.default_rng(2)
    R, r = _rot(rng), rng.normal(size=3)
    loads = rng.normal(size=(5, 6))
    np.testing.assert_allclose(rt.to_spacecraft(loads, R, r), loads @ geometry.load_transform(R, r).T,
                               rtol=0, atol=1e-14)


def test_lever_arm_transform_is_r_cross_f():
    """T_sc = R T + r × (R F), checked against numpy's cross product, and T Tᵀ-consistency of the 6×6."""
    rng = np.random.default_rng(3)
    R, r = _rot(rng), rng.normal(size=3)
    F, T = rng.normal(size=3), rng.normal(size=3)
    out = geometry.load_transform(R, r) @ np.concatenate([F, T])
    np.testing.assert_allclose(out[:3], R @ F, atol=1e-14)
    np.testing.assert_allclose(out[3:], R @ T + np.cross(r, R @ F), atol=1e-14)
    np.testing.assert_allclose(mounting.Mounting(R, tuple(r)).transform, geometry.load_transform(R, r), atol=0)


@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 0, 0), (0.3, 1, 0.2), (1, 1, 1), (0, -1, 1e-12)])
def test_spin_axis_builders_are_one(axis):
    """Both spin-axis DCMs are proper rotations with z along the axis; coupling's is the home's with
    coupling's reference direction."""
    cp = pytest.importorskip("rwadist.coupling")
    z = np.asarray(axis, float) / np.linalg.norm(axis)
    for R in (geometry.spin_axis_dcm(axis), mounting.dcm_from_spin_axis(axis), cp.spin_axis_dcm(axis)):
        assert geometry.rotation_problem(R, 1e-12) is None
        np.testing.assert_allclose(R[:, 2], z, atol=1e-15)
    with pytest.raises(ValueError, match="non-zero"):
        geometry.spin_axis_dcm((0, 0, 0))
