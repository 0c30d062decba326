"""The open world of ``rwadist diagnose`` (issue 33, items 3 and 4): what no class explains is described by its
signature, with no class added for it, nothing described on clean data, and a second metric that sees narrow lines.

Data: the independent wheel (tests/independent_wheel.py: the thesis's E wheel through its suspension modes, typed in
real coordinates, not read from rwadist) with the effects of tests/open_world_cases.py written into its records by
numpy and scipy.signal (a real IIR filter for the moving resonance), on the default path (no model).  The truth is
the injection's own numbers.  Each record is diagnosed once per test process (:func:`diagnosed`).
"""
import functools
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import open_world_cases as owc  # noqa: E402

from rwadist import api  # noqa: E402

SPEEDS = np.linspace(300.0, 3000.0, 20)


@functools.lru_cache(maxsize=None)
def diagnosed(kind: str):
    test, truth = owc.generate(kind, SPEEDS, seed=4)
    return test, truth, api.diagnose(test)


def _classes(d):
    return [e["kind"] for e in d.model.effects]


def test_clean_data_get_no_description_and_only_the_modes():
    _, _, d = diagnosed("clean")
    assert _classes(d) == ["suspension_modes"]
    assert d.unexplained == ()
    assert d.summary()["unexplained"] == []


@pytest.mark.parametrize("kind", ["fixed_lines", "channel_copy", "broadband_hump", "wide_hump", "rattle",
                                  "rattle_some_runs", "affine_line"])
def test_each_unknown_kind_is_described_by_its_signature_and_no_class_is_added(kind):
    _, truth, d = diagnosed(kind)
    assert _classes(d) == ["suspension_modes"], kind
    sigs = [u.signature for u in d.unexplained]
    assert truth["signature"] in sigs, (kind, sigs)
    assert set(sigs) == {truth["signature"]}, (kind, [u.text() for u in d.unexplained])


def test_fixed_lines_found_at_their_frequencies_and_the_mains_family_named():
    _, truth, d = diagnosed("fixed_lines")
    got = sorted(u.f_Hz[0] for u in d.unexplained)
    assert got == pytest.approx(sorted(truth["fixed_hz"]), abs=0.1)
    for u in d.unexplained:
        assert u.channels == ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz") and u.n_runs >= 15
        mains = abs(u.f_Hz[0] - 137.0) > 1
        assert ("60 Hz mains" in u.causes[0]) == mains, u.causes
        assert u.parameters["removed_before_the_search"] is True
    # the modes as on clean data (the lines were not forced into a resonance)
    _, _, clean = diagnosed("clean")
    m, m0 = d.model.effects[0], clean.model.effects[0]
    for key in ("radial_translation_Hz", "rocking_Hz", "axial_Hz"):
        assert m[key] == pytest.approx(m0[key], rel=0.005)


def test_channel_copy_names_source_target_and_gain():
    _, truth, d = diagnosed("channel_copy")
    (u,) = d.unexplained
    src, dst, k = truth["copy"]
    assert (u.parameters["source"], u.parameters["target"]) == (src, dst) and u.channels == (dst,)
    assert u.parameters["gain"] == pytest.approx(k, rel=0.03)
    assert abs(u.parameters["phase_deg"]) < 3.0


def _one_line(kappa_of, law_of, n_runs=16, seed=0):
    """The Tx line h = 1 of ``n_runs`` runs at 5-50 Hz of spin, |X| = Ω²·law_of(Ω) with a random phase per run, and
    Tz = kappa_of(Ω)·Tx, 20-60 dB over Tz's noise: the keyword arguments of :func:`rwadist.diagnose.channel_copy._pair`."""
    rng = np.random.default_rng(seed)
    omega = 2 * np.pi * np.linspace(5.0, 50.0, n_runs)
    x_s = omega**2 * law_of(omega) * np.exp(2j * np.pi * rng.uniform(size=n_runs))
    x_t = kappa_of(omega) * x_s
    noise_t = np.full(n_runs, np.min(np.abs(0.3 * x_s)) ** 2 / 100.0)
    return dict(X_s=x_s, X_t=x_t, noise_t=noise_t, runs=np.arange(n_runs), h=np.ones(n_runs), cs="Tx", ct="Tz",
                omega=omega)


def test_one_line_copy_is_a_copy_only_when_the_target_follows_the_sources_departure_from_its_law():
    """One line at one complex ratio in every run: a copy when the source's line departs from C·Ω² (here through a
    rigid rotor's rocking whirl with I_zz/I_rr 2.2, 1/(1 + 1.2·(Ω/ω0)²), 0.99 -> 0.45) and the target follows it;
    not when the source keeps its law (a load of the wheel's own in a fixed phase to it, both ∝ Ω², cannot be told
    from a copy), nor when the ratio itself changes with the speed (the target's own transfer)."""
    from rwadist.diagnose.channel_copy import _pair

    w0 = 2 * np.pi * 50.0
    whirl = lambda om: 1.0 / (1.0 + 1.2 * (om / w0) ** 2)      # noqa: E731
    got = _pair(**_one_line(lambda om: 0.3 + 0.0j, whirl))
    assert got is not None and got.lines_h == (1.0,) and got.kappa == pytest.approx(0.3, rel=1e-6)
    assert _pair(**_one_line(lambda om: 0.3 + 0.0j, lambda om: np.ones_like(om))) is None
    assert _pair(**_one_line(lambda om: 0.3 / whirl(om), whirl)) is None


def test_one_line_in_a_fixed_phase_through_two_modes_is_no_copy():
    """One continuous record (a sweep's slices) keeps every line's phases: Fz's 1x line through an axial mode at
    90 Hz (1/(1 − (f/90)²): 3.2 dB over C·Ω² at 50 Hz) and Fx's, of the same rotor in a fixed phase to it, following
    only part of that departure through its own mode further up (the ratio ∝ law^−0.6, 1.9 dB over the speeds: within
    the cluster's ±15 %) is the wheel's own pair of loads, not a copy; the same line with the ratio constant is."""
    from rwadist.diagnose.channel_copy import _pair

    axial = lambda om: 1.0 / (1.0 - (om / (2 * np.pi * 90.0)) ** 2)     # noqa: E731
    assert _pair(**_one_line(lambda om: 0.3 * axial(om) ** -0.6 + 0.0j, axial)) is None
    got = _pair(**_one_line(lambda om: 0.3 + 0.0j, axial))
    assert got is not None and got.kappa == pytest.approx(0.3, rel=1e-6)
    # ... nor when the source's strongest line (5 x stronger, h 2) stands in the target at another ratio: a copy scales
    # every line alike (a ball-pass line of one rotor read in two directions above both their modes)
    one, other = _one_line(lambda om: 0.3 + 0.0j, axial), _one_line(lambda om: 0.05j + 0.0, axial, seed=1)
    both = {k: np.concatenate([one[k], other[k] * (5.0 if k in ("X_s", "X_t") else 1.0)])
            for k in ("X_s", "X_t", "noise_t", "runs", "omega")}
    n = one["X_s"].size
    both["X_t"][n:] = 0.1 * np.abs(both["X_s"][n:]) * np.exp(2j * np.pi * np.random.default_rng(2).uniform(size=n))
    both.update(h=np.concatenate([one["h"], 2.0 * other["h"]]), cs="Tx", ct="Tz")
    assert _pair(**both) is None
    both["X_s"][n:] /= 25.0                                                # now the copied line is the strongest
    both["X_t"][n:] /= 25.0
    # ... but a copy puts the source's other line in the target at κ too: Tz holding h 2 at a third of 0.3·Tx there
    # (a line of its own) is a load of its own in a fixed phase to Tx, not a copy (a new user's rotor of fixed phases
    # on a test stand: Fz's axial imbalance read as 0.096 × Fy, Fy's other lines in Fz at 0.0004-0.002 of that)
    assert _pair(**both) is None
    both["X_t"][n:] += 0.3 * both["X_s"][n:]                               # Tz holds the copy of h 2 as well
    assert _pair(**both) is not None


