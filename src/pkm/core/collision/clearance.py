r"""The clearance of a mechanism at a configuration: the signed distance between every pair of its bodies that
:class:`~pkm.core.collision.geometry.CollisionModel` checks (negative: they interpenetrate by that much), the
closest pair, the witness points, and the derivative of the smallest distance with respect to the actuated
coordinates along the closed loops.

**Distances.** coal (Pinocchio's collision library) on the convex shapes, signed: GJK where the shapes are apart,
EPA where they penetrate (the penetration depth), to :data:`~pkm.core.collision.geometry.GJK_RTOL` of the
characteristic length; a pair of
bodies is as close as its closest pair of shapes. Checked against MuJoCo's ``mj_geomDistance`` on the humanoid ankle's
capsules and box, and against a segment-to-segment distance on the Gough-Stewart's legs (tests).

**Gradient.** With :math:`p_a`, :math:`p_b` the closest pair's witness points (world frame) and :math:`n` the unit
normal from body a to body b, a motion :math:`v` of the joints changes the distance at the rate
:math:`\dot d = n^\top (J_b(p_b) - J_a(p_a)) v`, :math:`J_k(p)` the velocity Jacobian of the point of body k at
:math:`p`; on the closed loops :math:`v = G \dot q_a` (:func:`~pkm.core.differential.velocity.passive_map`), so
:math:`\partial d_{min} / \partial q_a = n^\top (J_b - J_a) G`. It is the derivative of the smallest distance where
one pair is the closest and its witness points are unique (the minimum of several pairs has a kink where two tie).
Checked against Richardson-extrapolated differences of the minimum along the closed manifold (tests).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.collision.geometry import CollisionModel
from pkm.core.kinematics.constraints import check_closed
from pkm.core.model.mechanism import LimitViolation, Mechanism, check_mechanism
from pkm.errors import InvalidInputError
from pkm.validation import bounded


@dataclass(frozen=True)
class Clearance:
    """The clearance of a mechanism at one closed configuration (:func:`clearance`).

    Attributes:
        pairs: ``{(body_a, body_b): signed distance [m]}`` of every pair checked (negative: penetration depth).
        witness: ``{(body_a, body_b): (point on body_a, point on body_b)}`` [m], world frame.
        normals: ``{(body_a, body_b): unit normal}`` from body_a towards body_b (world frame).
        minimum: The smallest distance [m].
        closest: The pair at :attr:`minimum`.
        q: The configuration (nq,).
        outside_limits: The joints ``q`` puts outside their stated position limits (empty: none).
        excluded: ``{(body_a, body_b): reason}``: the pairs not checked (:attr:`CollisionModel.excluded`).
    """

    pairs: Mapping[tuple[str, str], float]
    witness: Mapping[tuple[str, str], tuple[np.ndarray, np.ndarray]]
    normals: Mapping[tuple[str, str], np.ndarray]
    minimum: float
    closest: tuple[str, str]
    q: np.ndarray
    outside_limits: tuple[LimitViolation, ...]
    excluded: Mapping[tuple[str, str], str]
    _mech: Mechanism = field(repr=False, compare=False)

    @property
    def interferes(self) -> bool:
        """Whether two checked bodies interpenetrate (:attr:`minimum` < 0)."""
        return self.minimum < 0.0

    @functools.cached_property
    def gradient(self) -> np.ndarray:
        r""":math:`\partial\, d_{min} / \partial q_a` (na,) [m/rad, m/m] along the closed loops (module doc).

        Raises:
            SingularityError: ``q`` is a direct singularity (the passive map is undefined there).
        """
        return distance_gradient(self._mech, self.q, self.witness[self.closest], self.normals[self.closest],
                                 self.closest)


def _point_jacobian(mech: Mechanism, joint: int, p: np.ndarray) -> np.ndarray:
    """The velocity Jacobian (3 x nv) of the point of joint ``joint``'s body at world position ``p`` (the joint
    Jacobians computed)."""
    J = pin.getJointJacobian(mech.model, mech.data, joint, pin.LOCAL_WORLD_ALIGNED)
    r = p - mech.data.oMi[joint].translation
    return J[:3] - pin.skew(r) @ J[3:]


def distance_gradient(mech: Mechanism, q: np.ndarray, witness: tuple[np.ndarray, np.ndarray], normal: np.ndarray,
                      pair: tuple[str, str]) -> np.ndarray:
    """:math:`n^\\top (J_b(p_b) - J_a(p_a)) G` at the closed ``q`` (module doc)."""
    from pkm.core.differential.velocity import passive_map

    cm = CollisionModel.of(mech)
    ja, jb = (cm.body_joints[b] for b in pair)
    pin.computeJointJacobians(mech.model, mech.data, q)
    row = normal @ (_point_jacobian(mech, jb, witness[1]) - _point_jacobian(mech, ja, witness[0]))
    return np.asarray(row @ passive_map(mech, q), dtype=float)


def clearance(mech: Mechanism, q: ArrayLike) -> Clearance:
    """The signed distances between the bodies of ``mech`` at the closed configuration ``q`` (module doc).

    Args:
        mech: A mechanism whose files carry collision geometry (:mod:`pkm.core.collision.geometry`).
        q: A closed configuration (nq,); outside the stated joint limits it is answered, and said
            (:attr:`Clearance.outside_limits`).

    Raises:
        NoCollisionGeometryError: the files carry no collision geometry, or every pair is excluded.
        InvalidInputError: ``q`` not a configuration of ``mech`` (shape, finiteness, quaternions) or not closed.

    Examples:
        >>> import pkm
        >>> gs = pkm.load("gough_stewart")
        >>> c = pkm.clearance(gs, gs.q_reference)
        >>> c.closest, round(c.minimum, 4), c.interferes
        (('rod_2', 'rod_3'), 0.1652, False)
    """
    mech = check_mechanism(mech)
    cm = CollisionModel.of(mech).require()
    q = mech.check_q(q)
    check_closed(mech, q)
    d = cm.distances(q).tolist()
    results = cm.data.distanceResults
    n = len(cm.pairs)
    best, at = [math.inf] * n, [0] * n
    for k, p in enumerate(cm.pair_of.tolist()):
        if d[k] < best[p]:
            best[p], at[p] = d[k], k
    pairs, witness, normals = {}, {}, {}
    for p, pair in enumerate(cm.pairs):
        k = at[p]
        r = results[k]
        pa, pb, normal = r.getNearestPoint1().copy(), r.getNearestPoint2().copy(), r.normal.copy()
        if cm.flipped[k]:  # (the shape pair's first shape is on body_b)
            pa, pb, normal = pb, pa, -normal
        pairs[pair] = best[p]
        witness[pair] = (pa, pb)
        normals[pair] = normal
    p_min = int(np.argmin(best))
    return Clearance(pairs, witness, normals, float(best[p_min]), cm.pairs[p_min], q.copy(),
                     mech.limit_violations(q), dict(cm.excluded), mech)


def clearance_map(mech: Mechanism, nodes: ArrayLike) -> np.ndarray:
    """The smallest signed distance [m] between checked bodies (:func:`clearance`'s ``minimum``) at each of
    ``nodes`` (N x nq configurations, evaluated as given: their loops are not checked here; their coordinates
    bounded and their quaternions of unit norm, as :meth:`~pkm.core.Mechanism.check_q`), for interference maps:
    negative where bodies interpenetrate.

    Raises:
        NoCollisionGeometryError: as :func:`clearance`.
        InvalidInputError: ``nodes`` not N x nq finite numbers, a coordinate beyond 1e6, a quaternion not of unit
            norm.
        NonFiniteError: coal's GJK fails on a pair with and without Nesterov's acceleration
            (:meth:`~pkm.core.collision.geometry.CollisionModel.compute`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> from pkm.core.collision import clearance_map
        >>> gs = pkm.load("gough_stewart")
        >>> nodes = [pkm.close_loops(gs, gs.actuated_q(gs.q_reference) + dq).q for dq in (0.0, 0.05)]
        >>> np.round(clearance_map(gs, nodes), 4)
        array([0.1652, 0.1652])
    """
    mech = check_mechanism(mech)
    cm = CollisionModel.of(mech).require()
    try:
        Q = np.asarray(nodes, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError("nodes", f"expected N x {mech.nq} configurations", nodes) from None
    if Q.ndim != 2 or Q.shape[1] != mech.nq or not np.all(np.isfinite(Q)):
        raise InvalidInputError("nodes", f"expected N x {mech.nq} finite configurations, got shape {Q.shape}", nodes)
    bounded(Q, "nodes", nodes)
    for name, start in cm.quaternions if len(Q) else ():  # (as Mechanism.check_q, for every node at once)
        norm = np.linalg.norm(Q[:, start:start + 4], axis=1)
        k = int(np.argmax(np.abs(norm - 1.0)))
        if abs(norm[k] - 1.0) > 1e-6:
            raise InvalidInputError("nodes", f"node {k}: the quaternion of joint {name!r} has norm {norm[k]:.6g}, "
                                             "expected 1", nodes)
    results, compute = cm.data.distanceResults, cm.compute
    out = np.empty(len(Q))
    for i, q in enumerate(Q):  # (the closest pair's result alone is read)
        out[i] = results[compute(q)].min_distance
    return out


__all__ = ["Clearance", "clearance", "clearance_map", "distance_gradient"]
