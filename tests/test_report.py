"""Model validation (thesis §3.1.4) and the report writer.

The data are generated: sinusoids C·Ω² at h·|Ω| plus white noise, so every
number compared has an independent closed form (Eq. 3.19, Parseval).
"""
from __future__ import annotations

import csv

import numpy as np
import pytest
from matplotlib.image import imread

from rwadist import compare, report
from rwadist.data import Run, SteadyTest
from rwadist.empirical import BinStat, EmpiricalFit, LineFit
from rwadist.model import Harmonic, WheelModel
from rwadist.spectra import compute_spectra, line_amplitude
from rwadist.units import RAD_S_TO_RPM, rpm_to_rad_s

FS = 1024.0          # Hz
N = 8192             # samples per run (8 s)
NPERSEG = 1024       # 1 Hz bins
F_LIM = 300.0        # Hz, band limit of "good data"
NOISE = 1e-3         # N, white noise standard deviation
RPM = np.concatenate([[0.0], np.arange(600.0, 3001.0, 200.0)])
#: true harmonics (h, C kg·m); h = 7 leaves the band above ~2570 rpm
TRUE = {"radial_force": [(1.0, 3.79e-6), (2.5, 1.0e-6), (7.0, 4.0e-7)],
        "axial_force": [(1.5, 2.0e-6)]}
MODAL = (2.5, 1400.0, 1800.0, 3.0)   # h, lo rpm, hi rpm, amplification of the data


def _amp(direction, h, C, rpm):
    a = C * rpm_to_rad_s(rpm) ** 2
    if direction == "radial_force" and h == MODAL[0] and MODAL[1] <= rpm <= MODAL[2]:
        a = a * MODAL[3]
    return a


def _make_test():
    rng = np.random.default_rng(7)
    t = np.arange(N) / FS
    runs, clean = [], []
    for rpm in RPM:
        w = abs(rpm_to_rad_s(rpm))
        sig = {}
        for ch, direction, shift in (("Fx", "radial_force", 0.0), ("Fy", "radial_force", np.pi / 2),
                                     ("Fz", "axial_force", 0.0)):
            x = np.zeros(N)
            for h, C in TRUE[direction]:
                x += _amp(direction, h, C, rpm) * np.sin(h * w * t + rng.uniform(0, 2 * np.pi) + shift)
            sig[ch] = x
        clean.append(sig)
        runs.append(Run(speed=float(rpm_to_rad_s(rpm)), sample_rate=FS,
                        signals={ch: x + NOISE * rng.standard_normal(N) for ch, x in sig.items()},
                        name=f"run_{int(rpm):04d}.csv"))
    return SteadyTest(runs), clean


def _eq310(d, w):
    return float(np.sum(d * w**2) / np.sum(w**4))


def _hand_fit(spectra):
    """An EmpiricalFit built by hand: line amplitudes measured at the known h·Ω, Eq. 3.10."""
    lines, bins = [], []
    model = WheelModel(name="synthetic")
    for direction, chans in (("radial_force", ("Fx", "Fy")), ("axial_force", ("Fz",))):
        hs = []
        for h, _ in TRUE[direction]:
            w_runs = np.abs(spectra.speed)
            ok = (w_runs > 0) & (h * w_runs / (2 * np.pi) <= spectra.band_limit)
            w = np.tile(w_runs[ok], len(chans))
            ch = np.repeat(np.array(chans), ok.sum())
            d = np.concatenate([line_amplitude(spectra.psd[c][ok], spectra.f, h * w_runs[ok] / (2 * np.pi))
                                for c in chans])
            rpm = w * RAD_S_TO_RPM
            excl = [[MODAL[1], MODAL[2]]] if (direction == "radial_force" and h == MODAL[0]) else []
            used = np.ones(w.size, bool)
            for lo, hi in excl:
                used &= ~((rpm >= lo) & (rpm <= hi))
            C = _eq310(d[used], w[used])
            resid = d[used] - C * w[used] ** 2
            se = float(np.sqrt(np.sum(resid**2) / (used.sum() - 1) / np.sum(w[used] ** 4)))
            n_possible = int(ok.sum() * len(chans))
            lines.append(LineFit(direction, h, C, se, _eq310(d, w), w, ch, d, used, excl, 1.0, n_possible))
            bins.append(BinStat(direction, h, n_possible, n_possible, 1.0, True))
            hs.append(Harmonic(h=h, C=C, C_stderr=se, n_points=int(used.sum()), presence=1.0, excluded_rpm=excl))
        model.empirical[direction] = hs
    bins.append(BinStat("radial_force", 3.3, 2, 26, 2 / 26, False))
    return EmpiricalFit(model=model, spectra=spectra, lines=lines, bins=bins, settings={"source": "test"})


