"""A radial channel wired with the wrong polarity, read from the rotation sense of the wheel's 1× lines (issue 33).

A load cell's radial pair (Fx, Fy) or (Tx, Ty) read as x + iy turns a load line A·e^{iωt} that rotates with the
rotor into its mirror when one of the two channels has the wrong sign: x − iy = conj(A)·e^{−iωt}.  Every line of the
pair then reads with the other rotation sense (a line's co-rotating share s becomes 1 − s), its power and frequency
unchanged.  Flipping x instead of y gives −conj(A)·e^{−iωt}: the same senses, the pair turned by 180° (the data
cannot tell Fx from Fy, only that one of them is reversed).

The physics that tells it: the imbalance of a rotor is a mass (static, in the radial force) and a product of inertia
(dynamic, in the radial torque) fixed to the rotor, so its 1× load turns with the rotor in both pairs.  An
anisotropic support can add a counter-rotating part to the response, but the force and the moment of one rotor on
one support keep one sense between them; a radial pair whose 1× line reads counter-rotating run after run while the
other pair's 1× line (the same rotor, the same speeds) reads co-rotating is the signature of a sign error on one of
that pair's channels, never of an imbalance (a genuine counter-rotating share q of the 1× reads 1 − q co, e.g.
0.75 at q = 0.25).

A speed column of the wrong sign reverses both pairs alike: both 1× lines read counter-rotating.  That is the
rotor turning about −z of the load cell's frame while the column says +z (a tachometer gives an unsigned speed; a
wheel mounted with its spin axis along the cell's −z; the cell's z axis pointing the other way).  The same
physics reads it: no imbalance turns against its rotor in both pairs.  Every run's speed is then negated (the
wheel's spin in the cell's frame, the frame every other channel is read in) rather than fitted as given, where the
imbalance would be named a counter-rotating q ≈ 1 and every radial line's sense reversed.

So before the search, per run, the 1× line of each radial pair is measured where the speed puts it
(:func:`rwadist.speed_check.run_line`: the strongest peak within 3 % of the 1× frequency, its co-rotating share
|X + iY|²/(|X + iY|² + |X − iY|²), swapped for Ω < 0, where it stands :data:`speed_scale.PAIR_SNR` over the local
noise).  A pair is called reversed, and its y channel's sign flipped in every run (the data as the wheel made them,
up to the 180° turn above), when

1. its 1× line is measured in at least :data:`MIN_RUNS` runs and half of the spinning runs, and the median of its
   co-rotating shares is at most 1 − :data:`POLARIZED_1X`;
2. the other pair's 1× line is measured alike and the median of its shares is at least :data:`POLARIZED_1X`.

Flipping rather than fitting as recorded: the sign error is an exact, invertible map of the data, and every effect
that reads the x/y phase is wrong without the flip (every radial line's sense, hence which whirl of the rocking mode
a torque line meets; the imbalance named a counter-rotating q ≈ 1; a load-cell offset r × F, whose Tx, Ty terms are
antisymmetric in Fx, Fy, cannot be fitted to a reversed channel).  PSDs do not change.  As evidence, the share of
each pair's line power that is counter-rotating is also measured (every bin of the complex spectrum of x + iy that
stands :data:`LINE_SNR` over the run's median; positive frequencies co-rotating for Ω > 0), before the flip.

What was found goes to ``data_quality`` (a ``reversed_polarity`` or ``reversed_spin`` record), the console and
report.md.

Units: Hz, rad/s, dimensionless shares.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .speed_check import LINES, MIN_RUNS, LineReads
from .speed_scale import PAIR_SNR

#: the radial pairs: direction -> (x channel, y channel)
PAIRS = {d: LINES[d][0] for d in ("radial_force", "radial_torque")}
#: median co-rotating share of a 1× line read as co-rotating (its mirror 1 − POLARIZED_1X: counter-rotating)
POLARIZED_1X = 0.8
#: a bin of a pair's complex spectrum counts as line power this many times over the run's median bin power
LINE_SNR = 100.0
#: bins above 0 Hz (either side) left out of the line power (the mean and the lowest drift)
LOW_BINS = 4


def _one_x_shares(test, direction: str, reads: dict) -> np.ndarray:
    """Per run the co-rotating share of the ``direction``'s 1× line relative to the run's spin (nan where not
    measured), from ``reads`` (:func:`rwadist.speed_check.line_reads` of ``test``: the line and its share at the
    run's given speed, nan where the run lacks the pair or the speed puts the line out of reach)."""
    _, snr, share = reads[direction].T
    speed = np.array([r.speed for r in test.runs], dtype=float)
    ok = (speed != 0) & np.isfinite(share) & (snr >= PAIR_SNR)
    return np.where(ok, np.where(speed > 0, share, 1.0 - share), np.nan)


def line_power_counter_share(test, pair: tuple) -> float:
    """Share of the pair's line power that turns against the spin, over every run: the Hann-windowed spectrum of
    x + iy (each less its mean), the bins :data:`LINE_SNR` over the run's median bin power, those at negative
    frequency (positive for Ω < 0) counter-rotating; nan when no bin stands so."""
    co = ct = 0.0
    for run in test.runs:
        if run.speed == 0 or not all(run.usable(c) for c in pair):
            continue
        x, y = (np.asarray(run.signals[c], float) for c in pair)
        z = np.fft.fft(np.hanning(x.size) * ((x - x.mean()) + 1j * (y - y.mean())))
        p = np.abs(z) ** 2
        k = np.fft.fftfreq(x.size)
        line = (p > LINE_SNR * np.median(p)) & (np.abs(k) * x.size > LOW_BINS)
        pos, neg = float(p[line & (k > 0)].sum()), float(p[line & (k < 0)].sum())
        co, ct = (co + pos, ct + neg) if run.speed > 0 else (co + neg, ct + pos)
    return ct / (co + ct) if co + ct > 0 else float("nan")


def _reading(shares: np.ndarray, spinning: int) -> float:
    """Median co share of a 1× line measured in enough runs (MIN_RUNS and half the spinning runs), else nan."""
    ok = shares[np.isfinite(shares)]
    return float(np.median(ok)) if ok.size >= max(MIN_RUNS, int(np.ceil(0.5 * spinning))) else float("nan")


def check_record(test, reads: LineReads | None = None) -> dict | None:
    """The ``reversed_polarity`` record of a steady test (module docstring) when one radial pair reads reversed
    against the other, the ``reversed_spin`` record when both read reversed, else None.  ``reads``: a
    :class:`rwadist.speed_check.LineReads` shared with the steps before and after this one, or None."""
    pairs = {d: p for d, p in PAIRS.items() if any(all(r.usable(c) for c in p) for r in test.runs)}
    if len(pairs) < 2:
        return None
    spinning = sum(1 for r in test.runs if r.speed != 0)
    read = (reads or LineReads())(test)
    shares = {d: _one_x_shares(test, d, read) for d in pairs}
    med = {d: _reading(s, spinning) for d, s in shares.items()}
    rev = [d for d in pairs if med[d] <= 1 - POLARIZED_1X]
    if len(rev) == 2:
        counter = {o: line_power_counter_share(test, p) for o, p in pairs.items()}
        return {"type": "reversed_spin", "directions": list(pairs),
                "one_x_co_shares": {d: round(med[d], 4) for d in pairs},
                "one_x_runs": {d: int(np.isfinite(shares[d]).sum()) for d in pairs},
                "line_power_counter_shares": {d: round(counter[d], 4) for d in pairs},
                "action": "every run's speed multiplied by -1 before the fit"}
    if len(rev) != 1:
        return None
    d = rev[0]
    other = next(o for o in pairs if o != d)
    if not med[other] >= POLARIZED_1X:
        return None
    x, y = pairs[d]
    counter = {o: line_power_counter_share(test, p) for o, p in pairs.items()}
    return {"type": "reversed_polarity", "direction": d, "channels": [x, y], "channel": y,
            "one_x_co_share": round(med[d], 4), "one_x_runs": int(np.isfinite(shares[d]).sum()),
            "other_direction": other, "other_one_x_co_share": round(med[other], 4),
            "other_one_x_runs": int(np.isfinite(shares[other]).sum()),
            "line_power_counter_share": round(counter[d], 4), "other_line_power_counter_share": round(counter[other], 4),
            "action": f"{y} multiplied by -1 in every run before the fit"}


def checked(test, reads: LineReads | None = None) -> tuple:
    """(test, record): ``test`` with the reversed pair's y channel multiplied by −1 in every run, or with every run's
    speed negated for a ``reversed_spin`` record (a copy; its meta records it) when :func:`check_record` finds one,
    else (``test``, None).  ``reads``: as :func:`check_record`'s."""
    rec = check_record(test, reads)
    if rec is None:
        return test, None
    if rec["type"] == "reversed_spin":
        runs = [replace(r, speed=-r.speed) for r in test.runs]
        return type(test)(runs, dict(test.meta or {}, spin_reversed=True)), rec
    y = rec["channel"]
    runs = [replace(r, signals={c: (-np.asarray(v) if c == y else v) for c, v in r.signals.items()})
            for r in test.runs]
    return type(test)(runs, dict(test.meta or {}, polarity_flipped=y)), rec


def polarity_lines(rec: dict) -> list:
    """Console / report lines of a ``reversed_polarity`` or ``reversed_spin`` record: what the data show, what was
    done, what to do."""
    if rec["type"] == "reversed_spin":
        shares = rec["one_x_co_shares"]
        read = " and ".join(f"the {d.replace('_', ' ')}'s {shares[d]:.3g} ({rec['one_x_runs'][d]} runs)"
                            for d in rec["directions"])
        return ["the rotor turns against the sign of the speed column: the 1x line (the imbalance, fixed to the "
                f"rotor: it turns with it) reads counter-rotating in both radial pairs, median co-rotating share {read}; "
                "no imbalance turns against its rotor in both",
                "every run's speed was multiplied by -1 before the fit (the wheel spins about -z of the load cell's "
                "frame); check the speed column's sign (a tachometer gives an unsigned speed) and the wheel's and the "
                "cell's z axes, and give the speed signed in the cell's frame; or the x and y channels exchanged in "
                "both radial pairs (Fx with Fy and Tx with Ty: two cables, or the channel map's x and y swapped), "
                "which reads every rotating line the other way round as well"]
    x, y = rec["channels"]
    d, o = rec["direction"].replace("_", " "), rec["other_direction"].replace("_", " ")
    return [f"{x}/{y} wired with the wrong polarity (one of them): the {d}'s 1x line (the imbalance, fixed to the "
            f"rotor: it turns with it) reads counter-rotating, co-rotating share {rec['one_x_co_share']:.3g} "
            f"(median of {rec['one_x_runs']} runs), while the {o}'s 1x line of the same rotor reads co-rotating "
            f"({rec['other_one_x_co_share']:.3g}, {rec['other_one_x_runs']} runs); "
            f"{100 * rec['line_power_counter_share']:.1f} % of the {d}'s line power turns against the spin "
            f"({100 * rec['other_line_power_counter_share']:.1f} % of the {o}'s): a sign error on {x} or {y} mirrors "
            "every line of the pair, no imbalance does",
            f"{y} was multiplied by -1 in every run before the fit (the data cannot tell {x} from {y}: flipping {x} "
            "instead turns the pair by 180 degrees, which changes no PSD or sense, only the sign of a fitted "
            f"load-cell offset's lateral coupling, nor from {x} and {y} exchanged, which turns it by 90 degrees); "
            f"check the {x}/{y} wiring (a sign, or the two cables swapped) and the load cell's calibration matrix, "
            "fix it and re-run"]