def test_lines_of_one_family_along_a_fixed_direction_are_no_copy():
    """Two ball-pass multiples (h 9.8, 13.1) read in Fz at 0.7 x Fx in every run, as a real force along a fixed x-z
    direction puts them (an outer-race impact train on the housing), are a copy only if Fz also holds 0.7 x Fx's
    strongest line: a crosstalk scales every component of its source.  Fx's imbalance line (30 x stronger) standing in
    Fz at 0.05 of it (Fz's own 1x line): no copy; the same data with Fz holding 0.7 x that line too (plus its own
    line, 0.05 of Fx's, at a phase of its own): a copy, κ 0.7."""
    from rwadist.diagnose.channel_copy import _pair

    rng = np.random.default_rng(4)
    n = 16
    omega = 2 * np.pi * np.linspace(15.0, 130.0, n)

    def phases():
        return np.exp(2j * np.pi * rng.uniform(size=n))

    fam = [omega**2 * 1e-3 * phases() for _ in range(2)]                  # the family's two lines in Fx
    one = omega**2 * 3e-2 * phases()                                       # Fx's imbalance line, 30 x stronger
    own = 0.05 * np.abs(one) * phases()                                    # Fz's own 1x line
    X_s = np.concatenate(fam + [one])
    h = np.concatenate([np.full(n, 9.8), np.full(n, 13.1), np.ones(n)])
    args = dict(X_s=X_s, noise_t=np.full(3 * n, np.min(np.abs(0.7 * X_s)) ** 2 / 1e3), runs=np.tile(np.arange(n), 3),
                h=h, cs="Fx", ct="Fz", omega=np.tile(omega, 3))
    assert _pair(X_t=np.concatenate([0.7 * f for f in fam] + [own]), **args) is None
    got = _pair(X_t=np.concatenate([0.7 * f for f in fam] + [0.7 * one + own]), **args)
    assert got is not None and abs(got.kappa - 0.7) < 0.02


def test_hump_where_it_is():
    _, truth, d = diagnosed("broadband_hump")
    (u,) = d.unexplained
    lo, hi = truth["hump_hz"]
    assert set(u.channels) <= {"Tx", "Ty", "Tz"} and len(u.channels) >= 2
    assert lo - 15 <= u.parameters["peak_Hz"] <= hi + 15 and u.f_Hz[0] < hi and u.f_Hz[1] > lo
    assert 5.0 <= u.level_dB <= 13.0


@pytest.mark.parametrize("kind", ["wide_hump", "rattle"])
def test_a_hump_wider_than_the_running_median_or_a_rattle_is_where_it_is(kind):
    _, truth, d = diagnosed(kind)
    (u,) = d.unexplained
    # the band-pass's corners lie within the hump; the rattle's ringing frequency at its peak (within 5 %)
    lo, hi = owc.WIDE_HUMP_HZ if kind == "wide_hump" else (0.95 * owc.RATTLE[0], 1.05 * owc.RATTLE[0])
    want = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz"} if kind == "wide_hump" else {"Fx", "Fy", "Tx", "Ty"}
    assert set(u.channels) == want
    assert lo <= u.parameters["peak_Hz"] <= hi
    assert u.f_Hz[0] < lo and u.f_Hz[1] > hi if kind == "wide_hump" else u.f_Hz[0] < owc.RATTLE[0] < u.f_Hz[1]
    # band-passed to the hump, noise has kurtosis 3; impacts ringing a resonance far more, and the rattle is named
    impacts = u.causes[0].startswith("impacts ringing a resonance")
    assert impacts == (kind == "rattle") and (u.parameters["kurtosis"] > 4.5) == impacts, u.parameters["kurtosis"]


def test_a_rattle_in_some_runs_is_described_in_those_runs_as_impacts():
    _, truth, d = diagnosed("rattle_some_runs")
    (u,) = d.unexplained
    assert u.parameters["in_every_run"] is False and set(u.channels) == {"Fx", "Fy", "Tx", "Ty"}
    assert u.parameters["run_speeds_rpm"] == pytest.approx(sorted(truth["rattle_rpm"]), rel=1e-6)
    assert u.f_Hz[0] < owc.RATTLE[0] < u.f_Hz[1] and abs(u.parameters["peak_Hz"] - owc.RATTLE[0]) < 35
    assert u.causes[0].startswith("impacts ringing a resonance at")


def test_a_line_off_both_axes_is_one_affine_line_at_its_offset_and_slope():
    _, truth, d = diagnosed("affine_line")
    (u,) = d.unexplained
    f0, b = owc.AFFINE
    assert set(u.channels) == {"Fz", "Tz"} and u.n_runs >= 18
    assert u.parameters["offset_Hz"] == pytest.approx(f0, abs=0.5)
    assert u.parameters["slope"] == pytest.approx(b, abs=0.01)
    assert u.causes[0].startswith(f"a source at {u.parameters['offset_Hz']:.4g} Hz")


def test_the_floors_lower_course_lets_a_monotone_floor_through_and_measures_a_hump_on_a_slope():
    from rwadist.diagnose.describe_hump import _lower_course

    f = np.linspace(1.0, 1000.0, 2001)
    one_over_f = -10 * np.log10(f)
    assert np.max(_lower_course(one_over_f, 0, f.size - 1)) == pytest.approx(0.0, abs=1e-9)
    roll_off = np.where(f < 800, 0.0, -40 * np.log10(f / 800))
    assert np.max(_lower_course(roll_off, 0, f.size - 1)) == pytest.approx(0.0, abs=1e-9)
    bump = 15.0 * np.exp(-0.5 * ((f - 500) / 120) ** 2)             # wider than an eighth of the band
    excess = _lower_course(one_over_f + bump, 0, f.size - 1)
    k = int(np.argmax(excess))
    # measured against the higher of the floors either side: the falling floor's left shoulder (about -22.5 dB, at
    # the bump's foot) against -27 + 15 dB at its centre
    assert f[k] == pytest.approx(500, abs=60) and 9.0 <= excess[k] <= 15.0


