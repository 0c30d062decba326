"""``counter_rotation``: the counter-rotating part of a radial line."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import COUNT, POSITIVE, STDERR, Effect, check, choice, number, register, statistic


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class CounterRotation(Effect):
    """A radial line with a counter-rotating part: fraction counter_fraction (0..1) of its power."""

    KIND: ClassVar[str] = "counter_rotation"
    direction: str = field(metadata=check(choice(("radial_force", "radial_torque"))))
    h: float = field(metadata=check(POSITIVE))
    counter_fraction: float = field(metadata=check(number(ge=0, le=1)))
    counter_fraction_stderr: float | None = field(default=None, metadata=check(STDERR))
    counter_fraction_phase: float | None = field(default=None, metadata=check(statistic(ge=None)))
    n_points: int | None = field(default=None, metadata=check(COUNT))
