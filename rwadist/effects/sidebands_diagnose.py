"""``sidebands``: amplitude modulation of one line at a fixed frequency."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..diagnose.constants import LINE_HALF
from ..diagnose.effects.base import register, schema_entry
from ..diagnose.engine import Context
from ..diagnose.measure import (
    _clear_of_lines,
    _offset_grid,
    _offset_scores,
    _offset_threshold,
    _refine_offset,
    _residual_z,
    _window_power,
)
from ..diagnose.state import State
from ..units import DIRECTION_CHANNELS

#: Runs scanned on the whole-run DFT per carrier (the fastest in band): the offset is the same at every speed, so a
#: few runs tell it; the fit then takes every run.
RECORD_SCAN_RUNS = 12
#: Scan step of the whole-run route, record bins (fs/n).
RECORD_STEP_BINS = 0.25
#: Half-width of :meth:`Sidebands.fit_record`'s refinement grid, scan steps: the scan's score is a median over the
#: runs whose two sides are clear of other lines, a set that changes along the offsets (a side reaching a line), so
#: its maximum can sit a step from the pair's (family wheel 4, f_mod 5.625 Hz at 0.9375-Hz record bins: scanned at
#: 5.859 as one of seven runs left, the pair's Σ|X|² at 5.625, on the edge of a one-step grid: no sidebands)
REFINE_STEPS = 2
#: Farthest offset of the whole-run scans, Welch bins: ``sidebands`` scans to 2.5 (``_record_offsets``), ``speed_ripple``
#: the same grid to 4 (its RECORD_WELCH_BINS); a carrier's line powers on the same runs are computed once, to the
#: farther (:meth:`Sidebands._scan_powers`), and each scan reads its part
RECORD_SCAN_WELCH_BINS = 4.0
#: A carrier's whole-run scan score (median |X|²/noise over runs, channels and both sides) a pair must clear:
#: that of :meth:`rwadist.effects.speed_sidebands_diagnose.SpeedSidebands.candidates` (the lines 20 × over the
#: noise on half the points).
RECORD_SCORE = 20.0
#: A Welch pair's sides are read where its fitted depth puts them this many times over the noise in their window
#: (:meth:`Sidebands.fit`): there a side's residual is its own line, whose power is centred on it
STRONG_OVER_NOISE = 10.0
#: Largest median |power centroid − the side's frequency| (Welch bins) of a pair's strong sides.  A line modulated
#: at a fixed frequency puts its sides at f ± f_mod at every speed, each a window kernel centred there (injected
#: pairs: 0.003-0.022 bins, tests/test_diagnose_modulation.py and tests/test_sidebands_centred.py); lines at other
#: ratios of the speed that the model lacks cross the sides' windows as the speed moves, off centre (family wheel 4's
#: 30-s run-up: the radial force's h 6.09 and 6.38, never resolved from each other and missing from the modes' base,
#: read by a "pair" at ±59.3 Hz of its h 4.62, depth 1.01, 1.0 bin; the E wheel with a line h 2.6 the model lacks
#: beside its h 2: 1.40-1.55 bins)
MAX_CENTROID_BINS = 0.5


def _plateau_middle(score: np.ndarray, sd: np.ndarray) -> int:
    """Index of the middle of the run of offsets around the best score whose scores lie within one noise standard
    deviation ``sd`` (per offset) of it.  The offsets are a quarter-bin grid but the score reads whole bins (and
    the largest of three, clipped): a sideband ridge is a plateau of equal scores some three bins wide, whose
    first point is where the ridge's reach begins, not the ridge (20 speeds: ten fit runs do not round it off).
    A score falling away from the grid's edge is still a plateau of one point there (no pair near)."""
    j = int(np.argmax(score))
    near = score >= score[j] - sd
    lo = j
    while lo > 0 and near[lo - 1]:
        lo -= 1
    hi = j
    while hi < score.size - 1 and near[hi + 1]:
        hi += 1
    return (lo + hi) // 2


