"""Dynamics: Khalil's projection of Pinocchio's RNEA onto the actuated joints, the virtual-work route, the
forward dynamics through ``constraintDynamics`` (:mod:`~pkm.core.dynamics.projection`).

The names of :mod:`~pkm.core.dynamics.projection` are importable from here too (``pkm.core.dynamics.projection.X``), imported on first
use, so that ``import pkm.core.dynamics.projection.<module>`` stays as cheap as that module.
"""

from __future__ import annotations

import importlib
from typing import Any


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    return getattr(importlib.import_module("pkm.core.dynamics.projection"), name)
