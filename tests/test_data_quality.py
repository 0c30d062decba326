"""A channel that froze in part of a run (a DAQ or amplifier dropout) is found where it is, left out of that run,
and said; clean and coarsely printed data never raise it (rwadist.data_quality)."""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from rwadist import api
from rwadist.data import SteadyTest, read_steady, write_steady
from rwadist.data_quality import (
    FALSE_ALARM,
    MIN_SAMPLES,
    clipped_levels,
    find_frozen,
    frozen_spans,
    quality_lines,
    screen,
)
from rwadist.empirical import fit_empirical
from rwadist.errors import RwadistWarning
from rwadist.spectra import compute_spectra

SPEEDS = np.linspace(600.0, 2400.0, 16)
#: (run, channel, first frozen sample, one after the last, kind): Fz held in three runs, Tx at zero in one
FROZEN = ((3, "Fz", 2000, 4500, "held"), (8, "Fz", 100, 3100, "held"), (13, "Fz", 5000, 8192, "held"),
          (5, "Tx", 3000, 6000, "zero"))


def _test(seed: int) -> SteadyTest:
    return api.simulate_test("ithaco-e", SPEEDS, n_samples=8192, seed=seed)


def _freeze(test: SteadyTest) -> SteadyTest:
    """Sample and hold (the last good sample's value) or zeros over the stretches of :data:`FROZEN`."""
    runs = list(test.runs)
    for i, c, a, b, kind in FROZEN:
        x = runs[i].signals[c].copy()
        x[a:b] = x[a - 1] if kind == "held" else 0.0
        runs[i] = replace(runs[i], signals={**runs[i].signals, c: x})
    return SteadyTest(runs, dict(test.meta))


def _round(x: np.ndarray, digits: int) -> np.ndarray:
    """``x`` printed with ``%.{digits}g`` and read back."""
    return np.array([float(f"{v:.{digits}g}") for v in x])


def test_frozen_stretches_found_where_they_are_after_a_csv_round_trip(tmp_path):
    test = read_steady(write_steady(_freeze(_test(1)), tmp_path / "d"))
    found = find_frozen(test)
    assert [(s.run, s.channel, s.kind) for s in found] == [(i, c, k) for i, c, _, _, k in sorted(FROZEN)]
    fs = test.runs[0].sample_rate
    for s, (i, c, a, b, kind) in zip(found, sorted(FROZEN)):
        # a held value is the last good sample's, which joins the stretch: the start within one sample
        assert a - 1 <= s.start <= a and s.stop == b
        assert s.start_s == pytest.approx(test.runs[i].t0 + s.start / fs)
        assert s.end_s == pytest.approx(test.runs[i].t0 + (b - 1) / fs)
    lines = quality_lines([s.to_json() for s in found])
    assert len(lines) == len(FROZEN) + 1 and "left out" in lines[0] and "4 channel(s)" in lines[-1]
    screened, again = screen(test)
    assert again == found
    sp = compute_spectra(screened)
    for i, c, _, _, _ in FROZEN:
        assert screened.runs[i].invalid == {c}
        # left out of that run's spectra, as a channel the run lacks; the other channels and runs untouched
        assert not sp.available(c)[i] and sum(sp.available(k)[i] for k in sp.channels) == 5
    assert sum(int(np.sum(~sp.available(k))) for k in sp.channels) == len(FROZEN)
    assert screened.meta["data_quality"] == [s.to_json() for s in found]


def test_nan_samples_are_found():
    test = _test(1)
    x = test.runs[2].signals["Ty"].copy()
    x[10:13] = np.nan
    runs = list(test.runs)
    runs[2] = replace(runs[2], signals={**runs[2].signals, "Ty": x})
    found = find_frozen(SteadyTest(runs))
    assert [(s.run, s.channel, s.kind, s.start, s.stop) for s in found] == [(2, "Ty", "nan", 10, 13)]


