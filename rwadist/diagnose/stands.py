"""Several test-stand resonances fitted with the wheel's modes, judged beside them as one hypothesis."""
from __future__ import annotations

from dataclasses import dataclass

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

    def apply(self, state: State) -> State:
        return state.plus(self)

    def contribute(self, parts) -> None:
        for e in self.members:
            e.contribute(parts)
