"""The modules that moved into pkm.core's concept packages (0.2.0) keep their old import paths, as deprecated
aliases: the same module object, with a DeprecationWarning naming the new home."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

MOVED = {"compare": "model", "joints": "model", "mechanism": "model", "spec": "model", "urdf": "model",
         "configuration": "kinematics", "constraints": "kinematics", "newton": "kinematics", "solve": "kinematics",
         "task": "kinematics", "trajectory": "kinematics", "indices": "differential", "screws": "differential",
         "maps": "analysis", "reconfiguration": "analysis", "redundant_parameter": "analysis"}


def test_an_old_path_is_the_new_module_with_a_warning():
    """In a fresh interpreter (where none is imported yet): each old path gives the new module, and warns."""
    code = f"""
import importlib, warnings
warnings.simplefilter("always")
for old, pkg in {MOVED!r}.items():
    new = f"pkm.core.{{pkg}}.{{old}}"
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        m = importlib.import_module(f"pkm.core.{{old}}")
    assert m is importlib.import_module(new), (old, m)
    assert any(issubclass(x.category, DeprecationWarning) and new in str(x.message) for x in w), (old, w)
"""
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_packages_at_old_paths_give_their_modules_names():
    """pkm.core.differential and pkm.core.dynamics are packages now; the names of the modules they were
    (differential.py, dynamics.py) are read from them as before."""
    differential = importlib.import_module("pkm.core.differential")
    dynamics = importlib.import_module("pkm.core.dynamics")
    velocity = importlib.import_module("pkm.core.differential.velocity")
    projection = importlib.import_module("pkm.core.dynamics.projection")
    assert differential.diagnose is velocity.diagnose and differential.actuation is velocity.actuation
    assert dynamics.KhalilProjection is projection.KhalilProjection and dynamics.partition is projection.partition
    with pytest.raises(AttributeError):
        differential.nothing_of_that_name  # noqa: B018
