"""The speed of a record with no trustworthy speed, from physics (issue 33, item 5).

Every line of a wheel sits at a fixed ratio h of the rotor speed, so between two quasi-steady slices of a sweep
the whole line pattern moves rigidly in ln f by the change of ln|Ω|, whatever the lines are.  The speed is
therefore found in two steps that assume no line set:

1. **Shape** (:func:`relative_track`).  Each slice's spectrum, as a signal-to-noise ratio R over its local
   floor, is read on a uniform grid in u = ln f and clipped to its clear lines, L = clip(ln(R/R_LINE), 0,
   L_CAP).  Consecutive slices are registered by the lag of the largest cross-correlation of L (within
   ±MAX_STEP_LAG: a harmonic comb also correlates at ln 2), then every slice again against the template of all
   slices shifted into one frame (no accumulated drift).  This gives ln|Ω| up to one constant: the relative
   track r(t).  Content at a fixed frequency (a fixture's ringing, an electrical line) does not move with the
   pattern: it is left out of the registration (:func:`fixed_content`) and smeared out of the template.
2. **Scale** (:func:`imbalance_line`).  The template's peaks are the wheel's lines, at orders O_i (in units of
   r).  Their rotation sense is read per slice from the x/y phase of each radial pair (co-rotating with +z:
   F_y lags F_x by 90°, |X + iY|² against |X − iY|²).  The imbalance is at exactly 1× the rotor speed, static
   in the radial force and dynamic in the radial torque, both turning with the rotor: the candidates are the
   lines with one sense in the radial-force pair and the same sense in the radial-torque pair (one pair when
   only one is recorded), not one that would put another candidate below SLOWEST_LINE of the speed (no load
   turning one way in force and torque turns slower than a cage).  Among them the 1× line is the one with the most
   integer multiples 1..INTEGER_ORDERS
   among the lines found (the integer harmonics: misalignment, looseness; the imbalance itself counted); a
   bearing line's multiples are non-integer in the rotor's units.  The count of lines, never their strength:
   every clear line's strength saturates at L_CAP, and a summed strength flipped with the sweep's duration
   (trial 11: a 300-s run-up took a ball-pass line at 3.6 with its 2× at 7.2 for the imbalance with its 2×,
   summed strengths 11.93 against 11.89; every speed 3.6× too high).  Candidates with equally many multiples
   tie: a ball-pass line with its harmonics lies above the rotor's fundamental, so the lowest is taken (unless it is
   the lower speed sideband of a carrier in the tie within SIDEBAND_SPAN: the carrier; or it lies at a cage's ratio,
   0.35-0.48, of a tied line 10 times stronger in the radial-force pair: that line, whose cage it is) and the
   others are kept (``tied``) for a second, physical test the data can give (the gyroscopic whirl of the
   wheel's rocking mode reads I_zz/I_rr in proportion to the speed scale, :mod:`rwadist.speed_whirl`); a
   cage line with a harmonic (below 1×) is what that test catches.  Its sense is the sign of the speed.  The
   other lines keep their ratios, h_i = O_i/O_1.

The caller (:func:`rwadist.sweep.estimate_speeds`) then refines each slice's speed on every line found, each
at its own h_i, and reports how well they agree (:class:`SpeedScale`).

Units: Hz for frequencies, dimensionless orders and ratios, ln of Hz on the registration grid.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import signal

from .bearings import RATIO_RANGES
from .spectra import find_lines

#: step of the registration grid in u = ln f (0.02 %)
LOG_STEP = 2.0e-4
#: a spectrum point counts as line content above this signal-to-noise ratio (R = PSD / local floor)
R_LINE = 4.0
#: cap of one point's log content (a mode-amplified line must not outweigh the pattern)
L_CAP = 6.0
#: largest change of ln|Ω| searched between consecutive slices (below ln 2, where a harmonic comb correlates
#: with itself an octave away)
MAX_STEP_LAG = 0.6
#: window of the re-registration of each slice against the template, in ln units
TEMPLATE_LAG = 0.02
#: multiples of a 1× candidate counted as the rotor's integer lines
INTEGER_ORDERS = 4
#: relative tolerance of "an integer multiple"
INTEGER_TOL = 0.004
#: No load of a wheel turning one way in both the radial force and torque, as the imbalance does, turns slower than
#: this share of the rotor: a ball bearing's cage, the slowest of its lines, turns at ½(1 − (d/D)·cos α) >= 0.35 of it
#: (:data:`rwadist.bearings.RATIO_RANGES`), less a wide margin (trial 11's ball pass 3.6 with its 2x, tied with the
#: imbalance, would put it at 0.278: left to the whirl).  A 1× candidate that puts another candidate below it is not
#: taken while another is there (a new user's ball-pass line at 4.70 with its 2x had been taken, the imbalance then at
#: h 0.21: every speed 4.7x too high in ``rwadist fit``); it stays among the candidates the whirl tests.  Lines of one
#: pair or of no one sense (a cage in the force alone, a sub-synchronous whirl) do not exclude.
SLOWEST_LINE = 0.25
#: The lowest of a tie at a cage's ratio of another tied line is that line's cage when this many times weaker in
#: power ... (:func:`_far_stronger`)
CAGE_POWER_RATIO = 10.0
#: ... in this share of the slices where both stand out
CAGE_SLICES = 0.8
#: Speed sidebands of a carrier lie within this share of its order (:func:`_between_sidebands`)
SIDEBAND_SPAN = 0.15
#: a line has a rotation sense in a pair when this share of its power turns one way
POLARIZED = 0.6
#: a line counts in a pair when its power there is this many times the local noise's
PAIR_SNR = 10.0
#: a template peak is a line when it is found where the pattern puts it in this share of the slices
PRESENCE = 0.5
#: template peaks: minimum mean log content and prominence
PEAK_HEIGHT = 0.3
PEAK_PROMINENCE = 0.2
#: a point of the registration grid holds content at a fixed frequency when it is line content in this share of the
#: active slices or more (:func:`fixed_content`) ...
FIXED_PRESENCE = 0.5
#: ... and such points are left out of the registration only while they hold less than this share of all content
FIXED_SHARE = 0.5
#: Fixed points closer than this many grid steps (0.02 in ln f) are one group, whose content must stand still: the
#: centroid of each third's median content over the group widened by FIXED_WINDOW of its width on either side moves
#: by at most FIXED_MOVE of its width between the thirds (a pickup stands; a wheel's low line, lit over several 1 Hz
#: bins, is lit at one point through a sweep of x1.5 and moves)
FIXED_GAP = 100
FIXED_WINDOW = 2
FIXED_MOVE = 0.1
#: a slice is registered when its content (fixed content out) is at least this share of the median active slice's
#: (:func:`relative_track`)
REGISTER_CONTENT = 0.01


@dataclass(frozen=True)
class SpeedScale:
    """How a speed was obtained from the data.

    method : one line of text.  ratios : h of every line found, in units of the rotor speed (ascending).
    one_x : the 1× line's evidence (co shares in force and torque pairs, multiples found).  sense : +1 or −1
    (the sign of the speed).  agreement : RMS over lines and slices of f_line/(h·f_rotor) − 1 after the
    per-slice fit (relative).  n_lines : lines found.  senses : per line of ``ratios``, (share co-rotating with
    +z in the radial-force pair, in the radial-torque pair), nan where the line is not in the pair.
    """

    method: str
    ratios: tuple
    one_x: dict
    sense: float
    agreement: float = float("nan")
    n_lines: int = 0
    senses: tuple = field(default_factory=tuple)

    def to_meta(self) -> dict:
        """JSON-ready record for the test's ``meta['slicing']['speed_scale']``."""
        def num(x):
            return None if x is None or not np.isfinite(x) else float(x)

        return {"method": self.method, "ratios": [round(float(h), 6) for h in self.ratios],
                "co_share": [[num(float(v)) for v in pair] for pair in self.senses],
                "one_x": {k: (num(v) if isinstance(v, float) else v) for k, v in self.one_x.items()},
                "sense": int(self.sense), "agreement_rel_rms": num(self.agreement), "n_lines": int(self.n_lines)}


