"""Reports a review can sign (issue 36 item 3), each checked on the figure or the file: summary.md of an extended fit
reports the extended model; every stated uncertainty says what it covers, with the model-form error beside the
statistical one; the NASTRAN deck holds the full 6x6 by default (or names the coherence left out); waterfall markers
leave the measured ridges visible and the lines carry their h; every plot's title gives its band, the PSD's each
wheel's law; a model file carries the rwadist version, the date and its data."""
from __future__ import annotations

import csv
import datetime
import json

import numpy as np
import pytest

import rwadist
from rwadist.cli import main


@pytest.fixture(scope="module")
def extended_fit(tmp_path_factory):
    """A small test through the extended physics, its empirical and extended fits, and the report of both."""
    from rwadist.report import write_report
    from rwadist.report_extended import write_extended_report

    out = tmp_path_factory.mktemp("ext")
    test = rwadist.simulate_test("ithaco-e", np.linspace(300.0, 2400.0, 24), n_samples=2048, physics="extended",
                                 seed=3)
    fit = rwadist.fit(test)
    efit, model = rwadist.fit_extended(test, fit, preset="ithaco-e")
    files = write_report(fit, out)
    files += write_extended_report(efit, fit, out, model=model, report_files=files)
    return fit, efit, model, out, files


def test_extended_summary_reports_the_extended_model(extended_fit):
    """summary.md of `fit --extended` was titled "Empirical fit report", gave the empirical model's RMS ratios,
    nothing of the modes or of the extended model's error, and listed none of the extended_* files."""
    fit, efit, model, out, files = extended_fit
    md = (out / "summary.md").read_text()
    assert md.startswith("# Extended fit report")
    for mode in ("radial_translation", "rocking", "axial_translation"):
        assert f"| {mode} | " in md
    rows = [ln for ln in md.splitlines() if ln.startswith("| radial_force | ") and ln.count("%") == 3]
    assert rows, "the extended model's error table"
    every = float(rows[0].split("|")[2].strip().rstrip(" %"))
    from rwadist.extended_fit import rms_comparison

    c = rms_comparison(efit, fit)["radial_force"]
    ok = c["data"] > 0
    expect = 100 * np.sqrt(np.mean(((c["extended"][ok] - c["data"][ok]) / c["data"][ok]) ** 2))
    assert every == pytest.approx(expect, rel=0.05)
    extended_files = [p.name for p in files if p.name.startswith("extended_")]
    assert len(extended_files) >= 4 and all(f"`{n}`" in md for n in extended_files)
    assert f"{sum(len(v) for v in model.empirical.values())} forcing lines" in md
    assert md.count("`summary.md`") == 1


def _pure_line(noise: float = 0.0):
    from rwadist.empirical import LineFit

    w = np.linspace(50.0, 250.0, 30)
    rng = np.random.default_rng(0)
    d = 2e-6 * w**2 * (1 + noise * rng.standard_normal(w.size))
    return LineFit("radial_force", 1.0, 2e-6, 1e-9, 2e-6, w, np.array(["Fx"] * w.size), d, np.ones(w.size, bool),
                   [], 1.0, w.size)


def test_model_form_error_is_zero_for_a_pure_law_and_grows_with_amplification():
    """The held-out error of C·Ω²: a line that is exactly C·Ω² predicts its held-out speeds exactly; a line lifted
    by a mode as the speed rises (|H| = 1/(1 - (Ω/Ω_n)²)) does not."""
    from rwadist.report import model_form_error

    assert model_form_error(_pure_line()) == pytest.approx(0.0, abs=1e-12)
    line = _pure_line()
    line.amplitude = line.amplitude / (1 - (line.speed / 400.0) ** 2)
    lifted = model_form_error(line)
    # independent: C on the even speeds (Eq. 3.10's weights on the power), its error at the odd ones (and the
    # reverse), the larger
    w, d = line.speed, line.amplitude
    errs = []
    for a, b in ((slice(0, None, 2), slice(1, None, 2)), (slice(1, None, 2), slice(0, None, 2))):
        C = np.sqrt(np.sum(d[a] ** 2) / np.sum(w[a] ** 4))
        errs.append(np.sqrt(np.mean((d[b] - C * w[b] ** 2) ** 2)) / np.sqrt(np.mean((C * w[b] ** 2) ** 2)))
    assert lifted == pytest.approx(max(errs), rel=1e-12) and lifted > 0.01


