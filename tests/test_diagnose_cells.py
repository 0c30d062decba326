"""``rwadist diagnose`` on cells off the robustness matrix's one-factor-at-a-time grid (issue 14, item 5):
a wide speed range or a short record combined with a test-stand resonance.

The data share nothing with the fit: the wheel is tests/independent_wheel.py (thesis Tables 3.4/4.2, typed, real
coordinates) and the stand is a real IIR filter run over the time series (scipy.signal.bilinear of
H(s) = (s² + 2gζω s + ω²)/(s² + 2ζω s + ω²), prewarped at f_r, its transient discarded), not the per-line gain
rwadist's virtual stand multiplies in.  The full cells print in benchmarks/diagnose_matrix.py.

Several tests diagnose the same record or start from the same reference fit: those are built once per test process
(:func:`shared_stand_test`, :func:`shared_reference`), their sample arrays read-only so that no test can change what
the next one reads.
"""
import functools
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402
from conftest import read_only  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.data import Run, SteadyTest  # noqa: E402
from rwadist.presets import preset  # noqa: E402

#: the fixture resonance filtered into the data: frequency (Hz), damping ratio, |H| at f_r
STAND_HZ, STAND_ZETA, STAND_GAIN = 180.0, 0.03, 5.0


def stand_filter(f_hz, zeta, gain, sample_rate):
    """(b, a) of the digital fixture resonance H(s) = (s² + 2gζω s + ω²)/(s² + 2ζω s + ω²), bilinear, prewarped so
    that its peak sits at ``f_hz``."""
    wd = 2 * sample_rate * np.tan(np.pi * f_hz / sample_rate)
    return signal.bilinear([1, 2 * gain * zeta * wd, wd * wd], [1, 2 * zeta * wd, wd * wd], fs=sample_rate)


def iir_stand_test(speeds_rpm, seed, n_samples=8192, sample_rate=3840.0, noise=0.01, stand=True, extra_lines=()):
    """Steady runs of the independent wheel (its lines and ``extra_lines``, as :data:`independent_wheel.E_LINES`),
    every channel filtered through the stand (when ``stand``), white noise of ``noise`` × the top-speed fundamental
    of each group added after it."""
    raw, _ = iw.generate(speeds_rpm, sample_rate=sample_rate, n_samples=2 * n_samples, noise=0.0, seed=seed,
                         lines=list(iw.E_LINES) + list(extra_lines))
    bz, az = stand_filter(STAND_HZ, STAND_ZETA, STAND_GAIN, sample_rate)
    rng = np.random.default_rng(seed + 77)
    w_top = max(abs(r.speed) for r in raw.runs)
    fund = {g: next(c for d, h, c, _ in iw.E_LINES if d == d0 and h == 1.0) * iw.C_UNIT * w_top**2
            for g, d0 in (("F", "radial_force"), ("T", "radial_torque"))}
    runs = []
    for r in raw.runs:
        sig = {ch: (signal.lfilter(bz, az, x) if stand else x)[n_samples:]
               + noise * fund[ch[0]] * rng.standard_normal(n_samples) for ch, x in r.signals.items()}
        runs.append(Run(speed=r.speed, sample_rate=sample_rate, signals=sig, t0=0.0, name=r.name))
    return SteadyTest(runs=runs, meta={"generator": "tests/independent_wheel.py + IIR stand"})


def _reference(test):
    wheel = preset("ithaco-e")
    return api.fit_extended(test, mass=wheel.mass_kg, radius=wheel.radius_m)[1]


@functools.lru_cache(maxsize=None)
def shared_stand_test(speeds_rpm: tuple, seed: int, n_samples: int = 8192, stand: bool = True):
    """:func:`iir_stand_test` of ``speeds_rpm`` (a tuple), built once per test process; its samples are read-only."""
    return read_only(iir_stand_test(np.asarray(speeds_rpm), seed, n_samples=n_samples, stand=stand))


@functools.lru_cache(maxsize=None)
def shared_reference(speeds_rpm: tuple, n_samples: int = 8192, stand: bool = True):
    """The reference model fitted on the seed-500 record of ``speeds_rpm`` (:func:`_reference`), once per process."""
    return _reference(shared_stand_test(speeds_rpm, 500, n_samples, stand))


