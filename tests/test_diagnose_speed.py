"""The speed-ups of ``rwadist diagnose`` keep its numbers: the closed-form Jacobian of the resonance's log power gain
against scipy's numerical derivative, the ``fixed_resonance`` peak locator against the direct window mask, and a
``fixed_resonance`` fit reused across search steps only when the state is the same on its channels."""
import numpy as np
import pytest

from rwadist.resonance import log_power_gain_jacobian, resonance_response

RESONANCES = [(47.0, 0.03, 4.0), (130.0, 0.1, 0.4), (200.0, 0.001, 60.0), (75.0, 0.5, 0.02)]


@pytest.mark.parametrize("f_r, zeta, g", RESONANCES)
def test_log_power_gain_jacobian_matches_scipy_differentiate(f_r, zeta, g):
    """∂ln|H|²/∂(ln f_r, ln ζ, ln g) in closed form = scipy.differentiate.jacobian (Richardson-extrapolated finite
    differences) of ln|H|² from :func:`resonance_response`, across the band, through the peak and at signed f."""
    jacobian = pytest.importorskip("scipy.differentiate", reason="scipy >= 1.15").jacobian
    f = np.concatenate([np.linspace(-400.0, 400.0, 801), f_r * np.array([0.999, 1.0, 1.001])])

    def log_gain(x):                          # x: (3, ...) log parameters, as scipy.differentiate passes them
        ff = np.abs(f).reshape((-1,) + (1,) * x[0].ndim)
        return np.log(np.abs(resonance_response(ff / np.exp(x[0]), np.exp(x[1]), np.exp(x[2]))) ** 2)

    numeric = jacobian(log_gain, np.log([f_r, zeta, g]), initial_step=1e-3).df        # (n, 3)
    closed = log_power_gain_jacobian(f, f_r, zeta, g)
    assert closed.shape == (f.size, 3)
    assert np.max(np.abs(closed - numeric) / (1.0 + np.abs(closed))) < 1e-6
    # landmarks: no dependence at f = 0; at f = f_r, ln|H|² = 2 ln g exactly, so ∂/∂ln g = 2 and ∂/∂ln ζ = 0
    assert np.allclose(closed[f == 0.0], 0.0, atol=1e-15)
    at = closed[np.isclose(f, f_r, rtol=0, atol=1e-12)]
    assert np.allclose(at[:, 2], 2.0, rtol=1e-12) and np.allclose(at[:, 1], 0.0, atol=1e-12)


def _peak_by_mask(f, y, lo, hi, df):
    """The strongest excess of y vs f by the direct (grid, points) window mask: the definition of
    :meth:`FixedResonance.peak` written out."""
    grid = np.arange(lo, hi, df)
    half = np.maximum(2.0 * df, 0.02 * grid)
    inside = np.abs(f[None, :] - grid[:, None]) <= half[:, None]
    cnt = inside.sum(1)
    mean = np.where(cnt > 0, (inside * y[None, :]).sum(1) / np.maximum(cnt, 1), 0.0)
    score = np.where(cnt >= 4, np.abs(mean) * np.sqrt(cnt), 0.0)
    i = int(np.argmax(score))
    return (float(grid[i]), float(mean[i])) if score[i] > 0 else None


def test_peak_locator_matches_the_window_mask():
    from rwadist.effects.fixed_resonance_diagnose import FixedResonance

    rng = np.random.default_rng(3)
    for _ in range(60):
        n = int(rng.integers(3, 2500))
        f = rng.uniform(1.0, 900.0, n)
        bump = rng.uniform(10.0, 800.0)
        y = rng.normal(0.0, 0.3, n) + rng.choice([-2.0, 2.0]) * np.exp(-(((f - bump) / 15.0) ** 2))
        want = _peak_by_mask(f, y, 2.0, 900.0, 0.47)
        got = FixedResonance.peak(f, y, 2.0, 900.0, 0.47)
        if want is None:
            assert got is None
        else:
            assert got[0] == want[0] and abs(got[1] - want[1]) <= 1e-12 * (1.0 + abs(want[1]))


def test_fixed_resonance_fit_reused_only_for_the_same_channels_content():
    """A fit is taken from the context's memo for a state equal on its channels (a line added on other channels
    in between) and equals a fresh fit; a state that differs on its channels is fitted anew."""
    from dataclasses import replace

    from rwadist.diagnose import Context, initial_state
    from rwadist.effects.fixed_resonance_diagnose import FixedResonance
    from rwadist.effects.missing_harmonic_diagnose import MissingHarmonic
    from rwadist.presets import preset
    from rwadist.spectra import compute_spectra
    from rwadist.teststand import Mode, simulate_steady

    w = replace(preset("ithaco-e"), test_stand_modes=[Mode("injected", 150.0, 0.03, 5.0, ("Fx", "Fy"))])
    t = simulate_steady(w, np.linspace(600.0, 3000.0, 24), sample_rate=1920.0, n_samples=4096, modes=False,
                        noise=0.01, seed=2)
    sp = compute_spectra(t, nperseg=1024)
    state = initial_state(Context(sp), preset("ithaco-e").to_model())
    chans = ("Fx", "Fy")
    ctx = Context(sp)
    first = FixedResonance.fit(ctx, state, chans, ctx.fit_runs)
    assert first is not None and first.f_r == pytest.approx(150.0, rel=0.01)
    n_memo = len(ctx._memo)
    # a line added on the axial force only: the radial-force channels read and predict the same
    other = MissingHarmonic("axial_force", 3.3, 1e-7).apply(state)
    again = FixedResonance.fit(ctx, other, chans, ctx.fit_runs)
    assert len(ctx._memo) == n_memo and again == first and again is not first
    fresh = FixedResonance.fit(Context(sp), other, chans, Context(sp).fit_runs)
    assert fresh == first
    # the resonance itself added on Fx, Fy: a different state on the fit's channels, fitted anew
    FixedResonance.fit(ctx, first.apply(state), chans, ctx.fit_runs)
    assert len(ctx._memo) == n_memo + 1


