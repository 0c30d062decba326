"""A calibration matrix missing one force-to-moment term (Ty_measured = Ty + k·Fx, Tx untouched) against a load-cell
offset (T_measured = T + r × F: Ty = r_z·Fx AND Tx = −r_z·Fy), on a wheel generated without rwadist's physics
(tests/standmodes_wheel.py) shaped like trial15's (9 kg, I_zz/I_rr 1.95, modes 480/70/220 Hz, 1000-9000 rpm).

The one term is a copy of Fx in Ty (:func:`rwadist.diagnose.channel_copy.find_channel_copies`, with κ = k: the
generator's own constant, nothing fitted); both terms of r × F are an offset, left to ``cross_coupling`` (no copy).
Before, every lever-arm pair was left to ``cross_coupling``, which cannot hold one term alone: trial15's crosstalkT
(k = 5 mm) lost the modes and named a 475 Hz 'wheel mode' and two amplitude laws."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import standmodes_wheel as sw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.diagnose.channel_copy import find_channel_copies  # noqa: E402
from rwadist.diagnose.engine import Context  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402

#: trial15's wheel shape (its generator is not in the repository): 9 kg, I_zz/I_rr 1.95, 480/70/220 Hz
WHEEL = sw.bearing_wheel("trial15-like", mass=9.0, inertia_ratio=1.95, radius=0.13, f_trans=480.0, f_rock=70.0,
                         f_axial=220.0, zeta=(0.02, 0.015, 0.025), u_s=5e-6)
SPEEDS = np.linspace(1000.0, 9000.0, 25)


def _test(seed: int, n_samples: int = 8192):
    test, _ = sw.generate(WHEEL, SPEEDS, sample_rate=10000.0, n_samples=n_samples, noise=0.002, seed=seed)
    return test


def _add(test, terms):
    """``terms``: (target, source, k) each: target += k·source (the forces as generated, read before any term)."""
    for run in test.runs:
        src = {c: run.signals[c].copy() for c in ("Fx", "Fy", "Fz")}
        for target, source, k in terms:
            run.signals[target] = run.signals[target] + k * src[source]
    return test


def _copies(test):
    return find_channel_copies(Context(compute_spectra(test, nperseg=2048), None, test))


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("target, source, k", [("Ty", "Fx", 0.005), ("Ty", "Fx", 0.0005), ("Tx", "Fy", -0.002)])
def test_one_force_to_moment_term_is_a_copy_at_its_gain(seed, target, source, k):
    copies = _copies(_add(_test(seed), [(target, source, k)]))
    assert [(c.source, c.target) for c in copies] == [(source, target)]
    # κ is the generator's real constant: within 3 % of it, gain, sign and phase (the 0.5 mm copy stands ~20 dB over
    # Ty's noise on its clean lines, the cage and twice the outer ball pass)
    assert abs(copies[0].kappa - k) <= 0.03 * abs(k)


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("r_z", [0.02, -0.005])
def test_both_terms_of_an_offset_are_no_copy(seed, r_z):
    # r × F with r = (0, 0, r_z): Tx −= r_z·Fy, Ty += r_z·Fx -- the cross_coupling class's, not a copy
    copies = _copies(_add(_test(seed), [("Tx", "Fy", -r_z), ("Ty", "Fx", r_z)]))
    assert [c for c in copies if c.target in ("Tx", "Ty", "Tz")] == []


@pytest.mark.slow
@pytest.mark.parametrize("seed", [4, 5])
def test_one_term_crosstalk_keeps_the_modes_on_the_default_path(seed):
    """`diagnose` with no model: the copy described (Ty = k·Fx, taken out before the search), every mode within 2 %,
    I_zz/I_rr within 0.02, nothing named but the modes (before: no modes, a 'wheel mode' and amplitude laws)."""
    k = 0.002
    d = api.diagnose(_add(_test(seed, 16384), [("Ty", "Fx", k)])).summary()
    assert [e["kind"] for e in d["effects"]] == ["suspension_modes"]
    modes = d["effects"][0]
    for mode, f in WHEEL.truth_hz.items():
        assert modes[f"{mode}_Hz"] == pytest.approx(f, rel=0.02), mode
    assert modes["inertia_ratio"] == pytest.approx(WHEEL.inertia_ratio, abs=0.02)
    copies = [u for u in d["unexplained"] if u["signature"] == "channel_copy"]
    assert [(u["parameters"]["source"], u["parameters"]["target"]) for u in copies] == [("Fx", "Ty")]
    assert copies[0]["parameters"]["gain"] == pytest.approx(k, rel=0.01)
