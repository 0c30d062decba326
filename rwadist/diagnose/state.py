"""The diagnosis state: what the model predicts at one step of the search."""
from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..model import WheelModel
from ..resonance import resonance
from ..units import CHANNEL_DIRECTION

if TYPE_CHECKING:
    from ..extended import ExtendedParams


@dataclass
class Prediction:
    """What the effects of a state add to its prediction, in the engine's terms (no effect kind): each effect object
    of the state puts its part here (its ``contribute``), in the order the effects were added.

    laws : (direction, h rounded to 4 places) -> (A_ref, Ω_ref rad/s, p): the line's amplitude A_ref·(|Ω|/Ω_ref)^p
        instead of C·Ω².  floors : channel -> (psd_ref(f) unit²/Hz on the grid, Ω_ref rad/s, p): a broadband floor
        psd_ref·(|Ω|/Ω_ref)^p added to the channel.  resonances : (f_r Hz, ζ, g, channels[, gain above]):
        fixed-frequency resonances multiplying the lines of their channels (:func:`rwadist.resonance.resonance`).  load_cell_offset : r (m, 3-vector) or None: the torque
        data are read corrected, T − r × F (:meth:`Context.data`).  modulations : (direction, h, f_mod Hz, depth m):
        the line h of that direction carries two more lines at h|Ω|/2π ± f_mod of amplitude m·a/2.
        speed_modulation : (ΔΩ_ref rad/s, f_r Hz, Ω_ref rad/s, q) or None: a periodic speed ripple
        Ω0 + ΔΩ sin 2πf_r t, ΔΩ = ΔΩ_ref·(|Ω0|/Ω_ref)^q; every line is spread over f_i + k·f_r with the powers of
        :func:`~rwadist.diagnose.ripple.ripple_sideband_powers`.  smear : |dΩ/dt| (rad/s²) or None: every line of a
        run is spread uniformly over the frequencies its harmonic sweeps during the run
        (:meth:`Context.smear_offsets`)."""

    laws: dict = field(default_factory=dict)
    floors: dict = field(default_factory=dict)
    resonances: list = field(default_factory=list)
    load_cell_offset: tuple | None = None
    modulations: list = field(default_factory=list)
    speed_modulation: tuple | None = None
    smear: float | None = None
    #: (direction, h rounded to 4 places) -> e: the line's x/y power split on the empirical base, x C·sqrt(1 + e) and y
    #: C·sqrt(1 − e) (a co + counter pair whose ellipse keeps one orientation in the stator, :mod:`rwadist.effects.
    #: counter_rotation_diagnose`)
    xy_splits: dict = field(default_factory=dict)


