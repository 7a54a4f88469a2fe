"""The kinematics of a mechanism at one configuration, computed once: closure residual and Jacobian, task value
and Jacobian.

A :class:`Configuration` is an immutable snapshot of numpy arrays, made by one pass of Pinocchio's
kinematics (``computeJointJacobians`` + ``updateFramePlacements``) into the calling thread's data. It
keeps no reference to that data: any number of them can be alive at once, in any thread, and what
one reads does not depend on what was computed before (the solvers and the differential analyses
build one per configuration instead of reading ``mech.data`` after a call that filled it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.kinematics import constraints
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism


@dataclass(frozen=True, eq=False)
class Configuration:
    """A mechanism's kinematics at ``q``.

    Attributes:
        mech: The mechanism.
        q: The configuration (nq,), a copy.
        residual: Closure residual (n_constraints,) [m, rad] (:func:`pkm.core.kinematics.constraints.residual`).
        constraint_jacobian: ``d(residual)/dq`` on the tangent space (n_constraints x nv).
        task_value: Task coordinates (:meth:`pkm.core.TaskMap.value`).
        task_jacobian: ``d(task)/dq`` on the tangent space (n_task x nv).
        ee_jacobian: The end-effector frame's Jacobian, ``[v; w]`` of its origin in world axes (6 x nv).
    """

    mech: Mechanism
    q: np.ndarray
    residual: np.ndarray
    constraint_jacobian: np.ndarray
    task_value: np.ndarray
    task_jacobian: np.ndarray
    ee_jacobian: np.ndarray

    def __post_init__(self) -> None:
        for value in vars(self).values():  # (an immutable snapshot: its arrays cannot be written to either)
            if isinstance(value, np.ndarray):
                value.setflags(write=False)

    @classmethod
    def at(cls, mech: Mechanism, q: ArrayLike) -> Configuration:
        """The kinematics of ``mech`` at ``q`` (checked: size, finiteness, unit quaternions)."""
        mech = check_mechanism(mech)
        return cls.compute(mech, mech.check_q(q))

    @classmethod
    def compute(cls, mech: Mechanism, q: np.ndarray) -> Configuration:
        """:meth:`at` without the checks, for callers that have checked ``q`` (the solvers' iterations)."""
        m, d = mech.model, mech.data
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        task = TaskMap.of(mech)
        return cls(mech, np.array(q, dtype=float), constraints.residual_from(mech, d),
                   constraints.jacobian_from(mech, d), task.value_from(d, q), task.jacobian_from(d),
                   pin.getFrameJacobian(m, d, mech.ee_frame, pin.LOCAL_WORLD_ALIGNED))

    @property
    def closure_and_task_jacobian(self) -> np.ndarray:
        """``[J_c; J_t]`` ((n_constraints + n_task) x nv): its column rank is lost at inverse singularities."""
        return np.vstack([self.constraint_jacobian, self.task_jacobian])


__all__ = ["Configuration"]
