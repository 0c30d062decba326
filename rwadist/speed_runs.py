"""Each run's own speed from its own 1× lines (issue 33, item 5: a speed column slightly off in each run).

A steady run's speed column can be off by a little in every run (a tach read once per run, a speed controller's
set-point printed instead of the speed reached): trial 16's runs each at a constant speed 0.25 % rms off their column
put a line at h 6.16 of 5000 rpm 1.3 Hz (5 bins of a 4 s record) beside the model's, 30-58x the clean error, with
nothing said.  :mod:`rwadist.speed_check` moves a whole test (a common scale) or a run whose 1× lines sit off by more
than the runs' scatter; a scatter of every run about its column is below that test by construction.  Here each run is
judged against its *own* uncertainty instead:

* the imbalance is at exactly 1× the rotor speed, on every wheel: the radial force pair, the radial torque pair and
  the axial force are read where :func:`rwadist.speed_check.line_ratios` counts them (they stand
  :data:`rwadist.speed_scale.PAIR_SNR` over the local noise, a pair turning one way, the way of the majority);
* each line's frequency is refined to well below a bin by maximising the exact Hann-windowed transform of the run
  (:func:`zoom_peak`: a three-point log parabola at :data:`ZOOM` of a native bin, twice, about the padded peak), with
  its standard deviation from the Cramér-Rao bound of a tone in white noise at the line's SNR
  (:func:`line_sigma`: ``df·√2 / (2π·√SNR)``, inflated by :data:`rwadist.speed_check.HANN_LOSS` for the window), and a floor
  :data:`REL_FLOOR` (what the neighbouring lines' leakage leaves);
* the run's relative speed error is the lines' inverse-variance mean of ``f_line/f_applied − 1``; its standard error
  is inflated by the lines' own disagreement (√(χ²/dof) when above 1).

A run's speed is taken from its lines only when at least two lines are read in it, they agree (χ²/dof within
:data:`AGREE_CHI2`: one line pulled by a fixed line passing near 1× is not the rotor; of three, one that the other two
agree without is left out, the radial force's kept: :func:`_agreeing`), and the mean is off its column by more than
:data:`SIGMAS` standard errors.  On true speeds every run's error is within its uncertainty and nothing
moves: the test is returned untouched (the identical object).  The speed within a run is taken as constant: the
refined frequency is the run's mean speed (a wander within the run, e.g. trial 16's 0.3 % Ornstein-Uhlenbeck, widens
the lines and is not corrected here).

Units: Hz for frequencies, rad/s for the runs' speeds, dimensionless relative errors.
"""
from __future__ import annotations

import warnings
from dataclasses import replace
from functools import lru_cache

import numpy as np

from .dft import BlockedRecords, blocked_records, demeaned_windowed, windowed_dft, windowed_dfts
from .speed_check import LINES, LineReads, _window_and_bins, line_ratios, tone_sigma

#: spacing, in native bins, of the three exact transforms about a peak whose log parabola refines it
ZOOM = 0.05
#: relative floor of one line's frequency uncertainty (leakage of the run's other lines, the window's bias)
REL_FLOOR = 1.0e-5
#: standard errors by which a run's mean speed must be off its column to be taken from its lines
SIGMAS = 6.0
#: χ²/dof of a run's lines about their mean above which they are called in disagreement (one is something else)
AGREE_CHI2 = 9.0
#: the runs' lines needed to judge a run's speed
MIN_LINES = 2
#: runs (and half of those judged) whose lines are all wider than a tone for the speed to be called wandering
MIN_WIDE = 3
#: offsets (native bins) about a line's refined peak at which its transform is compared with one steady tone's
LOBE = np.array([-2.0, -1.5, -1.0, -0.5, 0.5, 1.0, 1.5, 2.0])
#: standard deviation (native bins) of a peak per unit √(share of its main lobe's power that is not one tone): a
#: tone with a neighbour 0.3-4 bins away (sidebands of any phase, 1-20 % of it) is biased at most 2.4 bins x √share
NEIGHBOUR_GAIN = 0.5
#: multiple of the noise's expected share of the lobe's residual left to the noise (beyond it: a neighbour)
NOISE_MARGIN = 3.0


