"""A radial channel recorded late, undone (issue 33: the new-user trial nuN, Fy 3 samples late).

A channel sampled or filtered τ later than its partner (a multiplexed ADC, an anti-alias filter, a cable delay)
turns every line's x/y phase by 2πfτ: the line reads a part sin²(πfτ) of its power in the other rotation sense, and
the fit takes that part as the wheel's (counter-rotating parts of every radial line, 57-67 % of the co-rotating
amplitude at the top speeds in nuN's case), with the counter_rotation class misled by it (a true 20 % counter-rotating
imbalance missed on one seed, read 55 % high on the other).  The diagnosis reads the skew on the records at the
model's lines (:mod:`rwadist.diagnose.describe_skew`); when the reading is beyond doubt -- τ :data:`MIN_T` standard
errors from 0, its course explaining :data:`MIN_EXPLAINED` of the lines' phase and turning them
:data:`MIN_PHASE_DEG` or more at the highest line read -- the late channel is moved τ earlier in every run (a
fractional delay, its spectrum times e^{2πjfτ}: exact for the lines, the record's ends wrapped over τ, a few samples
the analysis window keeps at zero weight) and the data are diagnosed again, as a reversed channel or a distorted one
is put right before the search.  What was done goes to ``data_quality`` (a ``late_channel`` record), the console and
report.md.

Units: seconds, Hz.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

#: a skew is undone when τ stands this many standard errors from 0 ...
MIN_T = 20.0
#: ... its course explains this share of the lines' squared phase ...
MIN_EXPLAINED = 0.95
#: ... and turns the highest line read by this much (degrees)
MIN_PHASE_DEG = 10.0


def late_channels(diagnosis) -> list:
    """The ``late_channel`` records (JSON-ready dicts) of the diagnosis' ``channel_skew`` descriptions that are beyond
    doubt (module docstring): ``type`` "late_channel", ``channel`` (the late one), ``reference``, ``tau_s``,
    ``stderr_s``, ``explained``, ``phase_at_highest_deg``, ``lines_h``."""
    out = []
    for u in getattr(diagnosis, "unexplained", ()):
        p = u.parameters or {}
        if p.get("property") != "channel_skew":
            continue
        if (p["tau_s"] >= MIN_T * p["stderr_s"] and p["explained"] >= MIN_EXPLAINED
                and p["phase_at_highest_deg"] >= MIN_PHASE_DEG):
            out.append({"type": "late_channel", "channel": p["late"], "reference": p["early"],
                        "tau_s": float(p["tau_s"]), "stderr_s": float(p["stderr_s"]),
                        "explained": float(p["explained"]), "phase_at_highest_deg": float(p["phase_at_highest_deg"]),
                        "lines_h": [float(x) for x in p.get("lines_h", [])]})
    return out


def moved_earlier(x: np.ndarray, tau_s: float, sample_rate: float) -> np.ndarray:
    """``x`` (n,) read ``tau_s`` s earlier: its spectrum times e^{2πjfτ} (a circular fractional shift; the n·τ·fs
    samples at its end are its start's)."""
    from scipy import fft as sfft

    n = x.size
    f = sfft.rfftfreq(n, 1.0 / sample_rate)
    return sfft.irfft(sfft.rfft(np.asarray(x, dtype=float)) * np.exp(2j * np.pi * f * tau_s), n=n)


def undone(test, records: list):
    """``test`` with every ``late_channel`` record's channel moved earlier by its τ in every run (a new test; the
    given one untouched)."""
    runs = []
    for run in test.runs:
        signals = dict(run.signals)
        for rec in records:
            if rec["channel"] in signals and run.usable(rec["channel"]):     # a channel left out stays as it is
                signals[rec["channel"]] = moved_earlier(signals[rec["channel"]], rec["tau_s"], float(run.sample_rate))
        runs.append(replace(run, signals=signals))
    return replace(test, runs=runs, meta=dict(test.meta))


def in_time(diagnosed: tuple, diagnose_again) -> tuple:
    """(test, diagnosis, ``late_channel`` records): ``diagnosed`` (test, its diagnosis) when no channel reads late
    beyond doubt (:func:`late_channels`), else the late channels moved back (:func:`undone`) and
    ``diagnose_again(test) -> (test, diagnosis)`` of them."""
    test, diagnosis = diagnosed
    late = late_channels(diagnosis)
    if not late:
        return test, diagnosis, []
    test, diagnosis = diagnose_again(undone(test, late))
    return test, diagnosis, late


def late_lines(rec: dict) -> list:
    """Console / report lines of a ``late_channel`` record: what the data show, what was done, what to do."""
    ms = 1e3 * rec["tau_s"]
    return [f"{rec['channel']} was recorded {ms:.3g} ms (±{1e3 * rec['stderr_s']:.1g} ms) after {rec['reference']}: "
            f"every line of one rotation sense read its x/y phase off a quarter turn in proportion to its frequency "
            f"({rec['phase_at_highest_deg']:.3g}° at the highest line read, {100 * rec['explained']:.4g} % of the "
            "lines' phase explained), a multiplexed ADC, an anti-alias filter or a cable delay in that channel",
            f"{rec['channel']} was moved {ms:.3g} ms earlier in every run and the data diagnosed again; check the "
            "DAQ's channel-to-channel delay (one signal recorded on both channels at once shows it)"]


def summary_line(rec: dict) -> str:
    """One line for a warning."""
    return (f"{rec['channel']} was recorded {1e3 * rec['tau_s']:.3g} ms after {rec['reference']}: moved that much "
            "earlier in every run and diagnosed again (data_quality)")
