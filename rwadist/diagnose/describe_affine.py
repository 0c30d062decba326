"""Detector of the open world (issue 33, item 3) on the final model's residual: a line whose frequency moves with the
speed along a straight line that passes neither through 0 Hz nor stays at one frequency, f = f0 + b·|Ω|/2π (an
``affine_line``).

A source at a fixed frequency mixed with a line of the rotor (a product of the two: an amplitude modulation, a
nonlinearity, a drive's switching frequency modulated by the commutation) puts a line at f0 ± b·f_spin while the
carrier itself may stay under the noise; a ratio that falls with speed as b + f0/f_spin reads the same over a speed
range.  Neither the fixed lines, nor the speed lines, nor a fixed line's sidebands (a carrier found in the data) hold
it: each takes a piece (the new-user generator's line at 40 Hz + 0.5·f_spin on Fz and Tz, 1000-10000 rpm: a speed
line h 0.80 over the upper half, two fixed lines at 72.8 and 104.8 Hz over parts of the speeds and a ratio drift
named a cage slipping).  Found as a straight ridge of lit bins (:func:`.describe_lines._lit`, narrow: a line, not a
hump) in the plane of speed and frequency, pooled over the channels: for each slope b on a grid whose step moves the
track :data:`SLOPE_STEP_BINS` Welch bins over the speed range, each run's lit bins shifted by b·f_spin and counted per
offset; a track lit in :data:`~.describe_lines.RIDGE_FRACTION` of the runs where it lies in the band (and
:data:`MIN_RUNS` of them), that moves :data:`MIN_MOVE_BINS` Welch bins over its speeds (else a fixed line) and
departs :data:`MIN_OFFSET_BINS` Welch bins from the best line at a constant ratio through it (else a speed line), at
an offset that is no fixed line of the data (else that line's sideband), standing :data:`MIN_LEVEL_DB` over the
model in its cells (or :data:`MIN_PEAK_DB` at its own peaks).  Its offset and slope are then read on the peaks of its lit runs (a parabola through the top
three bins' log powers, a least-squares line), which lie on it within :data:`MAX_MISFIT_BINS`. The pieces the other
detectors made of it, and the hump it makes of the floor, are its own (:func:`without_pieces`). Steady runs only: a
sweep's slice smears a line over bins by the speed's change within it.
"""
from __future__ import annotations

import numpy as np

from .describe_alias import ALIAS_TELLS, alias_causes, alias_tracks, folded, offset_holds, reads_as_counted
from .describe_alias import MIN_RUNS as ALIAS_MIN_RUNS
from .describe_lines import RIDGE_FRACTION, _lit, log_parabola_offset, sliced
from .unexplained import Unexplained

