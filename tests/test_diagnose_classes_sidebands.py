"""``sidebands`` (amplitude modulation at a fixed f_mod) closer to the carrier than the Welch bins resolve: at
10 kHz and 8192 samples diagnose's Welch bins (n/4 segments) are 4.9 Hz wide and its offset grid starts at 2.5
bins (12.2 Hz), so 7-Hz sidebands sit inside the carrier's main lobe there; the whole record (1.2-Hz bins) holds
them 5.7 bins out.  Data: modes on (``rwadist.inject`` sends the modulated h = 2 radial-force load through the
suspension modes), the preset's model (the truth without the effect) on the extended base, the time series given
(as ``rwadist diagnose`` does).  Before the whole-run route the matrix cell rate=10000 missed them.
"""
import numpy as np
import pytest

from rwadist import api
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset

E = preset("ithaco-e")
SPEEDS = np.linspace(1200.0, 3000.0, 20)
KW = dict(sample_rate=10000.0, n_samples=8192, noise=0.01, physics="extended", test_stand=False)


def test_sidebands_inside_the_welch_main_lobe_found_on_the_whole_record():
    test = simulate_with_injections(E, [parse("sidebands:direction=radial_force,h=2,depth=0.4,f_mod_hz=7")],
                                    SPEEDS, seed=7, **KW)
    d = api.diagnose(test, E.to_model())
    assert 7.0 < 2.5 * d.ctx.df                          # the Welch offset grid does not reach 7 Hz
    assert [e["kind"] for e in d.model.effects] == ["sidebands"], d.model.effects
    e = d.model.effects[0]
    assert e["h"] == pytest.approx(2.0) and e["f_mod_Hz"] == pytest.approx(7.0, rel=0.02)
    assert e["depth"] == pytest.approx(0.4, rel=0.15)


def test_clean_data_get_no_near_sidebands():
    """The same settings without the modulation: nothing added (the carrier's own leakage is subtracted through
    its phasor, so its sidelobes are no sidebands)."""
    test = simulate_with_injections(E, [], SPEEDS, seed=8, **KW)
    d = api.diagnose(test, E.to_model())
    assert d.model.effects == []
