"""Standard errors of the extended fit's least squares with each load direction's own residual variance
(rwadist.extended_fit_lsq._covariance).

References: scipy.optimize.curve_fit's covariance (s²·(JᵀJ)⁻¹, s² = SSR/(n − p)) for one direction, and for rows of
two directions whose parameters are separate, each direction's covariance computed on its rows alone: a misfit of
one direction (a resonance moving with speed on the radial forces) does not widen the other's.
"""
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import curve_fit

from rwadist.extended_fit_lsq import _covariance


def _line(x, a, b):
    return a + b * x


def test_one_direction_is_curve_fits_covariance():
    rng = np.random.default_rng(4)
    x = np.linspace(0.0, 3.0, 40)
    y = 1.0 + 0.5 * x + 0.1 * rng.standard_normal(x.size)
    popt, pcov = curve_fit(_line, x, y)
    jac = np.column_stack([np.ones_like(x), x])
    res = SimpleNamespace(fun=y - _line(x, *popt), jac=jac, x=popt)
    assert np.allclose(_covariance(res, np.zeros(x.size, int)), pcov, rtol=1e-8)


def test_another_directions_misfit_does_not_widen_a_parameter_of_its_own():
    rng = np.random.default_rng(5)
    n = 30
    x = np.linspace(0.0, 1.0, n)
    quiet = 0.01 * rng.standard_normal(n)           # direction 0: its own line, small scatter
    loud = 0.5 * rng.standard_normal(n)             # direction 1: a large misfit
    jac = np.zeros((2 * n, 4))
    jac[:n, 0], jac[:n, 1] = 1.0, x
    jac[n:, 2], jac[n:, 3] = 1.0, x
    res = SimpleNamespace(fun=np.concatenate([quiet, loud]), jac=jac, x=np.zeros(4))
    cov = _covariance(res, np.repeat([0, 1], n))
    # each direction alone: its own mean squared residual times (JᵀJ)⁻¹ of its rows (the pooled n/(n − p) kept)
    scale = 2 * n / (2 * n - 4)
    own = np.linalg.inv(jac[:n, :2].T @ jac[:n, :2]) * np.mean(quiet**2) * scale
    assert np.allclose(cov[:2, :2], own, rtol=1e-10)
    pooled = np.linalg.inv(jac.T @ jac) * np.sum(res.fun**2) / (2 * n - 4)
    assert np.sqrt(pooled[1, 1]) > 20 * np.sqrt(cov[1, 1])      # pooled, the loud rows widened it 50x
    assert cov[:2, 2:] == pytest.approx(0.0, abs=1e-15)
