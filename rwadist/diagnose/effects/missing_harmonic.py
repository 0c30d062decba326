"""``missing_harmonic``: a line at h·|Ω| the model lacks."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model import Harmonic
from ...units import DIRECTION_CHANNELS
from ..engine import Context
from ..measure import _measure, refine_h, ridge_peaks
from ..state import State
from .base import register, schema_entry


@register(order=10)
@dataclass
class MissingHarmonic:
    """A line at h·|Ω| the model lacks; amplitude C·Ω² (C in SI per (rad/s)²)."""

    direction: str
    h: float
    C: float
    n_points: int = 0
    kind: str = "missing_harmonic"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        s.model.empirical[self.direction] = sorted(
            s.model.harmonics(self.direction) + [Harmonic(h=round(self.h, 4), C=self.C, n_points=self.n_points)],
            key=lambda x: x.h)
        s.effects.append(self)
        return s

    def refit(self, ctx: Context, state: State) -> "MissingHarmonic":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return MissingHarmonic.fit(ctx, state, self.direction, self.h, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "C": self.C}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "MissingHarmonic | None":
        d, w = _measure(ctx, state, direction, h, runs)
        if d.size < 3:
            return None
        C = float(np.sum(d * w**2) / np.sum(w**4))                      # thesis Eq. 3.10
        return MissingHarmonic(direction, float(h), C, int(d.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        out = []
        for d, chans in DIRECTION_CHANNELS.items():
            chans = [c for c in chans if c in ctx.channels]
            if not chans:
                continue
            for h in ridge_peaks(ctx, state, chans, runs, max_per_direction):
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)):
                    continue
                h = refine_h(ctx, state, chans, runs, h)
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)) or \
                        any(abs(h - x.h) < 0.005 for x in out if x.direction == d):
                    continue
                e = MissingHarmonic.fit(ctx, state, d, h, runs)
                if e is not None and e.C > 0:
                    out.append(e)
        return out
