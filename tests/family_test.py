"""The family generator's data (tests/family_wheel.py: numpy arrays, no rwadist import) as rwadist's
:class:`rwadist.data.SteadyTest` and :class:`rwadist.data.Sweep`, written once for the tests that read it."""
from __future__ import annotations

import family_wheel as fw

from rwadist.data import Run, SteadyTest, Sweep


def steady_test(data: fw.Steady) -> SteadyTest:
    """``data`` as a steady test: one :class:`Run` per speed (rad/s, as generated), its six channels in
    :data:`family_wheel.CHANNELS` order, named run_0000.csv on; no meta."""
    runs = [Run(speed=float(om), sample_rate=data.sample_rate, t0=0.0, name=f"run_{i:04d}.csv",
                signals={c: data.signals[i, j] for j, c in enumerate(fw.CHANNELS)}) for i, om in enumerate(data.speeds)]
    return SteadyTest(runs=runs, meta={})


def sweep_record(data: fw.SweepData) -> Sweep:
    """``data`` as a sweep record with no speed column: its six channels in :data:`family_wheel.CHANNELS` order."""
    return Sweep(time=data.time, signals={c: data.signals[j] for j, c in enumerate(fw.CHANNELS)},
                 sample_rate=data.sample_rate, tach=None)
