"""The stand's refit rounds jump to their limit once they converge geometrically (``rwadist fit --extended`` and the
wheel's modes in ``rwadist diagnose``: :func:`rwadist.stand_resonance.fit_extended_beside_stand`).

The rounds alternate the modes' fit (stand fixed) and the stand's (modes fixed); with the stand's start below its gain
each round removes only ~1/10 of what is left, so 25 rounds did not settle and the limit was taken only then.  The
limit is Aitken's Δ², exact for a geometric sequence (closed form below); once four moves of the stand keep one rate
the rounds go on from that limit.  Checked against the rounds without the early jump (25 rounds, then the same limit):
the same stand and modes, in fewer extended fits.
"""
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_diagnose_cells import iir_stand_test  # noqa: E402

import rwadist.extended_fit as extended_fit  # noqa: E402
import rwadist.stand_resonance as sr  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402

LIMIT = np.log([180.0, 0.03, 5.0])


def _history(rates, n, first=(-0.2, 0.5, -0.8)):
    """Stands (f_r, ζ, g) whose logs approach LIMIT geometrically: ln s_k = LIMIT + first·rate^k."""
    k = np.arange(n)[:, None]
    return [tuple(np.exp(row)) for row in LIMIT + np.asarray(first) * np.asarray(rates) ** k]


@pytest.mark.parametrize("rates", [(0.9, 0.9, 0.9), (0.5, 0.7, 0.95), (0.3, 0.3, 0.3)])
def test_aitken_step_is_the_limit_of_a_geometric_sequence(rates):
    limit, ratio = sr._aitken_step(_history(rates, 6), geometric_moves=4)
    assert np.log(limit) == pytest.approx(LIMIT, abs=1e-9)
    assert ratio == pytest.approx(max(rates), rel=1e-9)


def test_aitken_step_refuses_what_is_not_a_kept_rate():
    assert sr._aitken_step(_history((0.9, 0.9, 0.9), 4), geometric_moves=4) is None        # 3 moves, 4 asked
    assert sr._aitken_step(_history((-0.9, 0.9, 0.9), 6), geometric_moves=4) is None       # f oscillates
    assert sr._aitken_step(_history((0.99, 0.9, 0.9), 6), geometric_moves=4) is None       # ≥ EXTRAPOLATE_MAX_RATIO
    uneven = _history((0.9, 0.9, 0.9), 6)
    uneven[2] = tuple(np.exp(np.log(uneven[2]) + np.array([0.004, 0.0, 0.0])))              # f's ratios spread
    assert sr._aitken_step(uneven, geometric_moves=4) is None
    # the end-of-rounds use (2 moves) reads the last two moves only
    assert sr._aitken_step(uneven, geometric_moves=2) is not None
    settled = _history((0.9, 0.9, 0.9), 6, first=(1e-6, 1e-6, 1e-6))                        # nothing moving
    assert sr._aitken_step(settled, geometric_moves=4) is None


def test_rounds_jump_to_the_limit_the_plain_rounds_reach(monkeypatch):
    """2048 samples through the 180 Hz stand: the rounds settle at a ratio of ~0.9 a round.  With the jump: the stand
    and every mode where the 25 plain rounds and their limit put them (modes within 0.1 %, stand within 0.01 % in
    frequency and 1 % in ζ and gain), in less than half the extended fits."""
    test = iir_stand_test(np.linspace(300.0, 3000.0, 20), 3, n_samples=2048)
    fit = fit_empirical(compute_spectra(test))
    calls = []
    real_fit, real_step = extended_fit.fit_extended, sr._aitken_step
    monkeypatch.setattr(extended_fit, "fit_extended", lambda *a, **k: calls.append(1) or real_fit(*a, **k))
    jumped = sr.fit_extended_beside_stand(test, fit)
    n_jumped = len(calls)
    calls.clear()
    monkeypatch.setattr(sr, "_aitken_step", lambda h, moves=2: None if moves > 2 else real_step(h, moves))
    plain = sr.fit_extended_beside_stand(test, fit)
    assert plain.stand is not None and jumped.stand is not None
    assert 2 * n_jumped < len(calls), (n_jumped, len(calls))
    assert jumped.stand[0] == pytest.approx(plain.stand[0], rel=1e-4)
    assert jumped.stand[1:] == pytest.approx(plain.stand[1:], rel=0.01)
    for m, f in sr._mode_hz(plain.params).items():
        assert sr._mode_hz(jumped.params)[m] == pytest.approx(f, rel=1e-3), m
    assert jumped.unconstrained == plain.unconstrained == []


# --------------------------------------------------------------------------- the rounds on a known map

L_STAND = (180.0, 0.03, 5.0)


