"""The extended-model part of a fit's report (``rwadist fit --extended``): RMS of data, empirical and extended model
vs speed, line amplitudes through the fitted modes, the parameters, and summary.md as the extended fit's report
(:func:`write_extended_report`).  Built on :mod:`rwadist.report`'s helpers."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import compare
from .plot_util import log_axis
from .report import (
    DATA_ZORDER,
    MODEL_ZORDER,
    _band_top,
    _direction_label,
    _direction_unit,
    _new_figure,
    _save,
    _summary_md,
    harmonic_rows,
)
from .schema import PARAM_KEYS
from .text_table import write_rows
from .units import CHANNEL_UNIT, DIRECTION_C_UNIT, DIRECTION_CHANNELS, RAD_S_TO_RPM


def _extended_md(efit, comparison, model) -> list:
    """summary.md's section on the extended model: what the model file holds, the fitted modes, its errors."""
    from .extended import params_to_dict

    p = efit.params
    n_lines = sum(len(v) for v in model.empirical.values()) if model is not None else len(efit.lines)
    out = ["## The extended model (the model file)", "",
           f"The model file holds the extended model (rigid rotor on its suspension, thesis ch. 4): {n_lines} forcing "
           "lines through the fitted suspension modes" + (" (per unit mass and inertia: no --mass/--radius)"
                                                          if efit.per_unit else "") + ".", "",
           "### Suspension modes (fitted)", "",
           "| mode | frequency at rest (Hz) | ζ | stiffness | rel. std. error | located by the data |",
           "|---|---|---|---|---|---|"]
    for mode, omega, k, key, unit in (("radial_translation", p.omega_r, p.k_r, "k_r", "N/m"),
                                      ("rocking", p.omega_rock, p.k_rock, "k_rock", "N·m/rad"),
                                      ("axial_translation", p.omega_z, p.k_z, "k_z", "N/m")):
        rel = efit.rel_stderr.get(key, float("nan"))
        short = "axial" if mode == "axial_translation" else mode
        located = "no (starting value)" if short in efit.unconstrained else "yes"
        out.append(f"| {mode} | {omega / (2 * np.pi):.2f} | {efit.zeta.get(mode, float('nan')):.3f} | {k:.4g} {unit} | "
                   f"{'–' if not np.isfinite(rel) else f'{100 * rel:.2g} %'} | {located} |")
    out += ["", f"Imbalances: U_s {p.U_s:.4g} kg·m, U_d {p.U_d:.4g} kg·m²; all parameters: `extended_params.csv` "
            f"({len(params_to_dict(p)) - 1} values).", "",
            "### Error of the models against the data (RMS of (model − data)/data, data noise floor removed)", "",
            "| direction | extended, every speed | extended, where modes act | empirical, where modes act |",
            "|---|---|---|---|"]
    for d, c in comparison.items():
        ok = c["data"] > 0
        every = float(np.sqrt(np.mean(((c["extended"][ok] - c["data"][ok]) / c["data"][ok]) ** 2))) if ok.any() \
            else float("nan")
        out.append(f"| {d} | {100 * every:.2g} % | {100 * c['error_extended']:.2g} % | "
                   f"{100 * c['error_empirical']:.2g} % |")
    out.append("")
    for mode, db in efit.residual_db.items():
        out.append(f"- residual near {mode}: {db:.2f} dB RMS" + (" (a linear model does not match this resonance "
                                                                     "well)" if db > 2.0 else ""))
    out += [f"- note: {n}" for n in efit.notes]
    if efit.unconstrained:
        out.append(f"- UNCONSTRAINED by the data (starting values, listed in the model file): "
                   f"{', '.join(efit.unconstrained)}")
    if model is not None:
        out += ["", "### Forcing lines of the model file (through the modes; amplitude C·Ω² before the modes)", "",
                "| direction | h | sense | C (SI) |", "|---|---|---|---|"]
        out += [f"| {d} | {hm.h:.4g} | {hm.sense or 'co'} | {hm.C:.4g} {DIRECTION_C_UNIT[d]} |"
                for d in DIRECTION_CHANNELS for hm in model.harmonics(d)]
        out.append("- the co-rotating radial lines at h = 1 are the imbalances: U_s, U_d of the analytical section take "
                   "their place")
    return out


