"""The wheel's suspension modes located beside a resonance on every channel whose frequency moves with the speed
(``rwadist diagnose``'s ``suspension_modes``, :func:`rwadist.effects.suspension_modes_diagnose._locate`).

A resonance of the structure under the load cell (or of the rotor) that moves with the speed lifts the lines of every
direction where they cross its track.  The extended model has no such resonance: fitted on those lines, its modes are
pulled, their misfit near them passes :data:`rwadist.extended_fit.MISFIT_DB`, and every mode is declared
unconstrained (the session-69 new-user trial: a 3-kg wheel, modes 420/70/520 Hz, I_zz/I_rr 2, with a resonance at
150 + 0.9·f_spin Hz on every channel, μ 0.3, ζ 0.03: translation 422.9, rocking 71.4, axial 524.1 Hz, each declared;
no mode located, so no suspension_modes was proposed, the search kept the empirical base and its mode exclusion left
the dynamic imbalance out of the model).  A fixed resonance fitted over the track (a stand, a structure mode) is its
envelope only, and these data confirm none.

The track is read where the open world reads it (:func:`rwadist.diagnose.describe_structure._moving_fit`) on the
declared fit's own line residuals, every direction pooled (each line's offset out: its C), and held at it, divided
out of every line at f0 + slope·f_spin (``moving`` of :func:`rwadist.extended_fit.fit_extended`); then the track is
read again on what those modes leave (:data:`ROUNDS`).  Kept only when the modes so located are more than the declared
fit located; the resonance stays out of the wheel's model (it moves: the open world describes it,
``moving_resonance``), and the search judges the modes on the held-out runs as any fit.
"""
from __future__ import annotations

import numpy as np

#: rounds of the track read again on the lines of the modes located beside it
ROUNDS = 2


def _ratios(efit, track: tuple | None):
    """The dB ratios of the extended fit ``efit``'s measurements to its model, every direction pooled
    (:class:`rwadist.diagnose.describe_structure.LineRatios`), with the held resonance ``track`` (as
    :func:`moving_track` returns it) put back; None when too few."""
    from .describe_structure import LineRatios

    f, r, d = (np.asarray(v) for v in efit.line_residuals)
    h = np.asarray(efit.line_h, dtype=float)
    if h.size != f.size:
        return None
    ok = np.isfinite(r) & (h > 0) & (f > 0)
    f, q, d, h = f[ok], 20.0 / np.log(10.0) * r[ok], d[ok], h[ok]
    if f.size < 8:
        return None
    spin = f / h
    if track is not None:
        q = q + _track_db(f, spin, track)
    keys = np.char.add(d.astype(str), np.char.mod("%.4f", h))
    _, line = np.unique(keys, return_inverse=True)
    return LineRatios("every", q, f, np.zeros(f.size, int), spin, line, h, np.ones(f.size))


def _track_db(f: np.ndarray, spin: np.ndarray, track: tuple) -> np.ndarray:
    """20·log10 |H| at ``f`` Hz of the resonance ``track`` (f0 Hz, slope, ζ, peak gain, gain above) at spin ``spin`` Hz."""
    from ..resonance import resonance_response

    f0, slope, *shape = track
    return 20.0 * np.log10(np.maximum(np.abs(resonance_response(f / np.maximum(f0 + slope * spin, 1e-6), *shape)),
                                      1e-12))


def moving_track(efit, track: tuple | None = None) -> tuple | None:
    """(f0 Hz at rest, slope Hz per Hz of spin, ζ, peak gain, gain above) of the resonance moving with speed that the
    line residuals of ``efit`` hold (with ``track`` put back when it was divided out), or None when they hold none
    the open world would name (:func:`rwadist.diagnose.describe_structure._moving_fit`, alone or beside a fixed one)."""
    from .describe_structure import _moving_fit, gain_above

    r = _ratios(efit, track)
    if r is None or not np.any(r.q >= 2.0):
        return None
    got = _moving_fit(r)
    if got is None:
        return None
    # a fixed companion read beside it is kept out: a mode the declared fit left at its starting value (the fit runs
    # of that trial: every mode unlocated, the translation's and axial's lift read as a fixed resonance at 450 Hz) is
    # the modes' to take once the moving one is divided out
    _, f0, slope, zeta, gain, above = got[0]
    mid = 0.5 * (r.spin.min() + r.spin.max())
    return (float(f0 - slope * mid), float(slope), float(zeta), float(gain), gain_above(zeta, gain, above))


def beside_moving(test, fit, plain, near: dict | None = None):
    """The extended fit of ``test`` (empirical fit ``fit``) with the resonance moving with speed that ``plain`` (the
    fit without it) leaves divided out of every line (:func:`moving_track`), or None when there is none or the modes
    located beside it are no more than ``plain``'s."""
    from ..extended_fit import fit_extended

    track, best = None, None
    for _ in range(ROUNDS):
        got = moving_track(plain if best is None else best, track)
        if got is None:
            break
        try:
            efit = fit_extended(test, fit, near=near, moving=got)
        except ValueError:
            break
        if best is not None and len(efit.unconstrained) > len(best.unconstrained):
            break
        track, best = got, efit
    if best is None or track is None or not set(best.unconstrained) < set(plain.unconstrained):
        return None
    f0, slope, zeta, gain, above = track
    best.notes.append(f"modes located beside a resonance on every channel moving with speed ({f0:.4g} Hz at rest, "
                      f"{slope:+.2f} Hz per Hz of spin, ζ {zeta:.3g}, peak gain {gain:.3g}, {above:.3g} of the load far "
                      "above it), divided out of every line: not the wheel's model (`rwadist diagnose` describes it, "
                      "moving_resonance)")
    return best
