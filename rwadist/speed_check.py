"""A steady test's speed column checked against the wheel's own 1× lines (issue 33, item 5).

The imbalance is at exactly 1× the rotor speed, static in the radial force and dynamic in the radial torque, both
turning with the rotor (:mod:`rwadist.speed_scale`, whose rotation-sense rule this module reuses).  A speed column
read k times off (a tach constant, a gear ratio, a DAQ scale: trial 13's speeds 1 % high) puts every line of the
data at 1/k of its ratio and the imbalance at h = 1/k, which no model of the wheel holds (the search pins the
imbalance at 1× and the fit contradicts itself: trial 13, 43-54x the clean error, nothing said).  So before the
search each run's 1× lines are measured where the given speed puts them:

* the radial force pair (Fx, Fy) and the radial torque pair (Tx, Ty): the strongest peak of |X|² + |Y|² within
  :data:`SEARCH` of the given 1× frequency (Hann window, zero-padded :data:`PAD` times, refined by a parabola
  through the log of the three padded bins around it), counted where it stands :data:`speed_scale.PAIR_SNR` over
  the local noise (±4..8 native bins) and turns one way (its co-rotating share beyond
  :data:`speed_scale.POLARIZED`; :func:`rwadist.speed_scale.slice_senses`, the sweep path's rule), the same way
  relative to the given speed's sign in the runs kept (the majority);
* the axial force Fz, when it holds a line there (a plane line: no sense).

Each line's ratio to the given speed over the runs, r = f_line / f_given, gives its scale k_line (the median) and its
spread (1.4826 · MAD).  The column is called off, and every run's speed multiplied by the common k, only when

1. the radial force's 1× line is measured in at least :data:`MIN_RUNS` runs and in half of the spinning runs (a
   wheel whose radial 1× line is weak is never rescaled by other lines);
2. every 1× line measured in :data:`MIN_RUNS` runs or more sits at one k (within :data:`AGREE` or
   :data:`SIGMAS` standard errors; otherwise one of them is something else, e.g. a fixed line, and nothing moves);
3. the common k is off 1 beyond :data:`SCALE_FLOOR` and :data:`SIGMAS` standard errors (the resolution), and
   :data:`CONSISTENT` of the runs' radial-force ratios lie nearer k than 1.

On true speeds (every 1× line at 1 within its resolution) the test is left exactly as read.  What was measured
is :func:`check_record`'s record, which :func:`rwadist.speed_whirl.speed_record` turns into how the speed was
obtained.

Units: Hz for frequencies, rad/s for the runs' speeds, dimensionless ratios.
"""
from __future__ import annotations

import warnings
from dataclasses import replace
from functools import lru_cache

import numpy as np
from scipy import fft as sfft

from .speed_scale import PAIR_SNR, POLARIZED, slice_senses

#: zero-padding factor of a run's spectrum (the peak's sub-bin sampling)
PAD = 4
#: relative half-width of the window searched around the given 1× frequency (a speed column off by up to 3 %)
SEARCH = 0.03
#: a 1× line is judged on this many runs at least
MIN_RUNS = 3
#: relative scale below which a speed column is left as given (0.05 %: a DAQ's reading of a speed)
SCALE_FLOOR = 5.0e-4
#: standard errors by which a scale must exceed 1, and within which two lines' scales agree
SIGMAS = 6.0
#: relative difference within which two lines' scales always agree (a line's sub-bin accuracy at the lowest speeds)
AGREE = 3.0e-4
#: share of the runs' radial-force ratios that must lie nearer the common scale than 1
CONSISTENT = 0.8
#: the run's given 1× frequency must be this many native bins above 0 Hz to be measured
MIN_BINS = 12
#: padded bins, from a peak, of the local noise a line is read against (the median at ±4..8 native bins)
NOISE_BINS = PAD * np.array([-8, -6, -4, 4, 6, 8])
#: a line beside the radial force's counts only when its reads cluster: their spread (1.4826·MAD of r) below this share
#: of the spread of reads taken at random in the window (1.4826·SEARCH/2: noise's highest peak, wherever it falls)
CLUSTERED = 0.25
#: a tach's pulses a turn, counted as turns: the column reads that many times the rotor's speed
TACH_PULSES = (2, 3, 4)
#: the fractions of the given speed the 1× lines are read at beside it (:class:`LineReads`, :func:`_whole_factor`)
WHOLE_FRACTIONS = tuple(1.0 / n for n in TACH_PULSES)
#: the three 1× lines: key -> (channels, text)
LINES = {"radial_force": (("Fx", "Fy"), "radial force"), "radial_torque": (("Tx", "Ty"), "radial torque"),
         "axial_force": (("Fz",), "axial force")}


