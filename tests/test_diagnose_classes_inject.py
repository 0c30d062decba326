"""rwadist.inject with --physics extended: every wheel-load kind (missing_harmonic, amplitude_law, sidebands,
counter_rotation) is a load on the rotor and reaches the load cell through the suspension modes, then the
stand's fixture resonances, as every simulated line does (issue 14: a real wheel's extra line passes through
the modes).

Checked against an independent computation: each line's amplitude is measured back from the noise-free time
series (a Hann-window DFT at the line's exact frequency, X ± iY for the rotation sense) and compared with the
injected wheel load times the transmissibility of the rotor's equation of motion written here in closed form
(not rwadist.extended's): a radial force on the rotor's centre moves the translation mode only,
M·z̈ + c_r·ż + k_r·z = F e^{iνt}, and the interface carries (k_r + iνc_r)·z, so |T| = |k_r + iνc_r| /
|k_r − Mν² + iνc_r|; the axial force likewise with k_z, c_z.  The fixture resonance is the stand's
H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr) (peak gain g at r = f/f_r = 1).
"""
import numpy as np
import pytest

from rwadist.inject import parse, simulate_with_injections
from rwadist.presets import preset

E = preset("ithaco-e")
P = E.extended
SPEEDS = np.linspace(1500.0, 2400.0, 4)
FS, N = 1920.0, 8192
KW = dict(sample_rate=FS, n_samples=N, noise=0.0, physics="extended", test_stand=False)


def dft(x, f):
    """Complex amplitude of x at f (Hz): 2 Σ w x e^{−i2πft} / Σ w, Hann window (exact for a lone line)."""
    w = np.hanning(x.size + 1)[:-1]
    return 2 * np.sum(w * x * np.exp(-2j * np.pi * f * np.arange(x.size) / FS)) / np.sum(w)


def senses(run, f):
    """(co, counter) amplitudes of the radial-force line at f: x = a cos, y = ±a sin -> |X ± iY|/2."""
    X, Y = dft(run.signals["Fx"], f), dft(run.signals["Fy"], f)
    return abs(X + 1j * Y) / 2, abs(X - 1j * Y) / 2


def transmissibility(direction, f_hz):
    """|interface load / wheel load| of a force on the rotor's centre at f_hz, from the equation of motion."""
    nu = 2 * np.pi * f_hz
    k, c = (P.k_r, P.c_r) if direction == "radial_force" else (P.k_z, P.c_z)
    return abs(k + 1j * nu * c) / abs(k - P.mass * nu**2 + 1j * nu * c)


def test_missing_axial_harmonic_meets_the_axial_mode():
    """h = 2.73 crosses the 70-Hz axial mode between 1500 and 2400 rpm (gain up to ~10): the line's amplitude is
    0.3·C1·Ω²·|T_z(f)|, not the free load (what it was when added at the load cell)."""
    test = simulate_with_injections(E, [parse("missing_harmonic:direction=axial_force,h=2.73,fraction=0.3")],
                                    SPEEDS, seed=1, **KW)
    gains = []
    for r in test.runs:
        w = abs(r.speed)
        f = 2.73 * w / (2 * np.pi)
        load = 0.3 * E.fundamental_C("axial_force") * w**2
        gains.append(transmissibility("axial_force", f))
        assert abs(dft(r.signals["Fz"], f)) == pytest.approx(load * gains[-1], rel=0.01)
    assert max(gains) > 3.0                          # the case discriminates: the modes change the line
    assert test.meta["injected"][0]["kind"] == "missing_harmonic"


def test_amplitude_law_keeps_the_lines_sense_and_meets_the_translation_mode():
    """The preset's h = 2 radial-force line is counter-rotating: replaced by the law A(Ω) =
    C·Ω_mid²·(Ω/Ω_mid)³ it stays counter-rotating (a co-rotating copy at the load cell looked to diagnose like a
    change of sense), and its amplitude is A(Ω)·|T_r(f)|."""
    assert E.senses[("radial_force", 2.0)] == "counter"
    test = simulate_with_injections(E, [parse("amplitude_law:direction=radial_force,h=2,exponent=3")],
                                    SPEEDS, seed=2, **KW)
    C = dict(E.harmonics["radial_force"])[2.0]
    w_mid = float(np.median([abs(r.speed) for r in test.runs]))
    for r in test.runs:
        w = abs(r.speed)
        f = 2 * w / (2 * np.pi)
        co, counter = senses(r, f)
        assert counter == pytest.approx(C * w_mid**2 * (w / w_mid) ** 3 * transmissibility("radial_force", f), rel=0.01)
        assert co < 1e-3 * counter


