"""``speed_ripple``: a periodic wheel-speed ripple at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.constants import LINE_HALF
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.measure import (
    _clear_of_lines,
    _offset_grid,
    _offset_scores,
    _offset_threshold,
    _refine_offset,
    _residual_z,
    _window_power,
)
from ..diagnose.ripple import RIPPLE_IMBALANCE_DIRECTIONS, ripple_sideband_powers
from ..diagnose.state import State
from ..units import CHANNELS, DIRECTION_CHANNELS

#: A ripple is proposed on the whole record when this many carriers (lines of any direction) show sidebands at one
#: offset (within a record bin): an amplitude modulation of one line (``sidebands``) shows them on one.
RECORD_MIN_CARRIERS = 3
#: Carriers whose sidebands the whole-record fit reads: those standing this many times over the noise of their side
#: (|X|² of the carrier's model amplitude over the side's noise mean): ripple sidebands of 2-8 % of it are then
#: measured (the smaller ones at least near the noise, where the log fit reads them still).
RECORD_CARRIER_SNR = 1.0e4
#: Carriers whose offsets refine f_ripple on the whole record (the strongest sidebands of :meth:`record_candidates`).
RECORD_REFINE_CARRIERS = 4
#: A ripple closer to its lines than this many Welch bins is searched, fitted and judged on the whole record: there
#: its sidebands share their carrier's band of the error metric (BAND_BINS = 8 bins) and Welch kernel, and a ripple
#: just past the Welch grid's first offset (2.5 bins: family wheel 3, 5 Hz at 1.95-Hz bins) is no local maximum of it.
RECORD_WELCH_BINS = 4.0


def _on_record(ctx: Context, f_r: float) -> bool:
    """A ripple of ``f_r`` Hz is handled on the whole record (time series given, f_r < RECORD_WELCH_BINS bins)."""
    return ctx.test is not None and f_r < RECORD_WELCH_BINS * ctx.df


def _imbalance(direction: str, h: float) -> bool:
    """The line (direction, h) is an imbalance, U·(Ω² − jΩ̇): the ripple's Ω̇ pushes it along the rim too."""
    return direction in RIPPLE_IMBALANCE_DIRECTIONS and abs(h - 1.0) < 1e-6


