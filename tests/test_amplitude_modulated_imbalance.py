"""An imbalance line amplitude-modulated at a fixed frequency close to it: the carrier kept, its sidebands named.

Trial nuR (a 12-kg wheel of a new user's generator, 1x modulated 1 + 0.3·cos(2π·0.7 Hz·t) on the radial force and
torque) and family wheel 2 here (15 kg, I_zz/I_rr 2.2, modes 90/50/62 Hz, 300-3000 rpm, 2 kHz, 8192 samples): the
sidebands sit 0.7 Hz from the carrier, inside its Welch window and 2.9 record bins from it.  Before:

* the plain fit lost the imbalance: its candidates h 0.985, 1.0 and 1.0145 were all detected in every run, the tie
  went to the first and the carrier merged into its lower sideband's candidate, or the carrier's measurements were
  all refused for the sideband detections under its window;
* ``rwadist diagnose`` then put the 1x line back twice and wrote a model its own reader refuses (exit 2, "h 1 (sense
  'co') is empirical.radial_force[5] again"), the rocking mode found 5 % off (52.5 Hz, I_zz/I_rr 1.94);
* the sidebands measured on the whole record, added on top of a carrier whose Welch power already held them, raised
  the error (0.0059 -> 0.019) and were not taken.

The generator (tests/family_effects.Sidebands) is independent of rwadist: the closed form of an amplitude
modulation, a carrier and two lines of depth/2 at ±f_mod.
"""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import family_effects as fe  # noqa: E402
import family_wheel as fw  # noqa: E402

from rwadist import api, cli  # noqa: E402

DEPTH, F_MOD = 0.3, 0.7


@pytest.fixture(scope="module")
def modulated(tmp_path_factory):
    w = fw.family(0)[2]
    effects = [fe.Sidebands(direction=d, h=1.0, depth=DEPTH, f_mod_hz=F_MOD) for d in ("radial_force", "radial_torque")]
    path = fw.write_steady(fw.steady(w, noise=0.01, seed=1, effects=effects),
                           tmp_path_factory.mktemp("am") / "data", w.name)
    return w, path


def test_the_plain_fit_keeps_the_modulated_imbalance(modulated):
    w, path = modulated
    fit = api.fit(api.read(path))
    ones = [x for x in fit.model.harmonics("radial_force") if abs(x.h - 1.0) < 0.05]
    assert len(ones) == 1
    assert ones[0].h == pytest.approx(1.0, abs=1e-3)
    # its Welch window holds the sidebands' power with the carrier's: C·sqrt(1 + depth²/2), 2.2 % over the carrier
    assert ones[0].C == pytest.approx(w.imbalance("radial_force") * np.sqrt(1 + DEPTH**2 / 2), rel=0.03)
    side = [b for b in fit.bins if b.direction == "radial_force" and 1.0 < b.h < 1.1 and b.sideband_of is not None]
    assert side and not any(b.kept for b in side)


def test_diagnose_names_the_sidebands_on_both_directions_and_writes_its_model(modulated, tmp_path, capsys):
    w, path = modulated
    out = tmp_path / "report"
    assert cli.main(["diagnose", str(path), "-o", str(out)]) == 0
    capsys.readouterr()
    summary = json.loads((out / "summary.json").read_text())
    kinds = [e["kind"] for e in summary["effects"]]
    assert sorted(kinds) == ["sidebands", "sidebands", "suspension_modes"]
    for e in summary["effects"]:
        if e["kind"] == "sidebands":
            assert e["h"] == pytest.approx(1.0, abs=1e-3)
            assert e["f_mod_Hz"] == pytest.approx(F_MOD, abs=0.01)
            # the depth against the carrier itself, not against the Welch window's carrier-and-sidebands
            assert e["depth"] == pytest.approx(DEPTH, rel=0.05)
    assert sorted(e["direction"] for e in summary["effects"] if e["kind"] == "sidebands") == \
        ["radial_force", "radial_torque"]
    modes = next(e for e in summary["effects"] if e["kind"] == "suspension_modes")
    for key, truth in (("radial_translation_Hz", w.f_trans), ("rocking_Hz", w.f_rock), ("axial_Hz", w.f_axial)):
        assert modes[key] == pytest.approx(truth, rel=0.02)
    assert modes["inertia_ratio"] == pytest.approx(w.inertia_ratio, rel=0.02)
    assert summary["error_after"] < 0.02 * summary["error_before"]
    # the model file (read back by rwadist's own reader) holds each 1x line once, the carrier at its own amplitude
    model = api.load_model(out / "model.json")
    for d in ("radial_force", "radial_torque"):
        ones = [x for x in model.harmonics(d) if abs(x.h - 1.0) < 0.05]
        assert len(ones) == 1
    carrier = next(x for x in model.harmonics("radial_force") if abs(x.h - 1.0) < 0.05)
    assert carrier.C == pytest.approx(w.imbalance("radial_force"), rel=0.015)
