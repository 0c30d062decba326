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


def test_none_for_a_number_without_a_none_default_is_refused_by_name():
    """None passed the API's checks as "a default left to the function" for every number, then failed inside as a
    TypeError (psd(n_freq=None), fit(presence=None), diagnose(k_sigma=None), simulate_test(n_samples=None))."""
    import pytest

    import rwadist

    test = rwadist.simulate_test("ithaco-e", [600.0, 1200.0, 1800.0, 2400.0], n_samples=1024, seed=1)
    calls = {"n_freq": lambda: rwadist.psd(None, (600, 2400), preset="ithaco-e", n_freq=None),
             "n_speeds": lambda: rwadist.psd(None, (600, 2400), preset="ithaco-e", n_speeds=None),
             "presence": lambda: rwadist.fit(test, presence=None),
             "k_sigma": lambda: rwadist.diagnose(test, k_sigma=None),
             "n_samples": lambda: rwadist.simulate_test("ithaco-e", [600.0], n_samples=None)}
    for name, call in calls.items():
        with pytest.raises(rwadist.ParameterError, match=f"^{name}: None: must be a number"):
            call()
