"""``amplitude_law``: a line whose amplitude goes as |Ω|^p instead of Ω²."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import DIRECTIONS, NON_NEGATIVE, POSITIVE, STDERR, Effect, check, choice, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class AmplitudeLaw(Effect):
    """A line's amplitude amplitude_ref·(|Ω|/omega_ref_rad_s)^exponent (N or N·m) instead of C·Ω²."""

    KIND: ClassVar[str] = "amplitude_law"
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(POSITIVE))
    exponent: float = field(metadata=check(NON_NEGATIVE))
    exponent_stderr: float | None = field(default=None, metadata=check(STDERR))
    amplitude_ref: float = field(metadata=check(NON_NEGATIVE))
    omega_ref_rad_s: float = field(metadata=check(POSITIVE))

    @property
    def law(self) -> tuple:
        """(A_ref N or N·m, Ω_ref rad/s, exponent)."""
        return (float(self.amplitude_ref), float(self.omega_ref_rad_s), float(self.exponent))
