"""Data quality of the recorded samples: a channel that froze (a DAQ or amplifier dropout).

A load-cell channel that drops out for part of a run holds one value -- the last sample (sample and hold), or
zero -- for many consecutive samples, or (in an in-memory test) holds NaN.  Its spectra then lose the lines'
power over that stretch and gain the steps' broadband floor: every line amplitude of the channel reads low and
the run looks like a change of the wheel.  :func:`find_frozen` finds such stretches, per run and channel;
:func:`screen` marks the channel of each run that holds one invalid in that run (``Run.invalid``: its spectra get
the NaN row of a channel the run lacks, and the whole-record steps that ask ``Run.usable`` read it as absent) and
returns the records that say so.  The samples stay in the run: a torque referred through a load-cell offset
(T − r × F) still reads a frozen force, and so do the record scans docs/diagnose.md ("Data quality") lists.

When is a stretch of equal samples "frozen"?  Clean samples repeat a value only by chance: the noise moving by
less than the printed resolution.  The chance that a repeat goes on one more sample is estimated from the channel's
own repeats (every run of equal consecutive samples but the one tested, with one repeat and one change added as a
prior), ``p``; a stretch of ``L`` equal samples is frozen when the expected number of stretches that long in the
run, ``n_repeats · p^(L - 2)``, is below :data:`FALSE_ALARM` and ``L`` is at least :data:`MIN_SAMPLES`.  Coarse
printing (``%.4g``) raises ``p`` and with it the length needed; no threshold is tied to a wheel or a sample rate.
The chance model takes repeats as alike along the run, which a channel that moves only a few printed steps does
not satisfy; such a stretch, among few levels and leaving its value for the next one, is not called frozen
(:func:`_at_resolution`).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .formats.records import SteadyTest
from .units import CHANNELS, rad_s_to_rpm

#: expected number of chance stretches as long as a flagged one, per run and channel
FALSE_ALARM = 1e-9
#: fewest equal samples ever called frozen (or clipped)
MIN_SAMPLES = 16
#: a clipped extreme holds this many times the samples of any of the CLIP_LEVELS values next inside it
CLIP_RATIO = 10.0
CLIP_LEVELS = 4


@dataclass(frozen=True)
class FrozenStretch:
    """One frozen stretch of one channel of one run.

    Attributes
    ----------
    run : int
        Index of the run in the test (sorted by speed).
    run_name : str
        The run's file name.
    speed_rpm : float
        The run's speed, rpm.
    channel : str
        Channel name (``Fz``, ...).
    start, stop : int
        First sample of the stretch and the one after its last.
    sample_rate : float
        Hz.
    t0 : float
        Time of the run's first sample, s.
    kind : str
        ``"held"`` (one value held), ``"zero"`` (exact zeros held), ``"nan"`` (samples that are not numbers) or
        ``"clipped"`` (samples at the channel's limit, spread over ``start``..``stop``: see ``n_at``).
    value : float
        The value held (NaN for ``"nan"``), in the channel's unit (N, N·m).
    n_run : int
        Samples in the run.
    n_at : int or None
        For ``"clipped"``: how many samples sit at the limit (None: every sample of start..stop).
    """

    run: int
    run_name: str
    speed_rpm: float
    channel: str
    start: int
    stop: int
    sample_rate: float
    t0: float
    kind: str
    value: float
    n_run: int
    n_at: int | None = None

    @property
    def start_s(self) -> float:
        """Time of the first frozen sample, s."""
        return self.t0 + self.start / self.sample_rate

    @property
    def end_s(self) -> float:
        """Time of the last frozen sample, s."""
        return self.t0 + (self.stop - 1) / self.sample_rate

    @property
    def duration_s(self) -> float:
        """Length of the stretch, s (samples / sample rate)."""
        return (self.stop - self.start) / self.sample_rate

    def to_json(self) -> dict:
        n = self.stop - self.start if self.n_at is None else self.n_at
        return {"type": "clipped_channel" if self.kind == "clipped" else "frozen_channel", "run": self.run,
                "run_name": self.run_name, "speed_rpm": self.speed_rpm, "channel": self.channel, "kind": self.kind,
                "value": None if not np.isfinite(self.value) else float(self.value),
                "start_s": self.start_s, "end_s": self.end_s, "n_samples": n,
                "fraction_of_run": n / self.n_run, "action": "channel left out of this run"}


def _stretches(mask: np.ndarray) -> np.ndarray:
    """(K, 2) [start, stop) of the runs of True in ``mask``."""
    d = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return np.column_stack([np.flatnonzero(d == 1), np.flatnonzero(d == -1)])


#: a channel at its printed resolution takes at most this many distinct values around a stretch it holds
RESOLUTION_LEVELS = 6


def _at_resolution(x: np.ndarray, a: int, b: int, width: int) -> bool:
    """Whether the stretch of equal samples ``x[a:b]`` is a channel at its printed resolution, not a dropout.

    The chance model of the module docstring takes repeats as alike along the run.  A channel that moves less than
    a few printed steps (a quiet axial channel on its preload, ADC counts) breaks that: it sits on one of a few
    levels for long stretches and leaves it for the next.  A channel that froze hides a signal that went on moving:
    around the stretch the samples take many levels, and at its end (for zeros, at its start too) they jump by what
    the signal moved meanwhile, past levels seen nearby.  So a stretch is the channel at its resolution when the
    samples within ``width`` of it take at most :data:`RESOLUTION_LEVELS` distinct values and each change at its
    ends (inside the record) goes to a level next to the one held among those values (review15: a step-size rule
    excused holds of lines 2-10 steps high and failed where %.4g changes decade).  A whole record of one value has
    no end to read and stays frozen.
    """
    lo, hi = max(0, a - width), min(x.size, b + width)
    near = x[lo:hi]
    levels = np.unique(near[np.isfinite(near)])
    if levels.size > RESOLUTION_LEVELS:
        return False
    held = int(np.searchsorted(levels, x[a]))
    ends = [int(np.searchsorted(levels, x[i])) for i in (a - 1, b) if 0 <= i < x.size and np.isfinite(x[i])]
    return bool(ends) and all(abs(e - held) == 1 for e in ends)


def frozen_spans(x) -> list:
    """Frozen stretches of one record: [(start, stop, kind, value)] (samples, stop exclusive), by start.

    Parameters
    ----------
    x : array_like
        The samples (N or N·m).

    Returns
    -------
    list
        NaN stretches (every non-finite sample: never usable) and stretches of equal samples that chance does not
        explain (module docstring): ``kind`` "zero" when the value held is 0, else "held".
    """
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        total = np.sum(x)
    if x.size >= 2 and np.isfinite(total) and np.count_nonzero(x[1:] == x[:-1]) < MIN_SAMPLES - 1:
        # the first pass (most records): every sample finite (a finite sum: a NaN or an infinity makes it not) and
        # fewer than MIN_SAMPLES - 1 equal neighbours in all, so no stretch of MIN_SAMPLES equal samples -- nothing
        # the full test below could flag, in three passes over the samples instead of a dozen
        return []
    finite = np.isfinite(x)
    out = [(int(a), int(b), "nan", float("nan")) for a, b in _stretches(~finite)]
    if x.size < 2:
        return out
    eq = (x[1:] == x[:-1]) & finite[1:] & finite[:-1]
    runs = _stretches(eq)                       # in pairs: samples [a, b + 1)
    if runs.size:
        lengths = runs[:, 1] - runs[:, 0] + 1   # equal samples in each stretch
        order = np.argsort(-lengths, kind="stable")
        flagged = np.zeros(lengths.size, bool)
        for k in order:
            L = int(lengths[k])
            if L < MIN_SAMPLES:
                break
            others = ~flagged
            others[k] = False
            rest = lengths[others]
            p = (np.sum(rest - 2) + 1.0) / (np.sum(rest - 1) + 2.0)
            if (rest.size + 1) * p ** (L - 2) >= FALSE_ALARM:
                break
            a, b = int(runs[k, 0]), int(runs[k, 1]) + 1
            if _at_resolution(x, a, b, L):
                continue
            flagged[k] = True
            out.append((a, b, "zero" if x[a] == 0.0 else "held", float(x[a])))
    return sorted(out)


def clipped_levels(x) -> list:
    """The limits a record is clipped at: [(first sample, one after the last, value, samples at it)].

    A channel driven past its amplifier's or ADC's range holds the range's end wherever the signal exceeds it: many
    samples at exactly one extreme value.  Unclipped, the samples pile up near a sinusoid's extremes too (its
    arcsine density), but smoothly: printed to a step q, the top level holds at most about 2.4 times the level
    below it (sqrt(q) against sqrt(2q) − sqrt(q)), and a record printed finely holds its maximum once.  An extreme
    held by :data:`MIN_SAMPLES` samples or more and :data:`CLIP_RATIO` times the most any of the
    :data:`CLIP_LEVELS` values next inside it holds is a limit (trial15: Fx at ±3 N, 237-9128 samples against 1).
    Where the printed value changes decade just inside the peak the top level is up to ten finer steps wide and the
    2.4 bound does not hold: a sinusoid of amplitude 1.045 printed ``%.2g`` reads clipped at ±1 (review15).
    """
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)] if not np.all(np.isfinite(x)) else x
    if x.size < 2 * MIN_SAMPLES:
        return []
    # most records hold their extremes a few times: nothing to sort
    if np.count_nonzero(x == x.max()) < MIN_SAMPLES and np.count_nonzero(x == x.min()) < MIN_SAMPLES:
        return []
    levels, counts = np.unique(x, return_counts=True)
    if levels.size <= CLIP_LEVELS + 1:
        # a channel of a few levels (a quiet channel in ADC counts) holds its extremes by its nature (review15)
        return []
    out = []
    for end, inside in ((-1, slice(-1 - CLIP_LEVELS, -1)), (0, slice(1, 1 + CLIP_LEVELS))):
        n, near = int(counts[end]), counts[inside]
        if levels.size > 1 and n >= MIN_SAMPLES and n >= CLIP_RATIO * max(int(near.max()), 1):
            at = np.flatnonzero(x == levels[end])
            out.append((int(at[0]), int(at[-1]) + 1, float(levels[end]), n))
    return out


def find_frozen(test: SteadyTest) -> list:
    """Every frozen stretch of every run and channel of ``test``, as :class:`FrozenStretch` records (run order, then
    channel order, then time)."""
    found = []
    for i, run in enumerate(test.runs):
        for c in CHANNELS:
            if c not in run.signals:
                continue
            for a, b, kind, value in frozen_spans(run.signals[c]):
                found.append(FrozenStretch(i, run.name, float(rad_s_to_rpm(run.speed)), c, a, b,
                                           float(run.sample_rate), float(run.t0), kind, value, run.n_samples))
            for a, b, value, n in clipped_levels(run.signals[c]):
                found.append(FrozenStretch(i, run.name, float(rad_s_to_rpm(run.speed)), c, a, b,
                                           float(run.sample_rate), float(run.t0), "clipped", value, run.n_samples, n))
    return found


def screen(test: SteadyTest) -> tuple:
    """The test with every channel that froze in a run marked invalid in that run (``Run.invalid``: its spectra
    are left out of the run, as for a channel the run lacks), and the records.

    Returns
    -------
    (SteadyTest, list)
        The screened test (the same object when nothing froze) and the :class:`FrozenStretch` records;
        ``meta["data_quality"]`` of the screened test holds the records' JSON.
    """
    found = find_frozen(test)
    if not found:
        return test, []
    bad: dict = {}
    for s in found:
        bad.setdefault(s.run, set()).add(s.channel)
    runs = [replace(run, invalid=run.invalid | frozenset(bad[i])) if i in bad else run
            for i, run in enumerate(test.runs)]
    return SteadyTest(runs, dict(test.meta, data_quality=[s.to_json() for s in found])), found


def quality_lines(records) -> list:
    """Console / report lines of the records (JSON dicts of :meth:`FrozenStretch.to_json`): one per stretch and a
    closing line that says what was done and what to do next; a ``reversed_polarity`` or ``reversed_spin``
    record (:mod:`rwadist.channel_polarity`) first, in its own lines."""
    from .channel_distortion import distortion_lines
    from .channel_polarity import polarity_lines
    from .channel_timing import late_lines

    sign_errors = ("reversed_polarity", "reversed_spin")
    lines = [x for r in records if r.get("type") in sign_errors for x in polarity_lines(r)]
    lines += [x for r in records if r.get("type") == "distorted" for x in distortion_lines(r)]
    lines += [x for r in records if r.get("type") == "late_channel" for x in late_lines(r)]
    records = [r for r in records if r.get("type") not in sign_errors + ("distorted", "late_channel")]
    if not records:
        return lines
    for r in records:
        run = f"{r['channel']} of run {r['run_name'] or r['run']} ({r['speed_rpm']:.1f} rpm)"
        share = f"{r['n_samples']} samples, {100.0 * r['fraction_of_run']:.0f} % of the run"
        if r["kind"] == "clipped":
            lines.append(f"{run} clipped: {share} at its limit {r['value']:.6g} between {r['start_s']:.4f} s and "
                         f"{r['end_s']:.4f} s; that channel of that run is left out")
            continue
        what = {"held": f"held at {r['value']:.6g}", "zero": "held at exactly 0", "nan": "not a number"}[r["kind"]]
        lines.append(f"{run} froze: {what} from {r['start_s']:.4f} s to {r['end_s']:.4f} s ({share}); that channel "
                     "of that run is left out")
    pairs = {(r["run"], r["channel"]) for r in records}
    causes = [c for c, kinds in (("a DAQ or amplifier dropout: one value held for far longer than noise at the "
                                  "printed resolution allows", {"held", "zero", "nan"}),
                                 ("a channel past its amplifier's or ADC's range: clipped at one value",
                                  {"clipped"})) if any(r["kind"] in kinds for r in records)]
    todo = ("check the cabling, amplifier and DAQ" if "clipped" not in {r["kind"] for r in records} else
            "check the cabling, amplifier and DAQ, and set the range above the largest load of the fastest run")
    lines.append(f"{len(pairs)} channel(s) of runs left out ({'; '.join(causes)}); {todo}, and repeat those runs "
                 "if that channel matters")
    return lines


def summary_line(records) -> str:
    """One line for a warning: which channels froze in how many runs (records: JSON dicts of
    :meth:`FrozenStretch.to_json`), and that each stretch is listed in ``data_quality``."""
    runs: dict = {}
    for r in records:
        runs.setdefault(r["channel"], set()).add(r["run"])
    which = ", ".join(f"{c} in {len(runs[c])} run(s)" for c in CHANNELS if c in runs)
    what = ("froze (a DAQ or amplifier dropout)" if all(r["kind"] != "clipped" for r in records) else
            "clipped (past its range)" if all(r["kind"] == "clipped" for r in records) else "froze or clipped")
    return f"a channel {what}: {which}; each is left out of those runs, every stretch listed in data_quality"
