"""The gyroscopic whirl of a resonance moving with speed (issue 33, item 3: what a moving resonance could physically
be), for :func:`rwadist.diagnose.describe_structure.moving_resonance`.

:func:`whirl_note` says whether the track is the fitted rocking mode's whirl.  When no rocking mode was located,
:func:`rocking_whirl` asks whether a rocking whirl fits the track's lines as well as the straight track did: a rigid
rotor's rocking mode of frequency f_rest at rest splits with the spin frequency s (Hz) into

    f_±(s) = sqrt((a·s/2)² + f_rest²) ± a·s/2,    a = I_zz/I_rr,

(f² ∓ a·s·f − f_rest² = 0, the gyroscopic moment I_zz·Ω·ω beside I_rr·ω²), a forward branch rising towards slope a and
a backward one falling.  Data whose modes amplify the lines as Masterson's modal model does (every line lifted where
it meets either branch, whatever its sense; the ``simple`` physics of :mod:`rwadist.teststand`) are not the rotor on
its suspension the suspension-mode fit holds: the E wheel's 16 runs over 600-2400 rpm located no mode, and its forward
whirl (54.9 Hz, I_zz/I_rr 2) was described only as "a mode of the rotor stiffening with speed".
"""
from __future__ import annotations

import numpy as np

from ..resonance import resonance_response
from ..schema import MAX_INERTIA_RATIO
from .line_offsets import line_indicator, offset_free_sse

#: I_zz/I_rr tried for a rocking whirl through a moving track (0.02 steps, up to the effective ratio a model may hold)
WHIRL_RATIOS = np.round(np.arange(0.1, MAX_INERTIA_RATIO + 1e-9, 0.02), 2)
#: Rest frequencies tried about the one whose branch meets the straight track at the middle speed (factors)
REST_FACTORS = np.exp(np.arange(-0.2, 0.2001, 0.005))
#: The fine step about the best: the ratio ±0.06 in 0.01 steps, the rest frequency ±1 % in 0.25 % steps, and the
#: straight track's ζ and peak gain by these factors (its shape's gain above kept)
FINE_RATIOS = np.arange(-0.06, 0.0601, 0.01)
FINE_REST = np.exp(np.arange(-0.01, 0.01001, 0.0025))
FINE_SHAPE = (0.6, 0.8, 1.0, 1.25, 1.6)
#: A whirl fits "as well" when it leaves at most this times the straight track's misfit (both have two parameters),
#: "better" at most WHIRL_BETTER times it.  Over a short span a branch is nearly straight, and any slope between
#: ~0.05 and 1.5 Hz per Hz of spin (−1.5 backward) is met by some whirl as well as by a straight track (a straight
#: 120 Hz + 0.5·f_spin track: a forward whirl of I_zz/I_rr 0.89 at 0.88 of its misfit; the E wheel's true whirl over
#: 600-2400 rpm: 0.99-1.01 of it): the whirl is the first cause only when it fits better, or as well on the forward
#: branch with a wheel's ratio (WHEEL_RATIOS: a disc; a co-rotating imbalance drives the forward whirl), else it is
#: listed after the others
WHIRL_AS_WELL = 1.1
WHIRL_BETTER = 0.5
WHEEL_RATIOS = (1.0, MAX_INERTIA_RATIO)


def branch_hz(spin, f_rest, a, sign: float):
    """The rocking whirl's frequency (Hz) at spin frequency ``spin`` (Hz): forward ``sign`` +1, backward −1."""
    return np.sqrt((0.5 * a * spin) ** 2 + f_rest**2) + sign * 0.5 * a * spin


def whirl_note(direction: str, slope: float, modes, s_lo: float, s_hi: float, f_lo: float, f_hi: float) -> tuple:
    """(words on what the gyroscopic whirl would do, True when the track is the fitted rocking whirl within 5 %)."""
    if direction != "radial_torque":
        return (f"no gyroscopic whirl moves a {direction.replace('_', ' ')} mode (the whirl splits the rocking mode "
                "only)"), False
    if modes is not None:
        # the fitted whirl first: its I_zz/I_rr may exceed 2 (an effective ratio, rwadist.schema.MAX_INERTIA_RATIO)
        a, f0 = modes.inertia_ratio, modes.f0_Hz["rocking"]
        for sgn, name in ((1, "forward"), (-1, "backward")):
            if abs(branch_hz(s_lo, f0, a, sgn) / f_lo - 1) < 0.05 and abs(branch_hz(s_hi, f0, a, sgn) / f_hi - 1) < 0.05:
                return f"the fitted rocking {name} whirl", True
    if abs(slope) > 2.0:
        return "faster than any rigid rotor's whirl (at most I_zz/I_rr ≤ 2 Hz per Hz of spin)", False
    if modes is None:
        return "a rocking whirl with I_zz/I_rr ≈ %.2g could move so; no suspension modes were fitted" % abs(slope), False
    return (f"the fitted rocking whirl (I_zz/I_rr = {a:.3g}) runs {branch_hz(s_lo, f0, a, 1):.4g} -> "
            f"{branch_hz(s_hi, f0, a, 1):.4g} Hz forward and {branch_hz(s_lo, f0, a, -1):.4g} -> "
            f"{branch_hz(s_hi, f0, a, -1):.4g} Hz backward"), False


