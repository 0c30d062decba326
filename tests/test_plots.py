"""Plots ready for a design review (issue 17 item 4, issue 14 item 8), checked on the figure objects:
every frequency axis ends where the content ends (not at Nyquist), data are drawn over the model's
markers, absent or all-zero channels are left out, and every legend entry names an artist that is
drawn with data.  The data are generated (the virtual test stand, a few speeds) so the content band
has a closed form: the highest harmonic h·Ω_max/2π.
"""
from __future__ import annotations

import numpy as np
import pytest
from matplotlib.collections import PolyCollection, QuadMesh
from matplotlib.lines import Line2D

import rwadist
from rwadist import api, plot_util, report, report_extended
from rwadist.campbell import plot_campbell
from rwadist.psd_files import plot_psd

SPEEDS_RPM = np.linspace(600.0, 2400.0, 10)
N_SAMPLES = 2048
W_MAX = 2400.0 * 2 * np.pi / 60.0


@pytest.fixture(scope="module")
def fit():
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=SPEEDS_RPM, n_samples=N_SAMPLES, seed=3)
    for run in test.runs:                       # an axial-torque channel that measured nothing
        run.signals["Tz"] = np.zeros_like(run.signals["Tz"])
    return rwadist.fit(test)


def _legend_artists_are_drawn(fig):
    """Every legend label names a visible artist in its axes (or figure) that holds data."""
    for holder in list(fig.axes) + [fig]:
        legends = [holder.get_legend()] if holder is not fig else list(fig.legends)
        for leg in legends:
            if leg is None:
                continue
            labels = [t.get_text() for t in leg.get_texts()]
            assert labels, "an empty legend"
            pool = fig.axes if holder is fig else [holder]
            drawn = {}
            for ax in pool:
                for art in list(ax.lines) + list(ax.collections) + list(ax.patches):
                    lab = art.get_label()
                    if not lab or lab.startswith("_") or not art.get_visible():
                        continue
                    if isinstance(art, Line2D):
                        has = np.asarray(art.get_xdata()).size > 0
                    elif isinstance(art, PolyCollection):
                        has = len(art.get_paths()) > 0
                    else:
                        has = True
                    drawn[lab] = drawn.get(lab, False) or has
            for lab in labels:
                assert drawn.get(lab), f"legend entry {lab!r} names no drawn artist"


def _no_empty_axes(fig):
    for ax in fig.axes:
        if not ax.get_visible() or ax.get_label() == "<colorbar>":
            continue
        assert ax.lines or ax.collections or ax.images, f"an empty panel: {ax.get_title()!r}"


def _top_line_hz(model, direction):
    return max(hm.h for hm in model.harmonics(direction)) * W_MAX / (2 * np.pi)


def test_content_band_helpers():
    f = np.linspace(0.0, 1000.0, 1001)
    psd = np.full((1001, 2), 1e-20)
    psd[100, 0] = 1.0
    psd[250, 1] = 1e-6
    assert plot_util.content_top(f, psd) == pytest.approx(1.05 * 250.0)
    assert plot_util.log_floor(psd) == pytest.approx(1e-8)
    rows = np.ones((3, 1001))
    rows[1, 400] = 50.0
    assert plot_util.content_top_above_floor(f, rows) == pytest.approx(480.0)
    assert plot_util.content_top_above_floor(f, np.ones((3, 1001))) is None
    assert plot_util.group_identical(np.array([[1.0, 1.0, 2.0]]), ["Fx", "Fy", "Fz"]) == [(0, "Fx = Fy"), (2, "Fz")]
    y = plot_util.spread_labels([10.0, 10.2, 50.0, 10.1], 1.0)
    assert np.all(np.diff(np.sort(y)) >= 1.0 - 1e-12) and y[2] == 50.0


def test_waterfall_data_under_model_ticks_and_band_of_content(fit):
    view = report.content_top(fit.spectra, fit.lines)
    assert view < fit.spectra.f[-1]                     # not Nyquist
    assert view >= _top_line_hz(fit.model, "radial_force")
    fig, ax = report.plot_waterfall(fit.spectra, "Fx", model=fit.model, f_max=view, lines=fit.lines)
    assert ax.get_xlim()[1] == pytest.approx(view, rel=0.02)
    mesh = [c for c in ax.collections if isinstance(c, QuadMesh)][0]
    ticks = [ln for ln in ax.lines if ln.get_label().startswith("model lines h·Ω")][0]
    assert ticks.get_marker() == "|" and ticks.get_markersize() >= 5     # beside the ridge, not on it
    assert mesh.get_zorder() < ticks.get_zorder()
    _legend_artists_are_drawn(fig)


