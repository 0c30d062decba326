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
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .formats.records import SteadyTest
from .units import CHANNELS, rad_s_to_rpm

#: expected number of chance stretches as long as a flagged one, per run and channel
FALSE_ALARM = 1e-9
#: fewest equal samples ever called frozen
MIN_SAMPLES = 16


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
        ``"held"`` (one value held), ``"zero"`` (exact zeros held) or ``"nan"`` (samples that are not numbers).
    value : float
        The value held (NaN for ``"nan"``), in the channel's unit (N, N·m).
    n_run : int
        Samples in the run.
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
        return {"type": "frozen_channel", "run": self.run, "run_name": self.run_name, "speed_rpm": self.speed_rpm,
                "channel": self.channel, "kind": self.kind,
                "value": None if not np.isfinite(self.value) else float(self.value),
                "start_s": self.start_s, "end_s": self.end_s, "n_samples": self.stop - self.start,
                "fraction_of_run": (self.stop - self.start) / self.n_run, "action": "channel left out of this run"}


def _stretches(mask: np.ndarray) -> np.ndarray:
    """(K, 2) [start, stop) of the runs of True in ``mask``."""
    d = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return np.column_stack([np.flatnonzero(d == 1), np.flatnonzero(d == -1)])


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
            flagged[k] = True
            a, b = int(runs[k, 0]), int(runs[k, 1]) + 1
            out.append((a, b, "zero" if x[a] == 0.0 else "held", float(x[a])))
    return sorted(out)


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
    closing line that says what was done and what to do next."""
    if not records:
        return []
    lines = []
    for r in records:
        what = {"held": f"held at {r['value']:.6g}", "zero": "held at exactly 0", "nan": "not a number"}[r["kind"]]
        lines.append(f"{r['channel']} of run {r['run_name'] or r['run']} ({r['speed_rpm']:.1f} rpm) froze: {what} "
                     f"from {r['start_s']:.4f} s to {r['end_s']:.4f} s ({r['n_samples']} samples, "
                     f"{100.0 * r['fraction_of_run']:.0f} % of the run); that channel of that run is left out")
    pairs = {(r["run"], r["channel"]) for r in records}
    lines.append(f"{len(pairs)} channel(s) of runs left out (a DAQ or amplifier dropout: one value held for far "
                 "longer than noise at the printed resolution allows); check the cabling, amplifier and DAQ, "
                 "and repeat those runs if that channel matters")
    return lines
