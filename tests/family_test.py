"""The family generator's data (tests/family_wheel.py: numpy arrays, no rwadist import) as rwadist's
:class:`rwadist.data.SteadyTest` and :class:`rwadist.data.Sweep`, written once for the tests that read it, and the
checks several tests make of a diagnosis of it."""
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


def diagnosed_without_line(path, wheel: fw.Wheel, direction: str, h: float):
    """``rwadist diagnose`` (:func:`rwadist.api.diagnose`, no model) of the steady data at ``path``, checked to fit
    the wheel's translation mode located (within 1 %, ζ within 15 %) and to leave no line at ratio ``h`` (±0.01) of
    ``direction`` in the model: a source outside the wheel taken out before the search.  Returns the diagnosis."""
    import warnings

    from rwadist import api

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        diag = api.diagnose(str(path))
    modes = next(e for e in diag.state_after.effects if e.kind == "suspension_modes")
    assert not modes.unconstrained, modes.unconstrained
    assert abs(modes.f0_Hz["radial_translation"] / wheel.f_trans - 1) < 0.01
    assert abs(modes.zeta["radial_translation"] / wheel.zeta_trans - 1) < 0.15, (modes.zeta, wheel.zeta_trans)
    assert not [x for x in diag.model.harmonics(direction) if abs(x.h - h) < 0.01]
    return diag
