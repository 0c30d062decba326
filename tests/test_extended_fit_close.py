"""Close lines the empirical fit detected but could not measure apart, measured together on each whole record
(:mod:`rwadist.extended_fit_close`).

Independent references: records written out here (cosines of known amplitude and frequency plus white noise, no
rwadist), and an E-like wheel generated without rwadist's physics (tests/standmodes_wheel.py) with speed sidebands at
0.94 and 1.06 x the speed beside its imbalance, which the empirical fit detects and measures none of (the imbalance
included): the three lines measured at their h to 0.002 and their amplitudes in the generator's ratios.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
import standmodes_wheel as sw  # noqa: E402

from rwadist.dft import hann_transform, run_window, windowed_dfts, windowed_records  # noqa: E402
from rwadist.empirical import fit_empirical  # noqa: E402
from rwadist.extended_fit import fit_extended  # noqa: E402
from rwadist.extended_fit_close import chirp_transform, close_lines  # noqa: E402
from rwadist.spectra import compute_spectra  # noqa: E402


def test_lines_a_bin_apart_are_the_cosines_written():
    """Three cosines 1.3 record bins apart, the middle one 5 x stronger, in white noise 60 dB down: the least squares
    of the windowed transform on quarter-bin steps (the module's model, Σ_j (A_j/2)·W(f − f_j)) gives each amplitude to
    1e-3 and its phase to 1e-3 rad."""
    rng = np.random.default_rng(3)
    n, fs = 4096, 5000.0
    t = np.arange(n) / fs
    b = fs / n
    f = np.array([100.0, 100.0 + 1.3 * b, 100.0 + 2.6 * b]) + 0.37 * b
    amp, ph = np.array([0.2, 1.0, 0.25]), rng.uniform(0, 2 * np.pi, 3)
    x = sum(a * np.cos(2 * np.pi * fj * t + p) for a, fj, p in zip(amp, f, ph)) + 1e-3 * rng.standard_normal(n)
    grid = np.arange(f[0] - 2 * b, f[-1] + 2 * b, 0.25 * b)
    X = windowed_dfts(windowed_records([[x]], run_window("hann", n)[0]), fs, grid[None, :])[0][:, 0]
    M = 0.5 * hann_transform(n, fs, grid[:, None] - f[None, :])
    A = np.linalg.lstsq(M, X, rcond=None)[0]
    assert np.allclose(np.abs(A), amp, rtol=2e-3)
    assert np.allclose(np.angle(A * np.exp(-1j * ph)), 0.0, atol=2e-3)


@pytest.mark.parametrize("n_samples", [8192, 4096])
def test_speed_sidebands_beside_the_imbalance_are_measured(n_samples):
    """E-like wheel, 300-2400 rpm, sidebands 0.94/1.06 of depth 0.4 (each 0.2 of the imbalance): the empirical fit
    resolves none of the three (2.4 Hz apart at 2400 rpm; on 4096 samples it detects no upper side at all, found as the
    mirror of the lower); measured together, each h within 0.002 and each side's
    amplitude 0.2 of the carrier's within 10 %; the extended fit's imbalance U_s then within 2 % of the generator's."""
    test, _ = sw.generate(sw.E_WHEEL, np.linspace(300.0, 2400.0, 24), sample_rate=5000.0, n_samples=n_samples,
                          noise=0.01, seed=7, speed_sidebands=("radial_force", 1.0, 0.06, 0.4))
    fit = fit_empirical(compute_spectra(test)).without_mode_exclusion
    assert not any(x.direction == "radial_force" and abs(x.h - 1.0) < 0.1 for x in fit.lines)
    got = {round(x.h, 3): x for x in close_lines(test, fit) if x.direction == "radial_force" and x.h < 2}
    hs = sorted(got)
    assert len(hs) == 3 and np.allclose(hs, [0.94, 1.0, 1.06], atol=0.002), hs
    lo, c, hi = (got[h] for h in hs)
    for side in (lo, hi):
        assert side.C / c.C == pytest.approx(0.2, rel=0.1)
    efit = fit_extended(test, fit_empirical(compute_spectra(test)))
    assert efit.params.U_s == pytest.approx(sw.E_WHEEL.C("radial_force", 1.0), rel=0.02)


@pytest.mark.parametrize("c", [18.0, -7.5])
def test_a_chirped_line_is_the_chirp_written(c):
    """A cosine whose frequency moves linearly by ``c`` record bins across the record (a line of a sweep's slice;
    negative: a run-down), in white noise 60 dB down: the chirp's windowed transform equals the direct sum
    Σ w[m]·e^{jπc(m/n − ½)²}·e^{−2πjδm/n} to 1e-3 of its peak between the nodes of its table, and the least squares
    with it gives the amplitude to 1e-3, where the steady line's kernel reads it far short."""
    rng = np.random.default_rng(5)
    n, fs = 4096, 5000.0
    b = fs / n
    t = np.arange(n) / fs
    f0 = 300.0 + 0.3 * b                              # the mean frequency, at the record's middle
    k = c * b / (n / fs)                              # Hz/s
    x = 0.8 * np.cos(2 * np.pi * (f0 * (t - t[n // 2]) + 0.5 * k * (t - t[n // 2]) ** 2) + 1.1)
    x = x + 1e-3 * rng.standard_normal(n)
    # the grid off the kernel's table nodes (1/64 bin apart) by 0.37 of a node
    grid = np.arange(f0 - (abs(c) / 2 + 2) * b, f0 + (abs(c) / 2 + 2) * b, 0.25 * b) + 0.37 / 64 * b
    kern = chirp_transform(n, fs, grid - f0, c)
    m = np.arange(n)
    w = run_window("hann", n)[0]
    direct = np.exp(-2j * np.pi * np.outer((grid - f0) / b, m) / n) @ (w * np.exp(1j * np.pi * c * (m / n - 0.5) ** 2))
    assert np.max(np.abs(kern - direct)) < 1e-3 * np.max(np.abs(direct))
    X = windowed_dfts(windowed_records([[x]], w), fs, grid[None, :])[0][:, 0]
    amp = abs(np.linalg.lstsq(0.5 * kern[:, None], X, rcond=None)[0][0])
    steady = abs(np.linalg.lstsq(0.5 * hann_transform(n, fs, grid - f0)[:, None], X, rcond=None)[0][0])
    assert amp == pytest.approx(0.8, rel=1e-3)
    assert steady < 0.9 * 0.8


@pytest.mark.slow
@pytest.mark.parametrize("wheel_index, way, seed, direction, h_true", [
    (1, "up", 1, "axial_force", 6.66), (0, "down", 1, "radial_torque", 4.92), (4, "up", 7, "radial_force", 6.09)])
def test_a_line_smeared_over_a_fast_sweeps_record_is_held_once(tmp_path, capsys, wheel_index, way, seed,
                                                               direction, h_true):
    """Family wheels (tests/family_wheel.py: their own time integration) swept in 30 s without a speed column and
    diagnosed by the command a user types: a bearing line that moves over ~22 record bins of a slice (h·dΩ/dt·T²/2π)
    was read by the close-line least squares as three lines 0.4 % apart (wheel 1: axial 6.631 / 6.654 / 6.678 for
    6.66; wheel 0's run-down: radial torque 4.90 / 4.92 / 4.94).  Now every model line is within 0.2 % of one of the
    generator's, none twice (one direction and sense within 3 %), and that line once, its C within 10 % of the
    generator's; and no effect class is added to these clean sweeps but the wheel's own (its modes, the sweep's spin
    acceleration, its lines' counter-rotating parts).  Wheel 4 (6.09 and 6.38, 0.02 apart in h at 3840 Hz, read 5-6 %
    low by the search before) then had a broadband floor on Fy named: its held-out growth was the empirical start's
    noise, 440x the data's in the bands where the mode's lines overshoot the data (rwadist/effects/
    broadband_floor_diagnose.py, the null interpolated there from the bands beside)."""
    from rwadist.cli import main

    wheel = fw.family()[wheel_index]
    lo, hi = (wheel.min_rpm, wheel.max_rpm) if way == "up" else (wheel.max_rpm, wheel.min_rpm)
    csv = fw.write_sweep(fw.sweep(wheel, lo, hi, 30.0, noise=0.01, seed=seed), tmp_path / "sweep.csv", tach=False)
    assert main(["diagnose", str(csv), "-o", str(tmp_path / "r")]) == 0
    capsys.readouterr()
    model = json.loads((tmp_path / "r" / "model.json").read_text())
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    own = ("suspension_modes", "spin_acceleration", "counter_rotation")
    assert [e["kind"] for e in summary["effects"] if e["kind"] not in own] == []
    for d, rows in model["empirical"].items():
        truth = np.array([ln.h for ln in wheel.lines if ln.direction == d])
        for i, r in enumerate(rows):
            assert np.min(np.abs(r["h"] / truth - 1)) < 0.002, (d, r["h"])
            for q in rows[i + 1:]:
                assert r.get("sense", "co") != q.get("sense", "co") or abs(r["h"] / q["h"] - 1) >= 0.03, (d, r, q)
    held = [r for r in model["empirical"][direction] if abs(r["h"] / h_true - 1) < 0.03]
    true_C = [ln.C for ln in wheel.lines if ln.direction == direction and ln.h == h_true]
    assert len(held) == 1 and held[0]["C"] == pytest.approx(true_C[0], rel=0.1), held


def _span(h, lost, slope_rad_s2, speeds_rpm=(1000.0, 2000.0, 3000.0), n=8192, fs=8192.0):
    """A span of lines ``h`` (``lost`` the indices the fit did not measure) over runs of one-second records at
    ``speeds_rpm`` whose speed changes at ``slope_rad_s2`` (one per run, or one for all; the records themselves not
    needed by the merge)."""
    from rwadist.extended_fit_close import _Span

    span = object.__new__(_Span)
    span.h, span.lost = np.array(h, float), list(lost)
    slopes = np.broadcast_to(np.asarray(slope_rad_s2, float), (len(speeds_rpm),))
    span.runs = [(0, rpm * 2 * np.pi / 60, n, fs, [], None, None, float(a)) for rpm, a in zip(speeds_rpm, slopes)]
    return span


@pytest.mark.parametrize("slope", [30.0, 100.0])
def test_sidebands_beside_a_chirping_carrier_are_not_its_smear(slope):
    """Speed sidebands 0.94 / 1.06 beside a measured carrier on a sweep whose line chirps over 4.8-16 record bins:
    1-3 bins from the carrier, and the carrier's chirp differs from theirs by 0.3-1 bin, so the least squares
    tells them apart (the chirp taken off, a steady triple): none is merged into the carrier (the rule "apart by
    max(1, |c|) bins" had dropped both)."""
    span = _span([0.94, 1.0, 1.06], [0, 2], slope)
    span.merge_smeared()
    assert list(span.h) == [0.94, 1.0, 1.06] and span.lost == [0, 2]


def test_candidates_inside_one_smear_are_one_line_and_only_on_a_sweep():
    """Three lost candidates 0.002 apart in h (under a record bin at every speed) on a sweep whose lines chirp: one
    lost line at their mean; the same on steady runs, or on a sweep so slow its lines chirp 0.02 bin: left as they
    are (two lines the record cannot split are described, not merged)."""
    fast = _span([6.662, 6.658, 6.660, 5.0], [0, 1, 2], 30.0)
    fast.merge_smeared()
    assert fast.h == pytest.approx([6.660, 5.0]) and fast.lost == [0]
    for slope in (0.0, 0.05):
        slow = _span([2.999, 3.0, 3.001], [0, 2], slope)
        slow.merge_smeared()
        assert list(slow.h) == [2.999, 3.0, 3.001] and slow.lost == [0, 2]
    # two lost lines 0.03 apart that the fast, chirping runs do not measure apart, but the slow top of the run-up
    # does (a reviewer's case: merged when only the chirping runs were asked): two lines
    top = _span([3.0, 3.03], [0, 1], (30.0, 20.0, 0.3, 0.2), speeds_rpm=(1000.0, 1500.0, 3000.0, 3200.0))
    top.merge_smeared()
    assert list(top.h) == [3.0, 3.03] and top.lost == [0, 1]
