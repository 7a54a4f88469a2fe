"""Deprecated aliases of moved modules: the old import path gives the module at its new home, with a warning."""

from __future__ import annotations

import importlib
import sys
import warnings


def alias(old: str, new: str) -> None:
    """Make module ``old`` (being imported) the module ``new``, with a :class:`DeprecationWarning` naming it."""
    warnings.warn(f"{old} moved to {new} (pkm 0.2.0); import it from there", DeprecationWarning, stacklevel=3)
    sys.modules[old] = importlib.import_module(new)


__all__ = ["alias"]
