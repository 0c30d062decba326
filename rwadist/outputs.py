"""Outputs that are safe to keep: atomic files, folders and sets of them; nothing an output replaces is lost.

- A file is written to a hidden temporary sibling (same folder, so the final ``os.replace`` is a rename on one
  file system) and replaces the destination only once complete: a kill at any instant leaves the old complete
  file or the new complete one, never a truncated one.
- A folder (a report) is built in a hidden temporary sibling folder and swapped in whole.  A folder that exists
  is replaced only when rwadist wrote everything in it (its record :data:`MANIFEST` lists its files); one that
  holds anything else -- a reviewer's notes, a lab's runs -- is refused before any work (:func:`check_output_dir`).
- A set of outputs (``psd``'s table, cross-spectra, envelope and plot; ``fit``'s model and report) is swapped in
  as a set (:func:`output_set`): every member is complete in its temporary before the first is moved; then the old
  members are moved aside and the new ones moved in, a few renames with Ctrl-C held back, so a reader never finds
  members of two runs side by side (a SIGKILL inside those microseconds leaves some members absent, never mixed).
- An output that is not a regular file is never replaced by one: a character device or a FIFO (``-o /dev/null``,
  a pipe) is written into once the content is complete; a block device or a socket is refused.  A symbolic link
  is followed: its target is replaced.
- A failure (disk full, Ctrl-C) removes every temporary and leaves the old outputs; only a SIGKILL (or a crash)
  can leave a hidden ``.NAME.part-PID-*`` sibling, and the next write of that output removes those of processes
  that no longer run.

Ctrl-C in the command line (:func:`exit_on_interrupt`): one line, exit 130, temporaries removed, at any moment.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import errno
import json
import os
import re
import shutil
import signal
import stat
import sys
import tempfile
import threading
import uuid
from contextlib import contextmanager
from pathlib import Path

from .formats.records import DataError
from .output_record import MANIFEST, _version, record_written, refuse_foreign_file, written_by_rwadist

#: names a reader takes from a steady-test directory besides its run files
_DATASET_INDEX_FILES = ("runs.csv", "meta.json")
#: The key of ``meta.json`` a steady-test folder rwadist writes records itself under (:func:`rwadist.data.write_steady`),
#: and its value: only such a folder is replaced whole by a new dataset; any other (a lab's measured runs) is refused
WRITER_KEY, WRITER = "written_by", "rwadist"
#: what `rwadist simulate-test OUT_DIR --sweep` writes: replaced with the folder by a later steady test there
_SIMULATE_OUTPUTS = ("sweep.csv", "sweep.meta.json")
#: extensions of files a dataset reader may read (runs, sweeps, HDF5)
_DATA_SUFFIXES = (".csv", ".h5", ".hdf5", ".uff", ".unv", ".tdms", ".mat", ".json")
#: files an operating system's file browser leaves in any folder it shows: not the user's work
_BROWSER_LITTER = frozenset({".DS_Store", "Thumbs.db", "desktop.ini"})

#: temporaries being written (path -> None, in order): removed by the command line's Ctrl-C handler
_LIVE: dict = {}
#: outputs this process completed, in order (named by the Ctrl-C message)
_WRITTEN: list = []


# --------------------------------------------------------------------------- what an output path is

def _target(path: Path, flag: str) -> Path:
    """The path to replace for ``path``: a symbolic link's final target (the link itself is kept); a loop or a
    dangling chain of links is refused naming ``flag``."""
    if not path.is_symlink():
        return path
    try:
        target = Path(os.path.realpath(path, strict=True))
    except FileNotFoundError:       # a dangling link: its target is created
        target = Path(os.path.realpath(path))
    except (OSError, RuntimeError) as exc:
        raise DataError(flag, "value", f"{str(path)!r} is a symbolic link that cannot be followed ({exc.__class__.__name__}: "
                        "a loop?): give a file path") from None
    if target.is_symlink():         # realpath gave up (a loop): Path.is_symlink still sees a link
        raise DataError(flag, "value", f"{str(path)!r} is a loop of symbolic links: give a file path")
    return target


def _stat(path: Path, flag: str | None = None):
    """``os.stat(path)``, None when it does not exist; any other failure (ELOOP, EACCES on a parent, a name too
    long, a parent that is a file) is a :class:`DataError` naming ``flag`` (the option that gave the path)."""
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None
    except OSError as exc:
        why = exc.strerror or str(exc)
        if exc.errno == errno.ENOTDIR:
            why += " (a folder on the way to it is a file)"
        if flag is None:
            raise DataError(str(path), "path", why) from None
        raise DataError(flag, "value", f"{str(path)!r}: {why}: give a path in a folder you can write") from None


def is_special(path) -> bool:
    """True when ``path`` exists and is neither a regular file nor a folder (a device, a FIFO, a socket)."""
    st = _stat(Path(path))
    return st is not None and not (stat.S_ISREG(st.st_mode) or stat.S_ISDIR(st.st_mode))


def _check_special(path: Path, flag: str) -> None:
    """A non-regular output: a character device or a FIFO is written into (if writable); anything else refused."""
    mode = os.stat(path).st_mode
    if stat.S_ISBLK(mode):
        raise DataError(flag, "value", f"{str(path)!r} is a block device (a disk): rwadist does not write to disks; "
                        "give a file path")
    if stat.S_ISSOCK(mode):
        raise DataError(flag, "value", f"{str(path)!r} is a socket: give a file path")
    if not os.access(path, os.W_OK):
        raise DataError(flag, "value", f"{str(path)!r} is not writable")


def _writable(directory: Path) -> bool:
    """True when a file can be created in ``directory`` (tried: permissions alone miss read-only mounts)."""
    try:
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".rwadist-probe-"):
            return True
    except OSError:
        return False


def check_output_file(path, flag: str = "-o") -> Path:
    """``path`` as an output file, refused (:class:`DataError` naming ``flag``) when it is empty, a folder, a
    block device or socket, a loop of links, in a folder that cannot be created or written, or an existing file
    rwadist did not write (:func:`refuse_foreign_file`).  A character device or a FIFO is accepted (written into,
    never replaced)."""
    if path is None or str(path).strip() == "":
        raise DataError(flag, "value", "empty: give the path of the file to write")
    path = Path(path)
    target = _target(path, flag)
    st = _stat(target, flag)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise DataError(flag, "value", f"{str(path)!r} is a directory: give a file name inside it, "
                        f"e.g. {str(path / ('out' + (path.suffix or '')))!r}")
    if st is not None and not stat.S_ISREG(st.st_mode):
        _check_special(target, flag)
        return path
    if st is not None:
        refuse_foreign_file(target, flag, path)
    existing = target.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is a file, not a directory")
    if not _writable(existing):
        raise DataError(flag, "value", f"{str(path)!r}: the directory {str(existing)!r} is not writable")
    return path


def check_model_file(path, flag: str = "-o") -> Path:
    """``path`` as a model file to write (:func:`check_output_file`); a path ending in the extension of a data format
    rwadist reads (``.csv``, ``.h5``, ...) is refused: a model file is a JSON document (docs/formats.md, section 4),
    and such a path is most likely a slip onto a measurement."""
    suffix = Path(str(path)).suffix.lower() if path is not None else ""
    if suffix != ".json" and suffix in _DATA_SUFFIXES:
        raise DataError(flag, "value", f"{str(path)!r}: a model file is a JSON document, not a {suffix} file: "
                        "give a path ending in .json")
    return check_output_file(path, flag)


def refuse_special_base(path, flag: str, companions: str, remedy: str = "give a file path in a folder") -> None:
    """Refuse an output ``path`` that is a device or FIFO when the command also writes files named after it
    (``companions``: what, e.g. "its report folder null_report"): those would land beside the device."""
    if path is not None and is_special(_target(Path(path), flag)):
        raise DataError(flag, "value", f"{str(path)!r} is not a regular file (a device or a pipe), and this command "
                        f"also writes {companions} named after it: {remedy}")


def _manifest_files(folder: Path) -> set | None:
    """The file names :data:`MANIFEST` of ``folder`` lists (relative paths), or None without a readable one."""
    try:
        doc = json.loads((folder / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    files = doc.get("files") if isinstance(doc, dict) else None
    return {f for f in files if isinstance(f, str)} if isinstance(files, list) else None


def foreign_files(folder) -> list:
    """Entries of an existing output ``folder`` rwadist did not write (not listed in its :data:`MANIFEST`), sorted;
    every entry when it has no manifest.  File-browser litter (``.DS_Store``) does not count."""
    folder = Path(folder)
    listed = _manifest_files(folder) or set()
    out = []
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if rel == MANIFEST or p.name in _BROWSER_LITTER:
            continue
        if p.is_dir() and not p.is_symlink():
            if not any(f.startswith(rel + "/") for f in listed):
                out.append(rel + "/")
        elif rel not in listed:
            out.append(rel)
    return out


def check_output_dir(path, flag: str = "-o") -> Path:
    """``path`` as an output folder replaced whole, refused when it is empty, an existing file, not creatable, or a
    folder holding files rwadist did not write (a reviewer's notes beside a report: they would be deleted)."""
    if path is None or str(path).strip() == "":
        raise DataError(flag, "value", "empty: give the path of the folder to write")
    path = _target(Path(path), flag)
    if path.exists() and not path.is_dir():
        raise DataError(flag, "value", f"{str(path)!r} is not a folder: give a folder path")
    existing = path if path.exists() else path.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is a file, not a folder")
    if not _writable(existing):
        raise DataError(flag, "value", f"{str(path)!r}: {str(existing)!r} is not writable")
    if path.is_dir() and (other := foreign_files(path)):
        shown = ", ".join(other[:3]) + (f" and {len(other) - 3} more" if len(other) > 3 else "")
        older = ("; if it is a report of an older rwadist (before the record of what it wrote, " + MANIFEST + "), "
                 "delete it" if not (path / MANIFEST).exists() and any(n in ("summary.md", "report.md") for n in other)
                 else "")
        raise DataError(flag, "folder", f"{str(path)!r} holds files rwadist did not write ({shown}); the folder is "
                        f"replaced whole, which would delete them: move them out, or choose a new folder{older}")
    return path


def _is_within(child: Path, parent: Path) -> bool:
    try:
        child.relative_to(parent)
        return True
    except ValueError:
        return False


def _resolved(p, flag: str | None = None) -> Path:
    """``p`` resolved; a loop of symbolic links refused naming ``flag`` (an output) or the path (an input)."""
    try:
        return Path(p).resolve()
    except (OSError, RuntimeError):     # a loop of symbolic links (RuntimeError before Python 3.13)
        if flag is None:
            raise DataError(p, "path", "is a loop of symbolic links: give a real path") from None
        raise DataError(flag, "value", f"{str(p)!r} is a loop of symbolic links: give a real path") from None


def refuse_input_overwrite(outputs, inputs) -> None:
    """Raise :class:`DataError` when an output would overwrite or delete something a command reads.

    ``outputs``: ``(flag, path, kind)`` with kind ``"file"`` or ``"dir"`` (a folder that is replaced
    whole).  ``inputs``: paths read (files or dataset folders; None entries skipped).  Refused: an
    output file equal to an input file; an output file inside an input folder that is a file a dataset
    reader reads (runs.csv, meta.json, a data file); an output folder equal to, or holding, an input or
    the working directory."""
    ins = [_resolved(p) for p in inputs if p is not None and str(p) != ""]
    cwd = Path.cwd().resolve()
    for flag, out, kind in outputs:
        if out is None:
            continue
        o = _resolved(out, flag)
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


# --------------------------------------------------------------------------- temporaries

_STALE = re.compile(r"^\.(?P<base>.+)\.(?:part|old)-(?P<pid>\d+)-[0-9a-f]{8}")


def _token() -> str:
    return f"{os.getpid()}-{uuid.uuid4().hex[:8]}"


def _part_name(path: Path) -> Path:
    """A hidden temporary sibling of ``path`` keeping its suffix (writers choose formats by suffix)."""
    return path.parent / f".{path.stem}.part-{_token()}{path.suffix}"


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:         # another user's process: alive
        return True
    return True


def remove_stale_temporaries(path) -> list[str]:
    """Remove the hidden temporaries (``.NAME.part-PID-*``, ``.NAME.old-PID-*``) a killed earlier write of ``path``
    left beside it -- those of processes no longer running; returns their names."""
    path = Path(path)
    gone: list[str] = []
    try:
        entries = list(path.parent.iterdir())
    except OSError:
        return gone
    for p in entries:
        m = _STALE.match(p.name)
        if m and m["base"] in (path.stem, path.name) and int(m["pid"]) != os.getpid() and not _pid_alive(int(m["pid"])):
            _remove(p)
            gone.append(p.name)
    return gone


def _remove(p: Path) -> None:
    try:
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p, ignore_errors=True)
        elif p.exists() or p.is_symlink():
            p.unlink()
    except OSError:
        pass