def _windowed(run, channels: tuple) -> np.ndarray:
    """(n, channels) of the run's Hann-windowed samples, each channel less its mean (:func:`_power`'s records)."""
    win = _window_and_bins(run.n_samples, float(run.sample_rate))[0]
    return demeaned_windowed([run.signals[c] for c in channels], win).T


def _power(y: np.ndarray, fs: float, freqs: np.ndarray) -> np.ndarray:
    """Σ over the columns of ``y`` (:func:`_windowed`) of |Σ_k y_k e^(−i2πf k/fs)|² at ``freqs`` Hz: the exact
    transform (:func:`rwadist.dft.windowed_dft`: its kernel a product of two short tables of phasors, not one
    complex exponential per sample)."""
    x = windowed_dft(y, fs, freqs)                                                      # (F, channels)
    return np.sum(x.real ** 2 + x.imag ** 2, axis=1)


def _transform(run, channels: tuple, freqs: np.ndarray) -> np.ndarray:
    """Σ over ``channels`` of |X(f)|² of the run's Hann-windowed samples (less their mean) at ``freqs`` Hz: the exact
    transform (no bins)."""
    return _power(_windowed(run, channels), float(run.sample_rate), np.asarray(freqs, dtype=float))


def zoom_peak(run, channels: tuple, f_peak: float, y: np.ndarray | None = None) -> tuple:
    """(frequency Hz, curvature 1/Hz²) of the maximum of ``channels``' exact windowed power near ``f_peak`` (a padded
    spectrum's peak, :func:`rwadist.speed_check.run_line`): a log parabola through the transform at ``f ± ZOOM``
    native bins, twice (each step kept within one spacing); the curvature is the last parabola's d²(ln P)/df² (nan
    when the three points do not bend down); one record of :func:`zoom_peaks`.  ``y``: :func:`_windowed` of ``channels``,
    or None (made here)."""
    fs = float(run.sample_rate)
    y = _windowed(run, channels) if y is None else y
    f, curv = zoom_peaks(np.asarray(y, dtype=float)[None], fs, np.array([float(f_peak)]), ZOOM * fs / run.n_samples)
    return float(f[0]), float(curv[0])


def zoom_peaks(ys: "BlockedRecords | np.ndarray", fs: float, f_peaks: np.ndarray, step: float) -> tuple:
    """(frequencies Hz, curvatures 1/Hz²) of :func:`zoom_peak` of R records at once: ``ys``, each record's
    :func:`_windowed` channels (one sample rate ``fs`` Hz and length), (R, n, K) or in the layout of
    :func:`rwadist.dft.blocked_records`,
    ``f_peaks`` (R,) their padded peaks, ``step`` the spacing Hz (:data:`ZOOM` native bins).  Each of the two parabola
    steps is one :func:`rwadist.dft.windowed_dfts` of the records still refined (each record at its own three
    frequencies, its own products and sums: the numbers of one record at a time) instead of one transform per record
    and step."""
    f = np.asarray(f_peaks, dtype=float).copy()
    curv = np.full(f.size, np.nan)
    live = np.arange(f.size)
    for _ in range(2):
        if not live.size:
            break
        freqs = f[live, None] + np.array([-step, 0.0, step])[None, :]
        part = ys if live.size == len(ys) else BlockedRecords(ys.values[live], ys.n, ys.channels, ys.block) \
            if isinstance(ys, BlockedRecords) else ys[live]
        x = windowed_dfts(part, fs, freqs)                                                  # (r, 3, K)
        a, b, c = np.log(np.maximum(np.sum(x.real ** 2 + x.imag ** 2, axis=2), 1e-300)).T
        den = a - 2 * b + c
        bent = den < 0
        curv[live[~bent]] = np.nan
        live, a, c, den = live[bent], a[bent], c[bent], den[bent]
        curv[live] = den / step ** 2
        f[live] += step * np.clip(0.5 * (a - c) / den, -1.0, 1.0)
    return f, curv


@lru_cache(maxsize=8)
def _tone_curvature(n: int, fs: float) -> float:
    """:func:`tone_curvature` of a run of ``n`` samples at ``fs`` Hz (the same for every run of a test: made once)."""
    win = _window_and_bins(n, fs)[0]
    t = np.arange(n) / fs
    mean = float(np.sum(win * t) / np.sum(win))
    return float(-8 * np.pi ** 2 * np.sum(win * (t - mean) ** 2) / np.sum(win))


