"""A gain of the measurement chain that depends on the line's frequency is described (``line_property`` of property
``frequency_response``: rwadist.diagnose.describe_filter), never a gain trend with speed nor nothing.

An independent trial (session 39: its own generator, a 6-kg wheel, 22 runs 400-5000 rpm at 6 kHz) put every channel
through a 4-pole Butterworth at 600 Hz: the h 9.8 lines lost 11 dB at the top speed, their C's were fitted 25-27 %
low and the rocking mode's damping 0.018 for 0.025, and nothing said why.  Here the detector on synthetic line ratios
(closed form: the Butterworth magnitude itself) and on the robustness matrix's family wheels through the same filter
(tests/test_describe_gain_trend.py's filter cells)."""
import importlib
import re
from types import SimpleNamespace

import numpy as np
import pytest

describe_filter = importlib.import_module("rwadist.diagnose.describe_filter")

RPM = np.linspace(400.0, 5000.0, 22)
#: (direction, h) of the synthetic lines: a cage line, the imbalance, ball-pass lines and their multiples
LINES = (("radial_force", 0.38), ("radial_force", 1.0), ("radial_force", 3.1), ("radial_force", 4.9),
         ("radial_force", 9.8), ("radial_torque", 1.0), ("radial_torque", 6.2), ("axial_force", 3.1),
         ("axial_force", 6.2), ("axial_force", 9.8))


def _butterworth_db(f, corner, order, low=True):
    x = f / corner if low else corner / f
    return -10.0 * np.log10(1.0 + x ** (2 * order))


def _described(monkeypatch, db_of, seed=0, lines=LINES):
    """The detector's records on lines whose measured-over-predicted ratios (dB) are ``db_of(direction, h, rpm, f)``
    plus 0.05 dB of scatter and an offset of their own (a C fitted to the mean)."""
    rng = np.random.default_rng(seed)
    read = []
    for d, h in lines:
        f = h * RPM / 60.0
        db = db_of(d, h, RPM, f) + rng.uniform(-3, 3) + 0.05 * rng.standard_normal(RPM.size)
        read.append((d, h, np.arange(RPM.size), RPM, f, db, False))
    monkeypatch.setattr(describe_filter, "read_lines", lambda ctx, state, runs: read)
    ctx = SimpleNamespace(runs=np.arange(RPM.size), omega=RPM * 2 * np.pi / 60.0,
                          channels=("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))
    return describe_filter.frequency_response(ctx, None, lambda chans, hs, runs: (0.1, 0.0))


@pytest.mark.parametrize("corner, order", [(600.0, 4), (450.0, 2), (550.0, 8)])
def test_a_low_pass_on_every_channel_is_described_with_its_corner_and_order(monkeypatch, corner, order):
    (u,) = _described(monkeypatch, lambda d, h, rpm, f: _butterworth_db(f, corner, order))
    p = u.parameters
    assert (p["property"], p["shape"], p["order"]) == ("frequency_response", "low-pass", order)
    assert p["corner_Hz"] == pytest.approx(corner, rel=0.03)
    # the loss at the edge of the band read is the filter's own there
    edge = max(h for _, h in LINES) * RPM.max() / 60.0
    assert p["edge_Hz"] == pytest.approx(edge) and p["loss_dB_at_edge"] == pytest.approx(
        -_butterworth_db(edge, corner, order), abs=0.3)
    assert set(p["directions"]) >= {"radial_force", "axial_force"} and {"Fx", "Fz"} <= set(u.channels)
    # the causes name where the fitted magnitude takes 1 dB (half the corner for one pole only: review39)
    f_1db = float(re.search(r"above ([0-9.]+) Hz \(where it takes 1 dB\)", u.causes[0]).group(1))
    assert -_butterworth_db(f_1db, p["corner_Hz"], order) == pytest.approx(1.0, abs=0.02)


def test_a_high_pass_is_described_as_one(monkeypatch):
    (u,) = _described(monkeypatch, lambda d, h, rpm, f: _butterworth_db(f, 40.0, 2, low=False))
    assert u.parameters["shape"] == "high-pass" and u.parameters["corner_Hz"] == pytest.approx(40.0, rel=0.05)


@pytest.mark.parametrize("case", ["noise", "speed_gain", "one_line_law", "one_direction", "one_h", "radial_only",
                                  "common_law"])
def test_what_is_no_gain_of_the_frequency_is_not_described(monkeypatch, case):
    """Scatter alone; one gain falling 1 dB per 1000 rpm on every line (a gain trend with speed: the other detector's);
    one line's own amplitude law (Ω^3 on h 9.8 of the radial force: the amplitude_law class's); a filter that reaches
    one direction's lines alone (a chain filter acts on every channel: one direction's lines bending with frequency may
    be a suspension mode's misfit above it); a 'filter' on the lines of one h alone, in two directions (on one h a
    gain of the frequency is a gain of the speed: a bearing line's own law acts on each of its directions); the radial
    directions bent alike with the axial lines flat at the same frequencies (the force's transfer is in the torque
    through the height: one mode's misfit bends both); every line departing from Ω² by one law Ω^3 (review: described
    as a 1-pole low-pass at the corner grid's end before)."""
    def db_of(d, h, rpm, f):
        if case == "speed_gain":
            return -1.0 * rpm / 1000.0
        if case == "one_line_law":
            return 20.0 * np.log10(rpm / rpm[0]) if (d, h) == ("radial_force", 9.8) else 0.0 * rpm
        if case == "one_direction":
            return _butterworth_db(f, 300.0, 4)
        if case == "radial_only":       # the radial force and torque bent alike, the axial lines flat beside them
            return _butterworth_db(f, 600.0, 4) if d.startswith("radial") else 0.0 * rpm
        if case == "common_law":        # every line Ω^3: below any corner a low-pass is a power of f, one law
            return 20.0 * np.log10(rpm / rpm[0])
        if case == "one_h":
            return _butterworth_db(f, 500.0, 4) if h == 9.8 else 0.0 * rpm
        return 0.0 * rpm

    # one_direction: a chain filter, but only the radial force has lines in its band (family wheel 3 through a
    # 600-Hz filter: its h 4.8-8.0 radial-force lines alone); the other directions' flat lines there contradict it
    # otherwise (a filter bending one direction's lines only is no filter of the chain)
    lines = (LINES[:5] + (("radial_torque", 1.0), ("axial_force", 1.0), ("axial_force", 2.0))
             if case == "one_direction" else LINES)
    assert _described(monkeypatch, db_of, lines=lines) == []
