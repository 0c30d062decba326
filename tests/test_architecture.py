"""Architecture rules of the ``rwadist`` package, checked from its source (ast, nothing imported).

- no import cycle between the modules of ``rwadist/`` (every import counts, module level or inside a
  function: an import deferred into a function to dodge a cycle is still a cycle of the design);
- no module of ``rwadist/`` over :data:`MAX_LINES` lines.

Each rule has a list of KNOWN exceptions, being removed by work in progress; the lists may only shrink.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "rwadist"
MAX_LINES = 800

#: Import cycles still present, each as the sorted tuple of its modules (may only shrink).
KNOWN_CYCLES: set = set()

#: Modules still over MAX_LINES (may only shrink).
KNOWN_LONG: set = set()


#: source folders installed inside the package under another name (pyproject ``package-dir``): checked too
MAPPED = {"fmu": "rwadist.fmu", "coupling": "rwadist.coupling"}


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[0] in MAPPED:
        parts = MAPPED[parts[0]].split(".") + parts[1:]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def source_files() -> list:
    """Every .py file of the package: rwadist/ and the folders installed into it (:data:`MAPPED`)."""
    files = list(PACKAGE.rglob("*.py"))
    for folder in MAPPED:
        if (PACKAGE.parent / folder / "__init__.py").is_file():
            files += (PACKAGE.parent / folder).rglob("*.py")
    return sorted(files)


def modules() -> dict:
    """Dotted name -> path of every module of the package."""
    return {module_name(p): p for p in source_files()}


def imports_of(name: str, path: Path, known: dict) -> set:
    """The package's modules that module ``name`` imports (anywhere in its body)."""
    is_pkg = path.name == "__init__.py"
    here = name if is_pkg else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
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


def test_no_import_cycle():
    found = set(cycles(import_graph()))
    assert found <= KNOWN_CYCLES, f"import cycles in rwadist/: {sorted(found - KNOWN_CYCLES)}"


def test_no_module_over_max_lines():
    long = {}
    for p in source_files():
        n = len(p.read_text().splitlines())
        if n > MAX_LINES:
            long[p.relative_to(PACKAGE.parent).as_posix()] = n
    extra = {k: v for k, v in long.items() if k not in KNOWN_LONG}
    assert not extra, f"modules over {MAX_LINES} lines: {extra}"


def test_installed_packages_are_the_source_packages():
    """pyproject lists every package of the source tree, fmu/ and coupling/ installed as rwadist.fmu and
    rwadist.coupling (a package missing from the list would install without its modules)."""
    import tomllib

    root = PACKAGE.parent
    cfg = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    dirs = {"rwadist": "rwadist", **cfg["package-dir"]}
    found = set()
    for name, folder in dirs.items():
        for init in (root / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(root / folder).parts
            found.add(".".join((name, *rel)))
    assert found == listed
    assert set(cfg["package-dir"]) == {"rwadist.fmu", "rwadist.coupling"}
