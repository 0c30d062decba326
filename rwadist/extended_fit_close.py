"""Close lines the empirical fit detected but could not measure apart, measured together on each whole record.

The empirical fit measures a line by the power in a window of (2·line_half_width + 1) bins around it: two lines
closer than that window (speed sidebands at 0.94 and 1.06 × the speed beside the imbalance, 2.4 Hz from it at
2400 rpm on 0.61-Hz bins) are detected but neither is measured ("no measurement resolved from the other lines"),
and a base fitted from the data then lacks them all -- the imbalance included.  Here the lines of such a span are
fitted together on each run's whole-record Hann DFT: the windowed transform of x(t) = Σ_j Re(A_j e^{2πj f_j t}) at f
is Σ_j (A_j/2)·W(f − f_j) (:func:`rwadist.dft.hann_transform`; the images at −f_j, several bins away, left out), a
linear least squares for the complex amplitudes A_j on the transform at quarter-bin steps across the span and two
bins beyond, f_j = h_j·|Ω|/2π, on the runs where every two lines of the span are a record bin apart or more (Hann:
W(1 bin) = W(0)/2).  The h of each line the fit could not measure (known to its binning tolerance ε only) is the
one of least residual power over every run, on a grid of ε/40 steps within ±ε; a lone line beside the span's
strongest one (h₀ − δ without h₀ + δ: one of a speed-sideband pair, the other too close to the carrier for the
detection) has its mirror looked for the same way and kept when the records show it.  A measurement is kept where
the line's power stands :data:`MIN_SNR` over the noise the block floor gives in one record bin (white noise of
one-sided PSD S: E|X|² = S·f_s/2·Σw², Σw² = 3n/8; a line of amplitude a at its bin: |X| = a·n/4).

A run cut from a sweep is not steady: over its record of T s a line of harmonic h moves by c = h·(d|Ω|/dt)·T²/(2π)
record bins (:func:`rwadist.chirp.chirp_bins`).  There each line's column is the windowed transform of a linear chirp
of that c (:func:`chirp_transform`, a function of the offset from the line's mean frequency in bins, signed by the
sweep's direction) and the grid reaches c/2 bins further each side: with the steady kernel a fast run-up's line,
smeared over 22 record bins, was read as three lines 0.4 % apart.  Two lines are measured apart where their mean
frequencies are 1 + ½|c₁ − c₂| record bins apart (two lines chirp nearly alike: the chirp taken off, a steady pair);
candidates that no chirping run measures apart are one line's smear (:meth:`_Span.merge_smeared`).
"""
from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np

from .chirp import sliced_slopes
from .dft import hann_transform, run_window, windowed_dfts, windowed_records
from .units import DIRECTION_CHANNELS

#: A line of a sweep's run whose chirp across the record is below this many record bins is read as a steady line (the
#: steady kernel is then within 2e-3 of the chirp's transform, relative to its peak)
CHIRP_MIN_BINS = 1.0 / 64
#: Steps per record bin of the tabulated chirp transform (:func:`chirp_transform`; its linear phase taken off, the
#: rest linearly interpolated: within 4e-5 of its peak)
CHIRP_TABLE_STEPS = 64
#: ... for a chirp rounded to this many steps per bin (a chirp 1/128 bin off moves its transform by 8e-4 of its peak
#: at most: measured against the direct sum)
CHIRP_C_STEPS = 64
#: Candidates are merged as one line's smear (:meth:`_Span.merge_smeared`) only on runs where a line chirps over this
#: many record bins or more: a smear that moves the line less than a bin cannot split it into peaks
SMEAR_MIN_BINS = 1.0
#: A measurement of a close line is kept when its power over the noise in one record bin reaches this (10 dB)
MIN_SNR = 10.0
#: Lines of a span measured together where each two are at least this many record bins apart
MIN_SEPARATION_BINS = 1.0
#: Steps of the h grid of a line the fit could not measure, per side of its binning tolerance
H_STEPS = 40
#: A line the fit could not measure whose h lies this close to 1 is the once-per-revolution line, at h = 1 exactly
ONCE_PER_REV_TOL = 0.005
#: The mirror of a lone line beside the span's strongest is looked for up to this offset per revolution (the
#: ``speed_sidebands`` family's range) ...
MIRROR_MAX_PER_REV = 0.30
#: ... and kept at this fraction of the lone line's median amplitude or more
MIRROR_MIN_RATIO = 0.3


