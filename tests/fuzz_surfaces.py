"""Seeded fuzz cases of issue 36, shared by tests/test_fuzz_*.py (samples) and benchmarks/fuzz_all.py (>= 300 per
surface): model files through EVERY consumer (a model valid everywhere or nowhere), the Python API's arguments, and
the fields the readers read (meta.json, runs.csv, samples, TDMS, MATLAB v7.3).  Outcomes as in
:mod:`fuzz_cases` (ok, clear, unclear, silent, traceback); a model case is also ``silent`` when ``model show``
refuses the file and another consumer accepts it (or the reverse: an inconsistency between consumers)."""
from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import random
import warnings
from pathlib import Path

import fuzz_cases as fz

# --------------------------------------------------------------------------- model files x every consumer

CONSUMERS = ("show", "psd", "campbell", "fmu", "diagnose", "api", "coupling")
#: consumers that take seconds per case: run on every ``SLOW_EVERY``-th case
SLOW = {"fmu": 4, "diagnose": 6}


def _typed(doc: dict, path: tuple) -> bool:
    """True when the model-file field at ``path`` is one the schema checks (not a free-form place)."""
    from rwadist import schema

    top = path[0]
    if top in ("provenance", "units"):
        return False
    if top == "analytical":
        return len(path) < 2 or path[1] != "fit"
    if top == "effects" and len(path) >= 3:
        kind = doc["effects"][path[1]].get("kind") if isinstance(doc["effects"][path[1]], dict) else None
        cls = schema.EFFECT_KINDS.get(kind)
        keys = {key for _, key, _ in cls.spec()} | {"kind"} if cls else {"kind"}
        return path[2] in keys
    return True


#: fields that may be negative (signed lengths, phases, accelerations, speed pairs)
_SIGNED = {"height_m", "r_m", "alpha_rad_s2", "alpha_track_rad_s2", "alpha_residual_rad_s2", "alpha_slowest_rad_s2",
           "alpha_fastest_rad_s2", "counter_fraction_phase", "excluded_rpm"}