def _remove_temporary(tmp: Path) -> None:
    """Remove the temporary ``tmp`` and the companions its writer made beside it under its unique name: a writer's
    own temporary (``.w.part-PID-x.fmu.tmp``, the FMU zip written before its rename) or sidecar
    (``.s.part-PID-x.meta.json``) -- after a Ctrl-C, none is left."""
    _remove(tmp)
    name, suffix = tmp.name, tmp.suffix
    base = name[:-len(suffix)] if suffix and ".part-" in name[:-len(suffix)] else name
    try:
        entries = list(tmp.parent.iterdir())
    except OSError:
        return
    for q in entries:
        if q.name != name and q.name.startswith(base + "."):
            _remove(q)


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


def _write_into(tmp: Path, device: Path) -> None:
    """Copy the complete temporary ``tmp`` into the character device or FIFO ``device`` (opened for writing without
    truncation or creation; a FIFO waits for its reader)."""
    fd = os.open(device, os.O_WRONLY | getattr(os, "O_NOCTTY", 0))
    try:
        with open(tmp, "rb") as src:
            while chunk := src.read(1 << 20):
                view = memoryview(chunk)
                while view:
                    view = view[os.write(fd, view):]
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror, str(device)) from None
    finally:
        os.close(fd)


@contextmanager
def _signals_held():
    """Ctrl-C (SIGINT) and SIGTERM held back over a few renames: the handler runs after them (main thread only;
    elsewhere Python delivers no signal)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list = []
    held = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        old = signal.getsignal(sig)
        if old is None or old == signal.SIG_IGN:
            continue
        held[sig] = old
        signal.signal(sig, lambda signum, frame: pending.append((signum, frame)))
    try:
        yield
    finally:
        for sig, old in held.items():
            signal.signal(sig, old)
        for signum, frame in pending[:1]:
            old = held[signum]
            if callable(old):
                old(signum, frame)
            else:       # SIG_DFL: the default action, now that the renames are done
                os.kill(os.getpid(), signum)


# --------------------------------------------------------------------------- sets of outputs

class OutputSet:
    """Outputs replaced together (:func:`output_set`): declare each member, write its temporary, and the set is
    committed when the block ends without an error."""

    def __init__(self) -> None:
        self.members: list[tuple[Path, Path, str]] = []     # (final, temporary, kind: "file" | "dir" | "device")
        self.stale: list = []       # finals to remove with the commit (a companion this run does not write)

    def file(self, path, flag: str = "-o") -> Path:
        """A temporary path to write for the output file ``path`` (its suffix kept)."""
        final = _target(Path(path), flag)
        if final.is_dir():
            raise DataError(flag, "value", f"{path}: is a folder: give the path of a file to write")
        if is_special(final):
            _check_special(final, flag)
            tmp = Path(tempfile.gettempdir()) / f".rwadist.part-{_token()}{final.suffix}"
            kind = "device"
        else:
            refuse_foreign_file(final, flag, path)
            final.parent.mkdir(parents=True, exist_ok=True)
            remove_stale_temporaries(final)
            tmp = _part_name(final)
            kind = "file"
        _LIVE[tmp] = None
        self.members.append((final, tmp, kind))
        return tmp

    def folder(self, path) -> Path:
        """A temporary folder to fill for the output folder ``path`` (replaced whole; :data:`MANIFEST` added)."""
        final = _target(Path(path), "-o")
        final.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(final)
        tmp = final.parent / f".{final.name}.part-{_token()}"
        _LIVE[tmp] = None           # before it exists: a Ctrl-C between the two left the folder behind
        tmp.mkdir()
        self.members.append((final, tmp, "dir"))
        return tmp

    def remove(self, path) -> None:
        """An output of an earlier run this run does not write (a companion file): removed with the commit, so that
        no member of an earlier set stays beside the new one."""
        final = Path(path)
        if final.exists() and final.is_file() and all(final != m[0] for m in self.members) and \
                written_by_rwadist(final):      # a file rwadist did not write is not an earlier member: kept
            self.stale.append(final)

    def discard(self) -> None:
        for _, tmp, _ in self.members:
            _remove_temporary(tmp)
            _LIVE.pop(tmp, None)

    def commit(self) -> None:
        for final, tmp, kind in self.members:
            if kind == "dir":
                _write_manifest(tmp)
            elif not tmp.exists():
                raise FileNotFoundError(f"{tmp}: the writer produced no file")
            else:
                _fsync_file(tmp)
        for final, tmp, kind in self.members:       # outside the held signals: a FIFO may wait for its reader
            if kind == "device":
                _write_into(tmp, final)
        regular = [m for m in self.members if m[2] != "device"]
        with _signals_held():
            if len(regular) == 1 and not self.stale:
                _replace_one(*regular[0])
            else:
                for old in _replace_set(regular, self.stale):
                    _remove(old)
            for final, tmp, kind in self.members:
                if kind == "device":
                    _remove(tmp)
                _LIVE.pop(tmp, None)
            _WRITTEN.extend(m[0] for m in self.members)
            record_written([final for final, _, kind in self.members if kind == "file"])   # before a held Ctrl-C


def _write_manifest(folder: Path) -> None:
    files = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() and p.name != MANIFEST)
    doc = {"written_by": f"{WRITER} {_version()}", "files": files,
           "note": "the files rwadist wrote in this folder; it replaces the folder whole only when it holds no other"}
    (folder / MANIFEST).write_text(json.dumps(doc, indent=1) + "\n")


def _replace_one(final: Path, tmp: Path, kind: str) -> None:
    if kind == "file":
        os.replace(tmp, final)
    elif final.exists() and _exchange(tmp, final):      # tmp now holds the old folder
        _remove(tmp)
    elif final.exists():
        old = final.parent / f".{final.name}.old-{_token()}"
        os.replace(final, old)
        os.replace(tmp, final)
        _remove(old)
    else:
        os.replace(tmp, final)
    _fsync_dir(final.parent)


def _replace_set(members: list, stale: list) -> list:
    """Move every existing member (and the ``stale`` ones) aside, then every new one in; on a failure, undo.  A reader
    sees the old set, a part of the old one or a part of the new one, never members of both.  Returns the paths
    the old members were moved to (removed by the caller)."""
    aside: list = []
    placed: list = []
    try:
        for final in [m[0] for m in members] + stale:
            if final.exists() or final.is_symlink():
                old = final.parent / f".{final.name}.old-{_token()}"
                os.rename(final, old)
                aside.append((final, old))
        for final, tmp, _ in members:
            os.rename(tmp, final)
            placed.append((final, tmp))
    except BaseException:
        for final, tmp in reversed(placed):
            os.rename(final, tmp)
        for final, old in reversed(aside):
            os.rename(old, final)
        raise
    for parent in {m[0].parent for m in members}:
        _fsync_dir(parent)
    return [old for _, old in aside]


def _output_of(filename, members: list) -> str | None:
    """The output a failed write of ``filename`` (a member's temporary, a file in a temporary folder, or None: all of
    them) belongs to, named as the user gave it; None for a file that is none of them."""
    if filename is None:
        return ", ".join(str(f) for f, _, _ in members) or None
    name = Path(os.fsdecode(filename))
    for final, tmp, _ in members:
        if name == tmp:
            return str(final)
        if _is_within(name, tmp):
            return str(final / name.relative_to(tmp))
    return None


@contextmanager
def output_set():
    """Yield an :class:`OutputSet`; when the block ends, every member declared in it replaces its output together
    (see the module docstring); on any exception (Ctrl-C included) every temporary is removed and the outputs are
    left as they were."""
    s = OutputSet()
    try:
        yield s
        s.commit()
    except OSError as exc:      # named by the output the user gave, not by a hidden temporary
        s.discard()
        named = _output_of(exc.filename, s.members)
        if named is None or exc.errno is None:
            raise
        raise OSError(exc.errno, exc.strerror, named) from None
    except BaseException:
        s.discard()
        raise


@contextmanager
def atomic_file(path, flag: str = "-o"):
    """Yield a temporary path to write; on success it replaces ``path`` (atomic rename; a device or FIFO is written
    into), on any exception (Ctrl-C included) it is removed and ``path`` is left as it was."""
    with output_set() as s:
        yield s.file(path, flag)


@contextmanager
def atomic_dir(path):
    """Yield a temporary sibling folder to fill; on success it replaces the folder ``path`` whole
    (an atomic exchange where the OS has one, else two renames), on any exception it is removed and
    ``path`` is left as it was."""
    with output_set() as s:
        yield s.folder(path)


def write_file(path, writer, flag: str = "-o"):
    """Run ``writer(tmp)`` on a temporary sibling of ``path`` and rename it onto ``path`` when complete
    (:func:`atomic_file`; a refusal names ``flag``); returns ``path`` (a :class:`pathlib.Path`)."""
    path = Path(path)
    with atomic_file(path, flag) as tmp:
        writer(tmp)
    return path


# --------------------------------------------------------------------------- steady-test folders

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
    path = _target(Path(path), flag)
    if path.exists() and not path.is_dir():
        raise DataError(flag, "value", f"{str(path)!r} is not a folder: give a folder for a steady test")
    if path.is_dir():
        listed = _listed_runs(path) | (_manifest_files(path) or set())
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


# --------------------------------------------------------------------------- Ctrl-C in the command line

def interrupt_message(command: str, signum: int = signal.SIGINT) -> str:
    """The one line a command prints when Ctrl-C (or SIGTERM) ends it: what it completed before, nothing partial."""
    what = "interrupted" if signum == signal.SIGINT else "terminated"
    who = f"rwadist {command}" if command else "rwadist"
    done = [str(p) for p in _WRITTEN]
    if not done:
        return f"{who}: {what}; nothing written (outputs left as they were)"
    shown = ", ".join(done[:4]) + (f" and {len(done) - 4} more" if len(done) > 4 else "")
    return f"{who}: {what}; complete before it: {shown}; nothing partial written"


def _progress_shown() -> bool:
    tqdm = sys.modules.get("tqdm.std")
    try:
        return bool(tqdm and len(tqdm.tqdm._instances))
    except Exception:
        return False


@contextmanager
def exit_on_interrupt(command):
    """While the block runs (the command line's command), Ctrl-C (SIGINT) and SIGTERM end the process at once: the
    temporaries being written are removed, one line (:func:`interrupt_message`) goes to stderr, exit 130 (143).
    No exception is raised, so none can be swallowed by code that runs at that moment (a ``__del__``, a weakref
    callback) or turned into a traceback.  A set being swapped in holds the signal until its few renames are done.
    A signal ignored when the block starts (a background job's SIGINT) stays ignored.  Main thread only."""
    _WRITTEN.clear()        # this command's outputs (a process may run several: the tests call main() in turn)
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        for p in list(_LIVE):
            _remove_temporary(p)
        line = interrupt_message(command() if callable(command) else command, signum)
        try:
            sys.stdout.flush()
        except BaseException:       # noqa: BLE001 - the handler may run inside a write to stdout
            pass
        os.write(2, (("\n" if _progress_shown() else "") + line + "\n").encode(errors="replace"))
        os._exit(130 if signum == signal.SIGINT else 143)

    old = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(sig) != signal.SIG_IGN:
            old[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, h in old.items():
            signal.signal(sig, h if h is not None else signal.SIG_DFL)