def with_close_lines(test, fit):
    """``fit`` (an :class:`rwadist.empirical.EmpiricalFit`, ``test`` its data) with the lines of its unresolved spans
    measured together (:func:`close_lines`) added to its lines; kept on the fit per test (the stand's passes fit the
    same test and fit again)."""
    kept = fit.__dict__.get("_with_close_lines")
    if kept is not None and kept[0] is test:
        return kept[1]
    new = close_lines(test, fit)
    out = replace(fit, lines=list(fit.lines) + new) if new else fit
    fit.__dict__["_with_close_lines"] = (test, out)
    return out


def _spans(fit, close: float) -> dict:
    """direction -> [(sorted h of one span, the h of its lines the fit did not measure)]: the harmonics detected but
    not measured apart (BinStat reason "no measurement resolved from the other lines") with every line of the fit
    closer to them than ``close`` in h, grouped as :func:`rwadist.extended_fit.unresolved_spans` groups them."""
    out = {}
    for d in sorted({b.direction for b in fit.bins}):
        lost = sorted(b.h for b in fit.bins if b.direction == d and not b.kept
                      and b.reason.startswith("no measurement resolved"))
        if not lost:
            continue
        hs = sorted(set(lost) | {x.h for x in fit.lines if x.direction == d
                                 and any(abs(x.h - h) < close for h in lost)})
        spans: list[list[float]] = []      # runs of lines closer than ``close`` per rev
        for h in hs:
            if spans and h - spans[-1][-1] < close:
                spans[-1].append(h)
            else:
                spans.append([h])
        out[d] = [(s, [h for h in s if h in lost]) for s in spans if any(h in lost for h in s)]
    return out


def close_lines(test, fit) -> list:
    """:class:`rwadist.empirical.LineFit` of every harmonic of ``fit``'s unresolved spans (:func:`_spans`), and of the
    mirror of a lone one beside the span's strongest line, measured together on each run's whole record (module
    docstring); those with fewer than the fit's ``min_points`` measurements kept are left out.  ``test``: the
    SteadyTest of ``fit``'s spectra (its runs in the same order)."""
    from .empirical import FitSettings, LineFit, line_C

    eps = float(fit.settings.get("epsilon", FitSettings.epsilon))
    half = int(fit.settings.get("line_half_width", FitSettings.line_half_width))
    sp = fit.spectra
    f_spin = float(np.max(np.abs(sp.speed))) / (2 * np.pi) if np.size(sp.speed) else 0.0
    if f_spin <= 0:
        return []
    spans = _spans(fit, max(eps, (2 * half + 1) * sp.df / f_spin))
    min_points = int(fit.settings.get("min_points", FitSettings.min_points))
    out = []
    for d, groups in spans.items():
        chans = [c for c in DIRECTION_CHANNELS[d] if c in sp.psd]
        for hs, lost in groups:
            span = _Span(test, fit, chans, hs, lost, eps)
            span.merge_smeared()
            span.refine()
            span.add_mirrors(min_points)
            for j in span.lost:
                w, ch, amp = span.measurements(j)
                if w.size >= min_points:
                    C = line_C(amp, w)
                    out.append(LineFit(d, float(span.h[j]), C, float("nan"), C, w, ch, amp, np.ones(w.size, bool), [],
                                       1.0, int(w.size)))
    return out