# ------------------------------------------------------------------------------------------ registration
def log_content(R: np.ndarray, f_pad: np.ndarray, f_lo: float, f_hi: float) -> tuple:
    """(u grid ln Hz (n_u,), L (n_slices, n_u)): each row of the SNR spectra R (on the uniform grid f_pad) read
    at e^u by linear interpolation, as clip(ln(R/R_LINE), 0, L_CAP)."""
    u = np.arange(np.log(f_lo), np.log(f_hi), LOG_STEP)
    pos = np.exp(u) / (f_pad[1] - f_pad[0])
    i0 = np.clip(np.floor(pos).astype(int), 0, R.shape[1] - 2)
    w = pos - i0
    vals = R[:, i0] * (1.0 - w) + R[:, i0 + 1] * w
    return u, np.clip(np.log(np.maximum(vals, 1e-300) / R_LINE), 0.0, L_CAP)


def _best_lag(a: np.ndarray, b: np.ndarray, max_lag: int, center: int = 0) -> tuple:
    """Lag (grid steps, sub-step by a parabola) of b against a maximising Σ a(u)·b(u + lag) within
    center ± max_lag, and that maximum.  b(u + lag) = a(u) for a pattern that moved up by lag."""
    n = a.size
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    corr = np.fft.irfft(np.conj(np.fft.rfft(a, nfft)) * np.fft.rfft(b, nfft), nfft)
    lags = np.arange(center - max_lag, center + max_lag + 1)
    vals = corr[lags % nfft]
    j = int(np.argmax(vals))
    best = float(lags[j])
    if 0 < j < len(vals) - 1:
        lo, mid, hi = vals[j - 1], vals[j], vals[j + 1]
        den = lo - 2 * mid + hi
        if den < 0:
            best += float(np.clip(0.5 * (lo - hi) / den, -0.5, 0.5))
    return best, float(vals[j])


