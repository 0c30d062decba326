"""``amplitude_law``: a model harmonic whose amplitude goes as |Ω|^p, p ≠ 2."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.measure import in_unresolved_span, measure_run_powers
from ..diagnose.state import State
from ..units import DIRECTION_CHANNELS

#: Standard errors an exponent must lie away from 2 (the model's C·Ω²) to be proposed as a law.
EXPONENT_Z = 4.0
#: Smallest |p − 2| proposed as a law, whatever its standard error: the accuracy asked of a fitted exponent
#: (tests/test_diagnose.py: within 0.05).  A strong line on the extended base can give p = 1.993 ± 0.001: its C,
#: fitted across the modes, a few per mille off (model error of the base), not a law the data can tell from Ω².
MIN_EXPONENT_SHIFT = 0.05


def _law_lsq(X, y, leak, var_noise, rounds: int = 4):
    """(coefficients, covariance) of y ≈ X·c, y a run's log line amplitude, each of variance σ²·(1 + leak²) + its
    noise's ``var_noise``: what the base's model of a line misses (one relative error σ for every run, estimated from
    the median residual beyond the noise, ``rounds`` times: a run far off, the weakest
    beside a stronger neighbour, does not set it), more where the run's window rests on the prediction
    of neighbouring lines (``leak``: their predicted power over the line's), plus the line-noise cross term of the
    measured power, var(log a) = n/(p·ν) (floor n, line p, ν the spectra's degrees of freedom).

    Neither part alone: the noise's weights alone let the top speeds set the law (a line rising into a resonance the
    search had not named yet, a fixture 20 Hz above the top speed's line, passed for an Ω^3.5 law); a run's own noise
    ignored, the runs where an Ω³ line is 50-60 dB under its top level had the same say as the strong ones (p 2.91 for
    3.0 beside a 3x line); the neighbours ignored, family wheel 1's h 3.33, a bin from its 3x line at 1000-2200 rpm
    and read 25-70 % high there, gave p 2.85 and the error after 47x the clean level."""
    sys2 = None
    for _ in range(rounds):
        var = (1.0 if sys2 is None else sys2) * (1.0 + leak**2) + (0.0 if sys2 is None else var_noise)
        sw = 1.0 / np.sqrt(var)
        Xw = X * sw[:, None]
        coef, *_ = np.linalg.lstsq(Xw, y * sw, rcond=None)
        r = y - X @ coef
        sys2 = max(float(np.median((r**2 - var_noise) / (1.0 + leak**2))), 1e-12)
    rw = r * sw
    s2 = float(rw @ rw) / max(y.size - X.shape[1], 1)
    return coef, s2 * np.linalg.inv(Xw.T @ Xw)


@register(order=20)
@dataclass
class AmplitudeLaw:
    """A model harmonic whose amplitude is A_ref·(|Ω|/Ω_ref)^p (A_ref N or N·m, Ω_ref rad/s)."""

    direction: str
    h: float
    exponent: float
    amplitude_ref: float
    omega_ref: float
    exponent_stderr: float = float("nan")
    kind: str = "amplitude_law"
    #: it adds no line, only changes the amplitude of one the state has: judged with that line's beats at its own
    #: amplitudes (:func:`rwadist.diagnose.search._evidence`)
    own_beats: ClassVar[bool] = True

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        return state.plus(self)

    def contribute(self, parts) -> None:
        parts.laws[(self.direction, round(self.h, 4))] = (self.amplitude_ref, self.omega_ref, self.exponent)

    def refit(self, ctx: Context, state: State) -> "AmplitudeLaw":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return AmplitudeLaw.fit(ctx, state, self.direction, self.h, ctx.runs) or self

    def significant(self) -> bool:
        """False when the exponent lies within EXPONENT_Z standard errors (or MIN_EXPONENT_SHIFT) of the model's 2
        (no new law, only a re-estimate of the line's C): what :meth:`candidates` proposes, checked again after the refit on
        every run (:func:`rwadist.diagnose.search.diagnose`)."""
        return not abs(self.exponent - 2.0) <= max(EXPONENT_Z * self.exponent_stderr, MIN_EXPONENT_SHIFT)

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "exponent": self.exponent,
                "exponent_stderr": self.exponent_stderr, "amplitude_ref": self.amplitude_ref,
                "omega_ref_rad_s": self.omega_ref}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "AmplitudeLaw | None":
        d, w, leak, snr = measure_run_powers(ctx, state, direction, h, runs, skip=h)
        if d.size < 5 or np.ptp(np.log(w)) < 0.3:
            return None
        w_ref = ctx.omega_ref()
        X = np.column_stack([np.ones(w.size), np.log(w / w_ref)])
        coef, cov = _law_lsq(X, np.log(d), leak, 1.0 / (snr * ctx.dof))
        if coef[1] < 0:
            # a law of exponent < 0 grows without bound as the speed falls to 0 (a psd over a law through zero speed,
            # an FMU spinning up): the model file takes exponents >= 0 only (rwadist.schema), on either base
            return None
        return AmplitudeLaw(direction, float(h), float(coef[1]), float(np.exp(coef[0])), w_ref,
                            float(np.sqrt(cov[1, 1])))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        out = []
        # lines the model's extended fit detected but could not measure apart (``analytical.fit.unresolved_lines``:
        # h = 5.37 and 5.57 merged as one h = 5.49 on a 2048-sample record) are not one line: the merged line's
        # level against speed is no law of either (through a 180 Hz stand it passed as p 2.26, t 25, on clean data)
        for d in DIRECTION_CHANNELS:
            if not any(c in ctx.channels for c in DIRECTION_CHANNELS[d]):
                continue
            for hm in state.model.harmonics(d):
                if (d, round(hm.h, 4)) in state.laws or in_unresolved_span(state.model, d, hm.h):
                    continue
                e = AmplitudeLaw.fit(ctx, state, d, hm.h, runs)
                # an exponent within EXPONENT_Z standard errors of the model's 2 is no new law, only a
                # re-estimate of the line's C (on the extended base the fit's C is a compromise across the
                # modes, a few per mille off where the line is strong): not proposed
                if e is not None and e.significant():
                    out.append(e)
        return out
