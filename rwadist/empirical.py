"""The empirical harmonic model fitted automatically (thesis ch. 3).

The disturbance of one channel is ``sum_i C_i Ω² sin(h_i |Ω| t + α_i)``
(Eq. 3.1 with Ω in rad/s, C_i in SI).  :func:`fit_empirical` does what the
thesis toolbox did with a manual decision at every step:

1. **Lines** (``iden_harm.m``/``findpeaks.m``): in every PSD, local maxima
   above a noise threshold.  The thesis's histogram threshold is replaced by a
   statistical one: a Welch PSD of noise is its local mean times
   chi²(dof)/dof, the local mean comes from a running median, and the
   threshold is set for a chosen false-alarm probability per spectrum.
   Hann side lobes of strong lines are discarded.
2. **Harmonic numbers** (``bin.m``): peak frequencies divided by the speed,
   and for every candidate h the presence P = N_bin / N_poss (Eq. 3.5), where
   N_poss counts the (run, channel) pairs in which h·|Ω| is inside the good
   band (0, f_lim] (Table 3.2).  x and y channels of a direction are pooled,
   which is the thesis's radial combination.  Peaks of P above P_0 are
   harmonics; each h is refined by least squares of f = h·|Ω| over its lines.
3. **Amplitudes** (``find_coeff.m``): the line amplitude in each run where
   the line is in band, detected (Eq. 3.11) and resolved from the other
   harmonics (or with weaker lines only in its bins, their part taken out:
   :mod:`rwadist.line_overlap`), measured as the power under the line (exact between bins, by Parseval) less the
   local noise floor; C by Eq. 3.10's weights on the power (:func:`line_C`).
4. **Modal amplification** (``remove_mode.m``, automatic): speeds where the
   amplitude departs from C·Ω² by more than noise and scatter allow, grown
   into contiguous speed ranges, are excluded and C is refitted; the ranges
   are reported.
5. **Standard error** of every C: a cluster-robust (sandwich) estimate, clustered by run so x and y measurements
   of one run are not counted as independent.  It is the *statistical* error (noise, speed-to-speed scatter).  It
   does not cover a bias the model form cannot see: amplification by a mode's skirts below the exclusion threshold,
   or an amplitude law other than Ω²; compare C with C_all and look at the coefficient plots for those.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
from scipy import signal, stats

from .data import DataError
from .fit_sidebands import fixed_offset_sidebands, in_band
from .line_overlap import measured_beside
from .model import DIRECTIONS, Harmonic, WheelModel
from .progress import tqdm
from .spectra import Spectra, detection_threshold, welch_dof
from .units import DIRECTION_CHANNELS, RAD_S_TO_RPM


@dataclass
class FitSettings:
    """Tuning of the automatic fit; defaults follow the thesis (Table 3.5) where it has one.

    p_false : false-alarm probability of line detection per spectrum.
    epsilon : binning tolerance on the normalised frequency (thesis ε).
    presence_min : bin percentage threshold P_0 as a fraction.
    min_detections : fewest (run, channel) detections for a harmonic.
    min_points : fewest measurements left after exclusion to keep a harmonic.
    h_range : (lowest, highest) harmonic number searched.
    f_min_bins : lines below this many bins above 0 Hz are not used.
    line_half_width : bins either side summed for a line's power (Hann lobe ±2).
    sidelobe_db : a peak this much below a stronger one within 6 bins is a side lobe.
    exclude_modes : detect and exclude modal amplification.
    amp_min : smallest relative amplification that can mark a speed as modal.
    n_sigma : amplification threshold in standard deviations.
    scatter_floor : relative scatter assumed besides noise (model error).
    """

    p_false: float = 0.01
    epsilon: float = 0.02
    presence_min: float = 0.25
    min_detections: int = 5
    min_points: int = 5
    h_range: tuple = (0.1, 40.0)
    f_min_bins: int = 4
    line_half_width: int = 3
    sidelobe_db: float = 25.0
    exclude_modes: bool = True
    amp_min: float = 0.03
    n_sigma: float = 4.0
    scatter_floor: float = 0.005


@dataclass
class LineFit:
    """One harmonic of one direction, with every measurement behind its C.

    speed (rad/s, >0), channel, amplitude (N or N·m), used (bool): one entry
    per measurement.  C, C_stderr, C_all in SI per (rad/s)²; C_all is :func:`line_C`
    over every measurement before modal exclusion (the thesis's C-bar).
    excluded_rpm: [[lo, hi], ...] speed ranges excluded as modal amplification.
    noise: per measurement, the relative amplitude error the channel's noise floor under the line's bins
    makes (dimensionless, σ_d/d; :func:`measure_direction`), or None when not measured so.
    """

    direction: str
    h: float
    C: float
    C_stderr: float
    C_all: float
    speed: np.ndarray
    channel: np.ndarray
    amplitude: np.ndarray
    used: np.ndarray
    excluded_rpm: list
    presence: float
    n_possible: int
    noise: np.ndarray | None = None

    @property
    def n_points(self) -> int:
        return int(np.sum(self.used))


@dataclass
class BinStat:
    """A candidate harmonic number and its presence statistics (thesis Table 3.2)."""

    direction: str
    h: float
    n_bin: int
    n_possible: int
    presence: float
    kept: bool
    reason: str = ""
    #: h of the stronger line this candidate is a fixed-offset sideband of (:func:`rwadist.fit_sidebands.fixed_offset_sidebands`), or None
    sideband_of: float | None = None


@dataclass
class EmpiricalFit:
    """The fitted model plus everything needed to judge it."""

    model: WheelModel
    spectra: Spectra
    lines: list
    bins: list
    settings: dict = field(default_factory=dict)
    #: per channel (inputs, block floor, detected lines) (:func:`line_detections`): a second fit of the same spectra
    #: (``detections`` of :func:`fit_empirical`) takes them instead of computing them again
    detections: dict = field(default_factory=dict, repr=False, compare=False)
    #: per direction what the fit measured before modal exclusion (:func:`measure_direction`): the fit of the same
    #: spectra without modal exclusion (:attr:`without_mode_exclusion`) takes it instead of measuring again
    measured: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def fit_settings(self) -> "FitSettings":
        """The :class:`FitSettings` this fit was made with (``settings`` holds them as a plain dict, with extra keys
        for the model file)."""
        return FitSettings(**{k: v for k, v in self.settings.items() if k in FitSettings.__dataclass_fields__})

    @property
    def modally_left_out(self) -> list:
        """The :class:`BinStat` of every harmonic the data show that the modal exclusion left out of the model: its
        lines amplified at nearly every speed (too few measurements outside the modal ranges to fit C·Ω²)."""
        return [b for b in self.bins if not b.kept and "outside modal ranges" in b.reason]

    @cached_property
    def without_mode_exclusion(self) -> "EmpiricalFit":
        """The fit of the same spectra, settings and detections with ``exclude_modes=False``: every line the data
        show, at every speed (what :func:`rwadist.extended_fit.fit_extended` locates the modes on).  Computed once
        per fit: the extended fit's passes beside a fixture resonance ask for it at every pass (59 times in one
        diagnosis of 60 speeds through a fixture resonance, when the stand was refitted in rounds).  Read-only: the extended fit builds new lines from it, never changes it.
        The harmonics are identified and measured once: this fit's measurements (:attr:`measured`, which do not depend
        on ``exclude_modes``) are taken, only the lines are made again without the exclusion (the same numbers as a
        fit of its own, for 5 % of its CPU: 1.5 ms against 27 ms on 120 speeds)."""
        return _fit_empirical(self.spectra, replace(self.fit_settings, exclude_modes=False), detections=self.detections,
                              measured=self.measured)


@dataclass
class _Lines:
    """Detected lines of one direction, flat and sorted by (pair, normalised frequency).

    A *pair* is one (run, channel) spectrum.  pair_* arrays have one entry per
    pair; line_* arrays one per detected line.
    """

    pair_run: np.ndarray       # index into the fitted runs
    pair_chan: np.ndarray      # channel name
    pair_speed_hz: np.ndarray  # |Ω|/2π of the pair's run
    pair_tol: np.ndarray       # tolerance on h for the pair
    line_pair: np.ndarray
    line_star: np.ndarray      # f / speed_hz (normalised frequency)
    line_freq: np.ndarray      # Hz, refined
    scale: float               # > every line_star; keys = pair + star/scale are sorted

    def match(self, h):
        """Frequency (Hz) of the line nearest h·speed in every pair, within the
        pair's tolerance, else NaN.  h: (n_h,) -> (n_h, n_pairs)."""
        h = np.atleast_1d(np.asarray(h, float))
        n_pairs = self.pair_run.size
        out = np.full((h.size, n_pairs), np.nan)
        if self.line_pair.size == 0:
            return out
        keys = self.line_pair + self.line_star / self.scale
        pair = np.arange(n_pairs)[None, :]
        target = pair + h[:, None] / self.scale
        idx = np.searchsorted(keys, target)
        best = np.full(out.shape, np.inf)
        for cand in (idx - 1, idx):
            c = np.clip(cand, 0, keys.size - 1)
            ok = (cand >= 0) & (cand < keys.size) & (self.line_pair[c] == pair)
            dist = np.where(ok, np.abs(self.line_star[c] - h[:, None]), np.inf)
            better = (dist < best) & (dist <= self.pair_tol[None, :])
            out = np.where(better, self.line_freq[c], out)
            best = np.where(better, dist, best)
        return out