def test_waterfall_of_a_dense_speed_grid_leaves_the_data_visible_between_markers():
    # a sweep sliced into ~170 runs drew a ring at every speed of every line: the rings (11 px) merged into tubes
    # that hid the lines.  On 150 speeds the markers of each model line are no closer than the axis height over
    # MAX_MARKERS_PER_LINE, and every pair of ticks still flanks a line h·Ω of the model at a speed of the data
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(300.0, 2400.0, 150), n_samples=1024, seed=2)
    f = rwadist.fit(test)
    fig, ax = report.plot_waterfall(f.spectra, "Fx", model=f.model, lines=f.lines)
    ticks = [ln for ln in ax.lines if ln.get_label().startswith("model lines h·Ω")][0]
    y_all, x_all = np.asarray(ticks.get_ydata()), np.asarray(ticks.get_xdata())
    half = x_all.size // 2              # the left ticks, then the right ones: a pair per line and speed
    y, x = y_all[:half], 0.5 * (x_all[:half] + x_all[half:])
    hs = f.model.h_and_C("radial_force")[0]
    per_line = [np.sort(y[np.isclose(x, h * y / 60.0, rtol=1e-9)]) for h in hs]
    assert all(0 < v.size <= report.MAX_MARKERS_PER_LINE for v in per_line), [v.size for v in per_line]
    assert sum(v.size for v in per_line) == x.size                     # every pair flanks a model line
    span = 2400.0 - 300.0
    assert all(np.all(np.diff(v) >= span / report.MAX_MARKERS_PER_LINE * 0.9) for v in per_line)
    assert np.all(np.isin(np.round(y, 6), np.round(np.abs(f.spectra.speed) * 60 / (2 * np.pi), 6)))


def test_cumulative_rms_zoomed_and_data_over_model(fit):
    view = report.content_top(fit.spectra, fit.lines)
    fig, (ax_a, ax_c) = report.plot_cumulative_rms(fit.spectra, fit.model, "radial_force", 2400.0, f_max=view)
    for ax in (ax_a, ax_c):
        assert ax.get_xlim()[1] == pytest.approx(view)
    data = [ln for ln in ax_a.lines if ln.get_label().startswith("data")]
    model = [ln for ln in ax_a.lines if ln.get_label() == "model C·Ω²"] + list(ax_a.collections)
    assert data and model
    assert min(d.get_zorder() for d in data) > max(m.get_zorder() for m in model)
    staircase = [ln for ln in ax_c.lines if ln.get_label() == "model (staircase)"][0]
    assert min(ln.get_zorder() for ln in ax_c.lines if ln.get_label().startswith("data")) > staircase.get_zorder()
    _legend_artists_are_drawn(fig)


def test_direction_without_model_has_no_model_artists(fit):
    assert not fit.model.harmonics("axial_torque")
    fig, ax = report.plot_rms_vs_speed(fit.spectra, fit.model, "radial_force")
    assert isinstance(ax, tuple) and len(ax) == 2       # a ratio panel where the model has lines
    fig, ax = report.plot_rms_vs_speed(fit.spectra, fit.model, "axial_force")
    _legend_artists_are_drawn(fig)
    _no_empty_axes(fig)


def test_report_leaves_out_all_zero_channels_with_progress_over_every_file(fit, tmp_path, capsys):
    written = report.write_report(fit, tmp_path, progress=True)
    err = capsys.readouterr().err
    n_figures = sum(1 for p in written if p.suffix == ".png")
    assert "writing the report" in err and f"{n_figures + 1}/{n_figures + 1}" in err   # figures, then tables
    files = {p.name for p in written}
    assert "waterfall_Tz.png" not in files and "waterfall_Fx.png" in files
    assert not any("axial_torque" in name for name in files)
    summary = (tmp_path / "summary.md").read_text()
    assert "- Tz:" not in summary


