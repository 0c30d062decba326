"""One model line whose level steps between two runs, the others on their course (rwadist.diagnose.
describe_line_step: a ``line_property`` of property ``line_step``).

The new-user trial of session 52 (its own generator): the static imbalance 20 % stronger in the upper half of the runs
(a balance mass moved halfway through a test recorded in speed order) was described by nothing, 360-1480x the clean
error.  Here the family generator's wheels (tests/family_wheel.py) at the matrix's conditions: the runs above the
median speed are those of the same wheel with its imbalance line's C times ``factor`` (the truth: the change's
factor and the two runs it falls between); the same data with factor 1 hold no step."""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import diagnose_family_matrix as dfm  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.data import SteadyTest  # noqa: E402


def _stepped(index: int, factor: float, direction: str = "radial_force", seed: int = 1, name: str = "imbalance"):
    """(test, the speed rpm below which the runs keep the wheel's C): family wheel ``index``, its ``direction``
    line ``name`` (the imbalance) × ``factor`` in the runs above the median spinning speed."""
    wheel = dfm.wheels()[index]
    noise = dfm.CONDITIONS[index][2]
    a = family_test.steady_test(fw.steady(wheel, noise=noise, seed=seed))
    lines = [replace(ln, C=ln.C * factor) if ln.direction == direction and ln.name == name else ln
             for ln in wheel.lines]
    b = family_test.steady_test(fw.steady(fw.with_lines(wheel, lines), noise=noise, seed=seed))
    speeds = np.abs([r.speed for r in a.runs])
    median = float(np.median(speeds[speeds > 0]))
    runs = [rb if abs(ra.speed) > median else ra for ra, rb in zip(a.runs, b.runs)]
    return SteadyTest(runs, dict(a.meta or {})), median * 60 / (2 * np.pi)


def _steps(diag):
    return [u for u in diag.unexplained if u.parameters.get("property") == "line_step"]


@pytest.mark.slow
@pytest.mark.parametrize("index, factor", [(0, 1.2), (2, 0.8), (5, 1.2), (7, 1.2)])
def test_an_imbalance_changed_between_runs_is_one_line_step(index, factor):
    """Family wheels 0, 2, 5 and 7: one line_step on the radial force's h 1, its amplitude factor within 2 % of the
    truth, between the two runs either side of the median speed; no class added for it (on f0e05a4 wheel 7 added a
    missing_harmonic at h 0.955, C 0.48 x the 1x's, from the 1x's misfit in the Welch lobe at the slow runs, and read
    the step x 1.25: :data:`rwadist.effects.missing_harmonic_diagnose.APART_MIN_RATIO`)."""
    test, median_rpm = _stepped(index, factor)
    diag = api.diagnose(test)
    (u,) = _steps(diag)
    p = u.parameters
    assert p["direction"] == "radial_force" and p["h"] == pytest.approx(1.0, abs=1e-3)
    assert p["amplitude_ratio"] == pytest.approx(factor, rel=0.02)
    lo, hi = p["step_between_rpm"]
    assert lo <= median_rpm < hi
    assert u.causes[0].startswith("radial force h = 1 changed by x") and "the imbalance" in u.causes[0]
    assert [e.kind for e in diag.effects] == ["suspension_modes"]


@pytest.mark.slow
@pytest.mark.parametrize("index, name", [(0, "BPFO"), (5, "BPFO"), (6, "BPFO"), (1, "imbalance"), (2, "imbalance")])
def test_a_line_doubled_between_runs_is_a_step_not_a_law_nor_a_resonance(index, name):
    """The new-user trial of session 55 (its own generator, a 3 kg wheel to 10000 rpm and a 15 kg one to 2000 rpm): a
    bearing line doubling from the middle run was named an amplitude law Ω^2.46 (then, the law refused, a moving
    resonance of a rotor mode through its upper runs), and the imbalance doubling a 'wheel mode' of ζ 0.15, peak gain
    1.27 on the radial forces.  Here family wheels with their radial-force BPFO line or imbalance × 2 above the median
    speed: one line_step on that line, x 2 within 3 %, between the runs either side of the median speed, and no class
    added (:func:`rwadist.diagnose.describe_line_step.two_levels` in ``AmplitudeLaw.significant``, the fixed
    resonance's line points and the moving resonance's lines).  On ce37b70 wheels 0 and 6 named an amplitude law on
    the BPFO line, 5 and 2 (its imbalance) described a moving resonance through the upper runs (5 in place of the
    step), 1 one beside the step.  Not yet: wheel 3's BPFO (its step falls on its crossing of the translation mode,
    and is not described), wheel 4's imbalance (its 1x line read apart from the others in the upper runs only: a
    'wheel mode' at 41.9 Hz, ζ 0.11 still named), wheel 7's imbalance (a missing harmonic added, the step read x 3.3)."""
    wheel = dfm.wheels()[index]
    h = next(ln.h for ln in wheel.lines if ln.direction == "radial_force" and ln.name == name)
    test, median_rpm = _stepped(index, 2.0, name=name)
    diag = api.diagnose(test)
    steps = [u.parameters for u in _steps(diag)]
    assert [(p["direction"], round(p["h"], 3)) for p in steps] == [("radial_force", round(h, 3))], steps
    assert steps[0]["amplitude_ratio"] == pytest.approx(2.0, rel=0.03)
    lo, hi = steps[0]["step_between_rpm"]
    assert lo <= median_rpm < hi
    assert [e.kind for e in diag.effects] == ["suspension_modes"]
    assert not [u for u in diag.unexplained if u.signature == "moving_resonance"]


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 2, 5, 6])
def test_clean_family_wheels_hold_no_line_step(index):
    """The same wheels with nothing changed: no line_step (the lines' ratios through the fitted modes hold no step
    between runs, the crossings of the modes left out)."""
    test, _ = _stepped(index, 1.0)
    assert _steps(api.diagnose(test)) == []


