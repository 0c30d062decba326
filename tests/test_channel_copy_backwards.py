"""A copy found on the lines is not found again read backwards on the noise floor.

Trial 33 (an independent generator, Fz += 0.1·Fx, Fx's sensor noise too, every force sensor as noisy): the lines gave
"Fz reads 0.0995 × Fx", and the floor gave "Fx reads 0.0972 × Fz" beside it, taken out of Fx before the search.  The
target's floor carries the source's noise κ times, so regressed the other way the source's floor reads
κ·σ_s²/(σ_t² + κ²σ_s²) of the target's: the same copy read backwards (:func:`rwadist.diagnose.channel_copy._floor_copies`).

Data made here with numpy: 36 steady runs over 500-5000 rpm (4 kHz, 4 s), co-rotating radial lines h 1, 2, 3.27, 4.1
and 5.18, Fz lines of its own at h 1 and 3.27, white noise of one level on the forces and a tenth of it on the
torques, then Fz += 0.1·Fx on the records.  Before: the copy on the lines h 2 and 4.1 (κ 0.103 / 0.095) and "Fx =
0.0996 × Fz" on the floor beside it (z 12.2).  One copy, Fx → Fz, at κ within 5 % (the lines' estimate)."""
import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.channel_copy import find_channel_copies
from rwadist.diagnose.engine import Context
from rwadist.spectra import compute_spectra

KAPPA = 0.1
FS, N = 4000.0, 16000
#: the radial lines (h, C of the force, C of the torque; N/(rad/s)², N·m/(rad/s)²), co-rotating
LINES = ((1.0, 2.5e-6, 2e-7), (2.0, 4e-7, 0.0), (3.27, 8e-8, 1.6e-8), (4.1, 2e-7, 0.0), (5.18, 1e-7, 0.0))


def _copied(seed: int) -> SteadyTest:
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    runs = []
    for rpm in np.linspace(500.0, 5000.0, 36):
        om = rpm * 2 * np.pi / 60
        sig = {c: 0.05 * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz")}
        sig.update({c: 0.005 * rng.standard_normal(N) for c in ("Tx", "Ty", "Tz")})
        for h, c_force, c_torque in LINES:
            ph = rng.uniform(0, 2 * np.pi)
            for (cx, cy), c in ((("Fx", "Fy"), c_force), (("Tx", "Ty"), c_torque)):
                sig[cx] += c * om**2 * np.cos(h * om * t + ph)
                sig[cy] += c * om**2 * np.sin(h * om * t + ph)
        for h, c in ((1.0, 1e-6), (3.27, 2e-8)):
            sig["Fz"] += c * om**2 * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
        sig["Fz"] = sig["Fz"] + KAPPA * sig["Fx"]
        runs.append(Run(float(om), FS, sig, name=f"r{rpm:.0f}.csv"))
    return SteadyTest(runs)


@pytest.mark.parametrize("seed", [1, 2])
def test_a_force_copied_into_a_force_as_noisy_is_one_copy(seed):
    test = _copied(seed)
    copies = find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))
    assert [(c.source, c.target) for c in copies] == [("Fx", "Fz")]
    assert abs(copies[0].kappa) == pytest.approx(KAPPA, rel=0.05)
