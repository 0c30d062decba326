"""The report of a diagnosis (I/O at the edge): summary.json, model.json, CSVs, figures, report.md."""
from __future__ import annotations

import copy

import numpy as np

from ..formats.records import json_text
from ..text_table import cell, write_rows
from ..units import CHANNEL_UNIT, RAD_S_TO_RPM, RADIAL_PAIRS
from .constants import BAND_BINS, CONTRAST_METRIC, METRIC, NOISE_Z
from .search import Diagnosis


def _clean(x):
    """JSON-safe: numpy scalars to Python, NaN/inf to None."""
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x) if np.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def rms_vs_speed(diag: Diagnosis) -> dict:
    """Columns: speed_rpm, then per channel data RMS and model RMS before and after (band [f_lo, top])."""
    ctx = diag.ctx
    runs = ctx.runs
    cols = {"speed_rpm": np.asarray(ctx.sp.speed, float)[runs] * RAD_S_TO_RPM}
    for c in ctx.channels:
        u = CHANNEL_UNIT[c]
        cols[f"data_{c}_rms_{u}"] = np.sqrt(ctx.band_sums(ctx.sp.psd[c][runs]).sum(1))
        for tag, st in (("before", diag.state_before), ("after", diag.state_after)):
            cols[f"model_{tag}_{c}_rms_{u}"] = np.sqrt(ctx.band_sums(ctx.predict(st, c, runs)).sum(1))
    return cols


#: The radial channel pairs whose RMS :func:`pair_rms_error` combines.


def pair_rms_error(cols: dict, tag: str = "after") -> float:
    """The RMS-vs-speed relative error of the model ``tag`` ("before" or "after") with each radial pair's RMS
    combined, sqrt(x² + y²), the other channels as they are: the mean over runs and (combined) channels of
    abs(model − data)/data (``cols``: :func:`rms_vs_speed`'s columns; NaN when no channel is there).

    A line with a co and a counter-rotating part traces an ellipse whose orientation is its parts' phase in the
    run, which the model cannot know (it changes run to run); the model gives x and y the ellipse's mean square, so
    each radial channel alone misses the data by the orientation, while the pair's summed power,
    abs(a₊)² + abs(a₋)², holds whatever the phase."""
    def col(kind, c):
        return next((v for k, v in cols.items() if k.startswith(f"{kind}_{c}_rms_")), None)

    rows: list = []
    paired: set = set()
    for pair in RADIAL_PAIRS:
        d = [col("data", c) for c in pair]
        m = [col(f"model_{tag}", c) for c in pair]
        if all(x is not None for x in d + m):
            rows.append((np.hypot(*d), np.hypot(*m)))
            paired.update(pair)
    for k, v in cols.items():
        c = k.split("_")[1] if k.startswith("data_") else None
        if c is not None and c not in paired and col(f"model_{tag}", c) is not None:
            rows.append((v, col(f"model_{tag}", c)))
    if not rows:
        return float("nan")
    err = np.concatenate([np.abs(np.asarray(m, float) - np.asarray(d, float)) / np.asarray(d, float) for d, m in rows])
    return float(np.nanmean(err))


def counter_rotating_lines(model) -> list:
    """The (direction, h) of the radial lines of ``model`` (a WheelModel) that hold both a co and a
    counter-rotating part: a ``counter_rotation`` effect, or a co and a counter harmonic at one h."""
    out = [(e.get("direction", "radial_force"), float(e.get("h", 1.0))) for e in model.effects
           if e.get("kind") == "counter_rotation" and 0.0 < float(e.get("counter_fraction", 0.0)) < 1.0]
    for direction in ("radial_force", "radial_torque"):
        hs = model.harmonics(direction)
        co = {round(x.h, 3) for x in hs if (getattr(x, "sense", None) or "co") == "co" and x.C > 0}
        ct = {round(x.h, 3) for x in hs if getattr(x, "sense", None) == "counter" and x.C > 0}
        out += [(direction, h) for h in sorted(co & ct) if (direction, h) not in out]
    return out


def _fmt(v, spec: str) -> str:
    """A parameter for the report: floats with ``spec``, short lists space-separated and mappings as ``{key: value
    ...}`` (no commas: CSV)."""
    if isinstance(v, (list, tuple)):
        return "[" + " ".join(_fmt(x, spec) for x in v) + "]"
    if isinstance(v, dict):             # (a mode's ζ interval: its numbers to spec, not Python's repr of 17 digits)
        return "{" + " ".join(f"{k}: {_fmt(x, spec)}" for k, x in v.items()) + "}"
    if v is None:
        return "none"
    if isinstance(v, bool):
        return "yes" if v else "no"
    return format(v, spec) if isinstance(v, float) else str(v)


