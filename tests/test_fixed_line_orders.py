"""A fixed line that is a whole multiple of another fixed line found is named as its harmonic first
(rwadist.diagnose.fixed_lines.fundamental_of; mains families keep their own words)."""
from types import SimpleNamespace

import numpy as np

from rwadist.diagnose.fixed_lines import FixedLine, describe_fixed_lines, fundamental_of


def _line(f):
    return FixedLine(f, ("Fx", "Fy"), (0, 1, 2), 30.0, {"Fx": 1e-4, "Fy": 1e-4})


def test_whole_multiples_of_a_fixed_line_are_named_its_orders():
    assert fundamental_of(74.0, [37.0, 74.0, 111.0]) == 37.0
    assert fundamental_of(111.2, [37.0, 74.0]) == 37.0            # 3.005: within 0.5 %
    assert fundamental_of(112.0, [37.0]) is None                  # 3.03: not a multiple
    assert fundamental_of(37.0, [37.0, 74.0]) is None             # the fundamental itself
    ctx = SimpleNamespace(omega=np.array([100.0, 200.0, 300.0]))
    recs = describe_fixed_lines(ctx, [_line(37.0), _line(74.0), _line(111.0)], {})
    assert [r.causes[0].startswith("order") for r in recs] == [False, True, True]
    assert recs[2].causes[0].startswith("order 3 of the fixed line at 37 Hz")
    # a mains family keeps the pickup words
    mains = describe_fixed_lines(ctx, [_line(50.0), _line(100.0)], {})
    assert all(r.causes[0].startswith("electrical pickup") for r in mains)
