"""Rolling-bearing kinematics: the ratios of a bearing's lines to the shaft speed, as candidate causes of lines.

A ball bearing of n balls of diameter d on a pitch circle of diameter D, contact angle α, one race turning at the
wheel's speed and the other still, rolling without slip (every ratio is a line's frequency over the speed, the ``h``
of a harmonic; γ = (d/D)·cos α):

- cage (fundamental train, FTF): ½(1 − γ) with the inner race turning, ½(1 + γ) with the outer race turning;
- ball pass over the outer race (BPFO): (n/2)(1 − γ); over the inner race (BPFI): (n/2)(1 + γ) -- for either race
  turning (the balls pass the turning race at n·|ω_race − ω_cage|, the still one at n·ω_cage);
- ball spin (BSF, one ball's spin relative to the cage): (D/2d)(1 − γ²); a flaw on one ball meets both races each
  turn, at 2·BSF.

Derivation (no slip at either contact, cage frame): the contacts lie at radii (D ∓ d·cos α)/2 from the axis; the ball
centre moves at the mean of the races' surface speeds.  ``tests/test_bearings.py`` checks these closed forms against
the no-slip conditions solved as a linear system and against a bearing's published ratios.

Without geometry, the ranges the ratios can take (:data:`RATIO_RANGES`) from d/D in [0.05, 0.30] (ball bearings)
and α in [0°, 40°]: γ in [0.038, 0.30], the cage 0.35-0.48 of the speed (inner race turning) or 0.52-0.65 (outer race
turning).  :func:`line_causes` names the candidates for a line's ratio: a given bearing's ratios (and their 2nd and
3rd multiples) within the resolution, else the ranges, the relations among the lines (a ball pass n × the cage, an
outer/inner ball-pass pair summing to n, a line's k-th multiple) and, without geometry, the ball counts whose
ball passes can take the ratio.

Where the user gives the geometry (docs/diagnose.md, "Physical causes for lines"): the model file's ``wheel``
section (``"bearings": [{"balls": 9, "ball_diameter_m": ..., "pitch_diameter_m": ..., "contact_angle_deg": 15,
"name": "front", "rotating_race": "inner"}]``) or ``rwadist diagnose --bearing
balls=9,ball_diameter_m=0.00794,pitch_diameter_m=0.03904[,contact_angle_deg=15][,name=front][,rotating_race=inner]``
(repeatable; the flag's bearings replace the model file's).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from .errors import DataError

#: Ranges of γ = (d/D)·cos α without geometry: d/D in [0.05, 0.30], α in [0°, 40°].
GAMMA_RANGE = (0.05 * math.cos(math.radians(40.0)), 0.30)
#: The highest multiple k of another non-integer line a line is named as (a bearing defect's impacts hold many: trial
#: nuR's half-sine pulses at 3.31 put lines at 3.31·k to k = 12, the 2nd and 3rd alone were named)
MAX_MULTIPLE = 16
#: Ball counts a bearing's ball-pass relations are searched over.
BALL_COUNTS = (5, 40)
#: A ball pass n × a cage line holds within this share of h at most (:func:`_relations`): the balls pass a race at
#: exactly n × the cage's rate, slip or not, and both lines' ratios share the speed's errors (a cage read 0.6 % off
#: still names its ball pass); (1 + n) resolutions
#: alone grew with n (a new user's sweep, a bin of its slices 1.5 % of the cage: "19 × 0.3812 = 7.243" was named
#: for a line at 7.108, 1.9 % off, and "12 × 0.3812 = 4.574" for one at 4.702)
BALL_PASS_REL_TOL = 0.01

#: The ratios' ranges without geometry (name -> (lo, hi, what)).
RATIO_RANGES = {
    "FTF": (0.5 * (1 - GAMMA_RANGE[1]), 0.5 * (1 - GAMMA_RANGE[0]),
            "the cage of a ball bearing whose inner race turns with the wheel (FTF = ½(1 − (d/D)·cos α))"),
    "FTF_outer": (0.5 * (1 + GAMMA_RANGE[0]), 0.5 * (1 + GAMMA_RANGE[1]),
                  "the cage of a ball bearing whose outer race turns with the wheel (FTF = ½(1 + (d/D)·cos α))"),
}
#: Subharmonic orders k whose line at exactly 1/k of the speed is named as a rub or looseness (Muszynska's rotor rub:
#: 1/2 and 1/3 of the speed, the commonest)
SUBHARMONICS = (2, 3)
#: Keys of a bearing's description (model file ``wheel.bearings[i]`` and ``--bearing``).
KEYS = ("balls", "ball_diameter_m", "pitch_diameter_m", "contact_angle_deg", "name", "rotating_race")
RATIO_NAMES = {"FTF": "cage (FTF)", "BPFO": "ball pass, outer race (BPFO)", "BPFI": "ball pass, inner race (BPFI)",
               "BSF": "ball spin (BSF)", "2BSF": "ball flaw meeting both races (2·BSF)"}


class BearingError(DataError):
    """A bearing description that is not one: ``source: field: problem`` (a :class:`~rwadist.errors.DataError`: the
    CLI says it and exits 2)."""

    def __init__(self, source: str, field: str, problem: str):
        self.source, self.problem = str(source), problem
        super().__init__(source, field, problem)


@dataclass(frozen=True)
class Bearing:
    """One ball bearing of the wheel (lengths in m, the contact angle in degrees as catalogues give it).

    balls : number of balls n (>= 3).  ball_diameter_m, pitch_diameter_m : d and D (0 < d < D).
    contact_angle_deg : α (0 <= α < 90).  name : a label for the report.  rotating_race : 'inner' (the shaft
    turns, the housing is still) or 'outer' (the housing turns about a still shaft)."""

    balls: int
    ball_diameter_m: float
    pitch_diameter_m: float
    contact_angle_deg: float = 0.0
    name: str = ""
    rotating_race: str = "inner"

    @property
    def gamma(self) -> float:
        """γ = (d/D)·cos α."""
        return self.ball_diameter_m / self.pitch_diameter_m * math.cos(math.radians(self.contact_angle_deg))

    def ratios(self) -> dict:
        """Line frequency over shaft speed of each bearing line: FTF, BPFO, BPFI, BSF and 2BSF (dimensionless)."""
        g, n = self.gamma, self.balls
        ftf = 0.5 * (1.0 - g) if self.rotating_race == "inner" else 0.5 * (1.0 + g)
        bsf = self.pitch_diameter_m / (2.0 * self.ball_diameter_m) * (1.0 - g * g)
        return {"FTF": ftf, "BPFO": 0.5 * n * (1.0 - g), "BPFI": 0.5 * n * (1.0 + g), "BSF": bsf, "2BSF": 2.0 * bsf}

    def label(self) -> str:
        return f"bearing {self.name!r}" if self.name else "the bearing"


def parse_bearing(spec, source: str = "--bearing", field: str = "bearing") -> Bearing:
    """A :class:`Bearing` from a mapping (model file) or ``key=value,...`` text (the CLI flag); a
    :class:`BearingError` naming ``source``, the field and the value on anything missing, unknown or out of range."""
    if isinstance(spec, str):
        items = {}
        for part in (p.strip() for p in spec.split(",") if p.strip()):
            key, sep, value = part.partition("=")
            if not sep:
                raise BearingError(source, field, f"{part!r} is no key=value pair (keys: {', '.join(KEYS)})")
            items[key.strip()] = value.strip()
        spec = items
    if not isinstance(spec, Mapping):
        raise BearingError(source, field, f"must be an object of {', '.join(KEYS)}, got {spec!r}")
    unknown = [k for k in spec if k not in KEYS]
    if unknown:
        raise BearingError(source, f"{field}.{unknown[0]}", f"unknown key (keys: {', '.join(KEYS)})")

    def num(key, default=None):
        v = spec.get(key, default)
        if v is None:
            raise BearingError(source, f"{field}.{key}", "missing")
        try:
            if isinstance(v, bool):
                raise ValueError
            x = float(v)
        except (TypeError, ValueError):
            raise BearingError(source, f"{field}.{key}", f"{v!r} is no number") from None
        if not math.isfinite(x):
            raise BearingError(source, f"{field}.{key}", f"{v!r} is no finite number")
        return x

    balls = num("balls")
    if balls != int(balls) or balls < 3:
        raise BearingError(source, f"{field}.balls", f"{spec['balls']!r}: must be a whole number >= 3")
    d, D, a = num("ball_diameter_m"), num("pitch_diameter_m"), num("contact_angle_deg", 0.0)
    if not 0 < d < D:
        raise BearingError(source, f"{field}.ball_diameter_m", f"{d!r}: must be > 0 and below pitch_diameter_m ({D!r})")
    if not 0 <= a < 90:
        raise BearingError(source, f"{field}.contact_angle_deg", f"{a!r}: must be in [0, 90) degrees")
    if balls * d > math.pi * D:
        raise BearingError(source, f"{field}.balls", f"{int(balls)} balls of {d:g} m do not fit on a pitch circle "
                           f"of {D:g} m (n·d must be below π·D)")
    race = str(spec.get("rotating_race", "inner"))
    if race not in ("inner", "outer"):
        raise BearingError(source, f"{field}.rotating_race", f"{race!r}: must be 'inner' or 'outer'")
    return Bearing(int(balls), d, D, a, str(spec.get("name", "")), race)


def bearings_of(wheel: Mapping | None, source: str = "<model>") -> tuple:
    """The bearings of a model's ``wheel`` section (``wheel["bearings"]``: a list of bearing objects), () without."""
    items = (wheel or {}).get("bearings")
    if items is None:
        return ()
    if not isinstance(items, (list, tuple)):
        raise BearingError(source, "wheel.bearings", f"must be a list of bearing objects, got {items!r}")
    return tuple(parse_bearing(b, source, f"wheel.bearings[{i}]") for i, b in enumerate(items))