@pytest.fixture(scope="module")
def data():
    test, clean = _make_test()
    sp = compute_spectra(test, nperseg=NPERSEG, f_lim=F_LIM)
    sp_full = compute_spectra(test, nperseg=NPERSEG)
    return {"test": test, "clean": clean, "spectra": sp, "full": sp_full, "fit": _hand_fit(sp)}


def _true_model():
    return WheelModel(name="true", empirical={"radial_force": [Harmonic(h, C) for h, C in TRUE["radial_force"]],
                                              "axial_force": [Harmonic(h, C) for h, C in TRUE["axial_force"]],
                                              "radial_torque": [], "axial_torque": []})


# --------------------------------------------------------------------------- compare.py

def test_data_rms_is_time_domain_rms(data):
    """Parseval: integrated Welch PSD over the full band = time-domain RMS of each run."""
    for ch in ("Fx", "Fz"):
        x = np.stack([r.signals[ch] for r in data["test"].runs])
        direct = np.std(x, axis=1)
        np.testing.assert_allclose(compare.data_rms(data["full"], ch), direct, rtol=0.01)


def test_data_rms_band_limited_matches_lines_in_band(data):
    """Over [0, 300 Hz] the data RMS is the lines below 300 Hz plus that share of the noise,
    whatever f_max asks above the band limit."""
    sp = data["spectra"]
    w = np.abs(sp.speed)
    expect2 = np.full(w.size, NOISE**2 * F_LIM / (FS / 2))
    for h, C in TRUE["radial_force"]:
        amp = np.array([_amp("radial_force", h, C, r) for r in np.abs(RPM)])
        expect2 += np.where(h * w / (2 * np.pi) <= F_LIM, amp**2 / 2, 0.0)
    got = compare.data_rms(sp, "Fx", f_max=1e9)
    np.testing.assert_allclose(got, np.sqrt(expect2), rtol=0.02)
    # at the top speeds the h = 7 line is outside the band: the full-band mean square exceeds
    # the band-limited one by that line's variance plus the noise above 300 Hz
    top = np.abs(RPM) >= 2600
    extra = compare.data_rms(data["full"], "Fx")[top] ** 2 - got[top] ** 2
    h7 = (TRUE["radial_force"][2][1] * rpm_to_rad_s(RPM[top]) ** 2) ** 2 / 2
    np.testing.assert_allclose(extra, h7 + NOISE**2 * (1 - F_LIM / (FS / 2)), rtol=0.1)


def test_model_rms_eq_3_19_by_hand():
    C1, C2, h1, h2 = 3.0e-6, 1.0e-6, 1.0, 4.0
    m = WheelModel(empirical={"radial_force": [Harmonic(h1, C1), Harmonic(h2, C2)]})
    Om = np.array([100.0, -200.0, 300.0])
    hand = np.sqrt((C1**2 + C2**2) * Om**4 / 2)
    np.testing.assert_allclose(compare.model_rms_vs_speed(m, "radial_force", Om), hand, rtol=1e-12)
    # f_max between the two lines at 300 rad/s (47.7 and 191 Hz): only h1 counts there
    got = compare.model_rms_vs_speed(m, "radial_force", Om, f_max=100.0)
    np.testing.assert_allclose(got, [hand[0], np.sqrt(C1**2 * 200.0**4 / 2), C1 * 300.0**2 / np.sqrt(2)],
                               rtol=1e-12)
    f, var = compare.model_psd_lines(m, "radial_force", Om)
    np.testing.assert_allclose(f[1], [h1 * 200 / (2 * np.pi), h2 * 200 / (2 * np.pi)])
    np.testing.assert_allclose(var[2], [C1**2 * 300.0**4 / 2, C2**2 * 300.0**4 / 2])


