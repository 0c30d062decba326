"""Outputs that are safe to keep: atomic files and folders, refusal to overwrite an input.

Every file the command line writes goes first to a temporary sibling (same directory, so the final
``os.replace`` is a rename on one file system) and replaces the destination only once complete: a
kill at any instant leaves either the old complete file or the new complete one, never a truncated
one.  A report folder is built in a temporary sibling folder and swapped in whole.  An interrupted
or failed write removes its temporary file; only a SIGKILL can leave one behind (a hidden
``.NAME.part-*`` sibling, never the output itself).
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os
import shutil
import uuid
from contextlib import contextmanager
from pathlib import Path

from .formats.records import DataError

#: names a reader takes from a steady-test directory besides its run files
_DATASET_INDEX_FILES = ("runs.csv", "meta.json")
#: The key of ``meta.json`` a steady-test folder rwadist writes records itself under (:func:`rwadist.data.write_steady`),
#: and its value: only such a folder is replaced whole by a new dataset; any other (a lab's measured runs) is refused
WRITER_KEY, WRITER = "written_by", "rwadist"
#: what `rwadist simulate-test OUT_DIR --sweep` writes: replaced with the folder by a later steady test there
_SIMULATE_OUTPUTS = ("sweep.csv", "sweep.meta.json")
#: extensions of files a dataset reader may read (runs, sweeps, HDF5)
_DATA_SUFFIXES = (".csv", ".h5", ".hdf5", ".uff", ".unv", ".tdms", ".mat", ".json")


def _part_name(path: Path) -> Path:
    """A hidden temporary sibling of ``path`` keeping its suffix (writers choose formats by suffix)."""
    return path.parent / f".{path.stem}.part-{os.getpid()}-{uuid.uuid4().hex[:8]}{path.suffix}"


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # some file systems do not open directories; the rename is still atomic
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _writable(directory: Path) -> bool:
    """True when a file can be created in ``directory`` (tried: permissions alone miss read-only mounts)."""
    import tempfile

    try:
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".rwadist-probe-"):
            return True
    except OSError:
        return False


def check_output_file(path, flag: str = "-o") -> Path:
    """``path`` as an output file, refused (:class:`DataError` naming ``flag``) when it is empty, a
    directory, or in a directory that cannot be created or written."""
    if path is None or str(path).strip() == "":
        raise DataError(flag, "value", "empty: give the path of the file to write")
    path = Path(path)
    if path.is_dir():
        raise DataError(flag, "value", f"{str(path)!r} is a directory: give a file name inside it, "
                        f"e.g. {str(path / ('out' + (path.suffix or '')))!r}")
    parent = path.parent
    existing = parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is a file, not a directory")
    if not _writable(existing):
        raise DataError(flag, "value", f"{str(path)!r}: the directory {str(existing)!r} is not writable")
    return path


def check_output_dir(path, flag: str = "-o") -> Path:
    """``path`` as an output folder, refused when it is empty, an existing file, or not creatable."""
    if path is None or str(path).strip() == "":
        raise DataError(flag, "value", "empty: give the path of the folder to write")
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise DataError(flag, "value", f"{str(path)!r} is a file, not a folder: give a folder path")
    existing = path if path.exists() else path.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is a file, not a folder")
    if not _writable(existing):
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is not writable")
    return path


def _is_within(child: Path, parent: Path) -> bool:
    try:
        child.relative_to(parent)
        return True
    except ValueError:
        return False


def refuse_input_overwrite(outputs, inputs) -> None:
    """Raise :class:`DataError` when an output would overwrite or delete something a command reads.

    ``outputs``: ``(flag, path, kind)`` with kind ``"file"`` or ``"dir"`` (a folder that is replaced
    whole).  ``inputs``: paths read (files or dataset folders; None entries skipped).  Refused: an
    output file equal to an input file; an output file inside an input folder that is a file a dataset
    reader reads (runs.csv, meta.json, a data file); an output folder equal to, or holding, an input or
    the working directory."""
    ins = [Path(p).resolve() for p in inputs if p is not None and str(p) != ""]
    cwd = Path.cwd().resolve()
    for flag, out, kind in outputs:
        if out is None:
            continue
        o = Path(out).resolve()
        for i in ins:
            if kind == "dir":
                if _is_within(i, o):
                    raise DataError(flag, "value", f"{str(out)!r} holds the input {str(i)!r}; its report folder "
                                    "is replaced whole, which would delete the input: choose another folder")
                continue
            if o == i:
                raise DataError(flag, "value", f"{str(out)!r} is an input of this command; writing it would "
                                "destroy the input: choose another output path")
            if i.is_dir() and _is_within(o, i) and o.exists() and (
                    o.name in _DATASET_INDEX_FILES or o.suffix.lower() in _DATA_SUFFIXES):
                raise DataError(flag, "value", f"{str(out)!r} is a file of the input dataset {str(i)!r}; "
                                "writing it would damage the dataset: choose another output path")
            if i.is_file() and o == i.with_suffix(".meta.json"):
                raise DataError(flag, "value", f"{str(out)!r} is the metadata of the input {str(i)!r}: "
                                "choose another output path")
        if kind == "dir" and _is_within(cwd, o):
            raise DataError(flag, "value", f"{str(out)!r} holds the working directory; a report folder is "
                            "replaced whole: choose a new or dedicated folder")


@contextmanager
def atomic_file(path):
    """Yield a temporary sibling path to write; on success it replaces ``path`` (atomic rename),
    on any exception (Ctrl-C included) it is removed and ``path`` is left as it was."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _part_name(path)
    try:
        yield tmp
        if not tmp.exists():
            raise FileNotFoundError(f"{tmp}: the writer produced no file")
        _fsync_file(tmp)
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    except BaseException:
        _remove(tmp)
        raise


