"""Several test-stand resonances fitted with the wheel's modes, judged beside them as one hypothesis."""
from __future__ import annotations

from dataclasses import dataclass

from .effects.base import schema_entry
from .state import State


@dataclass
class StandGroup:
    """The fixture resonances (test-stand ``fixed_resonance`` effects, ``members``) the wheel's suspension modes were
    fitted beside, divided out together when the modes are judged beside them
    (:func:`rwadist.diagnose.search._judge_beside_stand`): two fixtures on every channel on either side of the
    translation mode (trial20, 128 and 208 Hz) each leave the other's lift in the lines, and the modes judged beside
    one of them alone carry the other.  Never named itself: the search names each member on its own (a
    ``fixed_resonance`` proposed from the modes' stands, judged on the held-out runs)."""

    members: tuple
    kind: str = "fixed_resonance"
    role: str = "test_stand"

    @property
    def f_r(self) -> float:
        """Frequency (Hz) of the first member: the stand the modes were fitted beside first."""
        return float(self.members[0].f_r)

    @property
    def channels(self) -> tuple:
        return tuple(self.members[0].channels)

    def params(self) -> dict:
        return {"members": [e.params() for e in self.members]}

    def to_schema(self) -> dict:
        """The entry of the hypothesis (summary.json's ``hypotheses``, hypotheses.csv): each member's parameters; the
        members named are written each as its own ``fixed_resonance``."""
        return schema_entry(self)

    def apply(self, state: State) -> State:
        return state.plus(self)

    def contribute(self, parts) -> None:
        for e in self.members:
            e.contribute(parts)


@dataclass
class StandSet(StandGroup):
    """Two or more fixture resonances the wheel's suspension modes located together (their ``stand`` and
    ``more_stands``), proposed as one hypothesis whose ``parts`` (its ``members``) the search names each as its own
    ``fixed_resonance`` (as a :class:`~rwadist.effects.broadband_floor_diagnose.FloorGroup`'s).

    Fixtures in series each carry the lines the other lifts or lowers: the new-user trial of session 54 (its own
    generator: a 2.5 kg wheel on fixtures at 350 Hz, ζ 0.03, and 800 Hz, ζ 0.02, base-excitation transmissibilities on
    every channel) had both located with the modes (350.0 and 800.0 Hz), but judged one at a time the 350 Hz stand
    gained 0.60 of the held-out misplaced power and the 800 Hz one lost 0.38 (alone it lifts lines the 350 Hz one's
    roll-off lowers), and one resonance at 349 Hz with 0.67 of the load far above, a compromise over both, gained
    0.92 and was named; the 800 Hz lift was then read as an 8-pole anti-alias filter at 882 Hz."""

    @property
    def parts(self) -> tuple:
        return self.members

    def apply(self, state: State) -> State:
        """Each part added in turn (one effect of the state per fixture)."""
        for e in self.members:
            state = e.apply(state)
        return state

    def refit(self, ctx, state: State) -> "StandSet":
        """Each part as the modes' fit on every run has it (:meth:`FixedResonance.refit`)."""
        return StandSet(tuple(e.refit(ctx, state) for e in self.members))

    def significant(self) -> bool:
        return all(e.significant() for e in self.members)
