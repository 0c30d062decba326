"""``speed_sidebands``: speed-proportional sidebands of a line (a record: the lines are harmonics)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import COEFFICIENT, COUNT, DIRECTIONS, HARMONIC_NUMBER, check, choice, register
from .element import Element, num, words


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SpeedSidebands(Element):
    """Lines at h_lower·|Ω| and h_upper·|Ω| beside the line h of ``direction`` (speed-proportional sidebands).
    A record of what diagnose found: the two lines are the model's empirical harmonics (C_lower, C_upper in
    kg·m or kg·m²), which every consumer applies; this entry adds nothing to them."""

    KIND: ClassVar[str] = "speed_sidebands"
    ORDER: ClassVar[int] = 15
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(HARMONIC_NUMBER))
    h_lower: float = field(metadata=check(HARMONIC_NUMBER))
    h_upper: float = field(metadata=check(HARMONIC_NUMBER))
    C_lower: float = field(metadata=check(COEFFICIENT))
    C_upper: float = field(metadata=check(COEFFICIENT))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    def named_lines(self) -> tuple:
        return ((self.direction, float(self.h_lower)), (self.direction, float(self.h_upper)))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        return (f"{words(e['direction'])}, lines at h {num(e['h_lower'])} and {num(e['h_upper'])} beside h "
                f"{num(e['h'])} (±{num(e['per_rev'], '.3g')} per revolution), C/C of the carrier "
                f"{num(e['ratio_lower'], '.3g')} and {num(e['ratio_upper'], '.3g')}")
