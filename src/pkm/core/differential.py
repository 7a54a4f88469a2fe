"""Velocity and acceleration kinematics of closed-loop mechanisms; singularity diagnostics.

With ``J_c`` the constraint Jacobian (:mod:`pkm.core.constraints`), split into
actuated columns ``J_a`` and passive columns ``J_p``, and ``J_t`` the task Jacobian
(:mod:`pkm.core.task`):

* passive rates: ``v_p = -J_p^+ J_a qd_a`` (``G = dq/dq_a``, :func:`passive_map`);
  undefined when ``J_p`` loses column rank: a *direct* (type 2) singularity, the
  actuators locked yet the mechanism movable;
* forward Jacobian ``J_fwd = J_t G`` (task rates from actuated rates);
* inverse Jacobian: ``[J_c; J_t] v = [0; yd]``, read on the actuated rows; undefined
  when ``[J_c; J_t]`` loses column rank: an *inverse* (type 1) singularity, the task
  frozen yet the joints movable;
* accelerations: ``J_c a + gamma_c = 0`` with the drift ``gamma_c = dJ_c/dt v``, and
  task accelerations ``J_t a + gamma_t``.

Rank decisions use singular values relative to the largest one (``rtol``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pkm.core import constraints
from pkm.core.configuration import Configuration
from pkm.core.indices import singularity_class
from pkm.core.mechanism import Mechanism, check_mechanism
from pkm.core.newton import least_squares
from pkm.errors import SingularityError
from pkm.validation import as_tolerance, as_vector, finite_result

RTOL = 1e-9


def _check(mech, q) -> tuple[Mechanism, np.ndarray]:
    """The mechanism and ``q`` checked (type, shape, finiteness, unit quaternions)."""
    mech = check_mechanism(mech)
    return mech, mech.check_q(q)


def _smin(A: np.ndarray, ncols: int | None = None) -> tuple[float, float]:
    """(smallest, largest) of the first ``ncols`` singular values (column-rank measure)."""
    finite_result(A, "Jacobian")
    try:
        s = np.linalg.svd(A, compute_uv=False)
    except np.linalg.LinAlgError as exc:
        finite_result(np.nan, "singular values", f"numpy: {exc}")
        raise
    n = A.shape[1] if ncols is None else ncols
    if len(s) < n:
        return 0.0, float(s[0]) if len(s) else 0.0
    return float(s[n - 1]), float(s[0])


def passive_map(mech: Mechanism, q, *, rtol: float = RTOL) -> np.ndarray:
    """``G = dq/dq_a`` (nv x na): all joint rates from the actuated rates.

    Raises:
        SingularityError: ``kind="direct"`` where the passive columns of the constraint
            Jacobian lose rank.
    """
    mech, q = _check(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    Jc = constraints.jacobian(mech, q)
    return finite_result(_passive_map(mech, Jc, rtol), "passive map G")


def _passive_map(mech: Mechanism, Jc: np.ndarray, rtol: float) -> np.ndarray:
    Jp = Jc[:, mech.passive_v]
    smin, smax = _smin(Jp)
    if smin <= rtol * max(smax, 1.0):
        raise SingularityError("direct", smin, "actuators locked, the mechanism can still move")
    G = np.zeros((mech.nv, mech.na))
    G[mech.act_v, np.arange(mech.na)] = 1.0
    G[mech.passive_v] = -least_squares(Jp, Jc[:, mech.act_v])
    return G


def forward_jacobian(mech: Mechanism, q) -> np.ndarray:
    """Task rates from actuated rates, ``yd = J qd_a`` (n_task x na)."""
    mech, q = _check(mech, q)
    c = Configuration.compute(mech, q)
    return finite_result(c.task_jacobian @ _passive_map(mech, c.constraint_jacobian, RTOL), "forward Jacobian")


def twist_jacobian(mech: Mechanism, q) -> np.ndarray:
    """End-effector twist ``[v; w]`` (origin velocity, world axes) from actuated rates (6 x na)."""
    mech, q = _check(mech, q)
    c = Configuration.compute(mech, q)
    return finite_result(c.ee_jacobian @ _passive_map(mech, c.constraint_jacobian, RTOL), "twist Jacobian")


def inverse_jacobian(mech: Mechanism, q, *, rtol: float = RTOL) -> np.ndarray:
    """Actuated rates from task rates, ``qd_a = J yd`` (na x n_task).

    Raises:
        SingularityError: ``kind="inverse"`` where ``[J_c; J_t]`` loses column rank.
    """
    mech, q = _check(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    A = Configuration.compute(mech, q).closure_and_task_jacobian
    smin, smax = _smin(A)
    if smin <= rtol * max(smax, 1.0):
        raise SingularityError("inverse", smin, "the task frozen, the joints can still move")
    rhs = np.zeros((A.shape[0], mech.n_task))
    rhs[mech.n_constraints:] = np.eye(mech.n_task)
    return finite_result(least_squares(A, rhs)[mech.act_v], "inverse Jacobian")


def velocities(mech: Mechanism, q, qd_actuated) -> np.ndarray:
    """All joint rates ``v`` (nv,) from the actuated rates."""
    G = passive_map(mech, q)
    return finite_result(G @ mech.check_actuated(qd_actuated, "qd_actuated"), "joint velocities")


def accelerations(mech: Mechanism, q, v, qdd_actuated) -> np.ndarray:
    """All joint accelerations ``a`` (nv,) from the actuated ones, the drift included."""
    mech, q = _check(mech, q)
    v = mech.check_v(v)
    qdd = mech.check_actuated(qdd_actuated, "qdd_actuated")
    gamma = constraints.drift(mech, q, v)
    Jc = constraints.jacobian(mech, q)
    _passive_map(mech, Jc, RTOL)  # raises at a direct singularity
    a = np.zeros(mech.nv)
    a[mech.act_v] = qdd
    a[mech.passive_v] = -least_squares(Jc[:, mech.passive_v], Jc[:, mech.act_v] @ qdd + gamma)
    return finite_result(a, "joint accelerations")


def task_velocity(mech: Mechanism, q, v) -> np.ndarray:
    """Task rates for joint rates ``v``."""
    mech, q = _check(mech, q)
    v = mech.check_v(v)
    return finite_result(mech.task_map.jacobian(q) @ v, "task velocity")


def task_acceleration(mech: Mechanism, q, v, a) -> np.ndarray:
    """Task accelerations ``J_t a + dJ_t/dt v``."""
    mech, q = _check(mech, q)
    v, a = mech.check_v(v), mech.check_v(a, "a")
    task = mech.task_map
    return finite_result(task.jacobian(q) @ a + task.bias(q, v), "task acceleration")


def inverse_velocities(mech: Mechanism, q, yd) -> np.ndarray:
    """All joint rates ``v`` for task rates ``yd`` (nv,)."""
    mech, q = _check(mech, q)
    yd = as_vector(yd, mech.n_task, "yd")
    A = Configuration.compute(mech, q).closure_and_task_jacobian
    return finite_result(least_squares(A, np.concatenate([np.zeros(mech.n_constraints), yd])), "joint velocities")


def inverse_accelerations(mech: Mechanism, q, v, ydd) -> np.ndarray:
    """All joint accelerations ``a`` for task accelerations ``ydd`` at state ``(q, v)``."""
    mech, q = _check(mech, q)
    v = mech.check_v(v)
    ydd = as_vector(ydd, mech.n_task, "ydd")
    task = mech.task_map
    gamma_c = constraints.drift(mech, q, v)
    gamma_t = task.bias(q, v)
    A = Configuration.compute(mech, q).closure_and_task_jacobian
    rhs = np.concatenate([-gamma_c, ydd - gamma_t])
    return finite_result(least_squares(A, rhs), "joint accelerations")


@dataclass(frozen=True)
class Diagnostics:
    """Rank and singularity measures at a configuration.

    Attributes:
        constraint_rank: Rank of the constraint Jacobian.
        redundant_constraints: Equations that are linearly dependent on others (planar loops
            closed with 3-D points have some).
        mobility: Instantaneous degrees of freedom, ``nv - constraint_rank``.
        sigma_direct: Smallest singular value of the passive columns ``J_p`` (type 2 measure).
        sigma_inverse: Smallest singular value of ``[J_c; J_t]`` (type 1 measure).
        classification: ``"regular"``, ``"inverse"``, ``"direct"`` or ``"combined"``.
    """

    constraint_rank: int
    redundant_constraints: int
    mobility: int
    sigma_direct: float
    sigma_inverse: float
    classification: str


def diagnose(mech: Mechanism, q, *, rtol: float = 1e-7) -> Diagnostics:
    """Rank, mobility and singularity classification at ``q`` (which should be assembled)."""
    mech, q = _check(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    c = Configuration.compute(mech, q)
    Jc = finite_result(c.constraint_jacobian, "constraint Jacobian")
    s = np.linalg.svd(Jc, compute_uv=False)
    rank = int(np.sum(s > rtol * max(s[0], 1.0))) if len(s) else 0
    sd, sdmax = _smin(Jc[:, mech.passive_v])
    si, simax = _smin(c.closure_and_task_jacobian)
    direct = sd <= rtol * max(sdmax, 1.0)
    inverse = si <= rtol * max(simax, 1.0)
    return Diagnostics(rank, mech.n_constraints - rank, mech.nv - rank, sd, si, singularity_class(inverse, direct))