def write_rms_csv(path, cols: dict):
    """rms_vs_speed.csv: :func:`rms_vs_speed`'s columns (speed in rpm, RMS in N and N·m as named), one row per
    run, 8 significant digits, a value that could not be computed (NaN) as an empty cell as in every table
    (:func:`rwadist.text_table.cell`)."""
    names = list(cols)
    return write_rows(path, names, zip(*(np.asarray(cols[k], dtype=float) for k in names)), digits=8)


_UNIT_LABEL = {"N": "N", "Nm": "N·m"}


def _waterfall_figure(diag: Diagnosis):
    """Residual data/model (dB of band power) before and after, speed × frequency, per channel;
    the frequency axis ends where the data's lines end (1.2× the highest band standing 10 dB
    above the noise floor in any channel), not at the band limit."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..plot_util import content_top_above_floor, is_empty

    ctx = diag.ctx
    runs = ctx.runs[np.argsort(ctx.omega[ctx.runs])]
    fc = ctx.band_centres()
    data = {c: ctx.band_sums(ctx.data(diag.state_before, c)[runs]) for c in ctx.channels}
    chans = [c for c in ctx.channels if not is_empty(data[c])]
    tops = [t for t in (content_top_above_floor(fc, data[c]) for c in chans) if t is not None]
    f_top = max(tops) if tops else float(fc[-1])      # noise only everywhere: the whole band
    n = max(len(chans), 1)
    # one column per channel, the speed and frequency axes shared (tick labels on the outer panels only), the rows
    # named once on their left, the colour bar beside the panels: laid out by matplotlib's constrained layout so no
    # label overlaps a neighbour and no margin is left empty
    fig = Figure(figsize=(2.3 * n + 1.6, 5.6), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, n, sharex=True, sharey=True, squeeze=False)
    rpm = ctx.omega[runs] * RAD_S_TO_RPM
    im = None
    for j, c in enumerate(chans):
        for i, (tag, st) in enumerate((("before", diag.state_before), ("after", diag.state_after))):
            D = ctx.band_sums(ctx.data(st, c)[runs])
            ax = axes[i, j]
            M = ctx.band_sums(ctx.predict(st, c, runs))
            with np.errstate(divide="ignore", invalid="ignore"):
                r = 10 * np.log10(np.maximum(D, 1e-300) / np.maximum(M, 1e-300))
            im = ax.pcolormesh(fc, rpm, r, cmap="RdBu_r", vmin=-10, vmax=10, shading="nearest", rasterized=True)
            ax.set_xlim(max(float(fc[0]) - 0.5 * float(fc[1] - fc[0]), 0.0) if len(fc) > 1 else 0.0, f_top)
            if i == 0:
                ax.set_title(c, fontsize=10)
            if j == 0:
                ax.set_ylabel(f"model {tag} diagnose\nwheel speed (rpm)", fontsize=9)
            if i == 1:
                ax.set_xlabel("frequency (Hz)", fontsize=9)
            ax.tick_params(labelsize=8)
            if i == 1:
                _mark_unexplained(ax, c, diag, rpm)
    if im is not None:
        fig.colorbar(im, ax=axes, label="data / model (dB of band power)", shrink=0.9, pad=0.01)
    fig.suptitle(f"Residual waterfall, 0–{f_top:.0f} Hz: data over model in {BAND_BINS}-bin bands "
                 "(red: data above the model, blue: below)", fontsize=10)
    return fig


#: Colour of the marks of what no class explains on the residual waterfall (stands out of the red/blue scale).
MARK_COLOUR = "#1b7837"


def _tag(ax, xs, ys, text: str, **kwargs) -> None:
    """The label ``text`` at the last point of the polyline (``xs``, ``ys``; data units) inside the panel, none when no
    point of it is: a label at a mark's end beyond the zoomed frequency axis (a speed line's ray to 990 Hz on a panel
    ending at 595 Hz) was drawn outside the panel, and the constrained layout widened the gaps between panels for it."""
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    if xs.size > 1:
        t = np.linspace(0.0, xs.size - 1.0, 256 * (xs.size - 1) + 1)
        xs, ys = np.interp(t, np.arange(xs.size), xs), np.interp(t, np.arange(ys.size), ys)
    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
    x1 -= 0.06 * (x1 - x0)                             # room for the label's own width left of the right edge
    inside = np.flatnonzero((xs >= x0) & (xs <= x1) & (ys >= y0) & (ys <= y1))
    if inside.size:
        k = inside[-1]
        ax.text(xs[k], ys[k], text, clip_on=True, **kwargs)


def _mark_unexplained(ax, c: str, diag: Diagnosis, rpm: np.ndarray) -> None:
    """Marks on one "after" panel (channel ``c``) of the records of ``diag.unexplained`` that hold the channel, each
    labelled with its number in report.md: a fixed line a dashed vertical, a speed line its ray f = h·rpm/60, a
    moving resonance its track, a hump a shaded frequency span, a copy and a run-to-run change a note (and short
    ticks at the runs' speeds)."""
    hi = float(np.max(rpm))
    style = dict(color=MARK_COLOUR, lw=1.2, zorder=5)
    for n, u in enumerate(diag.unexplained, 1):
        if c not in u.channels:
            continue
        tag = dict(color=MARK_COLOUR, fontsize=7, fontweight="bold", zorder=6)
        s0, s1 = u.speed_rpm
        if u.signature == "fixed_line":
            ax.axvline(u.f_Hz[0], ls="--", **style)
            _tag(ax, [u.f_Hz[0]], [hi], f" {n}", va="top", **tag)
        elif u.signature == "speed_line" and u.h is not None:
            s = np.array([s0, s1])
            ax.plot(u.h * s / 60.0, s, ls=":", **style)
            _tag(ax, u.h * s / 60.0, s, f" {n}", va="top", **tag)
        elif u.signature == "sideband_line" and "carrier_Hz" in u.parameters:
            s = np.linspace(s0, s1, 64)        # a lower side folds at 0 Hz (its |f|): a polyline, not a segment
            for side in u.parameters.get("sides", [1]):
                ax.plot(np.abs(u.parameters["carrier_Hz"] + side * u.parameters["h"] * s / 60.0), s, ls=":", **style)
            _tag(ax, [u.parameters["carrier_Hz"]], [s1], f" {n}", va="top", **tag)
        elif u.signature == "affine_line" and "offset_Hz" in u.parameters:
            s = np.array([s0, s1])
            f = u.parameters["offset_Hz"] + u.parameters["slope"] * s / 60.0
            ax.plot(f, s, ls=":", **style)
            _tag(ax, f, s, f" {n}", va="top", **tag)
        elif u.signature == "line_property" and u.parameters.get("property") == "blended_lines" and u.h is not None:
            s = np.array([s0, s1])                  # the blended model line's ray over the runs read
            ax.plot(u.h * s / 60.0, s, ls="-.", **style)
            _tag(ax, u.h * s / 60.0, s, f" {n}", va="top", **tag)
        elif u.signature == "partial_line" and u.h is not None:
            # a short mark on the line's ray at each run it is absent from
            s = np.asarray(u.parameters.get("absent_rpm", []), float)
            ax.plot(u.h * s / 60.0, s, ls="none", marker="|", ms=6, mew=1.2, color=MARK_COLOUR, zorder=5)
            if s.size:
                _tag(ax, u.h * s / 60.0, s, f" {n}", va="top", **tag)
        elif u.signature == "moving_resonance":
            fa = u.parameters.get("f_at_lowest_speed_Hz", u.f_Hz[0])
            fb = u.parameters.get("f_at_highest_speed_Hz", u.f_Hz[1])
            ax.plot([fa, fb], [s0, s1], ls="-.", **style)
            _tag(ax, [fa, fb], [s0, s1], f" {n}", va="top", **tag)
        elif u.signature == "broadband_hump":
            ax.axvspan(u.f_Hz[0], u.f_Hz[1], color=MARK_COLOUR, alpha=0.15, lw=0, zorder=4)
            _tag(ax, [0.5 * (u.f_Hz[0] + u.f_Hz[1])], [hi], f"{n}", ha="center", va="top", **tag)
        else:
            words = {"channel_copy": f"{n}: copy of {u.parameters.get('source', '?')}",
                     "run_change": f"{n}: runs differ"}.get(u.signature, f"{n}: {u.signature}")
            ax.text(0.02, 0.02, words, transform=ax.transAxes, va="bottom", **tag)
            if u.signature == "run_change":
                for r in u.parameters.get("run_speeds_rpm", []):
                    ax.plot([0.0, 0.04], [r, r], transform=ax.get_yaxis_transform(), **style)


def _rms_figure(diag: Diagnosis, cols: dict):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..plot_util import is_empty

    ctx = diag.ctx
    chans = [c for c in ctx.channels if not is_empty(cols[f"data_{c}_rms_{CHANNEL_UNIT[c]}"])]
    fig = Figure(figsize=(12, 6))
    FigureCanvasAgg(fig)
    order = np.argsort(cols["speed_rpm"])
    n_col = 3
    n_row = max(1, int(np.ceil(len(chans) / n_col)))
    for j, c in enumerate(chans):
        ax = fig.add_subplot(n_row, n_col, j + 1)
        u = CHANNEL_UNIT[c]
        for key, style, lab, z in ((f"model_before_{c}_rms_{u}", "C0-", "model before", 2),
                                   (f"model_after_{c}_rms_{u}", "C3--", "model after", 2),
                                   (f"data_{c}_rms_{u}", "k.", "data", 3)):
            ax.plot(cols["speed_rpm"][order], cols[key][order], style, label=lab, ms=3, zorder=z)
        ax.set_title(f"{c}", fontsize=9)
        ax.set_ylabel(f"RMS ({_UNIT_LABEL.get(u, u)})")
        ax.set_xlabel("Wheel speed (rpm)")
        if j == 0:
            ax.legend(fontsize=8)
    lo, hi = diag.band_Hz
    fig.suptitle(f"RMS vs wheel speed over {lo:.3g}–{hi:.0f} Hz (the metric's band): data and the model "
                 "before and after diagnose")
    fig.tight_layout()
    return fig


def unexplained_section(diag: Diagnosis) -> list:
    """report.md's lines on what the residual holds that no class explains (docs/diagnose.md, "Unexplained
    residual"): one item per record, its signature, where, strength, share, causes and what would tell."""
    if not diag.unexplained:
        return ["Nothing: no structure the classes leave stands above the noise in the residual."]
    out = ["Structure the residual holds above the noise that no effect class explains (described, not added to "
           "the model; marked on the residual waterfall):", ""]
    for i, u in enumerate(diag.unexplained, 1):
        out.append(f"{i}. **{u.signature}** ({u.description}): {u.where()}; {u.strength()}, "
                   f"{u.share_text()} of the misplaced power left, {u.n_runs} runs.")
        par = ", ".join(f"{k} = {_fmt(v, '.5g')}" for k, v in u.parameters.items())
        if par:
            out.append(f"   Parameters: {par}.")
        if u.causes:
            out.append("   Could be: " + "; ".join(u.causes) + ".")
        if u.would_tell:
            out.append(f"   What would tell: {u.would_tell}.")
    return out


def line_causes_section(diag: Diagnosis) -> list:
    """report.md's lines on the candidate physical causes of the model's lines (bearing ratios for the non-integer
    ones: named from the bearings' geometry within the resolution, else the ranges they can take; a motor's torque
    ripple for the axial torque's whole multiples of the speed)."""
    if diag.bearings:
        head = "Bearings given: " + "; ".join(
            f"{b.label()}: {b.balls} balls, d {1000 * b.ball_diameter_m:.4g} mm, D {1000 * b.pitch_diameter_m:.4g} mm, "
            f"contact {b.contact_angle_deg:g}°, {b.rotating_race} race turning (FTF {r['FTF']:.4g}, BPFO {r['BPFO']:.4g}, "
            f"BPFI {r['BPFI']:.4g}, BSF {r['BSF']:.4g})" for b in diag.bearings for r in (b.ratios(),)) + "."
    else:
        head = ("No bearing geometry given (`--bearing` or the model file's `wheel.bearings`): the ranges bearing "
                "ratios can take, and the relations among the lines, are named.")
    if not diag.line_causes:
        return [head, "", "No line of the model has a candidate cause (a bearing's ratio for a line at a non-integer "
                      "ratio, a motor's torque ripple for an axial-torque line at a whole one)."]
    out = [head, ""]
    for lc in diag.line_causes:
        out.append(f"- {lc['direction']} h = {lc['h']:.5g} ({lc['source']}): " + "; ".join(lc["causes"]))
    return out


#: hypotheses.csv's columns
HYPOTHESES_COLUMNS = ["iteration", "kind", "channels", "parameters", "heldout_gain", "heldout_gain_fraction", "t",
                      "passed"]


def hypotheses_rows(hypotheses) -> list:
    """hypotheses.csv's rows, each a list of its cells in the order of :data:`HYPOTHESES_COLUMNS` (iteration, kind,
    channels, parameters, held-out gain and fraction, t, passed as ``true``/``false``).  The parts of an effect of
    several parts (``Hypothesis.group``: a floor law of several channels, each channel its own entry of the model
    file) are one hypothesis: its held-out gain and gain fraction are written on its first part's row only (the
    others' left empty, their parameters marked ``part_of=`` the group's channels), so the columns sum to what the
    hypotheses gained."""
    rows = []
    seen: set = set()
    for h in hypotheses:
        e = h.effect
        # ';' separates the pairs: one inside a value (a law's text) would split it
        par = ";".join(f"{k}={_fmt(v, '.6g').replace(';', ' ')}" for k, v in e.params().items()
                       if not (isinstance(v, list) and len(v) > 4))
        g = getattr(h, "group", None)
        gain = [cell(h.gain, 6), cell(h.gain_fraction, 6)]
        if g is not None:
            par += f";part_of={' '.join(g.channels)}"
            gain = ["", ""] if id(g) in seen else gain
            seen.add(id(g))
        rows.append([cell(h.iteration), e.kind, " ".join(e.channels), par, *gain, cell(h.t, 4), cell(bool(h.passed))])
    return rows


def hypotheses_csv(hypotheses) -> str:
    """hypotheses.csv's text (:func:`hypotheses_rows` through the csv module: a comma inside a parameter's text is
    quoted, never a new column)."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(HYPOTHESES_COLUMNS)
    w.writerows(hypotheses_rows(hypotheses))
    return buf.getvalue()


def _measured_apart(effect) -> list:
    """The model lines a close line was measured apart from (``apart_entry`` of a ``missing_harmonic``), or []."""
    entry: dict = getattr(effect, "apart_entry", dict)()
    return list(entry.get("measured_apart", []))


def _taken_back(diag) -> list:
    """report.md's lines of the effects taken back: fitted to content no class explains, or an amplitude law taken
    before the wheel's modes or a load-cell offset and judged again on that base (:mod:`.law_recheck`)."""
    from ..effects_text import describe_effect

    md: list = []
    back = [h for h in diag.hypotheses if getattr(h, "forced_by", None)]
    if back:
        md += ["", "Taken back (the search fitted them to content described below as no class explains it):", ""]
        md += [f"- {describe_effect({'kind': h.effect.kind, **h.effect.params()})} (to the {h.forced_by})" for h in back]
    again = [h for h in diag.hypotheses if getattr(h, "taken_back", None)]
    if again:
        md += ["", "Taken back (an amplitude law taken before the wheel's modes or a load-cell offset, judged again on "
               "that base):", ""]
        md += [f"- {describe_effect({'kind': h.effect.kind, **h.effect.params()})} (iteration {h.iteration}): "
               f"{h.taken_back}" for h in again]
    return md


def write_report(diag: Diagnosis, out_dir) -> list:
    """summary.json, model.json (the improved model), rms_vs_speed.csv/.png, residual_waterfall.png,
    hypotheses.csv and report.md into ``out_dir``; returns the paths."""
    from pathlib import Path

    from ..model import save
    from ..plot_util import save_png

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = []
    summary = _clean(diag.summary())
    p = out / "summary.json"
    p.write_text(json_text(summary, indent=2) + "\n")       # valid JSON: a NaN as null
    files.append(p)
    model = copy.deepcopy(diag.model)
    model.effects = _clean(model.effects)
    files.append(save(model, out / "model.json"))
    cols = rms_vs_speed(diag)
    files.append(write_rms_csv(out / "rms_vs_speed.csv", cols))
    p = out / "rms_vs_speed.png"
    save_png(_rms_figure(diag, cols), p, dpi=100)
    files.append(p)
    p = out / "residual_waterfall.png"
    save_png(_waterfall_figure(diag), p, dpi=100)
    files.append(p)
    files.append(write_rows(out / "hypotheses.csv", HYPOTHESES_COLUMNS, hypotheses_rows(diag.hypotheses)))
    md = ["# rwadist diagnose", "",
          f"Metric: `{METRIC}` — {summary['metric_definition']}; a band's misplaced power is counted beyond "
          f"{NOISE_Z:g} noise standard deviations.", "",
          f"- band analysed: {summary['band_Hz'][0]:.3g}-{summary['band_Hz'][1]:.4g} Hz (the metrics' bands; "
          "`--f-lim` narrows it)",
          f"- base: {diag.state_before.base} (lines "
          + ("through the suspension modes of the model's analytical section)" if diag.state_before.ext is not None
             else "C·Ω², hard mounted)")
          + (f" -> {diag.state_after.base} (through the wheel's suspension modes fitted from the data)"
             if diag.state_after.base != diag.state_before.base else ""),
          *([f"- suspension modes: {summary['suspension_modes_status']['text']}"]
            if summary.get("suspension_modes_status") else []),
          f"- error before: {diag.error_before:.4g}", f"- error after: {diag.error_after:.4g}",
          f"- narrow-line error (`{CONTRAST_METRIC}`: {summary['narrow_line_metric_definition']}) before / after: "
          f"{diag.contrast_error_before:.4g} / {diag.contrast_error_after:.4g}",
          f"- RMS-vs-speed relative error before / after: {diag.rms_error_before:.4g} / {diag.rms_error_after:.4g}",
          f"- iterations: {diag.iterations}", ""]
    elliptic = counter_rotating_lines(diag.model)
    if elliptic:
        which = ", ".join(f"{d.replace('_', ' ')} h = {h:.4g}" for d, h in elliptic)
        md[-1:-1] = [f"- RMS-vs-speed relative error after, each radial pair combined (√(x² + y²)): "
                     f"{pair_rms_error(cols):.4g}.  The model holds lines with co and counter-rotating parts "
                     f"({which}): each traces an ellipse whose orientation is its parts' phase in the run, which "
                     "changes run to run; the model gives x and y the ellipse's mean square, so Fx and Fy (Tx and Ty) "
                     "each miss the data by the orientation, while the pair's summed power holds."]
    if diag.data_quality:
        from ..data_quality import quality_lines

        md += ["## Data quality", ""] + [f"- {line}" for line in quality_lines(diag.data_quality)] + [""]
    if diag.speed:
        from ..speed_whirl import speed_lines

        md += ["## Speed", ""] + [f"- {line}" for line in speed_lines(diag.speed)] + [""]
    md += ["## Effects added", ""]
    from ..effects_text import beyond_power, describe_effect

    chosen = [h for h in diag.hypotheses if h.passed]
    if not chosen:
        md.append("None: nothing left in the residual passed the held-out test.")
    for h in chosen:
        par = ", ".join(f"{k} = {_fmt(v, '.5g')}"
                        for k, v in h.effect.params().items() if not (isinstance(v, list) and len(v) > 4))
        words = describe_effect({"kind": h.effect.kind, **h.effect.params()})
        narrow = ("" if h.narrow_gain_fraction is None
                  else f", {h.narrow_gain_fraction:.1%} of the narrow-line misfit (taken on it: its power share is "
                       "below min_gain)")
        of_what = beyond_power(h.gain_fraction) or " of the unexplained power"
        md.append(f"- **{words}**: held-out gain {h.gain_fraction:.1%}{of_what}{narrow}, {h.t:.1f} noise standard "
                  f"errors (parameters: {par})"
                  + "".join(f"; beside it h = {m['h_before']:.5g}"
                            + (f" ({m['sense']}-rotating part)" if m.get("sense") in ("co", "counter") else "")
                            + f", C = {m['C_before']:.4g} was the two lines' blend on "
                            f"the Welch grid, measured apart on the whole-run DFT: h = {m['h']:.5g}, C = {m['C']:.4g}"
                            for m in _measured_apart(h.effect)))
    if diag.model_given and diag.state_after.base != diag.state_before.base:
        missing = diag.lines_missing_from_given_model()
        md += ["", "## The given model's harmonics", "",
               "The given model has no suspension modes the data could be read through (none, or assumed ones): its "
               "harmonics were replaced by those fitted with the wheel's modes from the data."
               + (" Lines of the data it lacks (in the improved model's harmonics, named as no effect):" if missing
                  else " It lacks none of the data's lines."), ""]
        md += [f"- {d} h = {h:.4g}" + (f" ({sense}-rotating part)" if sense in ("co", "counter") else "")
               + f", C = {C:.4g}" for d, h, C, sense in missing]
    md += _taken_back(diag)
    md += ["", "## Unexplained residual", ""] + unexplained_section(diag)
    md += ["", "## Physical causes for lines", ""] + line_causes_section(diag)
    md += ["", "## Hypotheses (best five per iteration)", "", "see `hypotheses.csv`", "",
           "![residual](residual_waterfall.png)", "", "![rms](rms_vs_speed.png)", ""]
    p = out / "report.md"
    p.write_text("\n".join(md))
    files.append(p)
    return files
