"""One BLAS/OpenMP thread while the kit computes: every command and every computing function of the API.

The kit's least squares and spectra are small per call; a pool's threads only wait on each other, and on a machine
whose cores are busy they wait on the neighbours too (``fit --extended`` of the demo's data beside two jobs on 2
cores: 108 s CPU, 4.6 s with one thread; the README's Python example under load: over 15 min, 2:23 with one).  A
count the user set in the environment is theirs and is left alone.  Thread counts also change the order of BLAS
sums, so holding them to one is what makes a call from Python give the command line's numbers to the last bit.
"""
from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import ParamSpec, TypeVar

#: thread-count variables of the BLAS/OpenMP libraries numpy and scipy load (a user who sets one has chosen)
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
#: what a library loaded later reads at its start: these set to 1 while the kit computes (BLIS, Apple Accelerate and
#: numexpr read their own)
ONE_THREAD_ENVIRONMENT = BLAS_THREAD_VARIABLES + ("BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")

_P = ParamSpec("_P")
_R = TypeVar("_R")


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """One thread in every BLAS and OpenMP pool inside the block, unless the environment sets a count.

    The pools loaded already are limited (threadpoolctl), and those loaded inside the block -- scipy.linalg's own
    OpenBLAS loads at its first use, with a thread per core (issue 37) -- read the thread-count variables, set to 1
    until the block ends; such a pool then gets the count it would have started with (one per core).  Nested blocks
    find the variables set and leave the outer one in charge."""
    if any(os.environ.get(v) for v in BLAS_THREAD_VARIABLES):
        yield
        return
    from threadpoolctl import ThreadpoolController, threadpool_limits

    loaded = {lib.filepath for lib in ThreadpoolController().lib_controllers}
    saved = {v: os.environ.get(v) for v in ONE_THREAD_ENVIRONMENT}
    os.environ.update({v: "1" for v in ONE_THREAD_ENVIRONMENT})
    try:
        with threadpool_limits(limits=1):
            yield
    finally:
        for v, value in saved.items():
            if value is None:
                os.environ.pop(v, None)
            else:
                os.environ[v] = value
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
        for lib in ThreadpoolController().lib_controllers:
            if lib.filepath not in loaded and lib.num_threads == 1:
                lib.set_num_threads(cores)


def in_one_blas_thread(function: Callable[_P, _R]) -> Callable[_P, _R]:
    """``function`` run inside :func:`one_blas_thread` (its name, signature and docstring kept)."""
    @functools.wraps(function)
    def held(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with one_blas_thread():
            return function(*args, **kwargs)
    return held
