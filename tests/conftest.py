"""Session-scoped generated datasets shared by the test files, and the order the tests run in.

The virtual test stand and the fits are deterministic for a given seed, so a dataset that several
tests (or several files) build with the same arguments is built once per test process here.  Under
``pytest -n 2`` each worker process builds its own copy the first time one of its tests asks.

The fixtures hand out shared objects: a test must not change them.  The sample arrays of every
dataset built here are made read-only, so a test that writes into one fails loudly instead of
changing what the next test sees; a test that edits its data builds its own.
"""
from __future__ import annotations

import fcntl
import inspect
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

# rwadist is imported inside the fixtures, when a test first asks for one: collecting the suite imports
# no more of the package than the test files themselves do

#: the thesis's E-wheel steady test (§2.2.2): 120 speeds 300-2400 rpm, 3840 Hz, 8192 samples a run
E_FULL_SPEEDS_RPM = np.linspace(300.0, 2400.0, 120)
E_FULL = dict(sample_rate=3840.0, n_samples=8192, noise=0.01, seed=0)


def read_only(test):
    """Mark every sample array of ``test`` read-only (in place) and return it."""
    for run in test.runs:
        for x in run.signals.values():
            x.flags.writeable = False
    return test


@pytest.fixture(scope="session")
def stand_steady():
    """``stand_steady(preset_name, speeds_rpm, **simulate_steady_kwargs)`` -> a read-only ``SteadyTest``.

    Memoised on its arguments for the session: two tests asking for the same preset, speeds (rpm)
    and stand settings get the same object, built once.
    """
    from rwadist.presets import preset
    from rwadist.teststand import simulate_steady

    cache: dict = {}

    def build(name: str, speeds_rpm, **kw):
        key = (name, tuple(np.asarray(speeds_rpm, dtype=float).tolist()), tuple(sorted(kw.items())))
        if key not in cache:
            cache[key] = read_only(simulate_steady(preset(name), speeds_rpm, **kw))
        return cache[key]

    return build


@pytest.fixture(scope="session")
def stand_sweep():
    """``stand_sweep(preset_name, rpm_start, rpm_end, **simulate_sweep_kwargs)`` -> a read-only ``Sweep``.

    Memoised on its arguments for the session, as ``stand_steady``.
    """
    from rwadist.presets import preset
    from rwadist.teststand import simulate_sweep

    cache: dict = {}

    def build(name: str, rpm_start: float, rpm_end: float, **kw):
        key = (name, float(rpm_start), float(rpm_end), tuple(sorted(kw.items())))
        if key not in cache:
            sweep = simulate_sweep(preset(name), rpm_start, rpm_end, **kw)
            for x in (sweep.time, sweep.tach, *sweep.signals.values()):
                if x is not None:
                    x.flags.writeable = False
            cache[key] = sweep
        return cache[key]

    return build


@pytest.fixture(scope="session")
def e_full_modes_off(stand_steady):
    """(wheel, empirical fit) of the full-size E-wheel test with the stand's modes off (issue 2 acceptance)."""
    from rwadist.empirical import fit_empirical
    from rwadist.presets import preset
    from rwadist.spectra import compute_spectra

    test = stand_steady("ithaco-e", E_FULL_SPEEDS_RPM, modes=False, **E_FULL)
    return preset("ithaco-e"), fit_empirical(compute_spectra(test))


@pytest.fixture(scope="session")
def e_full_modes_on(stand_steady):
    """(wheel, empirical fit) of the full-size E-wheel test with the stand's modes on (issue 2 acceptance)."""
    from rwadist.empirical import fit_empirical
    from rwadist.presets import preset
    from rwadist.spectra import compute_spectra

    test = stand_steady("ithaco-e", E_FULL_SPEEDS_RPM, modes=True, **E_FULL)
    return preset("ithaco-e"), fit_empirical(compute_spectra(test))


