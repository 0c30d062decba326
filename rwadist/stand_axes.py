"""A fixture resonance that acts on some channels only, measured on the x/y power ratio of the rotating lines.

A wheel's suspension modes are axisymmetric: they lift a rotating line's x and y components alike, so a circular line
reads the same power on Fx and Fy (on Tx and Ty) at every speed, whatever the modes do.  A fixture that sways along
one axis lifts one channel of a pair: the ratio of the pair's powers at a line's frequency f is then the fixture's
|H(f)|² itself (or its inverse), with no wheel mode in it.  :func:`axis_stand` reads that ratio on every line, finds
the frequency where it lifts, fits the resonance there (:func:`rwadist.stand_detect.fit_on_lines`, each line its own
offset: a line with a steady counter-rotating part is an ellipse of fixed shape) and names the channels it acts on:
the lifted channel of each radial pair whose ratios it explains, and the axial force or torque when the extended fit
explains their lines better with it (:func:`fit_beside`).  The extended fit then divides it out of those channels' measurements
(``stand_on`` of :func:`rwadist.extended_fit.fit_extended`) before it locates the modes.

A fixture on Fy and Tx at 0.8x the translation mode (peak gain 15) lost the radial translation and the rocking on
family wheels 1, 5 and 6 with the stand searched on every channel; divided out on those two channels at its true
parameters, every mode was located within 0.1 %.  A fixture that lifts both channels of a pair alike is not seen
here (:mod:`rwadist.stand_detect` reads those).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .resonance import resonance
from .stand_detect import GENERAL_WINDOW, STAND_MIN_LOG_GAIN, fit_on_lines, line_log_gains
from .units import CHANNELS, RADIAL_PAIRS

#: Largest median second difference of a line's log power ratio over neighbouring speeds for the line to be read (a
#: circular line's ratio is smooth in speed, through a fixture's peak too; a planar line, or one with a counter-rotating
#: part of changing phase, is an ellipse whose orientation changes from run to run: its ratio jumps by a factor 2 or
#: more, ln 2 ≈ 0.7).  Not the first difference: 24 speeds across a transmissibility of peak gain 17 step 0.4 each)
ROUGH_MAX = 0.35
#: A channel is named when its ratios (gains) near the stand leave this share or less of the squared residual they
#: leave without it (a factor 2 better at least)
EXPLAINED_SHARE = 0.5
#: Fewest measurements near the stand a channel is judged on
MIN_NEAR = 4


@dataclass(frozen=True)
class AxisStand:
    """A fixture resonance on some channels: f_r (Hz), ζ, peak gain |H(f_r)|, gain far above it (the general gain of
    :func:`rwadist.resonance.resonance`), and the channels it acts on (in :data:`rwadist.units.CHANNELS` order)."""

    f_r: float
    zeta: float
    peak_gain: float
    gain_above: float
    channels: tuple

    @property
    def resonance(self) -> tuple:
        """(f_r Hz, ζ, peak gain, gain above): the stand tuple the extended fit holds."""
        return (self.f_r, self.zeta, self.peak_gain, self.gain_above)


def ratio_points(fit) -> dict:
    """(direction, h) -> (f Hz, y) of every radial line of the empirical fit ``fit`` (its fit without modal exclusion)
    measured on both channels of its pair in the same run: f = h|Ω|/2π, y = ln(a_y² / a_x²), the log power ratio of
    the pair's y channel over its x channel.  Lines whose ratio jumps between neighbouring speeds (median step over
    :data:`ROUGH_MAX`: an ellipse turning from run to run) are left out."""
    out = {}
    pairs = dict(zip(("radial_force", "radial_torque"), RADIAL_PAIRS))
    for x in getattr(fit, "without_mode_exclusion", fit).lines:
        if x.direction not in pairs:
            continue
        cx, cy = pairs[x.direction]
        w = np.abs(np.asarray(x.speed, dtype=float))
        a = np.asarray(x.amplitude, dtype=float)
        ch = np.asarray(x.channel)
        ok = np.isfinite(a) & (a > 0) & (w > 0)
        sx, ix = np.unique(w[ok & (ch == cx)], return_index=True)
        sy, iy = np.unique(w[ok & (ch == cy)], return_index=True)
        both, jx, jy = np.intersect1d(sx, sy, return_indices=True)
        if both.size < 3:
            continue
        y = 2.0 * np.log(a[ok & (ch == cy)][iy[jy]] / a[ok & (ch == cx)][ix[jx]])
        if both.size >= 4 and np.median(np.abs(np.diff(y, 2))) > ROUGH_MAX:
            continue
        out[(x.direction, float(x.h))] = (x.h * both / (2 * np.pi), y)
    return out


#: Most frequencies a stand is fitted at (:func:`lift_frequencies`), best first
MAX_TRIED = 3
#: Relative half width of the neighbourhood a candidate frequency is scored on, and the distance between candidates
CANDIDATE_WINDOW = 0.1


def lift_frequencies(by_line: dict) -> list:
    """Frequencies (Hz, best first, :data:`MAX_TRIED` at most, :data:`CANDIDATE_WINDOW` apart) where the pairs' power
    ratios lift: each line's largest departure from its own median, where it reaches
    :data:`rwadist.stand_detect.STAND_MIN_LOG_GAIN` (a factor 1.5 between the channels of a pair), scored by the sum
    over the lines of their largest departure within ±:data:`CANDIDATE_WINDOW` of it.  Read on the points themselves,
    not on a local mean: a speed grid of 9 Hz steps puts no point within ±5 % of a 54 Hz fixture."""
    dev = {k: (f, np.abs(y - np.median(y))) for k, (f, y) in by_line.items()}
    cands = [float(f[np.argmax(d)]) for f, d in dev.values() if d.max() >= STAND_MIN_LOG_GAIN]

    def score(fc):
        near = [d[np.abs(f / fc - 1.0) <= CANDIDATE_WINDOW] for f, d in dev.values()]
        return sum(float(v.max()) for v in near if v.size)

    out: list[float] = []
    for fc in sorted(cands, key=score, reverse=True):
        if all(abs(fc / g - 1.0) > CANDIDATE_WINDOW for g in out) and len(out) < MAX_TRIED:
            out.append(fc)
    return out


def _signed_start(ratios: dict, f_s: float):
    """(f_r Hz, ζ, peak gain, gain above) of the resonance fitted near ``f_s`` on the ratios of the directions that
    depart there (:func:`rwadist.stand_detect.fit_on_lines`), each direction's sign-turned so its lifted channel's gain
    is read (the sign of its lines' largest departure within ±:data:`CANDIDATE_WINDOW`), or None."""
    signed = {}
    for d in {d for d, _ in ratios}:
        near = []
        for k, (f, y) in ratios.items():
            m = np.abs(f / f_s - 1.0) <= CANDIDATE_WINDOW
            if k[0] == d and m.any():
                dev = y[m] - np.median(y)
                near.append(dev[np.argmax(np.abs(dev))])
        lift = float(np.sum(near)) / len(near) if near else 0.0
        if abs(lift) >= STAND_MIN_LOG_GAIN / 2:
            signed.update({k: (f, np.sign(lift) * y) for k, (f, y) in ratios.items() if k[0] == d})
    return fit_on_lines(signed, f_s) if signed else None


def _explained(points: dict, log_h2) -> float:
    """The share of the squared residual of ``points`` ((f, y) per line, within :data:`GENERAL_WINDOW` of the stand)
    that is left with ``log_h2`` (ln|H(f)|² at each f) taken off over without it, each line its own offset; inf when
    fewer than :data:`MIN_NEAR` points."""
    f = np.concatenate([v[0] for v in points.values()]) if points else np.zeros(0)
    if f.size < MIN_NEAR:
        return np.inf
    line = np.concatenate([np.full(v[0].size, k) for k, v in enumerate(points.values())])
    y = np.concatenate([v[1] for v in points.values()])
    X = np.eye(len(points))[line]

    def rss(z):
        coef, *_ = np.linalg.lstsq(X, z, rcond=None)
        return float(np.sum((z - X @ coef) ** 2))

    without = rss(y)
    return rss(y - log_h2(f)) / without if without > 0 else np.inf


def _near(points: dict, f_r: float) -> dict:
    """``points`` ((f, y) per line) within :data:`GENERAL_WINDOW` of ``f_r``, lines with none dropped."""
    out = {}
    for k, (f, y) in points.items():
        m = (f >= GENERAL_WINDOW[0] * f_r) & (f <= GENERAL_WINDOW[1] * f_r)
        if m.any():
            out[k] = (f[m], y[m])
    return out


def axis_stand(fit) -> AxisStand | None:
    """The fixture resonance that lifts one channel of a radial pair in the empirical fit ``fit``, or None.

    Found where the pairs' power ratios lift (:func:`lift_frequencies`), fitted on the ratios of the directions that
    lift there (:func:`_signed_start`; the next frequency when that is no fixture resonance), then of each radial pair
    the channel whose ratios near it (:data:`GENERAL_WINDOW`) it explains (:func:`_explained` at most
    :data:`EXPLAINED_SHARE`), the better one: one of each pair, or None (one channel alone is no fixture).  The axial
    channels, which have no partner to read a ratio on, are the extended fit's to tell (:func:`axial_options`)."""
    ratios = ratio_points(fit)
    start = next((s for s in (_signed_start(ratios, f_s) for f_s in lift_frequencies(ratios)) if s is not None), None)
    if start is None:
        return None

    def log_h2(f):
        return np.log(np.maximum(np.abs(resonance(f, *start)) ** 2, 1e-300))

    channels = []
    for d, (cx, cy) in zip(("radial_force", "radial_torque"), RADIAL_PAIRS):
        near = _near({k: v for k, v in ratios.items() if k[0] == d}, start[0])
        share_y = _explained(near, log_h2)
        share_x = _explained(near, lambda f: -log_h2(f))
        if min(share_x, share_y) <= EXPLAINED_SHARE:
            channels.append(cy if share_y < share_x else cx)
    if len(channels) < 2:
        # one channel alone is that channel's own resonance (its sensor, amplifier or cabling: the open world's
        # ``channel_resonance``); a fixture swaying along an axis moves a force and a moment
        return None
    f_r, zeta, gain, above = (float(v) for v in start)
    return AxisStand(f_r, zeta, gain, above, channels=tuple(c for c in CHANNELS if c in channels))


def axial_options(fit, axis: AxisStand) -> list:
    """The channel sets the stand ``axis`` may act on, its radial channels first: with the axial force and/or torque
    as well where the fit ``fit`` has lines of them within :data:`GENERAL_WINDOW` of the stand (their lines have no
    partner channel to read a ratio on: the extended fit, which holds the wheel's axial mode, tells, :func:`fit_beside`)."""
    gains = line_log_gains(getattr(fit, "without_mode_exclusion", fit))
    axial = [c for d, c in (("axial_force", "Fz"), ("axial_torque", "Tz"))
             if _near({k: v for k, v in gains.items() if k[0] == d}, axis.f_r)]
    sets = [()] + [(c,) for c in axial] + ([tuple(axial)] if len(axial) == 2 else [])
    return [tuple(c for c in CHANNELS if c in axis.channels + extra) for extra in sets]


def fit_beside(test, fit, axis: AxisStand, **options):
    """The extended fit of ``test`` (empirical fit ``fit``) with the stand ``axis`` divided out of its channels, held
    (:func:`rwadist.extended_fit.fit_extended`'s ``stand_on``), or None when it does not explain the lines better than
    the modes alone beyond its parameters' worth (the Bayesian information criterion of
    :func:`rwadist.stand_resonance.stand_confirmed`, on the log residuals).  Of the channel sets of
    :func:`axial_options`, the one of least cost, each axial channel added counted as one parameter more.
    ``options``: :func:`rwadist.extended_fit.fit_extended`'s (``near``, ``mass``, ``radius``, ``height``, ...)."""
    from .extended_fit import fit_extended
    from .extended_fit_lsq import joint_cost
    from .stand_resonance import STAND_PARAMETERS

    plain = fit_extended(test, fit, **options)
    best, best_score = None, np.inf
    for chans in axial_options(fit, axis):
        efit = fit_extended(test, fit, stand=axis.resonance, stand_on=chans, **options)
        n = int(np.sum(np.isfinite(efit.line_residuals[1])))
        cost = joint_cost(efit)
        if n <= STAND_PARAMETERS or cost <= 0:
            continue
        score = n * np.log(cost) + (STAND_PARAMETERS + len(chans) - len(axis.channels)) * np.log(n)
        if score < best_score:
            best, best_score = efit, score
    n = int(np.sum(np.isfinite(plain.line_residuals[1])))
    if best is None or not n * np.log(max(joint_cost(plain), 1e-300)) > best_score:
        return None
    best.notes.append(f"test stand: a resonance at {axis.f_r:.4g} Hz (ζ {axis.zeta:.3g}, peak gain {axis.peak_gain:.3g}, "
                      f"{axis.gain_above:.3g} of the load far above it) lifts {', '.join(best.stand_on or ())} alone: a "
                      "fixture that sways along one axis, measured on the x/y power ratio of the rotating lines (the "
                      "wheel's modes lift x and y alike) and divided out of those channels; not part of the wheel's "
                      "model (analytical.fit.test_stand)")
    return best