def run_line(run, channels: tuple, f0: float, spectra: dict | None = None) -> tuple:
    """(frequency Hz, SNR, co-rotating share) of the strongest peak within :data:`SEARCH` of ``f0`` in a run's
    ``channels`` (an x/y pair or one channel); nan frequency when the run lacks a channel or the window.

    The peak is the largest |X|² + |Y|² (|X|² for one channel) of the Hann-windowed spectra zero-padded
    :data:`PAD` times, refined by a parabola through the log of the three padded bins around it.  A pair's SNR and
    co share are :func:`rwadist.speed_scale.slice_senses`' (the sweep path's one rule of a rotating line): the
    share |X + iY|²/(|X + iY|² + |X − iY|²) where the line stands PAIR_SNR over the median at ±4..8 native bins;
    one channel's SNR is its |X|² over that median, its share nan.  ``spectra``: the run's spectra
    (:func:`run_spectra`) holding ``channels``, or None (made here)."""
    none = (np.nan, 0.0, np.nan)
    if not all(run.usable(c) for c in channels) or not _measurable(run, f0):
        return none
    fs = float(run.sample_rate)
    df = fs / run.n_samples
    f = _window_and_bins(run.n_samples, fs)[1]
    spectra = spectra or run_spectra(run, channels)          # once for all channels (one stacked FFT)
    spec = {c: spectra[c] for c in channels}

    def power(bins):
        """|X|² + |Y|² (|X|² for one channel) at the padded ``bins`` (a slice or indices): only these are read."""
        return sum(np.abs(s[bins]) ** 2 for s in spec.values())

    lo = int(np.ceil((f0 * (1 - SEARCH) - 2 * df) / f[1]))
    hi = int(np.floor((f0 * (1 + SEARCH) + 2 * df) / f[1]))
    k = lo + int(np.argmax(power(slice(lo, hi + 1))))
    a, b, c = np.log(np.maximum(power(slice(k - 1, k + 2)), 1e-300))
    den = a - 2 * b + c
    f_peak = (k + (float(np.clip(0.5 * (a - c) / den, -0.5, 0.5)) if den < 0 else 0.0)) * f[1]
    if len(channels) == 2:
        share, snr, _ = next(iter(slice_senses({ch: v[None, :] for ch, v in spec.items()}, f, PAD,
                                            np.array([[f_peak]])).values()))
        return f_peak, float(snr[0, 0]), float(share[0, 0])
    noise = float(np.median(power(k + NOISE_BINS)))
    return f_peak, float(power(slice(k, k + 1))[0] / max(noise, 1e-300)), np.nan


@lru_cache(maxsize=4)
def _window_and_bins(n: int, fs: float) -> tuple:
    """(Hann window (n,), frequencies Hz of the :data:`PAD`-times zero-padded spectrum's bins) of an n-sample run at
    ``fs`` Hz: the same for every run of a test, made once (read-only)."""
    win, f = np.hanning(n), np.fft.rfftfreq(PAD * n, 1.0 / fs)
    win.flags.writeable = False
    f.flags.writeable = False
    return win, f


def _measurable(run, f0: float) -> bool:
    """Whether the run's given 1× frequency ``f0`` Hz is measured: :data:`MIN_BINS` native bins above 0 Hz, the window
    searched and the noise bins beside it below Nyquist."""
    fs = float(run.sample_rate)
    df = fs / run.n_samples
    return bool(np.isfinite(f0) and f0 >= MIN_BINS * df and f0 * (1 + SEARCH) + 8 * df < fs / 2)


def run_spectra(run, channels, buffers: dict | None = None) -> dict:
    """channel -> the Hann-windowed spectrum of the run's ``channels`` (each less its mean) zero-padded :data:`PAD`
    times, on :func:`_window_and_bins`' bins: one transform of the channels stacked (the numbers of one
    ``rfft(x, n=PAD·n)`` each, written into one zero-padded array instead of a padded copy per channel).
    ``buffers``: a dict (shape -> zero-padded array) kept over the runs of a test, whose arrays are reused (their
    padding stays zero: only the first n samples of a row are written), or None."""
    n = run.n_samples
    win = _window_and_bins(n, float(run.sample_rate))[0]
    shape = (len(channels), PAD * n)
    padded = None if buffers is None else buffers.get(shape)
    if padded is None:                  # made once per shape (not a new zero-filled array per run to discard)
        padded = np.zeros(shape)
        if buffers is not None:
            buffers[shape] = padded
    for row, c in zip(padded, channels):
        np.multiply(np.asarray(run.signals[c], dtype=float) - np.mean(run.signals[c]), win, out=row[:n])
    return dict(zip(channels, sfft.rfft(padded, axis=-1)))


