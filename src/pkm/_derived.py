"""What a layer above a class derives from an instance of it, made once and kept with the instance, the class
importing none of it: a mechanism's task map (:meth:`pkm.core.kinematics.task.TaskMap.of`) and the factors that
homogenise its Jacobians (:meth:`pkm.core.model.scale.JacobianScales.of`), a twin's task
(:meth:`pkm.core.twin.task.TaskTwin.of`). The model stays below what is built on it: its module imports neither."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")

#: The attribute of an instance that holds what was derived from it (``{make: made}``); the instance drops it where
#: what it was derived from changes (:attr:`Mechanism.q_reference <pkm.core.model.mechanism.Mechanism.q_reference>`).
SLOT = "_derived"


def derived(owner: Any, make: Callable[[Any], T]) -> T:
    """``make(owner)``, made on the first call and kept with ``owner`` (its ``__dict__``), so that later calls give
    the same object. Two threads' first calls may each make one (as :func:`functools.cached_property`); one is kept."""
    cache: dict[Callable[[Any], Any], Any] = owner.__dict__.setdefault(SLOT, {})
    try:
        return cache[make]  # type: ignore[no-any-return]
    except KeyError:
        return cache.setdefault(make, make(owner))  # type: ignore[no-any-return]


__all__ = ["SLOT", "derived"]
