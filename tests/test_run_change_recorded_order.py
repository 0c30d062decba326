"""A gain drifting in the order the runs were recorded, read in that order (rwadist.diagnose.describe_structure.
run_change, _recorded_drift).

New-user trial nuL (session 58, an independent generator): every channel's gain rising 1.00 -> 1.15 over 30 runs
recorded in shuffled speed order, a folder whose ``runs.csv`` rows are that order (docs/formats.md, section 1): the
drift was described on one seed of three (the runs' scatter about the lines' trends with speed 0.25-0.6 dB), said
``recorded_order: unknown`` there, and passed over in silence on the other two (error 51-78x the clean level).  Here
the family's drift (tests/family_effects.Drift, ±3 %: 0.52 dB over the test, under the 0.25 dB scatter the runs alone
must show) on wheels 0, 3 and 6, written with ``runs.csv`` in its recording order; on the code before, nothing was
described; and a step at the middle run recorded.  The same wheels clean, their rows shuffled alike, describe
nothing."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402

SEED = 5            # the drift's shuffled recording order (family_effects.Drift)


class Step(fe.Drift):
    """The gain stepping by ``fraction`` from the middle of the (shuffled) recording order on."""

    def _factor(self, run, n_runs):
        order = np.random.default_rng(self.params["seed"]).permutation(n_runs)
        return 1.0 + self.params["fraction"] * (order[run] >= n_runs // 2)


def _in_recorded_order(index: int, fraction: float, tmp_path, kind=fe.Drift) -> Path:
    """Family wheel ``index``'s steady test with a drift (or ``kind``) of ``fraction`` (0: none), its ``runs.csv`` rows
    in the order the runs were recorded."""
    wheel = fw.family()[index]
    data = fw.steady(wheel, seed=1, noise=0.01, effects=[kind(fraction=fraction, seed=SEED)])
    path = fw.write_steady(data, tmp_path / "data", wheel.name)
    place = np.random.default_rng(SEED).permutation(len(data.speeds))    # run i (by speed) recorded at place[i]
    header, *rows = (path / "runs.csv").read_text().splitlines()
    (path / "runs.csv").write_text("\n".join([header] + [rows[i] for i in np.argsort(place)]) + "\n")
    return path


@pytest.mark.parametrize("index", [0, 3, 6])
def test_a_small_drift_is_read_in_the_order_of_recording(index, tmp_path):
    diag = api.diagnose(api.read(_in_recorded_order(index, 0.06, tmp_path)))
    assert [e["kind"] for e in diag.model.effects] == ["suspension_modes"]
    (u,) = [u for u in diag.unexplained if u.signature == "run_change"]
    p = u.parameters
    truth = 20 * np.log10(1.03 / 0.97)
    assert p["pattern"] == "spread" and p["recorded_order"] == "known"
    assert p["drift_dB"] == pytest.approx(truth, rel=0.1) and p["rank_correlation"] > 0.9
    assert u.causes[0].startswith("the load cell's or its amplifier's gain drifting over the test")


@pytest.mark.parametrize("index", [0, 5])
def test_clean_runs_in_a_shuffled_order_hold_no_drift(index, tmp_path):
    diag = api.diagnose(api.read(_in_recorded_order(index, 0.0, tmp_path)))
    assert [u for u in diag.unexplained if u.signature == "run_change"] == []
    # nor one line's drift in that order (tests/test_line_drift_recorded_order.py)
    assert [u for u in diag.unexplained if u.parameters.get("property") == "line_drift"] == []


@pytest.mark.parametrize("index", [0, 3, 6])
def test_a_step_is_placed_in_the_order_of_recording(index, tmp_path):
    """A 10 % step (0.83 dB) from the middle run recorded on: the runs after it set apart, the place and the size
    said (trial nuL2: such a step was called a drift, "0.04 dB scatter", on one seed of two)."""
    diag = api.diagnose(api.read(_in_recorded_order(index, 0.1, tmp_path, kind=Step)))
    (u,) = [u for u in diag.unexplained if u.signature == "run_change"]
    p, n = u.parameters, fw.family()[index].n_speeds
    assert p["pattern"] == "step" and p["recorded_order"] == "known"
    assert p["recorded_before_the_step"] == n // 2 and len(p["runs"]) >= n - n // 2 - 2
    # read with the runs' common trend with speed taken off (the model leans towards the runs after the step): wheels
    # 0 and 3 read 0.63 and 0.70 dB without (-24 %, -16 %), 0.75 and 0.80 with it
    assert p["step_dB"] == pytest.approx(20 * np.log10(1.1), rel=0.12) and p["speed_trend_taken_off"]
    assert u.causes[0].startswith("the wheel or the fixture re-mounted")


def test_the_speed_trend_is_fitted_with_the_step_and_not_where_they_are_one():
    """gains = step on the runs recorded later + a trend with log speed common to all (closed form): the later runs
    mostly at the high speeds, so the sides' medians mix the step with the trend; fitted together, the trend comes
    back exactly (mean 0).  Later runs at the high speeds alone: step and trend are one, and none is taken off."""
    from rwadist.diagnose.run_order import speed_trend

    rng = np.random.default_rng(7)
    x = np.log(np.linspace(300.0, 9000.0, 40))
    u = (x - x.mean()) / x.std()
    trend = -0.2 * u + 0.05 * u * u
    later = rng.random(40) < 0.2 + 0.6 * (u > 0)
    gains = 0.67 * later + trend
    got = speed_trend(x, gains, later)
    np.testing.assert_allclose(got, trend - trend.mean(), atol=1e-12)
    assert abs(np.median(gains[later]) - np.median(gains[~later]) - 0.67) > 0.1     # what the medians alone read
    assert speed_trend(x, gains, u > 0.3) is None


@pytest.mark.parametrize("index", [0, 6])
def test_a_drift_of_the_force_bridges_alone_is_read_on_the_forces(index, tmp_path):
    """Session 60's trial: the forces' gain falling 1.5 dB over the test, the torques steady, was read "in Fx Fy Fz Tx
    Ty Tz" at −1.22 dB (the median of every line, the torques' steady ones among them).  Here the three force channels
    (lines and noise) of each run scaled by 1 + 0.2·(τ − ½), τ its place in the recording order: read on the forces
    alone, at the drift within 10 %."""
    wheel = fw.family()[index]
    data = fw.steady(wheel, seed=1, noise=0.01)
    place = np.random.default_rng(SEED).permutation(len(data.speeds))
    gain = 1.0 + 0.2 * (place / (len(place) - 1) - 0.5)
    forces = [fw.CHANNELS.index(c) for c in ("Fx", "Fy", "Fz")]
    data.signals[:, forces] *= gain[:, None, None]
    path = fw.write_steady(data, tmp_path / "data", wheel.name)
    header, *rows = (path / "runs.csv").read_text().splitlines()
    (path / "runs.csv").write_text("\n".join([header] + [rows[i] for i in np.argsort(place)]) + "\n")
    diag = api.diagnose(api.read(path))
    (u,) = [u for u in diag.unexplained if u.signature == "run_change"]
    assert u.channels == ("Fx", "Fy", "Fz"), u.channels
    assert u.parameters["drift_dB"] == pytest.approx(20 * np.log10(1.1 / 0.9), rel=0.1)


def test_a_change_read_on_some_channels_is_taken_out_of_those_alone():
    """Review of session 60: the drift read on the forces alone was still divided out of every channel when the search
    ran again (``scale_runs``), putting its inverse into the steady torques.  The factors of a ``run_change`` record
    (``run_steps``: a ``RunSteps`` carrying the record's channels, kept by ``step_sets``) scale those channels only."""
    import importlib
    from types import SimpleNamespace

    from rwadist.data import Run, SteadyTest

    describe = importlib.import_module("rwadist.diagnose.describe")
    run_gains = importlib.import_module("rwadist.diagnose.run_gains")
    ones = {c: np.ones(8) for c in fw.CHANNELS}
    test = SteadyTest([Run(speed=100.0, sample_rate=1000.0, signals=dict(ones)) for _ in range(2)], {})
    steps = describe.RunSteps({1: 20.0, 0: float("nan")}, ("Fx", "Fy", "Fz"))
    scaled = describe.scale_runs(test, {1: steps[1]}, steps.channels)
    assert [float(scaled.runs[1].signals[c][0]) for c in fw.CHANNELS] == [0.1, 0.1, 0.1, 1.0, 1.0, 1.0]
    assert float(scaled.runs[0].signals["Fx"][0]) == 1.0
    diag = SimpleNamespace(unexplained=[])
    got = run_gains.step_sets(diag, lambda d, every_run=True: steps, located=0)
    assert got and all(getattr(s, "channels", None) == ("Fx", "Fy", "Fz") for s in got)


def test_a_direction_of_one_line_is_judged_on_that_line():
    """Review of session 60: a direction's own factor asked for two lines a run, so a direction of one model line was
    always left out of a change every direction shares.  Here 20 runs drifting 0 -> −1.5 dB on the radial force's two
    lines and the radial torque's one, the axial force's two lines steady (0.05 dB noise): those two directions kept."""
    from types import SimpleNamespace

    from rwadist.diagnose.describe_structure import LineRatios
    from rwadist.diagnose.run_gains import in_changed_directions

    rng = np.random.default_rng(3)
    n = 20
    drift = np.linspace(0.0, -1.5, n)

    def ratios(direction, hs, moves):
        run = np.tile(np.arange(n), len(hs))
        line = np.repeat(np.arange(len(hs)), n)
        q = (drift[run] if moves else 0.0) + 0.05 * rng.standard_normal(run.size)
        spin = 10.0 + run
        h = np.asarray(hs, float)[line]
        return LineRatios(direction, q, h * spin, run, spin, line, h, np.full(run.size, 1e4))

    read = [ratios("radial_force", [1.0, 2.7], True), ratios("radial_torque", [1.0], True),
            ratios("axial_force", [2.7, 3.9], False)]
    kept = in_changed_directions(SimpleNamespace(runs=np.arange(n)), read)
    assert [r.direction for r in kept] == ["radial_force", "radial_torque"]
