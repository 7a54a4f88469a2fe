"""Typing: every public function of ``pkm.core``, ``pkm.errors``, ``pkm.validation`` and ``pkm.units`` is fully annotated.

A public function is a module-level function or a method (of a class at any depth) whose name does not start with
``_``; it is fully annotated when every parameter other than ``self``/``cls`` (including ``*args``/``**kwargs``) and
the return carry an annotation. mypy enforces the same (``disallow_untyped_defs`` on ``pkm.core.*`` in
``pyproject.toml``); this test reads the source with :mod:`ast`, so it needs neither mypy nor the imports.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src" / "pkm"



def _files() -> list[Path]:
    files = sorted((SRC / "core").rglob("*.py"))
    files += [SRC / "errors.py", SRC / "validation.py", SRC / "units.py"]
    return files


def _unannotated(fn: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> list[str]:
    """Names of ``fn``'s parameters lacking an annotation (``return`` for the return)."""
    a = fn.args
    params = [*a.posonlyargs, *a.args]
    if method and params and params[0].arg in ("self", "cls"):
        params = params[1:]
    params += a.kwonlyargs
    params += [p for p in (a.vararg, a.kwarg) if p is not None]
    missing = [p.arg for p in params if p.annotation is None]
    if fn.returns is None:
        missing.append("return")
    return missing


def _public_functions(body: list[ast.stmt], prefix: str, method: bool):  # -> Iterator[(qualname, node, method)]
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith("_"):
            yield f"{prefix}{node.name}", node, method
        elif isinstance(node, ast.ClassDef):
            yield from _public_functions(node.body, f"{prefix}{node.name}.", True)
        elif isinstance(node, ast.If):  # e.g. ``if TYPE_CHECKING:`` blocks, platform branches
            yield from _public_functions(node.body + node.orelse, prefix, method)


def _missing_annotations() -> list[str]:
    out = []
    for path in _files():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        rel = path.relative_to(SRC).as_posix()
        for name, fn, method in _public_functions(tree.body, "", False):
            missing = _unannotated(fn, method)
            if missing:
                out.append(f"{rel}:{fn.lineno} {name}: {', '.join(missing)}")
    return out


def test_the_scanned_files_exist() -> None:
    files = _files()
    assert len(files) > 40
    assert all(f.is_file() for f in files)


def test_every_public_function_is_fully_annotated() -> None:
    missing = _missing_annotations()
    assert not missing, f"{len(missing)} public functions lack annotations:\n" + "\n".join(missing)