def tone_curvature(run) -> float:
    """d²(ln P)/df² (1/Hz²) at the peak of one steady tone's Hann-windowed power: −8π² times the variance of the
    time under the window's weights (the second-order expansion of |Σ w_n e^(−i2πu t_n)|² about u = 0)."""
    return _tone_curvature(int(run.n_samples), float(run.sample_rate))


def width_rel(curv: float, tone: float, f_line: float) -> float:
    """A line's relative width beyond a steady tone's: √(1/|curv| − 1/|tone|)/f_line (a Gaussian line's variance
    added to the window's), 0 when the line is no wider than a tone, nan when ``curv`` is."""
    if not np.isfinite(curv):
        return np.nan
    return float(np.sqrt(max(0.0, -1.0 / curv + 1.0 / tone)) / f_line)


def line_sigma(run, snr: float, f_line: float, lobe_share: float = 0.0) -> float:
    """Standard deviation (Hz) of a line's refined frequency: the Cramér-Rao bound of one tone in white noise,
    ``df·√2/(2π·√SNR)`` with SNR the line's power over the mean noise power of a bin (the local median / ln 2),
    inflated by :data:`rwadist.speed_check.HANN_LOSS`, with the floor :data:`REL_FLOOR` · ``f_line``; and, in quadrature, the pull of a
    neighbour inside the window's main lobe: :data:`NEIGHBOUR_GAIN` · df · √(``lobe_share`` less the noise's expected
    share, :func:`lobe_shares`): speed sidebands 1 bin from a 1× line moved its peak 0.086 % with its Cramér-Rao
    bound at 0.0056 % (the new-user trial's runs "off the column" at 720 rpm)."""
    df = float(run.sample_rate) / run.n_samples
    snr_mean = max(snr * np.log(2.0), 1e-12)
    crb = float(tone_sigma(df, snr))
    excess = max(0.0, lobe_share - NOISE_MARGIN * _lobe_noise(run.n_samples, float(run.sample_rate)) / snr_mean)
    return float(np.hypot(max(crb, REL_FLOOR * f_line), NEIGHBOUR_GAIN * df * np.sqrt(excess)))


@lru_cache(maxsize=8)
def _lobe_kernel(n: int, fs: float) -> np.ndarray:
    """(len(LOBE),) the transform of a steady tone at :data:`LOBE` native bins from it, over its value at the tone: the
    window's own transform (:func:`_window_and_bins`' window) at those offsets (read-only)."""
    win = _window_and_bins(n, fs)[0]
    w = windowed_dft(np.asarray(win, dtype=float)[:, None], fs, np.concatenate(([0.0], LOBE * fs / n)))[:, 0]
    out = w[1:] / w[0]
    out.flags.writeable = False
    return out


def _lobe_noise(n: int, fs: float) -> float:
    """Expected share of the lobe's residual (:func:`lobe_shares`) per unit of the noise's mean power over the line's:
    each offset's noise and the tone's scaled copy of the peak's, Σ(1 + |W(δ)/W(0)|²)."""
    return float(np.sum(1.0 + np.abs(_lobe_kernel(n, fs)) ** 2))


def lobe_shares(ys: "BlockedRecords | np.ndarray", fs: float, n: int, f: np.ndarray) -> np.ndarray:
    """(R,) share of each record's power in the window's main lobe about its refined peak ``f`` (R,) Hz that one tone
    does not explain: Σ over :data:`LOBE` and the channels of |X(f + δ) − X(f)·W(δ)/W(0)|² over Σ|X(f)|² (``ys`` as in
    :func:`zoom_peaks`).  0 for a tone alone; the noise adds about :func:`_lobe_noise` over the SNR; a line beside it
    in the lobe (sidebands, a fixed line passing) adds its own share."""
    df = fs / n
    x = windowed_dfts(ys, fs, f[:, None] + np.concatenate(([0.0], LOBE * df))[None, :])      # (R, 1 + len(LOBE), K)
    resid = x[:, 1:, :] - x[:, :1, :] * _lobe_kernel(n, fs)[None, :, None]
    peak = np.sum(np.abs(x[:, 0, :]) ** 2, axis=1)
    return np.sum(np.abs(resid) ** 2, axis=(1, 2)) / np.maximum(peak, 1e-300)


