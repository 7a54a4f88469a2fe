"""Deprecated aliases: the former name of a renamed keyword, field or function still works, with a
:class:`DeprecationWarning` naming the new one. (The old import paths of the modules that moved into pkm.core's
concept packages in 0.2.0, ``pkm.core.solve``..., are gone: import them from their packages.)"""

from __future__ import annotations

import functools
import sys
import warnings
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, TypeVar, cast

from pkm.errors import InvalidInputError

T = TypeVar("T")
F = TypeVar("F", bound=Callable[..., Any])
C = TypeVar("C", bound=type)

#: The release that renamed what :func:`renamed` warns about; the former names go in the release after it.
RENAMED_IN = "0.2.0"


def renamed(what: str, old: str, new: str) -> None:
    """Warn that ``old`` (a keyword, field or function of ``what``) is now called ``new``: a
    :class:`DeprecationWarning` attributed to the innermost caller outside pkm (the user's line, which Python's
    default filters show when it is ``__main__``'s: a script, the ``pkm`` command)."""
    warnings.warn(f"{what}: {old!r} is now {new!r} (pkm {RENAMED_IN}); the old name goes in the next release",
                  DeprecationWarning, stacklevel=_outside_pkm())


def _outside_pkm() -> int:
    """The ``stacklevel`` that :func:`renamed`'s :func:`warnings.warn` needs to name the innermost frame outside pkm
    (the outermost frame when every one is pkm's)."""
    level, frame = 2, sys._getframe(2)  # 2: renamed's caller (1: renamed)
    while frame.f_back is not None and str(frame.f_globals.get("__name__", "")).partition(".")[0] == "pkm":
        level, frame = level + 1, frame.f_back
    return level


def renamed_keywords(what: str, kwargs: Mapping[str, T], names: Mapping[str, str]) -> dict[str, T]:
    """``kwargs`` with each former name of ``names`` (old -> new) replaced by the new one, in place (the order
    kept), a :func:`renamed` warning each.

    Raises:
        InvalidInputError: a former name given together with its new one.
    """
    for old in [k for k in kwargs if k in names]:
        new = names[old]
        if new in kwargs:
            raise InvalidInputError(old, f"{old!r} is the former name of {new!r}: give {new!r} only", kwargs[old])
        renamed(what, old, new)
    return {names.get(k, k): v for k, v in kwargs.items()}


def renamed_keyword(**names: str) -> Callable[[F], F]:
    """Decorator: the function still takes the former names of its keywords (``old="new"``), with a
    :func:`renamed` warning; its signature (``inspect.signature``) is the new one, and a cached function keeps its
    ``cache_clear``."""

    def wrap(func: F) -> F:
        what = f"{func.__module__}.{func.__qualname__}"

        @functools.wraps(func)
        def inner(*args: Any, **kwargs: Any) -> Any:
            if kwargs and not names.keys().isdisjoint(kwargs):
                kwargs = renamed_keywords(what, kwargs, names)
            return func(*args, **kwargs)

        for name in ("cache_clear", "cache_info", "cache_parameters"):  # a functools.cache'd function's own
            if hasattr(func, name):
                setattr(inner, name, getattr(func, name))
        return cast(F, inner)

    return wrap


def renamed_fields(**names: str) -> Callable[[C], C]:
    """Class decorator (above ``@dataclass``): the generated ``__init__`` still takes the former names of fields
    (``old="new"``), with a :func:`renamed` warning; the class's ``RENAMED`` maps them (old -> new) for the callers
    that look fields up by name (:func:`pkm.design_params`, the command line's ``--param``, sweeps)."""

    def wrap(cls: C) -> C:
        init = cls.__init__  # type: ignore[misc]

        @functools.wraps(init)
        def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
            if kwargs and not names.keys().isdisjoint(kwargs):
                kwargs = renamed_keywords(cls.__name__, kwargs, names)
            init(self, *args, **kwargs)

        cls.__init__ = __init__  # type: ignore[misc]
        cls.RENAMED = MappingProxyType({**getattr(cls, "RENAMED", {}), **names})  # type: ignore[attr-defined]
        return cls

    return wrap


def current_name(cls: type, name: str) -> str:
    """The name of ``cls``'s field ``name`` now: the new one, with a :func:`renamed` warning, when ``name`` is a
    former one (``cls.RENAMED``, see :func:`renamed_fields`), else ``name``."""
    new = getattr(cls, "RENAMED", {}).get(name)
    if new is None:
        return name
    renamed(cls.__name__, name, new)
    return cast(str, new)


__all__ = ["RENAMED_IN", "current_name", "renamed", "renamed_fields", "renamed_keyword", "renamed_keywords"]
