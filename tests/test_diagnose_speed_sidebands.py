"""rwadist.diagnose, issue 14 item 4(b): speed-proportional sidebands close to a strong line (modes on).

The imbalance amplitude-modulated at 6 % of the wheel speed puts lines at 0.94 and 1.06 × the speed beside the
radial-force fundamental.  ``missing_harmonic`` could not see them: its ridge score is clipped (a strong pair's
skirts saturate a wide plateau around the carrier, whose edges it took for the ridges) and it pooled every
speed, most of which hold the pair inside the carrier's main lobe.  ``speed_sidebands`` scans the offset δ per
revolution on the runs where h₀ ± δ stands >= 3 bins from the carrier, and adds the pair as two harmonics.

Data: the E wheel (preset "ithaco-e"), extended physics with its suspension modes ON, 20 speeds 300-3000 rpm,
16384 samples at 1920 Hz, Welch nperseg 4096 (0.47 Hz bins: the pair, 0.06·|Ω|/2π from the carrier, is resolved
above ~1200 rpm only), sensor noise 1 %; ``rwadist.inject`` ``sidebands:direction=radial_force,h=1,depth=0.4,
per_rev=0.06`` (what ``simulate-test --inject`` writes): two co-rotating wheel loads 0.2·U_s·Ω² at 0.94 and 1.06
through the modes.  Tolerances: h within 0.002, each sideband ratio C/U_s within 3 % of 0.2, the error back to
within 1.5 × that of the same data without the effect; the latter adds nothing.
"""
from __future__ import annotations

import numpy as np
import pytest

from rwadist.diagnose import diagnose
from rwadist.effects.speed_sidebands_diagnose import MIN_BINS, resolvable_runs
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.spectra import compute_spectra

E = preset("ithaco-e")
TRUTH = E.to_model()
SPEEDS = np.linspace(300.0, 3000.0, 20)
KW = dict(sample_rate=1920.0, n_samples=16384, noise=0.01, physics="extended")
SPEC = "sidebands:direction=radial_force,h=1,depth=0.4,per_rev=0.06"


def run(specs, seed):
    test = simulate_with_injections(E, [parse(s) for s in specs], SPEEDS, seed=seed, **KW)
    return diagnose(compute_spectra(test, nperseg=4096), TRUTH, test=test, base="extended")


@pytest.mark.parametrize("seed", [0, 1])
def test_speed_proportional_sidebands_found(seed):
    d = run([SPEC], seed)
    clean = run([], seed)
    assert [e["kind"] for e in d.model.effects] == ["speed_sidebands"]
    e = d.model.effects[0]
    assert e["direction"] == "radial_force" and e["h"] == pytest.approx(1.0)
    assert e["h_lower"] == pytest.approx(0.94, abs=0.002) and e["h_upper"] == pytest.approx(1.06, abs=0.002)
    assert e["ratio_lower"] == pytest.approx(0.2, rel=0.03) and e["ratio_upper"] == pytest.approx(0.2, rel=0.03)
    # the model holds them as two harmonics (every consumer reads those)
    hs = sorted(x.h for x in d.model.harmonics("radial_force"))
    assert any(abs(h - 0.94) < 0.002 for h in hs) and any(abs(h - 1.06) < 0.002 for h in hs)
    assert d.error_after < 1.5 * clean.error_after < d.error_before
    # only the fast runs resolve the pair
    n_res = resolvable_runs(d.ctx, d.state_before, "radial_force", 1.0, 0.94, d.ctx.runs).size
    assert 0 < n_res < d.ctx.runs.size
    assert clean.model.effects == []
    print(f"seed {seed}: h {e['h_lower']:.4f} / {e['h_upper']:.4f}, ratio {e['ratio_lower']:.4f} / "
          f"{e['ratio_upper']:.4f} (truth 0.2), error {d.error_before:.4f} -> {d.error_after:.4f} "
          f"(clean {clean.error_after:.4f}); {n_res}/{d.ctx.runs.size} runs resolve the pair (>= {MIN_BINS} bins)")


