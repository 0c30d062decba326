"""Diagnose what a wheel model leaves out of measured data, name the effect, add it (issue 7).

:func:`diagnose` starts from a model (the empirical fit of the data, or a given model file / preset),
predicts the expected Welch PSD of every run and channel, and looks at the residual on the speed ×
frequency plane.  Effect families (the diagnose hypothesis of each effect kind, beside its element in
:mod:`rwadist.effects`; one protocol, one registry, :mod:`rwadist.diagnose.effects`) propose hypotheses from
the residual, fit them on half of the speeds and are ranked on
the other half; the best one passing the held-out test is added and the search repeats until nothing
passes.  :func:`write_report` writes what was found.

The theory (predicted PSD, error metric, acceptance rule, every effect family's signature and fit) is
in ``docs/diagnose.md``; the package's modules:

- :mod:`~rwadist.diagnose.engine` the prediction engine (:class:`Context`, :func:`line_kernel`),
  :mod:`~rwadist.diagnose.state` the :class:`State`, :mod:`~rwadist.diagnose.metric` the error metric;
- :mod:`~rwadist.diagnose.measure` residual measurements shared by effect families;
- :mod:`~rwadist.diagnose.record_residual` the whole-run DFT residual (lines below the Welch band or apart from
  their neighbours);
- :mod:`~rwadist.diagnose.effects` the effect families' protocol and registry (the families themselves:
  ``rwadist/effects/<kind>_diagnose.py``);
- :mod:`~rwadist.diagnose.search` the greedy search (:func:`diagnose`); :mod:`~rwadist.diagnose.bases` its starting base (:func:`resolve_base`);
- :mod:`~rwadist.diagnose.report` the report (:func:`write_report`).
"""
from __future__ import annotations

from ..resonance import resonance
from .bases import BASES, resolve_base
from .constants import (
                        BAND_BINS,
                        F_MIN_BINS,
                        FLOOR_EXPONENTS,
                        KERNEL_HALF,
                        LINE_HALF,
                        METRIC,
                        NOISE_Z,
                        SNR_KNEE,
                        TORQUE_CHANNELS,
)
from .effects import REGISTRY, Effect, family_classes
from .engine import Context, initial_state, line_kernel, noise_estimate
from .measure import refine_h, ridge_peaks
from .report import rms_vs_speed, write_report
from .ripple import ripple_sideband_powers
from .search import Diagnosis, Hypothesis, diagnose, effect_entry
from .state import State

__all__ = [
    "BAND_BINS", "BASES", "F_MIN_BINS", "FLOOR_EXPONENTS", "KERNEL_HALF", "LINE_HALF", "METRIC", "NOISE_Z", "REGISTRY",
    "SNR_KNEE", "TORQUE_CHANNELS", "Context", "Diagnosis", "Effect", "Hypothesis", "State", "diagnose", "effect_entry",
    "family_classes", "initial_state", "line_kernel", "noise_estimate", "refine_h", "resonance", "resolve_base",
    "ridge_peaks", "ripple_sideband_powers", "rms_vs_speed", "write_report",
]
