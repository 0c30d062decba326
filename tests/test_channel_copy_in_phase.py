"""A channel's copy of one channel of a radial pair is named on the channel it copies, in phase, not on its partner a
quarter turn away (session 68's new-user trial: Fz += 0.3·Fx on co-rotating lines read "0.307 × Fy at +95.6°", and
what the copy's removal left was described as a ``partial_line`` of the wheel on Fz, "a rub").

A co-rotating line's Fy is its Fx a quarter turn later, so on such lines Fz = κ·Fx is also Fz = ±jκ·Fy: both
sources fit and hold the same lines.  A crosstalk term is a real gain; the source read in phase is named.  Data: the
family generator (tests/family_wheel.py, numpy only) on the trial's wheel A (every radial line co-rotating), the copy
added to the records; the truth is the factor added."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_wheel as fw  # noqa: E402
from family_test import steady_test  # noqa: E402


@pytest.mark.parametrize("source, partner, gain, seed", [("Fy", "Fx", 0.3, 0), ("Fx", "Fy", -0.2, 1)])
def test_the_copy_is_named_on_the_channel_it_copies_in_phase(source, partner, gain, seed):
    from rwadist.diagnose.channel_copy import find_channel_copies
    from rwadist.diagnose.engine import Context
    from rwadist.spectra import compute_spectra

    data = fw.steady(fw.trial_wheel_a(), noise=0.01, seed=seed)
    data.signals[:, fw.CHANNELS.index("Fz")] += gain * data.signals[:, fw.CHANNELS.index(source)]
    test = steady_test(data)
    (cp,) = find_channel_copies(Context(compute_spectra(test), test=test))
    assert (cp.source, cp.target, cp.alternatives) == (source, "Fz", (partner,))
    assert cp.kappa.real == pytest.approx(gain, rel=0.02)
    assert abs(np.degrees(np.angle(cp.kappa * np.sign(gain)))) < 2.0


def test_the_users_command_takes_the_copy_out_whole():
    """``rwadist.diagnose`` (no model) of Fz += 0.3·Fy: the copy named on Fy, nothing of it left for a partial line."""
    from rwadist.api import diagnose

    data = fw.steady(fw.trial_wheel_a(), noise=0.01, seed=2)
    data.signals[:, fw.CHANNELS.index("Fz")] += 0.3 * data.signals[:, fw.CHANNELS.index("Fy")]
    diag = diagnose(steady_test(data))
    (u,) = [u for u in diag.unexplained if u.signature == "channel_copy"]
    assert u.parameters["source"] == "Fy" and u.parameters["gain"] == pytest.approx(0.3, rel=0.02)
    assert not [v for v in diag.unexplained if v.signature == "partial_line" and "Fz" in v.channels]
