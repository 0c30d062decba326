"""``suspension_modes``: the wheel's own suspension modes as diagnose fitted them (a record)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

from ..schema import (
    COUNT,
    FREQUENCY,
    MAX_INERTIA_RATIO,
    MAX_ZETA,
    UNCONSTRAINED_DAMPING,
    UNCONSTRAINED_MODES,
    ZETA,
    boolean,
    check,
    names,
    number,
    numbers,
    optional,
    register,
)
from .element import Element, num


def _zeta_bounds():
    """Check of ``zeta_bounds``: {mode of :data:`UNCONSTRAINED_MODES`: [lo, hi] damping ratios, lo <= hi} ->
    {mode: (lo, hi)}."""
    pair = numbers(length=2, ge=0, le=MAX_ZETA, increasing=False)

    def run(v, where, err):
        if not isinstance(v, Mapping) or any(m not in UNCONSTRAINED_MODES for m in v):
            raise err(where[0], where[1], f"{v!r} must map modes ({', '.join(UNCONSTRAINED_MODES)}) to [lo, hi] "
                      "damping ratios")
        out = {m: tuple(float(x) for x in pair(b, (where[0], f"{where[1]}.{m}"), err)) for m, b in v.items()}
        if any(lo > hi for lo, hi in out.values()):
            raise err(where[0], where[1], f"each [lo, hi] needs lo <= hi, got {v!r}")
        return out
    run.json = {"type": "object", "additionalProperties": pair.json}  # type: ignore[attr-defined]
    return run


#: I_zz/I_rr of a thin disc, the most a rigid rotor has about its centre of mass (I_zz <= I_xx + I_yy)
RIGID_INERTIA_RATIO = 2.0
#: A ratio read from the whirls within this relative distance above RIGID_INERTIA_RATIO is a disc's, read to the
#: whirl fit's resolution (the new-user trial's 2.0 disc read 2.001, printed "2 (above 2 ...)")
RIGID_RATIO_RESOLUTION = 0.01
#: I_zz/I_rr below this is a rotor longer than it is wide (a thin rod's is 0): no reaction wheel's (a disc's 2, a
#: ring with its hub and shaft 1.2-2), and the likeliest cause is the speed column read k times the rotor's speed
WHEEL_INERTIA_RATIO_MIN = 1.0


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class SuspensionModes(Element):
    """The wheel's own suspension modes as diagnose fitted them from the data (per unit mass and transverse
    inertia): frequencies at rest (Hz), damping ratios, I_zz/I_rr, and the modes the data do not locate.
    The fitted parameters themselves are the model's ``analytical`` section."""

    KIND: ClassVar[str] = "suspension_modes"
    ORDER: ClassVar[int] = 100
    radial_translation_Hz: float = field(metadata=check(FREQUENCY))
    rocking_Hz: float = field(metadata=check(FREQUENCY))
    axial_Hz: float = field(metadata=check(FREQUENCY))
    zeta_radial_translation: float = field(metadata=check(ZETA))
    zeta_rocking: float = field(metadata=check(ZETA))
    zeta_axial: float = field(metadata=check(ZETA))
    inertia_ratio: float = field(metadata=check(number(gt=0, le=MAX_INERTIA_RATIO)))
    unconstrained: tuple = field(default=(), metadata=check(optional(names(UNCONSTRAINED_MODES + UNCONSTRAINED_DAMPING),
                                                                      ())))
    #: per mode whose damping is listed in ``unconstrained`` (zeta_<mode>), [lo, hi] the damping ratios the data allow
    #: (its zeta_<mode> is a value held inside them, not a fit)
    zeta_bounds: Mapping | None = field(default=None, metadata=check(optional(_zeta_bounds(), None)))
    #: per located mode whose damping the fit profiled, [lo, hi] the damping ratios the data allow (1.5 standard
    #: errors, the other parameters held: the narrowest they could give)
    zeta_interval: Mapping | None = field(default=None, metadata=check(optional(_zeta_bounds(), None)))
    per_unit: bool = field(default=True, metadata=check(optional(boolean(), True)))
    n_runs: int | None = field(default=None, metadata=check(COUNT))

    @classmethod
    def describe(cls, e: Mapping) -> str:
        free = [m for m in e.get("unconstrained") or () if m in UNCONSTRAINED_MODES]
        bounds = e.get("zeta_bounds") or {}
        note = ""
        a = e.get("inertia_ratio")
        if isinstance(a, (int, float)) and a > RIGID_INERTIA_RATIO * (1.0 + RIGID_RATIO_RESOLUTION):
            note = (f" (above {RIGID_INERTIA_RATIO:g}, which no rigid rotor rocking about its centre of mass exceeds: "
                    "an effective ratio of the whirls, from a flexible rotor or rocking coupled with other motion)")
        elif isinstance(a, (int, float)) and a < WHEEL_INERTIA_RATIO_MIN:
            note = (f" (below {WHEEL_INERTIA_RATIO_MIN:g}: a rotor longer than it is wide, not a wheel's disc; the "
                    "whirls' split grows as I_zz/I_rr times the speed, so speeds k times the rotor's read the ratio "
                    "k times low: check the tach's pulses per turn and the column's unit, or, with the speed from "
                    "the data, which line was taken as 1x)")

        def mode(name: str, label: str) -> str:
            # a mode the data do not locate has no frequency to print: the fit's end point is no finding
            if name in free:
                return f"{label} not located (the fit ended at {num(e[name + '_Hz'], '.4g')} Hz)"
            if name in bounds:
                # located, its damping held: the range the data allow, not the held value, is the finding
                lo, hi = bounds[name]
                return (f"{label} {num(e[name + '_Hz'], '.4g')} Hz (ζ not constrained by the data: held, "
                        f"{num(lo, '.2g')}-{num(hi, '.2g')} allowed)")
            return f"{label} {num(e[name + '_Hz'], '.4g')} Hz (ζ {num(e['zeta_' + name], '.2g')})"

        # I_zz/I_rr is read from the split of the rocking mode's whirls: no rocking, no ratio
        ratio = ("I_zz/I_rr not located (read from the rocking's whirls)" if "rocking" in free
                 else f"I_zz/I_rr {num(e['inertia_ratio'], '.3g')}{note}")
        return (f"{mode('radial_translation', 'radial translation')}, {mode('rocking', 'rocking at rest')}, "
                f"{mode('axial', 'axial')}, {ratio}")
