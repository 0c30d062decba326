"""The coupled line sweep's grouped blocked loads (rwadist.coupling.line_groups) built in blocks of speeds: the same
values, to the bit, as in one block (each speed's phasors are its own), with and without a speed ripple."""
import numpy as np
import pytest

from rwadist import extended as ext
from rwadist import extended_ripple
from rwadist.coupling import line_groups
from rwadist.coupling import performance as perf
from rwadist.presets import preset


@pytest.mark.parametrize("rippled", [False, True])
def test_blocks_of_speeds_give_the_one_block_values(monkeypatch, rippled):
    desc = preset("ithaco-e")
    lines = tuple(ext.lines_from_model(desc.to_model(), desc.extended))
    ripple = extended_ripple.Ripple(f_hz=8.0, delta_omega=2.0, omega_ref=100.0, exponent=1.0) if rippled else None
    spec = perf.WheelSpec(desc.extended, lines, ripple=ripple)
    omega = np.linspace(10.0, 300.0, 97)
    k = extended_ripple.ripple_order(lines, omega, ripple) if rippled else 0
    whole = line_groups._grouped_lines(spec, omega, k)
    per_speed = len(lines) * (2 * k + 1)
    monkeypatch.setattr(line_groups, "GROUPED_POINTS", 10 * per_speed + 3)       # blocks of 10 speeds, the last of 7
    blocked = line_groups.grouped_lines_blocked(spec, omega, k)
    for a, b in zip(whole, blocked):
        assert a.shape == b.shape and np.array_equal(a, b)
    assert blocked[4].shape[0] == omega.size and np.abs(blocked[4]).max() > 0
