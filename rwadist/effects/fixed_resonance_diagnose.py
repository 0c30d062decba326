"""``fixed_resonance``: a resonance at a fixed frequency multiplying the lines of its channels."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.constants import LINE_HALF, SNR_KNEE
from ..diagnose.describe_line_step import two_levels
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.fixed_resonance_moving import in_moving_reach, split_halves
from ..diagnose.stands import StandSet
from ..diagnose.state import State
from ..resonance import log_power_gain_jacobian, numerator_damping, resonance
from ..units import CHANNEL_DIRECTION, DIRECTION_CHANNELS, RADIAL_PAIRS

#: Smallest peak gain (or 1/gain, an anti-resonance of a test stand) proposed: |H| within 10 % of 1 everywhere is the size of the
#: fit's own model error near a mode (a per-unit extended base leaves ~1-3 % there), not a resonance.
MIN_PEAK_GAIN = 1.1

#: Largest damping ratio proposed: a "resonance" broader than this (the fit runs to its ζ bound of 0.5 on a
#: gentle tilt of the residual across the band) is not located by the data; the same limit as a fixture
#: resonance proposed by :func:`rwadist.effects.suspension_modes_diagnose.stand_resonance_start`.
MAX_ZETA = 0.2


def _line_gain_points(ctx, state, chans, runs, with_lines: bool = False):
    """(f Hz, y, weight, direction) of every model line of ``chans`` on ``runs`` measured above the noise and at least
    2·LINE_HALF bins from the channel's other lines:
    y = ln(measured power / predicted power) = 2 ln(a_measured/a_predicted), the log power gain a
    further resonance would have to supply at the line's frequency f = h|Ω|/2π.  weight = s²/(s² + s_k²)
    with s the line's power over the noise power in its window and s_k = :data:`SNR_KNEE`: the scatter of
    a log power falls as 1/s for weak lines and is bounded by model error for strong ones.  direction: the load
    direction of each point's channel (str).  ``with_lines``: three more, each point's line id (int), the lines
    ((direction, h) of each id, a list) and each point's predicted power (its line's level is read on the powers).

    On one radial direction's lines (``chans`` one pair, Fx/Fy or Tx/Ty: a wheel mode's fit) a line is read on the
    pair's power sum, one point for the pair (one measurement of the line: counted once where points are counted,
    :func:`speed_split`): a line with co- and counter-rotating parts is an ellipse whose orientation is set by the
    parts' phases, which change from run to run, so one channel's share of it does too (a planar line: 0 to 2x the
    power of each), and only the sum is the line's (the parts' cross term cancels between x and y).  Family wheel 3
    clean, seed 300: a planar line at h 8.03, measured on Fy alone at 5147 rpm (688.9 Hz; Fx did not measure it
    there), was fitted as a wheel mode at 688.8 Hz of peak gain 1.42 and added.  A run where one channel of the pair
    does not measure the line gives no point.  A stand's fit on every channel reads each channel as it is: read on
    the pairs' sums there, family wheel 7's fixture at 195 Hz on a table with a 20-mm load-cell offset was fitted
    with 1.6 % of the load far above it (1.0 % per channel), and the offset, judged beside that stand, lost its
    held-out gain (t +6.6 -> -4.5) and went unnamed.

    A line whose ratio to the speed drifts (:func:`rwadist.diagnose.describe_drift.drifting`: a bearing's cage
    slipping) is left out: read at its fixed ratio it falls away from the model as the data's line moves off, a loss
    a notch there fits (trial 30b wheel A, the cage slipping 5 %: a 'test stand' at 139.6 Hz of peak gain 0.27); so is
    a line whose level steps between two flat levels over the runs in speed order
    (:func:`rwadist.diagnose.describe_line_step.two_levels`: session 55's 3 kg wheel, its imbalance doubled from the
    20th of 40 runs, got a 'wheel mode' at 129.8 Hz, ζ 0.15, peak gain 1.27 on the radial forces)."""
    from ..diagnose.describe_drift import drifting

    moving = drifting(ctx, state.model)
    line_ids: dict = {}                 # (direction, h) -> its id (``with_lines``)
    offs = np.arange(-LINE_HALF, LINE_HALF + 1)
    read: dict = {}                     # channel -> {h: (f, measured power, predicted power, noise power, usable)}
    for c in chans:
        noise = ctx.floor_psd(state, c, runs)
        cl = ctx.channel_lines(state, c, runs)
        hs = np.array([x[0] for x in cl])
        measured = ctx.measure_lines(state, c, runs)          # each line against all the others, all at once
        read[c] = {}
        for (h, law, amp, _), a in zip(cl, measured):
            if any(d == CHANNEL_DIRECTION[c] and abs(x - float(h)) <= 1e-9 * x for d, x in moving):
                continue
            f = h * ctx.omega[runs] / (2 * np.pi)
            a_pred = amp * ctx.gain(state, c, f)
            # a line within 2·LINE_HALF bins of another beats with it in the Welch estimate: left out
            sep = np.abs(hs[hs != h][:, None] - h) * ctx.omega[runs][None, :] / (2 * np.pi) / ctx.df
            alone = np.all(sep >= 2 * LINE_HALF, axis=0) if sep.size else np.ones(runs.size, bool)
            ok = np.isfinite(a) & (a_pred > 0) & alone
            k = np.clip(np.rint(f / ctx.df).astype(int)[:, None] + offs, 0, ctx.f.size - 1)
            n_pow = np.take_along_axis(noise, k, axis=1).sum(1) * ctx.df
            read[c][float(h)] = (f, np.where(ok, a, 0.0) ** 2 / 2, a_pred ** 2 / 2, n_pow, ok)
    fs, ys, ws, ds, ids, preds = [], [], [], [], [], []
    one_pair = any(set(chans) == set(x) for x in RADIAL_PAIRS)
    for c in chans:
        pair = next((x for x in RADIAL_PAIRS if c in x), (c, c))
        partner = pair[1] if c == pair[0] else pair[0]
        other = read.get(partner, {}) if partner != c and one_pair else {}
        for h, (f, p, p_pred, n_pow, ok) in read[c].items():
            if h in other:
                if c != pair[0]:
                    continue            # the pair's point is its first channel's
                # the pair's power sum (this function's docstring)
                _, p2, p2_pred, n2, ok2 = other[h]
                ok = ok & ok2
                p, p_pred, n_pow = p + p2, p_pred + p2_pred, n_pow + n2
            with np.errstate(divide="ignore", invalid="ignore"):
                if two_levels(np.abs(ctx.omega[runs]), np.where(ok, 10 * np.log10(p / p_pred), np.nan)) is not None:
                    continue            # its level steps between two flat levels: no resonance's lift (docstring)
            snr = p[ok] / n_pow[ok]
            fs.append(f[ok])
            ys.append(np.log(p[ok] / p_pred[ok]))
            preds.append(p_pred[ok])
            ws.append(snr ** 2 / (snr ** 2 + SNR_KNEE**2))
            ds.append(np.full(int(ok.sum()), CHANNEL_DIRECTION[c]))
            ids.append(np.full(int(ok.sum()), line_ids.setdefault((CHANNEL_DIRECTION[c], h), len(line_ids))))
    if not fs:
        out = (np.empty(0), np.empty(0), np.empty(0), np.empty(0, str))
        return out + (np.empty(0, int), [], np.empty(0)) if with_lines else out
    out = (np.concatenate(fs), np.concatenate(ys), np.concatenate(ws), np.concatenate(ds))
    return out + (np.concatenate(ids), list(line_ids), np.concatenate(preds)) if with_lines else out


def _lifted_directions(e: "FixedResonance", f: np.ndarray, y: np.ndarray, w: np.ndarray, dirs: np.ndarray) -> int:
    """Number of load directions whose measured lines the resonance ``e`` explains, or 0 when it makes one worse.

    ``f`` (Hz), ``y`` (the log power gain each measured line needs over the model without ``e``: ln(measured /
    predicted power)), ``w`` (its weight, :func:`_line_gain_points`) and ``dirs`` (its load direction) of every point;
    those where ``e`` changes the power by a factor e^:data:`rwadist.stand_detect.STAND_MIN_LOG_GAIN` (1.5) or more,
    either way (the stand detection's own threshold), weigh each direction: it is explained when
    Σw(y − ln|H|²)² < Σwy² over its points, made worse when the reverse.  A fixture resonance lifts every direction's lines near it; a resonance of one direction (a housing
    mode on the radial forces) pooled over every channel lifts the torques' and axial lines it passes too, which
    the data do not show."""
    from ..stand_detect import STAND_MIN_LOG_GAIN, log_power_gain

    if f.size == 0:
        return 0
    lg = log_power_gain(e, f)
    acts = np.abs(lg) >= STAND_MIN_LOG_GAIN
    better = []
    read = {d: int(np.sum(acts & (dirs == d))) for d in np.unique(dirs[acts])}
    for d, n in read.items():
        if n < DIRECTION_MIN_POINTS and n < DIRECTION_MINOR_SHARE * max(read.values()):
            continue                    # a line or two at the top speeds where others hold many: neither way
        m = acts & (dirs == d)
        better.append(bool(np.sum(w[m] * (y[m] - lg[m]) ** 2) < np.sum(w[m] * y[m] ** 2)))
    return 0 if not all(better) else len(better)


#: A direction decides :func:`_lifted_directions` on this many points the resonance acts on or more (below): the new-user trial
#: of session 54 (its own generator: a 2.5 kg wheel on two fixtures, 350 Hz and 800 Hz on every channel), the 800 Hz
#: stand fitted beside the 350 Hz one lifted the radial forces, torques and axial force (their misfit 132 -> 18,
#: 54 -> 4, 103 -> 30 on 54, 28, 28 points) and was refused for Tz's 4 points at 580-661 Hz (0.12 -> 0.86), its two
#: lines' C fitted with the lift's top runs in them; the 800 Hz stand was never named and read as an 8-pole 882 Hz
#: anti-alias filter.  Six: a fit's own least number of points (:meth:`FixedResonance._fit`); only where another
#: direction is read on four times as many or more (a direction as few as the others is all there is to read).
DIRECTION_MIN_POINTS = 6
DIRECTION_MINOR_SHARE = 0.25


#: Evaluation limit of each least-squares fit: scipy's default for 'trf' with 3 parameters (100·n), written out
#: because :class:`_FlatNoResonance` projects to it.
MAX_NFEV = 300
#: A fit is stopped as "no resonance" (:class:`_FlatNoResonance`) after FLAT_MIN_ITER iterations when ln g, projected
#: linearly from its change over the last FLAT_WINDOW iterations to :data:`MAX_NFEV`, stays within NO_RESONANCE_FRACTION
#: of ln :data:`MIN_PEAK_GAIN`: near g = 1 the Jacobian's f_r and ζ columns vanish with g − 1, so the solver creeps
#: along a flat valley to its evaluation limit (ln g moves by ~0.01 in 250 iterations on clean data), and wherever it
#: stops the result is no resonance.  12 iterations (a 6-iteration window) rather than 40 (20): on clean data the
#: stopped starts were 90 % of a diagnosis's least-squares evaluations, and the robustness matrix
#: (benchmarks/diagnose_matrix.py, both paths, every class) gives the same table with 40/20, 20/10 and 12/6.
FLAT_MIN_ITER, FLAT_WINDOW, NO_RESONANCE_FRACTION = 12, 6, 0.8


class _FlatNoResonance:
    """least_squares ``callback``: StopIteration (status −2) once the iterate is a flat no-resonance (see
    :data:`NO_RESONANCE_FRACTION`); x = (ln f_r, ln ζ, ln g)."""

    def __init__(self):
        self.log_gains = []

    def __call__(self, intermediate_result):
        self.log_gains.append(float(intermediate_result.x[2]))
        n = len(self.log_gains)
        if n < FLAT_MIN_ITER:
            return
        now = self.log_gains[-1]
        pace = abs(now - self.log_gains[n - 1 - FLAT_WINDOW]) / FLAT_WINDOW       # per iteration (≥ 1 evaluation)
        left = max(MAX_NFEV - int(intermediate_result.nfev), 0)
        if abs(now) + pace * left < NO_RESONANCE_FRACTION * np.log(MIN_PEAK_GAIN):
            raise StopIteration


#: A resonance is fitted where the lines reach it: a measured line within this relative distance of f_r (or within
#: three of its relative half-power half-widths ζ) in one run at least, or one it changes by REACH_DB at least.
#: Beyond every line a narrow resonance is a smooth tilt of their misfit, its frequency and damping unmeasured (trial
#: 34, a clean 9-kg wheel whose radial torque lines reach 403 Hz: a 'wheel mode' at 1068 Hz (ζ 0.0197, peak gain 18.9
#: fitted again on the line gains it was proposed from; 0.44 dB at most on any line) took 22 % of a remainder of 0.11 %
#: of the data's power, a 2 % tilt the extended base left on the torque lines at 180-370 Hz), while a real one just
#: above the top line lifts it plainly (450 Hz, ζ 0.02, peak gain 10: the 403-Hz line 6 dB)
REACH = 0.1
REACH_DB = 2.0


def reached(f: np.ndarray, f_r: float, zeta: float, peak_gain: float = 1.0) -> bool:
    """Whether a line point at ``f`` (Hz) lies within :data:`REACH` (or 3ζ) of the resonance's f_r, relatively, or
    is changed by it (:func:`rwadist.resonance.resonance`, peak gain ``peak_gain``) by :data:`REACH_DB` at least."""
    if not f.size:
        return False
    if float(np.min(np.abs(np.log(f / f_r)))) <= max(REACH, 3.0 * zeta):
        return True
    return float(np.max(np.abs(20 * np.log10(np.abs(resonance(f, f_r, zeta, peak_gain)))))) >= REACH_DB


def _least_squares_has_callback() -> bool:
    import inspect

    from scipy.optimize import least_squares

    return "callback" in inspect.signature(least_squares).parameters


_HAS_CALLBACK = _least_squares_has_callback()


def _is_resonance_gain(peak_gain: float) -> bool:
    """True when a peak gain passes :data:`MIN_PEAK_GAIN` (either way: a peak or a notch)."""
    return abs(np.log(peak_gain)) >= np.log(MIN_PEAK_GAIN)


def _is_resonance(sol) -> bool:
    """:func:`_is_resonance_gain` of a least-squares solution x = (ln f_r, ln ζ, ln g)."""
    return _is_resonance_gain(float(np.exp(sol.x[2])))


def _soft_l1_cost(r: np.ndarray) -> float:
    """The cost least_squares minimises for residuals ``r`` with loss soft_l1 and f_scale 0.5."""
    return float(np.sum(2.0 * (np.sqrt(1.0 + (r / 0.5) ** 2) - 1.0))) * 0.125


def _general_refit(e: "FixedResonance", f, y, sw, lo: float, hi: float) -> "FixedResonance":
    """``e`` refitted in the general form of :mod:`rwadist.resonance` (f_r, ζ, the numerator's damping γ and the gain
    above β free) on the log power gains ``y`` at ``f`` (weights ``sw``): robust (soft-L1) least squares from ``e``
    itself (β = 1, γ = g) and from a transmissibility (β = 0, γ = 1); ``e`` kept unless the general fit is better."""
    from scipy.optimize import least_squares

    from ..resonance import general_log_power_gain, peak_of

    lb = np.array([np.log(lo), np.log(1e-3), 0.0, -1.0])
    ub = np.array([np.log(hi), np.log(0.5), 200.0, 3.0])

    def res_jac(x):
        lg, d = general_log_power_gain(f, float(np.exp(x[0])), float(np.exp(x[1])), float(x[2]), float(x[3]))
        return sw * (y - lg), -sw[:, None] * d

    base = res_jac(np.array([np.log(e.f_r), np.log(e.zeta), e.peak_gain, 1.0]))[0]
    base_cost = _soft_l1_cost(base)
    sols = []
    for gamma, beta in ((min(e.peak_gain, 199.0), 1.0), (1.0, 0.0)):
        x0 = np.clip([np.log(e.f_r), np.log(e.zeta), gamma, beta], lb + 1e-9, ub - 1e-9)
        sols.append(least_squares(lambda x: res_jac(x)[0], x0, jac=lambda x: res_jac(x)[1], loss="soft_l1",
                                  f_scale=0.5, bounds=(lb, ub), max_nfev=MAX_NFEV))
    best = min(sols, key=lambda sol: sol.cost)      # the first of the lowest cost
    if best.cost >= base_cost:
        return e
    from dataclasses import replace

    zeta = float(np.exp(best.x[1]))
    return replace(e, f_r=float(np.exp(best.x[0])), zeta=zeta, peak_gain=peak_of(zeta, float(best.x[2]),
                                                                                  float(best.x[3])),
                   gain_above=float(best.x[3]))


#: A proposed fixed resonance is read on the slower and the faster half of the runs (:func:`speed_split`) when each half
#: holds this many runs at least (fewer: the split tells nothing and the resonance is kept), the number the suspension
#: modes' structure-mode split asks (:data:`rwadist.stand_resonance.STRUCTURE_SPLIT_MIN_RUNS`)
SPLIT_MIN_RUNS = 5
#: ... and it moves with the speed when the two halves' centres lie more than its relative half-power half-width ζ
#: apart, and this at least: the same floor as that split's (``STRUCTURE_SPEED_SPLIT_TOL``)
SPLIT_MIN_MOVE = 0.03


def speed_split(ctx: Context, state: State, e: "FixedResonance") -> dict | None:
    """The resonance ``e`` (proposed on ``state``, which does not hold it) fitted with one centre for the slower and
    one for the faster half of the runs (ζ, the numerator's damping γ and, fixed, its gain far above shared), against
    one centre for both; None when a half holds fewer than :data:`SPLIT_MIN_RUNS` runs or the lines give too few
    points (the halves: :func:`rwadist.diagnose.fixed_resonance_moving.split_halves`).

    Both fits are robust (soft-L1) least squares of ln|H|² (:func:`rwadist.resonance.general_log_power_gain`) on the
    log power gains of ``e``'s channels' lines (:func:`_line_gain_points`, measured on each half's runs), from ``e``
    itself.  A resonance fixed in frequency lifts the lines near one frequency at every speed, the slower runs' high
    orders and the faster runs' low ones alike, and the two centres agree; a resonance whose centre moves with the
    speed (a disc mode stiffening, a drive resonance following the speed) lifts the slower runs' lines near one
    frequency and the faster runs' near another, and one fixed resonance fitted to it sits between them.

    Returns
    -------
    dict or None
        ``f_slow_Hz``, ``f_fast_Hz`` (the centres, Hz), ``f_common_Hz``, ``zeta`` (the split fit's), ``n`` (points),
        ``evidence`` (n·ln(cost_common/cost_split) − ln n: the Bayesian information criterion of the split's one more
        parameter, > 0 where the data want two centres) and ``moved`` (|ln(f_fast/f_slow)|)."""
    from scipy.optimize import least_squares

    from ..resonance import general_log_power_gain, numerator_damping

    chans = [c for c in e.channels if c in ctx.channels]
    # the halves of every run, else of the runs whose lines reach it (a half under its reach places no centre)
    parts = split_halves(ctx, e, lambda runs, **kw: _line_gain_points(ctx, state, chans, runs, **kw), SPLIT_MIN_RUNS)
    if parts is None:
        return None
    f, y, w = (np.concatenate([p[k] for p in parts]) for k in range(3))
    fast = np.repeat([False, True], [parts[0][0].size, parts[1][0].size])
    sw, beta = np.sqrt(w), float(e.gain_above)

    def res_jac(x, split):
        # x: (ln f_r[, ln f_r fast], ln ζ, γ); r = f/f_r of each point's own centre (general_log_power_gain of f/f_r at
        # f_r = 1: its derivative in ln f_r depends on r alone)
        centre = np.where(fast, np.exp(x[1]), np.exp(x[0])) if split else np.exp(x[0])
        lg, d = general_log_power_gain(f / centre, 1.0, float(np.exp(x[-2])), float(x[-1]), beta)
        cols = [d[:, 0] * ~fast, d[:, 0] * fast] if split else [d[:, 0]]
        return sw * (y - lg), -sw[:, None] * np.column_stack(cols + [d[:, 1], d[:, 2]])

    lo, hi = ctx.k_lo * ctx.df, ctx.k_hi * ctx.df
    lb, ub = np.array([np.log(lo), np.log(1e-3), 0.0]), np.array([np.log(hi), np.log(0.5), 200.0])
    x0 = np.clip([np.log(e.f_r), np.log(e.zeta), numerator_damping(e.zeta, e.peak_gain, beta)], lb + 1e-9, ub - 1e-9)
    kw = {"loss": "soft_l1", "f_scale": 0.5, "max_nfev": MAX_NFEV}
    one = least_squares(lambda x: res_jac(x, False)[0], x0, jac=lambda x: res_jac(x, False)[1], bounds=(lb, ub), **kw)
    two = least_squares(lambda x: res_jac(x, True)[0], np.r_[one.x[0], one.x], jac=lambda x: res_jac(x, True)[1],
                        bounds=(np.r_[lb[0], lb], np.r_[ub[0], ub]), **kw)
    n = int(f.size)
    evidence = n * np.log(max(one.cost, 1e-300) / max(two.cost, 1e-300)) - np.log(n)
    f_slow, f_fast = float(np.exp(two.x[0])), float(np.exp(two.x[1]))
    return {"f_slow_Hz": f_slow, "f_fast_Hz": f_fast, "f_common_Hz": float(np.exp(one.x[0])),
            "zeta": float(np.exp(two.x[2])), "n": n, "evidence": float(evidence),
            "moved": float(abs(np.log(f_fast / f_slow)))}


def moves_with_speed(ctx: Context, state: State, e: "FixedResonance") -> bool:
    """Whether the proposed fixed resonance ``e`` moves with the speed (:func:`speed_split`): the data want a centre of
    their own for each half of the runs (evidence > 0) and the two lie more than the resonance's relative half-power
    half-width ζ (and :data:`SPLIT_MIN_MOVE`) apart, beyond what a resonance of that width resolves.  Such a resonance
    is no fixed resonance: the open world describes it (``moving_resonance``, :mod:`rwadist.diagnose.describe_structure`)."""
    return moving_split(ctx, state, e) is not None


def moving_split(ctx: Context, state: State, e: "FixedResonance") -> dict | None:
    """:func:`speed_split` of ``e`` when it moves with the speed (:func:`moves_with_speed`), else None."""
    split = speed_split(ctx, state, e)
    moved = split is not None and split["evidence"] > 0 and split["moved"] > max(split["zeta"], SPLIT_MIN_MOVE)
    return split if moved else None


def _fit_stand_with_levels(ctx: Context, state: State, channels, chans, runs, f0, n_iter) -> "FixedResonance | None":
    """A test-stand resonance on the empirical base fitted with the levels of the lines it reaches
    (:func:`rwadist.diagnose.stand_levels.fit_with_levels`); ``n_iter`` passes, each re-measuring the lines
    with the previous pass's resonance (not its levels) in the state; None when no resonance is reached."""
    from dataclasses import replace

    from ..diagnose.stand_levels import fit_with_levels, starts_of

    lo, hi = ctx.k_lo * ctx.df, ctx.k_hi * ctx.df
    e, st = None, state
    for _ in range(n_iter):
        f, y, wt, dirs, ids, keys, pred = _line_gain_points(ctx, st, chans, runs, with_lines=True)
        if e is not None:
            prev = np.log(np.abs(resonance(f, e.f_r, e.zeta, e.peak_gain, e.gain_above)) ** 2)
            y, pred = y + prev, pred * np.exp(-prev)        # against the base without the previous pass's stand
            starts = [(e.f_r, e.zeta, numerator_damping(e.zeta, e.peak_gain, e.gain_above), e.gain_above)]
        else:
            starts = starts_of(f, y, wt, ids, lambda f_, y_: FixedResonance.peak(f_, y_, lo, hi, ctx.df), f0)
        got = fit_with_levels(f, y, wt, ids, lo, hi, starts, pred) if starts else None
        if got is None:
            return None
        f_r, zeta, gain, above, levels, _ = got
        e = FixedResonance(f_r, zeta, gain, tuple(channels), "test_stand", int(f.size), gain_above=above,
                           line_levels=tuple((d, h, float(np.exp(v / 2))) for (d, h), v in zip(keys, levels)
                                             if v != 0.0))
        st = replace(e, line_levels=()).apply(state)
    if e is None or not reached(f, e.f_r, e.zeta, e.peak_gain):
        return None
    # the directions it lifts, read on each line's gains about its fitted level
    y_level = y - levels[ids]
    return replace(e, lifted_directions=_lifted_directions(e, f, y_level, wt, dirs))


@register(order=40)
@dataclass
class FixedResonance:
    """A resonance at a fixed frequency f_r (Hz, the same at every speed) multiplying every line of its
    channels by H(f/f_r) (:func:`resonance`; ζ damping ratio, g = |H| at f_r, ``gain_above`` H far above f_r).
    ``role``: "test_stand" when it acts on every channel alike (a fixture resonance, to be excluded from the wheel's
    model; its gain above f_r is fitted: the force through a fixture spring falls there), "wheel_mode" when on one
    direction's channels only (an unmodelled wheel mode, to be added; H → 1 − μ above a mode of the load's path)."""

    f_r: float
    zeta: float
    peak_gain: float
    channels: tuple
    role: str
    #: line measurements its own fit used; None for one taken from an extended fit (of_stand, of_structure), whose
    #: lines that fit counts (trial21 read a stand's 0 as "fitted on nothing")
    n_points: int | None = None
    kind: str = "fixed_resonance"
    #: (f_r Hz, ζ, peak gain) of the stand an extended fit located at its own resolution (the wheel's
    #: ``suspension_modes`` on every run, or the given model's reference fit), for a resonance proposed from it
    #: (:meth:`candidates`): its refit; None for one fitted on diagnose's own line measurements
    extended_stand: tuple | None = None
    #: H far above f_r (1: the gain returns to 1 on both sides; 0: a transmissibility, :mod:`rwadist.resonance`)
    gain_above: float = 1.0
    #: load directions whose measured lines the resonance explains where it changes their power by 1.5x or more, 0
    #: when it makes one worse (:func:`_lifted_directions`), for a test-stand resonance fitted on diagnose's own
    #: lines; -1 when not counted (a wheel mode, a stand of the modes'
    #: extended fit, which has its own rule: :func:`rwadist.stand_resonance.lifts_every_direction`)
    lifted_directions: int = -1
    #: (direction, h, factor) of each empirical-base line whose C was fitted with the resonance
    #: (:mod:`rwadist.diagnose.stand_levels`: a test stand on the empirical base), multiplying that C when applied
    line_levels: tuple = ()

    def apply(self, state: State) -> State:
        if self.line_levels and state.ext is None:
            s = self.levelled(state)
            s.effects.append(self)
            return s
        return state.plus(self)

    def levelled(self, state: State) -> State:
        """A new ``state`` with the line levels fitted with the resonance (:attr:`line_levels`) and not the resonance
        itself."""
        from ..diagnose.stand_levels import levelled_harmonics

        s = state.copy()
        s.model.empirical = levelled_harmonics(s.model, self.line_levels)
        return s

    def contribute(self, parts) -> None:
        parts.resonances.append((self.f_r, self.zeta, self.peak_gain, tuple(self.channels), self.gain_above))

    def refit(self, ctx: Context, state: State) -> "FixedResonance":
        """Refitted on every run (``ctx.runs``); itself when that fit fails.  One proposed from the modes' stand is
        that stand as the modes' fit on every run (or the model's reference fit) has it."""
        if self.extended_stand is not None:
            from dataclasses import replace

            f_r, zeta, gain, *above = self.extended_stand
            return replace(self, f_r=f_r, zeta=zeta, peak_gain=gain, gain_above=above[0] if above else 1.0)
        return FixedResonance.fit(ctx, state, self.channels, ctx.runs, self.f_r, self.role) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    @staticmethod
    def finish(ctx: Context, state: State) -> State:
        """The search's last state with the test-stand resonances named before other effects refitted beside them
        (:func:`stands_refitted_last`)."""
        return stands_refitted_last(ctx, state)

    def significant(self) -> bool:
        """Still a resonance its family would propose (:meth:`candidates`' rules): |H| at f_r at least
        :data:`MIN_PEAK_GAIN` from 1 (a wheel mode above it: it amplifies) and ζ between the width a fit can measure
        (:data:`rwadist.stand_detect.STAND_MIN_ZETA`) and :data:`MAX_ZETA`.  The search
        asks it of the refit on every run: family wheel 6 with a fixture at 188 Hz, a wheel-mode candidate on the axial
        force at 88 Hz refitted to a peak gain of 1.003 was added."""
        from ..stand_detect import STAND_MIN_ZETA

        # a fit ending at its damping floor (1e-3) measured no width: one line's misfit at one speed lifted (family
        # wheel 6 with a fixture at 165 Hz: an axial 'wheel mode' at 89.7 Hz, ζ 0.001, beside its 85 Hz axial mode)
        # a test stand changes the lines of every direction at its frequency (a resonance of one direction's lines is
        # that direction's: family wheel 7 clean, seed 3: a 'stand' at 52.9 Hz, ζ 0.0026, gain 0.05, a notch on the
        # misfit of one direction's line at one speed, was added)
        return bool(abs(np.log(self.peak_gain)) >= np.log(MIN_PEAK_GAIN) and STAND_MIN_ZETA <= self.zeta <= MAX_ZETA
                    and (self.role != "wheel_mode" or self.peak_gain >= MIN_PEAK_GAIN)
                    and (self.role != "test_stand" or self.lifted_directions < 0 or self.lifted_directions >= 2))

    def params(self) -> dict:
        dirs = sorted({CHANNEL_DIRECTION[c] for c in self.channels})
        # a test stand on some of its directions' channels only (a fixture swaying along one axis): said so
        some = self.role == "test_stand" and set(self.channels) != {c for d in dirs for c in DIRECTION_CHANNELS[d]}
        return {"f_Hz": self.f_r, "zeta": self.zeta, "peak_gain": self.peak_gain, "gain_above": self.gain_above,
                "role": self.role, "directions": dirs, "n_points": self.n_points,
                "channels": list(self.channels) if some else None,
                "gain_law": "H = (1 - gain_above*r^2 + 2j*c*zeta*r)/(1 - r^2 + 2j*zeta*r) with r = f/f_Hz and "
                            "c = sqrt((2*zeta*peak_gain)^2 - (1 - gain_above)^2)/(2*zeta) (|H| = peak_gain at f_Hz)"}

    @staticmethod
    def of_stand(held, channels, stand) -> "FixedResonance":
        """The test-stand resonance ``held`` (f_r Hz, ζ, peak gain[, gain above]: what the held-out runs judge) of an
        extended fit, refitted as ``stand`` (the same fitted on every run)."""
        f_r, zeta, gain, *above = (float(v) for v in held)
        return FixedResonance(f_r, zeta, gain, tuple(channels), "test_stand", gain_above=above[0] if above else 1.0,
                              extended_stand=tuple(float(v) for v in stand))

    @staticmethod
    def of_structure(held, channels, structure) -> "FixedResonance":
        """The mode of the wheel's structure ``held`` (direction, f_r Hz, ζ, peak gain[, gain above]: what the held-out
        runs judge) of the suspension modes' extended fit, on ``channels``' channels of its direction, refitted as
        ``structure`` (the same fitted on every run); H → β far above it (1 when not given)."""
        direction, f_r, zeta, gain, *above = held[0], *(float(v) for v in held[1:5])
        chans = tuple(c for c in DIRECTION_CHANNELS[direction] if c in channels)
        refit = tuple(float(v) for v in structure[1:5])
        return FixedResonance(f_r, zeta, gain, chans, "wheel_mode", gain_above=above[0] if above else 1.0,
                              extended_stand=refit + (() if len(refit) == 4 else (1.0,)))

    @staticmethod
    def peak(f: np.ndarray, y: np.ndarray, lo: float, hi: float, df: float):
        """Frequency (Hz) and mean log power gain of the strongest excess of ``y`` vs ``f``: the mean of y
        within ±max(2 df, 2 %) of every grid frequency, scored by |mean|·sqrt(count) (4 points at least)."""
        grid = np.arange(lo, hi, df)
        if grid.size == 0 or f.size < 4:
            return None
        half = np.maximum(2.0 * df, 0.02 * grid)
        # the points within ±half of each grid frequency are a contiguous run of the sorted points: their count
        # and sum from a cumulative sum (a (grid, points) mask costs O(grid·points) memory and time)
        order = np.argsort(f, kind="stable")
        f_sorted = f[order]
        y_cum = np.concatenate([[0.0], np.cumsum(y[order])])
        i0 = np.searchsorted(f_sorted, grid - half, side="left")
        i1 = np.searchsorted(f_sorted, grid + half, side="right")
        cnt = i1 - i0
        mean = np.where(cnt > 0, (y_cum[i1] - y_cum[i0]) / np.maximum(cnt, 1), 0.0)
        score = np.where(cnt >= 4, np.abs(mean) * np.sqrt(cnt), 0.0)
        i = int(np.argmax(score))
        return (float(grid[i]), float(mean[i])) if score[i] > 0 else None

    @staticmethod
    def fit(ctx: Context, state: State, channels, runs, f0: float | None = None,
            role: str = "wheel_mode", n_iter: int = 3, reuse: bool = True) -> "FixedResonance | None":
        """f_r, ζ, g by robust (soft-L1) nonlinear least squares of ln|H(f)|² against the lines' log power
        gains (:func:`_line_gain_points`), parameters in logs (positive), started at the strongest excess
        (or ``f0``) with ζ ∈ {0.01, 0.03, 0.1}; ``n_iter`` passes, each re-measuring the lines with the
        previous pass's resonance in the state.

        The fit reads only what the state predicts and measures on ``chans``: it is kept on the context under
        :meth:`Context.content_key`, and a later search step whose state is the same there (its accepted effect
        touched other channels) gets it again instead of fitting anew.  ``reuse`` False: fitted without that key (a
        state no later step can meet again, such as the stand check of a suspension-modes fit: the digest of every
        channel's prediction costs more than it saves there)."""
        from dataclasses import replace

        chans = [c for c in channels if c in ctx.channels]
        if not reuse:
            return FixedResonance._fit(ctx, state, channels, chans, runs, f0, role, n_iter)
        key = ("fixed_resonance.fit", tuple(channels), role, n_iter, f0, ctx.content_key(state, chans, runs))
        if key not in ctx._memo:
            ctx._memo[key] = FixedResonance._fit(ctx, state, channels, chans, runs, f0, role, n_iter)
        e = ctx._memo[key]
        return None if e is None else replace(e)       # a copy: the caller's effect is its own

    @staticmethod
    def _fit(ctx: Context, state: State, channels, chans, runs, f0, role, n_iter) -> "FixedResonance | None":
        """:meth:`fit` computed (``chans``: the channels of ``channels`` the data have)."""
        from dataclasses import replace

        from scipy.optimize import least_squares

        if role == "test_stand" and state.ext is None:
            return _fit_stand_with_levels(ctx, state, channels, chans, runs, f0, n_iter)
        f, y, wt, dirs = _line_gain_points(ctx, state, chans, runs)
        lo, hi = ctx.k_lo * ctx.df, ctx.k_hi * ctx.df
        pk = FixedResonance.peak(f, y, lo, hi, ctx.df)
        if pk is None or f.size < 6:
            return None
        lb, ub = np.log([lo, 1e-3, 0.02]), np.log([hi, 0.5, 200.0])
        g0 = float(np.clip(np.exp(pk[1] / 2.0), 0.1, 50.0))
        starts = [np.log([pk[0] if f0 is None else f0, z0, max(g0, 1.01) if pk[1] > 0 else min(g0, 0.99)])
                  for z0 in (0.01, 0.03, 0.1)]
        e = None
        for _ in range(n_iter):
            if e is not None:
                # re-measure with the tentative resonance in the state, so that neighbouring lines are
                # subtracted amplified; the total log gain is the residual one plus the tentative ln|H|²
                st = e.apply(state)
                f, y, wt, dirs = _line_gain_points(ctx, st, chans, runs)
                y = y + np.log(np.abs(resonance(f, e.f_r, e.zeta, e.peak_gain)) ** 2)
                starts = [np.log([e.f_r, e.zeta, e.peak_gain])]
            if f.size < 6:
                return None

            sw = np.sqrt(wt)

            def res(x):
                return sw * (y - np.log(np.abs(resonance(f, np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2))

            def jac(x):
                # closed form (rwadist.resonance.log_power_gain_jacobian): 3 residual evaluations fewer per step
                return -sw[:, None] * log_power_gain_jacobian(f, *np.exp(x))
            def solve(x0, stop):
                # least_squares takes a callback from scipy 1.16 on: before, every start runs to its end
                stop = {"callback": _FlatNoResonance()} if stop and _HAS_CALLBACK else {}
                return least_squares(res, np.clip(x0, lb + 1e-9, ub - 1e-9), jac=jac, loss="soft_l1", f_scale=0.5,
                                     bounds=(lb, ub), max_nfev=MAX_NFEV, **stop)
            sols = [solve(x0, True) for x0 in starts]
            if any(s.status == -2 for s in sols) and any(s.status != -2 and _is_resonance(s) for s in sols):
                # another start found a resonance: which one fits best is decided on the stopped starts run to the end
                sols = [solve(x0, False) if s.status == -2 else s for x0, s in zip(starts, sols)]
            best = min(sols, key=lambda sol: sol.cost)      # the first of the lowest cost
            f_r, zeta, g = (float(v) for v in np.exp(best.x))
            e = FixedResonance(f_r, zeta, g, tuple(channels), role, int(f.size))
            if best.status == -2:
                return e        # no resonance here: re-measuring with a flat |H| ≈ 1 in the state changes nothing
        if e is not None and not reached(f, e.f_r, e.zeta, e.peak_gain):
            return None         # no line reaches it: a tilt of their misfit, no resonance measured
        if role == "test_stand" and e is not None:
            # a fixture's gain need not return to 1 above it: the general form, its gain above free, on the lines
            # re-measured with the resonance in place
            f, y, wt, dirs = _line_gain_points(ctx, e.apply(state), chans, runs)
            y = y + np.log(np.abs(resonance(f, e.f_r, e.zeta, e.peak_gain)) ** 2)
            if f.size >= 6:
                e = _general_refit(e, f, y, np.sqrt(wt), lo, hi)
            if not reached(f, e.f_r, e.zeta, e.peak_gain):
                return None
            e = replace(e, lifted_directions=_lifted_directions(e, f, y, wt, dirs))
        return e

    @staticmethod
    def candidates(ctx: Context, state: State, runs) -> list:
        """One resonance per direction (role wheel_mode) and one common to every channel (role test_stand)."""
        out = []
        dirs = [d for d, ch in DIRECTION_CHANNELS.items()
                if any(c in ctx.channels for c in ch) and state.model.harmonics(d)]
        for d in dirs:
            if not ctx.can_pass(state, DIRECTION_CHANNELS[d]):
                continue                # a resonance of these channels alone could not pass this step
            e = FixedResonance.fit(ctx, state, DIRECTION_CHANNELS[d], runs, role="wheel_mode")
            if e is not None:
                out.append(e)
        if len(dirs) > 1:
            e = FixedResonance.fit(ctx, state, ctx.channels, runs, role="test_stand")
            if e is not None:
                out.append(e)
            # the stand the wheel's suspension_modes fitted with the modes at the extended fit's own resolution and
            # confirmed there (:func:`rwadist.stand_resonance.fit_extended_beside_stand`): on a short
            # record diagnose's Welch segments leave no line near it measurable apart (2048 samples: h = 4 and 4.42
            # within 4 bins of each other around a 180 Hz stand), so the fit above cannot see it; proposed with
            # the stand of the modes' fit on the fit runs, judged on the held-out runs like any effect
            modes = [x for x in state.effects if getattr(x, "kind", "") == "suspension_modes"
                     and getattr(x, "stand", None) is not None]
            if modes:
                m = modes[-1]
                out += m.stand_effects(ctx.channels)         # its stand and any further ones fitted with it
            # the mode of the wheel's structure the suspension modes were fitted beside (on one direction): the same,
            # as a wheel-mode resonance (:func:`rwadist.stand_resonance.fit_extended_beside_structure_mode`)
            structured = [x for x in state.effects if getattr(x, "kind", "") == "suspension_modes"
                          and getattr(x, "structure", None) is not None]
            if structured:
                m = structured[-1]
                out.append(FixedResonance.of_structure(m.structure_fit_runs or m.structure, ctx.channels, m.structure))
            # the same from the given model: the stand its reference fit divided out (``analytical.fit.test_stand``,
            # another run on the same fixture): 2048 samples, diagnose's own fit gave 180.4 Hz, ζ 0.040, gain 3.9 for
            # the 180 Hz, ζ 0.03, gain 5 stand the reference located at 180.0 Hz, ζ 0.030, gain 5.02
            ref = (getattr(state.model, "analytical", None) or {}).get("fit") or {}
            stands = ([ref["test_stand"]] if ref.get("test_stand") else []) + list(ref.get("more_test_stands") or [])
            for k in stands if not modes else []:        # every stand of that fit (two fixtures: both)
                given = tuple(float(k[v]) for v in ("f_Hz", "zeta", "peak_gain")) + (float(k.get("gain_above", 1.0)),)
                # a stand on some channels only (``channels``: rwadist.stand_axes) proposed on those
                chans = tuple(c for c in ctx.channels if c in k["channels"]) if k.get("channels") else ctx.channels
                out.append(FixedResonance.of_stand(given, chans, given))
        # a "resonance" that changes no line by more than MIN_PEAK_GAIN is a patch on model error, not a mode; nor is a
        # wheel mode that lowers the lines at its frequency: a mode of the wheel's structure amplifies what passes it
        # (docs/diagnose.md), and a dip fitted on one direction's lines is a patch on the misfit of the few lines there
        # (family wheel 0 of seed 2, clean: gain 0.02, ζ 0.0045 at 489 Hz on one radial-force line at the top
        # speeds; the E-like wheel beside a 180 Hz stand: gain 0.89 at 96 Hz on the radial torques); nor a tilt across
        # the band that the fit can only bend by running ζ up to its bound (:meth:`significant`)
        out = [e for e in out if e.significant()]
        out = [e for e in out if e.role != "wheel_mode" or e.extended_stand is not None
               or not patches_a_stand(ctx, state, e, runs)]
        out = [e for e in out if not any(abs(e.f_r - r[0]) < 0.02 * r[0] and set(e.channels) & set(r[3])
                                         for r in state.resonances)]
        out = [e for e in out if e.role != "wheel_mode" or one_channel_of_pair(ctx, state, e, runs) is None]
        # nor a resonance whose centre moves with the speed, read on every run (:func:`moves_with_speed`): a fixed one
        # fitted to it was added as a wheel mode (family wheel 4, an axial disc mode stiffening 149 -> 167 Hz over
        # 300-3000 rpm: a 'wheel mode' at 158.5 Hz; the slower half of the runs wants 151.7 Hz, the faster 159.3 Hz)
        # (read with the line levels fitted with it: a fixture biases the base's C, and a line read against a biased C
        # lifts the half of the speeds on the fixture's other side, W7 trial wheel on a 120-Hz fixture)
        # (and one direction's resonance within the reach of one of more channels refused so: its lines cross the
        # moving one in a few runs, which its own split cannot place: :func:`~rwadist.diagnose.fixed_resonance_moving.
        # in_moving_reach`)
        splits = [moving_split(ctx, e.levelled(state) if e.line_levels else state, e) for e in out]
        moving = [(e, s) for e, s in zip(out, splits) if s is not None]
        out = [e for e, s in zip(out, splits) if s is None and not in_moving_reach(e, moving)]
        # the fixtures the modes located together, each kept so far: also as one hypothesis (:class:`StandSet`)
        located = [e for e in out if e.extended_stand is not None and e.role == "test_stand"]
        return out + ([StandSet(tuple(located))] if len(located) >= 2 else [])


#: A test stand's frequency as one direction's lines may read it (:func:`patches_a_stand`): one structure under the
#: wheel translates and rocks at frequencies a few per cent apart (ROSS's wheel D on a 105-Hz stand: 103.1 and
#: 108.6 Hz), and one resonance on every channel holds them as a compromise
STAND_DIRECTION_SPREAD = 0.1


#: A wheel-mode resonance on a radial pair lifts one channel alone when its lift of the other, fitted on that channel's
#: own lines (:func:`one_channel_of_pair`), is under this share of the first's
ONE_CHANNEL_LIFT_SHARE = 1.0 / 3.0


def one_channel_of_pair(ctx: Context, state: State, e: "FixedResonance", runs) -> str | None:
    """The channel of a radial pair that the wheel-mode resonance ``e`` (fitted on the pair's power sums) lifts alone,
    or None.  Each channel's line gains (:func:`_line_gain_points` of that channel alone) are fitted with ``e``'s
    shape scaled, y ≈ β·ln|H(f)|² (weighted least squares); the pair is lifted by one channel when β of the other is
    under :data:`ONE_CHANNEL_LIFT_SHARE` of the larger.  A mode of the wheel lifts the lines of a radial direction in
    x and in y alike (every line's ellipse passes through it whole); a resonance of one channel's sensor, amplifier or
    cabling lifts that channel's alone, and fitted on the pair's sums it read as a 'wheel mode' of half its power gain
    on both (the new-user trial's Fy sensor at 200 Hz, peak gain 5: a wheel mode of gain 3.6 on Fx and Fy, its
    prediction 3.6x on the untouched Fx)."""
    pair = next((p for p in RADIAL_PAIRS if set(p) == set(e.channels)), None)
    if pair is None or not all(c in ctx.channels for c in pair):
        return None
    beta = {}
    for c in pair:
        f, y, w, _ = _line_gain_points(ctx, state, [c], runs)
        shape = np.log(np.abs(resonance(f, e.f_r, e.zeta, e.peak_gain, e.gain_above)) ** 2)
        den = float(np.sum(w * shape * shape))
        if f.size < 6 or den <= 0:
            return None
        beta[c] = float(np.sum(w * shape * y)) / den
    lo, hi = sorted(pair, key=lambda c: beta[c])
    return hi if beta[hi] > 0 and beta[lo] < ONE_CHANNEL_LIFT_SHARE * beta[hi] else None


def stand_explains(f: np.ndarray, y: np.ndarray, sw: np.ndarray, e: "FixedResonance", stands) -> bool:
    """Whether what the wheel-mode resonance ``e`` fits in the log power gains ``y`` (ln measured / model power, the
    model holding ``stands``) at ``f`` (Hz; weights ``sw`` on the residuals) is the shape of one of the test-stand
    resonances ``stands`` on ``e``'s direction: that stand, refitted on those lines alone with its frequency within
    :data:`STAND_DIRECTION_SPREAD` of its own (its damping, gain and gain above free), fits them as well as ``e``
    does, and ``e`` added to the refitted stand explains less than half of what it explains beside the stand as it was
    (robust soft-L1 costs, as the fits').  A mode away from the stand explains as much beside either; a stand that only
    fits better elsewhere on the direction does not make it a patch."""
    from dataclasses import replace

    def cost(g, *resonances):
        return _soft_l1_cost(sw * (g - sum(np.log(np.abs(resonance(f, r.f_r, r.zeta, r.peak_gain, r.gain_above)) ** 2)
                                           for r in resonances)))

    alone = cost(y, e)
    explained = cost(y) - alone
    for s in stands:
        without = y + np.log(np.abs(resonance(f, s.f_r, s.zeta, s.peak_gain, s.gain_above)) ** 2)
        d = _general_refit(replace(s, extended_stand=None), f, without, sw, s.f_r * (1 - STAND_DIRECTION_SPREAD),
                           s.f_r * (1 + STAND_DIRECTION_SPREAD))
        refitted = cost(without, d)
        if refitted <= alone and refitted - cost(without, d, e) < 0.5 * explained:
            return True
    return False


def patches_a_stand(ctx: Context, state: State, e: "FixedResonance", runs) -> bool:
    """Whether the wheel-mode resonance ``e`` (proposed on ``state``, which does not hold it) fits its direction's line
    gains (:func:`_line_gain_points` on ``runs``) no better than a test stand of ``state`` refitted on them alone
    (:func:`stand_explains`).  On each radial pair's power sum a wheel mode sees a stand's compromise plainly: ROSS's
    wheel D on a 105-Hz stand (it translates at 103.1 Hz, rocks at 108.6 Hz), the stand fitted at 102.1 Hz on every
    channel, had a radial-torque 'wheel mode' at 84.7 Hz, ζ 0.092, gain 1.19 proposed (cost 2.32 against 2.47
    without it) where the stand refitted on the torques alone (97.6 Hz) costs 1.50, and 1.78 with the mode added."""
    stands = [x for x in state.effects if getattr(x, "kind", "") == "fixed_resonance" and x.role == "test_stand"]
    if not stands:
        return False
    f, y, wt, _ = _line_gain_points(ctx, state, [c for c in e.channels if c in ctx.channels], runs)
    return f.size >= 6 and stand_explains(f, y, np.sqrt(wt), e, stands)


def stands_refitted_last(ctx: Context, state: State) -> State:
    """``state`` with each test-stand resonance fitted on diagnose's own lines (not one of the modes' extended fit)
    that the search named before other effects refitted on every run beside them and every other effect of ``state``
    (:meth:`FixedResonance.fit` from its own frequency), where that lowers the error over every run
    (:meth:`Context.error`: one total); ``state`` itself when there is none or no refit does.

    A stand is fitted on the lines the state holds when it is named, and what the search names after it changes
    those lines:

    * a load-cell offset (a ``cross_coupling``).  Before it is named the torques are read as measured, T + r × F,
      while the wheel's modes predict the torques at the bearing centre (they were located on the torques corrected
      for the offset, and the search names the offset after them): a stand fitted then reads the forces' lines that
      r × F carries into the torques, lifted by the fixture as every line is, as a gain of its own.  Named after it,
      the offset takes r × F out of the torques, and the stand is measured again on what is left (family wheel 7, a
      fixture at 195 Hz (ζ 0.03, gain 5) at 1.5x its 130 Hz rocking mode, r_z = 20 mm: the stand named before the
      offset 195.36 Hz, ζ 0.0298, gain 5.07, 1.0099 of the load far above it, the error after 0.0141, 6.0x the clean
      cell's; refitted beside the offset 195.61 Hz, ζ 0.0297, gain 5.10, 1.0006, as the same fixture without an
      offset gives (195.59 Hz, 0.0297, 5.11, 1.0007), the error after 0.0044, 1.9x).
    * lines completed into the base after it (``missing_harmonic``): the empirical base leaves out a line amplified
      at nearly every speed, so the lines that pass closest to the fixture are not among those it is first fitted
      on, and its peak is read from its skirts (family wheel 5 hard mounted on a 300-Hz transmissibility, ζ 0.03: no
      line point within 4 % of it, ζ fitted 0.0285 at 300.33 Hz, the lines completed at 296.9 and 307.2 Hz after it
      read 3-4 % high in amplitude, the error after 910x the clean cell's).

    The stand proposed from the modes' own fit (``extended_stand``) was fitted with them beside the offset: left as
    it is.  The stand's held-out evidence is the search's judgement of it as named.
    tests/test_stands_refitted_last.py: a 150 Hz stand (ζ 0.03, gain 5) named before a 30 mm offset, 150.7 Hz,
    ζ 0.036, gain 4.3; refitted, 150.01 Hz, ζ 0.0301, gain within 3 % of 5.
    """
    stands = [e for e in state.effects[:-1] if isinstance(e, FixedResonance) and e.role == "test_stand"
              and e.extended_stand is None]
    for stand in stands:
        without = state.copy()
        without.effects = [e for e in state.effects if e is not stand]
        new = FixedResonance.fit(ctx, without, stand.channels, ctx.runs, stand.f_r, stand.role)
        if new is None or not new.significant():
            continue
        trial = new.levelled(without) if new.line_levels and without.ext is None else state.copy()
        trial.effects = [new if e is stand else e for e in state.effects]
        if ctx.error(trial) < ctx.error(state):
            state = trial
    return state