def test_no_false_alarm_on_clean_or_coarsely_printed_data():
    """Clean runs (the wheel still, in the 0-rpm run, and at speed), as simulated and printed with 4 significant
    digits (%.4g, as trial13's lab-like files) and 3: coarse printing repeats samples often."""
    test = api.simulate_test("ithaco-e", np.r_[0.0, SPEEDS], n_samples=8192, seed=3)
    assert find_frozen(test) == []
    for digits in (4, 3):
        rounded = SteadyTest([replace(r, signals={c: _round(v, digits) for c, v in r.signals.items()})
                              for r in test.runs])
        repeats = sum(int(np.sum(np.diff(v) == 0)) for r in rounded.runs for v in r.signals.values())
        assert repeats > 500           # rounding does repeat samples, by chance
        assert find_frozen(rounded) == [], digits
    assert screen(test)[0] is test


def test_axial_amplitudes_after_screening_within_the_clean_scatter():
    """The axial force lines' C from the frozen data, screened, agree with the clean data's as well as two noise
    seeds of clean data agree with each other; the same data not screened read them low."""
    clean = api.fit(_test(1)).model
    other = api.fit(_test(2)).model
    frozen = _freeze(_test(1))
    with pytest.warns(RwadistWarning, match="left out"):
        after = api.fit(frozen).model
    assert len(after.provenance["data_quality"]) == len(FROZEN)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RwadistWarning)
        before = fit_empirical(compute_spectra(frozen)).model

    def axial(model):
        return {round(x.h, 1): x.C for x in model.harmonics("axial_force")}

    c, o, a, b = axial(clean), axial(other), axial(after), axial(before)
    hs = [h for h in c if h in o and h in a and h in b]
    assert len(hs) >= 3
    scatter = max(abs(o[h] / c[h] - 1) for h in hs)
    err_after = max(abs(a[h] / c[h] - 1) for h in hs)
    err_before = max(abs(b[h] / c[h] - 1) for h in hs)
    assert err_after <= max(scatter, 0.01), (err_after, scatter)
    assert err_before > 2 * err_after, (err_before, err_after)


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_a_channel_at_its_printed_resolution_is_no_dropout_and_a_hold_in_it_is(seed):
    """Channels that move less than one printed step: ADC counts (0.45 LSB offset, a 0.1 LSB 1 Hz line, 0.03 LSB
    noise) and a 1.2345 N channel with a 0.1 mN 1 Hz line and 0.03 mN noise printed %.4g (1 mN steps).  They sit on
    one level for a long while and leave it by one step; the module's chance model takes repeats as alike along the
    run and called 8-22 such stretches per 8 s record frozen (review14).  The same channel with a 0.2 N (200 LSB) 10
    Hz line, held for 1 s (sample and hold), is still found: the hold ends with a jump of what the line moved."""
    fs, rng = 2000.0, np.random.default_rng(seed)
    t = np.arange(int(8 * fs)) / fs
    slow = np.sin(2 * np.pi * t + rng.uniform(0, 6))
    counts = np.round(0.45 + 0.1 * slow + 0.03 * rng.standard_normal(t.size))
    printed = _round(1.2345 + 1e-4 * slow + 3e-5 * rng.standard_normal(t.size), 4)
    for x in (counts, printed):
        held = np.diff(np.flatnonzero(np.diff(x) != 0))
        assert held.max() > 20 * MIN_SAMPLES and frozen_spans(x) == []   # levels held long, by the signal's nature
    for x, step in ((counts, 1.0), (printed, 1e-3)):
        moving = x + np.round(200 * np.sin(2 * np.pi * 10.3 * t + seed)) * step
        moving[6000:8000] = moving[5999]
        assert [(a, b, kind) for a, b, kind, _ in frozen_spans(moving)] == [(5999, 8000, "held")]
    # review15: where %.4g changes decade (levels 0.9999, 1.000, 1.001: steps 1e-4 and 1e-3) no alarm either, and a
    # line only 5 printed steps high, held 256 samples, is still found
    decade = _round(1.0003 + 4e-4 * slow + 3e-5 * rng.standard_normal(t.size), 4)
    assert frozen_spans(decade) == []
    weak = _round(1234.0 + 5.0 * np.sin(2 * np.pi * 61.7 * t + seed) + 0.3 * rng.standard_normal(t.size), 4)
    weak[3000:3256] = weak[2999]
    ((a, b, kind, _),) = frozen_spans(weak)
    assert 2990 <= a <= 2999 and 3256 <= b <= 3265 and kind == "held"   # the level may repeat beside it, by chance


