"""Time stamps as instruments print them (issue 14 item 1): rounded to 6 decimals (microseconds) or to 10
significant digits, they read and give the same fit as full precision; a dropped or repeated sample is refused
naming its line.  The rounded files are written by numpy.savetxt, not by rwadist's writer."""
from __future__ import annotations

import json

import numpy as np
import pytest

from rwadist.data import DataError, read_steady, write_steady
from rwadist.empirical import fit_empirical
from rwadist.hdf5 import read_hdf5, write_hdf5
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.teststand import simulate_steady

FS = 3840.0
SPEEDS_RPM = np.linspace(600.0, 2400.0, 8)


@pytest.fixture(scope="module")
def steady():
    return simulate_steady(preset("ithaco-e"), SPEEDS_RPM, sample_rate=FS, n_samples=4096, noise=0.01, seed=11)


def model_C(test) -> dict:
    model = fit_empirical(compute_spectra(test), progress=False).model
    return {d: model.h_and_C(d) for d in ("radial_force", "radial_torque", "axial_force", "axial_torque")}


def assert_same_model(a: dict, b: dict, rtol=1e-6) -> float:
    """Same harmonics, every C within ``rtol``; returns the largest relative C difference."""
    assert sum(a[d][1].size for d in a) >= 10  # the fit found the wheel's lines
    worst = 0.0
    for d in a:
        np.testing.assert_array_equal(a[d][0], b[d][0])
        if a[d][1].size:
            worst = max(worst, float(np.max(np.abs(b[d][1] / a[d][1] - 1))))
    assert worst <= rtol, worst
    return worst


def rewrite_time(directory, time_fmt: str, drop_meta_rate: bool):
    """Rewrite every run file of an interchange directory with its time column printed by ``time_fmt``."""
    for path in directory.glob("run_*.csv"):
        header = path.read_text().splitlines()[0]
        table = np.loadtxt(path, delimiter=",", skiprows=1)
        np.savetxt(path, table, delimiter=",", header=header, comments="",
                   fmt=[time_fmt] + ["%.17g"] * (table.shape[1] - 1))
    if drop_meta_rate:
        meta = json.loads((directory / "meta.json").read_text())
        meta.pop("sample_rate_hz")
        (directory / "meta.json").write_text(json.dumps(meta))


@pytest.mark.parametrize("time_fmt", ["%.6f", "%.10g"])
@pytest.mark.parametrize("drop_meta_rate", [False, True])
def test_rounded_time_stamps_give_the_full_precision_fit(tmp_path, steady, time_fmt, drop_meta_rate):
    full = read_steady(write_steady(steady, tmp_path / "full"))
    rounded_dir = write_steady(steady, tmp_path / "rounded")
    rewrite_time(rounded_dir, time_fmt, drop_meta_rate)
    second_stamp = (rounded_dir / "run_0000.csv").read_text().splitlines()[2].split(",")[0]
    assert second_stamp == {"%.6f": "0.000260", "%.10g": "0.0002604166667"}[time_fmt]
    rounded = read_steady(rounded_dir)
    rates = np.array([r.sample_rate for r in rounded.runs])
    assert np.max(np.abs(rates / FS - 1)) < (1e-9 if not drop_meta_rate else 1e-7)
    for a, b in zip(full.runs, rounded.runs):
        for ch in a.channels:
            np.testing.assert_array_equal(a.signals[ch], b.signals[ch])
    assert_same_model(model_C(full), model_C(rounded))


def _rounded_run(tmp_path, fmt="%.6f", n=2048):
    t = np.arange(n) / FS
    x = np.random.default_rng(0).standard_normal((n, 2))
    return t, x


@pytest.mark.parametrize("time_fmt", ["%.6f", "%.10g"])
def test_dropped_sample_is_refused_naming_its_line(tmp_path, time_fmt):
    t, x = _rounded_run(tmp_path)
    keep = np.ones(len(t), bool)
    keep[700] = False  # sample 700 missing: sample 701 follows sample 699 (line 701) on file line 702
    d = tmp_path / "d"
    d.mkdir()
    np.savetxt(d / "r.csv", np.column_stack([t, x])[keep], delimiter=",", header="time_s,Fx_N,Fy_N", comments="",
               fmt=[time_fmt, "%.17g", "%.17g"])
    (d / "runs.csv").write_text("file,speed_rpm\nr.csv,1000\n")
    with pytest.raises(DataError) as info:
        read_steady(d)
    msg = str(info.value)
    assert str(d / "r.csv") in msg and "time_s" in msg and "line 702" in msg and "1 dropped sample" in msg, msg


