"""``fixed_resonance``: a resonance at a fixed frequency: a mode of the wheel or of the test stand."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import COUNT, DIRECTIONS, POSITIVE, Effect, check, choice, names, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class FixedResonance(Effect):
    """A resonance at f_Hz (damping ratio zeta, gain peak_gain at f_Hz) of role ``wheel_mode`` (the
    wheel's loads of ``directions`` pass through it) or ``test_stand`` (a fixture: measurement only)."""

    KIND: ClassVar[str] = "fixed_resonance"
    f_Hz: float = field(metadata=check(POSITIVE))
    zeta: float = field(metadata=check(POSITIVE))
    peak_gain: float = field(metadata=check(POSITIVE))
    role: str = field(metadata=check(choice(("wheel_mode", "test_stand"))))
    directions: tuple = field(metadata=check(names(DIRECTIONS)))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    @property
    def resonance(self) -> tuple:
        """(f_r Hz, ζ, peak gain)."""
        return (float(self.f_Hz), float(self.zeta), float(self.peak_gain))
