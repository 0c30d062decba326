"""One line drifting over the test, read in the order the runs were recorded: a ``line_property`` of ``line_drift``.

New-user trial nuR (session 61, an independent generator: a 12-kg wheel, its bearing line h 3.31 growing x 1 -> x 3
in amplitude over 40 runs recorded in shuffled speed order, ``runs.csv`` in that order): nothing was described on
either seed (11x the clean error): a step of one line (``line_step``) or a change of every line (``run_change``) were
sought, a drift of one line was not.  Here family wheels 0 and 6 with their radial-force BPFO line (each wheel's
own h) grown linearly x 1 -> x ``GROWTH`` in amplitude along a shuffled recording order, ``runs.csv`` written in that
order (wheels 0 and 5 clean, rows shuffled alike, describe no drift: tests/test_run_change_recorded_order.py).
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402

SEED = 5            # the shuffled recording order
GROWTH = 2.5


class LineDrift(fe.Drift):
    """The radial-force line ``name`` grown x 1 -> x (1 + fraction) in amplitude along the recording order."""

    def __init__(self, fraction, seed, name="BPFO"):
        super().__init__(fraction=fraction, seed=seed)
        self.params["name"] = name

    def _factor(self, run, n_runs):
        place = np.random.default_rng(self.params["seed"]).permutation(n_runs)[run] / max(n_runs - 1, 1)
        return 1.0 + self.params["fraction"] * place

    def components(self, comp, omega, run, rng, wheel):
        g = np.array([self._factor(run, self._n_runs) if (d == "radial_force" and tag == self.params["name"]) else 1.0
                      for d, tag in zip(comp.direction, comp.tag)])
        return fw.Components(comp.direction, comp.w, comp.sense, comp.c * g, comp.tag)


def _recorded(index: int, fraction: float, tmp_path) -> Path:
    wheel = fw.family()[index]
    data = fw.steady(wheel, seed=1, noise=0.01, effects=[LineDrift(fraction, SEED)])
    path = fw.write_steady(data, tmp_path / "data", wheel.name)
    place = np.random.default_rng(SEED).permutation(len(data.speeds))    # run i (by speed) recorded at place[i]
    header, *rows = (path / "runs.csv").read_text().splitlines()
    (path / "runs.csv").write_text("\n".join([header] + [rows[i] for i in np.argsort(place)]) + "\n")
    return path


def _drifts(diag):
    return [u for u in diag.unexplained if u.parameters.get("property") == "line_drift"]


@pytest.mark.parametrize("index", [0, 6])
def test_one_line_drifting_in_the_order_of_recording_is_described(index, tmp_path):
    wheel = fw.family()[index]
    h = next(ln.h for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "BPFO")
    diag = api.diagnose(api.read(_recorded(index, GROWTH - 1.0, tmp_path)))
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes"]
    (u,) = _drifts(diag)
    p = u.parameters
    assert p["direction"] == "radial_force" and p["h"] == pytest.approx(h, abs=2e-3)
    assert p["order"] == "recorded" and set(u.channels) == {"Fx", "Fy"}
    # a Theil-Sen line through the dB of a linear growth: below the end-to-end ratio, above half of it in dB
    assert 0.5 * 20 * np.log10(GROWTH) < p["change_dB"] <= 1.05 * 20 * np.log10(GROWTH)
    assert abs(p["others_change_dB"]) < 0.2 * p["change_dB"]
    assert "drifted by x" in u.causes[0]
    # the other lines are not read as a change of every line
    assert [x for x in diag.unexplained if x.signature == "run_change"] == []