def sideband_fractions(h, dw, w, f_r, p, tangential) -> tuple:
    """(lower, upper, carrier) power fractions |c_∓1|², |c_0|² of a line h (amplitude ∝ |Ω|^p, ``tangential``: an imbalance) under
    the ripple ΔΩ = ``dw`` at mean speeds ``w`` (rad/s): :func:`rwadist.diagnose.ripple.ripple_sideband_powers` with
    β = h·ΔΩ/2πf_r, ε = ΔΩ/Ω0 and τ = ΔΩ·2πf_r/Ω0² on an imbalance (0 else).  All broadcastable."""
    w = np.maximum(np.asarray(w, float), 1e-12)
    tau = np.where(tangential, dw * 2 * np.pi * f_r / w**2, 0.0)
    _, P = ripple_sideband_powers(h * dw / (2 * np.pi * f_r), dw / w, p, k_max=4, tau=tau)
    return P[..., 3], P[..., 5], P[..., 4]


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
        """The state with the ripple; on a base the wheel's ``suspension_modes`` measured from these data, each line's
        C divided by its carrier coefficient |c_0| (:meth:`carrier_factor`): measured under the ripple, a line's C holds
        the carrier as the ripple left it (J_0(β)² of the power at β = hΔΩ/2πf_r: 0.82 at h 4.6 on family wheel 5),
        and the ripple takes that share off again in the prediction; the model file gets the free load's C."""
        s = state.plus(self)
        if any(getattr(e, "kind", "") == "suspension_modes" for e in state.effects):
            from dataclasses import replace

            from .. import extended as ext

            s.model.empirical = {d: [replace(x, C=x.C / self.carrier_factor(
                x.h, ext.is_imbalance(d, x.h, getattr(x, "sense", None)))) for x in v]
                                 for d, v in s.model.empirical.items()}
            if s.ext is not None:
                # the extended base's imbalance lines are U_s and U_d (extended.lines_from_model), not the empirical
                # fundamentals: measured under the ripple too (family wheel 7, 5-Hz ripple, β 0.13: without this the
                # 1x carrier was predicted J_0(β)² = 0.991 of its power short, and 1x sidebands at the ripple's own
                # frequency were named to make it up)
                imb = self.carrier_factor(1.0, True)
                s.ext = replace(s.ext, U_s=s.ext.U_s / imb, U_d=s.ext.U_d / imb)
                s.model.analytical = dict(s.model.analytical or {}, **ext.params_to_dict(s.ext))
        return s

    def carrier_factor(self, h: float, imbalance: bool = False) -> float:
        """|c_0| of a line h (C·Ω²; ``imbalance``: with its tangential term) under this ripple at Ω_ref
        (:func:`sideband_fractions`): the carrier's share of the line's amplitude."""
        _, _, c0 = sideband_fractions(h, self.delta_omega, self.omega_ref, self.f_ripple, 2.0, imbalance)
        return float(np.sqrt(max(float(c0), 1e-12)))

    def contribute(self, parts) -> None:
        parts.speed_modulation = (self.delta_omega, self.f_ripple, self.omega_ref, self.exponent)

    def refit(self, ctx: Context, state: State) -> "SpeedRipple":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        if _on_record(ctx, self.f_ripple):
            return SpeedRipple.fit_record(ctx, state, ctx.runs, self.f_ripple, self.exponent) or self
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
        fit of ln P to ln(|c_{±1}|²·a²/2) over the first-order sidebands standing 5σ above the noise
        (:meth:`_fit_delta`)."""
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
        ki = np.where(pt["side"] > 0, 1, -1)

        def predict(dw):
            k, P = ripple_sideband_powers(pt["h"] * dw / (2 * np.pi * f_r), dw / pt["w"], pt["p"], k_max=4)
            return (P[np.arange(ki.size), ki + 4] + (P[:, 4] - 1.0) * pt["leak"]) * pt["a"] ** 2 / 2

        return SpeedRipple._fit_delta(ctx, runs, f_r, exponent, pt["w"], np.log(pt["P"]), predict)

    @staticmethod
    def _fit_delta(ctx: Context, runs, f_r: float, exponent: float, w, y, predict) -> "SpeedRipple":
        """The ripple of ΔΩ_ref minimising the soft-L1 misfit of the measured log powers ``y`` of the sideband points
        (mean speeds ``w`` rad/s) to ln ``predict``(ΔΩ at each point): a log-spaced grid of ΔΩ_ref, then a bounded
        scalar minimisation, with ΔΩ < ½·min|Ω| of the runs."""
        from scipy.optimize import minimize_scalar

        w_ref = ctx.omega_ref()

        def cost(x):
            r = (y - np.log(np.maximum(predict(np.exp(x) * (w / w_ref) ** exponent), 1e-300))) / 0.5
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
        (:func:`_offset_scores`), fitted with q = 0 and q = 1 (two hypotheses judged on held-out speeds); and, with the
        time series, an offset closer than the Welch bins resolve shared by the sidebands of several lines on the
        whole record (:meth:`_record_candidates`)."""
        if state.speed_modulation is not None:
            return []
        return SpeedRipple._welch_candidates(ctx, state, runs) + SpeedRipple._record_candidates(ctx, state, runs)

    @staticmethod
    def _welch_candidates(ctx: Context, state: State, runs) -> list:
        """:meth:`candidates` on the Welch PSDs: offsets from 2.5 Welch bins (:func:`_offset_grid`)."""
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

    # ------------------------------------------------------------------ the whole record (ripple within RECORD_WELCH_BINS)
    @staticmethod
    def _carriers(ctx: Context, state: State) -> list:
        """[(direction, h, channels)] of every line of the state's model on the context's channels."""
        out = []
        for d, direction_chans in DIRECTION_CHANNELS.items():
            chans = [c for c in direction_chans if c in ctx.channels]
            if chans:
                out += [(d, float(x.h), chans) for x in state.model.harmonics(d)]
        return out

    @staticmethod
    def _record_candidates(ctx: Context, state: State, runs) -> list:
        """A ripple closer to its lines than the Welch grid reaches (a short record, a high sample rate: family wheel 1,
        a 7.3-Hz ripple at 4.9-Hz Welch bins), seen on the whole record: the sidebands of every line at a fixed offset
        that :meth:`rwadist.effects.sidebands_diagnose.Sidebands.record_candidates` scans (kept on the context: the
        ``sidebands`` family reads the same), the offset RECORD_MIN_CARRIERS carriers or more share within a record
        bin, fitted with q = 0 and q = 1 (:meth:`fit_record`)."""
        from .sidebands_diagnose import RECORD_STEP_BINS, Sidebands
        from .speed_sidebands_diagnose import RUN_MIN_BINS, _record_df

        if ctx.test is None:
            return []
        df_rec = float(np.max(_record_df(ctx, ctx.runs)))
        offsets = np.arange(RUN_MIN_BINS * df_rec, RECORD_WELCH_BINS * ctx.df, RECORD_STEP_BINS * df_rec)
        found = []                      # (score, direction, h, offset Hz)
        for d in DIRECTION_CHANNELS:
            hs = [h for dd, h, _ in SpeedRipple._carriers(ctx, state) if dd == d]
            if hs:
                found += [(sc, d, h, f) for sc, h, f in Sidebands.record_candidates(ctx, state, runs, d, hs, offsets)]
        if len(found) < RECORD_MIN_CARRIERS:
            return []
        offs = np.array([f for *_, f in found])
        near = np.abs(offs[:, None] - offs[None, :]) <= df_rec
        j = int(np.argmax(near.sum(1) + 1e-9 * np.array([sc for sc, *_ in found])))
        if near[j].sum() < RECORD_MIN_CARRIERS:
            return []
        shared = [found[i] for i in np.flatnonzero(near[j])]
        top = sorted(shared, key=lambda x: -x[0])[:RECORD_REFINE_CARRIERS]
        f_r = SpeedRipple._refine_record(ctx, state, runs, [(d, h) for _, d, h, _ in top],
                                         float(np.median([f for *_, f in shared])))
        if f_r is None:
            return []
        return [e for e in (SpeedRipple.fit_record(ctx, state, runs, f_r, q, refine=False) for q in (0.0, 1.0))
                if e is not None]

    @staticmethod
    def _refine_record(ctx: Context, state: State, runs, carriers, f_r: float) -> float | None:
        """f_ripple (Hz) of the sidebands of ``carriers`` [(direction, h)] near ``f_r`` on the whole record: the maximum
        of their summed |X|² over both sides, every channel and every valid run on a grid ±RECORD_STEP_BINS record
        bins around ``f_r`` (step 1/50 bin), as :meth:`rwadist.effects.sidebands_diagnose.Sidebands.fit_record` refines
        one carrier's; None when that maximum is at the grid's edge (no sidebands near ``f_r``)."""
        from .sidebands_diagnose import RECORD_STEP_BINS, Sidebands
        from .speed_sidebands_diagnose import _record_df

        df_rec = float(np.max(_record_df(ctx, runs)))
        grid = f_r + np.arange(-RECORD_STEP_BINS, RECORD_STEP_BINS + 1e-9, 0.02) * df_rec
        tot = np.zeros(grid.size)
        for d, h in carriers:
            _, P, _, ok = Sidebands._record_power(ctx, state, d, h, runs, grid)
            both = ok[:, :grid.size] & ok[:, grid.size:]
            tot += np.sum(np.where(both[:, :, None], P[:, :grid.size] + P[:, grid.size:], 0.0), axis=(0, 2))
        i = int(np.argmax(tot))
        return float(grid[i]) if 0 < i < grid.size - 1 else None

    @staticmethod
    def _record_points(ctx: Context, state: State, runs, f_r: float) -> dict:
        """The first-order ripple sidebands f_i ∓ f_r of every line of every channel on the whole record (the carrier's
        leakage taken off, :meth:`rwadist.effects.sidebands_diagnose.Sidebands._record_power`) whose carrier stands
        RECORD_CARRIER_SNR over the side's noise, at valid points (in band, clear of the direction's other lines):
        |X|² ``P`` and noise mean ``N``, h, Ω (rad/s), ``a`` the carrier's model amplitude in the channel times the
        side's own gain (the fixed resonances' at the side, the suspension modes' at the side against the carrier's:
        :meth:`Context.sideband_gain`), amplitude exponent ``p``, ``side`` (∓1), ``tangential`` (an imbalance),
        ``chan`` (index into ``ctx.channels``), ``carrier`` (an index per (direction, h))."""
        from .sidebands_diagnose import Sidebands

        cols: dict[str, list] = {k: [] for k in ("P", "N", "Pc", "h", "w", "a", "p", "side", "tangential", "chan",
                                                 "carrier")}
        for n_c, (d, h, chans) in enumerate(SpeedRipple._carriers(ctx, state)):
            f, P, N, ok = Sidebands._record_power(ctx, state, d, h, runs, np.array([f_r]))
            f_c = h * ctx.omega[runs] / (2 * np.pi)
            for j, c in enumerate(chans):
                line = next((x for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
                if line is None:
                    continue
                _, law, a, _ = line
                # the carrier as measured (the fit reads the sidebands against it: a base fitted C·Ω² does not follow
                # the modes), its phasor on the whole record
                Pc = np.abs(SpeedRipple._carrier_dft(ctx, runs, c, d, h, f_c)) ** 2
                g_c = ctx.gain(state, c, f_c) if state.resonances else 1.0
                for col, side in ((0, -1.0), (1, 1.0)):
                    g = (ctx.gain(state, c, f[:, col]) if state.resonances else 1.0) * \
                        ctx.sideband_gain(state, c, h, side * f_r, runs)
                    amp = a * g * np.ones(runs.size)
                    keep = ok[:, col] & np.isfinite(P[:, col, j]) & (amp**2 > RECORD_CARRIER_SNR * N[:, col, j])
                    for k, v in (("P", P[:, col, j]), ("N", N[:, col, j]), ("Pc", Pc * (g / g_c) ** 2),
                                 ("h", np.full(runs.size, h)), ("w", ctx.omega[runs]), ("a", amp),
                                 ("p", np.full(runs.size, 2.0 if law is None else law[2])),
                                 ("side", np.full(runs.size, side)),
                                 ("tangential", np.full(runs.size, _imbalance(d, h) and law is None)),
                                 ("chan", np.full(runs.size, ctx.channels.index(c))),
                                 ("carrier", np.full(runs.size, n_c))):
                        cols[k].append(np.asarray(v)[keep])
        return {k: np.concatenate(v) if v else np.empty(0) for k, v in cols.items()}

    @staticmethod
    def _carrier_dft(ctx: Context, runs, c: str, d: str, h: float, f_c) -> np.ndarray:
        """Whole-run phasors (len(runs),) of channel ``c`` at its carrier (direction ``d``, line h) at ``f_c`` Hz
        (:func:`rwadist.diagnose.measure.record_dfts`), kept on the context (the data's, the same at every step)."""
        from ..diagnose.measure import record_dfts

        key = ("speed_ripple_carrier", c, d, round(h, 9), np.asarray(runs).tobytes())
        if key not in ctx._memo:
            ctx._memo[key] = record_dfts(ctx, runs, c, np.asarray(f_c, float)[:, None])[:, 0]
        return ctx._memo[key]

    @staticmethod
    def _record_powers(pt: dict, dw, f_r: float, measured: bool = False) -> np.ndarray:
        """|X|² the ripple ΔΩ ``dw`` (per point) puts at the points ``pt`` of :meth:`_record_points`: |c_∓1|²·(a·g)²,
        or with ``measured`` |c_∓1|²/|c_0|² times the measured carrier's |X|² through the side's gain."""
        lo, up, c0 = sideband_fractions(pt["h"], dw, pt["w"], f_r, pt["p"], pt["tangential"])
        side = np.where(pt["side"] > 0, up, lo)
        return side / np.maximum(c0, 1e-12) * pt["Pc"] if measured else side * pt["a"] ** 2

    @staticmethod
    def fit_record(ctx: Context, state: State, runs, f_r: float, exponent: float = 0.0,
                   refine: bool = True) -> "SpeedRipple | None":
        """The fit on the whole-run DFT (time series given) of a ripple closer to its lines than the Welch bins
        resolve: f_ripple refined on the strongest carriers' sidebands (:meth:`_refine_record`, unless ``refine`` is
        False), ΔΩ_ref by the robust log fit of :meth:`_fit_delta` of |X|² to |c_∓1|²·(a·g)² + noise over the
        sidebands of :meth:`_record_points` (each side through the modes at its own frequency; an imbalance's
        tangential force included); None with fewer than 5 points."""
        if refine:
            carriers = sorted(SpeedRipple._carriers(ctx, state), key=lambda x: -float(np.max(
                [np.max(y[2]) for c in x[2] for y in ctx.channel_lines(state, c, runs) if abs(y[0] - x[1]) < 1e-9]
                or [0.0])))[:RECORD_REFINE_CARRIERS]
            got = SpeedRipple._refine_record(ctx, state, runs, [(d, h) for d, h, _ in carriers], f_r)
            if got is None:
                return None
            f_r = got
        pt = SpeedRipple._record_points(ctx, state, runs, f_r)
        if pt["P"].size < 5:
            return None
        return SpeedRipple._fit_delta(ctx, runs, f_r, exponent, pt["w"], np.log(np.maximum(pt["P"], 1e-300)),
                                      lambda dw: SpeedRipple._record_powers(pt, dw, f_r, measured=True) + pt["N"])

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of a ripple closer to its lines than RECORD_WELCH_BINS Welch bins (None otherwise: the
        search's own judge), as :meth:`rwadist.effects.sidebands_diagnose.Sidebands.heldout_evidence` for one line's sidebands: there
        they sit in their carrier's Welch kernel, whose power the error metric's bands sum with it (the true ripple
        of family wheel 0, 5 Hz at 2.4-Hz Welch bins, changed the error by 1e-4 of it), and the whole record resolves
        them.  (drop, se) of the misplaced power at the first-order sidebands of every line, over the points of
        :meth:`_record_points` on ``runs`` (the state predicts no line there, the ripple |c_∓1|²·(a·g)²;
        :func:`~rwadist.effects.missing_harmonic_diagnose.record_line_evidence`).  Not on a state with a spin smear
        or a speed ripple."""
        from .missing_harmonic_diagnose import record_line_evidence

        if not _on_record(ctx, self.f_ripple) or state.smear is not None \
                or state.speed_modulation is not None:
            return None
        pt = SpeedRipple._record_points(ctx, state, runs, self.f_ripple)
        if pt["P"].size < 5:
            return None
        M1 = SpeedRipple._record_powers(pt, self.delta_omega * (pt["w"] / self.omega_ref) ** self.exponent,
                                        self.f_ripple)
        chans = list(ctx.channels)
        rows = np.arange(len(chans))[:, None] == pt["chan"][None, :]           # each point on its own channel
        shape = (len(chans), pt["P"].size)
        return record_line_evidence(ctx, chans, np.broadcast_to(pt["P"], shape), np.broadcast_to(pt["N"], shape),
                                    rows, np.broadcast_to(M1, shape))
