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
    assert sorted(pkm.core.__all__) == sorted(pkm.core._WHERE)  # the literal list names every lazy export
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        pkm.nothing  # noqa: B018
