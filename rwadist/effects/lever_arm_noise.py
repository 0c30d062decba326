"""``lever_arm_noise``: force-sensor noise the lever-arm correction moves into the torques."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, LEVER_ARM, MAX_TRANSFER, check, number, register, statistic
from .element import Element, num, plus_minus


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class LeverArmNoise(Element):
    """The force sensors' noise that the lever-arm correction T − r × F moves into the torque channels:
    S_T'(f) = S_T(f) + noise_transfer·Σ r_k² S_Fj(f).  Measurement only (not a wheel load): no consumer
    applies it."""

    KIND: ClassVar[str] = "lever_arm_noise"
    ORDER: ClassVar[int] = 55
    r_m: np.ndarray = field(metadata=check(LEVER_ARM))
    noise_transfer: float = field(metadata=check(number(ge=0, le=MAX_TRANSFER)))
    noise_transfer_stderr: float | None = field(default=None, metadata=check(statistic(ge=0.0, le=MAX_TRANSFER)))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        rise = e.get("floor_rise_dB") or {}
        rises = ", ".join(f"{c} +{float(v):.2f} dB" for c, v in rise.items())
        return (f"force-sensor noise moved into the corrected torques by the lever arm, transfer "
                f"{num(e['noise_transfer'], '.3g')}{plus_minus(e, 'noise_transfer_stderr')} (1 = the lever arm alone)"
                + (f", noise floor {rises}" if rises else "") + " (measurement, not a wheel load)")
