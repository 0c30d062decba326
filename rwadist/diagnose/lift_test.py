"""Whether a line follows the lift the wheel's translation mode gives its radial-force lines: the test that tells a
load of the wheel (lifted where it crosses the mode) from a source added at the load cell (not lifted), shared by the
lines on one channel (:mod:`.one_channel_lines`) and those over one band of speeds (:mod:`.range_lines`), with the
record's parameters and words that say it (docs/diagnose.md, "Unexplained residual").
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..units import RAD_S_TO_RPM

#: the translation gain's range over the line's runs (max/min of |T|), at least: a lift to tell
MIN_LIFT_RANGE = 3.0
#: runs where the translation mode lifts the line by this factor or more, at least MIN_LIFTED_RUNS of them
LIFT_MIN = 2.0
MIN_LIFTED_RUNS = 2
#: the share of the translation mode's lift the line follows (slope of its log level on the log gain), at most
MAX_LIFT_FOLLOWED = 0.25


def lift_followed(a: np.ndarray, w: np.ndarray, h: float, mode: tuple) -> tuple | None:
    """(slope, its standard error, the gain |T| per run) of a line's log level ``log(a/Ω²)`` (``a``: its amplitude at
    the speeds ``w`` rad/s) on the log gain the translation mode ``mode`` (f0 Hz, ζ) gives h·Ω at Ω: 1 for a load of
    the wheel, 0 for one added at the load cell; None when that gain does not lift the line at its runs enough to
    tell (:data:`MIN_LIFT_RANGE`, :data:`LIFT_MIN` in :data:`MIN_LIFTED_RUNS` runs)."""
    from ..mode_scan import transmissibility_sq

    f0, zeta = mode
    gain = np.sqrt(transmissibility_sq(h * w, w, [f0], [zeta], [0.0])[0])
    if gain.max() / gain.min() < MIN_LIFT_RANGE or int(np.sum(gain >= LIFT_MIN)) < MIN_LIFTED_RUNS:
        return None                         # no lift of the wheel's lines at its runs to tell it by
    y = np.log(a / w**2)
    x = np.log(gain)
    X = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    cov = float(resid @ resid) / max(w.size - 2, 1) * np.linalg.inv(X.T @ X)
    return float(coef[1]), float(math.sqrt(max(cov[1, 1], 0.0))), gain


@dataclass(frozen=True)
class LiftTest:
    """The lift test of one line: the translation mode the wheel's other radial-force lines locate (f0 Hz, ζ), the
    largest lift it gives at the line's runs (dB, amplitude), the share of that lift the line follows (the slope of
    :func:`lift_followed` ± its standard error) and the speed (rpm) at which the line crosses the mode."""

    mode_Hz: float
    mode_zeta: float
    largest_lift_dB: float
    followed: float
    followed_stderr: float
    crossing_rpm: float

    @classmethod
    def of(cls, mode: tuple, got: tuple, h: float) -> "LiftTest":
        """The test of a line at ratio ``h`` from :func:`lift_followed`'s result ``got`` with the mode (f0 Hz, ζ)."""
        slope, se, gain = got
        f0, zeta = mode
        return cls(mode_Hz=float(f0), mode_zeta=float(zeta), largest_lift_dB=float(20 * np.log10(np.max(gain))),
                   followed=slope, followed_stderr=se, crossing_rpm=float(2 * np.pi * f0 / h * RAD_S_TO_RPM))

    def parameters(self) -> dict:
        """The record's parameters (summary.json's ``unexplained``) that hold the test."""
        return {"translation_Hz": self.mode_Hz, "translation_zeta": self.mode_zeta,
                "crossing_rpm": self.crossing_rpm, "largest_lift_dB": self.largest_lift_dB,
                "lift_followed": self.followed, "lift_followed_stderr": self.followed_stderr}


def lift_words(p: Mapping) -> str:
    """The test read from a record's parameters ``p`` (:meth:`LiftTest.parameters`) in words; a number the record
    lacks (null in JSON) reads "n/a"."""
    def num(key: str, spec: str) -> str:
        x = p.get(key)
        x = None if x is None else float(x)
        return "n/a" if x is None or not math.isfinite(x) else format(x + 0.0, spec)

    followed = p.get("lift_followed")
    share = "n/a" if followed is None or not math.isfinite(float(followed)) else f"{round(float(followed), 2) + 0.0:.2f}"
    return (f"not lifted by the wheel's translation mode ({num('translation_Hz', '.4g')} Hz, crossed at "
            f"{num('crossing_rpm', '.0f')} rpm): it follows {share} of the {num('largest_lift_dB', '.0f')} dB lift the "
            "wheel's other radial-force lines locate there")