def test_repeated_sample_and_gap_are_refused(tmp_path):
    t, x = _rounded_run(tmp_path)
    rows = np.column_stack([t, x])
    repeated = np.insert(rows, 300, rows[299], axis=0)  # sample 299 written twice: lines 301 and 302
    path = tmp_path / "rep.csv"
    np.savetxt(path, repeated, delimiter=",", header="time_s,Fx_N,Fy_N", comments="", fmt="%.6f")
    with pytest.raises(DataError, match=r"line 302 .*repeated sample"):
        from rwadist.data import read_run
        read_run(path, 1.0)
    gap = rows.copy()
    gap[1000:, 0] += 0.4 / FS  # 0.4 of a step missing: a clock glitch, not rounding
    np.savetxt(path, gap, delimiter=",", header="time_s,Fx_N,Fy_N", comments="", fmt="%.6f")
    with pytest.raises(DataError, match=r"line 1002 .*gap in the sampling"):
        read_run(path, 1.0)


def test_rate_disagreeing_with_meta_beyond_rounding_is_refused(tmp_path, steady):
    d = write_steady(simulate_steady(preset("ithaco-e"), [1200.0], sample_rate=FS, n_samples=4096, seed=1),
                     tmp_path / "t")
    rewrite_time(d, "%.6f", drop_meta_rate=False)
    meta = json.loads((d / "meta.json").read_text())
    meta["sample_rate_hz"] = FS * (1 + 2e-5)  # 2e-5 relative: the 6-decimal rounding allows ~1e-6 over 4096 samples
    (d / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match=r"run_0000.csv: time_s: sample rate .*disagrees with meta.json"):
        read_steady(d)
    meta["sample_rate_hz"] = FS
    (d / "meta.json").write_text(json.dumps(meta))
    assert read_steady(d).runs[0].sample_rate == FS


def test_hdf5_sweep_time_rounded_to_microseconds(tmp_path):
    """HDF5 uses the same time check: a sweep whose time dataset holds microsecond-rounded stamps reads."""
    import h5py

    from rwadist.data import Sweep

    n = 4096
    t = np.arange(n) / FS
    sweep = Sweep(time=t, signals={"Fx": np.sin(t)}, sample_rate=FS)
    path = write_hdf5(sweep, tmp_path / "s.h5")
    with h5py.File(path, "r+") as fh:
        fh["time_s"][...] = np.round(t, 6)
    back = read_hdf5(path)
    assert back.sample_rate == FS
    with h5py.File(path, "r+") as fh:
        del fh["time_s"]
        fh["time_s"] = np.round(np.delete(np.arange(n + 1) / FS, 77), 6)
    with pytest.raises(DataError, match=r"/time_s: sampling is not uniform: .*index 77 .*1 dropped sample"):
        read_hdf5(path)


def test_hdf5_sweep_time_stored_as_float32(tmp_path):
    """A lab's HDF5 time stamps in float32 jitter by float32 rounding: accepted; a dropped sample still refused."""
    import h5py

    from rwadist.data import Sweep

    n = 4096
    t = np.arange(n) / FS
    path = write_hdf5(Sweep(time=t, signals={"Fx": np.cos(t)}, sample_rate=FS), tmp_path / "s.h5")
    with h5py.File(path, "r+") as fh:
        del fh["time_s"]
        fh["time_s"] = t.astype(np.float32)
    assert read_hdf5(path).sample_rate == FS
    with h5py.File(path, "r+") as fh:
        del fh["time_s"]
        fh["time_s"] = np.delete(np.arange(n + 1) / FS, 2000).astype(np.float32)
    with pytest.raises(DataError, match=r"/time_s: sampling is not uniform: .*index 2000 .*1 dropped sample"):
        read_hdf5(path)


