"""The internal errors of issue 36's audit, each now one clear line (exit 2) naming what to do: `fmu build` without
the [fmu] extra said "internal error ... please report it"; a report folder of an older rwadist is named as such."""
from __future__ import annotations

import sys

from rwadist.cli import main


def test_a_missing_optional_package_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pythonfmu", None)     # import pythonfmu: ModuleNotFoundError, as uninstalled
    code = main(["fmu", "build", "--preset", "ithaco-e", "-o", str(tmp_path / "w.fmu")])
    err = capsys.readouterr().err
    assert code == 2 and "internal error" not in err and "pip install 'rwadist[fmu]'" in err and "pythonfmu" in err
    assert not (tmp_path / "w.fmu").exists()


def test_an_old_report_without_the_record_is_named(tmp_path, capsys):
    ds = tmp_path / "ds"
    assert main(["simulate-test", str(ds), "--preset", "ithaco-e", "--speeds-rpm", "600,1200,1800",
                 "--samples", "1024"]) == 0
    old = tmp_path / "m_report"
    old.mkdir()
    for name in ("summary.md", "harmonics.csv", "waterfall_Fx.png"):
        (old / name).write_text("an older rwadist's report\n")
    assert main(["fit", str(ds), "-o", str(tmp_path / "m.json")]) == 2
    err = capsys.readouterr().err
    assert "older rwadist" in err and "delete it" in err
    assert sorted(p.name for p in old.iterdir()) == ["harmonics.csv", "summary.md", "waterfall_Fx.png"]
