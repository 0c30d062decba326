"""Radial lines of a fixed direction in the x-y plane (rwadist.diagnose.describe_direction: a ``line_property`` of
property ``fixed_direction``).

The session-52 generator (benchmarks/newuser_generator_s52.py, written from the physics alone) gives its bearing lines
a planar load of one direction, Fx = A·cos(θ), Fy = A·sin(θ), θ drawn once per record: on its sweeps each such line
keeps its own x/y power ratio in every slice.  On bc9a831 the W1 sweep (seed 1) had "Fx reads 1.58 x Fy on the lines
h 2, 5.39 (2 of the 6 read)" described as a channel gain; the truth is no gain and four planar lines at −25.6°, 17.7°,
32.4°, −2.9° from +Fx.  The generator's θ are read here by replaying its own random draws (its ``synth`` wrapped, the
draws it makes repeated on a copy of its generator), not from rwadist."""
import importlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from rwadist import api

ROOT = Path(__file__).resolve().parents[1]


def _s52_sweep(wheel: str, seed: int, out: Path) -> dict:
    """The generator's sweep of ``wheel`` (seed ``seed``) written to ``out``; (direction, h) -> θ degrees in
    [−90, 90) of its planar lines, as the generator drew them."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        gen = importlib.import_module("newuser_generator_s52")
    finally:
        sys.path.pop(0)
    drawn: dict = {}
    synth = gen.synth

    def recording(p, lines, Om_t, theta_t, rng, *args, **kw):
        copy = np.random.default_rng()
        copy.bit_generator.state = rng.bit_generator.state
        for d, h, _, sense in lines:                    # the generator's draws per line: its phase, then θ
            copy.uniform(0, 2 * np.pi)
            ang = copy.uniform(0, np.pi)
            if sense == "planar":
                drawn[(d, float(h))] = float(np.degrees((ang + np.pi / 2) % np.pi - np.pi / 2))
        return synth(p, lines, Om_t, theta_t, rng, *args, **kw)

    gen.synth = recording
    argv = sys.argv
    try:
        sys.argv = ["newuser_generator_s52.py", "--wheel", wheel, "--case", "sweep", "--seed", str(seed),
                    "--out", str(out)]
        gen.main()
    finally:
        gen.synth, sys.argv = synth, argv
    return drawn


def _direction_records(diag) -> list:
    return [u for u in diag.unexplained if u.parameters.get("property") == "fixed_direction"]


@pytest.mark.slow
def test_planar_lines_of_their_own_directions_are_described_with_them_and_no_gain(tmp_path):
    drawn = _s52_sweep("W1", 1, tmp_path / "w1")
    truth = json.loads((tmp_path / "w1_truth.json").read_text())
    diag = api.diagnose(str(tmp_path / "w1" / "sweep.csv"))
    assert [u for u in diag.unexplained if u.parameters.get("property") == "channel_gain"] == []
    (u,) = _direction_records(diag)
    p = u.parameters
    assert (p["reference"], p["channel"]) == ("Fx", "Fy")
    planar = {h for (d, h) in drawn if d == "radial_force"}
    rotating = {ln["h"] for ln in truth["lines"] if ln["direction"] == "radial_force" and ln["sense"] == "co"}
    assert {round(h, 2) for h in p["lines_h"]} >= {2.0, 3.61, 5.39}
    for h, q, psi in zip(p["lines_h"], p["counter_over_co"], p["direction_deg"]):
        (true_h,) = [x for x in planar if abs(x - h) < 0.01]       # only planar lines are listed
        # a load along one direction: equal parts; its direction within 2 degrees (modulo a half turn)
        assert 0.9 <= q <= 1.1, (h, q)
        off = (psi - drawn[("radial_force", true_h)] + 90) % 180 - 90
        assert abs(off) < 2.0, (h, psi, drawn[("radial_force", true_h)])
    assert {round(h, 3) for h in p["lines_alike_h"]} <= {round(h, 3) for h in rotating}
    assert p["lines_alike_h"], p


@pytest.mark.slow
def test_lines_whose_direction_changes_from_run_to_run_are_not_of_a_fixed_direction(family_clean_cell):
    """Family wheel 3 (tests/family_wheel.py): its co + counter lines draw each part's phase per run, so each run's
    ellipse has its own direction and no line keeps an x/y ratio: nothing of a fixed direction is described."""
    _, folder = family_clean_cell(3)
    summary = json.loads((folder / "report" / "summary.json").read_text())
    assert [u for u in summary["unexplained"] if (u.get("parameters") or {}).get("property") == "fixed_direction"] == []
