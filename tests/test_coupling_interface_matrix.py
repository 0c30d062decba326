"""The pieces every coupled sweep evaluates at each point (issue 37's speed-ups of them): the coupled interface matrix
I − Σ Mtᵀ·Zc·Mt·G (written row block by row block, without zeroing when the wheels' nodes tile the interface) against
the dense sum of its definition, whatever the wheels' nodes; and the real-arithmetic complex reciprocal against
numpy's complex division."""
import numpy as np

from rwadist.coupling import geometry
from rwadist.coupling.components import reciprocal
from rwadist.coupling.interface import _interface_matrix


def _dense(G, parts):
    n = G.shape[-1]
    L = np.broadcast_to(np.eye(n, dtype=complex), G.shape).copy()
    for Mt, Z in parts:
        L -= Mt.T @ Z @ Mt @ G
    return L


def _mounts(nodes, n_nodes):
    rng = np.random.default_rng(len(nodes))
    out = []
    for node in nodes:
        axis = rng.normal(size=3)
        out.append(geometry.selector(geometry.Mount(node, geometry.spin_axis_dcm(axis / np.linalg.norm(axis)),
                                                    tuple(rng.normal(scale=0.1, size=3))), 6, 6 * n_nodes))
    return out


def test_interface_matrix_is_its_definition_for_any_placement():
    rng = np.random.default_rng(7)
    n_nodes = 4
    n = 6 * n_nodes
    G = rng.normal(size=(3, 5, n, n)) + 1j * rng.normal(size=(3, 5, n, n))
    for nodes in ([0, 1, 2, 3], [3, 1, 0, 2], [0, 0, 1, 2], [1, 2], [2], [0, 1, 2, 3, 3]):
        # distinct nodes covering the interface (no zeroing), two wheels on one node, nodes left free
        parts = [(Mt, rng.normal(size=(3, 5, 6, 6)) + 1j * rng.normal(size=(3, 5, 6, 6)))
                 for Mt in _mounts(nodes, n_nodes)]
        ref = _dense(G, parts)
        assert np.max(np.abs(_interface_matrix(G, parts) - ref)) < 1e-12 * np.max(np.abs(ref)), nodes
    # a wheel's dynamic mass broadcast over the speeds (one per frequency) against per-point plant responses
    parts = [(Mt, rng.normal(size=(5, 6, 6)) + 0j) for Mt in _mounts([0, 1, 2, 3], n_nodes)]
    ref = _dense(G, [(Mt, np.broadcast_to(Z, (3, 5, 6, 6))) for Mt, Z in parts])
    assert np.max(np.abs(_interface_matrix(G, parts) - ref)) < 1e-12 * np.max(np.abs(ref))


def test_reciprocal_is_complex_division():
    rng = np.random.default_rng(3)
    re = rng.normal(size=(40, 30)) * 10.0 ** rng.uniform(-8, 8, size=(40, 30))
    im = rng.normal(size=30) * 10.0 ** rng.uniform(-8, 8, size=30)
    z = re + 1j * im
    r = reciprocal(re, im)
    assert r.shape == (40, 30) and r.dtype == complex
    assert np.max(np.abs(r * z - 1)) < 1e-15 * 4
    assert np.max(np.abs(r - 1 / z) / np.abs(1 / z)) < 1e-15 * 4
    assert np.array_equal(reciprocal(2.0, 0.0), np.array(0.5 + 0j)) and reciprocal(0.0, -4.0) == 0.25j
