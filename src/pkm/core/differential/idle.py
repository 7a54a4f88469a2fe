"""The idle-motion convention: how much of each idle motion the joint rates and accelerations carry.

An *idle motion* (:func:`~pkm.core.differential.velocity.idle_motions`, basis ``N``, nv x k) moves neither the
closures, nor the task, nor the actuators: a rod spinning about its own axis between two ball joints. The kinematics
does not fix its rate or its acceleration; pkm fixes them by one rule, used by :func:`pkm.velocities`,
:func:`pkm.accelerations`, :func:`pkm.passive_map`, their inverse-kinematics twins, :func:`pkm.actuator_model` (hence
:func:`pkm.mass_matrix`, :func:`pkm.bias_efforts`, :func:`pkm.forward_dynamics`, :func:`pkm.simulate`) and the
compiled kernels' model (:class:`~pkm.core.twin.dynamics.ActuatorTwin`):

    **joint rates and accelerations carry no idle motion in the mass metric**: ``Nᵀ M v = 0`` and ``Nᵀ M a = 0``,

``M`` Pinocchio's joint-space mass matrix (``crba``). Among all the rates that give the same actuated rates, ``v``
is the one of least kinetic energy, so ``½ q̇ᵀ M_a q̇`` (``M_a = Ĝᵀ M Ĝ``, ``v = Ĝ q̇``) *is* the bodies' kinetic
energy; the spin carries no momentum of its own. For a rod whose inertia is symmetric about the line of its balls
(a cylinder, a point mass on the line) the spin is decoupled (``Nᵀ M Ĝ`` vanishes with the Euclidean choice too) and
the rule gives it zero rate. The efforts do not depend on the idle accelerations at all (``Ĝᵀ M N = 0``: an idle
acceleration changes no actuator effort), so the rule for ``a`` is only what the functions report for the idle joints
(the physical acceleration of an unforced spin, which Pinocchio's ``constraintDynamics`` gives, may differ).

A direction of ``N`` with no inertia (an axial inertia of exactly zero: a massless rod, a point mass on the axis) is
*massless*: the rule cannot fix it, and its rate and acceleration are then zero in the Euclidean metric (the
minimum-norm choice). Massless means an eigenvalue of ``Nᵀ M N`` at most :data:`MASSLESS` times the largest diagonal
entry of ``M`` (the rounding of ``Nᵀ M N`` is about 1e-16 of it; the lightest idle rod of Gepetto's robots, a few
grams, is 7e-8 of it on ``talos_like``).
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from pkm.core.model.joints import has_mimic
from pkm.core.model.mechanism import Mechanism
from pkm.validation import finite_result

#: An idle direction whose inertia is at most this times the largest diagonal entry of ``M`` is massless.
MASSLESS = 1e-12


def joint_inertia(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Pinocchio's joint-space mass matrix ``M(q)`` (nv x nv, ``crba``, symmetric; the actuators' reflected inertia,
    Pinocchio's ``armature``, on its diagonal) [kg m^2, kg m, kg].

    With mimic joints, ``M``'s columns are RNEA's efforts for unit accelerations at rest (gravity's taken off), as
    MuJoCo's mass matrix of the same file gives them (7e-15 on ToddlerBot): Pinocchio 4.1's ``crba`` is wrong there.
    It keeps a state between calls on the same ``Data`` where a mimic joint has children and shares an ancestor with
    the joint it follows (UFACTORY's xArm7 gripper on its arm: the arm's rows of the follower's finger grew by 5.5e-4
    kg m^2 a call, the forward dynamics by 0.29 rad/s^2; ToddlerBot's actuator-space mass matrix by 15 % of its
    largest entry a call), and even on a fresh ``Data`` it leaves out ToddlerBot's neck yaw's coupling to the neck's
    pitch rods (2.2e-7 kg m^2)."""
    model, data = mech.model, mech.data
    if has_mimic(model):
        zero = np.zeros(model.nv)
        rest = pin.rnea(model, data, q, zero, zero).copy()
        M = np.column_stack([pin.rnea(model, data, q, zero, e) - rest for e in np.eye(model.nv)])
    else:
        M = pin.crba(model, data, q)  # (a copy of data.M: its upper triangle)
    lower = _lower(model.nv)
    M[lower] = M.T[lower]  # (the upper triangle mirrored: np.triu(M) + np.triu(M, 1).T, a fifth of its time)
    return finite_result(M, "joint-space mass matrix")


@functools.lru_cache(maxsize=64)
def _lower(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The indices of the strictly lower triangle of an n x n matrix."""
    return np.tril_indices(n, -1)


def idle_inertia_inverse(M: np.ndarray, N: np.ndarray) -> np.ndarray:
    """``(Nᵀ M N)⁺`` (k x k): the inverse of the idle motions' inertia, its massless directions (module doc) dropped."""
    w, U = np.linalg.eigh(N.T @ M @ N)
    keep = w > MASSLESS * max(float(np.max(np.diag(M), initial=0.0)), 1e-300)
    return (U[:, keep] / w[keep]) @ U[:, keep].T


def without_idle(M: np.ndarray, N: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Joint rates or accelerations ``X`` (nv, or nv x m) with their idle part removed in the mass metric:
    ``X - N (Nᵀ M N)⁺ Nᵀ M X``, so that ``Nᵀ M X = 0`` (a massless idle direction keeps the part ``X`` has)."""
    if not N.shape[1]:
        return X
    return X - N @ (idle_inertia_inverse(M, N) @ (N.T @ (M @ X)))


__all__ = ["MASSLESS", "idle_inertia_inverse", "joint_inertia", "without_idle"]
