"""Motions of any mechanism: every joint, rate, acceleration and actuator effort along a sampled path.

:func:`follow_task` runs the inverse kinematics along task samples, :func:`follow_actuators` the forward
kinematics along actuator samples; each solve starts from the previous sample's configuration, so the
path stays on the working mode (assembly mode) it starts on. Where it cannot, the result says so instead
of hiding a jump: a :class:`Jump` at each sample where the solver did not converge, where the
configuration moved much further than the first-order prediction from the previous sample (a fold of
the branch: a singularity between the samples), or where the spec's branch signs changed.

The rates and accelerations come from :func:`pkm.inverse_velocities`/:func:`pkm.velocities` and their
acceleration twins, the efforts from :func:`pkm.inverse_dynamics`, per sample; all in SI (the result's
``units`` says which). A sample that did not converge, or where a map is singular, gets NaN rates and
efforts and a Jump.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.collision.interference import Interference, checks_collisions, first_interference, minimum_distances
from pkm.core.differential.velocity import (
    accelerations,
    inverse_accelerations,
    inverse_velocities,
    task_acceleration,
    task_velocity,
    velocities,
)
from pkm.core.dynamics.projection import inverse_dynamics
from pkm.core.kinematics.solve import SolveResult, close_loops, solve_ik
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import LimitViolation, Mechanism, check_mechanism
from pkm.errors import InvalidInputError, SingularityError
from pkm.validation import as_array, as_tolerance, bounded

#: A sample's joint step beyond this multiple of the first-order prediction (plus 1e-9) is a jump.
JUMP_RATIO = 1.0


@dataclass(frozen=True)
class Jump:
    """Where a followed path leaves its branch.

    Attributes:
        index: The sample (0-based) reached by the jump.
        reason: ``"did not converge"`` (the sample's rates and efforts are NaN), ``"corrected"`` (reached,
            but by a direct correction after the continuation failed), ``"fold"`` (the step far beyond the
            first-order prediction: a singularity between the samples), ``"singular"`` (a map singular at
            the sample: its rates and efforts are NaN) or ``"branch"`` (the spec's branch signs changed).
        detail: What was measured.
    """

    index: int
    reason: str
    detail: str


@dataclass(frozen=True)
class Trajectory:
    """A mechanism's motion along N samples (arrays with one row per sample, SI units).

    Attributes:
        q, v, a: Joint configurations (N x nq), velocities and accelerations (N x nv).
        actuated, actuated_velocity, actuated_acceleration: The actuated coordinates and their rates (N x na).
        task, task_velocity, task_acceleration: The task values (N x value size) and rates (N x task size).
        efforts: Actuator efforts (N x na) [N or N m], None when not asked for.
        residual: The closure (and task) residual of each solve (N).
        jumps: Where the path leaves its branch (empty: it stays on the one it starts on).
        units: The unit of every actuated joint and named task coordinate (``{"actuated": {...}, "task": {...}}``;
            the task's keys are :attr:`pkm.core.TaskMap.keys`, a pose's orientation by its Z-Y-X angles, while
            :attr:`task` holds its quaternion).
        outside_limits: Per joint that leaves the position limits the model states, ``(sample, violation)``: the
            first sample outside and there its :class:`~pkm.core.model.mechanism.LimitViolation` (joint, value,
            limit), in the order of the samples (:meth:`~pkm.core.Mechanism.limits_along`; empty: every joint
            within its limits throughout).
        clearance: The smallest signed distance between the bodies checked for collision at each sample (N) [m]
            (negative: two interpenetrate), where the mechanism has collision geometry (:mod:`pkm.core.collision`,
            about 20 us a sample); else None.
        interference: The first sample where two checked bodies interpenetrate, with the pair and the distance
            there (:class:`~pkm.core.collision.interference.Interference`); None where none does (or no geometry).
    """

    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    actuated: np.ndarray
    actuated_velocity: np.ndarray
    actuated_acceleration: np.ndarray
    task: np.ndarray
    task_velocity: np.ndarray
    task_acceleration: np.ndarray
    efforts: np.ndarray | None
    residual: np.ndarray
    jumps: tuple[Jump, ...]
    units: dict[str, dict[str, str]] = field(default_factory=dict)
    outside_limits: tuple[tuple[int, LimitViolation], ...] = ()
    clearance: np.ndarray | None = None
    interference: Interference | None = None

    def __len__(self) -> int:
        return len(self.q)


def _samples(x: ArrayLike | None, n: int | None, size: int, what: str) -> np.ndarray:
    """``x`` as N x size (a 1-D ``x`` for size 1 is N samples); zeros when None (with n)."""
    if x is None:
        if n is None:
            raise InvalidInputError(what, "needed", x)
        return np.zeros((n, size))
    arr = as_array(x, what, f"N x {size} samples")
    if arr.ndim == 1 and size == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] != size or (n is not None and arr.shape[0] != n) or not len(arr):
        raise InvalidInputError(what, f"expected {'N' if n is None else n} x {size} samples, got shape {arr.shape}",
                                x)
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(what, "holds non-finite values", x)
    return bounded(arr, what, x)


def _units(mech: Mechanism) -> dict[str, dict[str, str]]:
    unit = {"angle": "rad", "length": "m"}
    return {"actuated": {j.name: "rad" if j.revolute else "m" for j in mech.actuated},
            "task": {k: unit[kind] for k, kind in TaskMap.of(mech).kinds.items()}}


def _open(res: SolveResult, tol: float) -> bool:
    """Whether a solve's residual is above ``tol`` (the one the solver's tolerance bounds, lengths in ``L``)."""
    return bool(res.relative_residual > tol) if np.isfinite(res.relative_residual) else bool(res.residual > tol)


#: The continuation's default tolerance (:func:`follow_task`, :func:`follow_actuators`): lengths in the characteristic
#: length, angles in rad.
FOLLOW_TOL = 1e-10
#: A path's steps for :func:`_follow`: its sample count, ``solve``, ``predict`` and ``rates``.
_Steps = tuple[int, Callable[[int, np.ndarray], SolveResult], Callable[[int, np.ndarray], np.ndarray],
               Callable[[int, np.ndarray], tuple[np.ndarray, np.ndarray]]]


def _follow(mech: Mechanism, n: int, q0: ArrayLike | None, solve: Callable[[int, np.ndarray], SolveResult],
            predict: Callable[[int, np.ndarray], np.ndarray],
            rates: Callable[[int, np.ndarray], tuple[np.ndarray, np.ndarray]], efforts: bool, wrench: ArrayLike | None,
            tol: float, until: Collection[str] = ()) -> Trajectory:
    """The samples one by one: ``solve(k, q_from)`` from the previous sample (``q0`` for the first),
    ``predict(k, q_prev)`` the first-order step, ``rates(k, q) -> (v, a)``. With ``until``, the trajectory ends at
    the first sample with a jump of one of these reasons (the samples after it not solved: a mode's track stops
    there, :mod:`pkm.core.modes.tracking`)."""
    start = mech.q_reference if q0 is None else mech.check_q(q0, "q0")
    if not isinstance(efforts, (bool, np.bool_)):
        raise InvalidInputError("efforts", f"expected True or False, got {type(efforts).__name__}", efforts)
    tol = as_tolerance(tol, "tol")
    na, nv = mech.na, mech.nv
    q = np.empty((n, mech.nq))
    v, a = np.full((n, nv), np.nan), np.full((n, nv), np.nan)
    tau = np.full((n, na), np.nan) if efforts else None
    residual = np.empty(n)
    jumps: list[Jump] = []
    prev = None
    signs = None
    before = 0  # (the jumps of the samples before the last one)
    for k in range(n):
        if any(j.reason in until for j in jumps[before:]):  # (the sample before ended the path)
            q, v, a, residual = q[:k], v[:k], a[:k], residual[:k]
            tau = None if tau is None else tau[:k]
            break
        before = len(jumps)
        res = solve(k, start if prev is None else prev)
        q[k], residual[k] = res.q, res.residual
        if not res.converged:
            jumps.append(Jump(k, "did not converge", f"residual {res.residual:.3g} (m or rad)") if _open(res, tol)
                         else Jump(k, "corrected", "the continuation failed and a direct correction reached the "
                                                   "sample, possibly on another branch"))
        if prev is not None:
            try:
                dq_pred = predict(k, prev)
                dq = mech.difference(prev, res.q)
                miss = float(np.linalg.norm(dq - dq_pred))
                if miss > JUMP_RATIO * float(np.linalg.norm(dq_pred)) + 1e-9:
                    jumps.append(Jump(k, "fold", f"the joints moved by {np.linalg.norm(dq):.3g}, {miss:.3g} away from "
                                                 f"the first-order prediction {np.linalg.norm(dq_pred):.3g}"))
            except SingularityError as exc:
                jumps.append(Jump(k, "singular", f"at sample {k - 1}: {exc}"))
        now = {b: mech.on_branch(res.q, b) for b in mech.spec.branches}
        if signs is not None and now != signs:
            jumps.append(Jump(k, "branch", f"on {[b for b, on in now.items() if on]}, was on "
                                           f"{[b for b, on in signs.items() if on]}"))
        signs = now
        if _open(res, tol):  # no rates nor efforts where the loops or the task are open
            prev = res.q
            continue
        try:
            v[k], a[k] = rates(k, res.q)
            if tau is not None:
                tau[k] = inverse_dynamics(mech, res.q, v[k], a[k], wrench)
        except SingularityError as exc:
            if not jumps or jumps[-1].index != k:
                jumps.append(Jump(k, "singular", str(exc)))
        prev = res.q
    task = TaskMap.of(mech)
    values = np.array([task.value(qk) for qk in q])
    yd = np.array([task_velocity(mech, qk, vk) if np.all(np.isfinite(vk)) else np.full(mech.n_task, np.nan)
                   for qk, vk in zip(q, v)])
    ydd = np.array([task_acceleration(mech, qk, vk, ak) if np.all(np.isfinite(ak)) else np.full(mech.n_task, np.nan)
                    for qk, vk, ak in zip(q, v, a)])
    return Trajectory(q, v, a, q[:, mech.act_q], v[:, mech.act_v], a[:, mech.act_v], values, yd, ydd, tau, residual,
                      tuple(jumps), _units(mech), mech.limits_along(q), *interference_along(mech, q))


def interference_along(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray | None, Interference | None]:
    """:attr:`Trajectory.clearance` and :attr:`Trajectory.interference` of the samples ``q`` (N x nq)."""
    if not checks_collisions(mech):
        return None, None
    clear = minimum_distances(mech, q)
    return clear, first_interference(mech, q, clear)


def follow_task(mech: Mechanism, y: ArrayLike, yd: ArrayLike | None = None, ydd: ArrayLike | None = None, *,
                q0: ArrayLike | None = None, efforts: bool = True, wrench: ArrayLike | None = None, tol: float = FOLLOW_TOL) -> Trajectory:
    """Inverse kinematics, rates and efforts along task samples, tracking one working mode.

    Args:
        mech: The mechanism.
        y: N task samples (N x value size: as :meth:`pkm.core.TaskMap.value`, a pose as x y z qx qy qz qw).
        yd, ydd: Their task velocities and accelerations (N x task size; default zero).
        q0: The configuration the first solve starts from (default: the reference); the path stays on its
            working mode.
        efforts: Also compute the actuator efforts (:func:`pkm.inverse_dynamics`).
        wrench: External wrench at the end effector (world-aligned f, m), the same at every sample.
        tol: Solver tolerance: lengths in the characteristic length ``L``, angles in rad (:func:`solve_ik`).

    Raises:
        InvalidInputError: samples of the wrong shape or not finite.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> y = np.array([[x, 0.0, -0.36] for x in np.linspace(0.0, 0.05, 6)])
        >>> yd = np.tile([0.05, 0.0, 0.0], (6, 1))
        >>> traj = pkm.follow_task(delta, y, yd)
        >>> traj.actuated.shape, traj.efforts.shape
        ((6, 3), (6, 3))
        >>> np.round(traj.efforts[-1], 4)
        array([0.1647, 0.1005, 0.2231])
    """
    mech = check_mechanism(mech)
    n, solve, predict, rates = _task_steps(mech, y, yd, ydd, tol)
    return _follow(mech, n, q0, solve, predict, rates, efforts, wrench, tol)


def _task_steps(mech: Mechanism, y: ArrayLike, yd: ArrayLike | None, ydd: ArrayLike | None, tol: float) -> _Steps:
    """:func:`follow_task`'s samples, checked, and its steps for :func:`_follow`: ``(n, solve, predict, rates)``."""
    task = TaskMap.of(mech)
    Y = _samples(y, None, task.value_size, "y")
    n = len(Y)
    Yd, Ydd = _samples(yd, n, task.size, "yd"), _samples(ydd, n, task.size, "ydd")

    def solve(k: int, q_from: np.ndarray) -> SolveResult:
        return solve_ik(mech, Y[k], q_from, tol=tol, raise_on_failure=False)

    def predict(k: int, prev: np.ndarray) -> np.ndarray:
        return inverse_velocities(mech, prev, task.error(Y[k], Y[k - 1]))

    def rates(k: int, qk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        vk = inverse_velocities(mech, qk, Yd[k])
        return vk, inverse_accelerations(mech, qk, vk, Ydd[k])

    return n, solve, predict, rates


def follow_actuators(mech: Mechanism, qa: ArrayLike, qd: ArrayLike | None = None, qdd: ArrayLike | None = None, *,
                     q0: ArrayLike | None = None, efforts: bool = True, wrench: ArrayLike | None = None, tol: float = FOLLOW_TOL) -> Trajectory:
    """Forward kinematics, rates and efforts along actuator samples, tracking one assembly mode.

    Args:
        mech: The mechanism.
        qa: N actuator samples (N x na) [m or rad].
        qd, qdd: Their rates and accelerations (N x na; default zero).
        q0: The configuration the first solve starts from (default: the reference).
        efforts, wrench, tol: As :func:`follow_task`.

    Raises:
        InvalidInputError: samples of the wrong shape or not finite.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> qa = np.linspace([-0.9, -0.9, -0.9], [-0.8, -0.9, -1.0], 5)
        >>> traj = pkm.follow_actuators(delta, qa)
        >>> np.round(traj.task[-1], 4)
        array([-0.0118,  0.02  , -0.3691])
        >>> bool(traj.residual.max() < 1e-10)
        True
    """
    mech = check_mechanism(mech)
    n, solve, predict, rates = _actuator_steps(mech, qa, qd, qdd, tol)
    return _follow(mech, n, q0, solve, predict, rates, efforts, wrench, tol)


def _actuator_steps(mech: Mechanism, qa: ArrayLike, qd: ArrayLike | None, qdd: ArrayLike | None,
                    tol: float) -> _Steps:
    """:func:`follow_actuators`' samples, checked, and its steps for :func:`_follow`: ``(n, solve, predict,
    rates)``."""
    A = _samples(qa, None, mech.na, "qa")
    n = len(A)
    Ad, Add = _samples(qd, n, mech.na, "qd"), _samples(qdd, n, mech.na, "qdd")

    def solve(k: int, q_from: np.ndarray) -> SolveResult:
        return close_loops(mech, A[k], q_from, tol=tol, raise_on_failure=False)

    def predict(k: int, prev: np.ndarray) -> np.ndarray:
        return velocities(mech, prev, A[k] - A[k - 1])

    def rates(k: int, qk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        vk = velocities(mech, qk, Ad[k])
        return vk, accelerations(mech, qk, vk, Add[k])

    return n, solve, predict, rates


def task_values(mech: Mechanism, q: ArrayLike) -> dict[str, float]:
    """The task coordinates at ``q`` by name (a pose as x y z and Z-Y-X Euler roll pitch yaw) [m, rad].

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> pkm.task_values(delta, delta.q_reference)
        {'x': 0.0, 'y': 0.0, 'z': -0.254375}
        >>> hexapod = pkm.load("hexapod")
        >>> list(pkm.task_values(hexapod, hexapod.q_reference))
        ['x', 'y', 'z', 'roll', 'pitch', 'yaw', 'beta_1']
    """
    mech = check_mechanism(mech)
    return TaskMap.of(mech).named(mech.check_q(q))


__all__ = ["FOLLOW_TOL", "JUMP_RATIO", "Jump", "Trajectory", "follow_actuators", "follow_task", "task_values"]
