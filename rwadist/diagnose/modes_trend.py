"""A gain common to every line that changes with speed, taken out of the records before the wheel's suspension modes
are located again (``rwadist diagnose``'s ``suspension_modes``, :func:`rwadist.effects.suspension_modes_diagnose.
_fit_runs`).

The extended fit reads the rocking mode of a wheel whose forward whirl the 1x line never crosses (I_zz/I_rr > 1)
from that line's smooth trend in speed: its load is U·Ω² by its physics, so the trend of its measured amplitude is
what the whirl makes of it.  A gain of the measurement chain that changes with speed (a load cell warming as the
wheel runs faster, 1 − 0.08·Ω/Ω_max on every channel: −0.65 dB of power over the speed range) bends that trend:
family wheel 7 (16 speeds, noise 0.03) at seeds 1, 701, 703, 706 and 709 of 15 had its rocking mode (130 Hz, ζ 0.013,
I_zz/I_rr 2.1) not located on either fold (seed 701, fit runs: scanned at 122 Hz, I_zz/I_rr 2.26, its damping run to
the fit's floor), the modes rejected by the held-out runs (seed 701: gain −0.89 of the misplaced power) and amplitude
laws named in their place.  Clean, the same draws locate all three modes within 1 %; corrected so, the gain's draws
too (tests/test_modes_beside_gain_trend.py).

Every line departs from C·Ω² by the same exponent under such a gain, the lines far from the modes included: the
median over the measured lines of the slope of their log residuals against ln|Ω| (each line's own mean out, so the
C's take the mean gain) reads it from the lines the located modes fit.  When it changes the lines' power by
:data:`rwadist.diagnose.describe_trend.MIN_CHANGE_DB` or more over the speed range (the open world's own smallest
``gain_trend``), the records are divided by that power law (centred on the speeds' geometric mean) and the modes
located again; the result is kept only when it locates more modes (the search then judges them on the held-out runs,
as it judges any fit).  The gain itself is left to the open world, which describes it (``line_property``,
``gain_trend``).  tests/test_modes_trend_units.py checks both steps against a generator with a known power law
(δ −0.05 and +0.08 read within 0.003; the corrected records hold C·Ω² within 1 %).
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, cast

import numpy as np

if TYPE_CHECKING:
    from ..empirical import EmpiricalFit

#: a line's slope needs this many measurements at least
MIN_LINE_ROWS = 4
#: rounds: the trend read again on the lines of the modes located on the records it corrected (a fold whose modes
#: the trend bent reads it off: family wheel 7, seed 706, the held-out runs read -0.56 dB, then -0.10 dB more beside
#: the corrected modes, and located the rocking mode at -0.66 dB, the gain's -0.65)
TREND_ROUNDS = 3
#: a round whose trend read again adds less than this (dB of power over the speed range; a tenth of the open world's
#: smallest ``gain_trend``) corrects records the last round already located the modes on: no round follows (family
#: wheel 7 with a stand and a load-cell offset: -0.62 dB, then -0.047, then -0.0036 dB and a third location for it)
SETTLED_DB = 0.03


def common_trend(efit) -> tuple[float, float]:
    """(δ, change dB) of the extended fit ``efit``: δ the median over its measured lines (:attr:`ExtendedFit.measured`,
    :data:`MIN_LINE_ROWS` measurements or more) of each line's least-squares slope of its log residual
    (:attr:`ExtendedFit.line_residuals`, ln of measured over model amplitude) against ln|Ω|, the line's own mean out;
    change = 20·log10(e)·δ·(ln|Ω|max − ln|Ω|min), the power change (dB) across the measured speeds that δ makes.
    (0, 0) when the residuals cannot be matched to their lines or fewer than 3 lines are read."""
    from ..extended_fit import _axial_measurements, _radial_power
    from ..off_law_lines import line_regressors

    # the rows as the least squares ordered them: the axial lines' (which read only ``lines``), then the radial ones'
    la, sa = _axial_measurements(cast("EmpiricalFit", SimpleNamespace(lines=efit.measured)))[:2]
    lr, sr = _radial_power(efit.measured)[:2]
    r = np.asarray(efit.line_residuals[1], dtype=float)
    if r.size != la.size + lr.size or r.size == 0:
        return 0.0, 0.0
    row_line, log_w, centred = line_regressors(la, lr, sa, sr)
    slopes = []
    for j in np.unique(row_line):
        on = row_line == j
        c = centred[on]
        cc = float(c @ c)
        if on.sum() >= MIN_LINE_ROWS and cc > 0 and np.all(np.isfinite(r[on])):
            slopes.append(float(c @ r[on]) / cc)
    if len(slopes) < 3:
        return 0.0, 0.0
    delta = float(np.median(slopes))
    return delta, float(20.0 / np.log(10.0) * delta * np.ptp(log_w))


def beside_trend(ctx, test, fit, efit, stand_start, near, locate):
    """(test, fit, efit, stand) of the modes located (``locate``: :func:`~rwadist.effects.suspension_modes_diagnose.
    _locate`, with ``stand_start`` and ``near``) on the records of ``test`` divided by the lines' common trend
    (:func:`common_trend` of ``efit``, the modes located on ``test`` as it is, whose empirical fit is ``fit``):
    each run's records by (|Ω|/Ω_g)^δ, Ω_g the runs' geometric mean speed.  None when the trend changes the lines'
    power by less than :data:`rwadist.diagnose.describe_trend.MIN_CHANGE_DB` over the speed range, a run has no
    speed, or the corrected records locate no more modes than ``efit`` (rounds stop once the trend read again adds
    less than :data:`SETTLED_DB`); None too when ``efit`` locates no mode: the
    trend is read on the lines the located modes fit, and with none located each line's residual holds the
    resonances themselves (a hard-mounted wheel on a fixture: every mode above the band, the stand's skirt read as
    a 'gain' and the modes located again three times over for nothing, 41 of its diagnosis's 63 s)."""
    from ..empirical import fit_empirical
    from ..spectra import compute_spectra
    from .describe import scale_runs
    from .describe_trend import MIN_CHANGE_DB

    speed = np.abs(np.asarray(test.speeds, dtype=float))
    if not np.all(speed > 0) or efit.locates_no_mode:
        return None
    lw = np.log(speed)
    total, last = 0.0, efit
    for _ in range(TREND_ROUNDS):
        delta, change = common_trend(last)
        if last is efit and not abs(change) >= MIN_CHANGE_DB:
            return None
        if last is not efit and not abs(change) >= SETTLED_DB:
            return None         # read again beside the modes it gave, the trend no longer moves: they stay as located
        total += delta
        db = 20.0 / np.log(10.0) * total * (lw - lw.mean())
        test_t = scale_runs(test, {i: float(v) for i, v in enumerate(db)})
        fit_t = fit_empirical(compute_spectra(test_t, nperseg=fit.spectra.nperseg, window=ctx.sp.window,
                                              f_lim=ctx.sp.f_lim))
        efit_t, stand_t = locate(ctx, test_t, fit_t, stand_start, near)
        if len(efit_t.unconstrained) < len(efit.unconstrained):
            break
        last = efit_t
    else:
        return None
    delta, change = total, float(20.0 / np.log(10.0) * total * np.ptp(lw))
    efit_t.notes.append(f"speed trend: every line departs from C·Ω² alike, as |Ω|^{delta:+.3g} ({change:+.2f} dB of "
                        "power over the speeds: a gain of the measurement chain that changes with speed, whose trend "
                        "bends the lines' own through the modes); divided out of the records before the modes were "
                        "located (they located more modes so); not part of the wheel's model")
    return test_t, fit_t, efit_t, stand_t
