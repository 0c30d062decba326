"""Residual measurements shared by several effect families: line amplitudes pooled over a direction,
residual ridges along h·|Ω| and at constant frequency offsets, window powers."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..units import DIRECTION_CHANNELS
from .constants import LINE_HALF

if TYPE_CHECKING:                      # annotations only (the engine imports nothing from here at run time)
    from .engine import Context
    from .state import State


def in_unresolved_span(model, direction: str, h: float) -> bool:
    """True when the model's extended fit recorded (direction, h) inside a span of lines it detected but could
    not measure apart (``analytical.fit.unresolved_lines``, :func:`rwadist.extended_fit.unresolved_spans`)."""
    fit = (getattr(model, "analytical", None) or {}).get("fit") or {}
    return any(sp.get("direction") == direction and sp.get("h_min", np.inf) <= h <= sp.get("h_max", -np.inf)
               for sp in fit.get("unresolved_lines") or [])


def _measure(ctx, state, direction, h, runs, skip=None):
    """Line amplitudes of (direction, h) pooled over the direction's channels: (amplitude, omega)."""
    ds, ws = [], []
    for c in DIRECTION_CHANNELS[direction]:
        if c not in ctx.channels:
            continue
        a = ctx.measure_line(state, c, h, runs, skip=skip)
        a = a / ctx.gain(state, c, h * ctx.omega[runs] / (2 * np.pi))     # the line before any resonance
        if state.ext is not None:
            a = a / ctx.modal_gain(state, c, h, runs)                      # ... and before the wheel's modes
        ok = np.isfinite(a)
        ds.append(a[ok])
        ws.append(ctx.omega[runs][ok])
    return np.concatenate(ds) if ds else np.empty(0), np.concatenate(ws) if ws else np.empty(0)


def measure_run_powers(ctx, state, direction, h, runs, skip=None, channels=None):
    """Amplitude of the line (direction, h) per part, one per run, the powers of the direction's channels pooled:
    (amplitude, omega, leak, snr), amplitude N or N·m that each of the line's parts (its co- and counter-rotating
    harmonics in the state's model, one co-rotating part when it has none) would carry before any resonance and the
    wheel's modes -- the amplitude an amplitude law gives each of them (:class:`rwadist.effects.actions.LineLaw`) --,
    omega rad/s, leak the power the state predicts in the line's windows for its other lines over the line's own
    measured power (both summed over the channels): what the measurement rests on the neighbours' prediction, snr
    the line's measured power over the model floor's in its windows (summed over the channels).

    A radial line with co- and counter-rotating parts of free phases is |c₊ + c₋| in x and |c₊ − c₋| in y: one
    channel alone swings between 0 and twice the line's mean power from run to run, but the two channels' powers add
    to 2(|c₊|² + |c₋|²) whatever the phases (family wheel 4: its h 4.62 bearing line, half counter-rotating, read
    per channel at 0.03-1.4x its true amplitude, and its Ω³ law was missed).  So each run's amplitude is
    sqrt(Σ_c a_c² / Σ_c Σ_parts g_c,part²), g the resonance and modal gain of a unit load of the part's sense; a
    channel whose line is below its noise (NaN) beside one that is measured counts as 0.  ``channels``: those of the
    direction's channels to pool (default: every one the data hold)."""
    senses = [getattr(x, "sense", None) or "co" for x in state.model.harmonics(direction) if abs(x.h - h) < 1e-3]
    p_sum = np.zeros(runs.size)
    g_sum = np.zeros(runs.size)
    q_sum = np.zeros(runs.size)
    n_sum = np.zeros(runs.size)
    seen = np.zeros(runs.size, bool)
    for c in DIRECTION_CHANNELS[direction]:
        if c not in ctx.channels or (channels is not None and c not in channels):
            continue
        a = ctx.measure_line(state, c, h, runs, skip=skip)
        g = ctx.gain(state, c, h * ctx.omega[runs] / (2 * np.pi))
        modal = [ctx.unit_gain(state, c, direction, h, s, runs) for s in senses or ["co"]]
        ok = np.isfinite(a)
        seen |= ok
        p_sum += np.where(ok, a, 0.0) ** 2
        g_sum += g**2 * np.sum(np.square(modal), axis=0)
        q_sum += _neighbour_power(ctx, state, c, h, runs)
        n_sum += _window_floor(ctx, state, c, h, runs)
    with np.errstate(divide="ignore", invalid="ignore"):
        amp = np.sqrt(p_sum / g_sum)
        leak = q_sum / (0.5 * p_sum)
        snr = 0.5 * p_sum / n_sum
    keep = seen & np.isfinite(amp) & (amp > 0)
    return amp[keep], ctx.omega[runs][keep], leak[keep], snr[keep]


