"""Every column of every CSV table the commands write is defined in docs/formats.md (new-user trial 29: the report's
tables were named in the README only, ``heldout_rel`` and ``C_all_SI`` were nowhere explained, nor whether the PSD
envelope is a peak or an RMS amplitude).

The smallest real producers write the tables (the fit report, ``rwadist psd`` and ``rwadist campbell`` on a preset,
the extended report, the diagnose report), each file's header is read, and each column must
be named in the first cell of a table row of that file's own subsection of section 6 ("Report and result tables"):
a name, or a pattern such as ``data_<ch>_rms_<unit>`` whose placeholders stand for the channels, units, directions
and modes the tables use."""
from __future__ import annotations

import csv
import itertools
import re
from pathlib import Path

import numpy as np
import pytest
from cli_run import run

import rwadist
from rwadist.units import DIRECTION_CHANNELS

ROOT = Path(__file__).resolve().parents[1]
SECTION = "## 6. Report and result tables"

#: what each placeholder of a documented column pattern stands for
PLACEHOLDERS = {
    "ch": ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"),
    "a": ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"),
    "b": ("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"),
    "unit": ("N", "Nm", "N2", "N2m", "Nm2"),
    "direction": tuple(DIRECTION_CHANNELS),
    "mode": ("radial_translation", "rocking", "rocking_forward", "rocking_backward", "axial_translation"),
}


def _section_text(doc: str) -> str:
    """Section 6 of docs/formats.md, up to the next level-2 heading."""
    assert SECTION in doc, f"docs/formats.md has no section {SECTION!r}"
    return re.split(r"^## ", doc.split(SECTION, 1)[1], flags=re.M)[0]


def documented(table: str, doc: str | None = None) -> list:
    """The names (regular expressions) defined for ``table`` -- a key naming its subsection's heading, e.g.
    "`harmonics.csv`" or "`rms_vs_speed.csv` (`rwadist diagnose" -- by the backquoted names in the first cell of
    the table rows of that subsection."""
    text = _section_text(doc if doc is not None else (ROOT / "docs" / "formats.md").read_text())
    parts = [p for p in re.split(r"^### ", text, flags=re.M)[1:] if p.splitlines()[0].startswith(table)]
    assert len(parts) == 1, f"docs/formats.md section 6: {len(parts)} subsections headed {table!r}, expected 1"
    names = []
    for line in parts[0].splitlines():
        if not line.startswith("| `"):
            continue
        first = line.split("|")[1]
        for name in re.findall(r"`([^`]+)`", first):
            pattern = re.sub(r"<(\w+)>", lambda m: "(" + "|".join(PLACEHOLDERS[m.group(1)]) + ")",
                             re.escape(name).replace(r"\<", "<").replace(r"\>", ">"))
            names.append(pattern)
    assert names, f"docs/formats.md: the subsection {table!r} defines no column"
    return names


def undocumented(table: str, columns, doc: str | None = None) -> list:
    names = documented(table, doc)
    return [c for c in columns if not any(re.fullmatch(n, c) for n in names)]


def header(path: Path) -> list:
    with open(path, newline="") as fh:
        return next(csv.reader(fh))


def first_column(path: Path) -> list:
    with open(path, newline="") as fh:
        return [row[0] for row in itertools.islice(csv.reader(fh), 1, None)]


@pytest.fixture(scope="module")
def small_fit():
    """The smallest test the fits run on (6 speeds, 1024 samples: two lines, every table written)."""
    test = rwadist.simulate_test("ithaco-e", speeds_rpm=np.linspace(600, 2400, 6), n_samples=1024, seed=1)
    return test, rwadist.fit(test)


def test_the_fit_reports_tables_are_documented(small_fit, tmp_path):
    from rwadist.report import write_report

    write_report(small_fit[1], tmp_path)
    written = sorted(p.name for p in tmp_path.glob("*.csv"))
    assert written == ["bins.csv", "excluded_ranges.csv", "harmonics.csv", "rms_vs_speed.csv"], written
    missing = {name: undocumented(f"`{name}` (`rwadist fit` report", header(tmp_path / name)) for name in written}
    assert not any(missing.values()), f"columns not defined in docs/formats.md section 6: {missing}"