def _centroid(ctx: Context, R: np.ndarray, f_hz: np.ndarray) -> np.ndarray:
    """Power centroid (Welch bins from ``f_hz``, per run) of the positive residual ``R`` (runs, bins; unit²/Hz) in
    ±LINE_HALF bins about each run's ``f_hz`` (Hz): about 0 where that power is a line at ``f_hz``."""
    k = np.clip(np.rint(np.abs(f_hz) / ctx.df).astype(int)[:, None] + np.arange(-LINE_HALF, LINE_HALF + 1), 0,
                ctx.f.size - 1)
    w = np.maximum(np.take_along_axis(R, k, axis=1), 0.0)
    return np.sum(w * (k * ctx.df - np.abs(f_hz)[:, None]), axis=1) / np.maximum(w.sum(1), 1e-300) / ctx.df


def _depth_ok(m: float) -> bool:
    """True for a modulation depth a model holds, 0 < m <= :data:`rwadist.schema.MAX_DEPTH`: lines beside a carrier
    that many times stronger than it are no modulation of it (family wheel 2 with a fixture at 46.5 Hz: depth 78 on a
    weak carrier, and the model diagnose wrote was refused on writing)."""
    from ..schema import MAX_DEPTH

    return bool(0.0 < m <= MAX_DEPTH)


#: A carrier whose Welch-read amplitude would change by less than this fraction is not read again on the whole record
#: (:meth:`Sidebands.fit_record`): a depth below 0.1
CARRIER_SCALE_MIN = 0.0025


def _carrier_over_model(ctx: Context, state: State, direction: str, h: float, runs) -> float | None:
    """The median over ``runs`` and the direction's channels of the carrier's amplitude on the whole-run DFT (Hann,
    :func:`rwadist.dft.windowed_dfts`; its power less the state's noise there, points 10x over it) over the state's
    amplitude of the line (times the fixed resonances' gain): 1 where the state holds the carrier alone, below where
    it holds the carrier with sidebands read in its Welch window; None with fewer than 3 points."""
    from ..dft import windowed_dfts
    from .speed_sidebands_diagnose import _run_chunks, _run_noise, _run_records

    chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
    runs = np.asarray(runs)
    fc = h * ctx.omega[runs] / (2 * np.pi)
    P = np.full((runs.size, len(chans)), np.nan)
    for n, fs, wsum, rows in _run_chunks(ctx, runs, range(runs.size), len(chans)):
        X = 2.0 * windowed_dfts(_run_records(ctx, runs[rows], chans), fs, fc[rows][:, None]) / wsum
        P[rows] = np.abs(X[:, 0, :]) ** 2
    N = _run_noise(ctx, state, chans, runs, fc[:, None])[:, 0, :]
    out = []
    for j, c in enumerate(chans):
        a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
        if a is None:
            return None
        model = np.abs(a * (ctx.gain(state, c, fc) if state.resonances else 1.0)) * np.ones(runs.size)
        ok = (P[:, j] > 10.0 * N[:, j]) & (model > 0)
        out.append(np.sqrt(P[ok, j] - N[ok, j]) / model[ok])
    r = np.concatenate(out) if out else np.zeros(0)
    return float(np.median(r)) if r.size >= 3 else None


def _carrier_scaled(state: State, direction: str, h: float, scale: float) -> State:
    """A copy of ``state`` with the lines of (direction, h) (|Δh| < LAW_H_TOL) multiplied by ``scale``: the model's
    harmonics (their standard errors alike) and, when one is the imbalance of the extended base, its U_s or U_d."""
    from dataclasses import replace

    from .. import extended as ext

    s = state.copy()
    if s.ext is not None and any(ln.imbalance for ln in s.ext_lines()
                                 if ln.direction == direction and abs(ln.h - h) < ext.LAW_H_TOL):
        name = "U_s" if direction == "radial_force" else "U_d"
        s.ext = replace(s.ext, **{name: getattr(s.ext, name) * scale})
        s.model.analytical = dict(s.model.analytical or {}, **ext.params_to_dict(s.ext))
    s.model.empirical[direction] = [
        replace(x, C=x.C * scale, C_stderr=None if x.C_stderr is None else x.C_stderr * scale)
        if abs(x.h - h) < ext.LAW_H_TOL else x for x in s.model.harmonics(direction)]
    return s


