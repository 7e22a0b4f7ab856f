"""No import cycles among the ``demfem`` modules at module level.

A module-level import runs when its module is first imported; two modules that import each
other at that level work or fail depending on which one is imported first. This test reads
every module of the package (``python/demfem``) with :mod:`ast`, keeps the imports that run at
import time (module and class bodies, ``try``/``if`` blocks at that level; not function bodies,
not ``if TYPE_CHECKING:``), and looks for cycles among them. A package importing its own
submodule is no cycle by itself (a submodule's import runs its package's ``__init__``
first, which is then already under way); only the modules an import names count.

Run as a script (``python tests/python/test_import_cycles.py``) it prints every cycle found.
"""
from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

PACKAGE_ROOT = Path(__file__).resolve().parents[2] / "python"


def module_files(root: Path = PACKAGE_ROOT) -> dict[str, Path]:
    """{dotted module name: source file} of every ``.py`` module under ``root/demfem``."""
    found = {}
    for path in sorted((root / "demfem").rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _import_time_nodes(body: list[ast.stmt]):
    """The import statements of ``body`` that run when the module is imported."""
    for node in body:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        elif isinstance(node, ast.If):
            if not _is_type_checking(node.test):
                yield from _import_time_nodes(node.body)
            yield from _import_time_nodes(node.orelse)
        elif isinstance(node, ast.ClassDef):
            yield from _import_time_nodes(node.body)
        else:  # try, with, for, while: their blocks run at import time too
            for field in ("body", "orelse", "finalbody"):
                yield from _import_time_nodes(getattr(node, field, None) or [])
            for handler in getattr(node, "handlers", None) or []:
                yield from _import_time_nodes(handler.body)


def module_level_imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The ``demfem`` modules that ``name`` (source ``path``) imports at import time."""
    is_package = path.name == "__init__.py"
    targets: set[str] = set()
    for node in _import_time_nodes(ast.parse(path.read_text(encoding="utf-8")).body):
        if isinstance(node, ast.Import):
            bases = [alias.name for alias in node.names]
            for base in bases:
                if base in modules:
                    targets.add(base)
            continue
        if node.level:
            anchor = name.split(".") if is_package else name.split(".")[:-1]
            anchor = anchor[:len(anchor) - (node.level - 1)]
            base = ".".join(anchor + ([node.module] if node.module else []))
        else:
            base = node.module or ""
        for alias in node.names:
            sub = f"{base}.{alias.name}"
            if sub in modules:
                targets.add(sub)  # `from package import submodule`
            elif base in modules:
                targets.add(base)
    targets.discard(name)
    return targets


def import_graph(root: Path = PACKAGE_ROOT) -> dict[str, set[str]]:
    """{module: the demfem modules it imports at module level}."""
    modules = module_files(root)
    return {name: module_level_imports(name, path, modules) for name, path in modules.items()}


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of ``graph`` with more than one module (each one
    holds at least one cycle), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:  # Tarjan
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def test_the_reader_sees_a_cycle(tmp_path):
    pkg = tmp_path / "demfem"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("from demfem.sub.a import x\n")
    (pkg / "sub" / "a.py").write_text("from demfem.b import y\n"
                                      "def later():\n    from demfem.c import z\n")
    (pkg / "b.py").write_text("import demfem.sub.a\n")
    (pkg / "c.py").write_text("from demfem.sub import a\n")
    graph = import_graph(tmp_path)
    assert graph["demfem.sub"] == {"demfem.sub.a"}
    assert graph["demfem.sub.a"] == {"demfem.b"}  # not the import inside the function
    assert graph["demfem.c"] == {"demfem.sub.a"}
    assert import_cycles(graph) == [["demfem.b", "demfem.sub.a"]]


def test_no_import_cycles_in_the_package():
    graph = import_graph()
    for name in ("demfem.dem", "demfem.dem.table_run", "demfem.dem.table_record",
                 "demfem.dem.steady", "demfem.fem.cluster_run", "demfem.assess.run",
                 "demfem.pipeline", "demfem.cli"):
        assert name in graph, name
    assert import_cycles(graph) == []


def test_the_product_modules_import_on_their_own():
    """Each imported first (every demfem module but the compiled core forgotten before it):
    no order of imports hides a missing one or a cycle."""
    names = ("demfem.dem", "demfem.dem.table_run", "demfem.dem.table_record",
             "demfem.dem.steady", "demfem.fem.cluster_run", "demfem.run_report",
             "demfem.assess.job_stages", "demfem.assess", "demfem.pipeline", "demfem.cli",
             "demfem.studies.figures")
    code = ("import importlib, sys\n"
            "for name in sys.argv[1:]:\n"
            "    for m in [m for m in sys.modules if m.startswith('demfem') and m != 'demfem._core']:\n"
            "        del sys.modules[m]\n"
            "    importlib.import_module(name)\n")
    r = subprocess.run([sys.executable, "-c", code, *names], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


if __name__ == "__main__":
    cycles = import_cycles(import_graph())
    for c in cycles:
        print("cycle among: " + ", ".join(c))
    print(f"{len(cycles)} import cycle(s) among the demfem modules at module level")
    sys.exit(1 if cycles else 0)
