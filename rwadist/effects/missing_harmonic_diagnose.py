"""``missing_harmonic``: a line at h·|Ω| the model lacks.

Two routes.  The Welch route (:meth:`MissingHarmonic.candidates`' ridges of the residual PSD) measures a line whose
window of ±LINE_HALF Welch bins lies in the analysed band (from F_MIN_BINS Welch bins up).  Below that, where a short
record or a high sample rate puts the Welch grid's lowest analysed bin above a low line (h = 0.5 at 300-3000 rpm is
2.5-25 Hz; the lowest Welch bin measured is 52 Hz at 2048 samples and 3840 Hz, 34 Hz at 8192 samples and 10 kHz), the
time series still resolve it: the whole-run DFT's bins are 4× finer than the Welch segments'.  The record route
(:meth:`MissingHarmonic.record_candidates`) measures the line there, on the points the Welch route cannot, and judges
it there too (:meth:`MissingHarmonic.heldout_evidence`: the error metric's bands start at the same lowest bin, so the
PSDs cannot see it)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..diagnose.constants import LINE_HALF
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.measure import (
    _measure,
    hann_transform_ratio,
    in_unresolved_span,
    record_dfts,
    refine_h,
    ridge_peaks,
    state_line_freqs,
)
from ..diagnose.record_residual import RECORD_GRID_BINS, RECORD_SEP_BINS, record_residual, welch_low_limit
from ..diagnose.reduce import column_nanmedian
from ..diagnose.state import State
from ..empirical import line_C
from ..model import Harmonic
from ..speed_scale import ratios_near, sweep_ratios
from ..units import DIRECTION_CHANNELS

#: Half width of the Hann window's main lobe, Welch bins: a Welch-route ridge closer to a line of the model than this
#: at the fastest run (where lines of different h lie furthest apart) is inside that line's lobe at every speed.
WELCH_LOBE_BINS = 2.0
#: Inside a model line's main lobe, the smallest C of a line of its own, relative to that line's C: a fitted line's C
#: is known to 5-10 % (the foundation of issue 14: C within 5 % on clean data), and near a mode its shape a little
#: worse, so a weaker "line" there is that line's own misfit (the independent wheel on 20 speeds: h 1.937 at 4 % of
#: the 1.98 line beside it), while a missing line of its own is as strong as its neighbours (h 2.73 at 1.7 × the 2.96
#: line, 1.5 Welch bins from it at 2048 samples, measured to 0.6 %).
LOBE_MIN_RATIO = 0.2
#: A line re-measured apart from a model line (within two Welch lobes of it), not close: its whole-run DFT C (apart
#: from its neighbours) over its Welch C, at least.  Family wheel 7 with its imbalance x1.2 above the median speed: a
#: Welch ridge at h 0.935 re-measured at 0.955 took C 0.48 x the 1x's from the 1x's misfit at the slow runs.
APART_MIN_RATIO = 0.5
#: A ridge's score (median of |X|²/noise over its points) to clear: the line 20 × over the noise on half its points, as
#: the whole-run scans of ``sidebands`` and ``speed_sidebands``.
RECORD_SCORE = 20.0
#: Fewest points (run, channel) and runs of a record-route ridge or fit.
RECORD_MIN_POINTS = 6
RECORD_MIN_RUNS = 3
#: A model line's amplitude on the Welch PSDs over its amplitude on the whole-run DFT, at least (median of the faster
#: half of the runs), for a line hidden in its window (:func:`hidden_neighbours`): 6 % more power
HIDDEN_RATIO = 1.03
#: :func:`resolved_h`'s first scan grid (the second 5x finer), record bins at the fastest run: a line loses <= 0.4 dB
RESOLVED_SCAN_BINS = 0.5
#: Points used for C stand this many times over the noise (as the whole-run fit of ``speed_sidebands``).
RECORD_FIT_SNR = 10.0


def record_line_evidence(ctx: Context, chans, P, N, ok, M1) -> tuple:
    """(drop, se) of lines the state does not predict and an effect predicts with power M₁ (|X|² = a²), measured as
    P with noise mean N on the whole-run DFT; all (len(chans), n_points), ``ok`` the points to use.  In the units of
    the error metric (mean square a²/2, each channel divided by its group scale): drop = Σ |P − N| − |P − N − M₁|,
    se = sqrt(Σ min(M₁, σ)²) with σ² = N² + 2(P − N)N, the variance of the power of a line in complex Gaussian
    noise (the search's judge: a point's term changes by at most |ΔM|, and by about σ when the change is larger)."""
    drop, var = 0.0, 0.0
    for j, c in enumerate(chans):
        p, n, v, m1 = P[j], N[j], ok[j], M1[j]
        sig = np.sqrt(n**2 + 2.0 * np.maximum(p - n, 0.0) * n)
        scale = 2.0 * ctx.scale(c)
        drop += float(np.sum((np.abs(p - n) - np.abs(p - n - m1))[v])) / scale
        var += float(np.sum(np.minimum(m1, sig)[v] ** 2)) / scale**2
    return drop, float(np.sqrt(var))


def _apart_residuals(ctx: Context, state: State, direction: str, runs, h: float, grid: np.ndarray) -> list:
    """[(channel, rows (R',), X (R', G) complex)] of the direction's channels: the whole-run phasors at h'·|Ω|/2π for
    every h' of ``grid`` less the leakage of every line of the state on the channel (each line's own phasor times the
    window's transform, its negative-frequency image too: nought at each line of the state), in the runs ``rows``
    where ``h`` lies RECORD_SEP_BINS record bins or more from every such line."""
    w_hz = ctx.omega[runs] / (2 * np.pi)
    df_rec = np.array([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs])
    out = []
    for c in (c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels):
        lines = state_line_freqs(ctx, state, c, runs)                                   # (R, L)
        apart = np.all(np.abs(h * w_hz[:, None] - lines) >= RECORD_SEP_BINS * df_rec[:, None], axis=1)
        use = np.array([i for i, r in enumerate(runs) if apart[i] and ctx.test.runs[r].usable(c)], dtype=int)
        if not use.size:
            continue
        rows = runs[use]
        f = np.outer(w_hz[use], grid)                                                   # (R', G)
        X = record_dfts(ctx, rows, c, f)
        if lines.shape[1]:
            A = record_dfts(ctx, rows, c, lines[use])[:, None, :]                      # (R', 1, L)
            fl = lines[use][:, None, :]
            lengths = np.array([ctx.test.runs[r].n_samples for r in rows])
            for n in np.unique(lengths):                        # the window's transform, runs of one length at once
                k = lengths == n
                d = df_rec[use][k][:, None, None]
                X[k] -= (hann_transform_ratio(int(n), (f[k][:, :, None] - fl[k]) / d) * A[k]
                         + hann_transform_ratio(int(n), (f[k][:, :, None] + fl[k]) / d) * np.conj(A[k])).sum(2)
        out.append((c, rows, X))
    return out


def _remeasured_neighbours(ctx: Context, state: State, direction: str, runs: np.ndarray, h: float) -> tuple:
    """((h before, sense, C before, h, C), ...) of the model lines of ``direction`` within the Welch main lobe
    (WELCH_LOBE_BINS at the fastest run) of a close line h, measured on the whole-run DFT over the direction's channels
    and the runs where the line lies RECORD_SEP_BINS record bins or more from every other line of the state and from
    h: its h the maximum of its power there; its C the least-squares ratio of that power (|X|² at its own frequency) to
    the power the state predicts for it (through the modes and the fixed resonances: whatever form the line has, scaled
    as one), or, for a radial line the model holds as a co- and a counter-rotating part, each part's own amplitude
    (:func:`_sense_amplitudes`) over the amplitude the state gives it per unit C (the blend of two co-rotating lines
    one Welch lobe apart can read as a co/counter pair on the Welch grid: the record splits them again).  A line with
    fewer than RECORD_MIN_RUNS such runs is left as it is."""
    w_hz = ctx.omega[runs] / (2 * np.pi)
    lobe = WELCH_LOBE_BINS * ctx.df / max(float(w_hz.max()), 1e-300)
    df_rec = np.array([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs])
    out: list = []
    for h_model in sorted({x.h for x in state.model.harmonics(direction) if abs(x.h - h) < lobe}):
        parts_of = [x for x in state.model.harmonics(direction) if x.h == h_model]
        fx = h_model * w_hz
        parts = []
        for c in (c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels):
            entry = [a for hh, _, a, _ in ctx.channel_lines(state, c, runs) if abs(hh - h_model) < 1e-9]
            if not entry:
                continue
            lines = state_line_freqs(ctx, state, c, runs)
            near = np.abs(lines - fx[:, None]) < RECORD_SEP_BINS * df_rec[:, None]
            apart = (near.sum(1) <= 1) & (np.abs(fx - h * w_hz) >= RECORD_SEP_BINS * df_rec)
            apart &= np.array([ctx.test.runs[r].usable(c) for r in runs])
            if apart.any():
                parts.append((c, apart, entry[0]))
        if np.count_nonzero(np.any([a for _, a, _ in parts], axis=0) if parts else []) < RECORD_MIN_RUNS:
            continue
        # h: the maximum of Σ|X|² on a grid of ±½ record bin at the fastest run (41 points, a log-parabola
        # through the top three)
        grid = h_model + np.linspace(-0.5, 0.5, 41) * float(df_rec.max()) / float(w_hz.max())
        tot = sum((np.abs(record_dfts(ctx, runs[a], c, np.outer(w_hz[a], grid))) ** 2).sum(0) for c, a, _ in parts)
        i = int(np.clip(np.argmax(tot), 1, grid.size - 2))
        lo, mid, hi = np.log(np.maximum(tot[i - 1:i + 2], 1e-300))
        den = lo - 2 * mid + hi
        h_x = round(float(grid[i] + (0.5 * (lo - hi) / den if den < 0 else 0.0) * (grid[1] - grid[0])), 4)
        senses = {x.sense for x in parts_of}
        pair = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        if len(parts_of) == 2 and senses == {"co", "counter"} and len(pair) == 2 and len(parts) == 2:
            both = parts[0][1] & parts[1][1]
            if np.count_nonzero(both) < RECORD_MIN_RUNS:
                continue
            measured = _sense_amplitudes(ctx, state, direction, runs[both], h_x, pair)
            out += [(h_model, x.sense, x.C, h_x, measured[x.sense]) for x in parts_of]
            continue
        num = den = 0.0
        for c, a, amp in parts:
            p = np.abs(record_dfts(ctx, runs[a], c, (h_x * w_hz[a])[:, None])[:, 0]) ** 2
            m = amp[a] * (ctx.gain(state, c, h_x * w_hz[a]) if state.resonances else 1.0)
            num += float(np.sum(p * m**2))
            den += float(np.sum(m**4))
        if den > 0:
            out += [(h_model, x.sense, x.C, h_x, x.C * float(np.sqrt(num / den))) for x in parts_of]
    return tuple(out)


def _sense_amplitudes(ctx: Context, state: State, direction: str, rows: np.ndarray, h: float, pair: list) -> dict:
    """{"co": C, "counter": C} of a radial line h on the runs ``rows``: the whole-run phasors X, Y of its pair of
    channels split into the co-rotating part (X + jY)/2 (x + jy ∝ e^{+jωt}) and the counter-rotating one (X − jY)/2,
    each part's C the least-squares fit of its amplitude to the amplitude the state gives that part per unit C (its
    own modal gain, :meth:`~rwadist.diagnose.engine.Context.unit_gain`, times Ω² and the fixed resonances' gain)."""
    w = ctx.omega[rows]
    f = (h * w / (2 * np.pi))[:, None]
    X, Y = (record_dfts(ctx, rows, c, f)[:, 0] for c in pair)
    out = {}
    for sense, part in (("co", np.abs(X + 1j * Y) / 2), ("counter", np.abs(X - 1j * Y) / 2)):
        unit = ctx.unit_gain(state, pair[0], direction, h, sense, rows) * w**2
        if state.resonances:
            unit = unit * ctx.gain(state, pair[0], f[:, 0])
        out[sense] = float(np.sum(part * unit) / max(float(np.sum(unit**2)), 1e-300))
    return out


