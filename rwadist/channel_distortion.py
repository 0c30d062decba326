"""A radial channel whose signal chain is not linear (an amplifier distorting), read from the lines it makes alone.

A load cell's radial pair (Fx, Fy) or (Tx, Ty) sees one load: every line of a rotor turns, and what turns is in both
channels (equal power for a line of one sense; an elliptical suspension shifts the balance by a few dB, never to
nothing).  A channel whose amplifier, cable or converter is not linear, y = x + b₂x² + b₃x³ + ..., holds lines at
the sums and differences of its own lines (second order: f_i ± f_j and 2f_i; third order: f_i ± f_j ± f_k, 3f_i),
which its partner does not hold: they are made in that channel's electronics, after the load was split into x and y.
Undeclared, such a channel broke the diagnosis of the family wheels (a 2 % second- and third-order distortion on Fx
of family wheel 2: the suspension modes not fitted, amplitude laws invented on three directions, the error 112x the
clean level), as an outside trial's amplifier distortion had ("nothing" named, 37-48x).

So before the search, per run and per channel of each radial pair:

1. the lines: local maxima of the Hann-windowed power spectrum standing :data:`LINE_SNR` over the local noise (the
   medians of blocks of :data:`NOISE_BINS` bins, :func:`_local_noise`);
2. a line is the channel's *alone* when its partner shows nothing within ±2 bins (below :data:`PARTNER_QUIET` times
   its own local noise); the others are *shared*, the load's;
3. the products: every sum and difference of second and third order of the :data:`TOP_LINES` strongest shared lines,
   ±2 bins; an alone line there is *matched*; the share of the band the products cover is the chance that a line
   unrelated to them is matched.

The channel is called distorted when over the test at least :data:`MIN_MATCHED` alone lines are matched, in at least
:data:`MIN_RUNS` runs, making :data:`MIN_FRACTION` of its alone lines, and so many matches are unlikely by chance
(binomial tail at the runs' mean chance below :data:`FALSE_ALARM`: the guard; the counts only keep a handful of lines
from deciding).  Over the data of every cell of the family matrix and of seven open-world kinds on its eight wheels
(240 tests: 2-15 kg, modes 50-600 Hz, bearing lines, 2-10 kHz, fixtures, effects) none is called distorted, the
lowest false-alarm probability 1.3e-3; a 0.5 % distortion of Fx on family wheel 6 makes 45 alone lines, 45 matched.
Nor when its matched lines are another channel's, copied (:func:`_copy_source`: a linear crosstalk, which the
diagnosis describes as a ``channel_copy``).

The distortion is then undone, run by run: at the matched lines (±1 bin) the channel's spectrum Y is the products'
part of y², y³ (Y ≈ b₂·FFT(y²) + b₃·FFT(y³) there, as y ≈ x to first order), a linear least squares for (b₂, b₃) in
real arithmetic (one order alone when it does as well), refined on what the law's exact inverse leaves at those lines
(:func:`_coefficients`), and the run's channel becomes that inverse, x from y = x + b₂x² + b₃x³ (:func:`inverse`),
which also puts the compression of the channel's own lines right.  A run with fewer than :data:`MIN_RUN_LINES`
matched lines takes the median law of the others (relative to its RMS, or absolute: whichever does better), and a
run keeps its samples unless both its alone lines and its matched ones fall.  On the family wheels (the generator's
law y = x + a₂x²/σ + a₃x³/σ², σ the clean channel's RMS): a₂ = a₃ = 0.02 on Fx reads 0.0196-0.0201 and 0.0190-0.0203
(wheels 0, 2, 3, 6), a₃ = 0.03 alone on Ty 0.0286 and 0.0270, a₂ = 0.02 alone on Fy 0.0204, 0.005 both 0.0050 and
0.0049; the
corrected channel is within 0.04-0.3 % (median over the runs, of its RMS) of the clean one.  Like the polarity's flip
(:mod:`rwadist.channel_polarity`) it is an invertible map of the data, said in ``data_quality`` (a ``distorted``
record), the console and report.md, with the matches before and after.

Units: the coefficients are reported relative to each run's channel RMS σ (b₂σ, b₃σ²: the distortion's size at one
σ of signal), dimensionless.
"""
from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np

from .units import RADIAL_PAIRS  # the pairs whose channels are compared

