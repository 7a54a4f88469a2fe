"""Every third-party module that ``src/pkm`` imports is declared in ``pyproject.toml``: in the core
(``[project] dependencies``, what ``pip install pkm-robotics`` gives) or in one extra (``pkm-robotics[sweeps]``,
``pkm-robotics[figures]``, ...).

A module that arrives only as another package's dependency (scipy through proxsuite, umsgpack
through meshcat) works until that package drops it; so every import must name its own distribution.
A module of an extra is imported inside functions only (never at a module's top level: ``import pkm`` and every
module of it import without the extras), by modules that check the extra first (:mod:`pkm._optional`, whose table
of extras is the one in ``pyproject.toml``); ``tests/test_extras.py`` runs the library with the extras blocked.
"""

from __future__ import annotations

import ast
import functools
import re
import sys
import tomllib
from collections.abc import Iterator
from importlib.metadata import distributions, packages_distributions
from importlib.util import find_spec
from pathlib import Path

from pkm.errors import DISTRIBUTION

ROOT = Path(__file__).resolve().parents[1]


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def imported_modules(src: Path) -> dict[str, set[str]]:
    """Top-level names of the absolute imports under ``src`` (anywhere in a module), with the files."""
    found: dict[str, set[str]] = {}
    for path in sorted(src.rglob("*.py")):
        for node in _statements(ast.parse(path.read_text(encoding="utf-8"), str(path)).body):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for n in names:
                found.setdefault(n.split(".")[0], set()).add(str(path.relative_to(src.parent)))
    return found


def _statements(body: list) -> Iterator[ast.AST]:
    """Every statement in ``body``, those nested in functions, classes and blocks too (an import is a statement:
    no need to walk the expressions, nine nodes in ten)."""
    for node in body:
        yield node
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            inner = getattr(node, field, None)
            if isinstance(inner, list):
                yield from _statements(inner)


def owners(module: str) -> set[str]:
    """The distributions that install ``module``: from their top-level names, else (packages such as
    pin that install under a prefix, ``cmeel.prefix/...``) the ones whose file lists hold its origin."""
    found = _packages().get(module)
    if found:
        return {_canonical(d) for d in found}
    spec = find_spec(module)
    if spec is None or not spec.origin:
        return set()
    origin = Path(spec.origin).resolve()
    found = set()
    for d, base, record in _records():  # (the origin's path in a distribution's RECORD: a text search, where
        # parsing every distribution's file list took 1.5 s)
        if origin.is_relative_to(base) and f"\n{origin.relative_to(base).as_posix()}," in record:
            found.add(_canonical(d.metadata["Name"]))
    return found


@functools.cache
def _packages() -> dict:
    return packages_distributions()


@functools.cache
def _records() -> list:
    """Every installed distribution, the folder its RECORD's paths are relative to, and its RECORD (a newline
    first, so that every line starts with one)."""
    return [(d, Path(d.locate_file("")).resolve(), "\n" + (d.read_text("RECORD") or "")) for d in distributions()]


def _names(requirements) -> set[str]:
    return {_canonical(re.split(r"[\s<>=!~;\[]", d, maxsplit=1)[0]) for d in requirements}


def declared() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    return _names(project["dependencies"])