#: The slope grid's step moves a track this many Welch bins over the runs' speed range.
SLOPE_STEP_BINS = 0.5
#: Largest |slope| searched (Hz per Hz of spin).
MAX_SLOPE = 4.0
#: Runs the track is lit in, at least.
MIN_RUNS = 8
#: The track moves this many Welch bins over its lit runs' speeds, at least (else a fixed line's).
MIN_MOVE_BINS = 4.0
#: The track departs this many Welch bins, at its worst run, from the best constant-ratio line through it (else a
#: speed line's).
MIN_OFFSET_BINS = 4.0
#: Two tracks closer than this many Welch bins over the whole speed range are one.
SAME_TRACK_BINS = 3.0
#: A channel carries the line when lit in this fraction of its lit runs.
CHANNEL_FRACTION = 0.5
#: An offset within this many Welch bins of a fixed line of the data is that line's sideband.
CARRIER_BINS = 2.0
#: The peaks read in its lit runs lie on the straight line within this RMS (Welch bins): a line's peak is read to a
#: tenth of a bin (the new-user generator's 40 Hz + 0.5·f_spin: 0.01 bin); a chance alignment of lit noise is not
#: a line (the same data's other seed: 1.4 bins, 4.7 dB over the model); a line read on the model lines' skirts too
#: (:data:`~.describe_lines.SKIRT_FACTOR`), where the ratio's peak leans away from the model's line: 0.54 bin (a
#: review's 60 Hz + 1.3·f_spin on Fx and Fy among the E-like wheel's radial lines).
MAX_MISFIT_BINS = 0.6
#: The data over the model in its cells, at least (dB) ...
MIN_LEVEL_DB = 6.0
#: ... or at its own peaks, per channel, in the median run read (dB): the metric's bands of a radial channel hold the
#: model's lines beside it (a review's 60 Hz + 1.3·f_spin on Fx and Fy among the E-like wheel's lines, 3.7 Hz bins:
#: 3.5 dB in its bands, so it was not described and a moving resonance was fitted to the lines it lifted).
MIN_PEAK_DB = 10.0
#: A run's peak is read within this many Welch bins of the counted track (and its lit stretch); one this far off the
#: straight line through the others is another line's (a review's 60 Hz + 1.3·f_spin on Fx and Fy: two runs where
#: it passed under a model line read 9 and 5 Hz off, RMS 0.68 bin, and no line was described).
WINDOW_BINS = 2
OUTLIER_BINS = 1.5
#: ... read again this many times within WINDOW_BINS of the line read (a strong line's lit stretch lets slopes 0.28
#: through where the line's is 0.5: family wheel 1, read 0.549 at 0.56 bin RMS on the first pass)
REREADS = 2
KEPT_FRACTION = 0.75
#: A record of another detector is a piece of the track when it lies within this many Welch bins of it over this
#: fraction of its speeds at least (a line that crosses the track is its own).
PIECE_BINS = 3.0
PIECE_FRACTION = 0.6
#: ... or within twice that reach, reading the track's level within this (dB)
SAME_LEVEL_DB = 1.0
#: Candidate tracks read, at most (a strong line lets dozens of slopes through its lit stretches).
MAX_CANDIDATES = 400


def _segments(lit: np.ndarray) -> np.ndarray:
    """Labels (runs, n_f) of the runs of consecutive lit bins of ``lit`` within each run (0 where unlit), each its own
    label: a strong line lights several bins, through which several slopes pass."""
    from scipy.ndimage import label

    return label(lit, structure=np.array([[0, 0, 0], [1, 1, 1], [0, 0, 0]]))[0]