def run_errors(test, reads: LineReads | None = None) -> list:
    """Per run: None (not judged) or a dict ``rel`` (the lines' mean of f_line/f_applied − 1), ``se`` (its standard
    error, with the lines' width added in quadrature where every line of the run is wider than a tone beyond
    :data:`SIGMAS` of its own frequency's standard deviation), ``chi2`` (per degree of freedom), ``lines`` (the keys
    of :data:`rwadist.speed_check.LINES` read), ``width`` (that relative width, :func:`width_rel`'s median, else 0).
    ``reads``: a :class:`rwadist.speed_check.LineReads` shared with the steps before this one, or None."""
    read = (reads or LineReads())(test)     # each line's peak and SNR, read once for the ratios and the refinement
    ratios = line_ratios(test, read)
    judged = {i: [k for k, r in ratios.items() if np.isfinite(r[i])] for i in range(len(test.runs))}
    judged = {i: keys for i, keys in judged.items() if len(keys) >= MIN_LINES}
    zoomed = _zoomed(test, judged, read)
    out: list = []
    for i, run in enumerate(test.runs):
        f0 = abs(float(run.speed)) / (2 * np.pi)
        keys = judged.get(i)
        if keys is None:
            out.append(None)
            continue
        rel, sig, sig_tone, wid = [], [], [], []
        tone = tone_curvature(run)
        for k in keys:
            snr = float(read[k][i, 1])
            f, curv, share = zoomed[i, k]
            rel.append(f / f0 - 1.0)
            sig.append(line_sigma(run, snr, f, share) / f0)
            sig_tone.append(line_sigma(run, snr, f) / f0)
            wid.append(width_rel(curv, tone, f))
        use = _agreeing(keys, np.array(rel), 1.0 / np.array(sig) ** 2)
        rel_a, w = np.array(rel)[use], 1.0 / np.array(sig)[use] ** 2
        mean, chi2 = _mean_chi2(rel_a, w)
        se = float(np.sqrt(1.0 / np.sum(w)) * np.sqrt(max(1.0, chi2)))
        # every line of the run wider than a steady tone beyond its own uncertainty: the speed moved within the run,
        # and the peak is its mean only to within the width
        # (beyond a steady tone's own uncertainty in the noise: a wandering line's lobe is not one tone either)
        widened = bool(np.all(np.array(wid)[use] > SIGMAS * np.array(sig_tone)[use]))
        width = float(np.median(np.array(wid)[use])) if widened else 0.0
        got = {"rel": mean, "se": float(np.hypot(se, width)), "chi2": chi2, "lines": [keys[j] for j in use],
               "width": width, "per_line": {k: (float(rel[j]), float(sig[j])) for j, k in enumerate(keys)}}
        if len(use) < len(keys):
            got["left_out"] = [k for j, k in enumerate(keys) if j not in use]
        out.append(got)
    return out


def confirmed_off(test, runs: list) -> list:
    """Of ``runs`` (indices into ``test.runs``: runs whose 1× lines' padded peaks put them off their column,
    :func:`rwadist.speed_check.checked`), those whose finer reading here (:func:`run_errors`: the exact transform's
    peak, its uncertainty with a neighbour in the window's main lobe) puts them off by more than :data:`SIGMAS`
    standard errors too, or that it cannot judge.  The new-user trial nuN: speed sidebands at ±0.03 of a 500-rpm
    run's 1× (0.25 Hz, half a bin of its 2-s record), unresolved, pulled both 1× peaks to 0.9948 of the column, and the
    run was taken at 497.4 rpm, "a tach glitch"."""
    errors = run_errors(type(test)([test.runs[i] for i in runs], dict(test.meta or {})))
    return [i for i, e in zip(runs, errors) if e is None or abs(e["rel"]) > SIGMAS * e["se"]]


def _mean_chi2(rel: np.ndarray, w: np.ndarray) -> tuple:
    """(inverse-variance mean, χ² per degree of freedom about it) of relative errors ``rel`` with weights ``w``."""
    mean = float(np.sum(w * rel) / np.sum(w))
    return mean, float(np.sum(w * (rel - mean) ** 2) / (len(rel) - 1))


