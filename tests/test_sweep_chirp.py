"""Lines of a sweep read whole: the chirp of a line across a spectrum segment (issue 33's sweep acceptance).

Trial 11 (an independent generator; its sweep physics copied into tests/trial_wheel.py), ``rwadist diagnose`` on a
120-s run-up 300 -> 4500 rpm without a speed column: every line's h was right, but the lines at h 7.2 came out
9-10 % low in C on every direction and the spin acceleration 6-9 % low -- with the tach column too.  The wheel's
modes are fitted on slice-long segments (8192 samples at 4 kHz), across which h 7.2 sweeps 17.6 bins: the empirical
fit's ±3-bin window held 82 % of its power.  And the spin acceleration's prediction counted each segment's chirp
twice.  Truth: the generator's lines and its ramp.
"""
import functools
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import trial_wheel as tw  # noqa: E402

from rwadist.chirp import chirp_bins, speed_rates, window_fraction  # noqa: E402
from rwadist.data import Sweep  # noqa: E402
from rwadist.sweep import slice_sweep  # noqa: E402

RPM = 2 * np.pi / 60


@pytest.mark.parametrize("c, delta", [(0.0, 0.0), (2.0, 0.3), (8.8, 0.0), (8.8, -0.5), (17.6, 0.2), (30.0, 0.45)])
def test_window_fraction_is_the_share_a_sampled_chirp_leaves_in_seven_bins(c, delta):
    """A real chirp sampled on one Hann segment (its own periodogram, rfft, not the table's complex FFT): the power in
    the 7 bins about the bin nearest its centre over its whole power (Parseval) is :func:`window_fraction`'s."""
    n, fs = 4096, 4000.0
    L = n / fs
    k0 = 700
    f_c = (k0 + delta) / L                                # centre frequency, Hz
    beta = c / L**2                                       # Hz/s: c bins across the segment
    t = np.arange(n) / fs - L / 2
    x = np.cos(2 * np.pi * (f_c * t + 0.5 * beta * t**2) + 0.7)
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)
    p = np.abs(np.fft.rfft(w * x)) ** 2
    share = p[k0 - 3:k0 + 4].sum() / p.sum()
    assert window_fraction(c, delta) == pytest.approx(share, abs=2e-4)


def test_a_long_chirp_keeps_the_windows_shape():
    """Stationary phase: a chirp of c bins spends 1/c of the segment in each bin, so for c large the 7 bins hold the
    Hann window's squared weight over the middle 7/c of the segment: ∫cos⁴(πx) dx over |x| < 3.5/c, over 3/8."""
    c = 60.0
    u = 3.5 / c
    x = np.linspace(-u, u, 20001)
    expected = np.trapezoid(np.cos(np.pi * x) ** 4, x) / 0.375
    assert window_fraction(c, 0.0) == pytest.approx(expected, rel=0.02)


def test_speed_rates_of_one_sweep_and_of_steady_runs():
    """|dΩ/dt| of the runs in time order whatever their order; steady runs (one start time) have none."""
    t = np.array([3.0, 1.0, 2.0, 4.0])
    w = 10.0 + 2.5 * t
    assert np.allclose(speed_rates(t, w), 2.5)
    assert np.all(np.isnan(speed_rates(np.zeros(4), w)))
    assert chirp_bins(7.2, 3.665, 2.048) == pytest.approx(17.6, abs=0.05)


#: the rocking mode of trial 11's 120-s run-up read on the slices' mean speeds: 0.196 % low with a tach column, 0.22 %
#: without (rwadist.slice_angle: the imbalance's angle, the slices' mean speeds as a tach gives them)
ROCKING_REL = 0.003


@functools.lru_cache(maxsize=None)
def _sliced(duration: float, down: bool = False):
    rpm = (4500.0, 300.0) if down else (300.0, 4500.0)
    t, ch, omega = tw.sweep(rpm[0], rpm[1], duration, tw.LINES)
    sweep = Sweep(time=t, signals={c: ch[j] for j, c in enumerate(tw.CHANNELS)}, sample_rate=tw.FS, tach=None)
    test, _ = slice_sweep(sweep, speed_source="data")
    return test