def line_reads(test, factors=(1.0,), other_keys=None) -> dict:
    """Per 1× line of :data:`LINES` recorded: (n_runs, 3) of :func:`run_line`'s (frequency Hz, SNR, co-rotating
    share) in each run at its given speed, nan where the run is not measured.  With ``factors`` other than (1.0,):
    {factor: those reads at the factor times each run's given speed}, every factor read on one transform of each
    run; ``other_keys``: the lines (of :data:`LINES`) read at the factors other than 1 (None: every one)."""
    f_given = np.abs(np.array([r.speed for r in test.runs], dtype=float)) / (2 * np.pi)
    keys = [key for key, (channels, _) in LINES.items() if any(all(r.usable(c) for c in channels) for r in test.runs)]
    read: dict = {(k, key): [] for k in factors for key in keys
                  if k == 1.0 or other_keys is None or key in other_keys}
    buffers: dict = {}
    for r, f0 in zip(test.runs, f_given):
        # every 1× line of a run is read on the same spectra, made once
        chans = [c for key in keys for c in LINES[key][0] if all(r.usable(x) for x in LINES[key][0])]
        spectra = run_spectra(r, chans, buffers) if chans and any(_measurable(r, k * f0) for k in factors) else {}
        for k, key in read:
            read[k, key].append(run_line(r, LINES[key][0], k * f0, spectra))
    out: dict = {k: {} for k in factors}
    for (k, key), v in read.items():
        out[k][key] = np.array(v, dtype=float).reshape(len(test.runs), 3)
    return out[1.0] if tuple(factors) == (1.0,) else out


class LineReads:
    """:func:`line_reads` of the last test it was called with, kept: the steps before the search (the column's check,
    the radial pairs' polarity, the runs' own speeds, :func:`rwadist.api.diagnose`) read the 1× lines of one test
    once, and the column's check reads the radial force's at :data:`WHOLE_FRACTIONS` of the given speed on the same
    transforms (:meth:`at`).  The same test is the same object: a step that changes a speed or a channel returns a new one,
    which is read anew."""

    def __init__(self) -> None:
        self._test: object = None
        self._reads: dict = {}

    def __call__(self, test) -> dict:
        return self.at(test, 1.0)

    def at(self, test, factor: float) -> dict:
        """The reads of ``test`` at ``factor`` (1.0 or one of :data:`WHOLE_FRACTIONS`: the radial force's alone) times
        its given speeds."""
        if test is not self._test:
            self._reads, self._test = line_reads(test, (1.0,) + WHOLE_FRACTIONS, ("radial_force",)), test
        return self._reads[factor]

    @classmethod
    def of(cls, test, reads: dict) -> "LineReads":
        """A LineReads holding ``reads`` (:func:`line_reads` of ``test``, read elsewhere) as ``test``'s."""
        out = cls()
        out._test, out._reads = test, {1.0: reads}
        return out


def line_ratios(test, reads: dict | None = None) -> dict:
    """Per 1× line of :data:`LINES` recorded: (ratio f_line/f_given (n_runs,), nan where the line was not
    measured; the runs' indices kept).  A pair's line counts where it stands PAIR_SNR over its noise and turns
    one way, the same way relative to the run's speed as the majority of such runs.  ``reads``: the test's
    :func:`line_reads`, when the caller has them."""
    out = {}
    f_given = np.abs(np.array([r.speed for r in test.runs], dtype=float)) / (2 * np.pi)
    sign = np.sign([r.speed for r in test.runs])
    reads = line_reads(test) if reads is None else reads
    for key, meas in reads.items():
        channels = LINES[key][0]
        f_line, snr, share = meas[:, 0], meas[:, 1], meas[:, 2]
        ok = np.isfinite(f_line) & (snr >= PAIR_SNR)
        if len(channels) == 2:
            pol = np.where(share >= POLARIZED, 1.0, np.where(share <= 1 - POLARIZED, -1.0, 0.0)) * sign
            ok &= pol != 0
            if ok.any():
                major = 1.0 if np.sum(pol[ok] > 0) >= np.sum(pol[ok] < 0) else -1.0
                ok &= pol == major
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(ok, f_line / f_given, np.nan)
        out[key] = ratio
    return out


def _scale(ratio: np.ndarray) -> tuple:
    """(k, spread, standard error, runs) of one line's ratios: median, 1.4826·MAD, spread/√runs (nan when none)."""
    r = ratio[np.isfinite(ratio)]
    if r.size == 0:
        return np.nan, np.nan, np.nan, 0
    k = float(np.median(r))
    spread = float(1.4826 * np.median(np.abs(r - k)))
    return k, spread, spread / np.sqrt(r.size), int(r.size)


