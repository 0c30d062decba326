"""One exported error hierarchy (issue 34): ``rwadist.RwadistError`` and its kinds, raised by the library naming the
file, field or parameter and never a command-line flag; the command line reports those as bad input (exit 2, the
flag named) and anything else as an internal error (exit 3, the traceback in a file), never as bad input."""
from __future__ import annotations

import ast
import importlib.util
import re
from pathlib import Path

import pytest

import rwadist
from rwadist import errors, schema
from rwadist.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_the_hierarchy():
    kinds = (rwadist.DataError, rwadist.ModelError, rwadist.ParameterError, rwadist.MissingDependencyError)
    assert all(issubclass(k, rwadist.RwadistError) for k in kinds)
    assert all(issubclass(k, ValueError) for k in kinds[:3])               # except clauses written before hold
    assert issubclass(rwadist.MissingDependencyError, ImportError)
    from rwadist.coupling import CouplingError
    from rwadist.coupling.performance import CouplingModelError
    from rwadist.model import ModelFileError

    assert issubclass(ModelFileError, rwadist.ModelError) and issubclass(ModelFileError, rwadist.DataError)
    assert issubclass(CouplingError, rwadist.ParameterError)
    assert issubclass(CouplingModelError, rwadist.ModelError) and issubclass(CouplingModelError, CouplingError)
    assert issubclass(rwadist.model.ModelKeyWarning, rwadist.RwadistWarning)
    e = rwadist.ParameterError("presence", "2.0: out of range")
    assert (e.parameter, e.problem, str(e)) == ("presence", "2.0: out of range", "presence: 2.0: out of range")
    assert rwadist.ParameterError("two values that do not go together").parameter is None
    d = rwadist.DataError("runs.csv", "speed_rpm", "'abc': not a number")
    assert (d.file, d.field, str(d)) == ("runs.csv", "speed_rpm", "runs.csv: speed_rpm: 'abc': not a number")


def test_the_schema_copy_carries_its_own_root():
    """rwadist/schema.py is copied alone into the FMU (numpy only): loaded from its file outside the package, its
    ModelError still has a RwadistError root and is a ValueError; in the package the root is rwadist's."""
    tree = ast.parse(Path(schema.__file__).read_text())
    imported = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    assert not any(isinstance(n, ast.ImportFrom) and n.level for n in ast.walk(tree))
    assert "rwadist" not in imported
    spec = importlib.util.spec_from_file_location("lone_schema_copy", schema.__file__)
    lone = importlib.util.module_from_spec(spec)
    import sys

    sys.modules["lone_schema_copy"] = lone
    try:
        spec.loader.exec_module(lone)
    finally:
        del sys.modules["lone_schema_copy"]
    assert issubclass(lone.ModelError, lone.RwadistError) and issubclass(lone.ModelError, ValueError)
    assert errors.RwadistError is schema.RwadistError is rwadist.RwadistError


