"""A line a fast sweep smears across a segment is one line, not two or three.

A new user's 2.5-kg wheel run up 400 -> 4000 rpm in 40 s (session 63): its torque line h 9.407 swept 15 bins across a
4096-sample segment of the slices, read as a rippled plateau with several peaks.  The empirical fit's candidates at
h 9.379 and 9.404 (0.026 apart, beyond its ε 0.02) were both kept apart, each "not resolved" in the other's window,
and the extended fit's close-line reading measured both and added their mirror: three lines (9.3785, 9.4044, 9.4303,
each C ~1e-8 for the truth's one of 2e-8) in ``rwadist diagnose``'s model.  Two lines closer than the relative speed
change over a segment times h overlap on every segment's spectrum (:func:`rwadist.empirical.identify_harmonics`).

Data: family wheel 7 (tests/family_wheel.py, time-integrated physics), run up over 30 s, written with its tach
column; before, its axial 2xBPFO line (h 6.848) came out at 6.8267, 6.8495 and 6.8722."""
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402


def test_a_smeared_line_of_a_fast_run_up_is_one_line(tmp_path):
    """``rwadist.fit_extended`` of the run-up: no two lines of a direction closer than 0.06 in h (a co and a counter
    part of one line share their h exactly), and the axial 2xBPFO line once, within 20 % of the generator's C."""
    from rwadist import api

    wheel = fw.family()[7]
    data = fw.sweep(wheel, wheel.min_rpm, wheel.max_rpm, 30.0, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(data, tmp_path / "run_up.csv", tach=True))
        _, model = api.fit_extended(test)
    for d in ("radial_force", "radial_torque", "axial_force"):
        hs = np.array(sorted(x.h for x in model.harmonics(d)))
        gaps = np.diff(hs)
        assert not np.any((gaps > 0) & (gaps < 0.06)), (d, hs)
    truth = next(ln for ln in wheel.lines if ln.direction == "axial_force" and ln.name == "2xBPFO")
    got = [x for x in model.harmonics("axial_force") if abs(x.h - truth.h) < 0.1]
    assert len(got) == 1 and abs(got[0].h / truth.h - 1) < 0.002, got
    assert abs(got[0].C / truth.C - 1) < 0.2, (got[0].C, truth.C)