def line_causes(h: float, resolution: float, bearings=(), others=(), parents=()) -> list:
    """Candidate bearing causes (sentences) of a line at ratio ``h`` to the speed, resolved to ``resolution`` (in h).

    With ``bearings``: each bearing ratio (and its 2nd and 3rd multiple) within the resolution of h.  Without (or
    none within it): the ranges of :data:`RATIO_RANGES` that hold h.  ``others``: the ratios of the other lines
    (the model's and the data's): h = n × a cage-range line (a ball pass over the still race), h = n × (1 − a
    cage-range line) (over the turning race), or h + another non-integer line = n (an outer/inner ball-pass pair,
    whose cage ratio is then the smaller over n), n in :data:`BALL_COUNTS`, or the k-th multiple of another
    non-integer line; last, the ball counts whose ball passes can take h (:func:`_ball_pass_ranges`).  ``parents``: the
    ratios of the lines of h's direction stronger than it, whose sums and differences it may be (:func:`_combinations`:
    a combination is weaker than the lines it is made of, and read among every line one pair or another sums to
    nearly any h)."""
    out = []
    for b in bearings:
        for key, r in b.ratios().items():
            for k in (1, 2, 3):
                if abs(h - k * r) <= resolution:
                    mult = "" if k == 1 else f"{k}× "
                    out.append(f"{mult}{RATIO_NAMES[key]} of {b.label()} ({k * r:.4g}, {b.balls} balls)")
    if out:
        return out
    where = ("for any ball bearing (none of the given bearings' ratios within the resolution)" if bearings
             else "without the bearing's geometry")
    for lo, hi, what in RATIO_RANGES.values():
        if lo - resolution <= h <= hi + resolution:
            out.append(f"{what}: h in {lo:.2f}-{hi:.2f} {where}")
    if abs(h - round(h)) <= 2 * resolution:
        return out                              # a harmonic of the speed: no ball-pass relation to name
    for k in SUBHARMONICS:
        if abs(h - 1.0 / k) <= resolution:
            # a line at exactly 1/k of the speed comes from a support that is not linear, not from kinematics
            out.append(f"a subharmonic, 1/{k} of the speed: a rub (the rotor touching a still part every {k} turns, "
                       "its friction driving a backward, counter-rotating whirl) or looseness in a mount or a "
                       "bearing's fit (a support stiffer one way than the other halves the frequency)")
    out += _relations(h, resolution, others, parents)
    if not bearings:                            # the given geometry names a ball pass or rules it out
        out += _ball_pass_ranges(h, resolution, where)
    return out


