"""A radial channel wired with the wrong polarity (issue 33, trial16 flipFy): rwadist.channel_polarity.

A sign error on Fy turns Fx + iFy of every co-rotating line A·e^{iωt} into conj(A)·e^{−iωt}: the imbalance's 1x line
reads wholly counter-rotating while the radial torque's 1x line (the same rotor) stays co-rotating.  No imbalance
does that; main 906dfd9 named a counter_rotation of q 1 on the radial-force 1x and reversed every radial-force line's
sense, saying nothing of the wiring.

Data: family wheels (tests/family_wheel.py, generated without rwadist's physics: the imbalance co-rotating in both
pairs, the other lines with the senses the generator gives them), one channel's sign reversed after generation.
Checked against the generator's truth: the record names the pair; the channel flipped back gives the generated data
exactly (Fy) or turned by 180° (Tx reversed, Ty flipped: −(Tx + iTy), the same senses and PSDs); diagnose names no
counter_rotation on that pair and fits every line of it with the generator's sense and each mode within 2 %.  The
generator's genuine counter-rotation (30 % of the 1x, the matrix's counter_rotation cell) and a wheel spinning the
other way are left alone.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist.data import Run, SteadyTest  # noqa: E402

N_SPEEDS = 16
N_SAMPLES = 8192


def _test(wheel, seed, flip=None, effects=(), sign=1.0):
    """The wheel's steady test (N_SPEEDS speeds over its range, spinning ``sign``), channel ``flip`` multiplied by -1."""
    data = fw.steady(wheel, speeds_rpm=sign * np.linspace(wheel.min_rpm, wheel.max_rpm, N_SPEEDS),
                     n_samples=N_SAMPLES, noise=0.01, seed=seed, effects=effects)
    runs = [Run(speed=float(om), sample_rate=data.sample_rate, t0=0.0, name=f"run_{i:04d}.csv",
                signals={c: (-1.0 if c == flip else 1.0) * data.signals[i, j] for j, c in enumerate(fw.CHANNELS)})
            for i, om in enumerate(data.speeds)]
    return SteadyTest(runs=runs, meta={})


@pytest.mark.parametrize("index, seed, flip, direction, back", [(0, 1, "Fy", "radial_force", 1.0),
                                                                  (3, 2, "Fy", "radial_force", 1.0),
                                                                  (2, 3, "Tx", "radial_torque", -1.0),
                                                                  (5, 4, "Tx", "radial_torque", -1.0)])
def test_a_reversed_channel_is_found_and_flipped_back(index, seed, flip, direction, back):
    """The record names the pair (1x co share near 0 against near 1: the generator's imbalance is co-rotating in
    both); the test it returns holds the generated pair exactly (Fy) or −(x + iy) (Tx reversed, Ty flipped)."""
    from rwadist import channel_polarity as cp

    wheel = fw.family()[index]
    true, bad = _test(wheel, seed), _test(wheel, seed, flip)
    assert cp.check_record(true) is None
    fixed, rec = cp.checked(bad)
    assert rec is not None and rec["direction"] == direction and rec["channels"] == list(cp.PAIRS[direction])
    assert rec["one_x_co_share"] < 0.05 and rec["other_one_x_co_share"] > 0.95
    x, y = cp.PAIRS[direction]
    for r0, r1 in zip(true.runs, fixed.runs):
        z0 = r0.signals[x] + 1j * r0.signals[y]
        np.testing.assert_array_equal(r1.signals[x] + 1j * r1.signals[y], back * z0)
        for c in fw.CHANNELS:
            if c not in (x, y):
                np.testing.assert_array_equal(r1.signals[c], r0.signals[c])
    # the evidence: the pair's line power mirrored (counter share s -> 1 - s; the record rounds it to 1e-4)
    assert rec["line_power_counter_share"] == pytest.approx(1 - cp.line_power_counter_share(true, (x, y)), abs=1e-4)


@pytest.mark.parametrize("index, seed", [(0, 5), (6, 6)])
def test_genuine_counter_rotation_and_reverse_spin_are_left_alone(index, seed):
    """30 % of the radial-force 1x counter-rotating (1x co share 0.7), and the whole test spinning Ω < 0: no record."""
    from rwadist import channel_polarity as cp

    wheel = fw.family()[index]
    assert cp.check_record(_test(wheel, seed, effects=[fe.CounterRotation()])) is None
    assert cp.check_record(_test(wheel, seed, sign=-1.0)) is None
    rec = cp.check_record(_test(wheel, seed, "Fx", sign=-1.0))
    assert rec is not None and rec["direction"] == "radial_force"


@pytest.mark.parametrize("index, seed, flip", [(0, 1, "Fy"), (3, 2, "Fy"), (2, 3, "Tx"), (5, 4, "Tx")])
def test_diagnose_of_a_reversed_channel(index, seed, flip):
    """rwadist.diagnose with no model: no counter_rotation on the reversed pair (main named q 1 on the radial-force
    1x), a reversed_polarity record in data_quality, every line of the pair the generator makes wholly co- or
    counter-rotating fitted with that sense and each suspension mode within 2 % of the generator's."""
    from rwadist import api
    from rwadist.errors import RwadistWarning

    wheel = fw.family()[index]
    with pytest.warns(RwadistWarning, match="wired with the wrong polarity"):
        d = api.diagnose(_test(wheel, seed, flip))
    direction = "radial_force" if flip[0] == "F" else "radial_torque"
    assert not [e for e in d.model.effects if e["kind"] == "counter_rotation" and e["direction"] == direction]
    recs = [r for r in d.data_quality if r.get("type") == "reversed_polarity"]
    assert len(recs) == 1 and recs[0]["direction"] == direction
    assert d.model.provenance["data_quality"] == recs
    truth = {(ln.direction, round(ln.h, 3)): ln.co for ln in wheel.lines if ln.direction == direction}
    seen = 0
    for hm in d.model.empirical[direction]:
        co = truth.get((direction, round(hm.h, 3)))
        if co in (0.0, 1.0):            # a line wholly one way in the generator: every part of it fitted that way
            assert hm.sense == ("co" if co == 1.0 else "counter"), (hm, co)
            seen += 1
    assert seen >= 2
    sm = next(e for e in d.model.effects if e["kind"] == "suspension_modes")
    for m, f in wheel.modes_hz().items():
        if m not in (sm.get("unconstrained") or []):
            assert sm[f"{m}_Hz"] == pytest.approx(f, rel=0.02)