def test_fixed_frequency_sidebands_each_meet_the_modes_at_their_own_frequency():
    """sidebands on the co-rotating h = 4.42 line (near the 228-Hz translation mode at the top speeds): the carrier
    C·Ω²·|T(f_c)| and two lines (m/2)·C·Ω²·|T(f_c ± f_mod)| -- each side with the gain at its own frequency."""
    test = simulate_with_injections(E, [parse("sidebands:direction=radial_force,h=4.42,depth=0.4,f_mod_hz=7")],
                                    SPEEDS, seed=3, **KW)
    C = dict(E.harmonics["radial_force"])[4.42]
    for r in test.runs:
        w = abs(r.speed)
        fc = 4.42 * w / (2 * np.pi)
        for f, scale in ((fc, 1.0), (fc - 7.0, 0.2), (fc + 7.0, 0.2)):
            co, counter = senses(r, f)
            assert co == pytest.approx(scale * C * w**2 * transmissibility("radial_force", f), rel=0.01)
            assert counter < 1e-3 * co
    hi = test.runs[-1]
    fc = 4.42 * abs(hi.speed) / (2 * np.pi)
    # the two sides differ by the modes' slope: the check above is not satisfied by equal sides
    assert senses(hi, fc + 7.0)[0] / senses(hi, fc - 7.0)[0] > 1.05


def test_wheel_load_passes_through_the_stands_fixture_resonance():
    """A stand resonance (fixed_resonance role test_stand, 120 Hz, ζ 0.03, gain 5) filters everything the cell
    measures: an injected co-rotating missing harmonic at h = 4.8 (120-192 Hz: across the stand resonance) is its
    free load times |T_r(f)|·|H_stand(f)|."""
    specs = [parse("fixed_resonance:f_hz=120,zeta=0.03,gain=5,role=test_stand"),
             parse("missing_harmonic:direction=radial_force,h=4.8,fraction=0.2")]
    test = simulate_with_injections(E, specs, SPEEDS, seed=4, **{**KW, "test_stand": True})
    for r in test.runs:
        w = abs(r.speed)
        f = 4.8 * w / (2 * np.pi)
        x = f / 120.0
        H = abs((1 - x**2 + 2j * 5 * 0.03 * x) / (1 - x**2 + 2j * 0.03 * x))
        co, _ = senses(r, f)
        assert co == pytest.approx(0.2 * E.fundamental_C("radial_force") * w**2
                                   * transmissibility("radial_force", f) * H, rel=0.01)
    assert [s["kind"] for s in test.meta["injected"]] == ["fixed_resonance", "missing_harmonic"]


def test_load_cell_offset_takes_the_injected_wheel_loads_too():
    """cross_coupling is the load cell's geometry: its r × F holds every force the cell measures, the injected
    wheel load included (listed before or after it), not only the simulation's lines."""
    specs = [parse("cross_coupling:r_x=0,r_y=0,r_z=-0.06"),
             parse("missing_harmonic:direction=radial_force,h=0.5,fraction=0.5")]
    test = simulate_with_injections(E, specs, SPEEDS, seed=5, **KW)
    for r in test.runs:
        F = np.column_stack([r.signals[c] for c in ("Fx", "Fy", "Fz")])
        T_offset = np.cross([0.0, 0.0, -0.06], F)
        f = 0.5 * abs(r.speed) / (2 * np.pi)
        for j, c in enumerate(("Tx", "Ty")):
            # at the half-speed line the torque channels hold only the offset's r × F (the wheel has none: the leakage of its own torque lines is ~1e-5)
            assert abs(dft(r.signals[c], f)) == pytest.approx(abs(dft(T_offset[:, j], f)), rel=1e-3)
        # the offset's torque of the injected line: 0.06 m × its force (which the translation mode lifts by > 1)
        assert abs(dft(r.signals["Tx"], f)) > 0.06 * 0.5 * E.fundamental_C("radial_force") * abs(r.speed) ** 2