def _ball_counts(h: float, resolution: float, race: str) -> list:
    """The ball counts n in :data:`BALL_COUNTS` for which a ball pass over the ``race`` ('outer': (n/2)(1 − γ), 'inner':
    (n/2)(1 + γ)) can be ``h`` (to ``resolution``) with γ in :data:`GAMMA_RANGE` and the balls on their pitch circle
    (n·d < π·D, so γ < π/n)."""
    sign = -1.0 if race == "outer" else 1.0
    out = []
    for n in range(BALL_COUNTS[0], BALL_COUNTS[1] + 1):
        g_hi = min(GAMMA_RANGE[1], math.pi / n)
        lo, hi = sorted((0.5 * n * (1 + sign * GAMMA_RANGE[0]), 0.5 * n * (1 + sign * g_hi)))
        if lo - resolution <= h <= hi + resolution:
            out.append(n)
    return out


def _counts_text(ns: list) -> str:
    """'8-10' for a run of whole numbers, '6, 8' otherwise."""
    return f"{ns[0]}-{ns[-1]}" if len(ns) > 1 and ns[-1] - ns[0] == len(ns) - 1 else ", ".join(map(str, ns))


def _ball_pass_ranges(h: float, resolution: float, where: str) -> list:
    """The sentence naming the ball passes a non-integer line at ``h`` can be without the geometry: over the outer race
    (BPFO = (n/2)(1 − γ)) or the inner (BPFI = (n/2)(1 + γ)) of a bearing of the ball counts :func:`_ball_counts`
    finds (the geometry, ``--bearing``, tells which); [] for none."""
    parts = []
    for race, key in (("outer", "BPFO"), ("inner", "BPFI")):
        ns = _ball_counts(h, resolution, race)
        if ns:
            parts.append(f"over the {race} race ({key} = (n/2)(1 {'−' if race == 'outer' else '+'} γ)) of a bearing "
                         f"of {_counts_text(ns)} balls")
    return [f"a ball pass {where}: " + ", or ".join(parts)] if parts else []