def plot_extended_rms(comparison: dict, direction: str, ax=None, band_hz: float | None = None):
    """RMS vs speed of the data (noise floor removed), the empirical and the extended model;
    speeds where modes act (excluded ranges of the empirical fit) shaded."""
    c = comparison[direction]
    if ax is None:
        fig = _new_figure((8.0, 4.8))
        ax = fig.add_subplot(1, 1, 1)
    else:
        fig = ax.figure
    order = np.argsort(c["speed_rpm"])
    rpm = c["speed_rpm"][order]
    shade = c["in_modes"][order]
    if shade.any():
        ax.fill_between(rpm, 0, 1, where=shade, transform=ax.get_xaxis_transform(), color="tab:red", alpha=0.08,
                        label="modes act (empirical exclusion)")
    log_axis(ax)
    ax.plot(rpm, c["data"][order], "o", ms=3, color="k", zorder=DATA_ZORDER, label="data (noise floor removed)")
    ax.plot(rpm, c["empirical"][order], "-", color="tab:orange", zorder=MODEL_ZORDER,
            label=f"empirical model (error in modes {100 * c['error_empirical']:.1f} %)")
    ax.plot(rpm, c["extended"][order], "-", color="tab:blue", zorder=MODEL_ZORDER,
            label=f"extended model (error in modes {100 * c['error_extended']:.1f} %)")
    ax.set_xlabel("Wheel speed |Ω| (rpm)")
    ax.set_ylabel(f"RMS ({_direction_unit(direction)})")
    band = f" over 0–{band_hz:.0f} Hz" if band_hz else ""
    ax.set_title(f"{_direction_label(direction)}: RMS{band}, data vs empirical and extended model")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig, ax


