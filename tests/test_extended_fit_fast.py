"""The vectorised pieces that make the extended fit and diagnose fast, each against the direct form it replaces:
the least squares' line powers and Jacobian (:class:`rwadist.extended_fit_power.LinePower`) against
:func:`rwadist.extended.steady_lines` and central differences, the blocked DFT against the plain sum, the
tabulated line kernel against the direct window transform, the real-arithmetic scan against the complex
transmissibility."""
import math

import numpy as np
from scipy import signal

from rwadist import extended as ext
from rwadist.dft import windowed_dft
from rwadist.diagnose.engine import line_kernel
from rwadist.extended_fit_power import CHANNEL_INDEX, LinePower
from rwadist.mode_scan import transmissibility_sq
from rwadist.units import DIRECTION_CHANNELS

P = ext.ExtendedParams(mass=10.6, I_zz=0.2, I_rr=0.11, k_r=2e7, k_rock=1.4e4, k_z=2e6, height=0.0, c_r=400.0,
                       c_rock=3.0, c_z=90.0, U_s=0.0, U_d=0.0)
LINES = [ext.Line("radial_force", 1.0, 3e-6, "co", imbalance=True), ext.Line("radial_force", 1.0, 1e-7, "counter"),
         ext.Line("radial_torque", 2.0, 5e-7, "co"), ext.Line("radial_torque", 2.0, 2e-7, "counter"),
         ext.Line("axial_force", 1.98, 2e-6, "co"), ext.Line("axial_torque", 3.0, 1e-7, "co")]
VALS = {k: getattr(P, k) for k in ("mass", "I_zz", "I_rr", "k_r", "k_rock", "k_z", "c_r", "c_rock", "c_z")}


def _case():
    om = np.random.default_rng(0).uniform(-300.0, 300.0, 40)           # both spin senses, crossing every mode
    ax_line = np.array([4] * 20 + [5] * 20)
    ax_ch = np.array([2] * 20 + [5] * 10 + [2] * 10)                     # an axial-torque line read in Fz: no power
    rad_parts = np.array([[0, 1]] * 20 + [[2, 3]] * 20)
    return om, ax_line, ax_ch, rad_parts, LinePower(LINES, om, ax_line, ax_ch, om, rad_parts)


def test_line_power_is_steady_lines():
    om, ax_line, ax_ch, rad_parts, lp = _case()
    r, _, _ = lp.log_residuals(VALS, np.log([ln.C for ln in LINES]), np.zeros(lp.n_rows))
    _, A = ext.steady_lines(P, LINES, om)
    Pw = np.abs(A) ** 2
    ref_ax = Pw[np.arange(om.size), ax_line, ax_ch]
    ref_rad = np.array([sum(Pw[i, j, CHANNEL_INDEX[c]] for j in parts for c in DIRECTION_CHANNELS[LINES[j].direction])
                        for i, parts in enumerate(rad_parts)])
    ref = -0.5 * np.log(np.maximum(np.concatenate([ref_ax, ref_rad]), 1e-300))
    np.testing.assert_allclose(r, ref, rtol=1e-12, atol=1e-12)


def test_line_power_jacobian_is_the_central_difference():
    _, _, _, _, lp = _case()
    log_c = np.log([ln.C for ln in LINES])
    _, d_mode, d_c = lp.log_residuals(VALS, log_c, np.zeros(lp.n_rows))
    eps = 1e-6
    names = {"radial_translation": ("k_r", "c_r"), "rocking": ("k_rock", "c_rock"), "axial_translation": ("k_z", "c_z")}
    for mode, keys in names.items():
        for j, key in enumerate(keys):
            up, dn = dict(VALS), dict(VALS)
            up[key] *= math.exp(eps)
            dn[key] *= math.exp(-eps)
            fd = (lp.log_residuals(up, log_c, np.zeros(lp.n_rows))[0]
                  - lp.log_residuals(dn, log_c, np.zeros(lp.n_rows))[0]) / (2 * eps)
            np.testing.assert_allclose(d_mode[mode][j], fd, rtol=1e-5, atol=1e-7)
    for k in range(len(LINES)):
        up, dn = log_c.copy(), log_c.copy()
        up[k] += eps
        dn[k] -= eps
        fd = (lp.log_residuals(VALS, up, np.zeros(lp.n_rows))[0]
              - lp.log_residuals(VALS, dn, np.zeros(lp.n_rows))[0]) / (2 * eps)
        np.testing.assert_allclose(d_c[:, k], fd, rtol=1e-5, atol=1e-7)