def template(L: np.ndarray, shifts: np.ndarray, u: np.ndarray) -> tuple:
    """(o grid, T): the slices' content moved into one frame, o = u − shift, averaged where covered."""
    ok = np.isfinite(shifts)
    o = np.arange(u[0] - np.max(shifts[ok]), u[-1] - np.min(shifts[ok]) + LOG_STEP, LOG_STEP)
    total = np.zeros(o.size)
    count = np.zeros(o.size)
    for k in np.flatnonzero(ok):
        v = np.interp(o + shifts[k], u, L[k], left=np.nan, right=np.nan)
        m = np.isfinite(v)
        total[m] += v[m]
        count[m] += 1
    with np.errstate(invalid="ignore"):
        return o, np.where(count > 0, total / np.maximum(count, 1), 0.0)


def fixed_content(L: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Per point of the registration grid (n_u,), True where the log content ``L`` (n_slices, n_u) holds a line in
    :data:`FIXED_PRESENCE` of the ``active`` slices or more in each third of the record: content at a fixed
    frequency (a 50 Hz pickup, a machine of the stand), where a sweep's lines pass in a few slices each.  In each
    third, not over the whole: a run-down that slows exponentially dwells near its lowest speed, and its 1x line,
    lit over several 1 Hz bins, lit 6.5-7.7 Hz in over half the slices of a 90-s run-down of family wheel 2 (the late
    ones only).  A group of such points is fixed only when the content around it stands still from third to third
    (:data:`FIXED_MOVE`): a sweep of x1.5 lights the middle of a wheel's low line in every slice (a new user's wheel at
    1000-1500 rpm: its cage and 1x masked, 8 of 60 slices right; all 60 without).  All False when those points hold
    :data:`FIXED_SHARE` of the content or more: the lines themselves stand still (a record that hardly sweeps), and
    there is no pattern without them."""
    rows = L[np.asarray(active, dtype=bool)]
    if rows.shape[0] < 3:
        return np.zeros(L.shape[1], dtype=bool)
    fixed = np.ones(L.shape[1], dtype=bool)
    for part in np.array_split(rows > 0.0, 3):
        fixed &= np.mean(part, axis=0) >= FIXED_PRESENCE
    total = float(np.sum(rows))
    if not fixed.any() or total <= 0.0 or float(np.sum(rows[:, fixed])) >= FIXED_SHARE * total:
        return np.zeros(L.shape[1], dtype=bool)
    medians = [np.median(part, axis=0) for part in np.array_split(rows, 3)]
    idx = np.flatnonzero(fixed)
    for group in np.split(idx, np.flatnonzero(np.diff(idx) > FIXED_GAP) + 1):
        width = group[-1] - group[0] + 1
        lo, hi = max(group[0] - FIXED_WINDOW * width, 0), min(group[-1] + FIXED_WINDOW * width + 1, L.shape[1])
        x = np.arange(lo, hi)
        centres = [float(np.sum(x * m[lo:hi]) / max(float(np.sum(m[lo:hi])), 1e-30)) for m in medians]
        if max(centres) - min(centres) > FIXED_MOVE * width:
            fixed[group[0]:group[-1] + 1] = False
    return fixed


def relative_track(L: np.ndarray, u: np.ndarray, active: np.ndarray) -> np.ndarray:
    """ln of the relative speed of every slice (nan where not ``active``, and where the slice holds nothing to
    register: see below): consecutive registration, then two passes against the template (module docstring).  The
    first registered slice is 0.

    Content at a fixed frequency (:func:`fixed_content`) is left out of the registration: it correlates at lag 0
    between every two slices and pulls each step towards standing still (a 2 % pickup at 50 Hz on a new user's 90-s
    run-down from 4000 rpm read as 2048-sample slices: the track spanned ln 1.82 for the sweep's 2.56, and the cage
    was taken for the 1x line).  The template the caller reads the lines from keeps it, smeared."""
    L = np.where(fixed_content(L, active)[None, :], 0.0, L)
    # a slice whose only content stood still (a stopped wheel's pickup), or whose lines are too faint to place (near
    # zero speed), has nothing to register: left out as an inactive one, not chained on the lag an all-zero or
    # noise-only correlation peaks at (a run-down to a stop and up again, 2 % pickup: 31 of 90 slices right with the
    # stopped slices chained, 66 left out; +3000 -> -3000 rpm with the pickup: 41 with the faint slices around zero
    # chained, which the pickup itself had held at lag 0 before it was left out)
    active = np.asarray(active, dtype=bool)
    content = L.sum(axis=1)
    floor = REGISTER_CONTENT * float(np.median(content[active])) if active.any() else 0.0
    active = active & (L.max(axis=1) > 0.0) & (content >= floor)
    shifts = np.full(L.shape[0], np.nan)
    idx = np.flatnonzero(active)
    if idx.size == 0:
        return shifts
    max_lag = int(MAX_STEP_LAG / LOG_STEP)
    shifts[idx[0]] = 0.0
    for prev, k in zip(idx[:-1], idx[1:]):
        lag, _ = _best_lag(L[prev], L[k], max_lag)
        shifts[k] = shifts[prev] + lag * LOG_STEP
    small = int(TEMPLATE_LAG / LOG_STEP)
    for _ in range(2):
        o, T = template(L, shifts, u)
        new = shifts.copy()
        for k in idx:
            # T read on the slice's own grid at its current shift: the residual lag is a correction
            ref = np.interp(u - shifts[k], o, T, left=0.0, right=0.0)
            lag, _ = _best_lag(ref, L[k], small)
            new[k] = shifts[k] + lag * LOG_STEP
        shifts = new - new[idx[0]]
    return shifts


def template_lines(o: np.ndarray, T: np.ndarray) -> tuple:
    """(orders ln (n,), strength (n,)): the template's peaks (the wheel's lines), refined by a parabola."""
    idx, _ = signal.find_peaks(T, height=PEAK_HEIGHT, prominence=PEAK_PROMINENCE, distance=5)
    idx = idx[(idx > 0) & (idx < T.size - 1)]
    lo, mid, hi = T[idx - 1], T[idx], T[idx + 1]
    den = lo - 2 * mid + hi
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(den < 0, np.clip(0.5 * (lo - hi) / den, -0.5, 0.5), 0.0)
    return o[idx] + d * LOG_STEP, mid


def measured_lines(P: np.ndarray, F: np.ndarray, f_pad: np.ndarray, f_guess: np.ndarray, threshold: float,
                   df: float) -> np.ndarray:
    """(n_slices, n_lines) Hz: each line's peak in each slice (:func:`rwadist.spectra.find_lines` on P against F,
    log-parabolic), the nearest within 1.5 native bins of its guess ``f_guess`` (nan where none)."""
    out = np.full(f_guess.shape, np.nan)
    for k in range(f_guess.shape[0]):
        g = f_guess[k]
        ok = np.isfinite(g)
        if not ok.any():
            continue
        f_found, _ = find_lines(P[k], f_pad, F[k], threshold, f_max=np.nanmax(g) + 2 * df,
                                f_min=max(np.nanmin(g) - 2 * df, 0.0))
        if f_found.size == 0:
            continue
        j = np.argmin(np.abs(f_found[None, :] - g[ok][:, None]), axis=1)
        near = np.abs(f_found[j] - g[ok]) <= 1.5 * df
        out[k, np.flatnonzero(ok)[near]] = f_found[j][near]
    return out


def line_orders(f_meas: np.ndarray, orders0: np.ndarray, passes: int = 3) -> np.ndarray:
    """Orders of the lines (in the template's units) from their measured frequencies (n_slices, n_lines): each
    slice's scale is the median over its lines of f/O, each order the median over slices of f/scale; the common
    error of a slice's registration cancels."""
    orders = orders0.astype(float).copy()
    for _ in range(passes):
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)                # slices without any line: nan
            c = np.nanmedian(f_meas / orders[None, :], axis=1)
            new = np.nanmedian(f_meas / c[:, None], axis=0)
        orders = np.where(np.isfinite(new), new, orders)
    return orders


