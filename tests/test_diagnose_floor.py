"""The broadband floor on clean data (issue 14: no floor invented where there is none).

Independent reference: clean modal data of the thesis's wheel E (tests/independent_wheel.py, through
tests/test_diagnose_modelpath.py's helpers) diagnosed against a model fitted on another clean run of the same
stand: nothing may be added.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_diagnose_modelpath import _reference, _run  # noqa: E402

from rwadist import api  # noqa: E402


def test_model_path_at_low_noise_adds_no_broadband_floor():
    """Every factor at its lowest (300-2400 rpm, 20 speeds, 2048 samples, 1000 Hz, 0.1 % noise; the matrix's
    corner-low cell and its seeds): the lines stand ~85 dB over the noise.  Nothing is added (before: a
    broadband_floor on Fz, p 0.5, 99.9 % of whose held-out gain was the noise allowance it granted the lines'
    bins, the rest the lines' leakage beside them)."""
    low = dict(rpm=(300.0, 2400.0), n_speeds=20, n_samples=2048, rate=1000.0, noise=0.001)
    model = _reference(_run(2512, **low))
    d = api.diagnose(_run(2012, **low), model)
    assert [e["kind"] for e in d.model.effects] == []
    assert d.error_after == d.error_before
