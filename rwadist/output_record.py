"""The record of what rwadist wrote (:data:`MANIFEST`, a hidden JSON file in a folder), and the rule it serves: an
output never replaces a file rwadist did not write.

- An output folder (a report, a dataset) holds its own record, key ``files``: the files rwadist wrote in it; a folder
  holding any other file is not replaced whole (:func:`rwadist.outputs.check_output_dir`).
- An output file (a model, a PSD table, a converted sweep) is recorded in the record of the folder it is written in,
  key ``outputs``: its name with the size and modification time it had when written.  An existing file is replaced
  only when so recorded and unchanged since, or when it is a model file (``"schema": "rwadist.model"``); anything
  else -- a lab's CSV, another dataset's run or ``runs.csv``, someone's notes -- is refused, untouched
  (:func:`refuse_foreign_file`).
"""
from __future__ import annotations

import json
import os
import stat
import uuid
from pathlib import Path

from .formats.records import DataError

#: The record of what rwadist wrote in a folder: a hidden JSON file listing the files of an output folder (a report;
#: a folder whose files it does not all list is not replaced, :func:`rwadist.outputs.check_output_dir`) and the
#: output files written in that folder (:func:`record_written`).
MANIFEST = ".rwadist-files.json"
#: who wrote a record
WRITER = "rwadist"


def _version() -> str:
    """The installed rwadist's version (importlib.metadata: the package itself is not imported, no cycle)."""
    try:
        from importlib.metadata import version

        return version("rwadist")
    except Exception:   # a bare source tree, not installed
        return "unknown (not installed)"


_OWN_SIGNATURES = {".json": b'"schema": "rwadist.model"'}    # a model file: recognisable as rwadist's own


def _recorded(final: Path) -> dict | None:
    """The record (:data:`MANIFEST` of its folder, key ``outputs``) of the file ``final`` rwadist wrote as an output
    of its own: ``{"size", "mtime_ns"}`` of the file as written; None when not recorded.  A member of a folder rwadist
    wrote whole (a dataset's ``runs.csv``, listed under ``files``) is not one: another command's output never
    replaces it."""
    try:
        doc = json.loads((final.parent / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict):
        return None
    outs = doc.get("outputs")
    return outs[final.name] if isinstance(outs, dict) and isinstance(outs.get(final.name), dict) else None


def written_by_rwadist(path) -> bool:
    """True when the existing file ``path`` is one rwadist wrote and nobody changed since: recorded in its folder's
    :data:`MANIFEST` with the size and modification time it had when written, or a model file
    (``"schema": "rwadist.model"`` near its start: written by any rwadist)."""
    final = Path(path)
    rec = _recorded(final)
    if rec is not None:
        try:
            st = os.stat(final)
        except OSError:
            return False
        if rec.get("size") == st.st_size and rec.get("mtime_ns") == st.st_mtime_ns:
            return True
    sig = _OWN_SIGNATURES.get(final.suffix.lower())
    if sig is not None:
        try:
            with open(final, "rb") as f:
                return sig in f.read(4096)
        except OSError:
            return False
    return False


def refuse_foreign_file(path, flag: str = "-o", shown=None) -> None:
    """Refuse (:class:`DataError` naming ``flag``) to replace the existing regular file ``path`` unless rwadist
    wrote it (:func:`written_by_rwadist`): a lab's CSV, a dataset's run, someone's notes are never replaced."""
    final = Path(path)
    try:
        st = os.stat(final)
    except OSError:         # absent (or unreadable: refused by the caller's own checks)
        return
    if not stat.S_ISREG(st.st_mode) or written_by_rwadist(final):
        return
    raise DataError(flag, "value", f"{str(shown if shown is not None else path)!r} exists and rwadist did not write "
                    "it; it would be replaced: choose another output path, or move or delete that file yourself")


def record_written(finals: list) -> None:
    """Add the regular files ``finals`` (just written) to their folders' :data:`MANIFEST` with their size and
    modification time, so that a later run may replace them (and only while nobody changed them).  Best effort: a
    record that cannot be written only means that the next run refuses to replace the file."""
    by_folder: dict = {}
    for final in finals:
        by_folder.setdefault(final.parent, []).append(final)
    for folder, members in by_folder.items():
        record = folder / MANIFEST
        try:
            doc = json.loads(record.read_text())
        except (OSError, ValueError):
            doc = None
        if not isinstance(doc, dict):
            doc = {}
        found = doc.get("outputs")
        outs: dict = found if isinstance(found, dict) else {}
        for final in members:
            try:
                st = os.stat(final)
            except OSError:
                continue
            outs[final.name] = {"size": st.st_size, "mtime_ns": st.st_mtime_ns}
        for name in [n for n in outs if not (folder / n).is_file()]:       # files gone since: forgotten
            del outs[name]
        doc.setdefault("written_by", f"{WRITER} {_version()}")
        doc["outputs"] = outs
        doc.setdefault("note", "the files rwadist wrote in this folder; it replaces only those (while unchanged)")
        tmp = folder / f".{MANIFEST}.part-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        try:
            tmp.write_text(json.dumps(doc, indent=1) + "\n")
            os.replace(tmp, record)
        except OSError:
            tmp.unlink(missing_ok=True)