class _Span:
    """The lines ``h`` of one span of one direction's channels ``chans``, fitted together on every run's record;
    ``lost``: the indices of those the empirical fit did not measure (their h free within ±``eps``)."""

    def __init__(self, test, fit, chans, hs, lost, eps):
        self.h = np.asarray(hs, dtype=float)
        self.lost = [int(np.argmin(np.abs(self.h - h))) for h in lost]
        self.eps = eps
        self.floors = fit.detections
        self.f_axis = fit.spectra.f
        self.band_limit = fit.spectra.band_limit
        self.runs = []              # (run index, |Ω|, n, fs, channels, grid f (G,), X (G, K), d|Ω|/dt rad/s²)
        slopes = sliced_slopes(test)
        lo, hi = self.h.min() - eps, self.h.max() + eps
        for r, run in enumerate(test.runs):
            w = abs(float(run.speed))
            n, fs = run.n_samples, run.sample_rate
            bin_hz = fs / n
            chs = [c for c in chans if run.usable(c)]
            if w <= 0 or not chs or lo * w / (2 * np.pi) < 4 * bin_hz or hi * w / (2 * np.pi) > self.band_limit:
                continue
            slope = 0.0 if slopes is None or not np.isfinite(slopes[r]) else float(slopes[r])
            reach = 2 + 0.5 * abs(_chirp(hi, slope, n, fs))         # a chirp's smear beyond the span, bins
            grid = np.arange(lo * w / (2 * np.pi) - reach * bin_hz, hi * w / (2 * np.pi) + reach * bin_hz,
                             0.25 * bin_hz)
            x = windowed_records([[run.signals[c] for c in chs]], run_window("hann", n)[0])
            self.runs.append((r, w, n, fs, chs, grid, windowed_dfts(x, fs, grid[None, :])[0], slope))

    def _apart(self, h, run) -> bool:
        """Lines ``h`` can be measured apart on ``run``: their mean frequencies each :data:`MIN_SEPARATION_BINS` + ½|c₁ −
        c₂| record bins apart or more.  Two lines of a sweep chirp nearly alike (c ∝ h): the chirp taken off, they
        are two steady lines as far apart, whose columns correlate as a steady pair's do (a bin apart: 0.67, two
        bins: 0.17, whatever c); only the difference of their chirps widens the least squares' need."""
        _, w, n, fs = run[:4]
        hs = np.sort(np.asarray(h, dtype=float))
        c = _chirp(hs, run[7], n, fs)
        need = MIN_SEPARATION_BINS + 0.5 * np.abs(np.diff(c))
        return bool(np.all(np.diff(hs * w / (2 * np.pi)) >= need * fs / n))

    def _solve(self, h, run):
        """(A (L, K) complex amplitudes, residual power) of lines ``h`` on one run's record, or None where two lines
        are too close to measure apart (:meth:`_apart`)."""
        _, w, n, fs, _, grid, X, slope = run
        if not self._apart(h, run):
            return None
        f = h * w / (2 * np.pi)
        c = _chirp(h, slope, n, fs)
        M = np.empty((grid.size, f.size), complex)
        for j in range(f.size):
            M[:, j] = 0.5 * chirp_transform(n, fs, grid - f[j], c[j])                      # (G,)
        A, *_ = np.linalg.lstsq(M, X, rcond=None)
        return A, float(np.sum(np.abs(X - M @ A) ** 2))

    def _costs(self, h) -> np.ndarray:
        """Residual power of lines ``h`` on each run (NaN where two lines are too close to measure apart)."""
        out = np.full(len(self.runs), np.nan)
        for i, run in enumerate(self.runs):
            got = self._solve(h, run)
            if got is not None:
                out[i] = got[1]
        return out

    def merge_smeared(self) -> None:
        """Neighbouring lines, one of them lost, that no run measures apart (:meth:`_apart`; a pair apart on the slow,
        nearly steady top of a run-up stays two) are one line's smear: a lost line beside a measured one is dropped;
        lost ones become one lost line at their mean h.  Only where some run's lines chirp |c| ≥
        :data:`SMEAR_MIN_BINS`: on steady runs (and a sweep so slow that a line moves less than that) two lines within
        a record bin of each other are two lines the records cannot split (``line_property`` "blended_lines" describes
        them), not one smeared line."""
        chirped = [run for run in self.runs if abs(_chirp(self.h.max(), run[7], run[2], run[3])) >= SMEAR_MIN_BINS]
        merged = np.ones(self.h.size)           # lines each lost line stands for (its h their mean)
        while chirped:
            order = np.argsort(self.h)
            pair = next(((a, b) for a, b in zip(order[:-1], order[1:]) if (a in self.lost or b in self.lost)
                         and not any(self._apart(self.h[[a, b]], run) for run in self.runs)), None)
            if pair is None:
                return
            a, b = pair
            if a in self.lost and b in self.lost:
                self.h[a] = (merged[a] * self.h[a] + merged[b] * self.h[b]) / (merged[a] + merged[b])
                merged[a] += merged[b]
            drop = b if b in self.lost else a
            self.h, merged = np.delete(self.h, drop), np.delete(merged, drop)
            self.lost = [int(j - (j > drop)) for j in self.lost if j != drop]

    def refine(self) -> None:
        """Each lost line's h: the least residual power within ±eps, summed over the runs that every point of the
        grid solves (a point where two lines come closer than a bin solves fewer runs: compared on fewer, it would
        win)."""
        for j in self.lost:
            if abs(self.h[j] - 1.0) < ONCE_PER_REV_TOL:
                self.h[j] = 1.0         # the rotation itself: h is 1, whatever its neighbours make of the fit's grid
                continue
            grid = self.h[j] + np.linspace(-self.eps, self.eps, 2 * H_STEPS + 1)
            grid_costs = []
            for hj in grid:
                h = self.h.copy()
                h[j] = hj
                grid_costs.append(self._costs(h))
            costs = np.array(grid_costs)                                              # (grid, runs)
            common = np.all(np.isfinite(costs), axis=0)
            if common.any():
                self.h[j] = grid[int(np.argmin(costs[:, common].sum(axis=1)))]

    def add_mirrors(self, min_points: int) -> None:
        """For a lone lost line h₀ − δ beside the span's strongest line h₀ (δ up to :data:`MIRROR_MAX_PER_REV`, no
        line within eps of h₀ + δ), its mirror h₀ + δ (and the other way round) added as a lost line, refined, and
        kept when it is measured in ``min_points`` runs or more at :data:`MIRROR_MIN_RATIO` of the lone line's median
        amplitude or more (the two sides of a modulation are alike; a weaker "mirror" is the fit's own leakage)."""
        if not self.runs or len(self.h) < 2:
            return
        amps = [self.measurements(j)[2] for j in range(len(self.h))]
        strength = [float(np.median(a)) if a.size else 0.0 for a in amps]
        c = int(np.argmax(strength))
        for j in list(self.lost):
            mirror = 2 * self.h[c] - self.h[j]
            if j == c or mirror <= 0 or abs(mirror - self.h[c]) > MIRROR_MAX_PER_REV \
                    or np.any(np.abs(self.h - mirror) < self.eps):
                continue
            before = (self.h.copy(), list(self.lost))
            self.h = np.append(self.h, mirror)
            self.lost.append(len(self.h) - 1)
            self.refine_one(len(self.h) - 1)
            amp = self.measurements(len(self.h) - 1)[2]
            if amp.size < min_points or np.median(amp) < MIRROR_MIN_RATIO * strength[j]:
                self.h, self.lost = before

    def refine_one(self, j: int) -> None:
        """:meth:`refine` of line ``j`` alone."""
        lost, self.lost = self.lost, [j]
        self.refine()
        self.lost = lost

    def measurements(self, j: int) -> tuple:
        """(|Ω| rad/s, channel, amplitude) arrays of line ``j``'s measurements kept (module docstring)."""
        w_out, ch_out, a_out = [], [], []
        for run in self.runs:
            got = self._solve(self.h, run)
            if got is None:
                continue
            A = got[0]
            r, w, n, fs, chs = run[:5]
            f = self.h[j] * w / (2 * np.pi)
            for k, c in enumerate(chs):
                fl = self.floors.get(c)
                if fl is None or not np.all(np.isfinite(fl[1][r])):
                    continue
                noise = float(np.interp(f, self.f_axis, fl[1][r])) * fs / 2 * 3 * n / 8
                amp = float(np.abs(A[j, k]))
                if (amp * n / 4) ** 2 >= MIN_SNR * noise:
                    w_out.append(w)
                    ch_out.append(c)
                    a_out.append(amp)
        return np.asarray(w_out, float), np.asarray(ch_out, dtype=object).astype(str), np.asarray(a_out, float)


