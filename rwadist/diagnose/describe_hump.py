"""Detector of the open world (issue 33, item 3) on the final model's residual: a broadband hump above the noise
floor (a ``broadband_hump``), in every run or in some runs only, and whether it is made of impacts.

The model takes the data's noise floor as instrument noise at every speed, read per bin from the data themselves; a
hump in it (a fixture or sensor resonance excited by the surroundings, a pump of the stand, a part rattling) is then
in the model and nowhere on the residual waterfall.  Found on the data's own floor clear of the model's lines
(:func:`clean_floor`): against its smooth course, against its lower course for a hump wider than the running median
sees (:func:`broadband_hump`), and run by run against that floor for a hump in some runs only
(:func:`humps_in_some_runs`); in the records, band-passed to the hump, its kurtosis tells impacts from noise
(:func:`impulsiveness`).
"""
from __future__ import annotations

import numpy as np

from ..units import RAD_S_TO_RPM
from .unexplained import Unexplained

#: A hump stands this far over the floor's smooth course (dB) at its peak, over at least HUMP_MIN_BINS bins
#: (wider than a line's main lobe) and at most a quarter of the band.
HUMP_PEAK_DB = 4.0
HUMP_EDGE_DB = 2.0
HUMP_MIN_BINS = 4
#: The floor's smooth course: a running median over this fraction of the band's bins.
HUMP_BASELINE_FRACTION = 0.125
#: A hump wider than the running median sees (a band wider than an eighth of the band, or a rattle's ringing whose
#: skirts cover the band: the new-user generator's 450 +- 50 Hz and 350 Hz ringing at 2 kHz, 22 and 13 dB over the
#: floor, read 0 dB by the running median) is measured against the floor's lower course: at each bin, the higher of
#: the lowest floor on its left and on its right (a floor that only falls or only rises, a 1/f floor or a filter's
#: roll-off, stands 0 dB over it), after a running median over this fraction of the band that takes out the noise,
#: and must stand HUMP_WIDE_PEAK_DB over it at its peak.
HUMP_WIDE_SMOOTH_FRACTION = 1.0 / 64.0
HUMP_WIDE_PEAK_DB = 6.0
#: ... and peaks: within 3 dB of its peak over at most this fraction of the band (a floor shaped by the chain's
#: high-pass and anti-alias filters is a plateau: a review's 20 Hz high-pass and 1500 Hz low-pass read as a 9-1982 Hz
#: hump of +17 dB over its lower course, a floor rising as f^0.3 under the same low-pass as one of +7.4 dB, 3 dB wide
#: over 44 % of the band; the open-world cases' first-order band-pass of 450-1000 Hz, 29 %).
HUMP_TOP_FRACTION = 1.0 / 3.0
#: A hump in some runs peaks that far from the band's edges (a fraction of the band) at least.
HUMP_EDGE_FRACTION = 1.0 / 32.0


def _peaked(excess_db: np.ndarray, pk: int, k_lo: int, k_hi: int) -> bool:
    """Whether the hump of ``excess_db`` (dB per bin) peaking at ``pk`` stands within 3 dB of its peak over at most
    :data:`HUMP_TOP_FRACTION` of [k_lo, k_hi] (a plateau does not)."""
    top = excess_db >= excess_db[pk] - 3.0
    k0 = k1 = pk
    while k0 - 1 >= k_lo and top[k0 - 1]:
        k0 -= 1
    while k1 + 1 <= k_hi and top[k1 + 1]:
        k1 += 1
    return bool(k1 - k0 + 1 <= HUMP_TOP_FRACTION * (k_hi - k_lo))
#: A bin is clear of the model's lines in a run where their predicted PSD is below this fraction of the floor.
CLEAN_LINE_FRACTION = 0.01
#: Bins (either side of a line's centre) over which :func:`line_skirts` follows a strong line's Welch skirt at most
SKIRT_MAX_BINS = 256


#: |W(½)/W(0)|² of the periodic Hann window: a line's highest Welch bin holds at least this share of its centre's power
HANN_SCALLOP = (2.0 / np.pi / 0.75) ** 2


def _hann_skirt(offset) -> np.ndarray:
    """Upper bound of a line's Welch (periodic Hann) power ``offset`` bins from its HIGHEST bin, relative to that bin:
    the centre lies within half a bin of it (δ ≥ |offset| − ½ from the centre) and the bin holds at least
    :data:`HANN_SCALLOP` of the centre's power, while |W(δ)/W(0)|² = (sin πδ / (πδ(1 − δ²)))² ≤ 1/(πδ(δ² − 1))²
    (δ > 1; 1 nearer)."""
    d = np.abs(np.asarray(offset, dtype=float)) - 0.5
    with np.errstate(divide="ignore"):
        return np.where(d > 1.5, 1.0 / (np.pi * d * (d * d - 1.0)) ** 2 / HANN_SCALLOP, 1.0)


