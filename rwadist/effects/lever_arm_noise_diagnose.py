"""``lever_arm_noise``: the force sensors' noise the lever-arm correction T − r × F moves into the torques."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..diagnose.constants import BAND_BINS, TORQUE_CHANNELS
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.state import State
from .cross_coupling_diagnose import CrossCoupling

#: (torque channel, ((force channel, index of r whose square weighs it), ...)) of (r × F)_c:
#: Tx = r_y·Fz − r_z·Fy, Ty = r_z·Fx − r_x·Fz, Tz = r_x·Fy − r_y·Fx.
_TERMS = {"Tx": (("Fz", 1), ("Fy", 2)), "Ty": (("Fx", 2), ("Fz", 0)), "Tz": (("Fy", 0), ("Fx", 1))}


def transfer_psd(state: State, r) -> dict:
    """Torque channel -> PSD (unit²/Hz on the grid) that independent white sensor noise of the force channels
    (the state's instrument noise N_F) puts into the corrected torque T − r × F: Σ_j r_k² N_Fj over the two
    terms of (r × F)_c (the noises of different force channels are independent: their cross terms vanish)."""
    r = np.asarray(r, dtype=float)
    out = {}
    for c, terms in _TERMS.items():
        if c in state.noise and all(f in state.noise for f, _ in terms):
            out[c] = sum(r[k] ** 2 * np.asarray(state.noise[f], float) for f, k in terms)
    return out


@register(order=55)
@dataclass
class LeverArmNoise:
    """The noise floor of the torque channels read corrected for a load-cell offset r (a ``cross_coupling``
    effect): the force sensors' noise n_F enters the correction, T' = T + n_T − r × n_F, so the corrected
    torque floor is S_T + κ·Σ r_k² S_Fj (:func:`transfer_psd`; κ = 1 when the sensors' noise is added after
    the offset's geometry, as on a real stand; κ = 0 when the measured torque noise already held r × n_F).
    κ (``noise_transfer``) is fitted on the off-line band means of the corrected torques (the physics check:
    κ ≈ 1); the floor the diagnosis then uses for those channels is the noise re-estimated from the corrected
    data (:func:`rwadist.diagnose.engine.noise_estimate`: the transfer, and no bias from the uncorrected data's
    r × F line skirts).  ``floor_rise_dB``: its median rise over the analysed band per channel.  A measurement
    artefact (``role`` = ``measurement``): no consumer of the model file adds it to the wheel's loads."""

    r: np.ndarray
    noise_transfer: float
    noise_transfer_stderr: float
    noise: dict = field(repr=False)
    rise_db: dict = field(default_factory=dict)
    n_points: int = 0
    kind: str = "lever_arm_noise"

    @property
    def channels(self):
        return tuple(self.noise)

    def apply(self, state: State) -> State:
        s = state.copy()
        s.noise = dict(s.noise, **self.noise)
        s.effects.append(self)
        return s

    def refit(self, ctx: Context, state: State) -> "LeverArmNoise":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return LeverArmNoise.fit(ctx, state, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"r_m": [float(x) for x in self.r], "noise_transfer": self.noise_transfer,
                "noise_transfer_stderr": self.noise_transfer_stderr,
                "floor_rise_dB": {c: round(float(v), 3) for c, v in self.rise_db.items()},
                "n_points": self.n_points, "role": "measurement",
                "law": "corrected torque noise S_T'(f) = S_T(f) + noise_transfer * sum_k r_k^2 S_Fj(f) over the "
                       "terms of (r x F): the force sensors' noise moved into T - r x F"}

    @staticmethod
    def fit(ctx: Context, state: State, runs) -> "LeverArmNoise | None":
        """κ >= 0 by weighted linear least squares of the corrected torques' off-line band means y
        (:meth:`Context.offline_bands`, the state's coupling applied) on y = N_T + κ·X, N_T and X the band means
        of the state's torque noise and of :func:`transfer_psd`, pooled over the torque channels (weights:
        bins used / N_T², a band mean of chi² bins having a variance ∝ mean²/bins); standard error from the
        weighted residual.  The new torque floors: the noise re-estimated from the corrected data.  None without a coupling, once done, or when no torque channel gets any transfer."""
        if state.load_cell_offset is None or any(isinstance(e, LeverArmNoise) for e in state.effects):
            return None
        X = transfer_psd(state, state.load_cell_offset)
        chans = [c for c in TORQUE_CHANNELS if c in ctx.channels and c in X
                 and np.any(ctx.band_sums(X[c][None, :]) > 0)]
        if not chans:
            return None
        num = den = 0.0
        rows = []
        for c in chans:
            y, wt = ctx.offline_bands(state, c, runs)       # the corrected data (the state's coupling)
            mean = ctx.band_sums(np.asarray(state.noise[c], float)[None, :])[0] / (BAND_BINS * ctx.df)
            x = ctx.band_sums(X[c][None, :])[0] / (BAND_BINS * ctx.df)
            ok = np.isfinite(y) & (wt > 0)
            w = np.where(ok, wt / np.maximum(mean, 1e-300)[None, :] ** 2, 0.0)
            dy = np.where(ok, y - mean[None, :], 0.0)
            num += float(np.sum(w * x[None, :] * dy))
            den += float(np.sum(w * x[None, :] ** 2))
            rows.append((w, dy, x))
        if not den > 0:
            return None
        kappa = max(num / den, 0.0)
        n = sum(int(np.count_nonzero(w)) for w, _, _ in rows)
        sse = sum(float(np.sum(w * (dy - kappa * x[None, :]) ** 2)) for w, dy, x in rows)
        se = float(np.sqrt(sse / max(n - 1, 1) / den))
        cur = state.copy()
        cur.noise = dict(state.noise, **{c: np.asarray(state.noise[c], float) + kappa * X[c] for c in chans})
        if kappa <= 0:
            return None
        from ..diagnose.engine import noise_estimate

        fresh = noise_estimate(ctx, cur)
        noise, rise = {}, {}
        band = (ctx.f >= ctx.k_lo * ctx.df) & (ctx.f <= ctx.k_hi * ctx.df)
        for c in chans:
            n0 = np.asarray(state.noise[c], float)
            noise[c] = fresh[c]
            with np.errstate(divide="ignore", invalid="ignore"):
                rise[c] = float(np.nanmedian(10 * np.log10(noise[c][band] / n0[band])))
        return LeverArmNoise(np.asarray(state.load_cell_offset, float), float(kappa), se, noise, rise, n)

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """After a ``cross_coupling``: the transfer when κ departs from 0 by more than 2 standard errors."""
        if not any(isinstance(e, CrossCoupling) for e in state.effects):
            return []
        e = LeverArmNoise.fit(ctx, state, runs)
        return [e] if e is not None and e.noise_transfer > 2 * e.noise_transfer_stderr else []
