"""Seeded fuzz cases of the command line (issue 17), shared by tests/test_fuzz_*.py (a sample) and
benchmarks/fuzz_all.py (>= 300 cases per surface).

Each case runs ``rwadist.cli.main`` in-process and is classed:

- ``ok``: exit 0 on a value that may be valid;
- ``clear``: exit 1/2 with a last stderr line that is an error naming the file or flag of the case;
- ``unclear``: refused, but the message names neither the file nor the flag;
- ``silent``: exit 0 on a value known invalid (non-finite, not a number, outside its physical range);
- ``traceback``: an exception escaped main(), or main() reported an internal error (exit 3).
"""
from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import random
import warnings
from pathlib import Path

OUTCOMES = ("ok", "clear", "unclear", "silent", "traceback")


def run_case(argv, names, invalid: bool) -> tuple:
    """(outcome, detail) of ``rwadist argv``; ``names``: strings one of which a clear error must contain."""
    from rwadist.cli import main

    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                code = main([str(a) for a in argv])
            except SystemExit as exc:        # argparse refusing a value
                code = exc.code if isinstance(exc.code, int) else 2
    except BaseException as exc:             # noqa: BLE001 - anything escaping main() is the failure sought
        return "traceback", f"{type(exc).__name__}: {exc}"[:300]
    text = err.getvalue()
    lines = [ln for ln in text.splitlines() if ln.strip() and "%|" not in ln and "\r" not in ln]
    last = lines[-1] if lines else ""
    if code == 3 or "Traceback" in text:
        return "traceback", last[:300]
    if code == 0 or (code == 1 and "the model is empty" in last):     # a fit that ran and found no line (exit 1)
        return ("silent" if invalid else "ok"), " ".join(map(str, argv))[:300]
    if "error" in last and any(str(n) in last for n in names):
        return "clear", last[:300]
    return "unclear", f"exit {code}: {last[:300]}"


# --------------------------------------------------------------------------- CLI values

BAD_ALWAYS = ["nan", "inf", "-inf", "abc", "", "1e400", "NaN", "0x10", "1,5", "--"]
NUMBERS = ["-1", "0", "1e-300", "0.5", "1", "1.5", "2", "5", "100", "1e6", "1e12", "-1e12", "1e300", "3"]

#: (command prefix (with {tmp}), flag, physically invalid?(x) for a float x)
_FLAGS = [
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--speeds-rpm", "600,1200"],
     "--sample-rate", lambda x: x <= 0 or x > 1e7),
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--speeds-rpm", "600,1200"],
     "--noise", lambda x: x < 0),
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--speeds-rpm", "600:1200"],
     "--n-speeds", lambda x: x < 1 or x != int(x)),
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--speeds-rpm", "600,1200"],
     "--samples", lambda x: x < 2 or x != int(x)),
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--sweep", "--duration", "2"],
     "--sweep-end-rpm", lambda x: abs(x) > 1e6),
    (["simulate-test", "{tmp}/sim", "--preset", "ithaco-e", "--sweep", "--sweep-end-rpm", "600"],
     "--duration", lambda x: x <= 0),
    (["fit", "{tmp}/no_such_data", "-o", "{tmp}/m.json"], "--presence", lambda x: x <= 0 or x > 1),
    (["fit", "{tmp}/no_such_data", "-o", "{tmp}/m.json"], "--epsilon", lambda x: x <= 0 or x >= 1),
    (["fit", "{tmp}/no_such_data", "-o", "{tmp}/m.json", "--extended"], "--radius", lambda x: x <= 0),
    (["fit", "{tmp}/no_such_data", "-o", "{tmp}/m.json", "--extended"], "--mass", lambda x: x <= 0),
    (["fit", "{tmp}/no_such_data", "-o", "{tmp}/m.json"], "--nperseg", lambda x: x < 62 or x != int(x)),
    (["diagnose", "{tmp}/no_such_data", "-o", "{tmp}/diag"], "--k-sigma", lambda x: x <= 0),
    (["diagnose", "{tmp}/no_such_data", "-o", "{tmp}/diag"], "--min-gain", lambda x: x <= 0 or x >= 1),
    (["fmu", "check", "{tmp}/no_such.fmu"], "--step-size", lambda x: x <= 0),
    (["fmu", "check", "{tmp}/no_such.fmu"], "--stop-time", lambda x: x <= 0),
    (["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-speeds", "50",
      "-o", "{tmp}/psd.csv"], "--n-freq", lambda x: x < 2 or x != int(x)),
    (["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-freq", "201",
      "--n-speeds", "50", "-o", "{tmp}/psd.csv"], "--fmax", lambda x: x <= 0),
    (["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-freq", "201", "--dist",
      "normal", "--n-speeds", "50", "-o", "{tmp}/psd.csv"], "--std-rpm", lambda x: x <= 0),
    (["campbell", "--preset", "ithaco-e", "-o", "{tmp}/c.csv"], "--speeds-rpm", None),
    (["psd", "--preset", "ithaco-e", "--empirical", "--n-freq", "201", "--n-speeds", "50",
      "-o", "{tmp}/psd.csv"], "--speed-rpm", None),
]