def test_staircase_steps_at_lines_and_ends_at_model_rms():
    m = WheelModel(empirical={"axial_force": [Harmonic(1.0, 2e-6), Harmonic(2.7, 5e-7), Harmonic(5.2, 1e-7)]})
    Om = 250.0
    f = np.linspace(0.0, 400.0, 4001)
    stair = compare.model_cumulative_rms(m, "axial_force", Om, f)
    assert stair.shape == f.shape
    assert stair[-1] == pytest.approx(compare.model_rms_vs_speed(m, "axial_force", Om)[0], rel=1e-12)
    f_line, var = compare.model_psd_lines(m, "axial_force", Om)
    for k, fl in enumerate(f_line[0]):
        below = f < fl
        np.testing.assert_allclose(stair[below][-1], np.sqrt(var[0][:k].sum()), rtol=1e-12, atol=0)
        np.testing.assert_allclose(stair[~below][0], np.sqrt(var[0][:k + 1].sum()), rtol=1e-12)
    assert np.all(np.diff(stair) >= 0)
    # band-limited grid: last value = model RMS with the same f_max
    fb = f[f <= 150.0]
    assert compare.model_cumulative_rms(m, "axial_force", Om, fb)[-1] == pytest.approx(
        compare.model_rms_vs_speed(m, "axial_force", Om, f_max=150.0)[0], rel=1e-12)
    # many speeds at once agree with one at a time
    many = compare.model_cumulative_rms(m, "axial_force", np.array([100.0, Om]), f)
    np.testing.assert_array_equal(many[1], stair)


def test_model_psd_on_grid_parseval(data):
    m = _true_model()
    sp = data["spectra"]
    Om = np.abs(sp.speed)
    S = compare.model_psd_on_grid(m, "radial_force", Om, sp.f)
    total = np.sum(S, axis=-1) * sp.df
    # every line of the 14 speeds lies on the 0-512 Hz grid: integral = Eq. 3.15
    np.testing.assert_allclose(total, compare.model_rms_vs_speed(m, "radial_force", Om) ** 2, rtol=1e-12)
    # integrated alike with the data: over [0, band] model and data agree away from the modal range
    S_band = np.sum(S[:, sp.f <= F_LIM], axis=-1) * sp.df
    rpm = np.abs(RPM)
    ok = (rpm > 0) & ~((rpm >= MODAL[1]) & (rpm <= MODAL[2]))
    np.testing.assert_allclose(np.sqrt(S_band[ok]), compare.data_rms(sp, "Fx")[ok], rtol=0.03)
    # the line power in the model PSD sits where the data PSD has its line (h = 1 at 1200 rpm)
    j = int(np.argmin(np.abs(rpm - 1200)))
    k_model = np.argmax(compare.model_psd_on_grid(_only(m, 0), "radial_force", Om[j], sp.f))
    assert abs(k_model - np.argmax(sp.psd["Fx"][j])) <= 1


def _only(m, i):
    return WheelModel(empirical={"radial_force": [m.harmonics("radial_force")[i]]})


def test_rms_table_ratio_band_limited_alike(data):
    """With the true coefficients the model/data ratio is ~1 at every spinning speed outside the
    modal range, including the top speeds where h = 7 has left the band on both sides; inside it
    the amplified data exceed the model."""
    fit = data["fit"]
    fit_true = EmpiricalFit(model=_true_model(), spectra=fit.spectra, lines=fit.lines, bins=fit.bins)
    t = compare.rms_table(fit_true)
    assert list(t)[:1] == ["speed_rpm"]
    for col in ("data_Fx_rms_N", "data_Fy_rms_N", "data_Fz_rms_N", "model_radial_force_rms_N",
                "model_axial_force_rms_N", "ratio_Fx", "ratio_Fy", "ratio_Fz"):
        assert col in t and len(t[col]) == len(RPM)
    rpm = np.abs(t["speed_rpm"])
    modal = (rpm >= MODAL[1]) & (rpm <= MODAL[2])
    spin = rpm > 0
    for ch in ("Fx", "Fy", "Fz"):
        np.testing.assert_allclose(t[f"ratio_{ch}"][spin & ~modal], 1.0, atol=0.03)
    assert np.all(t["ratio_Fx"][modal] < 0.9)
    assert t["ratio_Fx"][~spin][0] == 0.0
    np.testing.assert_allclose(t["model_radial_force_rms_N"],
                               compare.model_rms_vs_speed(fit_true.model, "radial_force", fit.spectra.speed, F_LIM))


# --------------------------------------------------------------------------- report.py

def _read_csv(path):
    with open(path, newline="") as fh:
        r = csv.DictReader(fh)
        return r.fieldnames, list(r)