# ------------------------------------------------------------------------------------------ rotation sense
def pair_senses(spectra: dict, f_pad: np.ndarray, pad: int, f_lines: np.ndarray) -> dict:
    """Per radial pair present: (co share (n_lines,), snr (n_slices, n_lines), power (n_slices, n_lines): |X|² + |Y|²
    at the line); the co share is the median over
    the slices where the line stands PAIR_SNR over the local noise in the pair of |X + iY|²/(|X + iY|² +
    |X − iY|²) (nan where it never does): a median, so a slice where a fixed-frequency line crosses it cannot
    outweigh the others.  ``spectra``: channel -> complex
    Hann-windowed spectra (n_slices, n_f) zero-padded ``pad`` times on ``f_pad``; ``f_lines`` (n_slices,
    n_lines) Hz (nan: not in that slice), read at the nearest padded bin (an eighth of a bin off at most,
    which scales X and Y alike).  Co-rotating with +z: F_x = a cos, F_y = a sin, so Y = −iX: co |X + iY|²,
    counter |X − iY|².  The local noise is the median |X|² + |Y|² at ±4..8 native bins off the line (each slice's
    reading: :func:`slice_senses`)."""
    out = {}
    for key, (share, snr, power) in slice_senses(spectra, f_pad, pad, f_lines).items():
        with np.errstate(invalid="ignore"):
            med = np.full(share.shape[1], np.nan)
            seen = np.isfinite(share).any(axis=0)
            med[seen] = np.nanmedian(share[:, seen], axis=0)
        out[key] = (med, snr, power)
    return out