def _tracks(lit: np.ndarray, spin: np.ndarray, df: float, k_lo: int, k_hi: int) -> tuple:
    """(tracks, segment labels (:func:`_segments`)): the candidate tracks (slope b, offset bin j, runs lit (bool per
    run), fraction lit, lit segment label per run (0 where unlit)) of the pooled lit map ``lit`` (runs, n_f) that move
    :data:`MIN_MOVE_BINS` and depart :data:`MIN_OFFSET_BINS` from every constant ratio over their lit runs, the most
    lit first (at most :data:`MAX_CANDIDATES`).  A strong line's lit stretches are several bins wide and let several
    slopes through: :func:`affine_lines` reads them in turn, and one that reads a line claims its stretches."""
    R, K = lit.shape
    span = float(spin.max() - spin.min())
    seg = _segments(lit)
    if span <= 0:
        return [], seg
    step = SLOPE_STEP_BINS * df / span
    slopes = np.arange(-MAX_SLOPE, MAX_SLOPE + step / 2, step)
    slopes = slopes[np.abs(slopes) * span >= MIN_MOVE_BINS * df]
    r_lit, k_lit = np.nonzero(lit)                                      # the lit cells alone: the map is sparse
    r_lit, k_lit = r_lit[(k_lit >= k_lo) & (k_lit <= k_hi)], k_lit[(k_lit >= k_lo) & (k_lit <= k_hi)]
    pad = int(np.ceil(MAX_SLOPE * spin.max() / df)) + 1                 # offsets j from -pad (a line below b·f_spin)
    size = K + 2 * pad
    cands = []
    for b in slopes:
        shift = np.rint(b * spin / df).astype(int)                     # (R,) bins the track moves in each run
        # runs lit on the track of offset j (j = k - shift, one cell per run), and runs where it lies in the band
        n_hit = np.bincount(k_lit - shift[r_lit] + pad, minlength=size)
        n_in = np.cumsum(np.bincount(k_lo - shift + pad, minlength=size + 1)
                         - np.bincount(k_hi - shift + 1 + pad, minlength=size + 1))[:size]
        frac = np.where(n_in >= MIN_RUNS, n_hit / np.maximum(n_in, 1), 0.0)
        for jj in np.flatnonzero((frac >= RIDGE_FRACTION) & (n_hit >= MIN_RUNS)) - pad:
            k = jj + shift
            inb = (k >= k_lo) & (k <= k_hi)
            hit = lit[np.arange(R), np.clip(k, 0, K - 1)] & inb
            s_hit = spin[hit]
            if np.ptp(b * s_hit) < MIN_MOVE_BINS * df or _offset_from_ratio(jj * df, b, s_hit) < MIN_OFFSET_BINS * df:
                continue
            labels = np.where(hit, seg[np.arange(R), np.clip(k, 0, K - 1)], 0)
            cands.append(((float(frac[jj + pad]), int(n_hit[jj + pad])), float(b), int(jj), hit,
                          float(frac[jj + pad]), labels))
    cands.sort(key=lambda x: (-x[0][0], -x[0][1]))
    return [c[1:] for c in cands[:MAX_CANDIDATES]], seg


def _line_through(spin: np.ndarray, f: np.ndarray, offset: float | None) -> tuple:
    """(slope b, offset f0) of the least-squares line f = f0 + b·f_spin; with ``offset`` given, f0 is it and b alone is
    fitted (a line folded at the sample rate: its offset is known, and fitted free the track's few top runs, read back
    to 0 Hz, carried each peak's error ~8 times into f0)."""
    if offset is None:
        b, f0 = np.polyfit(spin, f, 1)
        return float(b), float(f0)
    return float(np.dot(spin, f - offset) / np.dot(spin, spin)), float(offset)


def _read_track(ctx, ratio: np.ndarray, runs: np.ndarray, windows: list, least: int = MIN_RUNS,
                offset: float | None = None) -> tuple | None:
    """(offset f0 Hz, slope b, RMS misfit Hz, peak dB) of the line in ``windows`` ((first, last) bin in each run of ``runs``):
    each run's peak of ``ratio`` (the data over the model summed over the line's channels, a row per run) there, refined by a parabola through the log
    powers of the top three bins, a least-squares line through them against f_spin (through f0 = ``offset`` when given,
    :func:`_line_through`), twice without the peaks off it by
    :data:`OUTLIER_BINS` (another line's, where the track passes under a model line), at least :data:`KEPT_FRACTION`
    of the runs kept (and ``least``); peak dB: the median over the runs kept of the peak's ``ratio``, dB."""
    df = ctx.df
    f_pk = np.full(runs.size, np.nan)
    r_pk = np.full(runs.size, np.nan)
    for i, (a, z) in enumerate(windows):
        a, z = max(a, 1), min(z, ratio.shape[1] - 2)
        if z < a or not np.all(np.isfinite(ratio[i, a - 1:z + 2])):
            continue
        k = a + int(np.argmax(ratio[i, a:z + 1]))
        f_pk[i] = (k + log_parabola_offset(ratio[i, k - 1:k + 2])) * df
        r_pk[i] = ratio[i, k]
    spin = np.abs(ctx.omega[runs]) / (2 * np.pi)
    ok = np.isfinite(f_pk)
    for _ in range(2):              # a run whose peak is another line's (under a model line, the track is not lit)
        if ok.sum() < least:
            return None
        b, f0 = _line_through(spin[ok], f_pk[ok], offset)
        ok &= np.abs(f_pk - (f0 + b * spin)) <= OUTLIER_BINS * df
    if ok.sum() < max(least, KEPT_FRACTION * runs.size):
        return None
    if offset is not None and not offset_holds(spin[ok], f_pk[ok], offset, df):
        return None
    b, f0 = _line_through(spin[ok], f_pk[ok], offset)
    rms = float(np.sqrt(np.mean((f_pk[ok] - (f0 + b * spin[ok])) ** 2)))
    return float(f0), float(b), rms, float(10 * np.log10(max(float(np.median(r_pk[ok])), 1e-300)))


