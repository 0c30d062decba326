"""Fuzz sample of damaged data files (steady CSV folders, sweep CSV, HDF5 with dangling links / flipped
bytes / NaN samples, UTF-16 text) read by `rwadist convert` (issue 17; the full run:
benchmarks/fuzz_all.py --surface readers).  Never a traceback, never a NaN read silently."""
import fuzz_cases as fz
import pytest


def test_fuzz_data_readers(tmp_path):
    sets = fz.make_datasets(tmp_path)
    cases = fz.reader_cases(60, 3, tmp_path, sets)
    results = [(fz.run_case(argv, names, invalid), what) for argv, names, invalid, what in cases]
    bad = [(r, what) for r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert fz.tally(r for r, _ in results)["clear"] >= 20


def test_utf16_and_dangling_link_name_the_file(tmp_path):
    import h5py

    sets = fz.make_datasets(tmp_path)
    utf16 = tmp_path / "utf16.csv"
    utf16.write_bytes(sets["sweep"].read_text().encode("utf-16"))
    outcome, msg = fz.run_case(["convert", utf16, "-o", tmp_path / "a.h5"], ["utf16.csv"], True)
    assert outcome == "clear" and "UTF-16" in msg
    with h5py.File(sets["h5"], "r+") as fh:
        name = sorted(fh["runs"])[0]
        del fh["runs"][name]
        fh["runs"][name] = h5py.SoftLink("/does/not/exist")
    outcome, msg = fz.run_case(["convert", sets["h5"], "-o", tmp_path / "b.h5"], ["test.h5"], True)
    assert outcome == "clear", msg


@pytest.fixture(scope="module")
def datasets(tmp_path_factory):
    """Small valid datasets shared by the tests below (each copies what it changes)."""
    return fz.make_datasets(tmp_path_factory.mktemp("sets"))


def test_fuzz_fields_the_readers_read(tmp_path, datasets):
    """Bad values of the fields the readers read (issue 36; the full run: benchmarks/fuzz_all.py --surface readers):
    tach pulses_per_rev NaN/0/-1/0.5/"1"/1e30, f_lim_hz "abc"/NaN/beyond Nyquist, sample_rate_hz, runs.csv speeds of
    1e308, a 1e308 sample, TDMS wf_start_offset NaN, a MATLAB v7.3 channel stored as a group: each refused naming the
    file (never used, never dropped without a word), good values accepted."""
    import fuzz_surfaces as fs

    cases = fs.reader_field_cases(36, 4, tmp_path, datasets["steady"])
    results = [(fz.run_case(argv, names, invalid), what) for argv, names, invalid, what in cases]
    bad = [(r, what) for r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert fz.tally(r for r, _ in results)["clear"] >= 15


def test_the_issues_reader_cases(tmp_path, datasets):
    """meta.json f_lim_hz "abc" (a TypeError, exit 3), a symbolic-link loop (RuntimeError, exit 3), `psd --dist`
    with an empty or header-only CSV (StopIteration/IndexError, exit 3): now one clear line each."""
    import json
    import shutil

    sets = datasets
    ds = tmp_path / "flim"
    shutil.copytree(sets["steady"], ds)
    meta = json.loads((ds / "meta.json").read_text())
    meta["f_lim_hz"] = "abc"
    (ds / "meta.json").write_text(json.dumps(meta))
    outcome, msg = fz.run_case(["fit", ds, "-o", tmp_path / "m.json", "--no-report"], ["meta.json"], True)
    assert outcome == "clear" and "f_lim_hz" in msg, msg
    loop_a, loop_b = tmp_path / "la", tmp_path / "lb"
    loop_a.symlink_to(loop_b)
    loop_b.symlink_to(loop_a)
    for argv in (["fit", loop_a, "-o", tmp_path / "m.json"], ["convert", loop_a, "-o", tmp_path / "x.h5"],
                 ["fit", sets["steady"], "-o", loop_a, "--no-report"]):
        outcome, msg = fz.run_case(argv, ["la", "-o"], True)
        assert outcome == "clear" and "loop" in msg, (argv, msg)
    empty, header = tmp_path / "empty.csv", tmp_path / "header.csv"
    empty.write_text("")
    header.write_text("speed_rpm,weight\n")
    for dist in (empty, header):
        outcome, msg = fz.run_case(["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical",
                                    "--n-freq", "201", "--dist", dist, "-o", tmp_path / "p.csv"], [dist.name], True)
        assert outcome == "clear", msg


def test_every_field_a_reader_reads_is_checked(tmp_path, datasets):
    """Accepted before (issue 36's audit): tach pulses_per_rev NaN (a model file with a bare NaN), 0, -1, 0.5, "1"
    and 1e30; a run at 1e308 rpm and one 1e308 sample (dropped from the fit without a word); TDMS wf_start_offset
    NaN (t0 = NaN in the .h5); a MATLAB v7.3 channel stored as a group (dropped).  Each is refused naming the file
    and the field; a good value of each field is read."""
    import json
    import random
    import shutil

    import fuzz_surfaces as fs

    def with_meta(name, **changes):
        d = tmp_path / name
        shutil.copytree(datasets["steady"], d)
        meta = json.loads((d / "meta.json").read_text())
        meta.update(changes)
        (d / "meta.json").write_text(json.dumps(meta, allow_nan=True))
        return d

    for i, ppr in enumerate([float("nan"), 0, -1, 0.5, "1", 1e30, 10**30]):
        d = with_meta(f"tach{i}", tach={"channel": "tach", "pulses_per_rev": ppr})
        outcome, msg = fz.run_case(["fit", d, "-o", tmp_path / "m.json", "--no-report"], ["meta.json"], True)
        assert outcome == "clear" and "pulses_per_rev" in msg, (ppr, msg)
    d = with_meta("tach_ok", tach={"channel": "tach", "pulses_per_rev": 2})
    assert fz.run_case(["convert", d, "-o", tmp_path / "ok.h5"], ["meta.json"], False)[0] == "ok"
    for name, edit, field in (("speed", lambda d: _cell(d / "runs.csv", 1, 1, "1e308"), "speed_rpm"),
                              ("sample", lambda d: _cell(sorted(d.glob("run_*.csv"))[0], 3, 2, "1e308"), "sample")):
        d = with_meta(name)
        edit(d)
        outcome, msg = fz.run_case(["fit", d, "-o", tmp_path / "m.json", "--no-report"], [d.name], True)
        assert outcome == "clear" and field in msg and "1e+308" in msg, msg
    for seed in range(12):          # lab files: bad ones refused naming the field, good ones read
        path, bad, what = fs._lab_file(tmp_path / f"lab{seed}", random.Random(seed))
        outcome, msg = fz.run_case(["convert", path, "-o", path.with_suffix(".h5")], [path.name], bad)
        assert outcome == ("clear" if bad else "ok"), (what, msg)
        if bad:
            assert ("wf_start_offset" in msg) if path.suffix == ".tdms" else ("group" in msg), msg


def _cell(path, row: int, col: int, value: str) -> None:
    lines = path.read_text().splitlines()
    cells = lines[row].split(",")
    cells[col] = value
    lines[row] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
