"""``speed_sidebands``: a pair of lines at (h₀ ± δ)·|Ω| beside a strong model line (a modulation at a frequency
proportional to the speed), searched on the speeds where they stand resolved from their carrier."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from ..dft import BlockedRecords
from ..diagnose.constants import LINE_HALF
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.measure import _measure, refine_h
from ..diagnose.state import State
from ..empirical import line_C
from ..extended import LAW_H_TOL
from ..model import Harmonic
from ..units import CHANNELS, DIRECTION_CHANNELS

#: Smallest separation (Welch bins) between a sideband and its carrier for a run to count: the Hann main lobe
#: is ±2 bins, so closer sidebands sit in the carrier's own kernel and are not measured there; half a bin more
#: for the scalloping of lines that are not bin-centred (beyond 2.5 bins the carrier's leakage is < −30 dB).
MIN_BINS = 2.5
#: Per-revolution offsets δ searched (fractions of the wheel speed).
DELTA_GRID = np.arange(0.01, 0.30001, 0.0025)
#: Farthest a fitted side's h lies from its carrier: the Welch route refines a side within half its δ (1.5·δ), the
#: record route within its grids' ±0.0131 of h₀ ± δ.
REACH = 1.5 * float(DELTA_GRID[-1])


#: Window of the whole-run DFT the sidebands are measured with when the time series are given: Hann, whose main
#: lobe (±2 record bins of fs/n: 4× finer than the Welch bins of n/4 segments) keeps the pair apart at low speeds;
#: the carrier's leakage beyond it (sidelobes from −31 dB) is subtracted with the carrier's own phasor
#: (:func:`_run_line_power`; the window's transform in closed form, :func:`rwadist.dft.hann_transform`: Hann only).
RUN_WINDOW = "hann"
#: Smallest separation (record bins) of a sideband from its carrier and from every other line of the direction
#: in the whole-run route: the edge of the Hann main lobe (±2 bins; beyond it the transform is below −31 dB, and
#: the carrier's part of it is subtracted).  No scalloping margin: the phasor is taken at the line's own frequency.
RUN_MIN_BINS = 2.0
#: Samples (runs × record length × channels) transformed together by :func:`_run_line_power`: a few tens of MB.
RUN_CHUNK_SAMPLES = 1 << 20
#: Bytes of windowed records :func:`_run_records` keeps on a context (those asked for again), at most
RUN_RECORDS_KEPT_BYTES = 1 << 26


def _scan_key(direction: str, h0: float, runs) -> tuple:
    """Key of the data's line powers of :meth:`SpeedSidebands._scan_record` on the context."""
    return ("speed_sidebands_scan", direction, round(h0, 6), np.asarray(runs).tobytes())


def _record_df(ctx: Context, runs) -> np.ndarray:
    """Frequency resolution fs/n (Hz) of each run's whole record (all runs' computed once per context: the search
    asks for it per δ and side)."""
    if "record_df" not in ctx._memo:
        ctx._memo["record_df"] = np.array([run.sample_rate / run.n_samples for run in ctx.test.runs], dtype=float)
    return ctx._memo["record_df"][np.asarray(runs, dtype=int)]


def _smear_hz(ctx: Context, runs, h0: float) -> np.ndarray:
    """How far (Hz) the line h0·|Ω| moves within each run of ``runs``: h0 × the speed's change over the run's record
    (a sweep's slice, ``meta["slicing"]["speed_spread_rpm"]``, :func:`rwadist.sweep.slice_sweep`), 0 for steady runs.
    A side closer to its carrier than that lies in the carrier's own smear: family wheel 7's 60-s run-up (speed from
    the data, 150 rpm/s: h 3.42 smeared over ~12 Hz per slice) got a speed_sidebands pair at ±0.0116 in h (1 Hz)
    and a counter_rotation on each side -- one line three times in the model."""
    if "speed_spread_hz" not in ctx._memo:
        spread = ((getattr(ctx.test, "meta", None) or {}).get("slicing") or {}).get("speed_spread_rpm")
        n = len(ctx.test.runs) if ctx.test is not None else ctx.omega.size
        ok = spread is not None and len(spread) == n
        ctx._memo["speed_spread_hz"] = np.asarray(spread, float) / 60.0 if ok else np.zeros(n)
    return abs(h0) * ctx._memo["speed_spread_hz"][np.asarray(runs, dtype=int)]


def resolvable_runs(ctx: Context, state: State, direction: str, h0: float, h_side: float, runs) -> np.ndarray:
    """The runs of ``runs`` where the line h_side·|Ω| is in band, at least MIN_BINS Welch bins from its carrier h0
    beyond the carrier's smear over the run (:func:`_smear_hz`) and 2·LINE_HALF bins from every other line of the
    direction's model: there the residual PSD measures it alone."""
    w = ctx.omega[runs] / (2 * np.pi)
    f = h_side * w
    ok = (np.abs(h_side - h0) * w >= MIN_BINS * ctx.df + _smear_hz(ctx, runs, h0)) \
        & (f >= (ctx.k_lo + LINE_HALF) * ctx.df) \
        & (f <= (ctx.k_hi - LINE_HALF) * ctx.df)
    for x in state.model.harmonics(direction):
        if abs(x.h - h0) > 1e-6:
            ok &= np.abs(x.h - h_side) * w >= 2 * LINE_HALF * ctx.df
    return runs[ok]