@pytest.mark.slow
def test_diagnose_warns_and_the_command_says_which_runs_were_left_out(tmp_path, capsys):
    """``api.diagnose`` warns as ``api.fit`` does (review14: a library user was told nothing); ``rwadist diagnose``
    prints that warning once on stderr and lists every stretch in its console, summary.json and report.md."""
    import json

    from rwadist.cli import main

    data = write_steady(_freeze(_test(1)), tmp_path / "d")
    assert main(["diagnose", str(data), "-o", str(tmp_path / "r")]) == 0
    out, err = capsys.readouterr()
    assert err.count("WARNING: a channel froze (a DAQ or amplifier dropout): Fz in 3 run(s), Tx in 1 run(s)") == 1
    # the stretches' lines (the suspension modes' own "!" line, when the data show modes it could not fit, apart)
    assert sum(line.startswith("  ! ") and not line.startswith("  ! suspension modes:")
               for line in out.splitlines()) == len(FROZEN) + 1
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert [(r["run"], r["channel"]) for r in summary["data_quality"]] == [(i, c) for i, c, *_ in sorted(FROZEN)]
    assert "Data quality" in (tmp_path / "r" / "report.md").read_text()
    # the same diagnosis (it costs a minute): these simulated runs are Masterson's modal model (the simple physics,
    # every radial line lifted where it meets either whirl of the 54.9-Hz rocking mode, I_zz/I_rr 2), which the
    # suspension-mode fit does not locate; the forward whirl is described as that whirl (tests/test_moving_whirl.py)
    whirls = [u["parameters"]["rocking_whirl"] for u in summary["unexplained"] if "rocking_whirl" in u["parameters"]]
    assert whirls and all(w["branch"] == "forward" for w in whirls), summary["unexplained"]
    assert all(abs(w["f_at_rest_Hz"] / 54.9 - 1) < 0.02 and abs(w["inertia_ratio"] / 2.0 - 1) < 0.03 for w in whirls)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_channel_past_its_range_is_found_clipped_and_a_sinusoids_peaks_are_not(seed):
    """trial15: Fx saturating at ±3 N in the fastest runs gave no data-quality record and 45-47 phantom fixed lines.
    Three lines and noise clipped at 70 % of their peak: both limits found, each with exactly the samples numpy
    counts past the limit.  The same record unclipped, and a single sinusoid printed %.4g and %.3g (whose top
    level holds up to ~2.4x the level below it, the arcsine density's pile-up): nothing."""
    rng = np.random.default_rng(seed)
    t = np.arange(20000) / 5000.0
    x = sum(a * np.sin(2 * np.pi * f * t + rng.uniform(0, 6)) for a, f in ((2.0, 61.3), (0.5, 122.6), (0.3, 226.0)))
    x = x + 0.02 * rng.standard_normal(t.size)
    limit = 0.7 * min(x.max(), -x.min())
    clipped = np.clip(x, -limit, limit)
    found = clipped_levels(clipped)
    assert sorted((v, n) for _, _, v, n in found) == [(-limit, int(np.sum(x <= -limit))), (limit, int(np.sum(x >= limit)))]
    assert clipped_levels(x) == []
    # a quiet channel in ADC counts holds its two levels by its nature, not past a range (review15)
    assert clipped_levels(np.round(0.45 + 0.1 * np.sin(2 * np.pi * t) + 0.03 * rng.standard_normal(t.size))) == []
    sine = 3.0 * np.sin(2 * np.pi * 61.3 * t + seed)
    for digits in (4, 3):
        assert clipped_levels(_round(sine, digits)) == [], digits
    test = _test(seed)
    runs = list(test.runs)
    fx = runs[-1].signals["Fx"]
    runs[-1] = replace(runs[-1], signals={**runs[-1].signals, "Fx": np.clip(fx, -0.5 * fx.max(), 0.5 * fx.max())})
    screened, records = screen(SteadyTest(runs, {}))
    assert {(s.run, s.channel, s.kind) for s in records} == {(len(runs) - 1, "Fx", "clipped")}
    assert screened.runs[-1].invalid == {"Fx"} and "clipped" in quality_lines([s.to_json() for s in records])[0]


