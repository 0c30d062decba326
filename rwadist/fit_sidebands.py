"""Fixed-offset sidebands among the empirical fit's candidate harmonics (:func:`rwadist.empirical.identify_harmonics`).

A modulation at a fixed frequency puts lines at a constant offset in Hz from their carrier: near the top speed they
gather at one h and can pass the fit's presence test as harmonics.  :func:`fixed_offset_sidebands` tells them from
harmonics by the scatter of their detections about each law, marks them not kept and records their carrier
(``BinStat.sideband_of``), by which the carrier is then measured with them under its window.
"""
from __future__ import annotations

import numpy as np


def in_band(h, lines, f_lo, f_hi):
    """(n_h, n_pairs) bool: the line h·speed of each pair of ``lines`` (the fit's detected lines) lies in
    [f_lo, f_hi] Hz."""
    f_line = np.asarray(h)[:, None] * lines.pair_speed_hz[None, :]
    return (f_line >= f_lo) & (f_line <= f_hi)


#: A candidate line is a pair of fixed-offset sidebands of a stronger line, not a harmonic, when its detections
#: scatter about f = h·|Ω| by more than this many frequency bins (median) ...
OFFSET_SCATTER_BINS = 0.3
#: ... and about f = h₀·|Ω| ± Δ (a constant offset Δ Hz from the stronger line h₀) by less than this fraction of that,
OFFSET_BETTER = 0.5
#: ... with |Δ| at least this many bins (a sideband detected apart from its carrier).
OFFSET_MIN_BINS = 2.0


def fixed_offset_sidebands(bins: list, lines, df: float, f_lo: float, f_hi: float) -> None:
    """Mark not kept (in place) the kept candidates of ``bins`` whose detections follow a stronger kept line h₀ at a
    constant offset in Hz rather than a constant ratio of the speed: the sidebands of a modulation at a fixed
    frequency (a speed ripple puts them beside every line, an amplitude modulation beside one).  Near the top speed
    h₀ ± Δ/|Ω| changes slowly, so their detections there gather at one h and pass the presence test (family wheel 0,
    a 5-Hz ripple at 600-6000 rpm: lines at h 0.94 and 1.06 in 42 % of the spectra, and the wheel's modes fitted on
    them went wrong); they are no harmonic: ``sidebands`` and ``speed_ripple`` describe them.  Judged on the median
    absolute scatter of the detections matched to the candidate about each law (a true harmonic is detected within a
    small fraction of a bin of h·|Ω|; sidebands of a constant offset scatter about it by Δ − (h₀ − h)|Ω|).  Then, the
    offsets Δ so found known, a candidate whose detections sit at whole multiples k·Δ (k ≠ 0) of a stronger line
    (higher orders of a deep ripple, matched at one order at some speeds and another at others: family wheel 5,
    β = 0.75 at h 5.64).  Every candidate so read (a rejected one with 5 detections or more too) gets its carrier's h in ``sideband_of``."""
    # every candidate is read (a rejected one's detections can be a carrier's sidebands too: their carrier is then
    # measured with them under its window, :func:`measure_direction`), only a kept one is marked not kept
    cands = [b for b in bins if b.kept or b.n_bin >= 5]
    if sum(b.kept for b in cands) < 1 or len(cands) < 2:
        return
    h = np.array([b.h for b in cands])
    fpk = lines.match(h)
    speed = lines.pair_speed_hz
    ok = np.isfinite(fpk) & in_band(h, lines, f_lo, f_hi)
    tol = OFFSET_SCATTER_BINS * df
    steps: list[float] = []                  # the offsets Δ (Hz) of the sidebands found
    for multiples in (False, True):
        for i, b in enumerate(cands):
            if b.sideband_of is not None or ok[i].sum() < 5:
                continue
            f, w = fpk[i, ok[i]], speed[ok[i]]
            ratio = float(np.median(np.abs(f - b.h * w)))
            if ratio <= tol:
                continue
            for a in cands:
                if a is b or not a.kept or a.n_bin <= b.n_bin:
                    continue
                dev = f - a.h * w
                if not multiples:
                    offset = float(np.median(dev))
                    # a sideband stands apart from its carrier (2 bins: two peaks); a candidate on the carrier's own
                    # detections (two candidates refined onto one unresolved pair: E wheel 5.37/5.57 at 2048 samples)
                    # is no sideband
                    if abs(offset) >= OFFSET_MIN_BINS * df and \
                            float(np.median(np.abs(dev - offset))) < OFFSET_BETTER * ratio:
                        b.sideband_of = a.h
                        if b.kept:
                            steps.append(abs(offset))
                            b.kept = False
                            b.reason = (f"sidebands of h {a.h:.4g} at a fixed offset of {offset:+.3g} Hz (not a "
                                        "constant ratio of the speed)")
                        break
                    continue
                hit = next((d for d in steps if np.all(np.rint(dev / d) != 0)
                            and float(np.median(np.abs(dev - d * np.rint(dev / d)))) < min(tol, OFFSET_BETTER * ratio)),
                           None)
                if hit is not None:
                    b.sideband_of = a.h
                    if b.kept:
                        b.kept = False
                        b.reason = f"sidebands of h {a.h:.4g} at multiples of a fixed offset of {hit:.3g} Hz"
                    break
