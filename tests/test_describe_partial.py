"""``partial_line`` (rwadist/diagnose/describe_partial.py) counts a run as one a line is absent from only where the
line is resolved from the other lines of its direction's model: where they predict no more power in its window than
it does (:func:`~rwadist.diagnose.describe_partial.others_in_window`).

Data: the E wheel of tests/test_diagnose.py (rwadist's simulator, no modes, 36 runs at 600-4800 rpm, Welch bins of
FS/NPERSEG = 1.875 Hz) with two lines written into its radial-force records by numpy: speed sidebands of the 1× line
at h 0.94 and 1.06 (a modulation depth of 0.2: each side 0.1 of the carrier) in every run, and a line at h 2.7 (half
the 1× line's C) in every third run only.  The state read is the generator's truth: the preset's lines, the two
sidebands and the 2.7 line at their injected C, nothing fitted.  So the truth is known run by run: the sidebands are
present in every run, the 2.7 line in every third.
"""
from __future__ import annotations

import functools
from copy import deepcopy

import numpy as np
from test_diagnose import FS, NPERSEG, TRUTH, N, spectra

from rwadist.diagnose.constants import LINE_HALF
from rwadist.diagnose.describe import Residual, describe_residual
from rwadist.diagnose.describe_partial import others_in_window
from rwadist.diagnose.engine import Context, initial_state
from rwadist.model import Harmonic
from rwadist.presets import preset
from rwadist.teststand import simulate_steady

SPEEDS = np.linspace(600.0, 4800.0, 36)
#: speed sidebands of the radial 1× line: offset per revolution, modulation depth (each side m/2 of the carrier)
DELTA, DEPTH = 0.06, 0.2
#: the partial line: h, C relative to the 1× line's, present in the runs i % EVERY == 0
PARTIAL_H, PARTIAL_C, EVERY = 2.7, 0.5, 3


@functools.lru_cache(maxsize=None)
def _truth_state(onset_rpm: float | None = None, stop_rpm: float = np.inf):
    """(context, the generator's truth as a state) of the records with the sidebands and the partial line (in every
    third run; with ``onset_rpm``, in the runs above that speed, and below ``stop_rpm``, instead)."""
    test = simulate_steady(preset("ithaco-e"), SPEEDS, sample_rate=FS, n_samples=N, modes=False, noise=0.01, seed=5)
    c1 = TRUTH.empirical["radial_force"][0].C
    lines = [(1 - DELTA, DEPTH / 2 * c1, 1), (1 + DELTA, DEPTH / 2 * c1, 1), (PARTIAL_H, PARTIAL_C * c1, EVERY)]
    rng = np.random.default_rng(7)
    for i, run in enumerate(test.runs):
        t = np.arange(run.n_samples) / run.sample_rate
        w = abs(run.speed)
        for h, C, every in lines:
            if (i % every == 0) if (onset_rpm is None or h != PARTIAL_H) else \
                    onset_rpm < w * 60 / (2 * np.pi) < stop_rpm:
                phase = h * w * t + rng.uniform(0, 2 * np.pi)
                run.signals["Fx"] = run.signals["Fx"] + C * w**2 * np.cos(phase)
                run.signals["Fy"] = run.signals["Fy"] + C * w**2 * np.sin(phase)
    model = deepcopy(TRUTH)
    model.empirical["radial_force"] = sorted(model.harmonics("radial_force") +
                                             [Harmonic(h=h, C=C) for h, C, _ in lines], key=lambda x: x.h)
    ctx = Context(spectra(test), test=test)
    return ctx, initial_state(ctx, model)


@functools.lru_cache(maxsize=None)
def _described():
    """(records of the truth's residual, names of the runs holding the partial line, run speeds rpm)."""
    ctx, state = _truth_state()
    found = describe_residual(Residual.of(ctx, state))
    test = ctx.test
    holding = {run.name for i, run in enumerate(test.runs) if i % EVERY == 0}
    return found, holding, {run.name: abs(run.speed) * 60.0 / (2 * np.pi) for run in test.runs}


def test_a_speed_sideband_within_a_line_window_of_its_carrier_is_not_a_partial_line():
    """The sidebands at 1 ± 0.06 lie 0.06·Ω/2π = 0.6-4.8 Hz from their carrier (0.3-2.6 bins), its main lobe in
    their window at every speed: read against it, the carrier's misfit and Welch beat with them made them read
    'absent' in some runs and present in others, and the sideband at 0.94 was described as a partial line (absent at
    2400, 2520, 3600 and 4080 rpm; family wheel 2's speed_sidebands cell the same way, where the true effect was then
    taken back as fitted to it).  Present in every run, they are described as nothing."""
    found, _, _ = _described()
    partial = [u for u in found if u.signature == "partial_line"]
    assert [round(u.h, 2) for u in partial] == [PARTIAL_H], [u.text() for u in partial]


