"""Broadband PSD over a wheel-speed law (Melody's model and the extended model), `rwadist psd`,
NASTRAN output.  Every check is against an independent computation: scipy quadrature of the
pdf (Parseval), the pointwise closed form S(f) = Σ σ²(Ω) p(Ω) |dΩ/df|, a Monte Carlo of the
virtual test stand at drawn speeds, pyNastran's reader."""
import json

import numpy as np
import pytest
from scipy import integrate, signal

from rwadist import broadband as bb
from rwadist import extended as ext
from rwadist import psd_files
from rwadist.cli import main
from rwadist.data import DataError
from rwadist.model import Harmonic, WheelModel, save
from rwadist.presets import preset
from rwadist.teststand import simulate_steady
from rwadist.units import RAD_S_TO_RPM, rpm_to_rad_s

E_MODEL = preset("ithaco-e").to_model()
W = float(rpm_to_rad_s(1.0))


def laws():
    return {"uniform": bb.Uniform(300 * W, 3000 * W),
            "normal": bb.TruncatedNormal(1500 * W, 400 * W, 300 * W, 3000 * W),
            "bidirectional": bb.Uniform(-3000 * W, 2000 * W)}


def _quad(fun, law):
    lo, hi = law.support
    pts = [0.0] if lo < 0 < hi else None
    return integrate.quad(lambda w: fun(w) * float(law.pdf(w)), lo, hi, points=pts, limit=400,
                          epsabs=0, epsrel=1e-10)[0]


@pytest.mark.parametrize("name", ["uniform", "normal", "bidirectional"])
def test_parseval_empirical(name):
    law = laws()[name]
    res = bb.broadband_psd(bb.empirical_lines(E_MODEL), law, 400.0, 40001, 2000)
    ms = res.mean_square()
    for c, d in ((0, "radial_force"), (1, "radial_force"), (2, "axial_force"), (3, "radial_torque")):
        h, C = E_MODEL.h_and_C(d)
        q = _quad(lambda w: float(np.sum(C**2 * w**4 / 2)), law)
        assert ms[c] == pytest.approx(q, rel=5e-3)
        assert abs(ms[c] / q - 1) < 1e-5          # measured: ~1e-6 (midpoint rule on 2000 cells)


@pytest.mark.parametrize("name", ["uniform", "normal"])
def test_parseval_extended(name):
    law = laws()[name]
    lines = bb.extended_lines_from_model(E_MODEL)
    res = bb.broadband_psd(lines, law, 400.0, 40001, 3000)
    p = ext.params_from_model(E_MODEL)
    imb = [ln for ln in lines.groups[0]]
    others = [g[0] for g in lines.groups[1:]]

    def ms_at(w, c):   # |A|²/2 summed over sources, via steady_rms (imbalances coherent, others apart)
        r1 = ext.steady_rms(p, imb, [w])[0, c] ** 2 if imb else 0.0
        return r1 + sum(ext.steady_rms(p, [ln], [w])[0, c] ** 2 for ln in others)

    for c in (0, 2, 3):
        q = _quad(lambda w: ms_at(w, c), law)
        assert res.mean_square()[c] == pytest.approx(q, rel=5e-3)


