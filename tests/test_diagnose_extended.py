"""rwadist.diagnose on the extended base (issue 7): lines through the rotor's suspension modes, and the
``counter_rotation`` effect (counter-rotating content the co-rotating model cannot excite).

Data: the E wheel (preset "ithaco-e") with extended physics -- the virtual stand
(``simulate_steady(..., physics="extended")``) for clean data, and :func:`ext_data` (the same lines through
:func:`rwadist.extended.steady_lines`, a second generator) when counter-rotating content is injected; 40 speeds
600-2400 rpm, 4096 samples at 1920 Hz, Welch nperseg 1024, sensor noise 0.01 of the group's fundamental at top
speed, as tests/test_diagnose.py.  The starting model is the preset's (analytical section, senses), which
declares no counter content beyond the preset's own h = 2.
Tolerances: counter fraction within 10 % relative (both the PSD fit and the x/y-phase estimate); the error
metric cut at least 3x.
"""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from test_diagnose import FS, SPEEDS, TRUTH, N, kinds, spectra

from rwadist import cli
from rwadist import extended as ext
from rwadist import model as model_io
from rwadist.data import Run, SteadyTest, write_steady
from rwadist.diagnose import Context, diagnose, initial_state, resolve_base
from rwadist.effects.counter_rotation_diagnose import CounterRotation
from rwadist.presets import preset
from rwadist.teststand import simulate_steady
from rwadist.units import CHANNELS, rpm_to_rad_s

E = preset("ithaco-e")
P = E.extended


def stand_data(seed, speeds=SPEEDS):
    """Clean extended-physics data from the virtual stand."""
    return simulate_steady(E, speeds, sample_rate=FS, n_samples=N, noise=0.01, seed=seed, physics="extended")


def ext_data(seed, counter=None, speeds=SPEEDS, noise=0.01):
    """E-wheel extended-physics data built here from rwadist.extended.steady_lines: the preset's lines, the
    imbalances at one random phase β per run (dynamic at β + imbalance_phase), other lines at uniform random
    phases; ``counter`` = {(direction, h): q} splits that line into co C·sqrt(1 − q) and counter C·sqrt(q) (an
    imbalance's co part is U·sqrt(1 − q)), the counter line at its own random phase.  White noise of std
    noise·C_1·Ω_max² per channel group, as the virtual stand."""
    p = P
    lines = E.extended_lines()
    for (d, h), q in (counter or {}).items():
        new = []
        for ln in lines:
            if ln.direction == d and abs(ln.h - h) < 1e-9:
                if ln.imbalance:
                    p = replace(p, **{"U_s" if d == "radial_force" else "U_d": ln.C * np.sqrt(1 - q)})
                new += [replace(ln, C=ln.C * np.sqrt(1 - q)), ext.Line(d, h, ln.C * np.sqrt(q), "counter")]
            else:
                new.append(ln)
        lines = new
    omegas = rpm_to_rad_s(np.asarray(speeds, float))
    wmax = np.abs(omegas).max()
    std = {c: noise * E.fundamental_C("radial_force" if c[0] == "F" else "radial_torque") * wmax**2 for c in CHANNELS}
    rng = np.random.default_rng(seed + 500)
    t = np.arange(N) / FS
    runs = []
    for k, om in enumerate(omegas):
        beta = rng.uniform(0, 2 * np.pi)
        ph = [beta if (ln.imbalance and ln.direction == "radial_force") else
              beta + E.imbalance_phase if ln.imbalance else rng.uniform(0, 2 * np.pi) for ln in lines]
        f, A = ext.steady_lines(p, [replace(ln, phase=float(x)) for ln, x in zip(lines, ph)], [om])
        keep = f[0] < FS / 2
        z = A[0][keep].T @ np.exp(2j * np.pi * np.outer(f[0][keep], t))
        sig = {c: z[i].real + rng.normal(0, std[c], N) for i, c in enumerate(CHANNELS)}
        runs.append(Run(speed=float(om), sample_rate=FS, signals=sig, t0=0.0, name=f"run_{k:04d}.csv"))
    return SteadyTest(runs=runs, meta={"sample_rate_hz": FS})


# --------------------------------------------------------------------------- extended base

