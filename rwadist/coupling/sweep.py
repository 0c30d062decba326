"""Sweeps over speeds, wheel sets and parameter sets, in parallel through dask.

Local by default with no setup (dask's threaded scheduler in this process); pass
``scheduler="processes"``/``"sync"`` for the other local schedulers, ``address="tcp://host:8786"``
to run on a dask.distributed cluster, or ``client=`` an existing ``distributed.Client`` (e.g. on
a ``LocalCluster``).  Work is split into (wheel set, speed chunk) tasks; each task runs
:func:`rwadist.coupling.performance.jitter_vs_speed` on its chunk, so results are identical to a serial
call whatever the scheduler (test).
"""
from __future__ import annotations

import numpy as np

from .assemble import PRACTICES
from .errors import CouplingError
from .performance import JitterResult, jitter_vs_speed


def _task(plant, wheels, omega, practices):
    return jitter_vs_speed(plant, wheels, omega, practices)


def _merge(parts):
    p0 = parts[0]
    return JitterResult(np.concatenate([p.omega for p in parts]), p0.perf_names,
                        {k: np.concatenate([p.rms[k] for p in parts]) for k in p0.rms},
                        {k: np.concatenate([p.rel_error[k] for p in parts]) for k in p0.rel_error})


def sweep(plant, wheel_sets, omega, practices=PRACTICES, chunk: int = 100, scheduler: str = "threads",
          address: str | None = None, client=None) -> dict:
    """Jitter vs speed for each wheel set.

    wheel_sets : {name: [WheelSpec, ...]} (several wheel configurations or parameter sets), or one
    list of WheelSpecs (returned under the name 'wheels').  omega : sweep speeds, rad/s.
    chunk : speeds per task.  scheduler : local dask scheduler ('threads', 'processes', 'sync')
    when neither ``address`` nor ``client`` is given.  Returns {name: JitterResult}.
    """
    import dask

    if not isinstance(wheel_sets, dict):
        wheel_sets = {"wheels": list(wheel_sets)}
    om = np.atleast_1d(np.asarray(omega, dtype=float))
    if om.size == 0:
        raise CouplingError("no speeds to sweep")
    if chunk < 1:
        raise CouplingError("chunk must be >= 1")
    practices = tuple(practices)
    pieces = [(name, om[i:i + chunk]) for name in wheel_sets for i in range(0, om.size, chunk)]
    own_client = None
    if address is not None and client is None:
        from distributed import Client
        client = own_client = Client(address)
    try:
        if client is not None:
            plant_f = client.scatter(plant, broadcast=True)
            sets_f = {n: client.scatter(list(ws), broadcast=True) for n, ws in wheel_sets.items()}
            futs = [client.submit(_task, plant_f, sets_f[n], o, practices, pure=False) for n, o in pieces]
            results = client.gather(futs)
        else:
            plant_d = dask.delayed(plant, traverse=False)
            sets_d = {n: dask.delayed(list(ws), traverse=False) for n, ws in wheel_sets.items()}
            tasks = [dask.delayed(_task, pure=False)(plant_d, sets_d[n], o, practices) for n, o in pieces]
            results = dask.compute(*tasks, scheduler=scheduler)
    finally:
        if own_client is not None:
            own_client.close()
    out: dict[str, list] = {}
    for (name, _), r in zip(pieces, results):
        out.setdefault(name, []).append(r)
    return {n: _merge(parts) for n, parts in out.items()}