#: values that make a valid run slow (and are valid): kept out so that a sample stays fast
_SLOW_VALID = {("--sample-rate", "1e6"), ("--samples", "1e6"), ("--n-speeds", "100"), ("--n-speeds", "1e6"),
               ("--duration", "100"), ("--duration", "1e6"), ("--n-freq", "1e6"), ("--n-freq", "100"),
               ("--sample-rate", "100"), ("--duration", "5")}


def _speed_spec(rng: random.Random) -> tuple:
    """A speed list or grid: (text, invalid?)."""
    a, b = rng.choice(NUMBERS + BAD_ALWAYS[:3]), rng.choice(NUMBERS + BAD_ALWAYS[:3])
    kind = rng.randrange(3)
    if kind == 0:
        step = rng.choice(["100", "0", "-5", "1e-6", "nan", "500"])
        text = f"{a}:{b}:{step}"
    elif kind == 1:
        text = f"{a}:{b}"
    else:
        text = f"{a},{b}"
    try:
        vals = [float(v) for v in (a, b)]
        bad = any(not math.isfinite(v) or abs(v) > 1e6 for v in vals)
        if kind == 0:
            st = float(step)
            bad |= not math.isfinite(st) or st <= 0 or (math.isfinite(vals[1] - vals[0]) and (vals[1] - vals[0]) / st > 1e7)
    except ValueError:
        bad = True
    return text, bad


def cli_cases(n: int, seed: int, tmp: Path) -> list:
    """``n`` seeded (argv, names, invalid) cases of mutated numeric flags and output paths."""
    rng = random.Random(seed)
    cases = []
    while len(cases) < n:
        if rng.random() < 0.12:            # output paths: a directory, empty, unwritable, a file for a folder
            cases.append(_output_case(rng, tmp))
            continue
        prefix, flag, physically_invalid = rng.choice(_FLAGS)
        argv = [p.replace("{tmp}", str(tmp)) for p in prefix]
        if physically_invalid is None:      # a speed list
            value, invalid = _speed_spec(rng)
        else:
            value = rng.choice(BAD_ALWAYS + NUMBERS + [repr(rng.uniform(-10, 10))])
            if (flag, value) in _SLOW_VALID:
                continue
            try:
                x = float(value)
                invalid = not math.isfinite(x) or physically_invalid(x) or value.strip() != value or "_" in value
            except ValueError:
                invalid = True
        # a valid value reaches the command, which then refuses the missing data file by its name
        cases.append((argv + [f"{flag}={value}"], [flag, "no_such"], invalid))
    return cases


def _output_case(rng: random.Random, tmp: Path) -> tuple:
    (tmp / "adir").mkdir(exist_ok=True)
    (tmp / "afile.txt").write_text("x")
    which = rng.randrange(5)
    if which == 0:
        return (["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:500", "-o", str(tmp / "adir")],
                ["-o"], True)
    if which == 1:
        return (["campbell", "--preset", "ithaco-e", "--speeds-rpm", "0:3000:500", "-o", ""], ["-o"], True)
    if which == 2:
        return (["psd", "--preset", "ithaco-e", "--speed-rpm", "600:2400", "--empirical", "--n-freq", "101",
                 "--n-speeds", "20", "-o", "/proc/psd.csv"], ["-o"], True)
    if which == 3:
        return (["fit", str(tmp / "no_such_data"), "-o", str(tmp / "m.json"), "--report", str(tmp / "afile.txt")],
                ["--report"], True)
    return (["fmu", "build", "--preset", "ithaco-e", "-o", str(tmp / "afile.txt" / "w.fmu")], ["-o"], True)


# --------------------------------------------------------------------------- model files

def _leaves(doc, path=()):
    """Every (path, value) of a JSON document, containers included."""
    yield path, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _leaves(v, path + (i,))


def _set(doc, path, value):
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


#: keys whose numbers are physically non-negative (a negative one must be refused)
_NON_NEGATIVE = {"C", "C_stderr", "h", "n_points", "mass_kg", "radius_m", "max_speed_rpm", "f_mod_Hz", "f_Hz",
                 "zeta", "damping", "k", "presence"}