def test_flat_no_resonance_stop_keeps_the_decision(monkeypatch):
    """Fits stopped early as "no resonance" (a least_squares callback, scipy >= 1.16) decide as fits run to the
    evaluation limit: on clean data both give no candidate resonance (|ln g| < ln MIN_PEAK_GAIN), with a 150-Hz
    fixture resonance both give the same f_r, ζ, g."""
    from dataclasses import replace

    from rwadist.diagnose import Context, initial_state
    from rwadist.effects import fixed_resonance_diagnose as fr
    from rwadist.effects.fixed_resonance_diagnose import FixedResonance
    from rwadist.presets import preset
    from rwadist.spectra import compute_spectra
    from rwadist.teststand import Mode, simulate_steady

    if not fr._HAS_CALLBACK:
        pytest.skip("least_squares has no callback before scipy 1.16: nothing is stopped")
    truth = preset("ithaco-e").to_model()
    for stand in ([], [Mode("injected", 150.0, 0.03, 5.0, ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))]):
        w = replace(preset("ithaco-e"), test_stand_modes=stand)
        t = simulate_steady(w, np.linspace(600.0, 3000.0, 24), sample_rate=1920.0, n_samples=4096, modes=False,
                            noise=0.01, seed=4)
        sp = compute_spectra(t, nperseg=1024)
        fits = []
        for has_callback in (True, False):
            monkeypatch.setattr(fr, "_HAS_CALLBACK", has_callback)
            ctx = Context(sp)
            state = initial_state(ctx, truth)
            fits.append([FixedResonance.fit(ctx, state, chans, ctx.fit_runs)
                         for chans in (("Fx", "Fy"), ("Fz",), ("Tx", "Ty"), ctx.channels)])
        for stopped, full in zip(*fits):
            assert (stopped is None) == (full is None)
            if full is None:
                continue
            assert fr._is_resonance_gain(stopped.peak_gain) == fr._is_resonance_gain(full.peak_gain)
            if stand and fr._is_resonance_gain(full.peak_gain):
                assert (stopped.f_r, stopped.zeta, stopped.peak_gain) == pytest.approx(
                    (full.f_r, full.zeta, full.peak_gain), rel=1e-6)
        if stand:
            assert fr._is_resonance_gain(fits[1][-1].peak_gain) and fits[1][-1].f_r == pytest.approx(150.0, rel=0.01)


def _pair_stats_written_out(Z, s, t):
    """The noise-bin statistics of channel pair (s, t) of one run's segments Z (M, F, K), straight from their definition
    (:mod:`rwadist.diagnose.channel_copy_broadband`): each channel's mean segment power, the bins where both are under
    NOISE_FACTOR x their median above bin 4, the cross-spectrum's sum over the power's (κ), its z over the null scatter,
    and per part of the bins (np.array_split) the sums of the cross-spectrum, the source's power and their null
    variance."""
    from rwadist.diagnose.channel_copy_broadband import BAND_PARTS, NOISE_FACTOR

    Pss = np.mean(np.abs(Z[:, :, s]) ** 2, axis=0)
    Ptt = np.mean(np.abs(Z[:, :, t]) ** 2, axis=0)
    Pst = np.mean(np.conj(Z[:, :, s]) * Z[:, :, t], axis=0)
    noise = (Pss < NOISE_FACTOR * np.median(Pss[4:])) & (Ptt < NOISE_FACTOR * np.median(Ptt[4:]))
    noise[:4] = False
    idx = np.flatnonzero(noise)
    M = Z.shape[0]
    null = np.sum(Pss[idx] * Ptt[idx]) / M
    kappa = complex(np.sum(Pst[idx]) / np.sum(Pss[idx]))
    z = float(abs(np.sum(Pst[idx])) / np.sqrt(null))
    parts = [(np.sum(Pst[b]), np.sum(Pss[b]), np.sum(Pss[b] * Ptt[b]) / M) for b in np.array_split(idx, BAND_PARTS)]
    return kappa, z, parts


def test_floor_copy_pair_statistics_are_their_definition_bit_for_bit():
    """The channel-copy floor statistics made per channel once and summed by np.add.reduce (its speed-up) are the
    numbers of their definition written out, to the last bit, for a pair holding a copy (z in the tens: its band parts
    too) and for independent pairs (z ~ 1: κ and z; their parts are not read below MIN_Z)."""
    from types import SimpleNamespace

    from rwadist.diagnose.channel_copy_broadband import MIN_Z, _channel_stats, _run_stats, _segments

    rng = np.random.default_rng(7)
    n, fs = 8192, 3840.0
    t = np.arange(n) / fs
    x = {c: rng.normal(0.0, 1.0, n) + 3.0 * np.sin(2 * np.pi * f * t) for c, f in zip("abcd", (37.0, 81.0, 50.0, 123.0))}
    x["d"] = x["d"] + 0.3 * x["a"]                       # d carries a copy of a, noise and line alike
    _, Z = _segments(SimpleNamespace(signals=x, sample_rate=fs), tuple(x))
    stats = _channel_stats(Z)
    strong = 0
    for s in range(4):
        for u in range(4):
            if s == u:
                continue
            want, got = _pair_stats_written_out(Z, s, u), _run_stats(Z, stats, s, u)
            assert got[:2] == want[:2]
            if want[1] >= MIN_Z:
                strong += 1
                assert got[2] == want[2]
            else:
                assert got[2] is None
    assert strong == 2                                  # a -> d and d -> a
