"""``missing_harmonic``: a harmonic the model's fit missed."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COEFFICIENT, DIRECTIONS, HARMONIC_NUMBER, check, choice, register
from ..units import DIRECTION_C_UNIT
from .element import Element, num, words


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class MissingHarmonic(Element):
    """A harmonic the fit missed: C·Ω² at h·|Ω|/2π (C in kg·m or kg·m²)."""

    KIND: ClassVar[str] = "missing_harmonic"
    ORDER: ClassVar[int] = 10
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(HARMONIC_NUMBER))
    C: float = field(metadata=check(COEFFICIENT))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        d = e["direction"]
        return f"{words(d)}, h {num(e['h'])}, C {num(e['C'], '.3e')} {DIRECTION_C_UNIT[d]}"

    # ------------------------------------------------------------------ injection
    #: ``missing_harmonic:direction=radial_force,h=0.5,fraction=0.5``: a line h·|Ω| of amplitude fraction·C1·Ω² (C1
    #: the direction's fundamental coefficient), co-rotating (x cos, y sin), random phase per run; with --physics
    #: extended a co-rotating wheel load through the suspension modes
    INJECT: ClassVar[Mapping] = {"direction": "radial_force", "h": 0.5, "fraction": 0.5}
    INJECT_TEXT: ClassVar[tuple] = ("direction",)
    INJECT_POSITIVE: ClassVar[tuple] = ("h",)

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        w = abs(run.speed)
        if stand.extended:
            line = stand.line(spec["direction"], float(spec["h"]),
                              float(spec["fraction"] * stand.wheel.fundamental_C(spec["direction"])), "co",
                              stand.rng.uniform(0, 2 * np.pi))
            stand.add_wheel_loads(run, [line])
            return
        a = spec["fraction"] * stand.wheel.fundamental_C(spec["direction"]) * w**2
        stand.add_line(run, spec["direction"], a, spec["h"] * w * stand.time(run) + stand.rng.uniform(0, 2 * np.pi))