def test_hand_fit_recovers_true_coefficients(data):
    """Sanity of the fixture: Eq. 3.10 on the measured lines gives the generated C, and the
    modal amplification raises C_all above C only for the amplified harmonic."""
    for ln in data["fit"].lines:
        C_true = dict(TRUE[ln.direction])[ln.h]
        assert ln.C == pytest.approx(C_true, rel=0.02)
        if ln.excluded_rpm:
            assert ln.C_all > 1.1 * ln.C
        else:
            assert ln.C_all == pytest.approx(ln.C, rel=1e-12)


def test_write_report_files_and_tables(data, tmp_path):
    fit = data["fit"]
    files = report.write_report(fit, tmp_path)
    names = {p.name for p in files}
    expect = {"waterfall_Fx.png", "waterfall_Fy.png", "waterfall_Fz.png",
              "rms_vs_speed_radial_force.png", "rms_vs_speed_axial_force.png",
              "cumulative_rms_radial_force.png", "cumulative_rms_axial_force.png",
              "coefficients_radial_force.png", "coefficients_axial_force.png",
              "harmonics.csv", "rms_vs_speed.csv", "bins.csv", "excluded_ranges.csv", "summary.md"}
    assert names == expect
    for p in files:
        assert p.exists() and p.stat().st_size > 0
        if p.suffix == ".png":
            img = imread(p)
            assert img.shape[0] > 300 and img.shape[1] > 300
            assert img[..., :3].std() > 0.05  # not blank

    cols, rows = _read_csv(tmp_path / "harmonics.csv")
    assert cols == ["direction", "h", "C_SI", "C_stderr_SI", "C_all_SI", "n_points", "presence", "in_model",
                    "heldout_rel"]
    assert len(rows) == len(fit.lines)
    for ln in fit.lines:
        (r,) = [r for r in rows if r["direction"] == ln.direction and float(r["h"]) == ln.h]
        assert float(r["C_SI"]) == pytest.approx(ln.C, rel=1e-12)
        assert float(r["C_stderr_SI"]) == pytest.approx(ln.C_stderr, rel=1e-12)
        assert float(r["C_all_SI"]) == pytest.approx(ln.C_all, rel=1e-12)
        assert int(r["n_points"]) == int(ln.used.sum())
        assert r["in_model"] == "true"

    # a line's excluded ranges: the rows of excluded_ranges.csv with its direction and h, the same text
    harmonics = rows
    cols, rows = _read_csv(tmp_path / "excluded_ranges.csv")
    assert cols == ["direction", "h", "lo_rpm", "hi_rpm"]
    assert [(r["direction"], float(r["h"]), float(r["lo_rpm"]), float(r["hi_rpm"])) for r in rows] == \
        [("radial_force", MODAL[0], MODAL[1], MODAL[2])]
    for ln in fit.lines:
        (r,) = [r for r in harmonics if r["direction"] == ln.direction and float(r["h"]) == ln.h]
        ranges = [[float(x["lo_rpm"]), float(x["hi_rpm"])] for x in rows
                  if (x["direction"], x["h"]) == (r["direction"], r["h"])]
        assert ranges == ln.excluded_rpm

    cols, rows = _read_csv(tmp_path / "bins.csv")
    assert cols[:6] == ["direction", "h", "n_bin", "n_possible", "presence", "kept"]
    assert len(rows) == len(fit.bins)
    assert [r["kept"] for r in rows] == ["true" if b.kept else "false" for b in fit.bins]
    assert [int(r["n_bin"]) for r in rows] == [b.n_bin for b in fit.bins]

    table = compare.rms_table(fit)
    cols, rows = _read_csv(tmp_path / "rms_vs_speed.csv")
    assert cols == list(table)
    for c in cols:
        got = np.array([float(r[c]) if r[c] else np.nan for r in rows])
        np.testing.assert_allclose(got, table[c], rtol=1e-12, equal_nan=True)

    md = (tmp_path / "summary.md").read_text()
    assert "1400–1800" in md
    for n in expect:
        assert f"`{n}`" in md


