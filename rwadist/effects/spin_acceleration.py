"""``spin_acceleration``: lines smeared by the wheel's acceleration during the runs of a sweep."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import MAX_ALPHA_RAD_S2, check, number, register, statistic
from .element import Element, num


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SpinAcceleration(Element):
    """The runs were recorded while the wheel accelerated at alpha_rad_s2 (rad/s², dΩ/dt from the runs' speeds against
    their start times: negative on a run-down); alpha_residual_rad_s2 is the acceleration that best explains the
    residual alone, the check.  Measurement only."""

    KIND: ClassVar[str] = "spin_acceleration"
    ORDER: ClassVar[int] = 90
    alpha_rad_s2: float = field(metadata=check(number(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_track_rad_s2: float | None = field(default=None, metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_residual_rad_s2: float | None = field(default=None,
                                                metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        residual = e.get("alpha_residual_rad_s2")
        check = "" if residual is None else f" (the speeds' track; the residual alone {num(residual, '.3g')})"
        way = " (a run-down)" if e["alpha_rad_s2"] < 0 else ""
        return f"α {num(e['alpha_rad_s2'], '.3g')} rad/s²{way}{check}"
