"""A one-direction resonance (a housing mode, ``fixed_resonance`` role wheel_mode) whose half-power band holds no
line: the lines fix f_r and g·ζ but not ζ, and the fit's damping runs to its floor.  The widest damping the lines
allow (:func:`rwadist.effects.fixed_resonance_diagnose._widest_width`) is taken instead of dropping the resonance.

Checked against the closed-form gain H(r) = (1 − r² + 2jgζr)/(1 − r² + 2jζr) written out here, on line gains
sampled from it (with scatter) at line frequencies that skip its half-power band, as the lines of a few speeds do."""
import numpy as np

from rwadist.effects.fixed_resonance_diagnose import MAX_ZETA, FixedResonance, _widest_width


def log_power_gain(f_hz, f_r, zeta, g):
    """ln|H|², H written out (not rwadist.resonance)."""
    r = np.asarray(f_hz, dtype=float) / f_r
    h = (1.0 - r**2 + 2j * g * zeta * r) / (1.0 - r**2 + 2j * zeta * r)
    return np.log(np.abs(h) ** 2)


def _lines(f_r, zeta, seed):
    """Line frequencies from 0.4 to 1.8 f_r, none within 1.5 half-power widths of f_r (the peak no line hit)."""
    rng = np.random.default_rng(seed)
    f = np.sort(rng.uniform(0.4, 1.8, 120)) * f_r
    return f[np.abs(f / f_r - 1.0) > 1.5 * zeta]


def _floor_fit(f, y, sw, f_r):
    """What the three-parameter fit ends at here (a floor damping, the peak gain keeping g·ζ): its cost."""
    from scipy.optimize import least_squares

    lo, hi = 0.3 * f_r, 2.0 * f_r
    lb, ub = np.log([lo, 1e-3, 0.02]), np.log([hi, 0.5, 200.0])

    def res(x):
        return sw * (y - log_power_gain(f, *np.exp(x)))

    sol = least_squares(res, np.log([f_r, 0.01, 10.0]), loss="soft_l1", f_scale=0.5, bounds=(lb, ub))
    return sol, lo, hi


def test_widest_width_recovers_a_housing_mode_whose_peak_no_line_hit():
    f_r, zeta, g = 368.0, 0.03, 5.0
    for seed in range(3):
        f = _lines(f_r, zeta, seed)
        rng = np.random.default_rng(100 + seed)
        y = log_power_gain(f, f_r, zeta, g) + rng.normal(0.0, 0.1, f.size)
        sw = np.ones(f.size)
        sol, lo, hi = _floor_fit(f, y, sw, f_r)
        floor = FixedResonance(float(np.exp(sol.x[0])), 1e-3, float(g * zeta / 1e-3), ("Fx", "Fy"), "wheel_mode")
        assert not floor.significant()                  # at its floor: what the search used to drop
        e = _widest_width(floor, f, y, sw, lo, hi, float(sol.cost))
        assert e.significant()
        assert abs(e.f_r / f_r - 1.0) < 0.01
        # the width the lines allow includes the truth, and is not much wider than the lines resolve
        assert 0.7 * zeta <= e.zeta <= 2.5 * zeta <= MAX_ZETA
        # what it predicts at the lines is the truth within their scatter
        pred = log_power_gain(f, e.f_r, e.zeta, e.peak_gain)
        assert np.sqrt(np.mean((pred - log_power_gain(f, f_r, zeta, g)) ** 2)) < 0.1


def test_widest_width_keeps_a_fit_its_lines_refuse_to_widen():
    # a true narrow peak (ζ 0.002) sampled close on both sides: no wider resonance fits those lines
    f_r, zeta, g = 200.0, 0.002, 30.0
    f = f_r * np.concatenate([np.linspace(0.9, 0.995, 30), np.linspace(1.005, 1.1, 30)])
    y = log_power_gain(f, f_r, zeta, g)
    sw = np.ones(f.size)
    sol, lo, hi = _floor_fit(f, y, sw, f_r)
    start = FixedResonance(f_r, 1e-3, g * zeta / 1e-3, ("Fx", "Fy"), "wheel_mode")
    e = _widest_width(start, f, y, sw, lo, hi, float(sol.cost))
    assert e.zeta < 0.004
