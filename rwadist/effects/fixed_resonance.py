"""``fixed_resonance``: a resonance at a fixed frequency: a mode of the wheel or of the test stand."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar

from ..schema import COUNT, DIRECTIONS, FREQUENCY, GAIN, MAX_ZETA, check, choice, names, number, optional, register
from ..units import CHANNELS, DIRECTION_CHANNELS
from .actions import LineFilter
from .element import Element, directions, num


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class FixedResonance(Element):
    """A resonance at f_Hz (damping ratio zeta, gain peak_gain at f_Hz, gain_above far above it:
    :func:`rwadist.resonance.resonance`) of role ``wheel_mode`` (the wheel's loads of ``directions`` pass through it:
    a mode of the path between the wheel's load and its interface keeps gain_above = 1 − μ of it, μ the mode's
    participation, :data:`rwadist.resonance.PATH_MODE_MAX_ABOVE`) or ``test_stand`` (a fixture: measurement only).
    ``channels``: a test stand's channels when it acts on some of its directions' channels only (a fixture that sways
    along one axis lifts Fy and Tx, not Fx and Ty), else None: every channel of ``directions``."""

    KIND: ClassVar[str] = "fixed_resonance"
    ORDER: ClassVar[int] = 40
    f_Hz: float = field(metadata=check(FREQUENCY))
    zeta: float = field(metadata=check(number(gt=0, le=MAX_ZETA)))
    peak_gain: float = field(metadata=check(GAIN))
    role: str = field(metadata=check(choice(("wheel_mode", "test_stand"))))
    directions: tuple = field(metadata=check(names(DIRECTIONS)))
    n_points: int | None = field(default=None, metadata=check(COUNT))
    gain_above: float = field(default=1.0, metadata=check(optional(number(ge=-1.0, le=3.0), 1.0)))
    channels: tuple | None = field(default=None, metadata=check(optional(names(CHANNELS))))

    def _validate(self, source, path, error):
        if self.channels is not None:
            own = {c for d in self.directions for c in DIRECTION_CHANNELS[d]}
            if self.role != "test_stand" or not set(self.channels) <= own:
                raise error(source, f"{path}.channels", f"is {list(self.channels)!r}: the channels of a test stand "
                            f"(role test_stand) on some of its directions' channels ({', '.join(sorted(own))}) only")
        least = self.smallest_peak(self.zeta, self.gain_above)
        if self.peak_gain < least * (1 - 1e-9):
            raise error(source, f"{path}.peak_gain", f"is {self.peak_gain!r}: a resonance of zeta {self.zeta!r} whose "
                        f"gain far above is {self.gain_above!r} peaks at least at {least:.6g} (|1 - gain_above|/(2 zeta))")

    @staticmethod
    def smallest_peak(zeta: float, gain_above: float) -> float:
        """|H(f_r)| = sqrt((1 − β)² + (2γζ)²)/(2ζ) >= |1 − β|/(2ζ) (:func:`rwadist.resonance.smallest_peak`, written
        here: the element is read without rwadist by the FMU)."""
        return abs(1.0 - gain_above) / (2.0 * zeta)

    @property
    def resonance(self) -> tuple:
        """(f_r Hz, ζ, peak gain), and the gain above when it is not 1."""
        out = (float(self.f_Hz), float(self.zeta), float(self.peak_gain))
        return out if self.gain_above == 1.0 else out + (float(self.gain_above),)

    def actions(self) -> tuple:
        """A wheel mode filters the lines of its directions; a test stand's resonance is a measurement artefact."""
        return (LineFilter(tuple(self.directions), *self.resonance),) if self.role == "wheel_mode" else ()

    @classmethod
    def describe(cls, e: Mapping) -> str:
        role = "test stand" if e["role"] == "test_stand" else "wheel mode"
        above = e.get("gain_above", 1.0)
        # a fitted 1e-6 either side of 0 is the spring's 0 (a "-1.1e-06 of the load" read as a finding)
        if isinstance(above, (int, float)):
            above = 0.0 if abs(above) < 1e-3 else 1.0 if abs(above - 1.0) < 1e-3 else above
        below = "" if above == 1.0 else f", {num(above, '.2g')} of the load far above"
        # a gain under 1 at f_r attenuates the lines there: said so, not left to read as a resonance (trial 30b)
        notch = " (under 1: a notch, the lines attenuated there)" if float(e["peak_gain"]) < 1.0 else ""
        chans = e.get("channels")
        where = ", ".join([chans] if isinstance(chans, str) else chans) if chans else directions(e["directions"])
        return (f"{role}, {num(e['f_Hz'], '.2f')} Hz, ζ {num(e['zeta'], '.3g')}, peak gain "
                f"{num(e['peak_gain'], '.3g')}{notch}{below}, on {where}")

    # ------------------------------------------------------------------ injection
    #: ``fixed_resonance:f_hz=150,zeta=0.03,gain=5,channels=Fx+Fy+Fz+Tx+Ty+Tz,role=test_stand,gain_above=1``: a
    #: fixed-frequency resonance H(f/f_r) on the lines of those channels (the stand's fixture resonance, or a wheel mode:
    #: role wheel_mode, --physics simple only), |H| = gain at f_hz and H -> gain_above far above it (0 is the force
    #: through a fixture spring, whose gain is then at least 1/(2 zeta); 1 - mu a wheel mode of participation mu)
    INJECT: ClassVar[Mapping] = {"f_hz": 150.0, "zeta": 0.03, "gain": 5.0, "channels": "Fx+Fy+Fz+Tx+Ty+Tz",
                                 "role": "test_stand", "gain_above": 1.0}
    INJECT_TEXT: ClassVar[tuple] = ("channels", "role")
    INJECT_POSITIVE: ClassVar[tuple] = ("f_hz", "zeta", "gain")
    ROLES: ClassVar[tuple] = ("test_stand", "wheel_mode")

    @classmethod
    def inject_check(cls, spec, bad):
        if spec["role"] not in cls.ROLES:
            raise bad("role", f"{spec['role']!r}; expected one of {', '.join(cls.ROLES)}")
        least = cls.smallest_peak(spec["zeta"], spec["gain_above"])
        if spec["gain"] < least * (1 - 1e-9):
            raise bad("gain", f"{spec['gain']!r}: with zeta={spec['zeta']!r} and gain_above={spec['gain_above']!r} the "
                      f"peak gain is at least {least:.4g} (|1 - gain_above|/(2 zeta))")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        mode = stand.mode(f"injected_{spec['role']}", spec["f_hz"], spec["zeta"], spec["gain"], spec["channels"],
                          spec["gain_above"])
        if spec["role"] == "test_stand":
            return replace(wheel, test_stand_modes=list(wheel.test_stand_modes) + [mode])
        if stand.extended:
            raise stand.error("role", "fixed_resonance role=wheel_mode needs `physics` 'simple' "
                              "(with extended physics the wheel's modes are its suspension)")
        return replace(wheel, modes=list(wheel.modes) + [mode])