#: the short-record and wide speed grids (rpm) several tests share
SHORT_GRID = tuple(np.linspace(300.0, 3000.0, 60).tolist())
WIDE_GRID = tuple(np.linspace(100.0, 6000.0, 60).tolist())


def _added(d):
    return [e["kind"] for e in d.model.effects]


def test_short_record_stand_never_raises_the_error():
    """2048 samples through the stand, a fitted reference model: the search's refit of the stand on every run ran off
    (ζ to its bound 1e-3, peak gain 137: between the lines only ζ·g is measured) and was added unjudged, raising the
    error 0.19 -> 6.4.  An accepted effect never raises the error on every run, and the stand is the one filtered in
    (diagnose's own fit of it on this record, 180.4 Hz, ζ 0.040, gain 3.9, left a false amplitude law on h = 4.42 beside
    it: the reference fit's stand, located at the fit's resolution, is proposed too)."""
    ref = shared_reference(SHORT_GRID, n_samples=2048)
    d = api.diagnose(shared_stand_test(SHORT_GRID, 3, n_samples=2048), ref)
    assert d.error_after < d.error_before
    state = d.state_before
    for e in d.state_after.effects:                 # every accepted step lowers (or keeps) the error
        nxt = e.apply(state)
        assert d.ctx.error(nxt) <= d.ctx.error(state) * (1 + 1e-9), e.kind
        state = nxt
    assert _added(d) == ["fixed_resonance"]         # the stand and nothing else
    (stand,) = d.model.effects
    assert stand["role"] == "test_stand"
    assert stand["f_Hz"] == pytest.approx(STAND_HZ, rel=0.01)
    assert stand["zeta"] == pytest.approx(STAND_ZETA, rel=0.1)
    assert stand["peak_gain"] == pytest.approx(STAND_GAIN, rel=0.1)


def _assert_modes_within(d, rel):
    (modes,) = [e for e in d.state_after.effects if e.kind == "suspension_modes"]
    for name, truth in iw.TRUTH_HZ.items():
        assert modes.f0_Hz[name] == pytest.approx(truth, rel=rel), name


def test_wide_speed_range_stand_names_the_modes_first():
    """100-6000 rpm through the 180 Hz stand, no model: the stand start the fit runs propose (187 Hz, gain 36) located
    no mode, nor did the fit without it, so suspension_modes was never proposed and the wheel's modes were patched as
    a missing radial-torque fundamental, an amplitude law and a 192 Hz wheel_mode (error 0.88 -> 0.44).  Now: the
    modes (each within 2 % of the generator's) and the stand (role test_stand, f_r within 1 %), nothing else."""
    d = api.diagnose(shared_stand_test(WIDE_GRID, 3))
    assert sorted(_added(d)) == ["fixed_resonance", "suspension_modes"]
    _assert_modes_within(d, 0.02)
    (stand,) = [e for e in d.model.effects if e["kind"] == "fixed_resonance"]
    assert stand["role"] == "test_stand"
    assert stand["f_Hz"] == pytest.approx(STAND_HZ, rel=0.01)
    assert stand["peak_gain"] == pytest.approx(STAND_GAIN, rel=0.1)
    assert d.error_after < 0.02 * d.error_before


def test_wide_speed_range_clean_adds_no_offset():
    """100-6000 rpm, no stand, a fitted reference model, clean data: a load-cell offset of (0.05, 0.00, 0.8) mm, 1.9
    standard errors from none, passed the judge on the drop it gave in the torque fundamental's bands at the top
    speeds (the imbalance torque keeps one phase to the force, so T − r × F moves it coherently).  Nothing is added;
    an offset injected into the same data (T += r × F, r = (0, 0, −58) mm, as a load-cell reference below the wheel)
    is still found within 5 %."""
    speeds = np.linspace(100.0, 6000.0, 60)
    ref = _reference(iir_stand_test(speeds, seed=500, stand=False))
    test = iir_stand_test(speeds, seed=3, stand=False)
    d = api.diagnose(test, ref)
    assert _added(d) == []
    r = np.array([0.0, 0.0, -0.058])
    offset = []
    for run in test.runs:
        F = np.column_stack([run.signals[k] for k in ("Fx", "Fy", "Fz")])
        T = np.cross(r[None, :], F)
        offset.append(Run(speed=run.speed, sample_rate=run.sample_rate, t0=0.0, name=run.name,
                          signals={**run.signals, **{k: run.signals[k] + T[:, j] for j, k in enumerate(("Tx", "Ty", "Tz"))}}))
    d = api.diagnose(SteadyTest(runs=offset, meta=dict(test.meta)), ref)
    (cc,) = [e for e in d.model.effects if e["kind"] == "cross_coupling"]
    assert cc["r_m"][2] == pytest.approx(r[2], rel=0.05)
    assert np.allclose(cc["r_m"][:2], 0.0, atol=1e-3)


