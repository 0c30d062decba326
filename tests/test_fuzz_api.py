"""Fuzz sample of the Python API's arguments (issue 36; the full run: benchmarks/fuzz_all.py --surface api): NaN,
inf, negatives, 1e308, strings, booleans, lists and None for the numbers of simulate_test, fit, psd, campbell and
diagnose, and a WheelModel with C = 1e308 saved: every one accepted as valid or refused naming the argument, never
another exception, never an invalid value used (the API checked no argument: a NaN noise simulated NaN data, a
1e308 speed ran campbell)."""
import fuzz_surfaces as fs


def test_fuzz_api_arguments(tmp_path):
    cases = [c for c in fs.api_cases(60, 5, tmp_path) if not c[3].startswith(("diagnose.", "fit."))]
    results = [(fs.run_api_case(c), c[3]) for c in cases]
    bad = [(r, what) for r, what in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    assert sum(r[0] == "clear" for r, _ in results) >= 20