def _steady(ctx: Context, state: State) -> bool:
    """The whole-run DFT holds the state's lines as steady ones: time series given, no spin smear, no speed ripple."""
    return ctx.test is not None and state.smear is None and state.speed_modulation is None


def resolved_h(ctx: Context, state: State, direction: str, runs, h: float, half: float) -> "float | None":
    """h of a line within ``half`` (h) of the Welch route's estimate ``h``, measured on the whole-run DFT, where a line
    closer to a model line than the Welch main lobe (the two one ridge on the Welch grid, its h a blend of both) stands
    apart: Σ|X − leakage|² (:func:`_apart_residuals`) over the direction's channels and the runs where ``h`` is apart
    from the state's lines, its maximum on a grid of RESOLVED_SCAN_BINS record bins (at the fastest run) over ±``half``,
    then on a grid of a fifth of that over ±1 step of the first, on the runs apart from that maximum (a blend's h can be
    off by a lobe), and a log-parabola through the top three.  None where the record's lines are not steady
    (:func:`_steady`) or with fewer than RECORD_MIN_RUNS such runs."""
    if not _steady(ctx, state):
        return None
    runs = np.asarray(runs)
    df_rec = max(ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs)
    step = RESOLVED_SCAN_BINS * df_rec / max(float(np.max(ctx.omega[runs])) / (2 * np.pi), 1e-9)
    grids = (np.arange(h - half, h + half + 0.5 * step, step), np.linspace(-step, step, 11))
    for k, grid in enumerate(grids):
        grid = grid + h if k else grid
        grid = grid[grid > 0]
        parts = _apart_residuals(ctx, state, direction, runs, h, grid)
        if grid.size < 3 or max((rows.size for _, rows, _ in parts), default=0) < RECORD_MIN_RUNS:
            return None
        tot = sum(np.sum(np.abs(X) ** 2, axis=0) for _, _, X in parts)
        i = int(np.argmax(tot))
        h = float(grid[i])
    if 0 < i < grid.size - 1:
        lo, mid, hi = np.log(np.maximum(tot[i - 1:i + 2], 1e-300))
        den = lo - 2 * mid + hi
        h += (0.5 * (lo - hi) / den if den < 0 else 0.0) * (grid[1] - grid[0])
    return h


