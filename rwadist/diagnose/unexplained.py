"""What the residual holds that no effect class explains (issue 33, item 3): the typed record of one description.

After the search, structured residual that stands above the noise and that no class explains is described, never
dropped and never forced into a class: by its signature (:data:`SIGNATURES`), where it is (channels, speed range,
frequency), its strength and its share of what is left, what it could physically be and which data would tell.
:class:`Unexplained` is one such description; summary.json's ``unexplained`` list holds their JSON form
(:meth:`Unexplained.to_json`, documented in docs/diagnose.md, "Unexplained residual"), which
:meth:`Unexplained.from_json` reads back.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from .lift_test import lift_words

#: A moving resonance's fitted shape whose peak (its ``peak_gain``, dB) stands this far under the largest lift its lines
#: show is said not to hold that lift
SHAPE_SHORT_DB = 6.0


class FrozenMapping(dict):
    """A dict that refuses changes (a record's ``parameters``): read like a dict, pickled and copied as one."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("an Unexplained record's parameters are read-only")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse

    def __reduce__(self):
        return (FrozenMapping, (dict(self),))


def _parameters_key(parameters: Mapping) -> tuple:
    """The hashable form of a record's ``parameters``: its (key, repr(value)) pairs, sorted (a dict subclass cannot
    override dict's ``__hash__ = None`` in the type system, so the record hashes this instead of the mapping)."""
    return tuple(sorted((k, repr(v)) for k, v in parameters.items()))


#: Signature -> what it is, in words (the JSON form's ``description``).
SIGNATURES = {
    "fixed_line": "a line at one fixed frequency in every run, or in the runs above (below) some speed",
    "speed_line": "a line at a constant ratio of the speed that no model line has",
    "line_property": "what the data's lines have in common that the model's lines do not",
    "channel_copy": "a channel that carries a copy of another channel's content",
    "moving_resonance": "a resonance whose frequency changes with speed in a way the fitted modes' gyroscopic whirl does not explain",
    "broadband_hump": "a broadband hump above the noise floor",
    "run_change": "a run-to-run change",
    "partial_line": "a model line present in some runs and absent from others, or whose strength scatters from run to "
                    "run",
    "sideband_line": "lines at a fixed line's frequency plus or minus a constant ratio of the speed",
    "affine_line": "a line whose frequency moves with the speed as f0 + b × the speed, neither fixed nor at a "
                   "constant ratio of it",
}

#: How ``level_dB`` reads for the signatures whose level is not the data over the model in their cells.
#: a level in words where :data:`LEVEL_WORDS` has none: the data's median over the model in its cells (a line the model
#: lacks reads a small level where it stands little over the noise in them: trial 21's "+1.5 dB over the model")
DEFAULT_LEVEL_WORDS = "the data {:+.1f} dB over the model in its bins (median)"
LEVEL_WORDS = {
    "broadband_hump": "{:+.1f} dB over the floor's smooth course",
    "broadband_hump:lower course": "{:+.1f} dB over the floor's lower course (the higher of its lowest on either side)",
    "broadband_hump:some runs": "{:+.1f} dB over the floor of the runs (their median) in those runs",
    "run_change": "the changed runs {} dB off the others",
    "run_change:spread": "every run off the model by its own factor, {:.2f} dB scatter ({:+.2f} to {:+.2f} dB over {} "
                         "runs)",
    "partial_line": "{:+.1f} dB against the model in the runs it is absent from",
    "line_property": "{:+.2f} dB (power) in the second channel's lines against the first's",
    "line_property:channel_gain:step": "{:+.2f} dB (power) step between runs in the second channel's lines against "
                                       "the first's",
    "line_property:channel_gain:trend": "{:+.2f} dB (power) change with speed in the second channel's lines against "
                                        "the first's",
    "line_property:gain_trend": "{:+.2f} dB (power) on every line from the lowest speed to the highest",
    "line_property:frequency_response": "{:+.1f} dB (power) on the lines at the edge of the band read",
    "line_property:amplitude_law": "{:+.1f} dB (power) against C·Ω² from the lowest speed to the highest",
    "line_property:blended_lines": "{:+.1f} dB (power) in the line's Welch window over the line itself on the "
                                      "whole record (median)",
    "line_property:fixed_direction": "{:+.1f} dB (power) in the second channel's line against the first's, the "
                                     "farthest of the lines' own ratios",
    "line_property:split_mode": "{:+.2f} dB (power) in Fy's lines against Fx's where they differ most",
    "line_property:channel_resonance": "{:+.2f} dB (power) in the channel's lines against its partner's at the "
                                       "resonance",
    "line_property:line_step": "{:+.2f} dB (power) step of the line between two runs, the other lines on their course",
    "line_property:line_drift": "{:+.2f} dB (power) drift of the line over the test in the order its runs were "
                                "recorded, the other lines on their course",
    "line_property:ratio_drift": "the data {:+.1f} dB over the model in its bins (median)",
    "line_property:channel_skew": "{:+.1f} dB: the other rotation sense's share of a line's power at the highest "
                                  "line read",
}


def _number(x) -> float | None:
    """A finite float, or None (JSON's null) for None, NaN and infinities."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def _plain(v):
    """JSON types of a parameter value: numbers as float/int (non-finite as None), sequences as lists."""
    if isinstance(v, bool) or v is None or isinstance(v, str):
        return v
    if isinstance(v, int):
        return v
    if isinstance(v, Mapping):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    try:
        return _number(v)
    except (TypeError, ValueError):
        return str(v)



def _percent(share: float) -> str:
    """A share 0..1 as a percentage a reader can tell from nothing: whole percent from 1 %, one decimal below it and
    "< 0.1 %" for a share that is there but smaller (trial24: a hump of 0.17 % was printed as "0 % of what is left")."""
    pct = 100.0 * share
    if pct >= 0.95:
        return f"{pct:.0f} %"
    if pct >= 0.095:
        return f"{pct:.1f} %"
    return "< 0.1 %" if pct > 0.0 else "0 %"


@dataclass(frozen=True)
class Unexplained:
    """One description of structured residual no effect class explains.

    signature : a key of :data:`SIGNATURES`.
    channels : the channels where it stands above the noise (names of :data:`rwadist.units.CHANNELS`).
    speed_rpm : (lowest, highest) wheel speed of the runs where it stands above the noise, rpm.
    f_Hz : (lowest, highest) frequency where it is, Hz (a fixed line: its frequency twice).
    level_dB : how far it stands out, dB: the median over its cells of 10·log10(data / model); for a
        ``broadband_hump`` (which the model takes as noise) its peak over the floor's smooth course (its lower
        course for a wide one, the runs' median floor for one in some runs), for a
        ``run_change`` the median offset of the changed runs from the lines' smooth trends with speed, for a
        ``line_property`` of a channel's gain the median power ratio of the pair's channels and of a ``gain_trend`` the
        lines' change of power from the lowest speed to the highest (:data:`LEVEL_WORDS`, keyed by signature, or by
        "signature:property").
    share : its share of what is left, 0..1: the misplaced power of its cells (the error metric's numerator
        over them) over the misplaced power of every cell after the search.
    n_runs : runs in which it stands above the noise.
    h : the ratio to the speed of a ``speed_line`` (and of a ``line_property`` of a line, and a ``sideband_line``'s
        offset from its carrier), else None.
    parameters : the signature's own numbers (docs/diagnose.md lists them per signature); read-only.
    causes : what it could physically be, where a known cause fits (each a short sentence); may be empty.
    would_tell : which data would tell the causes apart (or confirm the one named).
    """

    signature: str
    channels: tuple
    speed_rpm: tuple
    f_Hz: tuple
    level_dB: float
    share: float
    n_runs: int
    h: float | None = None
    parameters: Mapping = field(default_factory=dict)
    causes: tuple = ()
    would_tell: str = ""

    def __post_init__(self):
        if self.signature not in SIGNATURES:
            raise ValueError(f"unexplained: signature must be one of {sorted(SIGNATURES)}, got {self.signature!r}")
        object.__setattr__(self, "channels", tuple(str(c) for c in self.channels))
        object.__setattr__(self, "speed_rpm", (float(self.speed_rpm[0]), float(self.speed_rpm[1])))
        object.__setattr__(self, "f_Hz", (float(self.f_Hz[0]), float(self.f_Hz[1])))
        object.__setattr__(self, "causes", tuple(str(c) for c in self.causes))
        object.__setattr__(self, "parameters", FrozenMapping(self.parameters))

    def __hash__(self):
        return hash((self.signature, self.channels, self.speed_rpm, self.f_Hz, self.h,
                     _parameters_key(self.parameters)))

    @property
    def description(self) -> str:
        """The signature in words (:data:`SIGNATURES`)."""
        return SIGNATURES[self.signature]

    def where(self) -> str:
        """Where it is, in words: frequency (or ratio), channels, speeds."""
        lo, hi = self.f_Hz
        if self.h is not None:
            f = f"h = {self.h:.4g} ({lo:.4g}-{hi:.4g} Hz)"
        elif abs(hi - lo) <= 1e-6 * max(abs(hi), 1.0):
            f = f"{lo:.4g} Hz"
        else:
            f = f"{lo:.4g}-{hi:.4g} Hz"
        return f"{f} in {' '.join(self.channels) or 'no channel'}, {self.speed_rpm[0]:.0f}-{self.speed_rpm[1]:.0f} rpm"

    def strength(self) -> str:
        """``level_dB`` in words: over the model, or (:data:`LEVEL_WORDS`) what it is for the signature; a
        ``moving_resonance`` also the most its track lifts a line (``largest_line_lift_dB``): its cells (the track's
        bands ±3ζ in every run) are mostly noise, whose median reads near 0 dB however far the lines it crosses
        stand out (trial12: −0.1 dB for a line 17.9 dB over the model)."""
        gains = self.parameters.get("run_gains_dB") if self.signature == "run_change" else None
        if gains:
            return LEVEL_WORDS["run_change:spread"].format(abs(self.level_dB), min(gains), max(gains), len(gains))
        if self.signature == "run_change":
            return LEVEL_WORDS["run_change"].format(self._run_change_level())
        if self.signature == "channel_copy" and _number(self.level_dB) is None:
            # a copy under a tenth of the target's own content in every band (a radial pair's crosstalk: Fy += 0.2·Fx
            # is 4 % of Fy's own lines, trial 30) has no cells of its own: its level over the target's noise instead
            p, over = self.parameters, _number(self.parameters.get("copy_over_noise_dB"))
            return f"under a tenth of {p.get('target')}'s own content in every band" + (
                "" if over is None else f", the copy {over:+.1f} dB over its noise on {p.get('source')}'s lines (median)")
        key = f"{self.signature}:{self.parameters.get('property', self.parameters.get('measured_against'))}"
        words = LEVEL_WORDS.get(f"{key}:{self.parameters.get('pattern')}", LEVEL_WORDS.get(key))
        out = (words or LEVEL_WORDS.get(self.signature, DEFAULT_LEVEL_WORDS)).format(self.level_dB)
        lift = _number(self.parameters.get("largest_line_lift_dB")) if self.signature == "moving_resonance" else None
        if lift is not None:
            out += f" in its track's bands, the lines it lifts up to {lift:+.1f} dB"
            gain = _number(self.parameters.get("peak_gain"))
            if gain is not None and gain > 0 and lift > 20 * math.log10(gain) + SHAPE_SHORT_DB:
                # the shape fitted to the track (its ζ and peak gain) holds far less than the lines' lift: say so,
                # not leave "peak gain 1.2" beside "+29.5 dB" for a reviewer to reconcile (a rocking whirl the
                # modes' fit could not give the lines to, read as a track)
                out += (f" (its fitted shape peaks at {20 * math.log10(gain):+.1f} dB only: the lift is read on the "
                        "lines, the shape does not hold it)")
            for x in self.parameters.get("notched_lines") or ():
                # a line in its antiresonance (a partial line that is none, describe_structure.without_notched_lines)
                rpm = [v for v in x.get("absent_rpm", ()) if _number(v) is not None]
                said = (f", its antiresonance taking h = {x['h']:.4g} {x['shape_dB']:+.0f} dB at "
                        f"{min(rpm):.0f}-{max(rpm):.0f} rpm") if rpm and _number(x.get("shape_dB")) is not None else ""
                out += "" if said in out else said         # a pooled track's line of several directions: once
        floor = _number(self.parameters.get("level_over_floor_dB")) if self.signature == "fixed_line" else None
        if floor is not None:
            # a fixed line taken out of the data before the search reads ~0 dB over the model in its bins (a new
            # user's 50 Hz pickup, 33 dB over the noise, was "+0.1 dB over the model" and nothing else)
            out += f", {floor:+.1f} dB over the noise floor at its own bins" + (
                " (taken out of the data before the search)" if self.parameters.get("removed_before_the_search") else "")
        if self.signature == "speed_line" and self.parameters.get("one_channel"):
            # a line of one radial channel the translation mode does not lift (:mod:`.one_channel_lines`): its
            # signature is where it is not, and the lift it lacks
            p = self.parameters
            out += (f", on {p['one_channel']} alone ({p['partner']} {_number(p.get('partner_dB')) or 0:+.0f} dB under "
                    f"it, median over its runs), C {_number(p.get('C')) or 0:.3g}, and " + lift_words(p))
            if p.get("removed_before_the_search"):
                out += " (taken out of the data before the search)"
        if self.signature == "speed_line" and "present_over_noise_dB" in self.parameters:
            out += self._range_line_words()
        peak = _number(self.parameters.get("peak_over_model_dB"))
        if peak is not None:
            # a narrow line's bands hold the model's lines beside it: its own bins say how far it stands out
            out += f", {peak:+.1f} dB at its own bins"
        if self.signature == "partial_line":
            scatter, read = _number(self.parameters.get("scatter_dB")), self.parameters.get("read_dB")
            scattering = "" if scatter is None or not read or len(read) != 2 else (
                f"its strength scattering {scatter:.1f} dB (rms) from run to run ({read[0]:+.0f} to {read[1]:+.0f} dB "
                "against the model)")
            absent = [x for x in (self.parameters.get("absent_rpm") or []) if _number(x) is not None]
            if scattering and not absent:
                return scattering                   # in every run, at a strength of its own in each
            if scattering:                          # its weakest runs: no start or stop, no run's pattern
                return out + f" ({len(absent)} runs at {min(absent):.0f}-{max(absent):.0f} rpm), " + scattering
            out += self._partial_span()
        return out

    def _range_line_words(self) -> str:
        """A line on the radial-force pair over one band of speeds that the translation mode does not lift
        (:mod:`.range_lines`) in words: where it starts and stops, and the lift it lacks."""
        p = self.parameters
        edges = [f"{w} between {e[0]:.0f} and {e[1]:.0f} rpm" for w, e in (("starts", p.get("starts_between_rpm")),
                                                                        ("stops", p.get("stops_between_rpm"))) if e]
        out = (f", present over one band of speeds ({_number(p.get('present_over_noise_dB')) or 0:+.0f} dB over the "
               f"noise there; at the noise outside it, where its C·Ω² would stand "
               f"{_number(p.get('expected_over_noise_dB')) or 0:+.0f} dB over it: it {' and '.join(edges)}), and "
               + lift_words(p))
        return out + (" (taken out of the data before the search)" if p.get("removed_before_the_search") else "")

    def _partial_span(self) -> str:
        """A partial line's runs in words: where it is absent and present, and, when the two part at one speed, the
        speeds it starts (stops) between (trial25's rub, present above 2800 rpm, read "1625-4000 rpm" alone)."""
        absent = [x for x in (self.parameters.get("absent_rpm") or []) if _number(x) is not None]
        present = [x for x in (self.parameters.get("present_rpm") or []) if _number(x) is not None]
        if not absent or not present:
            return ""
        out = (f" ({len(absent)} runs at {min(absent):.0f}-{max(absent):.0f} rpm; present in {len(present)} at "
               f"{min(present):.0f}-{max(present):.0f} rpm")
        if self.parameters.get("interleaved", True):
            return out + ", the two interleaved)"
        if max(absent) < min(present):
            return out + f": it starts between {max(absent):.0f} and {min(present):.0f} rpm)"
        if min(absent) < min(present):          # one band of runs holding it, runs without it on both sides
            below, above = max(x for x in absent if x < min(present)), min(x for x in absent if x > max(present))
            return out + (f": it starts between {below:.0f} and {min(present):.0f} rpm and stops between "
                          f"{max(present):.0f} and {above:.0f} rpm)")
        return out + f": it stops between {max(present):.0f} and {min(absent):.0f} rpm)"

    def _run_change_level(self) -> str:
        """A run_change's level with its sign: "+3.52" when every changed run is up, "−3.52" when every one is down,
        "±3.52" when they go both ways (``parameters["run_offsets_dB"]``; "±" when not recorded)."""
        offsets = [x for x in (self.parameters.get("run_offsets_dB") or []) if x is not None and math.isfinite(x)]
        sign = "±"
        if offsets and all(x > 0 for x in offsets):
            sign = "+"
        elif offsets and all(x < 0 for x in offsets):
            sign = "−"
        return f"{sign}{abs(self.level_dB):.2f}"

    def share_text(self) -> str:
        """Its share of what is left as a percentage ("41 %", "0.2 %", "< 0.1 %")."""
        return _percent(self.share)

    def text(self) -> str:
        """The console's one line: signature, where, strength, share, the first cause and what would tell."""
        if self.signature == "channel_copy" and _number(self.level_dB) is None:
            share = "no band of its own in what is left"           # its cells are none (:meth:`strength`), not 0 %
        else:
            share = f"{self.share_text()} of what is left"
        out = f"{self.signature}: {self.where()}, {self.strength()}, {share}"
        if self.causes:
            out += f"; could be {self.causes[0]}"
        if self.would_tell:
            out += f"; {self.would_tell}"
        return out

    def to_json(self) -> dict:
        """The JSON form (summary.json's ``unexplained`` entries; docs/diagnose.md)."""
        return {"signature": self.signature, "description": self.description, "channels": list(self.channels),
                "speed_rpm": [_number(x) for x in self.speed_rpm], "f_Hz": [_number(x) for x in self.f_Hz],
                "h": _number(self.h), "level_dB": _number(self.level_dB), "share": _number(self.share),
                "n_runs": int(self.n_runs), "parameters": _plain(dict(self.parameters)),
                "causes": list(self.causes), "would_tell": self.would_tell, "text": self.text()}

    @classmethod
    def from_json(cls, doc: Mapping) -> "Unexplained":
        """The record of a JSON form (:meth:`to_json`); ``description`` and ``text`` are derived, not read.  A
        ValueError naming the key on a missing or malformed one."""
        try:
            nan = float("nan")
            return cls(signature=doc["signature"], channels=tuple(doc["channels"]),
                       speed_rpm=tuple(nan if x is None else x for x in doc["speed_rpm"]),
                       f_Hz=tuple(nan if x is None else x for x in doc["f_Hz"]),
                       level_dB=nan if doc["level_dB"] is None else float(doc["level_dB"]),
                       share=nan if doc["share"] is None else float(doc["share"]),
                       n_runs=int(doc["n_runs"]), h=None if doc.get("h") is None else float(doc["h"]),
                       parameters=dict(doc.get("parameters") or {}), causes=tuple(doc.get("causes") or ()),
                       would_tell=str(doc.get("would_tell") or ""))
        except KeyError as exc:
            raise ValueError(f"unexplained record: {exc.args[0]!r} missing") from None
        except (TypeError, IndexError) as exc:
            raise ValueError(f"unexplained record: malformed ({exc})") from None
