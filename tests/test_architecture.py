"""Architecture rules of the ``rwadist`` package, checked from its source (ast, nothing imported).

- no import cycle between the modules of ``rwadist/`` (every import counts, module level or inside a
  function: an import deferred into a function to dodge a cycle is still a cycle of the design; so does an
  ``importlib.import_module`` of a module named by a string of the source: a PEP 562 forwarder's table, a sibling
  loader's calls.  A registry importing whatever modules its package folder holds (``rwadist.effects``,
  ``rwadist.diagnose.effects``: pkgutil) is not counted: its edges point down to its own plug-ins);
- no module of ``rwadist/`` over :data:`MAX_LINES` lines;
- no function over :data:`MAX_FUNCTION_LINES` lines (``def`` to its last line, docstring included).

Each rule has a list of KNOWN exceptions, being removed by work in progress; the lists may only shrink.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "rwadist"
MAX_LINES = 800

MAX_FUNCTION_LINES = 100

#: Import cycles still present, each as the sorted tuple of its modules (may only shrink).
KNOWN_CYCLES: set = set()

#: Modules still over MAX_LINES (may only shrink).
KNOWN_LONG: set = set()

#: Functions still over MAX_FUNCTION_LINES, as "path::name" (may only shrink).
KNOWN_LONG_FUNCTIONS: set = set()


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def source_files() -> list:
    """Every .py file of the package (rwadist.fmu and rwadist.coupling included: they live in rwadist/)."""
    return sorted(PACKAGE.rglob("*.py"))


def modules() -> dict:
    """Dotted name -> path of every module of the package."""
    return {module_name(p): p for p in source_files()}


def _dynamic_targets(call: ast.Call, name: str, here: str, tree: ast.Module, known: dict) -> list:
    """The modules an ``importlib.import_module(...)`` call of module ``name`` (package ``here``) can import: a
    constant name; an f-string of a constant or ``__name__`` prefix (``__package__`` as second argument for a
    relative one) and a variable part: the modules under that prefix named by a string constant of the module
    (a forwarder's or a sibling loader's table)."""
    func = call.func
    if not (isinstance(func, ast.Attribute) and func.attr == "import_module" and call.args):
        return []
    arg = call.args[0]
    relative = len(call.args) > 1 and isinstance(call.args[1], ast.Name) and call.args[1].id == "__package__"
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return [f"{here}{arg.value}" if relative else arg.value]
    if not isinstance(arg, ast.JoinedStr):
        return []
    prefix = ""
    for part in arg.values:
        if isinstance(part, ast.Constant):
            prefix += str(part.value)
        elif isinstance(part, ast.FormattedValue) and isinstance(part.value, ast.Name) \
                and part.value.id == "__name__" and not prefix:
            prefix = name
        else:
            break
    if relative:
        prefix = here + prefix
    if not prefix.endswith("."):
        return []
    under = [m for m in known if m.startswith(prefix) and "." not in m[len(prefix):]]
    named = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    return [m for m in under if m[len(prefix):] in named]


def imports_of(name: str, path: Path, known: dict) -> set:
    """The package's modules that module ``name`` imports (anywhere in its body)."""
    is_pkg = path.name == "__init__.py"
    here = name if is_pkg else name.rpartition(".")[0]
    out = set()
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            targets = _dynamic_targets(node, name, here, tree, known)
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here.split(".")
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            # ``from pkg import sub``: the submodule when it is one, else the package itself
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in known else mod for a in node.names]
        else:
            continue
        for t in targets:
            # ``import a.b.c`` needs a.b.c (the parents' __init__ run too, but a parent importing its
            # own submodule is how a package exposes it, not a cycle of the design)
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name:
                out.add(t)
    return out


def import_graph() -> dict:
    known = modules()
    return {name: imports_of(name, path, known) for name, path in known.items()}