def test_pointwise_closed_form_empirical_and_extended():
    """Binned PSD vs S(f) = Σ_i Σ_± σ_i²(Ω) p(Ω) 2π/h_i at bin centres, away from the law's edges."""
    law = bb.Uniform(-2500 * W, 3000 * W)
    C, h = 2e-6, 2.0
    m = WheelModel(name="one", empirical={"radial_force": [], "radial_torque": [], "axial_torque": [],
                                          "axial_force": [Harmonic(h=h, C=C)]},
                   analytical=ext.params_to_dict(ext.from_table_4_2()))
    f_max = 150.0
    res = bb.broadband_psd(bb.empirical_lines(m), law, f_max, 15001, 4000)
    f = res.f
    wf = 2 * np.pi * f / h
    expect = 2 * (C * wf**2) ** 2 / 2 * (1 / 5500 / W) * 2 * np.pi / h          # both roots inside
    expect = np.where(wf > 2500 * W, expect / 2, expect)                        # only +Ω above 2500 rpm
    # the binned PSD is piecewise constant per speed cell (h·ΔΩ/2π = 0.046 Hz here, 4.6 bins):
    # compare 0.5 Hz averages (50 bins) of both
    def avg(x):
        n = x.size // 50 * 50
        return x[:n].reshape(-1, 50).mean(axis=1)

    fa = avg(f)
    sel = (fa > 5) & (np.abs(2 * np.pi * fa / h - 2500 * W) > 15 * W) & (2 * np.pi * fa / h < 2985 * W)
    np.testing.assert_allclose(avg(res.psd[:, 2])[sel], avg(expect)[sel], rtol=2e-3)
    # extended: axial mode transmissibility |(k + icν)/(k − Mν² + icν)|² inside the integral
    p = ext.from_table_4_2()
    rese = bb.broadband_psd(bb.extended_lines_from_model(m), law, f_max, 15001, 4000)
    nu = h * wf
    T2 = np.abs((p.k_z + 1j * p.c_z * nu) / (p.k_z - p.mass * nu**2 + 1j * p.c_z * nu)) ** 2
    np.testing.assert_allclose(avg(rese.psd[:, 2])[sel], avg(expect * T2)[sel], rtol=5e-3)
    assert T2.max() > 50          # the 70 Hz axial mode really amplifies (h = 2 crosses it at 2100 rpm)


def _mc_band_check(test, res, bands, channels, nperseg):
    """Band powers of each run's Welch PSD vs the analytic PSD; returns max |z| and the draws."""
    per_run = []
    for run in test.runs:
        x = np.vstack([run.signals[ch] for ch in channels])
        fw, P = signal.welch(x, fs=run.sample_rate, nperseg=nperseg, window="hann")
        dfw = fw[1] - fw[0]
        per_run.append([P[:, (fw >= a) & (fw < b)].sum(axis=1) * dfw for a, b in bands])
    X = np.array(per_run)                                     # (draws, bands, channels)
    mean, se = X.mean(axis=0), X.std(axis=0, ddof=1) / np.sqrt(X.shape[0])
    idx = [list(("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")).index(c) for c in channels]
    ana = np.array([[res.psd[(res.f >= a - res.df / 2) & (res.f < b - res.df / 2)][:, i].sum() * res.df
                     for i in idx] for a, b in bands])
    # bands without lines in a channel (e.g. Fz above its top harmonic) hold only leakage: both ~0
    empty = (ana < 1e-6 * ana.sum(axis=0)) & (mean < 1e-6 * mean.sum(axis=0))
    z = np.where(empty, 0.0, (mean - ana) / np.where(empty, 1.0, se))
    return z, X.shape[0]


@pytest.mark.slow
@pytest.mark.parametrize("physics", ["simple", "extended"])
def test_monte_carlo_virtual_stand(physics):
    """Steady runs of the virtual stand at speeds drawn from the law (no noise, no fixture, no simple
    modes), Welch-averaged; band powers inside ±4 Monte Carlo standard errors of the analytic PSD."""
    wheel = preset("ithaco-e")
    law = bb.TruncatedNormal(1500 * W, 500 * W, 300 * W, 2700 * W)
    rng = np.random.default_rng(7)
    speeds = law.sample(rng, 400) * RAD_S_TO_RPM
    kw = dict(sample_rate=1024.0, n_samples=4096, noise=0.0, test_stand=False, seed=3, physics=physics)
    if physics == "simple":
        kw["modes"] = False
    test = simulate_steady(wheel, speeds, **kw)
    lines = bb.preset_lines("ithaco-e", empirical=(physics == "simple"))
    res = bb.broadband_psd(lines, law, 400.0, 16001, 2000)
    bands = [(a, a + 20.0) for a in np.arange(10.0, 230.0, 20.0)]   # lines reach 251 Hz
    z, n = _mc_band_check(test, res, bands, ("Fx", "Fz", "Tx"), 1024)
    assert n == 400
    print(f"MC {physics}: {n} draws, max |z| = {np.abs(z).max():.2f} over {z.size} band/channel cells")
    assert np.abs(z).max() < 4.0, z