def _unchecked(ratios: dict, spinning: int) -> str:
    """Why the radial force's 1× line cannot judge the speed column, in words: the data hold no Fx/Fy pair, there
    are fewer than :data:`MIN_RUNS` spinning runs, or the line was measured in too few of them."""
    if "radial_force" not in ratios:
        return "the data hold no radial force pair (Fx, Fy) to measure the imbalance's 1x line in"
    seen = int(np.sum(np.isfinite(ratios["radial_force"])))
    if spinning < MIN_RUNS:
        return (f"{spinning} spinning run{'s' if spinning != 1 else ''}: the imbalance's radial-force 1x line is judged "
                f"on {MIN_RUNS} runs at least")
    return (f"the imbalance's radial-force 1x line was measured in {seen} of {spinning} spinning runs (at least "
            f"{max(MIN_RUNS, int(np.ceil(0.5 * spinning)))} needed: it stands {PAIR_SNR:g}x over the noise and turns "
            "one way there)")


def check_record(test, reads: LineReads | None = None, whole_factors: bool = True) -> dict:
    """What the 1× lines say of a steady test's speed column (module docstring): a JSON-ready dict with
    ``lines`` (per line measured: k, spread, runs), ``scale`` (the common k, or None when none is judged),
    ``scaled`` (True when the column is to be multiplied by ``scale``), ``agreement_rel`` (the RMS over the
    lines' runs of r/k − 1 about the k applied, 1 when not scaled) and ``text`` (one sentence); {} for a
    test whose speeds are a sweep's slices (``meta["slicing"]``) or with no spinning run.  ``reads``: a
    :class:`LineReads` shared with the steps after this one, or None.  ``whole_factors``: when the radial force's 1×
    line is not read at the given speed, whether the column is tried at :data:`WHOLE_FACTORS` of it
    (:func:`_whole_factor`)."""
    if (getattr(test, "meta", None) or {}).get("slicing") is not None:
        return {}
    spinning = int(np.sum(np.abs([r.speed for r in test.runs]) > 0))
    if spinning == 0:
        return {}
    reads = reads or LineReads()
    ratios = line_ratios(test, reads(test))
    stats = {key: _scale(r) for key, r in ratios.items()}
    # a wheel without an axial 1x still has noise peaks 10x over the median in some runs, at random in the window
    # (and another line read in under FEW_RUNS of the radial force's runs is such peaks: nuM's wheel, no axial 1x,
    # read "axial force 1.029 in 4 runs" of 40 and called the 1x lines in disagreement)
    most = stats["radial_force"][3] if "radial_force" in stats else 0
    judged = {key: s for key, s in stats.items() if s[3] >= MIN_RUNS
              and (key == "radial_force" or (s[1] < CLUSTERED * 1.4826 * SEARCH / 2 and s[3] >= FEW_RUNS * most))}
    lines = {key: {"k": round(s[0], 7), "spread_rel": round(s[1], 7), "runs": s[3]} for key, s in judged.items()}
    rec: dict = {"lines": lines, "scale": None, "scaled": False, "runs": spinning}
    force = judged.get("radial_force")
    if force is None or force[3] < 0.5 * spinning:
        why = _unchecked(ratios, spinning)
        rec["text"] = why + ": the speed column is not checked"
        return (_whole_factor(test, spinning, rec, why, reads, "radial_torque" in ratios) if whole_factors else None) \
            or rec
    pooled = np.concatenate([r[np.isfinite(r)] for key, r in ratios.items() if key in judged])
    k, _, se, _ = _scale(pooled)
    se = max(se, max(s[2] for s in judged.values()))
    rec["scale"] = round(k, 7)
    apart = [key for key, s in judged.items()
             if abs(s[0] - force[0]) > max(AGREE, SIGMAS * float(np.hypot(s[2], force[2])))]
    rf = ratios["radial_force"][np.isfinite(ratios["radial_force"])]
    nearer = float(np.mean(np.abs(rf - k) < np.abs(rf - 1.0)))
    off = abs(k - 1.0) > max(SCALE_FLOOR, SIGMAS * se)
    rec["scaled"] = bool(off and not apart and nearer >= CONSISTENT)
    about = k if rec["scaled"] else 1.0
    rec["agreement_rel"] = round(float(np.sqrt(np.mean((pooled / about - 1.0) ** 2))), 7)
    rec["runs_off"], rec["runs_doubtful"] = _runs_off(test, ratios, list(judged), about,
                                                      float(1.4826 * np.median(np.abs(pooled / about - 1))),
                                                      {key: v[:, 1] for key, v in reads(test).items()})
    if rec["runs_off"]:
        # the agreement of the runs that keep the column's speed
        off = {x["run"] for x in rec["runs_off"]}
        kept = np.concatenate([np.delete(ratios[key], list(off)) for key in judged])
        kept = kept[np.isfinite(kept)]
        rec["agreement_rel"] = round(float(np.sqrt(np.mean((kept / about - 1.0) ** 2))), 7)
    names = ", ".join(LINES[key][1] for key in judged)
    each = "; ".join(f"{LINES[key][1]} {s[0]:.6g} in {s[3]} runs" for key, s in judged.items())
    rec = _with_runs_off(rec, rec["runs_off"])
    if rec["runs_doubtful"]:
        rec["text_doubtful"] = "; ".join(
            f"run {x['run_name']}: its 1x lines ({x['lines']}) read at {x['ratio']:.6g} of the speed column's "
            f"{x['given_rpm']:.6g} rpm, but a line stands at the given speed too: the one read is something else turning "
            "near 1x (a neighbouring wheel, a fan), its speed kept as given" for x in rec["runs_doubtful"])
    if rec["scaled"]:
        rec["text"] = (f"speed column scaled by {k:.6g}: the 1x lines ({names}) sit at {k:.6g} of the "
                       f"given speed in {force[3]} of {spinning} spinning runs ({each}), spread "
                       f"{100 * rec['agreement_rel']:.3g} % RMS about it; every run's speed multiplied by {k:.6g}")
    elif apart:
        rec["text"] = (f"the 1x lines disagree ({each}): the speed column is left as given")
        rec["lines_apart"] = apart
    else:
        rec["text"] = (f"the 1x lines ({names}) agree with the given speed: {each}, "
                       f"{100 * rec['agreement_rel']:.3g} % RMS")
    if whole_factors:
        # the rotor's 2x (or 3x, 4x) lines read where a column 2 (3, 4) times the rotor's speed puts the 1x (or, a few
        # per cent off it, a bearing line there: family wheel 0's h 3.08 read as a column 2.7 % slow)
        why = f"lines stand at the given speed's 1x ({each})"
        return _whole_factor(test, spinning, rec, why, reads, "radial_torque" in ratios, WHOLE_FRACTIONS) or rec
    return rec