def test_plot_functions_return_axes_with_units(data):
    fit = data["fit"]
    sp = fit.spectra
    fig, ax = report.plot_waterfall(sp, "Fx", model=fit.model, lines=fit.lines)
    assert ax.get_xlabel() == "Frequency (Hz)" and "rpm" in ax.get_ylabel()
    modal = [l for l in ax.get_lines() if l.get_label().startswith("excluded (modal) measurement")]
    (ln,) = [x for x in fit.lines if x.excluded_rpm]
    n_modal = int(np.sum((ln.channel == "Fx") & ~ln.used))
    # a pair of ticks either side of each: their midpoints sit at h·Ω of their runs
    assert n_modal > 0 and len(modal) == 1 and len(modal[0].get_xdata()) == 2 * n_modal
    x = np.asarray(modal[0].get_xdata())
    np.testing.assert_allclose(np.sort(0.5 * (x[:n_modal] + x[n_modal:])),
                               np.sort(ln.h * ln.speed[(ln.channel == "Fx") & ~ln.used] / (2 * np.pi)))
    # model markers: a pair of ticks per harmonic and speed with the line inside the band
    (mk,) = [l for l in ax.get_lines() if l.get_label().startswith("model lines h·Ω")]
    w = np.unique(np.abs(sp.speed))
    w = w[w > 0]  # no markers for the noise run
    n_in = sum(int(np.sum(h * w / (2 * np.pi) <= F_LIM)) for h, _ in TRUE["radial_force"])
    assert len(mk.get_xdata()) == 2 * n_in

    fig, (a_rms, a_ratio) = report.plot_rms_vs_speed(sp, fit.model, "radial_force")
    assert "(N)" in a_rms.get_ylabel() and a_ratio.get_ylabel() == "model / data"
    fig, (a_amp, a_cum) = report.plot_cumulative_rms(sp, fit.model, "radial_force", 2000.0)
    (stair,) = [l for l in a_cum.get_lines() if l.get_label() == "model (staircase)"]
    assert stair.get_ydata()[-1] == pytest.approx(
        compare.model_rms_vs_speed(fit.model, "radial_force", rpm_to_rad_s(2000.0), F_LIM)[0])
    fig, axes = report.plot_coefficients(fit.lines, "radial_force")
    assert len(axes) == 3 and all("h = " in a.get_title() for a in axes)
    np.testing.assert_allclose(report.default_speeds_rpm(sp), [600.0, 1800.0, 3000.0])


def test_negative_speeds_and_missing_channel(data, tmp_path):
    """Wheels reverse through zero: the model depends on |Ω|; a run lacking a channel gives NaN, not 0."""
    import dataclasses
    sp = data["spectra"]
    speed = sp.speed.copy()
    speed[1::2] *= -1.0
    psd = {ch: v.copy() for ch, v in sp.psd.items()}
    amp = {ch: v.copy() for ch, v in sp.amplitude.items()}
    psd["Fy"][3] = np.nan
    amp["Fy"][3] = np.nan
    sp2 = dataclasses.replace(sp, speed=speed, psd=psd, amplitude=amp)
    fit = data["fit"]
    fit2 = EmpiricalFit(model=fit.model, spectra=sp2, lines=fit.lines, bins=fit.bins)
    t1, t2 = compare.rms_table(fit), compare.rms_table(fit2)
    np.testing.assert_allclose(t2["speed_rpm"], speed * RAD_S_TO_RPM, rtol=1e-12)
    np.testing.assert_allclose(t2["model_radial_force_rms_N"], t1["model_radial_force_rms_N"], rtol=1e-12)
    assert np.isnan(t2["data_Fy_rms_N"][3]) and np.isnan(t2["ratio_Fy"][3])
    np.testing.assert_allclose(np.delete(t2["ratio_Fy"], 3), np.delete(t1["ratio_Fy"], 3), rtol=1e-12)
    # report with a narrower band and one cumulative-RMS speed
    files = report.write_report(fit2, tmp_path, cumulative_speeds_rpm=[1000.0], f_max=200.0)
    assert all(p.stat().st_size > 0 for p in files)
    assert (tmp_path / "cumulative_rms_radial_force.png") in files
    _, rows = _read_csv(tmp_path / "rms_vs_speed.csv")
    assert rows[3]["data_Fy_rms_N"] == "" and float(rows[1]["speed_rpm"]) < 0
    np.testing.assert_allclose([float(r["data_Fx_rms_N"]) for r in rows], compare.data_rms(sp2, "Fx", 200.0),
                               rtol=1e-12)
    np.testing.assert_allclose([float(r["model_radial_force_rms_N"]) for r in rows],
                               compare.model_rms_vs_speed(fit.model, "radial_force", speed, 200.0), rtol=1e-12)
