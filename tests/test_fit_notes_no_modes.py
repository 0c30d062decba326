"""The extended fit's notes on a wheel without modes (trial 29): a mode no line comes near is said to lie past the end of
the scanned range when the refined best point lies beyond it (not "909.7 Hz of 1.25-882.8 Hz"), and a line whose
freed exponent moves it less than 1 dB over its speeds is not called a law."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist import api
from rwadist.empirical import fit_empirical
from rwadist.extended_fit import fit_extended
from rwadist.off_law_lines import OFF_LAW_NOTE_DB, off_law_note
from rwadist.spectra import compute_spectra


def _line(speed_lo: float, speed_hi: float):
    return SimpleNamespace(direction="axial_force", h=2.96, speed=np.linspace(speed_lo, speed_hi, 12))


@pytest.mark.parametrize("shift, span, law", [(-0.01, 8.0, False), (-0.06, 8.0, True), (0.04, 1.5, False),
                                              (1.0, 1.5, True)])
def test_a_freed_exponent_is_called_a_law_when_it_moves_the_line_a_decibel(shift, span, law):
    # the change over the speeds, in closed form: 20·|p − 2|·log10(Ω_max/Ω_min) dB
    change_db = 20 * abs(shift) * np.log10(span)
    assert (change_db >= OFF_LAW_NOTE_DB) == law
    note = off_law_note(_line(30.0, 30.0 * span), shift, 0.002)
    assert note.startswith("axial_force h=2.96: ")
    assert ("grows as" in note) == law and ("not as C·Ω²" in note) == law
    assert f"|Ω|^{2 + shift:.3g}" in note
    if not law:
        assert f"within {change_db:.1g} dB of C·Ω²" in note


def test_a_wheel_without_modes_fitted_extended_names_no_law_and_no_frequency_outside_its_range():
    test = api.simulate_test("ithaco-e", np.linspace(300, 2400, 16), modes=False, n_samples=4096, seed=2)
    efit = fit_extended(test, fit_empirical(compute_spectra(test)))
    scanned = [n for n in efit.notes if "of the scanned range" in n]
    assert scanned                               # no line comes near the radial modes (the preset's 670 Hz start)
    for note in efit.notes:
        assert "grows as" not in note            # the data are C·Ω² exactly: no law
        if "of the scanned range" in note:
            text = note.split("scanned range ")[1]
            lo, hi = (float(v) for v in text.split(" Hz")[0].split("-"))
            at = float(text.split(", at ")[1].split(" Hz")[0])
            assert ("past the" in note) == (not lo <= at <= hi)
