"""A law the search's last step judged twice on one line is described once (rwadist.diagnose.describe_law.
laws_below_gain; trial26's amplifier distortion printed the radial-force h 3 line's Ω^5.17 record twice in the console,
report.md and summary.json).  The hypotheses are the search's records as laws_below_gain reads them: an
``amplitude_law`` effect, its held-out t and gain fraction, its refit on every run."""
from types import SimpleNamespace

from rwadist.diagnose.describe_law import laws_below_gain


def _judged(h: float, exponent: float = 5.17):
    law = SimpleNamespace(direction="radial_force", h=h, exponent=exponent, significant=lambda: True)
    effect = SimpleNamespace(kind="amplitude_law", direction="radial_force", h=h, refit=lambda ctx, state: law)
    return SimpleNamespace(effect=effect, t=6.0, gain_fraction=1e-4)


def test_a_line_judged_twice_is_one_law_and_two_lines_are_two():
    none = SimpleNamespace(laws={})
    assert len(laws_below_gain(None, none, [_judged(3.0), _judged(3.0)], k_sigma=3.0, min_gain=0.01)) == 1
    assert len(laws_below_gain(None, none, [_judged(3.0), _judged(2.0)], k_sigma=3.0, min_gain=0.01)) == 2
    taken = SimpleNamespace(laws={("radial_force", 3.0): object()})
    assert laws_below_gain(None, taken, [_judged(3.0)], k_sigma=3.0, min_gain=0.01) == []
    # below k_sigma (not told from the noise): not described
    weak = _judged(3.0)
    weak.t = 2.0
    assert laws_below_gain(None, none, [weak], k_sigma=3.0, min_gain=0.01) == []