def _spans_by_the_rule(x) -> list:
    """The module docstring's rule written out sample by sample (a second implementation, loops only): every maximal
    stretch of non-finite samples; the stretches of equal finite samples tested longest first, each against the
    repeat chance ``p`` of all the others not yet flagged (one repeat and one change added), flagged while
    (stretches − flagged) · p^(L − 2) < FALSE_ALARM and L >= MIN_SAMPLES, unless it sits among few levels and its
    neighbours are on the levels next to it."""
    out, equal = [], []
    i = 0
    while i < len(x):
        j = i + 1
        if not np.isfinite(x[i]):
            while j < len(x) and not np.isfinite(x[j]):
                j += 1
            out.append((i, j, "nan"))
        else:
            while j < len(x) and np.isfinite(x[j]) and x[j] == x[i]:
                j += 1
            if j - i >= 2:
                equal.append((i, j))
        i = j
    order = sorted(range(len(equal)), key=lambda k: -(equal[k][1] - equal[k][0]))
    flagged: set = set()
    for k in order:
        L = equal[k][1] - equal[k][0]
        rest = [b - a for m, (a, b) in enumerate(equal) if m != k and m not in flagged]
        p = (sum(n - 2 for n in rest) + 1.0) / (sum(n - 1 for n in rest) + 2.0)
        if L < MIN_SAMPLES or (len(rest) + 1) * p ** (L - 2) >= FALSE_ALARM:
            break
        a, b = equal[k]
        # the channel at its printed resolution: the samples within L of the stretch take at most 6 values and each
        # neighbour of the stretch (inside the record) sits on a level next to the held one -- not flagged, and
        # still a chance repeat
        levels = sorted({x[i] for i in range(max(0, a - L), min(len(x), b + L)) if np.isfinite(x[i])})
        ends = [x[i] for i in (a - 1, b) if 0 <= i < len(x) and np.isfinite(x[i])]
        if len(levels) <= 6 and ends and all(abs(levels.index(e) - levels.index(x[a])) == 1 for e in ends):
            continue
        flagged.add(k)
        out.append((a, b, "zero" if x[a] == 0.0 else "held"))
    return sorted(out)


def test_frozen_spans_as_the_rule_says_sample_by_sample():
    """:func:`frozen_spans` (its first pass over the samples included) against the rule written out sample by sample,
    on short records: white noise, noise printed with 1-2 decimals (chance repeats), held values and zeros of 1-60
    samples, NaN and infinities, a record of equal neighbours scattered (MIN_SAMPLES - 1 of them and more, in no
    stretch long enough) and the first pass's edge (exactly MIN_SAMPLES - 1 equal neighbours in one stretch)."""
    rng = np.random.default_rng(37)
    flagged = 0
    for trial in range(3000):
        n = int(rng.integers(0, 200))
        x = rng.normal(size=n)
        kind = trial % 6
        if kind == 1:
            x = np.round(x, int(rng.integers(1, 3)))
        elif kind in (2, 3) and n > 2:
            a = int(rng.integers(0, n - 1))
            x[a:a + int(rng.integers(1, 61))] = x[a] if kind == 2 else 0.0
        elif kind == 4 and n:
            x[rng.integers(0, n, size=int(rng.integers(1, 4)))] = rng.choice([np.nan, np.inf, -np.inf])
        elif kind == 5 and n > 2 * MIN_SAMPLES + 2:
            pairs = rng.choice(np.arange(0, n - 1, 2), size=MIN_SAMPLES - 1 + trial % 3, replace=False)
            x[pairs + 1] = x[pairs]
            if trial % 4 == 1:
                x[:MIN_SAMPLES] = 0.25          # the edge: MIN_SAMPLES - 1 equal neighbours in one stretch
        got = [(a, b, kind) for a, b, kind, _ in frozen_spans(x)]
        assert got == _spans_by_the_rule(x), trial
        flagged += bool(got)
    assert flagged > 500               # the rule does flag (held stretches, zeros, non-finite samples)
