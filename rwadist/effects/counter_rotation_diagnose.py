"""``counter_rotation``: counter-rotating content of a radial harmonic (the extended base; the imbalance order alone on the empirical base)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..diagnose.constants import LINE_HALF, SNR_KNEE
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.state import State
from ..model import Harmonic
from ..units import CHANNELS, DIRECTION_CHANNELS


def _sense_group(state: State, direction: str, h: float):
    """The state's extended lines of (direction, h) (|Δh| < LAW_H_TOL) when they are all co- or counter-rotating and
    carry no amplitude law: (h of the group, C_co, C_counter, imbalance?) with C the root-sum-square of the lines'
    C (kg·m or kg·m², per (rad/s)²; an imbalance's C is U_s or U_d of the analytical section); else None.  On the
    empirical base the same of its harmonics of the imbalance's order h = 1 (:func:`_empirical_group`)."""
    from .. import extended as ext

    if state.ext is None:
        return _empirical_group(state, direction, h)
    g = [ln for ln in state.ext_lines() if ln.direction == direction and abs(ln.h - h) < ext.LAW_H_TOL]
    if not g or any(ln.sense == "planar" or ln.law is not None for ln in g):
        return None
    c_co = float(np.sqrt(sum(ln.C**2 for ln in g if ln.sense == "co")))
    c_ct = float(np.sqrt(sum(ln.C**2 for ln in g if ln.sense == "counter")))
    if c_co**2 + c_ct**2 <= 0:
        return None
    return float(g[0].h), c_co, c_ct, any(ln.imbalance for ln in g)


#: The one line whose counter-rotating part is an effect on the empirical base: the imbalance's order h = 1 (within
#: this).  Every other line of a hard-mounted wheel turns as its source does (a bearing line may hold both senses), and
#: a part of either sense is the line's own, not an effect; the imbalance turns with the rotor, and a counter-rotating
#: part of it is what the extended base names too (an anisotropic suspension or mount, a planar load at 1x).
EMPIRICAL_H = 1.0
EMPIRICAL_H_TOL = 1e-3


def _empirical_group(state: State, direction: str, h: float):
    """(h, C_co, C_counter, False) of the empirical base's harmonics of (direction, h) at the imbalance's order h = 1
    (:data:`EMPIRICAL_H`): a sense of None counted as co (the imbalance turns with the rotor); None for another h, a
    planar harmonic or one under an amplitude law."""
    if abs(h - EMPIRICAL_H) > EMPIRICAL_H_TOL:
        return None
    g = [x for x in state.model.harmonics(direction) if abs(x.h - h) <= EMPIRICAL_H_TOL]
    if not g or any(x.sense == "planar" for x in g) or (direction, round(g[0].h, 4)) in state.laws:
        return None
    c_co = float(np.sqrt(sum(x.C**2 for x in g if x.sense != "counter")))
    c_ct = float(np.sqrt(sum(x.C**2 for x in g if x.sense == "counter")))
    if c_co**2 + c_ct**2 <= 0:
        return None
    return float(g[0].h), c_co, c_ct, False


@register(order=80)
@dataclass
class CounterRotation:
    """Counter-rotating content of a radial harmonic (any line of the extended base; the imbalance order h = 1 of the empirical base).

    The radial load of harmonic h is F = a₊e^{+iσθ} + a₋e^{−iσθ} (θ = h·φ, φ the rotor angle, complex x + iy
    coordinates): a co-rotating part a₊ and a counter-rotating part a₋ (a planar, anisotropic load is
    |a₊| = |a₋|).  ``counter_fraction`` q = |a₋|²/(|a₊|² + |a₋|²), the total free power |a₊|² + |a₋|² = C²Ω⁴
    kept: the harmonic becomes a co line of C·sqrt(1 − q) and a counter line of C·sqrt(q) (for the
    imbalance h = 1 the co part is U_s or U_d of the analytical section, scaled by sqrt(1 − q)).
    Hard mounted the two parts have the same PSD; through the rotor's modes the co part meets the forward
    whirl and the counter part the backward one (:mod:`rwadist.extended`), so q is seen where
    |G₊| ≠ |G₋|, above all at the backward-whirl crossing.  The radial translation has no gyroscopic split
    (|G₊| = |G₋|): q of a radial-force line is not seen in PSDs; it is fitted from the x/y phase alone
    (:meth:`fit_phase`, needs the time series) and judged by :meth:`heldout_evidence`.
    ``counter_fraction_phase``: a second, independent estimate from the x/y phase of the time series
    (:meth:`fit`), NaN without them."""

    direction: str
    h: float
    counter_fraction: float
    counter_fraction_stderr: float = float("nan")
    counter_fraction_phase: float = float("nan")
    n_points: int = 0
    kind: str = "counter_rotation"
    #: e = (P_x − P_y)/(P_x + P_y) of the line on the empirical base when the runs agree on it (:func:`xy_split`): a co
    #: and a counter part whose ellipse keeps one orientation in the stator (an anisotropic mount or bearing), x read
    #: C·sqrt(1 + e) and y C·sqrt(1 − e); 0 when it changes from run to run (the parts' phases of their own) or on the
    #: extended base
    xy_split: float = 0.0
    #: the line's total C (co and counter parts' root-sum-square) measured with the split on the empirical base, from the
    #: x + y power of the phasors, or 0 (the state's kept): the empirical fit of C on an ellipse's x and y amplitudes
    #: reads their mean, below the root-mean-square (the W7 trial wheel, q 0.083 held at one orientation: 3 % low)
    c_total: float = 0.0

    def contribute(self, parts) -> None:
        if self.xy_split:
            parts.xy_splits[(self.direction, round(self.h, 4))] = self.xy_split

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def split(self, state: State):
        """(C_co, C_counter) of the harmonic after this effect, from the state's group total."""
        g = _sense_group(state, self.direction, self.h)
        if g is None:
            raise ValueError(f"counter_rotation: no co/counter line {self.direction} h = {self.h} in the state")
        c_tot = self.c_total if self.c_total > 0 else float(np.hypot(g[1], g[2]))
        q = float(np.clip(self.counter_fraction, 0.0, 1.0))
        return c_tot * np.sqrt(1.0 - q), c_tot * np.sqrt(q)

    def apply(self, state: State) -> State:
        from .. import extended as ext

        h0, c_co0, c_ct0, imb = _sense_group(state, self.direction, self.h)
        c_co, c_ct = self.split(state)
        s = state.copy()
        d = self.direction
        old = s.model.harmonics(d)
        at_h = [x for x in old if abs(x.h - h0) < ext.LAW_H_TOL]
        keep = [x for x in old if abs(x.h - h0) >= ext.LAW_H_TOL]
        h_key = at_h[0].h if at_h else h0
        new = []
        if imb:
            # the co part is the imbalance of the analytical section; the model's co harmonic (its empirical
            # coefficient, read by the hard-mounted consumers) is scaled alike
            name = "U_s" if d == "radial_force" else "U_d"
            if s.ext is None:       # an imbalance line is one of the extended base's (_sense_group)
                raise ValueError("counter_rotation: an imbalance line on a state without extended parameters")
            s.ext = replace(s.ext, **{name: c_co})
            s.model.analytical = dict(s.model.analytical or {}, **ext.params_to_dict(s.ext))
            scale = c_co / c_co0 if c_co0 > 0 else 0.0
            new += [replace(x, C=x.C * scale) for x in at_h if x.sense != "counter"]
        elif c_co > 0 and s.ext is None and at_h:
            # the empirical base's line keeps what its fit measured (its standard error scaled alike)
            x = at_h[0]
            new.append(replace(x, h=h_key, C=c_co, sense="co",
                               C_stderr=None if x.C_stderr is None else x.C_stderr * c_co / max(x.C, 1e-300)))
        elif c_co > 0:
            new.append(Harmonic(h=h_key, C=c_co, sense="co", C_stderr=self._part_stderr(c_co, c_ct, 1.0, at_h),
                                n_points=at_h[0].n_points if at_h else 0))
        if c_ct > 0:
            # its standard error from the line's and the split's (C₋ = C·√q), its measurements the line's
            new.append(Harmonic(h=h_key, C=c_ct, sense="counter", C_stderr=self._part_stderr(c_co, c_ct, -1.0, at_h),
                                n_points=at_h[0].n_points if at_h else 0))
        s.model.empirical[d] = sorted(keep + new, key=lambda x: (x.h, x.sense == "counter"))
        s.effects.append(self)
        return s

    def _part_stderr(self, c_co: float, c_ct: float, sense: float, line=()) -> float | None:
        """Standard error of the co (``sense`` +1) or counter (−1) part of the split C·√(1 − q), C·√q: relative
        √((σ_C/C)² + (σ_q/(2s))²), s the part's power share (1 − q or q), σ_q ``counter_fraction_stderr``, σ_C/C the
        line's own before the split (``line``: its harmonics at h, √(Σ C_i² σ_i²)/Σ C_i²; 0 where none is known);
        None where σ_q is not known (a new user's ``model show`` had the counter part with no standard error and 0
        points beside the effect's q ± 2.4e-5)."""
        se = self.counter_fraction_stderr
        c_tot = float(np.hypot(c_co, c_ct))
        part = c_co if sense > 0 else c_ct
        share = (part / max(c_tot, 1e-300)) ** 2
        if se is None or not np.isfinite(se) or share <= 0:
            return None
        known = [(x.C, x.C_stderr) for x in line if x.C_stderr is not None and np.isfinite(x.C_stderr)]
        total = sum(c**2 for c, _ in known)
        rel_line = float(np.sqrt(sum((c * e) ** 2 for c, e in known)) / total) if known and total > 0 else 0.0
        return float(part * np.hypot(rel_line, se / (2.0 * share)))

    def significant(self) -> bool:
        """Where the time series give the x/y phase estimate (``counter_fraction_phase``, independent of the PSD fit),
        it must see the same split: within half the smaller of q and 1 − q (plus 2 standard errors) of the fitted q.
        A PSD fit of a few per cent is the modes' own misfit at a whirl crossing (clean data of a wheel whose rocking
        mode the per-unit fit places 0.5 % off: q 0.017 ± 0.002 on its torque imbalance, the phase 0.000)."""
        qp = self.counter_fraction_phase
        if not np.isfinite(qp):
            return True
        q = self.counter_fraction
        se = self.counter_fraction_stderr if np.isfinite(self.counter_fraction_stderr) else 0.0
        return bool(abs(qp - q) <= 0.5 * min(q, 1.0 - q) + 2.0 * se)

    def refit(self, ctx: Context, state: State) -> "CounterRotation":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return CounterRotation.fit(ctx, state, self.direction, self.h, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "counter_fraction": self.counter_fraction,
                "counter_fraction_stderr": self.counter_fraction_stderr,
                "counter_fraction_phase": self.counter_fraction_phase, "n_points": self.n_points,
                **({"xy_split": self.xy_split} if self.xy_split else {}),
                "law": "radial load C*omega^2*(sqrt(1-q) e^{+i h phi} + sqrt(q) e^{-i h phi}), q = counter_fraction "
                       "= |a-|^2/(|a+|^2+|a-|^2); model: a co harmonic C*sqrt(1-q) and a counter one C*sqrt(q)"}

    @staticmethod
    def _points(ctx, state, direction, h, runs):
        """Per run: measured power of the line h summed over the direction's x and y channels (cross term of
        the co/counter pair cancels), and its prediction P_o + P₊ + q·(P₋ − P₊) at counter fraction q;
        returns (Pm, P_o, P₊, P₋, weight, ok) arrays."""
        g = _sense_group(state, direction, h)
        h0, c_co, c_ct, _ = g
        c_tot = float(np.hypot(c_co, c_ct))
        q0 = c_ct**2 / c_tot**2
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        w = ctx.omega[runs]
        f = h0 * w / (2 * np.pi)
        a2 = (c_tot * w**2) ** 2 / 2.0                      # free mean square of the harmonic
        Pm, Po, Pp, Pn, Nn = (np.zeros(runs.size) for _ in range(5))
        ok = np.ones(runs.size, bool)
        offs = np.arange(-LINE_HALF, LINE_HALF + 1)
        k = np.clip(np.rint(f / ctx.df).astype(int)[:, None] + offs, 0, ctx.f.size - 1)
        for c in chans:
            a = ctx.measure_line(state, c, h0, runs, skip=h0)
            ok &= np.isfinite(a)
            Hc2 = ctx.gain(state, c, f) ** 2
            gp = ctx.unit_gain(state, c, direction, h0, "co", runs) ** 2
            gn = ctx.unit_gain(state, c, direction, h0, "counter", runs) ** 2
            grp = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h0) < 1e-3), np.zeros(runs.size))
            other = np.maximum(grp**2 / 2.0 - a2 * ((1 - q0) * gp + q0 * gn), 0.0)
            Pm += np.where(np.isfinite(a), a, 0.0) ** 2 / 2.0
            Po += other * Hc2
            Pp += a2 * gp * Hc2
            Pn += a2 * gn * Hc2
            Nn += np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1).sum(1) * ctx.df
        snr = Pm / np.maximum(Nn, 1e-300)
        return Pm, Po, Pp, Pn, snr**2 / (snr**2 + SNR_KNEE**2), ok & (Pm > 0)

    @staticmethod
    def phase_fraction(ctx, state, direction, h, runs) -> float:
        """Counter fraction from the x/y phase of the time series (NaN without them): per run the complex
        amplitudes X, Y of the direction's x and y channels at h|Ω|/2π (:meth:`Context.phasors`) split into the
        co-rotating |X + iY|²/4 and counter-rotating |X − iY|²/4 mean squares (swapped for Ω < 0), each divided
        by its modal power gain |G±|² (and the fixed resonances) to the free load; q = Σ counter / Σ both."""
        pw = CounterRotation._phase_powers(ctx, state, direction, h, runs)
        if pw is None:
            return float("nan")
        co, ct, _noise, gp, gn, ok = pw
        tot = float(np.sum(co[ok] / gp[ok] + ct[ok] / gn[ok]))
        return float(np.sum(ct[ok] / gn[ok]) / tot) if tot > 0 else float("nan")

    @staticmethod
    def _phase_powers(ctx, state, direction, h, runs):
        """Per run of ``runs``: the co- and counter-rotating mean squares of the line (direction, h) from the x/y
        phasors (co |X + iY|²/4, counter |X − iY|²/4, swapped for Ω < 0; their sum is the x + y line power), each
        channel's fixed resonances divided out of its phasor (``state.channel_gain``: a fixture on Fy alone turns
        a circular line into an ellipse), the noise's expected share of each (white noise of the model floor S_x, S_y
        at the line through the whole-run Hann window: (S_x + S_y)/2 · f_s·Σw²/(Σw)², each divided alike), the modal power
        gains |G₊|², |G₋|² of a unit co and counter load, and an in-band mask.  None without time series."""
        chans = DIRECTION_CHANNELS[direction]
        if ctx.test is None or not all(c in ctx.channels for c in chans):
            return None
        from ..dft import run_window

        h0 = _sense_group(state, direction, h)[0]
        f = h0 * ctx.omega[runs] / (2 * np.pi)
        inb = (f >= ctx.k_lo * ctx.df) & (f <= ctx.k_hi * ctx.df)
        X = ctx.phasors(runs, f[:, None])[:, 0, :]
        x, y = (X[:, CHANNELS.index(c)] / state.channel_gain(c, f) for c in chans)
        co, ct = np.abs(x + 1j * y) ** 2 / 4.0, np.abs(x - 1j * y) ** 2 / 4.0
        neg = np.asarray(ctx.sp.speed, float)[runs] < 0
        co, ct = np.where(neg, ct, co), np.where(neg, co, ct)
        k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)[:, None]
        S = sum(np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1)[:, 0] / np.abs(state.channel_gain(c, f)) ** 2
                for c in chans) / 2.0
        enbw = np.empty(runs.size)
        for i, r in enumerate(runs):
            run = ctx.test.runs[r]
            _, wsum, w2sum = run_window(ctx.sp.window, run.n_samples)
            enbw[i] = run.sample_rate * w2sum / wsum ** 2
        noise = S * enbw
        gp = ctx.unit_gain(state, chans[0], direction, h0, "co", runs) ** 2
        gn = ctx.unit_gain(state, chans[0], direction, h0, "counter", runs) ** 2
        ok = inb & np.isfinite(co) & np.isfinite(ct) & (gp > 0) & (gn > 0)
        return co, ct, noise, gp, gn, ok

    @staticmethod
    def fit_phase(ctx: Context, state: State, direction: str, h: float, runs) -> "CounterRotation | None":
        """q from the x/y phase alone, for a line whose PSD cannot tell the senses apart (a radial-force line:
        the translation mode has no gyroscopic split).  Per run the noise's expected share is taken off the co
        and counter mean squares and each is divided by its modal power gain (:meth:`_phase_powers`);
        q = Σ counter / Σ (co + counter) over the runs (the high speeds weigh most: the load grows as Ω⁴).
        Its standard error from the noise of each mean square (a line of power P in complex Gaussian noise
        of mean n: variance n² + 2Pn).  None without time series or with fewer than 3 runs in band."""
        pw = CounterRotation._phase_powers(ctx, state, direction, h, runs)
        if pw is None:
            return None
        co, ct, noise, gp, gn, ok = pw
        if ok.sum() < 3:
            return None
        co, ct, noise, gp, gn = (v[ok] for v in (co, ct, noise, gp, gn))
        a, b = (co - noise) / gp, (ct - noise) / gn
        tot = float(np.sum(a + b))
        if not tot > 0:
            return None
        q = float(np.clip(np.sum(b) / tot, 0.0, 1.0))
        var_a = np.sum((noise**2 + 2 * np.maximum(co - noise, 0) * noise) / gp**2)
        var_b = np.sum((noise**2 + 2 * np.maximum(ct - noise, 0) * noise) / gn**2)
        se = float(np.sqrt(var_b * (1 - q) ** 2 + var_a * q**2) / tot)
        if not _one_share(a, b, np.abs(ctx.omega[runs][ok]), se):
            return None
        split, c_total = 0.0, 0.0
        if state.ext is None:
            split = xy_split(ctx, state, direction, h, runs, q)
            w4 = ctx.omega[runs][ok] ** 4
            c_total = float(np.sqrt(max(float(np.sum((a + b) * w4) / np.sum(w4 * w4)), 0.0)))
        return CounterRotation(direction, float(h), q, se, q, int(ok.sum()), xy_split=split, c_total=c_total)

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of a split the PSDs cannot see (:meth:`fit_phase`): (drop, se), in the units of the
        error metric (x + y power divided by the channels' group scale), of the misplaced rotating power
        Σ_runs |co − n − M₊| + |counter − n − M₋|, M± the model's co and counter mean squares of the line
        (its x + y power through the modal gains, before and after this effect); se as the search's judge
        (Σ min(|ΔM|, σ)², σ² = n² + 2Pn).  None when the effect changes the PSDs (the search's own judge)."""
        if self.xy_split:
            return None         # the split changes the x and y PSDs: the search's own judge
        g = _sense_group(state, self.direction, self.h)
        pw = CounterRotation._phase_powers(ctx, state, self.direction, self.h, runs)
        if g is None or pw is None or CounterRotation._sees_senses(ctx, state, self.direction, self.h, runs):
            return None
        co, ct, noise, gp, gn, ok = pw
        # the phasors' powers are read with the channels' fixed resonances divided out (:meth:`_phase_powers`): put
        # back in measured units, those of the error metric the drop is weighed against (the pair's mean |H|²)
        f = g[0] * np.abs(ctx.omega[runs]) / (2 * np.pi)
        back = sum(np.abs(state.channel_gain(c, f)) ** 2 for c in DIRECTION_CHANNELS[self.direction]) / 2.0
        co, ct, noise, gp, gn = co * back, ct * back, noise * back, gp * back, gn * back
        c_tot2 = g[1] ** 2 + g[2] ** 2
        q0 = g[2] ** 2 / c_tot2
        free = c_tot2 * ctx.omega[runs] ** 4                       # free x + y mean square of the harmonic
        scale = ctx.scale(DIRECTION_CHANNELS[self.direction][0])
        drop, var = 0.0, 0.0
        for meas, gain, s0, s1 in ((co, gp, 1 - q0, 1 - self.counter_fraction), (ct, gn, q0, self.counter_fraction)):
            r0 = meas - noise - s0 * free * gain
            r1 = meas - noise - s1 * free * gain
            sig = np.sqrt(noise**2 + 2 * np.maximum(meas - noise, 0) * noise)
            dm = np.abs((s1 - s0) * free * gain)
            drop += float(np.sum((np.abs(r0) - np.abs(r1))[ok]))
            var += float(np.sum(np.minimum(dm, sig)[ok] ** 2))
        return drop / scale, np.sqrt(var) / scale

    @staticmethod
    def _sees_senses(ctx, state, direction, h, runs) -> bool:
        """True when the modes give the co and counter parts PSDs the data can tell apart (max |ln |G₋|²/|G₊|²|
        >= 0.1 over the runs)."""
        h0 = _sense_group(state, direction, h)[0]
        c = DIRECTION_CHANNELS[direction][0]
        gp = ctx.unit_gain(state, c, direction, h0, "co", runs) ** 2
        gn = ctx.unit_gain(state, c, direction, h0, "counter", runs) ** 2
        return bool(np.max(np.abs(np.log(np.maximum(gn, 1e-300) / np.maximum(gp, 1e-300)))) >= 0.1)

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "CounterRotation | None":
        """q by weighted least squares of ln(measured x + y line power) on ln(P_o + P₊ + q(P₋ − P₊)) over the
        runs where the line stands above the noise (:meth:`_points`; weights s²/(s² + SNR_KNEE²), s the line's
        power over the noise in its window), q in [0, 1] (grid, then a bounded scalar minimisation); its
        standard error from the curvature and the residual scatter.  None when the data cannot tell the senses
        apart (max |ln P₋/P₊| < 0.1 over the runs) or fewer than 3 runs measure the line."""
        from scipy.optimize import minimize_scalar

        if _sense_group(state, direction, h) is None:
            return None
        Pm, Po, Pp, Pn, wt, ok = CounterRotation._points(ctx, state, direction, h, runs)
        if ok.sum() < 3:
            # too few runs hold the line's whole PSD window in band (coarse bins: a short record); the x/y phase
            # needs only the line's own frequency in band, and is the estimate anyway where the PSDs are blind
            if CounterRotation._sees_senses(ctx, state, direction, h, runs):
                return None
            return CounterRotation.fit_phase(ctx, state, direction, h, runs)
        Pm, Po, Pp, Pn, wt = (v[ok] for v in (Pm, Po, Pp, Pn, wt))
        if np.max(np.abs(np.log(np.maximum(Pn, 1e-300) / np.maximum(Pp, 1e-300)))) < 0.1:
            # the PSDs cannot tell the senses apart (a radial-force line): the x/y phase can
            return CounterRotation.fit_phase(ctx, state, direction, h, runs)
        y = np.log(Pm)

        def cost(q):
            return float(np.sum(wt * (y - np.log(np.maximum(Po + Pp + q * (Pn - Pp), 1e-300))) ** 2))

        grid = np.linspace(0.0, 1.0, 201)
        # cost at every grid point at once (each row the same operations as cost(q) and summed as np.sum sums it)
        vals = np.sum(wt * (y - np.log(np.maximum(Po + Pp + grid[:, None] * (Pn - Pp), 1e-300))) ** 2, axis=1).tolist()
        i = int(np.argmin(vals))
        sol = minimize_scalar(cost, bounds=(grid[max(i - 1, 0)], grid[min(i + 1, 200)]), method="bounded",
                              options={"xatol": 1e-6})
        q = float(sol.x) if sol.fun <= vals[i] else float(grid[i])
        P = Po + Pp + q * (Pn - Pp)
        J = (Pn - Pp) / P
        info = float(np.sum(wt * J**2))
        s2 = cost(q) / max(y.size - 1, 1)
        se = float(np.sqrt(s2 / info)) if info > 0 else float("inf")
        q_phase = CounterRotation.phase_fraction(ctx, state, direction, h, runs)
        return CounterRotation(direction, float(h), q, se, q_phase, int(y.size))

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """Every co/counter radial harmonic of the extended base not yet split, whose fitted q departs from the
        state's own (0 for a co line, 1 for a counter line) by more than 0.01 and 2 standard errors."""
        if state.ext is None and ctx.test is None:
            return []           # the empirical base's x/y phase is read on the records
        done = {(e.direction, round(e.h, 3)) for e in state.effects if isinstance(e, CounterRotation)}
        out = []
        if ctx.test is not None:
            # the x/y phasors of every line (:meth:`_phase_powers`) in one pass over the records
            h0s = [g[0] for d in ("radial_force", "radial_torque")
                   if all(c in ctx.channels for c in DIRECTION_CHANNELS[d])
                   for h in _line_orders(state, d)
                   if (g := _sense_group(state, d, h)) is not None and (d, round(h, 3)) not in done]
            if h0s:
                ctx.prefetch_phasors(runs, np.outer(ctx.omega[runs], h0s) / (2 * np.pi))
        def split(d) -> list:
            found = []
            for h in _line_orders(state, d):
                g = _sense_group(state, d, h)
                if g is None or (d, round(h, 3)) in done:
                    continue
                q0 = g[2] ** 2 / (g[1] ** 2 + g[2] ** 2)
                e = CounterRotation.fit(ctx, state, d, h, runs)
                if e is not None and abs(e.counter_fraction - q0) > max(0.01, 2 * e.counter_fraction_stderr):
                    found.append(e)
            return found

        for d in ("radial_force", "radial_torque"):
            chans = [c for c in DIRECTION_CHANNELS[d] if c in ctx.channels]
            if chans:
                # a direction's split from its own channels alone (Context.reuse)
                out += ctx.reuse("counter_rotation", state, chans, runs, lambda d=d: split(d))
        return out


#: The counter-rotating shares of the slower and the faster half of the runs differ by more than this factor: no
#: property of the load (:func:`_one_share`)
HALVES_RATIO = 3.0


def _one_share(a: np.ndarray, b: np.ndarray, speed: np.ndarray, se: float) -> bool:
    """True when the free load's counter-rotating share is one number over the speeds: the share of the slower half
    of the runs and that of the faster half (Σb/Σ(a + b) of each; ``a``, ``b`` each run's co and counter mean squares
    less the noise, divided by their modal gains; ``speed`` rad/s) within :data:`HALVES_RATIO` of each other, or
    within 4 standard errors ``se`` of q.

    A counter-rotating part of a load C·Ω² is the same share of it at every speed.  An ellipse made on the way to the
    load cell is not: a fixture flexible along y alone at 120 Hz (the new-user trial, session 56) lifts Fy over Fx as
    a line nears it, and the 1x line's share went from 0.001 over the slower half to 0.019 over the faster, fitted
    as a counter_rotation (q 0.0197, "an anisotropic mount or bearing") added to the wheel's model, where the modes
    were lost to the fixture; a true 30 % counter part read 0.0826 and 0.0826."""
    order = np.argsort(speed, kind="stable")
    half = order.size // 2
    if half < 2:
        return True
    shares = sorted(float(np.sum(b[i]) / np.sum(a[i] + b[i])) if np.sum(a[i] + b[i]) > 0 else 0.0
                    for i in (order[:half], order[half:]))
    return bool(shares[1] <= HALVES_RATIO * max(shares[0], 0.0) or shares[1] - shares[0] <= 4.0 * se)


def _line_orders(state: State, direction: str) -> list:
    """The orders h (rounded to 4 places, sorted) of the state's lines of ``direction``: the extended base's lines, or
    the empirical base's harmonics."""
    if state.ext is None:
        return sorted({round(x.h, 4) for x in state.model.harmonics(direction)})
    return sorted({round(ln.h, 4) for ln in state.ext_lines() if ln.direction == direction})


#: The x/y split is kept when its weighted mean over the runs stands this many standard errors from 0 (the runs'
#: scatter about it): a split whose sign and size change from run to run is the parts' phases of their own
XY_SPLIT_MIN_T = 5.0


def xy_split(ctx: Context, state: State, direction: str, h: float, runs, q: float) -> float:
    """e = Σ(P_x − P_y)/Σ(P_x + P_y) of the line (direction, h) over ``runs`` from the x/y phasors (each run's line
    powers less the noise's expected share, each channel's fixed resonances divided out), when the runs agree on it (:data:`XY_SPLIT_MIN_T`), else 0.

    A radial load z = x + iy = a₊e^{iθ} + a₋e^{−iθ} reads |x|² ∝ |a₊|² + |a₋|² + 2|a₊||a₋|cos ψ and |y|² with −, ψ the
    phase of a₊a₋: twice the ellipse's orientation in the stator.  An anisotropic mount or bearing holds ψ at every
    run (x cos θ and y sin θ of different stiffness), so e = 2·sqrt(q(1 − q))·cos ψ the same in every run, bounded by
    that of q; a counter part of its own phase (a second source) turns ψ from run to run and e averages out."""
    h0 = _sense_group(state, direction, h)[0]
    cx, cy = DIRECTION_CHANNELS[direction]
    w = ctx.omega[runs]
    f = h0 * np.abs(w) / (2 * np.pi)
    inb = (f >= ctx.k_lo * ctx.df) & (f <= ctx.k_hi * ctx.df)
    X = ctx.phasors(runs, (h0 * w / (2 * np.pi))[:, None])[:, 0, :]
    px, py = (np.abs(X[:, CHANNELS.index(c)] / state.channel_gain(c, f)) ** 2 for c in (cx, cy))
    ok = inb & np.isfinite(px) & np.isfinite(py) & (px + py > 0)
    if ok.sum() < 3:
        return 0.0
    px, py = px[ok], py[ok]
    e_run = (px - py) / (px + py)
    wt = (px + py) / np.sum(px + py)
    e = float(np.sum(wt * e_run))
    n_eff = 1.0 / float(np.sum(wt**2))
    scatter = float(np.sqrt(np.sum(wt * (e_run - e) ** 2)))
    if abs(e) < XY_SPLIT_MIN_T * max(scatter, 1e-12) / np.sqrt(n_eff):
        return 0.0
    bound = 2.0 * np.sqrt(max(q * (1.0 - q), 0.0))
    return float(np.clip(e, -bound, bound))
