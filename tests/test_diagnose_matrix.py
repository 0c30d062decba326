"""A sample of the robustness matrix of ``rwadist diagnose`` on modes-on data (issue 14, item 5); the full
table is ``benchmarks/diagnose_matrix.py`` (its docstring defines the matrix: one factor at a time around a
nominal cell plus two corners).

The cheap cells (20 speeds): clean data get nothing beyond the wheel's own suspension modes, every mode
found within 2 % of the thesis numbers (tests/independent_wheel.py) or declared unconstrained (never a
silent wrong mode), and an injected amplitude law (h = 2 radial force as Ω³, a load on the rotor:
rwadist.inject sends it through the suspension modes) is named with its exponent.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import diagnose_matrix as matrix  # noqa: E402

CELLS = {c["name"]: c for c in matrix.cells()}


def test_the_matrix_is_one_factor_at_a_time_plus_corners():
    cells = matrix.cells()
    assert len(cells) == 1 + sum(len(v) - 1 for v in matrix.LEVELS.values()) + 2
    nominal = cells[0]
    for c in cells[1:-2]:                                   # exactly one factor off the nominal cell
        assert sum(c[k] != nominal[k] for k in matrix.LEVELS) == 1, c
    # every family the registry lists is either injected or said why not
    for kind in matrix.registry_kinds():
        spec, why = matrix.injection(kind)
        assert (spec is None) != (why is None), kind


@pytest.mark.parametrize("name", ["n_speeds=20", "corner-low"])
def test_clean_cell_adds_nothing_beyond_the_wheel_modes(name):
    r = matrix.evaluate(CELLS[name], "clean")
    assert r["extra"] == [], r
    assert r["modes"] != "no suspension_modes"
    assert not r["silent"], r["modes"]
    assert r["error"][1] < 0.02 * r["error"][0]          # the modes explain the data


def test_injected_amplitude_law_named():
    r = matrix.evaluate(CELLS["n_speeds=20"], "amplitude_law")
    assert r["found"], r
    assert r["extra"] == [], r
    assert not r["silent"], r["modes"]
    assert r["effect"]["h"] == pytest.approx(2.0, abs=0.01)
    assert r["effect"]["exponent"] == pytest.approx(3.0, rel=0.10)


# ---------------------------------------------------------------- the three classes added last (issue 14 item 4)
def test_hann_leakage_is_the_windows_closed_form():
    """The periodic Hann window's transform: 1 at the line's bin, 1/4 one bin off, 0 at every other whole bin."""
    got = matrix._hann_leakage(512, [0.0, 1.0, -1.0, 2.0, 3.0, -5.0, 0.5])
    assert got[:3] == pytest.approx([1.0, 0.25, 0.25], abs=1e-12)
    assert got[3:6] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    # half a bin off: |W(½)|²/W(0)² = (sinc(½)/(1 − ¼))² = (2/π · 4/3)² for the continuous Hann window
    assert got[6] == pytest.approx((8 / (3 * np.pi)) ** 2, rel=1e-3)


def test_line_to_noise_matches_a_welch_psd():
    """A²n/(6σ²), the signature measure's line-to-noise power in the line's bin, against scipy's Welch PSD of a
    bin-centred sinusoid in white noise (Hann, n = 1024, 50 % overlap)."""
    from scipy import signal

    rng = np.random.default_rng(3)
    fs, n, A, sigma = 1024.0, 1024, 0.05, 1.0
    t = np.arange(64 * n) / fs
    x = A * np.cos(2 * np.pi * 100.0 * t) + rng.normal(0.0, sigma, t.size)
    f, p = signal.welch(x, fs, window="hann", nperseg=n)
    floor = np.median(p)
    assert floor == pytest.approx(2 * sigma**2 / fs, rel=0.05)
    measured = (p[f == 100.0][0] - floor) / floor
    assert measured == pytest.approx(matrix._line_to_noise(A, sigma, n), rel=0.15)


def test_new_classes_found_on_the_model_path_where_eligible():
    """Path "model" (diagnose --model, the extended model fitted on the cell's clean reference run), cell
    n_speeds=20: the counter-rotating force content and the lever-arm noise transfer stand above the noise (by the
    injection truth) and are named, with q 0.3 and κ 1; clean data of the cell get nothing."""
    cell = CELLS["n_speeds=20"]
    clean = matrix.evaluate(cell, "clean", "model")
    assert clean["extra"] == [], clean
    assert not clean["silent"], clean["modes"]
    r = matrix.evaluate(cell, "counter_rotation", "model")
    assert r["eligible"] and r["found"], r
    assert r["extra"] == [], r
    assert r["effect"]["counter_fraction"] == pytest.approx(0.3, abs=0.01)
    r = matrix.evaluate(cell, "lever_arm_noise", "model")
    assert r["eligible"] and r["found"], r
    assert r["extra"] == [], r                      # the offset itself (cross_coupling, r_z -60 mm) is expected
    assert r["effect"]["noise_transfer"] == pytest.approx(1.0, rel=0.1)


def test_speed_sidebands_eligible_only_where_resolved_and_found_there():
    """At 3840 Hz and 2048 samples (1.9 Hz record bins) the 0.06·|Ω| sidebands sit inside the carrier's Hann main
    lobe at every speed up to 3000 rpm (not above the noise plus the carrier's leakage: not eligible); with 8192
    samples (0.47 Hz) they stand clear at the higher speeds, and diagnose --model names them at 0.94/1.06 with
    C/C_carrier 0.2 (the whole-run DFT: at the Welch bins of n/4 segments they are not resolved)."""
    short = CELLS["samples=2048"]
    test = matrix.generate(short, matrix.SPECS["speed_sidebands"])
    assert matrix.signature(short, "speed_sidebands", test)["eligible"] is False
    r = matrix.evaluate(CELLS["n_speeds=20"], "speed_sidebands", "model")
    assert r["eligible"] and r["found"], r
    assert r["extra"] == [], r
    e = r["effect"]
    assert e["h_lower"] == pytest.approx(0.94, abs=0.002) and e["h_upper"] == pytest.approx(1.06, abs=0.002)
    assert e["ratio_lower"] == pytest.approx(0.2, rel=0.1) and e["ratio_upper"] == pytest.approx(0.2, rel=0.1)


def test_counter_rotation_found_from_the_phase_at_coarse_bins():
    """Cell samples=2048 (7.5 Hz Welch bins): the fundamental's PSD window (±3 bins) lies in band in 2 runs only,
    but the line itself in 27 of 60 (the signature measure: eligible); the x/y phase needs only those, and
    diagnose --model names q = 0.3 (it found nothing before: the PSD route returned None below 3 points)."""
    r = matrix.evaluate(CELLS["samples=2048"], "counter_rotation", "model")
    assert r["eligible"] and r["found"], r
    assert r["effect"]["counter_fraction"] == pytest.approx(0.3, abs=0.01)


def test_corner_low_on_the_model_path_does_not_crash():
    """corner-low (300-2400 rpm, 20 speeds, 2048 samples, 1 kHz, 0.1 % noise) with the reference model: the
    broadband-floor candidate of Fz met bands whose off-line data sit at the model's axial-mode skirts (fitted
    noise 0) and set the floor there to 0, and every noise-relative measure after it divided by zero
    (``ValueError: Residuals are not finite``).  Now it runs; the modes stay where they are."""
    r = matrix.evaluate(CELLS["corner-low"], "clean", path="model")
    assert "crashed" not in r, r
    assert not r["silent"], r["modes"]
