"""A sample of the robustness matrix of ``rwadist diagnose`` on modes-on data (issue 14, item 5); the full
table is ``benchmarks/diagnose_matrix.py`` (its docstring defines the matrix: one factor at a time around a
nominal cell plus two corners).

The cheap cells (20 speeds): clean data get nothing beyond the wheel's own suspension modes, every mode
found within 2 % of the thesis numbers (tests/independent_wheel.py) or declared unconstrained (never a
silent wrong mode), and an injected amplitude law (h = 2 radial force as Ω³, lines added at the load cell)
is named with its exponent.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import diagnose_matrix as matrix  # noqa: E402

CELLS = {c["name"]: c for c in matrix.cells()}


def test_the_matrix_is_one_factor_at_a_time_plus_corners():
    cells = matrix.cells()
    assert len(cells) == 1 + sum(len(v) - 1 for v in matrix.LEVELS.values()) + 2
    nominal = cells[0]
    for c in cells[1:-2]:                                   # exactly one factor off the nominal cell
        assert sum(c[k] != nominal[k] for k in matrix.LEVELS) == 1, c
    # every family the registry lists is either injected or said why not
    for kind in matrix.registry_kinds():
        spec, why = matrix.injection(kind)
        assert (spec is None) != (why is None), kind


@pytest.mark.parametrize("name", ["n_speeds=20", "corner-low"])
def test_clean_cell_adds_nothing_beyond_the_wheel_modes(name):
    r = matrix.evaluate(CELLS[name], "clean")
    assert r["extra"] == [], r
    assert r["modes"] != "no suspension_modes"
    assert not r["silent"], r["modes"]
    assert r["error"][1] < 0.02 * r["error"][0]          # the modes explain the data


def test_injected_amplitude_law_named():
    r = matrix.evaluate(CELLS["n_speeds=20"], "amplitude_law")
    assert r["found"], r
    assert r["extra"] == [], r
    assert not r["silent"], r["modes"]
    assert r["effect"]["h"] == pytest.approx(2.0, abs=0.01)
    assert r["effect"]["exponent"] == pytest.approx(3.0, rel=0.10)
