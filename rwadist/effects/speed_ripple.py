"""``speed_ripple``: a periodic ripple of the wheel speed at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import COUNT, NON_NEGATIVE, POSITIVE, Effect, check, optional, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SpeedRipple(Effect):
    """Ω(t) = Ω0 + ΔΩ sin 2π f_ripple_Hz t, ΔΩ = delta_omega_rad_s·(|Ω0|/omega_ref_rad_s)^speed_exponent."""

    KIND: ClassVar[str] = "speed_ripple"
    ONE_PER_WHEEL: ClassVar[bool] = True
    f_ripple_Hz: float = field(metadata=check(POSITIVE))
    delta_omega_rad_s: float = field(metadata=check(NON_NEGATIVE))
    omega_ref_rad_s: float = field(metadata=check(POSITIVE))
    speed_exponent: float = field(default=0.0, metadata=check(optional(NON_NEGATIVE, 0.0)))
    n_points: int | None = field(default=None, metadata=check(COUNT))