@register(order=60)
@dataclass
class Sidebands:
    """Amplitude modulation of one harmonic line at a FIXED frequency f_mod (Hz, the same at every speed: a
    cage or electronics frequency, a drive's PWM beat): a(Ω)·(1 + m·cos 2πf_mod t)·cos(2πf_i t + φ) is the
    carrier plus two lines at f_i ± f_mod of amplitude m·a/2 (depth m, dimensionless)."""

    direction: str
    h: float
    f_mod: float
    depth: float
    n_points: int = 0
    kind: str = "sidebands"
    #: the carrier's amplitude in the state is multiplied by this when the effect is applied (:meth:`fit_record`: a
    #: pair inside the carrier's Welch kernel, whose power the base measured with the carrier's)
    carrier_scale: float = 1.0

    @property
    def channels(self):
        return DIRECTION_CHANNELS[self.direction]

    def apply(self, state: State) -> State:
        if self.carrier_scale == 1.0:
            return state.plus(self)
        return _carrier_scaled(state, self.direction, self.h, self.carrier_scale).plus(self)

    def contribute(self, parts) -> None:
        parts.modulations.append((self.direction, round(self.h, 4), self.f_mod, self.depth))

    def refit(self, ctx: Context, state: State) -> "Sidebands":
        """Refitted on every run (``ctx.runs``), on the whole-run DFT when the offset is below the Welch grid
        (:meth:`fit_record`); itself when that fit fails."""
        if self.f_mod < 2.5 * ctx.df and ctx.test is not None:
            return Sidebands.fit_record(ctx, state, self.direction, self.h, ctx.runs, self.f_mod) or self
        return Sidebands.fit(ctx, state, self.direction, self.h, ctx.runs, self.f_mod) or self

    def to_schema(self) -> dict:
        return schema_entry(self)

    def params(self) -> dict:
        return {"direction": self.direction, "h": round(self.h, 4), "f_mod_Hz": self.f_mod, "depth": self.depth,
                "n_points": self.n_points,
                "law": "a(1 + depth*cos(2 pi f_mod t)): lines at h|omega|/2pi +- f_mod_Hz of amplitude depth*a/2"}

    @staticmethod
    def fit(ctx: Context, state: State, direction: str, h: float, runs, f_mod: float) -> "Sidebands | None":
        """f_mod by :func:`_refine_offset` on both sides of the carrier; m² by linear least squares of the
        measured sideband window powers P on their prediction per unit m², q = (a/2)²/2 (a the carrier's model
        amplitude, times the resonance gain at the sideband), over every in-band side clear of other lines."""
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        f_mod, n = _refine_offset(ctx, state, chans, runs, [h], f_mod)
        if n < 3 or f_mod <= 0:
            return None
        P_parts, Q_parts, N_parts, C_parts = [], [], [], []     # per channel and side, the runs kept: measured and
        # model powers, noise power in the window, the residual's power centroid (bins from the side)
        for c in chans:
            R, _ = _residual_z(ctx, state, c, runs)
            a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
            if a is None:
                return None
            for side in (1.0, -1.0):
                f = h * ctx.omega[runs] / (2 * np.pi) + side * f_mod
                p, noise, _, inb = _window_power(ctx, state, c, runs, f, R)
                ok = inb & _clear_of_lines(ctx, state, c, runs, f, h) & (f > 0)
                g = (ctx.gain(state, c, f) if state.resonances else 1.0) * \
                    ctx.sideband_gain(state, c, h, side * f_mod, runs)            # through the modes at f
                P_parts.append(p[ok])
                Q_parts.append(((a * g) ** 2 / 8.0 * np.ones(runs.size))[ok])
                N_parts.append(noise[ok])
                C_parts.append(_centroid(ctx, R, f)[ok])
        P, Q = np.concatenate(P_parts), np.concatenate(Q_parts)
        if P.size < 3 or not np.sum(Q * Q) > 0:
            return None
        m = float(np.sqrt(max(float(np.sum(P * Q) / np.sum(Q * Q)), 0.0)))
        strong = m * m * Q > STRONG_OVER_NOISE * np.concatenate(N_parts)
        if strong.sum() >= 3 and np.median(np.abs(np.concatenate(C_parts)[strong])) > MAX_CENTROID_BINS:
            return None                 # not centred on the sides: other lines crossing their windows
        return Sidebands(direction, float(h), float(f_mod), m, int(P.size)) if _depth_ok(m) else None

    @staticmethod
    def _record_offsets(ctx: Context) -> np.ndarray:
        """Offsets (Hz) only the whole-run DFT resolves: from RUN_MIN_BINS record bins (the Hann main lobe's edge)
        up to where the Welch grid starts (:func:`_offset_grid`: 2.5 Welch bins); empty without the time series."""
        from .speed_sidebands_diagnose import RUN_MIN_BINS, _record_df

        if ctx.test is None:
            return np.empty(0)
        df_rec = float(np.max(_record_df(ctx, ctx.runs)))
        return np.arange(RUN_MIN_BINS * df_rec, 2.5 * ctx.df, RECORD_STEP_BINS * df_rec)

    @staticmethod
    def _record_valid(ctx: Context, state: State, direction: str, h: float, runs, f_hz) -> np.ndarray:
        """(len(runs), L) mask: the sideband frequencies ``f_hz`` in band and at least RUN_MIN_BINS record bins from
        every other line of the direction (the carrier's own leakage is subtracted, :func:`_run_line_power`)."""
        from .speed_sidebands_diagnose import RUN_MIN_BINS, _record_df

        w = ctx.omega[runs][:, None] / (2 * np.pi)
        sep = RUN_MIN_BINS * _record_df(ctx, runs)[:, None]
        ok = (f_hz >= (ctx.k_lo + 1) * ctx.df) & (f_hz <= (ctx.k_hi - 1) * ctx.df)
        for x in state.model.harmonics(direction):
            if abs(x.h - h) > 1e-6:
                ok &= np.abs(f_hz - x.h * w) >= sep
        return ok

    @staticmethod
    def _record_power(ctx: Context, state: State, direction: str, h: float, runs, offsets,
                      single: bool = False) -> tuple:
        """(f (runs, 2L), |X|² (runs, 2L, chans), noise (runs, 2L, chans), valid (runs, 2L)) of the lower then upper
        sides f_c ∓ offsets on the whole-run DFT, the carrier's leakage taken off (:func:`_line_powers`).

        |X|² is the data's alone (the noise and the valid points are the state's): kept on the context, so the search's
        later steps (a new state of the same data) and the held-out judge of the same sidebands read it again.
        ``single``: the sums in single precision (:func:`_line_powers`), for the scan of :meth:`record_candidates`."""
        from .speed_sidebands_diagnose import _line_powers, _run_noise

        fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
        f = np.concatenate([fc - offsets[None, :], fc + offsets[None, :]], axis=1)
        key = ("sidebands_record_power", direction, float(h), np.asarray(runs).tobytes(), f.tobytes(), single)
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        if key not in ctx._memo:
            P = Sidebands._scan_powers(ctx, chans, direction, h, runs, offsets) if single else None
            if P is None:
                P = _line_powers(ctx, chans, runs, f, h, single=single)
            P.flags.writeable = False                   # shared by every later reader
            ctx._memo[key] = P
        return f, ctx._memo[key], _run_noise(ctx, state, chans, runs, f), \
            Sidebands._record_valid(ctx, state, direction, h, runs, f)

    @staticmethod
    def _scan_powers(ctx: Context, chans, direction: str, h: float, runs, offsets) -> "np.ndarray | None":
        """The single-precision line powers (:func:`_line_powers`) of the lower then upper sides f_c ∓ ``offsets`` when
        ``offsets`` begin the whole-run scans' grid (:meth:`_record_offsets` continued to :data:`RECORD_SCAN_WELCH_BINS`):
        read from that grid's powers, computed once per carrier and runs (the same numbers: each phasor is its own
        frequency's, whatever others are transformed with it); None for other offsets."""
        from .speed_sidebands_diagnose import RUN_MIN_BINS, _line_powers, _record_df

        df_rec = float(np.max(_record_df(ctx, ctx.runs)))
        grid = np.arange(RUN_MIN_BINS * df_rec, RECORD_SCAN_WELCH_BINS * ctx.df, RECORD_STEP_BINS * df_rec)
        n = offsets.size
        if not 0 < n <= grid.size or not np.array_equal(grid[:n], offsets):
            return None
        key = Sidebands._scan_key(direction, h, runs, grid)
        if key not in ctx._memo:
            fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
            ctx._memo[key] = _line_powers(ctx, chans, runs, np.concatenate([fc - grid, fc + grid], axis=1), h,
                                          single=True)
        P = ctx._memo[key]
        return np.concatenate([P[:, :n], P[:, grid.size:grid.size + n]], axis=1)

    @staticmethod
    def _prefetch_scan_powers(ctx: Context, direction: str, hs, runs, offsets) -> None:
        """The scan powers (:meth:`_scan_powers`) of every carrier of ``hs`` that :meth:`record_candidates` is about to
        read from them (the whole-run scans' grid begins with ``offsets``, and neither its scan nor its powers are
        kept yet), computed together (:func:`~rwadist.effects.speed_sidebands_diagnose._carrier_line_powers`: the
        numbers of one carrier at a time) and kept as :meth:`_scan_powers` keeps them."""
        from .speed_sidebands_diagnose import RUN_MIN_BINS, _carrier_line_powers, _record_df

        df_rec = float(np.max(_record_df(ctx, ctx.runs)))
        grid = np.arange(RUN_MIN_BINS * df_rec, RECORD_SCAN_WELCH_BINS * ctx.df, RECORD_STEP_BINS * df_rec)
        n = offsets.size
        if not 0 < n <= grid.size or not np.array_equal(grid[:n], offsets):
            return
        todo = []
        for h in hs:
            fc = h * ctx.omega[runs][:, None] / (2 * np.pi)
            f = np.concatenate([fc - offsets[None, :], fc + offsets[None, :]], axis=1)
            if ("sidebands_record_power", direction, float(h), np.asarray(runs).tobytes(), f.tobytes(), True) \
                    in ctx._memo or Sidebands._scan_key(direction, h, runs, grid) in ctx._memo:
                continue
            todo.append((h, np.concatenate([fc - grid, fc + grid], axis=1)))
        if len(todo) < 2:
            return                      # one carrier: :meth:`_scan_powers` computes it as ever
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        P = _carrier_line_powers(ctx, chans, runs, [f for _, f in todo], [h for h, _ in todo], single=True)
        for (h, _), p in zip(todo, P):
            ctx._memo[Sidebands._scan_key(direction, h, runs, grid)] = p

    @staticmethod
    def _scan_key(direction: str, h: float, runs, grid: np.ndarray) -> tuple:
        """Key of a carrier's scan powers (:meth:`_scan_powers`) on the context."""
        return ("sidebands_scan_powers", direction, float(h), np.asarray(runs).tobytes(), grid.tobytes())

    @staticmethod
    def fit_record(ctx: Context, state: State, direction: str, h: float, runs, f_mod: float) -> "Sidebands | None":
        """The fit on the whole-run DFT (time series given) of sidebands closer to their carrier than the Welch bins
        resolve: f_mod the maximum of Σ|X|² over both sides and every valid run on a grid ±REFINE_STEPS scan steps
        (RECORD_STEP_BINS record bins each) around ``f_mod`` (step 1/50 bin); the sides' amplitudes sqrt(|X|² − noise) of the points 10 × over
        the noise, on their prediction per unit depth q = a·g/2 (a the carrier's model amplitude in the channel, g
        the fixed resonances' gain at the side): m by least squares, Σ A·q / Σ q²."""
        from .speed_sidebands_diagnose import _record_df

        df_rec = float(np.max(_record_df(ctx, runs)))
        half = REFINE_STEPS * RECORD_STEP_BINS
        grid = f_mod + np.arange(-half, half + 1e-9, 0.02) * df_rec
        f, P, _, ok = Sidebands._record_power(ctx, state, direction, h, runs, grid)
        both = ok[:, :grid.size] & ok[:, grid.size:]
        tot = np.sum(np.where(both[:, :, None], P[:, :grid.size] + P[:, grid.size:], 0.0), axis=(0, 2))
        i = int(np.argmax(tot))
        if not 0 < i < grid.size - 1:
            return None                                     # the maximum at the grid's edge: no pair near f_mod
        f_mod = float(grid[i])
        f, P, N, ok = Sidebands._record_power(ctx, state, direction, h, runs, np.array([f_mod]))
        chans = [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels]
        A_parts, Q_parts = [], []        # per channel and side: measured and model amplitudes of the runs kept
        for j, c in enumerate(chans):
            a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - h) < 1e-9), None)
            if a is None:
                return None
            for col in (0, 1):                               # lower, upper
                g = (ctx.gain(state, c, f[:, col]) if state.resonances else 1.0) * \
                    ctx.sideband_gain(state, c, h, (2 * col - 1) * f_mod, runs)
                keep = ok[:, col] & (P[:, col, j] > 10.0 * N[:, col, j])
                A_parts.append(np.sqrt(np.maximum(P[:, col, j] - N[:, col, j], 0.0))[keep])
                Q_parts.append((0.5 * a * g * np.ones(runs.size))[keep])
        A, Q = np.concatenate(A_parts), np.concatenate(Q_parts)
        if A.size < 3 or not np.sum(Q * Q) > 0:
            return None
        m = float(np.sum(A * Q) / np.sum(Q * Q))
        # the pair sits inside the carrier's Welch kernel: where the state's carrier amplitude a was measured with it,
        # a² = a_c²(1 + depth²/2) with a_c the carrier's own, and m = depth·a_c/a.  The whole record, which resolves
        # the pair, reads the carrier itself and tells which: then the carrier is scaled to a_c and the depth given
        # against it, the kernel's power kept (a 1x line modulated 0.3 at 0.7 Hz, trial nuR: read 0.294 against a, the
        # sidebands added on top raised the error 0.0059 -> 0.019 and were not taken); a base that measured the
        # carrier apart from the pair (family wheel 1, ±7.3 Hz at 10 kHz) is left as it is
        scale = 1.0
        full = float(np.sqrt(1.0 - 0.5 * m * m)) if m * m < 1.98 else 1.0          # m < sqrt(2) always: a_c > 0
        if full < 1.0 - CARRIER_SCALE_MIN:
            # the carrier read on the runs the depth was read on (both sides valid)
            r = _carrier_over_model(ctx, state, direction, h, np.asarray(runs)[ok[:, 0] & ok[:, 1]])
            if r is not None and abs(np.log(r / full)) < abs(np.log(r)):
                scale = full
        m /= scale
        return Sidebands(direction, float(h), f_mod, m, int(A.size), carrier_scale=scale) if _depth_ok(m) else None

    def heldout_evidence(self, ctx: Context, state: State, runs):
        """Held-out evidence of sidebands closer to their carrier than 2.5 Welch bins (None otherwise: the search's own
        judge).  There the pair sits in the carrier's own Welch kernel, whose power the error metric's bands sum with
        it: the PSDs hardly see it (at 2048 samples, f_mod 7 Hz is 0.9 Welch bin), the whole record does
        (:meth:`_record_power`, the carrier's leakage taken off).  (drop, se) of the misplaced sideband power on the
        valid points of both sides (:func:`~rwadist.effects.missing_harmonic_diagnose.record_line_evidence`; the
        state predicts no sidebands on this carrier, the effect (m·a·g/2)² per side, a the carrier's model amplitude
        in the channel, g the fixed resonances' gain at the side).  Not on a state with a spin smear or a speed ripple
        (their lines are no steady lines on the record)."""
        from .missing_harmonic_diagnose import record_line_evidence

        if ctx.test is None or self.f_mod >= 2.5 * ctx.df or state.smear is not None \
                or state.speed_modulation is not None:
            # (a swept speed smears the carrier over the record, a speed ripple gives it sidebands of its own that the
            # state predicts in its PSDs: the record's lines are not steady ones, and the search's judge decides)
            return None
        if any(d == self.direction and abs(h - self.h) < 1e-4 for d, h, _, _ in state.modulations):
            return None
        f, P, N, ok = Sidebands._record_power(ctx, state, self.direction, self.h, runs, np.array([self.f_mod]))
        chans = [c for c in DIRECTION_CHANNELS[self.direction] if c in ctx.channels]
        m1_rows = []
        for c in chans:
            a = next((x[2] for x in ctx.channel_lines(state, c, runs) if abs(x[0] - self.h) < 1e-9), None)
            if a is None:
                return None
            g = np.column_stack([ctx.gain(state, c, f[:, col]) for col in (0, 1)]) if state.resonances else 1.0
            g = g * np.column_stack([ctx.sideband_gain(state, c, self.h, side * self.f_mod, runs) for side in (-1, 1)])
            # the carrier as the effect leaves it (a·carrier_scale: the sides are depth/2 of the carrier's own)
            m1_rows.append((0.5 * self.depth * self.carrier_scale * a[:, None] * g * np.ones((runs.size, 2))) ** 2)
        M1 = np.array(m1_rows).reshape(len(chans), -1)                        # (chans, runs·2)
        P = np.moveaxis(P, 2, 0).reshape(len(chans), -1)
        N = np.moveaxis(N, 2, 0).reshape(len(chans), -1)
        ok = np.broadcast_to(ok.reshape(1, -1), P.shape)
        return record_line_evidence(ctx, chans, P, N, ok, M1)

    @staticmethod
    def record_candidates(ctx: Context, state: State, runs, direction: str, hs, offsets=None) -> list:
        """[(score, h, f_mod)] of the carriers ``hs`` whose sidebands sit closer than the Welch grid reaches
        (:meth:`_record_offsets`, or the ``offsets`` Hz given): per offset the median over the RECORD_SCAN_RUNS fastest
        runs, channels and both sides of |X|²/noise on the whole-run DFT (valid points only, >= 6 of them), the best
        offset kept when it clears RECORD_SCORE and is a local maximum.  The line powers are kept on the context, per
        state prediction."""
        from .speed_sidebands_diagnose import side_pair_medians

        given = offsets is not None
        offsets = np.asarray(offsets, float) if given else Sidebands._record_offsets(ctx)
        if offsets.size < 3:
            return []
        sel = runs[np.argsort(ctx.omega[runs])[::-1][:RECORD_SCAN_RUNS]]
        # the noise and the valid points read the state (its floor, its lines): keyed by what it predicts there
        state_key = ctx.content_key(state, [c for c in DIRECTION_CHANNELS[direction] if c in ctx.channels], sel)
        out = []
        keys = [("sidebands_record_scan", direction, round(h, 6), sel.tobytes(), state_key) +
                ((offsets.tobytes(),) if given else ()) for h in hs]
        Sidebands._prefetch_scan_powers(ctx, direction, [h for h, key in zip(hs, keys) if key not in ctx._memo],
                                        sel, offsets)
        for h, key in zip(hs, keys):
            if key not in ctx._memo:
                ctx._memo[key] = Sidebands._record_power(ctx, state, direction, h, sel, offsets, single=True)
            f, P, N, ok = ctx._memo[key]
            z = P / np.maximum(N, 1e-300)
            L = offsets.size
            both = ok[:, :L] & ok[:, L:]                # the runs whose two sides are both valid, per offset
            score = side_pair_medians(z, np.concatenate([both, both], axis=1), np.arange(L))
            j = int(np.argmax(score))
            if 0 < j < L - 1 and score[j] > RECORD_SCORE:
                out.append((score[j], h, float(offsets[j])))
        return out

    @staticmethod
    def candidates(ctx: Context, state: State, runs, max_per_direction: int = 3) -> list:
        """Per direction, the carriers whose best constant-offset ridge pair (:func:`_offset_scores`) clears
        :func:`_offset_threshold`; at most ``max_per_direction``, strongest first."""
        out: list[Sidebands] = []
        offsets = _offset_grid(ctx)
        if offsets.size < 3:
            return out
        for d, direction_chans in DIRECTION_CHANNELS.items():
            chans = [c for c in direction_chans if c in ctx.channels]
            hs = [x.h for x in state.model.harmonics(d)
                  if not any(dd == d and abs(hh - x.h) < 1e-4 for dd, hh, _, _ in state.modulations)]
            if not chans or not hs:
                continue
            # a direction's sidebands from its own channels alone (Context.reuse); not skipped where a metric-judged
            # effect could not pass (Context.can_pass): a Welch-route pair refined below 2.5 bins brings its own
            # held-out evidence
            out += ctx.reuse("sidebands", state, chans, runs,
                             lambda d=d, chans=chans, hs=hs: Sidebands._welch_candidates(
                                 ctx, state, runs, d, chans, hs, offsets, max_per_direction))
            out += ctx.reuse("sidebands", state, chans, runs,
                             lambda d=d, hs=hs: Sidebands._record_candidates_fitted(ctx, state, runs, d, hs,
                                                                                    max_per_direction),
                             part="record")
        if state.smear is not None:
            # under a spin smear a line sweeps h|α|T/2π Hz over a run: a "pair" within that sweep (and the main lobe
            # beyond it) is the line's own spread -- a Welch pair's offset refined toward its carrier (family wheel 7's
            # 60-s run-up: ±0.31 Hz, depth 0.55, on the radial torque's h 3.42 smeared over ±2.8 Hz)
            T = float(np.max(ctx.run_durations(np.asarray(runs))))
            out = [e for e in out if e.f_mod >= 2.5 * ctx.df + e.h * state.smear * T / (4 * np.pi)]
        return out

    @staticmethod
    def _welch_candidates(ctx: Context, state: State, runs, d: str, chans, hs, offsets, max_per_direction: int) -> list:
        """:meth:`candidates` of direction ``d`` (its channels ``chans``, carriers ``hs``) on the Welch PSDs."""
        out = []
        tot, cnt = _offset_scores(ctx, state, chans, runs, hs, offsets)
        score = np.where(cnt >= 6, tot / np.maximum(cnt, 1), 0.0)
        found = []
        for i, h in enumerate(hs):
            s = score[i]
            j = _plateau_middle(s, np.sqrt(2.0 / ctx.dof) / np.sqrt(np.maximum(cnt[i], 1)))
            if 0 < j < s.size - 1 and s[j] > _offset_threshold(ctx, cnt[i, j]):
                found.append((s[j], h, float(offsets[j])))
        for _, h, f_m in sorted(found, reverse=True)[:max_per_direction]:
            e = Sidebands.fit(ctx, state, d, h, runs, f_m)
            if e is not None:
                out.append(e)
        return out

    @staticmethod
    def _record_candidates_fitted(ctx: Context, state: State, runs, d: str, hs, max_per_direction: int) -> list:
        """Sidebands of direction ``d`` closer to the carrier than 2.5 Welch bins (a short record, a high sample rate:
        f_mod 7 Hz at 7.5-Hz Welch bins), resolved by the whole record only: :meth:`record_candidates`, fitted.  None on
        a state with a spin smear: a line sweeping h|α|T/2π Hz over the record spreads over many record bins, and a
        "pair" that close is its own spread (their held-out evidence is not read there
        either, :meth:`heldout_evidence`; family wheel 7's 60-s run-up: a pair at ±0.31 Hz, depth 0.55, on the radial torque's h 3.42)."""
        out: list = []
        if state.smear is not None:
            return out
        near = Sidebands.record_candidates(ctx, state, runs, d, hs)
        for _, h, f_m in sorted(near, reverse=True)[:max_per_direction]:
            e = Sidebands.fit_record(ctx, state, d, h, runs, f_m)
            if e is not None:
                out.append(e)
        return out
