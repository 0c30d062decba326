"""Which line of a sweep without a speed column is 1x (issue 33, item 5; trial 11's fault).

Trial 11 (an independent generator, its sweep physics copied into tests/trial_wheel.py): a wheel with lines at h
0.41, 1, 2, 3.6 and 7.2, the 1x and the ball-pass line 3.6 both co-rotating in the radial force and torque, each
with its 2x.  The speed scale took the line whose integer multiples carried the most *summed template strength*;
every clear line's strength saturates, so the choice flipped with the sweep's duration: 300-s run-ups took 3.6 as
1x (speeds 3.6x too high, I_zz/I_rr 0.48).  Now the count of multiples decides, the lowest of a tie is taken, and
when diagnose fits the wheel's suspension modes the gyroscopic whirl must read a physical I_zz/I_rr
(:mod:`rwadist.speed_whirl`), else the candidate scale it supports is diagnosed.  Truth: the generator's speed.
"""
import functools
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import trial_wheel as tw  # noqa: E402

from rwadist import speed_scale as sc  # noqa: E402
from rwadist import speed_whirl as sw  # noqa: E402
from rwadist.data import Sweep  # noqa: E402
from rwadist.sweep import slice_sweep  # noqa: E402

TRUE_H = (0.41, 1.0, 2.0, 3.6, 7.2)


@functools.lru_cache(maxsize=None)
def _sliced(duration: float, modes: bool = True, rpm=(300.0, 4500.0)):
    """(sliced test, slice infos, true speed rad/s per sample) of trial 11's wheel swept in ``duration`` s."""
    t, ch, omega = tw.sweep(rpm[0], rpm[1], duration, tw.LINES, modes=modes)
    sweep = Sweep(time=t, signals={c: ch[j] for j, c in enumerate(tw.CHANNELS)}, sample_rate=tw.FS, tach=None)
    test, infos = slice_sweep(sweep, speed_source="data")
    return test, infos, omega


def test_saturated_strengths_do_not_choose_the_one_x_line():
    """The template strengths trial 11's 300-s run-up measured (every line near the cap L_CAP = 6): the summed
    strength of 3.6's multiples (5.976 + 5.951) beat the imbalance's (6.0 + 5.891) and 3.6 was taken.  Both have
    two integer multiples: the lowest is 1x, and the other is kept as tied."""
    orders = np.array([1.0, 2.439, 4.878, 8.7805, 17.5608])
    strength = np.array([5.659, 6.0, 5.891, 5.976, 5.951])
    nan = np.nan
    senses = {"F": (np.ones(5), None), "T": (np.array([nan, 1.0, nan, 1.0, 0.0]), None)}
    best, sense, ev, why = sc.imbalance_line(orders, strength, senses)
    assert best == 1 and sense == 1.0 and ev["multiples_found"] == [1, 2]
    assert [round(c["h"], 3) for c in ev["tied"]] == [3.6] and "the lowest taken" in why


@pytest.mark.parametrize("rpm", [(300.0, 4500.0), (4500.0, 300.0)])
def test_ball_pass_line_with_its_harmonic_is_not_taken_for_the_imbalance(rpm):
    """Trial 11's wheel swept 300 <-> 4500 rpm in 30 s, no speed column: every slice's speed within 0.2 % of the
    generator's where the speed changes by less than 5 % over the slice (median of all within 0.05 %), every line of the speed scale above h 0.3 within 0.1 % of a true ratio and
    each true line found (before: every speed 3.6x too high, ratios 0.1139, 0.2778, 0.5556, 1, 2)."""
    test, infos, omega = _sliced(30.0, rpm=rpm)
    est = np.array([i.speed for i in infos])
    truth = np.array([omega[i.start:i.stop].mean() for i in infos])
    change = np.array([np.ptp(omega[i.start:i.stop]) for i in infos]) / truth
    err = np.abs(est / truth - 1)
    # the slowest slices of a 30-s sweep change speed by 10 % or more over their length and are smeared
    assert np.max(err[change < 0.05]) < 0.002 and np.median(err) < 0.0005
    scale = test.meta["slicing"]["speed_scale"]
    ratios = [h for h in scale["ratios"] if h > 0.3]
    for h in ratios:
        assert min(abs(h / t - 1) for t in TRUE_H) < 0.001, h
    for t in TRUE_H:
        assert min(abs(h / t - 1) for h in ratios) < 0.001, t
    assert [round(c["h"], 2) for c in scale["one_x"]["tied"]] == [3.6]


