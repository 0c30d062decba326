"""``broadband_floor``: a broadband (noise-like) load floor of some channels, growing with speed."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import CHANNELS, NON_NEGATIVE, POSITIVE, Effect, check, names, numbers, register


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class BroadbandFloor(Effect):
    """A blocked-load PSD S(f, Ω) = psd_ref(f)·(|Ω|/omega_ref_rad_s)^exponent on each of its channels,
    psd_ref linear between the knots f_Hz (Hz, >= 0, increasing), 0 outside; unit²/Hz."""

    KIND: ClassVar[str] = "broadband_floor"
    channel: tuple = field(metadata=check(names(CHANNELS)))
    exponent: float = field(metadata=check(NON_NEGATIVE))
    omega_ref_rad_s: float = field(metadata=check(POSITIVE))
    f_Hz: np.ndarray = field(metadata=check(numbers(min_len=2, ge=0.0, increasing=True)))
    psd_ref: np.ndarray = field(metadata=check(numbers(ge=0.0)))

    def _validate(self, source, path, error):
        if self.psd_ref.size != self.f_Hz.size:
            raise error(source, f"{path}.psd_ref", f"has {self.psd_ref.size} values for {self.f_Hz.size} "
                        "f_Hz knots (one per knot)")

    @property
    def channel_indices(self) -> tuple:
        return tuple(CHANNELS.index(c) for c in self.channel)
