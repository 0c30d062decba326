"""Every dataset ``rwadist simulate-test`` writes holds rwadist's record of its files (``.rwadist-files.json``,
:data:`rwadist.outputs.MANIFEST`); ``fit``/``diagnose`` then printed ``note: 1 file(s) in DIR not listed in runs.csv,
not read: .rwadist-files.json``.  That bookkeeping file is no run left out; a user's stray file still is named."""
from __future__ import annotations

import shutil

import rwadist
from rwadist.cli import main
from rwadist.outputs import MANIFEST


def _dataset(tmp_path):
    path = tmp_path / "w"
    assert main(["simulate-test", str(path), "--preset", "ithaco-e", "--speeds-rpm", "600:3000", "--n-speeds", "6",
                 "--samples", "1024"]) == 0
    assert (path / MANIFEST).is_file()
    return path


def test_rwadist_s_own_file_record_is_not_an_unlisted_file(tmp_path, capsys):
    path = _dataset(tmp_path)
    capsys.readouterr()
    assert main(["fit", str(path), "-o", str(tmp_path / "m.json"), "--no-report"]) == 0
    err = capsys.readouterr().err
    assert "not listed in runs.csv" not in err
    assert MANIFEST not in err
    assert "unlisted_files" not in rwadist.read(path).meta


def test_a_stray_file_is_still_named(tmp_path):
    path = _dataset(tmp_path)
    shutil.copy(path / "run_0000.csv", path / "extra.csv")
    assert rwadist.read(path).meta["unlisted_files"] == ["extra.csv"]
