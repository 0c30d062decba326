"""The beats of a line's co- and counter-rotating parts under a spin smear (:meth:`rwadist.diagnose.metric.
Metric.beat_variance`).

A planar (fixed-direction) radial line is a co/counter pair whose Fx/Fy split the model does not know: its parts beat
with a relative phase that is one over a whole run, allowed for as a variance of the band powers.  The smear's state
had none (its lines were taken for no steady lines), so adding a smear at any |α| > 0 raised the misplaced power by
what that allowance had held, and the smear at the sweep's true acceleration read worse than no smear at all.

Data: the E wheel run up 2100 -> 2900 rpm in 8 s (10.5 rad/s², the state equations integrated through its modes,
``physics="extended"``, as tests/test_smear_transfer.py), sliced into 2.1-s runs; the model the preset's with its
radial-force lines planar."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rwadist.diagnose import Context, initial_state
from rwadist.effects.spin_acceleration_diagnose import SpinAcceleration
from rwadist.presets import preset
from rwadist.spectra import compute_spectra
from rwadist.sweep import slice_sweep
from rwadist.teststand import simulate_sweep

RPM = 2 * np.pi / 60


def test_a_smear_tending_to_zero_is_no_smear_and_the_true_one_explains_more():
    wheel = preset("ithaco-e")
    sw = simulate_sweep(wheel, 2100.0, 2900.0, duration=8.0, sample_rate=1920.0, noise=0.002, modes=True,
                        test_stand=False, seed=3, physics="extended")
    test, _ = slice_sweep(sw, slice_samples=4096)
    ctx = Context(compute_spectra(test, nperseg=1024), test=test)
    model = wheel.to_model()
    planar = [dataclasses.replace(x, sense="planar") for x in model.empirical["radial_force"]]
    model = dataclasses.replace(model, empirical={**model.empirical, "radial_force": planar})
    steady = initial_state(ctx, model, ext_params=wheel.extended)

    def error(state):
        return float(ctx.run_errors(state, ctx.runs)[0].sum())

    none = error(steady)
    # continuity: the smear's prediction tends to the steady one as α -> 0 (before: 1.188 -> 1.883 at 1e-6 rad/s²)
    for alpha in (0.0, 1e-6):
        assert error(steady.plus(SpinAcceleration(alpha))) == pytest.approx(none, rel=1e-6)
    # the sweep's own acceleration explains the slices better than steady lines (before: 1.281 against 1.188)
    assert error(steady.plus(SpinAcceleration((2900.0 - 2100.0) * RPM / 8.0))) < 0.7 * none
