"""A mode coupled to the test stand: its standard error with the stand free, from the stand's refit rounds.

:func:`rwadist.stand_resonance.fit_extended_beside_stand` alternates the modes' least squares (stand fixed) and the
stand's (modes fixed).  The check here is the closed form of such block-coordinate rounds on a linear least-squares
problem y = a·x1 + b·x2 + noise, independent of the fit: a's moves shrink by r² a round (r the correlation of x1 and
x2), and its marginal standard error is σ/sqrt(x1·x1·(1 − r²)) while with b fixed it is σ/sqrt(x1·x1) (the Schur
complement of (XᵀX)).  :func:`coupled_stderr`, given a's trajectory as a mode's ln f and the fixed-b standard error,
must return the marginal one; :func:`declare_coupled_modes` declares the mode when 1.5 of those exceed the tolerance.
"""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.stand_resonance import coupled_stderr, declare_coupled_modes

MODES = ("radial_translation", "rocking", "axial")


def _rounds(r: float, sigma: float, n_rounds: int = 12, n: int = 400, seed: int = 0):
    """(trajectory of a over the rounds, se of a with b fixed, marginal se of a) for regressors of correlation r."""
    rng = np.random.default_rng(seed)
    u, v = rng.standard_normal(n), rng.standard_normal(n)
    u, v = u / np.linalg.norm(u), v - (v @ u) / (u @ u) * u
    v /= np.linalg.norm(v)
    x1, x2 = u, r * u + np.sqrt(1 - r * r) * v           # unit norm, x1·x2 = r exactly
    y = 5.3 * x1 - 2.0 * x2 + sigma * rng.standard_normal(n)
    a, b, path = 0.0, 0.0, []
    for _ in range(n_rounds):
        a = x1 @ (y - b * x2) / (x1 @ x1)                 # the modes, stand fixed
        b = x2 @ (y - a * x1) / (x2 @ x2)                 # the stand, modes fixed
        path.append(a)
    X = np.column_stack([x1, x2])
    marginal = sigma * np.sqrt(np.linalg.inv(X.T @ X)[0, 0])
    return np.array(path), sigma / np.sqrt(x1 @ x1), marginal


def _as_modes(lnf):
    """Round-by-round mode frequencies: the translation following exp(ln f), the others fixed."""
    return [{"radial_translation": float(np.exp(x)), "rocking": 55.0, "axial": 70.0} for x in lnf]


@pytest.mark.parametrize("r", [0.6, 0.9, 0.97])
def test_stderr_with_the_stand_free_is_the_schur_complement(r):
    path, se_fixed, marginal = _rounds(r, sigma=0.01)
    lnf = np.log(200.0) + 0.01 * path                      # a small, geometric drift of ln f
    got = coupled_stderr(_as_modes(lnf), {"k_r": 2 * 0.01 * se_fixed, "k_rock": 0.01, "k_z": 0.01})
    assert set(got) == {"radial_translation"}            # the modes that did not move are not coupled
    rho, fixed, free = got["radial_translation"]
    assert rho == pytest.approx(r * r, rel=1e-6)
    assert fixed == pytest.approx(0.01 * se_fixed, rel=1e-12)
    assert free == pytest.approx(0.01 * marginal, rel=1e-6)


def test_no_drift_or_noise_like_moves_are_not_coupled():
    rng = np.random.default_rng(3)
    noisy = np.log(200.0) + 1e-4 * rng.standard_normal(12)          # moves of both signs
    assert coupled_stderr(_as_modes(noisy), {"k_r": 0.02}) == {}
    # geometric but smaller in all than the fixed-stand standard error: nothing measurable moved
    small = np.log(200.0) + 1e-4 * (1 - 0.5 ** np.arange(12))
    assert coupled_stderr(_as_modes(small), {"k_r": 0.02}) == {}
    # one sign and shrinking, but not at one rate (0.9, 0.33, 0.9): no rate of the rounds is measured
    steps = 0.01 * np.array([1.0, 0.9, 0.3, 0.27])
    uneven = np.log(200.0) + np.concatenate([[0.0], np.cumsum(steps)])
    assert coupled_stderr(_as_modes(uneven), {"k_r": 0.002}) == {}
    assert set(coupled_stderr(_as_modes(np.log(200.0) + np.concatenate([[0.0], np.cumsum(0.01 * 0.9 ** np.arange(4))])),
                              {"k_r": 0.002})) == {"radial_translation"}
    # too few rounds to measure a rate
    assert coupled_stderr(_as_modes(np.log(200.0) + 0.01 * (1 - 0.9 ** np.arange(4))), {"k_r": 0.02}) == {}


