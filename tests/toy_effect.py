"""A toy effect kind registered from this one file (issue 34: "adding a kind is one new file"): the element and its
diagnose family, nothing else edited.  tests/test_effect_elements.py imports it, runs it through the virtual stand,
diagnose, the model file, the console text, the PSD and the FMUs, and unregisters it.

``toy_line_gain``: the wheel's line (direction, h) is stronger or weaker than the model's coefficient says, by a
gain that does not depend on the speed: its amplitude is amplitude_ref·(|Ω|/omega_ref_rad_s)² (N or N·m) instead of
the model's C·Ω².  (The ``amplitude_law`` family does not name it: its exponent stays 2.)  Its action on the wheel's
loads is a line law (:class:`rwadist.effects.actions.LineLaw`), which every consumer already applies.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from rwadist.diagnose.effects.base import register as register_family
from rwadist.diagnose.effects.base import schema_entry
from rwadist.diagnose.measure import _measure
from rwadist.effects.actions import LineLaw
from rwadist.effects.element import Element, num, rpm, words
from rwadist.schema import DIRECTIONS, POSITIVE, check, choice, register
from rwadist.units import DIRECTION_CHANNELS

KIND = "toy_line_gain"
#: the family proposes a gain at least this far from 1 (a re-estimate of C within it is no effect)
MIN_GAIN_SHIFT = 0.2


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class ToyLineGain(Element):
    """The element: the model file's fields, the text, the action and the injection."""

    KIND: ClassVar[str] = KIND
    ORDER: ClassVar[int] = 25
    direction: str = field(metadata=check(choice(DIRECTIONS)))
    h: float = field(metadata=check(POSITIVE))
    amplitude_ref: float = field(metadata=check(POSITIVE))
    omega_ref_rad_s: float = field(metadata=check(POSITIVE))

    def actions(self) -> tuple:
        return (LineLaw(self.direction, float(self.h), (float(self.amplitude_ref), float(self.omega_ref_rad_s), 2.0)),)

    @classmethod
    def describe(cls, e: Mapping) -> str:
        return (f"{words(e['direction'])}, h {num(e['h'])}, amplitude {num(e['amplitude_ref'], '.3g')} at "
                f"{rpm(e['omega_ref_rad_s'])}")

    INJECT: ClassVar[Mapping] = {"direction": "radial_force", "h": 2.0, "gain": 2.0}
    INJECT_TEXT: ClassVar[tuple] = ("direction",)
    INJECT_POSITIVE: ClassVar[tuple] = ("h", "gain")

    @classmethod
    def inject_prepare(cls, wheel, spec, stand):
        """The wheel's line (direction, h) times ``gain``: the simulation makes it."""
        h, _ = stand.harmonic(wheel, spec, spec["direction"], spec["h"])
        scaled = [(hh, C * spec["gain"] if hh == h else C) for hh, C in wheel.harmonics[spec["direction"]]]
        return replace(wheel, harmonics={**wheel.harmonics, spec["direction"]: scaled})


@register_family(order=25)
@dataclass
class ToyLineGainFamily:
    """The diagnose hypothesis: a line of the model whose measured amplitudes are A·(Ω/Ω_ref)², A fitted (the mean of
    ln a − 2 ln(Ω/Ω_ref)), proposed where A is off the model's C·Ω_ref² by more than :data:`MIN_GAIN_SHIFT`."""

    direction: str
    h: float
    amplitude_ref: float
    omega_ref: float
    kind: str = KIND

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state):
        return state.plus(self)

    def contribute(self, parts) -> None:
        parts.laws[(self.direction, round(self.h, 4))] = (self.amplitude_ref, self.omega_ref, 2.0)

    def refit(self, ctx, state):
        return ToyLineGainFamily.fit(ctx, state, self.direction, self.h, ctx.runs) or self

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "amplitude_ref": self.amplitude_ref,
                "omega_ref_rad_s": self.omega_ref}

    def to_schema(self) -> dict:
        return schema_entry(self)

    @staticmethod
    def fit(ctx, state, direction, h, runs):
        a, w = _measure(ctx, state, direction, h, runs, skip=h)
        if a.size < 5:
            return None
        w_ref = ctx.omega_ref()
        return ToyLineGainFamily(direction, float(h), float(np.exp(np.mean(np.log(a) - 2.0 * np.log(w / w_ref)))),
                                 w_ref)

    @staticmethod
    def candidates(ctx, state, runs) -> list:
        out = []
        for d in DIRECTION_CHANNELS:
            for hm in state.model.harmonics(d):
                if (d, round(hm.h, 4)) in state.laws:
                    continue
                e = ToyLineGainFamily.fit(ctx, state, d, hm.h, runs)
                if e is not None and abs(e.amplitude_ref / (hm.C * e.omega_ref**2) - 1.0) > MIN_GAIN_SHIFT:
                    out.append(e)
        return out