def _offset_from_ratio(f0: float, b: float, spin: np.ndarray) -> float:
    """Largest distance (Hz) over ``spin`` (Hz) of the track f0 + b·f_spin from the best line h·f_spin through it."""
    f = f0 + b * spin
    h = float(np.dot(f, spin) / np.dot(spin, spin))
    return float(np.max(np.abs(f - h * spin)))


def _sample_rate(ctx) -> float | None:
    """The sample rate (Hz) every run of the context's test shares, or None (no time series, or several rates)."""
    test = getattr(ctx, "test", None)
    rates = {float(test.runs[int(r)].sample_rate) for r in ctx.runs} if test is not None else set()
    return rates.pop() if len(rates) == 1 else None


def affine_lines(ctx, state, shares, carriers=()) -> list:
    """``affine_line`` records of the residual's straight ridges f = f0 + b·f_spin (module docstring); ``shares``
    gives (share, level) of a track's cells (channels, frequency per run, runs), ``carriers`` the fixed lines found
    before the search (:class:`~rwadist.diagnose.fixed_lines.FixedLine`)."""
    runs = ctx.runs
    if runs.size < ALIAS_MIN_RUNS or sliced(ctx):
        return []
    df = float(ctx.df)
    spin = np.abs(ctx.omega[runs]) / (2 * np.pi)
    lits = {c: _lit(ctx, state, c, narrow=True) for c in ctx.channels}
    pooled = np.any(np.stack(list(lits.values())), axis=0)
    out: list[Unexplained] = []
    tracks, seg = _tracks(pooled, spin, df, ctx.k_lo, min(ctx.k_hi, ctx.f.size - 1))
    fs = _sample_rate(ctx)
    if fs is not None:
        # a line above the Nyquist frequency folded at the sample rate: one parameter, counted over fewer runs
        folds = alias_tracks(pooled, seg, spin, df, fs, ctx.k_lo, min(ctx.k_hi, ctx.f.size - 1))
        tracks = sorted([t + (False,) for t in tracks] + folds, key=lambda t: -t[3])
    bins = np.arange(ctx.f.size)
    claimed: set = set()            # the lit stretches of the lines read so far
    ratios: dict = {}               # the data over the model summed over a channel set, per set
    for b_counted, jj, runs_lit, frac, labels, *fold in tracks:
        is_fold = bool(fold and fold[0])
        least, offset = (ALIAS_MIN_RUNS, fs) if is_fold else (MIN_RUNS, None)
        mine = labels[labels > 0].tolist()
        if sum(x in claimed for x in mine) >= 0.5 * len(mine):
            continue                # mostly a line already read (or refused): the same line at another slope
        s = spin[runs_lit]
        k_run = np.clip(np.rint((jj * df + b_counted * s) / df).astype(int), 0, ctx.f.size - 1)
        chans = tuple(c for c in ctx.channels if lits[c][runs_lit][np.arange(s.size), k_run].mean() >= CHANNEL_FRACTION)
        if not chans:
            continue
        rows = np.flatnonzero(runs_lit)
        windows = [(max(int(bins[seg[i] == labels[i]].min()), int(k) - WINDOW_BINS),
                    min(int(bins[seg[i] == labels[i]].max()), int(k) + WINDOW_BINS)) for i, k in zip(rows, k_run)]
        if chans not in ratios:
            ratios[chans] = sum(ctx.data(state, c, runs)[runs] / np.maximum(ctx.predict(state, c, runs), 1e-300)
                                for c in chans)
        got = _read_track(ctx, ratios[chans][rows], runs[runs_lit], windows, least, offset)
        for _ in range(REREADS):        # the counted slope is a grid's, through a stretch: read again on the line read
            if got is None:
                break
            k_fit = np.rint((got[0] + got[1] * s) / df).astype(int)
            got = _read_track(ctx, ratios[chans][rows], runs[runs_lit],
                              [(int(k) - WINDOW_BINS, int(k) + WINDOW_BINS) for k in k_fit], least, offset)
        if got is None:
            continue
        f0, b, rms, peak_db = got
        if is_fold and (not reads_as_counted(f0, b, -float(b_counted), s, fs or 0.0, df) or rms > MAX_MISFIT_BINS * df):
            continue                # a fold counted over few runs read as another line: none of its gates passed
        claimed.update(mine)
        # a fixed line's sideband (its lower side past 0 Hz folds: f0 = -f_c) is the sideband detector's
        if rms > MAX_MISFIT_BINS * df or np.ptp(b * s) < MIN_MOVE_BINS * df or \
                _offset_from_ratio(f0, b, s) < MIN_OFFSET_BINS * df or \
                any(abs(abs(f0) - ln.f_Hz) <= CARRIER_BINS * df for ln in carriers) or \
                any(np.max(np.abs(f0 + b * s - track_of(u, s))) <= SAME_TRACK_BINS * df for u in out):
            continue
        f_run = f0 + b * s
        share, level = shares(chans, f_run, runs[runs_lit])
        peak_db -= 10 * np.log10(len(chans))              # the ratio is summed over the channels
        if not (level >= MIN_LEVEL_DB or peak_db >= MIN_PEAK_DB):
            continue
        rpm = s * 60.0
        out.append(Unexplained(
            signature="affine_line", channels=chans, speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f_run.min()), float(f_run.max())), level_dB=level, share=share, n_runs=int(s.size),
            parameters={"offset_Hz": f0, "slope": b, "misfit_rms_Hz": rms, "lit_fraction": frac,
                        "peak_over_model_dB": float(peak_db),
                        "h_at_lowest_speed": float(f_run[np.argmin(s)] / s.min()),
                        "h_at_highest_speed": float(f_run[np.argmax(s)] / s.max())},
            causes=(alias_causes(f0, b, fs) if fs is not None and folded(f0, b, fs, df) else ()) + _causes(f0, b),
            would_tell=ALIAS_TELLS if folded(f0, b, fs, df) else
            "a record with the wheel still shows a source of its own at the offset frequency; runs at more "
            "speeds, and below and above these, show whether the offset stays fixed (a mixing of two "
            "sources) or the ratio keeps drifting (a slip)"))
    return out


