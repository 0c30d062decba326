"""``spin_acceleration``: lines smeared by the wheel's acceleration during each run of a sweep."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context, noise_estimate
from ..diagnose.state import State
from ..units import CHANNELS


@register(order=90)
@dataclass
class SpinAcceleration:
    """Lines smeared by the wheel's acceleration during each run of a sweep (a measurement artefact of
    slicing a spin-up or run-down into quasi-steady runs): the line of harmonic h sweeps h|α|T/2π Hz
    during a run of length T.  ``alpha`` (rad/s², |dΩ/dt|) is fitted to the residual; ``alpha_track``
    is the independent estimate from the runs' speeds and start times (NaN for steady runs)."""

    alpha: float
    alpha_track: float = float("nan")
    noise: dict | None = None        # instrument noise re-estimated with the smeared lines masked
    kind: str = "spin_acceleration"

    @property
    def channels(self):
        return CHANNELS

    def apply(self, state: State) -> State:
        s = state.plus(self)
        if self.noise is not None:
            s.noise = self.noise
        return s

    def contribute(self, parts) -> None:
        parts.smear = self.alpha

    def refit(self, ctx: Context, state: State) -> "SpinAcceleration":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return SpinAcceleration.fit(ctx, state, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"alpha_rad_s2": self.alpha, "alpha_track_rad_s2": self.alpha_track, "role": "measurement"}

    @staticmethod
    def track(ctx: Context, runs) -> float:
        """Median |dΩ/dt| (rad/s²) from the runs' speeds against their start times (runs of one sweep,
        ``Run.t0`` distinct), or NaN."""
        if ctx.test is None or len(runs) < 3:
            return float("nan")
        t0 = np.array([ctx.test.runs[r].t0 for r in runs], dtype=float)
        w = ctx.omega[runs]
        order = np.argsort(t0)
        dt = np.diff(t0[order])
        if not np.all(np.isfinite(t0)) or np.any(dt <= 0):
            return float("nan")
        return float(np.median(np.abs(np.diff(w[order]) / dt)))

    @staticmethod
    def fit(ctx: Context, state: State, runs) -> "SpinAcceleration | None":
        from scipy import optimize

        if state.smear is not None or len(runs) < 3:
            return None
        track = SpinAcceleration.track(ctx, np.asarray(runs))
        if not np.isfinite(track):      # not slices of one sweep (steady runs, or no time series given)
            return None
        T = float(np.median(ctx.run_durations(runs)))
        h_max = max((h for c in ctx.channels for h, *_ in ctx.channel_lines(state, c, runs)), default=0.0)
        if h_max <= 0 or T <= 0:
            return None
        # search up to the acceleration that smears the highest line over 16 bins
        a_max = max(2 * np.pi * 16 * ctx.df / (h_max * T), 3.0 * track)

        def cost(a):
            trial = state.plus(SpinAcceleration(float(a)))
            return float(ctx.run_errors(trial, runs)[0].sum())

        res = optimize.minimize_scalar(cost, bounds=(0.0, a_max), method="bounded",
                                       options={"xatol": 1e-3 * a_max})
        if not (res.x > 1e-3 * a_max and res.fun < cost(0.0)):
            return None
        trial = state.plus(SpinAcceleration(float(res.x)))
        return SpinAcceleration(float(res.x), track, noise_estimate(ctx, trial))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        e = SpinAcceleration.fit(ctx, state, runs)
        return [] if e is None else [e]
