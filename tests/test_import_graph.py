"""pkm's import graph has no cycle (issue "architecture, round two", item 2).

The graph is read from the source (``ast``), every ``import`` and ``from ... import`` counted wherever it stands,
deferred imports inside functions included, and ``importlib.import_module("pkm....")`` of a literal name too (a
builder reached that way is still imported); only imports under ``if TYPE_CHECKING:`` (annotations, never run) are
left out, except in the core (``pkm.core``), whose layers are strict: there an annotation's import counts too (the
model is built by its builder and carries no import of what is built on it, its task map, its scales, its twin's
task: those import the model, never the reverse). An edge goes from a module to each pkm module it names:
``from pkm.a import b`` is an edge to ``pkm.a.b`` when that is a module, else to ``pkm.a``. A package's ``__init__``
is the module of the package's name; importing a submodule is not counted as importing its parents (their
``__init__`` files import nothing at import time but what their own edges say).
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def _modules() -> dict[str, Path]:
    out = {}
    for path in (SRC / "pkm").rglob("*.py"):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or \
        (isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING")


def _import_module(node: ast.Call) -> bool:
    """Whether ``node`` is ``importlib.import_module("<literal>")`` (or ``import_module("<literal>")``)."""
    f = node.func
    named = (isinstance(f, ast.Attribute) and f.attr == "import_module") or \
        (isinstance(f, ast.Name) and f.id == "import_module")
    return named and len(node.args) >= 1 and isinstance(node.args[0], ast.Constant) and \
        isinstance(node.args[0].value, str)


def _imports(tree: ast.AST, package: str, type_checking: bool = False, calls: bool = True) \
        -> list[tuple[str, list[str]]]:
    """``(module, names)`` of every import (relative ones resolved), those in ``if TYPE_CHECKING:`` blocks only with
    ``type_checking``; ``calls`` False: the statements alone are walked, not their expressions (for a source
    without the text ``import_module``, which has no such call: nine nodes in ten are expressions)."""
    found: list[tuple[str, list[str]]] = []

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _type_checking(node) and not type_checking:
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            found.extend((a.name, []) for a in node.names)
        elif isinstance(node, ast.Call) and _import_module(node):  # importlib.import_module("pkm.x"): an import too
            found.append((node.args[0].value, []))  # type: ignore[attr-defined]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parent + ([base] if base else []))
            found.append((base, [a.name for a in node.names]))
        for child in ast.iter_child_nodes(node):
            if calls or isinstance(child, (ast.stmt, ast.excepthandler, ast.match_case)):
                visit(child)

    visit(tree)
    return found


@functools.cache
def _tree(path: Path) -> tuple[ast.Module, bool]:
    """A module's syntax tree, parsed once a session (both graphs read it), and whether its text names
    ``import_module`` (else its expressions hold no import: :func:`_imports`' ``calls``)."""
    text = path.read_text()
    return ast.parse(text), "import_module" in text


@functools.cache
def import_graph(type_checking: bool = False) -> dict[str, set[str]]:
    """``{module: the pkm modules it imports}`` (module doc); ``type_checking``: the imports of ``if TYPE_CHECKING:``
    blocks too. (Read once per session and argument: do not change what it returns.)"""
    modules = _modules()
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        tree, calls = _tree(path)
        for module, names in _imports(tree, package, type_checking, calls=calls):
            if not module.startswith("pkm"):
                continue
            targets = [f"{module}.{n}" for n in names if f"{module}.{n}" in modules]
            if len(targets) < len(names) or not names:
                targets.append(module)
            graph[name] |= {t for t in targets if t in modules and t != name}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def strong(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
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
                out.append(sorted(comp))

    import sys

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10_000))
    try:
        for v in sorted(graph):
            if v not in index:
                strong(v)
    finally:
        sys.setrecursionlimit(limit)
    return out


def test_the_graph_is_read():
    graph = import_graph()
    assert "pkm.core.kinematics.solve" in graph and "pkm.core.model.mechanism" in graph["pkm.core.kinematics.solve"]


def test_there_is_no_import_cycle():
    found = cycles(import_graph())
    assert not found, "import cycles (deferred imports count):\n" + "\n".join(" <-> ".join(c) for c in found)


def core_graph() -> dict[str, set[str]]:
    """The core's own graph (``pkm.core`` and its modules, the edges between them), ``TYPE_CHECKING`` imports and
    deferred ones included."""
    return {m: {t for t in targets if t.startswith("pkm.core")}
            for m, targets in import_graph(type_checking=True).items() if m.startswith("pkm.core")}


def test_the_core_has_no_cycle_even_through_annotations_and_deferred_imports():
    """The mechanism imports neither its task map nor its scales (they import it), the twin not its task."""
    graph = core_graph()
    found = cycles(graph)
    assert not found, "import cycles in pkm.core (TYPE_CHECKING and deferred imports count):\n" + \
        "\n".join(" <-> ".join(c) for c in found)
    mechanism = graph["pkm.core.model.mechanism"]
    assert {"pkm.core.model.actuators", "pkm.core.model.spec"} <= mechanism  # (the graph is read)
    assert not mechanism & {"pkm.core.kinematics.task", "pkm.core.model.scale", "pkm.core.model.builder"}
    assert "pkm.core.model.mechanism" in graph["pkm.core.kinematics.task"] & graph["pkm.core.model.scale"]
    assert "pkm.core.twin.task" not in graph["pkm.core.twin.tree"]
    assert "pkm.core.twin.tree" in graph["pkm.core.twin.task"]


def test_an_annotation_s_import_is_an_edge_only_when_asked():
    tree = ast.parse("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkm.core.model import scale\n"
                     "def f():\n    import pkm.core.kinematics.task\n")
    assert _imports(tree, "pkm.core.model") == [("typing", ["TYPE_CHECKING"]), ("pkm.core.kinematics.task", [])]
    assert ("pkm.core.model", ["scale"]) in _imports(tree, "pkm.core.model", type_checking=True)


def test_a_literal_import_module_is_an_edge():
    tree = ast.parse('import importlib\ndef f():\n    return importlib.import_module("pkm.core.model.builder")\n')
    assert ("pkm.core.model.builder", []) in _imports(tree, "pkm.core.model")


def test_the_statements_alone_hold_every_import_statement():
    """calls=False (a source without ``import_module``) finds the imports nested in classes, functions, ``with``,
    ``for``, ``try``'s handlers and ``else``, and ``match``'s cases, as the whole walk does."""
    tree = ast.parse("class C:\n    def g(self):\n        with x:\n            for i in y:\n                try:\n"
                     "                    import pkm.a\n                except E:\n                    from pkm import b\n"
                     "                else:\n                    import pkm.c\nmatch v:\n    case 1:\n        import pkm.d\n")
    assert _imports(tree, "pkm", calls=False) == _imports(tree, "pkm") == \
        [("pkm.a", []), ("pkm", ["b"]), ("pkm.c", []), ("pkm.d", [])]


def test_a_planted_cycle_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


#: What the core may not import: the faces (command line, service, previews, report, benchmarks, sweeps) and the
#: paper studies. The core is what they are built on.
ABOVE_THE_CORE = ("pkm.papers", "pkm.cli", "pkm.serve", "pkm.viz", "pkm.report", "pkm.bench", "pkm.sweeps",
                  "pkm.mechanisms")


def test_the_core_imports_no_face_and_no_paper():
    graph = import_graph()
    found = sorted(f"{m} -> {t}" for m, targets in graph.items() if m.startswith("pkm.core")
                   for t in targets if t.startswith(ABOVE_THE_CORE))
    assert found == []