def _mutate(doc: dict, rng: random.Random) -> tuple:
    """(document, invalid?, what) of one mutation aimed at issue 36's findings."""
    leaves = [p for p, v in fz._leaves(doc) if p and isinstance(v, (int, float)) and not isinstance(v, bool)]
    kind = rng.randrange(12)
    if kind == 0:                       # a number beyond any real wheel's range
        path = rng.choice(leaves)
        value = rng.choice([1e308, 1e15, -1e308])
        fz._set(doc, path, value)
        return doc, _typed(doc, path), f"{'/'.join(map(str, path))} <- {value:g}"
    if kind == 1:                       # NaN or infinity (JSON's NaN extension)
        path = rng.choice(leaves)
        fz._set(doc, path, rng.choice([math.nan, math.inf]))
        return doc, _typed(doc, path), f"{'/'.join(map(str, path))} <- nan/inf"
    if kind == 2:                       # a string or a boolean for a number
        path = rng.choice(leaves)
        value = rng.choice(["fast", "1", True, [], {}])
        fz._set(doc, path, value)
        return doc, _typed(doc, path), f"{'/'.join(map(str, path))} <- {value!r}"
    if kind == 3:                       # negative where the value is a magnitude
        path = rng.choice(leaves)
        node = doc
        for k in path[:-1]:
            node = node[k]
        old = node[path[-1]]
        fz._set(doc, path, -abs(old) - 1.0)
        signed = any(str(k) in _SIGNED for k in path)
        return doc, _typed(doc, path) and not signed, f"{'/'.join(map(str, path))} <- negative"
    if kind == 4:                       # a misspelt key (top level, a section, a harmonic)
        where = rng.choice(["top", "wheel", "analytical", "harmonic"])
        target = doc if where == "top" else doc.get(where) if where != "harmonic" else \
            (doc["empirical"].get("radial_force") or [{}])[0]
        if not isinstance(target, dict) or not target:
            return doc, False, "no key to misspell"
        key = rng.choice([k for k in target if k not in ("schema", "schema_version")] or list(target))
        bad = key[:-1] + ("x" if key[-1] != "x" else "y")
        target[bad] = target.pop(key)
        return doc, True, f"{where}.{key} -> {bad}"
    if kind == 5:                       # a required section missing
        doc.pop("empirical", None)
        return doc, True, "empirical removed"
    if kind == 6:                       # an effect kind this version does not know, or an extension's
        ext = rng.random() < 0.4
        doc.setdefault("effects", []).append({"kind": ("x-" if ext else "") + "future_effect", "f_Hz": 10.0})
        return doc, not ext, "effect kind " + ("x-future_effect (extension)" if ext else "future_effect")
    if kind == 7:                       # an effect with a physically absurd parameter
        effect = rng.choice([
            {"kind": "speed_ripple", "f_ripple_Hz": 4.0, "delta_omega_rad_s": 1e308, "omega_ref_rad_s": 200.0},
            {"kind": "amplitude_law", "direction": "radial_force", "h": 2.0, "exponent": 1000.0,
             "amplitude_ref": 0.01, "omega_ref_rad_s": 200.0},
            {"kind": "fixed_resonance", "f_Hz": 150.0, "zeta": 0.02, "peak_gain": 1e308, "role": "wheel_mode",
             "directions": ["radial_force"]},
            {"kind": "sidebands", "direction": "radial_force", "h": 2.0, "f_mod_Hz": 5.0, "depth": 1e308}])
        doc.setdefault("effects", []).append(effect)
        return doc, True, f"effect {effect['kind']} absurd"
    if kind == 8:                       # too many harmonics (campbell hung on 20 000)
        doc["empirical"]["radial_force"] = [{"h": 1.0 + 0.01 * i, "C": 1e-7} for i in range(rng.choice([1001, 20000]))]
        return doc, True, "too many harmonics"
    if kind == 9:                       # an extension key: carried, valid
        doc["x-lab"] = {"bench": 3}
        return doc, False, "x-lab extension"
    if kind == 10:                      # a value inside the ranges: valid
        path = rng.choice([p for p in leaves if p[-1] in ("C", "h") and p[0] == "empirical"] or leaves)
        node = doc
        for k in path[:-1]:
            node = node[k]
        fz._set(doc, path, node[path[-1]] * rng.uniform(0.5, 1.5))
        return doc, False, f"{'/'.join(map(str, path))} scaled"
    # NaN standard error (was written by an extended fit, not JSON)
    rf = doc["empirical"].get("radial_force") or []
    if not rf:
        return doc, False, "no harmonic"
    rf[0]["C_stderr"] = math.nan
    return doc, True, "C_stderr NaN"


def model_consumer_cases(n: int, seed: int, tmp: Path, data_dir: Path, consumers=None) -> list:
    """``n`` seeded cases: (doc file, invalid?, what, [consumers to run]).  ``data_dir``: a small steady test for
    diagnose.  ``consumers``: run these on every case (default: the fast ones on every case, the slow ones on every
    ``SLOW[c]``-th)."""
    rng = random.Random(seed)
    base = fz.model_document()
    cases = []
    for i in range(n):
        doc, invalid, what = _mutate(copy.deepcopy(base), rng)
        path = tmp / f"mc_{seed}_{i}.json"
        path.write_text(json.dumps(doc, allow_nan=True))
        # `show` always: a file it refuses and another consumer accepts is the silent case sought
        chosen = ["show"] + [c for c in consumers if c != "show"] if consumers else \
            ["show", "psd", "campbell", "api", "coupling"] + [c for c, every in SLOW.items() if i % every == 0]
        cases.append((path, invalid, what, chosen, data_dir))
    return cases


def _api_outcome(fn, names, invalid: bool) -> tuple:
    """(outcome, detail) of calling ``fn()`` (the Python API): an error of rwadist naming one of ``names`` is
    clear (any :class:`rwadist.RwadistError`); another ValueError/TypeError unclear; any other exception a traceback; a return on invalid input silent."""
    from rwadist.errors import RwadistError

    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = fn()
    except RwadistError as exc:         # the library's errors: DataError, ModelError, ParameterError, ...
        return ("clear" if any(str(x) in str(exc) for x in names) else "unclear"), str(exc)[:300]
    except (ValueError, TypeError) as exc:
        return "unclear", f"{type(exc).__name__}: {exc}"[:300]
    except Exception as exc:  # noqa: BLE001 - the failure sought
        return "traceback", f"{type(exc).__name__}: {exc}"[:300]
    return ("silent" if invalid else "ok"), repr(result)[:120]


