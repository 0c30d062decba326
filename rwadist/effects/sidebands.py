"""``sidebands``: an amplitude modulation of one line at a fixed frequency."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, DEPTH, DIRECTIONS, FREQUENCY, HARMONIC_NUMBER, check, choice, register
from .actions import LineModulation
from .element import Element, num, words


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class Sidebands(Element):
    """Amplitude modulation a(1 + depth·cos 2π f_mod_Hz t) of the lines (direction, h)."""

    KIND: ClassVar[str] = "sidebands"
    ORDER: ClassVar[int] = 60
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(HARMONIC_NUMBER))
    f_mod_Hz: float = field(metadata=check(FREQUENCY))
    depth: float = field(metadata=check(DEPTH))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    def actions(self) -> tuple:
        return (LineModulation(self.direction, float(self.h), float(self.f_mod_Hz), float(self.depth)),)

    @classmethod
    def describe(cls, e: Mapping) -> str:
        return (f"{words(e['direction'])}, h {num(e['h'])}, lines at ±{num(e['f_mod_Hz'], '.3g')} Hz, "
                f"depth {num(e['depth'], '.3g')}")

    # ------------------------------------------------------------------ injection
    #: ``sidebands:direction=radial_force,h=2,depth=0.4,f_mod_hz=7`` (or per_rev: a fraction of the wheel speed,
    #: speed-proportional sidebands at (h ± per_rev)·Ω): the line (d, h) amplitude modulated
    #: C·Ω²·(1 + depth·cos(2π f_mod t + φ)), random carrier and modulation phases; with --physics extended a wheel
    #: load: the carrier (the line's own sense) and two lines (depth/2)·C·Ω² at f_c ± f_mod (or (h ± per_rev)·Ω)
    #: through the modes, each at its own frequency; on h = 1 the imbalance U (simulated through the modes) is the
    #: carrier and only the two sides are added
    INJECT: ClassVar[Mapping] = {"direction": "radial_force", "h": 2.0, "depth": 0.4, "f_mod_hz": None,
                                 "per_rev": None}
    INJECT_TEXT: ClassVar[tuple] = ("direction",)
    INJECT_POSITIVE: ClassVar[tuple] = ("h", "f_mod_hz", "per_rev")

    @classmethod
    def inject_check(cls, spec, bad):
        if (spec["f_mod_hz"] is None) == (spec["per_rev"] is None):
            raise bad("f_mod_hz/per_rev", "give exactly one of f_mod_hz (fixed) or per_rev (speed-proportional)")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        h, spec["C"] = stand.harmonic(wheel, spec, spec["direction"], spec["h"])
        if stand.extended and stand.is_imbalance(spec["direction"], h):
            # the imbalance stays in the simulation (through the modes); only its two sidebands are added
            spec["C"] = getattr(wheel.extended, "U_s" if spec["direction"] == "radial_force" else "U_d")
            spec["sidebands_only"] = True
            return wheel
        return stand.without(wheel, spec["direction"], h)

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        w, t, rng = abs(run.speed), stand.time(run), stand.rng
        d, h = spec["direction"], spec["h"]
        if stand.extended:
            sense = "co" if spec.get("sidebands_only") else stand.sense(d, h)
            ph_c, ph_m = rng.uniform(0, 2 * np.pi, 2)
            side_C = 0.5 * spec["depth"] * spec["C"]
            lines = [] if spec.get("sidebands_only") else [stand.line(d, float(h), float(spec["C"]), sense, ph_c)]
            for side in (1.0, -1.0):
                if spec["per_rev"] is not None:
                    lines.append(stand.line(d, float(h + side * spec["per_rev"]), float(side_C), sense,
                                            ph_c + side * ph_m))
                else:
                    lines.append(stand.line(d, float(h), float(side_C), sense, ph_c + side * ph_m,
                                            f_offset=side * spec["f_mod_hz"]))
            stand.add_wheel_loads(run, lines)
            return
        f_mod = spec["f_mod_hz"] if spec["f_mod_hz"] is not None else spec["per_rev"] * w / (2 * np.pi)
        env = 1.0 + spec["depth"] * np.cos(2 * np.pi * f_mod * t + rng.uniform(0, 2 * np.pi))
        stand.add_line(run, d, spec["C"] * w**2 * env, h * w * t + rng.uniform(0, 2 * np.pi))
