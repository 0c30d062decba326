"""``broadband_floor``: a broadband (noise-like) load floor of some channels, growing with speed."""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ..schema import (
    CHANNELS,
    EXPONENT,
    MAX_FREQ_HZ,
    MAX_KNOTS,
    MAX_PSD,
    SPEED,
    check,
    choice,
    names,
    numbers,
    optional,
    register,
)
from ..units import CHANNEL_UNIT
from .actions import NoiseFloor
from .element import Element, FmuSwitch, num, rpm

#: the share of a floor's power whose band its words give (the central part: a twentieth cut off either side)
POWER_SHARE = 0.9


@register
@dataclass(frozen=True, eq=False, kw_only=True)
class BroadbandFloor(Element):
    """A blocked-load PSD S(f, Ω) = psd_ref(f)·(|Ω|/omega_ref_rad_s)^exponent on each of its channels,
    psd_ref linear between the knots f_Hz (Hz, >= 0, increasing), 0 outside; unit²/Hz."""

    KIND: ClassVar[str] = "broadband_floor"
    FMU_SWITCH: ClassVar[FmuSwitch] = FmuSwitch(1, "broadband_floor", "diagnosed broadband floors (model file "
                                                "effects) added to the outputs as random-phase multisines")
    ORDER: ClassVar[int] = 30
    channel: tuple = field(metadata=check(names(CHANNELS)))
    exponent: float = field(metadata=check(EXPONENT))
    omega_ref_rad_s: float = field(metadata=check(SPEED))
    f_Hz: np.ndarray = field(metadata=check(numbers(min_len=2, ge=0.0, increasing=True, le=MAX_FREQ_HZ,
                                                    max_len=MAX_KNOTS)))
    psd_ref: np.ndarray = field(metadata=check(numbers(ge=0.0, le=MAX_PSD, max_len=MAX_KNOTS)))
    #: "at_least" (or "at_most") where the fitted exponent is the largest (smallest) of the grid ``rwadist diagnose``
    #: chooses it from: the likeliest law may lie beyond it, so the data bound the exponent from that side only; absent
    #: (None) for an exponent inside the grid.  The floor uses ``exponent`` as it is either way.
    exponent_bound: str | None = field(default=None, metadata=check(optional(choice(("at_least", "at_most")))))

    def _validate(self, source, path, error):
        if self.psd_ref.size != self.f_Hz.size:
            raise error(source, f"{path}.psd_ref", f"has {self.psd_ref.size} values for {self.f_Hz.size} "
                        "f_Hz knots (one per knot)")

    @property
    def channel_indices(self) -> tuple:
        return tuple(CHANNELS.index(c) for c in self.channel)

    def actions(self) -> tuple:
        """One floor per channel it names (a channel named twice has one)."""
        return tuple(NoiseFloor(c, np.array(self.f_Hz), np.array(self.psd_ref), float(self.omega_ref_rad_s),
                                float(self.exponent)) for c in self.channel_indices)

    @classmethod
    def describe(cls, e: Mapping) -> str:
        f = np.asarray(e["f_Hz"], dtype=float)
        psd = np.asarray(e["psd_ref"], dtype=float)
        chans = " ".join(e["channel"]) if isinstance(e["channel"], (list, tuple)) else str(e["channel"])
        p = num(e["exponent"], ".3g")
        bounds = {"at_least": f" (p >= {p}: the fit's largest exponent, a lower bound)",
                  "at_most": f" (p <= {p}: the fit's smallest exponent, an upper bound)"}
        bound = bounds.get(str(e.get("exponent_bound")), "")
        lo, hi = cls._power_band(f, psd)
        return (f"{chans}, PSD ∝ |Ω|^{p}{bound}, {100 * POWER_SHARE:.0f} % of its power at {lo:.0f}–{hi:.0f} Hz, "
                f"peak {psd.max():.3g} {cls._psd_unit(e)} at {f[int(np.argmax(psd))]:.0f} Hz and "
                f"{rpm(e['omega_ref_rad_s'])}")

    @staticmethod
    def _power_band(f: np.ndarray, psd: np.ndarray) -> tuple:
        """(lowest, highest) frequency (Hz) of the band holding the central :data:`POWER_SHARE` of the power of the
        floor ``psd`` (unit²/Hz, linear between the knots ``f``); the knots' range when it holds none.  The knots
        span the whole band the floor was fitted on: a hump's floor said "8–1990 Hz" for its power at 365–477 Hz
        (the session-68 trial)."""
        seg = 0.5 * (psd[1:] + psd[:-1]) * np.diff(f)
        total = float(seg.sum())
        if not total > 0:
            return float(f.min()), float(f.max())
        cum = np.concatenate([[0.0], np.cumsum(seg)])
        tail = 0.5 * (1.0 - POWER_SHARE) * total

        def at(power: float) -> float:
            # the cumulative power is quadratic in each segment, P(f0 + t) = P0 + p0·t + (p1 − p0)/(2Δ)·t²: its root
            # in the segment that holds ``power``, in the form that keeps its precision when the slope vanishes
            k = int(np.clip(np.searchsorted(cum, power, side="right") - 1, 0, f.size - 2))
            d = f[k + 1] - f[k]
            a, b, r = (psd[k + 1] - psd[k]) / (2.0 * d), psd[k], power - cum[k]
            root = math.sqrt(max(b * b + 4.0 * a * r, 0.0))
            t = 2.0 * r / (b + root) if b + root > 0 else d
            return float(f[k] + min(max(t, 0.0), d))

        return at(tail), at(total - tail)

    @staticmethod
    def _psd_unit(e) -> str:
        """The floor's PSD unit: its channel's unit squared per Hz (N²/Hz or (N·m)²/Hz)."""
        chans = e["channel"] if isinstance(e["channel"], (list, tuple)) else [e["channel"]]
        unit = CHANNEL_UNIT.get(chans[0]) if chans else None
        return {"N": "N²/Hz", "Nm": "(N·m)²/Hz"}.get(unit or "", f"({unit})²/Hz" if unit else "unit²/Hz")

    # ------------------------------------------------------------------ injection
    #: ``broadband_floor:channels=Fx+Fy+Fz,level=0.05,exponent=3,fc_hz=60``: Gaussian noise low-passed at fc
    #: (2nd-order Butterworth), RMS level·C1·Ω_max²·(Ω/Ω_max)^(exponent/2) (its PSD grows as Ω^exponent); a floor
    #: at the load cell on the channels given (not a load direction), with either physics
    INJECT: ClassVar[Mapping] = {"channels": "Fx+Fy+Fz", "level": 0.05, "exponent": 3.0, "fc_hz": 60.0}
    INJECT_TEXT: ClassVar[tuple] = ("channels",)
    INJECT_POSITIVE: ClassVar[tuple] = ("fc_hz",)

    @classmethod
    def inject_run(cls, spec, run, index, stand):
        w, w_max = abs(run.speed), stand.w_max
        for c in spec["channels"]:
            c1 = stand.wheel.fundamental_C("radial_force" if c.startswith("F") else "radial_torque")
            x = stand.lowpass_noise(spec["fc_hz"], run)
            x /= np.sqrt(np.mean(x**2))
            run.signals[c] = run.signals[c] + spec["level"] * c1 * w_max**2 * (w / w_max) ** (spec["exponent"] / 2) * x