def test_speed_law_validation_errors():
    with pytest.raises(DataError, match="empty or inverted"):
        bb.Uniform(2.0, 1.0)
    with pytest.raises(DataError, match="empty or inverted"):
        bb.Uniform(1.0, 1.0)
    with pytest.raises(DataError, match="std"):
        bb.TruncatedNormal(1.0, 0.0, 0.0, 2.0)
    with pytest.raises(DataError, match="pdf: integrates to 0.5"):
        bb.Histogram((0.0, 1.0, 2.0), (0.25, 0.25))
    with pytest.raises(DataError, match="fmax"):
        bb.broadband_psd(bb.empirical_lines(E_MODEL), bb.Uniform(0, 3000 * W), 30.0, 101, 10)


def test_pdf_csv_not_normalised_and_time_profile(tmp_path):
    p = tmp_path / "pdf.csv"
    p.write_text("speed_rpm,pdf_per_rpm\n1000,0.001\n2000,0.001\n3000,0.001\n")
    # a density sampled at its rows: it spans 1000-3000 rpm (each row's bin halfway to its neighbours), 2 in all
    with pytest.raises(DataError, match="pdf_per_rpm: integrates to 2 over rpm"):
        bb.law_from_csv(p)
    # histogram weights are relative: normalised
    q = tmp_path / "hist.csv"
    q.write_text("speed_rpm,weight\n1000,1\n2000,3\n3000,0\n")
    law = bb.law_from_csv(q)
    assert float(law.cdf(2500 * W)) == pytest.approx(1.0)
    assert float(law.cdf(1500 * W)) == pytest.approx(0.25)
    # time profile: ramp 0->3000 rpm over 10 s then 3000->1000 over 10 s = uniform 0..1000 (weight 1/2)
    # + uniform 1000..3000 (weight 1/2 from the first ramp's upper part... computed exactly below)
    t = np.array([0.0, 10.0, 20.0])
    r = tmp_path / "prof.csv"
    r.write_text("time_s,speed_rpm\n" + "\n".join(f"{a},{b}" for a, b in zip(t, [0, 3000, 1000])))
    law = bb.law_from_csv(r)
    for s in (500.0, 1000.0, 2000.0, 2900.0):
        exact = 0.5 * s / 3000 + 0.5 * np.clip((s - 1000) / 2000, 0, 1)
        assert float(law.cdf(s * W)) == pytest.approx(exact, abs=2e-3)


def test_negative_speed_cross_term_and_hermitian():
    """Co-rotating radial line: csd[Fx,Fy] = +i|A|²/2-weighted for Ω > 0 and −i for Ω < 0 (the
    90° relation), so a law symmetric in ±Ω has no x–y cross term; PSD matrix is PSD."""
    m = WheelModel(name="co", empirical={"radial_force": [Harmonic(h=1.0, C=3e-6)], "radial_torque": [],
                                         "axial_force": [], "axial_torque": []})
    pos = bb.broadband_psd(bb.empirical_lines(m), bb.Uniform(300 * W, 3000 * W), 300.0, 3001, 500)
    neg = bb.broadband_psd(bb.empirical_lines(m), bb.Uniform(-3000 * W, -300 * W), 300.0, 3001, 500)
    sym = bb.broadband_psd(bb.empirical_lines(m), bb.Uniform(-3000 * W, 3000 * W), 300.0, 3001, 500)
    assert np.abs(sym.csd[:, 0, 1]).max() < 1e-9 * sym.psd[:, 0].max()
    k = np.argmax(pos.psd[:, 0])
    assert pos.csd[k, 0, 1] == pytest.approx(1j * pos.psd[k, 0], rel=1e-9)
    assert neg.csd[k, 0, 1] == pytest.approx(-1j * neg.psd[k, 0], rel=1e-9)
    # scipy's csd is conj(ours): check the sign on a sampled co-rotating line
    t = np.arange(8192) / 1024.0
    x, y = np.cos(2 * np.pi * 50 * t), np.sin(2 * np.pi * 50 * t)
    fs, Pxy = signal.csd(x, y, fs=1024.0, nperseg=1024)
    assert np.conj(Pxy[np.argmax(np.abs(Pxy))]).imag > 0
    ev = np.linalg.eigvalsh(bb.broadband_psd(bb.extended_lines_from_model(E_MODEL), bb.Uniform(-3000 * W, 3000 * W),
                                             400.0, 4001, 1000).csd)
    assert ev.min() >= -1e-12 * ev.max()