def record_resolvable_runs(ctx: Context, state: State, direction: str, h0: float, h_side: float,
                           runs) -> np.ndarray:
    """As :func:`resolvable_runs` for the whole-run DFT (time series given, :func:`_run_line_power`): the line in
    band and at least RUN_MIN_BINS record bins (fs/n) from its carrier and from every other line of the direction,
    the state's fixed-offset sidebands (``sidebands``) included."""
    return runs[_record_resolvable(ctx, state, direction, h0, np.array([h_side]), runs)[:, 0]]


def _record_resolvable(ctx: Context, state: State, direction: str, h0: float, h_side: np.ndarray,
                       runs) -> np.ndarray:
    """(len(runs), len(h_side)) mask of :func:`record_resolvable_runs` for every line h_side·|Ω| of ``h_side``
    at once."""
    w = (ctx.omega[runs] / (2 * np.pi))[:, None]
    f = h_side[None, :] * w
    sep = RUN_MIN_BINS * _record_df(ctx, runs)[:, None]
    ok = (np.abs(h_side - h0)[None, :] * w >= sep + _smear_hz(ctx, runs, h0)[:, None]) \
        & (f >= (ctx.k_lo + LINE_HALF) * ctx.df) \
        & (f <= (ctx.k_hi - LINE_HALF) * ctx.df)
    for x in state.model.harmonics(direction):
        if abs(x.h - h0) > 1e-6:
            ok &= np.abs(x.h - h_side)[None, :] * w >= sep
    # a fixed-offset pair the state predicts is a line there too: the held-out judge reads a point as one the state
    # predicts nothing at (family wheel 7, 5-Hz sidebands of the 1x named: speed sidebands 0.032 per rev, 5.3 Hz off at
    # the top speed, then took their power again as held-out evidence, 114 % of the misplaced power, and were named)
    for d, h_c, f_mod, _ in state.modulations:
        if d == direction:
            for side in (-1.0, 1.0):
                ok &= np.abs(f - (h_c * w + side * f_mod)) >= sep
    return ok


