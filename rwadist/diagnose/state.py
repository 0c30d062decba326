"""The diagnosis state: what the model predicts at one step of the search."""
from __future__ import annotations

import copy
from dataclasses import dataclass, field, replace

from ..model import WheelModel
from ..units import CHANNEL_DIRECTION


@dataclass
class State:
    """What the model predicts: harmonics, their amplitude laws, noise and broadband floors.

    model : WheelModel (harmonics in ``empirical``).  laws : (direction, h) -> (amp_ref, omega_ref, p).
    noise : channel -> N_c(f), unit²/Hz.  floors : channel -> (psd_ref(f) unit²/Hz, omega_ref rad/s, p).
    resonances : (f_r Hz, ζ, g, channels) fixed-frequency resonances multiplying the lines of their channels.
    coupling : load-cell offset r (m, 3-vector) of a ``cross_coupling`` effect, or None: the torque data are
        then read corrected, T − r × F (:meth:`Context.data`).
    sidebands : (direction, h, f_mod Hz, depth m) of ``sidebands`` effects: the line h of that direction
        carries two more lines at h|Ω|/2π ± f_mod of amplitude m·a/2.
    ripple : (ΔΩ_ref rad/s, f_ripple Hz, Ω_ref rad/s, q) of a ``speed_ripple`` effect, or None: every line
        is spread over f_i + k·f_ripple with the powers of :func:`ripple_sideband_powers`.
    smear : |dΩ/dt| (rad/s²) of a ``spin_acceleration`` effect, or None: every line of a run is spread
        uniformly over the frequencies its harmonic sweeps during the run (:meth:`Context.smear_offsets`).
    effects : effect objects added so far.
    """

    model: WheelModel
    noise: dict
    laws: dict = field(default_factory=dict)
    floors: dict = field(default_factory=dict)
    effects: list = field(default_factory=list)
    resonances: list = field(default_factory=list)
    coupling: tuple | None = None
    sidebands: list = field(default_factory=list)
    ripple: tuple | None = None
    ext: object = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)
    smear: float | None = None

    def copy(self) -> "State":
        return State(copy.deepcopy(self.model), self.noise, dict(self.laws), dict(self.floors), list(self.effects),
                     list(self.resonances), self.coupling, list(self.sidebands), self.ripple, self.ext,
                     smear=self.smear)

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

        out = ext.lines_from_model(self.model, self.ext, effects=False)
        if self.laws:
            laws = [(d, h, law) for (d, h), law in self.laws.items()]
            out = [replace(ln, law=next((lw for d, h, lw in laws
                                         if d == ln.direction and abs(h - ln.h) < ext.LAW_H_TOL), None))
                   for ln in out]
        return out

    def line_components(self, channel: str, h: float):
        """(frequency shift Hz, relative amplitude) of the line h of ``channel``: the carrier (0, 1) and the
        pairs (±f_mod, m/2) of its ``sidebands`` effects."""
        d = CHANNEL_DIRECTION[channel]
        out = [(0.0, 1.0)]
        for dd, hh, f_m, m in self.sidebands:
            if dd == d and abs(hh - h) < 1e-4:
                out += [(f_m, 0.5 * m), (-f_m, 0.5 * m)]
        return out

    def lines(self, channel: str):
        """(h, amplitude function of omega) for every harmonic acting on ``channel``."""
        d = CHANNEL_DIRECTION[channel]
        out = []
        for hm in self.model.harmonics(d):
            law = self.laws.get((d, round(hm.h, 4)))
            out.append((hm.h, hm.C, law))
        return out
