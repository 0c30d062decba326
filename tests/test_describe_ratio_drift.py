"""A line whose ratio to the speed drifts with it (a bearing's cage slipping) is described as a ``ratio_drift``
(trial 30b: a wheel whose cage slipped 5 % at its top speed, three seeds: never described, a mode declared
unconstrained, a test stand invented on one seed).

Records made here with numpy alone (no rwadist physics): rotating radial-force lines at h 1, the outer race's ball
pass BPFO = 8·0.41·(1 − s) and the inner race's 8 − BPFO, s = 0.05·(Ω/Ω_max)², on Fx/Fy and Fz; the truth of each
line's ratio at the lowest and highest speed is the formula's.  Without slip nothing is described."""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.diagnose import describe_drift
from rwadist.diagnose.describe import Residual, cells_of
from rwadist.diagnose.describe_drift import MIN_DRIFT, SAME_LINE, beside_drifts, drifting_speed_lines, ratio_drift
from rwadist.diagnose.engine import Context, initial_state
from rwadist.diagnose.unexplained import Unexplained
from rwadist.effects.fixed_resonance_diagnose import _line_gain_points
from rwadist.empirical import fit_empirical
from rwadist.spectra import compute_spectra

FS, N = 2000.0, 8192
RPM = np.linspace(600.0, 3000.0, 16)
CAGE, BALLS = 0.41, 8


