"""The greedy search of ``rwadist diagnose``: hypotheses from every registered effect family, judged on
held-out speeds, the best passing one refitted on every run and added (docs/diagnose.md)."""
from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import stats

from ..empirical import fit_empirical
from ..model import WheelModel
from ..spectra import Spectra
from . import describe
from .bases import fits_modes_from_data, resolve_base
from .constants import BAND_BINS, CONTRAST_METRIC, CONTRAST_NOISE_Z, METRIC, NOISE_Z
from .describe_law import laws_below_gain
from .effects import family_classes
from .effects.base import Effect
from .engine import Context, initial_state
from .law_recheck import recheck_laws
from .measure import in_unresolved_span
from .modes_status import modes_status
from .start_model import start_model
from .state import State


@dataclass
class Hypothesis:
    """A fitted effect judged on held-out speeds."""

    effect: Effect
    gain: float           # held-out improvement / held-out data power
    gain_fraction: float  # improvement / held-out unexplained power
    t: float              # improvement in standard errors
    passed: bool
    iteration: int
    #: a line of the wheel completed into a base fitted from the data (:func:`_base_lines`), not a foreign effect
    base_line: bool = False
    #: the signature of what the residual holds that no class explains this effect was fitted to (it was taken back:
    #: :func:`rwadist.diagnose.describe.forced_effects`), or None
    forced_by: str | None = None
    #: the test-stand resonance fitted jointly with the effect that it was judged beside (:func:`_judge_beside_stand`:
    #: the wheel's suspension modes with their fixture divided out on both sides of the comparison), or the load-cell
    #: offset (a ``cross_coupling``) the modes were judged with (:func:`_judge_with_offset`), or None
    beside: Effect | None = None
    #: the effect of several parts this hypothesis's effect is one part of (a floor law of several channels,
    #: :class:`rwadist.effects.broadband_floor_diagnose.FloorGroup`: one hypothesis, each part its own entry of the
    #: model file and its own hypothesis with the judgement of the whole), or None
    group: Effect | None = None
    #: the drop of the narrow-line misfit (:meth:`Context.contrast_error`) on the held-out runs over the state's, for
    #: an effect judged there as well (:func:`_narrow_judge`), else None
    narrow_gain_fraction: float | None = None
    #: why a law taken before the base changed was taken back on the new base (:mod:`.law_recheck`), or None
    taken_back: str | None = None


@dataclass
class Diagnosis:
    model: WheelModel
    state_before: State
    state_after: State
    error_before: float
    error_after: float
    rms_error_before: float
    rms_error_after: float
    hypotheses: list
    iterations: int
    ctx: Context
    #: True when the search started from a model the caller gave (not the empirical fit of the data)
    model_given: bool = False
    #: what the residual holds that no class explains (:class:`~rwadist.diagnose.unexplained.Unexplained` records)
    unexplained: tuple = ()
    #: the narrow-line figure of merit (``waterfall_band_contrast``, :meth:`Context.contrast_error`) before and after
    contrast_error_before: float = float("nan")
    contrast_error_after: float = float("nan")
    #: candidate physical causes of the model's non-integer lines ([{"direction", "h", "source", "causes"}])
    line_causes: list = field(default_factory=list)
    #: the wheel's bearings those causes were named from (:class:`rwadist.bearings.Bearing`)
    bearings: tuple = ()
    #: how the runs' speeds were obtained (:func:`rwadist.speed_whirl.speed_record`; {} when not told)
    speed: dict = field(default_factory=dict)
    #: channels of runs left out because they froze (:meth:`rwadist.data_quality.FrozenStretch.to_json` records)
    data_quality: list = field(default_factory=list)
    #: [(hypothesis, law refitted on every run)] of the amplitude laws the last step measured beyond ``k_sigma`` but
    #: below ``min_gain`` (:func:`rwadist.diagnose.describe_law.laws_below_gain`), described in ``unexplained``
    laws_below_gain: list = field(default_factory=list)

    @property
    def effects(self) -> list:
        return self.state_after.effects

    def lines_missing_from_given_model(self) -> list:
        """[(direction, h, C, sense)] of the lines of the improved model that the given model lacks (no harmonic within
        0.03 in h), when the search replaced the given model's harmonics by those fitted with the wheel's suspension
        modes (a given model without modes, or with assumed ones, on data that show modes): those lines are in the
        fitted base, named as no effect; empty otherwise.  ``sense``: 'co' or 'counter' of a radial line's part, or
        None."""
        if not self.model_given or self.state_before.base == self.state_after.base:
            return []
        from ..model import DIRECTIONS

        given = self.state_before.model
        return [(d, float(x.h), float(x.C), getattr(x, "sense", None)) for d in DIRECTIONS
                for x in self.model.harmonics(d) if not any(abs(x.h - y.h) < 0.03 for y in given.harmonics(d))]

    @property
    def band_Hz(self) -> tuple:
        """(lowest, highest) frequency of the bands the metrics count, Hz (the band analysed)."""
        ctx = self.ctx
        return (max(float(ctx.f[ctx.k_lo]) - 0.5 * ctx.df, 0.0),
                float(ctx.f[min(ctx.k_lo + ctx.n_bands * BAND_BINS - 1, ctx.f.size - 1)]) + 0.5 * ctx.df)

    def summary(self) -> dict:
        chosen = [h for h in self.hypotheses if h.passed and not h.base_line]
        return {
            "metric": METRIC,
            "base": self.state_before.base, "base_after": self.state_after.base,
            "metric_definition": "sum over channels, runs and %d-bin bands of |data - model| power / sum of "
                                 "data power (each channel divided by the mean power of its unit group)" % BAND_BINS,
            "band_Hz": list(self.band_Hz),
            "error_before": self.error_before, "error_after": self.error_after,
            "narrow_line_metric": CONTRAST_METRIC,
            "narrow_line_metric_definition": "mean over every channel, run and %d-bin band of max(|data - model| - "
                                             "%g sigma, 0) / max(data, model): every band weighs alike, so a narrow "
                                             "line standing out of the noise counts as on the waterfall"
                                             % (BAND_BINS, CONTRAST_NOISE_Z),
            "narrow_line_error_before": self.contrast_error_before,
            "narrow_line_error_after": self.contrast_error_after,
            "rms_relative_error_before": self.rms_error_before, "rms_relative_error_after": self.rms_error_after,
            "iterations": self.iterations,
            "effects": [effect_entry(h) for h in chosen],
            "base_lines": [{**effect_entry(h), **getattr(h.effect, "apart_entry", dict)()}
                           for h in self.hypotheses if h.passed and h.base_line],
            "lines_missing_from_given_model": [{"direction": d, "h": h, "C": C, "sense": sense}
                                               for d, h, C, sense in self.lines_missing_from_given_model()],
            "unexplained": [u.to_json() for u in self.unexplained],
            "line_causes": list(self.line_causes),
            "bearings": [dict(vars(b)) for b in self.bearings],
            "speed": dict(self.speed),
            "data_quality": list(self.data_quality),
            "suspension_modes_status": modes_status(self),
            "hypotheses": [effect_entry(h) for h in self.hypotheses],
        }