def _raised_texts(path: Path):
    """The string constants of every ``raise`` statement of a module (f-string parts included)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Raise) and node.exc is not None:
            for sub in ast.walk(node.exc):
                if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
                    yield node.lineno, sub.value


def test_the_library_names_no_command_line_flag():
    """A flag is the command line's to name (it translates a parameter, ``presence`` -> ``--presence``): no error the
    library raises names one (api.py named --mass, --radius and --preset)."""
    files = [p for p in sorted((ROOT / "rwadist").rglob("*.py")) if not p.name.startswith("cli")]
    found = [f"{p.relative_to(ROOT)}:{line}: {text!r}" for p in files for line, text in _raised_texts(p)
             if re.search(r"(^|[\s(\"'])--[a-z]", text)]
    assert not found, "\n".join(found)


def _small_test(tmp_path, capsys) -> Path:
    """A two-speed E-wheel test written by ``rwadist simulate-test`` (its console output read away): data for a
    command that is made to fail inside."""
    data = tmp_path / "d"
    assert main(["simulate-test", str(data), "--preset", "ithaco-e", "--speeds-rpm", "600,1200", "--samples",
                 "256"]) == 0
    capsys.readouterr()
    return data


def test_an_internal_error_is_never_bad_input(tmp_path, capsys, monkeypatch):
    """A ValueError that is no RwadistError is a bug: exit 3 with its traceback in a file, not 'bad input' (the CLI
    read every ValueError as bad input, and every ValueError of diagnose's engine as a --base problem)."""
    from rwadist import api

    data = _small_test(tmp_path, capsys)

    def broken(*args, **kwargs):
        raise ValueError("operands could not be broadcast together")

    monkeypatch.setattr(api, "diagnose", broken)
    assert main(["diagnose", str(data), "-o", str(tmp_path / "r")]) == 3
    err = capsys.readouterr().err
    assert "internal error (ValueError: operands could not be broadcast" in err and "--base" not in err
    log = Path(re.search(r"full traceback in (\S+);", err).group(1))
    assert "operands could not be broadcast" in log.read_text() and "Traceback" in log.read_text()
    log.unlink()


def test_a_missing_package_is_named_with_its_install(tmp_path, capsys, monkeypatch):
    find = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pythonfmu" else find(name, *a))
    with pytest.raises(rwadist.MissingDependencyError) as err:
        rwadist.build_fmu(preset="ithaco-e", path=tmp_path / "w.fmu")
    assert err.value.package == "pythonfmu" and isinstance(err.value, ImportError)
    assert main(["fmu", "build", "--preset", "ithaco-e", "-o", str(tmp_path / "w.fmu")]) == 2
    assert "pip install 'rwadist[fmu]'" in capsys.readouterr().err and not (tmp_path / "w.fmu").exists()


def test_a_parameter_is_named_by_its_flag(tmp_path, capsys):
    """The library's ParameterError names the parameter and, in backquotes, those its message points to; the command
    line names their flags: ``rwadist.fit_extended(mass=10.6)`` and ``fit --extended --mass 10.6``."""
    with pytest.raises(rwadist.ParameterError) as err:
        rwadist.fit_extended("no-data", mass=10.6)
    assert str(err.value).startswith("mass: needs `radius` too")
    with pytest.raises(rwadist.ParameterError, match=r"speed_rpm: 3000:300: empty or inverted"):
        rwadist.psd(preset="ithaco-e", speed_rpm=(3000, 300))
    assert main(["psd", "--preset", "ithaco-e", "--speed-rpm", "3000:300", "-o", str(tmp_path / "p.csv")]) == 2
    assert "rwadist: error: --speed-rpm: value: 3000:300: empty or inverted" in capsys.readouterr().err
    with pytest.warns(rwadist.RwadistWarning, match=r"^speed_rpm: 0:10000 rpm reaches beyond the maximum speed"):
        rwadist.psd(preset="ithaco-e", speed_rpm=(0, 10000), empirical=True, n_freq=101, n_speeds=20)


def test_coupling_model_error_keeps_both_contracts():
    """A CouplingModelError is a ModelError and a ParameterError: it has ParameterError's ``parameter`` (None: a file's
    entry, no function parameter) and a string ``problem``, so the command line words it as the file's error."""
    from rwadist.cli import user_message
    from rwadist.coupling.performance import CouplingModelError

    e = CouplingModelError("<model>", "effects[0].f_Hz", "-1.0: must be > 0")
    assert (e.parameter, e.field, e.problem) == (None, "effects[0].f_Hz", "-1.0: must be > 0")
    assert user_message(e) == str(e) == "<model>: effects[0].f_Hz: -1.0: must be > 0"
    whole = CouplingModelError("wheel: mass_kg and radius_m must be positive, got 0, 0.1")
    assert (whole.parameter, whole.field, whole.problem) == (None, None, str(whole))
    assert user_message(whole) == str(whole)


def test_a_model_the_diagnosis_made_that_does_not_validate_is_an_internal_error(tmp_path, capsys, monkeypatch):
    """The diagnosis's own model refused by the schema is a bug, not the user's input: exit 3 with its traceback in a
    file (a new user's fixture on the rocking mode, no model given, got "error: <model>: effects[2]...", exit 2)."""
    import importlib

    from rwadist import api
    from rwadist.errors import ModelError

    data = _small_test(tmp_path, capsys)

    def broken(*args, **kwargs):
        raise ModelError("<model>: effects[2].exponent_beyond_stand: NaN is not a JSON number")

    monkeypatch.setattr(importlib.import_module("rwadist.diagnose"), "diagnose", broken)
    with pytest.raises(RuntimeError, match="the diagnosis made a model that does not validate"):
        api.diagnose(str(data))
    assert main(["diagnose", str(data), "-o", str(tmp_path / "r")]) == 3
    err = capsys.readouterr().err
    assert "internal error" in err and "exponent_beyond_stand" in err, err
    Path(re.search(r"full traceback in (\S+);", err).group(1)).unlink()
