"""The diagnosis context's content key (:meth:`rwadist.diagnose.engine.Context.content_key`, which keys the reuse of
``fixed_resonance`` fits between search steps) with its per-channel digests kept on the state: the key read back
from the state is the key computed afresh, and it still tells states apart exactly where they differ."""
import numpy as np

from rwadist.diagnose.engine import Context, initial_state
from rwadist.effects.fixed_resonance_diagnose import FixedResonance
from rwadist.empirical import fit_empirical
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady


def test_content_key_kept_on_the_state_is_the_fresh_one():
    test = simulate_steady(preset("ithaco-e"), np.linspace(600.0, 3000.0, 8), sample_rate=1000.0, n_samples=2048,
                           noise=0.01, seed=3, test_stand=False)
    sp = compute_spectra(test, nperseg=512)
    ctx = Context(sp, test=test)
    plain = initial_state(ctx, fit_empirical(sp).model)
    forces = FixedResonance(150.0, 0.03, 5.0, ("Fx", "Fy"), "wheel_mode").apply(plain)
    runs = ctx.runs
    for chans in (["Fx", "Fy"], ["Tx", "Ty"], list(ctx.channels)):
        for state in (plain, forces):
            first = ctx.content_key(state, chans, runs)
            again = ctx.content_key(state, chans, runs)                  # read back from the state's cache
            fresh_state = state.copy()              # the same content (its effects, hence its resonances), no cache
            fresh_state.noise = state.noise
            assert first == again == ctx.content_key(fresh_state, chans, runs)
        touched = bool({"Fx", "Fy"} & set(chans))
        assert (ctx.content_key(plain, chans, runs) != ctx.content_key(forces, chans, runs)) == touched
    # other runs, other key
    assert ctx.content_key(plain, ["Fx"], runs) != ctx.content_key(plain, ["Fx"], runs[1:])


def test_band_sums_are_numpys_sums_of_each_band():
    """:meth:`Metric.band_sums` written as numpy's pairwise order of its 8 bins: bit for bit ``reshape(...).sum(-1)``
    on numbers spread over many decades (where another order of the adds would differ in the last bits)."""
    test = simulate_steady(preset("ithaco-e"), np.linspace(600.0, 3000.0, 4), sample_rate=1000.0, n_samples=2048,
                           noise=0.01, seed=3, test_stand=False)
    ctx = Context(compute_spectra(test, nperseg=512), test=test)
    rng = np.random.default_rng(0)
    x = rng.standard_normal((7, ctx.f.size)) * np.exp(5.0 * rng.standard_normal((7, ctx.f.size)))
    lo, n = ctx.k_lo, ctx.n_bands * 8
    plain = x[:, lo:lo + n].reshape(7, ctx.n_bands, 8).sum(-1) * ctx.df
    assert np.array_equal(ctx.band_sums(x), plain)
