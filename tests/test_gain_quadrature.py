"""A channel gain is read on the lines of one rotation sense only (rwadist.diagnose.describe_gain.in_quadrature).

A line of both senses (an ellipse) gives x and y its own powers, and they move as its co- and counter-rotating parts
pass the rocking mode's two whirl branches apart: family wheel 4 (the E-like wheel, rocking 55 Hz), clean, seed 2,
described "Fx's gain changed by x 3.23 between 770 and 887 rpm" from its h 2 (co 0.8) and h 4.62 (co 0.5) lines.  A
gain scales one channel and keeps every line's quarter turn between x and y; those cells alone are read now.  Closed
form first: a gain keeps the quarter turn, an ellipse tilted off the axes does not."""
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.describe_gain import QUADRATURE_DEG, in_quadrature  # noqa: E402


class _Records:
    """A context whose transforms are given phasors (R, L, 2)."""

    def __init__(self, z):
        self.test, self.omega, self._z = object(), np.ones(z.shape[0]), z

    def transforms(self, runs, f, pair):
        return self._z


def test_a_gain_keeps_the_quarter_turn_and_an_ellipse_does_not():
    a = np.exp(1j * np.linspace(0, 6, 5))                       # co-rotating lines of any phase, 5 runs x 1 line
    co = np.stack([a, -1j * a], axis=-1)[:, None, :]
    gained = co * np.array([1.0, 1.5])                          # y read 1.5 x
    b = 0.5 * np.exp(1j * 0.7)                                  # a counter part, the ellipse tilted
    ellipse = np.stack([a + b, -1j * a + 1j * b], axis=-1)[:, None, :]
    h, runs = np.array([2.0]), np.arange(5)
    assert in_quadrature(_Records(gained), ("Fx", "Fy"), h, runs).all()
    assert not in_quadrature(_Records(ellipse), ("Fx", "Fy"), h, runs).any()
    assert QUADRATURE_DEG == 15.0


def test_clean_wheel_4_describes_no_gain_step():
    diag = api.diagnose(family_test.steady_test(fw.steady(fw.family()[4], seed=2, noise=0.01)))
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes"]
    assert [u.parameters.get("property") for u in diag.unexplained] == []


def test_no_records_no_judgement():
    ctx = SimpleNamespace(test=None)
    assert in_quadrature(ctx, ("Fx", "Fy"), np.array([1.0, 2.0]), np.arange(3)).all()
