"""A suspension mode no recorded channel reads is said so (rwadist.diagnose.modes_status: status "unread").

The new-user trial of session 54 (its own generator, a test of the forces Fx, Fy, Fz alone): "rocking at rest not
located (the fit ended at 3964 Hz)" and nothing about the torques never recorded, while the model held the rocking
and I_zz/I_rr at the fit's starting values.  Here family wheel 0 (tests/family_wheel.py) with its forces only, and the
same data with all six channels."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import diagnose_family_matrix as dfm  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.data import Run, SteadyTest  # noqa: E402


@pytest.mark.slow
def test_a_mode_no_recorded_channel_reads_is_said_unread_and_only_then():
    wheel = dfm.wheels()[0]
    test = family_test.steady_test(fw.steady(wheel, noise=dfm.CONDITIONS[0][2], seed=1))
    forces = SteadyTest([Run(speed=r.speed, sample_rate=r.sample_rate, t0=r.t0, name=r.name,
                             signals={c: r.signals[c] for c in ("Fx", "Fy", "Fz")}) for r in test.runs], {})
    status = api.diagnose(forces).summary()["suspension_modes_status"]
    assert status is not None and status["status"] == "unread" and status["unread"] == ["rocking"], status
    assert "no Tx or Ty recorded" in status["text"]
    assert api.diagnose(test).summary()["suspension_modes_status"] is None
