"""One element per effect kind (rwadist/effects/, issue 34): every kind is one module that owns everything about it,
the shipped part imports numpy and the schema only, and no other module of the package names a kind."""
from __future__ import annotations

import ast
import sys
from pathlib import Path

from rwadist import effects, schema

ROOT = Path(__file__).resolve().parents[1]
EFFECTS = ROOT / "rwadist" / "effects"


def _imports(path: Path) -> set:
    """Top names a module imports (``numpy``, ``dataclasses``, ...); a relative import as ``.`` + its module."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            out.add("." * node.level + (node.module or "") if node.level else (node.module or "").split(".")[0])
    return out


def test_every_registered_kind_is_an_element_module_of_its_own():
    """Each built-in kind is registered by the module rwadist/effects/<kind>.py, one kind per module."""
    builtin = {k: c for k, c in schema.EFFECT_KINDS.items() if c.__module__.startswith("rwadist.effects.")}
    assert len(builtin) == 12
    for kind, cls in builtin.items():
        assert cls.__module__ == f"rwadist.effects.{kind}", (kind, cls.__module__)
    assert set(builtin) <= set(effects.element_module_names())


def test_shipped_element_files_import_numpy_and_the_schema_only():
    """The files the pythonfmu FMU ships (the elements and this package's __init__) run on a host with Python and
    numpy alone: no scipy, no rwadist module but the schema and the units (read as the sibling package's
    ``..schema``, ``..units``)."""
    stdlib = set(sys.stdlib_module_names)
    files = effects.shipped_files()
    assert {f.name for f in files} >= {"__init__.py", "speed_ripple.py"}
    for f in files:
        for name in _imports(f):
            ok = name in stdlib or name in ("numpy", "..schema", "..units") or (name.startswith(".") and
                                                                                 not name.startswith(".."))
            assert ok, (f.name, name)
