"""Differential kinematics: rate and acceleration maps, singularity diagnosis and the actuation's fit
(:mod:`~pkm.core.differential.velocity`), screws (:mod:`~pkm.core.differential.screws`) and condition indices
(:mod:`~pkm.core.differential.indices`).

The names of :mod:`~pkm.core.differential.velocity` are importable from here too (``pkm.core.differential.velocity.X``), imported on first
use, so that ``import pkm.core.differential.velocity.<module>`` stays as cheap as that module.
"""

from __future__ import annotations

import importlib
from typing import Any


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    return getattr(importlib.import_module("pkm.core.differential.velocity"), name)