def _window_k(ctx, h, runs):
    """Bins (len(runs), 2·LINE_HALF + 1) of the line h's window in each run (:meth:`Context.measure_line`'s)."""
    k0 = np.rint(h * ctx.omega[runs] / (2 * np.pi) / ctx.df).astype(int)
    return np.clip(k0[:, None] + np.arange(-LINE_HALF, LINE_HALF + 1), 0, ctx.f.size - 1)


def _window_floor(ctx, state, c, h, runs):
    """Power (unit²) of the model floor of channel ``c`` in the line h's window of each run."""
    return ctx.floor_psd(state, c, runs)[np.arange(runs.size)[:, None], _window_k(ctx, h, runs)].sum(1) * ctx.df


def _neighbour_power(ctx, state, c, h, runs):
    """Power (unit²) the state predicts for its lines other than h (not its floor) in channel ``c``'s ±LINE_HALF-bin
    window of the line h of each run (the window :meth:`Context.measure_line` measures it in)."""
    k = _window_k(ctx, h, runs)
    rows = np.arange(runs.size)[:, None]
    others = (ctx.predict(state, c, runs)[rows, k] - ctx._predict(state, c, runs, None, h, bins=k)
              - ctx.floor_psd(state, c, runs)[rows, k])
    return np.maximum(others, 0.0).sum(1) * ctx.df


def _ridge_score(ctx, state, chans, runs, h_grid):
    """Mean normalised residual along f = h|Ω|/2π for every h of ``h_grid`` (pairs in band only)."""
    score = np.zeros(h_grid.size)
    count = np.zeros(h_grid.size)
    k = np.rint(np.outer(h_grid, ctx.omega[runs]) / (2 * np.pi) / ctx.df).astype(int)       # (n_h, n_runs)
    inb = (k >= ctx.k_lo) & (k <= ctx.k_hi)
    flat = np.arange(runs.size)[None, :] * ctx.f.size + np.clip(k, 0, ctx.f.size - 1)      # the same for every channel
    for c in chans:
        R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
        z = R / ctx.floor_psd(state, c, runs)
        zmax = np.maximum(np.maximum(z, np.roll(z, 1, axis=1)), np.roll(z, -1, axis=1))
        vals = np.ravel(zmax).take(flat)
        vals = np.clip(vals, -5.0, 20.0)          # a presence-like score: strong lines count alike
        score += np.where(inb, vals, 0).sum(1)
        count += inb.sum(1)
    return np.where(count >= 6, score / np.maximum(count, 1), 0.0)


def ridge_peaks(ctx, state, chans, runs, n_max: int, h_min: float = 0.1):
    """Harmonic numbers of the strongest residual ridges (local maxima of the ridge score above
    10 noise standard deviations of a pooled residual)."""
    top = ctx.k_hi * ctx.df * 2 * np.pi / max(ctx.omega[runs].min(), 1e-9)
    h_grid = np.arange(h_min, min(top, 40.0), 0.005)
    if h_grid.size < 3:
        return []
    s = _ridge_score(ctx, state, chans, runs, h_grid)
    # a noise bin of the pooled mean has std ~ sqrt(2/dof)/sqrt(n_pairs); demand a clear ridge
    thr = 10.0 * np.sqrt(2.0 / ctx.dof) / np.sqrt(max(runs.size * len(chans), 1)) + 0.5
    peaks = np.nonzero((s[1:-1] > s[:-2]) & (s[1:-1] >= s[2:]) & (s[1:-1] > thr))[0] + 1
    peaks = peaks[np.argsort(-s[peaks])][:n_max]
    return [float(h_grid[i]) for i in peaks]


def refine_h(ctx, state, chans, runs, h, n_iter: int = 3):
    """Harmonic number of the ridge near ``h``: in every (run, channel) the residual peak within
    ±2 bins of h|Ω|/2π, its frequency refined by a log-parabola through three bins (accurate to a few
    hundredths of a bin for a Hann window), and h = least squares of f_peak = h·|Ω|/2π over the peaks
    standing clear of the noise (residual > 20 × floor)."""
    for _ in range(n_iter):
        fs_, ws_ = [], []
        for c in chans:
            R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
            z = R / ctx.floor_psd(state, c, runs)
            k0 = np.rint(h * ctx.omega[runs] / (2 * np.pi) / ctx.df).astype(int)
            offs = np.arange(-2, 3)
            k = np.clip(k0[:, None] + offs, 1, ctx.f.size - 2)
            rows = np.arange(runs.size)[:, None]
            # the peak of the residual itself (z = R / floor can peak beside it where the floor dips), kept
            # only where it is a local maximum standing clear of the noise
            kp = k[np.arange(runs.size), np.argmax(R[rows, k], axis=1)]
            r = np.arange(runs.size)
            ok = (kp - 1 >= ctx.k_lo) & (kp + 1 <= ctx.k_hi) & (z[r, kp] > 20.0)
            ok &= (R[r, kp] >= R[r, kp - 1]) & (R[r, kp] >= R[r, np.minimum(kp + 1, ctx.f.size - 1)])
            lo, mid, hi = (np.log(np.maximum(R[r, kp + j], 1e-300)) for j in (-1, 0, 1))
            den = lo - 2 * mid + hi
            with np.errstate(divide="ignore", invalid="ignore"):
                dl = np.clip(np.where(den < 0, 0.5 * (lo - hi) / den, 0.0), -0.5, 0.5)
            fs_.append(((kp + dl) * ctx.df)[ok])
            ws_.append((ctx.omega[runs] / (2 * np.pi))[ok])
        f_pk, w_hz = np.concatenate(fs_), np.concatenate(ws_)
        if f_pk.size < 3:
            return h
        h = float(np.sum(f_pk * w_hz) / np.sum(w_hz**2))
    return h