def _remove(p: Path) -> None:
    try:
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p, ignore_errors=True)
        elif p.exists() or p.is_symlink():
            p.unlink()
    except OSError:
        pass


_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    return fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0


@contextmanager
def atomic_dir(path):
    """Yield a temporary sibling folder to fill; on success it replaces the folder ``path`` whole
    (an atomic exchange where the OS has one, else two renames), on any exception it is removed and
    ``path`` is left as it was."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.part-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    tmp.mkdir()
    try:
        yield tmp
        if path.exists():
            if _exchange(tmp, path):     # tmp now holds the old folder
                _remove(tmp)
            else:
                old = path.parent / f".{path.name}.old-{os.getpid()}-{uuid.uuid4().hex[:8]}"
                os.replace(path, old)
                os.replace(tmp, path)
                _remove(old)
        else:
            os.replace(tmp, path)
        _fsync_dir(path.parent)
    except BaseException:
        _remove(tmp)
        raise


def _listed_runs(folder: Path) -> set:
    """File names an existing ``runs.csv`` in ``folder`` lists (first column); empty when unreadable."""
    try:
        lines = (folder / "runs.csv").read_text(errors="replace").splitlines()[1:]
    except OSError:
        return set()
    return {ln.split(",")[0].strip() for ln in lines if ln.strip()}


def _is_dataset_entry(p: Path, listed: set) -> bool:
    """A file a steady-test folder holds: its index files, a run file (``run*`` or listed in
    ``runs.csv``), a sweep simulate-test wrote there, or a writer's hidden leftover temporary."""
    if p.name.startswith("."):
        return True
    if not p.is_file():
        return False
    return p.name in _DATASET_INDEX_FILES or p.name in listed or p.name in _SIMULATE_OUTPUTS or (
        p.name.lower().startswith("run") and p.suffix.lower() in _DATA_SUFFIXES)


def _written_by_rwadist(folder: Path) -> bool:
    """True when ``folder``'s ``meta.json`` records that rwadist wrote the dataset: ``written_by`` (every dataset
    :func:`rwadist.data.write_steady` writes), or the virtual stand's ``generator`` (simulate-test before that key)."""
    import json

    try:
        meta = json.loads((folder / "meta.json").read_text(errors="replace"))
    except (OSError, ValueError):
        return False
    if not isinstance(meta, dict):
        return False
    return any(isinstance(meta.get(k), str) and meta[k].split(" ")[0].split(".")[0] == WRITER
               for k in (WRITER_KEY, "generator"))


def check_dataset_dir(path, flag: str = "-o") -> Path:
    """Refuse (:class:`DataError` naming ``flag``) a folder ``path`` that exists and holds anything but a
    steady-test dataset rwadist wrote: the folder is replaced whole, so other files in it -- or a dataset rwadist
    did not write, a lab's measured runs -- would be lost."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise DataError(flag, "value", f"{str(path)!r} is a file, not a folder: give a folder for a steady test")
    if path.is_dir():
        listed = _listed_runs(path)
        entries = list(path.iterdir())
        other = sorted(p.name for p in entries if not _is_dataset_entry(p, listed))
        if other:
            shown = ", ".join(other[:3]) + (f" and {len(other) - 3} more" if len(other) > 3 else "")
            raise DataError(flag, "folder", f"{str(path)!r} holds files that are not a steady-test dataset "
                            f"({shown}); the folder is replaced whole: choose a new or dedicated folder")
        files = [p for p in entries if not p.name.startswith(".") and p.name not in _SIMULATE_OUTPUTS]
        if files and not _written_by_rwadist(path):
            raise DataError(flag, "folder", f"{str(path)!r} holds a steady-test dataset ({len(files)} files) that "
                            f"rwadist did not write (its meta.json does not say {WRITER_KEY}: {WRITER}); the folder "
                            "is replaced whole, which would delete those runs: choose a new folder (if rwadist wrote "
                            f"it, before this check existed, add \"{WRITER_KEY}\": \"{WRITER}\" to its meta.json)")
    return path


@contextmanager
def atomic_dataset_dir(path, flag: str = "-o"):
    """Yield a temporary sibling folder for a steady-test dataset (run files, ``runs.csv``,
    ``meta.json``); on success it replaces the folder ``path`` as ONE set (:func:`atomic_dir`: an
    atomic exchange, else two renames), never file by file, so a reader sees the old complete
    dataset or the new complete one, never runs of one with the index of the other.  An existing
    folder that holds anything but a dataset is refused before anything is written
    (:func:`check_dataset_dir`)."""
    path = check_dataset_dir(path, flag)
    with atomic_dir(path) as tmp:
        yield tmp


def write_file(path, writer):
    """Run ``writer(tmp)`` on a temporary sibling of ``path`` and rename it onto ``path`` when complete
    (:func:`atomic_file`); returns ``path`` (a :class:`pathlib.Path`)."""
    path = Path(path)
    with atomic_file(path) as tmp:
        writer(tmp)
    return path