def test_pair_inside_the_welch_kernel_judged_on_the_whole_record(tmp_path):
    """The default path (no model) on family wheel 1 (tests/family_wheel.py: 16 speeds to 10000 rpm, 8192 samples at
    10 kHz, diagnose's 2048-sample segments: 4.9 Hz bins): the pair at 0.94/1.06 x the speed stands at most 2.05 Welch
    bins from its carrier, inside its Welch kernel at every speed, where the PSD judge refused it (-5 % held-out gain:
    it grants no allowance for the beat of a line added beside another); the whole record resolves it from 2440 rpm
    and judges it.  Checked against the generator's truth: h 0.94/1.06, each side 0.2 of the carrier."""
    import sys
    from dataclasses import replace
    from pathlib import Path

    from rwadist import api

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import family_effects as fe
    import family_wheel as fw

    wheel = replace(fw.family()[1], n_speeds=16, n_samples=8192)
    data = fw.steady(wheel, noise=0.003, seed=101, effects=[fe.SpeedSidebands(per_rev=0.06, depth=0.4)])
    d = api.diagnose(fw.write_steady(data, tmp_path, wheel.name))
    assert [e["kind"] for e in d.model.effects] == ["suspension_modes", "speed_sidebands"]
    e = d.model.effects[1]
    assert e["direction"] == "radial_force" and e["h"] == pytest.approx(1.0)
    assert e["h_lower"] == pytest.approx(0.94, abs=0.002) and e["h_upper"] == pytest.approx(1.06, abs=0.002)
    assert e["ratio_lower"] == pytest.approx(0.2, rel=0.05) and e["ratio_upper"] == pytest.approx(0.2, rel=0.05)
    # no run resolves either side on the Welch PSDs: the whole record judged it
    for h in (0.94, 1.06):
        assert resolvable_runs(d.ctx, d.state_before, "radial_force", 1.0, h, d.ctx.runs).size == 0
    assert d.error_after < 0.01 * d.error_before


def test_a_side_inside_its_carriers_smear_over_a_sweeps_slice_is_not_resolvable():
    """A sweep's slice moves the speed by ΔΩ within its record: the carrier h0 is smeared over h0·ΔΩ/2π, and a side
    closer than that plus the resolution is not measured apart from it (family wheel 7's 60-s run-up: h 3.42 over
    ~12 Hz per slice, a pair at ±0.0116 in h invented there).  Steady runs (no slicing) keep the resolution alone."""
    from types import SimpleNamespace

    from rwadist.data import Run, SteadyTest

    omega = 2 * np.pi * np.array([20.0, 40.0, 80.0])                    # rad/s
    runs = [Run(speed=float(w), sample_rate=2048.0, signals={"Fx": np.zeros(8192)}) for w in omega]
    state = SimpleNamespace(model=SimpleNamespace(harmonics=lambda d: []))

    def ctx(meta):
        return SimpleNamespace(omega=omega, df=1.0, k_lo=0, k_hi=1000, test=SteadyTest(runs, meta), _memo={})

    idx = np.arange(3)
    # side 0.1 in h from h0 = 3: 2, 4, 8 Hz from the carrier; MIN_BINS (2.5 bins of 1 Hz) passes the two fast runs
    steady = resolvable_runs(ctx({}), state, "radial_force", 3.0, 3.1, idx)
    assert list(steady) == [1, 2]
    # a slice whose speed moves 60 rpm (1 Hz of spin): the carrier spans 3 Hz, the side must be 5.5 Hz away
    swept = ctx({"slicing": {"speed_spread_rpm": [60.0, 60.0, 60.0]}})
    assert list(resolvable_runs(swept, state, "radial_force", 3.0, 3.1, idx)) == [2]