def effect_entry(hyp: Hypothesis) -> dict:
    """The model file's entry of a hypothesis's effect (:meth:`Effect.to_schema`) with its held-out evidence."""
    e = hyp.effect
    d = {**e.to_schema(),
         "evidence": {"heldout_gain": hyp.gain, "heldout_gain_fraction": hyp.gain_fraction,
                      "t": hyp.t, "passed": hyp.passed, "iteration": hyp.iteration}}
    if hyp.narrow_gain_fraction is not None:
        d["evidence"]["heldout_narrow_gain_fraction"] = hyp.narrow_gain_fraction
    group = getattr(hyp, "group", None)
    if group is not None:
        # one hypothesis of several parts: the gain and t above are the whole group's, not this part's alone
        d["evidence"]["part_of"] = list(group.channels)
    if hyp.forced_by:
        d["evidence"]["taken_back"] = f"fitted to content described as {hyp.forced_by}"
    if hyp.taken_back:
        d["evidence"]["taken_back"] = hyp.taken_back
    if getattr(hyp.beside, "kind", None) == "cross_coupling":
        d["evidence"]["judged_with_load_cell_offset_m"] = [float(x) for x in getattr(hyp.beside, "r")]
    elif hyp.beside is not None:
        d["evidence"]["judged_beside_test_stand_Hz"] = float(getattr(hyp.beside, "f_r", np.nan))
    return d


def _state_errors(ctx, state, runs, chans, memo):
    """:meth:`Context.run_errors` of ``state`` on ``runs`` over ``chans`` (None: every channel), with detail,
    computed once per search step: every hypothesis of a step is judged against the same state."""
    key = None if chans is None else tuple(chans)
    if memo is None:
        return ctx.run_errors(state, runs, None if key is None else list(key), detail=True)
    if key not in memo:
        memo[key] = ctx.run_errors(state, runs, None if key is None else list(key), detail=True)
    return memo[key]


def _judge(ctx, state, effect, k_sigma, min_gain, iteration, memo=None):
    """Held-out evidence of ``effect`` (fitted on the fit runs) added to ``state``.

    gain = Σ over held-out runs of the drop in misplaced power; its noise standard error is
    sqrt(Σ_bands min(|Δ|, σ)²·P_b), Δ = the change of the residual D − M (of the model M, or of the data
    D as read for a measurement correction such as ``cross_coupling``): if the data were M_0 plus
    Gaussian noise of std σ, a band's term max(|D − M| − zσ, 0) changes by at most |Δ| (and by about σ
    when the change is larger), and changes at all only with probability P_b = 2·Q(z − |Δ|/σ).  Passes
    when gain > k_sigma·SE and gain ≥ min_gain × the held-out misplaced power.  ``memo``: a dict shared by the
    hypotheses of one search step (the state's own errors, computed once), or None."""
    runs = ctx.held_runs
    other_fold = getattr(effect, "judge_runs", None)
    if other_fold is not None:
        # fitted on the held-out runs (the other fold, :func:`_other_folds`): judged on the fit runs
        runs, memo = np.asarray(other_fold), None
    own = getattr(effect, "heldout_evidence", None)
    ev = own(ctx, state, runs) if own is not None else None
    if ev is not None:
        # an effect the PSDs cannot see (e.g. counter rotation of a radial-force line) brings its own held-out
        # misplaced-power drop and standard error, in the metric's units
        gain, se = ev
        e0_all, all_tot, _ = _state_errors(ctx, state, runs, None, memo)
        t = gain / se if se > 0 else (np.inf if gain > 0 else 0.0)
        frac = gain / max(float(e0_all.sum()), 1e-300)
        hyp = Hypothesis(effect, gain / max(float(all_tot.sum()), 1e-300), frac, float(t),
                         bool(t > k_sigma and frac >= min_gain), iteration)
        return _narrow_measured(ctx, state, hyp, effect.apply(state), runs, k_sigma)
    chans = [c for c in effect.channels if c in ctx.channels]
    applied = effect.apply(state)
    gain, frac, t, total = _evidence(ctx, state, applied, runs, chans, memo,
                                     own_beats=getattr(effect, "own_beats", False))
    if getattr(effect, "role", "") == "test_stand":
        t = max(t, _by_direction_t(ctx, state, runs, chans, applied, memo))
    hyp = Hypothesis(effect, gain / total, frac, float(t), bool(t > k_sigma and frac >= min_gain), iteration)
    if hyp.passed:
        return hyp
    _narrow_measured(ctx, state, hyp, applied, runs, k_sigma)
    stand = getattr(effect, "stand_effect", lambda channels: None)(ctx.channels)
    if stand is not None:
        beside = _judge_beside_stand(ctx, state, effect, stand, runs, chans, k_sigma, min_gain, iteration)
        if beside.passed:
            return beside
    offset = getattr(effect, "offset_effect", lambda: None)() if ctx.offset_pair else None
    if offset is not None:
        with_offset = _judge_with_offset(ctx, state, effect, offset, runs, chans, k_sigma, min_gain, iteration)
        if with_offset.passed:
            return with_offset
    return hyp


