"""``speed_ripple``: a periodic ripple of the wheel speed at a fixed frequency."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import COUNT, EXPONENT, FREQUENCY, SPEED, SPEED_AMPLITUDE, check, optional, register
from ..units import DIRECTION_CHANNELS, RAD_S_TO_RPM
from .actions import SpeedModulation
from .element import Element, FmuSwitch, num, rpm


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SpeedRipple(Element):
    """Ω(t) = Ω0 + ΔΩ sin 2π f_ripple_Hz t, ΔΩ = delta_omega_rad_s·(|Ω0|/omega_ref_rad_s)^speed_exponent."""

    KIND: ClassVar[str] = "speed_ripple"
    ORDER: ClassVar[int] = 70
    ONE_PER_WHEEL: ClassVar[bool] = True
    FMU_SWITCH: ClassVar[FmuSwitch] = FmuSwitch(0, "speed_ripple", "diagnosed wheel-speed ripple (model file effects) "
                                                "added to wheel_speed; off when wheel_speed is a measured speed that "
                                                "already carries it")
    f_ripple_Hz: float = field(metadata=check(FREQUENCY))
    delta_omega_rad_s: float = field(metadata=check(SPEED_AMPLITUDE))
    omega_ref_rad_s: float = field(metadata=check(SPEED))
    speed_exponent: float = field(default=0.0, metadata=check(optional(EXPONENT, 0.0)))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    def actions(self) -> tuple:
        return (SpeedModulation(float(self.f_ripple_Hz), float(self.delta_omega_rad_s), float(self.omega_ref_rad_s),
                                float(self.speed_exponent)),)

    @classmethod
    def describe(cls, e: Mapping) -> str:
        dw = float(e["delta_omega_rad_s"]) * RAD_S_TO_RPM
        tail = f", ∝ |Ω|^{num(e['speed_exponent'], '.3g')}" if float(e.get("speed_exponent") or 0.0) else ""
        return f"{num(e['f_ripple_Hz'], '.3g')} Hz, amplitude {dw:.3g} rpm at {rpm(e['omega_ref_rad_s'])}{tail}"

    # ------------------------------------------------------------------ injection
    #: ``speed_ripple:f_ripple_hz=8,delta_omega=3``: Ω(t) = Ω0 + ΔΩ sin(2π f t + φ) on every line of the wheel
    #: (amplitude C·Ω(t)², phase h·∫Ω dt); --physics simple with --no-modes (the rippled lines are rebuilt from the
    #: wheel's harmonics, over the noise of the simulation)
    INJECT: ClassVar[Mapping] = {"f_ripple_hz": 8.0, "delta_omega": 3.0}
    INJECT_POSITIVE: ClassVar[tuple] = ("f_ripple_hz",)
    INJECT_CLEAN: ClassVar[bool] = True

    @classmethod
    def inject_requires(cls, spec, physics, modes, stand):
        if modes and physics == "simple":
            raise stand.error(cls.KIND, "needs the wheel's modes off (`modes`: the rippled lines are rebuilt without "
                              "the wheel's resonances)")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        if stand.extended:
            raise stand.error(cls.KIND, "needs `physics` 'simple' (the ripple is applied to the preset's lines)")
        return wheel

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        t, w, wheel = stand.time(run), abs(run.speed), stand.wheel
        c_run = stand.clean.runs[index]
        for ch in run.signals:
            run.signals[ch] = run.signals[ch] - c_run.signals[ch]          # the noise alone
        ph = stand.rng.uniform(0, 2 * np.pi)
        th = 2 * np.pi * spec["f_ripple_hz"] * t + ph
        omega = w + spec["delta_omega"] * np.sin(th)
        psi = w * t - spec["delta_omega"] / (2 * np.pi * spec["f_ripple_hz"]) * (np.cos(th) - np.cos(ph))
        for d in DIRECTION_CHANNELS:
            for h, C in wheel.harmonics.get(d, []):
                if h * (w + spec["delta_omega"]) / (2 * np.pi) >= 0.5 * run.sample_rate:
                    continue
                sense = -1.0 if wheel.senses.get((d, h)) == "counter" else 1.0
                stand.add_line(run, d, C * omega**2, h * psi + stand.rng.uniform(0, 2 * np.pi), sense)
