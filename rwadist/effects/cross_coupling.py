"""``cross_coupling``: a load-cell reference offset: the measured torques carry r × F."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, Effect, check, numbers, optional, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class CrossCoupling(Effect):
    """A load-cell offset r (m, wheel frame): T_measured = T + r × F.  Measurement only."""

    KIND: ClassVar[str] = "cross_coupling"
    r_m: np.ndarray = field(metadata=check(numbers(length=3)))
    r_stderr_m: np.ndarray | None = field(default=None, metadata=check(optional(numbers(length=3, ge=0.0))))
    n_points: int | None = field(default=None, metadata=check(COUNT))
