"""Interchange format (rwadist.data) and HDF5 storage (rwadist.hdf5).

Round trips must lose nothing; every bad input must raise DataError naming the
file and the field.  Files for the bad-input tests are written by hand (not by
write_steady) where the writer could not produce them.
"""
from __future__ import annotations

import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from rwadist.data import (
    DataError,
    Run,
    SteadyTest,
    Sweep,
    read_data,
    read_run,
    read_steady,
    read_sweep,
    write_steady,
    write_sweep,
)
from rwadist.hdf5 import FORMAT, FORMAT_VERSION, read_hdf5, write_hdf5
from rwadist.units import CHANNEL_COLUMN, CHANNELS, RAD_S_TO_RPM, rpm_to_rad_s

N = 1024
FS = 2048.0
#: Values that a lossy float->text->float path would mangle.
# (the largest: the readers refuse a load beyond 1e9 N or N·m, rwadist.formats.records.MAX_LOAD)
AWKWARD = np.array([-0.0, 5e-324, 2.2250738585072014e-308, 999999999.99999988, 0.1, 1 / 3, -2.0**-1074 * 3])


def bits(x):
    """Bit pattern of a float64 array (distinguishes -0.0, denormals)."""
    return np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)


def assert_bit_identical(a, b):
    assert a.shape == b.shape
    assert np.array_equal(bits(a), bits(b))