def _relations(h: float, resolution: float, others, parents=()) -> list:
    """Sentences relating a non-integer line at ``h`` to the other lines' ratios ``others``: a ball pass n × a
    cage-range line (over the still race) or n × (1 − it) (over the turning race), an outer/inner ball-pass pair
    summing to n, and the k-th multiple (2 <= k <= :data:`MAX_MULTIPLE`) of another non-integer line (a bearing line's
    harmonics).

    Ordered by how well each holds: those within half of their own tolerance first (a multiple of another line before
    a pair before a ball pass: the fewer causes, the likelier), then the rest by their distance in units of their own
    tolerance (k × the resolution for the k-th multiple, 2 × it for a pair, (1 + n) × it for n × a cage-range
    line).  trial14's 11-ball bearing: 9.242 was first
    "16 × 0.5799 = 9.278", 14 whole-record bins off, before the exact 2nd multiple of 4.621."""
    n_lo, n_hi = BALL_COUNTS
    found: list = []                    # (key: the relation and the line's group, (closeness, rank, sentence))
    multiple_of: dict = {}              # a multiple's sentence -> the line it is a multiple of
    cage = [RATIO_RANGES[k][:2] for k in ("FTF", "FTF_outer")]
    group = _line_groups(others, resolution)
    for o in sorted(group):
        if abs(o - h) <= resolution:
            continue
        if any(lo <= o <= hi for lo, hi in cage) and h > 1.5:
            for name, base in (("over the still race", o), ("over the turning race", 1.0 - o)):
                n = round(h / base)
                tol = min(resolution * (1 + n), BALL_PASS_REL_TOL * h)
                if n_lo <= n <= n_hi and abs(h - n * base) <= tol:
                    found.append((("pass", name, n, group[o]),
                                  (abs(h - n * base) / tol, 2,
                                   f"ball pass {name} of a {n}-ball bearing whose cage is the line h = {o:.4g} "
                                   f"({n} × {base:.4g} = {n * base:.4g})")))
        s = h + o
        n = round(s)
        if n_lo <= n <= n_hi and abs(s - n) <= 2 * resolution and abs(o - round(o)) > 2 * resolution \
                and RATIO_RANGES["FTF"][0] <= min(h, o) / n <= RATIO_RANGES["FTF"][1]:
            found.append((("pair", n, group[o]),
                          (abs(s - n) / (2 * resolution), 1,
                           f"an outer/inner ball-pass pair of a {n}-ball bearing with the line h = {o:.4g} "
                           f"(BPFO + BPFI = n; cage {min(h, o) / n:.4g})")))
        k = round(h / o) if o > 0 else 0
        # a cage-range line's multiples beyond the 3rd are its ball passes' relation (BPFO = Z·FTF), said above
        top = 3 if any(lo <= o <= hi for lo, hi in cage) else MAX_MULTIPLE
        if 2 <= k <= top and abs(o - round(o)) > 2 * resolution and abs(h - k * o) <= k * resolution:
            sentence = (f"the {_ordinal(k)} multiple of the line h = {o:.4g} (a harmonic of that line's cause: a "
                        "bearing line's impacts are not sinusoidal)")
            multiple_of[sentence] = o
            found.append((("multiple", k, group[o]), (abs(h - k * o) / (k * resolution), 0, sentence)))
    out = _closest_of_each(found)
    out += _combinations(h, resolution, [o for o in parents if abs(o - h) > resolution and o > 0])
    # of the multiples that hold, the one of the lowest line first: the series' own base (trial nuR's impacts at
    # 3.31·k: h 13.24 read "the 2nd multiple of 6.62" and h 29.79 "the 3rd of 9.93")
    out.sort(key=lambda x: (x[0] > 0.5, x[1] if x[0] <= 0.5 else 0, multiple_of.get(x[2], math.inf) if x[0] <= 0.5 else 0,
                            x[0]))
    # one line read in several directions (h 3.3 in the radial force, torque and axial force, each a few 1e-4 apart)
    # is one relation: each sentence once, in the order of its closeness
    return list(dict.fromkeys(x[2] for x in out))


