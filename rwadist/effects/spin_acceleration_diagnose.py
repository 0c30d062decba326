"""``spin_acceleration``: lines smeared by the wheel's acceleration during each run of a sweep."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.effects.base import finite_or_none, register, schema_entry
from ..diagnose.engine import Context, noise_estimate
from ..diagnose.smear import speed_track, track_span
from ..diagnose.state import State
from ..units import CHANNELS


@register(order=90)
@dataclass
class SpinAcceleration:
    """Lines smeared by the wheel's acceleration during each run of a sweep (a measurement artefact of
    slicing a spin-up or run-down into quasi-steady runs): the line of harmonic h sweeps h|α|T/2π Hz
    during a run of length T.  ``alpha`` (rad/s², dΩ/dt: negative on a run-down) is the acceleration whose smear is
    predicted: the speed track ``alpha_track`` (the runs' speeds against their start times, NaN for steady runs), a
    direct measurement; ``alpha_residual`` is the acceleration that best explains the residual alone (:meth:`fit`;
    its size, given the track's sign), the check that the smear is what the residual holds.  The smear depends on
    |α| only (a line higher in frequency is faster both ways, :mod:`rwadist.diagnose.smear`)."""

    alpha: float
    alpha_track: float = float("nan")
    noise: dict | None = None        # instrument noise re-estimated with the smeared lines masked
    alpha_residual: float = float("nan")
    alpha_span: tuple = (float("nan"), float("nan"))   # the slowest and fastest dΩ/dt between slices (track_span)
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
        parts.smear = abs(self.alpha)

    def refit(self, ctx: Context, state: State) -> "SpinAcceleration":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return SpinAcceleration.fit(ctx, state, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"alpha_rad_s2": self.alpha, "alpha_track_rad_s2": finite_or_none(self.alpha_track),
                "alpha_residual_rad_s2": finite_or_none(self.alpha_residual),
                "alpha_slowest_rad_s2": finite_or_none(self.alpha_span[0]), "alpha_fastest_rad_s2": finite_or_none(self.alpha_span[1]),
                "role": "measurement"}

    @staticmethod
    def track(ctx: Context, runs) -> float:
        """Median dΩ/dt (rad/s², negative on a run-down) from the runs' speeds against their start times (runs of
        one sweep, ``Run.t0`` distinct), or NaN (:func:`rwadist.diagnose.smear.speed_track`)."""
        return speed_track(ctx, np.asarray(runs), signed=True)

    @staticmethod
    def fit(ctx: Context, state: State, runs) -> "SpinAcceleration | None":
        """The smear at the speed track's acceleration when it lowers the fit runs' misplaced power, with the
        residual's own best acceleration beside it; None for runs that are not slices of one sweep or when the
        track's smear does not lower the misplaced power.

        The smear is predicted at the track's |α| (a direct measurement: the slices' speeds against their start
        times, read to a fraction of a per cent) rather than at the residual's minimum: the misplaced power changes
        by about 1 % between no smear and the track's (the E wheel's 40-s run-up, 500-2400 rpm, through the command
        with no model: the whole empirical fit's misfit beside it), so its minimum follows the rest of the misfit,
        4.6-6.4 rad/s² over one search for a 4.97 rad/s² ramp, 7.07 for 7.85 on an outside generator's run-up."""
        from scipy import optimize

        if state.smear is not None or len(runs) < 3:
            return None
        signed = SpinAcceleration.track(ctx, np.asarray(runs))
        if not np.isfinite(signed):     # not slices of one sweep (steady runs, or no time series given)
            return None
        track, sign = abs(signed), (-1.0 if signed < 0 else 1.0)
        T = float(np.median(ctx.run_durations(runs)))
        h_max = max((h for c in ctx.channels for h, *_ in ctx.channel_lines(state, c, runs)), default=0.0)
        if h_max <= 0 or T <= 0 or track <= 0:
            return None

        def cost(a):
            trial = state.plus(SpinAcceleration(float(a)))
            return float(ctx.run_errors(trial, runs)[0].sum())

        if not cost(track) < cost(0.0):
            return None
        # the residual's own best |α| (the check), searched up to the acceleration that smears the highest line
        # over 16 bins
        a_max = max(2 * np.pi * 16 * ctx.df / (h_max * T), 3.0 * track)
        res = optimize.minimize_scalar(cost, bounds=(0.0, a_max), method="bounded",
                                       options={"xatol": 1e-3 * a_max})
        trial = state.plus(SpinAcceleration(track))
        return SpinAcceleration(signed, signed, noise_estimate(ctx, trial), sign * float(res.x),
                                track_span(ctx, np.asarray(runs)))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        e = SpinAcceleration.fit(ctx, state, runs)
        return [] if e is None else [e]
