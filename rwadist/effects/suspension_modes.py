"""``suspension_modes``: the wheel's own suspension modes as diagnose fitted them (a record)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import (
    COUNT,
    FREQUENCY,
    MAX_INERTIA_RATIO,
    UNCONSTRAINED_MODES,
    ZETA,
    boolean,
    check,
    names,
    number,
    optional,
    register,
)
from .element import Element, directions, num

#: I_zz/I_rr of a thin disc, the most a rigid rotor has about its centre of mass (I_zz <= I_xx + I_yy)
RIGID_INERTIA_RATIO = 2.0


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SuspensionModes(Element):
    """The wheel's own suspension modes as diagnose fitted them from the data (per unit mass and transverse
    inertia): frequencies at rest (Hz), damping ratios, I_zz/I_rr, and the modes the data do not locate.
    The fitted parameters themselves are the model's ``analytical`` section."""

    KIND: ClassVar[str] = "suspension_modes"
    ORDER: ClassVar[int] = 100
    radial_translation_Hz: float = field(metadata=check(FREQUENCY))
    rocking_Hz: float = field(metadata=check(FREQUENCY))
    axial_Hz: float = field(metadata=check(FREQUENCY))
    zeta_radial_translation: float = field(metadata=check(ZETA))
    zeta_rocking: float = field(metadata=check(ZETA))
    zeta_axial: float = field(metadata=check(ZETA))
    inertia_ratio: float = field(metadata=check(number(gt=0, le=MAX_INERTIA_RATIO)))
    unconstrained: tuple = field(default=(), metadata=check(optional(names(UNCONSTRAINED_MODES), ())))
    per_unit: bool = field(default=True, metadata=check(optional(boolean(), True)))
    n_runs: int | None = field(default=None, metadata=check(COUNT))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        free = e.get("unconstrained") or ()
        note = f"; not located by the data: {directions(free)}" if free else ""
        a = e.get("inertia_ratio")
        if isinstance(a, (int, float)) and a > RIGID_INERTIA_RATIO:
            note = (f" (above {RIGID_INERTIA_RATIO:g}, which no rigid rotor rocking about its centre of mass exceeds: "
                    "an effective ratio of the whirls, from a flexible rotor or rocking coupled with other motion)"
                    + note)
        return (f"radial translation {num(e['radial_translation_Hz'], '.4g')} Hz "
                f"(ζ {num(e['zeta_radial_translation'], '.2g')}), rocking at rest {num(e['rocking_Hz'], '.4g')} Hz "
                f"(ζ {num(e['zeta_rocking'], '.2g')}), axial {num(e['axial_Hz'], '.4g')} Hz "
                f"(ζ {num(e['zeta_axial'], '.2g')}), I_zz/I_rr {num(e['inertia_ratio'], '.3g')}{note}")