def _test(slip: float, seed: int = 1, cage: float = 0.0) -> SteadyTest:
    """``cage``: the cage's own line CAGE·(1 − s) on the same channels, of ``cage`` x 1e-5 N per (rad/s)² (0: none)."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    runs = []
    for i, rpm in enumerate(RPM):
        om = rpm * 2 * np.pi / 60
        s = slip * (rpm / RPM[-1]) ** 2
        bpfo = BALLS * CAGE * (1 - s)
        sig = {c: 1e-4 * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")}
        for h, C in ((1.0, 1e-5), (bpfo, 3e-6), (BALLS - bpfo, 2e-6), (CAGE * (1 - s), cage * 1e-5)):
            a, ph = C * om**2, rng.uniform(0, 2 * np.pi)
            sig["Fx"] += a * np.cos(h * om * t + ph)
            sig["Fy"] += a * np.sin(h * om * t + ph)
            sig["Fz"] += 0.3 * a * np.cos(h * om * t + rng.uniform(0, 2 * np.pi))
            sig["Tx"] += 0.02 * a * np.cos(h * om * t + ph)
            sig["Ty"] += 0.02 * a * np.sin(h * om * t + ph)
        runs.append(Run(speed=om, sample_rate=FS, t0=0.0, name=f"run_{i:04d}.csv", signals=sig))
    return SteadyTest(runs=runs, meta={})


def _context(slip: float, cage: float = 0.0) -> tuple:
    test = _test(slip, cage=cage)
    sp = compute_spectra(test)
    return Context(sp, test=test), fit_empirical(sp).model


def _drifts(slip: float, cage: float = 0.0) -> list:
    ctx, model = _context(slip, cage)
    return ratio_drift(ctx, SimpleNamespace(model=model), lambda chans, h, runs: (0.0, 0.0))


def test_a_slipping_cages_ball_pass_lines_are_described_with_their_drift():
    got = {(u.parameters["direction"], round(u.parameters["h"], 1)): u for u in _drifts(0.05)}
    lo, hi = (BALLS * CAGE * (1 - 0.05 * (r / RPM[-1]) ** 2) for r in (RPM[0], RPM[-1]))
    # the axial force's lines are in the empirical fit (these rotating radial ones, spread over their bins by the
    # drift, do not pass its presence threshold here: only a model's lines are read)
    assert {d for d, _ in got} == {"axial_force"}
    for d in ("axial_force",):
        outer = next(u for (dd, h), u in got.items() if dd == d and abs(h - 3.2) < 0.15)
        assert outer.parameters["h_at_lowest_speed"] == pytest.approx(lo, rel=0.005)
        assert outer.parameters["h_at_highest_speed"] == pytest.approx(hi, rel=0.005)
        inner = next(u for (dd, h), u in got.items() if dd == d and abs(h - 4.8) < 0.15)
        assert inner.parameters["h_at_highest_speed"] == pytest.approx(BALLS - hi, rel=0.005)
        assert outer.parameters["drift_percent"] < 0 < inner.parameters["drift_percent"]
        assert "cage slipping" in outer.causes[0] and "falls" in outer.causes[0] and "rises" in inner.causes[0]
        assert "inner-race ball pass" in inner.causes[0] and "inner-race" not in outer.causes[0]
    # no line read twice in a direction (a drifting line may be split in two by the fit's binning)
    dirs = [u.parameters["direction"] for u in got.values()]
    assert len(dirs) == len(set(zip(dirs, [round(u.parameters["h"], 1) for u in got.values()])))


def test_lines_at_constant_ratios_hold_no_drift():
    assert _drifts(0.0) == []
    assert _drifts(0.0, cage=0.5) == []
    assert MIN_DRIFT == 0.01


def test_a_resonance_is_fitted_without_the_drifting_lines(monkeypatch):
    """The lines a fixed resonance is fitted to (the log power gain each needs over the model) leave the drifting
    ones out: read at their fixed ratio they lose 3-18 dB at the top speeds as the data's lines move off, the loss a
    notch fits (trial 30b wheel A: a 'test stand' at 139.6 Hz of peak gain 0.27); the lines locked to the rotor stay,
    needing nothing."""
    ctx, model = _context(0.05)
    state = initial_state(ctx, model)
    f, y, _, _ = _line_gain_points(ctx, state, ["Fz"], ctx.runs)
    spin = np.abs(ctx.omega[ctx.runs]) / (2 * np.pi)
    assert np.allclose(np.sort(f), np.sort(spin))                  # the 1x line in every run, and nothing else
    assert np.max(np.abs(y)) < 0.05
    monkeypatch.setattr(describe_drift, "drifting", lambda ctx, model: set())
    f_all, y_all, _, _ = _line_gain_points(ctx, state, ["Fz"], ctx.runs)
    assert f_all.size > f.size and np.sum(y_all < -2.0) >= 5       # what the exclusion keeps from the fit


def test_the_cells_of_a_drift_span_the_model_line_and_the_data_line():
    """A ``ratio_drift`` record covers, in each run, the bands from the model's line to the data's (an effect whose
    gain lies there is fitted to the drift and taken back); its partial-line reading is the drift's, not described
    again."""
    ctx, model = _context(0.05)
    u = next(x for x in ratio_drift(ctx, SimpleNamespace(model=model), lambda chans, h, runs: (0.0, 0.0))
             if abs(x.h - 3.25) < 0.1)
    res = Residual.of(ctx, initial_state(ctx, model))
    cells = cells_of(u, res)["Fz"]
    top = int(np.argmax(np.abs(ctx.omega[ctx.runs])))
    spin = abs(float(ctx.omega[ctx.runs][top])) / (2 * np.pi)
    b_model, b_data = (int(res.band_of(h * spin)) for h in (u.h, u.parameters["h_at_highest_speed"]))
    assert b_model != b_data
    assert cells[top, min(b_model, b_data):max(b_model, b_data) + 1].all()
    assert cells[top].sum() == abs(b_model - b_data) + 3
    partial = Unexplained(signature="partial_line", channels=("Fz",), speed_rpm=(600.0, 3000.0), f_Hz=(30.0, 160.0),
                          level_dB=-20.0, share=0.01, n_runs=16, h=u.h * (1 + SAME_LINE / 2))
    other = Unexplained(signature="partial_line", channels=("Fz",), speed_rpm=(600.0, 3000.0), f_Hz=(30.0, 160.0),
                        level_dB=-20.0, share=0.01, n_runs=16, h=2.0)
    assert beside_drifts([partial, other], [u]) == [other, u]


def test_a_cage_line_under_the_welch_resolution_is_read_on_the_whole_records():
    """The cage's own line (h 0.41, 20 Hz at the top speed): a 5 % slip moves it 1 Hz, under two Welch bins, so it is
    read on the whole records, and its ratios at the extreme speeds are the formula's (trial 30b wheel A: the cage
    line at h ≈ 0.4 was not read; its drift by the ball-pass lines' fraction names the bearing)."""
    ctx, model = _context(0.05, cage=0.5)
    assert describe_drift.MIN_DRIFT * CAGE * RPM[-1] / 60 < describe_drift.MIN_BINS * ctx.sp.df
    got = [u for u in ratio_drift(ctx, SimpleNamespace(model=model), lambda chans, h, runs: (0.0, 0.0))
           if abs(u.h - CAGE) < 0.05]
    assert got, "the cage line's drift is described"
    for u in got:
        rpm = np.asarray(u.parameters["readings_rpm"])
        for key, r in (("h_at_lowest_speed", rpm.min()), ("h_at_highest_speed", rpm.max())):
            assert u.parameters[key] == pytest.approx(CAGE * (1 - 0.05 * (r / RPM[-1]) ** 2), rel=0.003)
        assert u.parameters["drift_percent"] < -1.0