def test_every_uncertainty_says_what_it_covers(extended_fit):
    """Coefficient plots stated "± 0.23 % (2σ)" of the noise alone beside errors of +1.2 … +4.4 % against truth."""
    from rwadist.report import UNCERTAINTY_NOTE, plot_coefficients

    fit, _, _, out, _ = extended_fit
    fig, axes = plot_coefficients(fit.lines, "radial_force")
    titles = [ax.get_title() for ax in axes]
    assert all("(2σ noise)" in t for t in titles if "±" in t)
    assert sum("(model form)" in t for t in titles) >= 1
    assert UNCERTAINTY_NOTE[:40] in fig.legends[0].get_title().get_text().replace("\n", " ")
    md = (out / "summary.md").read_text()
    assert "±2σ noise" in md and "held-out (model form)" in md and "Neither covers" in md
    rows = list(csv.DictReader((out / "harmonics.csv").open()))
    assert "heldout_rel" in rows[0]


def test_waterfall_markers_leave_the_ridge_visible_and_lines_carry_h(extended_fit):
    """Markers centred on the lines hid the measured ridges; the lines were not labelled by h.  Now each line is
    marked by two ticks either side, RIDGE_CLEARANCE_PX or more from it in the saved figure, and no tick sits on
    another line's ridge unless the two lines are too close to tell apart (within two clearances)."""
    from rwadist import compare
    from rwadist.report import _DPI, RIDGE_CLEARANCE_PX, plot_waterfall

    fit, _, _, _, _ = extended_fit
    fig, ax = plot_waterfall(fit.spectra, "Fx", model=fit.model, lines=fit.lines)
    lo, hi = ax.get_xlim()
    hz_per_px = (hi - lo) / (ax.get_position().width * fig.get_figwidth() * _DPI)
    clear = RIDGE_CLEARANCE_PX * hz_per_px
    marks = [ln for ln in ax.get_lines() if ln.get_label().startswith("model lines")]
    assert marks
    x, y = np.asarray(marks[0].get_xdata(), float), np.asarray(marks[0].get_ydata(), float)
    speeds = np.unique(y)
    f_line, _ = compare.model_psd_lines(fit.model, "radial_force", rwadist.units.rpm_to_rad_s(speeds))
    for yy, row in zip(speeds, f_line):
        ticks = x[y == yy]
        row = row[row <= hi]
        for f in row:            # its own pair: symmetric about the line, clear of it
            d = ticks - f
            pairs = [g for g in d[d > 0] if np.any(np.isclose(d, -g, rtol=0, atol=1e-6 * max(1.0, f)))]
            assert pairs and max(pairs) >= 0.99 * clear, (yy, f, pairs, clear)
        for t in ticks:          # no tick on a ridge of a line that stands apart from its neighbours
            near = row[np.abs(row - t) < 0.5 * clear]
            for f in near:
                assert np.any((np.abs(row - f) > 0) & (np.abs(row - f) < 2.2 * clear)), (yy, t, f)
    labels = {t.get_text() for t in ax.texts}
    assert {f"{hm.h:.3g}" for hm in fit.model.harmonics("radial_force")} <= labels


def test_every_report_plot_is_titled_with_its_band(extended_fit, tmp_path):
    from rwadist.campbell import plot_campbell
    from rwadist.report import plot_cumulative_rms, plot_rms_vs_speed
    from rwadist.report_extended import plot_extended_rms

    fit, efit, _, _, _ = extended_fit
    _, ax = plot_rms_vs_speed(fit.spectra, fit.model, "radial_force")
    assert "Hz" in ax[0].get_title()
    _, (upper, _) = plot_cumulative_rms(fit.spectra, fit.model, "radial_force", 1500.0)
    assert "Hz" in upper.get_title()
    from rwadist.extended_fit import rms_comparison

    _, ax = plot_extended_rms(rms_comparison(efit, fit), "radial_force", band_hz=fit.spectra.band_limit)
    assert f"0–{fit.spectra.band_limit:.0f} Hz" in ax.get_title()
    fig = plot_campbell(efit.params, np.linspace(0, 3000, 31))
    assert "Hz" in fig.axes[0].get_title() and "rpm" in fig.axes[0].get_title()