#: a line stands this many times over the local noise of its channel's power spectrum
LINE_SNR = 30.0
#: bins of a block whose median is the local noise
NOISE_BINS = 64
#: the partner holds nothing at a line when its power within ±2 bins stays below this many times its local noise
PARTNER_QUIET = 3.0
#: the strongest shared lines whose products are formed
TOP_LINES = 5
#: bins either side of a product (or a line) that count as at it
PRODUCT_HALF = 2
#: the test's matched alone lines, runs with two or more, share of the alone lines, binomial false-alarm probability
MIN_MATCHED = 6
MIN_RUNS = 3
MIN_FRACTION = 0.6
FALSE_ALARM = 1e-9
#: the largest law undone (b₂σ, b₃σ²), and the largest change of the channel's RMS its inverse may make
MAX_ORDER = 0.2
#: matched lines a run needs for its own coefficients
MIN_RUN_LINES = 3
#: a model of one order is kept when its residual at the product lines is within this share of both orders'
SIMPLER = 0.1
#: fixed-point steps of the inverse of a fitted law, and refits of the law on what its inverse leaves
INVERSE_STEPS = 6
REFINE = 3
#: a channel's lines at products are another channel's content copied into it (a linear crosstalk, which
#: :mod:`rwadist.diagnose.channel_copy` describes), not made by its electronics, when one complex factor over the
#: test times that channel's spectrum holds at least this share of their power
COPY_EXPLAINED = 0.9


@functools.lru_cache(maxsize=8)
def _window(n: int) -> np.ndarray:
    """The Hann window of n samples, made once per length (read-only)."""
    w = np.hanning(n)
    w.flags.writeable = False
    return w


def _spectrum(x: np.ndarray) -> np.ndarray:
    """The Hann-windowed spectrum of the rows of ``x`` (each less its mean)."""
    return np.fft.rfft((x - x.mean(axis=-1, keepdims=True)) * _window(x.shape[-1]), axis=-1)


def _run_power(run, channels: tuple) -> dict:
    """channel -> (power spectrum, its lines, the spectrum over its noise) of a run's ``channels``,
    made in one transform: what every pair direction reads.  The lines: the local maxima (over ±2 bins) standing
    :data:`LINE_SNR` over the local noise (:func:`_local_noise`)."""
    from scipy import ndimage

    P = np.abs(_spectrum(np.stack([np.asarray(run.signals[c], dtype=float) for c in channels]))) ** 2
    noise = _local_noise(P)
    peak = (P == ndimage.maximum_filter1d(P, 2 * PRODUCT_HALF + 1, axis=1)) & (P > LINE_SNR * noise)
    peak[:, :PRODUCT_HALF + 1] = False
    return {c: (P[j], np.nonzero(peak[j])[0], P[j] / noise[j]) for j, c in enumerate(channels)}


def _level_at(over_noise: np.ndarray, bins: np.ndarray) -> np.ndarray:
    """The largest of ``over_noise`` (a spectrum over its noise) within ±PRODUCT_HALF bins of each of ``bins``: the
    numbers of a running maximum over the whole spectrum, read at those bins only."""
    k = np.clip(bins[:, None] + np.arange(-PRODUCT_HALF, PRODUCT_HALF + 1), 0, over_noise.size - 1)
    return over_noise[k].max(axis=1) if bins.size else over_noise[:0]