def test_modal_gain_is_the_closed_form_transmissibility():
    """Context.channel_lines on the extended base: g of a line is |(k + icν)/(k − mν² + I_zz Ω ν + icν)| at
    ν = ±hΩ (sign = sense; closed form written out here), i.e. the counter h = 2 torque line is amplified at its
    backward-whirl crossing (1165 rpm), the co h = 3 torque line not there; the axial line through k_z."""
    w_cross = ext.crossing_closed_form(P, 2.0, "rocking_backward")
    speeds = np.array([700.0, w_cross * 30 / np.pi, 2300.0])
    test = stand_data(0, speeds)
    ctx = Context(spectra(test))
    st = initial_state(ctx, TRUTH, P)
    runs = ctx.runs
    w = ctx.omega[runs]

    def T(m, c, k, gyro, nu):
        return np.abs((k + 1j * c * nu) / (k - m * nu**2 + gyro * w * nu + 1j * c * nu))

    rock = (P.I_rr, P.c_rock, P.k_rock, P.I_zz)
    lines = {c: {round(h, 2): (a, g) for h, _, a, g in ctx.channel_lines(st, c, runs)} for c in ("Tx", "Ty", "Fz")}
    for c in ("Tx", "Ty"):
        assert np.allclose(lines[c][2.0][1], T(*rock, -2.0 * w), rtol=1e-9)            # counter: backward whirl
        assert np.allclose(lines[c][3.0][1], T(*rock, 3.0 * w), rtol=1e-9)             # co
        C2 = dict(E.harmonics["radial_torque"])[2.0]
        assert np.allclose(lines[c][2.0][0], C2 * w**2 * T(*rock, -2.0 * w), rtol=1e-9)
    assert lines["Tx"][2.0][1][1] > 10.0 > lines["Tx"][3.0][1][1]                       # at the crossing
    assert np.allclose(lines["Fz"][1.98][1], T(P.mass, P.c_z, P.k_z, 0.0, 1.98 * w), rtol=1e-9)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_clean_extended_data_adds_nothing(seed):
    """Extended-physics data explained by the extended base: no effect, small error; every class tried."""
    test = stand_data(seed)
    d = diagnose(spectra(test), TRUTH, test=test, base="extended")
    assert d.summary()["base"] == "extended"
    assert d.model.effects == []
    assert d.error_after == d.error_before < 2e-3
    assert {h.effect.kind for h in d.hypotheses} >= {"broadband_floor"}


def test_empirical_base_on_extended_data_needs_patches():
    """The contrast: the same data read with the hard-mounted C·Ω² model misplace a large fraction of the power
    (the crossings, the imbalance U_d vs the empirical C), and diagnose patches it with effects."""
    test = stand_data(0)
    sp = spectra(test)
    emp = diagnose(sp, TRUTH, base="empirical", max_iterations=3)
    good = diagnose(sp, TRUTH, base="extended", max_iterations=1)
    assert emp.summary()["base"] == "empirical"
    assert emp.error_before > 100 * good.error_before
    assert len(emp.model.effects) >= 1
    assert emp.error_after < emp.error_before


def test_resolve_base():
    assert resolve_base(TRUTH, "auto") == "extended"
    bare = replace(TRUTH, analytical=None)
    assert resolve_base(bare, "auto") == "empirical"
    assert resolve_base(TRUTH, "empirical") == "empirical"
    with pytest.raises(ValueError, match="analytical"):
        resolve_base(bare, "extended")
    with pytest.raises(ValueError, match="base must be"):
        resolve_base(TRUTH, "modal")


# --------------------------------------------------------------------------- counter rotation

