"""Fuzz sample of damaged data files (steady CSV folders, sweep CSV, HDF5 with dangling links / flipped
bytes / NaN samples, UTF-16 text) read by `rwadist convert` (issue 17; the full run:
benchmarks/fuzz_all.py --surface readers).  Never a traceback, never a NaN read silently."""
import fuzz_cases as fz


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