def test_the_pair_carries_its_carriers_rotation_sense():
    """A carrier of co- and counter-rotating parts (C_co e^{iΩt} + C_ct e^{-iΩt}, amplitude-modulated by
    1 + m·cos δΩt): its spectrum (an FFT of the closed form, one rotating vector x + iy) has the pair at ±(1 ± δ)Ω in
    the proportion of the parts; the model's harmonics ``SpeedSidebands.apply`` writes hold the same split."""
    from rwadist.diagnose.state import State
    from rwadist.effects.speed_sidebands_diagnose import SpeedSidebands
    from rwadist.model import Harmonic, WheelModel

    n, m, delta, c_co, c_ct = 4096, 0.4, 0.0625, 0.8, 0.6
    t = np.arange(n) / n
    omega = 2 * np.pi * 64                     # 64 cycles per record: every line on a bin
    z = (1 + m * np.cos(delta * omega * t)) * (c_co * np.exp(1j * omega * t) + c_ct * np.exp(-1j * omega * t))
    spectrum = np.abs(np.fft.fft(z)) / n       # amplitude per rotating line, bin k = k cycles per record
    lower_co, lower_ct = spectrum[60], spectrum[-60]    # (1 − δ)·64 = 60 cycles: co at +60, counter at −60
    c_lower = np.hypot(lower_co, lower_ct)     # what a power (x² + y²) measurement of the pair reads
    assert c_lower == pytest.approx(m / 2, rel=1e-9)

    model = WheelModel(name="split carrier")
    model.empirical["radial_force"] = [Harmonic(1.0, c_co, sense="co"), Harmonic(1.0, c_ct, sense="counter")]
    effect = SpeedSidebands("radial_force", 1.0, 1 - delta, 1 + delta, c_lower, c_lower, 1.0)
    added = [x for x in effect.apply(State(model, {})).model.harmonics("radial_force") if abs(x.h - 1.0) > 1e-3]
    lower = {x.sense: x.C for x in added if x.h < 1}
    assert lower["co"] == pytest.approx(lower_co, rel=1e-9) and lower["counter"] == pytest.approx(lower_ct, rel=1e-9)
    assert sorted(x.sense for x in added) == ["co", "co", "counter", "counter"]

    only_counter = WheelModel(name="counter carrier")
    only_counter.empirical["radial_force"] = [Harmonic(4.7, 1.0, sense="counter")]
    effect = SpeedSidebands("radial_force", 4.7, 4.6, 4.8, 0.2, 0.2, 1.0)
    added = [x for x in effect.apply(State(only_counter, {})).model.harmonics("radial_force") if x.h != 4.7]
    assert [(x.h, x.C, x.sense) for x in added] == [(4.6, 0.2, "counter"), (4.8, 0.2, "counter")]


def test_a_carriers_parts_give_one_pair_from_the_base():
    """The base the suspension modes fitted lists a pair per rotation-sense part of a split carrier (co 0.8, counter
    0.6 of the carrier; each part's pair 0.2 × it): one pair is proposed, whose sides hold both parts' power
    (C = hypot of the parts' C: 0.2 × 1.0)."""
    from types import SimpleNamespace

    from rwadist.diagnose.state import State
    from rwadist.effects.speed_sidebands_diagnose import SpeedSidebands
    from rwadist.model import Harmonic, WheelModel

    model = WheelModel(name="split carrier")
    model.empirical["radial_force"] = [Harmonic(1.0, 0.8, sense="co"), Harmonic(1.0, 0.6, sense="counter")]
    modes = SimpleNamespace(kind="suspension_modes", sideband_pairs=(
        ("radial_force", 1.0, 0.94, 1.06, 0.16, 0.16, 20), ("radial_force", 1.0, 0.94, 1.06, 0.12, 0.12, 18)))
    pairs = SpeedSidebands._from_base(State(model, {}, [modes]), [])
    assert len(pairs) == 1
    assert (pairs[0].C_lower, pairs[0].C_upper) == pytest.approx((0.2, 0.2), rel=1e-12)
    assert pairs[0].n_points == 20