def extra(name: str) -> set[str]:
    """An optional extra's distributions (those of ``dask[distributed]`` included: dask and distributed)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    reqs = project["optional-dependencies"][name]
    inner = {_canonical(x) for r in reqs if "[" in r for x in r.split("[", 1)[1].split("]", 1)[0].split(",")}
    return _names(reqs) | inner


#: Extras of tools, not of the library (no module of pkm imports them), and the one that installs all of them.
TOOLING = ("dev", "all", "docs", "contract")
#: Modules of pkm that import an extra's module without checking it themselves, each with its reason.
UNGUARDED = {
    "pkm/sweeps/store.py": "internal: its callers (pkm.sweep, SweepResult.read) check pkm-robotics[sweeps] first",
    "pkm/serve/wire.py": "internal: its callers (create_app, pkm.client.Client) check pkm-robotics[serve] first",
    "pkm/serve/schemas.py": "internal: its caller (create_app) checks pkm-robotics[serve] first",
}
#: Modules of pkm that import an extra's module when they are imported, each with its reason (all in UNGUARDED).
TOP_LEVEL = {
    "pkm/serve/schemas.py": "pydantic models are module-level classes; only create_app imports it, inside",
}


def top_level_imports(path: Path) -> set[str]:
    """Top-level names imported by the statements of ``path`` that run when it is imported (module body, its
    ``if``/``try`` blocks; ``if TYPE_CHECKING:`` blocks excepted), not inside functions or classes."""
    found: set[str] = set()

    def visit(body):
        for node in body:
            if isinstance(node, ast.Import):
                found.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
            elif isinstance(node, ast.If) and "TYPE_CHECKING" not in ast.unparse(node.test):
                visit(node.body)
                visit(node.orelse)
            elif isinstance(node, ast.Try):
                visit(node.body)
                for h in node.handlers:
                    visit(h.body)
                visit(node.orelse)
                visit(node.finalbody)

    visit(ast.parse(path.read_text(encoding="utf-8")).body)
    return found


def test_every_third_party_import_is_a_declared_dependency():
    third_party = {m: files for m, files in imported_modules(ROOT / "src" / "pkm").items()
                   if m not in sys.stdlib_module_names and m not in ("pkm", "__future__")}
    assert {"numpy", "pinocchio", "casadi"} <= set(third_party)  # the scan sees the imports
    deps = declared()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = {name: extra(name) for name in project["optional-dependencies"] if name not in TOOLING}
    missing, optional = {}, {}
    for mod, files in sorted(third_party.items()):
        dists = owners(mod) or {_canonical(mod)}  # (an extra's module may not be installed here: its own name)
        if dists & deps:
            continue
        holders = [name for name, d in extras.items() if dists & d]
        if holders:
            assert len(holders) == 1, f"{mod!r} is in several extras: {holders}"
            optional[mod] = (holders[0], files)
            continue
        assert owners(mod), f"{mod!r} (imported by {sorted(files)}) belongs to no installed distribution"
        missing[mod] = (sorted(dists), sorted(files))
    assert not missing, f"imported but not declared in pyproject.toml (core or an extra): {missing}"
    assert {"dask", "pyarrow", "matplotlib", "mujoco", "bertini"} <= set(optional), sorted(optional)
    src = ROOT / "src"
    for mod, (name, files) in sorted(optional.items()):
        for f in sorted(files):
            text = (src / f).read_text(encoding="utf-8")
            assert mod not in top_level_imports(src / f) or f in TOP_LEVEL, \
                f"{f} imports {mod} (pkm-robotics[{name}]) when it is imported"
            guarded = "pkm._optional" in text or "MissingDependencyError" in text or "unavailable" in text
            assert guarded or f in UNGUARDED, \
                f"{f} imports {mod} (pkm-robotics[{name}]) without checking the extra first (pkm._optional.require)"


def test_the_extras_table_is_pyprojects():
    """:data:`pkm._optional.EXTRAS` names the extras of ``pyproject.toml`` (tooling aside) and their distributions;
    ``all`` installs every one of them; the core declares none of them."""
    from pkm._optional import EXTRAS

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    named = [n for n in project["optional-dependencies"] if n not in TOOLING]
    assert named == list(EXTRAS)
    for name, modules in EXTRAS.items():
        assert {_canonical(d) for d in modules.values()} == extra(name), name
        assert not extra(name) & declared(), name
    (everything,) = project["optional-dependencies"]["all"]
    assert everything == f"{DISTRIBUTION}[{','.join(EXTRAS)}]"


def test_the_distribution_is_named_as_pip_installs_it():
    """``pyproject.toml``'s ``[project] name`` is :data:`pkm.errors.DISTRIBUTION` (``pkm`` on PyPI is another
    project), its extras refer to it by that name, and no document, example, tool or message of pkm tells to
    ``pip install pkm`` or ``pip install "pkm[...]"`` (which would install that other project)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["name"] == DISTRIBUTION != "pkm"
    selves = {r.split("[")[0] for reqs in project["optional-dependencies"].values() for r in reqs
              if _canonical(r.split("[")[0]) in ("pkm", _canonical(DISTRIBUTION))}
    assert selves == {DISTRIBUTION}, selves
    files = [ROOT / "README.md", ROOT / "pyproject.toml", ROOT / "Makefile", *sorted((ROOT / ".ci").iterdir())]
    for folder, pattern in (("docs", "*.md"), ("src", "*.py"), ("examples", "*.py"), ("examples", "*.md"),
                            ("tools", "*.py")):
        files += sorted((ROOT / folder).rglob(pattern))
    assert len(files) > 100 and ROOT / "src" / "pkm" / "_optional.py" in files
    found = [f"{f.relative_to(ROOT)}:{n}: {line.strip()}" for f in files if f.is_file()
             for n, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1) if OLD_NAME.search(line)]
    assert not found, "pip install of the other project's name:\n" + "\n".join(found)


#: ``pip install pkm``, ``pip install "pkm[x]"``, ``pip install 'pkm[x]'`` (not ``pkm-robotics``, not a path).
OLD_NAME = re.compile(r"pip3? install\s+(-\S+\s+)*[\"']?pkm(\[|[\"'`)\s]|$)")


def test_the_old_name_pattern_finds_what_it_is_for():
    said = ["pip install pkm", 'pip install "pkm[sweeps]"', "pip install pkm[bench])", "`pip install pkm`, no",
            "pip install --quiet 'pkm[all]'", "pip3 install pkm"]
    fine = [f"pip install {DISTRIBUTION}", f'pip install "{DISTRIBUTION}[sweeps]"', "pip install pkm-no-such",
            'pip install -e ".[dev,all]"', "pip install pkmx", "import pkm"]
    assert [bool(OLD_NAME.search(s)) for s in said + fine] == [True] * len(said) + [False] * len(fine)


def test_the_top_level_scan_skips_function_bodies(tmp_path):
    (tmp_path / "m.py").write_text("import numpy\ntry:\n    import yaml\nexcept ImportError:\n    pass\n"
                                   "if TYPE_CHECKING:\n    import dask\ndef f():\n    import matplotlib\n")
    assert top_level_imports(tmp_path / "m.py") == {"numpy", "yaml"}


def test_the_scan_catches_an_undeclared_import(tmp_path):
    """A module importing scipy inside a function is found (the scan is not limited to the top)."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "m.py").write_text("def f():\n    from scipy.optimize import brentq\n    import os\n"
                                          "class C:\n    def g(self):\n        with x:\n            for i in y:\n"
                                          "                try:\n                    pass\n"
                                          "                except E:\n                    import yaml\n"
                                          "                else:\n                    import dask\n"
                                          "match v:\n    case 1:\n        import lxml\n")
    assert set(imported_modules(tmp_path / "pkg")) == {"scipy", "os", "yaml", "dask", "lxml"}
    assert owners("pinocchio") == {"pin"}  # (installed under cmeel.prefix: found by its file in pin's RECORD)