def _line_groups(ratios, resolution: float) -> dict:
    """Each distinct ratio of ``ratios`` -> the index of its line: ascending, a ratio is the line of the group it
    starts unless it lies within ``resolution`` of that group's first ratio (a group spans the resolution at most, so
    a run of lines each a little closer than it to the next stays several lines).  One line read in several
    directions (a cage at 0.4137 in the radial force and 0.4138 in the torque) is one line: a relation of it is named
    once (:func:`_closest_of_each`), not once per reading (a new user's report named one ball pass twice, "whose cage
    is the line h = 0.4137" and "... h = 0.4138")."""
    out: dict = {}
    first, index = None, -1
    for v in sorted({float(o) for o in ratios}):
        if first is None or v - first > resolution:
            first, index = v, index + 1
        out[v] = index
    return out


def _closest_of_each(found: list) -> list:
    """The (closeness, rank, sentence) of least closeness of each key of ``found`` [(key, entry)], in the order the
    keys first appear: of one line's readings, the one that holds a relation best names it."""
    best: dict = {}
    for key, entry in found:
        if key not in best or entry[0] < best[key][0]:
            best[key] = entry
    return list(best.values())


def _ordinal(k: int) -> str:
    """2nd, 3rd, 4th, ..., 11th, 12th, 13th, 21st, ..."""
    return f"{k}{'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')}"


def _combinations(h: float, resolution: float, others) -> list:
    """(closeness, rank, sentence) of a line at ``h`` that is the sum or the difference of two other lines' ratios
    (``others``, distinct from h), within 2 × the resolution: one line modulating the other puts lines at their sum and
    difference -- a bearing defect's line carried round by the cage or the shaft, or a nonlinearity of the structure
    or the measuring chain (a quadratic term makes every sum and difference of the lines it carries).  The new-user
    trial's quadratic load cell channel: 3.22 = 3.63 − 0.41 and 4.04 = 3.63 + 0.41 were named ball passes of 8- and
    10-ball bearings and nothing said they were combinations."""
    found = []
    group = _line_groups(others, resolution)
    uniq = sorted(group)
    for i, a in enumerate(uniq):
        for b in uniq[:i]:                              # b < a
            if group[a] == group[b]:
                continue                                # two readings of one line
            for value, word, sign in ((a + b, "sum", "+"), (a - b, "difference", "−")):
                if abs(h - value) <= 2 * resolution:
                    found.append(((word, group[a], group[b]),
                                  (abs(h - value) / (2 * resolution), 1,
                                   f"the {word} of the lines h = {a:.4g} and {b:.4g} ({a:.4g} {sign} {b:.4g} = "
                                   f"{value:.4g}): one modulating the other (a bearing defect's line carried round by the "
                                   "cage or the shaft) or a nonlinearity of the structure or the measuring chain, which "
                                   "puts lines at every sum and difference of the lines it carries")))
    return _closest_of_each(found)