def run_model_case(path: Path, invalid: bool, consumers, data_dir: Path, work: Path) -> dict:
    """{consumer: (outcome, detail)} of one model file through ``consumers``; an accepted file ``model show``
    refused (or a refused one it accepted, for the validation-only consumers) is ``silent``."""
    out = {}
    for c in consumers:
        if c == "show":
            out[c] = fz.run_case(["model", "show", path], [path.name], invalid)
        elif c == "psd":
            out[c] = fz.run_case(["psd", path, "--speed-rpm", "600:2400", "--n-freq", "201", "--n-speeds", "40",
                                  "--empirical", "-o", work / f"{path.stem}_psd.csv"], [path.name], invalid)
        elif c == "campbell":
            out[c] = fz.run_case(["campbell", path, "--speeds-rpm", "0:3000:500", "-o", work / f"{path.stem}_c.csv"],
                                 [path.name], invalid)
        elif c == "fmu":
            out[c] = fz.run_case(["fmu", "build", path, "--native", "-o", work / f"{path.stem}.fmu"], [path.name],
                                 invalid)
        elif c == "diagnose":
            out[c] = fz.run_case(["diagnose", data_dir, "--model", path, "-o", work / f"{path.stem}_diag"],
                                 [path.name], invalid)
        elif c == "api":
            import rwadist

            out[c] = _api_outcome(lambda: rwadist.psd(rwadist.load_model(path), (600.0, 2400.0), empirical=True,
                                                      n_freq=201, n_speeds=40).rms(), [path.name], invalid)
        elif c == "coupling":
            import rwadist
            from rwadist import coupling

            out[c] = _api_outcome(lambda: coupling.wheel_spec_from_model(rwadist.load_model(path)), [path.name],
                                  invalid)
    refused = out["show"][0] in ("clear", "unclear")
    for c, (outcome, detail) in list(out.items()):
        if c != "show" and refused and outcome == "ok":
            out[c] = ("silent", f"model show refused the file, {c} accepted it: {detail}")
    return out


# --------------------------------------------------------------------------- the Python API's arguments

BAD_NUMBERS = [math.nan, math.inf, -math.inf, -1.0, 0.0, 1e308, -1e308, "3", None, True, [1.0, 2.0], 1e-300]


