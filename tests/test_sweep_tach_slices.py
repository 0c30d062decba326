"""A sweep read with its tach column is cut as finely as the chirp of its highest line asks, as without it (session
56's new-user trial: a 40-s run-up 300 -> 6000 rpm, fastest at its start, cut into 8192-sample slices with its tach
and 2048 without; with the tach the rocking mode 3.5 % low, a spin acceleration and a line invented, the error 48
times the same data's without the tach column).

Data: family wheel 2 (tests/family_wheel.py, time-integrated physics) run up over 40 s at a motor's exponential speed
(:func:`family_wheel.speed_profile` "exp": its fastest change at the start), written with and without its tach."""
import sys
import warnings
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402


@pytest.mark.slow
def test_a_run_up_read_with_its_tach_is_diagnosed_as_well_as_without_it(tmp_path):
    """``rwadist.diagnose`` (no model) of the run-up with its tach column: the slices' highest line sweeps at most
    2 bins of a Welch segment (the rule says so), every suspension mode located within 2 % (a damping may be declared
    held: the translation's ζ 0.0099, held within 5e-5-0.0164, on every OpenBLAS kernel), and the error within
    twice that of the same file without the tach column (on main: 19 slices against 37, the translation and rocking
    modes 14x and 27x off, the error 0.205 against 0.0088)."""
    from rwadist import api

    wheel = fw.family()[2]
    data = fw.sweep(wheel, wheel.min_rpm, wheel.max_rpm, 40.0, seed=2, profile="exp")
    got = {}
    for tach in (True, False):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            test = api.read(fw.write_sweep(data, tmp_path / f"run_up_{tach}.csv", tach=tach))
            got[tach] = (test, api.diagnose(test))
    test, d = got[True]
    slicing = test.meta["slicing"]
    assert slicing["speed_source"] == "tach" and "chirp" in slicing["slice_rule"], slicing["slice_rule"]
    sm = next(e for e in d.model.effects if e["kind"] == "suspension_modes")
    # every mode located (its damping may be declared held: ζ_trans 0.0099 of a 40-s run-up's slices)
    assert not [m for m in sm.get("unconstrained") or [] if not m.startswith("zeta_")], sm.get("unconstrained")
    for m, f in wheel.modes_hz().items():
        assert abs(sm[f"{m}_Hz"] / f - 1) < 0.02, (m, sm[f"{m}_Hz"], f)
    assert d.error_after < 2.0 * got[False][1].error_after, (d.error_after, got[False][1].error_after)
