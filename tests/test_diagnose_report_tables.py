"""The tables of ``rwadist diagnose -o DIR`` are written as every other table (docs/formats.md section 6): through the
csv module, booleans ``true``/``false``, a value that could not be computed as an empty cell (docs review: hypotheses.csv
was joined by hand with Python's ``True``/``False``, rms_vs_speed.csv written by ``np.savetxt``, a NaN as ``nan``)."""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass

import numpy as np

from rwadist.diagnose.report import HYPOTHESES_COLUMNS, hypotheses_csv, write_rms_csv
from rwadist.diagnose.search import Hypothesis
from rwadist.text_table import cell


@dataclass(eq=False)
class _Effect:
    kind: str
    channels: tuple
    law: str

    def params(self) -> dict:
        return {"law": self.law, "exponent": 2.5, "knots_Hz": [1.0, 2.0]}


def _read(text: str) -> list:
    return list(csv.reader(io.StringIO(text)))


def test_hypotheses_read_back_by_the_csv_module_with_true_false():
    """A law's text holding commas stays in one cell (quoted, as written); passed is true/false; a NaN gain empty."""
    law = "psd_ref(f) * (|omega|/omega_ref)^exponent, linear between knots, 0 outside"
    hyps = [Hypothesis(_Effect("broadband_floor", ("Fx", "Fy"), law), 0.125, 0.5, 11.0, True, 1),
            Hypothesis(_Effect("amplitude_law", ("Tz",), "a; b"), float("nan"), float("nan"), -0.61744, False, 2)]
    rows = _read(hypotheses_csv(hyps))
    assert rows[0] == HYPOTHESES_COLUMNS
    assert [len(r) for r in rows] == [len(HYPOTHESES_COLUMNS)] * 3
    first, second = (dict(zip(rows[0], r)) for r in rows[1:])
    assert first["parameters"].split(";") == [f"law={law}", "exponent=2.5", "knots_Hz=[1 2]"]
    assert (first["iteration"], first["kind"], first["channels"]) == ("1", "broadband_floor", "Fx Fy")
    assert (first["heldout_gain"], first["heldout_gain_fraction"], first["t"]) == ("0.125", "0.5", "11")
    assert [first["passed"], second["passed"]] == ["true", "false"]
    assert second["heldout_gain"] == second["heldout_gain_fraction"] == "" and second["t"] == "-0.6174"
    assert second["parameters"].startswith("law=a  b;")
    assert "True" not in hypotheses_csv(hyps) and "nan" not in hypotheses_csv(hyps)


def test_rms_vs_speed_writes_a_missing_value_as_an_empty_cell(tmp_path):
    """No ``nan`` text: the cell is empty, as in the fit report's tables; the numbers keep 8 significant digits."""
    cols = {"speed_rpm": np.array([-600.0, 1200.0]), "data_Fx_rms_N": np.array([0.0123456789, np.nan]),
            "model_before_Fx_rms_N": np.array([np.inf, 2.0])}
    path = write_rms_csv(tmp_path / "rms_vs_speed.csv", cols)
    text = path.read_text()
    assert "nan" not in text.lower() and "inf" not in text.lower()
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows == [list(cols), ["-600", "0.012345679", ""], ["1200", "", "2"]]


def test_one_cell_format():
    assert [cell(True), cell(np.bool_(False)), cell(np.int64(3)), cell(0.1), cell(np.float64(-2.5e-7), 3),
            cell(float("nan")), cell(-np.inf), cell(None), cell("a,b")] == \
        ["true", "false", "3", "0.1", "-2.5e-07", "", "", "", "a,b"]


def test_a_mapping_parameter_reads_to_its_precision_not_as_pythons_repr():
    """A mode's ζ interval (a mapping of lists) in report.md's parameters: its numbers to the report's precision, no
    commas (hypotheses.csv shares the format), not "{'radial_translation': [0.019994940519915492, ...]}" (a new user's
    design-review reading)."""
    from rwadist.diagnose.report import _fmt

    got = _fmt({"radial_translation": [0.019994940519915492, 0.02171], "rocking": None}, ".5g")
    assert got == "{radial_translation: [0.019995 0.02171] rocking: none}"
    assert "," not in got and "'" not in got