def _column_negated(test):
    """``test`` as a tachometer's unsigned speed reads a wheel spinning Ω < 0: every run's speed column multiplied
    by -1, the signals as recorded."""
    from dataclasses import replace

    return SteadyTest(runs=[replace(r, speed=-r.speed) for r in test.runs], meta={})


@pytest.mark.parametrize("index, seed", [(1, 7), (4, 8), (7, 9)])
def test_a_speed_column_of_the_wrong_sign_is_found_and_negated(index, seed):
    """A wheel spinning Ω < 0 given with a positive speed column: both radial pairs' 1x read counter-rotating (the
    generator's imbalance turns with the rotor in both); the record says reversed_spin and the test it returns is
    the generated one exactly (speeds and signals).  One channel reversed on top of it is still a polarity error."""
    from rwadist import channel_polarity as cp

    wheel = fw.family()[index]
    true = _test(wheel, seed, sign=-1.0)
    assert cp.check_record(true) is None
    fixed, rec = cp.checked(_column_negated(true))
    assert rec is not None and rec["type"] == "reversed_spin"
    assert set(rec["directions"]) == set(cp.PAIRS)
    assert all(s < 0.05 for s in rec["one_x_co_shares"].values())
    for r0, r1 in zip(true.runs, fixed.runs):
        assert r1.speed == r0.speed < 0
        for c in fw.CHANNELS:
            np.testing.assert_array_equal(r1.signals[c], r0.signals[c])
    one = cp.check_record(_column_negated(_test(wheel, seed, "Fy", sign=-1.0)))
    assert one is not None and one["type"] == "reversed_polarity" and one["direction"] == "radial_torque"


@pytest.mark.parametrize("index, seed", [(2, 10), (6, 11)])
def test_diagnose_of_a_speed_column_of_the_wrong_sign(index, seed):
    """rwadist.diagnose with no model on the wrong-sign column: the same effects, model lines and error as on the
    signed column (main named a counter_rotation of q 1 on the radial-force 1x), a reversed_spin record in
    data_quality and the model's provenance, and the speed record saying the speeds were negated."""
    from rwadist import api
    from rwadist.errors import RwadistWarning

    wheel = fw.family()[index]
    true = _test(wheel, seed, sign=-1.0)
    right = api.diagnose(true)
    with pytest.warns(RwadistWarning, match="turns against the sign of the speed column"):
        d = api.diagnose(_column_negated(true))
    assert not [e for e in d.model.effects if e["kind"] == "counter_rotation"]
    assert [e["kind"] for e in d.model.effects] == [e["kind"] for e in right.model.effects]
    assert d.error_after == pytest.approx(right.error_after, rel=1e-9)
    for direction, lines in right.model.empirical.items():
        assert [(hm.h, hm.sense) for hm in d.model.empirical[direction]] == [(hm.h, hm.sense) for hm in lines]
    recs = [r for r in d.data_quality if r.get("type") == "reversed_spin"]
    assert len(recs) == 1 and d.model.provenance["data_quality"] == recs
    assert "multiplied by -1" in d.speed["method"]


@pytest.mark.parametrize("index, seed, pairs, kind", [(1, 12, (("Fx", "Fy"), ("Tx", "Ty")), "reversed_spin"),
                                                      (4, 13, (("Fx", "Fy"),), "reversed_polarity")])
def test_exchanged_x_and_y_channels_are_named_beside_the_sign(index, seed, pairs, kind):
    """x and y exchanged (Fx + iFy of a co-rotating A·e^{iΩt} becomes Fy + iFx = i·conj(A)·e^{−iΩt}, counter-rotating):
    both radial pairs exchanged read as the speed column's sign reversed, one pair as that pair's polarity; the
    console's lines say the exchange could be it (the session-55 trial's swapped cable pair was sent to the speed
    column's sign and the z axes only).  The test returned is the generated one with every run's speed negated
    (both pairs) or its y channel negated (one pair), as for a sign error: no PSD or sense tells them apart."""
    from rwadist import channel_polarity as cp

    wheel = fw.family()[index]
    true = _test(wheel, seed)
    swap = {a: b for x, y in pairs for a, b in ((x, y), (y, x))}
    runs = [Run(speed=r.speed, sample_rate=r.sample_rate, name=r.name,
                signals={swap.get(c, c): v for c, v in r.signals.items()}) for r in true.runs]
    rec = cp.check_record(SteadyTest(runs, {}))
    assert rec is not None and rec["type"] == kind
    text = " ".join(cp.polarity_lines(rec))
    assert ("x and y channels exchanged" in text) if kind == "reversed_spin" else ("two cables swapped" in text)