def _narrow_measured(ctx, state, hyp: Hypothesis, applied, runs, k_sigma) -> Hypothesis:
    """``hyp`` with its ``narrow_gain_fraction`` measured (``applied``: its effect applied to ``state``) when it did not
    pass, its effect is judged on the narrow lines as well and its t is beyond ``k_sigma`` (:func:`_narrow_judge`)."""
    if not hyp.passed and getattr(hyp.effect, "judged_on_narrow_lines", False) and hyp.t > k_sigma:
        c0 = ctx.contrast_error(state, runs)
        hyp.narrow_gain_fraction = (c0 - ctx.contrast_error(applied, runs)) / c0 if c0 > 0 else 0.0
    return hyp


def _narrow_judge(ctx, state, judged, min_gain) -> tuple:
    """(hypothesis, its effect refitted on every run, the state with it) of the step's ``judged`` hypotheses (none passed)
    whose effect is judged on the narrow lines as well (``judged_on_narrow_lines``: an ``amplitude_law``), held-out t
    beyond ``k_sigma`` (:func:`_judge` measured ``narrow_gain_fraction`` only then) and drop of the held-out narrow-line
    misfit at least ``min_gain`` of the state's, the largest drop first, still significant refitted on every run and
    no worse (:func:`_no_worse`); (None, None, None) when none.

    ``min_gain`` is a share of a power-weighted sum: a law re-weights a line the model already has, and on a weak line
    (a bearing line 20-40 dB under the imbalance) it gains little of that sum however well it is measured, the more so
    beside a misfit of the modes.  trial21 (11-kg wheel, Ω^2.6 on the bearing line h 3.3): t 83-188 on the held-out
    runs, 0.13-0.47 % of the misplaced power, the torques' misfit at the rocking whirl crossings holding 85 % of it;
    the same laws took 14-29 % of the narrow-line misfit, the reviewer's view of the waterfall
    (``waterfall_band_contrast``: every band weighs alike).  An effect that adds content (a floor, a resonance, a line
    but a close one or one the base left out) is not judged so: its power share is its measure, and every band alike
    would let a floor's many bands pass."""
    modes = [e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"]
    if (getattr(ctx, "base_switch", False) and not modes) or \
            any(not m.startswith("zeta") for e in modes for m in e.unconstrained):
        # a wheel mode not located (or none, where the data were to give them) leaves its lines' misfit to whatever
        # re-weights them: no law on the narrow lines, only a line the base left out found beside a stand (trial24:
        # rocking not located beside an Ω^2.4 torque line crossing its backward whirl, Ω^1.66 on h 0.41)
        judged = [h for h in judged if getattr(h.effect, "left_out", False)]
    narrow = [h for h in judged if h.narrow_gain_fraction is not None and h.narrow_gain_fraction >= min_gain]
    for h in sorted(narrow, key=lambda h: -float(h.narrow_gain_fraction)):
        refit = h.effect.refit(ctx, state)
        if getattr(refit, "significant", lambda: True)():
            ok, applied = _no_worse(ctx, state, refit, h.beside)
            if ok:
                return h, refit, applied
    return None, None, None


def _evidence(ctx, state, applied, runs, chans, memo, own_beats=False) -> tuple:
    """(held-out gain, its fraction of the held-out misplaced power, t, the held-out data power) of the state
    ``applied`` over ``state`` on ``runs`` and ``chans`` (:func:`_judge`).  ``own_beats``: the effect adds no line,
    only changes the amplitude of lines ``state`` has (an amplitude law), so their beats are read at its amplitudes."""
    # judged against the noise of the lines it is proposed to: a line added beside another beats with it, and the
    # allowance for that beat (Metric.beat_variance) is no evidence for the line.  An effect that adds no line changes
    # no pair that beats, only its powers: read at the old amplitudes, the beat of a co/counter pair an Ω³ law makes
    # 3x stronger at the top speed was left unforgiven (family wheel 4, h 4.62 half counter-rotating: held-out gain
    # 15 % of the misplaced power at t 0.7; at its own amplitudes 99.6 %, t 4.4)
    _, _, p1 = ctx.run_errors(applied, runs, chans, detail=True, beat_state=applied if own_beats else state)
    e0_all, all_tot, _ = _state_errors(ctx, state, runs, None, memo)
    gain, t = _t_value(ctx, state, runs, chans, p1, memo)
    return gain, gain / max(float(e0_all.sum()), 1e-300), t, max(float(all_tot.sum()), 1e-300)


def _judge_beside_stand(ctx, state, effect, stand, runs, chans, k_sigma, min_gain, iteration) -> Hypothesis:
    """Held-out evidence of ``effect`` (the wheel's suspension modes) with the test-stand resonance ``stand`` fitted
    jointly with it divided out on both sides: ``stand`` and ``effect`` added to ``state`` against ``stand`` alone.

    A fixture resonance on the strongest lines (family wheel 2, a 45 Hz fixture under its 50-90 Hz modes, crossed by
    the imbalance at 2700 rpm) leaves the modes alone most of the held-out misplaced power: their own gain was 2 %
    of it, below ``min_gain``, and the search named no mode, while the modes fitted with the stand were within
    0.6 % of the truth.  The modes are the hypothesis; the stand is named after them (a ``fixed_resonance`` of
    role test_stand proposed from their stand, judged on its own).  Same rule as :func:`_judge`."""
    base = stand.apply(state)
    gain, frac, t, total = _evidence(ctx, base, effect.apply(state).plus(stand), runs, chans, None)
    return Hypothesis(effect, gain / total, frac, float(t), bool(t > k_sigma and frac >= min_gain), iteration,
                      beside=stand)


def _judge_with_offset(ctx, state, effect, offset, runs, chans, k_sigma, min_gain, iteration) -> Hypothesis:
    """Held-out evidence of ``effect`` (the wheel's suspension modes) read with the load-cell offset ``offset`` (a
    ``cross_coupling``) it was located beside: ``effect`` and ``offset`` added to ``state`` against the better of
    ``state`` as it is and ``state`` with ``offset`` alone.

    The modes predict the torques at the bearing centre; a load cell whose reference sits below it reads T + r × F,
    whose r × F carries the forces' lines, amplified by the translation mode, into the torques, where the empirical
    base fits each line freely: judged alone, the modes lose the torques (tests/standmodes_wheel's new wheel,
    r_z = 30 mm: modes within 0.1 % rejected in every iteration; a 'wheel mode' and an amplitude law named instead).
    The pair is judged against the state without either, as one hypothesis of the test (a wheel with these modes on
    a load cell with this offset); the modes are taken, and the offset is left to the search, which names it
    (``cross_coupling``, judged on its own) after them.  Same rule as :func:`_judge`.

    The pair is judged against the better of the state as it is and the state with the offset alone (the one whose
    held-out misplaced power is lower): r × F is a gain of the offset's own, and an offset that explains the runs
    alone would otherwise carry any modes located beside it (review14: a hard-mounted wheel's fixture fitted as
    modes beside a lever arm).  The modes must add their own gain beside the offset, as a wheel's modes beside a
    fixture must beside the fixture (:func:`_judge_beside_stand`).  A search that names modes so judged and then no
    offset is searched again without this path (:func:`_search`)."""
    pair = effect.apply(state).plus(offset)
    base = offset.apply(state)
    if _evidence(ctx, state, base, runs, chans, None)[0] > 0:
        state = base            # the offset alone explains the held-out runs better: the modes' share beside it
    gain, frac, t, total = _evidence(ctx, state, pair, runs, chans, None)
    return Hypothesis(effect, gain / total, frac, float(t), bool(t > k_sigma and frac >= min_gain), iteration,
                      beside=offset)


def _judge_families(ctx, state, families, k_sigma, min_gain, iteration, memo, other_folds=False) -> list:
    """The hypotheses of the candidates of ``families`` on ``state`` (:func:`_judge`), best held-out gain first; with
    ``other_folds``, when none passes, also those of their other folds (:func:`_other_folds`)."""
    cands = [e for cls in families for e in cls.candidates(ctx, state, ctx.fit_runs)]
    new = [_judge(ctx, state, e, k_sigma, min_gain, iteration, memo) for e in cands]
    if other_folds and not any(h.passed for h in new):
        new += [_judge(ctx, state, e, k_sigma, min_gain, iteration, memo) for e in _other_folds(ctx, state, new)]
    stands = [h.effect.f_r for h in new if h.passed and getattr(h.effect, "role", "") == "test_stand"]

    def under_a_stand(h) -> bool:
        # a resonance of one direction at a passing test stand's frequency is that stand seen on one direction: the
        # stand, which lifts every direction, is taken first (family wheel 5, a fixture on its 600 Hz translation: the
        # radial forces' own fit gained 0.93 of the held-out misfit, the stand 0.87, and two wheel-mode resonances
        # were named instead of it)
        return getattr(h.effect, "role", "") == "wheel_mode" and any(abs(h.effect.f_r / f - 1) < SAME_STAND_FREQUENCY
                                                                     for f in stands)
    return sorted(new, key=lambda h: (under_a_stand(h), -h.gain))


#: A wheel-mode resonance within this relative distance of a passing test-stand resonance is that stand
SAME_STAND_FREQUENCY = 0.02


def _other_folds(ctx, state, judged) -> list:
    """The effects of the judged hypotheses ``judged`` (none of which passed) fitted on the held-out runs instead, to
    be judged on the fit runs (``judge_runs``): ``effect.other_fold(ctx, state)`` where a family has it (the wheel's
    suspension modes).  The split of the speeds is arbitrary: half of a short speed grid can miss a sharp mode's
    peak while the other half holds it (family wheel 0 of seed 2, clean: the translation mode's ζ 0.013 ran to the
    fit's floor on the fit runs and no mode was located; the held-out runs locate all three within 0.05 %)."""
    out = []
    for h in judged:
        get = getattr(h.effect, "other_fold", None)
        e = get(ctx, state) if get is not None else None
        if e is not None:
            out.append(e)
    return out


def _band_terms(ctx, state, runs, chans, p1, memo) -> tuple:
    """(gain, variance, reach), each (len(runs), n_bands), of every band of every held-out run summed over ``chans``:
    the drop of the band's misplaced power max(|D − M| − NOISE_Z·σ, 0) from ``state`` (band residuals and σ: its
    :meth:`Context.run_errors` with detail) to the state whose band residuals and σ are ``p1``; its noise variance
    min(|Δ|, σ)²·P_b (see :func:`_judge`); and min(|Δ|, σ)², what that variance would be if the term moved in every
    draw of the noise (variance / reach: the chance P_b that it moves at all).  A band of one run is summed over the
    channels: they see the same lines beating in it, so their terms are not independent of one another, the bands
    are."""
    _, _, p0 = _state_errors(ctx, state, runs, chans, memo)
    gain, var, reach = (np.zeros((runs.size, ctx.n_bands)) for _ in range(3))
    for c in chans:
        (r0, sig), (r1, sig1) = p0[c], p1[c]
        ok = np.isfinite(r0[:, 0]) & np.isfinite(r1[:, 0])          # the runs with data (as run_errors counts them)
        dm = np.abs(r1 - r0)                                           # |Δ(D − M)|
        r = dm / np.maximum(sig, 1e-300)
        # a band's term changes only when the noise reaches past the forgiven NOISE_Z·σ less |ΔM|
        p_change = np.minimum(2.0 * stats.norm.sf(np.maximum(NOISE_Z - r, 0.0)), 1.0)
        g = np.maximum(np.abs(r0) - NOISE_Z * sig, 0.0) - np.maximum(np.abs(r1) - NOISE_Z * sig1, 0.0)
        step = np.minimum(dm, sig) ** 2
        gain[ok] += g[ok]
        var[ok] += (step * p_change)[ok]
        reach[ok] += step[ok]
    return gain, var, reach


def _t_value(ctx, state, runs, chans, p1, memo) -> tuple:
    """(held-out gain over ``chans``, its t-value :func:`held_out_t`) of the state whose band residuals are ``p1``
    against ``state`` (:func:`_judge`)."""
    gain, var, reach = _band_terms(ctx, state, runs, chans, p1, memo)
    return float(gain.sum()), held_out_t(gain, var, reach)


def held_out_t(gain: np.ndarray, var: np.ndarray, reach: np.ndarray) -> float:
    """The held-out t-value of a gain summed over independent bands, Σ gain / √(Σ var), with a band that holds more of
    the variance than all the others together and most likely does not move (var < reach / 2) judged apart: then the
    same ratio over the other bands, that band's gain counted only when it is a loss; and so on while the largest
    band left holds more than the rest and most likely does not move.

    ``gain``, ``var``, ``reach``: each band's drop in misplaced power, its noise variance min(|Δ|, σ)²·P_b and
    min(|Δ|, σ)² (:func:`_band_terms`; any shape, the same).  The ratio is read as a normal deviate, which needs no
    band to dominate the sum (Lindeberg's condition) unless that band's own term is near normal.  A band whose change
    |Δ| is a fraction of its noise σ moves at all only with the probability P_b that the noise reaches past the
    forgiven NOISE_Z·σ: its term is 0 in most draws and a jump of about ±|Δ| in the others, and a sum it dominates
    has that distribution, not a normal one (tests/test_diagnose_heldout_t.py: with such a band holding 0.7-0.99 of
    the variance, the ratio passes 3 under no effect 10-16x as often as a normal deviate; the other bands' ratio not
    more often).  Its large variance also hides the other bands' evidence: family wheel 4, a fixture resonance at
    1.5x the 227.7 Hz translation mode: one band of the top speed where the bearing line h 4.62 beats near that mode
    (σ 7.6, the stand's change 1.6, P_b 0.07) held 0.296 of the radial forces' 0.300, its own gain 0; the stand
    gained 77 % of the held-out misplaced power at t 0.64 and was not named.  The other bands are a valid test by
    themselves: leaving out an independent term leaves their null distribution as it was, and which band is left out
    is read from the variances alone (the state's σ and the change the effect, fitted on other runs, makes), not
    from the held-out data; a loss in it still counts, which can only lower the value."""
    gains, variances, reaches = (np.ravel(a) for a in (gain, var, reach))
    g, v = float(np.sum(gain)), float(np.sum(var))
    # the rule again on what is left, while it applies: a second such band dominates the rest once the first is
    # set aside (review of 942a0e9: one band set aside, a rarer one holding the rest passed 3 at 9-14x Q(3))
    left = variances
    while v > 0:
        i = int(np.argmax(left))
        v_i = float(left[i])
        if not (v_i > v - v_i and 2.0 * v_i < float(reaches[i])):
            break
        g, v = g - float(gains[i]) + min(float(gains[i]), 0.0), v - v_i
        left = left.copy() if left is variances else left
        left[i] = -np.inf
    return g / np.sqrt(v) if v > 0 else (np.inf if g > 0 else 0.0)


#: A test-stand resonance may not make a load direction worse by more than this many standard errors
STAND_DIRECTION_WORSE = 1.0


def _by_direction_t(ctx, state, runs, chans, applied, memo) -> float:
    """The held-out evidence of a resonance on every channel (role test_stand) read per load direction: the second
    largest of the directions' t-values (:func:`held_out_t`), or -inf when a
    direction's is below −:data:`STAND_DIRECTION_WORSE`.

    A fixture resonance's signature is a lift in every load direction; its evidence summed over the channels is
    diluted by the direction whose lines are measured least precisely (family wheel 3, a fixture at 288 Hz: the
    radial forces' strong lines near it, t 1.3, held the sum at t 3.97 while the torques alone gave 20 and the axial
    force 69, and the search named a wheel-mode resonance of the torques at the stand's frequency instead).  Two
    directions each passing the test by themselves, none made worse, is that signature; under no effect, two
    independent directions beyond k_sigma = 4 standard errors is as unlikely as one beyond about 5.5."""
    from ..units import CHANNEL_DIRECTION

    ts = []
    for d in sorted({CHANNEL_DIRECTION[c] for c in chans}):
        dch = [c for c in chans if CHANNEL_DIRECTION[c] == d]
        _, _, p1 = ctx.run_errors(applied, runs, dch, detail=True, beat_state=state)
        g_b, v_b, reach = _band_terms(ctx, state, runs, dch, p1, memo)
        gain, var = float(g_b.sum()), float(v_b.sum())
        if var <= 0 and gain == 0:
            continue                    # a direction the resonance does not touch (Tz: no line)
        ts.append(held_out_t(g_b, v_b, reach) if var > 0 else (np.inf if gain > 0 else -np.inf))
    if len(ts) < 2 or min(ts) < -STAND_DIRECTION_WORSE:
        return -np.inf
    return float(sorted(ts)[-2])


def _base_lines(hyps, model=None, left_out=()) -> None:
    """Mark the passing ``missing_harmonic`` hypotheses added after a ``suspension_modes`` as lines of the wheel's
    base (``Hypothesis.base_line``), not foreign effects.

    Once the wheel's modes are fitted from the data, the base's harmonics are the data's own lines (the
    extended fit of :class:`~rwadist.effects.suspension_modes_diagnose.SuspensionModes` replaces the starting
    model's): there is no model a line could be missing from, so a line at a constant h that this fit did not
    resolve (two close lines merged at a short record's resolution, a line below the fit's detection at the
    low speeds) is the wheel's own content, completed into the base.  It stays in the improved model's
    harmonics and is listed in its provenance (``diagnose.base_lines``) and the summary's ``base_lines``.

    The same for a given ``model`` whose extended fit recorded lines it detected but could not measure apart
    (``analytical.fit.unresolved_lines``: a close pair on the reference's short record): a missing harmonic found
    inside such a span is the wheel's own content the model already said it could not measure, completed into the
    model, not a foreign effect.

    And a line the empirical base left out as modally amplified at nearly every speed (``left_out``: (direction, h)
    of each) found again after a test-stand resonance was named: the fixture amplified it, and with the fixture
    divided out it is the wheel's own line (the W7 trial wheel on a 120-Hz fixture: the three lines h 3.12)."""
    stand_at = min((h.iteration for h in hyps if h.passed and getattr(h.effect, "role", "") == "test_stand"),
                   default=None)
    for h in hyps:
        e = h.effect
        if (stand_at is not None and h.passed and h.iteration > stand_at and getattr(e, "kind", "") == "missing_harmonic"
                and any(d == e.direction and abs(x - e.h) <= 1e-3 * x for d, x in left_out)):
            h.base_line = True
    for h in hyps:
        e = h.effect
        if (h.passed and getattr(e, "kind", "") == "missing_harmonic"
                and in_unresolved_span(model, getattr(e, "direction", ""), float(getattr(e, "h", np.nan)))):
            h.base_line = True
    modes_at = min((h.iteration for h in hyps if h.passed and getattr(h.effect, "kind", "") == "suspension_modes"),
                   default=None)
    if modes_at is None:
        return
    for h in hyps:
        if h.passed and h.iteration > modes_at and getattr(h.effect, "kind", "") == "missing_harmonic":
            h.base_line = True


NO_WORSE_TOLERANCE = 1e-3   # relative rise of the error an accepted effect's refit may cause (see _no_worse)


def _state_error(ctx, state) -> float:
    """:meth:`Context.error` of ``state`` on every run, kept on the state (a state is not changed once made): the
    search asks for the current state's error at every accepted hypothesis and for the first and last states' at
    the end."""
    if "search_error" not in state._cache:
        state._cache["search_error"] = ctx.error(state)
    return state._cache["search_error"]


def _take(ctx, state, h, k_sigma, min_gain) -> tuple:
    """(the hypothesis taken, ``h``'s effect refitted on every run, the state with it) of a hypothesis ``h`` that
    passed the judge, or (None, refit, None).  Refitted on every run, an effect must still be what its family proposes
    (an exponent that moved back to 2 within its standard errors is no new law) and be no worse (:func:`_no_worse`):
    else the next passing one is taken.

    The wheel's modes that passed alone but whose refit raised the error are judged with the load-cell offset they
    were located beside (:func:`_judge_with_offset`) before that: modes fitted on the fit runs can gain on the held-out
    runs' forces while their refit, which reads the torques at the bearing centre, loses the offset's r × F on every
    run.  trial25 height_s1 (a load cell 50 mm below the rotor): the modes passed alone (10.9 % of the held-out
    misplaced power), their refit raised the error 0.315 -> 0.372, and an Ω^2.09 law on the imbalance was taken
    first, the modes taken beside the offset only in the next iteration (docs/diagnose.md, "Amplitude laws judged
    again on a new base")."""
    refit = h.effect.refit(ctx, state)
    if not getattr(refit, "significant", lambda: True)():
        return None, refit, None
    ok, applied = _no_worse(ctx, state, refit, h.beside)
    if ok:
        return h, refit, applied
    offset = getattr(h.effect, "offset_effect", lambda: None)() if ctx.offset_pair and h.beside is None else None
    if offset is None:
        return None, refit, None
    other = getattr(h.effect, "judge_runs", None)
    runs = ctx.held_runs if other is None else np.asarray(other)
    chans = [c for c in h.effect.channels if c in ctx.channels]
    pair = _judge_with_offset(ctx, state, h.effect, offset, runs, chans, k_sigma, min_gain, h.iteration)
    if not pair.passed:
        return None, refit, None
    ok, applied = _no_worse(ctx, state, refit, offset)
    return (pair, refit, applied) if ok else (None, refit, None)


def _no_worse(ctx, state, refit, beside=None) -> tuple[bool, State]:
    """(ok, refit.apply(state)): ok is True when ``refit`` (a passing hypothesis refitted on every run) does not raise
    the error on every run (:meth:`Context.error`); the applied state is returned so that the search carries on from
    it (its predictions and error computed here are kept on it).  The judge weighed the effect fitted on the fit runs
    on the held-out runs; the refit is a
    new fit that nothing has judged, and a fit the data do not constrain can run off (a resonance whose peak falls
    between the lines: only ζ·g is measured, and ζ → its bound with g ×30 raised the error 34×).  Such a hypothesis
    is not added (the next passing one is taken), as one whose refit is not :meth:`significant`.  "Raise" means by
    more than ``NO_WORSE_TOLERANCE``: a line the Welch metric cannot measure (below its band, found on the whole
    record) moves the error by its window's leakage only (+1e-6 relative for a subharmonic at 2048 samples), while a
    refit that runs off raises it by factors.  ``beside``: the test stand the hypothesis was judged beside
    (:func:`_judge_beside_stand`): the refit's own stand (else that one) is then in both states compared; or the
    load-cell offset the modes were judged with (:func:`_judge_with_offset`): the refit with its own offset (else that
    one) is compared with the better of ``state`` as it is and ``state`` with that offset alone, and the state
    returned holds the refit without the offset."""
    new = refit.apply(state)
    if getattr(beside, "kind", None) == "cross_coupling":
        # judged with the offset it was located beside (:func:`_judge_with_offset`): the refit with its own offset
        offset = getattr(refit, "offset_effect", lambda: None)() or beside
        before = min(_state_error(ctx, state), ctx.error(offset.apply(state)))
        return ctx.error(new.plus(offset)) <= before * (1.0 + NO_WORSE_TOLERANCE), new
    if beside is not None:
        stand = getattr(refit, "stand_effect", lambda channels: None)(ctx.channels) or beside
        return ctx.error(new.plus(stand)) <= ctx.error(stand.apply(state)) * (1.0 + NO_WORSE_TOLERANCE), new
    return _state_error(ctx, new) <= _state_error(ctx, state) * (1.0 + NO_WORSE_TOLERANCE), new


class BaseRejected(Exception):
    """The wheel's own suspension modes the search fitted from the data failed the caller's ``base_check``: the
    search stopped there (``entry``: the ``suspension_modes`` record, :func:`effect_entry`)."""

    def __init__(self, entry: dict):
        super().__init__("the suspension modes fitted from the data failed the caller's check")
        self.entry = entry


def diagnose(spectra: Spectra, model: WheelModel | None = None, k_sigma: float = 4.0, min_gain: float = 0.05,
             max_iterations: int = 8, channels=None, test=None, base: str = "empirical", bearings=None,
             base_check=None) -> Diagnosis:
    """Greedy effect search on ``spectra`` starting from ``model`` (default: the empirical fit).

    k_sigma, min_gain : acceptance rule (docs/diagnose.md).  test : the SteadyTest ``spectra`` were
    computed from (50 % overlap), needed for ``cross_coupling`` (phases); without it that class is not tried.
    base : 'empirical' (default; lines C·Ω², hard mounted), 'extended' (lines through the suspension modes of
    the model's ``analytical`` section, :func:`rwadist.extended.steady_lines`) or 'auto' (extended when the
    model has an analytical section with modes not assumed and ``test`` does not record the modes off;
    otherwise empirical, and the search may move to the wheel's suspension modes fitted from the data); see
    :func:`resolve_base` and :func:`fits_modes_from_data`.  bearings : the wheel's bearings
    (:class:`rwadist.bearings.Bearing`), candidate causes of the lines (docs/diagnose.md, "Physical causes for
    lines"); None: those of the model's ``wheel`` section, if any.  base_check : None, or a callable taking the
    ``suspension_modes`` record (:func:`effect_entry`) the search fitted from the data, as soon as it is taken;
    False stops the search with :class:`BaseRejected` (a speed scale from the data the wheel's whirl contradicts,
    :mod:`rwadist.speed_whirl`: nothing after it is worth fitting on those speeds).
    Returns a :class:`Diagnosis` whose ``model`` carries the added harmonics in ``empirical`` and every
    effect in ``effects``.
    """
    given = model is not None
    if bearings is None:
        from ..bearings import bearings_of

        bearings = bearings_of(getattr(model, "wheel", None) if given else None)
    args = (spectra, model, k_sigma, min_gain, max_iterations, channels, test, base, bearings, base_check)
    diag = _search(*args)
    # a run-to-run change (a re-mounting, a range switch) left in the records is forced into classes and spoils the
    # wheel's modes: when one is described and the search added more than its base (or could not fit the modes), the
    # search is run again on the records with the changed runs' common factor taken out (docs/diagnose.md)
    from .run_gains import step_sets

    sets = step_sets(diag, describe.run_steps, describe.search_standing(diag)[0])
    if not sets:
        return _with_channel_step(diag, args)
    # the runs whose change was not read (NaN) may be changed ones: searched with them left in (as unchanged) and left
    # out, each kept by the search's own standard below (family wheel 2, the switched 442-rpm run unread: left in, an
    # amplitude law was added; family wheel 7 --seed 2, the unread 1000-rpm run unchanged: left out, the rocking
    # mode alone was located)
    # kept when it did better by the search's own standard (the wheel's modes located where they were not, else fewer
    # effects beyond the base; a drift spread over every run is taken out of every run first, :mod:`.run_gains`); a
    # search at the best standing there is (every mode located, nothing added) ends the tries: none can do better
    best = diag
    for s in sets:
        if describe.search_standing(best) >= describe.BEST_STANDING:
            break
        again = _search(*args, steps=s)
        if describe.search_standing(again) > describe.search_standing(best):
            best = again
    return best


def _with_channel_step(diag: Diagnosis, args: tuple) -> Diagnosis:
    """``diag``, or the search run again on the records with a channel's gain step taken out
    (:func:`.gain_step.channel_steps`: one channel of a radial pair switched gain between runs, and a wheel's mode
    rests on its lines) when that does as well by the search's own standard (:func:`.describe.search_standing`): its
    modes are then fitted on one gain, not through two, and the step is described as it was read."""
    from .gain_step import channel_steps, with_step_taken_out

    got = channel_steps(diag)
    if got is None:
        return diag
    again = _search(*args, steps=describe.RunSteps(*got))
    if describe.search_standing(again) < describe.search_standing(diag):
        return diag
    again.unexplained = with_step_taken_out(again, diag)
    return again


def _search(*args, **kwargs) -> Diagnosis:
    """:func:`diagnose` of its arguments (those of :func:`_search_once`), searched again without judging the wheel's
    modes with a load-cell offset (:func:`_judge_with_offset`) when the modes were taken so and no offset was named
    after them (:func:`_modes_without_their_offset`): their evidence was that of the pair, and the state kept the modes
    alone.  The second search's result is the answer, not compared with the first by
    :func:`rwadist.diagnose.describe.search_standing` (which ranks a search that located the modes first): the first
    is no candidate, its model holding modes whose test it passed only with an offset that model lacks
    (tests/test_modes_offset_own_gain.py)."""
    diag = _search_once(*args, **kwargs)
    if _modes_without_their_offset(diag):
        diag = _search_once(*args, **{**kwargs, "offset_pair": False})
    return diag


def _modes_without_their_offset(diag: Diagnosis) -> bool:
    """True when ``diag`` took an effect judged with a load-cell offset (:func:`_judge_with_offset`) and named no
    ``cross_coupling``."""
    taken = [h for h in diag.hypotheses if h.passed]
    return (any(getattr(h.beside, "kind", None) == "cross_coupling" for h in taken)
            and not any(getattr(h.effect, "kind", None) == "cross_coupling" for h in taken))


def _search_once(spectra: Spectra, model: WheelModel | None, k_sigma: float, min_gain: float, max_iterations: int,
                 channels, test, base: str, bearings, base_check=None, steps: dict | None = None,
                 offset_pair: bool = True) -> Diagnosis:
    """:func:`diagnose` of its arguments, ``bearings`` resolved; ``steps`` (run index -> dB, or None): the common
    factor of those runs taken out of the records the search reads (:func:`rwadist.diagnose.describe.start`);
    ``offset_pair``: the wheel's modes that do not pass alone may be judged with the load-cell offset they were
    located beside (:func:`_judge_with_offset`)."""
    given = model is not None
    # the open world (docs/diagnose.md, "Unexplained residual"): fixed-frequency lines and a channel's copy of another
    # taken out of the records all after reads, a model's empirical fit included (no class explains them), described
    opened = describe.start(Context(spectra, channels, test), steps)
    ctx = opened.ctx
    ctx.offset_pair = offset_pair
    if model is None:
        fit0 = fit_empirical(ctx.sp)
        model = start_model(ctx, fit0)         # with the carriers of sideband pairs only the records resolve
        ctx.left_out = tuple((b.direction, float(b.h)) for b in fit0.modally_left_out)
    request = base
    base = resolve_base(model, base, test)
    ext_params = None
    if base == "extended":
        from ..extended import params_from_model

        ext_params = params_from_model(model, getattr(model, "name", "<model>"))
    # 'auto' on the empirical base (no analytical model) may move to the extended base: the wheel's own
    # suspension modes, fitted from the data (``suspension_modes``), unless the test records the modes off
    ctx.base_switch = fits_modes_from_data(model, request, test)
    state0 = initial_state(ctx, model, ext_params)
    # its error on every run first (the diagnosis reports it): the held-out and fit runs' terms are then its rows
    _state_error(ctx, state0)
    state = state0
    hyps: list = []
    judged: list = []                           # the last step's hypotheses (read after the loop, with its best)
    it, best = 0, None
    # a family marked ``first`` (the wheel's own modes) is proposed and judged alone, before any other, and the others
    # only when it is not taken (the choice of judging all together, without fitting them to a state about to change)
    first = [cls for cls in family_classes() if getattr(cls, "first", False)]
    rest = [cls for cls in family_classes() if not getattr(cls, "first", False)]
    for it in range(1, max_iterations + 1):
        memo: dict = {}
        judged = []
        # what a family's fit could at most gain on the held-out runs (Context.can_pass): the step's own errors
        ctx.step = (state, lambda chans, state=state, memo=memo: _state_errors(ctx, state, ctx.held_runs, chans, memo),
                    min_gain)
        best = refit = applied = None
        for families in (first, rest):
            new = _judge_families(ctx, state, families, k_sigma, min_gain, it, memo, other_folds=families is first)
            for h in new:
                passed = h.passed
                h.passed = False                # set again on the one taken
                if passed and best is None:
                    best, refit, applied = _take(ctx, state, h, k_sigma, min_gain)
            judged = sorted(judged + new, key=lambda h: -h.gain)
            if best is not None:
                break
        if best is None:
            best, refit, applied = _narrow_judge(ctx, state, judged, min_gain)
        hyps += judged[:5] + ([best] if best is not None and best not in judged[:5] else [])
        if best is None or applied is None:     # (set together: applied is the state best was taken into)
            break
        best.passed = True
        state = applied                         # refit.apply(state), made by _no_worse
        best.effect = state.effects[-1]
        if base_check is not None and best.effect.kind == "suspension_modes" and not base_check(effect_entry(best)):
            raise BaseRejected(effect_entry(best))
        parts = getattr(refit, "parts", None)
        if parts:
            # an effect of several parts (a floor law of several channels, each channel's floor its own entry of the
            # model file): one passed hypothesis per part, each with the judgement of the whole
            k = next(i for i, h in enumerate(hyps) if h is best)
            best.group = refit
            hyps[k:k] = [replace(best, effect=e) for e in state.effects[-len(parts):-1]]
    else:
        it = max_iterations
    ctx.step = None
    state = recheck_laws(ctx, state, hyps, k_sigma, min_gain, _evidence)
    # a family may revise what it added in the light of what came after it (``finish``: the wheel's modes beside the
    # fixture resonances named after them); the hypotheses report the revised effects
    for cls in family_classes():
        finish = getattr(cls, "finish", None)
        if finish is not None:
            done = finish(ctx, state)
            revised = {id(a): b for a, b in zip(state.effects, done.effects) if a is not b}
            for h in hyps:
                h.effect = revised.get(id(h.effect), h.effect)
            state = done
    _base_lines(hyps, model, getattr(ctx, "left_out", ()))
    out = improved_model(model, state, hyps)
    diag = Diagnosis(out, state0, state, _state_error(ctx, state0), _state_error(ctx, state), ctx.rms_error(state0),
                     ctx.rms_error(state), hyps, it, ctx, model_given=given)
    if best is None:
        # the last step took nothing: a law it measured to t > k_sigma but below min_gain is described, not dropped
        # (a law on a weak line gains little of a power-weighted misplaced power: docs/diagnose.md)
        diag.laws_below_gain = laws_below_gain(ctx, state, judged, k_sigma, min_gain)
    # measured on the data as given, what the residual holds that no class explains described (and an effect the
    # search fitted to that content taken back: the model made again without it)
    return describe.finish(diag, opened, bearings, rebuild=lambda st, hs: improved_model(model, st, hs))


def improved_model(model: WheelModel, state: State, hyps) -> WheelModel:
    """The model file of the search's ``state``: its model with the starting ``model``'s effects and every passing
    hypothesis's entry (:func:`effect_entry`; a line completed into the base listed in the provenance instead)."""
    out = copy.deepcopy(state.model)
    out.effects = list(model.effects) + [effect_entry(h) for h in hyps if h.passed and not h.base_line]
    prov: dict[str, object] = {"metric": METRIC, "base": state.base}
    base_lines = [{k: v for k, v in effect_entry(h).items() if k in ("direction", "h", "C")}
                  for h in hyps if h.passed and h.base_line]
    if base_lines:
        prov["base_lines"] = base_lines
    out.provenance = dict(out.provenance, diagnose=prov)
    return out
