"""The imbalance is never silently absent from a diagnosed model (issue 33: nothing passed over in silence).

ROSS (benchmarks/ross_new_wheel.py; stored in tests/data/ross_family4_stand_rocking_half.json) computes family wheel 4
of benchmarks/diagnose_ross_family.py (7.53 kg, I_zz/I_rr 1.59, hard-mounted modes 280.8 / 74.5 / 239 Hz, 1000-10000
rpm) on a heavy test stand (75.3 kg per support, sprung at 37.2 Hz, half its rocking frequency): one structure whose
modes at rest are ROSS's 27.6-37.2 Hz (the stand), 100.6 Hz (the rocking, moved 35 %), 250.9 and 287.9 Hz.  The 1x lines
cross the stand's and the coupled rocking's resonances over nearly the whole speed range, and their amplitude follows
no C·Ω² (ROSS's radial force at 1x peaks near 2000 rpm and falls above it).  The starting empirical fit leaves such a
harmonic out of the model (too few measurements outside its modal ranges).  When the diagnosis cannot locate the
wheel's modes either, the model file lacks the imbalance: that was said nowhere (the suspension-modes status claimed
every line fitted as C·Ω², the residual's h = 1 ridge was called a line 'the classes could not fit').  Now each
harmonic the data show is either in the model or listed as left out, with the reason, on the console, in summary.json
and on the residual's record of its ridge.
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import ross_dataset as rd  # noqa: E402

DOC = Path(__file__).resolve().parent / "data" / "ross_family4_stand_rocking_half.json"


@pytest.mark.slow
def test_an_imbalance_the_model_lacks_is_said_on_the_console_in_the_summary_and_on_its_ridge(tmp_path):
    doc, model, summary, console = rd.diagnosed(DOC, tmp_path, 6600.0)
    status = summary["suspension_modes_status"] or {}
    left = {(x["direction"], round(x["h"], 3)) for x in status.get("left_out", [])}
    # ROSS's imbalance lines, U_s and U_d given to it: h = 1 on the radial force and the radial torque
    truth = {(ln["direction"], ln["h"]) for ln in doc["lines"] if ln["imbalance"]}
    assert truth == {("radial_force", 1.0), ("radial_torque", 1.0)}
    for direction, h in truth:
        in_model = any(abs(x["h"] - h) <= 0.005 * h for x in model["empirical"].get(direction, []))
        if in_model:
            continue
        # not in the model: listed as left out, with its reason, on the console and on the residual's ridge
        assert (direction, round(h, 3)) in left, (direction, status)
        assert f"{direction.replace('_', ' ')} h {h:.4g}" in status["text"]
        assert "left out of it" in console and "the model lacks" in console
        ridge = [u for u in summary["unexplained"] if u["signature"] == "speed_line"
                 and u["parameters"]["direction"] == direction and abs(u["h"] - h) <= 0.01]
        assert ridge, summary["unexplained"]
        assert "left out of the model" in ridge[0]["causes"][0], ridge[0]["causes"]
    # a harmonic listed as left out is one the model indeed lacks
    for direction, h in left:
        assert not any(abs(x["h"] - h) <= 0.005 * h for x in model["empirical"].get(direction, []))
    if left:
        assert status["status"] in ("not_located", "rejected")
