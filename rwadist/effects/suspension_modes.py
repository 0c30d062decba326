"""``suspension_modes``: the wheel's own suspension modes as diagnose fitted them (a record)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import (
    COUNT,
    NON_NEGATIVE,
    POSITIVE,
    UNCONSTRAINED_MODES,
    Effect,
    boolean,
    check,
    names,
    optional,
    register,
)


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SuspensionModes(Effect):
    """The wheel's own suspension modes as diagnose fitted them from the data (per unit mass and transverse
    inertia): frequencies at rest (Hz), damping ratios, I_zz/I_rr, and the modes the data do not locate.
    The fitted parameters themselves are the model's ``analytical`` section."""

    KIND: ClassVar[str] = "suspension_modes"
    radial_translation_Hz: float = field(metadata=check(POSITIVE))
    rocking_Hz: float = field(metadata=check(POSITIVE))
    axial_Hz: float = field(metadata=check(POSITIVE))
    zeta_radial_translation: float = field(metadata=check(NON_NEGATIVE))
    zeta_rocking: float = field(metadata=check(NON_NEGATIVE))
    zeta_axial: float = field(metadata=check(NON_NEGATIVE))
    inertia_ratio: float = field(metadata=check(POSITIVE))
    unconstrained: tuple = field(default=(), metadata=check(optional(names(UNCONSTRAINED_MODES), ())))
    per_unit: bool = field(default=True, metadata=check(optional(boolean(), True)))
    n_runs: int | None = field(default=None, metadata=check(COUNT))