def _chirp(h, slope: float, n: int, fs: float) -> np.ndarray:
    """Record bins (signed) a line of harmonic ``h`` sweeps across a record of ``n`` samples at ``fs`` Hz while the
    speed changes at ``slope`` = d|Ω|/dt rad/s² (0 on a steady run)."""
    return np.asarray(h, dtype=float) * slope * (n / fs) ** 2 / (2 * np.pi)


def chirp_transform(n: int, fs: float, offset_hz: np.ndarray, c: float) -> np.ndarray:
    """Σ_m w[m]·e^{jπc(m/n − ½)²}·e^{−2πj·offset·m/fs}: the periodic Hann window's transform (:func:`rwadist.dft.
    hann_transform`) of a linear chirp sweeping ``c`` record bins across the record, at ``offset_hz`` (1-D) from its
    mean frequency.  For |c| below :data:`CHIRP_MIN_BINS` the steady line's closed form; otherwise a table
    (:func:`_chirp_table`) linearly interpolated."""
    offset_hz = np.asarray(offset_hz, dtype=float)
    if abs(c) < CHIRP_MIN_BINS:
        return hann_transform(n, fs, offset_hz)
    bins = offset_hz * n / fs
    reach = 8 * int(np.ceil((np.max(np.abs(bins)) + 1) / 8))
    at, table = _chirp_table(n, round(c * CHIRP_C_STEPS) / CHIRP_C_STEPS, reach)
    return (np.interp(bins, at, table.real) + 1j * np.interp(bins, at, table.imag)) * _turn(bins, n)