def side_pair_medians(z: np.ndarray, ok: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Per column j of ``cols``: the median of the values z[r, j, k] and z[r, L + j, k] over the runs r where ``ok``
    holds there and every k (the lower and upper side of a pair: ``z`` (runs, 2L, K), ``ok`` (runs, 2L)), 0 with
    fewer than 6 values, NaN when a value is NaN -- np.median of each column's values, for every column at once: the
    values sorted per column (the unused ones +inf, after them), the middle one, or the mean (a + b)/2 of the middle
    two as np.median takes it."""
    n_side = z.shape[1] // 2
    out = np.zeros(cols.size)
    if cols.size == 0:
        return out
    vals = np.concatenate([z[:, cols, :], z[:, n_side + cols, :]], axis=0)          # (2·runs, J, K)
    use = np.concatenate([ok[:, cols], ok[:, n_side + cols]], axis=0)[:, :, None]
    vals = np.moveaxis(np.where(use, vals, np.inf), 1, 0).reshape(cols.size, -1)      # (J, 2·runs·K)
    count = np.broadcast_to(use, (use.shape[0], cols.size, z.shape[2])).sum(axis=(0, 2))
    has_nan = np.isnan(vals).any(axis=1)
    srt = np.sort(vals, axis=1)
    rows = np.arange(cols.size)
    lo, hi = srt[rows, np.maximum((count - 1) // 2, 0)], srt[rows, np.minimum(count // 2, vals.shape[1] - 1)]
    med = np.where(count % 2 == 1, lo, (srt[rows, np.maximum(count // 2 - 1, 0)] + hi) / 2.0)
    out = np.where(count >= 6, np.where(has_nan, np.nan, med), 0.0)
    return out


def _run_records(ctx: Context, runs: np.ndarray, chans) -> "BlockedRecords":
    """The windowed records (:data:`RUN_WINDOW`) of channels ``chans`` of ``runs`` (one record length) in the layout of
    :func:`rwadist.dft.windowed_dfts` (:func:`rwadist.dft.blocked_records`), kept on the context from the second request
    for the same records on, up to :data:`RUN_RECORDS_KEPT_BYTES` in all: the sidebands' scans and fits and the search's
    later steps ask for the same runs' records at other frequencies (the same numbers as made anew)."""
    from ..dft import blocked_records, run_window

    key = ("run_records", np.asarray(runs).tobytes(), tuple(chans))
    kept = ctx._memo.get(key)
    if kept is not None and kept is not True:
        return kept
    made = blocked_records([[ctx.test.runs[r].signals[c] for c in chans] for r in runs],
                           run_window(RUN_WINDOW, ctx.test.runs[runs[0]].n_samples)[0])
    size = made.values.nbytes * 3 // 2                  # with its single-precision copy
    used = ctx._memo.get("run_records_bytes", 0)
    if kept is True and used + size <= RUN_RECORDS_KEPT_BYTES:
        ctx._memo[key], ctx._memo["run_records_bytes"] = made, used + size
    elif kept is None:
        ctx._memo[key] = True                           # asked once: kept if asked again
    return made


def _run_line_power(ctx: Context, state: State, direction: str, runs, f_hz, h0: float, need=None) -> tuple:
    """(|X|² (len(runs), L, n_chans), noise mean of |X|² same shape): the whole-run line powers of the direction's
    channels at ``f_hz`` (len(runs), L) Hz (:func:`_line_powers`) and the mean |X|² white noise of the state's floor S
    gives there, 2·S·fs·Σw²/(Σw)² (:func:`_run_noise`)."""
    chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
    return _line_powers(ctx, chans, runs, f_hz, h0, need), _run_noise(ctx, state, chans, runs, f_hz)


def _line_powers(ctx: Context, chans, runs, f_hz, h0: float, need=None, single: bool = False) -> np.ndarray:
    """|X|² (len(runs), L, len(chans)): the whole-run line powers of channels ``chans`` at ``f_hz`` (len(runs), L) Hz,
    Hann-windowed (:data:`RUN_WINDOW`; X = 2·Σ w x e^{−2πj f t}/Σ w, so a line a·cos(2π f t + φ) gives |X| = a), less
    the leakage of the carrier h0: X(f) − X(f_c)·W(f − f_c)/W(0), f_c = h0|Ω|/2π, W the window's transform (a line at
    f_c puts X(f_c)·W(f − f_c)/W(0) at f).  ``need`` (len(runs), L) bool, optional: only those phasors are computed,
    the others are NaN (the scan's unresolvable points, which it never reads).  The data's alone (no state).
    ``single``: the sums in single precision (:func:`rwadist.dft.windowed_dfts`), for a scan: a phasor is then exact to
    ~1e-7 of the record's strongest line, the carrier's leakage taken off with it (measured: 3e-3 of the noise's |X|
    beside a carrier 60 dB over the samples' noise, the matrix's 0.1 % noise; 1e-5 of the noise's power).

    The runs of one record length are transformed together (:func:`rwadist.dft.windowed_dfts`: every channel of
    ``chans`` with one table of phasors), each at its needed frequencies (moved to the front of its row; the rest of
    the row padded with its carrier), in chunks of :data:`RUN_CHUNK_SAMPLES` samples; W in closed form
    (:func:`rwadist.dft.hann_transform`)."""
    from ..dft import hann_transform, windowed_dfts

    if need is None:
        need = np.ones(f_hz.shape, dtype=bool)
    X = np.full((runs.size, f_hz.shape[1], len(chans)), np.nan + 0j)
    for n, fs, wsum, rows in _run_chunks(ctx, runs, np.flatnonzero(need.any(axis=1)), len(chans)):
        nd = need[rows]
        pick = np.argsort(~nd, axis=1, kind="stable")[:, :int(nd.sum(1).max())]
        valid = np.take_along_axis(nd, pick, axis=1)
        f_c = h0 * ctx.omega[runs[rows]] / (2 * np.pi)
        f_i = np.where(valid, np.take_along_axis(f_hz[rows], pick, axis=1), f_c[:, None])
        x = _run_records(ctx, np.asarray(runs)[rows], chans)
        both = 2.0 * windowed_dfts(x, fs, np.column_stack([f_i, f_c]), single=single) / wsum
        leak = hann_transform(n, fs, f_i - f_c[:, None]) / wsum                      # W(f − f_c)/W(0)
        r, j = np.nonzero(valid)
        X[rows[r], pick[r, j]] = both[r, j] - leak[r, j, None] * both[r, -1]
    return np.abs(X) ** 2


def _run_chunks(ctx: Context, runs, rows_wanted, n_chans: int):
    """Yield ``(n, fs, wsum, rows)``: the rows ``rows_wanted`` of ``runs`` grouped by (record length n, sample rate fs
    Hz), in chunks of at most :data:`RUN_CHUNK_SAMPLES` samples x ``n_chans`` channels, with the sum of the
    :data:`RUN_WINDOW` window's weights ``wsum`` of a record of n samples (rows: int array into ``runs``)."""
    from ..dft import run_window

    groups: dict[tuple[int, float], list[int]] = {}            # rows by (record length, sample rate)
    for i in rows_wanted:
        run = ctx.test.runs[runs[i]]
        groups.setdefault((run.n_samples, run.sample_rate), []).append(int(i))
    for (n, fs), rows_all in groups.items():
        _, wsum, _ = run_window(RUN_WINDOW, n)
        step = max(1, RUN_CHUNK_SAMPLES // (n * max(n_chans, 1)))
        for s in range(0, len(rows_all), step):
            yield n, fs, wsum, np.asarray(rows_all[s:s + step])


#: Most frequency x (sample block, channel) elements of one record that :func:`_carrier_line_powers` transforms at once
#: (:func:`rwadist.dft.windowed_dfts` holds ~24 bytes each for one record: its phasor table, float32 products and complex
#: sums, whatever its own chunking): the carriers are taken in batches under it, at least one carrier a batch.
CARRIER_BATCH_ELEMENTS = 1 << 22


def _carrier_batches(widths, n: int, n_chans: int) -> list:
    """Consecutive carriers [[k, ...], ...] of frequency counts ``widths`` (each carrier's points and its own phasor)
    whose elements (frequencies x (blocks of 128 samples of a record of ``n``) x ``n_chans``) stay within
    :data:`CARRIER_BATCH_ELEMENTS`: the transient of one transform bounded whatever the number of carriers."""
    per_f = max(128, -(-n // 128) * max(n_chans, 1))
    out: list[list[int]] = []
    size = 0
    for k, w_k in enumerate(widths):
        need = (int(w_k) + 1) * per_f
        if out and size + need <= CARRIER_BATCH_ELEMENTS:
            out[-1].append(k)
            size += need
        else:
            out.append([k])
            size = need
    return out


def _carrier_line_powers(ctx: Context, chans, runs, f_list, hs, single: bool = False) -> list:
    """``[_line_powers(ctx, chans, runs, f, h, single=single) for f, h in zip(f_list, hs)]`` (each f (len(runs), L_k)
    Hz, every point needed) with one transform per chunk of runs for all the carriers ``hs``: their frequencies and the
    carriers themselves in one table (:func:`rwadist.dft.windowed_dfts`: each phasor is its own frequency's, whatever
    others are transformed with it), each carrier's leakage taken off its own points as :func:`_line_powers` does --
    the same numbers, one set of tables and products instead of one per carrier (the ``sidebands`` scans ask for
    every carrier of a direction on the same runs).  The carriers in batches of :func:`_carrier_batches` (a
    transform's transient grows with its frequencies: at most :data:`CARRIER_BATCH_ELEMENTS` a record)."""
    from ..dft import hann_transform, windowed_dfts

    runs = np.asarray(runs)
    widths = [int(f.shape[1]) for f in f_list]
    out = [np.full((runs.size, w_k, len(chans)), np.nan + 0j) for w_k in widths]
    for n, fs, wsum, rows in _run_chunks(ctx, runs, range(runs.size if sum(widths) else 0), len(chans)):
        f_c = [h * ctx.omega[runs[rows]] / (2 * np.pi) for h in hs]
        f_i = [np.asarray(f, dtype=float)[rows] for f in f_list]
        x = _run_records(ctx, runs[rows], chans)
        for ks in _carrier_batches(widths, n, len(chans)):
            e = np.concatenate([[0], np.cumsum([widths[k] for k in ks])]).astype(int)
            both = 2.0 * windowed_dfts(x, fs, np.column_stack([f_i[k] for k in ks] + [f_c[k] for k in ks]),
                                       single=single) / wsum
            for j, k in enumerate(ks):
                leak = hann_transform(n, fs, f_i[k] - f_c[k][:, None]) / wsum               # W(f − f_c)/W(0)
                out[k][rows] = both[:, e[j]:e[j + 1]] - leak[:, :, None] * both[:, e[-1] + j][:, None, :]
    return [np.abs(X) ** 2 for X in out]


def _run_noise(ctx: Context, state: State, chans, runs, f_hz) -> np.ndarray:
    """Mean |X|² (len(runs), L, len(chans)) that white noise of the state's floor S puts into the whole-run phasor
    at ``f_hz``: 2·S·fs·Σw²/(Σw)² (:data:`RUN_WINDOW`)."""
    from ..dft import run_window

    enbw = np.empty(runs.size)
    for i, r in enumerate(runs):
        run = ctx.test.runs[r]
        _, wsum, w2sum = run_window(RUN_WINDOW, run.n_samples)
        enbw[i] = run.sample_rate * w2sum / wsum ** 2
    k = np.clip(np.rint(f_hz / ctx.df).astype(int), 0, ctx.f.size - 1)
    noise = np.stack([np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1) for c in chans], axis=-1)
    return 2.0 * noise * enbw[:, None, None]



def _record_carrier_C(ctx: Context, state: State, direction: str, h0: float, sides: tuple, runs) -> float | None:
    """The carrier's C (:func:`~rwadist.empirical.line_C`) from its whole-run DFT amplitude |X|
    (:meth:`Context.phasors`, the fixed resonances divided out) on the runs where both sides stand :data:`RUN_MIN_BINS` record bins from it, or None (fewer than 3
    such runs)."""
    sub = runs
    for h in sides:
        sub = np.intersect1d(sub, record_resolvable_runs(ctx, state, direction, h0, h, runs))
    if sub.size < 3:
        return None
    f = h0 * ctx.omega[sub] / (2 * np.pi)
    X = ctx.phasors(sub, f[:, None])[:, 0, :]
    d_parts, w_parts = [], []
    for c in DIRECTION_CHANNELS[direction]:
        if c in ctx.channels:
            a = np.abs(X[:, CHANNELS.index(c)]) / ctx.gain(state, c, f)
            ok = np.isfinite(a)
            d_parts.append(a[ok])
            w_parts.append(ctx.omega[sub][ok])
    return _positive_C(np.concatenate(d_parts), np.concatenate(w_parts))


def _positive_C(d: np.ndarray, w: np.ndarray):
    """The C of amplitudes ``d`` (unit) against speeds ``w`` (rad/s), d = C·w² (:func:`rwadist.empirical.line_C`);
    None with fewer than 3 points or a C that is not positive."""
    if d.size < 3:
        return None
    C = line_C(d, w)
    return C if C > 0 else None

@register(order=15)
@dataclass
class SpeedSidebands:
    """Two lines of the carrier's rotation sense at h_lower·|Ω| and h_upper·|Ω| (h_lower < h₀ < h_upper) beside the
    carrier line h₀ of a direction: an amplitude modulation of the carrier at δ·|Ω| (a cage or a bearing defect's once-per-δ-rev
    beat, a tone ring) puts them at (h₀ ± δ)|Ω| with amplitudes (m/2)·C₀Ω² each.  They move with the speed, so
    they are harmonics (``missing_harmonic`` would take each, if it could see them): the model file gets two
    harmonics C_lower, C_upper (every consumer reads them) and this record.  Close to a strong line they are
    resolved only at the higher speeds (δ|Ω|/2π >= MIN_BINS Welch bins, :func:`resolvable_runs`, or RUN_MIN_BINS
    record bins on the whole-run DFT when the time series are given, :func:`record_resolvable_runs`): the search
    and the fit use those runs; the prediction holds at every speed."""

    direction: str
    h0: float
    h_lower: float
    h_upper: float
    C_lower: float
    C_upper: float
    C_carrier: float
    n_points: int = 0
    kind: str = "speed_sidebands"
    #: two narrow lines beside a strong carrier: beside the share of the misplaced power, judged on the share of the
    #: narrow-line misfit they take (:func:`rwadist.diagnose.search._narrow_judge`).  The session-55 new-user trial's
    #: 7 kg wheel on a 162 Hz fixture: its 3 % sidebands of the imbalance fitted at t ≈ 1600, 2.6-4.8 % of the
    #: misplaced power the fixture's compromise leaves (under min_gain) and left out, with nothing said
    judged_on_narrow_lines: ClassVar[bool] = True
    #: the carrier's C read on the whole records apart from the pair (empirical base, :func:`_record_carrier_C`),
    #: which the carrier takes when applied; 0: the state's kept
    carrier_record_C: float = 0.0

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        s = state.copy()
        if self.carrier_record_C > 0 and s.ext is None:
            # the empirical base fitted the carrier on Welch bins that hold the pair at the low speeds: its C took
            # their power (family wheel 4 hard mounted, 0.95/1.05 at 20 %: +4 %, and the pair on top failed its refit)
            parts = [x for x in s.model.harmonics(self.direction) if abs(x.h - self.h0) < LAW_H_TOL and x.C > 0]
            norm = float(np.sqrt(sum(x.C**2 for x in parts)))
            scale = self.carrier_record_C / norm if norm > 0 else 1.0
            s.model.empirical[self.direction] = [replace(x, C=x.C * scale) if any(x is p for p in parts) else x
                                                 for x in s.model.harmonics(self.direction)]
        # a rotating load modulated in size, (1 + m·cos δΩt)·C·e^{±iΩt}, is the carrier and two lines (m/2)·C at
        # (1 ± δ)Ω of the carrier's own rotation sense: each part of the carrier (co, counter) gets its share of the
        # pair (written with no sense, every consumer read them co-rotating)
        new = [Harmonic(h=round(h, 4), C=C * share, n_points=self.n_points, sense=sense)
               for sense, share in self.carrier_parts(state)
               for h, C in ((self.h_lower, self.C_lower), (self.h_upper, self.C_upper))]
        s.model.empirical[self.direction] = sorted(s.model.harmonics(self.direction) + new, key=lambda x: x.h)
        s.effects.append(self)
        return s

    def carrier_parts(self, state: State) -> list:
        """[(sense, share)] of the model's carrier line h0 in ``state``: each rotation-sense part of it ('co',
        'counter', 'planar') and its share C_part/√(ΣC²) of the carrier's amplitude (the shares' squares sum to 1: the
        pair keeps its measured power); [(None, 1.0)] for an axial line or a carrier the model does not hold."""
        parts = [x for x in state.model.harmonics(self.direction) if abs(x.h - self.h0) < LAW_H_TOL and x.C > 0]
        norm = float(np.sqrt(sum(x.C**2 for x in parts)))
        if self.direction == "axial_force" or norm <= 0:
            return [(None, 1.0)]
        return [(x.sense, x.C / norm) for x in parts]

    def refit(self, ctx: Context, state: State) -> "SpeedSidebands":
        """Refitted on every run (``ctx.runs``); itself when that fit fails."""
        return SpeedSidebands.fit(ctx, state, self.direction, self.h0, ctx.runs,
                                  0.5 * (self.h_upper - self.h_lower)) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of a pair the Welch PSDs do not resolve from its carrier (None otherwise: the search's own
        judge), as :meth:`rwadist.effects.sidebands_diagnose.Sidebands.heldout_evidence` for a fixed offset.

        Where a side is MIN_BINS Welch bins from the carrier in fewer than 3 of ``runs`` (:func:`resolvable_runs`;
        family wheel 1 at 10 kHz, 2048-sample segments: 0.06 x 10000 rpm is 2.05 bins), the pair sits in the
        carrier's own Welch kernel and beats with it there: the judge, which grants no allowance for the beat of a
        line it adds beside another, saw the true pair (depth 0.40 of 0.40) raise the held-out misfit by 5 % while
        the refit on every run took the error from 5.9x to 1.0x the clean level.  The whole record resolves it
        (RUN_MIN_BINS record bins, :func:`record_resolvable_runs`, the carrier's leakage taken off by
        :func:`_run_line_power`): (drop, se) of the misplaced power at both sides on the resolved points
        (:func:`~rwadist.effects.missing_harmonic_diagnose.record_line_evidence`; the state predicts no line there,
        the effect its side's amplitude in the channel, modes and fixed resonances included).  Not on a state with a
        spin smear or a speed ripple (their lines are no steady lines on the record)."""
        from .missing_harmonic_diagnose import record_line_evidence

        if ctx.test is None or state.smear is not None or state.speed_modulation is not None:
            return None
        sides = np.array([self.h_lower, self.h_upper])
        if all(resolvable_runs(ctx, state, self.direction, self.h0, h, runs).size >= 3 for h in sides):
            return None
        ok = _record_resolvable(ctx, state, self.direction, self.h0, sides, runs)          # (runs, 2)
        if ok.sum() < 6:
            return None
        f = np.outer(ctx.omega[runs] / (2 * np.pi), sides)
        P, N = _run_line_power(ctx, state, self.direction, runs, f, self.h0, need=ok)
        applied = self.apply(state)
        chans = [c for c in DIRECTION_CHANNELS[self.direction] if c in ctx.channels]
        m1 = np.zeros((len(chans),) + f.shape)
        for j, c in enumerate(chans):
            for k, h in enumerate(np.round(sides, 4)):
                # the side's every rotation-sense part (a carrier split co/counter gives its pair two, apply())
                a2 = [x[2] ** 2 for x in ctx.channel_lines(applied, c, runs) if abs(x[0] - h) < 1e-6]
                if not a2:
                    return None
                m1[j, :, k] = sum(a2) * ctx.gain(applied, c, f[:, k]) ** 2
        P = np.moveaxis(P, 2, 0).reshape(len(chans), -1)
        N = np.moveaxis(N, 2, 0).reshape(len(chans), -1)
        use = np.broadcast_to(ok.reshape(1, -1), P.shape)
        return record_line_evidence(ctx, chans, P, N, use, m1.reshape(len(chans), -1))

    def params(self) -> dict:
        c0 = self.C_carrier
        return {"direction": self.direction, "h": round(self.h0, 4), "h_lower": round(self.h_lower, 4),
                "h_upper": round(self.h_upper, 4), "per_rev": round(0.5 * (self.h_upper - self.h_lower), 4),
                "C_lower": self.C_lower, "C_upper": self.C_upper,
                "ratio_lower": self.C_lower / c0 if c0 > 0 else float("nan"),
                "ratio_upper": self.C_upper / c0 if c0 > 0 else float("nan"),
                "depth": (self.C_lower + self.C_upper) / c0 if c0 > 0 else float("nan"), "n_points": self.n_points,
                "law": "lines of the carrier's rotation sense, C_lower*omega^2 at h_lower*|omega| and C_upper*omega^2 "
                       "at h_upper*|omega| (harmonics of the model); ratio = C/C of the carrier h, depth = ratio_lower + ratio_upper"}

    @staticmethod
    def _carrier_C(state: State, direction: str, h0: float) -> float:
        """Free-load C of the carrier (an imbalance's U_s or U_d on the extended base)."""
        if state.ext is not None:
            from .. import extended as ext

            g = [ln.C for ln in state.ext_lines() if ln.direction == direction and abs(ln.h - h0) < ext.LAW_H_TOL]
            if g:
                return float(np.sqrt(np.sum(np.square(g))))
        return float(np.sqrt(sum(x.C**2 for x in state.model.harmonics(direction) if abs(x.h - h0) < 1e-6)))

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h0: float, runs, delta: float) -> "SpeedSidebands | None":
        """Each side's h refined on its residual peaks (:func:`rwadist.diagnose.measure.refine_h`) and its C by
        :func:`~rwadist.empirical.line_C` on the amplitudes measured (modal gain divided out), both on the runs where
        that side is resolved (:func:`resolvable_runs`); None when a side has fewer than 3 measured points or no
        positive C."""
        if ctx.test is not None:
            return SpeedSidebands._fit_record(ctx, state, direction, h0, runs, delta)
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        out = []
        for side in (-1.0, 1.0):
            h = h0 + side * delta
            sub = resolvable_runs(ctx, state, direction, h0, h, runs)
            if sub.size < 3:
                return None
            h = refine_h(ctx, state, chans, sub, h)
            if not (0 < side * (h - h0) and abs(h - (h0 + side * delta)) < 0.5 * delta):
                return None
            sub = resolvable_runs(ctx, state, direction, h0, h, runs)
            d, w = _measure(ctx, state, direction, h, sub)
            C = _positive_C(d, w)
            if C is None:
                return None
            out.append((h, C, d.size))
        return SpeedSidebands._from_sides(state, direction, h0, out)

    @staticmethod
    def _fit_record(ctx: Context, state: State, direction: str, h0: float, runs, delta: float):
        """:meth:`fit` on the whole-run DFT (time series given): each side's h is the maximum of the summed line
        power Σ|X|² over a grid h₀ ± δ ± 0.0125 (step 0.0005, then ± 0.0006 in steps of 0.00002, each refined by a
        parabola through the top three) on the runs where it is resolved; its C by :func:`~rwadist.empirical.line_C`
        on the amplitudes sqrt(|X|² − noise) of the points standing 10 × over the noise, divided by the fixed resonances' and the modal gain (the line before the mount)."""
        out = []
        for side in (-1.0, 1.0):
            h = h0 + side * delta
            sub = record_resolvable_runs(ctx, state, direction, h0, h, runs)
            if sub.size < 3:
                return None
            # coarse, then fine: the scan's δ can sit a grid step or two off the pair (its median favours the few
            # fastest runs resolved at a larger δ, where the pair's own main lobe still lifts the score)
            for half, step in ((0.0125, 0.0005), (0.0006, 0.00002)):
                grid = h + np.arange(-half, half + 0.5 * step, step)
                grid = grid[side * (grid - h0) > 0]
                P, _ = _run_line_power(ctx, state, direction, sub, np.outer(ctx.omega[sub] / (2 * np.pi), grid), h0)
                tot = P.sum(axis=(0, 2))
                i = int(np.argmax(tot))
                if not 0 < i < grid.size - 1:
                    return None                         # the peak at the grid's edge: no line near h0 ± δ
                lo, mid, hi = np.log(np.maximum(tot[i - 1:i + 2], 1e-300))
                den = lo - 2 * mid + hi
                h = float(grid[i] + (0.5 * (lo - hi) / den if den < 0 else 0.0) * step)
            sub = record_resolvable_runs(ctx, state, direction, h0, h, runs)
            if sub.size < 3:
                return None
            f = (h * ctx.omega[sub] / (2 * np.pi))[:, None]
            P, N = _run_line_power(ctx, state, direction, sub, f, h0)
            chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
            d_parts, w_parts = [], []           # per channel: line amplitudes and speeds (rad/s) of the runs kept
            for j, c in enumerate(chans):
                ok = P[:, 0, j] > 10.0 * N[:, 0, j]
                a = np.sqrt(np.maximum(P[:, 0, j] - N[:, 0, j], 0.0)) / ctx.gain(state, c, f[:, 0])
                if state.ext is not None:
                    a = a / ctx.modal_gain(state, c, h, sub)
                d_parts.append(a[ok])
                w_parts.append(ctx.omega[sub][ok])
            d, w = np.concatenate(d_parts), np.concatenate(w_parts)
            C = _positive_C(d, w)
            if C is None:
                return None
            out.append((h, C, d.size))
        e = SpeedSidebands._from_sides(state, direction, h0, out)
        if state.ext is None:
            c0 = _record_carrier_C(ctx, state, direction, h0, (out[0][0], out[1][0]), runs)
            if c0 is not None:
                e = replace(e, carrier_record_C=c0, C_carrier=c0)
        return e

    @staticmethod
    def _from_sides(state: State, direction: str, h0: float, out) -> "SpeedSidebands":
        """The effect from the two sides' (h, C, number of points), lower side first."""
        (hl, cl, nl), (hu, cu, nu) = out
        return SpeedSidebands(direction, float(h0), float(hl), float(hu), cl, cu,
                              SpeedSidebands._carrier_C(state, direction, h0), int(nl + nu))

    @staticmethod
    def _scan_record(ctx: Context, state: State, direction: str, h0: float, runs) -> tuple:
        """:meth:`scan` on the whole-run DFT: per δ the median over channels, resolved runs and both sides of
        |X|² over the noise's mean at (h₀ ± δ)|Ω|/2π, the carrier's leakage taken off (:func:`_run_line_power`;
        the main lobe itself is kept clear by :func:`record_resolvable_runs`)."""
        grid = np.concatenate([h0 - DELTA_GRID, h0 + DELTA_GRID])
        f_hz = np.outer(ctx.omega[runs] / (2 * np.pi), grid)
        SpeedSidebands._prefetch_scans(ctx, [(direction, h0)], runs)
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        z = ctx._memo[_scan_key(direction, h0, runs)] / np.maximum(_run_noise(ctx, state, chans, runs, f_hz), 1e-300)
        ok = _record_resolvable(ctx, state, direction, h0, grid, runs)         # (runs, 2G): both sides of every δ
        n = DELTA_GRID.size
        score = np.zeros(n)
        cols = np.flatnonzero((ok[:, :n].sum(0) >= 3) & (ok[:, n:].sum(0) >= 3))
        score[cols] = side_pair_medians(z, ok, cols)
        return DELTA_GRID, score

    @staticmethod
    def _prefetch_scans(ctx: Context, jobs, runs) -> None:
        """The data's line powers of :meth:`_scan_record` for every (direction, h₀) of ``jobs`` not yet kept on the
        context (the same at every step of the search): the directions that share a carrier h₀ (an imbalance at h = 1
        in the radial forces, the radial torques and the axial force) transformed together, with one table of
        phasors for all their channels (:func:`_line_powers`), then kept per direction."""
        by_h0: dict[float, tuple[float, list[str]]] = {}
        for d, h0 in jobs:
            if _scan_key(d, h0, runs) not in ctx._memo:
                by_h0.setdefault(round(h0, 6), (h0, []))[1].append(d)
        for h0, dirs in by_h0.values():
            grid = np.concatenate([h0 - DELTA_GRID, h0 + DELTA_GRID])
            f_hz = np.outer(ctx.omega[runs] / (2 * np.pi), grid)
            # only where a point can be resolved on any step: in band and RUN_MIN_BINS record bins from the carrier
            # (the state-independent part of record_resolvable_runs; the same expressions, so the same booleans)
            w = ctx.omega[runs] / (2 * np.pi)
            need = (np.abs(grid - h0)[None, :] * w[:, None] >= RUN_MIN_BINS * _record_df(ctx, runs)[:, None]) \
                & (f_hz >= (ctx.k_lo + LINE_HALF) * ctx.df) & (f_hz <= (ctx.k_hi - LINE_HALF) * ctx.df)
            chans = {d: [c for c in DIRECTION_CHANNELS[d] if c in ctx.channels] for d in dirs}
            every = [c for d in dirs for c in chans[d]]
            P = _line_powers(ctx, every, runs, f_hz, h0, need, single=True)
            for d in dirs:
                ctx._memo[_scan_key(d, h0, runs)] = P[:, :, [every.index(c) for c in chans[d]]]

    @staticmethod
    def scan(ctx: Context, state: State, direction: str, h0: float, runs) -> tuple:
        """(δ grid, score): per δ of :data:`DELTA_GRID`, the median over the channels, resolved runs and both sides of
        the residual PSD at (h₀ ± δ)|Ω|/2π (the largest of the bin and its neighbours) over the run's model floor,
        i.e. how far above the noise a pair of lines at ±δ per revolution stands; 0 where a side is resolved in
        fewer than 3 runs (:meth:`fit` needs 3) or fewer than 6 values.
        Not clipped: beside a strong carrier the true pair stands out as the peak of a broad hump of skirts.
        With the time series (``ctx.test``): :meth:`_scan_record`, the whole-run DFT (4× finer than the Welch bins:
        the pair is resolved at lower speeds and shorter records)."""
        if ctx.test is not None:
            return SpeedSidebands._scan_record(ctx, state, direction, h0, runs)
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        z = {}
        for c in chans:
            R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
            zz = R / ctx.floor_psd(state, c, runs)
            z[c] = np.maximum(np.maximum(zz, np.roll(zz, 1, axis=1)), np.roll(zz, -1, axis=1))
        pos = {r: i for i, r in enumerate(runs)}
        score = np.zeros(DELTA_GRID.size)
        for j, dl in enumerate(DELTA_GRID):
            parts: list[np.ndarray] = []        # per side and channel: the z of the sideband's bin per run
            for side in (-1.0, 1.0):
                sub = resolvable_runs(ctx, state, direction, h0, h0 + side * dl, runs)
                if sub.size < 3:                # as :meth:`fit`: a side resolved in fewer runs is not fitted
                    parts = []
                    break
                rows = np.array([pos[r] for r in sub])
                k = np.rint((h0 + side * dl) * ctx.omega[sub] / (2 * np.pi) / ctx.df).astype(int)
                for c in chans:
                    parts.append(z[c][rows, k])
            vals = np.concatenate(parts) if parts else np.empty(0)
            score[j] = float(np.median(vals)) if vals.size >= 6 else 0.0
        return DELTA_GRID, score

    @staticmethod
    def candidates(ctx: Context, state: State, runs, n_carriers: int = 2) -> list:
        """Per direction, its ``n_carriers`` strongest lines (largest free C): the δ
        of the highest :meth:`scan` score when it clears 20 (the lines stand 20 × over the floor on half the
        resolved points) and is a local maximum, fitted by :meth:`fit`."""
        out = []
        tops = {}
        for d, chans in DIRECTION_CHANNELS.items():
            if not any(c in ctx.channels for c in chans):
                continue
            done = {round(e.h0, 4) for e in state.effects if isinstance(e, SpeedSidebands) and e.direction == d}
            hs = [x for x in state.model.harmonics(d) if round(x.h, 4) not in done]
            top = sorted(hs, key=lambda x: -SpeedSidebands._carrier_C(state, d, x.h))[:n_carriers]
            # a pair beside h0 changes the direction's channels within (h0 ± REACH)|Ω|/2π only: no pair there can pass
            # when the held-out misplaced power there is below min_gain of it all (Context.can_pass); not scanned
            # (under a speed ripple or a spin smear the lines spread further: the whole channels' bound)
            w = ctx.omega[ctx.held_runs] / (2 * np.pi)
            spread = state.speed_modulation is not None or state.smear is not None
            tops[d] = [x for x in top if ctx.can_pass(
                state, chans, None if spread else ctx.reach_bands((x.h - REACH) * w, (x.h + REACH) * w))]
        if ctx.test is not None:
            SpeedSidebands._prefetch_scans(ctx, [(d, x.h) for d, top in tops.items() for x in top], runs)
        for d, top in tops.items():
            for x in top:
                dl, sc = SpeedSidebands.scan(ctx, state, d, x.h, runs)
                j = int(np.argmax(sc))
                if not (0 < j < sc.size - 1 and sc[j] > 20.0 and sc[j] >= sc[j - 1] and sc[j] >= sc[j + 1]):
                    continue
                e = SpeedSidebands.fit(ctx, state, d, x.h, runs, float(dl[j]))
                if e is not None:
                    out.append(e)
        return out + SpeedSidebands._from_base(state, out, getattr(ctx, "base_sideband_pairs", ()))

    @staticmethod
    def _from_base(state: State, found: list, start_pairs=()) -> list:
        """The pairs the wheel's ``suspension_modes`` left out of the base it fitted from the data (:func:`rwadist.
        diagnose.modes_base.wheel_base`: close lines measured together on the records, where this
        family's own search needs RUN_MIN_BINS record bins from the carrier: 0.94/1.06 x the speed is 1.97 bins at
        2400 rpm on 4096 samples at 5 kHz), as measured there, those the search did not find itself; judged on the
        held-out runs like any.  Without the modes, the pairs the empirical starting model's Welch resolution left out
        (``start_pairs``, :func:`rwadist.diagnose.start_model.start_model`: read on the whole records)."""
        modes = [e for e in state.effects if getattr(e, "kind", "") == "suspension_modes"]
        done = {(e.direction, round(e.h0, 3)) for e in state.effects if isinstance(e, SpeedSidebands)} | \
            {(e.direction, round(e.h0, 3)) for e in found}
        # one pair per carrier: the base lists a pair per rotation-sense part (a carrier split co/counter), whose
        # powers add (apply() splits the pair again as its carrier)
        pairs: dict = {}
        for d, h0, hl, hu, cl, cu, n in (getattr(modes[-1], "sideband_pairs", ()) if modes else start_pairs):
            key = (d, round(h0, 3))
            if key in pairs:
                _, _, _, _, cl0, cu0, n0 = pairs[key]
                cl, cu, n = float(np.hypot(cl0, cl)), float(np.hypot(cu0, cu)), max(n0, n)
            pairs[key] = (d, h0, hl, hu, cl, cu, n)
        return [SpeedSidebands(d, h0, hl, hu, cl, cu, SpeedSidebands._carrier_C(state, d, h0), n)
                for key, (d, h0, hl, hu, cl, cu, n) in pairs.items() if key not in done and state.model.harmonics(d)]
