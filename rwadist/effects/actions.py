"""What an effect does to the wheel's loads, in a few generic actions every consumer knows (no effect kind).

An element (:mod:`rwadist.effects`) says what it does to the loads the wheel exerts with :meth:`actions` (a tuple of
the classes below; a measurement artefact or a record does nothing to them); the consumers of a model apply the
actions, in the order of :func:`ordered`:

- the line spectrum and PSD (:func:`rwadist.broadband.apply_effects`), the extended model's lines
  (:func:`rwadist.extended.apply_line_effects`, :func:`rwadist.extended_ripple.ripple_from_effects`), the coupling kit
  (:func:`rwadist.coupling.performance.wheel_spec_from_model`);
- the FMUs: the numpy runtime (:func:`rwadist.fmu.runtime.effects_from_doc`) and the C kernel, which gets them
  compiled in when the FMU is built (``rwadist/fmu/native_build.py``).

Units SI: Hz, rad/s, N or N·m.  Numpy only (shipped into the FMU with the elements).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: |Δh| within which a line action belongs to a line of the model (as every consumer matches them)
H_TOL = 1e-3


@dataclass(frozen=True)
class LineLaw:
    """The lines of ``direction`` at harmonic ``h`` (|Δh| < :data:`H_TOL`) have the amplitude
    law[0]·(|Ω|/law[1])^law[2] (N or N·m; law = (A_ref, Ω_ref rad/s, p)) instead of C·Ω²."""

    direction: str
    h: float
    law: tuple

    STAGE = 0


@dataclass(frozen=True)
class LineFilter:
    """The lines of ``directions`` pass through a resonance at ``f_hz`` (damping ratio ``zeta``, gain ``peak_gain``
    there, ``gain_above`` far above it): H(ν) = (1 − r² + 2j·g·ζ·r)/(1 − r² + 2j·ζ·r) when ``gain_above`` is 1,
    r = ν/(2π f_r), at each line's whirl rate ν (the general form: :func:`rwadist.resonance.resonance`)."""

    directions: tuple
    f_hz: float
    zeta: float
    peak_gain: float
    gain_above: float = 1.0

    STAGE = 0

    @property
    def resonance(self) -> tuple:
        """(f_r Hz, ζ, peak gain), and the gain above when it is not 1."""
        out = (self.f_hz, self.zeta, self.peak_gain)
        return out if self.gain_above == 1.0 else out + (self.gain_above,)


@dataclass(frozen=True)
class NoiseFloor:
    """A blocked-load PSD S(f, Ω) = psd_ref(f)·(|Ω|/omega_ref)^exponent (unit²/Hz) on channel ``channel`` (index in
    Fx..Tz), psd_ref linear between the knots ``f_hz`` (Hz), 0 outside; incoherent with everything."""

    channel: int
    f_hz: np.ndarray
    psd_ref: np.ndarray
    omega_ref: float
    exponent: float

    STAGE = 0


@dataclass(frozen=True)
class LineModulation:
    """The lines of ``direction`` at harmonic ``h`` (|Δh| < :data:`H_TOL`; after their amplitude laws) are amplitude
    modulated, a(1 + depth·cos 2π f_mod t): each gets two more lines at ±``f_mod_hz`` of amplitude depth·a/2."""

    direction: str
    h: float
    f_mod_hz: float
    depth: float

    STAGE = 1


@dataclass(frozen=True)
class SpeedModulation:
    """The wheel turns at Ω(t) = Ω0 + ΔΩ sin 2π f_hz t, ΔΩ = delta_omega·(|Ω0|/omega_ref)^exponent (rad/s): every line is
    phase and amplitude modulated (applied last, on every line).  At most one per wheel."""

    f_hz: float
    delta_omega: float
    omega_ref: float
    exponent: float

    STAGE = 2


def of_effects(effects, sources: bool = False) -> list:
    """The actions of typed effects (:func:`rwadist.schema.parse_effects`), in the order consumers apply them:
    by stage (line laws, filters and floors; then amplitude modulations; then a speed modulation), in file order
    within a stage.  An effect without actions (a bare :class:`rwadist.schema.Effect`, an unknown kind) adds none.
    ``sources``: pairs (effect, action), the effect each action comes from."""
    out = [(e, a) for e in effects for a in (e.actions() if hasattr(e, "actions") else ())]
    out.sort(key=lambda p: p[1].STAGE)
    return out if sources else [a for _, a in out]