@pytest.fixture(scope="session")
def e_full_extended_fit(stand_steady):
    """(wheel, empirical fit, extended fit) of the full-size E-wheel test generated through the extended
    model with its suspension modes (Table 4.2, height 0; issue 3 acceptance)."""
    from rwadist.empirical import fit_empirical
    from rwadist.extended_fit import fit_extended
    from rwadist.presets import preset
    from rwadist.spectra import compute_spectra

    wheel = preset("ithaco-e")
    test = stand_steady("ithaco-e", E_FULL_SPEEDS_RPM, modes=True, physics="extended", **E_FULL)
    fit = fit_empirical(compute_spectra(test))
    return wheel, fit, fit_extended(test, fit, wheel.mass_kg, wheel.radius_m)


# --------------------------------------------------------------------------- built once per test run

def once_per_run(tmp_path_factory, name: str, build) -> Path:
    """A folder ``name`` filled by ``build(folder)`` once per pytest run, across the ``-n`` worker processes.

    The first process to get here builds under an exclusive lock (``fcntl.flock``) and marks the folder
    complete; a process arriving meanwhile waits for the lock, then reads the finished folder.  Without
    xdist the folder lives in this session's own temporary directory.  A build that raised leaves no mark:
    the next process to ask builds again (and fails the same way, in its own test).  Readers must not
    change the folder.
    """
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent                  # .../pytest-N/popen-gwK -> .../pytest-N, one per run, shared
    folder = root / name
    done = root / f"{name}.complete"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            if not done.exists():
                shutil.rmtree(folder, ignore_errors=True)
                folder.mkdir()
                build(folder)
                done.touch()
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    return folder


@pytest.fixture(scope="session")
def family_clean_cell(tmp_path_factory):
    """``family_clean_cell(i)`` -> (row, cell folder) of family wheel ``i``'s clean cell of the robustness matrix
    (benchmarks/diagnose_family_matrix.py ``run_cell``: its data at seed 1 + 100·i written as a lab's CSV and
    ``rwadist diagnose DATA -o REPORT`` run on them; the folder holds ``data``, ``truth.json`` and ``report``), run once
    per test run across the ``-n`` workers: several files compare a cell with the same wheel's clean one.  ``row`` is
    the cell's evaluation as ``run_cell`` returns it (read back from JSON: lists for its tuples)."""
    import json
    import sys

    def get(i: int):
        def build(folder: Path) -> None:
            sys.path.insert(0, str(TESTS_DIR.parent / "benchmarks"))
            import diagnose_family_matrix as dfm

            row = dfm.run_cell(i, dfm.wheels()[i], "clean", "clean", [], 1 + 100 * i, folder, None)
            (folder / "row.json").write_text(json.dumps(row))

        folder = once_per_run(tmp_path_factory, f"family_clean_cell_{i}", build)
        return json.loads((folder / "row.json").read_text()), folder / f"w{i}_clean"

    return get


#: the example notebook, executed by test_notebook.py and test_coupling.py
EXAMPLE_NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "coupling_study.ipynb"


@pytest.fixture(scope="session")
def executed_notebook(tmp_path_factory):
    """(executed notebook, folder it ran in) of ``examples/coupling_study.ipynb``, executed once per run.

    Executed as a user would run it: a Jupyter kernel driven by nbclient (per-cell timeout 300 s), with
    the folder as its working directory, so the figures it saves land in ``folder``.  The executed
    notebook is written to ``folder/executed.ipynb`` and read back here; the tests that check it
    (the figures inline and saved, no error output) all read this one run.
    """
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")

    def execute(folder: Path) -> None:
        nb = nbformat.read(EXAMPLE_NOTEBOOK, as_version=4)
        nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                                resources={"metadata": {"path": str(folder)}}).execute()
        nbformat.write(nb, folder / "executed.ipynb")

    folder = once_per_run(tmp_path_factory, "executed_notebook", execute)
    return nbformat.read(folder / "executed.ipynb", as_version=4), folder


#: what the fresh virtual environment holds: numpy and what fmpy imports (lxml, attrs), libcosimpy (the second
#: FMU host); fmpy itself goes in with --no-deps (its other dependencies are for its GUI and are not imported)
FRESH_VENV_PACKAGES = ("numpy", "lxml", "attrs", "libcosimpy")