#: speed columns off the rotor's speed by a whole factor, (true speed / the column's, what does it): the imbalance's 1×
#: lines then sit at that factor of the column's speed, outside the window read about it
WHOLE_FACTORS = tuple((1.0 / n, f"a tach giving {n} pulses a turn counted as turns") for n in TACH_PULSES) + (
    (60.0 / (2.0 * np.pi), "a column in rad/s written as rpm"),)
#: the 1× lines read at a whole factor must give it within this (relative): a line near it (a cage at 0.49) is no
#: unit's or tach's exact factor
WHOLE_FACTOR_TOL = 2.0e-3


def _whole_factor(test, spinning: int, given: dict, why: str, reads: LineReads, torques: bool,
                  factors=None) -> dict | None:
    """The record of a speed column that reads the rotor's speed times a whole factor (of :data:`WHOLE_FACTORS`), or
    None.  ``given``: :func:`check_record`'s record at the given speed, ``why`` what it read there, in words;
    ``reads`` the test's :class:`LineReads`; ``torques`` whether the radial torques are recorded; ``factors`` those
    tried (true speed / the column's; None: every one).  Read at a factor, the 1× lines must pass :func:`check_record`'s every rule
    (the radial force's in half the spinning runs, every line read at one scale) at a scale within
    :data:`WHOLE_FACTOR_TOL` of 1, with the radial torque's among them when the torques are recorded (the imbalance
    is static and dynamic: its 1x stands in both radial pairs, turning with the rotor); of the factors that pass, the
    lowest is taken (a column at the rotor's speed holds its 2x lines too, so lines at the given 1x and at half of it
    make the half the rotor's; family wheel 4 with a 4-pulse tach reads its 1x and 2x at a quarter and a half of the
    column); the record's scale is the factor times that scale.  The new-user trial (session 52): a tach's 2 pulses a turn counted as turns put the
    imbalance at h 0.5 of the column, which the search named "a subharmonic: a rub" with U_s 100 times low, I_zz/I_rr
    0.65 for 1.3, and the error at the clean level; nothing was said."""
    passed = []
    for k, what in WHOLE_FACTORS:
        if factors is not None and k not in factors:
            continue
        scaled = type(test)([replace(r, speed=r.speed * k) for r in test.runs], dict(test.meta or {}))
        if k in WHOLE_FRACTIONS:
            # the radial force's line read at the fraction with the given speed's (the same transforms) judges first
            force = check_record(scaled, LineReads.of(scaled, reads.at(test, k)), whole_factors=False)
            if force.get("scale") is None or abs(force["scale"] - 1.0) > WHOLE_FACTOR_TOL:
                continue
        rec = check_record(scaled, LineReads.of(scaled, line_reads(test, (k,))[k]), whole_factors=False)
        if rec.get("scale") is None or abs(rec["scale"] - 1.0) > WHOLE_FACTOR_TOL or rec.get("lines_apart"):
            continue
        if torques and "radial_torque" not in rec["lines"]:
            continue
        passed.append((k, what, rec))
    if not passed:
        return None
    k, what, rec = min(passed, key=lambda x: x[0])
    scale = k * rec["scale"]
    each = "; ".join(f"{LINES[key][1]} {v['k'] * k:.6g} in {v['runs']} runs" for key, v in rec["lines"].items())
    return {"lines": given["lines"], "scale": round(scale, 7), "scaled": True, "runs": spinning,
            "agreement_rel": rec["agreement_rel"], "runs_off": [], "runs_doubtful": [],
            "whole_factor": {"factor": round(k, 7), "cause": what, "lines_at_factor": rec["lines"]},
            "text": (f"speed column scaled by {scale:.6g}: {why}, but the imbalance's 1x lines sit at {k:.6g} of the "
                     f"given speed ({each}; {100 * rec['agreement_rel']:.3g} % RMS about it){' in both radial pairs' if torques else ''}"
                     f": {what}; every run's speed multiplied by {scale:.6g}")}