@pytest.mark.parametrize("duration_s, fmt", [(390.0, "%.17g"), (390.0, "%.10g"), (390.0, "%.6f"), (4.0, "%.17g")])
def test_a_long_record_of_exact_time_stamps_is_uniform(duration_s, fmt):
    # the default sweep of `rwadist simulate-test --sweep` (390 s at 3840 Hz: 1 497 600 samples, time printed to 17
    # significant digits) was refused as "a gap in the sampling" at its third step: the least-squares step, summed
    # directly over time stamps up to 390 s, came out 6.5e-13 off, 17 times the 17-digit rounding the check allows.
    # Exact time stamps i/f_s, parsed back from the printed text as a reader does, must give f_s; the same column
    # with one sample dropped is still refused naming its line
    from rwadist.formats.timebase import sample_step

    n = int(round(duration_s * FS))
    t = np.arange(n) / FS
    if fmt == "%.6f":         # rounded as a DAQ prints (vectorised: a text round trip of 1.5 M values is slow)
        t = np.round(t, 6)
    elif fmt == "%.10g":      # 10 significant digits
        scale = 10.0 ** (9 - np.floor(np.log10(np.where(t > 0, t, 1.0))))
        t = np.round(t * scale) / scale
    step = sample_step("x.csv", "time_s", t)
    assert abs(step * FS - 1.0) <= (1e-13 if fmt == "%.17g" else 1e-9), step * FS - 1.0
    with pytest.raises(DataError, match=r"x\.csv: time_s: sampling is not uniform: .* at line 1003 .*1 dropped sample"):
        sample_step("x.csv", "time_s", np.delete(t, 1001))


@pytest.mark.parametrize("fs", [6000.0, 7000.0, 5120.0, 3000.0])
@pytest.mark.parametrize("drop_meta_rate", [False, True])
def test_stamps_printed_coarser_than_a_quarter_step_read_when_one_uniform_grid_fits(tmp_path, fs, drop_meta_rate):
    """A DAQ printing its stamps to 0.1 ms at 6 kHz (0.6 of a step; session 60's new-user trial: every run refused as
    "a gap in the sampling"): each stamp still names one sample, so the column is read, at the declared rate, with
    the samples unchanged; the same samples at full precision are the reference."""
    run = simulate_steady(preset("ithaco-e"), [1500.0], sample_rate=fs, n_samples=4096, noise=0.01, seed=3)
    full = read_steady(write_steady(run, tmp_path / "full"))
    coarse_dir = write_steady(run, tmp_path / "coarse")
    rewrite_time(coarse_dir, "%.4f", drop_meta_rate)
    coarse = read_steady(coarse_dir)
    # without meta.json's rate, the least-squares step of 4096 stamps rounded to q: ~q/n^1.5 (2.7e-6 of a 7 kHz step)
    assert abs(coarse.runs[0].sample_rate / fs - 1) < (1e-12 if not drop_meta_rate else 1e-5)
    for ch in full.runs[0].channels:
        np.testing.assert_array_equal(full.runs[0].signals[ch], coarse.runs[0].signals[ch])


@pytest.mark.parametrize("fs", [6000.0, 7000.0, 3000.0])
@pytest.mark.parametrize("where", [5, 1700, 4090])
def test_a_lost_or_repeated_sample_in_stamps_printed_coarser_than_a_quarter_step_is_refused(tmp_path, fs, where):
    """The same 0.1 ms stamps with one sample lost or one written twice, near either end or in the middle: refused,
    naming the line where the stamps leave the grid and what was lost."""
    from rwadist.data import read_run
    t = np.arange(4097) / fs
    x = np.random.default_rng(1).standard_normal((4097, 2))
    rows = np.column_stack([t, x])
    path = tmp_path / "r.csv"
    for kind, table, line in (("1 dropped sample", np.delete(rows, where, axis=0)[:4096], where + 2),
                              ("repeated sample", np.insert(rows[:4095], where, rows[where - 1], axis=0), where + 2)):
        np.savetxt(path, table, delimiter=",", header="time_s,Fx_N,Fy_N", comments="", fmt=["%.4f", "%.17g", "%.17g"])
        with pytest.raises(DataError) as info:
            read_run(path, 1.0)
        msg = str(info.value)
        assert f"line {line} " in msg and kind in msg, (kind, line, msg)


@pytest.mark.parametrize("fs, q", [(4000.0, 1e-4), (5120.0, 1e-4), (40000.0, 1e-5), (51200.0, 1e-5)])
@pytest.mark.parametrize("t0", [0.1, 1.37, 2.9])
def test_coarse_stamps_rounding_on_ties_are_read(fs, q, t0):
    """Review of session 60: where the step is an odd multiple of half the rounding, stamps fall on rounding ties that
    round one way over long stretches and tilt the least-squares step; the grid was looked for along that step alone
    and 8 of 12 such columns (4 kHz, 0.1 ms, 40 000 samples, t0 = 0.1 s) were refused as a gap.  The grid's step is
    searched too: read, at the declared rate."""
    from rwadist.formats.timebase import sample_step

    t = np.round((t0 + np.arange(40000) / fs) / q) * q
    assert sample_step("r.csv", "time_s", t, fs) == 1.0 / fs
