"""``sidebands``: an amplitude modulation of one line at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import COUNT, DIRECTIONS, NON_NEGATIVE, POSITIVE, Effect, check, choice, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class Sidebands(Effect):
    """Amplitude modulation a(1 + depth·cos 2π f_mod_Hz t) of the lines (direction, h)."""

    KIND: ClassVar[str] = "sidebands"
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(POSITIVE))
    f_mod_Hz: float = field(metadata=check(POSITIVE))
    depth: float = field(metadata=check(NON_NEGATIVE))
    n_points: int | None = field(default=None, metadata=check(COUNT))