#: a 1× line other than the radial force's is judged when read in this share of the runs the radial force's is read in
FEW_RUNS = 0.25
#: variance inflation of a Hann-windowed frequency estimate over the rectangular window's Cramér-Rao bound
HANN_LOSS = 1.5


def tone_sigma(df: float, snr) -> np.ndarray:
    """Standard deviation (Hz) of the frequency of one tone in white noise read in a Hann-windowed record of bin
    ``df`` Hz: the Cramér-Rao bound ``df·√2/(2π·√SNR)`` inflated by :data:`HANN_LOSS`, SNR the line's power over
    the mean noise power of a bin (``snr``, over the local median, times ln 2); any shape of ``snr``."""
    snr_mean = np.maximum(np.asarray(snr, dtype=float) * np.log(2.0), 1e-12)
    return df * np.sqrt(2.0 * HANN_LOSS) / (2 * np.pi * np.sqrt(snr_mean))


def _with_runs_off(rec: dict, runs_off: list) -> dict:
    """``rec`` with ``runs_off`` (and its sentence ``text_runs``, none when empty)."""
    out = {k: v for k, v in rec.items() if k != "text_runs"}
    out["runs_off"] = runs_off
    if runs_off:
        out["text_runs"] = "; ".join(
            f"run {x['run_name']}: the speed column reads {x['given_rpm']:.6g} rpm, its 1x lines ({x['lines']}) sit at "
            f"{x['ratio']:.6g} of it: its speed taken as {x['speed_rpm']:.6g} rpm" for x in runs_off)
    return out


