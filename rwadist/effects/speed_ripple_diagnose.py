"""``speed_ripple``: a periodic wheel-speed ripple at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.constants import LINE_HALF
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context, ripple_sideband_powers
from ..diagnose.measure import (
    _clear_of_lines,
    _offset_grid,
    _offset_scores,
    _offset_threshold,
    _refine_offset,
    _residual_z,
    _window_power,
)
from ..diagnose.state import State
from ..units import CHANNELS


@register(order=70)
@dataclass
class SpeedRipple:
    """A periodic wheel-speed ripple at a fixed frequency f_ripple (Hz): Ω(t) = Ω0 + ΔΩ·sin(2π f_ripple t),
    with ΔΩ(|Ω0|) = ΔΩ_ref·(|Ω0|/Ω_ref)^q (rad/s; q = 0 a ripple of fixed size, q = 1 a fixed fraction of the
    speed).  Every line is phase modulated (β_h = h·ΔΩ/2πf_ripple) and amplitude modulated (a ∝ |Ω(t)|^p):
    lines at f_i + k·f_ripple with the power fractions of :func:`ripple_sideband_powers`."""

    delta_omega: float
    f_ripple: float
    omega_ref: float
    exponent: float = 0.0
    n_points: int = 0
    kind: str = "speed_ripple"

    @property
    def channels(self):
        return CHANNELS

    def apply(self, state: State) -> State:
        return state.plus(self)

    def contribute(self, parts) -> None:
        parts.speed_modulation = (self.delta_omega, self.f_ripple, self.omega_ref, self.exponent)

    def refit(self, ctx: Context, state: State) -> "SpeedRipple":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return SpeedRipple.fit(ctx, state, ctx.runs, self.f_ripple, self.exponent) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"f_ripple_Hz": self.f_ripple, "delta_omega_rad_s": self.delta_omega,
                "omega_ref_rad_s": self.omega_ref, "speed_exponent": self.exponent,
                "ripple_frac_at_ref": self.delta_omega / self.omega_ref, "n_points": self.n_points,
                "law": "omega(t) = omega0 + dw*sin(2 pi f_ripple t), dw = delta_omega_rad_s*(|omega0|/omega_ref)"
                       "^speed_exponent; line h: phase index h*dw/(2 pi f_ripple), amplitude ~ |omega(t)|^p"}

    @staticmethod
    def _points(ctx, state, runs, f_r):
        """Measured first-order ripple sidebands of every model line: (P window power, σ noise std, h, Ω,
        a carrier amplitude × gain, p amplitude exponent, side) over channels, lines and both sides, in band
        and clear of other lines."""
        cols: dict[str, list] = {k: [] for k in ("P", "sig", "h", "w", "a", "p", "side", "leak")}
        for c in ctx.channels:
            if not np.isfinite(ctx.sp.psd[c][runs, 0]).all():
                continue
            R, _ = _residual_z(ctx, state, c, runs)
            for h, law, a, _ in ctx.channel_lines(state, c, runs):
                f0 = h * ctx.omega[runs] / (2 * np.pi)
                for side in (1.0, -1.0):
                    f = f0 + side * f_r
                    p, _, sig, inb = _window_power(ctx, state, c, runs, f, R)
                    ok = inb & (f > 0) & _clear_of_lines(ctx, state, c, runs, f, h)
                    g = ctx.gain(state, c, f0) if state.resonances else np.ones(runs.size)
                    # the fraction of the carrier's power the window holds: the ripple takes (1 − c_0²) of it away
                    # (into the sidebands), a deficit the residual of the window shows beside the sideband
                    k0 = np.rint(np.abs(f) / ctx.df).astype(int)[:, None] + np.arange(-LINE_HALF, LINE_HALF + 1)
                    leak = ctx.psd_at(f0, np.ones(runs.size), k0).sum(1) * ctx.df
                    for k, v in (("P", p), ("sig", sig), ("h", np.full(runs.size, h)), ("w", ctx.omega[runs]),
                                 ("a", a * g), ("p", np.full(runs.size, 2.0 if law is None else law[2])),
                                 ("side", np.full(runs.size, side)), ("leak", leak)):
                        cols[k].append(np.asarray(v, float)[ok])
        return {k: np.concatenate(v) if v else np.empty(0) for k, v in cols.items()}

    @staticmethod
    def fit(ctx: Context, state: State, runs, f_r: float, exponent: float = 0.0) -> "SpeedRipple | None":
        """f_ripple by :func:`_refine_offset` over every line of every channel; ΔΩ_ref by a robust (soft-L1)
        fit of ln P to ln(|c_{±1}|²·a²/2) over the first-order sidebands standing 5σ above the noise (a log-
        spaced grid, then a bounded scalar minimisation), with ΔΩ < ½·min|Ω| of the runs."""
        from scipy.optimize import minimize_scalar

        hs = sorted({x[0] for c in ctx.channels for x in state.lines(c)})
        if not hs:
            return None
        f_r, n = _refine_offset(ctx, state, ctx.channels, runs, hs, f_r)
        if n < 3 or f_r <= 0:
            return None
        pt = SpeedRipple._points(ctx, state, runs, f_r)
        det = pt["P"] > 5.0 * pt["sig"]
        if det.sum() < 5:
            return None
        pt = {k: v[det] for k, v in pt.items()}
        w_ref = ctx.omega_ref()
        y = np.log(pt["P"])
        ki = np.where(pt["side"] > 0, 1, -1)

        def cost(x):
            dw = np.exp(x) * (pt["w"] / w_ref) ** exponent
            k, P = ripple_sideband_powers(pt["h"] * dw / (2 * np.pi * f_r), dw / pt["w"], pt["p"], k_max=4)
            pred = (P[np.arange(ki.size), ki + 4] + (P[:, 4] - 1.0) * pt["leak"]) * pt["a"] ** 2 / 2
            r = (y - np.log(np.maximum(pred, 1e-300))) / 0.5
            return float(np.sum(2.0 * (np.sqrt(1.0 + r * r) - 1.0)))        # soft-L1

        top = np.log(0.5 * float(np.min(ctx.omega[runs] * (w_ref / ctx.omega[runs]) ** exponent)))
        grid = np.linspace(top - 12.0, top, 97)
        vals = [cost(x) for x in grid]
        i = int(np.argmin(vals))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        sol = minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
        x = float(sol.x) if sol.fun <= vals[i] else float(grid[i])
        return SpeedRipple(float(np.exp(x)), float(f_r), w_ref, float(exponent), int(y.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """The strongest constant offset of residual ridges around every line of every channel pooled
        (:func:`_offset_scores`), fitted with q = 0 and q = 1 (two hypotheses judged on held-out speeds)."""
        if state.speed_modulation is not None:
            return []
        offsets = _offset_grid(ctx)
        tot = np.zeros(offsets.size)
        cnt = np.zeros(offsets.size)
        for c in ctx.channels:
            hs = [x[0] for x in state.lines(c)]
            if not hs:
                continue
            t, n = _offset_scores(ctx, state, [c], runs, hs, offsets)
            tot += t.sum(0)
            cnt += n.sum(0)
        score = np.where(cnt >= 6, tot / np.maximum(cnt, 1), 0.0)
        if score.size < 3:
            return []
        j = int(np.argmax(score))
        if not (0 < j < score.size - 1 and score[j] > _offset_threshold(ctx, cnt[j])):
            return []
        out = []
        for q in (0.0, 1.0):
            e = SpeedRipple.fit(ctx, state, runs, float(offsets[j]), q)
            if e is not None:
                out.append(e)
        return out