def slice_senses(spectra: dict, f_pad: np.ndarray, pad: int, f_lines: np.ndarray) -> dict:
    """Per radial pair present ("F", "T"): (co share (n_slices, n_lines), snr (n_slices, n_lines), power |X|² + |Y|²
    at the line (n_slices, n_lines)) of each slice apart, the share nan where the line does not stand PAIR_SNR over the local noise: what :func:`pair_senses` takes
    the median of over the slices (same arguments); a steady test's run is one slice
    (:func:`rwadist.speed_check.run_line`)."""
    dfp = f_pad[1] - f_pad[0]
    n_f = f_pad.size
    ok = np.isfinite(f_lines)
    k = np.clip(np.rint(np.where(ok, f_lines, 0.0) / dfp).astype(int), 0, n_f - 1)
    rows = np.arange(f_lines.shape[0])[:, None]
    offsets = pad * np.array([-8, -6, -4, 4, 6, 8])
    out = {}
    for pair in (("Fx", "Fy"), ("Tx", "Ty")):
        if not all(c in spectra for c in pair):
            continue
        X, Y = (spectra[c][rows, k] for c in pair)
        line = np.abs(X) ** 2 + np.abs(Y) ** 2
        ko = np.clip(k[..., None] + offsets, 0, n_f - 1)
        off = sum(np.abs(spectra[c][rows[..., None], ko]) ** 2 for c in pair)
        snr = np.where(ok, line / np.maximum(np.median(off, axis=-1), 1e-300), 0.0)
        co, ct = np.abs(X + 1j * Y) ** 2, np.abs(X - 1j * Y) ** 2
        out[pair[0][0]] = (np.where(snr >= PAIR_SNR, co / np.maximum(co + ct, 1e-300), np.nan), snr, line)
    return out


