"""``fit --extended`` on a sweep whose speed came from the data says when the rocking whirl contradicts the scale.

A new user's 2.5-kg wheel (session 63), swept without a speed column: the scale took a ball pass at 4.70 for 1x and
``rwadist fit --extended`` printed "I_zz/I_rr = 0.286 fitted from the whirls" as a note.  The whirl reads the inertia
ratio in proportion to the speed scale (:mod:`rwadist.speed_whirl`), and a flywheel's lies in 1-2: outside 0.8-2.5 the
scale is likely wrong, and the fit says so with the other candidates (diagnose tries them; the fit has no search).

Data: family wheel 4 (tests/family_wheel.py, time-integrated physics; I_zz/I_rr 2.0), run down over 60 s without a
speed column, sliced with the speed from the data; the same test with its speeds scaled by the ball pass's ratio (every
speed 4.6x too high: the whirl reads 0.43)."""
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402


def _fit(test):
    from rwadist import api
    from rwadist.errors import RwadistWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        efit, _ = api.fit_extended(test)
    return efit, [str(w.message) for w in caught if issubclass(w.category, RwadistWarning)]


def test_a_whirl_out_of_the_flywheel_band_is_said_on_a_speed_from_the_data(tmp_path):
    from rwadist import api
    from rwadist.speed_whirl import rescaled

    wheel = fw.family()[4]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(fw.sweep(wheel, wheel.max_rpm, wheel.min_rpm, 60.0, seed=1),
                                       tmp_path / "run_down.csv", tach=False))
    efit, said = _fit(test)
    assert efit.params.inertia_ratio == pytest.approx(wheel.I_zz / wheel.I_rr, rel=0.05)
    assert not [s for s in said if "rocking whirl reads" in s], said
    bpfo = next(ln.h for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "BPFO")
    ratios = np.array(test.meta["slicing"]["speed_scale"]["ratios"])
    wrong = rescaled(test, float(ratios[np.argmin(np.abs(ratios - bpfo))]))
    efit, said = _fit(wrong)
    assert efit.params.inertia_ratio == pytest.approx(wheel.I_zz / wheel.I_rr / bpfo, rel=0.1)
    assert [s for s in said if "rocking whirl reads I_zz/I_rr 0.4" in s and "outside 0.8-2.5" in s
            and "`rwadist diagnose` tries the candidates" in s], said
