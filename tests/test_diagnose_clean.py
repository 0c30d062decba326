"""``rwadist diagnose DATA`` (no model) adds nothing to clean modes-on data where its fits reach their limits
(issue 14, the matrix's clean rows).

* Short records (2048 samples at 3840 Hz: one Welch segment for the fit, 7.5-Hz bins for the search): the E
  wheel's radial-force lines h = 5.37 and 5.57 are 0.2·Ω/2π apart, unresolved at the low speeds, so the
  modes' fit leaves them out and the search sees their merged ridge near h = 5.47.  With no model there is
  nothing a line could be missing from: it is completed into the fitted base (``provenance.diagnose.base_lines``),
  not named as a foreign ``missing_harmonic``.  Independent check: its C is the pair's combined amplitude,
  sqrt(C_5.37² + C_5.57²) (two lines of independent phases add in power), from the thesis Table 3.4 values
  typed in tests/independent_wheel.py.
* A fixture resonance (180 Hz, ζ 0.03, peak gain 5, every channel) beside the radial translation mode (227.7 Hz)
  over 100-6000 rpm at 10 kHz with 5 % noise: the fixture's start, fitted on every direction's lines pooled, was
  pulled by the translation mode's skirt (185 Hz, ζ 0.06-0.09, gain 7-8) and, divided out, left no mode
  located: no suspension_modes and five invented effects.  The start now gives each direction its own smooth
  trend beside the common resonance; the truth is the thesis's modes (tests/independent_wheel.py) and the
  injected fixture.  The matrix's high corner itself (120 speeds, 32768 samples) is the slow test.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import independent_wheel as iw  # noqa: E402

from rwadist import api  # noqa: E402
from rwadist.inject import parse, simulate_with_injections  # noqa: E402
from rwadist.presets import preset  # noqa: E402
from rwadist.teststand import simulate_steady  # noqa: E402

# thesis Table 3.4 (E wheel), radial force, SI: the close pair
C_537, C_557 = (c * iw.C_UNIT for d, h, c, _ in iw.E_LINES if d == "radial_force" and h in (5.37, 5.57))


def test_short_records_merged_lines_completed_into_the_base():
    test = simulate_steady(preset("ithaco-e"), np.linspace(300.0, 3000.0, 30), sample_rate=3840.0, n_samples=2048,
                           noise=0.01, seed=2, physics="extended", test_stand=False)
    d = api.diagnose(test)
    kinds = [e["kind"] for e in d.model.effects]
    assert kinds[0] == "suspension_modes"
    assert "missing_harmonic" not in kinds, kinds
    lines = d.model.provenance["diagnose"].get("base_lines")
    assert lines and [x["direction"] for x in lines] == ["radial_force"]
    assert 5.37 < lines[0]["h"] < 5.57
    assert lines[0]["C"] == pytest.approx(np.hypot(C_537, C_557), rel=0.10)
    # completed into the improved model's harmonics, not dropped
    assert any(abs(x.h - lines[0]["h"]) < 1e-3 for x in d.model.harmonics("radial_force"))
    assert d.summary()["base_lines"] and not any(e["kind"] == "missing_harmonic" for e in d.summary()["effects"])


def _modes_and_stand_only(d):
    kinds = sorted(e["kind"] for e in d.model.effects)
    assert kinds == ["fixed_resonance", "suspension_modes"], kinds
    sm = next(e for e in d.model.effects if e["kind"] == "suspension_modes")
    assert not sm.get("unconstrained")
    for m in ("radial_translation", "rocking", "axial"):
        assert sm[f"{m}_Hz"] == pytest.approx(iw.TRUTH_HZ[m], rel=0.02)
    st = next(e for e in d.model.effects if e["kind"] == "fixed_resonance")
    assert st["role"] == "test_stand"
    assert st["f_Hz"] == pytest.approx(180.0, rel=0.01)
    assert st["zeta"] == pytest.approx(0.03, rel=0.10)
    assert st["peak_gain"] == pytest.approx(5.0, rel=0.05)


def _stand_beside_translation(n_speeds, n_samples, seed):
    return simulate_with_injections(preset("ithaco-e"), [parse("fixed_resonance:f_hz=180,zeta=0.03,gain=5,role=test_stand")],
                                    np.linspace(100.0, 6000.0, n_speeds), physics="extended", seed=seed,
                                    sample_rate=10000.0, n_samples=n_samples, noise=0.05, test_stand=True)


def test_stand_beside_the_translation_mode_modes_and_stand_only():
    _modes_and_stand_only(api.diagnose(_stand_beside_translation(40, 8192, 1)))


@pytest.mark.slow
def test_high_corner_clean_modes_and_stand_only():
    """The matrix's corner-high cell, clean."""
    _modes_and_stand_only(api.diagnose(_stand_beside_translation(120, 32768, 2013)))
