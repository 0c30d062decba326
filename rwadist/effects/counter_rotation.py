"""``counter_rotation``: the counter-rotating part of a radial line."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from ..schema import COUNT, HARMONIC_NUMBER, check, choice, number, register, statistic
from .element import Element, num, plus_minus, words


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class CounterRotation(Element):
    """A radial line with a counter-rotating part: fraction counter_fraction (0..1) of its power."""

    KIND: ClassVar[str] = "counter_rotation"
    ORDER: ClassVar[int] = 80
    direction: str = field(metadata=check(choice(("radial_force", "radial_torque"))))
    h: float = field(metadata=check(HARMONIC_NUMBER))
    counter_fraction: float = field(metadata=check(number(ge=0, le=1)))
    counter_fraction_stderr: float | None = field(default=None, metadata=check(statistic(ge=0.0, le=1.0)))
    counter_fraction_phase: float | None = field(default=None, metadata=check(statistic(ge=-4 * math.pi, le=4 * math.pi)))
    n_points: int | None = field(default=None, metadata=check(COUNT))
    #: (P_x − P_y)/(P_x + P_y) of the line measured hard mounted when every run agrees on it: the ellipse of a co and a
    #: counter part held in one orientation by the stator (an anisotropic mount); None when not measured
    xy_split: float | None = field(default=None, metadata=check(statistic(ge=-1.0, le=1.0)))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        q = float(e["counter_fraction"])
        # q is a share of the line's power; an engineer's "25 % counter" is often the amplitudes' ratio
        ratio = f" (power; counter/co amplitude {math.sqrt(q / (1.0 - q)):.3g})" if 0.0 <= q < 1.0 else " (power)"
        split = e.get("xy_split")
        held = (f"; x/y power split {float(split):+.3g} in every run: the ellipse held in one orientation by the "
                f"stator (an anisotropic mount or bearing)") if split else ""
        return (f"{words(e['direction'])}, h {num(e['h'])}, counter-rotating fraction q "
                f"{num(e['counter_fraction'], '.3g')}{plus_minus(e, 'counter_fraction_stderr')}{ratio}{held}")

    # ------------------------------------------------------------------ injection
    #: ``counter_rotation:direction=radial_force,h=1,fraction=0.3``: that share of the line's power turned against
    #: the spin (x cos, y −sin), the rest left co-rotating; with --physics extended a wheel load: the counter part
    #: goes through the suspension modes and, on h = 1, the imbalance U_s or U_d keeps the co part (scaled by
    #: sqrt(1 − fraction))
    INJECT: ClassVar[Mapping] = {"direction": "radial_force", "h": 1.0, "fraction": 0.3}
    INJECT_TEXT: ClassVar[tuple] = ("direction",)
    INJECT_POSITIVE: ClassVar[tuple] = ("h",)

    @classmethod
    def inject_check(cls, spec, bad):
        if not 0 < spec["fraction"] <= 1:
            raise bad("fraction", f"fraction={spec['fraction']!r} must be in (0, 1]")
        if spec["direction"] == "axial_force":
            raise bad("direction", "an axial line has no rotation sense")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        d = spec["direction"]
        h, spec["C"] = stand.harmonic(wheel, spec, d, spec["h"])
        keep = math.sqrt(1 - spec["fraction"])
        if stand.extended and stand.is_imbalance(d, h):
            name = "U_s" if d == "radial_force" else "U_d"
            spec["C"] = getattr(wheel.extended, name)
            return replace(wheel, extended=replace(wheel.extended, **{name: spec["C"] * keep}))
        return replace(wheel, harmonics={dd: [(hh, c * keep if dd == d and hh == h else c) for hh, c in v]
                                         for dd, v in wheel.harmonics.items()})

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        w = abs(run.speed)
        if stand.extended:
            line = stand.line(spec["direction"], float(spec["h"]), float(spec["C"] * math.sqrt(spec["fraction"])),
                              "counter", stand.rng.uniform(0, 2 * np.pi))
            stand.add_wheel_loads(run, [line])
            return
        a = spec["C"] * math.sqrt(spec["fraction"]) * w**2
        stand.add_line(run, spec["direction"], a, spec["h"] * w * stand.time(run) + stand.rng.uniform(0, 2 * np.pi),
                       -1.0)
