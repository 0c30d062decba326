"""A fixed line one channel never reads (its tone fit past the misfit limit in every run) is measured on the others
without numpy's "All-NaN slice encountered" on the console (trial 33: a fixture at 100 Hz, the user's command printed
``fixed_lines.py:204: RuntimeWarning: All-NaN slice encountered``).

Data made here with numpy: a 50 Hz tone on every channel of 8 steady runs; the tone's amplitudes of Tz made NaN, as
:func:`rwadist.diagnose.fixed_lines.run_amplitudes` gives them where its fit leaves too much."""
import importlib
import warnings

import numpy as np

from rwadist.data import Run, SteadyTest
from rwadist.diagnose.engine import Context
from rwadist.spectra import compute_spectra

fixed_lines = importlib.import_module("rwadist.diagnose.fixed_lines")
CHANNELS = ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz")


def test_a_fixed_line_no_run_reads_on_one_channel_is_measured_without_a_numpy_warning(monkeypatch):
    rng = np.random.default_rng(33)
    fs, n = 2000.0, 8192
    t = np.arange(n) / fs
    runs = [Run(float(om), fs, {c: 0.3 * np.cos(2 * np.pi * 50.0 * t + rng.uniform(0, 6)) + 0.01 * rng.standard_normal(n)
                                for c in CHANNELS}, name=f"r{i}.csv")
            for i, om in enumerate(np.linspace(60.0, 250.0, 8))]
    test = SteadyTest(runs)
    ctx = Context(compute_spectra(test), test=test)
    read = fixed_lines.run_amplitudes

    def tz_unread(ctx_, f_hz, chans):
        out = read(ctx_, f_hz, chans)
        out[:, list(chans).index("Tz")] = np.nan
        return out

    monkeypatch.setattr(fixed_lines, "run_amplitudes", tz_unread)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        line = fixed_lines._measure(ctx, int(round(50.0 / float(ctx.sp.df))), CHANNELS)
    assert line is not None and abs(float(np.atleast_1d(line.f_Hz)[0]) - 50.0) < 0.05
