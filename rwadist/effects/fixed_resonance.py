"""``fixed_resonance``: a resonance at a fixed frequency: a mode of the wheel or of the test stand."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar

from ..schema import COUNT, DIRECTIONS, FREQUENCY, GAIN, MAX_ZETA, check, choice, names, number, register
from .actions import LineFilter
from .element import Element, directions, num


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class FixedResonance(Element):
    """A resonance at f_Hz (damping ratio zeta, gain peak_gain at f_Hz) of role ``wheel_mode`` (the
    wheel's loads of ``directions`` pass through it) or ``test_stand`` (a fixture: measurement only)."""

    KIND: ClassVar[str] = "fixed_resonance"
    ORDER: ClassVar[int] = 40
    f_Hz: float = field(metadata=check(FREQUENCY))
    zeta: float = field(metadata=check(number(gt=0, le=MAX_ZETA)))
    peak_gain: float = field(metadata=check(GAIN))
    role: str = field(metadata=check(choice(("wheel_mode", "test_stand"))))
    directions: tuple = field(metadata=check(names(DIRECTIONS)))
    n_points: int | None = field(default=None, metadata=check(COUNT))

    @property
    def resonance(self) -> tuple:
        """(f_r Hz, ζ, peak gain)."""
        return (float(self.f_Hz), float(self.zeta), float(self.peak_gain))

    def actions(self) -> tuple:
        """A wheel mode filters the lines of its directions; a test stand's resonance is a measurement artefact."""
        return (LineFilter(tuple(self.directions), *self.resonance),) if self.role == "wheel_mode" else ()

    @classmethod
    def describe(cls, e: Mapping) -> str:
        role = "test stand" if e["role"] == "test_stand" else "wheel mode"
        return (f"{role}, {num(e['f_Hz'], '.2f')} Hz, ζ {num(e['zeta'], '.3g')}, peak gain "
                f"{num(e['peak_gain'], '.3g')}, on {directions(e['directions'])}")

    # ------------------------------------------------------------------ injection
    #: ``fixed_resonance:f_hz=150,zeta=0.03,gain=5,channels=Fx+Fy+Fz+Tx+Ty+Tz,role=test_stand``: a fixed-frequency
    #: resonance H(f/f_r) on the lines of those channels (the stand's fixture resonance, or a wheel mode: role
    #: wheel_mode, --physics simple only)
    INJECT: ClassVar[Mapping] = {"f_hz": 150.0, "zeta": 0.03, "gain": 5.0, "channels": "Fx+Fy+Fz+Tx+Ty+Tz",
                                 "role": "test_stand"}
    INJECT_TEXT: ClassVar[tuple] = ("channels", "role")
    INJECT_POSITIVE: ClassVar[tuple] = ("f_hz", "zeta", "gain")
    ROLES: ClassVar[tuple] = ("test_stand", "wheel_mode")

    @classmethod
    def inject_check(cls, spec, bad):
        if spec["role"] not in cls.ROLES:
            raise bad("role", f"{spec['role']!r}; expected one of {', '.join(cls.ROLES)}")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        mode = stand.mode(f"injected_{spec['role']}", spec["f_hz"], spec["zeta"], spec["gain"], spec["channels"])
        if spec["role"] == "test_stand":
            return replace(wheel, test_stand_modes=list(wheel.test_stand_modes) + [mode])
        if stand.extended:
            raise stand.error("role", "fixed_resonance role=wheel_mode needs `physics` 'simple' "
                              "(with extended physics the wheel's modes are its suspension)")
        return replace(wheel, modes=list(wheel.modes) + [mode])