def make_run(speed, name, channels=CHANNELS, seed=0, fs=FS, t0=0.0, n=N):
    """A run of noise plus a sinusoid per channel, ~1 N / 0.01 N·m scale, with awkward values at the start."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    signals = {}
    for k, ch in enumerate(channels):
        scale = 1.0 if ch.startswith("F") else 0.01
        x = scale * (rng.standard_normal(n) + np.sin(2 * np.pi * (37.0 + 11 * k) * t + rng.uniform(0, 6.28)))
        x[: len(AWKWARD)] = AWKWARD
        signals[ch] = x
    return Run(speed=float(speed), sample_rate=fs, signals=signals, t0=t0, name=name)


def make_test():
    """Four runs sorted by speed: negative, zero, two positive; one lacks Fy and Tz."""
    runs = [
        make_run(-314.159, "run_neg.csv", seed=1, t0=0.0),
        make_run(0.0, "run_zero.csv", seed=2, t0=12.345),
        make_run(104.71975511965977, "run_1000rpm.csv", channels=("Fx", "Fz", "Tx", "Ty"), seed=3),
        make_run(523.5987755982989, "run_5000rpm.csv", seed=4, t0=-1.5),
    ]
    meta = {"wheel": {"name": "E", "mass_kg": 10.6, "radius_m": 0.1965}, "notes": "bench 3, 1/3 g",
            "sample_rate_hz": FS}
    return SteadyTest(runs, meta)


def assert_runs_equal(a: Run, b: Run):
    assert a.name == b.name
    assert a.channels == b.channels
    assert a.sample_rate == b.sample_rate
    assert a.t0 == b.t0
    for ch in a.channels:
        assert_bit_identical(a.signals[ch], b.signals[ch])


def write_csv(path, header, table):
    """Write a CSV by hand: header list + 2-D table (17 significant digits)."""
    lines = [",".join(header)] + [",".join(f"{v:.17g}" for v in row) for row in np.atleast_2d(table)]
    Path(path).write_text("\n".join(lines) + "\n")


def run_table(n=N, fs=FS, n_ch=6, seed=0):
    rng = np.random.default_rng(seed)
    return np.column_stack([np.arange(n) / fs] + [rng.standard_normal(n) for _ in range(n_ch)])


HEADER = ["time_s"] + [CHANNEL_COLUMN[c] for c in CHANNELS]


def steady_dir(tmp_path, speeds_rpm=(1000.0, 2000.0), files=None, meta=None, n=N):
    """A hand-written steady test directory; returns it."""
    d = tmp_path / "test"
    d.mkdir()
    files = files or [f"r{i}.csv" for i in range(len(speeds_rpm))]
    for i, fname in enumerate(dict.fromkeys(files)):
        write_csv(d / fname, HEADER, run_table(n=n, seed=i))
    (d / "runs.csv").write_text("file,speed_rpm\n" + "".join(f"{f},{s}\n" for f, s in zip(files, speeds_rpm)))
    if meta is not None:
        (d / "meta.json").write_text(json.dumps(meta))
    return d


def expect_error(fn, file, *fields):
    """fn() raises DataError whose message names ``file`` and every string in ``fields``."""
    with pytest.raises(DataError) as info:
        fn()
    msg = str(info.value)
    assert str(file) in msg, msg
    for f in fields:
        assert f in msg, f"{f!r} not in {msg!r}"
    return info.value


# =========================================================================== CSV round trips

def test_steady_round_trip_is_lossless(tmp_path):
    test = make_test()
    back = read_steady(write_steady(test, tmp_path / "t"))
    assert len(back.runs) == len(test.runs)
    for a, b in zip(test.runs, back.runs):
        assert_runs_equal(a, b)
    # rpm is written with repr and converted back: the only rounding is the rpm<->rad/s product
    np.testing.assert_allclose(back.speeds, test.speeds, rtol=1e-15, atol=0)
    assert np.array_equal(np.sign(back.speeds), np.sign(test.speeds))
    assert back.channels == CHANNELS
    assert back.meta == test.meta


def test_steady_round_trip_missing_channel_stays_absent(tmp_path):
    back = read_steady(write_steady(make_test(), tmp_path / "t"))
    partial = next(r for r in back.runs if r.name == "run_1000rpm.csv")
    assert partial.channels == ("Fx", "Fz", "Tx", "Ty")
    assert "Fy" not in partial.signals and "Tz" not in partial.signals
    header = (tmp_path / "t" / "run_1000rpm.csv").read_text().splitlines()[0]
    assert header == "time_s,Fx_N,Fz_N,Tx_Nm,Ty_Nm"


def test_steady_round_trip_odd_sample_rate_exact(tmp_path):
    """A sample rate that 1/median(dt) would not reproduce exactly survives through meta.json."""
    fs = 1000.0 / 3.0
    test = SteadyTest([make_run(10.0, "a.csv", fs=fs, t0=7.1), make_run(20.0, "b.csv", fs=fs, seed=5)])
    back = read_steady(write_steady(test, tmp_path / "t"))
    assert [r.sample_rate for r in back.runs] == [fs, fs]
    for a, b in zip(test.runs, back.runs):
        assert_runs_equal(a, b)
    assert back.meta == {"sample_rate_hz": fs}  # the writer records the common rate


def test_steady_round_trip_unsorted_input_comes_back_sorted(tmp_path):
    test = make_test()
    shuffled = SteadyTest([test.runs[i] for i in (3, 0, 2, 1)], test.meta)
    back = read_steady(write_steady(shuffled, tmp_path / "t"))
    assert [r.name for r in back.runs] == [r.name for r in test.runs]
    assert np.all(np.diff(back.speeds) >= 0)


@pytest.mark.parametrize("with_tach", [True, False])
def test_sweep_round_trip(tmp_path, with_tach):
    fs, n = 1000.0, 4096
    rng = np.random.default_rng(7)
    time = 100.0 + np.arange(n) / fs
    omega = np.linspace(-50.0, 400.0, n)  # through zero
    signals = {ch: rng.standard_normal(n) for ch in ("Fx", "Fy", "Tz")}
    signals["Fx"][: len(AWKWARD)] = AWKWARD
    sweep = Sweep(time=time, signals=signals, sample_rate=fs, tach=omega if with_tach else None)
    path = write_sweep(sweep, tmp_path / "sub" / "sweep.csv")
    header = path.read_text().splitlines()[0]
    assert header == "time_s,Fx_N,Fy_N,Tz_Nm" + (",speed_rpm" if with_tach else "")
    back = read_sweep(path)
    assert_bit_identical(back.time, time)
    assert back.channels == ("Fx", "Fy", "Tz")
    for ch in signals:
        assert_bit_identical(back.signals[ch], signals[ch])
    # the sweep CSV has no meta.json: the rate comes from the time column
    assert back.sample_rate == pytest.approx(fs, rel=1e-9)
    if with_tach:
        np.testing.assert_allclose(back.tach, omega, rtol=1e-15, atol=1e-13)
    else:
        assert back.tach is None
    assert read_data(path).channels == back.channels


def test_steady_write_duplicate_names_lose_nothing(tmp_path):
    a, b = make_run(1.0, "run_0001.csv", seed=1), make_run(2.0, "run_0001.csv", seed=2)
    back = read_steady(write_steady(SteadyTest([a, b]), tmp_path / "t"))
    assert_bit_identical(back.runs[0].signals["Fx"], a.signals["Fx"])
    assert_bit_identical(back.runs[1].signals["Fx"], b.signals["Fx"])


def test_runs_csv_line_numbers_survive_blank_lines(tmp_path):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text("file,speed_rpm\n\nr0.csv,1000\n\nr1.csv,fast\n")
    expect_error(lambda: read_steady(d), d / "runs.csv", "speed_rpm (line 5)")


# =========================================================================== documented legal oddities

def test_missing_channel_column_is_absent_not_filled(tmp_path):
    d = steady_dir(tmp_path)
    write_csv(d / "r1.csv", ["time_s", "Fx_N", "Fz_N", "Tz_Nm"], run_table(n_ch=3))
    test = read_steady(d)
    r = next(r for r in test.runs if r.name == "r1.csv")
    assert set(r.signals) == {"Fx", "Fz", "Tz"}
    assert r.channels == ("Fx", "Fz", "Tz")
    assert test.channels == CHANNELS  # the other run has them all


def test_duplicate_speeds_kept_as_two_runs(tmp_path):
    d = steady_dir(tmp_path, speeds_rpm=(3000.0, 1000.0, 3000.0), files=["a.csv", "b.csv", "c.csv"])
    test = read_steady(d)
    assert [r.name for r in test.runs] == ["b.csv", "a.csv", "c.csv"]  # stable: file order breaks the tie
    np.testing.assert_allclose(test.speeds, rpm_to_rad_s([1000.0, 3000.0, 3000.0]), rtol=1e-15)
    assert not np.array_equal(test.runs[1].signals["Fx"], test.runs[2].signals["Fx"])


def test_unsorted_speeds_sorted_on_read(tmp_path):
    d = steady_dir(tmp_path, speeds_rpm=(5000, 200, 3000, 1000), files=["a.csv", "b.csv", "c.csv", "d.csv"])
    test = read_steady(d)
    assert [r.name for r in test.runs] == ["b.csv", "d.csv", "c.csv", "a.csv"]
    np.testing.assert_allclose(test.speeds * RAD_S_TO_RPM, [200, 1000, 3000, 5000], rtol=1e-14)


def test_zero_and_negative_speeds_keep_sign(tmp_path):
    d = steady_dir(tmp_path, speeds_rpm=("-1500.5", "0", "-0.0", "750"), files=["a.csv", "b.csv", "c.csv", "d.csv"])
    test = read_steady(d)
    assert [r.name for r in test.runs] == ["a.csv", "b.csv", "c.csv", "d.csv"]
    np.testing.assert_allclose(test.speeds, rpm_to_rad_s([-1500.5, 0.0, 0.0, 750.0]), rtol=1e-15)
    assert test.speeds[0] < 0 and test.speeds[1] == 0


# =========================================================================== bad input: run files

def test_nan_sample_names_file_column_and_row(tmp_path):
    d = steady_dir(tmp_path)
    table = run_table()
    table[16, 2] = np.nan  # data row 17 (file line 18), column Fy_N
    write_csv(d / "r1.csv", HEADER, table)
    err = expect_error(lambda: read_steady(d), d / "r1.csv", "Fy_N", "row 17", "line 18", "nan")
    assert err.field == "Fy_N" and err.file == str(d / "r1.csv")


def test_inf_sample_rejected(tmp_path):
    path = tmp_path / "r.csv"
    table = run_table()
    table[100, 6] = -np.inf
    write_csv(path, HEADER, table)
    expect_error(lambda: read_run(path, 1.0), path, "Tz_Nm", "row 101", "inf")


def test_unknown_column_wrong_units(tmp_path):
    d = steady_dir(tmp_path)
    write_csv(d / "r0.csv", ["time_s", "Fx_lbf", "Fy_N"], run_table(n_ch=2))
    err = expect_error(lambda: read_steady(d), d / "r0.csv", "Fx_lbf", "Fx_N")
    assert err.field == "Fx_lbf"


def test_unknown_column_not_a_channel(tmp_path):
    path = tmp_path / "r.csv"
    write_csv(path, ["time_s", "Fx_N", "temperature_C"], run_table(n_ch=2))
    expect_error(lambda: read_run(path, 0.0), path, "temperature_C", "unknown column")


def test_duplicate_column(tmp_path):
    path = tmp_path / "r.csv"
    write_csv(path, ["time_s", "Fx_N", "Fx_N"], run_table(n_ch=2))
    expect_error(lambda: read_run(path, 0.0), path, "Fx_N", "twice")


def test_first_column_not_time(tmp_path):
    path = tmp_path / "r.csv"
    write_csv(path, ["Fx_N", "time_s"], run_table(n_ch=1))
    expect_error(lambda: read_run(path, 0.0), path, "header", "time_s")


def test_truncated_csv_names_last_line(tmp_path):
    d = steady_dir(tmp_path)
    text = (d / "r1.csv").read_text()
    lines = text.splitlines()
    last = lines[-1]
    cut = last[: last.index(",", last.index(",") + 1) + 4]  # mid-way through the third field
    (d / "r1.csv").write_text("\n".join(lines[:-1] + [cut]))  # no final newline, as a killed writer leaves it
    err = expect_error(lambda: read_steady(d), d / "r1.csv", f"line {len(lines)}", "truncated")
    assert err.field == f"line {len(lines)}"


def test_non_numeric_sample(tmp_path):
    path = tmp_path / "r.csv"
    write_csv(path, HEADER, run_table())
    lines = path.read_text().splitlines()
    fields = lines[40].split(",")
    fields[3] = "12.5N"
    lines[40] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    expect_error(lambda: read_run(path, 0.0), path, "line 41", "'12.5N'")


def test_empty_run_file(tmp_path):
    d = steady_dir(tmp_path)
    (d / "r0.csv").write_text("")
    expect_error(lambda: read_steady(d), d / "r0.csv", "header", "empty")


def test_header_only_run_file(tmp_path):
    d = steady_dir(tmp_path)
    (d / "r0.csv").write_text(",".join(HEADER) + "\n")
    expect_error(lambda: read_steady(d), d / "r0.csv", "data", "no data rows")


def test_non_uniform_time(tmp_path):
    d = steady_dir(tmp_path)
    table = run_table()
    table[500:, 0] += 0.1 / FS  # a 10 % longer step between rows 500 and 501 (file lines 501, 502)
    write_csv(d / "r1.csv", HEADER, table)
    expect_error(lambda: read_steady(d), d / "r1.csv", "time_s", "not uniform", "line 502")


def test_time_not_increasing(tmp_path):
    path = tmp_path / "r.csv"
    table = run_table()
    table[:, 0] = table[::-1, 0]
    write_csv(path, HEADER, table)
    expect_error(lambda: read_run(path, 0.0), path, "time_s", "does not increase")


def test_meta_sample_rate_disagrees_with_time_column(tmp_path):
    d = steady_dir(tmp_path, meta={"sample_rate_hz": 2000.0})  # files are sampled at 2048 Hz
    expect_error(lambda: read_steady(d), d / "r0.csv", "time_s", "meta.json", "2000", "2048")


def test_meta_sample_rate_agreeing_is_used(tmp_path):
    d = steady_dir(tmp_path, meta={"sample_rate_hz": FS, "notes": "ok"})
    test = read_steady(d)
    assert [r.sample_rate for r in test.runs] == [FS, FS]
    assert test.meta == {"sample_rate_hz": FS, "notes": "ok"}


@pytest.mark.parametrize("bad, field", [(-5.0, "sample_rate_hz"), ("fast", "sample_rate_hz")])
def test_meta_bad_sample_rate(tmp_path, bad, field):
    d = steady_dir(tmp_path, meta={"sample_rate_hz": bad})
    expect_error(lambda: read_steady(d), d / "meta.json", field)


def test_meta_invalid_json(tmp_path):
    d = steady_dir(tmp_path)
    (d / "meta.json").write_text('{"notes": "x",\n "sample_rate_hz": }')
    expect_error(lambda: read_steady(d), d / "meta.json", "line 2", "JSON")


# =========================================================================== bad input: runs.csv and directory

def test_duplicate_file_entry(tmp_path):
    d = steady_dir(tmp_path, speeds_rpm=(1000, 2000, 3000), files=["a.csv", "b.csv", "a.csv"])
    err = expect_error(lambda: read_steady(d), d / "runs.csv", "file (line 4)", "'a.csv'", "line 2")
    assert err.field == "file (line 4)"


@pytest.mark.parametrize("speed", ["fast", "", "1e3.5", "1,000"])
def test_non_numeric_speed(tmp_path, speed):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text(f"file,speed_rpm\nr0.csv,1000\nr1.csv,{speed}\n")
    expect_error(lambda: read_steady(d), d / "runs.csv", "speed_rpm (line 3)", "not a number")


@pytest.mark.parametrize("speed", ["nan", "inf", "-inf"])
def test_non_finite_speed(tmp_path, speed):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text(f"file,speed_rpm\nr0.csv,{speed}\nr1.csv,10\n")
    expect_error(lambda: read_steady(d), d / "runs.csv", "speed_rpm (line 2)", speed)


def test_runs_csv_missing_column(tmp_path):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text("file,speed_rad_s\nr0.csv,100\n")
    expect_error(lambda: read_steady(d), d / "runs.csv", "speed_rpm", "missing")


def test_runs_csv_without_rows(tmp_path):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text("file,speed_rpm\n")
    expect_error(lambda: read_steady(d), d / "runs.csv", "rows", "no runs")


def test_runs_csv_empty(tmp_path):
    d = steady_dir(tmp_path)
    (d / "runs.csv").write_text("")
    expect_error(lambda: read_steady(d), d / "runs.csv", "header", "empty")


def test_listed_file_missing(tmp_path):
    d = steady_dir(tmp_path)
    (d / "r1.csv").unlink()
    err = expect_error(lambda: read_steady(d), d / "runs.csv", "file (line 3)", "'r1.csv'", "does not exist")
    assert err.file == str(d / "runs.csv")


def test_empty_directory(tmp_path):
    d = tmp_path / "empty"
    d.mkdir()
    expect_error(lambda: read_steady(d), d, "runs.csv", "empty")
    expect_error(lambda: read_data(d), d, "runs.csv")


def test_directory_without_runs_csv(tmp_path):
    d = steady_dir(tmp_path)
    (d / "runs.csv").unlink()
    expect_error(lambda: read_steady(d), d, "runs.csv", "r0.csv")


def test_not_a_directory(tmp_path):
    expect_error(lambda: read_steady(tmp_path / "nowhere"), tmp_path / "nowhere", "directory")


# =========================================================================== bad input: sweeps

def test_sweep_nan_in_tach(tmp_path):
    path = tmp_path / "s.csv"
    table = np.column_stack([run_table(n_ch=2), np.linspace(0, 3000, N)])
    table[9, 3] = np.nan
    write_csv(path, ["time_s", "Fx_N", "Fy_N", "speed_rpm"], table)
    expect_error(lambda: read_sweep(path), path, "speed_rpm", "row 10")


def test_sweep_truncated(tmp_path):
    path = tmp_path / "s.csv"
    write_csv(path, HEADER, run_table())
    text = path.read_text()
    path.write_text(text[: len(text) - 25])
    expect_error(lambda: read_sweep(path), path, f"line {N + 1}")


def test_sweep_without_channels(tmp_path):
    path = tmp_path / "s.csv"
    write_csv(path, ["time_s", "speed_rpm"], run_table(n_ch=1))
    expect_error(lambda: read_sweep(path), path, "header", "no channel")


def test_sweep_missing_file(tmp_path):
    expect_error(lambda: read_sweep(tmp_path / "none.csv"), tmp_path / "none.csv", "does not exist")


# =========================================================================== HDF5

def test_hdf5_steady_round_trip_bit_identical(tmp_path):
    test = make_test()
    path = write_hdf5(test, tmp_path / "t.h5")
    back = read_data(path)
    assert isinstance(back, SteadyTest)
    assert len(back.runs) == len(test.runs)
    for a, b in zip(test.runs, back.runs):
        assert_runs_equal(a, b)
        assert b.speed == a.speed  # rad/s stored as float64: exact, sign kept
    assert back.meta == test.meta
    assert "Fy" not in back.runs[2].signals
    with h5py.File(path) as fh:
        assert fh.attrs["format"] == FORMAT and fh.attrs["format_version"] == FORMAT_VERSION
        assert fh.attrs["kind"] == "steady"
        assert json.loads(fh.attrs["meta"]) == test.meta
        g = fh["runs/run_0003"]
        assert g.attrs["speed_rpm"] == pytest.approx(5000.0, rel=1e-14)
        assert sorted(g) == sorted(CHANNEL_COLUMN.values())
        assert sorted(fh["runs/run_0002"]) == ["Fx_N", "Fz_N", "Tx_Nm", "Ty_Nm"]


def test_hdf5_from_csv_and_back_to_csv(tmp_path):
    """CSV -> HDF5 -> CSV: the second CSV directory reads back the same as the first."""
    first = read_steady(write_steady(make_test(), tmp_path / "csv1"))
    h5 = read_hdf5(write_hdf5(first, tmp_path / "t.hdf5", compression="gzip"))
    second = read_steady(write_steady(h5, tmp_path / "csv2"))
    for a, b, c in zip(first.runs, h5.runs, second.runs):
        assert_runs_equal(a, b)
        assert_runs_equal(a, c)
        assert a.speed == b.speed == c.speed
    assert first.meta == h5.meta == second.meta


@pytest.mark.parametrize("with_tach", [True, False])
def test_hdf5_sweep_round_trip_bit_identical(tmp_path, with_tach):
    fs, n = 1000.0 / 3.0, 3000
    rng = np.random.default_rng(11)
    time = 5.0 + np.arange(n) / fs
    signals = {"Fz": rng.standard_normal(n), "Tx": 1e-3 * rng.standard_normal(n)}
    signals["Fz"][: len(AWKWARD)] = AWKWARD
    tach = np.linspace(300.0, -300.0, n) if with_tach else None
    sweep = Sweep(time=time, signals=signals, sample_rate=fs, tach=tach, meta={"notes": "run-down", "k": [1, 2]})
    back = read_data(write_hdf5(sweep, tmp_path / "s.h5"))
    assert isinstance(back, Sweep)
    assert back.sample_rate == fs
    assert_bit_identical(back.time, time)
    assert back.channels == ("Fz", "Tx")
    for ch in signals:
        assert_bit_identical(back.signals[ch], signals[ch])
    if with_tach:
        assert_bit_identical(back.tach, tach)
    else:
        assert back.tach is None
    assert back.meta == sweep.meta


def test_hdf5_write_rejects_other_objects(tmp_path):
    with pytest.raises(TypeError):
        write_hdf5({"runs": []}, tmp_path / "x.h5")


@pytest.fixture
def steady_h5(tmp_path):
    return write_hdf5(make_test(), tmp_path / "t.h5")


@pytest.fixture
def sweep_h5(tmp_path):
    n, fs = 2048, 1000.0
    sweep = Sweep(time=np.arange(n) / fs, signals={"Fx": np.ones(n), "Fy": np.zeros(n)}, sample_rate=fs,
                  tach=np.linspace(0, 100, n))
    return write_hdf5(sweep, tmp_path / "s.h5")


def _edit(path, fn):
    with h5py.File(path, "r+") as fh:
        fn(fh)


def test_hdf5_wrong_format(steady_h5):
    _edit(steady_h5, lambda fh: fh.attrs.modify("format", "someone.else"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "format", "someone.else")


def test_hdf5_missing_format(steady_h5):
    _edit(steady_h5, lambda fh: fh.attrs.__delitem__("format"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "format", "missing")


@pytest.mark.parametrize("version", [2, 0, 1.5, "1"])
def test_hdf5_wrong_version(steady_h5, version):
    _edit(steady_h5, lambda fh: fh.attrs.__setitem__("format_version", version))  # replaces type too
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "format_version", str(version))


def test_hdf5_wrong_kind(steady_h5):
    _edit(steady_h5, lambda fh: fh.attrs.modify("kind", "psd"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "kind", "psd")


def test_hdf5_bad_meta(steady_h5):
    _edit(steady_h5, lambda fh: fh.attrs.modify("meta", "{notes: x}"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "meta", "JSON")


def test_hdf5_missing_runs_group(steady_h5):
    _edit(steady_h5, lambda fh: fh.__delitem__("runs"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs", "missing")


def test_hdf5_run_without_channel_datasets(steady_h5):
    def strip(fh):
        for name in list(fh["runs/run_0001"]):
            del fh["runs/run_0001"][name]
    _edit(steady_h5, strip)
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0001", "no channel datasets")


def test_hdf5_missing_run_attribute(steady_h5):
    _edit(steady_h5, lambda fh: fh["runs/run_0002"].attrs.__delitem__("sample_rate_hz"))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0002/sample_rate_hz", "missing")


def test_hdf5_speed_rpm_disagrees(steady_h5):
    _edit(steady_h5, lambda fh: fh["runs/run_0003"].attrs.modify("speed_rpm", 5001.0))
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0003/speed_rpm", "5001")


def test_hdf5_unknown_dataset_units(steady_h5):
    def rename(fh):
        fh["runs/run_0000"].move("Fx_N", "Fx_lbf")
    _edit(steady_h5, rename)
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0000/Fx_lbf", "Fx_N")


def test_hdf5_nan_sample(steady_h5):
    def poison(fh):
        ds = fh["runs/run_0001/Ty_Nm"]
        x = ds[()]
        x[77] = np.nan
        ds[...] = x
    _edit(steady_h5, poison)
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0001/Ty_Nm", "index 77")


def test_hdf5_channel_lengths_differ(steady_h5):
    def shorten(fh):
        g = fh["runs/run_0000"]
        x = g["Fz_N"][:-1]
        del g["Fz_N"]
        g["Fz_N"] = x
    _edit(steady_h5, shorten)
    expect_error(lambda: read_hdf5(steady_h5), steady_h5, "/runs/run_0000", "differ in length")


def test_hdf5_sweep_missing_time(sweep_h5):
    _edit(sweep_h5, lambda fh: fh.__delitem__("time_s"))
    expect_error(lambda: read_hdf5(sweep_h5), sweep_h5, "/time_s", "dataset missing")


def test_hdf5_sweep_tach_wrong_length(sweep_h5):
    def shorten(fh):
        x = fh["speed_rad_s"][:-3]
        del fh["speed_rad_s"]
        fh["speed_rad_s"] = x
    _edit(sweep_h5, shorten)
    expect_error(lambda: read_hdf5(sweep_h5), sweep_h5, "/speed_rad_s", "2045")


def test_hdf5_sweep_rate_disagrees_with_time(sweep_h5):
    _edit(sweep_h5, lambda fh: fh.attrs.modify("sample_rate_hz", 1024.0))
    expect_error(lambda: read_hdf5(sweep_h5), sweep_h5, "/time_s", "sample_rate_hz", "1024")


def test_hdf5_not_hdf5(tmp_path):
    path = tmp_path / "fake.h5"
    write_csv(path, HEADER, run_table(n=8))
    expect_error(lambda: read_data(path), path, "file", "not an HDF5")
    expect_error(lambda: read_hdf5(tmp_path / "none.h5"), tmp_path / "none.h5", "file", "does not exist")


def test_csv_body_is_the_text_numpy_savetxt_writes():
    """The interchange CSV body (:func:`rwadist.formats.csv_table._format_table`, one ``%`` of the whole table) is
    byte for byte what ``np.savetxt(fmt="%.17g", delimiter=",")`` writes, for extreme, subnormal, signed-zero and
    non-finite values and for tables of 0, 1 and many rows."""
    import io

    from rwadist.formats.csv_table import _format_table

    rng = np.random.default_rng(3)
    cases = [[rng.normal(size=n) * 10.0 ** rng.integers(-300, 300) for _ in range(k)]
             for n, k in ((0, 3), (1, 1), (7, 7), (2000, 4))]
    cases.append([np.array([np.nan, np.inf, -np.inf, -0.0, 1e-310, 5e-324, 1 / 3, 1e300])] * 2)
    for cols in cases:
        buf = io.StringIO()
        np.savetxt(buf, np.column_stack(cols), delimiter=",", fmt="%.17g")
        assert _format_table(cols) == buf.getvalue()