def test_rescaled_moves_every_speed_and_ratio_by_the_candidates_ratio():
    """Taking the line at h 3.6 as 1x multiplies every run's speed by 3.6 and divides every ratio by it (the
    speed scale's own ratios: the sweep is sliced once); the original 1x is then the candidate at h 1/3.6 with its
    multiples, and taking it back restores the speeds."""
    test, _, _ = _sliced(30.0)
    wrong = sw.rescaled(test, 3.6)
    assert wrong.speeds == pytest.approx(3.6 * test.speeds, rel=1e-12)
    assert sorted(wrong.meta["slicing"]["speed_scale"]["ratios"]) == pytest.approx(
        sorted(h / 3.6 for h in test.meta["slicing"]["speed_scale"]["ratios"]), abs=1e-6)       # rounded to 1e-6
    one = wrong.meta["slicing"]["speed_scale"]["one_x"]
    back = [c for c in one["candidates"] if abs(c["h"] * 3.6 - 1) < 1e-3]
    assert back and back[0]["multiples_found"] == [1, 2] and one["multiples_found"] == [1, 2]
    assert sw.rescaled(wrong, back[0]["h"]).speeds == pytest.approx(test.speeds, rel=1e-5)
    assert 1.0 in test.meta["slicing"]["speed_scale"]["ratios"]      # the original left alone


def test_rescaled_turns_the_speed_with_the_new_one_x_lines_sense():
    """A line at h 0.41 counter-rotating in both radial pairs (trial23's generator has its cage line so): the speed's
    sign is the 1x line's sense about +z, so taking that line as 1x gives speeds −0.41 × the rotor's, and moving
    the 1x back to the imbalance turns them round again: the generator's speeds, positive.  Before, the sign was kept, and trial23's run-up (its cage taken as 1x first, then moved to the
    imbalance by the whirl) read the imbalance counter-rotating, a counter_rotation of q = 1 added."""
    cage = tuple(x for x in tw.LINES if x[1] != 0.41) + (
        ("radial_force", 0.41, -1, 0.06 * tw.U_S), ("radial_torque", 0.41, -1, 0.06 * tw.U_D))
    t, ch, omega = tw.sweep(300.0, 4500.0, 30.0, cage, modes=False)
    sweep = Sweep(time=t, signals={c: ch[j] for j, c in enumerate(tw.CHANNELS)}, sample_rate=tw.FS, tach=None)
    test, infos = slice_sweep(sweep, speed_source="data")
    truth = np.array([omega[i.start:i.stop].mean() for i in infos])
    assert test.speeds == pytest.approx(truth, rel=2e-3)
    h_cage = next(c["h"] for c in test.meta["slicing"]["speed_scale"]["one_x"]["candidates"] if abs(c["h"] - 0.41) < 1e-3)
    on_cage = sw.rescaled(test, h_cage)
    assert on_cage.speeds == pytest.approx(-h_cage * truth, rel=2e-3)
    assert on_cage.meta["slicing"]["speed_scale"]["sense"] == -1
    assert on_cage.meta["slicing"]["speed_scale"]["one_x"]["co_share_force"] < 0.4      # the new 1x line's evidence
    back = next(c["h"] for c in on_cage.meta["slicing"]["speed_scale"]["one_x"]["candidates"] if abs(c["h"] * h_cage - 1) < 1e-3)
    assert sw.rescaled(on_cage, back).speeds == pytest.approx(truth, rel=2e-3)