def polarized_senses(shares: list, n: int) -> np.ndarray:
    """Per line, its rotation sense about +z, +1 or −1, where every pair's co share (``shares``: one array (n,) per
    radial pair) is finite and at least :data:`POLARIZED` the same way; 0 elsewhere (a line turning no one way, absent
    from a pair, or the pairs disagreeing), and 0 for every line with no pair."""
    sense = np.zeros(n)
    ok = np.full(n, bool(shares))
    for s in shares:
        s = np.asarray(s, dtype=float)
        pol = np.where(s >= POLARIZED, 1.0, np.where(s <= 1 - POLARIZED, -1.0, 0.0))
        pol = np.where(np.isfinite(s), pol, 0.0)
        ok &= pol != 0
        sense = np.where(sense == 0, pol, np.where(sense == pol, sense, 0.0))
    return np.where(ok, sense, 0.0)


def imbalance_line(orders: np.ndarray, strength: np.ndarray, senses: dict) -> tuple:
    """The 1× line among the template's lines (module docstring, step 2).

    Parameters
    ----------
    orders : ndarray (n,)
        The lines' orders, linear, in the template's units (any common scale).
    strength : ndarray (n,)
        The lines' template strength (mean log content); a line of strength 0 (outside a given rpm range) is neither
        a candidate nor a multiple.
    senses : dict
        :func:`pair_senses`'s output: "F", "T" -> (co share (n,), snr).

    Returns
    -------
    tuple
        (index of the 1× line, its sense ±1, evidence dict, reason text).  Candidates: one sense in every recorded
        radial pair, the same in all; with no such line, every line (said in the reason).  The evidence holds the
        line's order and multiples, its co shares, ``tied``: the other candidates with as many integer multiples
        ({"h": ratio in units of the chosen line, "multiples_found"}; empty when the choice is unique), and
        ``candidates``: every other candidate, the tied first, then by fewer multiples.
    """
    share = {key: v[0] for key, v in senses.items()}
    n = orders.size
    sense = polarized_senses(list(share.values()), n)
    cand = sense != 0
    how = ("one sense in " + " and ".join({"F": "radial force", "T": "radial torque"}[k] for k in share)
           if share else "no radial x/y pair recorded: every line a candidate")
    if not cand.any():
        cand = np.ones(n, dtype=bool)
        sense = np.ones(n)
        how = "no line with one rotation sense in the radial pairs: every line a candidate"
    seen = strength > 0
    if (cand & seen).any():
        cand &= seen
    # a candidate that puts another candidate (a load turning one way in force and torque, as the imbalance does)
    # below the slowest cage is not the rotor's (module docstring); it stays a candidate for the whirl's test
    below = np.array([np.any(cand & (orders < SLOWEST_LINE * orders[c])) for c in range(n)], dtype=bool)
    excluded = cand & below if (cand & ~below).any() else np.zeros(n, dtype=bool)
    multiples = {}
    for c in np.flatnonzero(cand):
        ratio = orders / orders[c]
        k = np.rint(ratio)
        hit = seen & (k >= 1) & (k <= INTEGER_ORDERS) & (np.abs(ratio - k) <= INTEGER_TOL * np.maximum(k, 1))
        multiples[int(c)] = sorted({int(x) for x in k[hit]} | {1})
    most = max(len(m) for c, m in multiples.items() if not excluded[c])
    tied = sorted((c for c, m in multiples.items() if len(m) == most and not excluded[c]), key=lambda c: orders[c])
    # the lowest of a tie the lower sideband of a carrier in the tie: the carrier (speed sidebands at 0.93 and 1.07 tie
    # with the imbalance at 1, one multiple each)
    carriers = [c for c in tied[1:] if orders[c] <= (1 + SIDEBAND_SPAN) * orders[tied[0]]
                and _between_sidebands(orders, seen, c)]
    if carriers:
        tied = carriers[:1] + [c for c in tied if c != carriers[0]]
    # the lowest of a tie at a cage's ratio of a far stronger line in the tie: that line (a cage turns one way in force
    # and torque as the imbalance does, far weaker; a new user's wheel of a 1x, a cage 0.414 and ball-pass lines with no
    # integer harmonic had every speed read 2.42x too low on the cage)
    lo, hi = RATIO_RANGES["FTF"][:2]
    rotors = [c for c in tied[1:] if not carriers and lo <= orders[tied[0]] / orders[c] <= hi
              and _far_stronger(senses, tied[0], c)]
    if rotors:
        tied = rotors[:1] + [c for c in tied if c != rotors[0]]
    best = tied[0]
    if excluded.any():
        how += (f"; not the line{'s' if excluded.sum() > 1 else ''} at h "
                + ", ".join(f"{orders[c] / orders[best]:.4g}" for c in np.flatnonzero(excluded))
                + f", which would put a line turning one way in force and torque below {SLOWEST_LINE:g}x the speed")
    mult = multiples[best]
    others = [{"h": float(orders[c] / orders[best]), "multiples_found": multiples[c]} for c in tied[1:]]
    rest = sorted((c for c in multiples if c not in tied), key=lambda c: (bool(excluded[c]), -len(multiples[c]),
                                                                          orders[c]))
    evidence = {"order": float(orders[best]), "multiples_found": mult, "tied": others,
                "candidates": others + [{"h": float(orders[c] / orders[best]), "multiples_found": multiples[c]}
                                        for c in rest],
                **{f"co_share_{'force' if k == 'F' else 'torque'}": float(v[best]) for k, v in share.items()}}
    reason = f"the 1x line: {how}, with the most integer multiples (found {mult})"
    if others:
        reason += ("; as many for the line" + ("s" if len(others) > 1 else "") + " at h "
                   + ", ".join(f"{o['h']:.4g}" for o in others)
                   + (": the one midway between two lines (a carrier and its sidebands) taken" if carriers
                      else f": the one whose cage the lowest would be ({lo:.2f}-{hi:.2f} of it, "
                      f"{CAGE_POWER_RATIO:g}x weaker) taken" if rotors else ": the lowest taken"))
    return best, float(sense[best]), evidence, reason