def test_short_record_stand_no_model_fits_stand_beside_modes():
    """2048 samples through the 180 Hz stand, no model: the stand divided out before the modes were located was not
    confirmed on diagnose's own line measurements (its Welch segments leave no line near 180 Hz measurable apart), so
    the modes were refitted without it (radial translation pulled to the stand: -18.6 %, misfit noted) and the stand
    was never named (error 0.98 -> 0.17).  Now the stand is confirmed on the modes' residual at the fit's resolution,
    the modes are each within 2 % of the generator's, and the stand is named (role test_stand, within 1 %)."""
    d = api.diagnose(shared_stand_test(SHORT_GRID, 3, n_samples=2048))
    _assert_modes_within(d, 0.02)
    # and nothing else: the merged h = 5.37/5.57 pair (one h = 5.49 line at this resolution, listed unresolved) is
    # no amplitude law
    assert sorted(_added(d)) == ["fixed_resonance", "suspension_modes"]
    stands = [e for e in d.model.effects if e["kind"] == "fixed_resonance"]
    assert [e["role"] for e in stands] == ["test_stand"]
    assert stands[0]["f_Hz"] == pytest.approx(STAND_HZ, rel=0.01)
    assert stands[0]["peak_gain"] == pytest.approx(STAND_GAIN, rel=0.1)
    assert d.error_after < 0.02 * d.error_before


def test_a_refit_that_raises_the_error_is_not_added(monkeypatch):
    """The search adds a passing hypothesis refitted on every run; that refit is judged by nothing.  Made to run off as
    the stand's did on this record (ζ at its bound 1e-3, peak gain 137 at 178.4 Hz: the error ×34), it is not added,
    and no accepted effect raises the error."""
    from dataclasses import replace

    from rwadist.effects.fixed_resonance_diagnose import FixedResonance

    ref = shared_reference(SHORT_GRID, n_samples=2048)
    monkeypatch.setattr(FixedResonance, "refit", lambda self, ctx, state: replace(self, f_r=178.44, zeta=1e-3,
                                                                                 peak_gain=137.0))
    d = api.diagnose(shared_stand_test(SHORT_GRID, 3, n_samples=2048), ref)
    assert not [r for r in d.state_after.resonances if r[1] < 0.0015]      # the run-off refit is in no state
    assert d.error_after <= d.error_before


def _through_stand(test, f_hz, zeta, gain):
    """``test`` with every channel filtered through one more fixture resonance (as :func:`iir_stand_test`'s)."""
    runs = []
    for r in test.runs:
        bz, az = stand_filter(f_hz, zeta, gain, r.sample_rate)
        runs.append(Run(speed=r.speed, sample_rate=r.sample_rate, t0=0.0, name=r.name,
                        signals={ch: signal.lfilter(bz, az, x) for ch, x in r.signals.items()}))
    return SteadyTest(runs=runs, meta=dict(test.meta))


