"""A copy into a channel that has lines of its own at the source's lines is read the right way round.

A new user's 9-kg wheel with Ty += 0.15·Fx (session 63): the wheel's torque lines share the force lines' h, so at Fx's
line points 22 % of Ty's power is its own.  The copy is read on the noise floor both ways (a Gaussian pair of floors
reads alike either way: κ forward, κ·σ_s²/(σ_t² + κ²σ_s²) = 5.7 backward), and the way kept was the one whose removal
took the more of the target's power at the source's lines: 0.781 forward against 0.774 backward, a gap the lines'
random phases decided; "Fx reads 5.72 × Ty" on 2 of 9 seeds, and the diagnosis then lost the rocking mode and
invented a cross-coupling or a counter-rotation.  A rotor's radial lines are rotating loads, x and y of one amplitude:
removed the right way the copy leaves Fx round against Fy and Ty against Tx, read backwards neither
(:func:`rwadist.diagnose.channel_copy._round_after`).

Data made here with numpy: 30 steady runs over 500-5000 rpm (4 kHz, 4 s), co-rotating radial force and torque lines at
h 1, 2, 3.6 and 5.4 (each with a phase of its own per run), an Fz line, white noise on the forces and 6 % of it on the
torques, then Ty += 0.15·Fx on the records.  Before: seeds 5, 8, 9 and 10 of 0-11 read it backwards."""
import numpy as np
import pytest

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.channel_copy import find_channel_copies
from rwadist.diagnose.engine import Context
from rwadist.spectra import compute_spectra

KAPPA = 0.15
FS, N = 4000.0, 16000
#: the radial lines (h, C of the force, C of the torque; N/(rad/s)², N·m/(rad/s)²), co-rotating
LINES = ((1.0, 2.5e-6, 2e-7), (2.0, 4e-7, 3e-8), (3.6, 1.5e-7, 1.2e-8), (5.4, 1e-7, 8e-9))


def _copied(seed: int, lines=LINES, axial=(3.6, 3e-7), target: str = "Ty", kappa: float = KAPPA,
            ellipse: float = 1.0) -> SteadyTest:
    """30 runs of the radial ``lines`` (Fy ``ellipse`` × a quarter turn of Fx: 1, round), an Fz line ``axial``
    (h, C), white noise, and ``target`` += ``kappa``·Fx on the records."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / FS
    runs = []
    for rpm in np.linspace(500.0, 5000.0, 30):
        om = rpm * 2 * np.pi / 60
        sig = {c: 0.05 * rng.standard_normal(N) for c in ("Fx", "Fy", "Fz")}
        sig.update({c: 0.003 * rng.standard_normal(N) for c in ("Tx", "Ty", "Tz")})
        for h, c_force, c_torque in lines:
            for (cx, cy), c in ((("Fx", "Fy"), c_force), (("Tx", "Ty"), c_torque)):
                ph = rng.uniform(0, 2 * np.pi)
                sig[cx] += c * om**2 * np.cos(h * om * t + ph)
                sig[cy] += ellipse * c * om**2 * np.sin(h * om * t + ph)
        sig["Fz"] += axial[1] * om**2 * np.cos(axial[0] * om * t + rng.uniform(0, 2 * np.pi))
        sig[target] = sig[target] + kappa * sig["Fx"]
        runs.append(Run(float(om), FS, sig, name=f"r{rpm:.0f}.csv"))
    return SteadyTest(runs)


@pytest.mark.parametrize("seed", [0, 5, 8])
def test_a_force_copied_into_a_torque_with_lines_of_its_own_is_read_forward(seed):
    test = _copied(seed)
    copies = find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))
    assert [(c.source, c.target) for c in copies] == [("Fx", "Ty")]
    assert abs(copies[0].kappa) == pytest.approx(KAPPA, rel=0.01)


def _force_in_axial(seed: int, ellipse: float) -> SteadyTest:
    """Fz += 0.1·Fx where Fx's lines stand under 10 dB in Fz (read on the floor alone); Fy = ``ellipse`` × a quarter
    turn of Fx on every radial line (1: round)."""
    return _copied(seed, ((1.0, 2.5e-7, 2e-8), (2.0, 4e-8, 3e-9), (3.27, 3e-8, 2e-9), (4.1, 2e-8, 0.0)),
                   axial=(3.27, 3e-8), target="Fz", kappa=0.1, ellipse=ellipse)


@pytest.mark.parametrize("seed, ellipse", [(0, 1.0), (1, 1.0), (2, 0.8)])
def test_a_radial_force_copied_into_an_axial_one_on_the_floor_is_read_forward(seed, ellipse):
    """One radial channel in the pair: removing the copy from Fz leaves Fx as it was, so the lines' roundness cannot
    tell the ways apart (a reviewer's case: judged by it, "Fx reads 0.1 × Fz" on 6 seeds of 10, 3 of 3 with elliptic
    lines); the target's power taken at the source's lines decides, as before."""
    test = _force_in_axial(seed, ellipse)
    copies = find_channel_copies(Context(compute_spectra(test, nperseg=1024), test=test))
    assert [(c.source, c.target) for c in copies] == [("Fx", "Fz")]