def model_document() -> dict:
    from rwadist import catalogue
    from rwadist.model import to_json

    return to_json(catalogue.load("ithaco-e"))


def model_cases(n: int, seed: int, tmp: Path) -> list:
    """``n`` seeded cases: a mutated ithaco-e model file through show, psd, campbell (and fmu build)."""
    rng = random.Random(seed)
    base = model_document()
    leaves = [p for p, _ in _leaves(base) if p]
    cases = []
    for i in range(n):
        doc = copy.deepcopy(base)
        path = rng.choice(leaves)
        old = None
        node = doc
        for k in path:
            node = node[k]
        old = node
        kind = rng.randrange(12)
        invalid = False
        if kind == 0:
            new = rng.choice([math.nan, math.inf, -math.inf])
            invalid = isinstance(old, (int, float)) and not isinstance(old, bool)
        elif kind == 1:
            new = rng.choice([True, False])
            invalid = isinstance(old, (int, float)) and not isinstance(old, bool)
        elif kind == 2:
            new = rng.choice(["x", "", "1e3", None])
            # null is "absent" for an optional field (the schema's rule), a required one is refused anyway
            invalid = isinstance(old, (int, float)) and not isinstance(old, bool) and new is not None
        elif kind == 3:
            new = rng.choice([{}, {"a": 1}, [], [1, 2]])
            invalid = isinstance(old, (int, float)) and not isinstance(old, bool)
        elif kind == 4:
            new = -abs(old) - 1 if isinstance(old, (int, float)) and not isinstance(old, bool) else old
            invalid = path[-1] in _NON_NEGATIVE and new is not old
        elif kind == 5:
            new = 1.5 if isinstance(old, int) and not isinstance(old, bool) else old
            invalid = new is not old and path[-1] in ("n_points", "schema_version")
        elif kind == 6:      # deep nesting, written as text below (json.dumps itself recurses)
            new = "__DEEP__"
            depth = rng.choice([50, 2000, 100000])
        elif kind == 7:
            new = [rng.random() for _ in range(rng.choice([1000, 100000]))]
        elif kind == 8:
            new = 1e300 if isinstance(old, (int, float)) and not isinstance(old, bool) else old
        elif kind == 9:      # a list given as a dict / a dict given as a list
            new = ({str(j): v for j, v in enumerate(old)} if isinstance(old, list)
                   else list(old.values()) if isinstance(old, dict) else old)
            invalid = new is not old and isinstance(old, list) and len(old) > 0
        elif kind == 10:     # a key removed
            parent = doc
            for k in path[:-1]:
                parent = parent[k]
            if isinstance(parent, dict):
                parent.pop(path[-1])
            new = None
        else:
            new = rng.uniform(-1e3, 1e3) if isinstance(old, (int, float)) else old
        if kind != 10:
            _set(doc, path, new)
        if path[0] == "provenance":       # free-form metadata (what was measured, sources): any JSON is kept
            invalid = False
        fname = tmp / f"model_{seed}_{i}.json"
        text = json.dumps(doc, allow_nan=True)
        if kind == 6:
            text = text.replace('"__DEEP__"', "[" * depth + "0.0" + "]" * depth)
        if rng.random() < 0.05:      # damaged JSON text
            cut = rng.randrange(1, len(text))
            text = text[:cut]
            invalid = True
        fname.write_text(text)
        command = rng.choice(["show", "psd", "campbell", "show", "psd", "fmu"])
        if command == "show":
            argv = ["model", "show", fname]
        elif command == "psd":
            argv = ["psd", fname, "--speed-rpm", "600:2400", "--n-freq", "401", "--n-speeds", "40",
                    "-o", tmp / f"psd_{i}.csv"] + (["--empirical"] if rng.random() < 0.5 else [])
        elif command == "campbell":
            argv = ["campbell", fname, "--speeds-rpm", "0:3000:500", "-o", tmp / f"camp_{i}.csv"]
        else:
            argv = ["fmu", "build", fname, "--native", "-o", tmp / f"w_{i}.fmu"]
        cases.append((argv, [fname.name], invalid, "/".join(map(str, path)) + f" <- {str(new)[:40]}"))
    return cases


# --------------------------------------------------------------------------- data files