@pytest.mark.slow
def test_two_fixture_resonances_no_mode_wrong_without_a_word():
    """100-6000 rpm through two fixture resonances (150 and 180 Hz, ζ 0.03, gain 5, every channel), no model: the
    modes' fit divides out one resonance between them (167 Hz) and the search then names both fixtures; the radial
    translation came out 2.7 % low with nothing said.  Every mode is now within 2 % of the generator's or declared
    (the effect's and the model's ``unconstrained``, with a note giving its value with every fixture divided out)."""
    test = _through_stand(shared_stand_test(WIDE_GRID, 3), 150.0, 0.03, 5.0)
    d = api.diagnose(test)
    (modes,) = [e for e in d.model.effects if e["kind"] == "suspension_modes"]
    stands = [e["f_Hz"] for e in d.model.effects if e["kind"] == "fixed_resonance" and e["role"] == "test_stand"]
    assert any(abs(f / 150.0 - 1) < 0.01 for f in stands)
    notes = " ".join(d.model.analytical["fit"]["notes"])
    for name, truth in iw.TRUTH_HZ.items():
        if abs(modes[f"{name}_Hz"] / truth - 1) > 0.02:
            assert name in modes["unconstrained"] and name in d.model.analytical["unconstrained"], name
            assert f"{name}: NOT CONSTRAINED beside the fixture resonances" in notes


def test_more_stands_divide_the_lines_as_the_stand():
    """:func:`rwadist.extended_fit.fit_extended`: a fixture resonance given in ``more_stands`` is divided out of the
    lines as the one given as ``stand`` (the same modes), and two given either way round give the same fit."""
    from rwadist.empirical import fit_empirical
    from rwadist.extended_fit import fit_extended
    from rwadist.spectra import compute_spectra

    test = iir_stand_test(np.linspace(300.0, 3000.0, 12), seed=5, n_samples=2048)
    fit = fit_empirical(compute_spectra(test))
    a = (STAND_HZ, STAND_ZETA, STAND_GAIN)
    b = (150.0, 0.03, 2.0)
    as_stand = fit_extended(test, fit, stand=a).params
    as_more = fit_extended(test, fit, more_stands=(a,)).params
    assert as_more == as_stand
    ab = fit_extended(test, fit, stand=a, more_stands=(b,)).params
    ba = fit_extended(test, fit, stand=b, more_stands=(a,)).params
    for key in ("k_r", "k_rock", "k_z", "c_r", "c_rock", "c_z"):
        assert getattr(ab, key) == pytest.approx(getattr(ba, key), rel=1e-9), key
    assert ab.k_r != pytest.approx(as_stand.k_r, rel=1e-6)          # the second resonance is divided out too


def test_line_shape_near_a_mode_is_no_line_beside_it():
    """20 speeds, no stand, a fitted reference model, clean data: the wheel's axial h = 1.98 line crosses the 70 Hz
    axial mode (the generator's own transmissibility), and the few speeds leave the reference's shape there a little
    off.  Since the exact Hann kernel, diagnose proposed a line at h = 1.937 (4 % of the 1.98 line's C), inside that
    line's Hann main lobe at every speed (1.2 Welch bins from it at 3000 rpm), which patched the shape (error 0.0030
    -> 0.0019) and was added.  A Welch-route line is not proposed inside a model line's main lobe: nothing added."""
    speeds = np.linspace(300.0, 3000.0, 20)
    ref = _reference(iir_stand_test(speeds, seed=500, stand=False))
    d = api.diagnose(iir_stand_test(speeds, seed=3, stand=False), ref)
    assert _added(d) == []


def test_missing_line_inside_a_weaker_lines_lobe_is_found():
    """2048 samples (7.5 Hz Welch bins), a fitted reference model: an axial line at h = 2.73 (0.3 × the radial
    fundamental's C, 1.7 × the wheel's h = 2.96 line beside it) lies inside that line's Hann main lobe at every speed
    (1.5 bins from it at 3000 rpm), yet it is a line of its own: found, h and C within 1 %."""
    speeds = np.linspace(300.0, 3000.0, 60)
    c_fund = next(c for d, h, c, _ in iw.E_LINES if d == "radial_force" and h == 1.0)
    ref = _reference(iir_stand_test(speeds, seed=500, n_samples=2048, stand=False))
    d = api.diagnose(iir_stand_test(speeds, seed=3, n_samples=2048, stand=False,
                                    extra_lines=[("axial_force", 2.73, 0.3 * c_fund, 1.0)]), ref)
    (line,) = d.model.effects
    assert line["kind"] == "missing_harmonic" and line["direction"] == "axial_force"
    assert line["h"] == pytest.approx(2.73, rel=0.01)
    assert line["C"] == pytest.approx(0.3 * c_fund * iw.C_UNIT, rel=0.01)
