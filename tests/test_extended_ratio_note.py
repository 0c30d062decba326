"""The extended fit says where I_zz/I_rr came from: "fitted from the whirls" only when the rocking mode the ratio was
read with is located.  A new user's hard-mounted wheel (no mode in band, every mode NOT CONSTRAINED) was told
"I_zz/I_rr = 3.000 fitted from the whirls", the scan's bound."""
import numpy as np
import pytest

import rwadist


@pytest.fixture(scope="module")
def hard_mounted_fit():
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 12), n_samples=4096, seed=3)
    return rwadist.fit_extended(test)[0]


def test_an_unlocated_rocking_mode_fits_no_ratio(hard_mounted_fit):
    """The E wheel simulated hard-mounted (no mode in band): every mode NOT CONSTRAINED, and the ratio's note says
    the whirls do not fix it."""
    efit = hard_mounted_fit
    notes = " ".join(efit.notes)
    assert set(efit.unconstrained) == {"radial_translation", "rocking", "axial"}
    assert "fitted from the whirls" not in notes
    assert "I_zz/I_rr" in notes and "the whirls do not fix it" in notes