def test_a_line_truly_absent_from_some_runs_reads_absent_where_it_is_resolved_and_never_where_it_is_present():
    """No run holding the 2.7 line reads absent, and none without it present; and every run without it where the
    3× line's main lobe (±2 bins; the nearest line, 0.3·Ω/2π away) lies outside its window (±3 bins about its
    nearest bin), 0.3·Ω/2π > 5.5 bins of 1.875 Hz, above 2062.5 rpm (closed form), reads absent: the 2.7 line holds
    its window alone there."""
    found, holding, rpm = _described()
    (u,) = [u for u in found if u.signature == "partial_line"]
    clear = {name for name, r in rpm.items() if abs(3.0 - PARTIAL_H) * r / 60.0 > (LINE_HALF + 2.5) * FS / NPERSEG}
    assert 15 <= len(clear) < len(rpm)
    absent, present = set(u.parameters["runs_absent"]), set(u.parameters["runs_present"])
    assert clear - holding <= absent <= set(rpm) - holding
    assert clear & holding <= present <= holding
    assert u.parameters["direction"] == "radial_force" and u.parameters["interleaved"] is True
    assert u.level_dB <= -10.0


def test_others_in_window_is_the_neighbours_share_of_the_lines_window():
    """:func:`others_in_window` on the truth: the sidebands' window holds their carrier, 1/0.1² = 100 times their own
    power, less the carrier's part outside the window (its kernel's tail; 20 ± 1 dB); the 2.7 line's window holds
    none of another line's main lobe where 3× is more than 5.5 bins away, sidelobes only (< -25 dB)."""
    ctx, state = _truth_state()
    runs = ctx.runs
    spin = ctx.omega[runs] / (2 * np.pi)
    side = 10 * np.log10(others_in_window(ctx, state, "radial_force", 1 - DELTA, runs))
    assert np.all(np.abs(side - 20 * np.log10(2 / DEPTH)) <= 1.0), side
    far = 0.3 * spin > (LINE_HALF + 2.5) * ctx.df
    assert far.sum() >= 15
    assert np.all(others_in_window(ctx, state, "radial_force", PARTIAL_H, runs)[far] < 10 ** -2.5)


def test_a_line_that_starts_at_one_speed_says_between_which_speeds_it_starts():
    """The 2.7 line present only above 3060 rpm (a rub that a speed brings on; trial25's rub read "1625-4000 rpm"
    alone, joining the runs without it and with it): described as starting between the fastest run without it and the
    slowest with it, the two bracketing the generator's onset, no run interleaved."""
    onset = 3060.0                      # between two runs of the 120 rpm grid
    ctx, state = _truth_state(onset)
    found = describe_residual(Residual.of(ctx, state))
    (u,) = [u for u in found if u.signature == "partial_line"]
    p = u.parameters
    assert p["interleaved"] is False and max(p["absent_rpm"]) < onset < min(p["present_rpm"])
    assert f"starts between {max(p['absent_rpm']):.0f} and {min(p['present_rpm']):.0f} rpm" in u.text(), u.text()


def test_a_line_over_one_band_of_speeds_says_where_it_starts_and_stops_not_interleaved():
    """The 2.7 line present only at 2460-3900 rpm (one band, the runs without it on both sides): described as starting
    and stopping between the runs bracketing the generator's band, not as interleaved with the runs lacking it (a new
    user's trial, wheel A's h 2.73 on Fz at 2054-3954 rpm: "the two interleaved", "an intermittent source")."""
    onset, stop = 2460.0, 3900.0        # between runs of the 120 rpm grid
    ctx, state = _truth_state(onset, stop)
    found = describe_residual(Residual.of(ctx, state))
    (u,) = [u for u in found if u.signature == "partial_line"]
    p = u.parameters
    assert p["interleaved"] is False and onset < min(p["present_rpm"]) and max(p["present_rpm"]) < stop
    below = max(x for x in p["absent_rpm"] if x < onset)
    above = min(x for x in p["absent_rpm"] if x > stop)
    assert (f"starts between {below:.0f} and {min(p['present_rpm']):.0f} rpm and stops between "
            f"{max(p['present_rpm']):.0f} and {above:.0f} rpm") in u.text(), u.text()
    assert u.causes[0].startswith("a source that starts or stops"), u.causes
