"""Line classes on the default path (``rwadist diagnose DATA`` with no model) on wheels of the family generator
(tests/family_wheel.py, its own physics, not rwadist's) that are not the matrix's eight: other masses, inertia
ratios, modes, line sets, speeds, rates and noise (issue 33, item 2).

An amplitude law (Ω³ instead of Ω², equal at the mid speed) on a bearing line beside the wheel's 3x line: the
runs below a third of the top speed, where the law's line is 40-60 dB under its top-speed level and its window holds
its neighbour's leakage, had the say in an unweighted log fit (family wheel 1: p 2.85 for 3.0, error after 47x the
clean level).  A law on a line half co-, half counter-rotating: one channel's line swings with the two parts'
phases from run to run (family wheel 4, missed, 145x).  Sidebands and a speed ripple closer to their carriers than
the Welch grid (the whole-record route): the pair's offset refined from a scan step off it, and the imbalances' size
under a ripple."""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api  # noqa: E402


def _wheel(index, row, n_speeds, n_samples, co=None):
    """A wheel of :func:`family_wheel.make_wheel` from its own table row, its radial BPFO line's co-rotating share set
    to ``co`` (None: as drawn)."""
    w = fw.make_wheel(index, *row)
    if co is not None:
        w = replace(w, lines=tuple(replace(ln, co=co) if ln.direction == "radial_force" and ln.name == "BPFO" else ln
                                   for ln in w.lines))
    return replace(w, n_speeds=n_speeds, n_samples=n_samples)


def _diagnose(wheel, effects, noise, seed, tmp_path):
    data = fw.steady(wheel, noise=noise, seed=seed, effects=effects)
    return api.diagnose(fw.write_steady(data, tmp_path / "data", wheel.name)).summary()


def test_amplitude_law_of_a_half_counter_rotating_line_read_on_both_channels(tmp_path):
    """The law's fit alone, on the empirical base (the wheel's modes far above the band: its lines as loaded): the
    line's x and y powers pooled per run, whatever its co and counter parts' phases.  Read per channel, the
    exponent came out 2.93 ± 0.31 and 2.81 ± 0.28 (seeds 1 and 2)."""
    from rwadist.data import read_steady
    from rwadist.diagnose.engine import Context, initial_state
    from rwadist.effects.amplitude_law_diagnose import AmplitudeLaw
    from rwadist.empirical import fit_empirical
    from rwadist.spectra import compute_spectra

    wheel = _wheel(31, (8.0, 1.5, 0.15, (40000.0, 30000.0, 35000.0), 6000.0, 4000.0, 10, 0.21, 5.0, False), 16, 8192,
                   co=0.5)
    law = fe.default_effect("amplitude_law", wheel)
    bpfo = next(ln for ln in wheel.lines if ln.direction == "radial_force" and ln.name == "BPFO")
    w_mid = 0.5 * (wheel.min_rpm + wheel.max_rpm) * fw.RPM
    for seed in (1, 2):
        test = read_steady(fw.write_steady(fw.steady(wheel, noise=0.003, seed=seed, effects=[law]),
                                           tmp_path / f"s{seed}", wheel.name))
        ctx = Context(compute_spectra(test, nperseg=api.diagnose_nperseg(test)), None, test)
        model = fit_empirical(ctx.sp).model
        state = initial_state(ctx, model)
        h = min((x.h for x in model.harmonics("radial_force")), key=lambda x: abs(x - bpfo.h))
        assert h == pytest.approx(bpfo.h, abs=0.01)
        e = AmplitudeLaw.fit(ctx, state, "radial_force", h, ctx.runs)
        assert e.exponent == pytest.approx(3.0, abs=0.02)
        # the line's amplitude at the reference speed: C·Ω_mid²·(Ω_ref/Ω_mid)³ (the generator's law, both parts)
        assert e.amplitude_ref == pytest.approx(bpfo.C * w_mid**2 * (e.omega_ref / w_mid) ** 3, rel=0.02)


#: (index, make_wheel row, speeds, samples, BPFO co share, noise, seed): 3.5 kg, I_zz/I_rr 1.35, modes 450/160/230 Hz,
#: 800-8000 rpm at 8 kHz, integer lines (the 3x beside BPFO 3.39)
LAW_WHEELS = {
    "3x-beside": (22, (3.5, 1.35, 0.08, (450.0, 160.0, 230.0), 8000.0, 8000.0, 9, 0.25, 10.0, True), 14, 8192, 1.0,
                  0.005, 4),
    }


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(LAW_WHEELS))
def test_amplitude_law_on_a_bearing_line_named_with_its_exponent(case, tmp_path):
    index, row, n_speeds, n_samples, co, noise, seed = LAW_WHEELS[case]
    wheel = _wheel(index, row, n_speeds, n_samples, co)
    law = fe.default_effect("amplitude_law", wheel)
    s = _diagnose(wheel, [law], noise, seed, tmp_path)
    named = [e for e in s["effects"] if e["kind"] == "amplitude_law"]
    assert [e["kind"] for e in s["effects"] if e["kind"] not in ("suspension_modes", "amplitude_law")] == []
    (e,) = named
    assert e["direction"] == "radial_force" and e["h"] == pytest.approx(law.params["h"], abs=0.01)
    # the injected law's exponent (the generator's truth), not a fit's own noise: within 0.05 of 3
    assert e["exponent"] == pytest.approx(law.params["exponent"], abs=0.05)


