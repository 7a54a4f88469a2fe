"""Names of a package imported on first use (PEP 562), so that importing the package stays cheap."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy(package: str, namespace: dict[str, Any], where: Mapping[str, str]) -> tuple[Callable[[str], Any],
                                                                                     Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package`` whose name ``n`` lives in module ``where[n]``; a name is
    imported once, then kept in the package's ``namespace``."""

    def getattr_(name: str) -> Any:
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(where[name]), name)
        namespace[name] = value
        return value

    def dir_() -> list[str]:
        return sorted(set(namespace) | set(where))

    return getattr_, dir_


def delegate(module: str) -> Callable[[str], Any]:
    """``__getattr__`` for a package whose names (private ones included) are those of its main ``module``, imported
    on first use (so that importing one of the package's other modules does not import it)."""

    def getattr_(name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(importlib.import_module(module), name)

    return getattr_
