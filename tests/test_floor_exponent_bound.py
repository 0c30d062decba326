"""A broadband floor's exponent at the edge of the grid it is chosen from
(:data:`rwadist.diagnose.constants.FLOOR_EXPONENTS`, 0.5-8) is a bound, not a value: the likeliest law lies there or
beyond.  Checked on band means of known laws (a floor ∝ Ω^10 is read p 8: ``at_least``; ∝ Ω^5, inside the grid: 5, no
bound; a flat-ish ∝ Ω^0.2: p 0.5, ``at_most``), written in the floor's entry (the model file's, which reads back) and
in its line of words."""
from __future__ import annotations

import numpy as np
import pytest

from rwadist.diagnose.constants import FLOOR_EXPONENTS
from rwadist.effects.broadband_floor_diagnose import BroadbandFloor, _floor_law
from rwadist.effects_text import describe_effect
from rwadist.schema import parse_effects


@pytest.mark.parametrize("p_true, p_read, bound", [(10.0, 8.0, "at_least"), (5.0, 5.0, None),
                                                   (0.2, 0.5, "at_most")])
def test_an_exponent_at_the_grid_edge_is_written_as_a_bound(p_true, p_read, bound):
    assert FLOOR_EXPONENTS[0] == 0.5 and FLOOR_EXPONENTS[-1] == 8.0
    x0 = np.linspace(0.2, 1.6, 16)                       # Ω/Ω_ref of 16 runs
    n, g = np.array([1.0, 2.0, 0.5]), np.array([3.0, 1.0, 4.0])
    y = n[None, :] + g[None, :] * x0[:, None] ** p_true  # band means of the law, no scatter
    p, _, _ = _floor_law(np.full(y.shape, 8.0), y, x0)
    assert p == p_read
    f = np.linspace(10.0, 200.0, 40)
    floor = BroadbandFloor("Fz", float(p), 300.0, f, np.full(f.size, 1e-4), np.full(f.size, 1e-6))
    entry = {"kind": "broadband_floor", **floor.params(), "channel": ["Fz"]}
    assert entry.get("exponent_bound") == bound
    words = describe_effect(entry)
    if bound == "at_least":
        assert "p >= 8: the fit's largest exponent, a lower bound" in words
    elif bound == "at_most":
        assert "p <= 0.5: the fit's smallest exponent, an upper bound" in words
    else:
        assert ">=" not in words and "<=" not in words
    back = parse_effects([entry], "<test>")[0]
    assert back.exponent_bound == bound and back.exponent == p


def test_the_words_give_the_band_that_holds_the_floors_power():
    """A floor's line of words gives the band of the central 90 % of its power and its peak's frequency, not the knots'
    whole range (the session-68 trial's hump at 420 Hz, fitted as a floor over 8-1990 Hz, was said "8–1990 Hz").
    A flat floor over 0-1000 Hz holds 5 % of its power below 50 Hz and above 950 Hz (its cumulative power is linear);
    a triangle of half-width 20 Hz about 420 Hz holds 5 % of its power below 400 + 20·√0.1 Hz (the cumulative power of
    its rising side is ½·((f − 400)/20)²) and 5 % above 440 − 20·√0.1 Hz."""
    base = {"kind": "broadband_floor", "channel": ["Fz"], "exponent": 3.0, "omega_ref_rad_s": 300.0}
    flat = describe_effect({**base, "f_Hz": [0.0, 1000.0], "psd_ref": [1e-6, 1e-6]})
    assert "90 % of its power at 50–950 Hz" in flat
    f = [8.0, 400.0, 420.0, 440.0, 1990.0]
    hump = describe_effect({**base, "f_Hz": f, "psd_ref": [0.0, 0.0, 2e-6, 0.0, 0.0]})
    lo, hi = (float(x) for x in hump.split("of its power at ")[1].split(" Hz")[0].split("–"))
    assert lo == round(400.0 + 20.0 * np.sqrt(0.1)) and hi == round(440.0 - 20.0 * np.sqrt(0.1))
    assert "peak 2e-06 N²/Hz at 420 Hz" in hump and "8–1990" not in hump
