"""The Python API computes with one BLAS thread, as the command line does (issue 37; a new user's README example
took over 15 min beside busy neighbours, 2:23 with ``OPENBLAS_NUM_THREADS=1``): every computing function holds the
pools to one thread for its whole call, including scipy.linalg's pool loaded during it, and gives them back after."""
import json
import os
import subprocess
import sys

import rwadist
from rwadist import threads

#: the public functions that compute (read, load_model, save_model, write_nastran and build_fmu only move bytes)
COMPUTING = ("simulate_test", "simulate_sweep", "fit", "fit_extended", "diagnose", "psd", "campbell")


def test_every_computing_function_of_the_api_holds_one_thread():
    for name in COMPUTING:
        function = getattr(rwadist, name)
        assert function.__wrapped__.__module__.startswith("rwadist.api"), name     # the decorator's, docstring kept
        assert function.__doc__ == function.__wrapped__.__doc__ and "Parameters" in function.__doc__, name


CODE = """
import json
import numpy as np
from threadpoolctl import threadpool_info
import rwadist
from rwadist import spectra

def pools():
    return sorted((i["filepath"], i["num_threads"]) for i in threadpool_info())

seen = []
real = spectra.compute_spectra
def recording(*args, **kwargs):
    import scipy.linalg                    # the pool a fit loads during its call
    seen.append(pools())
    return real(*args, **kwargs)
spectra.compute_spectra = recording
test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 8), n_samples=2048, seed=1,
                             sample_rate=1920.0)
before = pools()
fit = rwadist.fit(test)
print(json.dumps({"before": before, "inside": seen[0], "after": pools(),
                  "harmonics": len(fit.model.harmonics("radial_force"))}))
"""


def test_a_fit_from_python_runs_every_pool_with_one_thread_and_gives_them_back():
    env = {k: v for k, v in os.environ.items() if k not in threads.ONE_THREAD_ENVIRONMENT}
    run = subprocess.run([sys.executable, "-c", CODE], env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout.splitlines()[-1])
    cores = len(os.sched_getaffinity(0))
    assert out["harmonics"] > 0
    assert len(out["inside"]) >= 2 and all(n == 1 for _, n in out["inside"]), out      # numpy's pool and scipy's
    assert all(n == cores for _, n in out["after"]), out
    assert {tuple(p) for p in out["before"]} <= {tuple(p) for p in out["after"]}            # numpy's pool back at the count it had


def test_a_count_the_user_set_is_left_alone(monkeypatch):
    from threadpoolctl import threadpool_info

    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "1")     # as under pytest -n: the user's (here conftest's) choice
    before = [i["num_threads"] for i in threadpool_info()]
    with threads.one_blas_thread():
        assert [i["num_threads"] for i in threadpool_info()] == before
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
