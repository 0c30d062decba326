"""Diagnose what a wheel model leaves out of measured data, name the effect, add it (issue 7).

:func:`diagnose` starts from a model (the empirical fit of the data, or a given model file / preset),
predicts the expected Welch PSD of every run and channel, and looks at the residual on the speed ×
frequency plane.  Effect families (one module each in :mod:`rwadist.diagnose.effects`, one protocol,
one registry) propose hypotheses from the residual, fit them on half of the speeds and are ranked on
the other half; the best one passing the held-out test is added and the search repeats until nothing
passes.  :func:`write_report` writes what was found.

The theory (predicted PSD, error metric, acceptance rule, every effect family's signature and fit) is
in ``docs/diagnose.md``; the package's modules:

- :mod:`~rwadist.diagnose.engine` the prediction engine (:class:`Context`, :func:`line_kernel`),
  :mod:`~rwadist.diagnose.state` the :class:`State`, :mod:`~rwadist.diagnose.metric` the error metric;
- :mod:`~rwadist.diagnose.measure` residual measurements shared by effect families;
- :mod:`~rwadist.diagnose.effects` the effect families and their registry;
- :mod:`~rwadist.diagnose.search` the greedy search (:func:`diagnose`, :func:`resolve_base`);
- :mod:`~rwadist.diagnose.report` the report (:func:`write_report`).
"""
from __future__ import annotations

from ..resonance import resonance
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
from .effects import EFFECT_CLASSES, REGISTRY, Effect
from .effects.amplitude_law import AmplitudeLaw
from .effects.broadband_floor import BroadbandFloor
from .effects.counter_rotation import CounterRotation
from .effects.cross_coupling import CrossCoupling
from .effects.fixed_resonance import FixedResonance
from .effects.missing_harmonic import MissingHarmonic
from .effects.sidebands import Sidebands
from .effects.speed_ripple import SpeedRipple
from .effects.spin_acceleration import SpinAcceleration
from .effects.suspension_modes import SuspensionModes
from .engine import Context, initial_state, line_kernel, noise_estimate, ripple_sideband_powers
from .measure import refine_h, ridge_peaks
from .report import rms_vs_speed, write_report
from .search import BASES, Diagnosis, Hypothesis, diagnose, effect_entry, resolve_base
from .state import State

__all__ = [
    "BAND_BINS", "BASES", "EFFECT_CLASSES", "F_MIN_BINS", "FLOOR_EXPONENTS", "KERNEL_HALF", "LINE_HALF", "METRIC",
    "NOISE_Z", "REGISTRY", "SNR_KNEE", "TORQUE_CHANNELS", "AmplitudeLaw", "BroadbandFloor", "Context",
    "CounterRotation", "CrossCoupling", "Diagnosis", "Effect", "FixedResonance", "Hypothesis", "MissingHarmonic",
    "Sidebands", "SpeedRipple", "SpinAcceleration", "State", "SuspensionModes", "diagnose", "effect_entry", "initial_state",
    "line_kernel", "noise_estimate", "refine_h", "resonance", "resolve_base", "ridge_peaks",
    "ripple_sideband_powers", "rms_vs_speed", "write_report",
]