@pytest.mark.parametrize("r, declared", [(0.6, False), (0.97, True)])
def test_a_mode_coupled_to_the_stand_is_declared(r, declared):
    path, se_fixed, marginal = _rounds(r, sigma=0.01)
    scale = 0.009 / se_fixed                                # the mode known to ±0.9 % with the stand fixed
    lnf = np.log(220.0) + scale * path
    last = _as_modes(lnf)[-1]
    k = {m: (2 * np.pi * last[m]) ** 2 for m in MODES}            # per unit mass and inertia: f = sqrt(k)/2π
    params = SimpleNamespace(k_r=k["radial_translation"], mass=1.0, k_rock=k["rocking"], I_rr=1.0, k_z=k["axial"])
    rel = {"k_r": 2 * 0.009, "k_rock": 0.002, "k_z": 0.002}
    efit = SimpleNamespace(params=params, unconstrained=[], notes=[], rel_stderr=rel,
                           coupled=coupled_stderr(_as_modes(lnf), rel),
                           identified={"radial_translation": True, "rocking": True, "axial_translation": True})
    out = declare_coupled_modes(efit, tolerance=0.02)
    # 1.5 standard errors with the stand free against the 2 % tolerance: 1.5·0.9 %/sqrt(1 − r²) is 1.7 % at r 0.6
    # and 5.5 % at r 0.97
    assert (out == ["radial_translation"]) is declared
    assert ("radial_translation" in efit.unconstrained) is declared
    assert efit.identified["radial_translation"] is (not declared)
    if declared:
        (note,) = efit.notes
        assert note.startswith("radial_translation: NOT CONSTRAINED beside the test stand")
        assert f"up to ±{100 * 1.5 * scale * marginal:.1f} % with it free" in note
        assert f"located at {last['radial_translation']:.4g} Hz" in note
    else:
        assert efit.notes == []


def test_the_reference_fit_declares_what_the_rounds_recorded(monkeypatch):
    """``rwadist fit --extended`` (:func:`rwadist.api.fit_extended`) declares the modes its stand rounds recorded as
    dragged along (``ExtendedFit.coupled``) when 1.5 of their stand-free standard errors exceed 2 %, in the model
    file's ``analytical.unconstrained`` and a note; a mode within the tolerance is not declared."""
    import rwadist.stand_resonance as sr
    from rwadist import api
    from rwadist.presets import preset
    from rwadist.teststand import simulate_steady

    real = sr.fit_extended_beside_stand

    def recorded(*args, **kwargs):
        efit = real(*args, **kwargs)
        efit.coupled = {"rocking": (0.95, 0.003, 0.0134), "axial": (0.5, 0.002, 0.0028)}
        return efit

    monkeypatch.setattr(sr, "fit_extended_beside_stand", recorded)
    w = preset("ithaco-e")
    test = simulate_steady(w, np.linspace(600.0, 2400.0, 12), sample_rate=1920.0, n_samples=4096, physics="extended",
                           noise=0.01, seed=4)
    efit, model = api.fit_extended(test, mass=w.mass_kg, radius=w.radius_m)
    assert "rocking" in model.analytical["unconstrained"] and "axial" not in model.analytical["unconstrained"]
    assert any(n.startswith("rocking: NOT CONSTRAINED beside the test stand") for n in model.analytical["fit"]["notes"])


def _drift(ratios, first=0.01):
    """ln f of a mode whose successive moves are ``first`` times the running products of ``ratios``."""
    moves = first * np.cumprod(np.r_[1.0, ratios])
    return np.log(200.0) + np.concatenate([[0.0], np.cumsum(moves)])


def test_each_mode_reads_its_own_rate_and_standard_error():
    # rocking and axial drift at different, geometric rates; their stand-fixed errors are half of k_rock's and k_z's
    lnr, lnz = _drift([0.85, 0.9, 0.95]), _drift([0.5, 0.5, 0.5])
    modes = [{"radial_translation": 220.0, "rocking": float(np.exp(r)), "axial": float(np.exp(z))}
             for r, z in zip(lnr, lnz)]
    got = coupled_stderr(modes, {"k_r": 0.01, "k_rock": 0.004, "k_z": 0.006})
    assert set(got) == {"rocking", "axial"}
    assert got["rocking"][0] == pytest.approx(0.9) and got["axial"][0] == pytest.approx(0.5)   # the mean ratio
    assert got["rocking"][1] == pytest.approx(0.002) and got["axial"][1] == pytest.approx(0.003)
    assert got["rocking"][2] == pytest.approx(0.002 / np.sqrt(0.1))
    # a drift that grows (ratios above 1) is no convergence: no rate
    assert coupled_stderr(_as_modes(_drift([1.05, 1.1, 1.15])), {"k_r": 0.002}) == {}


def _efit(coupled, unconstrained=()):
    k = {m: (2 * np.pi * f) ** 2 for m, f in (("radial_translation", 220.0), ("rocking", 55.0), ("axial", 70.0))}
    params = SimpleNamespace(k_r=k["radial_translation"], mass=1.0, k_rock=k["rocking"], I_rr=1.0, k_z=k["axial"])
    return SimpleNamespace(params=params, unconstrained=list(unconstrained), notes=[], rel_stderr={}, coupled=coupled,
                           identified={"radial_translation": True, "rocking": True, "axial_translation": True})


def test_declared_at_one_and_a_half_bounds_over_the_tolerance():
    # 1.5 × 1.6 % = 2.4 % > 2 %: declared; 1.5 × 1.3 % = 1.95 %: not (at 1 standard error both would pass)
    efit = _efit({"axial": (0.9, 0.005, 0.016), "rocking": (0.9, 0.004, 0.013)})
    assert declare_coupled_modes(efit, tolerance=0.02) == ["axial"]
    assert efit.unconstrained == ["axial"] and efit.identified["axial_translation"] is False
    assert efit.identified["rocking"] is True
    (note,) = efit.notes
    assert note.startswith("axial: NOT CONSTRAINED") and "up to ±2.4 % with it free" in note and "70 Hz" in note
    # a mode already declared (by the fit or another rule) is not declared twice
    again = _efit({"rocking": (0.95, 0.01, 0.045)}, unconstrained=["rocking"])
    assert declare_coupled_modes(again) == [] and again.notes == [] and again.unconstrained == ["rocking"]
