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