def api_cases(n: int, seed: int, tmp: Path) -> list:
    """``n`` seeded cases (callable, names a clear error must contain, invalid?, what) over the public API."""
    import numpy as np

    import rwadist

    rng = random.Random(seed)
    from rwadist import catalogue

    test = rwadist.simulate_test("ithaco-e", np.array([600.0, 1200.0, 1800.0, 2400.0]), n_samples=1024, seed=1)
    model = catalogue.load("ithaco-e")
    mpath = rwadist.save_model(model, tmp / "api_model.json")
    #: arguments whose default is None ("decide"): None is valid there
    none_ok = {"simulate_test.sample_rate", "fit.f_lim", "fit.nperseg", "psd.fmax", "psd.std_rpm"}
    checks = {   # name -> (call with the value, physically invalid?(v) for a number)
        "simulate_test.speeds_rpm": (lambda v: rwadist.simulate_test("ithaco-e", [600.0, v], n_samples=256),
                                     lambda x: abs(x) > 1e5),
        "simulate_test.sample_rate": (lambda v: rwadist.simulate_test("ithaco-e", [600.0, 1200.0], sample_rate=v,
                                                                      n_samples=256), lambda x: x <= 0 or x > 1e6),
        "simulate_test.n_samples": (lambda v: rwadist.simulate_test("ithaco-e", [600.0], n_samples=v),
                                    lambda x: x < 64 or x != int(x) or x > 5e7),
        "simulate_test.noise": (lambda v: rwadist.simulate_test("ithaco-e", [600.0], n_samples=256, noise=v),
                                lambda x: x < 0 or x > 10),
        "fit.f_lim": (lambda v: rwadist.fit(test, f_lim=v), lambda x: x <= 0 or x > 1920),
        "fit.nperseg": (lambda v: rwadist.fit(test, nperseg=v), lambda x: x < 62 or x != int(x) or x > 1024),
        "fit.presence": (lambda v: rwadist.fit(test, presence=v), lambda x: x <= 0 or x > 1),
        "fit.epsilon": (lambda v: rwadist.fit(test, epsilon=v), lambda x: x <= 0 or x > 0.5),
        "psd.speed_rpm": (lambda v: rwadist.psd(model, (600.0, v), empirical=True, n_freq=201, n_speeds=40),
                          lambda x: not 600 < x <= 1e5),
        "psd.n_freq": (lambda v: rwadist.psd(model, (600.0, 2400.0), empirical=True, n_freq=v, n_speeds=40),
                       lambda x: x < 2 or x != int(x) or x > 200_001),
        "psd.n_speeds": (lambda v: rwadist.psd(model, (600.0, 2400.0), empirical=True, n_freq=201, n_speeds=v),
                         lambda x: x < 2 or x != int(x) or x > 20_000),
        "psd.fmax": (lambda v: rwadist.psd(model, (600.0, 2400.0), empirical=True, fmax=v, n_freq=201, n_speeds=40),
                     lambda x: x <= 0 or x > 1e6),
        "psd.std_rpm": (lambda v: rwadist.psd(model, (600.0, 2400.0), dist="normal", std_rpm=v, empirical=True,
                                              n_freq=201, n_speeds=40), lambda x: x <= 0 or x > 1e5),
        "campbell.speeds_rpm": (lambda v: rwadist.campbell(None, [0.0, v], preset="ithaco-e"),
                                lambda x: abs(x) > 1e5 or x == 0),
        "diagnose.k_sigma": (lambda v: rwadist.diagnose(test, model, k_sigma=v), lambda x: x <= 0 or x > 100),
        "diagnose.min_gain": (lambda v: rwadist.diagnose(test, model, min_gain=v), lambda x: x <= 0 or x >= 1),
    }
    slow = {"diagnose.k_sigma", "diagnose.min_gain", "fit.f_lim", "fit.nperseg", "fit.presence", "fit.epsilon"}
    cases = []
    names = list(checks)
    while len(cases) < n:
        name = rng.choice(names)
        if name in slow and rng.random() < 0.6:
            continue
        call, physically_invalid = checks[name]
        v = rng.choice(BAD_NUMBERS + [rng.uniform(-10, 3000)])
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            invalid = bool(physically_invalid(float(v)))
        else:
            invalid = not (v is None and name in none_ok)
        arg = name.split(".")[1]
        cases.append((lambda call=call, v=v: call(v), [arg, "--" + arg.replace("_", "-"), "speed"], invalid,
                      f"{name}={v!r}"))
    for what, fn in (("load_model(nan C)", lambda: rwadist.load_model(_bad_model(tmp, mpath))),
                     ("save_model(C=1e308)", lambda: rwadist.save_model(_huge(model), tmp / "huge.json"))):
        cases.append((fn, ["C", "api_model", "huge"], True, what))
    return cases


def _bad_model(tmp: Path, mpath: Path) -> Path:
    doc = json.loads(mpath.read_text())
    doc["empirical"]["radial_force"][0]["C"] = math.nan
    p = tmp / "api_nan.json"
    p.write_text(json.dumps(doc))
    return p


def _huge(model):
    m = copy.deepcopy(model)
    m.empirical["radial_force"][0].C = 1e308
    return m


def run_api_case(case) -> tuple:
    fn, names, invalid, _ = case
    return _api_outcome(fn, names, invalid)


# --------------------------------------------------------------------------- fields the readers read