def test_narrow_line_metric_sees_the_fixed_lines_the_power_metric_hardly_does():
    """Three pickup lines 26 dB over the noise in their bins, in every channel and run: stripes a reviewer sees at
    once; the power-weighted metric moves little for what they are (the issue: 1.0 -> 1.1 × the clean level; here
    5.7 ×, the wheel's own data being very clean), the narrow-line one ten times more (59 ×)."""
    _, _, clean = diagnosed("clean")
    _, _, d = diagnosed("weak_fixed_lines")
    assert sorted(u.f_Hz[0] for u in d.unexplained) == pytest.approx(sorted(owc.FIXED_HZ), abs=0.1)
    power = d.error_after / clean.error_after
    narrow = d.contrast_error_after / clean.contrast_error_after
    assert narrow > 10.0 and narrow > 5.0 * power, (power, narrow)
    # the definition, from the data's and the model's PSDs summed into the bands afresh (numpy alone)
    ctx, st = d.ctx, d.state_after
    vals = []
    for c in ctx.channels:
        D = ctx.band_sums(ctx.sp.psd[c][ctx.runs])
        M = ctx.band_sums(ctx.predict(st, c, ctx.runs))
        sig = ctx.band_sigma(st, c, ctx.runs)
        vals.append(np.maximum(np.abs(D - M) - 3.0 * sig, 0.0) / np.maximum(D, M))
    assert d.contrast_error_after == pytest.approx(float(np.mean(np.concatenate(vals))), rel=1e-9)