def _runs_off(test, ratios: dict, judged: list, about: float, spread: float,
              snrs: dict | None = None) -> tuple[list, list]:
    """(runs whose own speed reads off, runs whose lines read off beside a line at the given speed): two 1× lines or
    more measured in the run (of ``judged``) agree with each other (within :data:`AGREE` or :data:`SIGMAS` times
    ``spread``, the runs' scatter of r/k) at a ratio to the speed applied (``about`` × given: ``ratio`` is to the given
    speed) off 1 beyond :data:`SCALE_FLOOR`, :data:`SIGMAS` × ``spread`` and :data:`SIGMAS` × the run's own
    uncertainty (its lines' :func:`tone_sigma` at their SNRs, ``snrs``, combined: the new-user trial nuM's runs at 300
    and 523 rpm, their 1x lines 20 dB over the noise, read 0.1-0.4 % off their exact columns and were moved) (a tach
    glitch, a run's speed typed wrong: trial15's one run 1 % high, silent).  One line alone could be a fixed line passing near 1×; two of the rotor's 1×
    lines at one ratio are the rotor's speed, unless a line stands at the given speed as well
    (:func:`_line_at_given`): a run whose column is wrong holds nothing there, and the peak read is then another
    source turning near 1× and stronger than the wheel's own (a neighbouring wheel on the plate: review15's 0.2 N at
    2370 rpm moved a run given as 2307.7 rpm by +2.7 %); such a run is listed in the second list, not moved.
    JSON-ready dicts."""
    out: list = []
    doubtful: list = []
    tol = max(SCALE_FLOOR, SIGMAS * spread)
    for i, run in enumerate(test.runs):
        r = np.array([ratios[key][i] for key in judged if np.isfinite(ratios[key][i])]) / about
        # a run's own 1x lines are read no closer than RUN_BIN_FLOOR of its bin (neighbouring lines' leakage, noise)
        resolution = RUN_BIN_FLOOR * float(run.sample_rate) / run.n_samples / max(about * abs(run.speed) / (2 * np.pi),
                                                                                  1e-300)
        if (r.size < 2 or abs(float(np.median(r)) - 1.0) <= max(tol, resolution)
                or np.ptp(r) > max(AGREE, SIGMAS * spread, 2 * resolution)):
            continue
        if snrs is not None:
            snr = np.array([snrs[key][i] for key in judged if np.isfinite(ratios[key][i])])
            df = float(run.sample_rate) / run.n_samples
            sigma = tone_sigma(df, snr) / max(about * abs(run.speed) / (2 * np.pi), 1e-300)
            if abs(float(np.median(r)) - 1.0) <= SIGMAS / float(np.sqrt(np.sum(sigma ** -2.0))):
                continue
        k = float(np.median(r))
        given = float(abs(run.speed)) * 30 / np.pi
        read = [key for key in judged if np.isfinite(ratios[key][i])]
        f_given = about * abs(run.speed) / (2 * np.pi)
        entry = {"run": i, "run_name": run.name or str(i), "given_rpm": round(given, 6),
                 "ratio": round(k * about, 7), "speed_rpm": round(given * about * k, 6),
                 "lines": ", ".join(LINES[key][1] for key in read)}
        near = [test.runs[j] for j in np.argsort(np.abs(np.abs([x.speed for x in test.runs]) - abs(run.speed)))
                if j != i and test.runs[j].speed != 0][:FIXED_CHECK_RUNS]
        at_given = any(_line_at_given(run, LINES[key][0], f_given, f_given * ratios[key][i] / about, near)
                       for key in read)
        (doubtful if at_given else out).append(entry)
    return out, doubtful


#: a run's own 1× lines are read off its given speed only beyond this share of its native bin (over the 1×
#: frequency): clean family wheel 2's lowest run (300 rpm, 5 Hz, bins of 0.244 Hz) read its three 1× lines together at
#: +0.0032-0.0040 Hz (0.013-0.016 bins), and was called a tach glitch at 1.00079
RUN_BIN_FLOOR = 0.03


#: a line at a run's given 1× frequency, beside the one read, counts within this power ratio of it (a Hann window's
#: highest sidelobe is 31.5 dB down: a sidelobe of the peak read never counts)
GIVEN_LINE_SHARE = 0.01


#: runs of the nearest speeds read at the frequency of a line found at a run's given 1× (:func:`_line_at_given`)
FIXED_CHECK_RUNS = 4


def _stands_at(run, channels: tuple, f_hz: float) -> tuple | None:
    """(frequency Hz, power, noise, the padded power spectrum) of the local maximum of ``channels``' zero-padded power (:func:`run_line`'s) within
    one native bin of ``f_hz`` in ``run``, or None when the bins there hold no local maximum (or the run lacks a
    channel); the noise is the median at ±4..8 native bins."""
    if not all(run.usable(c) for c in channels):
        return None
    f = _window_and_bins(run.n_samples, float(run.sample_rate))[1]
    power = sum(np.abs(s) ** 2 for s in run_spectra(run, channels).values())
    k0 = int(round(f_hz / f[1]))
    lo, hi = max(k0 - PAD, 1), min(k0 + PAD, power.size - 2)
    if hi < lo:
        return None
    k = lo + int(np.argmax(power[lo:hi + 1]))
    if not (power[k] > power[k - 1] and power[k] > power[k + 1]):
        return None
    noise = float(np.median(power[np.clip(k + NOISE_BINS, 0, power.size - 1)]))
    return float(f[k]), float(power[k]), noise, power


