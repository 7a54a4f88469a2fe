"""Every third-party module that ``src/pkm`` imports is declared in ``pyproject.toml``.

A module that arrives only as another package's dependency (scipy through proxsuite, umsgpack
through meshcat) works until that package drops it; so every import must name its own distribution.
A benchmark baseline (the ``bench`` extra, MuJoCo) may be imported by ``pkm/bench`` alone, and the optional
homotopy solver (the ``homotopy`` extra, Bertini 2, GPL-3) by ``pkm/core/modes/continuation.py`` alone.
"""

from __future__ import annotations

import ast
import functools
import re
import sys
import tomllib
from importlib.metadata import distributions, packages_distributions
from importlib.util import find_spec
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def imported_modules(src: Path) -> dict[str, set[str]]:
    """Top-level names of the absolute imports under ``src`` (anywhere in a module), with the files."""
    found: dict[str, set[str]] = {}
    for path in sorted(src.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for n in names:
                found.setdefault(n.split(".")[0], set()).add(str(path.relative_to(src.parent)))
    return found


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
    return {_canonical(d.metadata["Name"]) for d, f in _files_by_name().get(origin.name, ())
            if Path(d.locate_file(f)).resolve() == origin}


@functools.cache
def _packages() -> dict:
    return packages_distributions()


@functools.cache
def _files_by_name() -> dict[str, list]:
    """Every installed distribution's files by file name (one pass: some distributions list tens of thousands)."""
    out: dict[str, list] = {}
    for d in distributions():
        for f in d.files or ():
            out.setdefault(f.name, []).append((d, f))
    return out


def _names(requirements) -> set[str]:
    return {_canonical(re.split(r"[\s<>=!~;\[]", d, maxsplit=1)[0]) for d in requirements}


def declared() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    return _names(project["dependencies"])


def extra(name: str) -> set[str]:
    """An optional extra's distributions (``bench``: baselines only ``pkm/bench`` may import)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    return _names(project["optional-dependencies"][name])


def test_every_third_party_import_is_a_declared_dependency():
    third_party = {m: files for m, files in imported_modules(ROOT / "src" / "pkm").items()
                   if m not in sys.stdlib_module_names and m not in ("pkm", "__future__")}
    assert {"numpy", "pinocchio", "casadi"} <= set(third_party)  # the scan sees the imports
    deps, bench, homotopy = declared(), extra("bench"), extra("homotopy")
    missing = {}
    for mod, files in sorted(third_party.items()):
        if _canonical(mod) in bench:
            assert all(f.startswith("pkm/bench/") for f in files), (mod, sorted(files))
            continue
        if owners(mod) & homotopy:
            assert sorted(files) == ["pkm/core/modes/continuation.py"], (mod, sorted(files))
            continue
        dists = owners(mod)
        assert dists, f"{mod!r} (imported by {sorted(files)}) belongs to no installed distribution"
        if not dists & deps:
            missing[mod] = (sorted(dists), sorted(files))
    assert not missing, f"imported but not declared in pyproject.toml [project] dependencies: {missing}"


def test_the_scan_catches_an_undeclared_import(tmp_path):
    """A module importing scipy inside a function is found (the scan is not limited to the top)."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "m.py").write_text("def f():\n    from scipy.optimize import brentq\n    import os\n")
    assert set(imported_modules(tmp_path / "pkg")) == {"scipy", "os"}