def _residual_z(ctx, state, c, runs):
    """Residual (data − model) of channel ``c`` and its value over the model's floor, the latter the
    maximum of each bin and its two neighbours (a line between bins)."""
    R = ctx.data(state, c)[runs] - ctx.predict(state, c, runs)
    z = R / ctx.floor_psd(state, c, runs)
    return R, np.maximum(np.maximum(z, np.roll(z, 1, axis=1)), np.roll(z, -1, axis=1))


def _offset_scores(ctx, state, chans, runs, hs, offsets):
    """Sum and count (len(hs), len(offsets)) of the clipped normalised residual at h|Ω|/2π ± Δ for every
    carrier h of ``hs`` and offset Δ (Hz) of ``offsets``, over ``chans``, ``runs`` and both sides (in band
    only): parallel ridges at a constant frequency offset from a line."""
    tot = np.zeros((len(hs), offsets.size))
    cnt = np.zeros((len(hs), offsets.size))
    rows = np.arange(runs.size)[None, :]
    for c in chans:
        _, z = _residual_z(ctx, state, c, runs)
        z = np.clip(z, -5.0, 20.0)
        for i, h in enumerate(hs):
            f0 = h * ctx.omega[runs] / (2 * np.pi)
            for side in (1.0, -1.0):
                k = np.rint((f0[None, :] + side * offsets[:, None]) / ctx.df).astype(int)
                inb = (k >= ctx.k_lo) & (k <= ctx.k_hi)
                vals = z[rows, np.clip(k, 0, ctx.f.size - 1)]
                tot[i] += np.where(inb, vals, 0.0).sum(1)
                cnt[i] += inb.sum(1)
    return tot, cnt


def _offset_threshold(ctx, n):
    """Pooled-score threshold of a ridge (as :func:`ridge_peaks`): 10 noise standard deviations of a mean
    of ``n`` normalised residual bins, plus 0.5."""
    return 10.0 * np.sqrt(2.0 / ctx.dof) / np.sqrt(max(n, 1)) + 0.5


def _offset_grid(ctx, f_max: float = 50.0):
    """Offsets (Hz) searched for sidebands: from 2.5 bins (clear of the carrier's main lobe) to f_max."""
    return np.arange(2.5 * ctx.df, min(f_max, 0.5 * ctx.k_hi * ctx.df), 0.25 * ctx.df)


def _refine_offset(ctx, state, chans, runs, hs, off, n_iter: int = 2):
    """Constant offset (Hz) of the sideband ridges near ``off`` around the carriers ``hs``: in every (channel,
    run, carrier, side) the residual peak within ±2 bins of f_i ± off, refined by a log-parabola through three
    bins and kept when > 20 × floor; the offset is the median of side·(f_peak − f_i).  Returns (offset, count)."""
    n = 0
    for _ in range(n_iter):
        found = []            # per channel and side: the offsets measured, Hz
        for c in chans:
            R, _ = _residual_z(ctx, state, c, runs)
            z = R / ctx.floor_psd(state, c, runs)
            r = np.arange(runs.size)
            for h in hs:
                f0 = h * ctx.omega[runs] / (2 * np.pi)
                for side in (1.0, -1.0):
                    k0 = np.rint((f0 + side * off) / ctx.df).astype(int)
                    k = np.clip(k0[:, None] + np.arange(-2, 3), 1, ctx.f.size - 2)
                    kp = k[r, np.argmax(z[r[:, None], k], axis=1)]
                    ok = (kp - 1 >= ctx.k_lo) & (kp + 1 <= ctx.k_hi) & (z[r, kp] > 20.0)
                    lo, mid, hi = (np.log(np.maximum(R[r, kp + j], 1e-300)) for j in (-1, 0, 1))
                    den = lo - 2 * mid + hi
                    with np.errstate(divide="ignore", invalid="ignore"):
                        dl = np.clip(np.where(den < 0, 0.5 * (lo - hi) / den, 0.0), -0.5, 0.5)
                    found.append((side * ((kp + dl) * ctx.df - f0))[ok])
        est = np.concatenate(found) if found else np.empty(0)
        n = est.size
        if n < 3:
            return off, n
        off = float(np.median(est))
    return off, n