def _agreeing(keys: list, rel: np.ndarray, w: np.ndarray) -> list:
    """Indices of the lines ``keys`` a run's speed is read from: all of them, or, when they disagree (χ²/dof over
    :data:`AGREE_CHI2`) and three or more are read, all but the one whose leaving out makes the rest agree, the radial
    force's line kept: two rotating lines that agree to a few ppm are the rotor, and a third pulled off them (an axial
    line beside another near 1x) is not (the new-user trial's runs 1.5 % fast: four of 25 not moved, their axial read
    off the radial force's and torque's, which agreed to 7e-6)."""
    every = list(range(len(keys)))
    if len(keys) < 3 or _mean_chi2(rel, w)[1] <= AGREE_CHI2:
        return every
    best = None
    for j, k in enumerate(keys):
        if k == "radial_force":
            continue
        rest = [i for i in every if i != j]
        chi2 = _mean_chi2(rel[rest], w[rest])[1]
        if chi2 <= AGREE_CHI2 and (best is None or chi2 < best[0]):
            best = (chi2, rest)
    return every if best is None else best[1]


def _demeaned(x) -> np.ndarray:
    """``x`` less its mean (float): what :func:`rwadist.dft.demeaned_windowed` multiplies by the window."""
    x = np.asarray(x, dtype=float)
    return x - x.mean()


def _zoomed(test, judged: dict, read: dict) -> dict:
    """(run, line key) -> :func:`zoom_peak` (frequency Hz, curvature 1/Hz²) and :func:`lobe_shares` of every line of ``judged`` (run -> the keys
    of its lines read, :data:`rwadist.speed_check.LINES`) from its padded peak in ``read``: the runs of one line, sample
    rate and length refined together (:func:`zoom_peaks`)."""
    groups: dict = {}
    for i, keys in judged.items():
        run = test.runs[i]
        for k in keys:
            groups.setdefault((k, run.n_samples, float(run.sample_rate)), []).append(i)
    out: dict = {}
    for (k, n, fs), rows in groups.items():
        # each channel less its mean, times the window (the numbers of :func:`_windowed`); a pair's in the transform's
        # layout (blocked_records), one channel's as the (R, n, 1) records whose blocks the transform reads in place
        # (the numbers of one run at a time: its product of a strided view rounds apart from a contiguous one)
        win = _window_and_bins(n, fs)[0]
        ys: BlockedRecords | np.ndarray
        if len(LINES[k][0]) == 1:
            ys = demeaned_windowed([test.runs[i].signals[LINES[k][0][0]] for i in rows], win)[:, :, None]
        else:
            ys = blocked_records([[_demeaned(test.runs[i].signals[c]) for c in LINES[k][0]] for i in rows], win)
        f, curv = zoom_peaks(ys, fs, np.array([float(read[k][i, 0]) for i in rows]), ZOOM * fs / n)
        share = lobe_shares(ys, fs, n, f)
        out.update({(i, k): (float(f[j]), float(curv[j]), float(share[j])) for j, i in enumerate(rows)})
    return out


