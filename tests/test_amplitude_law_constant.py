"""A line of constant amplitude at a ratio of the speed (a motor's cogging torque, a pickup locked to the rotor angle)
is an amplitude law of exponent 0 (rwadist.effects.amplitude_law_diagnose: an exponent fitted below 0 within its
errors is fitted as 0, the least the model file takes).

The new-user trial of session 54 (its own generator: a 2.5 kg wheel, a Tz line at h 24 of 5 mN·m at every speed from
1000 to 9000 rpm) had p = −0.002 ± 0.003 fitted on 4 of 6 seeds: no law was proposed (exponents below 0 were refused
outright), and the base kept C·Ω², 18x low at the lowest speed and 20 % high at the top, its C "known to 0.3 %".  Here
the family generator's wheels (tests/family_wheel.py, the matrix's conditions) with such a line added on the axial
force, its amplitude that of the wheel's axial 1x at the middle speed."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import diagnose_family_matrix as dfm  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


def _with_constant_line(index: int, seed: int = 1):
    """(test, h, amplitude N) of family wheel ``index`` with an axial-force line of constant amplitude at h, a third
    of the way to the anti-alias cut at its top speed, 0.15 or more from every other axial line."""
    wheel = dfm.wheels()[index]
    noise = dfm.CONDITIONS[index][2]
    top = wheel.max_rpm * fw.RPM
    h = round(0.3 * fw.ANTI_ALIAS * 2 * np.pi * wheel.sample_rate / top, 2)
    while any(abs(h - ln.h) < 0.15 for ln in wheel.lines):
        h = round(h + 0.17, 2)
    mid = 0.5 * (wheel.min_rpm + wheel.max_rpm) * fw.RPM
    amplitude = wheel.imbalance("axial_force") * mid**2
    line = fw.Line("axial_force", h, amplitude / mid**2, name="constant", exponent=0.0, omega_ref=mid)
    data = fw.steady(fw.with_lines(wheel, tuple(wheel.lines) + (line,)), noise=noise, seed=seed)
    return family_test.steady_test(data), h, amplitude


@pytest.mark.slow
@pytest.mark.parametrize("index", [1, 4, 6])
def test_a_line_of_constant_amplitude_is_a_law_of_exponent_zero(index):
    test, h, amplitude = _with_constant_line(index)
    diag = api.diagnose(test)
    laws = [e for e in diag.effects if e.kind == "amplitude_law"]
    assert [round(e.h, 1) for e in laws] == [round(h, 1)], (h, [(e.h, e.exponent) for e in laws])
    (law,) = laws
    assert law.direction == "axial_force" and 0.0 <= law.exponent <= 0.05, law
    at = law.amplitude_ref                # a law of exponent ~0: its amplitude at the reference is that at every speed
    assert abs(at / amplitude - 1) < 0.05, (at, amplitude)
    assert {e.kind for e in diag.effects} <= {"suspension_modes", "amplitude_law"}, [e.kind for e in diag.effects]