def _far_stronger(senses: dict, weak: int, strong: int) -> bool:
    """Whether line ``strong``'s power |X|² + |Y|² in the radial-force pair (the radial-torque pair when no force pair
    is recorded) is :data:`CAGE_POWER_RATIO` times line ``weak``'s or more in :data:`CAGE_SLICES` of the slices where
    both stand PAIR_SNR over their local noise (3 such slices at least; :func:`pair_senses`): compared slice by slice,
    at one speed, where C·Ω² makes the ratio (C_strong/C_weak)² (the higher line's wider chirp lowers its peak up to
    the ratio of their h).  Not over the local noise: a strong line's snr is held down by its own leakage (a new
    user's 1x over its cage read 4-3000 from slice to slice for a C² ratio of 121); and not a mere "stronger": a line
    on a mode is lifted 10-30 times, and a one-way line 2.42x above a weak 1x had been taken for the 1x (a reviewer's
    well-balanced wheel, 6x the 1x's power; one crossing a mode)."""
    key = "F" if "F" in senses else "T" if "T" in senses else None
    got = senses.get(key) if key else None
    if got is None or len(got) < 3 or got[1] is None or got[2] is None:
        return False
    snr, power = np.asarray(got[1], dtype=float), np.asarray(got[2], dtype=float)
    both = (snr[:, weak] >= PAIR_SNR) & (snr[:, strong] >= PAIR_SNR)
    if both.sum() < 3:
        return False
    return bool(np.mean(power[both, strong] >= CAGE_POWER_RATIO * power[both, weak]) >= CAGE_SLICES)