def _window_power(ctx, state, c, runs, f_hz, R):
    """Residual power (unit²) in ±LINE_HALF bins around ``f_hz`` (len(runs),), the model floor's power there,
    its noise standard deviation (as :meth:`Context.measure_line`) and an in-band mask."""
    k0 = np.rint(np.abs(f_hz) / ctx.df).astype(int)
    offs = np.arange(-LINE_HALF, LINE_HALF + 1)
    inband = (k0 - LINE_HALF >= ctx.k_lo) & (k0 + LINE_HALF <= ctx.k_hi)
    k = np.clip(k0[:, None] + offs, 0, ctx.f.size - 1)
    p = np.take_along_axis(R, k, axis=1).sum(1) * ctx.df
    noise = np.take_along_axis(ctx.floor_psd(state, c, runs), k, axis=1).sum(1) * ctx.df
    sig = 2.0 * noise * np.sqrt(2.0 / ctx.dof) / np.sqrt(2 * LINE_HALF + 1)
    return p, noise, sig, inband


def _clear_of_lines(ctx, state, c, runs, f_hz, own_h):
    """True where frequency ``f_hz`` (len(runs),) lies at least 2·LINE_HALF bins from every line of channel
    ``c`` other than ``own_h`` (and their sidebands): its window measures that line's component alone."""
    ok = np.ones(runs.size, bool)
    for h, _, _ in state.lines(c):
        if abs(h - own_h) < 1e-9:
            continue
        for shift, _ in state.line_components(c, h):
            g = np.abs(h * ctx.omega[runs] / (2 * np.pi) + shift)
            ok &= np.abs(g - np.abs(f_hz)) >= 2 * LINE_HALF * ctx.df
    return ok


# ------------------------------------------------------------------ whole-record helpers (missing_harmonic, broadband_floor)
def hann_transform_ratio(n: int, delta: np.ndarray) -> np.ndarray:
    """W(δ)/W(0) of the periodic Hann window of ``n`` samples at offsets ``delta`` (record bins, any real):
    :func:`rwadist.dft.hann_transform` at f = δ·fs/n (taken with fs = n, so f is δ) over W(0) = Σw = n/2.  A line
    A·e^{2πj f_l t} puts A·W((f − f_l)/df)/W(0) into the whole-run phasor at f (the convention of
    :func:`rwadist.dft.windowed_dft`: Σ x e^{−2πj f t})."""
    from ..dft import hann_transform

    return hann_transform(n, float(n), np.asarray(delta, dtype=float)) / (0.5 * n)


def state_line_freqs(ctx: Context, state: State, c: str, runs) -> np.ndarray:
    """(len(runs), L) frequencies (Hz, ≥ 0) of every line the state predicts on channel ``c`` (carriers and their
    sidebands)."""
    out = []
    for h, _, _, _ in ctx.channel_lines(state, c, runs):
        for shift, _ in state.line_components(c, h):
            out.append(np.abs(h * ctx.omega[runs] / (2 * np.pi) + shift))
    return np.column_stack(out) if out else np.empty((runs.size, 0))


def record_dfts(ctx: Context, rows, c: str, f_hz: np.ndarray) -> np.ndarray:
    """Whole-run phasors X = 2·Σ w (x − x̄) e^{−2πj f t}/Σ w (len(rows), L) of channel ``c`` of the runs ``rows`` at
    ``f_hz`` (len(rows), L) Hz (the spectra's window): the runs of one record length transformed together
    (:func:`rwadist.dft.windowed_dfts`: each record's sums are those of :func:`rwadist.dft.windowed_dft` of it
    alone, the same numbers)."""
    from ..dft import demeaned_windowed, run_window, windowed_dfts

    out = np.empty(f_hz.shape, dtype=complex)
    groups: dict[tuple[int, float], list[int]] = {}       # rows by (record length, sample rate)
    for i, r in enumerate(rows):
        run = ctx.test.runs[r]
        groups.setdefault((run.n_samples, run.sample_rate), []).append(i)
    for (n, fs), idx in groups.items():
        w, wsum, _ = run_window(ctx.sp.window, n)
        xs = demeaned_windowed([ctx.test.runs[rows[i]].signals[c] for i in idx], w)
        out[idx] = 2.0 * windowed_dfts(xs[:, :, None], fs, f_hz[idx])[:, :, 0] / wsum
    return out