def _misfits(r, fr: np.ndarray, zeta: float, gain: float, beta: float) -> np.ndarray:
    """Misfit (K,) of each track ``fr`` (K, N) Hz through the points of ``r`` (a LineRatios), each line's own offset
    taken out (as the straight track's fit does)."""
    g = 20 * np.log10(np.maximum(np.abs(resonance_response(r.f[None, :] / fr, zeta, gain, beta)), 1e-12))
    return offset_free_sse(r.q[None, :] - g, *line_indicator(r.line))


def _straight(r, f0: float, slope: float, shapes) -> float:
    """The least misfit of a straight track f0·FINE_REST + (slope ± FINE_RATIOS)·(spin − spin_mid) over ``shapes``:
    the straight track at the whirl's own resolution, so that neither wins by a finer grid."""
    mid = 0.5 * (r.spin.min() + r.spin.max())
    f0s, slopes = np.repeat(f0 * FINE_REST, FINE_RATIOS.size), np.tile(slope + FINE_RATIOS, FINE_REST.size)
    fr = np.maximum(f0s[:, None] + slopes[:, None] * (r.spin[None, :] - mid), 1e-6)
    return min(float(np.min(_misfits(r, fr, zeta, gain, beta))) for zeta, gain, beta in shapes)


def _fit(r, sign: float, ratios: np.ndarray, rests: np.ndarray, shapes) -> tuple:
    """(misfit, I_zz/I_rr, f_rest Hz, ζ, peak gain) of the best whirl over the grids (``ratios`` × ``rests`` pairs)."""
    fr = branch_hz(r.spin[None, :], rests[:, None], ratios[:, None], sign)
    best = (np.inf, np.nan, np.nan, np.nan, np.nan)
    for zeta, gain, beta in shapes:
        sse = _misfits(r, fr, zeta, gain, beta)
        i = int(np.argmin(sse))
        if sse[i] < best[0]:
            best = (float(sse[i]), float(ratios[i]), float(rests[i]), zeta, gain)
    return best


def rocking_whirl(r, modes, track: tuple, sse: float) -> tuple | None:
    """(parameters, whirl words, cause, first) of the rocking whirl that fits the points of ``r`` (a
    :class:`~rwadist.diagnose.describe_structure.LineRatios` of a radial direction) as well as the straight track
    ``track`` (f0 Hz at the middle speed, slope Hz per Hz of spin, ζ, peak gain, gain far above) of misfit ``sse``
    does (:data:`WHIRL_AS_WELL`), on the branch of the slope's sign; None when one does not, on the axial direction,
    or when the fitted ``modes`` (the ``suspension_modes`` effect) located the rocking mode (:func:`whirl_note` then
    compares the track with that mode's whirl).  ``first``: whether the whirl leads the causes (:data:`WHIRL_BETTER`,
    :data:`WHEEL_RATIOS`)."""
    f0, slope, zeta, gain, beta = track
    if r.direction not in ("radial_force", "radial_torque") or slope == 0.0 or \
            (modes is not None and "rocking" not in modes.unconstrained):
        return None
    sign = 1.0 if slope > 0 else -1.0
    mid = 0.5 * (r.spin.min() + r.spin.max())
    # the rest frequency of each ratio whose branch meets the straight track at the middle speed: f² ∓ a·s·f = f_rest²
    rest2 = f0 * f0 - sign * WHIRL_RATIOS * mid * f0
    ok = rest2 > 0
    if not ok.any():
        return None
    ratios = np.repeat(WHIRL_RATIOS[ok], REST_FACTORS.size)
    rests = np.outer(np.sqrt(rest2[ok]), REST_FACTORS).ravel()
    coarse = _fit(r, sign, ratios, rests, [(zeta, gain, beta)])
    if not np.isfinite(coarse[0]):
        return None
    a = np.clip(coarse[1] + FINE_RATIOS, WHIRL_RATIOS[0], MAX_INERTIA_RATIO)
    ratios, rests = np.repeat(a, FINE_REST.size), np.tile(coarse[2] * FINE_REST, a.size)
    shapes = [(zeta * x, max(gain * y, 1.1), beta) for x in FINE_SHAPE for y in FINE_SHAPE]
    best = min(coarse, _fit(r, sign, ratios, rests, shapes), key=lambda t: t[0])
    sse = min(sse, _straight(r, f0, slope, shapes))
    if not best[0] <= WHIRL_AS_WELL * sse:
        return None
    misfit, a, f_rest = best[:3]
    name = "forward" if sign > 0 else "backward"
    where = "" if r.direction == "radial_torque" else (" (seen on the radial forces: the rocking coupled with the "
                                                       "translation, or the loads measured away from the rotor's centre)")
    ratio = misfit / max(sse, 1e-300)
    params = {"branch": name, "f_at_rest_Hz": f_rest, "inertia_ratio": a, "misfit_ratio_to_straight_track": ratio}
    words = (f"the lines fit a rocking {name} whirl (≈ {f_rest:.4g} Hz at rest, I_zz/I_rr ≈ {a:.3g}) "
             f"{'better than' if ratio <= WHIRL_BETTER else 'as well as'} a straight track; no rocking mode was located")
    first = ratio <= WHIRL_BETTER or (sign > 0 and WHEEL_RATIOS[0] <= a <= WHEEL_RATIOS[1])
    cause = (f"the wheel's rocking mode whirling with speed, its {name} branch (≈ {f_rest:.4g} Hz at rest, I_zz/I_rr "
             f"≈ {a:.3g}){where}, amplifying lines the suspension-mode fit could not give to it (lines of either "
             "rotation sense lifted by either branch, as Masterson's modal model has it, or a rocking coupled with "
             "other motion)")
    return params, words, cause, first
