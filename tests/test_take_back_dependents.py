"""An effect left acting on a line that only a taken-back effect had put in the model goes with it
(:func:`rwadist.diagnose.take_back.without_taken_back`).

Session 69's new-user trial (a resonance rising with speed on every channel): the search added the radial torque's
h 2 line (``missing_harmonic``) and then an ``amplitude_law`` on it; the description took the line back (fitted to a
broadband hump it described), the law stayed in the model on no line -- "+ amplitude law: radial torque, h 2" on the
console while the model's error did not move (0.6088 -> 0.6088)."""
from rwadist.diagnose.take_back import on_a_line_gone, without_taken_back


class _Line:
    def __init__(self, h):
        self.h = h


class _Model:
    def __init__(self, lines):
        self.lines = lines                      # (direction, h)

    def harmonics(self, direction):
        return [_Line(h) for d, h in self.lines if d == direction]


class _State:
    def __init__(self, lines=()):
        self.model = _Model(tuple(lines))


class _AddsLine:
    """A missing harmonic: puts the line (direction, h) in the model."""

    def __init__(self, direction, h):
        self.direction, self.h = direction, h

    def apply(self, state):
        return _State(state.model.lines + ((self.direction, self.h),))


class _ChangesLine(_AddsLine):
    """An amplitude law: changes the line (direction, h) the model has (``own_beats``)."""

    own_beats = True

    def apply(self, state):
        assert (self.direction, self.h) in state.model.lines
        return _State(state.model.lines)


def test_a_law_on_a_line_taken_back_goes_with_it_and_one_on_a_line_that_stays_does_not():
    line, other = _AddsLine("radial_torque", 2.0), _AddsLine("axial_force", 3.62)
    law, law_kept = _ChangesLine("radial_torque", 2.0), _ChangesLine("axial_force", 3.62)
    effects = [line, other, law, law_kept]
    gone, state = without_taken_back(_State(), effects, {id(line): "broadband_hump"})
    assert gone == {id(line): "broadband_hump", id(law): "broadband_hump"}
    assert state.model.lines == (("axial_force", 3.62),)
    # a law on a line of the base (the state started with it) stays when nothing of its line is taken back
    gone, state = without_taken_back(_State([("radial_torque", 2.0)]), [other, law], {id(other): "moving_resonance"})
    assert gone == {id(other): "moving_resonance"} and state.model.lines == (("radial_torque", 2.0),)
    assert on_a_line_gone(law, _State()) and not on_a_line_gone(line, _State())
