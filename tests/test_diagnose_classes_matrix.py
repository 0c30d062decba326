"""The robustness matrix (benchmarks/diagnose_matrix.py) counts a class FOUND only when diagnose names the
injected effect itself: an effect of the same kind on another line (a missing harmonic at h 5.5 while h 0.5 was
injected, a law on h = 4.42 while h = 2 follows Ω³) is an addition beside it, and a miss of the injection."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import diagnose_matrix as matrix  # noqa: E402

from rwadist.inject import parse  # noqa: E402


def test_found_means_the_injected_line():
    mh = parse(matrix.SPECS["missing_harmonic"])
    assert matrix._matches({"kind": "missing_harmonic", "direction": "radial_force", "h": 0.5003}, "missing_harmonic", mh)
    assert not matrix._matches({"kind": "missing_harmonic", "direction": "radial_force", "h": 5.499},
                               "missing_harmonic", mh)
    assert not matrix._matches({"kind": "missing_harmonic", "direction": "axial_force", "h": 0.5},
                               "missing_harmonic", mh)
    law = parse(matrix.SPECS["amplitude_law"])
    assert matrix._matches({"kind": "amplitude_law", "direction": "radial_force", "h": 2.0}, "amplitude_law", law)
    assert not matrix._matches({"kind": "amplitude_law", "direction": "radial_force", "h": 4.42}, "amplitude_law", law)
    sb = parse(matrix.SPECS["sidebands"])
    assert matrix._matches({"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 7.01}, "sidebands", sb)
    assert not matrix._matches({"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 11.0},
                               "sidebands", sb)
    floor = parse(matrix.SPECS["broadband_floor"])
    assert matrix._matches({"kind": "broadband_floor", "channel": ["Fy"]}, "broadband_floor", floor)
    assert not matrix._matches({"kind": "broadband_floor", "channel": ["Ty"]}, "broadband_floor", floor)
    # a speed-sidebands injection (kind sidebands in rwadist.inject) is matched by the speed_sidebands record
    assert matrix._matches({"kind": "speed_sidebands", "h": 1.0}, "speed_sidebands", parse(matrix.SPECS["speed_sidebands"]))
