"""The error metric of ``rwadist diagnose`` (``waterfall_unexplained_fraction``, docs/diagnose.md).

:class:`Metric` is mixed into :class:`rwadist.diagnose.engine.Context`: it needs the context's bands,
degrees of freedom, data and predictions.
"""
from __future__ import annotations

import numpy as np

from .constants import BAND_BINS, NOISE_Z
from .state import State


class Metric:
    """Band powers, their noise standard deviations and the misplaced power (methods of a Context)."""

    def band_sums(self, x: np.ndarray) -> np.ndarray:
        lo = self.k_lo
        n = self.n_bands * BAND_BINS
        return x[:, lo:lo + n].reshape(x.shape[0], self.n_bands, BAND_BINS).sum(-1) * self.df

    def band_sigma(self, state: State, c: str, runs: np.ndarray, floor=None, lines=None) -> np.ndarray:
        """Noise standard deviation (unit²) of the data power in every band if the model were right.

        A Welch PSD bin of noise N plus a deterministic line L has variance (N² + 2·L·N)·2/ν
        (ν = Welch degrees of freedom; the second term is the line × noise cross term); bins
        are summed as if independent and the result doubled for the Hann correlation of
        neighbouring bins (an approximation, stated)."""
        N = self.floor_psd(state, c, runs) if floor is None else floor
        L = (self.predict(state, c, runs) - N) if lines is None else lines
        var_bin = (N**2 + 2.0 * np.maximum(L, 0.0) * N) * 2.0 / self.dof
        return np.sqrt(2.0 * self.band_sums(var_bin) * self.df)

    def run_errors(self, state: State, runs: np.ndarray, channels=None, detail: bool = False):
        """Per run: (E_num, D_tot) summed over channels and bands, E_num = Σ max(|D − M| − 2σ, 0)
        (the misplaced power beyond two noise standard deviations), each channel divided by the mean
        data power of its unit group so forces and torques weigh alike.  ``detail``: also the per-band
        (channel -> (D − M, σ)) arrays (the residual: an effect may change the model M or, a measurement
        correction, the data D as the state reads them)."""
        err = np.zeros(runs.size)
        tot = np.zeros(runs.size)
        parts = {}
        for c in channels or self.channels:
            Dfull = self.data(state, c, runs)[runs]
            ok = np.isfinite(Dfull[:, 0])
            D = self.band_sums(Dfull)
            N = self.floor_psd(state, c, runs)
            Mfull = self.predict(state, c, runs)
            M = self.band_sums(Mfull)
            sig = self.band_sigma(state, c, runs, N, Mfull - N)
            scale = self.scale(c)
            e = np.maximum(np.abs(D - M) - NOISE_Z * sig, 0.0)
            err[ok] += e[ok].sum(1) / scale
            tot[ok] += D[ok].sum(1) / scale
            parts[c] = ((D - M) / scale, sig / scale)
        return (err, tot, parts) if detail else (err, tot)

    def scale(self, c):
        return self._scale[c]

    def error(self, state: State, runs=None) -> float:
        e, t = self.run_errors(state, self.runs if runs is None else runs)
        return float(e.sum() / t.sum())

    def rms_error(self, state: State) -> float:
        vals = []
        for c in self.channels:
            D = self.band_sums(self.data(state, c)[self.runs]).sum(1)
            M = self.band_sums(self.predict(state, c, self.runs)).sum(1)
            vals.append(np.abs(np.sqrt(M) - np.sqrt(D)) / np.sqrt(D))
        return float(np.nanmean(np.concatenate(vals)))