# --------------------------------------------------------------------------- step 1: lines

def block_floor(psd: np.ndarray, block: int = 32, dof: float = 2.0) -> np.ndarray:
    """Mean noise level of PSDs (n_runs, n_f): medians of blocks of ``block`` bins,
    interpolated between block centres, scaled from the median to the mean of
    chi²(dof)/dof.  Block medians cost O(n) and ignore lines narrower than half a block.
    A spectrum shorter than one block (9 bins at nperseg 16) is one block of all its bins.
    """
    n_runs, n_f = psd.shape
    block = max(min(block, n_f), 1)
    n_blocks = max(n_f // block, 1)
    # np.median's values (the mean of the middle one or two of each sorted block, NaN where a block holds NaN),
    # from one sort: several times faster than np.median's partition for these short blocks
    ordered = np.sort(psd[:, :n_blocks * block].reshape(n_runs, n_blocks, block), axis=-1)
    med = np.mean(ordered[..., (block - 1) // 2:block // 2 + 1], axis=-1)
    med[np.isnan(ordered[..., -1])] = np.nan
    centres = (np.arange(n_blocks) + 0.5) * block
    # linear interpolation between block centres, flat beyond the end ones, all rows at once
    x = np.clip(np.arange(n_f), centres[0], centres[-1])
    k = np.clip(np.searchsorted(centres, x, "right") - 1, 0, max(n_blocks - 2, 0))
    if n_blocks > 1:
        t = (x - centres[k]) / block
        floor = med[:, k] * (1 - t) + med[:, k + 1] * t
    else:
        floor = np.repeat(med, n_f, axis=1)
    dof = max(dof, 2.0)
    return floor * (dof / stats.chi2.median(dof))


def detect_lines(psd: np.ndarray, f: np.ndarray, floor: np.ndarray, threshold: float,
                 f_lo: float, f_hi: float, sidelobe_db: float):
    """Significant peaks of every row of ``psd`` (n_runs, n_f), Hann side lobes removed.

    Returns (run index, refined frequency Hz) of each line.  A local maximum
    counts when it exceeds ``threshold`` × the local mean noise; it is a side
    lobe when something ``sidelobe_db`` stronger lies within 6 bins.  The
    frequency is refined by a log-parabolic fit through three bins.
    """
    df = f[1] - f[0]
    band = (f >= f_lo) & (f <= f_hi)
    mid = psd[:, 1:-1]
    is_peak = (mid > psd[:, :-2]) & (mid >= psd[:, 2:]) & (mid > threshold * floor[:, 1:-1]) & band[None, 1:-1]
    is_peak &= np.isfinite(mid)
    run, k = np.nonzero(is_peak)
    k = k + 1
    # side lobes: the strongest value within ±6 bins, gathered at the candidates only
    window = np.clip(k[:, None] + np.arange(-6, 7), 0, psd.shape[1] - 1)
    strongest = psd[run[:, None], window].max(axis=1)
    lobe = strongest > 10 ** (sidelobe_db / 10) * psd[run, k]
    run, k = run[~lobe], k[~lobe]
    lo, md, hi = (np.log(np.maximum(psd[run, k + o], 1e-300)) for o in (-1, 0, 1))
    denom = lo - 2 * md + hi
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(denom < 0, 0.5 * (lo - hi) / denom, 0.0)
    return run, f[k] + np.clip(delta, -0.5, 0.5) * df


# --------------------------------------------------------------------------- step 2: harmonic numbers

def collect_lines(spectra: Spectra, chans, fit_runs, detected: dict, epsilon: float) -> _Lines:
    """Pool the lines of a direction's channels over the fitted runs."""
    speed_hz_all = np.abs(spectra.speed) / (2 * np.pi)
    pr, pc, lp, ls, lf = [], [], [], [], []
    base = 0
    for c in chans:
        runs = fit_runs[spectra.available(c)[fit_runs]]
        remap = -np.ones(len(spectra.speed), int)
        remap[runs] = base + np.arange(runs.size)
        run_of_line, freq = detected[c]
        pair = remap[run_of_line]
        keep = pair >= 0
        pr.append(runs)
        pc.append(np.full(runs.size, c))
        lp.append(pair[keep])
        lf.append(freq[keep])
        ls.append(freq[keep] / speed_hz_all[run_of_line[keep]])
        base += runs.size
    pair_run = np.concatenate(pr)
    pair_speed = speed_hz_all[pair_run]
    line_pair, line_star, line_freq = np.concatenate(lp), np.concatenate(ls), np.concatenate(lf)
    order = np.lexsort((line_star, line_pair))
    scale = float(line_star.max() * 2 + 1) if line_star.size else 1.0
    tol = np.maximum(epsilon, 0.5 * spectra.df / pair_speed)
    return _Lines(pair_run, np.concatenate(pc), pair_speed, tol, line_pair[order], line_star[order],
                  line_freq[order], scale)


def presence_curve(h_grid: np.ndarray, lines: _Lines, f_lo: float, f_hi: float):
    """N_bin and N_poss (thesis Eq. 3.5, Table 3.2) on a grid of h (increasing).

    N_bin(h): pairs with a line within ±tol of h; N_poss(h): pairs in which
    f_lo <= h·speed <= f_hi.  Each line covers a grid interval and each pair's band is one run of the grid (h·speed
    grows with h): a pair's lines merged into disjoint intervals and cut to its band, every interval's ends go into one
    difference array of the grid, whose running sum counts the pairs (integers: the counts of a per-pair coverage
    matrix, without its n_pairs × n_grid passes).
    """
    n_grid = h_grid.size
    speed = lines.pair_speed_hz
    # each pair's band [b_lo, b_hi): the grid points passing the elementwise test f_lo <= h·speed <= f_hi
    b_lo = _first_where(h_grid, speed, lambda x: x >= f_lo)
    b_hi = _first_where(h_grid, speed, lambda x: x > f_hi)
    b_hi = np.maximum(b_hi, b_lo)
    n_poss = np.cumsum(np.bincount(b_lo, minlength=n_grid + 1) - np.bincount(b_hi, minlength=n_grid + 1))[:n_grid]
    pair = lines.line_pair
    tol = lines.pair_tol[pair]
    lo = np.maximum(np.searchsorted(h_grid, lines.line_star - tol, "left"), b_lo[pair])
    hi = np.minimum(np.searchsorted(h_grid, lines.line_star + tol, "right"), b_hi[pair])
    keep = lo < hi
    pair, lo, hi = pair[keep], lo[keep], hi[keep]
    if pair.size == 0:
        return np.zeros(n_grid, dtype=n_poss.dtype), n_poss
    # the pairs' intervals on one axis, each pair n_grid + 1 apart: merged where one starts within the reach so far
    span = n_grid + 1
    start, end = pair * span + lo, pair * span + hi
    order = np.lexsort((start, pair))
    start, end = start[order], end[order]
    reach = np.maximum.accumulate(end)
    first = np.r_[True, start[1:] > reach[:-1]]
    last = np.r_[first[1:], True]
    n_bin = np.cumsum(np.bincount(start[first] % span, minlength=span) - np.bincount(reach[last] % span, minlength=span))
    return n_bin[:n_grid], n_poss


def _first_where(h_grid: np.ndarray, speed: np.ndarray, test) -> np.ndarray:
    """Per speed, the first index g of the increasing ``h_grid`` with ``test(h_grid[g]·speed)`` true (h_grid.size if
    none), for a test that holds from some product on (a threshold: h·speed rounded never decreases with h): by
    bisection on the products themselves, so the index of the elementwise test."""
    n = h_grid.size
    lo = np.zeros(speed.size, dtype=np.intp)
    hi = np.full(speed.size, n, dtype=np.intp)
    while np.any(lo < hi):
        mid = (lo + hi) // 2
        ok = test(h_grid[np.minimum(mid, n - 1)] * speed)
        active = lo < hi
        hi = np.where(active & ok, mid, hi)
        lo = np.where(active & ~ok, mid + 1, lo)
    return lo


def identify_harmonics(lines: _Lines, f_lo: float, f_hi: float, s: FitSettings, direction: str,
                       df: float | None = None):
    """Harmonic numbers of one direction: candidate bins from N_bin(h), each h
    refined by least squares of f = h·|Ω| over its lines (Eq. 3.2), kept when
    P >= P_0 and, given the spectra's resolution ``df`` (Hz), not the sidebands of a stronger line at a fixed offset
    (:func:`rwadist.fit_sidebands.fixed_offset_sidebands`).  Returns a list of :class:`BinStat` sorted by h."""
    if lines.pair_run.size == 0:
        return []
    h_hi = min(s.h_range[1], f_hi / lines.pair_speed_hz.min())
    step = s.epsilon / 4
    h_grid = np.arange(s.h_range[0], h_hi + step, step)
    # candidates from the strict tolerance ε only: the half-bin widening at low speed would smear two close harmonics
    # into one peak (presence below uses the widened tolerance); and from ε/2: lines 2ε apart (a carrier, its speed
    # sideband at 0.04: trial nuL) abut at ±ε, the weaker a shoulder, no peak (a line seen twice is one once refined:
    # candidates within ε merged below)
    cand = []
    for tol in (s.epsilon, s.epsilon / 2):
        n_bin, _ = presence_curve(h_grid, replace(lines, pair_tol=np.full_like(lines.pair_tol, tol)), f_lo, f_hi)
        cand.append(signal.find_peaks(np.concatenate([[0], n_bin, [0]]), height=s.min_detections,
                                      distance=max(int(tol / step), 1))[0])
    h = h_grid[np.union1d(*cand) - 1]
    for _ in range(2):
        fpk = lines.match(h)
        ok = np.isfinite(fpk) & in_band(h, lines, f_lo, f_hi)
        w = np.where(ok, lines.pair_speed_hz[None, :], 0.0)
        num, den = np.sum(np.where(ok, fpk, 0.0) * w, axis=1), np.sum(w**2, axis=1)
        h = np.where(den > 0, num / np.where(den > 0, den, 1), h)
    fpk = lines.match(h)
    ok = np.isfinite(fpk) & in_band(h, lines, f_lo, f_hi)
    n_b, n_p = ok.sum(axis=1), in_band(h, lines, f_lo, f_hi).sum(axis=1)
    # each candidate's detections' scatter about f = h·|Ω| (Hz, median): a harmonic's lie on its law, a candidate
    # refined between a carrier and its sidebands scatters by their offset
    scatter = [float(np.median(np.abs(fpk[i, ok[i]] - h[i] * lines.pair_speed_hz[ok[i]]))) if ok[i].any() else np.inf
               for i in range(h.size)]
    stats_ = []
    for hk, nb, npss, sc in zip(h, n_b, n_p, scatter):
        presence = float(nb / npss) if npss else 0.0
        kept = bool(presence >= s.presence_min and nb >= s.min_detections)
        reason = "" if kept else (f"presence {presence:.0%} < P0 {s.presence_min:.0%}"
                                  if presence < s.presence_min else f"only {int(nb)} detections")
        stats_.append((BinStat(direction, float(hk), int(nb), int(npss), presence, kept, reason), sc))
    stats_.sort(key=lambda bs: bs[0].h)
    merged: list[BinStat] = []
    merged_scatter = np.inf
    for b, sc in stats_:
        # two candidates refined onto one line: keep the better supported, of two as well supported the one on its
        # law (a 1x line amplitude-modulated at 0.7 Hz, trial nuR: candidates at h 0.985, 1.0 and 1.0145 all in every
        # run; the first kept on a tie, the carrier merged into its lower sideband's candidate and the 1x line lost)
        if merged and abs(b.h - merged[-1].h) < s.epsilon:
            if (b.n_bin, -sc) > (merged[-1].n_bin, -merged_scatter):
                merged[-1], merged_scatter = b, sc
            continue
        merged.append(b)
        merged_scatter = sc
    if df is not None:
        fixed_offset_sidebands(merged, lines, df, f_lo, f_hi)
    return merged


# --------------------------------------------------------------------------- steps 3-5: coefficients

def line_C(d, w):
    """C of a line from its amplitudes ``d`` (SI) at speeds ``w`` (rad/s), (m,) each: Eq. 3.10's Ω⁴ weights on the
    power, C² = Σ d²/Σ Ω⁴.  Exact for a steady line, as Eq. 3.10 (C = Σ dΩ²/Σ Ω⁴); unlike it, it reads the mean power
    (the model's C²Ω⁴/2 a channel) of a line whose amplitude on a channel changes from run to run (both senses with
    their own phases: Eq. 3.10 read a planar line 10-14 % low), and d² (power less noise) is unbiased."""
    return float(np.sqrt(np.sum(np.square(d)) / np.sum(np.asarray(w, float) ** 4)))


def _cluster_stderr(d, w, runs, C):
    """Cluster-robust standard error of :func:`line_C`'s estimate, clustered by run: the sandwich variance of
    C² = Σ d² / Σ Ω⁴ (its residuals d² − C²Ω⁴ summed per run), carried to C by var(C) = var(C²) / (2C)²."""
    e = d**2 - C**2 * w**4
    uniq, inv = np.unique(runs, return_inverse=True)
    g = np.bincount(inv, weights=e)
    n_cl = uniq.size
    if n_cl < 2 or not C > 0:
        return float("nan")
    var = np.sum(g**2) / np.sum(w**4) ** 2 * n_cl / (n_cl - 1)
    return float(np.sqrt(var) / (2 * C))


def _ranges(speeds_sorted, flags_sorted):
    """Contiguous runs of flagged points -> [[lo, hi], ...] in the speed's unit."""
    edges = np.diff(np.concatenate([[0], np.asarray(flags_sorted, int), [0]]))
    return [[float(speeds_sorted[a]), float(speeds_sorted[b - 1])] for a, b in zip(np.flatnonzero(edges == 1),
                                                                                 np.flatnonzero(edges == -1))]


def modal_exclusion(d, w, run, sigma_noise, s: FitSettings):
    """Flag measurements amplified by a structural mode.

    d : amplitudes; w : speeds (rad/s); run : run index; sigma_noise : relative
    amplitude error expected from noise.  Returns a boolean mask of excluded
    measurements.

    Works on the log ratio ℓ = log(d / (C·Ω²)) per run (x and y of a run share
    a verdict), in speed order.  C is the median ratio of the runs not yet
    flagged: a mode's wide skirts bias C (whose Ω⁴ weights favour the
    top speeds), not the median.  The random scatter is estimated from
    differences of neighbouring runs, so the smooth rise of a resonance is not
    mistaken for noise.  A core of runs departing by more than
    max(amp_min, n_sigma·σ) is grown into neighbours departing by more than
    half that, single-run gaps are closed, and the whole is repeated with the
    new C until nothing changes.  One-sided: C only falls as runs are flagged,
    so the flagged set only grows and the loop converges.
    """
    uniq, inv = np.unique(run, return_inverse=True)
    n = uniq.size
    counts = np.bincount(inv)
    w_run = np.bincount(inv, weights=w) / counts
    order = np.argsort(w_run, kind="stable")
    log_ratio = np.log(np.maximum(d, 1e-300) / w**2)
    lr_run = np.bincount(inv, weights=log_ratio) / counts
    sig_run = np.sqrt(np.bincount(inv, weights=sigma_noise**2)) / counts
    excluded_run = np.zeros(n, bool)
    for _ in range(20):
        clean = ~excluded_run
        if clean.sum() < 3:
            break
        ell_run = lr_run - np.median(lr_run[clean])
        steps = np.diff(ell_run[order][clean[order]])
        scatter = 1.4826 * np.median(np.abs(steps)) / np.sqrt(2) if steps.size > 4 else 0.0
        scatter = max(scatter, s.scatter_floor)
        thr = np.maximum(np.log1p(s.amp_min), s.n_sigma * np.sqrt(sig_run**2 + scatter**2))
        e_s, t_s = ell_run[order], thr[order]
        f_s = e_s > t_s
        weak = e_s > 0.5 * t_s
        while True:  # grow along speed
            nb = np.zeros(n, bool)
            nb[1:] |= f_s[:-1]
            nb[:-1] |= f_s[1:]
            grown = f_s | (nb & weak)
            if np.array_equal(grown, f_s):
                break
            f_s = grown
        gap = np.zeros(n, bool)
        gap[1:-1] = ~f_s[1:-1] & f_s[:-2] & f_s[2:]
        f_s |= gap
        new = np.empty(n, bool)
        new[order] = f_s
        if np.array_equal(new, excluded_run):
            break
        excluded_run = new
    return excluded_run[inv]


@dataclass
class _LineMeasurements:
    """Every valid (harmonic, pair) measurement of the kept harmonics' lines ``lines``: harmonic index ``hi`` and
    pair index ``pi`` (shape (m,) each), amplitude ``d`` (SI) and relative noise ``sig``."""

    lines: _Lines
    hi: np.ndarray
    pi: np.ndarray
    d: np.ndarray
    sig: np.ndarray


@dataclass
class _DirectionMeasurements:
    """What :func:`fit_direction` measures of one direction before any modal exclusion: the harmonics identified
    (``bins``, as identified: the line step marks its own copies) and their line measurements (None when no harmonic
    was kept).  It depends on the settings' identification and measurement fields only, not on ``exclude_modes``: a
    fit without modal exclusion of the same spectra (:attr:`EmpiricalFit.without_mode_exclusion`) takes it instead of
    identifying the harmonics again."""

    bins: list
    measured: _LineMeasurements | None = None


def measure_direction(spectra: Spectra, direction: str, s: FitSettings, floors: dict, detected: dict,
                      fit_runs: np.ndarray) -> _DirectionMeasurements:
    """Steps 2-3 of one direction: identification and the line amplitudes (see :class:`_DirectionMeasurements`)."""
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in spectra.psd]
    if not chans:
        return _DirectionMeasurements([])
    df = spectra.df
    f_lo, f_hi = s.f_min_bins * df, spectra.band_limit
    lines = collect_lines(spectra, chans, fit_runs, detected, s.epsilon)
    bins = identify_harmonics(lines, f_lo, f_hi, s, direction, df)
    kept = [b for b in bins if b.kept]
    if not kept:
        return _DirectionMeasurements(bins)
    h = np.array([b.h for b in kept])
    fpk = lines.match(h)                                    # (n_h, n_pairs)
    predicted = h[:, None] * lines.pair_speed_hz[None, :]
    valid = np.isfinite(fpk) & in_band(h, lines, f_lo, f_hi)
    # resolved: no other harmonic's line within the summed bins of this one ...
    at = np.where(np.isfinite(fpk), fpk, predicted)
    clear = np.abs(predicted[None, :, :] - at[:, None, :]) >= (2 * s.line_half_width + 1) * df   # (a, b, pair)
    clear[np.arange(h.size), np.arange(h.size), :] = True
    # ... nor any other detected line (a harmonic too weak or too rare to be kept) under its window
    n_near = np.zeros(fpk.shape, int)
    if lines.line_pair.size:
        n_near = _detections_near(lines, fpk, (s.line_half_width + 0.5) * df)
    # a carrier's own fixed-offset sidebands (an amplitude modulation, a speed ripple) may lie under its window: its
    # measurement then holds their power with its own, as a harmonic read with weak neighbours does (a 1x line
    # modulated 0.3 at 0.7 Hz, family wheel 2 at 4096 samples: its two sidebands under the window in every run, the
    # imbalance left out of the fit and the wheel's modes lost with it)
    resolved = valid & clear.all(axis=1) & (n_near <= 1 + _own_sides_near(bins, h, lines, fpk, s, df))
    hi_, pi_ = np.nonzero(resolved)
    d, sig = _line_powers(spectra, chans, lines, fpk, hi_, pi_, floors, s)
    # a line with only weak lines in its bins (a carrier's speed sidebands at low speed) is measured there too
    power = np.full(fpk.shape, np.nan)
    power[hi_, pi_] = np.where(d > 0, d ** 2 / 2, np.nan)
    hb, pb, part, beat = measured_beside(valid, resolved, clear, n_near, fpk, predicted, power, df, s.line_half_width,
                                   spectra.window, spectra.nperseg)
    if hb.size:
        db, sb = _line_powers(spectra, chans, lines, fpk, hb, pb, floors, s)
        order = np.lexsort((np.concatenate([pi_, pb]), np.concatenate([hi_, hb])))
        hi_, pi_ = np.concatenate([hi_, hb])[order], np.concatenate([pi_, pb])[order]
        d = np.concatenate([d, db / np.sqrt(1 + part)])[order]
        sig = np.concatenate([sig, np.hypot(sb * np.sqrt(1 + part), beat / 2)])[order]
    return _DirectionMeasurements(bins, _LineMeasurements(lines, hi_, pi_, d, sig))


def _own_sides_near(bins: list, h: np.ndarray, lines: _Lines, fpk: np.ndarray, s: FitSettings, df: float) -> np.ndarray:
    """(n_h, n_pairs) int: per kept harmonic ``h`` and pair, how many detections lie within a bin of its own
    fixed-offset sidebands f ± Δ under its window (±(L + ½) bins about its peak ``fpk``): Δ (Hz) the median offset of
    each candidate of ``bins`` whose ``sideband_of`` is it from the peak, read where it is detected under the window
    (an amplitude modulation's sides stand at ±Δ at every speed, found as a candidate near the top speed only)."""
    out = np.zeros(fpk.shape, int)
    if lines.line_pair.size == 0:
        return out
    window = (s.line_half_width + 0.5) * df
    for i, hk in enumerate(h):
        sides = [b.h for b in bins if b.sideband_of is not None and abs(b.sideband_of - hk) < 1e-9]
        offsets = set()
        for off in lines.match(np.array(sides)) - fpk[i][None, :] if sides else ():
            near = np.abs(off[np.isfinite(off)])
            near = near[(near > 0.5 * df) & (near <= window)]
            if near.size:
                offsets.add(float(np.median(near)))
        for d in offsets:
            for at in (fpk[i] - d, fpk[i] + d):
                out[i] += np.where(np.isfinite(at), np.minimum(_detections_near(lines, at, df), 1), 0)
    return out


def _detections_near(lines: _Lines, f_hz: np.ndarray, half_hz: float) -> np.ndarray:
    """Per pair, the detected lines of ``lines`` within ``half_hz`` of ``f_hz`` (Hz; (..., n_pairs), NaN read as 0:
    none there), the same shape: one sorted search over the (pair, normalised frequency) keys."""
    keys = lines.line_pair + lines.line_star / lines.scale
    pair = np.arange(lines.pair_run.size)
    star = np.where(np.isfinite(f_hz), f_hz, 0.0) / lines.pair_speed_hz
    half = half_hz / lines.pair_speed_hz
    return (np.searchsorted(keys, pair + (star + half) / lines.scale, "right")
            - np.searchsorted(keys, pair + (star - half) / lines.scale, "left"))


def _line_powers(spectra: Spectra, chans, lines: _Lines, fpk: np.ndarray, hi_: np.ndarray, pi_: np.ndarray,
                 floors: dict, s: FitSettings) -> tuple:
    """Amplitude (SI) and relative noise of the lines of the cells (``hi_``, ``pi_``) (m,) each: the power in the
    2L+1 bins about the detected peak less the channel's noise floor there, one gather per channel."""
    d = np.zeros(hi_.size)
    sig = np.zeros(hi_.size)
    offsets = np.arange(-s.line_half_width, s.line_half_width + 1)
    for c in chans:
        m = lines.pair_chan[pi_] == c
        if not m.any():
            continue
        runs = lines.pair_run[pi_[m]]
        bins_ = np.clip(np.rint(fpk[hi_[m], pi_[m]] / spectra.df).astype(int)[:, None] + offsets, 0,
                        spectra.f.size - 1)
        p = spectra.psd[c][runs[:, None], bins_].sum(axis=1) * spectra.df
        noise = floors[c][runs[:, None], bins_].sum(axis=1) * spectra.df
        power = np.maximum(p - noise, 0.0)
        d[m] = np.sqrt(2 * power)
        sig[m] = np.sqrt(noise / np.maximum(2 * power, 1e-300))
    return d, sig


def direction_lines(direction: str, meas: _DirectionMeasurements, s: FitSettings):
    """Steps 4-5 of one direction from its measurements: (LineFit list, BinStat list).  The BinStats are copies of
    the measurements' (a harmonic left without measurements is marked not kept on its copy)."""
    bins = [replace(b) for b in meas.bins]
    kept = [b for b in bins if b.kept]
    if not kept or meas.measured is None:
        return [], bins
    lines, hi_, pi_, d, sig = (meas.measured.lines, meas.measured.hi, meas.measured.pi, meas.measured.d,
                               meas.measured.sig)
    w_all = 2 * np.pi * lines.pair_speed_hz[pi_]
    out = []
    for k, b in enumerate(kept):
        m = (hi_ == k) & (d > 0)
        if not m.any():
            b.kept = False
            b.reason = "no measurement resolved from the other lines"
            continue
        w, dk, run, ch, sg = w_all[m], d[m], lines.pair_run[pi_[m]], lines.pair_chan[pi_[m]], sig[m]
        C_all = line_C(dk, w)
        excluded = modal_exclusion(dk, w, run, sg, s) if s.exclude_modes else np.zeros(w.size, bool)
        used = ~excluded
        if used.sum() < s.min_points:
            b.kept = False
            b.reason = f"only {int(used.sum())} measurements outside modal ranges (< {s.min_points})"
            continue
        C = line_C(dk[used], w[used])
        se = _cluster_stderr(dk[used], w[used], run[used], C)
        rpm = w * RAD_S_TO_RPM
        order = np.argsort(rpm, kind="stable")
        out.append(LineFit(direction, float(b.h), C, se, C_all, w, ch, dk, used,
                           _ranges(rpm[order], excluded[order]), b.presence, b.n_possible, sg))
    return out, bins


def fit_direction(spectra: Spectra, direction: str, s: FitSettings, floors: dict, detected: dict,
                  fit_runs: np.ndarray):
    """Harmonics of one direction: identification, coefficients, modal exclusion ((LineFit list, BinStat list))."""
    return direction_lines(direction, measure_direction(spectra, direction, s, floors, detected, fit_runs), s)


def _detection_inputs(spectra: Spectra, s: FitSettings) -> tuple:
    """(dof, threshold, f_lo, f_hi, sidelobe_db): everything a channel's block floor and detected lines depend on
    besides its PSD rows."""
    dof = welch_dof(int(np.min(spectra.n_segments)))
    f = spectra.f
    f_lo, f_hi = s.f_min_bins * spectra.df, spectra.band_limit
    n_bins = int(np.sum((f >= f_lo) & (f <= f_hi)))
    return dof, detection_threshold(dof, n_bins, s.p_false), f_lo, f_hi, s.sidelobe_db


def line_detections(spectra: Spectra, settings: FitSettings | None = None, channels=None) -> dict:
    """Per channel of ``channels`` (default every channel of the spectra): (key, block floor (n_runs, n_f) with NaN
    rows where the run lacks the channel, detected lines (run index, Hz) of :func:`detect_lines`); ``key`` holds the
    inputs besides the PSD rows (:func:`_detection_inputs`).  Each run's floor and lines are its own: those of some
    runs are rows of these (:func:`detections_of_runs`)."""
    s = settings or FitSettings()
    key = _detection_inputs(spectra, s)
    dof, threshold, f_lo, f_hi, sidelobe_db = key
    out = {}
    for c in (spectra.channels if channels is None else channels):
        psd = spectra.psd[c]
        fl = np.full_like(psd, np.nan)
        ok = spectra.available(c)
        fl[ok] = block_floor(psd[ok], dof=dof)
        out[c] = (key, fl, detect_lines(psd, spectra.f, fl, threshold, f_lo, f_hi, sidelobe_db))
    return out


def detections_of_runs(detections: dict, rows) -> dict:
    """:func:`line_detections` of the spectra's rows ``rows`` (increasing run indices) from those of every run: the
    floors' rows and the lines of those runs, renumbered (in the same order as computed on those rows alone)."""
    rows = np.asarray(rows, dtype=int)
    out = {}
    for c, (key, fl, (run, freq)) in detections.items():
        new = -np.ones(fl.shape[0], int)
        new[rows] = np.arange(rows.size)
        keep = new[run] >= 0
        out[c] = (key, fl[rows], (new[run[keep]], freq[keep]))
    return out


def fit_empirical(spectra: Spectra, settings: FitSettings | None = None, directions=None,
                  name: str = "fitted wheel", progress: bool = False, detections: dict | None = None) -> EmpiricalFit:
    """Fit the empirical model to the spectra of a steady-state test.

    Runs at zero speed (noise runs) are not used.  Returns an
    :class:`EmpiricalFit` whose ``model`` goes to the model file.  ``detections``: block floors and detected lines of
    THESE spectra (:func:`line_detections`, or an earlier fit's ``detections``): a channel's are taken when they
    were made with the same inputs (the settings' p_false, f_min_bins, sidelobe_db; e.g. the extended fit's second
    pass without modal exclusion), else computed.
    """
    return _fit_empirical(spectra, settings, directions, name, progress, detections)


def _measurement_key(s: FitSettings) -> FitSettings:
    """The settings a direction's measurements (:func:`measure_direction`) are valid for: all but ``exclude_modes``."""
    return replace(s, exclude_modes=False)


def _fit_empirical(spectra: Spectra, settings: FitSettings | None = None, directions=None,
                   name: str = "fitted wheel", progress: bool = False, detections: dict | None = None,
                   measured: dict | None = None) -> EmpiricalFit:
    """:func:`fit_empirical`; ``measured``: an earlier fit's :attr:`EmpiricalFit.measured` of THESE spectra, a
    direction's taken when made with the same settings but ``exclude_modes`` (:func:`_measurement_key`)."""
    s = settings or FitSettings()
    directions = tuple(directions) if directions is not None else DIRECTIONS
    speed = np.abs(spectra.speed)
    fit_runs = np.nonzero(speed > 0)[0]
    if fit_runs.size == 0:
        raise DataError(spectra.run_names[0] if spectra.run_names else "<test>", "speed_rpm",
                        "every run is at zero speed: nothing to fit (zero-speed runs are noise runs)")
    key = _detection_inputs(spectra, s)
    dof, threshold = key[0], key[1]
    channels = [c for c in spectra.channels if any(c in DIRECTION_CHANNELS[d] for d in directions)]
    bar = tqdm(total=len(channels) + len(directions), desc="rwadist fit", disable=not progress, unit="step")
    known = {c: v for c, v in (detections or {}).items() if v[0] == key and v[1].shape == spectra.psd[c].shape}
    known.update(line_detections(spectra, s, [c for c in channels if c not in known]))
    floors = {c: known[c][1] for c in channels}
    detected = {c: known[c][2] for c in channels}
    bar.update(len(channels))
    model = WheelModel(name=name)
    lines, bins = [], []
    mkey = _measurement_key(s)
    done = {}
    for d in directions:
        got = (measured or {}).get(d)
        meas = got[1] if got is not None and got[0] == mkey else \
            measure_direction(spectra, d, s, floors, detected, fit_runs)
        done[d] = (mkey, meas)
        ls, bs = direction_lines(d, meas, s)
        lines += ls
        bins += bs
        model.empirical[d] = [Harmonic(h=round(x.h, 4), C=x.C, C_stderr=x.C_stderr, n_points=x.n_points,
                                       presence=round(x.presence, 4), excluded_rpm=x.excluded_rpm) for x in ls]
        bar.update()
    bar.close()
    model.provenance = {
        "method": "rwadist empirical fit (thesis ch. 3, automatic)",
        "n_runs": int(fit_runs.size),
        "speed_range_rpm": [float(speed[fit_runs].min() * RAD_S_TO_RPM), float(speed[fit_runs].max() * RAD_S_TO_RPM)],
        "f_lim_hz": spectra.f_lim,
        "nperseg": spectra.nperseg,
        "sample_rate_hz": spectra.sample_rate,
    }
    idle = [str(spectra.run_names[i]) for i in np.nonzero(speed == 0)[0]] if spectra.run_names else []
    if idle:        # never a run left out without saying which and why
        model.provenance["runs_not_fitted"] = {"runs": idle, "why": "zero speed: noise runs, no harmonic to fit"}
    settings_doc = {k: getattr(s, k) for k in s.__dataclass_fields__}
    settings_doc["detection_threshold"] = threshold
    settings_doc["dof"] = dof
    return EmpiricalFit(model=model, spectra=spectra, lines=lines, bins=bins, settings=settings_doc,
                        detections={c: known[c] for c in channels}, measured=done)
