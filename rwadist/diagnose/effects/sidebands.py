"""``sidebands``: amplitude modulation of one line at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...units import DIRECTION_CHANNELS
from ..engine import Context
from ..measure import (
    _clear_of_lines,
    _offset_grid,
    _offset_scores,
    _offset_threshold,
    _refine_offset,
    _residual_z,
    _window_power,
)
from ..state import State
from .base import register, schema_entry


@register(order=60)
@dataclass
class Sidebands:
    """Amplitude modulation of one harmonic line at a FIXED frequency f_mod (Hz, the same at every speed: a
    cage or electronics frequency, a drive's PWM beat): a(Ω)·(1 + m·cos 2πf_mod t)·cos(2πf_i t + φ) is the
    carrier plus two lines at f_i ± f_mod of amplitude m·a/2 (depth m, dimensionless)."""

    direction: str
    h: float
    f_mod: float
    depth: float
    n_points: int = 0
    kind: str = "sidebands"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        s.sidebands.append((self.direction, round(self.h, 4), self.f_mod, self.depth))
        s.effects.append(self)
        return s

    def refit(self, ctx: Context, state: State) -> "Sidebands":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return Sidebands.fit(ctx, state, self.direction, self.h, ctx.runs, self.f_mod) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "f_mod_Hz": self.f_mod, "depth": self.depth,
                "n_points": self.n_points,
                "law": "a(1 + depth*cos(2 pi f_mod t)): lines at h|omega|/2pi +- f_mod_Hz of amplitude depth*a/2"}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs, f_mod: float) -> "Sidebands | None":
        """f_mod by :func:`_refine_offset` on both sides of the carrier; m² by linear least squares of the
        measured sideband window powers P on their prediction per unit m², q = (a/2)²/2 (a the carrier's model
        amplitude, times the resonance gain at the sideband), over every in-band side clear of other lines."""
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        f_mod, n = _refine_offset(ctx, state, chans, runs, [h], f_mod)
        if n < 3 or f_mod <= 0:
            return None
        P, Q = [], []
        for c in chans:
            R, _ = _residual_z(ctx, state, c, runs)
            a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
            if a is None:
                return None
            for side in (1.0, -1.0):
                f = h * ctx.omega[runs] / (2 * np.pi) + side * f_mod
                p, _, _, inb = _window_power(ctx, state, c, runs, f, R)
                ok = inb & _clear_of_lines(ctx, state, c, runs, f, h) & (f > 0)
                g = ctx.gain(state, c, f) if state.resonances else 1.0
                P.append(p[ok])
                Q.append(((a * g) ** 2 / 8.0 * np.ones(runs.size))[ok])
        P, Q = np.concatenate(P), np.concatenate(Q)
        if P.size < 3 or not np.sum(Q * Q) > 0:
            return None
        m2 = float(np.sum(P * Q) / np.sum(Q * Q))
        if m2 <= 0:
            return None
        return Sidebands(direction, float(h), float(f_mod), float(np.sqrt(m2)), int(P.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        """Per direction, the carriers whose best constant-offset ridge pair (:func:`_offset_scores`) clears
        :func:`_offset_threshold`; at most ``max_per_direction``, strongest first."""
        out = []
        offsets = _offset_grid(ctx)
        if offsets.size < 3:
            return out
        for d, chans in DIRECTION_CHANNELS.items():
            chans = [c for c in chans if c in ctx.channels]
            hs = [x.h for x in state.model.harmonics(d)
                  if not any(dd == d and abs(hh - x.h) < 1e-4 for dd, hh, _, _ in state.sidebands)]
            if not chans or not hs:
                continue
            tot, cnt = _offset_scores(ctx, state, chans, runs, hs, offsets)
            score = np.where(cnt >= 6, tot / np.maximum(cnt, 1), 0.0)
            found = []
            for i, h in enumerate(hs):
                s = score[i]
                j = int(np.argmax(s))
                if 0 < j < s.size - 1 and s[j] > _offset_threshold(ctx, cnt[i, j]):
                    found.append((s[j], h, float(offsets[j])))
            for _, h, f_m in sorted(found, reverse=True)[:max_per_direction]:
                e = Sidebands.fit(ctx, state, d, h, runs, f_m)
                if e is not None:
                    out.append(e)
        return out