def test_settle_follows_the_whirl_and_says_when_it_cannot():
    """:func:`rwadist.speed_whirl.settle` with a stand-in diagnosis whose whirl reads I_zz/I_rr = 1.8 x (true
    speed / speed given), as I_rr·ω² − I_zz·Ω·ω − k_θ = 0 does: taking 3.6 as 1x it reads 0.5, is rejected, and
    the candidate that brings the ratio into [0.8, 2.5] is diagnosed and kept; a wheel whose modes are not fitted
    keeps the tie's lowest with a warning naming the tied line and asking for a speed column."""
    from rwadist.diagnose.search import BaseRejected

    test, _, _ = _sliced(30.0)
    true_speeds = test.speeds

    class Fake:
        def __init__(self, ratio):
            self.entry = {"kind": "suspension_modes", "inertia_ratio": ratio, "unconstrained": []}

        def summary(self):
            return {"effects": [self.entry]}

    def run(t, check):
        e = Fake(round(1.8 * float(np.median(true_speeds / t.speeds)), 2))
        if check is not None and not check(e.entry):
            raise BaseRejected(e.entry)
        return e

    kept, diag = sw.settle(sw.rescaled(test, 3.6), run)
    whirl = kept.meta["slicing"]["speed_scale"]["whirl"]
    assert whirl["status"] == "moved" and whirl["rejected"]["inertia_ratio"] == 0.5
    # the words carry the ratios of the scale kept (the slicing's first console line gave the rejected scale's)
    now = [float(x) for x in whirl["text"].split("(ratios now ")[1].rstrip(")").split(", ")]
    assert now == pytest.approx(kept.meta["slicing"]["speed_scale"]["ratios"], rel=1e-3) and 1.0 in now
    assert kept.speeds == pytest.approx(true_speeds, rel=1e-5) and diag.entry["inertia_ratio"] == 1.8
    kept, _ = sw.settle(test, run)
    assert kept.meta["slicing"]["speed_scale"]["whirl"]["status"] == "agrees"

    class NoModes:
        def summary(self):
            return {"effects": []}

    kept, _ = sw.settle(sw.rescaled(test, 1.0), lambda t, check: NoModes())
    rec = sw.speed_record(kept.meta)
    assert rec["source"] == "data" and rec["whirl"]["status"] == "untested"
    assert "3.6" in rec["warning"] and "tach" in rec["warning"]
    assert sw.speed_record({})["source"] == "measured"


def test_a_whirl_of_a_rocking_mode_not_located_is_said_as_no_reading():
    """A diagnosis whose rocking mode is not located (``unconstrained``) still carries the ratio it was fitted with;
    settle's verdict says the mode was not located rather than that the whirl "reads" that ratio (a new user's run-up:
    "the gyroscopic whirl reads I_zz/I_rr 0.145" beside "rocking at rest not located")."""
    from rwadist.diagnose.search import BaseRejected

    test, _, _ = _sliced(30.0)

    class Unlocated:
        entry = {"kind": "suspension_modes", "inertia_ratio": 0.145, "unconstrained": ["rocking"]}

        def summary(self):
            return {"effects": [self.entry]}

    def run(t, check):
        e = Unlocated()
        if check is not None and not check(e.entry):
            raise BaseRejected(e.entry)
        return e

    kept, _ = sw.settle(test, run)
    whirl = kept.meta["slicing"]["speed_scale"]["whirl"]
    assert whirl["status"] == "disagrees" and whirl["rocking_located"] is False
    assert whirl["text"].startswith("the rocking mode was not located") and "whirl reads" not in whirl["text"]
    assert "suspect" in whirl["warning"]


def test_report_says_how_the_speed_was_obtained(tmp_path):
    """Hard-mounted (no modes: nothing the whirl can read) 30-s run-up of trial 11's wheel: diagnose's summary.json
    and report.md say the speed came from the data, which line is 1x, the ratios, the agreement and that the data
    cannot tell 1 from 3.6 (a tach asked for); the model's imbalance at h 1."""
    from rwadist import api
    from rwadist.diagnose import write_report

    test, _, _ = _sliced(30.0, modes=False)
    diag = api.diagnose(test)
    speed = diag.summary()["speed"]
    assert speed["source"] == "data" and speed["one_x"]["multiples_found"] == [1, 2]
    assert 0 < speed["agreement_rel_rms"] < 0.02 and speed["whirl"]["status"] == "untested"
    assert "3.6" in speed["warning"]
    write_report(diag, tmp_path)
    md = (tmp_path / "report.md").read_text()
    assert "## Speed" in md and "the 1x line" in md and "agree with the speed" in md and "tach" in md
    assert any(abs(x.h - 1.0) < 0.002 for x in diag.model.harmonics("radial_force"))


