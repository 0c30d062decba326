"""``rwadist fit`` warns when one radial channel reads its partner's lines by a unit factor (new-user trial 29: Fy in
lbf declared N, the radial-force C off by 39 % and the fit said nothing; only diagnose named it).  The ratio is read
on the fitted lines against a second, independent reading: the generator's own channel scale."""
import warnings
from dataclasses import replace

import numpy as np
import pytest

import rwadist
from rwadist.errors import RwadistWarning
from rwadist.fit_warnings import pair_amplitude_ratios
from rwadist.spectra import compute_spectra


@pytest.fixture(scope="module")
def test_data():
    # the extended physics: a rotating load on the radial pairs (x and y of the same power), as a rotor makes it
    return rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 16), n_samples=4096, seed=3,
                                 physics="extended")


def _scaled(test, channel: str, factor: float):
    return type(test)([replace(r, signals={**r.signals, channel: r.signals[channel] * factor}) for r in test.runs],
                      test.meta)


def _fit_warnings(test) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rwadist.fit(test)
    return [str(w.message) for w in caught if issubclass(w.category, RwadistWarning)]


@pytest.mark.parametrize("channel, factor, unit", [("Fy", 4.44822, "lbf"), ("Tx", 1 / 8.85075, "in·lbf"),
                                                   ("Fx", 9.80665, "kgf")])
def test_a_channel_in_another_unit_is_named_by_the_fit(test_data, channel, factor, unit):
    said = [w for w in _fit_warnings(_scaled(test_data, channel, factor)) if "times" in w]
    assert len(said) == 1
    assert f"in one {unit}" in said[0] or f"{unit} in one" in said[0]
    assert said[0].startswith(channel if factor > 1 else {"Tx": "Ty"}[channel])


def test_the_ratio_read_is_the_scale_applied_and_a_plain_gain_is_no_unit(test_data):
    clean = pair_amplitude_ratios(compute_spectra(test_data), rwadist.fit(test_data).model)
    # a rotating load: both pairs read 1 to a few per cent (the independent truth: x and y carry the same power)
    assert clean[("Fx", "Fy")] == pytest.approx(1.0, rel=0.05) and clean[("Tx", "Ty")] == pytest.approx(1.0, rel=0.05)
    scaled = _scaled(test_data, "Fy", 1.3)
    ratios = pair_amplitude_ratios(compute_spectra(scaled), rwadist.fit(scaled).model)
    assert ratios[("Fx", "Fy")] == pytest.approx(clean[("Fx", "Fy")] / 1.3, rel=1e-6)
    assert not [w for w in _fit_warnings(scaled) if "times" in w]
    assert not [w for w in _fit_warnings(test_data) if "times" in w]