@pytest.mark.slow
def test_a_lines_hump_through_its_parents_resonance_is_no_step(tmp_path):
    """The session-51 new-user generator's own wheel W3 (3 kg, I_zz/I_rr 1.25, axial mode 580 Hz, 1000-10000 rpm;
    benchmarks/newuser_generator_s51.py, written from the physics alone) with a quadratic Fz channel: h 7.26 = 2 x 3.63
    follows the square of its parent's course through the axial mode the fit does not locate, a hump over the five top
    runs (+7.9 to +18.2 dB over the model, back to +4.9) after 39 flat ones.  On ba1394f a 13.6 dB "step" between 8977
    and 9182 rpm was described (the change point's scatter, pooled over both sides, 2.3 dB; the hump's own 6.8): each
    level must be flat on its own, and none is read."""
    import subprocess

    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "w3_nonlinear"
    subprocess.run([sys.executable, str(root / "benchmarks" / "newuser_generator_s51.py"), "W3", "nonlinear", str(out),
                    "--seed", "2"], check=True, capture_output=True)
    assert [(u.parameters["direction"], u.parameters["h"]) for u in _steps(api.diagnose(str(out)))] == []


def _recorded_in_random_order(index: int, factor: float, k: int, seed: int = 1):
    """(test, each run's place in the recording by name): family wheel ``index``'s runs recorded in a random speed
    order (``Run.recorded``), its radial-force imbalance x ``factor`` from the ``k``-th recorded run on (k from 0)."""
    wheel = dfm.wheels()[index]
    noise = dfm.CONDITIONS[index][2]
    a = family_test.steady_test(fw.steady(wheel, noise=noise, seed=seed))
    lines = [replace(ln, C=ln.C * factor) if ln.direction == "radial_force" and ln.name == "imbalance" else ln
             for ln in wheel.lines]
    b = family_test.steady_test(fw.steady(fw.with_lines(wheel, lines), noise=noise, seed=seed))
    order = np.random.default_rng(index).permutation(len(a.runs))     # order[j]: the j-th run recorded
    position = np.argsort(order)                                      # each run's place in the recording
    runs = [replace(rb if position[i] >= k else ra, recorded=int(position[i]))
            for i, (ra, rb) in enumerate(zip(a.runs, b.runs))]
    return SteadyTest(runs, {}), {r.name: r.recorded for r in runs}


@pytest.mark.slow
@pytest.mark.parametrize("index", [0, 5])
def test_a_change_in_time_is_read_in_the_order_the_runs_were_recorded(index, tmp_path):
    """The session-55 new-user trials (their own generators: a 9.5 kg and a 3 kg wheel): the imbalance 1.5x (a
    bearing line 2x) from the middle of the runs as recorded, the runs recorded in a random speed order and runs.csv
    listing them so.  On ce37b70 the runs were read in speed order only: 'changed by x 0.667 between 4720 and 4880
    rpm', the model's C a blend of the two levels, 68-250x the clean error.  Here family wheels written so
    (:func:`rwadist.data.write_steady` writes runs.csv's rows in the recorded order, :func:`rwadist.data.read_steady`
    keeps it on each run) and diagnosed from the folder: one line_step on h 1, read in the recorded order, x 1.5
    within 2 %, between two runs recorded either side of the change; no class added, and no scatter of the line
    described beside it."""
    from rwadist.data import read_steady, write_steady

    test, place = _recorded_in_random_order(index, 1.5, 12)
    folder = write_steady(test, tmp_path / "shuffled")
    rows = (folder / "runs.csv").read_text().splitlines()[1:]
    back = read_steady(folder)
    assert [r.name for r in sorted(back.runs, key=lambda r: r.recorded)] == [x.split(",")[0] for x in rows]
    assert [r.recorded for r in sorted(back.runs, key=lambda r: r.recorded)] == list(range(len(rows)))
    diag = api.diagnose(str(folder))
    steps = [u.parameters for u in _steps(diag)]
    assert [(p["direction"], round(p["h"], 3), p["order"]) for p in steps] == [("radial_force", 1.0, "recorded")], steps
    assert steps[0]["amplitude_ratio"] == pytest.approx(1.5, rel=0.02)
    # the runs read last before the change and first after it, in the recording (a run whose 1x is not read, the
    # slowest, is not one of them)
    before, after = (place[n] for n in steps[0]["step_between_runs"])
    assert before < 12 <= after
    assert [e.kind for e in diag.effects] == ["suspension_modes"]
    assert not [u for u in diag.unexplained if u.signature == "partial_line" and u.parameters.get("h") == 1.0]