@pytest.mark.parametrize("seed", [0, 1, 2])
def test_counter_rotation_of_the_imbalance_found(seed):
    """20 % of the radial-torque fundamental's power counter-rotating (the thesis's h = 1 amplification at the
    backward whirl, 1903 rpm): named, q recovered by the PSD fit and by the x/y phase, total power kept."""
    q = 0.2
    test = ext_data(seed, {("radial_torque", 1.0): q})
    d = diagnose(spectra(test), TRUTH, test=test, base="extended")
    assert kinds(d) == ["counter_rotation"]
    e = d.model.effects[0]
    assert e["direction"] == "radial_torque" and e["h"] == pytest.approx(1.0)
    assert e["counter_fraction"] == pytest.approx(q, rel=0.10)
    assert e["counter_fraction_phase"] == pytest.approx(q, rel=0.10)
    assert d.error_before > 3 * d.error_after
    # the model file: U_d scaled by sqrt(1 - q), a counter harmonic U_d·sqrt(q); U_d'² + C_ct² = U_d² (power kept)
    U = d.model.analytical["U_d_kg_m2"]
    ct = [x for x in d.model.harmonics("radial_torque") if x.sense == "counter" and abs(x.h - 1.0) < 1e-3]
    assert len(ct) == 1
    assert U == pytest.approx(P.U_d * np.sqrt(1 - q), rel=0.02)
    assert U**2 + ct[0].C ** 2 == pytest.approx(P.U_d**2, rel=1e-9)


def test_counter_rotation_round_trip_through_the_model_file(tmp_path):
    """Counter content on the co h = 3 torque line (backward crossing 851 rpm): found; the improved model, saved
    and loaded, read back by lines_from_model, explains the data: a second diagnosis from it adds nothing and
    starts at the first one's final error."""
    q = 0.3
    test = ext_data(7, {("radial_torque", 3.0): q})
    sp = spectra(test)
    d = diagnose(sp, TRUTH, test=test, base="extended")
    assert kinds(d) == ["counter_rotation"]
    e = d.model.effects[0]
    assert e["h"] == pytest.approx(3.0) and e["counter_fraction"] == pytest.approx(q, rel=0.10)
    assert d.error_before > 3 * d.error_after
    C3 = dict(E.harmonics["radial_torque"])[3.0]
    got = {x.sense: x.C for x in d.model.harmonics("radial_torque") if abs(x.h - 3.0) < 1e-3}
    assert got["co"] ** 2 + got["counter"] ** 2 == pytest.approx(C3**2, rel=1e-9)
    model_io.save(d.model, tmp_path / "m.json")
    m = model_io.load(tmp_path / "m.json")
    senses = [ln.sense for ln in ext.lines_from_model(m, ext.params_from_model(m)) if abs(ln.h - 3.0) < 1e-9
              and ln.direction == "radial_torque"]
    assert sorted(senses) == ["co", "counter"]
    d2 = diagnose(sp, m, test=test, base="extended")
    assert d2.model.effects[len(m.effects):] == []
    assert d2.error_before == pytest.approx(d.error_after, rel=0.05)


def test_counter_rotation_not_proposed_for_radial_force():
    """The radial translation has no gyroscopic split: co and counter force lines have the same modal gain, so
    the PSD cannot tell them apart and the class proposes nothing there (fit returns None)."""
    test = stand_data(1, SPEEDS[::4])
    ctx = Context(spectra(test))
    st = initial_state(ctx, TRUTH, P)
    for h in (1.0, 2.0, 4.42):
        assert CounterRotation.fit(ctx, st, "radial_force", h, ctx.runs) is None


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(100, 110))
def test_clean_extended_ten_seeds_no_false_addition(seed):
    """Ten seeds, one test each (so the workers share them): nothing added to clean extended data."""
    test = stand_data(seed)
    assert kinds(diagnose(spectra(test), TRUTH, test=test, base="extended")) == []


# --------------------------------------------------------------------------- CLI

def test_cli_picks_the_extended_base_for_a_preset(tmp_path):
    """rwadist diagnose --preset ithaco-e on extended-physics data (meta modes: true): extended base, nothing
    added; the same with --base empirical misplaces far more power."""
    test = stand_data(3)
    write_steady(test, tmp_path / "data")
    for base, rep in (("auto", tmp_path / "a"), ("empirical", tmp_path / "b")):
        assert cli.main(["diagnose", str(tmp_path / "data"), "--preset", "ithaco-e", "--nperseg", "1024",
                         "--base", base, "-o", str(rep)]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    b = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert a["base"] == "extended" and a["effects"] == [] and a["error_before"] < 2e-3
    assert b["base"] == "empirical" and b["error_before"] > 100 * a["error_before"]
