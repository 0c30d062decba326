"""A line that is one of two sidebands of a stronger line is named so (rwadist.sideband_causes).

Session 60's new-user trial: the imbalance and the bearing lines of a wheel whose rotor angle is phase-modulated 6
times a revolution (index 0.05); the sidebands at h ± 6 were read right (the imbalance's lower one a
counter-rotating line at h 5) and named bearing ball passes, the pair h 5 / h 7 nothing.  Here the model's lines of
that modulation, built from its closed form: a carrier p of load C·Ω² phase-modulated by β sin(mθ) holds, for a small
β, two lines of C·β/2 at the signed ratios p ± m (Jacobi-Anger: J₁(β) ≈ β/2)."""
from types import SimpleNamespace

import pytest
from scipy.special import jv

from rwadist.sideband_causes import sideband_causes, signed_lines

RES = 0.002


def _lines(pairs):
    return [SimpleNamespace(h=h, C=c, sense=s) for h, c, s in pairs]


def _modulated(carriers, m=6.0, beta=0.05):
    """The carriers (h, C) and their first sidebands at p ± m of C·J₁(β), a negative ratio read as a counter line."""
    out = []
    for p, c in carriers:
        out.append((p, c * jv(0, beta), "co"))
        for s in (p + m, p - m):
            out.append((abs(s), c * jv(1, beta), "co" if s > 0 else "counter"))
    return out


def test_the_sidebands_of_a_modulated_imbalance_and_bearing_line_are_named():
    model = _lines(_modulated([(1.0, 4e-7), (3.07, 2.4e-8)]))
    lines = signed_lines("radial_force", model)
    lower = sideband_causes("radial_force", 5.0, "counter", lines, RES)
    upper = sideband_causes("radial_force", 7.0, "co", lines, RES)
    assert len(lower) == 1 and "sidebands of the line h = 1 at ±6 per rev" in lower[0] and "line h = 7" in lower[0]
    assert len(upper) == 1 and "counter-rotating line h = 5" in upper[0] and "motor" in upper[0]
    assert "sidebands of the line h = 3.07 at ±6" in sideband_causes("radial_force", 2.93, "counter", lines, RES)[0]
    assert sideband_causes("radial_force", 1.0, "co", lines, RES) == []          # the carrier itself
    # read without its sense the counter line at 5 is no sideband of anything: the mirror of +5 about 1 is −3
    assert sideband_causes("radial_force", 5.0, "co", lines, RES) == []


@pytest.mark.parametrize("fall", [0.3, 0.5, 0.7])
def test_a_series_of_harmonics_is_no_sideband_pair(fall):
    """Harmonics 1-6 of C falling by ``fall`` a step: neighbours differ in C by more than SAME_C."""
    model = _lines([(float(k), 1e-6 * fall ** (k - 1), "co") for k in range(1, 7)])
    lines = signed_lines("radial_force", model)
    assert all(sideband_causes("radial_force", float(k), "co", lines, RES) == [] for k in range(1, 7))


def test_an_axial_line_reads_its_lower_sideband_at_the_absolute_ratio():
    model = _lines([(2.0, 1e-7, None), (8.0, 5e-9, None), (4.0, 5e-9, None)])
    lines = signed_lines("axial_force", model)
    assert "sidebands of the line h = 2 at ±6" in sideband_causes("axial_force", 8.0, None, lines, RES)[0]


def _impacts(base=3.31, n=12, c=2e-7):
    """A bearing defect's impacts along one fixed direction (trial nuR): the lines k·base, each of both senses (a
    fixed-direction load is a co- and a counter-rotating part of half its amplitude each, read a few per cent apart),
    their C falling slowly with k (a short pulse's spectrum: 2 % a harmonic)."""
    return [(k * base, c * (1 - 0.02 * k) * (1.03 if s == "co" else 1.0), s) for k in range(1, n + 1)
            for s in ("co", "counter")]


def test_the_harmonics_of_a_planar_non_integer_line_are_no_sidebands():
    """Trial nuR: the counter part of h 3.31 was "one of two sidebands of the line h = 3.31", and every multiple from
    the 4th "one of two sidebands of h 3.31 at ±13.24 per rev": the series of one non-sinusoidal source."""
    lines = signed_lines("radial_force", _lines(_impacts()))
    for k in range(1, 13):
        for sense in ("co", "counter", None):
            assert sideband_causes("radial_force", k * 3.31, sense, lines, RES) == [], (k, sense)


def test_a_modulation_of_a_non_integer_line_beside_its_harmonics_is_still_named():
    """The rule above asks for one series: the 6/rev sidebands of the bearing line 3.07 (2.93 and 9.07 are no
    multiples of 3.07) are named beside that line's own 2nd and 3rd harmonics."""
    model = _lines(_modulated([(1.0, 4e-7), (3.07, 2.4e-8)]) + [(6.14, 6e-9, "co"), (9.21, 3e-9, "co")])
    lines = signed_lines("radial_force", model)
    assert "sidebands of the line h = 3.07 at ±6" in sideband_causes("radial_force", 2.93, "counter", lines, RES)[0]


@pytest.mark.parametrize("extra", [(0.5, 1e-9, "counter"), (0.4137, 1e-9, "co"), (1.5, 1e-9, "co")])
def test_a_weak_low_line_elsewhere_does_not_make_a_modulation_one_series(extra):
    """A weak rub at h 0.5, a cage at 0.4137 or a line at 1.5 divides the imbalance's sidebands h 5 and 7 at some order:
    no series of theirs (the review of session 61: the pair was no longer named beside a line at 0.5)."""
    lines = signed_lines("radial_force", _lines(_modulated([(1.0, 4e-7), (3.07, 2.4e-8)]) + [extra]))
    for res in (RES, 0.005):
        assert "sidebands of the line h = 1 at ±6" in sideband_causes("radial_force", 5.0, "counter", lines, res)[0]
        assert "sidebands of the line h = 3.07 at ±6" in sideband_causes("radial_force", 2.93, "counter", lines, res)[0]
