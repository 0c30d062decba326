"""Every fixture resonance fitted at once with the wheel's modes (the extended fit's least squares).

:func:`rwadist.stand_resonance.beside_more_stands` finds further fixture resonances one at a time, each fitted with
the modes while the others are held (:func:`rwadist.stand_resonance._with_new_stand`, twice round).  Two fixtures on
either side of the radial translation pull on its lines from both sides; held in turn, each settles where the other's
error and the mode's meet, and the mode with them (family wheel 1, 0.81x and 1.25x its 520 Hz translation, ζ 0.03, peak
gain 5 each: the stands 420.9 Hz (ζ 0.031, 1.024 of the load above it) and 651.3 Hz (ζ 0.026, gain 4.78), the
translation 520.8 Hz, ζ 0.0190 against 0.0184: the error after 15.7x the clean cell's; the modes fitted beside the
true stands held: 520.01 Hz, ζ 0.01844, 0.8x).  :func:`rwadist.stand_resonance.fit_every_stand` fits them all free in one least squares
(:class:`FittedStands`), the modes located again beside each pass's stands until they settle.
"""
from __future__ import annotations

import numpy as np

from .resonance import PATH_MODE_MAX_ABOVE, FittedResonance


class FittedStands:
    """Several fixture resonances' parameters in one least squares of log line amplitudes, each a
    :class:`rwadist.resonance.FittedResonance` on every row: θ their θ's one after the other, ln|H|² the sum of
    theirs.  The same interface as one (``NAMES``, ``x0``, ``lower``, ``upper``, ``start_log_gain``,
    :meth:`log_gain`, :meth:`stand`), with :meth:`more` the others.

    Parameters
    ----------
    starts : sequence of (f_r Hz, ζ, peak gain[, gain above]), the first the fit's ``stand``.
    f_rows : each least-squares row's line frequency, Hz.
    """

    def __init__(self, starts, f_rows):
        self.parts = [FittedResonance(s, f_rows) for s in starts]
        self.NAMES = tuple(n if i == 0 else n.replace("stand_", f"stand{i + 1}_")
                           for i, p in enumerate(self.parts) for n in p.NAMES)
        self.x0 = np.concatenate([p.x0 for p in self.parts])
        self.lower = np.concatenate([p.lower for p in self.parts])
        self.upper = np.concatenate([p.upper for p in self.parts])
        self.start_log_gain = np.sum([p.start_log_gain for p in self.parts], axis=0)

    def _split(self, theta) -> list:
        edges = np.cumsum([0] + [len(p.NAMES) for p in self.parts])
        return [np.asarray(theta, dtype=float)[a:b] for a, b in zip(edges[:-1], edges[1:])]

    def log_gain(self, theta):
        """(Σ ln|H_k|² at every row (rows,), its derivatives (rows, len(θ)) in θ)."""
        got = [p.log_gain(t) for p, t in zip(self.parts, self._split(theta))]
        return np.sum([g[0] for g in got], axis=0), np.concatenate([g[1] for g in got], axis=1)

    def stand(self, theta) -> tuple:
        """(f_r Hz, ζ, peak gain, gain above) of the first resonance."""
        return self.parts[0].stand(self._split(theta)[0])

    def more(self, theta, held=()) -> tuple:
        """The others' (f_r Hz, ζ, peak gain, gain above), in order (``held``: what they were held at, unused)."""
        return tuple(p.stand(t) for p, t in zip(self.parts[1:], self._split(theta)[1:]))


def log_data(meas_lines: list, la: np.ndarray, sa: np.ndarray, aa: np.ndarray, lr: np.ndarray, sr: np.ndarray,
             pr: np.ndarray, joint_stand: tuple | None, stand_direction: str | None = None,
             more_stands: tuple = ()) -> tuple:
    """(log amplitude per least-squares row, the stands fitted with the modes or None): the axial rows (line ``la``,
    speed ``sa`` rad/s, amplitude ``aa`` per channel), then the radial ones (``lr``, ``sr``, x²+y² power ``pr`` per
    run); with ``joint_stand`` (its start, divided out of the lines) multiplied back: the least squares divides out
    its own (a :class:`rwadist.resonance.FittedResonance`).  ``stand_direction``: the stand is a mode of the wheel's
    structure acting on that direction's rows only, keeping β <= 1 of the load above it (``rows``, ``max_above``).
    ``more_stands``: further fixture resonances on every row (divided out of the lines too) fitted with it, every one
    multiplied back (a :class:`FittedStands`); not beside a ``stand_direction`` (a structure mode is fitted alone:
    ValueError, rather than the further stands left held unsaid)."""
    if more_stands and stand_direction is not None:
        raise ValueError(f"further stands fitted beside a structure mode on {stand_direction}: fit one or the other")
    out = np.concatenate([np.log(np.maximum(aa, 1e-300)), 0.5 * np.log(np.maximum(pr, 1e-300))])
    if joint_stand is None:
        return out, None
    h_meas = np.array([x.h for x in meas_lines]) if meas_lines else np.zeros(0)
    f_rows = np.concatenate([h_meas[la] * np.abs(sa), h_meas[lr] * np.abs(sr)]) / (2 * np.pi)
    joint: FittedResonance | FittedStands
    if more_stands:
        joint = FittedStands((joint_stand,) + tuple(more_stands), f_rows)
    elif stand_direction is None:
        joint = FittedResonance(joint_stand, f_rows)
    else:
        d_rows = np.concatenate([np.full(la.size, "axial_force"), [meas_lines[j].direction for j in lr]])
        joint = FittedResonance(joint_stand, f_rows, rows=d_rows == stand_direction, max_above=PATH_MODE_MAX_ABOVE)
    return out + 0.5 * joint.start_log_gain, joint