def make_datasets(tmp: Path) -> dict:
    """Small valid datasets to mutate: a steady-test directory, a sweep CSV and an HDF5 file."""
    import numpy as np

    from rwadist import api
    from rwadist.data import write_steady, write_sweep
    from rwadist.hdf5 import write_hdf5
    from rwadist.presets import preset
    from rwadist.teststand import simulate_sweep

    test = api.simulate_test("ithaco-e", np.array([600.0, 1500.0]), n_samples=1024, noise=0.01, seed=1)
    write_steady(test, tmp / "steady")
    sweep = simulate_sweep(preset("ithaco-e"), rpm_start=600.0, rpm_end=1200.0, duration=3.0, sample_rate=1920.0,
                           noise=0.01, seed=2)
    write_sweep(sweep, tmp / "sweep.csv")
    write_hdf5(test, tmp / "test.h5")
    return {"steady": tmp / "steady", "sweep": tmp / "sweep.csv", "h5": tmp / "test.h5"}


def _mutate_bytes(data: bytes, rng: random.Random) -> tuple:
    """(mutated bytes, invalid?) of a text or binary file."""
    kind = rng.randrange(7)
    if kind == 0:    # flipped bytes
        b = bytearray(data)
        for _ in range(rng.choice([1, 5, 50])):
            k = rng.randrange(len(b))
            b[k] ^= 1 << rng.randrange(8)
        return bytes(b), False
    if kind == 1:    # truncated
        return data[:rng.randrange(len(data))], False
    if kind == 2:    # UTF-16 text
        try:
            return data.decode("utf-8").encode("utf-16"), False
        except UnicodeDecodeError:
            return data[::-1], False
    if kind == 3:    # empty
        return b"", True
    if kind == 4:    # garbage
        return bytes(rng.randrange(256) for _ in range(200)), True
    if kind == 5:    # a NaN or inf sample in a text table
        lines = data.split(b"\n")
        if len(lines) > 3 and b"," in lines[2]:
            cells = lines[2].split(b",")
            cells[rng.randrange(len(cells))] = rng.choice([b"nan", b"inf", b"-inf", b"", b"x"])
            lines[2] = b",".join(cells)
            return b"\n".join(lines), True
        return data, False
    lines = data.split(b"\n")        # a line dropped or duplicated
    if len(lines) > 3:
        k = rng.randrange(len(lines))
        lines.insert(k, lines[k]) if rng.random() < 0.5 else lines.pop(k)
    return b"\n".join(lines), False


def _mutate_h5(path: Path, rng: random.Random) -> bool:
    """Damage an HDF5 file in place through h5py; True when the result is known invalid."""
    import h5py
    import numpy as np

    with h5py.File(path, "r+") as fh:
        names = []
        fh.visit(names.append)
        kind = rng.randrange(4)
        target = rng.choice(names)
        if kind == 0:         # a dangling soft link in place of a member
            del fh[target]
            fh[target] = h5py.SoftLink("/does/not/exist")
            return True
        if kind == 1:         # a member deleted: a run or a channel fewer is still a valid test
            del fh[target]
            return False
        obj = fh[target]
        if kind == 2 and isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size:
            arr = obj[()]
            flat = np.array(arr, dtype=float).ravel()
            flat[rng.randrange(flat.size)] = rng.choice([np.nan, np.inf])
            obj[...] = flat.reshape(np.shape(arr))
            return True
        if obj.attrs:         # an attribute changed to garbage
            key = rng.choice(list(obj.attrs))
            obj.attrs[key] = rng.choice(["garbage", -1.0, np.nan])
            return False
    return False


def reader_cases(n: int, seed: int, tmp: Path, sets: dict) -> list:
    """``n`` seeded cases: a damaged copy of a dataset converted (read fully) to HDF5."""
    import shutil

    rng = random.Random(seed)
    cases = []
    for i in range(n):
        which = rng.choice(["steady", "sweep", "h5", "h5"])
        case_dir = tmp / f"case_{seed}_{i}"
        case_dir.mkdir()
        src = sets[which]
        if which == "steady":
            dst = case_dir / "steady"
            shutil.copytree(src, dst)
            files = sorted(dst.iterdir())
            victim = rng.choice(files)
            data, invalid = _mutate_bytes(victim.read_bytes(), rng)
            victim.write_bytes(data)
            names = [dst.name, victim.name]
        elif which == "sweep":
            dst = case_dir / "sweep.csv"
            data, invalid = _mutate_bytes(src.read_bytes(), rng)
            dst.write_bytes(data)
            names = [dst.name]
        else:
            dst = case_dir / "test.h5"
            shutil.copyfile(src, dst)
            if rng.random() < 0.3:
                data, invalid = _mutate_bytes(dst.read_bytes(), rng)
                dst.write_bytes(data)
            else:
                invalid = _mutate_h5(dst, rng)
            names = [dst.name]
        cases.append((["convert", dst, "-o", case_dir / "out.h5"], names, invalid, which))
    return cases


def tally(results) -> dict:
    counts = {k: 0 for k in OUTCOMES}
    for outcome, _ in results:
        counts[outcome] += 1
    return counts
