"""A line that is one of two sidebands of a stronger line: the candidate cause "that line modulated m times a
revolution".

A rotating load of ratio p (its angle p·θ) whose amplitude or phase is modulated m times a revolution,
a·(1 + ε·cos(mθ))·e^{i(pθ + β·sin(mθ))}, holds, besides its carrier, two lines at the signed ratios p + m and
p − m: a line of a radial direction turns forward at a positive ratio and backward at a negative one, so the lower
sideband of the imbalance (p = 1) modulated 6 times a revolution is a counter-rotating line at h 5 beside a
co-rotating one at h 7 (session 60's new-user trial: a 6/rev phase modulation of index 0.05, both read right and
named a bearing's ball passes).  For a small phase modulation the two sidebands hold β/2 of the carrier each, for an
amplitude modulation ε/2 each: the same C (a line's C is its load over Ω², and both ride the carrier's load).  So a
line is named a sideband where a stronger line of its direction stands at p and a line of the same C
(:data:`SAME_C`) at the mirror ratio 2p − s.  A series of harmonics (1, 2, 3 of falling C) is not: its neighbours
differ in C.  A whole m is a motor's ripple or cogging (:mod:`rwadist.motor`), or a gear's mesh."""
from __future__ import annotations

import math

#: Two lines are a sideband pair when their C differ by at most this factor.
SAME_C = 1.25
#: The mirror line is looked for within this many ratio resolutions of 2p − s (three measured ratios' errors add up)
MIRROR_RESOLUTIONS = 3.0
#: The highest order of one series (:func:`_one_series`) read as such
MAX_ORDER = 16
#: The directions whose lines turn (a counter-rotating line: a negative ratio).
TURNING = ("radial_force", "radial_torque")


def signed_lines(direction: str, harmonics) -> list:
    """[(signed ratio, C)] of a direction's harmonics (objects with ``h``, ``C``, ``sense``): a radial line's
    counter-rotating part at −h, a planar one (both senses) at ±h."""
    out = []
    for x in harmonics:
        c = getattr(x, "C", None)
        if c is None:
            continue
        sense = getattr(x, "sense", None) if direction in TURNING else None
        h = float(x.h)
        if sense in ("counter", "planar"):
            out.append((-h, abs(float(c))))
        if sense != "counter":
            out.append((h, abs(float(c))))
    return out


def sideband_causes(direction: str, h: float, sense, lines: list, resolution: float) -> list:
    """Candidate causes (sentences) of the line at ratio ``h`` (its ``sense``: "counter" reads it at −h) among its
    ``direction``'s ``lines`` (:func:`signed_lines`), ratios resolved to ``resolution``: "one of two sidebands of the
    line h = p" for each stronger line at p whose mirror 2p − s holds a line of the same C (module docstring; in a
    direction that does not turn, the mirror at |2p − s|)."""
    turning = direction in TURNING
    signs: tuple[float, ...]
    if not turning:
        signs = (h,)
    else:
        signs = (-h,) if sense == "counter" else (h,) if sense == "co" else (h, -h)   # a line of both parts: either
    out = []
    for s in signs:
        own = [c for r, c in lines if abs(r - s) <= resolution]
        if not own:
            continue
        c0 = max(own)
        for p, cp in lines:
            m = abs(s - p)
            # the line's own part of the other sense is no carrier of it (a planar line: trial nuR's impacts at h 3.31,
            # "one of two sidebands of the line h = 3.31")
            if cp <= c0 or p == 0 or m <= 2 * resolution or abs(abs(p) - abs(s)) <= resolution:
                continue
            at = 2 * p - s if turning else abs(2 * p - s)
            mirror = [c for r, c in lines if abs(r - at) <= MIRROR_RESOLUTIONS * resolution]
            if not any(abs(math.log(c / c0)) <= math.log(SAME_C) for c in mirror if c > 0) or \
                    _one_series((s, p, at), (s, p, at, *(r for r, c in lines if c >= c0)), resolution):
                continue
            whole = abs(m - round(m)) <= 2 * resolution
            out.append(f"one of two sidebands of the line h = {abs(p):.4g} at ±{m:.4g} per rev (with the {_line(at)}, "
                       f"of the same C): that line modulated {m:.4g} times a revolution, in amplitude or phase"
                       + (" (a motor's torque ripple or cogging, a gear's mesh)" if whole else ""))
    return out


def _one_series(ratios, bases, resolution: float) -> bool:
    """Whether every ratio of ``ratios`` (signed) is a whole multiple (1 to :data:`MAX_ORDER`) of one of ``bases`` (the
    three lines' own ratios and those of the lines as strong as the one named) that is no simple fraction (k/q, q <= 4:
    the imbalance's 1 and its subharmonics divide whole ratios at every order): the harmonics of one non-sinusoidal
    source (a bearing defect's impacts, trial nuR: its lines at 3.31·k, each of both senses, read "sidebands of h
    3.31 at ±13.24 per rev"), not a modulation.  A modulation of the imbalance m times a revolution puts its sidebands
    at whole ratios (the trial of session 60's 6/rev phase modulation): no simple fraction is asked, nor a weak line
    elsewhere (a rub's h 0.5)."""
    for b in {abs(r) for r in bases}:
        if b <= 2 * resolution or any(abs(b * q - round(b * q)) <= 2 * resolution * q for q in range(1, 5)):
            continue
        k = [round(abs(r) / b) for r in ratios]
        if all(1 <= n <= MAX_ORDER and abs(abs(r) - n * b) <= MIRROR_RESOLUTIONS * resolution * n
               for r, n in zip(ratios, k)):
            return True
    return False


def _line(signed: float) -> str:
    return f"counter-rotating line h = {-signed:.4g}" if signed < 0 else f"line h = {signed:.4g}"