def test_the_psd_and_campbell_tables_are_documented(capsys, tmp_path):
    out = tmp_path / "psd.csv"
    code, _, err = run(capsys, "psd", "--preset", "ithaco-e", "--empirical", "--speed-rpm", "600:2400",
                       "--n-freq", "257", "-o", out)
    assert code == 0, err
    code, _, err = run(capsys, "campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:500",
                       "-o", tmp_path / "campbell.csv")
    assert code == 0, err
    written = sorted(p.name for p in tmp_path.glob("*.csv"))
    assert written == ["campbell.csv", "psd.csv", "psd_cross.csv", "psd_envelope.csv", "psd_envelope_harmonics.csv"], \
        written
    missing = {name: undocumented(f"`{name}`", header(tmp_path / name)) for name in written}
    assert not any(missing.values()), f"columns not defined in docs/formats.md section 6: {missing}"


def test_a_column_left_undocumented_is_caught():
    """The check reads the table's own subsection: a column defined only in another table's fails."""
    doc = (ROOT / "docs" / "formats.md").read_text()
    cols = ["direction", "h", "C_SI", "C_stderr_SI", "C_all_SI", "n_points", "presence", "in_model", "heldout_rel"]
    assert undocumented("`harmonics.csv`", cols, doc) == []
    cut = re.sub(r"^\| `heldout_rel` \|.*\n", "", doc, flags=re.M)
    assert cut != doc
    assert undocumented("`harmonics.csv`", cols, cut) == ["heldout_rel"]
    assert undocumented("`bins.csv`", ["reason", "heldout_rel"], doc) == ["heldout_rel"]
    assert undocumented("`rms_vs_speed.csv` (`rwadist fit`", ["ratio_Fx", "ratio_Fq", "model_before_Fx_rms_N"],
                        doc) == ["ratio_Fq", "model_before_Fx_rms_N"]


def test_the_extended_reports_tables_are_documented(small_fit, tmp_path):
    """fit --extended's tables, and the parameter names that are the rows of extended_params.csv."""
    from rwadist.report_extended import write_extended_report

    test, fit = small_fit
    efit, model = rwadist.fit_extended(test, fit)
    write_extended_report(efit, fit, tmp_path, model=model)
    assert sorted(p.name for p in tmp_path.glob("*.csv")) == ["extended_params.csv", "extended_rms_vs_speed.csv"]
    missing = {
        "extended_rms_vs_speed.csv": undocumented("`extended_rms_vs_speed.csv`",
                                                  header(tmp_path / "extended_rms_vs_speed.csv")),
        "extended_params.csv": undocumented("`extended_params.csv`", header(tmp_path / "extended_params.csv")),
        "extended_params.csv rows": undocumented("`extended_params.csv`",
                                                 first_column(tmp_path / "extended_params.csv")),
    }
    assert not any(missing.values()), f"columns not defined in docs/formats.md section 6: {missing}"


def test_the_diagnose_reports_tables_are_documented(small_fit, tmp_path):
    """The tables of ``rwadist diagnose -o DIR`` (its report writer)."""
    from rwadist.diagnose import write_report

    test, fit = small_fit
    write_report(rwadist.diagnose(test, fit.model), tmp_path)
    assert sorted(p.name for p in tmp_path.glob("*.csv")) == ["hypotheses.csv", "rms_vs_speed.csv"]
    missing = {
        "rms_vs_speed.csv": undocumented("`rms_vs_speed.csv` (`rwadist diagnose", header(tmp_path / "rms_vs_speed.csv")),
        "hypotheses.csv": undocumented("`hypotheses.csv`", header(tmp_path / "hypotheses.csv")),
    }
    assert not any(missing.values()), f"columns not defined in docs/formats.md section 6: {missing}"
    # as every table: booleans true/false, a missing value an empty cell (docs review: True/False, nan)
    with open(tmp_path / "hypotheses.csv", newline="") as fh:
        assert {r["passed"] for r in csv.DictReader(fh)} <= {"true", "false"}
    for name in ("hypotheses.csv", "rms_vs_speed.csv"):
        assert "nan" not in (tmp_path / name).read_text().lower(), name