def test_coefficient_band_named_only_when_visible(fit):
    line = next(ln for ln in fit.lines if ln.direction == "radial_force")
    fig, ax = report.plot_coefficient(line)
    labels = [c.get_label() for c in ax.collections]
    visible = line.C > 0 and 2 * line.C_stderr / line.C >= report.COEFFICIENT_BAND_VISIBLE
    assert ("C ± 2σ" in labels) == visible
    assert "%" in ax.get_title()                       # the 2σ width is always given
    curves = [ln for ln in ax.lines if ln.get_label() in ("C·Ω²", "C_all·Ω² (all points)")]
    points = [ln for ln in ax.lines if ln.get_label() in ("used", "left out of C")]
    assert min(p.get_zorder() for p in points) > max(c.get_zorder() for c in curves)
    fig, axes = report.plot_coefficients(fit.lines, "radial_force")
    _legend_artists_are_drawn(fig)


def test_psd_plot_band_floor_and_channels():
    res = api.psd(None, preset="ithaco-e", speed_rpm=(300.0, 3000.0), n_freq=2001, n_speeds=200)
    fig = plot_psd(res)
    ax_f, ax_t, ax_cf, ax_ct = fig.axes
    psd = res.psd
    top = plot_util.content_top(res.f, psd)
    assert top < res.f[-1]
    for ax in fig.axes:
        assert ax.get_xlim()[1] == pytest.approx(top)
    lo_f = ax_f.get_ylim()[0]
    assert lo_f >= 0.99e-8 * psd[:, :3].max()          # 80 dB, not round-off at 1e-18
    labels_t = [t.get_text() for t in ax_t.get_legend().get_texts()]
    assert "Tz" not in " ".join(labels_t)              # the extended E wheel has no axial torque
    assert np.all(psd[:, 5] == 0)
    assert np.max(np.abs(psd[:, 3] - psd[:, 4])) <= 1e-6 * psd[:, 3].max()
    assert labels_t == ["Tx = Ty"]
    for ax in fig.axes:
        _legend_artists_are_drawn(fig)
    _no_empty_axes(fig)


def test_campbell_labels_name_every_harmonic_and_do_not_overlap():
    params, lines, _ = api.extended_source(None, preset="ithaco-e")
    fig = plot_campbell(params, np.arange(0.0, 3001.0, 100.0), lines)
    ax = fig.axes[0]
    texts = {t.get_text(): t for t in ax.texts}
    hs = sorted({ln.h for ln in lines})
    assert set(texts) == {f"{h:g}×" for h in hs}
    fmax = ax.get_ylim()[1]
    right = sorted(t.xyann[1] for t in ax.texts if t.get_va() == "center")
    assert np.all(np.diff(right) >= 0.035 * fmax - 1e-9)
    _legend_artists_are_drawn(fig)


@pytest.mark.slow
def test_residual_waterfall_zoomed_to_the_lines():
    from rwadist.diagnose.report import _waterfall_figure

    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600.0, 2400.0, 8), n_samples=2048, seed=5)
    model = rwadist.fit(test).model
    diag = rwadist.diagnose(test, model)
    fig = _waterfall_figure(diag)
    band_top = float(diag.ctx.band_centres()[-1])
    tops = {ax.get_xlim()[1] for ax in fig.axes if ax.get_label() != "<colorbar>"}
    assert len(tops) == 1
    top = tops.pop()
    assert top < 0.5 * band_top                        # the E wheel's lines end near 230 Hz, Nyquist 1920
    assert top >= _top_line_hz(model, "radial_force")
    # laid out for a review: no panel's labels, ticks or title run into another's, and the panels with the colour
    # bar fill the width (the figure before 2026-11-25: tick labels against the neighbour's frame, a fifth empty)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = [ax.get_tightbbox(renderer) for ax in fig.axes]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            overlap_w = min(a.x1, b.x1) - max(a.x0, b.x0)
            overlap_h = min(a.y1, b.y1) - max(a.y0, b.y0)
            assert overlap_w <= 1.0 or overlap_h <= 1.0, (a, b)        # pixels
    width = fig.bbox.width
    assert min(b.x0 for b in boxes) < 0.05 * width and max(b.x1 for b in boxes) > 0.95 * width



def test_extended_rms_data_over_both_models():
    rpm = np.linspace(300.0, 2400.0, 12)
    comparison = {"radial_force": {"speed_rpm": rpm, "in_modes": rpm > 1500.0, "data": 1e-8 * rpm ** 2,
                                   "empirical": 1.1e-8 * rpm ** 2, "extended": 0.9e-8 * rpm ** 2,
                                   "error_empirical": 0.1, "error_extended": 0.05}}
    fig, ax = report_extended.plot_extended_rms(comparison, "radial_force")
    data = [ln for ln in ax.lines if ln.get_label().startswith("data")]
    models = [ln for ln in ax.lines if "model" in ln.get_label()]
    assert len(data) == 1 and len(models) == 2
    assert data[0].get_zorder() > max(m.get_zorder() for m in models)
    assert ax.get_ylabel() == "RMS (N)"
    _legend_artists_are_drawn(fig)