def _truth_C(direction, h):
    return next(C for d, hh, _, C in tw.LINES if d == direction and hh == h)


@pytest.mark.parametrize("down", [False, True])
def test_modes_fit_reads_the_ball_pass_lines_whole_on_a_fast_sweep(down):
    """Trial 11's wheel swept in 120 s without a speed column, the extended fit (the wheel's modes, as diagnose fits
    them): every line at h 3.6 and 7.2 within 1.5 % of the generator's C (before: 7.2 9.3-9.7 % low, 3.6 0.6 % low),
    the modes within 0.2 % (the rocking mode 0.3 %: on the slices' mean speeds, which a tach column gives and the
    speed from the data now reads on the imbalance's angle, it comes out 69.863 Hz with the tach, 69.844 without;
    the lines' peaks, which read the slow slices 0.1-0.4 % high, had put it at 69.975)."""
    from rwadist.empirical import fit_empirical
    from rwadist.extended_fit import fit_extended, to_model
    from rwadist.spectra import compute_spectra

    test = _sliced(120.0, down)
    fit = fit_empirical(compute_spectra(test))
    efit = fit_extended(test, fit)
    model = to_model(efit, fit)
    got = {}
    for d in ("radial_force", "radial_torque", "axial_force"):
        for x in model.harmonics(d):
            if min(abs(x.h - 3.6), abs(x.h - 7.2)) < 0.01:
                got[(d, round(x.h, 1))] = x.C / _truth_C(d, round(x.h, 1)) - 1
    print({k: f"{100 * v:+.2f} %" for k, v in got.items()})
    assert {k for k in got if k[1] == 7.2} == {("radial_force", 7.2), ("radial_torque", 7.2), ("axial_force", 7.2)}
    assert max(abs(v) for v in got.values()) < 0.015
    p = efit.params
    for k, inertia, f, rel in (("k_r", p.mass, tw.F_R, 0.002), ("k_rock", p.I_rr, tw.F_T, ROCKING_REL),
                               ("k_z", p.mass, tw.F_Z, 0.002)):
        assert np.sqrt(getattr(p, k) / inertia) / (2 * np.pi) == pytest.approx(f, rel=rel)
    assert not efit.unconstrained


def test_diagnose_fast_sweep_lines_and_spin_acceleration():
    """``diagnose`` of trial 11's 120-s run-up without a speed column: every line's h within 0.2 % of a true line, no
    line twice, every C within 1.5 % (7.2: 9-10 % low before), the modes within 0.2 %, and the spin acceleration within
    2 % of the generator's ramp, 4200 rpm / 120 s = 3.665 rad/s² (before: 3.32-3.45, 6-9 % low); the rocking mode
    within :data:`ROCKING_REL`."""
    from rwadist import api

    test = _sliced(120.0)
    d = api.diagnose(test)
    s = d.summary()
    eff = {e["kind"]: e for e in s["effects"]}
    alpha_true = 4200.0 * RPM / 120.0
    assert eff["spin_acceleration"]["alpha_rad_s2"] == pytest.approx(alpha_true, rel=0.02)
    sm = eff["suspension_modes"]
    for key, f, rel in (("radial_translation_Hz", tw.F_R, 0.002), ("rocking_Hz", tw.F_T, ROCKING_REL),
                        ("axial_Hz", tw.F_Z, 0.002)):
        assert sm[key] == pytest.approx(f, rel=rel)
    for d_ in ("radial_force", "radial_torque", "axial_force", "axial_torque"):
        truth = [(h, C) for dd, h, _, C in tw.LINES if dd == d_]
        hs = sorted(x.h for x in d.model.harmonics(d_))
        assert all(b / a - 1 > 0.03 for a, b in zip(hs, hs[1:])), (d_, hs)          # no line twice
        for x in d.model.harmonics(d_):
            h, C = min(truth, key=lambda t: abs(x.h / t[0] - 1))
            assert abs(x.h / h - 1) < 0.002, (d_, x.h)
            assert x.C == pytest.approx(C, rel=0.015), (d_, x.h, x.C / C - 1)


