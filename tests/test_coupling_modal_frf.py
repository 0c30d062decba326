"""A modal plant's accelerance and performance FRFs (Plant.frf: the modal sums, which every coupled sweep evaluates
at each of its points) are the state-space model's frequency response (coupling.frf: a balanced solve of
(sI − A)X = B with refinement), and G is symmetric, at any shape of frequencies."""
import numpy as np

from rwadist import coupling as cp


def _plant(seed=3):
    rng = np.random.default_rng(seed)
    fn = np.concatenate([np.zeros(3), np.geomspace(2.0, 600.0, 17)])           # rigid-body and flexible modes
    zeta = np.concatenate([np.zeros(3), rng.uniform(0.002, 0.05, 17)])
    Phi = rng.normal(scale=0.1, size=(12, fn.size))
    Phip = rng.normal(scale=1e-3, size=(3, fn.size))
    return cp.modal_plant(fn, zeta, Phi, Phip, ("a", "b", "c"))


def test_modal_frf_is_the_state_space_response():
    plant = _plant()
    wn = 2 * np.pi * np.asarray(plant.modal[0])
    f = np.concatenate([[0.3, 1.7, 45.0, 2500.0], wn[5:9] / (2 * np.pi) * (1 + 1e-4)]).reshape(2, 4)
    G, P = plant.frf(f)
    assert G.shape == (2, 4, 12, 12) and P.shape == (2, 4, 3, 12)
    H = np.moveaxis(cp.frf(plant.state_space(), f.ravel()), -1, 0).reshape(2, 4, 15, 12)
    for ours, ref in ((G, H[..., :12, :]), (P, H[..., 12:, :])):
        scale = np.max(np.abs(ref), axis=(-2, -1), keepdims=True)                  # each frequency's largest entry
        assert np.max(np.abs(ours - ref) / scale) < 1e-11
    assert np.array_equal(G, np.swapaxes(G, -1, -2))


def test_modal_frf_at_one_frequency_keeps_its_shape():
    plant = _plant(5)
    G, P = plant.frf(12.5)
    G1, P1 = plant.frf(np.array([12.5]))
    assert G.shape == (12, 12) and P.shape == (3, 12)
    assert np.array_equal(G, G1[0]) and np.array_equal(P, P1[0])
