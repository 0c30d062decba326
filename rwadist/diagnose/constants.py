"""Constants of ``rwadist diagnose``: bands, kernel, noise allowance, the metric's name."""
from __future__ import annotations

import numpy as np

#: Torque channels, in the order of the components of r × F.
TORQUE_CHANNELS = ("Tx", "Ty", "Tz")

#: Bins per band of the error metric.
BAND_BINS = 8
#: Lowest frequency used, in bins (as the empirical fit's f_min_bins).
F_MIN_BINS = 4
#: Half width (bins) of a line's window when measuring its power.
LINE_HALF = 3
#: Half width (bins) of the line kernel used in predictions.
KERNEL_HALF = 16
#: Exponent grid of the broadband-floor fit (PSD ∝ |Ω|^p).
FLOOR_EXPONENTS = np.arange(0.5, 8.01, 0.25)
METRIC = "waterfall_unexplained_fraction"
#: Line-to-noise power ratio above which a line's log gain gets full weight in a resonance fit.
SNR_KNEE = 10.0
#: Noise standard deviations forgiven per band by the error metric.
NOISE_Z = 2.0
#: The second figure of merit, beside METRIC: every band of the waterfall weighs alike (docs/diagnose.md).
CONTRAST_METRIC = "waterfall_band_contrast"
#: Noise standard deviations forgiven per band by CONTRAST_METRIC: what a reviewer does not see as a feature.
CONTRAST_NOISE_Z = 3.0
