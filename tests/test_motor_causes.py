"""A motor's torque ripple as the cause of an axial-torque line at a whole multiple of the speed (trial16: a Tz line at
h 18, a 3-pole-pair motor's commutation, had no cause).

The names are checked against the motor's torque computed, not against the closed forms :mod:`rwadist.motor`
states: a three-phase motor's torque T(θ) = Σ_k e_k(θ)·i_k(θ)/ω over one mechanical revolution (back-EMF e_k and
current i_k of phase k at electrical angle p·θ), and the cogging torque as the sum over every pole-tooth pair of one
periodic pull; the lowest harmonic of the revolution each holds (an FFT) is the line's h.
"""
from types import SimpleNamespace

import numpy as np
import pytest

from rwadist.diagnose.describe import line_causes
from rwadist.motor import POLE_PAIRS, cogging_motors, motor_causes

#: Samples of one revolution: the cogging's pulls are sums of sinusoids below N/2 (no aliasing) ...
N_THETA = 512
#: ... the block currents' edges fall at multiples of 2π/(12p): with this many samples (a multiple of 12p for every p
#: named) taken half a sample off the edges, the sampled torque repeats exactly every 2π/(6p)
N_BLOCKS = 12 * 27720


def _lowest_harmonic(torque: np.ndarray) -> int:
    """The lowest harmonic of the revolution (k ≥ 1) holding more than 1e-9 of the torque's ripple power."""
    spec = np.abs(np.fft.rfft(torque - torque.mean())) ** 2
    return int(np.flatnonzero(spec[1:] > 1e-9 * spec[1:].sum())[0] + 1)


def _three_phase_torque(p: int, kind: str) -> np.ndarray:
    """The torque of a three-phase motor of ``p`` pole pairs over one revolution (arbitrary units): ``six_step``
    sinusoidal back-EMF with 120° block currents (commutated); ``unbalance`` sinusoidal currents with one phase's
    back-EMF 10 % strong; ``offset`` sinusoidal currents with one phase's current sensor 5 % of the peak off."""
    th = 2 * np.pi * (np.arange(N_BLOCKS) + 0.5) / N_BLOCKS
    torque = np.zeros(N_BLOCKS)
    for k in range(3):
        ang = p * th - 2 * np.pi * k / 3
        e = np.sin(ang) * (1.1 if kind == "unbalance" and k == 0 else 1.0)
        if kind == "six_step":
            i = np.where(np.sin(ang) > 0.5, 1.0, np.where(np.sin(ang) < -0.5, -1.0, 0.0))
        else:
            i = np.sin(ang) + (0.05 if kind == "offset" and k == 0 else 0.0)
        torque += e * i
    return torque


def _cogging_torque(slots: int, p: int) -> np.ndarray:
    """The cogging torque over one revolution: one pull g (every harmonic of the revolution, random phases) of each
    of the 2p pole edges on each of the ``slots`` tooth edges."""
    rng = np.random.default_rng(slots * 100 + p)
    th = 2 * np.pi * np.arange(N_THETA) / N_THETA
    m = np.arange(1, 200)
    amp, phase = rng.uniform(0.5, 1.0, m.size), rng.uniform(0, 2 * np.pi, m.size)
    torque = np.zeros(N_THETA)
    for i in range(2 * p):
        for j in range(slots):
            x = th + 2 * np.pi * i / (2 * p) - 2 * np.pi * j / slots
            torque += (amp[:, None] * np.sin(m[:, None] * x[None, :] + phase[:, None])).sum(0)
    return torque


@pytest.mark.parametrize("p", range(POLE_PAIRS[0], POLE_PAIRS[1] + 1))
def test_each_electrical_ripple_is_named_with_the_pole_pairs_that_put_it_there(p):
    for kind, words in (("six_step", "commutation"), ("unbalance", "unbalance"), ("offset", "offset")):
        h = _lowest_harmonic(_three_phase_torque(p, kind))
        if h == 1:
            continue            # a 1-pole-pair motor's sensor offset is once per revolution: at 1x, not named
        named = [x for x in motor_causes(float(h), 1e-3, "axial_torque") if words in x]
        want = "pole pair" if p == 1 else "pole pairs"
        assert named and f"p = {p} {want}" in named[0], (kind, p, h, named)


@pytest.mark.parametrize("slots,p", [(9, 3), (12, 4), (12, 5), (18, 8), (27, 3), (14, 11), (36, 6), (15, 1)])
def test_cogging_is_named_at_the_order_the_pulls_of_every_pole_and_tooth_sum_to(slots, p):
    h = _lowest_harmonic(_cogging_torque(slots, p))
    assert (slots, p) in cogging_motors(h)
    assert any(f"least common multiple {h}" in x for x in motor_causes(float(h), 1e-3, "axial_torque"))


def test_only_whole_axial_torque_lines_get_a_motor_cause():
    assert motor_causes(18.0, 1e-3, "axial_force") == []
    assert motor_causes(18.0, 1e-3, "radial_torque") == []
    assert motor_causes(18.3, 1e-3, "axial_torque") == []
    assert motor_causes(1.0, 1e-3, "axial_torque") == []              # the imbalance's own line
    assert motor_causes(18.0005, 1e-3, "axial_torque") != []          # within the resolution
    assert cogging_motors(2) == [] and cogging_motors(9) == []         # LCM(S ≥ 3, 2p): even, 4 at the least


def test_the_diagnosis_names_the_motor_for_a_tz_line_and_keeps_bearing_causes_for_the_rest():
    lines = {"axial_torque": [18.0, 1.0], "axial_force": [18.0], "radial_force": [1.0, 3.08, 4.92]}
    model = SimpleNamespace(harmonics=lambda d: [SimpleNamespace(h=h) for h in lines.get(d, [])], typed_effects=tuple)
    state = SimpleNamespace(base=None)
    ctx = SimpleNamespace(test=None, df=0.25, omega=np.array([2 * np.pi * 5000 / 60]), runs=np.arange(1))
    diag = SimpleNamespace(ctx=ctx, hypotheses=[], model_given=True, state_before=state, state_after=state,
                           model=model)
    got = {(lc["direction"], lc["h"]): lc["causes"] for lc in line_causes(diag)}
    assert any("p = 3 pole pairs" in x for x in got[("axial_torque", 18.0)])
    assert ("axial_force", 18.0) not in got and ("axial_torque", 1.0) not in got
    assert any("ball-pass pair of a 8-ball bearing" in x for x in got[("radial_force", 3.08)])
