"""``missing_harmonic``: a harmonic the model's fit missed."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import DIRECTIONS, NON_NEGATIVE, POSITIVE, Effect, check, choice, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class MissingHarmonic(Effect):
    """A harmonic the fit missed: C·Ω² at h·|Ω|/2π (C in kg·m or kg·m²)."""

    KIND: ClassVar[str] = "missing_harmonic"
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(POSITIVE))
    C: float = field(metadata=check(NON_NEGATIVE))