def line_skirts(ctx, state, c: str, runs) -> np.ndarray:
    """Bins (len(runs), n_f) of channel ``c`` where a line of the model stands over :data:`CLEAN_LINE_FRACTION` of
    the floor on its Welch skirt beyond the ±KERNEL_HALF bins the model carries it (:func:`_hann_skirt`, from the
    line's highest predicted bin over the floor).  A line 60 dB or
    more over the floor (one passing a lightly damped mode) still stands over it there, and read as the floor of its
    runs its skirt was a hump (the new-user generator's 3 kg wheel, clean: its h 3.63 line on the 580 Hz axial mode,
    95 dB over the floor at 9600 rpm, +13 dB 16 bins off its centre, described as a 430-551 Hz hump in 4 runs)."""
    from .constants import KERNEL_HALF

    runs = np.asarray(runs)
    key = ("line_skirts", c, runs.tobytes())     # kept read-only on the state, as its prediction: three readers
    cache = getattr(state, "_cache", None)
    if cache is not None and key in cache:
        return cache[key]
    M, N = ctx.predict(state, c, runs), ctx.floor_psd(state, c, runs)
    out = np.zeros(M.shape, dtype=bool)
    E = M - N
    # the lines strong enough for their skirt to reach past the kernel: local peaks of the lines' PSD over the floor,
    # against the run's median floor (the floor read beside a strong line holds some of its skirt)
    floor = np.median(N, axis=1, keepdims=True)
    strong = E[:, 1:-1] > floor * CLEAN_LINE_FRACTION / _hann_skirt(KERNEL_HALF)
    strong &= (E[:, 1:-1] >= E[:, :-2]) & (E[:, 1:-1] >= E[:, 2:])
    offsets = np.arange(-SKIRT_MAX_BINS, SKIRT_MAX_BINS + 1)
    skirt = _hann_skirt(offsets)
    n_f = M.shape[1]
    for r, k in zip(*np.nonzero(strong)):
        k += 1
        ks = k + offsets
        ok = (ks >= 0) & (ks < n_f)
        out[r, ks[ok]] |= E[r, k] * skirt[ok] > CLEAN_LINE_FRACTION * N[r, ks[ok]]
    out.flags.writeable = False
    if cache is not None:
        cache[key] = out
    return out


def _running_median(x: np.ndarray, half: int) -> np.ndarray:
    """Running median of ``x`` (1-D) over ±``half`` points (the end points repeated)."""
    from ..spectra import running_median

    return running_median(x, 2 * half + 1, mode="nearest")


def _over(top_db: np.ndarray, base_db: np.ndarray, beside=None) -> np.ndarray:
    """``top_db`` over ``base_db`` (dB per bin); with ``beside`` (a floor the model holds already, per bin, in the
    same unit as the dB's power), both with it added: a residual floor's hump counted against all the floor there."""
    if beside is None:
        return top_db - base_db
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):    # -inf (no floor) stays -inf
        return 10 * np.log10((10 ** (top_db / 10) + beside) / (10 ** (base_db / 10) + beside))


def _lower_course(lf: np.ndarray, k_lo: int, k_hi: int, beside=None) -> np.ndarray:
    """The floor ``lf`` (dB per bin) over its lower course (``lf`` smoothed by a running median over
    :data:`HUMP_WIDE_SMOOTH_FRACTION` of the band: at each bin of [k_lo, k_hi] the higher of the lowest value on its
    left and the lowest on its right, so only what rises and falls again stands over it), dB; ``beside``: as
    :func:`_over`."""
    half = max(int(HUMP_WIDE_SMOOTH_FRACTION * (k_hi - k_lo) / 2), HUMP_MIN_BINS)
    smooth = _running_median(lf, half)
    course = np.full(lf.size, np.inf)
    course[k_lo:k_hi + 1] = _course(smooth[k_lo:k_hi + 1])
    return _over(smooth, course, beside)


def _course(x: np.ndarray) -> np.ndarray:
    """Along the last axis of ``x``, the higher of the lowest value on the left and the lowest on the right."""
    return np.maximum(np.minimum.accumulate(x, axis=-1), np.flip(np.minimum.accumulate(np.flip(x, -1), axis=-1), -1))