def _pynastran_bdf():
    pytest.importorskip("pyNastran")
    if not hasattr(np, "in1d"):               # pyNastran 1.4 uses np.in1d, removed in numpy 2.4
        np.in1d = np.isin
    from pyNastran.bdf.bdf import BDF
    return BDF


@pytest.mark.parametrize("fmt,rtol", [("small", 1e-4), ("free", 1e-9)])
def test_nastran_read_back_by_pynastran(tmp_path, fmt, rtol):
    BDF = _pynastran_bdf()
    deck = tmp_path / "deck.bdf"
    out = tmp_path / "psd.csv"
    argv = ["psd", "--preset", "ithaco-e", "--speed-rpm=-2000:3000", "--dist", "normal", "--n-freq", "801",
            "--n-speeds", "400", "--cross", "none"]
    assert main(argv + ["-o", str(out)]) == 0
    assert main(argv + ["--format", "nastran", "--nastran-fields", fmt, "--nastran-cross", "-o", str(deck)]) == 0
    f, psd = psd_files.read_psd_csv(out)
    full = tmp_path / "full.bdf"
    full.write_text("CEND\nBEGIN BULK\n" + deck.read_text() + "ENDDATA\n")
    model = BDF(debug=None)
    model.read_bdf(str(full), xref=False)
    entries = model.dload_entries[1]
    auto = {e.j: e.tid for e in entries if e.j == e.k}
    assert sorted(auto) == [1, 2, 3, 4, 5]                      # Tz is identically zero: skipped
    for j, tid in auto.items():
        tab = model.random_tables[tid]
        ch = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")[j - 1]
        np.testing.assert_allclose(tab.x, f, rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(tab.y, psd[ch], rtol=rtol, atol=rtol * psd[ch].max())
    assert any(e.j != e.k and e.y == 1.0 for e in entries)      # imaginary parts of cross terms


def test_cli_psd_outputs_and_errors(tmp_path, capsys):
    m = tmp_path / "e.json"
    save(E_MODEL, m)
    out = tmp_path / "psd.csv"
    assert main(["psd", str(m), "--speed-rpm", "300:3000", "--dist", "uniform", "--n-freq", "1001", "--empirical",
                 "-o", str(out)]) == 0
    header = out.read_text().splitlines()[0]
    assert header == "f_Hz,Fx_N2_per_Hz,Fy_N2_per_Hz,Fz_N2_per_Hz,Tx_Nm2_per_Hz,Ty_Nm2_per_Hz,Tz_Nm2_per_Hz"
    for suffix in ("_cross.csv", "_envelope.csv", "_envelope_harmonics.csv", ".png"):
        assert (tmp_path / ("psd" + suffix)).exists()
    cross = (tmp_path / "psd_cross.csv").read_text().splitlines()[0].split(",")
    assert len(cross) == 1 + 2 * 15 and "Fx_Tx_re_N2m_per_Hz" in cross
    # fmax below the first harmonic
    assert main(["psd", str(m), "--speed-rpm", "300:3000", "--fmax", "10", "-o", str(out)]) == 2
    assert "fmax" in capsys.readouterr().err
    # inverted range, missing model in a wheels file
    assert main(["psd", str(m), "--speed-rpm", "3000:300", "-o", str(out)]) == 2
    assert "empty or inverted" in capsys.readouterr().err
    wj = tmp_path / "wheels.json"
    wj.write_text(json.dumps({"wheels": [{"model": "nope.json", "mounting": {"preset": "pyramid-4", "index": 0}}]}))
    assert main(["psd", str(m), "--speed-rpm", "300:3000", "--wheels", str(wj), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "wheels[0].model" in err and "nope.json" in err and "does not exist" in err
    # flags the output or the law would ignore, and an extension naming the other format (each was taken silently)
    for extra, flag in ((["--nastran-cross"], "--nastran-cross"), (["--std-rpm", "100"], "--std-rpm"),
                        (["--format", "nastran"], "-o")):
        assert main(["psd", str(m), "--speed-rpm", "300:3000", "-o", str(out)] + extra) == 2
        assert f"{flag}: value:" in capsys.readouterr().err
    assert main(["psd", str(m), "--speed-rpm", "300:3000", "-o", str(tmp_path / "p.bdf")]) == 2
    assert "its extension names the other format" in capsys.readouterr().err


def test_envelope_is_largest_line_amplitude():
    lines = bb.empirical_lines(E_MODEL)
    f = np.linspace(0, 300, 3001)
    env = bb.line_envelope([(lines, None)], (300 * W, 3000 * W), f, 2000)
    h, C = E_MODEL.h_and_C("radial_force")
    # closed form: for a line h at f, amplitude C (2πf/h)²; envelope = max over lines in range
    wf = 2 * np.pi * f[:, None] / h[None, :]
    amp = np.where((wf >= 300 * W) & (wf <= 3000 * W), C * wf**2, 0).max(axis=1)
    np.testing.assert_allclose(env.amplitude[:, 0], amp, rtol=1e-5, atol=1e-9 * amp.max())
    row = [r for r in env.table if r["h"] == 1.0 and r["channel"] == "Fx"][0]
    assert row["max_amplitude"] == pytest.approx(C[0] * (3000 * W) ** 2, rel=1e-9)
    assert row["speed_rpm"] == pytest.approx(3000.0)


def test_histogram_file_within_the_speed_range_and_on_one_side_of_zero(tmp_path):
    """A histogram's outer bins (as wide as their neighbours) end at the speed range given beside the file, and never
    cross zero speed when every centre is on one side: centres 500 and 2500 rpm made a law over -500..3500 rpm (a
    wheel that reverses) whatever the range, and a file at 5000-6000 rpm was taken with --speed-rpm 300:3000."""
    q = tmp_path / "two.csv"
    q.write_text("speed_rpm,weight\n500,1\n2500,3\n")
    law = bb.law_from_spec(str(q), 300.0, 3000.0)
    assert law.support == pytest.approx((300 * W, 3000 * W))
    assert float(law.cdf(1500 * W)) == pytest.approx(0.25)          # the first bin, 300..1500 rpm, holds 1/4
    assert bb.law_from_csv(q).support == pytest.approx((0.0, 3500 * W))
    far = tmp_path / "far.csv"
    far.write_text("speed_rpm,weight\n5000,1\n6000,1\n")
    with pytest.raises(DataError, match=r"row 0 \(5000 rpm\) is outside the speed range 300:3000 rpm \(`speed_rpm`\)"):
        bb.law_from_spec(str(far), 300.0, 3000.0)
    prof = tmp_path / "prof.csv"
    prof.write_text("time_s,speed_rpm\n0,0\n10,3500\n")
    with pytest.raises(DataError, match=r"the profile spans 0:3500 rpm, outside the speed range 0:3000 rpm"):
        bb.law_from_spec(str(prof), 0.0, 3000.0)


@pytest.mark.parametrize("n_rows", [3, 5, 50])
def test_density_file_is_the_law_it_describes(tmp_path, n_rows):
    """A constant pdf_per_rpm over the range is the uniform law, whatever its number of rows: each bin's probability
    is the density times the bin's width (the outer bins end at the range; weighting the values alike gave the end
    bins double weight: Fx RMS +7.4 % with 5 rows).  Rows at the range's own ends are inside it."""
    s = np.linspace(300.0, 2400.0, n_rows)
    p = tmp_path / "pdf.csv"
    p.write_text("speed_rpm,pdf_per_rpm\n" + "".join(f"{float(x)!r},{1 / 2100!r}\n" for x in s))
    uniform = bb.law_from_spec("uniform", 300.0, 2400.0)
    grid = np.linspace(300.0, 2400.0, 43) * W
    # the same law whatever range is given beside the file, or none (a wheels.json speed law)
    for law in (bb.law_from_spec(str(p), 300.0, 2400.0), bb.law_from_spec(str(p), 0.0, 3000.0), bb.law_from_csv(p)):
        np.testing.assert_allclose(law.cdf(grid), uniform.cdf(grid), atol=1e-9)


def test_auto_spectra_are_never_negative():
    """The bin spreading's second differences left ~-1e-18 on thousands of bins without power (written to psd.csv and
    the NASTRAN TABRND1 tables); an auto-spectrum is >= 0, and the RMS is unchanged."""
    from rwadist import api

    for empirical in (True, False):
        r = api.psd(preset="ithaco-e", speed_rpm=(300, 2400), empirical=empirical, n_freq=4001, n_speeds=500)
        assert np.all(r.psd >= 0.0)
        assert np.all(np.isfinite(r.rms())) and r.rms()[0] > 0
        S = r.psd
        assert np.all(np.abs(r.csd) ** 2 <= S[:, :, None] * S[:, None, :] * (1 + 1e-12) + 1e-300)   # Cauchy-Schwarz


def test_cli_psd_warns_beyond_the_wheels_rated_speed(tmp_path, capsys):
    """The E wheel is rated 3850 rpm (its model's wheel.max_speed_rpm): 0:10000 rpm is computed with a warning that
    names the flag and the limit; within it, nothing is said."""
    out = tmp_path / "p.csv"
    argv = ["psd", "--preset", "ithaco-e", "--n-freq", "401", "--n-speeds", "50", "--empirical", "-o", str(out)]
    assert main(argv + ["--speed-rpm", "0:10000"]) == 0
    err = capsys.readouterr().err
    assert "WARNING: --speed-rpm 0:10000 rpm reaches beyond the maximum speed of ithaco-e, 3850 rpm" in err
    assert main(argv + ["--speed-rpm", "0:3000"]) == 0
    assert "WARNING" not in capsys.readouterr().err


def test_cli_psd_nastran_without_output_writes_psd_bdf(tmp_path, monkeypatch):
    """--format nastran without -o writes psd.bdf (the default psd.csv was refused as naming the other format)."""
    monkeypatch.chdir(tmp_path)
    assert main(["psd", "--preset", "ithaco-e", "--speed-rpm", "300:3000", "--format", "nastran", "--n-freq", "201",
                 "--n-speeds", "50", "--cross", "none"]) == 0
    assert (tmp_path / "psd.bdf").exists() and not (tmp_path / "psd.csv").exists()


@pytest.mark.parametrize("rows", [[(0, 1000), (10, 3000), (20, 3000)], [(0, 3000), (10, 3000), (20, 1000)],
                                  [(0, 1000), (10, 3000), (20, 3000), (30, 2000)]])
def test_time_profile_hold_at_the_top_speed_weighs_its_time(rows):
    """A mission profile holding its top speed (after, before or between ramps): E[Ω⁴] of the speed law against the
    closed form of the time average, ∫Ω⁴ dt / T with a ramp a -> b over τ giving τ(b⁵ − a⁵)/(5(b − a)) and a hold
    τ·b⁴, within 1e-3 (the law's 2000 bins place the hold at its bin's centre).  Session 62's trial: a 10-s ramp
    1000 -> 3000 rpm then 10 s at 3000 rpm weighed the hold as 5 s (its point mass split half past the grid), the RMS
    9.5 % low."""
    t = np.array([r[0] for r in rows], float)
    w = np.array([r[1] for r in rows], float) * W
    total = 0.0
    for (t0, a), (t1, b) in zip(zip(t[:-1], w[:-1]), zip(t[1:], w[1:])):
        total += (t1 - t0) * (b**4 if a == b else (b**5 - a**5) / (5 * (b - a)))
    from rwadist import speed_laws

    law = speed_laws.from_time_profile(t, w)
    assert speed_laws.abs_power_mean(law, 4.0) == pytest.approx(total / (t[-1] - t[0]), rel=1e-3)