def window_ratios(ctx: Context, state: State, c: str, h: float, rows: np.ndarray) -> np.ndarray:
    """(len(rows),) of model line h on channel ``c`` in runs ``rows``: its amplitude on the Welch PSDs
    (:meth:`~rwadist.diagnose.engine.Context.measure_line`, every other line of the state taken off) over its amplitude
    on the whole-run DFT (|X| at its own frequency).  A line alone in its Welch window reads 1: more is another line
    inside it (:mod:`rwadist.diagnose.describe_blend` reads every line of a channel at once)."""
    welch = ctx.measure_line(state, c, h, rows, skip=h)
    record = np.abs(record_dfts(ctx, rows, c, (h * ctx.omega[rows] / (2 * np.pi))[:, None])[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        return welch / record


def record_noise(ctx: Context, state: State, c: str, rows: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
    """E|X|² (the shape of ``f_hz``) of white noise on the whole-run phasor X = 2·Σwx·e^{−2πjft}/Σw of channel ``c`` at
    ``f_hz`` ((len(rows),) or (len(rows), L): frequencies per run of ``rows``): 2·S·f_s·Σw²/(Σw)², S the state's floor
    at the nearest Welch bin."""
    from ..dft import run_window

    f_hz = np.asarray(f_hz, dtype=float)
    k = np.clip(np.rint(f_hz / ctx.df).astype(int), ctx.k_lo, ctx.k_hi).reshape(rows.size, -1)
    S = np.take_along_axis(ctx.floor_psd(state, c, rows), k, axis=1)
    fs, w2, w1 = (np.empty((rows.size, 1)) for _ in range(3))
    for i, r in enumerate(rows):
        run = ctx.test.runs[r]
        _, w1[i], w2[i] = run_window(ctx.sp.window, run.n_samples)
        fs[i] = run.sample_rate
    return (2.0 * S * fs * w2 / w1**2).reshape(f_hz.shape)


def hidden_neighbours(ctx: Context, state: State, direction: str, chans, runs) -> list:
    """h of the model lines of ``direction`` whose Welch window holds more power than the line itself on the whole-run
    DFT: the median over the faster half of ``runs`` and ``chans`` of :func:`window_ratios` at least HIDDEN_RATIO, and
    the lower quartile a third of that excess (:func:`hidden_in_window`): another line inside the window, too close
    for a ridge of its own (a blend the base measured as one line: the E-like wheel's counter-rotating h 2 line with a
    co-rotating h 1.96 at 23 % of its power reads 1.11; every line of clean data 0.99-1.00).  [] where the record's
    lines are not steady (:func:`_steady`)."""
    if not _steady(ctx, state):
        return []
    runs = np.asarray(runs)
    w_hz = ctx.omega[runs] / (2 * np.pi)
    fast = runs[w_hz >= np.median(w_hz)]
    out = []
    for h in sorted({x.h for x in state.model.harmonics(direction)}):
        ratios = []
        for c in chans:
            usable = np.array([ctx.test.runs[r].usable(c) for r in fast])
            if usable.any():
                ratios.append(window_ratios(ctx, state, c, h, fast[usable]))
        r = np.concatenate(ratios) if ratios else np.empty(0)
        if hidden_in_window(r[np.isfinite(r)]):
            out.append(h)
    return out


def hidden_in_window(r: np.ndarray) -> bool:
    """Whether :func:`window_ratios`' ratios ``r`` (finite) show a line hidden in a model line's window: at least
    RECORD_MIN_RUNS of them, their median HIDDEN_RATIO or more and their lower quartile a third of that excess."""
    return bool(r.size >= RECORD_MIN_RUNS and np.median(r) >= HIDDEN_RATIO and
                np.percentile(r, 25) >= 1.0 + (HIDDEN_RATIO - 1.0) / 3.0)


def _hidden_lines(ctx: Context, state: State, direction: str, chans, runs, found: list, sep_rec: float) -> list:
    """``close`` lines (:meth:`MissingHarmonic.fit_close`) beside the model lines that hide one
    (:func:`hidden_neighbours`): on each side of such a line, the maximum of the whole-run residual over half the Welch
    window's width in h at the fastest run (:func:`resolved_h`), kept when RECORD_SEP_BINS record bins from every model
    line and not one of ``found``."""
    hidden = hidden_neighbours(ctx, state, direction, chans, runs)
    if not hidden:
        return []
    half = (LINE_HALF + 1) * ctx.df / max(float(np.max(ctx.omega[runs])) / (2 * np.pi), 1e-300)
    out: list[MissingHarmonic] = []
    for h_model in hidden:
        for side in (-1.0, 1.0):
            h = resolved_h(ctx, state, direction, runs, h_model + 0.5 * side * half, 0.5 * half)
            if h is None or any(abs(h - x.h) < sep_rec for x in state.model.harmonics(direction)) or \
                    any(abs(h - e.h) < 0.005 for e in found + out):
                continue
            e = MissingHarmonic.fit_close(ctx, state, direction, h, runs)
            if e is not None:
                out.append(e)
    return out


def left_out_beside_stand(ctx: Context, state: State, direction: str, h: float | None = None) -> bool:
    """Whether ``ctx.left_out`` (lines the base left out) holds ``direction``'s line ``h`` (any: None) beside a stand."""
    return any(x == direction and (h is None or abs(y - h) <= 1e-3 * y) for x, y in getattr(ctx, "left_out", ())) \
        and any(getattr(e, "role", "") == "test_stand" for e in state.effects)


@register(order=10)
@dataclass
class MissingHarmonic:
    """A line at h·|Ω| the model lacks; amplitude C·Ω² (C in SI per (rad/s)²).  ``record``: found and fitted on the
    whole-run DFT below the Welch route's lowest frequency (:meth:`record_candidates`), judged there
    (:meth:`heldout_evidence`)."""

    direction: str
    h: float
    C: float
    n_points: int = 0
    record: bool = False
    close: bool = False
    #: ((h before, sense, C before, h, C), ...): the model lines within the Welch lobe of a ``close`` line, measured again
    #: apart from it on the whole-run DFT (the base's fit measured the blend of both on the Welch grid)
    beside: tuple = ()
    #: a line the base left out as amplified at nearly every speed (``ctx.left_out``), fitted beside a test stand
    left_out: bool = False
    kind: str = "missing_harmonic"

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    @property
    def judged_on_narrow_lines(self) -> bool:
        """A ``close`` line is judged on the narrow lines as well (:func:`rwadist.diagnose.search._narrow_judge`): it
        moves power between two lines one Welch lobe apart, a share of the power-weighted misfit as small as the
        weaker line, where a reviewer of the waterfall sees both.  So is a line the base left out, found again beside a
        test stand: the wheel's own line, whose share of the power-weighted misfit beside the stand's is small (family
        wheel 4 hard mounted on a 90-Hz transmissibility: axial h 4.62, +33 dB over the model in its bins, 1 %)."""
        return self.close or self.left_out

    def apply(self, state: State) -> State:
        s = state.copy()
        remeasured = {(h, sense): (h_new, C) for h, sense, _, h_new, C in self.beside}
        kept = [replace(x, h=remeasured[x.h, x.sense][0], C=remeasured[x.h, x.sense][1])
                if (x.h, x.sense) in remeasured else x for x in s.model.harmonics(self.direction)]
        s.model.empirical[self.direction] = sorted(
            kept + [Harmonic(h=round(self.h, 4), C=self.C, n_points=self.n_points)], key=lambda x: x.h)
        s.effects.append(self)
        return s

    def refit(self, ctx: Context, state: State) -> "MissingHarmonic":
        """Refitted on every run (``ctx.runs``), on the whole-run DFT for a record-route line; itself when that fit
        fails."""
        if self.record:
            return MissingHarmonic.fit_record(ctx, state, self.direction, self.h, ctx.runs) or self
        if self.close:
            return MissingHarmonic.fit_close(ctx, state, self.direction, self.h, ctx.runs) or self
        return MissingHarmonic.fit(ctx, state, self.direction, self.h, ctx.runs) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def apart_entry(self) -> dict:
        """``{"measured_apart": [{h_before, C_before, h, C}, ...]}`` of the model lines a ``close`` line was measured
        apart from (:attr:`beside`), for the summary; {} when none."""
        return {"measured_apart": [{"h_before": a, "sense": sense, "C_before": b, "h": c, "C": d}
                                   for a, sense, b, c, d in self.beside]} if self.beside else {}

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "C": self.C}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs) -> "MissingHarmonic | None":
        d, w = _measure(ctx, state, direction, h, runs)
        if d.size < 3:
            return None
        return MissingHarmonic(direction, float(h), line_C(d, w), int(d.size),
                               left_out=left_out_beside_stand(ctx, state, direction, h))

    @staticmethod
    def fit_close(ctx: Context, state: State, direction: str, h: float, runs) -> "MissingHarmonic | None":
        """A line closer to a model line than the Welch main lobe (:func:`resolved_h`), fitted on the whole-run DFT
        where the two stand apart: C by :func:`~rwadist.empirical.line_C` on the amplitudes sqrt(|X − leakage|² − noise)
        (:func:`_apart_residuals`; the noise the white noise of the state's floor at the nearest Welch bin) of the
        points RECORD_FIT_SNR × over the noise, divided by the fixed resonances' and the modal gain.  None where the
        record's lines are not steady, with such points in fewer than RECORD_MIN_RUNS runs, or no positive C."""
        if not _steady(ctx, state):
            return None
        d_parts: list[np.ndarray] = []
        w_parts: list[np.ndarray] = []
        used: set[int] = set()
        for c, rows, X in _apart_residuals(ctx, state, direction, np.asarray(runs), h, np.array([h])):
            w = ctx.omega[rows]
            N = record_noise(ctx, state, c, rows, h * w / (2 * np.pi))
            P = np.abs(X[:, 0]) ** 2
            keep = P > RECORD_FIT_SNR * N
            unit = MissingHarmonic._line_amplitude(ctx, state, c, direction, h, 1.0, rows)    # per unit C
            a = np.sqrt(np.maximum(P - N, 0.0)) / np.maximum(unit, 1e-300) * w**2
            d_parts.append(a[keep])
            w_parts.append(w[keep])
            used.update(int(r) for r in rows[keep])
        if not d_parts:
            return None
        d, w = np.concatenate(d_parts), np.concatenate(w_parts)
        if len(used) < RECORD_MIN_RUNS:             # (points of RECORD_FIT_SNR: one channel of an axial line is enough)
            return None
        C = line_C(d, w)
        if C <= 0:
            return None
        return MissingHarmonic(direction, float(h), C, int(d.size), close=True,
                               beside=_remeasured_neighbours(ctx, state, direction, np.asarray(runs), h))

    # ------------------------------------------------------------------ the record route (below the Welch band)
    @staticmethod
    def _record_points(ctx: Context, state: State, direction: str, runs, h_grid, exact: bool = False) -> tuple:
        """(|X|², noise, valid), each (len(chans), len(runs), len(h_grid)), of the lines h·|Ω|/2π of ``h_grid`` on the
        direction's channels (:func:`record_residual`), and the channels."""
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        f = np.outer(ctx.omega[runs] / (2 * np.pi), np.atleast_1d(h_grid))
        out = [record_residual(ctx, state, c, runs, f, exact) for c in chans]
        return (np.array([o[0] for o in out]), np.array([o[1] for o in out]), np.array([o[2] for o in out]), chans)

    @staticmethod
    def _line_amplitude(ctx: Context, state: State, c: str, direction: str, h: float, C: float, runs) -> np.ndarray:
        """Amplitude (unit, per run) in channel ``c`` of a line (direction, h) of free amplitude C·Ω²: through the
        state's modes (extended base) and fixed resonances."""
        w = ctx.omega[runs]
        a = C * w**2 * ctx.gain(state, c, h * w / (2 * np.pi))
        if state.ext is not None:
            a = a * ctx.modal_gain(state, c, h, runs)
        return a

    @staticmethod
    def fit_record(ctx: Context, state: State, direction: str, h: float, runs) -> "MissingHarmonic | None":
        """The record route's fit: h the maximum of Σ|X|² over the valid points on a grid ±1 record-grid step (at the
        fastest run) around ``h`` (steps of 1/20 of it, then a parabola through the top three; the points' own
        frequencies, :func:`record_residual` exact), C by :func:`~rwadist.empirical.line_C` on
        the amplitudes sqrt(|X|² − noise) of the points RECORD_FIT_SNR × over the noise, divided by the fixed
        resonances' and the modal gain (the line before the mount).  None with fewer than RECORD_MIN_POINTS such
        points or RECORD_MIN_RUNS runs, or no positive C."""
        if ctx.test is None:
            return None
        df_rec = float(np.max([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs]))
        step = RECORD_GRID_BINS * df_rec / max(float(ctx.omega[runs].max()) / (2 * np.pi), 1e-9)
        grid = h + np.arange(-20, 21) * step / 20.0
        P, N, ok, chans = MissingHarmonic._record_points(ctx, state, direction, runs, grid, exact=True)
        every = ok.all(axis=2)                                 # the points valid across the whole grid
        tot = np.sum(np.where(every[:, :, None], P, 0.0), axis=(0, 1))
        i = int(np.argmax(tot))
        if 0 < i < grid.size - 1:
            lo, mid, hi = np.log(np.maximum(tot[i - 1:i + 2], 1e-300))
            den = lo - 2 * mid + hi
            h = float(grid[i] + (0.5 * (lo - hi) / den if den < 0 else 0.0) * (grid[1] - grid[0]))
        else:
            h = float(grid[i])
        P, N, ok, chans = MissingHarmonic._record_points(ctx, state, direction, runs, [h], exact=True)
        d_parts, w_parts, used = [], [], np.zeros(runs.size, bool)     # per channel: amplitudes, speeds (rad/s)
        for j, c in enumerate(chans):
            keep = ok[j, :, 0] & (P[j, :, 0] > RECORD_FIT_SNR * N[j, :, 0])
            unit = MissingHarmonic._line_amplitude(ctx, state, c, direction, h, 1.0, runs)   # per unit C
            a = np.sqrt(np.maximum(P[j, :, 0] - N[j, :, 0], 0.0)) / np.maximum(unit, 1e-300) * ctx.omega[runs] ** 2
            d_parts.append(a[keep])
            w_parts.append(ctx.omega[runs][keep])
            used |= keep
        d, w = np.concatenate(d_parts), np.concatenate(w_parts)
        if d.size < RECORD_MIN_POINTS or used.sum() < RECORD_MIN_RUNS:
            return None
        C = line_C(d, w)
        return MissingHarmonic(direction, h, C, int(d.size), record=True) if C > 0 else None

    @staticmethod
    def record_candidates(ctx: Context, state: State, runs, max_per_direction: int = 3, directions=None) -> list:
        """Lines below the Welch route's lowest frequency (:func:`welch_low_limit`) on the whole-run DFT: per direction
        and h of a grid (from 0.1 to where the slowest run's line reaches that frequency, steps of one record-grid step
        at the fastest run), the median over the valid points (runs, channels) of |X|²/noise (:func:`record_residual`),
        with at least RECORD_MIN_POINTS points in RECORD_MIN_RUNS runs; its local maxima above RECORD_SCORE, strongest
        first, away from the state's harmonics, fitted by :meth:`fit_record`.  Nothing on a state with a spin smear or
        a speed ripple (the record's lines are not steady there).  ``directions``: only these (default every one)."""
        if ctx.test is None or state.smear is not None or state.speed_modulation is not None:
            return []                   # a swept or rippled speed: the record's lines are not steady ones
        w_hz = ctx.omega[runs] / (2 * np.pi)
        if w_hz.size < RECORD_MIN_RUNS or w_hz.min() <= 0:
            return []
        df_rec = float(np.max([ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs]))
        h_top = welch_low_limit(ctx) / w_hz.min()
        h_grid = np.arange(0.1, h_top, RECORD_GRID_BINS * df_rec / w_hz.max())
        if h_grid.size < 3:
            return []
        out = []
        for d, chans in DIRECTION_CHANNELS.items():
            if not any(c in ctx.channels for c in chans) or (directions is not None and d not in directions):
                continue
            P, N, ok, _ = MissingHarmonic._record_points(ctx, state, d, runs, h_grid)
            z = np.where(ok, P / np.maximum(N, 1e-300), np.nan).reshape(-1, h_grid.size)
            enough = (ok.sum(axis=(0, 1)) >= RECORD_MIN_POINTS) & (ok.any(axis=0).sum(axis=0) >= RECORD_MIN_RUNS)
            score = np.zeros(h_grid.size)
            if enough.any():
                score[enough] = column_nanmedian(z[:, enough])
            peaks = np.nonzero((score[1:-1] > score[:-2]) & (score[1:-1] >= score[2:])
                               & (score[1:-1] > RECORD_SCORE))[0] + 1
            found: list[MissingHarmonic] = []
            for i in peaks[np.argsort(-score[peaks])]:
                h = float(h_grid[i])
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)) or \
                        any(abs(h - x.h) < 0.03 for x in found):
                    continue
                e = MissingHarmonic.fit_record(ctx, state, d, h, runs)
                if e is not None and not any(abs(e.h - x.h) < 0.03 for x in state.model.harmonics(d)):
                    found.append(e)
                if len(found) >= max_per_direction:
                    break
            out += found
        return out

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of a record-route line (None for a Welch-route one: the search's own judge): (drop, se)
        in the units of the error metric (mean square, each channel divided by its group scale) of the misplaced line
        power on the whole-run DFT, Σ |P − n − M₀| − |P − n − M₁| over the valid points of ``runs``, M₀ = 0 (the
        state predicts no line there: the points are clear of its lines) and M₁ the line's power as this effect
        predicts it (|X|² = a²); se as the search's judge, sqrt(Σ min(|ΔM|, σ)²), σ² = n² + 2Pn of a line of power
        P in complex Gaussian noise of mean n.  None on a state with a spin smear or a speed ripple."""
        if not self.record or ctx.test is None or state.smear is not None or state.speed_modulation is not None:
            return None
        P, N, ok, chans = MissingHarmonic._record_points(ctx, state, self.direction, runs, [self.h], exact=True)
        m1 = [MissingHarmonic._line_amplitude(ctx, state, c, self.direction, self.h, self.C, runs) ** 2 for c in chans]
        return record_line_evidence(ctx, chans, P[:, :, 0], N[:, :, 0], ok[:, :, 0], np.array(m1))

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        """The Welch route's ridges (:func:`rwadist.diagnose.measure.ridge_peaks`), then the record route's lines
        below it (:meth:`record_candidates`, time series given)."""
        out = []
        # a line fitted within the main lobe of a model line (WELCH_LOBE_BINS, in h at the fastest run) weaker than
        # LOBE_MIN_RATIO of it is that line's misfit, except inside a span the model's fit listed unresolved (a close
        # pair it measured as one line: the other line is expected there and completed into the base,
        # search._base_lines)
        lobe = WELCH_LOBE_BINS * ctx.df / max(float(np.max(np.abs(ctx.omega[runs]))) / (2 * np.pi), 1e-300)

        def misfit(e) -> bool:
            if in_unresolved_span(state.model, e.direction, e.h):
                return False
            return any(abs(e.h - x.h) < lobe and e.C < LOBE_MIN_RATIO * abs(x.C)
                       for x in state.model.harmonics(e.direction))

        ratios = sweep_ratios(ctx.test.meta if ctx.test is not None else None)
        # RECORD_SEP_BINS record bins at the fastest run, in h: a line measured on the whole-run DFT this close to a
        # model line is that line
        sep_rec = 0.0 if ctx.test is None else RECORD_SEP_BINS * max(
            ctx.test.runs[r].sample_rate / ctx.test.runs[r].n_samples for r in runs) / max(
            float(np.max(np.abs(ctx.omega[runs]))) / (2 * np.pi), 1e-300)

        def welch(d, chans) -> list:
            found: list[MissingHarmonic] = []
            for h in ridge_peaks(ctx, state, chans, runs, max_per_direction):
                if any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)):
                    continue
                # on a sweep whose speed came from the data, the wheel's lines of the speed scale's ratios within the
                # ridge's lobe (a blend of two close lines, a smeared line's ridge beside itself), else the ridge's h
                for h in ratios_near(refine_h(ctx, state, chans, runs, h), ratios, lobe):
                    # near a model line the ridge's h is a blend of the two lines (one Welch lobe apart, the blend's
                    # ridge up to a lobe beside them): measured again on the whole-run DFT, where they stand apart
                    # (resolved_h), and kept when apart from every line; a line within a lobe of one is fitted there
                    near = any(abs(h - x.h) < 2.0 * lobe for x in state.model.harmonics(d))
                    h_rec = resolved_h(ctx, state, d, runs, h, 2.0 * lobe) if near else None
                    close = False
                    if h_rec is not None:
                        h = h_rec
                        if any(abs(h - x.h) < sep_rec for x in state.model.harmonics(d)):
                            continue
                        close = any(abs(h - x.h) < lobe for x in state.model.harmonics(d))
                    elif any(abs(h - x.h) < 0.03 for x in state.model.harmonics(d)):
                        continue
                    if any(abs(h - x.h) < 0.005 for x in found):
                        continue
                    e = (close and MissingHarmonic.fit_close(ctx, state, d, h, runs)) or \
                        MissingHarmonic.fit(ctx, state, d, h, runs)
                    # re-measured apart, a line not close holds its Welch C where it stands apart (APART_MIN_RATIO)
                    if h_rec is not None and not close and e is not None and _steady(ctx, state) and (
                            (a := MissingHarmonic.fit_close(ctx, state, d, h, runs)) is None
                            or a.C < APART_MIN_RATIO * e.C):
                        continue
                    if e is not None and e.C > 0 and not misfit(e):
                        found.append(e)
            return found + [e for e in _hidden_lines(ctx, state, d, chans, runs, found, sep_rec) if not misfit(e)]

        # each direction's lines from its own channels alone (Context.reuse): the Welch route's first, then the record
        # route's (below the Welch band) of every direction, a line the Welch route found not proposed again
        lanes = {d: [c for c in chans if c in ctx.channels] for d, chans in DIRECTION_CHANNELS.items()}
        lanes = {d: chans for d, chans in lanes.items() if chans}
        def welch_lines(d):
            return ctx.reuse("missing_harmonic", state, lanes[d], runs, lambda: welch(d, lanes[d]))

        # a Welch-route line is judged by the error metric on the direction's channels: proposed only where it could
        # pass (Context.can_pass) but one the base left out, beside a stand (judged on the narrow lines too); the record
        # route's lines bring their own held-out evidence, and one within 0.03 of a Welch-route line of its direction
        # is not proposed (that line still found, where skipped, to tell)
        skipped = set()
        for d, chans in lanes.items():
            if ctx.can_pass(state, chans):
                out += welch_lines(d)
            else:
                skipped.add(d)
                out += [e for e in welch_lines(d) if e.left_out] if left_out_beside_stand(ctx, state, d) else []
        for d, chans in lanes.items():
            found = ctx.reuse("missing_harmonic", state, chans, runs,
                              lambda d=d: MissingHarmonic.record_candidates(ctx, state, runs, max_per_direction, (d,)),
                              part="record")
            told = welch_lines(d) if found and d in skipped else []
            for e in found:
                if not any(abs(e.h - x.h) < 0.03 for x in out + told if x.direction == e.direction):
                    out.append(e)
        return out