def _empirical_context(wheel, effects, noise, seed, tmp_path):
    """(Context with the time series, the state of the data-fitted empirical base) of the wheel's data."""
    from rwadist.data import read_steady
    from rwadist.diagnose.engine import Context, initial_state
    from rwadist.empirical import fit_empirical
    from rwadist.spectra import compute_spectra

    test = read_steady(fw.write_steady(fw.steady(wheel, noise=noise, seed=seed, effects=effects), tmp_path / "data",
                                       wheel.name))
    ctx = Context(compute_spectra(test, nperseg=api.diagnose_nperseg(test)), None, test)
    return ctx, initial_state(ctx, fit_empirical(ctx.sp).model)


@pytest.mark.parametrize("side", (-1.0, 1.0))
def test_sidebands_closer_than_the_welch_grid_refined_from_a_scan_step_off(side, tmp_path):
    """A fixed-offset pair 6 record bins off the imbalance (below 2.5 Welch bins: the whole-record route), its fit
    started one scan step (RECORD_STEP_BINS) off the pair, as the scan's median over a changing set of runs left it on
    family wheel 4 (5.859 Hz for 5.625): the pair's offset and depth (the generator's), not the edge of a one-step
    grid (which gave no fit there, and sidebands at 6.07 Hz beside an invented line a search step later)."""
    from rwadist.effects.sidebands_diagnose import RECORD_STEP_BINS, Sidebands

    # 6 kg, I_zz/I_rr 1.7, modes far above the band (the lines as loaded), 300-3000 rpm at 3 kHz, 4096 samples
    wheel = _wheel(43, (6.0, 1.7, 0.14, (40000.0, 30000.0, 35000.0), 3000.0, 3000.0, 10, 0.2, 0.0, True), 12, 4096)
    df_rec = wheel.sample_rate / wheel.n_samples
    f_mod = 6 * df_rec
    ctx, state = _empirical_context(wheel, [fe.Sidebands(h=1.0, f_mod_hz=f_mod, depth=0.4)], 0.003, 3, tmp_path)
    assert f_mod < 2.5 * ctx.df                                   # the whole-record route
    e = Sidebands.fit_record(ctx, state, "radial_force", 1.0, ctx.runs, f_mod + side * RECORD_STEP_BINS * df_rec)
    assert e is not None
    assert e.f_mod == pytest.approx(f_mod, abs=0.05 * df_rec)
    # (the depth on the carrier's amplitude as the empirical base fitted it: 0.378 for 0.4 here)
    assert e.depth == pytest.approx(0.4, rel=0.1)


@pytest.mark.slow
def test_speed_ripple_leaves_the_imbalances_at_their_free_size(tmp_path):
    """A 5.9-Hz speed ripple (β = ΔΩ/2πf_r = 0.2 on the 1x) on the default path: the wheel's modes and the ripple
    named, nothing else, and the imbalances U_s, U_d of the extended base at the generator's (the ripple's carrier
    |c_0| taken off them as off every other line: they were J_0(0.2) = 0.990 of it, and on family wheel 7 the 1x
    carrier's missing power was named as 1x sidebands at the ripple's own frequency)."""
    # 5 kg, I_zz/I_rr 1.5, modes 260/80/150 Hz, 600-6000 rpm at 4 kHz, 4096 samples, 12 speeds
    wheel = _wheel(44, (5.0, 1.5, 0.12, (260.0, 80.0, 150.0), 6000.0, 4000.0, 9, 0.22, 0.0, True), 12, 4096)
    f_r = 6 * wheel.sample_rate / wheel.n_samples
    ripple = fe.SpeedRipple(f_ripple_hz=f_r, delta_omega=0.2 * 2 * np.pi * f_r)
    data = fw.steady(wheel, noise=0.005, seed=5, effects=[ripple])
    d = api.diagnose(fw.write_steady(data, tmp_path / "data", wheel.name))
    assert sorted(e.kind for e in d.state_after.effects) == ["speed_ripple", "suspension_modes"]
    for direction, name in (("radial_force", "U_s"), ("radial_torque", "U_d")):
        truth = next(ln.C for ln in wheel.lines if ln.direction == direction and ln.name == "imbalance")
        assert getattr(d.state_after.ext, name) == pytest.approx(truth, rel=0.003)


def test_speed_sidebands_take_no_evidence_from_the_fixed_offset_pair_the_state_has(tmp_path):
    """5-Hz sidebands of the 1x in the state (fitted on the whole record): a speed-proportional pair that meets them
    at the top speed (δ = f_mod/f_top per rev) holds nothing the state lacks there, and its held-out evidence on the
    whole record is not significant (family wheel 7: such a pair, 0.032 per rev, took the fixed pair's power as its
    own, t 158, and was named beside it)."""
    from rwadist.effects.sidebands_diagnose import Sidebands
    from rwadist.effects.speed_sidebands_diagnose import SpeedSidebands

    wheel = _wheel(43, (6.0, 1.7, 0.14, (40000.0, 30000.0, 35000.0), 3000.0, 3000.0, 10, 0.2, 0.0, True), 12, 4096)
    f_mod = 6 * wheel.sample_rate / wheel.n_samples
    ctx, state = _empirical_context(wheel, [fe.Sidebands(h=1.0, f_mod_hz=f_mod, depth=0.4)], 0.003, 3, tmp_path)
    pair = Sidebands.fit_record(ctx, state, "radial_force", 1.0, ctx.runs, f_mod)
    assert pair is not None and pair.f_mod == pytest.approx(f_mod, rel=0.01)
    state = pair.apply(state)
    c1 = next(x.C for x in state.model.harmonics("radial_force") if abs(x.h - 1.0) < 0.01)
    delta = f_mod / (wheel.max_rpm * fw.RPM / (2 * np.pi))
    fake = SpeedSidebands("radial_force", 1.0, 1.0 - delta, 1.0 + delta, 0.2 * c1, 0.2 * c1, c1)
    ev = fake.heldout_evidence(ctx, state, ctx.runs)
    assert ev is None or ev[0] < 4.0 * ev[1]