def own_speeds(test, check: dict, reads: LineReads | None = None) -> tuple:
    """(test, check): ``test`` with each run whose own 1× lines put its mean speed off the speed applied (module
    docstring) at the speed they give, and ``check`` (:func:`rwadist.speed_check.check_record`'s record) with
    ``runs_speed``: method, the runs judged, their RMS relative error, the runs moved (name, given and taken rpm,
    relative correction and its standard error, lines), the runs off the column whose lines disagree (``runs_unsettled``:
    not moved, said) and one sentence ``text``; ``test`` itself, untouched, when no run moves.  Runs :func:`rwadist.speed_check.checked` already moved (``runs_off``) or doubted are left alone.
    ``reads``: a :class:`rwadist.speed_check.LineReads` shared with the steps before this one, or None."""
    if not check or not check.get("lines"):
        return test, check
    skip = {x["run"] for x in check.get("runs_off", []) + check.get("runs_doubtful", [])}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        errors = run_errors(test, reads)
    judged = {i: e for i, e in enumerate(errors) if e is not None and i not in skip}
    if not judged:
        return test, check
    wide = [e["width"] for e in judged.values() if e["width"] > 0]
    wander = len(wide) >= max(MIN_WIDE, 0.5 * len(judged))
    # a speed that wanders within the runs: a line's peak is not the run's mean speed (trial 16's 0.3 % wander read
    # 0.1 % RMS off the runs' means), and nothing is moved
    moved = {} if wander else {i: e for i, e in judged.items()
                               if e["chi2"] <= AGREE_CHI2 and abs(e["rel"]) > SIGMAS * e["se"]}
    rms = float(np.sqrt(np.mean([e["rel"] ** 2 for e in judged.values()])))
    rec = {"method": ("each run's mean speed from its own 1x lines (exact windowed transform's peak, weighted by "
                      "their SNR); taken where two lines or more agree and sit off the column beyond "
                      f"{SIGMAS:g} standard errors"),
           "runs_judged": len(judged), "rms_rel": round(rms, 7),
           "runs_moved": [{"run": i, "run_name": test.runs[i].name or str(i),
                           "given_rpm": round(abs(float(test.runs[i].speed)) * 30 / np.pi, 6),
                           "speed_rpm": round(abs(float(test.runs[i].speed)) * 30 / np.pi * (1 + e["rel"]), 6),
                           "rel": round(e["rel"], 7), "se_rel": round(e["se"], 7),
                           "lines": ", ".join(LINES[k][1] for k in e["lines"])} for i, e in moved.items()]}
    if moved:
        big = max(moved.values(), key=lambda e: abs(e["rel"]))
        rec["text"] = (f"{len(moved)} of {len(judged)} runs taken at the speed of their own 1x lines: each run's speed "
                       f"is off its column by {100 * rms:.3g} % RMS (largest {100 * big['rel']:+.3g} %, "
                       f"to +/-{100 * float(np.median([e['se'] for e in moved.values()])):.2g} % each)")
    else:
        rec["text"] = (f"each run's 1x lines agree with its speed within their uncertainty "
                       f"({len(judged)} runs, {100 * rms:.3g} % RMS)")
    # runs whose radial force's 1x line sits off the column beyond its uncertainty while the run's other lines disagree
    # with it: not moved, and said (before, the sentence above said every run's lines agreed with its speed)
    def force_off(e) -> bool:                       # the radial force's own line off the column beyond its σ
        rel, sig = e["per_line"].get("radial_force", (0.0, np.inf))
        return abs(rel) > SIGMAS * sig

    unsettled = {} if wander else {i: e for i, e in judged.items() if e["chi2"] > AGREE_CHI2 and force_off(e)}
    if unsettled:
        rec["runs_unsettled"] = [{"run": i, "run_name": test.runs[i].name or str(i),
                                  "rel_by_line": {LINES[k][1]: round(v[0], 7) for k, v in e["per_line"].items()},
                                  "chi2": round(e["chi2"], 3)} for i, e in unsettled.items()]
        names = ", ".join(f"{test.runs[i].name or i} (radial force {100 * e['per_line']['radial_force'][0]:+.2g} %)"
                          for i, e in list(unsettled.items())[:4])
        lead = rec["text"] if moved else f"{len(moved)} of {len(judged)} runs moved"
        rec["text"] = (f"{lead}; {len(unsettled)} run(s) off the column by their radial force's 1x line, which the "
                       f"run's other 1x lines disagree with, not moved: {names}{' ...' if len(unsettled) > 4 else ''}")
    if wander:
        rec["wander"] = {"runs": len(wide), "width_rel_median": round(float(np.median(wide)), 7), "text": (
            f"the speed wanders within the runs: in {len(wide)} of {len(judged)} runs every 1x line is wider than a "
            f"steady tone's (by {100 * float(np.median(wide)):.2g} % of its frequency, median; from the peak's "
            "curvature, which reads a slow wander low), the lines of a run alike: the rotor's speed moved during each "
            "record (a speed loop hunting, a drifting set-point); the model takes each run at one speed, and lines "
            "at high h are smeared in the data"),
            "action": "the runs' speeds are kept as given (a wandering line's peak is not the run's mean speed)"}
    check = dict(check, runs_speed=rec)
    if not moved:
        return test, check
    runs = [replace(r, speed=r.speed * (1 + moved[i]["rel"])) if i in moved else r for i, r in enumerate(test.runs)]
    return type(test)(runs, dict(test.meta or {})), check
