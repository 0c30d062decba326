"""Third-party data: ROSS's steady response of a disk on a shaft with two bearings (gyroscopics on,
unbalance and rotating harmonics), as load-cell time series (tests/ross_dataset.py, made by
benchmarks/ross_loadcell.py).  The extended fit must find ROSS's own whirl frequencies (ROSS's
run_modal Campbell diagram stored with the data) within 1 % at three speeds."""
import numpy as np
import pytest
from ross_dataset import campbell, load_doc, ross_test

from rwadist import extended as ext
from rwadist.empirical import fit_empirical
from rwadist.extended_fit import fit_extended
from rwadist.spectra import compute_spectra


@pytest.fixture(scope="module")
def ross_fit():
    doc = load_doc()
    test = ross_test(noise=0.01, seed=0)
    fit = fit_empirical(compute_spectra(test))
    return doc, fit_extended(test, fit, doc["rotor"]["mass_kg"], doc["rotor"]["radius_m"])


def _ross_modes(row):
    """ROSS's lateral modes at one speed by whirl label: rocking backward / forward, translation, axial."""
    f, w = np.asarray(row["modes_hz"]), list(row["whirl"])
    axial = [x for x, lab in zip(f, w) if lab not in ("Forward", "Backward")]
    lateral = sorted((x, lab) for x, lab in zip(f, w) if lab in ("Forward", "Backward"))
    backward = lateral[0]
    assert backward[1] == "Backward"
    forward = next(x for x, lab in lateral[1:] if lab == "Forward")
    translation = np.mean([x for x, _ in lateral[1:] if x != forward])
    return {"rocking_backward": backward[0], "rocking_forward": forward, "radial_translation": translation,
            "axial_translation": axial[0]}


def test_whirl_frequencies_match_ross_campbell_within_1_percent(ross_fit):
    doc, ef = ross_fit
    assert ef.unconstrained == [], ef.notes
    rows = campbell(doc)
    assert len(rows) == 3
    for row in rows:
        want = _ross_modes(row)
        got = ext.whirl_frequencies(ef.params, row["speed_rpm"] * np.pi / 30)
        for mode, f_ross in want.items():
            err = float(got[mode]) / f_ross - 1
            print(f"{row['speed_rpm']:6.0f} rpm {mode:18s} fit {float(got[mode]):9.4f} Hz  ROSS {f_ross:9.4f} Hz "
                  f"{100 * err:+.3f} %")
            assert abs(err) < 0.01, (row["speed_rpm"], mode, float(got[mode]), f_ross)


def test_senses_of_the_ross_forcing_recovered(ross_fit):
    """The h = 2 lines were applied against the spin in ROSS, the others with it."""
    doc, ef = ross_fit
    for ln in doc["lines"]:
        if ln["direction"] == "axial_force":
            continue
        key = next(k for k in ef.senses if k[0] == ln["direction"] and abs(k[1] - ln["h"]) < 0.02)
        assert ef.senses[key][0] == ln["sense"], (key, ef.senses[key], ln["sense"])