@dataclass
class State:
    """What the model predicts: its harmonics, the instrument noise and the effects added so far.

    model : WheelModel (harmonics in ``empirical``).  noise : channel -> N_c(f), unit²/Hz.  effects : the effect
    objects added so far (the families' hypotheses, :mod:`rwadist.diagnose.effects`), in order; their part of the
    prediction is :attr:`prediction` (read through :attr:`laws`, :attr:`floors`, ...).  ext : the extended
    parameters when the lines go through the rotor's suspension modes, else None.

    A state is made once and not changed after (an effect's ``apply`` returns a new one: :meth:`plus`); its
    predictions are kept on it."""

    model: WheelModel
    noise: dict
    effects: list = field(default_factory=list)
    ext: ExtendedParams | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def copy(self) -> "State":
        """A new state with this one's model copied (its harmonics' lists new, the :class:`~rwadist.model.Harmonic`
        objects shared: no code changes one in place, an effect's ``apply`` puts new ones in a new list; the rest
        of the model deep-copied) and its effects' list new (a deep copy of every harmonic was 3 % of a diagnose)."""
        m = self.model
        model = WheelModel(name=m.name, wheel=copy.deepcopy(m.wheel),
                           empirical={d: list(v) for d, v in m.empirical.items()},
                           analytical=copy.deepcopy(m.analytical), effects=copy.deepcopy(m.effects),
                           provenance=copy.deepcopy(m.provenance))
        return State(model, self.noise, list(self.effects), self.ext)

    def plus(self, effect) -> "State":
        """A new state with ``effect`` added after the others (this state is not changed)."""
        s = self.copy()
        s.effects.append(effect)
        return s

    @property
    def prediction(self) -> Prediction:
        """The effects' parts of the prediction (:class:`Prediction`), made once per list of effects."""
        key = tuple(map(id, self.effects))
        kept = self._cache.get("prediction")
        if kept is None or kept[0] != key:
            parts = Prediction()
            for e in self.effects:
                contribute = getattr(e, "contribute", None)
                if contribute is not None:
                    contribute(parts)
            kept = self._cache["prediction"] = (key, parts)
        return kept[1]

    @property
    def laws(self) -> dict:
        return self.prediction.laws

    @property
    def floors(self) -> dict:
        return self.prediction.floors

    @property
    def resonances(self) -> list:
        return self.prediction.resonances

    def channel_gain(self, channel: str, f_hz) -> np.ndarray:
        """Complex H of the state's fixed resonances acting on ``channel`` at the line frequencies ``f_hz`` (Hz, any
        shape; :func:`rwadist.resonance.resonance` of each, multiplied): what the channel's phasor is divided by to
        read the load before the mount; 1 where none acts on it."""
        gain = np.ones(np.shape(f_hz), dtype=complex)
        for f_r, zeta, peak, chans, *above in self.resonances:
            if channel in chans:
                gain = gain * resonance(f_hz, f_r, zeta, peak, *above)
        return gain

    @property
    def load_cell_offset(self) -> tuple | None:
        return self.prediction.load_cell_offset

    @property
    def modulations(self) -> list:
        return self.prediction.modulations

    @property
    def speed_modulation(self) -> tuple | None:
        return self.prediction.speed_modulation

    @property
    def smear(self) -> float | None:
        return self.prediction.smear

    @property
    def base(self) -> str:
        """'extended' when the lines go through the rotor's suspension modes (``ext`` set), else 'empirical'."""
        return "empirical" if self.ext is None else "extended"

    def ext_lines(self) -> list:
        """The :class:`rwadist.extended.Line` objects of the extended base: :func:`rwadist.extended.lines_from_model`
        of the model (imbalances from ``ext``, senses from the harmonics) with the state's amplitude laws attached
        (same direction, |Δh| < LAW_H_TOL)."""

        # kept on the state, under what they are made from (a state is not changed once searched, but one being made
        # is: the harmonics, senses, laws and extended parameters are read again, which costs little)
        made_of = (self.ext, tuple(sorted(self.laws.items())),
                   tuple((d, x.h, x.C, x.sense) for d, v in self.model.empirical.items() for x in v))
        kept = self._cache.get("ext_lines")
        if kept is not None and kept[0] == made_of:
            return list(kept[1])
        out = self._make_ext_lines()
        self._cache["ext_lines"] = (made_of, tuple(out))
        return out

    def _make_ext_lines(self) -> list:
        """:meth:`ext_lines` computed."""
        from .. import extended as ext

        if self.ext is None:
            raise ValueError("extended lines asked of a state on the empirical base (ext is None)")
        out = ext.lines_from_model(self.model, self.ext, effects=False)
        if self.laws:
            laws = [(d, h, law) for (d, h), law in self.laws.items()]
            out = [replace(ln, law=next((lw for d, h, lw in laws
                                         if d == ln.direction and abs(h - ln.h) < ext.LAW_H_TOL), None))
                   for ln in out]
        return out

    def line_components(self, channel: str, h: float):
        """(frequency shift Hz, relative amplitude) of the line h of ``channel``: the carrier (0, 1) and the
        pairs (±f_mod, m/2) of its amplitude modulations (:attr:`modulations`)."""
        d = CHANNEL_DIRECTION[channel]
        out = [(0.0, 1.0)]
        for dd, hh, f_m, m in self.modulations:
            if dd == d and abs(hh - h) < 1e-4:
                out += [(f_m, 0.5 * m), (-f_m, 0.5 * m)]
        return out

    def _parts(self, direction: str) -> list:
        """[(h, [C of each harmonic of that h])] of ``direction``'s harmonics, those of one h (a co and a counter
        part of a radial line, :mod:`rwadist.effects.counter_rotation_diagnose`) together."""
        out: list = []
        for hm in self.model.harmonics(direction):
            if out and out[-1][0] == hm.h:
                out[-1][1].append(hm.C)
            else:
                out.append((hm.h, [hm.C]))
        return out

    def lines(self, channel: str):
        """(h, C, amplitude law or None) of every line acting on ``channel``: harmonics of one h merged into one line
        of their root-sum-square C (independent phases: the expected power; the pair's cross term cancels between x
        and y), scaled by its x/y split on a radial pair's channels (:attr:`Prediction.xy_splits`)."""
        d = CHANNEL_DIRECTION[channel]
        out = [(h, Cs[0] if len(Cs) == 1 else float(sum(C ** 2 for C in Cs) ** 0.5), self.laws.get((d, round(h, 4))))
               for h, Cs in self._parts(d)]
        splits = self.prediction.xy_splits
        if splits and channel in ("Fx", "Fy", "Tx", "Ty"):
            sign = 1.0 if channel in ("Fx", "Tx") else -1.0
            out = [(h, C * (1.0 + sign * splits.get((d, round(h, 4)), 0.0)) ** 0.5, law) for h, C, law in out]
        return out

    def mixing_shares(self, channel: str) -> list:
        """Per line of :meth:`lines`: the share of its power squared the cross terms of its parts carry in variance,
        Σ_{i<j} 2·P_i·P_j / (Σ P)² (a co and a counter part of independent phases: their cross term is constant over a
        run and of zero mean over the runs); 0 for a line of one part, or one whose x/y split is known (the parts' phase
        held by the stator: the cross term is predicted, :attr:`Prediction.xy_splits`)."""
        d = CHANNEL_DIRECTION[channel]
        splits = self.prediction.xy_splits
        out = []
        for h, Cs in self._parts(d):
            p = [C ** 2 for C in Cs]
            total = sum(p)
            out.append(0.0 if len(p) < 2 or total <= 0 or (d, round(h, 4)) in splits
                       else (total ** 2 - sum(x * x for x in p)) / total ** 2)
        return out