def test_axial_mode_reached_by_one_force_line_beside_a_flat_spin_axis_torque_line():
    """Trial 11's wheel without its 7.2 lines swept in 300 s (its tach): the axial mode (260 Hz) is reached by the
    axial force's h 3.6 alone, at the top of the sweep, while the spin-axis torque's h 3.6 (no mode: hard-mounted)
    runs flat to 270 Hz.  The extended fit locates the axial mode within 0.5 % and frees no line's exponent (before:
    the scan read the Tz line as if through the axial mode, put it at 293 Hz, the least squares at its ±5 % limit,
    declared it not constrained and gave the Fz line an Ω^2.82 law: diagnose then invented an amplitude law and a
    moving resonance)."""
    from rwadist.empirical import fit_empirical
    from rwadist.extended_fit import fit_extended
    from rwadist.spectra import compute_spectra

    lines = tuple(x for x in tw.LINES if x[1] != 7.2)
    t, ch, omega = tw.sweep(300.0, 4500.0, 300.0, lines)
    sweep = Sweep(time=t, signals={c: ch[j] for j, c in enumerate(tw.CHANNELS)}, sample_rate=tw.FS, tach=omega)
    test, _ = slice_sweep(sweep, speed_source="tach")
    fit = fit_empirical(compute_spectra(test))
    efit = fit_extended(test, fit)
    p = efit.params
    assert "axial" not in efit.unconstrained and not any("exponent was left free" in n for n in efit.notes)
    assert np.sqrt(p.k_z / p.mass) / (2 * np.pi) == pytest.approx(tw.F_Z, rel=0.005)


def test_a_slice_whose_speed_reads_another_line_is_dropped_not_kept():
    """A run-up's slices whose speed estimate took another line for 1x (the session-55 new-user trial: a 4.5 kg wheel
    swept 500 -> 7500 rpm in 90 s without a speed column read its cage line, h 0.41, as 1x in its two first slices:
    1244 and 1299 rpm for 510 and 530) lie off the track the other slices make: their speed is unknown (standard
    error inf: :func:`rwadist.sweep.slice_sweep` drops them as uncertain) and the slice-length rule does not read their
    jumps.  On ce37b70 both kept their own values (an outlier next to another supported it), and their jumps set the
    chirp rule's largest sweep rate.  Closed form: a linear ramp of the rotor frequency, 1 % scatter."""
    from rwadist.sweep import SliceInfo, _fuse_track, _slice_change, _slice_chirp

    rng = np.random.default_rng(5)
    n = 120
    truth = np.linspace(8.5, 125.0, n)                       # Hz, 510 -> 7500 rpm
    f0 = truth * (1 + 0.001 * rng.standard_normal(n))
    sigma = 0.001 * truth
    wrong = [0, 1, 60]
    f0[wrong] = truth[wrong] / 0.41                          # the cage taken for 1x there
    fused, s = _fuse_track(f0, sigma)
    assert np.flatnonzero(~np.isfinite(s)).tolist() == wrong
    ok = np.isfinite(s)
    assert np.max(np.abs(fused[ok] / truth[ok] - 1)) < 0.005
    fs, L = 8000.0, 2048
    infos = [SliceInfo(start=k * L, stop=(k + 1) * L, speed=2 * np.pi * fused[k], speed_source="data",
                       speed_spread=0.0, confidence=1.0, speed_stderr=2 * np.pi * s[k]) for k in range(n)]
    alpha = 2 * np.pi * (truth[1] - truth[0]) / (L / fs)      # rad/s²
    seg = L / fs / 4
    # the chirp of h 6.56 over a quarter-slice segment, h·α·seg²/2π, and the speed's change over a slice
    assert _slice_chirp(infos, fs, 6.56) == pytest.approx(6.56 * alpha * seg**2 / (2 * np.pi), rel=0.1)
    assert _slice_change(infos, fs) == pytest.approx(np.median(alpha * L / fs / (2 * np.pi * truth)), rel=0.05)
