"""Finite-difference checks shared by the tests of the core and of the mechanisms.

Each function returns the relative error ``|A - A_fd| / |A_fd|`` (Frobenius) of an analytic
quantity against central differences, computed only through position-level solvers. The
differences are Richardson-extrapolated, ``(4 D(h/2) - D(h)) / 3``, so that their truncation
error is O(h^4): close to a singularity the O(h^2) error of a plain central difference is
amplified and would mask the comparison.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

import pkm
from pkm.core import TaskMap, close_loops
from pkm.core.kinematics import constraints


def richardson(diff: Callable[[float], np.ndarray], h: float) -> np.ndarray:
    """``(4 D(h/2) - D(h)) / 3`` for a central difference ``D``."""
    return (4.0 * diff(h / 2) - diff(h)) / 3.0


def rel(A, B) -> float:
    return float(np.linalg.norm(np.asarray(A) - np.asarray(B)) / max(np.linalg.norm(B), 1e-300))


def forward_jacobian_error(mech, q, h: float = 1e-6) -> float:
    """Forward Jacobian vs differences of the task over generic loop closures."""
    task, qa = TaskMap(mech), mech.actuated_q(q)

    def diff(hh):
        return np.column_stack([task.error(task.value(close_loops(mech, qa + e, q).q),
                                           task.value(close_loops(mech, qa - e, q).q)) / (2 * hh)
                                for e in hh * np.eye(mech.na)])
    return rel(pkm.forward_jacobian(mech, q), richardson(diff, h))


def inverse_jacobian_error(mech, q, ik: Callable[[np.ndarray], np.ndarray], h: float = 1e-6) -> float:
    """Inverse Jacobian vs differences of an inverse-kinematics function ``ik(y) -> q_actuated``."""
    task = TaskMap(mech)
    y = task.value(q)

    def diff(hh):
        return np.column_stack([(ik(task.retract(y, e)) - ik(task.retract(y, -e))) / (2 * hh)
                                for e in hh * np.eye(task.size)])
    return rel(pkm.inverse_jacobian(mech, q), richardson(diff, h))


def constraint_jacobian_error(mech, q, h: float = 1e-6) -> float:
    """Constraint Jacobian vs differences of the closure residual on the tangent space."""
    Jfd = np.column_stack([
        (constraints.residual(mech, pin.integrate(mech.model, q, e))
         - constraints.residual(mech, pin.integrate(mech.model, q, -e))) / (2 * h)
        for e in h * np.eye(mech.nv)])
    return rel(constraints.jacobian(mech, q), Jfd)


def acceleration_errors(mech, q, rng: np.random.Generator, h: float = 1e-6) -> dict[str, float]:
    """Joint and task accelerations vs differences of velocities along an actuated parabola."""
    qa = mech.actuated_q(q)
    qd, qdd = rng.normal(size=mech.na), rng.normal(size=mech.na)

    def state(t):
        qt = close_loops(mech, qa + t * qd + 0.5 * t * t * qdd, q).q
        return qt, pkm.velocities(mech, qt, qd + t * qdd)

    def diff(hh):  # joint and task velocity differences, stacked
        (qp, vp), (qm, vm) = state(hh), state(-hh)
        return np.concatenate([vp - vm, pkm.task_velocity(mech, qp, vp) - pkm.task_velocity(mech, qm, vm)]) / (2 * hh)

    fd = richardson(diff, h)
    v = pkm.velocities(mech, q, qd)
    a = pkm.accelerations(mech, q, v, qdd)
    ydd = pkm.task_acceleration(mech, q, v, a)
    return {
        "joint": rel(a, fd[:mech.nv]),
        "task": rel(ydd, fd[mech.nv:]),
        "closure": float(np.abs(constraints.jacobian(mech, q) @ a + constraints.drift(mech, q, v)).max()),
        "inverse": rel(pkm.inverse_accelerations(mech, q, v, ydd), a),
    }