def test_fit_warns_of_a_tied_speed_scale():
    """``rwadist fit`` fits no modes, so nothing tests a tie of the speed scale: trial 11's hard-mounted 30-s run-up
    (the ball pass 3.6 with its 2x ties the imbalance with its 2x) is fitted with a warning naming the tied line, diagnose
    and a tach; with a tach column nothing is said."""
    from rwadist import api
    from rwadist.errors import RwadistWarning

    test, _, _ = _sliced(30.0, modes=False)
    with pytest.warns(RwadistWarning, match=r"cannot tell the 1x line: the line at h 3\.6 .*rwadist diagnose.*tach"):
        api.fit(test)
    t, ch, omega = tw.sweep(300.0, 4500.0, 30.0, tw.LINES, modes=False)
    sweep = Sweep(time=t, signals={c: ch[j] for j, c in enumerate(tw.CHANNELS)}, sample_rate=tw.FS, tach=omega)
    measured, _ = slice_sweep(sweep, speed_source="tach")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RwadistWarning)
        api.fit(measured)


@pytest.mark.slow
def test_whirl_brings_back_the_imbalance_from_a_wrong_scale():
    """Trial 11's wheel (modes 140/70/260 Hz, I_zz/I_rr 1.8) swept in 30 s with its speeds given 3.6x too high (the
    ball-pass line as 1x, as before): the whirl of the fitted modes reads about 0.5, the 1x line is moved back to the
    imbalance, and the diagnosis is the clean one: I_zz/I_rr within 3 % of 1.8, every mode within 2 %, the speeds
    those of the data's scale again (the generator's: median within 0.05 %)."""
    from rwadist import api

    test, infos, omega = _sliced(30.0)
    diag = api.diagnose(sw.rescaled(test, 3.6))
    speed = diag.summary()["speed"]
    assert speed["whirl"]["status"] == "moved" and speed["whirl"]["rejected"]["inertia_ratio"] < 0.8
    modes = next(e for e in diag.summary()["effects"] if e["kind"] == "suspension_modes")
    assert modes["inertia_ratio"] == pytest.approx(tw.RATIO, rel=0.03)
    for key, f in (("radial_translation_Hz", tw.F_R), ("rocking_Hz", tw.F_T), ("axial_Hz", tw.F_Z)):
        assert modes[key] == pytest.approx(f, rel=0.02), key
    truth = np.array([omega[i.start:i.stop].mean() for i in infos])          # the runs' order
    assert diag.ctx.test.speeds == pytest.approx(test.speeds, rel=1e-5)
    assert np.median(np.abs(diag.ctx.test.speeds / truth - 1)) < 0.0005


def test_a_line_turning_no_one_way_turns_no_speed_round():
    """The sense of the line a speed scale moves its 1x to is read as the 1x candidates are (every pair's co share
    >= POLARIZED one way): a line with shares 0.52 / 0.47, or pairs that disagree (0.9 / 0.2), tells no sense."""
    scale = {"ratios": [0.41, 1.0, 2.0], "co_share": [[0.52, 0.47], [0.9, 0.2], [0.1, None]]}
    assert sw._line_sense(scale, 0.41)[0] is None
    assert sw._line_sense(scale, 1.0)[0] is None
    assert sw._line_sense(scale, 2.0)[0] == -1

