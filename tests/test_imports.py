"""``import pkm`` and the pure-numpy modules stay cheap: Pinocchio and the other heavy libraries load only when used."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEAVY = ("pinocchio", "yourdfpy", "trimesh", "scipy", "lxml", "casadi", "matplotlib", "meshcat", "proxsuite")


@pytest.mark.parametrize("module", ["pkm", "pkm.core.differential.screws", "pkm.core.differential.indices", "pkm.validation", "pkm.mechanisms"])
def test_importing_loads_no_heavy_library(module):
    code = f"import sys, {module}; print(' '.join(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r}))))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.split()
    assert out == [], f"import {module} loads {out}"


def test_the_lazy_names_resolve():
    """The names ``pkm`` and ``pkm.core`` export lazily are the objects of their modules."""
    import pkm
    from pkm.core.kinematics import solve, task

    assert pkm.solve_ik is solve.solve_ik and pkm.core.TaskMap is task.TaskMap
    assert "close_loops" in dir(pkm) and "zyx_matrix" in dir(pkm.core)
    assert set(pkm.core.__all__) == set(pkm.core._WHERE)  # (derived from the one declaration)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        pkm.nothing  # noqa: B018


@pytest.mark.parametrize("package", ["pkm", "pkm.core", "pkm.core.formats"])
def test_the_static_view_of_the_lazy_names_is_the_declaration(package):
    """Each lazy package declares its public names once (``_WHERE``: name -> module); its ``TYPE_CHECKING`` block,
    which type checkers read, imports exactly those names from exactly those modules."""
    import ast
    import importlib

    mod = importlib.import_module(package)
    tree = ast.parse(open(mod.__file__).read())
    block = next(n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", "") == "TYPE_CHECKING")
    static = {a.asname or a.name: node.module for node in block.body if isinstance(node, ast.ImportFrom)
              and node.module.startswith("pkm") for a in node.names}
    where = dict(mod._WHERE)
    if package == "pkm":  # (the core's names reach pkm through pkm.core's own table)
        static = {n: where[n] if m == "pkm.core" else m for n, m in static.items()}
    assert static == where
    assert set(where) <= set(mod.__all__)


#: The flat paths of the modules that moved into pkm.core's concept packages in 0.2.0 (deprecated aliases until
#: they were removed): old name -> the package it lives in.
MOVED = {"compare": "model", "joints": "model", "mechanism": "model", "spec": "model", "urdf": "model",
         "configuration": "kinematics", "constraints": "kinematics", "newton": "kinematics", "solve": "kinematics",
         "task": "kinematics", "trajectory": "kinematics", "indices": "differential", "screws": "differential",
         "maps": "analysis", "reconfiguration": "analysis", "redundant_parameter": "analysis"}


def test_the_moved_modules_are_found_at_their_packages_only():
    from importlib.util import find_spec

    assert [old for old, pkg in MOVED.items() if find_spec(f"pkm.core.{pkg}.{old}") is None] == []
    assert [old for old in MOVED if find_spec(f"pkm.core.{old}") is not None] == []