def plot_extended_lines(efit, direction: str, fig=None):
    """One panel per harmonic of ``direction``: measured line amplitude vs speed (every speed),
    the extended model's |A| (modal amplification included) and the hard-mounted C·Ω²."""
    from .extended import steady_lines

    pairs = [x for x in efit.measured if x.direction == direction]
    if not pairs:
        return None
    n = len(pairs)
    cols = min(3, n)
    rows_ = int(np.ceil(n / cols))
    fig = fig if fig is not None else _new_figure((4.2 * cols, 3.2 * rows_))
    ch = DIRECTION_CHANNELS[direction][0]
    k_ch = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz").index(ch)
    for i, x in enumerate(pairs):
        ax = fig.add_subplot(rows_, cols, i + 1)
        parts = efit.parts_of(direction, x.h)
        w = np.linspace(np.abs(x.speed).min(), np.abs(x.speed).max(), 400)
        _, A = steady_lines(efit.params, parts, w)
        model_amp = np.sqrt(np.sum(np.abs(A[:, :, k_ch]) ** 2, axis=1))   # parts add in power
        c_total = float(np.sqrt(sum(p.C**2 for p in parts)))
        rpm = w * RAD_S_TO_RPM
        sel = np.asarray(x.channel) == ch
        ax.plot(np.abs(x.speed[sel]) * RAD_S_TO_RPM, x.amplitude[sel], "o", ms=3, color="k", zorder=DATA_ZORDER,
                label=f"data {ch}")
        ax.plot(rpm, model_amp, "-", color="tab:blue", zorder=MODEL_ZORDER, label="extended model")
        ax.plot(rpm, c_total * w**2, "--", color="tab:orange", zorder=MODEL_ZORDER, label="C·Ω² (hard-mounted)")
        log_axis(ax)
        sense = "+".join(p.sense for p in parts)
        ax.set_title(f"h = {x.h:.2f} ({sense})", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        if i % cols == 0:
            ax.set_ylabel(f"Amplitude ({_direction_unit(direction)})")
        if i >= n - cols:
            ax.set_xlabel("Wheel speed |Ω| (rpm)")
    fig.axes[0].legend(fontsize=7)
    f_all = np.concatenate([x.h * np.abs(x.speed) / (2 * np.pi) for x in pairs])
    fig.suptitle(f"{_direction_label(direction)}: line amplitudes ({f_all.min():.3g}–{f_all.max():.3g} Hz), data vs "
                 "extended model")
    return fig


def rms_columns(comparison: dict) -> list:
    """extended_rms_vs_speed.csv's columns: ``speed_rpm``, then per direction of ``comparison`` (radial force, radial
    torque, axial force, as :func:`rwadist.extended_fit.rms_comparison` holds them) with its first channel <ch> and
    its unit <unit> (N, Nm): ``data_floor_removed_<ch>_rms_<unit>``, ``empirical_<ch>_rms_<unit>``,
    ``extended_<ch>_rms_<unit>`` and ``modes_act_<direction>``."""
    cols = ["speed_rpm"]
    for d in comparison:
        c = DIRECTION_CHANNELS[d][0]
        u = CHANNEL_UNIT[c]
        cols += [f"data_floor_removed_{c}_rms_{u}", f"empirical_{c}_rms_{u}", f"extended_{c}_rms_{u}", f"modes_act_{d}"]
    return cols


def write_rms_csv(comparison: dict, spectra, path) -> Path:
    """extended_rms_vs_speed.csv: one row per spinning run of ``spectra`` with a direction's first channel, in the
    test's order, its speed signed (rpm); per direction (:func:`rms_columns`) the data's RMS with the noise floor's
    mean square removed, the empirical and the extended model's RMS (N or N·m, over (0, band limit]) and whether the
    speed lies inside an excluded (modal) range of the direction; cells of a run without the channel left empty.
    ``comparison``: :func:`rwadist.extended_fit.rms_comparison`'s.  Returns the path."""
    runs = sorted({int(r) for c in comparison.values() for r in c["runs"]})
    rows = {r: {"speed_rpm": float(spectra.speed[r]) * RAD_S_TO_RPM} for r in runs}
    for d, c in comparison.items():
        ch = DIRECTION_CHANNELS[d][0]
        u = CHANNEL_UNIT[ch]
        for k, r in enumerate(c["runs"]):
            rows[int(r)] |= {f"data_floor_removed_{ch}_rms_{u}": float(c["data"][k]),
                             f"empirical_{ch}_rms_{u}": float(c["empirical"][k]),
                             f"extended_{ch}_rms_{u}": float(c["extended"][k]), f"modes_act_{d}": bool(c["in_modes"][k])}
    cols = rms_columns(comparison)
    return write_rows(path, cols, ([row.get(col) for col in cols] for row in rows.values()))


#: a relative standard error below this is no estimate: the least squares did not move the parameter
NOT_MOVED = 1e-9


def param_rel_stderr(efit, name: str) -> float:
    """The relative standard error (σ/value) of the extended model's parameter ``name`` (a key of the fit's
    parameters: "k_r", "c_rock", "U_s", ...) from the extended fit ``efit``'s final least squares, NaN where it has
    none: a stiffness or damping of a mode the least squares did not leave free (held at its starting value), a
    damping it held (its mode in ``efit.zeta_bounds``) or pinned at its ceiling (the least squares does not move it:
    its error would read 0, below :data:`NOT_MOVED`), the mass, the inertias and the lever arm (given, or per unit, or the rocking scan's ratio: not fitted there).  The
    imbalances U_s and U_d are the coefficients of the h = 1 co-rotating radial force and torque lines: their lines'
    errors."""
    if name in ("U_s", "U_d"):
        d = "radial_force" if name == "U_s" else "radial_torque"
        line = next((ln for ln in efit.lines if ln.imbalance and ln.direction == d), None)
        return float("nan") if line is None else float(
            efit.rel_stderr.get(f"C[{line.direction},{line.h:g},{line.sense}]", float("nan")))
    held = {"c_r": "radial_translation", "c_rock": "rocking", "c_z": "axial_translation"}.get(name)
    rel = float(efit.rel_stderr.get(name, float("nan")))
    # a parameter the least squares does not move (a held damping, or one pinned at its ceiling: its column of the
    # Jacobian zero) comes out with an error of 0, or of rounding's 1e-18
    return float("nan") if held in efit.zeta_bounds or rel < NOT_MOVED else rel


def param_rows(efit, comparison: dict) -> list:
    """extended_params.csv's rows [parameter, value, rel_stderr]: the model file's ``analytical`` parameters (units in
    their names) with :func:`param_rel_stderr`, the modes' damping ratios and the models' errors where modes act
    (fractions; no standard error: NaN)."""
    from .extended import params_to_dict

    nan = float("nan")
    rows = []
    for key, value in params_to_dict(efit.params).items():
        if key == "kind":
            continue
        name = next(n for n, k in PARAM_KEYS.items() if k == key)
        rows.append([key, value, param_rel_stderr(efit, name)])
    rows += [[f"zeta_{mode}", z, nan] for mode, z in efit.zeta.items()]
    for d, c in comparison.items():
        rows += [[f"rms_error_in_modes_empirical_{d}", c["error_empirical"], nan],
                 [f"rms_error_in_modes_extended_{d}", c["error_extended"], nan]]
    return rows


def write_extended_report(efit, fit, out_dir, model=None, report_files=None) -> list:
    """Extended-model part of the report: ``extended_rms_<direction>.png``,
    ``extended_lines_<direction>.png``, ``extended_rms_vs_speed.csv`` and ``extended_params.csv``.
    With ``report_files`` (what :func:`write_report` wrote in ``out_dir``), summary.md is written again as the
    extended fit's report: the extended model (``model``, the model file's) first -- its modes, its errors, every
    file -- then the empirical fit it started from."""
    from .extended_fit import rms_comparison

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    comparison = rms_comparison(efit, fit)
    files = []
    for d in comparison:
        fig, _ = plot_extended_rms(comparison, d, band_hz=fit.spectra.band_limit)
        files.append(_save(fig, out / f"extended_rms_{d}.png"))
        fig = plot_extended_lines(efit, d)
        if fig is not None:
            files.append(_save(fig, out / f"extended_lines_{d}.png"))
    files.append(write_rms_csv(comparison, fit.spectra, out / "extended_rms_vs_speed.csv"))
    files.append(write_rows(out / "extended_params.csv", ["parameter", "value", "rel_stderr"],
                            param_rows(efit, comparison)))
    if report_files is not None:
        top = _band_top(fit.spectra, None)
        every = [f for f in report_files if Path(f).name != "summary.md"] + files
        (out / "summary.md").write_text(_summary_md(fit, harmonic_rows(fit), compare.rms_table(fit, top), top, every,
                                                    extended=_extended_md(efit, comparison, model)))
    return files