def _line_at_given(run, channels: tuple, f_given: float, f_read: float, others=()) -> bool:
    """Whether ``channels`` of ``run`` hold a line at the given 1× frequency ``f_given`` (Hz) besides the peak read at
    ``f_read``: a local maximum of the zero-padded power (:func:`run_line`'s) within one native bin of ``f_given``, two
    native bins or more from ``f_read``, :data:`speed_scale.PAIR_SNR` over the noise there and within
    :data:`GIVEN_LINE_SHARE` of the peak read's power, and not a fixed line: it does not stand at the same frequency
    in most of ``others`` (runs of other speeds, their own 1× two native bins or more from it; a 50 Hz pickup at a
    run typed 3000 rpm is no rotor turning at the given speed)."""
    fs = float(run.sample_rate)
    df = fs / run.n_samples
    if abs(f_read - f_given) < 2 * df:
        return False
    got = _stands_at(run, channels, f_given)
    if got is None or abs(got[0] - f_read) < 2 * df:
        return False
    f_k, p_k, noise, power = got
    peak = float(power[int(round(f_read / _window_and_bins(run.n_samples, fs)[1][1]))])
    if not (p_k >= PAIR_SNR * noise and p_k >= GIVEN_LINE_SHARE * peak):
        return False
    # the same frequency in runs of other speeds (their 1x away from it): a line there too is fixed, not the rotor's
    seen = [_stands_at(o, channels, f_k) for o in others
            if abs(abs(o.speed) / (2 * np.pi) - f_k) >= 2 * float(o.sample_rate) / o.n_samples]
    fixed = [x is not None and abs(x[0] - f_k) <= df and x[1] >= PAIR_SNR * x[2] for x in seen]
    return not (len(fixed) >= 2 and np.mean(fixed) >= 0.5)


def checked(test, reads: LineReads | None = None, confirm=None) -> tuple:
    """(test, record): ``test`` with every run's speed multiplied by the scale its 1× lines give when
    :func:`check_record` calls the column off, and each run whose own 1× lines put it off (``runs_off``) at the
    speed they give (a copy; its meta is left alone), else ``test`` itself, untouched.  ``reads``: a
    :class:`LineReads` shared with the steps after this one, or None.  ``confirm(test, runs) -> runs``: the runs
    off (indices) whose own lines' finer reading confirms it (:func:`rwadist.speed_runs.confirmed_off`), or None."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        rec = check_record(test, reads)
        if confirm is not None and rec.get("runs_off") and not rec.get("scaled"):
            kept = set(confirm(test, [x["run"] for x in rec["runs_off"]]))
            rec = _with_runs_off(rec, [x for x in rec["runs_off"] if x["run"] in kept])
    scale = rec["scale"] if rec.get("scaled") else 1.0
    each = {x["run"]: x["ratio"] for x in rec.get("runs_off", [])}
    if scale == 1.0 and not each:
        return test, rec
    return type(test)([replace(r, speed=r.speed * each.get(i, scale)) for i, r in enumerate(test.runs)],
                      dict(test.meta or {})), rec


#: units a speed column labelled rpm is mistaken for, and what multiplies their values into rpm
MISREAD_UNITS = (("rev/s (Hz)", 60.0), ("rad/s", 60.0 / (2 * np.pi)))
#: a misread unit is named when the imbalance's line sits this close to the unit's speed (relative: the thesis's B
#: wheel's first radial line is at h 0.99; the units' factors are 6.3 times apart)
UNIT_MATCH = 0.02


def misread_unit(test) -> dict | None:
    """The unit a speed column given as rpm was written in, when the imbalance's radial-force 1× line says so: the
    Fx/Fy pair's strongest line stands :data:`PAIR_SNR` over its noise within :data:`UNIT_MATCH` of the column's value
    read in that unit (×60 for rev/s, ×60/2π for rad/s, :data:`MISREAD_UNITS`) in at least :data:`MIN_RUNS` and half
    of the spinning runs, and in fewer runs at the column's value read in rpm.  A dict (``unit``, ``factor`` to rpm,
    ``runs`` found, ``spinning``), or None (the column reads as rpm, or nothing tells).  Read only when a fit comes
    out empty: a column in rev/s puts the wheel's lines at 60 times their harmonic numbers, beyond the fit's band."""
    spinning = [r for r in test.runs if np.isfinite(r.speed) and r.speed != 0]
    if len(spinning) < MIN_RUNS or not all(r.usable(c) for r in spinning for c in ("Fx", "Fy")):
        return None

    def found(factor: float) -> int:
        hits = 0
        for run in spinning:
            f0 = factor * abs(run.speed) / (2 * np.pi)
            f_line, snr, _ = run_line(run, ("Fx", "Fy"), f0)
            hits += bool(np.isfinite(f_line) and snr >= PAIR_SNR and abs(f_line / f0 - 1.0) < UNIT_MATCH)
        return hits

    as_rpm = found(1.0)
    for unit, factor in MISREAD_UNITS:
        hits = found(factor)
        if hits >= max(MIN_RUNS, 0.5 * len(spinning)) and hits > as_rpm:
            return {"unit": unit, "factor": factor, "runs": hits, "spinning": len(spinning)}
    return None