def _turn(bins, n: int) -> np.ndarray:
    """e^{−jπ·δ(n − 1)/n}: about the linear phase of a window's transform at δ bins (the delay of its centre, n/2
    samples for the periodic Hann), which turns by π per bin: taken off the table (and put back exactly), the rest is
    smooth to interpolate."""
    return np.exp(-1j * np.pi * np.asarray(bins, dtype=float) * (n - 1) / n)


@functools.lru_cache(maxsize=1024)
def _chirp_table(n: int, c: float, reach: int) -> tuple:
    """(offsets in bins, transform) of :func:`chirp_transform` on :data:`CHIRP_TABLE_STEPS` points per bin from
    −``reach`` to ``reach`` bins: the zoom FFT (:func:`scipy.signal.zoom_fft`) of the windowed chirp (one per run
    length, chirp and reach: the lines of a span ask for the same few on every step of their h grids)."""
    from scipy.signal import zoom_fft

    m = 2 * reach * CHIRP_TABLE_STEPS + 1
    x = np.arange(n) / n - 0.5
    table = zoom_fft(run_window("hann", n)[0] * np.exp(1j * np.pi * c * x**2), [-reach, reach], m=m, fs=n,
                     endpoint=True)
    at = np.linspace(-reach, reach, m)
    return at, table / _turn(at, n)