def test_a_speed_line_of_no_model_that_drifts_is_described_as_the_drift():
    """A drifting line no model holds is caught as a ridge at one h (trial 31 wheel D: twice the ball pass slipping 4 %
    read as 'speed lines' at h 6.795 and 6.747, named 15-16 and 16-ball bearings): read again, it is the drift, once;
    a speed line at a constant ratio stays.  Here the radial-force ball-pass lines, in no model of this data."""
    ctx, model = _context(0.05)
    state = SimpleNamespace(model=model)

    def speed_line(h, chans=("Fx", "Fy"), d="radial_force"):
        return Unexplained(signature="speed_line", channels=chans, speed_rpm=(600.0, 3000.0), f_Hz=(30.0, 160.0),
                           level_dB=15.0, share=0.01, n_runs=16, h=h, parameters={"direction": d, "h": h})

    outer = BALLS * CAGE
    a, b, steady = speed_line(outer * 0.985), speed_line(outer * 0.975), speed_line(1.5)
    kept, found = drifting_speed_lines(ctx, state, [a, b, steady])
    assert kept == [steady]
    (got,) = found
    d, chans, h0, rows, _, h_lo, h_hi = got
    assert d == "radial_force" and chans == ("Fx", "Fy")
    rpm = rows[:, 1]
    for h, r in ((h_lo, rpm.min()), (h_hi, rpm.max())):
        assert h == pytest.approx(outer * (1 - 0.05 * (r / RPM[-1]) ** 2), rel=0.005)
    # the same track as the model's own drifting axial line (the generator's outer race on Fx/Fy and Fz): one record
    # of both directions, read from both lines, beside the inner race's
    recs = ratio_drift(ctx, state, lambda chans, h, runs: (0.0, 0.0), found)
    (rec,) = [u for u in recs if abs(u.h - outer) < 0.15]
    assert rec.signature == "line_property" and rec.parameters["property"] == "ratio_drift"
    assert rec.channels == ("Fx", "Fy", "Fz") and rec.parameters["directions"] == ["axial_force", "radial_force"]
    assert pytest.approx(a.h) in rec.parameters["model_h"] and rec.parameters["drift_percent"] < -1.0
    assert len(recs) == 2