@pytest.fixture(scope="session")
def fresh_fmpy_venv(tmp_path_factory) -> Path:
    """Python of a new virtual environment with only FRESH_VENV_PACKAGES and fmpy -- no rwadist, no pythonfmu.

    Built once per run and shared by the fresh-venv tests of test_fmu.py and test_fmu_native.py, which only
    run scripts in it (their files go to their own tmp_path) and each check that neither rwadist nor pythonfmu
    can be imported there.  The environment gets no pip of its own (``--without-pip``: ensurepip was ~3.6 s of
    CPU); this test run's pip installs into it (``pip --python``), without byte-compiling every installed
    module (``--no-compile``: the scripts compile the few they import).  ~4 s of CPU instead of ~8.4 s.
    """
    import subprocess
    import sys

    def build(folder: Path) -> None:
        subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder / "venv")], check=True)
        py = folder / "venv" / "bin" / "python"
        pip = [sys.executable, "-m", "pip", "--python", str(py), "install", "--quiet", "--no-compile"]
        subprocess.run([*pip, *FRESH_VENV_PACKAGES], check=True, timeout=300)
        subprocess.run([*pip, "--no-deps", "fmpy"], check=True, timeout=300)

    return once_per_run(tmp_path_factory, "fresh_fmpy_venv", build) / "venv" / "bin" / "python"


# --------------------------------------------------------------------------- workers

#: thread-count variables of the BLAS/OpenMP libraries numpy and scipy load
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def pytest_configure(config):
    """``pytest -n N``: one BLAS thread per worker process (unless the caller set a count).

    The workers already use every core; OpenBLAS would start one thread per core in each of them as
    well, and the threads then wait on each other.  Measured on the 2-core machine of the README with
    one extended fit (the per-unit cell of test_extended_fit_matrix.py, 20 speeds): 8.3 and 6.9 s wall,
    4.8 and 4.3 s CPU with OpenBLAS's own threads; 3.6 and 3.3 s wall, 2.3 and 2.2 s CPU with one.  The
    controller runs this before it starts the workers, which inherit the variables and read them when
    they load numpy.
    """
    if getattr(config.option, "numprocesses", None):
        for name in BLAS_THREAD_VARIABLES:
            os.environ.setdefault(name, "1")


# --------------------------------------------------------------------------- order of the tests

TESTS_DIR = Path(__file__).resolve().parent
WIDE_SCOPES = ("class", "module", "package", "session")


def _builds_shared_data(fixturedef) -> bool:
    """A fixture of this test tree (a test file or this conftest) kept beyond one test."""
    if fixturedef.scope not in WIDE_SCOPES:
        return False
    try:
        return TESTS_DIR in Path(inspect.getfile(fixturedef.func)).resolve().parents
    except TypeError:            # a builtin or C-level callable: not ours
        return False


def pytest_collection_modifyitems(config, items):
    """The tests marked ``slow`` (full-size runs of several seconds each) first, in their order.

    ``pytest -n 2`` (pytest-xdist, ``--dist worksteal`` from pyproject.toml) gives each worker one half of
    the tests in this order, and a worker that runs dry takes half of what the other has not started, from
    the end of its queue: a long test collected last could still keep one worker busy while the other idles
    (the slow sweeps of test_sweep.py and test_teststand.py sort near the end).  At the start of the first
    half, the long tests overlap with the short ones.  A slow test that uses a fixture shared with its neighbours
    (module or session scope, defined in this tree) stays where it is, so nothing is built twice in a
    serial run either.

    (Grouping the tests of a shared fixture onto one worker with ``--dist loadgroup`` would avoid a second
    build on the other worker, but pytest-xdist 3.8 with pytest 9.2 drops the groups silently:
    pytest-dev/pytest-xdist#1386.)
    """
    def stays(item) -> bool:
        info = getattr(item, "_fixtureinfo", None)
        shared = info is not None and any(_builds_shared_data(d) for defs in info.name2fixturedefs.values()
                                          for d in defs)
        return shared or item.get_closest_marker("slow") is None

    items.sort(key=stays)