def reader_field_cases(n: int, seed: int, tmp: Path, steady: Path, rate: float = 3840.0) -> list:
    """``n`` seeded cases: a copy of the steady test ``steady`` with one field the readers read set to a bad (or a
    good) value -- meta.json's tach, f_lim_hz, sample_rate_hz; runs.csv speeds; one sample -- read by `convert` and
    `fit`; plus lab files (TDMS wf_start_offset, MATLAB v7.3 groups).  ``rate``: the test's sample rate, Hz.
    (argv, names, invalid, what)."""
    import shutil

    rng = random.Random(seed)
    cases = []
    for i in range(n):
        d = tmp / f"rf_{seed}_{i}"
        kind = rng.randrange(6)
        if kind == 5:
            path, invalid, what = _lab_file(d, rng)
            cases.append((["convert", path, "-o", d / "out.h5"], [path.name], invalid, what))
            continue
        shutil.copytree(steady, d / "ds")
        meta_path = d / "ds" / "meta.json"
        meta = json.loads(meta_path.read_text())
        if kind == 0:
            v = rng.choice([math.nan, 0, -1, 0.5, "1", 1e30, 10**30, True, 1, 2, 360])
            meta["tach"] = {"channel": "tach", "pulses_per_rev": v}
            invalid = not (isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 100_000)
            what = f"tach.pulses_per_rev={v!r}"
        elif kind == 1:
            v = rng.choice(["abc", math.nan, -5.0, 0.0, 1e308, 5000.0, 150.0, None])
            meta["f_lim_hz"] = v
            invalid = not (v is None or (isinstance(v, float) and 0 < v <= rate / 2))
            what = f"f_lim_hz={v!r}"
        elif kind == 2:
            v = rng.choice(["fast", math.nan, -1.0, 1e308, rate])
            meta["sample_rate_hz"] = v
            invalid = v != rate
            what = f"sample_rate_hz={v!r}"
        elif kind == 3:
            lines = (d / "ds" / "runs.csv").read_text().splitlines()
            v = rng.choice(["1e308", "-1e308", "nan", "2e5", "1500"])
            cells = lines[1].split(",")
            cells[1] = v
            lines[1] = ",".join(cells)
            (d / "ds" / "runs.csv").write_text("\n".join(lines) + "\n")
            invalid = v != "1500"
            what = f"runs.csv speed {v}"
        else:
            run = sorted((d / "ds").glob("run_*.csv"))[0]
            lines = run.read_text().splitlines()
            v = rng.choice(["1e308", "-1e300", "1e12", "12.5"])
            cells = lines[3].split(",")
            cells[1 + rng.randrange(len(cells) - 1)] = v
            lines[3] = ",".join(cells)
            run.write_text("\n".join(lines) + "\n")
            invalid = v != "12.5"
            what = f"sample {v}"
        meta_path.write_text(json.dumps(meta, allow_nan=True))
        command = rng.choice([["convert", d / "ds", "-o", d / "out.h5"],
                              ["fit", d / "ds", "-o", d / "m.json", "--no-report"]])
        cases.append((command, ["ds", "meta.json", "runs.csv", "run_"], invalid, what))
    return cases


def _lab_file(d: Path, rng: random.Random) -> tuple:
    """A lab file with a bad field: a TDMS channel whose wf_start_offset is NaN, or a MATLAB v7.3 file whose channel
    is a struct (an HDF5 group); or the same files with good fields."""
    import h5py
    import numpy as np

    d.mkdir(parents=True)
    t = np.arange(2048) / 1024.0
    sig = {c: np.sin(2 * np.pi * (10 + k) * t) for k, c in enumerate(("Fx", "Fy", "Fz", "Tx", "Ty", "Tz"))}
    if rng.random() < 0.5:
        from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

        bad = rng.random() < 0.7
        path = d / "s.tdms"
        with TdmsWriter(str(path)) as w:
            objs = [RootObject(), GroupObject("run")]
            for c, y in sig.items():
                objs.append(ChannelObject("run", c, y, properties={
                    "wf_increment": 1.0 / 1024.0, "unit_string": "N" if c[0] == "F" else "N·m",
                    "wf_start_offset": float("nan") if bad and c == "Fy" else 0.0}))
            w.write_segment(objs)
        return path, bad, f"tdms wf_start_offset {'NaN' if bad else 'ok'}"
    from rwadist.formats.matlab import V73_HEADER

    bad = rng.random() < 0.7
    path = d / "s.mat"
    with h5py.File(path, "w", userblock_size=512) as fh:
        fh.create_dataset("time_s", data=t.reshape(1, -1))
        for c, y in sig.items():
            name = f"{c}_{'N' if c[0] == 'F' else 'Nm'}"
            if bad and c == "Tz":
                fh.create_group(name).create_dataset("data", data=y.reshape(1, -1))
            else:
                fh.create_dataset(name, data=y.reshape(1, -1))
    with open(path, "r+b") as fh:
        fh.write(V73_HEADER.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")
    return path, bad, f"mat v7.3 {'channel as a group' if bad else 'ok'}"
