"""A radial channel that carries a linear copy of another channel is no distorted channel (rwadist.channel_distortion).

New-user trial nuL (session 58, an independent generator: an 8-kg wheel, bearing lines h 0.41, 3.6, 5.3 on both
radial directions, their doubles 0.82 and 7.2 on the radial force alone): Ty holding 8 % of Fx was called distorted,
44 of its 44 lines alone (Fx's doubles, copied) sitting at sums of its own lines; on two seeds of three the
correction then diverged and the command ended in an internal error (LinAlgError).  Here the family's wheels are given
that line set (their own cage and ball-pass lines, the doubles on the radial force alone) and the same crosstalk; on
the code before, wheels 0 and 7 raised LinAlgError and wheels 1, 4, 5 and 6 had Ty "corrected"."""
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

import family_effects as fe  # noqa: E402
import family_test  # noqa: E402
import family_wheel as fw  # noqa: E402
from test_channel_distortion import distorted  # noqa: E402

from rwadist import channel_distortion  # noqa: E402
from rwadist.cli import main  # noqa: E402


def doubled(wheel: fw.Wheel) -> fw.Wheel:
    """``wheel`` with the trial's line set: its imbalances, its cage and ball-pass lines on both radial directions
    (the torque's a tenth of the force's, scaled as the imbalances), their doubles on the radial force alone."""
    imb = [x for x in wheel.lines if x.name == "imbalance"]
    force = [x for x in wheel.lines if x.direction == "radial_force" and x.name in ("cage", "BPFO", "BPFI")]
    f_imb, t_imb = (next(x for x in imb if x.direction == d) for d in ("radial_force", "radial_torque"))
    twos = [dataclasses.replace(x, h=2 * x.h, C=0.4 * x.C, name="2x" + x.name) for x in force]
    torque = [dataclasses.replace(x, direction="radial_torque", C=0.1 * x.C * t_imb.C / f_imb.C) for x in force]
    return dataclasses.replace(wheel, lines=tuple(imb + force + twos + torque))


@pytest.fixture(scope="module")
def wheels():
    return fw.family()


@pytest.mark.parametrize("index", [0, 5, 7])
def test_a_copy_of_another_channel_is_left_as_it_is(wheels, index):
    test = family_test.steady_test(fw.steady(doubled(wheels[index]), seed=1, effects=[fe.Crosstalk("Fx", "Ty", 0.08)]))
    matched, alone, chance = channel_distortion._channel_matches(test, "Ty", "Tx")
    assert channel_distortion._verdict(matched, alone, chance)["distorted"]     # what the counts alone would say
    out, records = channel_distortion.corrected(test)
    assert records == [] and out is test


def test_a_distortion_beside_the_same_line_set_is_still_undone(wheels):
    """Ty's own products at 2·h sit where Fx holds lines too: no one factor of Fx's spectrum makes them."""
    test = family_test.steady_test(distorted(fw.steady(doubled(wheels[5]), seed=1), "Ty", 0.02, 0.02))
    _, records = channel_distortion.corrected(test)
    assert [r["channel"] for r in records] == ["Ty"], records
    assert records[0]["second_order"] == pytest.approx(0.02, rel=0.12)
    assert records[0]["third_order"] == pytest.approx(0.02, rel=0.12)


def test_the_command_describes_the_copy_and_no_distortion(wheels, tmp_path, capsys):
    """Family wheel 0 (the code before: exit 3, LinAlgError): the copy described, the modes kept (tests/
    test_channel_copy_lever_pair.py: a force in a moment read on the lines)."""
    data = fw.write_steady(fw.steady(doubled(wheels[0]), seed=1, effects=[fe.Crosstalk("Fx", "Ty", 0.08)]),
                           tmp_path / "data")
    assert main(["diagnose", str(data), "-o", str(tmp_path / "out")]) == 0
    console = capsys.readouterr()
    assert "not linear" not in console.out + console.err and "internal error" not in console.err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert not [r for r in summary.get("data_quality", []) if r.get("type") == "distorted"]
    (copy,) = [u for u in summary["unexplained"] if u["signature"] == "channel_copy"]
    assert (copy["parameters"]["source"], copy["parameters"]["target"]) == ("Fx", "Ty")
    assert abs(copy["parameters"]["gain"]) == pytest.approx(0.08, rel=0.02)
    assert [e["kind"] for e in summary["effects"]] == ["suspension_modes"]


def test_a_distorted_channel_copied_into_another_is_still_the_distorted_one(wheels):
    """Fx distorted, then 8 % of it in Ty: Fx's products read back from Ty would need a factor 1/0.08 (the stronger
    way round, refused) and carry Ty's own noise 12.5 times, so Fx is still called distorted and put right; Ty's
    products are Fx's, copied, and Ty is left as it is."""
    data = distorted(fw.steady(wheels[0], seed=1), "Fx", 0.02, 0.02)
    signals = data.signals.copy()
    signals[:, 4, :] += 0.08 * signals[:, 0, :]                  # Ty += 0.08·Fx, after Fx's amplifier
    test = family_test.steady_test(dataclasses.replace(data, signals=signals))
    _, records = channel_distortion.corrected(test)
    assert [r["channel"] for r in records] == ["Fx"], records
    assert records[0]["second_order"] == pytest.approx(0.02, rel=0.12)


def test_a_correction_that_diverges_is_not_applied(wheels):
    """The copy's lines taken for products anyway (the check before the correction bypassed): the law fitted to them
    diverges in its inverse; the code before raised LinAlgError there (the trial's exit 3), now no run is changed by
    a law that diverges and every sample stays finite."""
    test = family_test.steady_test(fw.steady(doubled(wheels[0]), seed=1, effects=[fe.Crosstalk("Fx", "Ty", 0.08)]))
    matched, alone, _ = channel_distortion._channel_matches(test, "Ty", "Tx")
    runs = list(test.runs)
    fixed, coef = channel_distortion._undo(runs, matched, alone, "Ty", "Tx")
    assert all(np.all(np.isfinite(r.signals["Ty"])) for r in runs)
    assert all(np.all(np.isfinite(v)) for v in coef.values()) and sorted(coef) == fixed