def cycles(graph: dict) -> list:
    """Strongly connected components of more than one module (Tarjan), each as a sorted tuple."""
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(tuple(sorted(comp)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(out)


def test_graph_builder_finds_a_planted_cycle(tmp_path, monkeypatch):
    """The checker itself: a two-module cycle through a relative import inside a function is found, a
    parent package importing its submodule is not one."""
    pkg = tmp_path / "rwadist"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("from .a import f\n")
    (pkg / "a.py").write_text("from .b import g\n\ndef f():\n    return g()\n")
    (pkg / "b.py").write_text("def g():\n    from . import a\n    return a\n")
    (pkg / "c.py").write_text("import rwadist.sub.d\n")
    (pkg / "sub" / "__init__.py").write_text("from .d import x\n")
    (pkg / "sub" / "d.py").write_text("from ..c import y\nx = 1\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    g = import_graph()
    assert g["rwadist.b"] == {"rwadist.a"}
    assert g["rwadist.c"] == {"rwadist.sub.d"}
    assert cycles(g) == [("rwadist.a", "rwadist.b"), ("rwadist.c", "rwadist.sub.d")]


def test_graph_builder_counts_dynamic_imports(tmp_path, monkeypatch):
    """The checker itself: a PEP 562 forwarder's table and a sibling loader's calls are imports of the modules they
    name; a registry's loop over its package's files is not."""
    pkg = tmp_path / "rwadist"
    (pkg / "reg").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("import importlib\n_MOVED = {'f': 'b'}\n\ndef __getattr__(name):\n"
                              "    return getattr(importlib.import_module(f'.{_MOVED[name]}', __package__), name)\n")
    (pkg / "b.py").write_text("from .a import g\n")
    (pkg / "c.py").write_text("import importlib\n\ndef load(stem):\n"
                              "    return importlib.import_module(f'rwadist.{stem}')\n\nX = load('b')\n")
    (pkg / "reg" / "__init__.py").write_text("import importlib\nimport pkgutil\nfor m in pkgutil.iter_modules(__path__):\n"
                                             "    importlib.import_module(f'{__name__}.{m.name}')\n")
    (pkg / "reg" / "one.py").write_text("")
    (pkg / "reg" / "two.py").write_text("from .. import c\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", pkg)
    g = import_graph()
    assert g["rwadist.a"] == {"rwadist.b"}
    assert g["rwadist.c"] == {"rwadist.b"}
    assert g["rwadist.reg"] == set()
    assert cycles(g) == [("rwadist.a", "rwadist.b")]


def test_no_import_cycle():
    found = set(cycles(import_graph()))
    assert found <= KNOWN_CYCLES, f"import cycles in rwadist/: {sorted(found - KNOWN_CYCLES)}"


def test_no_module_forwards_names_of_another():
    """No module but the package's ``__init__`` (its curated API, loaded on first use) has a module ``__getattr__``:
    a PEP 562 forwarder kept a split-off module's names importable from the module they left, and hid the back edge
    of an import cycle (rwadist.extended -> extended_ripple/extended_time, rwadist.broadband -> psd_files)."""
    found = [p.relative_to(PACKAGE.parent).as_posix() for p in source_files() if p != PACKAGE / "__init__.py"
             and any(isinstance(n, ast.FunctionDef) and n.name == "__getattr__" for n in ast.parse(p.read_text()).body)]
    assert not found, found


def test_no_function_over_max_lines():
    long = {}
    for p in source_files():
        for node in ast.walk(ast.parse(p.read_text(), str(p))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                key = f"{p.relative_to(PACKAGE.parent).as_posix()}::{node.name}"
                if n > MAX_FUNCTION_LINES and key not in KNOWN_LONG_FUNCTIONS:
                    long[key] = n
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines: {long}"


def test_no_module_over_max_lines():
    long = {}
    for p in source_files():
        n = len(p.read_text().splitlines())
        if n > MAX_LINES:
            long[p.relative_to(PACKAGE.parent).as_posix()] = n
    extra = {k: v for k, v in long.items() if k not in KNOWN_LONG}
    assert not extra, f"modules over {MAX_LINES} lines: {extra}"


def test_installed_packages_are_the_source_packages():
    """pyproject lists every package of the source tree (a package missing from the list would install without its
    modules), and installs each from the folder of its name, so the repository root imports the same package as an
    installed copy (fmu/ and coupling/ sat at the top level and were mapped in: from the root
    ``from rwadist import coupling`` failed)."""
    import tomllib

    root = PACKAGE.parent
    cfg = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    # every folder that holds a file (a package, or the native FMU's C sources: namespace packages to setuptools,
    # which warns "Package would be ignored" at each build for one not listed)
    found = {".".join(f.parent.relative_to(root).parts) for f in PACKAGE.rglob("*")
             if f.is_file() and "__pycache__" not in f.parts}
    assert found == set(cfg["packages"])
    assert "package-dir" not in cfg
    assert not (root / "fmu").exists() and not (root / "coupling").exists()


def test_the_subpackages_import_from_the_repository_root():
    """``from rwadist import coupling, fmu`` run in the repository root imports them from the source tree's rwadist/
    (the package Python finds first there)."""
    import subprocess

    root = PACKAGE.parent
    code = ("import rwadist.fmu.native_build as nb; from rwadist import coupling, fmu; "
            "print(coupling.__file__); print(fmu.__file__); print(nb.__file__)")
    out = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, check=True)
    files = [Path(line) for line in out.stdout.split()]
    assert files == [PACKAGE / "coupling" / "__init__.py", PACKAGE / "fmu" / "__init__.py",
                     PACKAGE / "fmu" / "native_build.py"]
