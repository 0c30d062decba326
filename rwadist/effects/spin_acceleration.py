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
    residual alone, the check; alpha_slowest_rad_s2 and alpha_fastest_rad_s2 the slowest and fastest dΩ/dt over an
    eighth of the runs (:func:`rwadist.diagnose.smear.track_span`: one α, the median, stands for them all).
    Measurement only."""

    KIND: ClassVar[str] = "spin_acceleration"
    ORDER: ClassVar[int] = 90
    alpha_rad_s2: float = field(metadata=check(number(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_track_rad_s2: float | None = field(default=None, metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_residual_rad_s2: float | None = field(default=None,
                                                metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_slowest_rad_s2: float | None = field(default=None,
                                               metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))
    alpha_fastest_rad_s2: float | None = field(default=None,
                                               metadata=check(statistic(ge=-MAX_ALPHA_RAD_S2, le=MAX_ALPHA_RAD_S2)))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        residual = e.get("alpha_residual_rad_s2")
        check = "" if residual is None else f" (the speeds' track; the residual alone {num(residual, '.3g')})"
        way = " (a run-down)" if e["alpha_rad_s2"] < 0 else ""
        return f"α {num(e['alpha_rad_s2'], '.3g')} rad/s²{way}{check}{_span_text(e)}"


#: The fastest slices' |dΩ/dt| this many times the slowest's or more: one α is said to be a compromise
SPREAD_SAID = 2.0


def _span_text(e: Mapping) -> str:
    """'; one α for slices from ... to ... rad/s²: ...' when the sweep's dΩ/dt spreads over a factor :data:`SPREAD_SAID`
    or more (a motor's exponential run-down) one way (a sweep that dwells or turns back is not this: '')."""
    slow, fast = e.get("alpha_slowest_rad_s2"), e.get("alpha_fastest_rad_s2")
    if slow is None or fast is None or not slow * fast > 0 or not abs(fast) >= SPREAD_SAID * abs(slow):
        return ""
    return (f"; one α for slices whose dΩ/dt runs from {num(slow, '.3g')} to {num(fast, '.3g')} rad/s²: the fastest "
            "slices' smear is predicted short and the slowest's long")