def test_summary_report_and_console_carry_the_descriptions(tmp_path, capsys):
    from rwadist.cli import main
    from rwadist.data import write_steady

    test, _, _ = diagnosed("fixed_lines")
    data = write_steady(test, tmp_path / "data")
    out = tmp_path / "report"
    assert main(["diagnose", str(data), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert printed.count("  ? fixed_line: ") == 3 and "band-by-band misfit" in printed
    # the described lines are in no model: the console says the figures count them (trial12 read 77x as a bad model)
    assert "described above with ? is in no model: it counts in both figures" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert [u["signature"] for u in summary["unexplained"]] == ["fixed_line"] * 3
    # the band the metrics count, said once in each (the new-user trial of session 43 never read it): within the
    # records' band, and holding the lines (the fixed ones at 60-180 Hz)
    lo, hi = summary["band_Hz"]
    assert 0.0 <= lo < min(owc.FIXED_HZ) and max(owc.FIXED_HZ) < hi <= test.runs[0].sample_rate / 2
    assert f"diagnosed {len(test.runs)} runs over {lo:.3g}-{hi:.4g} Hz in " in printed
    assert f"- band analysed: {lo:.3g}-{hi:.4g} Hz" in (out / "report.md").read_text()
    assert summary["narrow_line_metric"] == "waterfall_band_contrast" and summary["narrow_line_error_after"] > 0
    md = (out / "report.md").read_text()
    assert "## Unexplained residual" in md and md.count("**fixed_line**") == 3
    assert (out / "residual_waterfall.png").stat().st_size > 10_000


def test_bearing_ratios_name_the_lines_within_the_resolution():
    """The E wheel's radial line h = 4.42 is the outer-race ball pass of a 10-ball bearing with d/D = 0.116 (n/2·(1 −
    d/D) = 4.42); named from that geometry, and from the ranges and the lines' relations without it."""
    from rwadist.bearings import Bearing
    from rwadist.diagnose.describe import line_causes
    from rwadist.diagnose.describe_lines import ratio_resolution

    _, _, d = diagnosed("clean")
    b = Bearing(10, 0.116, 1.0, name="front")
    got = {(x["direction"], round(x["h"], 2)): x for x in line_causes(d, [b])}
    hit = got[("radial_force", 4.42)]
    assert hit["source"] == "base" and any("BPFO" in c and "'front'" in c for c in hit["causes"])
    res = ratio_resolution(d.ctx)
    assert 0.001 < res < 0.05
    # without geometry: 4.42 + 5.58 (radial torque) = 10, an outer/inner pair (cage 0.442, in the cage's range)
    plain = line_causes(d)
    assert any("10-ball" in c and "pair" in c for x in plain for c in x["causes"])
    # an integer harmonic is never given a bearing cause; an axial-torque one gets a motor's ripple (rwadist.motor)
    whole = [x for x in plain if abs(x["h"] - round(x["h"])) <= 2 * res]
    assert all(x["direction"] == "axial_torque" and all("motor" in c for c in x["causes"]) for x in whole), whole


def test_a_line_with_co_and_counter_rotating_parts_is_named_once():
    """A line that holds a co- and a counter-rotating part is two harmonics at one h in the model file; report.md's
    causes list it once (session 6 listed it twice)."""
    import copy
    import dataclasses

    from rwadist.bearings import Bearing
    from rwadist.diagnose.describe import line_causes

    _, _, d = diagnosed("clean")
    d2 = copy.deepcopy(d)
    lines = d2.model.empirical["radial_force"]
    i = next(k for k, x in enumerate(lines) if abs(x.h - 4.42) < 0.01)
    co = dataclasses.replace(lines[i], sense="co", C=0.7 * lines[i].C)
    lines[i:i + 1] = [co, dataclasses.replace(co, sense="counter", C=0.3 * lines[i].C)]
    got = [(x["direction"], round(x["h"], 2)) for x in line_causes(d2, [Bearing(10, 0.116, 1.0)])]
    assert got.count(("radial_force", 4.42)) == 1, got
    assert len(got) == len(set(got)), got


def test_bearings_from_the_flag_and_the_model_file(tmp_path, capsys):
    from rwadist import model as model_io
    from rwadist.cli import main
    from rwadist.data import write_steady
    from rwadist.model import ModelFileError
    from rwadist.presets import preset

    doc = model_io.to_json(preset("ithaco-e").to_model())
    doc["wheel"] = {**doc["wheel"], "bearings": [{"balls": 9, "ball_diameter_m": 0.05, "pitch_diameter_m": 0.04}]}
    with pytest.raises(ModelFileError, match=r"wheel.bearings\[0\].ball_diameter_m"):
        model_io.from_json(doc, "m.json")
    doc["wheel"]["bearings"][0]["ball_diameter_m"] = 0.005
    assert model_io.from_json(doc, "m.json").wheel["bearings"][0]["balls"] == 9
    test, _, _ = diagnosed("clean")
    data = write_steady(test, tmp_path / "data")
    assert main(["diagnose", str(data), "-o", str(tmp_path / "r"), "--bearing", "balls=10,ball_diameter_m=0.1"]) == 2
    assert "--bearing: bearing 1.pitch_diameter_m: missing" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


@pytest.mark.slow
@pytest.mark.parametrize("kind,signature", [("pickup", "fixed_line"), ("crosstalk", "channel_copy")])
def test_the_new_wheel_of_the_family_on_the_command_line(kind, signature, tmp_path):
    """The issue's new wheel (tests/family_wheel.py #0: 4.2 kg, I_zz/I_rr 1.56, modes 310/95/140 Hz, 600-6000 rpm,
    5 kHz) with the family's own unknown kinds (tests/family_effects.py: 50/100/150/250 Hz pickup; Fz carrying 0.2 ×
    Fy), written to the interchange format and diagnosed as a user types it: described by their signature, no class
    beside the wheel's modes (a notch the search fitted at the pickup's 100 Hz in the runs where a wheel line hides
    it is taken back), the modes within 1 % of the truth."""
    import family_effects as fe
    import family_wheel as fw

    from rwadist.cli import main

    wheel = fw.family()[0]
    data = fw.steady(wheel, noise=0.01, seed=0, effects=[fe.default_effect(kind, wheel)])
    path = fw.write_steady(data, tmp_path / "data", wheel.name)
    assert main(["diagnose", str(path), "-o", str(tmp_path / "r")]) == 0
    summary = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert [e["kind"] for e in summary["effects"]] == ["suspension_modes"]
    assert {u["signature"] for u in summary["unexplained"]} == {signature}
    modes = summary["effects"][0]
    for key, truth in (("radial_translation_Hz", 310.0), ("rocking_Hz", 95.0), ("axial_Hz", 140.0)):
        assert modes[key] == pytest.approx(truth, rel=0.01)


def test_run_change_flags_the_switched_runs_and_not_a_resonance_crossing():
    """Lines' measured-over-predicted ratios (dB) of 21 runs: every third run 3.5 dB up on all its lines (a range
    switched) is a run_change of exactly those runs; one line lifted 8 dB in one run (a resonance crossing it) and
    a smooth trend with speed are not."""
    from types import SimpleNamespace

    from rwadist.diagnose.describe_structure import LineRatios, run_change

    R, L = 21, 4
    spin = np.linspace(5.0, 50.0, R)
    run, line = np.tile(np.arange(R), L), np.repeat(np.arange(L), R)
    q = 0.02 * spin[run] + 0.01 * np.sin(3.0 * run + line)             # a smooth trend and a little scatter
    q[(line == 2) & (run == 10)] += 8.0                                   # one line through a resonance
    ctx = SimpleNamespace(runs=np.arange(R), omega=2 * np.pi * spin, channels=("Fx", "Fy"), test=None,
                          sp=SimpleNamespace(run_names=[f"run_{i}" for i in range(R)]))

    def ratios(q):
        return [LineRatios("radial_force", q, spin[run] * (line + 1), run, spin[run], line, line + 1.0,
                           np.ones(run.size))]

    shares = lambda runs: (0.5, 1.0)                                      # noqa: E731
    assert run_change(ctx, ratios(q), shares) == []
    stepped = run % 3 == 1
    (u,) = run_change(ctx, ratios(q + 3.5 * stepped), shares)
    assert sorted(u.parameters["runs"]) == sorted(f"run_{i}" for i in range(R) if i % 3 == 1)
    assert u.level_dB == pytest.approx(3.5, abs=0.1)
    # one factor on a few runs, the others on their trend: a step, its causes (a re-mounting, a range) first
    assert u.parameters["pattern"] == "step" and "re-mounted" in u.causes[0]
    # the words carry the step's sign: every changed run up reads "+", down "−", both ways "±"
    assert u.strength().startswith("the changed runs +3.") and "±" not in u.text()
    (d,) = run_change(ctx, ratios(q - 3.5 * stepped), shares)
    assert d.strength().startswith("the changed runs −3.") and d.level_dB == pytest.approx(3.5, abs=0.1)
    # re-mountings going opposite ways (runs 1, 7, 13, 19 +3.5 dB; 4, 10, 16 -3.5 dB), the others on trend: a step
    (s,) = run_change(ctx, ratios(q + 3.5 * (run % 6 == 1) - 3.5 * (run % 6 == 4)), shares)
    assert len(s.parameters["runs"]) == 7
    assert s.parameters["pattern"] == "step" and "re-mounted" in s.causes[0]
    assert s.strength().startswith("the changed runs ±3.")
    # the runs recorded in shuffled speed order, the gain drifting 0.15 dB a run: a spread, the drift named first
    order = np.random.default_rng(3).permutation(R)
    (v,) = run_change(ctx, ratios(q + 0.15 * order[run]), shares)
    assert v.parameters["pattern"] == "spread" and "drifting" in v.causes[0]


def test_run_change_offsets_with_the_top_run_switched():
    """20 runs, every third one from the second 3.5 dB up (the top run among them): the lines' trends are made again
    without the switched runs, so each reads its own 3.5 dB and its unswitched neighbours are not set apart (the
    top run's window held two switched runs: it read 1.75 dB and its two neighbours -1.3 and -0.9 dB)."""
    from types import SimpleNamespace

    from rwadist.diagnose.describe_structure import LineRatios, run_change

    R, L = 20, 5
    spin = np.linspace(10.0, 100.0, R)
    run, line = np.tile(np.arange(R), L), np.repeat(np.arange(L), R)
    q = 0.03 * spin[run] - 0.5 * line + 0.01 * np.sin(3.0 * run + line) + 3.5 * (run % 3 == 1)
    ctx = SimpleNamespace(runs=np.arange(R), omega=2 * np.pi * spin, channels=("Fx", "Fy"), test=None,
                          sp=SimpleNamespace(run_names=[f"run_{i}" for i in range(R)]))
    ratios = [LineRatios("radial_force", q, spin[run] * (line + 1), run, spin[run], line, line + 1.0, np.ones(run.size))]
    (u,) = run_change(ctx, ratios, lambda runs: (0.5, 1.0))
    assert u.parameters["runs"] == [f"run_{i}" for i in range(R) if i % 3 == 1]
    assert np.allclose(u.parameters["run_offsets_dB"], 3.5, atol=0.05)


@pytest.mark.slow
def test_switched_runs_taken_out_and_searched_again(tmp_path):
    """Family wheel 0 (tests/family_wheel.py: 4.2 kg, modes 310/95/140 Hz, 20 speeds 600-6000 rpm, 8192 samples at
    5 kHz) with every third run re-mounted 3.5 dB stronger (benchmarks/diagnose_open_world.py ``remount_step``), the
    default path: left in the records, the changed runs kept the modes from being located and a test-stand resonance
    (317 Hz, gain 7.5) was fitted to them.  The search is run again with the described runs' factor taken out: the
    wheel's modes within 1 % of the truth and nothing else added; the run change described on the data as given,
    the switched runs only, each 3.5 dB (the generator's step) within 0.2 dB."""
    from dataclasses import replace

    import family_wheel as fw

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import diagnose_open_world as ow

    wheel = replace(fw.family()[0], n_speeds=20, n_samples=8192)
    speeds = np.linspace(wheel.min_rpm, wheel.max_rpm, 20)
    step = ow.RemountStep()
    data = fw.steady(wheel, speeds_rpm=speeds, noise=0.01, seed=0, effects=[step])
    d = api.diagnose(fw.write_steady(data, tmp_path / "data", wheel.name))
    assert [e["kind"] for e in d.model.effects] == ["suspension_modes"]
    modes = d.model.effects[0]
    for key, truth in (("radial_translation_Hz", 310.0), ("rocking_Hz", 95.0), ("axial_Hz", 140.0)):
        assert modes[key] == pytest.approx(truth, rel=0.01)
    (u,) = [u for u in d.unexplained if u.signature == "run_change"]
    switched = {f"run_{i:04d}.csv" for i in range(20) if step.stepped(i)}
    assert set(u.parameters["runs"]) <= switched and len(u.parameters["runs"]) >= len(switched) - 1
    assert np.allclose(u.parameters["run_offsets_dB"], step.step_db, atol=0.2)


def test_a_weak_line_ridge_read_at_its_ratio_on_the_whole_records():
    """A line at h 9.1394 too weak for a Welch peak (0.5 x the noise std in amplitude: 1-2 dB over the floor in a
    Welch bin), 12 runs 300-3000 rpm of 4096 samples at 2 kHz: started 0.045 off (the ridge's lit bins are as wide
    as a Welch bin at the lowest speeds), the whole records put it within a tenth of their resolution of the truth."""
    from rwadist.data import Run, SteadyTest
    from rwadist.diagnose.describe_lines import _record_h, ratio_resolution
    from rwadist.diagnose.engine import Context
    from rwadist.spectra import compute_spectra

    rng = np.random.default_rng(3)
    fs, n, h_true = 2000.0, 4096, 9.1394
    t = np.arange(n) / fs
    runs = []
    for rpm in np.linspace(300.0, 3000.0, 12):
        f = h_true * rpm / 60.0
        ph = rng.uniform(0, 2 * np.pi)
        sig = {"Fx": 0.5 * np.cos(2 * np.pi * f * t + ph) + rng.standard_normal(n),
               "Fy": 0.5 * np.sin(2 * np.pi * f * t + ph) + rng.standard_normal(n)}
        runs.append(Run(speed=rpm * 2 * np.pi / 60.0, sample_rate=fs, signals=sig, t0=0.0, name=f"r{rpm:g}"))
    test = SteadyTest(runs=runs, meta={})
    ctx = Context(compute_spectra(test, nperseg=1024), ("Fx", "Fy"), test)
    res = ratio_resolution(ctx)
    for start in (h_true - 0.045, h_true + 0.04):
        assert abs(_record_h(ctx, ["Fx", "Fy"], ctx.runs, start) - h_true) < 0.1 * res


def _lines_through(spin_hz, hs, gain_db):
    """The :class:`LineRatios` of radial-force lines ``hs`` at ``spin_hz`` whose measured/predicted ratio (dB) is
    ``gain_db(f)`` plus each line's own offset (a C fitted off by the resonances), with 0.05 dB of scatter."""
    from rwadist.diagnose.describe_structure import LineRatios

    rng = np.random.default_rng(5)
    spin, h = np.meshgrid(spin_hz, hs)
    line = np.meshgrid(spin_hz, np.arange(len(hs)))[1].ravel()
    f = (h * spin).ravel()
    q = gain_db(f, spin.ravel()) + rng.normal(0.0, 1.0, len(hs))[line] + rng.normal(0.0, 0.05, f.size)
    return LineRatios("radial_force", q, f, np.tile(np.arange(spin_hz.size), len(hs)), spin.ravel(), line,
                      h.ravel(), np.full(f.size, 1e4))


def _transmissibility_db(f, f_n, zeta):
    r = f / f_n
    return 20 * np.log10(np.abs((1 + 2j * zeta * r) / (1 - r**2 + 2j * zeta * r)))


def _softening_db(f, spin, f0=420.0, drop=0.4, spin_max=100.0, zeta=0.03, gain=5.0):
    r = f / (f0 * (1 - drop * spin / spin_max))
    return 20 * np.log10(np.abs((1 - r**2 + 2j * gain * zeta * r) / (1 - r**2 + 2j * zeta * r)))


def test_a_moving_resonance_beside_a_mode_the_model_lacks_is_described():
    """Radial-force lines (h 0.37, 1, 2, 3, 5.67; 16 speeds to 6000 rpm) lifted by a translation mode the model lacks
    (520 Hz, ζ 0.02: the wheel's suspension modes not fitted) and by a resonance softening with speed (f_r = 420 ×
    (1 − 0.4 Ω/Ω_max), ζ 0.03, peak gain 5): the moving one is described, falling through its true frequencies, the
    fixed one beside it named; the mode alone is no moving resonance; the moving one alone is found alone."""
    from types import SimpleNamespace

    from rwadist.diagnose.describe_structure import moving_resonance

    spin = np.linspace(10.0, 100.0, 16)
    hs = (0.37, 1.0, 2.0, 3.0, 5.67)
    ctx, state = SimpleNamespace(channels=("Fx", "Fy")), SimpleNamespace(effects=[])

    def described(gain_db):
        return moving_resonance(ctx, state, [_lines_through(spin, hs, gain_db)], lambda *a: (0.0, 0.0))

    both = described(lambda f, s: _transmissibility_db(f, 520.0, 0.02) + _softening_db(f, s))
    assert len(both) == 1 and both[0].channels == ("Fx", "Fy")
    p = both[0].parameters
    assert p["slope_Hz_per_Hz_of_spin"] < 0
    assert p["f_at_lowest_speed_Hz"] == pytest.approx(420 * (1 - 0.4 * 0.1), rel=0.1)
    assert p["f_at_highest_speed_Hz"] == pytest.approx(420 * 0.6, rel=0.1)
    assert p["beside_fixed_resonance_Hz"] == pytest.approx(520.0, rel=0.05)
    assert described(lambda f, s: _transmissibility_db(f, 520.0, 0.02)) == []
    alone = described(lambda f, s: _softening_db(f, s))
    assert len(alone) == 1 and "beside_fixed_resonance_Hz" not in alone[0].parameters


def test_an_effect_a_later_one_needs_is_not_taken_back_alone():
    """Taking an effect back re-applies the others in their order; when one of them cannot be applied without it (a
    counter_rotation splitting a line the taken-back effect made), :func:`take_back.without` says so (None) instead of
    raising: a 60-s run-up of family wheel 7 ended diagnose with an internal error there."""
    from rwadist.diagnose.take_back import without as _without

    class Add:
        def __init__(self, name, needs=None):
            self.name, self.needs = name, needs

        def apply(self, state):
            if self.needs is not None and self.needs not in state:
                raise ValueError(f"no {self.needs} in the state")
            return state + (self.name,)

    a, b, c = Add("a"), Add("b"), Add("c", needs="b")
    assert _without((), [a, b, c], a) == ("b", "c")
    assert _without((), [a, b, c], c) == ("a", "b")
    assert _without((), [a, b, c], b) is None


def test_a_moving_resonance_between_sparse_runs_is_described():
    """16 runs 1000-10000 rpm, radial-force lines h 1 and 3.55 through a resonance softening with speed (f_r = 330 ×
    (1 − 0.4 Ω/Ω_max) Hz, ζ 0.03, peak gain 5; family wheel 7's open-world cell): the line h 3.55 moves ~56 Hz from
    run to run past a resonance 20 Hz wide, so it is lifted 13 dB in one run only, the others 2-3 dB (h 1 near the
    top speed): described, falling through its true frequencies."""
    from types import SimpleNamespace

    from rwadist.diagnose.describe_structure import LineRatios, moving_resonance

    spin = np.linspace(1000.0, 10000.0, 16) / 60.0
    hs = (1.0, 3.55)
    s, h = np.meshgrid(spin, hs)
    line = np.repeat(np.arange(len(hs)), spin.size)
    f = (h * s).ravel()
    q = _softening_db(f, s.ravel(), f0=330.0, spin_max=spin.max()) + np.random.default_rng(5).normal(0, 0.05, f.size)
    assert np.sum(q >= 3.0) == 1                                             # the case: one run lifted by much
    r = LineRatios("radial_force", q, f, np.tile(np.arange(spin.size), len(hs)), s.ravel(), line, h.ravel(),
                   np.full(f.size, 1e4))
    (u,) = moving_resonance(SimpleNamespace(channels=("Fx", "Fy")), SimpleNamespace(effects=[]), [r],
                            lambda *a: (0.0, 0.0))
    p = u.parameters
    assert p["slope_Hz_per_Hz_of_spin"] < 0 and u.channels == ("Fx", "Fy")
    assert p["f_at_lowest_speed_Hz"] == pytest.approx(330.0 * (1 - 0.4 * 0.1), rel=0.05)
    assert p["f_at_highest_speed_Hz"] == pytest.approx(330.0 * 0.6, rel=0.05)


def test_runs_whose_change_is_not_read_are_left_out_of_the_second_search():
    """20 runs, every third one from the second 3.5 dB up, the four slowest with no line over the noise (the 442-rpm
    run of family wheel 2 among them, switched and unread: left in, it put I_zz/I_rr at 2.5 and an amplitude law was
    added): the run change lists them as not read, :func:`run_steps` gives them NaN, and :func:`describe.start`
    leaves them out of the context the search reads (kept in the one the residual is described on) while the read
    runs are divided by their offsets."""
    from types import SimpleNamespace

    from rwadist.diagnose import describe
    from rwadist.diagnose.describe_structure import LineRatios, run_change
    from rwadist.diagnose.engine import Context
    from rwadist.spectra import compute_spectra

    R, L = 20, 5
    spin = np.linspace(5.0, 50.0, R)
    run, line = np.tile(np.arange(R), L), np.repeat(np.arange(L), R)
    q = 0.03 * spin[run] - 0.5 * line + 0.01 * np.sin(3.0 * run + line) + 3.5 * (run % 3 == 1)
    read = run >= 4
    names = [f"run_{i}" for i in range(R)]
    ctx = SimpleNamespace(runs=np.arange(R), omega=2 * np.pi * spin, channels=("Fx", "Fy"), test=None,
                          sp=SimpleNamespace(run_names=names))
    ratios = [LineRatios("radial_force", q[read], spin[run[read]] * (line[read] + 1), run[read], spin[run[read]],
                         line[read], line[read] + 1.0, np.ones(read.sum()))]
    (u,) = run_change(ctx, ratios, lambda runs: (0.5, 1.0))
    assert u.parameters["runs"] == [f"run_{i}" for i in range(4, R) if i % 3 == 1]
    assert u.parameters["runs_not_read"] == names[:4]

    test, _ = owc.generate("clean", np.linspace(300.0, 3000.0, R), n_samples=1024, seed=1)
    test = owc.with_runs(test, [_renamed(r, n) for r, n in zip(test.runs, names)])
    whole = Context(compute_spectra(test, nperseg=256), None, test)
    diag = SimpleNamespace(ctx=whole, unexplained=[u], hypotheses=[], state_after=SimpleNamespace(effects=[]),
                           model_given=False)
    steps = describe.run_steps(diag)
    assert [r for r, dB in steps.items() if np.isnan(dB)] == [0, 1, 2, 3]
    opened = describe.start(whole, steps)
    assert opened.ctx.runs.size == R - 4 and opened.whole is not None and opened.whole.runs.size == R
    scaled = opened.whole.test.runs[7].signals["Fx"] / test.runs[7].signals["Fx"]
    assert np.allclose(scaled, 10 ** (-steps[7] / 20))


def _renamed(run, name):
    from dataclasses import replace

    return replace(run, name=name)


def test_a_line_in_every_third_run_only_is_described_as_partial_and_not_forced_into_a_class():
    """A radial-force line at h 2.7 present in every third run only (tests/open_world_cases.py ``partial_line``): the
    base fitted from the data holds it at the strength of the runs that have it, so the others show it far over the
    data.  It is described (``partial_line``: the runs without it among the generator's, those with it among the
    generator's, interleaved), and no class is added for it.  On e91bc1c it was in the base, described nowhere (an
    independent trial wheel, h 2.7 in 10 of 30 runs, found it so)."""
    test, truth, d = diagnosed("partial_line")
    assert _classes(d) == ["suspension_modes"], [u.text() for u in d.unexplained]
    (u,) = [u for u in d.unexplained if u.signature == "partial_line"]
    assert u.h == pytest.approx(truth["partial_line"][0], abs=0.01)
    assert u.parameters["direction"] == "radial_force" and u.parameters["interleaved"] is True
    with_line = set(truth["partial_runs"])
    assert set(u.parameters["runs_present"]) <= with_line
    assert not set(u.parameters["runs_absent"]) & with_line
    assert len(u.parameters["runs_absent"]) >= 5 and u.level_dB <= -10.0
    assert "partial_line" in u.text() and "absent" in u.text()
    assert "scatter_dB" not in u.parameters and u.causes[0].startswith("an intermittent source")


@pytest.mark.parametrize("seed", [8])
def test_a_line_of_random_strength_is_described_as_scattering_not_as_coming_and_going(seed):
    """A radial-force line at h 2.3 in every run, its strength lognormal from run to run (8 dB; the new-user
    generator's wheel 2): it reads from far under to far over the model, most runs neither absent nor present.  Its
    record says how much it scatters, and its first cause is a strength not locked to the speed, not a source that
    comes and goes.  (Its scatter still outweighs the other lines' departures from C·Ω² in the mode fit on this
    wheel, whose broad translation (227.6 Hz, ζ 0.17) it can leave unlocated, and what that leaves is described as a
    moving resonance: not asserted here; see the closing notes of session 45.)"""
    from scipy import stats

    amp = 10 ** (stats.norm.rvs(size=len(SPEEDS), scale=8.0, random_state=seed) / 20)

    def scatter(i, r, t, std, rng):
        f_line = 2.3 * abs(r.speed) / (2 * np.pi)
        a = 30.0 * std["Fx"] * amp[i] * (abs(r.speed) / (2 * np.pi * 50.0)) ** 2     # C·Ω², 3000 rpm at the top
        r.signals["Fx"] = r.signals["Fx"] + a * np.cos(2 * np.pi * f_line * t)
        r.signals["Fy"] = r.signals["Fy"] + a * np.sin(2 * np.pi * f_line * t)

    _, d = _with(change=scatter)
    (u,) = [u for u in d.unexplained if u.signature == "partial_line" and abs(u.h - 2.3) < 0.01]
    assert u.parameters["scatter_dB"] >= 4.0 and u.causes[0].startswith("a source whose strength is not locked")
    assert "scattering" in u.text()


def test_a_true_law_on_a_neighbour_of_a_partial_line_is_not_taken_back_with_it(monkeypatch):
    """The independent E wheel with its radial-force 3× line on an Ω^3.5 law (each run's 3× line of the generator
    scaled by (Ω/Ω_mid)^1.5) and a partial line at h 2.4 in every third run (tests/open_world_cases.py ``partial_line``):
    the law on 3× is a class the search finds (Ω^3.50), the partial line is described.  The partial line's cells are
    its own band: with the bands either side (3 × 30 Hz wide), the true law on 3×, 0.6·Ω/2π away, was taken back with
    the law the search fitted to the partial line (error after 0.0035 -> 0.053, nothing describing the 3× law)."""
    from dataclasses import replace

    iw, p_true = owc.iw, 3.5
    generate = iw.generate

    def with_law(speeds_rpm, sample_rate=3840.0, n_samples=8192, noise=0.01, seed=0, lines=iw.E_LINES,
                 co_fraction=None):
        law = [ln for ln in lines if ln[0] == "radial_force" and ln[1] == 3.0]
        test, tr = generate(speeds_rpm, sample_rate, n_samples, noise, seed, [ln for ln in lines if ln not in law],
                            co_fraction)
        ones = [(d, 1.0, 0.0, 1.0) for d in ("radial_force", "radial_torque")]         # (no power: the 3× alone)
        only, _ = generate(speeds_rpm, sample_rate, n_samples, 0.0, seed + 1, law + ones, co_fraction)
        om = np.array([r.speed for r in test.runs])
        mid = np.sqrt(om.min() * om.max())
        runs = [replace(a, signals={c: a.signals[c] + (a.speed / mid) ** (p_true - 2) * b.signals[c] for c in a.signals})
                for a, b in zip(test.runs, only.runs)]
        return replace(test, runs=runs), tr

    monkeypatch.setattr(iw, "generate", with_law)
    monkeypatch.setattr(owc, "PARTIAL_LINE", (2.4, 0.08))
    test, truth = owc.generate("partial_line", SPEEDS, seed=4)
    d = api.diagnose(test)
    laws = [e for e in d.model.effects if e["kind"] == "amplitude_law"]
    assert [round(e["h"], 2) for e in laws] == [3.0], [u.text() for u in d.unexplained]
    assert laws[0]["exponent"] == pytest.approx(p_true, abs=0.05)
    (u,) = [u for u in d.unexplained if u.signature == "partial_line"]
    assert u.h == pytest.approx(2.4, abs=0.01)
    assert not set(u.parameters["runs_absent"]) & set(truth["partial_runs"])


# ---- session 44's review: the cases that broke the first version of the hump and affine-line detectors
def _noise_std(test):
    """The generator's white-noise std per channel (tests/open_world_cases.py: 0.01 of the top-speed fundamental)."""
    import independent_wheel as iw

    w_top = max(abs(r.speed) for r in test.runs)
    fund = {g: c * iw.C_UNIT * w_top**2 for g, c in zip("FT", owc._noise_std(iw.E_LINES).values())}
    return {ch: 0.01 * fund[ch[0]] for ch in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}


def _with(kind="clean", noise=0.01, change=None):
    test, truth = owc.generate(kind, SPEEDS, seed=4, noise=noise)
    rng = np.random.default_rng(7)
    std = _noise_std(test)
    for i, r in enumerate(test.runs):
        t = np.arange(r.signals["Fz"].size) / r.sample_rate
        change(i, r, t, std, rng)
    return test, api.diagnose(test)


def test_hot_runs_in_two_groups_far_apart_are_two_groups_and_the_loop_ends():
    from rwadist.diagnose.describe_hump import _run_groups

    peaks = np.array([100, 103, 900, 905, 500])
    groups = _run_groups(peaks, np.array([0, 1, 2, 3]), near=20.0)          # the median (501.5) lies in the gap
    assert sorted(sorted(g.tolist()) for g in groups) == [[0, 1], [2, 3]]
    assert [g.tolist() for g in _run_groups(peaks, np.array([4]), near=20.0)] == [[4]]


def test_a_floor_through_a_high_pass_and_an_anti_alias_filter_is_no_hump():
    from scipy import signal

    sos = None

    def floor(i, r, t, std, rng):
        nonlocal sos
        if sos is None:
            sos = np.vstack([signal.butter(8, 1500.0, "lowpass", fs=r.sample_rate, output="sos"),
                             signal.butter(2, 20.0, "highpass", fs=r.sample_rate, output="sos")])
        for ch in r.signals:
            r.signals[ch] = r.signals[ch] + std[ch] * signal.sosfilt(sos, rng.standard_normal(t.size + 4096))[4096:]

    _, d = _with(noise=1e-9, change=floor)
    assert _classes(d) == ["suspension_modes"] and d.unexplained == (), [u.text() for u in d.unexplained]


@pytest.mark.parametrize("f_tone", [215.0, 300.0])
def test_a_tone_in_the_fastest_runs_is_a_fixed_line_there_and_no_hump_or_moving_resonance(f_tone):
    """A tone in Fz over the top five of twenty runs (from 2432 rpm): one fixed line from there up, at its frequency.
    At 215 Hz it lifted one model line in the two fastest runs and a moving resonance was fitted through them (its
    leakage, :func:`~rwadist.diagnose.describe_structure.without_line_leaks`); at 300 Hz it was taken for the radial
    translation mode (ζ 0.17, 76 Hz away), which does not move Fz; both times five runs were too few for a block."""
    def tone(i, r, t, std, rng):
        if abs(r.speed) * 30 / np.pi >= 2300:
            r.signals["Fz"] = r.signals["Fz"] + 5.0 * std["Fz"] * np.cos(2 * np.pi * f_tone * t + rng.uniform(0, 6.3))

    test, d = _with(change=tone)
    texts = [u.text() for u in d.unexplained]
    assert [u.signature for u in d.unexplained] == ["fixed_line"] and _classes(d) == ["suspension_modes"], texts
    u = d.unexplained[0]
    first = min(abs(r.speed) * 30 / np.pi for r in test.runs if abs(r.speed) * 30 / np.pi >= 2300)
    assert u.channels == ("Fz",) and u.f_Hz[0] == pytest.approx(f_tone, abs=0.5) and u.n_runs == 5
    assert u.speed_rpm[0] == pytest.approx(first) and u.parameters["peak_over_model_dB"] > 20.0


def test_an_affine_line_among_the_radial_lines_is_described_and_no_moving_resonance():
    """60 Hz + 1.3·f_spin on Fx and Fy, through the E-like wheel's radial lines: 3.5 dB over the model in its bands
    (their lines beside it), +34 dB at its own bins; it was passed over and a moving resonance of slope 3.1 was fitted
    to the lines its leakage lifted."""
    def affine(i, r, t, std, rng):
        f_line = 60.0 + 1.3 * abs(r.speed) / (2 * np.pi)
        for ch in ("Fx", "Fy"):
            r.signals[ch] = r.signals[ch] + 5.0 * std[ch] * np.cos(2 * np.pi * f_line * t + rng.uniform(0, 6.3))

    _, d = _with(change=affine)
    assert [u.signature for u in d.unexplained] == ["affine_line"], [u.text() for u in d.unexplained]
    u = d.unexplained[0]
    assert set(u.channels) == {"Fx", "Fy"} and _classes(d) == ["suspension_modes"]
    assert u.parameters["offset_Hz"] == pytest.approx(60.0, abs=1.0)
    assert u.parameters["slope"] == pytest.approx(1.3, abs=0.02)


def test_a_moving_resonance_is_a_narrow_lines_leakage_only_when_that_line_stands_far_above_its_lifts():
    from rwadist.diagnose.describe_structure import without_line_leaks
    from rwadist.diagnose.unexplained import Unexplained

    rpm = np.array([1000.0, 1500.0, 2000.0])
    moving = Unexplained(signature="moving_resonance", channels=("Fx", "Fy"), speed_rpm=(1000.0, 2000.0),
                         f_Hz=(80.0, 120.0), level_dB=0.0, share=0.1, n_runs=3,
                         parameters={"largest_line_lift_dB": 6.0, "lifted_rpm": rpm.tolist(),
                                     "lifted_Hz": (60.0 + 1.3 * rpm / 60.0 + [1.0, -9.0, 30.0]).tolist()})

    def line(peak, chans=("Fx", "Fy")):
        return Unexplained(signature="affine_line", channels=chans, speed_rpm=(300.0, 3000.0), f_Hz=(66.5, 125.0),
                           level_dB=3.0, share=0.1, n_runs=20,
                           parameters={"offset_Hz": 60.0, "slope": 1.3, "peak_over_model_dB": peak})

    # two of three lifted lines within 4 bins (3.75 Hz) of a line 28 dB over the model: its leakage
    assert without_line_leaks([moving, line(34.0)], 3.75) == [line(34.0)]
    # a line no higher than the lifts (a resonance's own hump read as a line), on other channels, or farther: kept
    assert len(without_line_leaks([moving, line(10.0)], 3.75)) == 2
    assert len(without_line_leaks([moving, line(34.0, ("Fz",))], 3.75)) == 2
    assert len(without_line_leaks([moving, line(34.0)], 1.0)) == 2


def test_an_affine_line_and_a_fixed_line_it_crosses_are_both_described():
    def both(i, r, t, std, rng):
        f_line = 150.0 + 1.5 * abs(r.speed) / (2 * np.pi)
        for ch in ("Fz", "Tz"):
            r.signals[ch] = r.signals[ch] + 5.0 * std[ch] * np.cos(2 * np.pi * f_line * t + rng.uniform(0, 6.3))
        r.signals["Fz"] = r.signals["Fz"] + 5.0 * std["Fz"] * np.cos(2 * np.pi * 190.0 * t + rng.uniform(0, 6.3))

    _, d = _with(change=both)
    sig = sorted(u.signature for u in d.unexplained)
    assert sig == ["affine_line", "fixed_line"], [u.text() for u in d.unexplained]
    fixed = next(u for u in d.unexplained if u.signature == "fixed_line")
    assert fixed.f_Hz[0] == pytest.approx(190.0, abs=0.5)


def test_a_line_below_a_multiple_of_the_speed_is_read_with_its_negative_offset():
    """f = 3·f_spin − 40 Hz on Fz and Tz (a drive's lower side): a shallower track through more runs, refused as a
    speed line, had claimed its stretches first and two speed lines were described instead."""
    def lower(i, r, t, std, rng):
        f_line = abs(3.0 * abs(r.speed) / (2 * np.pi) - 40.0)
        for ch in ("Fz", "Tz"):
            r.signals[ch] = r.signals[ch] + 5.0 * std[ch] * np.cos(2 * np.pi * f_line * t + rng.uniform(0, 6.3))

    _, d = _with(change=lower)
    affine = [u for u in d.unexplained if u.signature == "affine_line"]
    assert len(affine) == 1, [u.text() for u in d.unexplained]
    assert affine[0].parameters["offset_Hz"] == pytest.approx(-40.0, abs=1.5)
    assert affine[0].parameters["slope"] == pytest.approx(3.0, abs=0.03)
    # below a multiple of the speed, the ratio rises with it (b + f0/f_spin, f0 < 0): no "falls"
    assert any("rises as" in c for c in affine[0].causes) and not any("falls as" in c for c in affine[0].causes)


# ---- session 45's independent trial (a 6-kg wheel of its own generator): a gain of one channel, a line on a skirt
def test_a_gain_of_fz_alone_rising_with_speed_is_described_and_no_amplitude_law_added():
    """Fz's chain gain 1.0 -> 1.2 over the runs (recorded in speed order): every axial-force line departs from Ω² by
    one factor, its 1x among them, the other channels' lines keep theirs.  The search gave three axial lines amplitude
    laws (Ω^2.11-2.14) and said nothing; the gain trend asked for two directions."""
    n = len(SPEEDS)

    def drift(i, r, t, std, rng):
        r.signals["Fz"] = r.signals["Fz"] * (1.0 + 0.2 * i / (n - 1))

    _, d = _with(change=drift)
    assert _classes(d) == ["suspension_modes"], [u.text() for u in d.unexplained]
    trends = [u for u in d.unexplained if (u.parameters or {}).get("property") == "gain_trend"]
    assert len(trends) == 1 and trends[0].channels == ("Fz",) and trends[0].parameters["one_channel"]
    assert trends[0].parameters["gain_change_percent"] == pytest.approx(20.0, abs=3.0)


def test_a_line_riding_on_the_model_lines_skirts_is_read_as_one_affine_line():
    """30 Hz + 0.5·f_spin on Fx, Fy and Fz among the wheel's low lines: on a model line's skirt (its predicted PSD over
    the floor) in half of its runs, where nothing was lit; a piece of it was described as a stand's machine at one
    frequency over part of the speeds."""
    def low(i, r, t, std, rng):
        f_line = 30.0 + 0.5 * abs(r.speed) / (2 * np.pi)
        for ch in ("Fx", "Fy", "Fz"):
            r.signals[ch] = r.signals[ch] + 5.0 * std[ch] * np.cos(2 * np.pi * f_line * t + rng.uniform(0, 6.3))

    _, d = _with(change=low)
    affine = [u for u in d.unexplained if u.signature == "affine_line"]
    assert len(affine) == 1 and _classes(d) == ["suspension_modes"], [u.text() for u in d.unexplained]
    assert not [u for u in d.unexplained if u.signature in ("fixed_line", "speed_line")]
    u = affine[0]
    assert set(u.channels) == {"Fx", "Fy", "Fz"}
    assert u.parameters["offset_Hz"] == pytest.approx(30.0, abs=1.0)
    assert u.parameters["slope"] == pytest.approx(0.5, abs=0.03)
