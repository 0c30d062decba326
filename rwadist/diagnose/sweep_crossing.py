"""Where a line of a run cut from a sweep passes a fitted resonance faster than the resonance settles: its measured
power there is not the steady-state response the model predicts, so the open world's line readers do not read it.

On a sweep (the ``spin_acceleration`` effect, |dΩ/dt| = α) a line of harmonic h moves at ḟ = h·α/2π Hz/s.  A mode of
frequency f_m and damping ζ follows a moving force quasi-statically only when the force's frequency moves by much
less than the mode's half-power half-width ζ·f_m in one of its time constants τ = 1/(2πζf_m), i.e. when
η = ḟ·τ/(ζ·f_m) = ḟ/(2π(ζf_m)²) ≪ 1; above that the response lags, its peak falls and the mode rings on at its own
frequency after the line has passed (Lollock, AIAA 2002-1230, the swept-sine response of a single mode).  The model's
lines are the steady-state response evaluated at each Welch segment's own speed (``Context.smear_transfer``), which is
right away from the modes and wrong by several dB in a fast crossing: family wheel 0's 30-s run-up (α 18.8 rad/s²,
lines at 9-15 Hz/s through the 77-83 Hz backward rocking whirl, ζ 0.018: η 0.8-1.1) read its h 3.08 and 4.92 torque
lines 1.2-3.2 dB over the model there, which the moving-resonance detector fitted as a rotor mode of 1 nodal diameter.

A point (line, run) is a crossing when η ≥ :data:`MIN_ETA` and the line's frequency span over the run's record
(f ± ḟ·T/2) comes within :data:`HALF_WIDTHS` half-power half-widths, plus the distance the line moves in
:data:`TIME_CONSTANTS` time constants, plus its read window, of a fitted resonance: the suspension modes' whirl
frequencies at the run's speed and every fixed resonance named.  Steady tests (no spin acceleration) have none.

Units: Hz, s, rad/s².
"""
from __future__ import annotations

import numpy as np

from .constants import LINE_HALF

#: The crossing's dimensionless rate η = ḟ/(2π(ζf_m)²) from which the steady-state response is not read.  A single
#: mode's response to a linear chirp (scipy.signal.lsim, ζ 0.02, tests/test_sweep_crossing.py), its mean square over
#: records of 0.25-8 half-widths of sweep against the steady |H|² averaged over them: off by at most 0.61, 0.96, 1.26,
#: 1.98, 3.04 dB at η = 0.1, 0.15, 0.2, 0.3, 0.5 (the shortest records the most); at η = 3, by more than 0.5 dB from
#: 5 half-widths below the mode to 9 above it.  Below this η no record is off by 1 dB
MIN_ETA = 0.15
#: Half-power half-widths (ζ·f_m) about the resonance in which the lagged response differs from the steady one
HALF_WIDTHS = 3.0
#: Time constants τ over which the mode rings on after the line has passed (e^-5: 0.7 % of its amplitude; the ringing
#: of a fast crossing, η = 4, still moved records 15 half-widths past the mode by 1-1.8 dB at 3 time constants)
TIME_CONSTANTS = 5.0


def _resonances(state, spin_hz: np.ndarray) -> list:
    """(frequency Hz per run (R,), ζ) of every resonance of the state's effects: the suspension modes' whirl
    frequencies at each run's spin ``spin_hz`` (Hz) and each fixed resonance."""
    out = []
    for e in state.effects:
        kind = getattr(e, "kind", "")
        if kind == "suspension_modes":
            half = 0.5 * e.inertia_ratio * spin_hz
            root = np.sqrt(half**2 + e.f0_Hz["rocking"] ** 2)
            out += [(np.full(spin_hz.shape, e.f0_Hz["radial_translation"]), e.zeta["radial_translation"]),
                    (root + half, e.zeta["rocking"]), (root - half, e.zeta["rocking"]),
                    (np.full(spin_hz.shape, e.f0_Hz["axial"]), e.zeta["axial"])]
        elif kind == "fixed_resonance":
            out.append((np.full(spin_hz.shape, e.f_r), e.zeta))
    return [(f, z) for f, z in out if z > 0 and np.all(np.isfinite(f))]


def near_crossing(f, f_dot, half_span, f_m, zeta: float, read: float = 0.0) -> np.ndarray:
    """Boolean (broadcast): a line at ``f`` Hz (its record's centre) moving at ``f_dot`` Hz/s over ``±half_span`` Hz in
    its record, read in ``±read`` Hz about it, is a fast crossing of the resonance at ``f_m`` Hz of damping ``zeta``:
    η ≥ :data:`MIN_ETA` and its span within :data:`HALF_WIDTHS`·ζf_m + :data:`TIME_CONSTANTS`·τ·ḟ + ``read`` of f_m."""
    f_m = np.asarray(f_m, dtype=float)
    bw = zeta * f_m                                                  # half-power half-width, Hz
    f_dot = np.abs(np.asarray(f_dot, dtype=float))
    fast = f_dot / (2 * np.pi * bw**2) >= MIN_ETA
    gap = np.maximum(np.abs(np.asarray(f, dtype=float) - f_m) - half_span, 0.0)
    return fast & (gap <= HALF_WIDTHS * bw + TIME_CONSTANTS * f_dot / (2 * np.pi * bw) + read)


def crossings(ctx, state, h: np.ndarray, run: np.ndarray, alpha: float | None = None) -> np.ndarray:
    """Boolean mask (P,) of the points (line ratio ``h``, position ``run`` in the context's runs) whose line passes a
    fitted resonance too fast for its steady-state response within the run's record (:func:`near_crossing`), the
    wheel accelerating at the state's spin smear or else ``alpha`` (rad/s², |dΩ/dt|); all False on a steady test
    (neither given)."""
    h = np.abs(np.asarray(h, dtype=float))
    run = np.asarray(run, dtype=int)
    mask = np.zeros(h.shape, bool)
    rate = state.smear if state.smear is not None else alpha
    if rate is None or not np.isfinite(rate) or rate == 0 or h.size == 0:
        return mask
    runs = ctx.runs[run]
    spin = np.abs(ctx.omega[runs]) / (2 * np.pi)
    f_dot = h * abs(float(rate)) / (2 * np.pi)                       # Hz/s
    half_span = 0.5 * f_dot * ctx.run_durations(runs)
    for f_m, zeta in _resonances(state, spin):
        mask |= near_crossing(h * spin, f_dot, half_span, f_m, zeta, (LINE_HALF + 1) * ctx.df)
    return mask
