"""``amplitude_law``: a line whose amplitude goes as |Ω|^p instead of Ω²."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import (
    AMPLITUDE,
    COUNT,
    DIRECTIONS,
    EXPONENT,
    HARMONIC_NUMBER,
    MAX_EXPONENT,
    SPEED,
    check,
    choice,
    register,
    statistic,
)
from .actions import LineLaw
from .element import Element, num, plus_minus, rpm, words


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class AmplitudeLaw(Element):
    """A line's amplitude amplitude_ref·(|Ω|/omega_ref_rad_s)^exponent (N or N·m) instead of C·Ω²."""

    KIND: ClassVar[str] = "amplitude_law"
    ORDER: ClassVar[int] = 20
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(HARMONIC_NUMBER))
    exponent: float = field(metadata=check(EXPONENT))
    exponent_stderr: float | None = field(default=None, metadata=check(statistic(ge=0.0, le=MAX_EXPONENT)))
    amplitude_ref: float = field(metadata=check(AMPLITUDE))
    omega_ref_rad_s: float = field(metadata=check(SPEED))
    #: beside a test stand (``rwadist diagnose``): the number of runs no named test-stand resonance reaches (its gain
    #: on the line within 1.5x of 1 in power), and the exponent (± its standard error) fitted on them alone, the law
    #: checked where no fitted stand gain rests on it; the exponent null where too few runs are left to fit it (the
    #: law then judged over every run alone).  Absent where no named stand reaches the line.
    runs_beyond_stand: int | None = field(default=None, metadata=check(COUNT))
    exponent_beyond_stand: float | None = field(default=None, metadata=check(statistic(ge=None)))
    exponent_beyond_stand_stderr: float | None = field(default=None, metadata=check(statistic(ge=0.0)))
    #: on a model with the wheel's suspension modes (``rwadist diagnose``): the exponent of the line as the load cell
    #: reads it, the law's plus the slope of the modes' gain on the line over its runs.  Near 2 with the law's far
    #: from it, the line is C·Ω² at the interface: a load that reaches it without the suspension.  Absent on a model
    #: without modes.
    exponent_at_interface: float | None = field(default=None, metadata=check(statistic(ge=None)))

    @property
    def law(self) -> tuple:
        """(A_ref N or N·m, Ω_ref rad/s, exponent)."""
        return (float(self.amplitude_ref), float(self.omega_ref_rad_s), float(self.exponent))

    #: unit of the amplitude of a line of each direction
    AMPLITUDE_UNIT: ClassVar[dict] = {"radial_force": "N", "axial_force": "N", "radial_torque": "N·m",
                                      "axial_torque": "N·m"}

    def actions(self) -> tuple:
        return (LineLaw(self.direction, float(self.h), self.law),)

    @classmethod
    def describe(cls, e: Mapping) -> str:
        d = e["direction"]
        return (f"{words(d)}, h {num(e['h'])}, amplitude ∝ |Ω|^{num(e['exponent'], '.3g')}"
                f"{plus_minus(e, 'exponent_stderr')}, {num(e['amplitude_ref'], '.3g')} {cls.AMPLITUDE_UNIT[d]} at "
                f"{rpm(e['omega_ref_rad_s'])}{cls._at_interface(e)}{cls._beyond_stand(e)}")

    #: |exponent at the interface − 2| within this (or twice the exponent's standard error, at most twice this) with
    #: the law's own twice this or more from it: C·Ω² at the load cell, a load that bypasses the suspension (:meth:`_at_interface`)
    INTERFACE_OMEGA2: ClassVar[float] = 0.15

    @classmethod
    def _at_interface(cls, e: Mapping) -> str:
        """The law as the load cell reads it (``exponent_at_interface``) in words, with what it says when it is Ω²
        there and the law is not; nothing on a model without modes."""
        q = e.get("exponent_at_interface")
        if q is None:
            return ""
        out = f" (|Ω|^{num(q, '.3g')} at the load cell, through the suspension modes"
        se = e.get("exponent_stderr") or 0.0
        if abs(float(q) - 2.0) <= min(max(cls.INTERFACE_OMEGA2, 2.0 * float(se)), 2.0 * cls.INTERFACE_OMEGA2) and abs(float(e["exponent"]) - 2.0) >= 2.0 * \
                cls.INTERFACE_OMEGA2:
            out += (": C·Ω² there, which is also what a load that reaches the interface without the suspension "
                    "gives (on the housing side: the motor stator's, a structure's); a tap or shaker test of the "
                    "housing tells the two apart")
        return out + ")"

    @staticmethod
    def _beyond_stand(e: Mapping) -> str:
        """The law's check beyond a test stand (``runs_beyond_stand``, ``exponent_beyond_stand``) in words, or
        nothing where no stand reaches the line."""
        n = e.get("runs_beyond_stand")
        if n is None:
            return ""
        p = e.get("exponent_beyond_stand")
        if p is None or not np.isfinite(float(p)):
            return (f"; beside a test stand that leaves {int(n)} run{'' if int(n) == 1 else 's'} out of its reach, "
                    "too few or too close in speed to check the law there (judged over every run)")
        return (f"; beyond the test stand ({int(n)} run{'' if int(n) == 1 else 's'} out of its reach) "
                f"|Ω|^{num(p, '.3g')}"
                f"{plus_minus(e, 'exponent_beyond_stand_stderr')}")

    # ------------------------------------------------------------------ injection
    #: ``amplitude_law:direction=radial_force,h=2,exponent=3,fraction=1``: the line (d, h) of the wheel replaced by
    #: A(Ω) = fraction·C_h·Ω_mid²·(Ω/Ω_mid)^exponent (Ω_mid the median speed); with --physics extended a wheel load
    #: with the line's own sense through the suspension modes
    INJECT: ClassVar[Mapping] = {"direction": "radial_force", "h": 2.0, "exponent": 3.0, "fraction": 1.0}
    INJECT_TEXT: ClassVar[tuple] = ("direction",)
    INJECT_POSITIVE: ClassVar[tuple] = ("h",)

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        h, spec["C"] = stand.harmonic(wheel, spec, spec["direction"], spec["h"])
        if stand.extended and stand.is_imbalance(spec["direction"], h):
            raise stand.error("h", f"{cls.KIND}: with `physics` 'extended' the radial h = 1 lines are the rotor's "
                              "imbalances; pick another h or `physics` 'simple'")
        return stand.without(wheel, spec["direction"], h)

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        w, w_mid = abs(run.speed), stand.w_mid
        if stand.extended:
            law = (spec["fraction"] * spec["C"] * w_mid**2, w_mid, spec["exponent"])
            line = stand.line(spec["direction"], float(spec["h"]), float(spec["C"]),
                              stand.sense(spec["direction"], spec["h"]), stand.rng.uniform(0, 2 * np.pi), law=law)
            stand.add_wheel_loads(run, [line])
            return
        a = spec["fraction"] * spec["C"] * w_mid**2 * (w / w_mid) ** spec["exponent"]
        stand.add_line(run, spec["direction"], a, spec["h"] * w * stand.time(run) + stand.rng.uniform(0, 2 * np.pi))