def _causes(f0: float, b: float) -> tuple:
    """What a line at f0 + b·f_spin could be, worded for the signs of f0 and b."""
    sign = "+" if b >= 0 else "−"
    out = [f"a source at {abs(f0):.4g} Hz (a machine of the stand, the electronics, a structural resonance rung "
           f"steadily) mixed with a line of the rotor at {abs(b):.3g} × the speed: f = {f0:.4g} Hz {sign} "
           f"{abs(b):.3g}·f_spin, a product of the two (an amplitude modulation, a nonlinear joint or sensor) whose "
           "carrier stays under the noise"]
    n = round(abs(b))
    if abs(abs(b) - n) <= 0.02 and n >= 1:
        out.append(f"a motor drive's switching frequency ({abs(f0):.4g} Hz) modulated by the commutation at {n} × "
                   f"the speed, its {'upper side' if b > 0 and f0 > 0 else 'lower side (past 0 Hz when f0 < 0)'} "
                   f"(the pole pairs times a harmonic of the electrical frequency make {n})")
    if b > 0:
        trend = "falls" if f0 > 0 else "rises"
        out.append(f"a line whose ratio to the speed {trend} as {b:.3g} + ({f0:.4g} Hz)/f_spin over these speeds (a "
                   f"ratio drifting with the speed: a bearing's slip), which a fixed offset describes here")
    return tuple(out)


