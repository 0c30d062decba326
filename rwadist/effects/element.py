"""The base of every element of :mod:`rwadist.effects`: what the kit does with an effect besides reading and writing it.

:class:`rwadist.schema.Effect` is the model file's side of a kind (its checked fields, JSON in and out); an element
derives from :class:`Element`, which adds the hooks the kit's consumers call, each with a neutral default (a kind
registered as a bare :class:`~rwadist.schema.Effect` is read, written and shown, and acts on nothing):

- :meth:`Element.describe`: its one line of words and numbers for the console;
- :meth:`Element.actions`: what it does to the wheel's loads, as generic actions (:mod:`rwadist.effects.actions`),
  and the FMU parameter that turns them off (``FMU_SWITCH``, a :class:`FmuSwitch`);
- the ``INJECT`` table and the ``inject_*`` hooks: its injection into the virtual test stand, called by
  :mod:`rwadist.inject` with a :class:`rwadist.inject.Stand` (the stand's services: its wheel, random numbers, adding
  a line to a run, a wheel load through the rotor's modes, low-passed noise).

Besides, the helpers the elements' texts share (:func:`words`, :func:`num`, :func:`rpm`, ...).  Numpy and the
schema only (shipped into the FMU with the elements).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..schema import Effect
from ..units import RAD_S_TO_RPM


@dataclass(frozen=True)
class FmuSwitch:
    """A Boolean parameter of the wheel FMUs that turns an element's actions on the FMU's outputs off (its noise
    floors, its speed modulation: what the runtime adds on top of the lines).  ``slot``: which of the FMUs' effect
    switches it is (their value references follow ``start_steady``, in slot order; the FMUs have
    ``rwadist.fmu.runtime.SWITCH_SLOTS`` of them); ``name``, ``description``: the variable's."""

    slot: int
    name: str
    description: str


@dataclass(frozen=True, eq=False, kw_only=True)
class Element(Effect):
    """An effect kind of :mod:`rwadist.effects` (base class; the hooks' defaults do nothing)."""

    #: rank among the kinds: the order kinds are listed in (and ``rwadist diagnose`` asks its families in)
    ORDER: ClassVar[int] = 1000

    # ------------------------------------------------------------------ text
    @classmethod
    def describe(cls, entry: Mapping) -> str | None:
        """``entry`` (the kind's JSON object, or a diagnose summary entry with more keys) as one line of words and
        numbers with units, without the kind's name (``rwadist.effects_text.describe_effect`` puts it in front);
        None: the generic line of its scalar fields.  KeyError, TypeError or ValueError (fields of another version)
        also give the generic line."""
        return None

    def named_lines(self) -> tuple:
        """The model's lines this effect names, ((direction, h), ...): lines the search put into the model as its
        record (a sideband pair's two lines), whose cause is the effect itself, not a bearing ratio or a
        combination of other lines; none by default."""
        return ()

    # ------------------------------------------------------------------ what it does to the wheel's loads
    #: the FMU parameter that turns this kind's floors and speed modulation off (:class:`FmuSwitch`), or None
    FMU_SWITCH: ClassVar[FmuSwitch | None] = None

    def actions(self) -> tuple:
        """What this effect does to the loads the wheel exerts, as generic actions (:mod:`rwadist.effects.actions`)
        every consumer of a model applies; none by default (a measurement artefact, a record of the search)."""
        return ()

    # ------------------------------------------------------------------ injection into the virtual stand
    #: ``--inject KIND:PARAM=VALUE,...`` parameters {name: default} (None: an optional parameter without default);
    #: None for a kind the stand does not inject
    INJECT: ClassVar[Mapping | None] = None
    #: parameters given as text (``direction``, ``channels``: checked by :func:`rwadist.inject.parse`); others are
    #: numbers, >= 0 unless listed in INJECT_POSITIVE (> 0) or INJECT_SIGNED (any sign)
    INJECT_TEXT: ClassVar[tuple] = ()
    INJECT_POSITIVE: ClassVar[tuple] = ()
    INJECT_SIGNED: ClassVar[tuple] = ()
    #: applied after every other kind (it acts on what the load cell measures, the other injections included)
    INJECT_LAST: ClassVar[bool] = False
    #: needs the noise-free simulation of the prepared wheel (``stand.clean``)
    INJECT_CLEAN: ClassVar[bool] = False

    @classmethod
    def inject_check(cls, spec: dict, bad) -> None:
        """Checks of a parsed ``spec`` across its parameters; ``raise bad(field, why)`` on a wrong one."""

    @classmethod
    def inject_requires(cls, spec: dict, physics: str, modes: bool, stand: Any) -> None:
        """Checks of the simulation asked for (``--physics``, ``modes``) before anything is simulated;
        ``raise stand.error(field, why)``."""

    @classmethod
    def inject_prepare(cls, wheel: Any, spec: dict, stand: Any) -> Any:
        """The wheel to simulate with this injection (a :class:`rwadist.teststand.WheelSpec`, replaced, never
        changed): lines it replaces taken out or scaled, resonances added; ``spec`` may keep values for
        :meth:`inject_run` (the line's ``C``)."""
        return wheel

    @classmethod
    def inject_run(cls, spec: dict, run: Any, index: int, stand: Any) -> None:
        """Add this injection to one simulated run (``run.signals`` replaced channel by channel); ``index``: the
        run's position in the test (``stand.clean.runs[index]`` is its noise-free twin)."""


# ---------------------------------------------------------------------- words and numbers of the one-line texts

def words(name: str) -> str:
    """A key or kind in words (``f_mod_Hz`` -> ``f mod Hz``)."""
    return str(name).replace("_", " ")


def num(v, spec: str = ".4g") -> str:
    return format(float(v), spec)


def rpm(omega_rad_s) -> str:
    """A speed in rad/s as ``NNN rpm``."""
    return f"{abs(float(omega_rad_s)) * RAD_S_TO_RPM:.0f} rpm"


def plus_minus(e: Mapping, key: str, spec: str = ".2g") -> str:
    """`` ±x`` of a standard error ``e[key]``, or nothing when it is absent or not finite."""
    v = e.get(key)
    return f" ±{format(float(v), spec)}" if v is not None and np.isfinite(float(v)) else ""


def directions(v) -> str:
    """A direction or a list of them in words."""
    return ", ".join(words(d) for d in (v if isinstance(v, (list, tuple)) else [v]))
