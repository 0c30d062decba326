"""The lines' common speed trend read from an extended fit's residuals and divided out of the records before the
modes are located again (:func:`rwadist.diagnose.modes_trend.common_trend`, :func:`~rwadist.diagnose.modes_trend.
beside_trend`), checked against a generator with a known power law.

Data: lines of a hard-mounted wheel (axial h 1, 2; radial h 1, 3, co-rotating) whose every amplitude is C·Ω²·(Ω/Ω_g)^δ
(a gain of the measurement chain that changes with speed, written as the power law modes_trend divides out; δ −0.05:
−0.95 dB of power over 1000-8000 rpm), each line its own random phase in every run, white sensor noise.  The truth is
the generator's δ and its C·Ω²; the "modes" are the lines' own C·Ω² (a model the law bends), so the residual of a
line is ln(measured/C·Ω²) = δ·ln(Ω/Ω_g) + noise."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.modes_trend import SETTLED_DB, beside_trend, common_trend
from rwadist.empirical import LineFit
from rwadist.extended_fit import _axial_measurements, _radial_power

FS, N = 2048.0, 4096                      # 2 s records: every line an integer number of cycles below
RPM = np.linspace(1000.0, 8000.0, 8)
OMEGA = RPM * np.pi / 30.0
#: (direction, h, C) kg·m
LINES = [("axial_force", 1.0, 2e-6), ("axial_force", 2.0, 1e-6), ("radial_force", 1.0, 4e-6),
         ("radial_force", 3.0, 1.5e-6)]
DELTA = -0.05
CHANNELS = {"axial_force": ("Fz",), "radial_force": ("Fx", "Fy")}


def _omega_on_bins():
    """The speeds moved so that every line sits on a record bin (a whole number of cycles: no leakage to model)."""
    df = FS / N
    return np.round(OMEGA / (2 * np.pi) / df) * df * 2 * np.pi


def _test(delta: float, seed: int = 0, noise: float = 1e-4) -> SteadyTest:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    om_all = _omega_on_bins()
    og = float(np.exp(np.mean(np.log(om_all))))
    runs = []
    for i, om in enumerate(om_all):
        sig = {c: noise * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        for d, h, C in LINES:
            z = C * om**2 * (om / og) ** delta * np.exp(1j * (h * om * t + rng.uniform(0, 2 * np.pi)))
            if d == "axial_force":
                sig["Fz"] += z.real
            else:
                sig["Fx"] += z.real
                sig["Fy"] += z.imag
        runs.append(Run(speed=float(om), sample_rate=FS, signals=sig, name=f"run_{i:02d}.csv"))
    return SteadyTest(runs, {})


def _amplitude(x: np.ndarray, f: float) -> float:
    """A line's amplitude on a record bin (rectangular window: the record holds whole cycles)."""
    k = int(round(f * N / FS))
    return float(2.0 * abs(np.fft.rfft(x)[k]) / N)


def _efit(test: SteadyTest, unconstrained: list):
    """An extended fit's parts common_trend reads: the lines measured on ``test`` (LineFit per line, every run) and the
    least squares' residuals ln(measured / C·Ω²) in its row order (the axial rows, then the radial powers)."""
    measured = []
    for d, h, C in LINES:
        chans = CHANNELS[d]
        speed = np.repeat([r.speed for r in test.runs], len(chans))
        chan = np.array([c for _ in test.runs for c in chans])
        amp = np.array([_amplitude(r.signals[c], h * r.speed / (2 * np.pi)) for r in test.runs for c in chans])
        measured.append(LineFit(direction=d, h=h, C=C, C_stderr=0.0, C_all=C, speed=speed, channel=chan, amplitude=amp,
                                used=np.ones(speed.size, bool), excluded_rpm=[], presence=1.0, n_possible=speed.size))
    la, sa, _, aa, _ = _axial_measurements(SimpleNamespace(lines=measured))
    lr, sr, pr, _, _ = _radial_power(measured)
    model_a = np.array([measured[j].C for j in la]) * sa**2
    model_r = np.array([measured[j].C for j in lr]) * sr**2 * np.sqrt(2.0)        # x and y each C·Ω²
    r = np.concatenate([np.log(aa / model_a), np.log(np.sqrt(pr) / model_r)])
    return SimpleNamespace(measured=measured, line_residuals=(np.zeros(r.size), r, np.zeros(r.size, str)),
                           unconstrained=list(unconstrained), notes=[],
                           locates_no_mode={"radial_translation", "rocking", "axial"} <= set(unconstrained))


