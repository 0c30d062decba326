"""Lines diagnose's Welch grid cannot measure but the whole record resolves (issue 14, the robustness matrix's cells
samples=2048 and rate=10000).

diagnose's Welch segments are a quarter of the record, and its lowest analysed bin is F_MIN_BINS = 4 of them: 30 Hz at
3840 Hz and 2048 samples, a line's ±3-bin window reaching down to it from 52 Hz.  A subharmonic h = 0.5 at 1500-3000
rpm (12.5-25 Hz) is below all of it, and a 7-Hz modulation's sidebands sit 0.9 Welch bin from their carrier, inside
its main lobe.  The whole record (1.875-Hz bins) holds both.  Data: the virtual stand with modes on
(:mod:`rwadist.inject` sends the wheel loads through the suspension modes), the preset's model (the truth without the
effect) on the extended base, the time series given (as ``rwadist diagnose`` does).  Before the record routes these
were missed (nothing added).
"""
import numpy as np
import pytest

from rwadist import api
from rwadist.dft import windowed_dft
from rwadist.diagnose.measure import hann_transform_ratio
from rwadist.effects.missing_harmonic_diagnose import welch_low_limit
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset

E = preset("ithaco-e")
SPEEDS = np.linspace(1500.0, 3000.0, 16)
KW = dict(sample_rate=3840.0, n_samples=2048, noise=0.01, physics="extended", test_stand=False)


def test_hann_transform_is_the_windows_dft():
    """The closed form of the periodic Hann window's transform (three Dirichlet kernels) against its direct DFT
    (:func:`windowed_dft` of the window itself), at offsets between and on bins, near and far."""
    from scipy import signal

    n = 512
    w = signal.get_window("hann", n)
    delta = np.array([0.0, 0.3, 1.0, 1.7, 2.0, 2.5, 3.9, 7.25, 40.6])
    direct = windowed_dft(w[:, None], float(n), delta)[:, 0] / np.sum(w)          # fs = n: f in bins
    assert np.allclose(hann_transform_ratio(n, delta), direct, atol=1e-12)


def test_subharmonic_below_the_welch_band_found_on_the_whole_record():
    test = simulate_with_injections(E, [parse("missing_harmonic:direction=radial_force,h=0.5,fraction=0.5")],
                                    SPEEDS, seed=3, **KW)
    d = api.diagnose(test, E.to_model())
    assert 0.5 * SPEEDS.max() / 60.0 < welch_low_limit(d.ctx)            # no run's line is measured on the Welch grid
    hit = [e for e in d.model.effects if e["kind"] == "missing_harmonic" and abs(e["h"] - 0.5) < 0.02]
    assert len(hit) == 1, d.model.effects
    assert hit[0]["h"] == pytest.approx(0.5, abs=0.002)
    # the injected load: fraction·C₁ of the radial-force fundamental (the preset's static imbalance U_s)
    assert hit[0]["C"] == pytest.approx(0.5 * E.fundamental_C("radial_force"), rel=0.05)
    assert len(d.model.effects) == 1, d.model.effects


def test_near_sidebands_on_a_short_record_found_and_judged_on_the_whole_record():
    test = simulate_with_injections(E, [parse("sidebands:direction=radial_force,h=2,depth=0.4,f_mod_hz=7")],
                                    SPEEDS, seed=4, **KW)
    d = api.diagnose(test, E.to_model())
    assert 7.0 < d.ctx.df                                  # inside the carrier's Welch main lobe
    assert [e["kind"] for e in d.model.effects] == ["sidebands"], d.model.effects
    e = d.model.effects[0]
    assert e["h"] == pytest.approx(2.0) and e["f_mod_Hz"] == pytest.approx(7.0, rel=0.01)
    assert e["depth"] == pytest.approx(0.4, rel=0.1)


def test_clean_short_record_gets_nothing():
    """The same settings without an effect: the record routes add nothing (the model's own low lines -- the
    fundamental at 25-50 Hz is below the Welch route's lowest measured frequency too -- have their leakage taken
    off through their own phasors)."""
    test = simulate_with_injections(E, [], SPEEDS, seed=5, **KW)
    d = api.diagnose(test, E.to_model())
    assert d.model.effects == []
