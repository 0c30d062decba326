"""``broadband_floor``'s one law of a unit group's channels (:class:`rwadist.effects.broadband_floor_diagnose.FloorGroup`):
its refit keeps only the channels whose own part grows on the held-out runs (:data:`PART_GROWTH_T`), so that the summed
evidence of a floor on one channel does not name a floor on the group's other channels.  Checked against the injected
truth: which channels carry the floor (E wheel, 30 speeds over 300-3000 rpm, 2048 samples at 3840 Hz, as
tests/test_diagnose_floor_record.py)."""
from __future__ import annotations

import numpy as np
import pytest

from rwadist.diagnose.engine import Context, initial_state
from rwadist.effects.broadband_floor_diagnose import GROWTH_T, PART_GROWTH_T, FloorGroup
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.spectra import compute_spectra


def _group(channels: str):
    wheel = preset("ithaco-e")
    spec = f"broadband_floor:channels={channels},level=0.05,exponent=3,fc_hz=60"
    test = simulate_with_injections(wheel, [parse(spec)], np.linspace(300.0, 3000.0, 30), physics="extended",
                                    seed=21, sample_rate=3840.0, n_samples=2048, noise=0.01, test_stand=True)
    ctx = Context(compute_spectra(test, nperseg=512), test=test)
    state = initial_state(ctx, wheel.to_model())
    g = FloorGroup.fit(ctx, state, ["Fx", "Fy", "Fz"], ctx.fit_runs)
    assert g is not None and g.channels == ("Fx", "Fy", "Fz")      # fitted on every force channel, floor or none
    ts = {e.channel: (lambda d, s: d / s)(*e.growth_evidence(ctx, state, ctx.held_runs)) for e in g.parts}
    return g, g.refit(ctx, state), ts


@pytest.mark.parametrize("channels, kept", [("Fz", ()), ("Fx+Fy+Fz", ("Fx", "Fy", "Fz"))])
def test_a_group_keeps_only_the_channels_the_floor_reaches(channels, kept):
    g, refit, ts = _group(channels)
    reached = set(channels.split("+"))
    assert all(ts[c] > PART_GROWTH_T for c in reached), ts
    if len(reached) == 1:
        # the other channels' parts are fitted to noise, while the whole's summed evidence passes on Fz's alone
        assert all(abs(ts[c]) < 1.0 for c in set(g.channels) - reached), ts
        assert not refit.significant()
    else:
        assert refit.channels == kept and refit.significant() and refit.growth_t > GROWTH_T