def _humps(excess_db: np.ndarray, k_lo: int, k_hi: int, max_width: int | None = None,
           peak_db: float = HUMP_PEAK_DB) -> list:
    """(k0, k1, peak bin) of every run of bins in [k_lo, k_hi] standing HUMP_EDGE_DB over the course and
    ``peak_db`` at its peak, HUMP_MIN_BINS to ``max_width`` (a quarter of the band) wide."""
    max_width = (k_hi - k_lo) // 4 if max_width is None else max_width
    above = excess_db >= HUMP_EDGE_DB
    above[:k_lo] = False
    above[k_hi + 1:] = False
    out = []
    k = k_lo
    while k <= k_hi:
        if not above[k]:
            k += 1
            continue
        k1 = k
        while k1 + 1 <= k_hi and above[k1 + 1]:
            k1 += 1
        width = k1 - k + 1
        if HUMP_MIN_BINS <= width <= max_width:
            pk = k + int(np.argmax(excess_db[k:k1 + 1]))
            if excess_db[pk] >= peak_db:
                out.append((k, k1, pk))
        k = k1 + 1
    return out


def clean_floor(ctx, state, c: str, less_class_floor: bool = False) -> np.ndarray:
    """The data's own noise floor of channel ``c`` per bin (n_f,): the median over the runs of the data's PSD at the
    bins where the model's lines stand below :data:`CLEAN_LINE_FRACTION` of its floor in that run (the noise alone,
    clear of every line's leakage and of a misfit of it), NaN where fewer than a quarter of the runs (and 3) are.
    ``less_class_floor``: each run's PSD less the ``broadband_floor`` class's floor at that run's speed first (the
    floor the class explains; taken off run by run, as the runs clear of lines differ from bin to bin: the class's
    floor at one speed taken off the median of other runs leaves humps where those runs are faster or slower)."""
    from .reduce import column_nanmedian

    runs = ctx.runs
    ok = np.isfinite(ctx.sp.psd[c][runs, 0])
    runs = runs[ok]
    D = ctx.data(state, c, runs)[runs]
    N = ctx.floor_psd(state, c, runs)
    clean = ((ctx.predict(state, c, runs) - N) < CLEAN_LINE_FRACTION * N) & ~line_skirts(ctx, state, c, runs)
    if less_class_floor:
        D = D - (N - np.asarray(state.noise[c]))
    count = clean.sum(0)
    med = column_nanmedian(np.where(clean, D, np.nan))
    return np.where(count >= max(3, runs.size // 4), med, np.nan)


def _class_floor(ctx, state, c: str):
    """The ``broadband_floor`` class's floor of channel ``c`` (per bin, the median over the runs of its value at each
    run's speed), or None when the class holds none there.  What stands over the residual floor's course stands over
    all the floor only when it stands over this as well: where the class's floor rises 40 dB over the instrument's
    (nuI c6, a 400 Hz hump growing as Ω² named a floor), a 1 % misfit of its shape is a 20 dB hump of the residual."""
    if c not in state.floors:
        return None
    ref, w_ref, p = state.floors[c]
    return ref * float(np.median((np.abs(ctx.omega[ctx.runs]) / w_ref) ** p))


def broadband_hump(ctx, state, shares) -> list:
    """A broadband hump: the data's own noise floor (:func:`clean_floor`, 3-bin means of its dB) standing over its
    smooth course (a running median over an eighth of the band) by :data:`HUMP_PEAK_DB` at its peak, over a
    frequency range wider than a line and narrower than a quarter of the band, or over its lower course
    (:func:`_lower_course`) by :data:`HUMP_WIDE_PEAK_DB` and peaked (:func:`_peaked`), in one channel or several (one
    record, the channels listed).  The model takes such a hump as instrument noise (at every speed) or, growing with
    speed as a power law, as the ``broadband_floor`` class (whose floor is not counted here: it is the data's
    floor less the class's).  What it could be: a fixture or sensor resonance excited by the surroundings, a pump
    or fan of the stand, the electronics' own noise shape."""
    k_lo, k_hi = ctx.k_lo, min(ctx.k_hi, ctx.f.size - 1)
    found: dict[int, list[tuple]] = {}      # peak bin -> (channel, k0, k1, peak, excess dB, against what)
    half = max(int(HUMP_BASELINE_FRACTION * (k_hi - k_lo) / 2), 3 * HUMP_MIN_BINS)
    floors = {}
    for c in ctx.channels:
        fl = clean_floor(ctx, state, c, less_class_floor=True)  # a floor the broadband_floor class holds is explained
        valid = np.isfinite(fl) & (fl > 0)
        if valid[k_lo:k_hi + 1].sum() < 4 * HUMP_MIN_BINS:
            continue
        k = np.arange(fl.size)
        lf = np.interp(k, k[valid], 10 * np.log10(fl[valid]))
        lf = np.convolve(lf, np.ones(3) / 3.0, mode="same")
        held = _class_floor(ctx, state, c)
        excess = np.where(valid, _over(lf, _running_median(lf, half), held), -np.inf)
        wide = np.where(valid, _lower_course(lf, k_lo, k_hi, held), -np.inf)
        floors[c] = (fl, lf if held is None else 10 * np.log10(10 ** (lf / 10) + held))
        narrow = _humps(excess, k_lo, k_hi)
        # a wide hump peaks: a floor shaped by the chain's high-pass and anti-alias filters is a plateau
        broad = [(k0, k1, pk) for k0, k1, pk in _humps(wide, k_lo, k_hi, k_hi - k_lo, HUMP_WIDE_PEAK_DB)
                 if not any(a <= pk <= b for a, b, _ in narrow) and _peaked(wide, pk, k_lo, k_hi)]
        for (k0, k1, pk), ex, how in [(h, excess, "smooth") for h in narrow] + [(h, wide, "lower") for h in broad]:
            key = next((x for x, v in found.items() if abs(x - pk) <= max(3, min(k1 - k0, v[0][2] - v[0][1]) // 2)),
                       pk)
            found.setdefault(key, []).append((c, k0, k1, pk, float(ex[pk]), how))
    out = []
    for items in found.values():
        chans = tuple(x[0] for x in items)
        k0, k1 = min(x[1] for x in items), max(x[2] for x in items)
        peak = max(items, key=lambda x: x[4])
        f0, f1, fp = ctx.f[k0], ctx.f[k1], ctx.f[peak[3]]
        if _at_a_fitted_resonance(ctx, state, fp, chans):
            continue
        width = float(_half_power_width(ctx, floors[peak[0]][1], peak[3]))     # of all the floor, the class's too
        kurt = impulsiveness(ctx, state, chans, ctx.runs, fp, 0.5 * width)
        if kurt is not None and kurt < LINE_KURTOSIS:
            continue                # a line stands in it (a sinusoid's kurtosis is 1.5): the line detectors' to say
        share, level = shares(chans, f0, f1)
        rpm = ctx.omega[ctx.runs] * RAD_S_TO_RPM
        growth = speed_growth(ctx, state, chans, k0, k1)
        out.append(Unexplained(
            signature="broadband_hump", channels=chans, speed_rpm=(float(rpm.min()), float(rpm.max())),
            f_Hz=(float(f0), float(f1)), level_dB=peak[4], share=share, n_runs=int(ctx.runs.size),
            parameters={"peak_Hz": float(fp), "peak_over_floor_dB": peak[4], "over_the_model_dB": level,
                        "half_power_width_Hz": width, "in_every_run": True, "kurtosis": kurt,
                        "measured_against": "smooth course" if peak[5] == "smooth" else "lower course",
                        "speed_exponent": growth[0] if growth else None,
                        "growth_over_speeds_dB": growth[1] if growth else None},
            causes=_growing_causes(growth, kurt, fp) if growth else _hump_causes(kurt, fp, "at every speed"),
            would_tell=_GROWING_TELLS if growth else _HUMP_TELLS))
    return out


#: A hump in every run whose band's power grows with the speed by this much (dB, its power law over the speed range)
#: is the wheel's (:func:`speed_growth`), not the surroundings'
HUMP_GROWTH_DB = 10.0


def speed_growth(ctx, state, chans, k0: int, k1: int) -> tuple | None:
    """(exponent p, growth dB) of the power in bins [k0, k1] of ``chans`` over the speeds, PSD ∝ |Ω|^p (each run's
    median dB over the band bins less the model's lines, the channels' mean; p by least squares on log |Ω| over the
    runs 6 dB or more over the lowest, where the floor does not hold the band), when it grows with the speed by
    :data:`HUMP_GROWTH_DB` or more from its lowest run to its highest; else None.  The new-user trial's hump at
    120 Hz growing as Ω⁶ (+60 dB over 600-6000 rpm) was described as the surroundings' "at every speed"."""
    from .reduce import column_nanmedian

    runs = ctx.runs
    omega = np.abs(ctx.omega[runs])
    if runs.size < 4 or omega.min() <= 0 or omega.max() / omega.min() < 1.5:
        return None
    per_channel = []
    for c in chans:
        D = ctx.data(state, c, runs)[runs][:, k0:k1 + 1]
        N = ctx.floor_psd(state, c, runs)[:, k0:k1 + 1]
        clear = (ctx.predict(state, c, runs)[:, k0:k1 + 1] - N) < CLEAN_LINE_FRACTION * N
        with np.errstate(divide="ignore", invalid="ignore"):
            db = np.where(clear & (D > 0), 10 * np.log10(D), np.nan)
        per_channel.append(column_nanmedian(db.T))
    y = _mean_of_finite(np.stack(per_channel))
    ok = np.isfinite(y)
    if ok.sum() < 4:
        return None
    x, y = np.log10(omega[ok]), y[ok]
    growth = float(np.max(y) - np.min(y))
    if growth < HUMP_GROWTH_DB or np.corrcoef(x, y)[0, 1] <= 0:
        return None
    # the law read where the hump stands over the slowest runs' band (there the floor holds it): 6 dB or more
    over = y >= np.min(y) + 6.0
    if over.sum() < 3 or np.ptp(x[over]) <= 0:
        return None
    slope = float(np.polyfit(x[over], y[over], 1)[0])          # dB per decade of speed
    return (slope / 10.0, growth) if slope > 0 else None


def _growing_causes(growth: tuple, kurt: float | None, f_peak: float) -> tuple:
    """What a hump in every run growing with the speed could be (``growth``: :func:`speed_growth`'s)."""
    p, db = growth
    first = (f"a resonance at {f_peak:.4g} Hz of the wheel's structure, the fixture or the load cell rung by the "
             f"wheel's own broadband loads (bearing noise, a rub, a motor's commutation): its power grows with the speed "
             f"as |Ω|^{p:.2g} ({db:+.0f} dB over the speeds), which the surroundings do not")
    if kurt is not None and kurt >= IMPULSIVE_KURTOSIS:
        return (f"impacts ringing a resonance at {f_peak:.4g} Hz (kurtosis {kurt:.1f} in its band, 3 for noise), "
                f"struck harder as the wheel runs faster ({db:+.0f} dB over the speeds): a loose part or a bearing's "
                "defect",) + (first,)
    return (first,)


_GROWING_TELLS = ("a run with the wheel coasting down (its loads fall with the speed and the hump with them), and a tap "
                  "test of the wheel, fixture and load cell at rest to place the resonance; the broadband_floor class "
                  "models a floor growing with the speed (diagnose names it where it gains on the held-out runs)")


_HUMP_TELLS = ("a record with the wheel still (stand running, then stopped) shows a hump of the stand or its "
               "surroundings; one in the electronics stays with the cell unloaded; a tap test of the fixture finds a "
               "resonance there; a loose part rattles on a shaker or by hand")
#: The records band-passed to a hump (its half-power width about its peak, the model's lines' bins left out) have
#: kurtosis 3 when it is noise; above this, impacts ringing a resonance: a rattle (the open-world cases' 20 impacts a
#: second ringing at 700 Hz, ζ 0.05: kurtosis 8-9).  A kurtosis is read on at most IMPULSE_RUNS runs.
IMPULSIVE_KURTOSIS = 4.5
IMPULSE_RUNS = 12
#: ... and below this a line stands in it (a sinusoid's kurtosis is 1.5; noise's 3): not a hump but a line the model
#: lacks, which the line detectors describe (a review's 215 Hz tone in the top four runs read as a hump, 1.506).
LINE_KURTOSIS = 2.0


def impulsiveness(ctx, state, chans, runs, f_peak: float, width: float) -> float | None:
    """The median over ``chans`` and up to :data:`IMPULSE_RUNS` of ``runs`` of the kurtosis E[y⁴]/E[y²]² of the
    records band-passed to ``f_peak`` ± ``width`` (Hz) by their whole-record FFT (a 10 % Tukey taper first, the
    moments over the middle 80 %: the record's ends wrapped onto each other are a step), the bins where a model line
    stands in the Welch bin (its prediction over the floor by :data:`CLEAN_LINE_FRACTION` of it) left out: 3 for
    Gaussian noise, more for impacts, 1.5 for a sinusoid; None without the records."""
    from scipy.signal.windows import tukey

    test = getattr(ctx, "test", None)
    if test is None or width <= 0:
        return None
    runs = np.asarray(runs)[np.linspace(0, len(runs) - 1, min(len(runs), IMPULSE_RUNS)).astype(int)]
    pos = {int(r): i for i, r in enumerate(ctx.runs)}
    out = []
    for c in chans:
        M, N = ctx.predict(state, c, ctx.runs), ctx.floor_psd(state, c, ctx.runs)
        for r in runs:
            run = test.runs[int(r)]
            if c not in run.signals:
                continue
            x = np.asarray(run.signals[c], dtype=float)
            x = (x - x.mean()) * tukey(x.size, 0.1)
            f = np.fft.rfftfreq(x.size, 1.0 / run.sample_rate)
            k = np.clip(np.rint(f / ctx.df).astype(int), 0, ctx.f.size - 1)
            lines = M[pos[int(r)], k] - N[pos[int(r)], k] > CLEAN_LINE_FRACTION * N[pos[int(r)], k]
            keep = (np.abs(f - f_peak) <= width) & ~lines
            if keep.sum() < 8:
                continue
            y = np.fft.irfft(np.where(keep, np.fft.rfft(x), 0.0), n=x.size)
            y = y[x.size // 10: x.size - x.size // 10]      # clear of the taper and the filter's wrap-around
            m2 = float(np.mean(y * y))
            if m2 > 0:
                out.append(float(np.mean(y ** 4)) / m2 ** 2)
    return float(np.median(out)) if out else None


def _hump_causes(kurt: float | None, f_peak: float, when: str) -> tuple:
    """What a hump could be: impacts ringing a resonance first when its kurtosis says so."""
    noise = (f"a resonance of the fixture or the load cell excited by the surroundings (the floor, pumps, air) {when}",
             "a pump, fan or compressor of the stand (broadband, at one frequency whatever the wheel does)",
             "the shape of the sensor or amplifier noise (a filter's peaking)")
    if kurt is not None and kurt >= IMPULSIVE_KURTOSIS:
        return (f"impacts ringing a resonance at {f_peak:.4g} Hz (kurtosis {kurt:.1f} in its band, 3 for noise): a "
                "loose part, fastener or cable rattling, or a bearing's defect struck by its balls",) + noise[:1]
    return noise


#: A hump in some runs only: a run's floor over the runs' (:func:`_run_excess`), each run's dB first the running median over RUN_HUMP_SMOOTH_FRACTION of
#: the band (at least RUN_HUMP_MIN_SMOOTH bins: a Welch bin's dB scatters by 1-2 dB, a line's lobe spans 4 bins)
#: with the bins where a line stands out of its neighbours left out, by this much (dB) at its peak in at least
#: RUN_HUMP_RUNS runs whose peaks lie within RUN_HUMP_PEAKS_FRACTION of the band of the first's (the run whose peak
#: has most others near it), and in at most RUN_HUMP_MAX_FRACTION of the runs (in more, the floor of the runs holds
#: it: :func:`broadband_hump`); it spans the bins around that peak where those runs' mean excess stands
#: RUN_HUMP_EDGE_DB, and it peaks (:func:`_peaked`: a floor growing with speed lifts the whole band of the fast
#: runs).  A rattle in every third run (the new-user generator's 700 Hz impacts at 4 kHz) lifts its runs'
#: floor 10-20 dB at its ringing and by 2-6 dB over most of the band (its skirts).
RUN_HUMP_PEAK_DB = 6.0
RUN_HUMP_EDGE_DB = 2.0
RUN_HUMP_SMOOTH_FRACTION = 1.0 / 64.0
RUN_HUMP_MIN_SMOOTH = 9
RUN_HUMP_RUNS = 2
RUN_HUMP_MAX_FRACTION = 0.6
RUN_HUMP_PEAKS_FRACTION = 1.0 / 16.0


def _run_excess(ctx, state, c: str, width: int) -> np.ndarray:
    """Each run's data over the runs' floor (:func:`clean_floor`, scaled as the model's floor changes from run to
    run), dB (runs, n_f), a running median over ``width`` bins of the bins clear of the model's lines and of any line
    standing out of its neighbours (:func:`~.describe_lines._lit`, narrow); NaN where fewer than half of a window's
    bins are."""
    from scipy.ndimage import uniform_filter1d

    from ..spectra import running_median
    from .describe_lines import _lit

    runs = ctx.runs
    D = ctx.data(state, c, runs)[runs]
    N = ctx.floor_psd(state, c, runs)
    clean = ((ctx.predict(state, c, runs) - N) < CLEAN_LINE_FRACTION * N) & ~_lit(ctx, state, c, narrow=True) \
        & ~line_skirts(ctx, state, c, runs)
    # the runs' floor, the median over them (a hump in a third of them does not lift it; the model's noise, a mean,
    # is lifted by a third of its height: family wheel 0's rattle read +4.8 dB for +15), as the model's floor
    # changes from run to run (a broadband_floor class's, growing with speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        ref = clean_floor(ctx, state, c)[None, :] * N / np.median(N, axis=0)[None, :]
        x = np.where(clean & (D > 0) & (ref > 0), 10 * np.log10(D / ref), np.nan)
    ok = np.isfinite(x)
    k = np.arange(x.shape[1])
    filled = np.zeros_like(x)
    for i in range(x.shape[0]):                      # a row at a time: the gaps bridged for the median filter
        if ok[i].sum() >= 2:
            filled[i] = np.interp(k, k[ok[i]], x[i, ok[i]])
    med = running_median(filled, width, mode="nearest")
    share = uniform_filter1d(ok.astype(float), width, axis=1, mode="nearest")
    return np.where(share >= 0.5, med, np.nan)


def _over_lower_course(excess: np.ndarray, k_lo: int, k_hi: int) -> np.ndarray:
    """Each row of ``excess`` (runs, n_f; dB, NaN unknown) over its lower course in [k_lo, k_hi] (the higher of the
    lowest value on either side, :func:`_lower_course`'s): what rises and falls again, not a run's floor rising into
    the band's edge (a review's anti-alias roll-off to -100 dB, where a rattle's skirt stood 90 dB over the runs'
    floor and hid its 15 dB peak at 700 Hz)."""
    band = np.where(np.isfinite(excess[:, k_lo:k_hi + 1]), excess[:, k_lo:k_hi + 1], np.inf)
    course = _course(band)
    out = np.full(excess.shape, np.nan)
    with np.errstate(invalid="ignore"):
        out[:, k_lo:k_hi + 1] = np.where(np.isfinite(band) & np.isfinite(course), band - course, np.nan)
    return out


def _mean_of_finite(x: np.ndarray) -> np.ndarray:
    """Column means of the finite entries of ``x`` (rows, n), NaN where a column has none."""
    ok = np.isfinite(x)
    n = ok.sum(0)
    return np.where(n > 0, np.where(ok, x, 0.0).sum(0) / np.maximum(n, 1), np.nan)


def _run_groups(peak_bin: np.ndarray, hot: np.ndarray, near: float) -> list:
    """The hot runs (``hot``: rows) in groups whose peaks (``peak_bin``) lie within ``near`` bins of the group's
    first: each time the run with most other hot runs near it, and those runs."""
    left, out = hot.copy(), []
    while left.size:
        close = np.abs(peak_bin[left][:, None] - peak_bin[left][None, :]) <= near
        first = int(np.argmax(close.sum(1)))
        out.append(left[close[first]])
        left = left[~close[first]]
    return out


def humps_in_some_runs(ctx, state, shares, every=()) -> list:
    """``broadband_hump`` records of a hump in some runs only (:data:`RUN_HUMP_PEAK_DB`): the runs whose floor
    stands over the model's floor at one frequency in one channel or several, one record with the channels where their
    mean excess does, none where a hump of ``every`` (the humps in every run) peaks, at a suspension mode's whirl in
    those runs or a fixed resonance (:func:`~.describe_fixed._at_a_mode`), or where a line stands (its kurtosis under
    :data:`LINE_KURTOSIS`).  ``shares(chans, f0, f1, runs)``: (share, level) of the cells of the band
    in those runs (indices of the test)."""
    from .describe_fixed import _at_a_mode
    from .describe_lines import sliced

    k_lo, k_hi = ctx.k_lo, min(ctx.k_hi, ctx.f.size - 1)
    R = ctx.runs.size
    # steady runs only: a sweep's slices smear its lines over bins by the speed's change within each, and the fast
    # slices' smeared skirts read as humps (family wheel 5's 1000-10000 rpm sweeps: +6-7 dB at 512 Hz in 2-5 slices)
    if R < 2 * RUN_HUMP_RUNS or k_hi - k_lo < 64 or sliced(ctx):
        return []
    width = max(RUN_HUMP_MIN_SMOOTH, int(RUN_HUMP_SMOOTH_FRACTION * (k_hi - k_lo)))
    margin = max(width, int(HUMP_EDGE_FRACTION * (k_hi - k_lo)))
    ex = {c: _over_lower_course(_run_excess(ctx, state, c, width), k_lo, k_hi) for c in ctx.channels}
    band = np.zeros(ctx.f.size, bool)
    band[k_lo + margin:k_hi - margin + 1] = True     # a run's peak away from the edges, where the floor may fall away
    pooled = np.max(np.stack([np.where(np.isfinite(e) & band, e, -np.inf) for e in ex.values()]), axis=0)
    peak_bin, peak_db = np.argmax(pooled, axis=1), np.max(pooled, axis=1)
    hot = np.flatnonzero(peak_db >= RUN_HUMP_PEAK_DB)
    out: list[Unexplained] = []
    for rows in _run_groups(peak_bin, hot, max(RUN_HUMP_PEAKS_FRACTION * (k_hi - k_lo), width)):
        if not RUN_HUMP_RUNS <= rows.size <= RUN_HUMP_MAX_FRACTION * R:
            continue
        pk = int(np.rint(np.median(peak_bin[rows])))
        mean = {c: _mean_of_finite(e[rows]) for c, e in ex.items()}
        # a channel carries it where its runs' mean stands half the peak's level near it (a line of the model
        # over part of the hump leaves fewer of its bins to read)
        chans = tuple(c for c in ctx.channels if np.nanmax(mean[c][max(pk - 2 * width, 0):pk + 2 * width + 1],
                                                           initial=-np.inf) >= 0.5 * RUN_HUMP_PEAK_DB)
        if not chans:
            continue
        m = np.max(np.stack([np.where(np.isfinite(mean[c]), mean[c], -np.inf) for c in chans]), axis=0)
        k0 = k1 = pk
        while k0 - 1 >= k_lo and m[k0 - 1] >= RUN_HUMP_EDGE_DB:
            k0 -= 1
        while k1 + 1 <= k_hi and m[k1 + 1] >= RUN_HUMP_EDGE_DB:
            k1 += 1
        a, z = max(k0, k_lo + margin), min(k1, k_hi - margin)
        top_k = a + int(np.argmax(m[a:z + 1])) if z >= a else pk
        # a floor growing with speed lifts the fast runs' band (no peak); one rising on into the band's edge is the
        # runs' floor falling away there (an anti-alias filter's roll-off: 1830-1920 Hz, +8 dB in two runs): the
        # peak stands 3 dB over the excess 4 smoothing widths either side, inside the band
        sides = [top_k - 4 * width, top_k + 4 * width]
        if not _peaked(m, top_k, k_lo, k_hi) or not all(k_lo <= k <= k_hi for k in sides) or \
                m[top_k] - max(m[sides[0]], m[sides[1]]) < 3.0:
            continue
        f0, f1 = float(ctx.f[k0]), float(ctx.f[k1])
        fp = float(ctx.f[top_k])
        runs = ctx.runs[rows]
        # a suspension mode's whirl rung by broadband loads in those runs is the wheel's own
        if any(u.f_Hz[0] <= fp <= u.f_Hz[1] for u in every) or _at_a_mode(ctx, state, fp, runs, chans):
            continue
        kurt = impulsiveness(ctx, state, chans, runs, fp, max(min(fp - f0, f1 - fp), 4 * ctx.df))
        if kurt is not None and kurt < LINE_KURTOSIS:
            continue
        share, level = shares(chans, f0, f1, runs)
        rpm = np.sort(ctx.omega[runs] * RAD_S_TO_RPM)
        top = float(m[top_k])
        out.append(Unexplained(
            signature="broadband_hump", channels=chans, speed_rpm=(float(rpm[0]), float(rpm[-1])),
            f_Hz=(f0, f1), level_dB=top, share=share, n_runs=int(rows.size),
            parameters={"peak_Hz": fp, "peak_over_floor_dB": top, "over_the_model_dB": level,
                        "half_power_width_Hz": None, "in_every_run": False, "run_speeds_rpm": rpm.tolist(),
                        "kurtosis": kurt, "measured_against": "some runs"},
            causes=_hump_causes(kurt, fp, f"in {rows.size} of the {R} runs only"),
            would_tell=_HUMP_TELLS + "; the runs' order in time shows whether it comes and goes"))
    return out

#: A hump peaking within this many half-power half-widths (ζ·f_r) of a fitted fixed resonance (plus a band's width)
#: is that resonance: a fixture's resonance lifts the noise passing through the stand as it lifts the lines.
RESONANCE_HALF_WIDTHS = 3.0


#: The largest damping ratio of a suspension mode's window in :func:`_at_a_fitted_resonance` (three half widths)
MODE_ZETA_MAX = 0.05


def _at_a_fitted_resonance(ctx, state, f_peak: float, chans) -> bool:
    """True when a fixed resonance of ``state`` (the ``fixed_resonance`` class: a test stand's or a wheel mode's), or
    a suspension mode of its extended base whose frequency does not move with the speed (the axial mode on Fz, the
    radial translation on the radial forces) where a ``broadband_floor`` class holds the channel, on one of ``chans``
    peaks within :data:`RESONANCE_HALF_WIDTHS` ζ·f_r (and a band; a mode's ζ at most :data:`MODE_ZETA_MAX`, and a bin)
    of ``f_peak``: the hump is the noise through that resonance, which a class names (family wheel 6's floor through
    its 85 Hz axial mode of ζ 0.011, narrower than the floor class's knots, was a hump of what it left)."""
    from .constants import BAND_BINS

    # (f_r, ζ, channels, slack): a class's resonance within a band; a suspension mode within a bin (its frequency
    # is fitted on the lines: a hump of the floor a band off it is not its)
    found = [(f_r, zeta, on, BAND_BINS * ctx.df) for f_r, zeta, _, on, *_ in state.resonances]
    if state.ext is not None:
        # only where a floor class holds the channel (its knots may cut a narrow mode's peak; without one, the noise
        # through the mode is no class's, and a hump there is described), a lightly damped mode's own width
        e = state.ext
        found += [(f, min(zeta, MODE_ZETA_MAX), tuple(c for c in on if c in state.floors), ctx.df)
                  for f, zeta, on in ((e.omega_z / (2 * np.pi), e.zeta_z, ("Fz",)),
                                      (e.omega_r / (2 * np.pi), e.zeta_r, ("Fx", "Fy")))]
    return any(set(on) & set(chans) and abs(f_peak - f_r) <= RESONANCE_HALF_WIDTHS * zeta * f_r + slack
               for f_r, zeta, on, slack in found)


def _half_power_width(ctx, log_floor: np.ndarray, pk: int) -> float:
    """Width (Hz) over which a floor (dB per bin) stays within 3 dB of its value at bin ``pk``."""
    k0 = k1 = pk
    while k0 > 0 and log_floor[k0 - 1] >= log_floor[pk] - 3.0:
        k0 -= 1
    while k1 + 1 < log_floor.size and log_floor[k1 + 1] >= log_floor[pk] - 3.0:
        k1 += 1
    return (k1 - k0 + 1) * ctx.df
