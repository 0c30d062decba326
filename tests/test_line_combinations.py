"""A model line at the sum or difference of two stronger lines of its direction is said to be one
(rwadist.bearings._combinations): one line modulating the other, or a nonlinearity that carries both.

The new-user trial (session 51, an independent generator): a quadratic nonlinearity on Fz made lines at 3.22 =
3.63 − 0.41 and 4.04 = 3.63 + 0.41, which were named ball passes of 8- and 10-ball bearings with no word of the
combination.  Here the closed form: x = a·cos(ω_a t) + b·cos(ω_b t) through y = x + β·x² holds the lines at ω_a ± ω_b
(with 2ω_a, 2ω_b), read from a periodogram, and the causes of each name the pair."""
import numpy as np
import pytest

from rwadist.bearings import line_causes


def test_the_sum_and_difference_lines_of_a_quadratic_channel_are_named_combinations():
    fs, n, f_spin = 4096.0, 1 << 15, 50.0
    t = np.arange(n) / fs
    h_a, h_b = 3.63, 0.41
    x = np.cos(2 * np.pi * h_a * f_spin * t) + 0.5 * np.cos(2 * np.pi * h_b * f_spin * t)
    y = x + 0.1 * x**2
    spec = np.abs(np.fft.rfft(y * np.hanning(n))) / n
    f = np.fft.rfftfreq(n, 1 / fs)
    peaks = [k for k in range(2, f.size - 2) if spec[k] == spec[k - 2:k + 3].max() and spec[k] > 1e-4]
    h = {round(f[k] / f_spin, 2): float(spec[k]) for k in peaks}
    res = 2 * fs / n / f_spin                                     # two bins, in h
    assert {3.22, 4.04, 3.63, 0.41} <= set(h)
    for combo, word in ((3.22, "difference"), (4.04, "sum")):
        parents = [o for o, a in h.items() if a > h[combo]]
        causes = line_causes(combo, res, (), sorted(h), parents)
        assert causes[0].startswith(f"the {word} of the lines h = 3.63 and 0.41")
    # the strongest line is no combination of weaker ones, whatever their ratios add up to
    parents = [o for o, a in h.items() if a > h[3.63]]
    assert not any("sum of the lines" in c or "difference of the lines" in c
                   for c in line_causes(3.63, res, (), sorted(h), parents))


def test_a_line_no_two_stronger_lines_add_up_to_is_no_combination():
    causes = line_causes(3.3, 0.002, (), [0.4, 2.0, 1.0], [0.4, 2.0, 1.0])
    assert not any("of the lines h =" in c for c in causes)
    assert line_causes(2.4, 0.002, (), [0.4, 2.0], [0.4, 2.0])[0].startswith("the sum of the lines h = 2 and 0.4") \
        or any("sum of the lines h = 2 and 0.4" in c for c in line_causes(2.4, 0.002, (), [0.4, 2.0], [0.4, 2.0]))


@pytest.mark.parametrize("ratio, noted", [(2.001, False), (2.0, False), (2.2, True)])
def test_an_inertia_ratio_read_at_a_discs_two_is_no_flexible_rotor(ratio, noted):
    """A disc's I_zz/I_rr = 2 read as 2.001 from the whirls (the new-user trial) is printed without the note that no
    rigid rotor exceeds 2; 2.2 keeps it."""
    from rwadist.effects.suspension_modes import SuspensionModes

    e = {"radial_translation_Hz": 300.0, "rocking_Hz": 60.0, "axial_Hz": 120.0, "zeta_radial_translation": 0.02,
         "zeta_rocking": 0.03, "zeta_axial": 0.02, "inertia_ratio": ratio}
    assert ("which no rigid rotor" in SuspensionModes.describe(e)) is noted
