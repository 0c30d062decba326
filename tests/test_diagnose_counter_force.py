"""rwadist.diagnose, issue 14 item 4(a): counter-rotating content on a radial FORCE line (modes on).

The radial translation has no gyroscopic split, so a co and a counter force line have the same PSD in every
channel: only the x/y phase tells them apart.  ``counter_rotation`` then fits q from the phasors
(|X + iY|², |X − iY|²) and is judged on held-out speeds by the misplaced rotating power.

Data: the E wheel (preset "ithaco-e"), extended physics with its suspension modes ON, made by
``rwadist.inject`` (what ``simulate-test --inject counter_rotation:...`` writes): 30 % of the radial-force
fundamental's power counter-rotating, the counter part a wheel load through the modes, the imbalance U_s keeping
the co part; 20 speeds 300-3000 rpm, 8192 samples at 1920 Hz, Welch nperseg 2048, sensor noise 1 % of the
group's fundamental at top speed.  The starting model is the preset's (all co-rotating force lines).
Tolerances: q within 2 % relative (the phasor estimate; noise is ~1e-4 of the line power at top speed), the
model file's U_s and counter harmonic within 2 %; the same data without the effect: nothing added.
"""
from __future__ import annotations

import numpy as np
import pytest

from rwadist import extended as ext
from rwadist import model as model_io
from rwadist.diagnose import diagnose
from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset
from rwadist.spectra import compute_spectra

E = preset("ithaco-e")
TRUTH = E.to_model()
SPEEDS = np.linspace(300.0, 3000.0, 20)
KW = dict(sample_rate=1920.0, n_samples=8192, noise=0.01, physics="extended")
Q = 0.3


def data(seed, q=None):
    specs = [] if q is None else [parse(f"counter_rotation:direction=radial_force,h=1,fraction={q}")]
    return simulate_with_injections(E, specs, SPEEDS, seed=seed, **KW)


def run(test):
    return diagnose(compute_spectra(test, nperseg=2048), TRUTH, test=test, base="extended")


def test_injected_counter_part_goes_through_the_modes():
    """The injection itself, measured with a DFT of its own: x/y phase gives q, the total power is U_s²Ω⁴ times
    the translation mode's |G|² (the closed-form transmissibility, same for both senses).  Every 6th run; at
    300 rpm the line's amplitude equals the noise std (1 % of the top-speed fundamental), hence 0.01 and 5 %."""
    test = data(4, Q)
    for r in test.runs[::6]:
        n = r.n_samples
        w = np.hanning(n + 1)[:-1]
        f = abs(r.speed) / (2 * np.pi)
        e = np.exp(-2j * np.pi * f * np.arange(n) / r.sample_rate)
        X, Y = (2 * np.sum(w * r.signals[c] * e) / np.sum(w) for c in ("Fx", "Fy"))
        co, ct = abs(X + 1j * Y) ** 2 / 4, abs(X - 1j * Y) ** 2 / 4
        assert ct / (co + ct) == pytest.approx(Q, abs=0.01)
        G = abs(ext.transmissibility(E.extended, "radial_force", abs(r.speed), abs(r.speed)))
        assert co + ct == pytest.approx((E.extended.U_s * r.speed**2 * G) ** 2, rel=0.05)


@pytest.mark.parametrize("seed", [0, 1])
def test_counter_rotation_of_the_force_fundamental_found(seed, tmp_path):
    d = run(data(seed, Q))
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds == ["counter_rotation"]
    e = d.model.effects[0]
    assert e["direction"] == "radial_force" and e["h"] == pytest.approx(1.0)
    assert e["counter_fraction"] == pytest.approx(Q, rel=0.02)
    assert e["counter_fraction_stderr"] < 0.01
    assert e["evidence"]["t"] > 4
    print(f"seed {seed}: q = {e['counter_fraction']:.4f} (truth {Q}), t = {e['evidence']['t']:.0f}")
    # the model file: U_s keeps the co part, a counter harmonic U_s·sqrt(q), read back as a counter Line
    U = d.model.analytical["U_s_kg_m"]
    assert U == pytest.approx(E.extended.U_s * np.sqrt(1 - Q), rel=0.02)
    model_io.save(d.model, tmp_path / "m.json")
    m = model_io.load(tmp_path / "m.json")
    ct = [ln for ln in ext.lines_from_model(m, ext.params_from_model(m))
          if ln.direction == "radial_force" and ln.sense == "counter" and abs(ln.h - 1) < 1e-9]
    assert len(ct) == 1
    assert ct[0].C == pytest.approx(E.extended.U_s * np.sqrt(Q), rel=0.02)
    # the counter harmonic's standard error is the split's, C·dq/(2√q) (it had none)
    counter = next(x for x in m.harmonics("radial_force") if x.sense == "counter")
    c_tot = np.hypot(U, counter.C)
    assert counter.C_stderr == pytest.approx(c_tot * e["counter_fraction_stderr"] / (2 * np.sqrt(
        e["counter_fraction"])), rel=0.02)


@pytest.mark.parametrize("seed", [0, 1])
def test_clean_modal_data_get_no_force_counter_rotation(seed):
    d = run(data(seed))
    assert d.model.effects == []
    cr = [h for h in d.hypotheses if h.effect.kind == "counter_rotation"]
    assert all(not h.passed for h in cr)


def test_rms_of_a_counter_rotating_line_is_matched_on_the_radial_pair(tmp_path):
    """30 % of the force fundamental counter-rotating, its phase to the co part random run to run: each run's Fx and
    Fy RMS depend on the ellipse's orientation, which no model can know, but Fx² + Fy² is abs(a₊)² + abs(a₋)² whatever
    the phase (checked on the data's own DFT in :func:`test_injected_counter_part_goes_through_the_modes`).  The
    report's pair-combined RMS error is then as small as on clean data, while the per-channel error of the same
    model is several times larger; report.md says why."""
    from rwadist.diagnose.report import counter_rotating_lines, pair_rms_error, rms_vs_speed, write_report

    d, clean = run(data(2, Q)), run(data(2))
    assert counter_rotating_lines(d.model) == [("radial_force", 1.0)] and counter_rotating_lines(clean.model) == []
    cols = rms_vs_speed(d)
    per_channel = np.mean([np.mean(np.abs(cols[f"model_after_{c}_rms_N"] - cols[f"data_{c}_rms_N"])
                                   / cols[f"data_{c}_rms_N"]) for c in ("Fx", "Fy")])
    paired, clean_paired = pair_rms_error(cols), pair_rms_error(rms_vs_speed(clean))
    print(f"per channel {per_channel:.4f}, pair {paired:.4f}, clean pair {clean_paired:.4f}")
    assert paired < 1.5 * clean_paired + 0.01 and per_channel > 3 * paired
    write_report(d, tmp_path / "r")
    write_report(clean, tmp_path / "c")
    assert f"each radial pair combined (√(x² + y²)): {paired:.4g}" in (tmp_path / "r" / "report.md").read_text()
    assert "each radial pair combined" not in (tmp_path / "c" / "report.md").read_text()
