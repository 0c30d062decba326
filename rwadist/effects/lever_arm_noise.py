"""``lever_arm_noise``: force-sensor noise the lever-arm correction moves into the torques."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, NON_NEGATIVE, STDERR, Effect, check, numbers, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class LeverArmNoise(Effect):
    """The force sensors' noise that the lever-arm correction T − r × F moves into the torque channels:
    S_T'(f) = S_T(f) + noise_transfer·Σ r_k² S_Fj(f).  Measurement only (not a wheel load): no consumer
    applies it."""

    KIND: ClassVar[str] = "lever_arm_noise"
    r_m: np.ndarray = field(metadata=check(numbers(length=3)))
    noise_transfer: float = field(metadata=check(NON_NEGATIVE))
    noise_transfer_stderr: float | None = field(default=None, metadata=check(STDERR))
    n_points: int | None = field(default=None, metadata=check(COUNT))