def test_one_drifting_line_caught_as_two_ridges_is_one_record():
    """New-user trial nuM: a line drifting 1.55 -> 1.85 over the speeds, in no model, was caught as two ridges (speed
    lines at h 1.688 and 1.75, further apart than SAME_LINE), each read again as the drift over overlapping speeds
    with the same readings in the runs both read, and described four times (twice per direction), its share counted
    twice.  Here the radial-force outer-race line as two ridges 2.5 % apart, the axial force's (a third reading of the
    track) taken out of the model: both read the drift, one record is made of them, spanning the readings of both."""
    from dataclasses import replace

    ctx, model = _context(0.05)
    axial = [x for x in model.harmonics("axial_force") if abs(x.h - 3.2) > 0.3]
    state = SimpleNamespace(model=replace(model, empirical={**model.empirical, "axial_force": axial}))
    outer = BALLS * CAGE
    ridges = [Unexplained(signature="speed_line", channels=("Fx", "Fy"), speed_rpm=(600.0, 3000.0), f_Hz=(30.0, 160.0),
                          level_dB=15.0, share=0.01, n_runs=16, h=h, parameters={"direction": "radial_force", "h": h})
              for h in (outer * 0.99, outer * 0.965)]
    kept, found = drifting_speed_lines(ctx, state, ridges)
    assert kept == [] and len(found) == 2                   # each ridge reads the drift
    recs = [u for u in ratio_drift(ctx, state, lambda chans, h, runs: (0.0, 0.0), found) if abs(u.h - outer) < 0.2]
    assert len(recs) == 1
    (rec,) = recs
    assert rec.channels == ("Fx", "Fy") and rec.parameters["model_h"] == pytest.approx([outer * 0.965, outer * 0.99])
    lo, hi = (outer * (1 - 0.05 * (r / RPM[-1]) ** 2) for r in (RPM[0], RPM[-1]))
    assert rec.parameters["h_at_highest_speed"] == pytest.approx(hi, rel=0.005)
    assert rec.speed_rpm[1] == RPM[-1] and rec.n_runs <= RPM.size


def _readings(h: np.ndarray, rpm: np.ndarray) -> np.ndarray:
    return np.column_stack([np.arange(rpm.size, dtype=float), rpm, h])


#: trial 33's readings (rpm, h_run) of its h 3.27 radial-force line, band-limited noise at 260-340 Hz on the forces:
#: read on the hump's noise in its window at the two top speeds (Welch bins of 0.25 Hz)
TRIAL33_READINGS = [
    (1785.7143, 3.2704934), (1914.2857, 3.2694048), (2042.8571, 3.2693842), (2171.4286, 3.2698887),
    (2300.0, 3.2698384), (2428.5714, 3.2699318), (2557.1429, 3.2700014), (2685.7143, 3.2699856),
    (2814.2857, 3.2700421), (2942.8571, 3.269899), (3071.4286, 3.2699875), (3200.0, 3.2699457),
    (3328.5714, 3.2700705), (3457.1429, 3.2700161), (3585.7143, 3.2699048), (3714.2857, 3.2702343),
    (3842.8571, 3.269905), (3971.4286, 3.2699867), (4100.0, 3.2700231), (4228.5714, 3.2699284),
    (4357.1429, 3.2700941), (4614.2857, 3.5171339), (4742.8571, 3.4088531)]


def test_a_line_at_one_ratio_read_in_a_hump_at_its_top_speeds_is_no_drift():
    """Trial 33 (an independent generator): the weak h 3.27 line read at 3.2700 ± 0.0003 in 21 runs and on a hump's
    noise at the two top speeds was described as a cage slipping, "the line's ratio rises from 3.27 to 3.409 (+4.2 %)".
    The Theil-Sen line through the readings does not drift by half MIN_DRIFT: no drift.  A slip growing as Ω² to 5 %
    over the same speeds, read with the same scatter: its drift, from the readings at the ends."""
    rpm, h = (np.array(v) for v in zip(*TRIAL33_READINGS))
    assert describe_drift.drift_of(_readings(h, rpm), 3.2699, 0.25) is None
    rng = np.random.default_rng(33)
    slip = 3.28 * (1 - 0.05 * (rpm / rpm[-1]) ** 2) + 0.0003 * rng.standard_normal(rpm.size)
    got = describe_drift.drift_of(_readings(slip, rpm), 3.28, 0.25)
    assert got is not None and got[1:] == (pytest.approx(slip[0]), pytest.approx(slip[-1]))