def test_a_ball_pass_with_its_harmonic_is_not_the_one_x_when_it_puts_the_cage_below_any_cage():
    """A new user's 2.5-kg wheel (session 63), swept without a speed column: the imbalance at 1 with no integer line
    beside it, a ball pass at 4.7036 with its 2x at 9.4072 (co-rotating in force and torque), a counter-rotating line
    at 7.1083 and a cage at 0.3812 (force only).  Counted, the ball pass had the most multiples and ``rwadist fit``
    read every h 4.7x low (the imbalance at 0.2126, the cage at 0.081); no load turning one way in force and torque
    turns slower than a cage (0.35 of the rotor), so a 1x that puts another such line below 0.25x is not taken while
    another candidate is there; it stays a candidate (for diagnose's whirl)."""
    orders = np.array([0.3812, 1.0, 4.7036, 7.1083, 9.4072])
    strength = np.full(orders.size, 5.0)
    nan = np.nan
    senses = {"F": (np.array([0.0, 1.0, 1.0, 0.0, 1.0]), None), "T": (np.array([nan, 1.0, 1.0, 0.0, 1.0]), None)}
    best, sense, ev, why = sc.imbalance_line(orders, strength, senses)
    assert best == 1 and sense == 1.0 and ev["multiples_found"] == [1], why
    assert "not the lines at h 4.704, 7.108, 9.407" in why and ev["tied"] == []
    assert sorted(round(c["h"], 3) for c in ev["candidates"]) == [4.704, 7.108, 9.407]
    # the same wheel with speed sidebands at 0.93 and 1.07 of the imbalance's, co-rotating too: they tie with it (one
    # multiple each), and the lowest of a tie was taken (every speed 7 % low); the carrier lies midway between them, and
    # within 15 % of the lowest (a ball pass tied far above, with the cage's sidebands beside it, is not taken)
    orders = np.array([0.3812, 0.93, 1.0, 1.07, 4.7036, 7.1083, 9.4072])
    senses = {"F": (np.array([0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0]), None),
              "T": (np.array([nan, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0]), None)}
    best, _, ev, why = sc.imbalance_line(orders, np.full(orders.size, 5.0), senses)
    assert best == 2 and sorted(round(c["h"], 2) for c in ev["tied"]) == [0.93, 1.07], why
    assert "midway between two lines" in why
    # the imbalance with its 2x tied with a ball pass 3.08 with its 2x and the cage's sidebands beside it (2.69, 3.47;
    # the cage itself not seen): the lowest, the imbalance (a reviewer's case: the carrier rule had taken 3.08)
    orders = np.array([1.0, 2.0, 2.69, 3.08, 3.47, 6.16])
    senses = {"F": (np.array([1.0, 1.0, 1.0, 1.0, 1.0, 1.0]), None), "T": (np.array([1.0, nan, nan, 1.0, nan, nan]),
                                                                           None)}
    best, _, ev, _ = sc.imbalance_line(orders, np.full(orders.size, 5.0), senses)
    assert best == 0 and [round(c["h"], 2) for c in ev["tied"]] == [3.08]
    # a line of one sense in the force alone below 0.25x (a sub-synchronous whirl, no candidate) excludes nothing
    orders = np.array([0.2, 0.4, 1.0, 2.0, 3.08])
    senses = {"F": (np.array([1.0, 1.0, 1.0, 1.0, 1.0]), None), "T": (np.array([nan, nan, 1.0, nan, 1.0]), None)}
    best, _, _, why = sc.imbalance_line(orders, np.full(orders.size, 5.0), senses)
    assert best == 2 and "not the line" not in why


def _per_slice(power) -> np.ndarray:
    """Per-slice values (3 slices, lines) about ``power`` (per line)."""
    return np.tile(np.asarray(power, float), (3, 1)) * np.array([[0.8], [1.0], [1.3]])


def test_a_tie_with_a_cage_below_a_far_stronger_line_takes_the_stronger():
    """A new user's wheel (session 64, trial nuA): a 1x, its bearing's cage at 0.4137 and ball-pass lines 3.6871 and
    7.3742, no integer harmonic, every radial line co-rotating: the 1x and the cage tie (one multiple each) and the
    lowest was taken, every speed 2.42x low.  A tie's lowest at a cage's ratio (0.35-0.48) of a tied line 10x
    stronger in the radial-force pair's power, slice by slice, is that line's cage: that line taken.  Controls: a
    weak 1x with a one-way line 2.42x above it 6x stronger (a reviewer's well-balanced wheel: the lowest, the 1x,
    kept); a cage stronger than the line above it (no ground to move: the lowest)."""
    orders = np.array([0.4137, 1.0, 3.6871, 7.3742])
    strength = np.full(orders.size, 6.0)                        # saturated: the template's strength tells nothing
    co = np.ones(orders.size)
    lit = _per_slice([40.0, 900.0, 300.0, 60.0])                # over the local noise: all stand out
    senses = {"F": (co, lit, _per_slice([4e-3, 0.48, 0.02, 3e-3])), "T": (co, lit, _per_slice([1, 30, 2, 1]))}
    best, _, ev, why = sc.imbalance_line(orders, strength, senses)
    assert best == 1 and [round(t["h"], 4) for t in ev["tied"]] == [0.4137], why
    assert "the one whose cage the lowest would be" in why
    orders2 = np.array([1.0, 2.42, 3.6871])
    senses2 = {"F": (np.ones(3), _per_slice([900.0, 900.0, 300.0]), _per_slice([0.16, 1.0, 0.2]))}
    assert sc.imbalance_line(orders2, np.full(3, 6.0), senses2)[0] == 0
    senses3 = {"F": (co, lit, _per_slice([0.9, 0.48, 0.02, 3e-3]))}
    assert sc.imbalance_line(orders, strength, senses3)[0] == 0