def without_pieces(records: list, affine: list, df: float) -> list:
    """``records`` without the pieces the other detectors made of an ``affine_line`` of ``affine``: a ``fixed_line``,
    ``speed_line``, ``partial_line``, ``sideband_line`` or ratio-drift ``line_property`` on a channel of the track that
    lies within :data:`PIECE_BINS` Welch bins of ``df`` Hz of it over :data:`PIECE_FRACTION` of its own speeds (one
    that crosses the track is a line of its own), and a ``broadband_hump`` within the track's frequencies (the
    family's wheel 4 with a line at 432 Hz + 0.5·f_spin on Fz and Tz: a hump of 435-454 Hz there, its kurtosis 1.5,
    a sinusoid's)."""
    def piece_f(u, s):
        p = u.parameters
        if u.signature == "fixed_line" or (u.h is None and u.signature != "sideband_line"):
            return np.full(s.size, u.f_Hz[0])
        if u.signature == "sideband_line" and "carrier_Hz" in p:
            return np.abs(p["carrier_Hz"] + np.asarray(p.get("sides", [1]), float)[:, None] * p["h"] * s[None, :])
        if u.signature == "line_property" and p.get("readings_rpm"):
            return np.interp(s, np.asarray(p["readings_rpm"], float) / 60.0, np.asarray(p["readings_h"], float)) * s
        return u.h * s

    def meets(u, a) -> bool:
        if not set(u.channels) & set(a.channels):
            return False
        if u.signature == "broadband_hump":       # the line's bins, clear of the model's lines, lift the floor there
            return bool(a.f_Hz[0] - 2 * df <= u.f_Hz[0] and u.f_Hz[1] <= a.f_Hz[1] + 2 * df)
        if not (u.signature in ("fixed_line", "speed_line", "partial_line", "sideband_line") or
                (u.signature == "line_property" and u.parameters.get("property") == "ratio_drift")):
            return False
        s = np.linspace(u.speed_rpm[0], u.speed_rpm[1], 64) / 60.0
        gap = np.min(np.abs(np.atleast_2d(piece_f(u, s)) - track_of(a, s)[None, :]), axis=0)
        # a strong line lights a stretch several bins wide: a piece that reads the track's own level (the same bins'
        # content) is its within twice the reach (w3_own_s2: a fixed line at 101.2 Hz over 5385-10000 rpm, 38.0 dB
        # against the track's 38.0, within 3 bins over 59 % of its speeds)
        same = u.level_dB is not None and abs(float(u.level_dB) - float(a.level_dB)) <= SAME_LEVEL_DB
        return bool(np.mean(gap <= PIECE_BINS * df) >= PIECE_FRACTION or
                    (same and np.mean(gap <= 2 * PIECE_BINS * df) >= PIECE_FRACTION))
    return [u for u in records if not any(meets(u, a) for a in affine)]


def track_of(u, spin: np.ndarray) -> np.ndarray:
    """The frequency (Hz) of the ``affine_line`` record ``u`` at the spin frequencies ``spin`` (Hz)."""
    return u.parameters["offset_Hz"] + u.parameters["slope"] * np.asarray(spin, dtype=float)


def with_affine_lines(ctx, state, records: list, affine: list) -> list:
    """``records`` with the ``affine_line`` records of the residual ``affine`` (:func:`affine_lines`) in place of the
    pieces the other detectors made of them (:func:`without_pieces`)."""
    return without_pieces(records, affine, float(ctx.df)) + affine
