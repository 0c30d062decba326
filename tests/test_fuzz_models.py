"""Fuzz sample of mutated model files through model show / psd / campbell / fmu build (issue 17; the full
run: benchmarks/fuzz_all.py --surface models).  Never a traceback, never a known-invalid value used."""
import fuzz_cases as fz


def test_fuzz_model_files(tmp_path):
    cases = [c for c in fz.model_cases(40, 2, tmp_path) if c[0][0] != "fmu"]   # fmu builds: the benchmark
    results = [(fz.run_case(argv, names, invalid), what) for argv, names, invalid, what in cases]
    bad = [(r, what) for r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert fz.tally(r for r, _ in results)["clear"] >= 5