def _between_sidebands(orders: np.ndarray, seen: np.ndarray, c: int) -> bool:
    """Whether line ``c`` lies midway (within :data:`INTEGER_TOL` of its order) between two other lines of the pattern
    at most :data:`SIDEBAND_SPAN` of its order away: a carrier with its lower and upper speed sidebands."""
    o = orders[c]
    near = seen & (np.abs(orders - o) <= SIDEBAND_SPAN * o) & (np.arange(orders.size) != c)
    lo, hi = orders[near & (orders < o)], orders[near & (orders > o)]
    return bool(lo.size and hi.size and np.min(np.abs((lo[:, None] + hi[None, :]) / 2.0 - o)) <= INTEGER_TOL * o)


# ------------------------------------------------------------------------------------------ the lines' ratios
def sweep_ratios(meta) -> np.ndarray:
    """The ratios h (ascending) of the lines a sweep's speed scale found (``meta["slicing"]["speed_scale"]
    ["ratios"]`` of a test sliced from a sweep with the speed from the data, :meth:`SpeedScale.to_meta`); empty
    for any other test (steady runs, a tach column)."""
    scale = ((meta or {}).get("slicing") or {}).get("speed_scale") or {}
    return np.asarray(scale.get("ratios") or (), dtype=float)


def ratios_near(h: float, ratios: np.ndarray, tol: float) -> list:
    """The ratios of ``ratios`` within ``tol`` of ``h`` (both in units of the rotor speed), nearest first; ``[h]``
    when none is (or there are no ratios).

    The speed scale measured every line's ratio on the whole slices (zero-padded) of every speed, registered into
    one frame.  Where a diagnosis reads a line from shorter spectra (``tol``: the main lobe at the fastest run), two
    lines closer than that blend into one peak between them at the low speeds (a 30-s run-up of the family's wheel
    4: 6.09 and 6.38 read as 6.15), and a line smeared over its slice leaves a ridge beside itself (a 30-s run-down
    of wheel 6: 2.038 beside 2.000): what is there is the wheel's lines of the speed scale's ratios."""
    if ratios.size == 0 or not np.isfinite(h):
        return [h]
    d = np.abs(ratios - h)
    near = np.argsort(d)[: int(np.sum(d <= tol))]
    return [float(ratios[j]) for j in near] if near.size else [h]