def test_blocked_dft_is_the_plain_sum():
    rng = np.random.default_rng(1)
    for n, fs in ((8192, 3840.0), (1001, 1000.0)):                        # a length that is not a multiple of the block
        x = rng.normal(size=(n, 2))
        f = rng.uniform(0.5, 0.45 * fs, 13)
        ref = np.exp(-2j * np.pi * np.outer(f, np.arange(n) / fs)) @ x
        np.testing.assert_allclose(windowed_dft(x, fs, f), ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def test_line_kernel_is_the_window_transform():
    for nperseg, fs in ((256, 1000.0), (2048, 3840.0)):
        delta, K = line_kernel(nperseg, fs)
        w = signal.get_window("hann", nperseg)
        W = np.exp(-2j * np.pi * np.outer(delta, np.arange(nperseg)) / nperseg) @ w
        np.testing.assert_allclose(K, np.abs(W) ** 2 / (fs * np.sum(w**2)), rtol=0, atol=1e-13 * K.max())
        # Parseval: Σ_k K(k)·df = 1 over integer offsets (the table's ±(half + 1) bins hold all but ~1e-4)
        assert abs(np.sum(K[(delta % 1) == 0]) * fs / nperseg - 1) < 1e-3


def test_scan_transmissibility_is_the_complex_ratio():
    rng = np.random.default_rng(2)
    nu, om = rng.uniform(-600, 600, 50), rng.uniform(-300, 300, 50)
    f0, z, a = np.array([20.0, 55.0, 230.0]), np.array([0.01, 0.05, 0.3]), np.array([0.0, 2.0, 1.3])
    w0 = 2 * np.pi * f0[:, None]
    d = 2 * z[:, None] * w0 * nu[None, :]
    ref = np.abs(w0**2 + 1j * d) ** 2 / np.abs(w0**2 - nu**2 + a[:, None] * np.abs(om) * nu + 1j * d) ** 2
    np.testing.assert_allclose(transmissibility_sq(nu, om, f0, z, a), ref, rtol=1e-12)


def test_line_power_cells_sum_as_add_at_does():
    # d_C sums each (row, line) cell's terms by one bincount over lp.cell: the numbers of np.add.at over (row, line)
    # in the same order, bit for bit (a radial row holds two terms; a co/counter pair of one line shares a cell)
    _, _, _, _, lp = _case()
    w = np.random.default_rng(3).normal(size=lp.row.size)
    ref = np.zeros((lp.n_rows, lp.n_lines))
    np.add.at(ref, (lp.row, lp.line), w)
    got = np.bincount(lp.cell, w, minlength=lp.n_rows * lp.n_lines).reshape(lp.n_rows, lp.n_lines)
    assert np.array_equal(got, ref)
    # every live row's shares sum to one: its d_C row to -1
    _, _, d_c = lp.log_residuals(VALS, np.log([ln.C for ln in LINES]), np.zeros(lp.n_rows))
    np.testing.assert_allclose(d_c.sum(axis=1)[d_c.any(axis=1)], -1.0, rtol=1e-12)


def test_residuals_alone_are_those_of_the_jacobians_evaluation():
    # a damping's profile reads _Residuals.value: the residuals of the least squares' own evaluation bit for bit, with
    # a freed exponent, row weights, a clamped and a held damping, and the cache of the Jacobian left as it was
    from rwadist.extended_fit_lsq import LogAmplitudeProblem, _Residuals

    om, _, _, _, lp = _case()
    rng = np.random.default_rng(4)
    base = dict(VALS, height=0.0, U_s=0.0, U_d=0.0)
    row_line = rng.integers(0, 3, lp.n_rows)
    problem = LogAmplitudeProblem(base, LINES, lp, rng.normal(size=lp.n_rows), None, row_line,
                                  rng.normal(size=lp.n_rows), [], held_zeta={"axial_translation": 0.02})
    modes = ["radial_translation", "rocking", "axial_translation"]
    res = _Residuals(problem, modes, [np.where(row_line == 1, problem.centred_log_w, 0.0)])
    theta0 = np.concatenate([np.log([VALS[k] for k in ("k_r", "c_r", "k_rock", "c_rock", "k_z", "c_z")]),
                             np.log([ln.C for ln in LINES]), [0.3]])
    for weights in (None, rng.uniform(0.2, 1.0, lp.n_rows)):
        res.weights = weights
        for shift in (0.0, 0.4, 9.0):                  # 9: the rocking damping beyond critical, clamped
            theta = theta0 + shift * (np.arange(theta0.size) == 3) + 0.01 * rng.normal(size=theta0.size)
            alone = res.value(theta)
            assert res.key != theta.tobytes()          # the cache untouched
            assert np.array_equal(alone, res.residuals(theta))
