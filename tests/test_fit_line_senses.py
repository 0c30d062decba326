"""``rwadist fit`` writes each radial line's rotation sense as the x/y phase reads it.

Session 61's new-user trial (a 3-kg wheel, a counter-rotating line): the plain fit's model held no sense, so every
consumer (``model show``, the FMU, the PSD's x/y pattern) read the counter-rotating line co-rotating, while
``rwadist diagnose`` of the same data said counter.

Data: family wheels (tests/family_wheel.py, time-integrated physics), whose bearing lines have a known co-rotating share
of their power (the cage counter-rotating, BPFI 0.8 co, 2xBSF planar) and random phases per run."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402
from cli_run import run  # noqa: E402


def _expected(co: float) -> str:
    """The sense a line of co-rotating share ``co`` reads (rwadist.line_senses.SENSE_SHARE 0.75 either way), with a
    margin for the noise of its x/y phase; '' where the share is too near the threshold to say."""
    return "co" if co >= 0.85 else "counter" if co <= 0.15 else "planar" if 0.35 <= co <= 0.65 else ""


@pytest.mark.parametrize("index", [2, 5])
def test_plain_fit_model_holds_the_measured_senses(tmp_path, capsys, index):
    """The command a user types (``rwadist fit DATA -o model.json``, then ``rwadist model show``): every radial line of
    the wheel the fit finds carries the sense its generator's co-rotating share gives (the cage 'counter', a
    co-rotating ball pass 'co', a planar line 'planar'); the imbalance none (co-rotating, the diagnosis' counter_rotation
    measures it); and the table shows them."""
    from rwadist import api

    wheel = fw.family()[index]
    data = fw.write_steady(fw.steady(wheel, seed=1 + 100 * index), tmp_path / "data")
    code, out, err = run(capsys, "fit", data, "-o", tmp_path / "model.json", "--no-report")
    assert code == 0, err
    model = api.load_model(tmp_path / "model.json")
    checked = 0
    for line in (ln for ln in wheel.lines if ln.direction in ("radial_force", "radial_torque")):
        got = [hm for hm in model.harmonics(line.direction) if abs(hm.h - line.h) < 2e-3 * line.h]
        if not got:
            continue
        if abs(line.h - 1.0) < 1e-3:
            assert got[0].sense is None, (line.name, got[0])
            continue
        want = _expected(line.co)
        if want:
            assert got[0].sense == want, (line.direction, line.name, line.h, line.co, got[0].sense)
            checked += 1
    assert checked >= 3, checked
    code, shown, err = run(capsys, "model", "show", tmp_path / "model.json")
    assert code == 0, err
    counter = [ln for ln in wheel.lines if ln.co <= 0.15 and ln.direction == "radial_force"]
    assert counter and any(f"{counter[0].h:7.3f} counter" in row for row in shown.splitlines()), shown