def test_psd_title_gives_each_wheels_own_law(tmp_path):
    """The psd plot's title gave the command line's speed law although the wheels of a set have their own."""
    from rwadist.plot_util import psd_title

    wheels_json = tmp_path / "wheels.json"
    wheels_json.write_text(json.dumps({"wheels": [
        {"name": "RW1", "preset": "ithaco-e", "dcm": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "position_m": [0, 0, 0],
         "speed": {"dist": "uniform", "min_rpm": 600, "max_rpm": 1200}},
        {"name": "RW2", "preset": "ithaco-e", "dcm": [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], "position_m": [0.3, 0, 0],
         "speed": {"dist": "normal", "min_rpm": 1000, "max_rpm": 2000}},
        {"name": "RW3", "preset": "ithaco-e", "mounting": {"preset": "pyramid-4", "index": 2},
         "tie": {"to": "RW1", "ratio": -1}}]}))
    res = rwadist.psd(None, (0.0, 100.0), preset="ithaco-e", wheels=wheels_json, empirical=True, fmax=300.0,
                      n_freq=51, n_speeds=20)
    title = psd_title("empirical (Melody)", res).replace("\n", " ")
    assert "RW1: uniform 600..1200 rpm" in title and "RW2: normal 1500" in title and "0–300 Hz" in title
    assert "RW3: tied to RW1 ×-1" in title


def test_nastran_deck_holds_the_full_matrix_by_default(tmp_path, capsys):
    """The deck left out the cross-spectra by default, without a word (coherence 0.51 Fy-Tx on a 4-wheel set)."""
    base = ["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--n-freq", "201", "--n-speeds", "100",
            "--format", "nastran"]
    assert main(base + ["-o", str(tmp_path / "full.bdf")]) == 0
    deck = (tmp_path / "full.bdf").read_text()
    assert "cross-spectra: included" in deck
    randps = [ln.split() for ln in deck.splitlines() if ln.startswith("RANDPS")]
    assert any(r[2] != r[3] for r in randps)                  # cross pairs present (J != K)
    assert main(base + ["-o", str(tmp_path / "auto.bdf"), "--nastran-auto-only"]) == 0
    out = capsys.readouterr().out
    deck = (tmp_path / "auto.bdf").read_text()
    assert "CROSS-SPECTRA LEFT OUT" in deck and "AUTO-SPECTRA ONLY" in out
    assert all(r[2] == r[3] for r in ([ln.split() for ln in deck.splitlines() if ln.startswith("RANDPS")]))
    # the coherence stated, against the cross- and auto-spectra written as CSV (read back here, not from the deck)
    from rwadist.psd_files import read_psd_csv

    assert main(["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--n-freq", "201", "--n-speeds", "100",
                 "-o", str(tmp_path / "p.csv")]) == 0
    _, auto = read_psd_csv(tmp_path / "p.csv")
    rows = list(csv.reader((tmp_path / "p_cross.csv").read_text().splitlines()))
    col = {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(rows[0])}
    stated = [ln.split() for ln in deck.splitlines() if ln.startswith("$   ") and " at " in ln]
    assert stated
    for fields in stated[:3]:
        j, k = fields[1].rstrip(":").split("-")
        re_, im_ = [col[h] for h in col if h.startswith(f"{j}_{k}_re_")][0], \
            [col[h] for h in col if h.startswith(f"{j}_{k}_im_")][0]
        den = auto[j] * auto[k]
        coh = np.where(den > 0, (re_**2 + im_**2) / np.where(den > 0, den, 1.0), 0.0)
        assert float(fields[2]) == pytest.approx(min(float(coh.max()), 1.0), abs=2e-3), fields


def test_model_files_carry_version_date_and_data(tmp_path):
    test = rwadist.simulate_test("ithaco-e", [600.0, 1200.0, 1800.0], n_samples=1024, seed=2)
    prov = rwadist.fit(test).model.provenance
    assert prov["rwadist"] and "3 runs" in prov["data"]
    when = datetime.datetime.fromisoformat(prov["created_utc"])
    assert abs((datetime.datetime.now(datetime.timezone.utc) - when).total_seconds()) < 3600
    ds = tmp_path / "ds"
    assert main(["simulate-test", str(ds), "--preset", "ithaco-e", "--speeds-rpm", "600:2400", "--n-speeds", "8",
                 "--samples", "2048"]) == 0
    assert main(["fit", str(ds), "-o", str(tmp_path / "m.json"), "--no-report"]) == 0
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["provenance"]["data"] == str(ds) and doc["provenance"]["rwadist"] == rwadist.__version__
