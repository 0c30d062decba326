"""User-facing messages (issue 17 item 5): `--version`, an elapsed-time line while a stage of unknown
length runs, units in printed numbers."""
from __future__ import annotations

import time
from importlib.metadata import version

import pytest

from rwadist import progress
from rwadist.cli import main
from rwadist.progress import working


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"rwadist {version('rwadist')}"


def test_working_line_ticks_while_the_stage_runs(capsys, monkeypatch):
    # stderr captured is no terminal: the progress is written as lines, here one per 0.2 s at most
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.2)
    with working("searching", interval_s=0.2):
        time.sleep(1.3)
    err = capsys.readouterr().err
    assert err.count("searching: 00:01 elapsed") >= 1 and err.count("searching:") >= 4
    with working("quiet", enabled=False):
        pass
    assert "quiet" not in capsys.readouterr().err


def test_psd_prints_rms_with_units(tmp_path, capsys):
    out = tmp_path / "p.csv"
    assert main(["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-freq", "2001",
                 "--n-speeds", "200", "-o", str(out)]) == 0
    rms = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("RMS: ")][0]
    assert "Fx " in rms and rms.count(" N,") >= 2 and rms.rstrip().endswith("N·m")
