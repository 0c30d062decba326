"""A radial line measured on one channel of its pair at every speed is fitted through the modes, not left free.

The extended fit reads a radial line's power as d_x² + d_y² on the speeds where both channels measured it.  A planar
line (co : counter 0.5, a random orientation per run) detected on whichever channel it leans to is measured on both at
no speed: it had no row in the least squares, its coefficient went where rounding took it (100-150x its level, 4e-18
relative standard error), and the diagnosis of family wheel 2's run-up with its tach lost the wheel's modes on the
held-out runs on machines whose OpenBLAS kernels rounded one way (CI, session 61: three fixed resonances and a law
named instead).

Data: family wheel 2 (tests/family_wheel.py, time-integrated physics; its 2xBSF line h 5.397 planar) run up over 40 s
at a motor's exponential speed, written with its tach column."""
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import family_wheel as fw  # noqa: E402


def test_every_radial_line_of_a_run_up_is_fitted_near_its_load(tmp_path):
    """``rwadist.fit_extended`` of the run-up: every radial-force line the wheel has is fitted within a factor 1.4 of
    its free load (the co and counter parts' root-sum-square against the generator's C; a line measured on one channel
    is read within 2^¼ of its pair's power), each part with a standard error the data give (not a free parameter's
    ~0); before, the planar h 5.397 line came out 117-151x its load."""
    from rwadist import api

    wheel = fw.family()[2]
    data = fw.sweep(wheel, wheel.min_rpm, wheel.max_rpm, 40.0, seed=2, profile="exp")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        test = api.read(fw.write_sweep(data, tmp_path / "run_up.csv", tach=True))
        efit, model = api.fit_extended(test)
    # the case: the planar 2xBSF line measured at each speed on one channel of the pair, never both
    bsf = next(x for x in efit.measured if x.direction == "radial_force" and abs(x.h - 5.397) < 0.01)
    chan = np.asarray(bsf.channel)
    assert not set(bsf.speed[chan == "Fx"]) & set(bsf.speed[chan == "Fy"]), bsf
    assert not efit.unconstrained and abs(efit.params.omega_r / (2 * np.pi) / wheel.f_trans - 1) < 0.02
    fitted = model.harmonics("radial_force")
    for line in (ln for ln in wheel.lines if ln.direction == "radial_force"):
        parts = [hm for hm in fitted if abs(hm.h - line.h) < 2e-3 * line.h]
        assert parts, (line.name, line.h, [hm.h for hm in fitted])
        total = float(np.sqrt(sum(hm.C ** 2 for hm in parts)))
        assert abs(np.log(total / line.C)) < np.log(1.4), (line.name, line.h, total, line.C)
        for hm in parts:
            assert hm.C_stderr > 1e-4 * hm.C, (line.name, hm)


def test_radial_power_reads_a_line_of_one_channel_by_what_the_other_read():
    """The rows of :func:`rwadist.extended_fit._radial_power`, by hand: a line measured on both channels keeps its
    paired speeds (d_x² + d_y², noise sqrt(d_x⁴s_x² + d_y⁴s_y²)/(d_x² + d_y²)); a line measured at each speed on one
    channel (Fx at one, Fy at another) gets every speed: √2·d² where the other channel was read (x² + y² between d² and
    2d²; ½ ln of it scattering by the measurement's error and ln2/(4√3)), 2d² where it was not (a turning load)."""
    from types import SimpleNamespace

    from rwadist.extended_fit import ONE_CHANNEL_LOG_SPREAD, _radial_power

    def line(h, channel, speed, amplitude, noise):
        return SimpleNamespace(direction="radial_force", h=h, channel=np.array(channel), speed=np.array(speed, float),
                               amplitude=np.array(amplitude, float), noise=np.array(noise, float))

    paired = line(1.0, ["Fx", "Fy", "Fx", "Fy", "Fx"], [10, 10, 20, 20, 30], [3, 4, 1, 1, 9], [0.1, 0.2, 0.1, 0.1, 0.3])
    lone = line(5.4, ["Fx", "Fy", "Fx"], [10, 20, 30], [2.0, 3.0, 5.0], [0.1, 0.2, 0.05])
    axial = SimpleNamespace(direction="axial_force", h=2.0, channel=np.array(["Fz"]), speed=np.array([10.0]),
                            amplitude=np.array([1.0]), noise=None)
    read = {"Fx": np.array([10.0, 20.0, 30.0]), "Fy": np.array([10.0, 30.0])}      # Fy not read at 20 rad/s
    li, sp, pw, dr, nz = _radial_power([paired, axial, lone], read)
    assert li.tolist() == [0, 0, 2, 2, 2] and sp.tolist() == [10, 20, 10, 20, 30]
    assert np.allclose(pw[:2], [25.0, 2.0])
    assert np.isclose(nz[0], np.sqrt((9 * 0.1) ** 2 + (16 * 0.2) ** 2) / 25)
    # 10 rad/s on Fx (Fy read): √2·4; 20 on Fy (Fx read): √2·9; 30 on Fx (Fy read): √2·25
    assert np.allclose(pw[2:], np.sqrt(2.0) * np.array([4.0, 9.0, 25.0]))
    assert np.allclose(nz[2:], np.hypot([0.1, 0.2, 0.05], ONE_CHANNEL_LOG_SPREAD))
    assert np.isclose(ONE_CHANNEL_LOG_SPREAD, np.std(0.5 * np.log(np.exp(np.linspace(0, np.log(2), 200001)))), rtol=1e-4)
    # Fx not read at 20 rad/s: the Fy measurement there is a turning load's, 2·9
    li, sp, pw, dr, nz = _radial_power([lone], {"Fx": np.array([10.0, 30.0]), "Fy": np.array([10.0, 20.0, 30.0])})
    assert np.allclose(pw, [np.sqrt(2.0) * 4.0, 2.0 * 9.0, np.sqrt(2.0) * 25.0])
    assert np.isclose(nz[1], 0.2) and dr.tolist() == ["radial_force"] * 3
