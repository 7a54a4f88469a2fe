"""Interference in the workspace answers: the smallest signed distance between checked bodies at configurations a
map, a solver, a mode search or a plan's check points found, for mechanisms whose files carry collision geometry.

Every answer asks :func:`checks_collisions` first: a mechanism without collision geometry (or whose every pair is
excluded, :class:`~pkm.core.collision.geometry.CollisionModel`) is answered as before, with no interference field
(None) and no warning; one with geometry is answered with the smallest distance per configuration
(:func:`~pkm.core.collision.clearance.clearance_map`'s route: coal's closest pair, about 15-30 us a configuration on
the Gough-Stewart's 66 pairs) and, where one interferes, the pair (:func:`first_interference`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from pkm.core.collision.clearance import clearance_map
from pkm.core.collision.geometry import CollisionModel
from pkm.core.model.mechanism import Mechanism


def checks_collisions(mech: Mechanism) -> bool:
    """Whether ``mech`` has pairs of bodies to check (collision geometry read, not every pair excluded): the
    workspace answers report interference then, and only then. The collision model is made on first use and kept
    with the mechanism (:meth:`CollisionModel.of`)."""
    cm = CollisionModel.of(mech)
    return bool(cm.bodies) and bool(cm.pairs)


def minimum_distances(mech: Mechanism, Q: np.ndarray) -> np.ndarray:
    """The smallest signed distance [m] between checked bodies at each of ``Q`` (N x nq configurations: the callers' own
    solutions; a row with a NaN, an unreached node, gives NaN), negative where two interpenetrate."""
    Q = np.asarray(Q, dtype=float)
    out = np.full(len(Q), math.nan)
    finite = np.all(np.isfinite(Q), axis=1)
    if finite.any():
        out[finite] = clearance_map(mech, Q[finite])
    return out


class Interference(NamedTuple):
    """The first configuration of a sequence at which two checked bodies interpenetrate."""

    #: Its index in the sequence.
    at: int
    #: The signed distance of the closest pair there [m] (negative: the penetration depth).
    distance: float
    #: The pair ``(body_a, body_b)``.
    pair: tuple[str, str]


def first_interference(mech: Mechanism, Q: np.ndarray, minima: np.ndarray | None = None) -> Interference | None:
    """The first of ``Q`` (N x nq) where two checked bodies interpenetrate, with the closest pair there; None where
    none does (``minima``: :func:`minimum_distances` of ``Q``, when already computed)."""
    minima = minimum_distances(mech, Q) if minima is None else minima
    bad = np.flatnonzero(minima < 0.0)
    if not bad.size:
        return None
    k = int(bad[0])
    cm = CollisionModel.of(mech)
    d = cm.body_distances(np.asarray(Q[k], dtype=float))
    p = int(np.argmin(d))
    return Interference(k, float(d[p]), cm.pairs[p])


__all__ = ["Interference", "checks_collisions", "first_interference", "minimum_distances"]