@pytest.mark.parametrize("delta", [-0.05, 0.08])
def test_common_trend_reads_the_generators_exponent(delta):
    got, change = common_trend(_efit(_test(delta), ["rocking"]))
    assert got == pytest.approx(delta, abs=0.003)
    # the change of power over the speeds: the law's own, 20·δ·log10(Ω_max/Ω_min)
    om = _omega_on_bins()
    assert change == pytest.approx(20 * delta * np.log10(om.max() / om.min()), abs=0.06)


def test_common_trend_is_the_median_line():
    """One line of a law of its own (its residual Ω^+1 more: an amplitude law on one harmonic) does not move it: the
    median over the lines; with the lines' own laws alone (δ 0) it reads 0."""
    efit = _efit(_test(DELTA), ["rocking"])
    r = efit.line_residuals[1].copy()
    la = _axial_measurements(SimpleNamespace(lines=efit.measured))[0]
    on = np.flatnonzero(la == 0)                                   # the axial 1x's rows
    r[on] += np.log(np.asarray(efit.measured[0].speed))[: on.size]
    efit.line_residuals = (efit.line_residuals[0], r, efit.line_residuals[2])
    assert common_trend(efit)[0] == pytest.approx(DELTA, abs=0.003)
    assert common_trend(_efit(_test(0.0), ["rocking"]))[0] == pytest.approx(0.0, abs=0.003)


def _locate(calls: list):
    """A stand-in for the modes' location: measures the lines on the records it is given and locates 'the modes' when
    what is left of the trend there changes the lines' power by less than 0.1 dB over the speeds."""
    def locate(ctx, test, fit, stand_start, near):
        calls.append(test)
        efit = _efit(test, [])
        left = common_trend(efit)[1]
        efit.unconstrained = [] if abs(left) < 0.1 else ["rocking"]
        return efit, None
    return locate


def _ctx():
    return SimpleNamespace(sp=SimpleNamespace(window="hann", f_lim=None))


def test_beside_trend_divides_the_law_out_of_the_records():
    test = _test(DELTA)
    calls: list = []
    got = beside_trend(_ctx(), test, SimpleNamespace(spectra=SimpleNamespace(nperseg=1024)),
                       _efit(test, ["rocking"]), None, None, _locate(calls))
    assert got is not None
    test_t, _, efit_t, _ = got
    assert test_t is calls[-1] and not efit_t.unconstrained and "speed trend" in efit_t.notes[0]
    # the corrected records hold the generator's C·Ω² in every run (the law's (Ω/Ω_g)^δ divided out), within 1 %
    for d, h, C in LINES:
        for run in test_t.runs:
            a = _amplitude(run.signals[CHANNELS[d][0]], h * run.speed / (2 * np.pi))
            assert a == pytest.approx(C * run.speed**2, rel=0.01), (d, h, run.speed)
    # ... and the input is unchanged
    om = test.runs[0].speed
    og = np.exp(np.mean(np.log([r.speed for r in test.runs])))
    assert _amplitude(test.runs[0].signals["Fz"], om / (2 * np.pi)) == pytest.approx(2e-6 * om**2 * (om / og) ** DELTA,
                                                                                      rel=0.01)


def test_beside_trend_none_below_the_change_tested_or_when_no_more_modes_are_located():
    calls: list = []
    small = _test(0.01)                                             # 0.19 dB of power over the speeds: < 0.3 dB
    assert beside_trend(_ctx(), small, SimpleNamespace(spectra=SimpleNamespace(nperseg=1024)),
                        _efit(small, ["rocking"]), None, None, _locate(calls)) is None
    assert not calls
    test = _test(DELTA)
    efit = _efit(test, ["rocking"])

    asked: list = []

    def never(ctx, test, fit, stand_start, near):
        asked.append(test)
        return _efit(test, ["rocking"]), None
    assert beside_trend(_ctx(), test, SimpleNamespace(spectra=SimpleNamespace(nperseg=1024)), efit, None, None,
                        never) is None
    # the records corrected once hold the generator's C·Ω²: the trend read again on them adds less than SETTLED_DB,
    # and no second location is asked of records that would not change
    assert len(asked) == 1 and abs(common_trend(_efit(asked[0], ["rocking"]))[1]) < SETTLED_DB
    # no mode located: the lines' residuals hold the resonances themselves, no gain of the chain is read from them
    # (the stand-in would locate the modes on the corrected records: it is never asked)
    none = _efit(test, ["radial_translation", "rocking", "axial"])
    assert beside_trend(_ctx(), test, SimpleNamespace(spectra=SimpleNamespace(nperseg=1024)), none, None, None,
                        _locate(calls)) is None
    assert not calls