class _Rounds:
    """A stand's refit rounds whose map is known: the stand left on the residual of the modes' fit with stand s is
    M(s) = L + rate·(s − L) in logs (a geometric convergence to L at ``rate``), plus ``kick`` on every component when s
    is L itself (a limit the check must refuse); the radial translation follows the stand's gain (ln f = ln 227 +
    0.2·ln(g/5): the stand drags it), rocking and axial do not move.  Counts the extended fits and the stands the
    limits were checked at."""

    def __init__(self, rate, kick=0.0, start=(176.0, 0.045, 3.0)):
        self.rate, self.kick, self.start, self.fits, self.checked = rate, kick, start, 0, []

    def fit_extended(self, test, fit, stand=None, **kwargs):
        self.fits += 1
        g = 5.0 if stand is None else stand[2]
        f = {"radial_translation": 227.0 * (g / 5.0) ** 0.2, "rocking": 55.0, "axial": 70.0}
        params = SimpleNamespace(mass=1.0, I_rr=1.0, k_r=(2 * np.pi * f["radial_translation"]) ** 2,
                                 k_rock=(2 * np.pi * f["rocking"]) ** 2, k_z=(2 * np.pi * f["axial"]) ** 2)
        return SimpleNamespace(params=params, stand=stand, unconstrained=[], notes=[], coupled={},
                               rel_stderr={"k_r": 0.004, "k_rock": 0.004, "k_z": 0.004})

    def stand_on_modes(self, efit, near_hz):
        s = np.log(np.asarray(efit.stand, dtype=float))
        at_limit = np.allclose(np.exp(s), L_STAND, rtol=1e-9, atol=0.0)
        return tuple(np.exp(np.log(L_STAND) + self.rate * (s - np.log(L_STAND)) + (self.kick if at_limit else 0.0)))

    def run(self, monkeypatch, rounds=None):
        monkeypatch.setattr(extended_fit, "fit_extended", self.fit_extended)
        monkeypatch.setattr(sr, "stand_on_modes", self.stand_on_modes)
        real = sr._checked_limit
        monkeypatch.setattr(sr, "_checked_limit", lambda t, f, limit, h, kw: self.checked.append(len(h)) or
                            real(t, f, limit, h, kw))
        if rounds is not None:
            monkeypatch.setattr(sr, "REFERENCE_STAND_ROUNDS", rounds)
        return sr.fit_extended_beside_stand(SimpleNamespace(runs=[]), None, stand_start=self.start)


def test_a_geometric_map_jumps_to_its_fixed_point(monkeypatch):
    """rate 0.9: the jump after the stand's 4th move lands on L (Aitken is exact on a geometric sequence), the next
    round settles: 1 plain fit, the start, 4 rounds, the limit and one round (8 fits; the plain rounds would need ~75).
    The translation's rate is the map's and its drift is read over every round (start to end)."""
    r = _Rounds(0.9)
    efit = r.run(monkeypatch)
    assert np.allclose(efit.stand, L_STAND, rtol=1e-9)
    assert r.fits == 8 and r.checked == [5]
    rho, se_fixed, se_free = efit.coupled["radial_translation"]
    assert rho == pytest.approx(0.9, rel=1e-6)
    assert se_free == pytest.approx(se_fixed / np.sqrt(0.1), rel=1e-6)
    assert set(efit.coupled) == {"radial_translation"}                  # rocking and axial do not move


def test_a_refused_limit_is_asked_again_after_as_many_rounds_and_twice_at_most(monkeypatch):
    """A limit whose check moves away (the kick) is refused after the 4th move and again after 4 more, then not asked
    again: the rounds run to their cap (25), then the end-of-rounds limit of the last three stands is asked (f_r has
    settled there and is kept, so that limit is not L and is taken, with its note)."""
    r = _Rounds(0.9, kick=0.05)
    efit = r.run(monkeypatch)
    assert r.checked == [5, 9, 26]                                       # two in the rounds, one at their end
    assert r.fits == 1 + 1 + sr.REFERENCE_STAND_ROUNDS + 3
    assert any("had not settled after 25" in n for n in efit.notes)
    assert efit.stand[0] != pytest.approx(L_STAND[0], rel=1e-3)


def test_the_last_round_leaves_the_limit_to_the_end_of_the_rounds(monkeypatch):
    """With 4 rounds, the stand's 4th move comes in the last round: no jump there (it would leave one stand to the
    end-of-rounds limit, without its note), the end-of-rounds limit is taken with its note."""
    r = _Rounds(0.9)
    efit = r.run(monkeypatch, rounds=4)
    assert r.checked == [5]
    assert np.allclose(efit.stand, L_STAND, rtol=1e-9)
    assert any("had not settled after 4" in n and "Aitken" in n for n in efit.notes)