def test_log_axes_carry_minor_ticks_at_2_and_5_of_each_decade():
    """:func:`rwadist.plot_util.log_axis`: the kit's log axes span up to 8 decades; their minor ticks are 2 and 5 of
    each decade (a tick at every integer cost half of a 6-panel report figure's drawing), on the axis asked for."""
    from matplotlib.figure import Figure

    from rwadist.plot_util import log_axis

    ax = Figure().add_subplot()
    ax.plot([1.0, 2.0], [1e-6, 1e2])
    log_axis(ax)
    assert ax.get_yscale() == "log" and ax.get_xscale() == "linear"
    ax.set_ylim(1e-6, 1e2)
    minor = ax.yaxis.get_minorticklocs()
    minor = minor[(minor >= 1e-6) & (minor <= 1e2)]
    mantissa = np.round(minor / 10.0 ** np.floor(np.log10(minor)), 6)
    assert set(mantissa) == {2.0, 5.0} and minor.size == 16


@pytest.mark.parametrize("lo, hi", [(1e-11, 1e-2), (2e-4, 3e-3), (0.3, 40.0)])
def test_log_axis_labels_are_plain_text_naming_their_tick(lo, hi):
    """:func:`rwadist.plot_util.log_axis` labels ticks as matplotlib's scientific notation does, in plain text
    (``10⁻⁵``, ``2×10⁻³``: no math-text parser): read back, each label is its tick's value; a tick matplotlib leaves
    unlabelled stays unlabelled."""
    from matplotlib.figure import Figure

    from rwadist.plot_util import log_axis

    def value(label):
        coeff, _, power = label.translate(str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")).rpartition("×")
        number = 10.0 ** int(power[2:]) if label.rpartition("×")[2][2:] else float(power)
        return float(coeff or 1.0) * number

    ours, theirs = Figure().add_subplot(), Figure().add_subplot()
    log_axis(ours)
    theirs.set_yscale("log")
    theirs.yaxis.set_minor_locator(ours.yaxis.get_minor_locator())
    for ax in (ours, theirs):
        ax.set_ylim(lo, hi)
        ax.figure.canvas.draw()
    labelled = set()
    for which in ("major", "minor"):
        got = [t.get_text() for t in ours.yaxis.get_ticklabels(which=which)]
        ref = [t.get_text() for t in theirs.yaxis.get_ticklabels(which=which)]
        locs = ours.yaxis.get_minorticklocs() if which == "minor" else ours.yaxis.get_majorticklocs()
        assert [bool(t) for t in got] == [bool(t) for t in ref] and (any(got) or which == "minor")
        labelled.update(t for t in got if t)
        for text, loc in zip(got, locs):
            assert "$" not in text
            if text:
                assert value(text) == pytest.approx(loc, rel=1e-9), (text, loc)
    assert hi / lo > 100 or any("×" in t for t in labelled)      # a narrow range labels its minor ticks: 2×10⁻⁴


def test_a_waterfall_mark_is_labelled_inside_its_panel_on_the_mark():
    """trial21: the label of a speed line's ray h 6.6 (to 990 Hz at 9000 rpm) on a panel zoomed to 595 Hz was drawn
    at the ray's end, outside the panel, and the constrained layout opened wide gaps between the panels for it."""
    from matplotlib.figure import Figure

    from rwadist.diagnose.report import _tag

    ax = Figure().subplots()
    ax.set_xlim(0.0, 595.0)
    ax.set_ylim(300.0, 9000.0)
    s = np.array([678.0, 9000.0])
    _tag(ax, 6.6 * s / 60.0, s, " 1")
    (label,) = ax.texts
    x, y = label.get_position()
    assert 0.0 <= x <= 595.0 and 300.0 <= y <= 9000.0 and label.get_clip_on()
    assert x == pytest.approx(6.6 * y / 60.0, rel=1e-9) and x == pytest.approx(0.94 * 595.0, rel=0.01)   # on the ray, by the edge
    _tag(ax, [700.0], [9000.0], " 2")                  # a fixed line beyond the zoom: no label
    assert len(ax.texts) == 1