def _local_noise(P: np.ndarray) -> np.ndarray:
    """The local noise of power spectra ``P`` (rows × bins): the median of each block of :data:`NOISE_BINS` bins (lines
    are too sparse to move it), read between the blocks' centres linearly (a running median cost 10x the rest)."""
    n = P.shape[1]
    m = max(n // NOISE_BINS, 1)
    med = np.median(P[:, :m * NOISE_BINS].reshape(P.shape[0], m, -1), axis=2)
    centres = (np.arange(m) + 0.5) * NOISE_BINS - 0.5
    bins = np.arange(n)
    return np.maximum(np.stack([np.interp(bins, centres, row) for row in med]), 1e-300)


def _products(top: np.ndarray, n: int) -> np.ndarray:
    """(n,) bool: bins within PRODUCT_HALF of a sum or difference of second or third order of the bins ``top``, the
    lines themselves left out."""
    f = top.astype(float)
    two = np.concatenate([(f[:, None] + f[None, :]).ravel(), np.abs(f[:, None] - f[None, :]).ravel()])
    three = np.abs(two[:, None] + np.concatenate([f, -f])[None, :]).ravel()
    at = np.rint(np.concatenate([two, three])).astype(int)
    at = at[(at > PRODUCT_HALF) & (at < n - PRODUCT_HALF)]
    cover = np.zeros(n, bool)
    offsets = np.arange(-PRODUCT_HALF, PRODUCT_HALF + 1)
    cover[(at[:, None] + offsets).ravel()] = True
    cover[np.clip(top[:, None] + offsets, 0, n - 1).ravel()] = False
    cover[:PRODUCT_HALF + 1] = False
    return cover


def _run_matches(run, channel: str, partner: str, power: dict | None = None) -> tuple:
    """(matched alone bins, alone lines, chance) of one run's ``channel`` against ``partner``; ``power``: the run's
    :func:`_run_power` holding both, or None (made here)."""
    power = power or _run_power(run, (channel, partner))
    P, lines, _ = power[channel]
    quiet = _level_at(power[partner][2], lines) < PARTNER_QUIET
    alone, shared = lines[quiet], lines[~quiet]
    if alone.size == 0 or shared.size == 0:
        return alone[:0], int(alone.size), 0.0
    top = shared[np.argsort(P[shared])[::-1][:TOP_LINES]]
    cover = _products(top, P.size)
    return alone[cover[alone]], int(alone.size), float(cover.mean())


def _fit_orders(z: np.ndarray, k: np.ndarray, orders: list | None) -> tuple:
    """(coefficients (2,), orders used) of Z ≈ b₂·FFT(z²) + b₃·FFT(z³) at bins ``k`` (real least squares): with
    ``orders`` None, the simplest of (b₂ alone, b₃ alone, both) whose residual power is within :data:`SIMPLER` of both's
    (an odd distortion, a symmetric amplifier, makes no second-order products, and a b₂ fitted to them anyway makes
    lines of its own)."""
    Y, Y2, Y3 = (_spectrum(z**p)[k] for p in (1, 2, 3))
    A = np.vstack([np.column_stack([Y2.real, Y3.real]), np.column_stack([Y2.imag, Y3.imag])])
    target = np.concatenate([Y.real, Y.imag])
    fits = []
    for cols in ([0], [1], [0, 1]) if orders is None else (orders,):
        b, *_ = np.linalg.lstsq(A[:, cols], target, rcond=None)
        full = np.zeros(2)
        full[cols] = b
        fits.append((float(np.sum((target - A @ full) ** 2)), full, cols))
    best = fits[-1][0]
    _, b, cols = next(f for f in fits if f[0] <= (1.0 + SIMPLER) * best)
    return b, cols


def inverse(y: np.ndarray, b2: float, b3: float) -> np.ndarray:
    """x with y = x + b₂x² + b₃x³, by fixed-point iteration from x = y (a contraction for |2b₂x + 3b₃x²| < 1, i.e. a
    distortion of a few per cent at the signal's peaks; :data:`INVERSE_STEPS` steps leave (that)^steps of it)."""
    x = y
    for _ in range(INVERSE_STEPS):
        x = y - b2 * x**2 - b3 * x**3
    return x


def _coefficients(y: np.ndarray, bins: np.ndarray) -> tuple:
    """(b₂, b₃) of y = x + b₂x² + b₃x³, fitted at the product ``bins`` (±1 bin each): to first order the products of
    y are b₂·FFT(y²) + b₃·FFT(y³) there (:func:`_fit_orders`); what the exact inverse of that law leaves at them is
    fitted again and added, :data:`REFINE` times (a 2 % distortion of both orders reads 25 % low at first order).
    (NaN, NaN) when the refits diverge (lines at products that no such law makes: the inverse's iteration grows
    without bound), which no run is corrected with."""
    k = np.unique(np.clip((bins[:, None] + np.arange(-1, 2)).ravel(), 0, y.size // 2))
    with np.errstate(over="ignore", invalid="ignore"):
        try:
            b, orders = _fit_orders(y, k, None)
            for _ in range(REFINE):
                z = inverse(y, *b)
                if not np.all(np.isfinite(z)):
                    return np.nan, np.nan
                step, _ = _fit_orders(z, k, orders)
                b = b + step
        except np.linalg.LinAlgError:       # powers of a diverged inverse overflow in the products' spectra
            return np.nan, np.nan
    return float(b[0]), float(b[1])


def _copy_source(test, channel: str, partner: str, matched: list) -> str | None:
    """The channel (neither ``channel`` nor its ``partner``) whose spectrum times one complex factor a over the test
    (|a| < 1: the weaker way round) holds :data:`COPY_EXPLAINED` or more of the power of ``channel``'s lines at
    products (``matched``: per run, their bins, or None), and bin by bin leaves a median of at most 1 −
    COPY_EXPLAINED of each: those lines are that channel's content copied (a crosstalk holds every line of its source, and
    a bearing's line set, h 0.41, 0.82, 3.6, 7.2, sits at sums and differences of itself: new-user trial nuL, Ty
    holding 8 % of Fx, was called distorted, 44 of 44 lines), not products of ``channel``'s own lines; or None."""
    from .units import CHANNELS

    rows = [(i, m) for i, m in enumerate(matched) if m is not None and m.size]
    sources = [c for c in CHANNELS if c not in (channel, partner)
               and rows and all(test.runs[i].usable(c) for i, _ in rows)]
    if not sources:
        return None
    # every run's spectra at its matched bins, once: (the channel, then each source)
    at = [_spectrum(np.stack([np.asarray(test.runs[i].signals[c], dtype=float) for c in (channel, *sources)]))[:, m]
          for i, m in rows]
    y = np.concatenate([a[0] for a in at])
    for j, source in enumerate(sources, start=1):
        z = np.concatenate([a[j] for a in at])
        own = float(np.vdot(z, z).real)
        a = np.vdot(z, y) / own if own > 0 else 0.0
        if not 0.0 < abs(a) < 1.0:
            continue        # the copy is the weaker way round: a distorted source read back from its copy is not one
        left = np.abs(y - a * z)
        # held by the power (the strongest bins) and bin by bin (the median), so one strong bin does not decide it
        if float(np.sum(left**2)) <= (1.0 - COPY_EXPLAINED) * float(np.vdot(y, y).real) and \
                float(np.median(left / np.maximum(np.abs(y), 1e-300))) <= 1.0 - COPY_EXPLAINED:
            return source
    return None


def _undo(runs: list, matched: list, alone: np.ndarray, channel: str, partner: str) -> tuple:
    """Put ``channel`` right in place in ``runs`` (a list of runs): each run whose matched lines number
    :data:`MIN_RUN_LINES` (2 when no run has as many) with its own (b₂, b₃), the others with the median of those, relative to the run's RMS (b·σ)
    or absolute, whichever leaves fewer alone lines; a run keeps its samples unless both its alone lines and its matched
    ones fall.  Returns (indices of the runs put right, {index: (b₂σ, b₃σ²)})."""
    coef: dict = {}

    def attempt(i: int, b2: float, b3: float) -> bool:
        y = np.asarray(runs[i].signals[channel], dtype=float)
        sigma_y = float(np.std(y))
        if not (abs(b2) * sigma_y <= MAX_ORDER and abs(b3) * sigma_y**2 <= MAX_ORDER):
            return False                # no slight distortion: the inverse's iteration need not converge
        x = inverse(y, b2, b3)
        if not (np.all(np.isfinite(x)) and abs(float(np.std(x)) / sigma_y - 1.0) <= MAX_ORDER):
            return False
        trial = replace(runs[i], signals=dict(runs[i].signals, **{channel: x}))
        m_after, alone_after, _ = _run_matches(trial, channel, partner)
        if alone_after >= alone[i] or m_after.size >= matched[i].size:
            return False
        sigma = float(np.std(trial.signals[channel]))
        coef[i] = (b2 * sigma, b3 * sigma**2)
        runs[i] = trial
        return True

    own = [i for i, m in enumerate(matched) if m is not None and m.size >= MIN_RUN_LINES]
    if not own:                     # a weak distortion: runs of two lines each fit their own law
        own = [i for i, m in enumerate(matched) if m is not None and m.size >= 2]
    fitted = {i: _coefficients(np.asarray(runs[i].signals[channel], dtype=float), matched[i]) for i in own}
    for i in own:
        attempt(i, *fitted[i])
    if coef:
        absolute = np.median([fitted[i] for i in coef], axis=0)
        relative = np.median([coef[i] for i in coef], axis=0)
        for i, m in enumerate(matched):
            if m is None or m.size == 0 or i in coef:
                continue
            sigma = float(np.std(runs[i].signals[channel]))
            for b2, b3 in ((relative[0] / sigma, relative[1] / sigma**2), tuple(absolute)):
                if attempt(i, float(b2), float(b3)):
                    break
    return sorted(coef), coef


def _channel_matches(test, channel: str, partner: str, powers: list | None = None) -> tuple:
    """Per run (matched bins or None where the run lacks the pair), alone lines and chance, of ``channel``;
    ``powers``: each run's :func:`_run_power` (or None), or None (made here)."""
    matched: list = []
    alone, chance = np.zeros(len(test.runs)), np.zeros(len(test.runs))
    for i, run in enumerate(test.runs):
        if not (run.usable(channel) and run.usable(partner)) or not np.isfinite(run.speed) or run.speed == 0:
            matched.append(None)
            continue
        power = powers[i] if powers is not None and powers[i] is not None else None
        m, alone[i], chance[i] = _run_matches(run, channel, partner, power)
        matched.append(m)
    return matched, alone, chance


def _test_powers(test) -> list:
    """Each run's :func:`_run_power` of the radial channels it holds usable (None for a run with none)."""
    out = []
    for run in test.runs:
        chans = tuple(c for pair in RADIAL_PAIRS for c in pair if run.usable(c))
        out.append(_run_power(run, chans) if chans else None)
    return out


def _verdict(matched: list, alone: np.ndarray, chance: np.ndarray) -> dict | None:
    """The test's counts of one channel, and whether they call it distorted (module docstring)."""
    from scipy import stats

    n_matched = np.array([0 if m is None else m.size for m in matched])
    total, hits = int(alone.sum()), int(n_matched.sum())
    if total == 0:
        return None
    p = float(np.sum(chance * alone) / total)
    tail = float(stats.binom.sf(hits - 1, total, p)) if hits else 1.0
    runs = int(np.sum(n_matched >= 2))
    distorted = hits >= MIN_MATCHED and runs >= MIN_RUNS and hits >= MIN_FRACTION * total and tail <= FALSE_ALARM
    return {"lines_alone": total, "lines_at_products": hits, "expected_by_chance": round(p * total, 2),
            "false_alarm": tail, "runs_with_products": runs, "distorted": distorted}


def corrected(test) -> tuple:
    """(test, records): ``test`` with every distorted radial channel (module docstring) put right in the runs whose
    products show (a copy; the same object when none is), and one ``distorted`` record (JSON-ready) per channel."""
    runs = list(test.runs)
    records = []
    powers = _test_powers(test)
    for pair in RADIAL_PAIRS:
        for channel, partner in (pair, pair[::-1]):
            matched, alone, chance = _channel_matches(test, channel, partner, powers)
            before = _verdict(matched, alone, chance)
            if before is None or not before["distorted"] or _copy_source(test, channel, partner, matched):
                continue
            fixed, coef = _undo(runs, matched, alone, channel, partner)
            second = [coef[i][0] for i in fixed]
            third = [coef[i][1] for i in fixed]
            after = _verdict(*_channel_matches(type(test)(runs, dict(test.meta or {})), channel, partner))
            records.append({
                "type": "distorted", "channel": channel, "partner": partner, **{k: v for k, v in before.items()
                                                                                  if k != "distorted"},
                "runs": len([m for m in matched if m is not None]), "runs_corrected": len(fixed),
                "run_names": [runs[i].name for i in fixed],
                "second_order": round(float(np.median(second)), 5) if second else None,
                "third_order": round(float(np.median(third)), 5) if third else None,
                "after": {"lines_alone": (after or {}).get("lines_alone", 0),
                          "lines_at_products": (after or {}).get("lines_at_products", 0)}})
    if not records:
        return test, []
    return type(test)(runs, dict(test.meta or {})), records


def distortion_lines(rec: dict) -> list:
    """Console / report lines of a ``distorted`` record: what the data show, what was done, what to do."""
    x, y = rec["channel"], rec["partner"]
    orders = ", ".join(f"{name} order {100 * abs(rec[key]):.2g} %" for name, key in (("2nd", "second_order"),
                                                                                    ("3rd", "third_order"))
                       if rec.get(key) is not None)
    return [f"{x}'s signal chain is not linear (an amplifier driven past its linear range, a saturating charge "
            f"amplifier, a cable or connector fault): {rec['lines_at_products']} of the {rec['lines_alone']} lines "
            f"{x} holds and {y} does not sit at sums and differences of {x}'s own strongest lines "
            f"({rec['expected_by_chance']:g} expected by chance), in {rec['runs_with_products']} of {rec['runs']} runs; "
            "a load turns in both channels of a pair, so lines in one alone are made after the split into x and y"
            + (f"; its distortion, fitted on those lines: {orders} of the channel's RMS" if orders else ""),
            f"{x} was corrected in {rec['runs_corrected']} run(s) (the inverse of y = x + b2*x^2 + b3*x^3, each run's "
            f"b fitted on its product lines): lines at products {rec['lines_at_products']} -> "
            f"{rec['after']['lines_at_products']}; "
            f"check the range and gain of {x}'s amplifier and re-run the test, or swap the {x} and {y} amplifiers "
            "(the lines move with the amplifier)"]


def summary_line(rec: dict, step: str) -> str:
    """One line for a warning: the channel distorted, and what was done before ``step`` ("the fit", "the diagnosis")."""
    return (f"{rec['channel']}'s signal chain is not linear: {rec['lines_at_products']} lines {rec['channel']} holds "
            f"and {rec['partner']} does not sit at sums and differences of its own lines; {rec['channel']} was corrected "
            f"in {rec['runs_corrected']} run(s) before {step} (data_quality)")