def test_a_joined_drift_drops_the_partial_lines_of_every_line_it_was_read_from():
    """Review of session 59: a record joined from the model lines 1.688 and 1.75 (nuM's case, 3.7 % apart, more than
    SAME_LINE) kept the fixed-ratio ``partial_line`` of 1.75, its lead being 1.688."""
    drift = Unexplained(signature="line_property", channels=("Fx", "Fy", "Fz"), speed_rpm=(969.0, 9000.0),
                        f_Hz=(25.0, 277.0), level_dB=22.0, share=0.08, n_runs=35, h=1.688,
                        parameters={"property": "ratio_drift", "direction": "radial_force", "h": 1.688,
                                    "model_h": [1.688, 1.75]})
    partial = Unexplained(signature="partial_line", channels=("Fz",), speed_rpm=(969.0, 9000.0), f_Hz=(30.0, 260.0),
                          level_dB=-20.0, share=0.01, n_runs=30, h=1.75)
    other = Unexplained(signature="partial_line", channels=("Fz",), speed_rpm=(969.0, 9000.0), f_Hz=(30.0, 260.0),
                        level_dB=-20.0, share=0.01, n_runs=30, h=2.2)
    assert beside_drifts([partial, other], [drift]) == [other, drift]


def test_a_rising_ratio_is_worded_by_where_the_line_sits():
    """A rising ratio in a cage's range is that cage's contact angle, which slip cannot raise (session 60's new-user
    trial: a cage line drifting 0.3755 -> 0.39 read as "an inner-race ball pass (BPFI = n − BPFO)", which needs fewer
    than one ball), the outer-race-turning cage's range (0.52-0.65) too; over the least ball pass over a turning race
    (5 balls, γ 0.3: 1.75) a ball pass the cage's slip raises; between them neither."""
    from rwadist.diagnose.describe_drift import _cause
    rpm = np.array([1945.0, 6000.0])
    cage = _cause("rises", 0.3755, 0.39, 0.038, rpm)
    assert "cage" in cage and "inner race turns" in cage and "contact angle" in cage and "BPFI" not in cage
    assert "outer race turns" in _cause("rises", 0.55, 0.57, 0.036, rpm)
    assert "turning race" in _cause("rises", 4.70, 4.80, 0.02, rpm)
    between = _cause("rises", 1.10, 1.13, 0.027, rpm)
    assert "no bearing slip" in between and "1.75" in between and "contact angle" not in between
    assert "cage slipping" in _cause("falls", 0.40, 0.39, -0.025, rpm)


def test_a_drift_drops_the_blend_its_fixed_ratio_reading_makes():
    """Session 60's trial: a cage line drifting 0.3755 -> 0.39, its model line at 0.3849, read in the Welch window as
    'two or more lines within ±0.0513' on Fx Fy and on Tx Ty beside its drift; a blend of another line stays."""
    drift = Unexplained(signature="line_property", channels=("Fx", "Fy", "Tx", "Ty"), speed_rpm=(1945.0, 6000.0),
                        f_Hz=(12.2, 39.0), level_dB=0.0, share=0.03, n_runs=20, h=0.3849,
                        parameters={"property": "ratio_drift", "direction": "radial_force", "h": 0.3849})
    blends = [Unexplained(signature="line_property", channels=chans, speed_rpm=(3297.0, 6000.0), f_Hz=(21.2, 38.5),
                          level_dB=2.0, share=0.009, n_runs=12, h=h,
                          parameters={"property": "blended_lines", "direction": "radial_force"})
              for chans, h in ((("Fx", "Fy"), 0.3849), (("Tx", "Ty"), 0.3849), (("Fx", "Fy"), 2.73))]
    assert beside_drifts(blends, [drift]) == [blends[2], drift]
