"""Kinetostatic indices of the reconfigurable hexapod: ``w_rot``, ``w_tras`` (eqs. 34-37), condition numbers.

Following the paper (sec. 4, after Ueberle et al. 2004), the Jacobian of the base model,
``J = (J_x^T DELTA)^-1 J_q`` (eq. 37: ``J'_q`` left out, i.e. ``beta`` held fixed), maps the six
arm rates to the platform twist ``[w; v]`` and is split into its rotation rows ``J_rot`` and its
translation rows ``J_tras`` (eq. 34); then ``w_rot = sqrt(det(J_rot J_rot^T))`` (eq. 35, [1]) and
``w_tras = sqrt(det(J_tras J_tras^T))`` (eq. 36, [m^3]).

Which point's velocity ``v`` is: the paper's twists are referred to the origin O (screw
convention: ``v`` is the velocity of the platform point passing through O), and so is
``w_tras`` by default (``point="O"``); ``point="P"`` uses the velocity of the platform centre P,
``v_P = v_O + w x P``. ``w_rot`` does not depend on the point.

Condition numbers (:mod:`pkm.core.differential.indices`, spectral): ``kappa_rot`` of ``J_rot`` and
``kappa_tras`` of ``J_tras`` (each homogeneous in units), and ``kappa`` of the whole ``J`` with
its rotation rows multiplied by a characteristic length (default: the arm length ``LA``, so that
``w LA`` compares with the speed ``alpha_dot LA`` of the elbows).

Batches: :class:`PoseIndex` evaluates an index for many (pose, beta) pairs at once with the
closed-form inverse kinematics and the screw Jacobians (:mod:`pkm.mechanisms.hexapod.screws`),
which is what the beta selection (:mod:`pkm.mechanisms.hexapod.reconfiguration`) calls; the tests
check it against the generic core.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from pkm.core.differential import indices as core_indices
from pkm.core.differential import screws
from pkm.core.kinematics.task import as_rotation
from pkm.errors import InvalidInputError
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms._common import check_params
from pkm.mechanisms.hexapod import screws as hs
from pkm.validation import as_scalar, as_vector

#: Index names accepted by :class:`PoseIndex` and the beta selection.
INDICES = ("w_rot", "w_tras")
POINTS = ("O", "P")


@dataclass(frozen=True)
class Indices:
    """The indices of one configuration.

    Attributes:
        w_rot: Rotational manipulability (eq. 35) [1].
        w_tras: Translational manipulability (eq. 36) [m^3], at ``point``.
        kappa_rot: Condition number of ``J_rot``.
        kappa_tras: Condition number of ``J_tras``.
        kappa: Condition number of ``J`` with its rotation rows times ``length``.
        point: ``"O"`` or ``"P"``.
        length: The characteristic length of ``kappa`` [m].
    """

    w_rot: float
    w_tras: float
    kappa_rot: float
    kappa_tras: float
    kappa: float
    point: str
    length: float


def base_jacobian(params: hx.HexapodParams, R, P, beta: float, branch=hx.DEFAULT_BRANCH,
                  point: str = "O") -> np.ndarray:
    """``J = (J_x^T DELTA)^-1 J_q`` of eq. (37): twist ``[w; v]`` per arm rate, ``beta`` fixed, (6, 6)."""
    return hs.jacobians(params, R, P, beta, branch).twist_jacobian(_point(point))[:, :6]


def indices(params: hx.HexapodParams, R, P, beta: float, branch=hx.DEFAULT_BRANCH, point: str = "O",
            length: float | None = None) -> Indices:
    """``w_rot``, ``w_tras`` and the condition numbers at a platform pose and ``beta`` [rad].

    Raises:
        UnreachableError: a leg cannot reach; SingularityError: ``J_x`` is singular.
    """
    J = base_jacobian(params, R, P, beta, branch, point)
    L = params.LA if length is None else as_scalar(length, "length", low=0.0, strict_low=True, unit="m")
    return Indices(float(core_indices.manipulability(J[:3])), float(core_indices.manipulability(J[3:])),
                   float(core_indices.condition_number(J[:3])), float(core_indices.condition_number(J[3:])),
                   float(core_indices.condition_number(core_indices.homogenize(J, slice(0, 3), L))), point, L)


class PoseIndex:
    """An index over a list of poses, vectorised over (pose, beta) pairs.

    ``PoseIndex(params, poses, "w_rot")(k, beta)`` is the index of pose ``k`` at ``beta`` [rad];
    ``k`` and ``beta`` are arrays of one shape. Where a leg cannot reach, the value is 0 (the
    manipulabilities tend to 0 at the edge of reachability, where an arm and its rod align).

    Args:
        params: The design.
        poses: Sequence of ``(R, P)`` (rotation, position [m]); each rotation is checked by
            :func:`pkm.mechanisms.hexapod.as_rotation`.
        index: One of :data:`INDICES`.
        branch: Working mode, for all legs or one per leg.
        point: ``"O"`` or ``"P"`` for ``w_tras``.
    """

    def __init__(self, params: hx.HexapodParams, poses, index: str = "w_rot", branch=hx.DEFAULT_BRANCH,
                 point: str = "O"):
        check_params(params, hx.HexapodParams)
        if not isinstance(index, str) or index not in INDICES:
            raise InvalidInputError("index", f"use one of {list(INDICES)}, got {index!r}", index)
        self.params, self.index, self.point = params, index, _point(point)
        self.signs = np.array([-hx.BRANCHES[b] for b in hx.branch_names(branch)], dtype=float)
        Rs, Ps = [], []
        if isinstance(poses, (str, bytes, np.ndarray)) or not isinstance(poses, Iterable):
            raise InvalidInputError("poses", f"expected a sequence of (R, P) pairs, got {type(poses).__name__}", poses)
        for j, pose in enumerate(poses):
            try:
                R, P = pose
            except (TypeError, ValueError):
                raise InvalidInputError("poses", f"pose {j}: expected a pair (R, P)", pose) from None
            Rs.append(as_rotation(R, f"poses[{j}].R"))
            Ps.append(as_vector(P, 3, f"poses[{j}].P"))
        if not Rs:
            raise InvalidInputError("poses", "needs at least one pose", poses)
        self.R, self.P = np.array(Rs), np.array(Ps)
        self.C = np.array([hx.platform_points(params, R, P) for R, P in zip(Rs, Ps)])

    def __len__(self) -> int:
        return len(self.P)

    def legs(self, k, beta) -> hs.LegBatch:
        """The legs of poses ``k`` at ``beta`` (see :func:`pkm.mechanisms.hexapod.screws.leg_batch`)."""
        return hs.leg_batch(self.params, self.C[np.asarray(k)], beta, self.signs)

    def __call__(self, k, beta) -> np.ndarray:
        k, beta = np.asarray(k, dtype=int), np.asarray(beta, dtype=float)
        legs = self.legs(k, beta)
        M, jq, _ = hs.klein_rows(legs)
        J = np.linalg.inv(M) * jq[..., None, :]  # (J_x^T DELTA)^-1 diag(J_q)
        if self.index == "w_rot":
            X = J[..., :3, :]
        elif self.point == "O":
            X = J[..., 3:, :]
        else:
            X = np.swapaxes(screws.shift(np.swapaxes(J, -1, -2), self.P[k][..., None, :]), -1, -2)[..., 3:, :]
        w = np.sqrt(np.maximum(np.linalg.det(X @ np.swapaxes(X, -1, -2)), 0.0))
        return np.where(np.all(legs.margin >= 0.0, axis=-1), w, 0.0)


def _point(point: str) -> str:
    if not isinstance(point, str) or point not in POINTS:
        raise InvalidInputError("point", f"use 'O' (the paper's) or 'P', got {point!r}", point)
    return point


__all__ = ["INDICES", "POINTS", "Indices", "PoseIndex", "base_jacobian", "indices"]
