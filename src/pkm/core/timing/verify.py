r"""A time law checked, not just planned (:func:`verify`).

1. **The efforts again, by another route, finer**: on every segment of the planning grid, ``factor + 1`` points
   (both ends and ``factor - 1`` between: 10x the planning resolution by default) with the segment's
   :math:`\ddot s` and :math:`\dot s^2 = \dot s_i^2 + 2 u_i (s - s_i)`; at each, the inverse kinematics of the path
   point, the joint rates and accelerations (:func:`pkm.follow_task` or :func:`pkm.follow_actuators`) and the
   efforts by :func:`pkm.inverse_dynamics` (Khalil's projection or virtual work: not the actuator-space model the
   plan was built on) on the mechanism with its payload, plus the joints' friction (the planner's law,
   :func:`pkm.core.timing.coefficients._friction`: Coulomb's sign exact, through the passive map at the point, which
   is the identity on the actuated joints' rows where only they rub). Each effort is compared with its actuator's
   curve at that speed, each speed and acceleration with its limit: :attr:`Verification.effort_usage` etc., 1 at
   the true limit. The plan holds the limits where these are at most ``1 + 1e-6`` (:attr:`Verification.holds`);
   planned at ``1 - margin`` (:data:`~pkm.core.timing.limits.MARGIN`), they stay under 1 by the margin less what
   the grid misses between its points.
2. **Pontryagin's structure**: on a time-optimal law some limit is active at every instant but the switching
   points. "Active" is the planner's definition (:func:`~pkm.core.timing.solve.planned_usage`): a row of the problem
   it solved at its bound to within :data:`~pkm.core.timing.solve.ACTIVE_RTOL`, at a segment's end, with the
   speed-dependent terms (a motor line, viscous friction) linearised where it linearised them and each row
   tightened as it was. The efforts, joint rates and accelerations at the segments' ends are this check's own
   (step 1); the linearisation point, the tightening factors and the viscous coefficient :math:`d` (to take the
   term :math:`d \dot s` out of the recomputed efforts) are the plan's. :attr:`Verification.inactive` lists the
   segments where no row is active: it equals :attr:`TimeOptimal.inactive <pkm.core.timing.solve.TimeOptimal>`
   where the two routes agree (tested). Against the true limits, an active segment with viscous friction or a
   motor line may use less than 1 (the tangent is an upper bound; a friction that helps is not counted):
   :attr:`Verification.effort_usage` is the true use.
3. **Position limits**: every joint the model states position limits for (actuated, task, passive) stays within
   them at every check point (:meth:`pkm.core.Mechanism.limit_violations`); the first one outside is named in
   :attr:`Verification.reason` and the plan does not hold. Where the mechanism has collision geometry
   (:mod:`pkm.core.collision`), no two checked bodies interpenetrate at any check point either
   (:attr:`Verification.clearance`, the smallest distance; the first point and pair where two do named in the
   reason).
4. **Tracking**: :func:`pkm.simulate` (the model's friction, Coulomb smoothed) under the planned efforts plus a
   PD on the actuated coordinates, :math:`\tau = \tau_{plan}(t) + K_p (q_{a,ref} - q_a) + K_d (\dot q_{a,ref} -
   \dot q_a)`, gains from the mass matrix at the start, :math:`K_p = \omega_n^2 \operatorname{diag} M_a`,
   :math:`K_d = 2 \zeta \omega_n \operatorname{diag} M_a` (:math:`\omega_n = 2\pi \cdot 20` rad/s,
   :math:`\zeta = 1`); the largest actuated and task-space tracking errors are reported.

**Independent and shared**: the check's own are the inverse kinematics at every check point (not the plan's
configurations), the joint rates and accelerations, the efforts (another dynamics route than the planner's
actuator-space model) and the simulation; shared with the planner are the path, the law ``(s, sd, sdd)`` under
test, the limits and their margin, the friction law, and for step 2 the linearisation point
(:attr:`~pkm.core.timing.solve.TimeOptimal.linearised_at`), the tightening factors and the viscous coefficient.

**Two routes** (``kernels``): the generic core, per check point (:func:`pkm.follow_task`,
:func:`pkm.inverse_dynamics`: about 2 ms a point), or, for a task-space path, the compiled kernels
(:class:`pkm.Kernels`) in batches: the inverse kinematics warm-started along the check points
(:meth:`~pkm.Kernels.ik_path`, to 1e-14), the actuated rates and accelerations exactly
(:meth:`~pkm.Kernels.inverse_rates`: the time derivative of the inverse Jacobian's rates, no finite differences)
and the efforts from the twin's projection (:meth:`~pkm.Kernels.inverse_dynamics`; with idle motions
:math:`M_a \ddot q_a + h_a` of :meth:`~pkm.Kernels.mass_and_bias`, their rates mass-orthogonal as the core's: the
exported C's formula). Idle motions (a rod spinning between two balls) are held in the kernels' Newton steps, one
coordinate each (:func:`~pkm.core.twin.dynamics.idle_columns`), where the core's steps are of least norm: the
rods' spin may end elsewhere, which changes nothing the check reports where a rod's inertia is symmetric about its
axis (tests hold the two routes' efforts, usages and labels equal to 1e-10 relative on the humanoid ankle and the
RSSR). On the compiled route the efforts of a mechanism with idle motions come from the same expressions
(:class:`~pkm.core.twin.dynamics.ActuatorTwin`) as the planner's coefficients on its compiled route: what stays
independent of such a plan is the inverse kinematics at every check point and the exact rates and accelerations
(the planner's are Richardson differences); of a plan made on the core, everything above. Where the
compiled route meets a sample above the core's residual, a step the core would call a fold (the first-order
prediction's idle part held), or a change of branch, the core follows the path instead and names it. The compiled
route's Python is vectorised: the humanoid ankle's 11,000 check points take about 0.15 s of CPU against 25 s on
the core (``pkm bench time_optimal``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pkm.core.collision.interference import checks_collisions, first_interference, minimum_distances
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism
from pkm.core.timing.solve import ACTIVE_RTOL, TimeOptimal, planned_usage
from pkm.errors import InvalidInputError
from pkm.validation import as_count

if TYPE_CHECKING:
    from pkm.core.twin.kernels import Kernels

#: The recomputed efforts may exceed the limits by this fraction (rounding) and still hold.
HOLD_RTOL = 1e-6
PD_FREQUENCY = 20.0  # [Hz]
PD_DAMPING = 1.0


@dataclass(frozen=True)
class Verification:
    """What :func:`verify` found (module doc).

    Attributes:
        s, time: The check points (m,) and their times [s].
        efforts: :func:`pkm.inverse_dynamics`' efforts there, with friction (m x na) [N m, N].
        effort_usage: max over points and actuators of ``|tau| / T(|omega|)`` (1: at the true curve).
        speed_usage, acceleration_usage: likewise for the speed and acceleration limits (0 where none).
        holds: Every usage is at most ``1 + HOLD_RTOL``, every joint within its position limits, no two bodies
            interpenetrating (where the mechanism has collision geometry), and the motors' motion continuous.
        inactive: Planning segments where no limit is active (switching points of the law; module doc).
        planned_usage: Per segment, the largest use of the planner's rows recomputed from these efforts (1:
            active).
        tracking_error: The largest actuated error of the simulated tracking (na,) [rad, m]; None if not run.
        task_error: The largest task-space distance of the simulated end effector from the plan's [m] (position
            coordinates); None if not run or where the task has no position coordinates (an ankle's pitch and
            roll: ``tracking_error`` has the motors').
        simulated_duration: How long the simulation ran [s] (the cycle time, or less where it stopped: see
            ``event``).
        event: Why the simulation stopped early, or None.
        outside_limits: The joints that leave their stated position limits at some check point (in the order they
            do).
        reason: Why the plan does not hold, in words (None where it holds).
        clearance: The smallest signed distance between the bodies checked for collision over the check points [m]
            (negative: two interpenetrate, the reason names the first point and the pair), where the mechanism has
            collision geometry (:mod:`pkm.core.collision`); else None.
        route: What recomputed the motion at the check points: ``"core"``, or ``"kernels (...)"`` (what ran them;
            module doc, "Two routes").
    """

    s: np.ndarray
    time: np.ndarray
    efforts: np.ndarray
    effort_usage: float
    speed_usage: float
    acceleration_usage: float
    holds: bool
    inactive: tuple[int, ...]
    tracking_error: np.ndarray | None
    task_error: float | None
    simulated_duration: float
    event: str | None
    outside_limits: tuple[str, ...] = ()
    reason: str | None = None
    planned_usage: np.ndarray | None = None
    route: str = "core"
    clearance: float | None = None


def _points(plan: TimeOptimal, factor: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(s, t, sd, sdd)`` at ``factor + 1`` points of each segment, with the segment's law."""
    frac = np.linspace(0.0, 1.0, factor + 1)
    s0, ds = plan.s[:-1, None], np.diff(plan.s)[:, None]
    s = (s0 + frac[None] * ds).ravel()
    u = np.repeat(plan.sdd, factor + 1)
    x0 = np.repeat(plan.sd[:-1] ** 2, factor + 1)
    x = np.maximum(x0 + 2.0 * u * (s - np.repeat(plan.s[:-1], factor + 1)), 0.0)
    sd = np.sqrt(x)
    t = np.repeat(plan.time[:-1], factor + 1) + 2.0 * (s - np.repeat(plan.s[:-1], factor + 1)) / np.maximum(
        np.repeat(plan.sd[:-1], factor + 1) + sd, 1e-300)
    return s, t, sd, u


def verify(plan: TimeOptimal, *, factor: int = 10, simulate: bool = True, dt: float | None = None,
           kernels: object = None) -> Verification:
    """Check ``plan`` (module doc): the efforts by :func:`pkm.inverse_dynamics` at ``factor`` times the planning
    resolution against the limits, Pontryagin's structure (the active limits by the planner's definition, from
    these efforts), and a tracking simulation (``simulate``; step ``dt``, default the cycle time / 2000). What is
    recomputed independently and what is the planner's: the module doc.

    ``kernels``: the compiled route (True: the kernels of the plan's mechanism, built once and kept, as
    :func:`pkm.time_optimal` keeps them; or :class:`pkm.Kernels` of ``plan.mech``) for a task-space path: the
    inverse kinematics, rates, accelerations and efforts at the check points by the kernels (module doc, "Two
    routes"), equal to the core's to 1e-10 relative (tested); default the generic core.

    Raises:
        InvalidInputError: ``plan`` is not a :class:`~pkm.core.timing.solve.TimeOptimal`; ``kernels`` not of its
            mechanism.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> plan = pkm.time_optimal(delta, [[-0.05, 0.0, -0.36], [0.05, 0.0, -0.36]], points=20)
        >>> check = pkm.verify_time_optimal(plan, simulate=False)
        >>> check.holds, round(check.speed_usage, 3), check.inactive
        (True, 0.999, ())
    """
    from pkm.core.differential.velocity import passive_map
    from pkm.core.timing.coefficients import _friction, friction_map
    from pkm.core.timing.solve import kernels_of

    if not isinstance(plan, TimeOptimal):
        raise InvalidInputError("plan", "expected a TimeOptimal (pkm.time_optimal)", plan)
    factor = as_count(factor, "factor", low=1, high=1000)
    mech, L = plan.mech, plan.limits
    K = kernels_of(mech, kernels) if kernels is not None and kernels is not False else None
    s, t, sd, u = _points(plan, factor)
    y, dy, ddy = plan.path.evaluate(s)
    yd, ydd = dy * sd[:, None], ddy * (sd * sd)[:, None] + dy * u[:, None]
    traj = None if K is None or plan.path.space != "task" else _compiled(mech, K, y, yd, ydd, plan.coefficients.q[0])
    if traj is None:
        traj = _core(plan, y, yd, ydd)
    tau = traj.efforts.copy()
    omega = traj.actuated_velocity
    # (the joints' friction through the passive map at each point, Coulomb's sign exact: the planner's law)
    G = friction_map(mech, len(s), lambda: np.stack([passive_map(mech, qk) for qk in traj.q]))
    if G is not None:
        coulomb, viscous = _friction(mech, G, omega)
        tau += coulomb + viscous
    effort = float(np.max(np.abs(tau) / L.effort_limit(omega)))
    speed = float(np.max(np.abs(omega) / L.speed[None]))
    acc = float(np.max(np.abs(traj.actuated_acceleration) / L.acceleration[None]))
    reasons = [f"{what} used to {use:.6g} of its limit" for what, use in
               (("effort", effort), ("speed", speed), ("acceleration", acc)) if not use <= 1.0 + HOLD_RTOL]
    if traj.jumps:
        reasons.append("the motors' motion jumps (the path's inverse kinematics changed branch)")
    if traj.outside_limits:  # (per joint, the first check point outside)
        reasons.append("position limits crossed: " + "; ".join(
            f"{v.joint} = {v.value:.6g} at s = {s[k]:.6g}, outside its limits [{v.limit[0]:.6g}, {v.limit[1]:.6g}]"
            for k, v in traj.outside_limits))
    clearance = None
    if checks_collisions(mech):  # (about 20 us a check point)
        minima = traj.clearance if traj.clearance is not None else minimum_distances(mech, traj.q)
        clearance = float(np.nanmin(minima))
        hit = first_interference(mech, traj.q, minima)
        if hit is not None:
            reasons.append(f"bodies interpenetrate: {hit.pair[0]} and {hit.pair[1]} by {-hit.distance:.6g} m at "
                           f"s = {s[hit.at]:.6g}")
    holds = not reasons
    ends = np.stack([np.arange(len(plan.sdd)) * (factor + 1), np.arange(len(plan.sdd)) * (factor + 1) + factor])
    static = tau[ends] - np.stack([plan.coefficients.d[:-1], plan.coefficients.d[1:]]) * sd[ends][..., None]
    planned, _ = planned_usage(plan.coefficients, L, plan.sd, plan.sdd, plan.tightened, plan.linearised_at,
                               static, omega[ends], traj.actuated_acceleration[ends])
    inactive = tuple(int(i) for i in np.flatnonzero(planned < 1.0 - ACTIVE_RTOL))
    track, task_err, dur, event = None, None, 0.0, None
    if simulate:
        track, task_err, dur, event = _track(plan, t, traj, tau, dt)
    return Verification(s, t, tau, effort, speed, acc, holds, inactive, track, task_err, dur, event,
                        tuple(v.joint for _, v in traj.outside_limits), "; ".join(reasons) or None, planned,
                        traj.route, clearance)


@dataclass(frozen=True)
class _Motion:
    """The motion at the check points, from either route: configurations (m x nq), the actuated coordinates,
    rates and accelerations (m x na), the efforts without friction (m x na), the task values, whether the motion
    leaves its branch, the joints outside their position limits (:meth:`pkm.core.Mechanism.limits_along`), the
    route, and the smallest distances between checked bodies where the route computed them (the core's)."""

    q: np.ndarray
    actuated: np.ndarray
    actuated_velocity: np.ndarray
    actuated_acceleration: np.ndarray
    efforts: np.ndarray
    task: np.ndarray
    jumps: bool
    outside_limits: tuple
    route: str = "core"
    clearance: np.ndarray | None = None


def _core(plan: TimeOptimal, y: np.ndarray, yd: np.ndarray, ydd: np.ndarray) -> _Motion:
    """The generic core's motion: :func:`pkm.follow_task` (or :func:`pkm.follow_actuators`) with the efforts of
    :func:`pkm.inverse_dynamics`."""
    from pkm.core.kinematics.trajectory import follow_actuators, follow_task

    follow = follow_task if plan.path.space == "task" else follow_actuators
    traj = follow(plan.mech, y, yd, ydd, q0=plan.coefficients.q[0], efforts=True, tol=1e-12)
    assert traj.efforts is not None
    return _Motion(traj.q, traj.actuated, traj.actuated_velocity, traj.actuated_acceleration, traj.efforts,
                   traj.task, bool(traj.jumps), traj.outside_limits, clearance=traj.clearance)


def _compiled(mech: Mechanism, K: Kernels, y: np.ndarray, yd: np.ndarray, ydd: np.ndarray,
              q0: np.ndarray) -> _Motion | None:
    """The compiled route's motion (module doc), or None where the core must follow the path itself to name what
    happens there: a sample whose residual is above the core's tolerance, a step further from its first-order
    prediction than :func:`pkm.follow_task` allows (a fold), a change of the spec's branch signs."""
    from pkm.core.kinematics.trajectory import JUMP_RATIO

    res = K.ik_path(y, q0, tol=1e-14)
    if not res.residual.max() <= 1e-12:
        return None
    v, qdd = K.inverse_rates(res.q, yd, ydd)
    if len(y) > 1:  # (the fold test of pkm.follow_task, the prediction's idle coordinates held)
        task = TaskMap.of(mech)
        step = np.array([task.error(y[k], y[k - 1]) for k in range(1, len(y))])
        pred, _ = K.inverse_rates(res.q[:-1], step, np.zeros_like(step))
        dq = np.array([mech.difference(a, b) for a, b in zip(res.q[:-1], res.q[1:])])
        norm = np.linalg.norm(pred, axis=1)
        if np.any(np.linalg.norm(dq - pred, axis=1) > JUMP_RATIO * norm + 1e-9):
            return None
    for b in mech.spec.branches:
        if len({mech.on_branch(qk, b) for qk in res.q}) > 1:
            return None
    qd = v[:, mech.act_v]
    if K.dynamics.idle:  # (M_a qdd + h_a: the model's mass-orthogonal idle motions, as the exported C)
        M, h = K.mass_and_bias(res.q, qd)
        tau = np.einsum("kij,kj->ki", M.reshape(len(qd), mech.na, mech.na), qdd) + h  # (one motor: a column)
    else:
        tau = K.inverse_dynamics(res.q, qd, qdd)
    return _Motion(res.q, res.q[:, mech.act_q], qd, qdd, tau, y, False, res.outside_limits, f"kernels ({res.how})")


def _track(plan: TimeOptimal, t: np.ndarray, traj: object, tau: np.ndarray,
           dt: float | None) -> tuple[np.ndarray, float | None, float, str | None]:
    from pkm.core.dynamics.model import actuator_model
    from pkm.core.dynamics.simulate import simulate

    mech = plan.mech
    order = np.argsort(t, kind="stable")
    tt = t[order]
    ref_q, ref_v = traj.actuated[order], traj.actuated_velocity[order]  # type: ignore[attr-defined]
    ff = tau[order]
    Md = np.diag(actuator_model(mech, plan.coefficients.q[0]).M)
    wn = 2.0 * np.pi * PD_FREQUENCY
    Kp, Kd = wn * wn * Md, 2.0 * PD_DAMPING * wn * Md
    act_q, act_v = mech.act_q, mech.act_v

    def at(table: np.ndarray, time: float) -> np.ndarray:
        return np.array([np.interp(time, tt, table[:, i]) for i in range(table.shape[1])])

    def controller(time: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return at(ff, time) + Kp * (at(ref_q, time) - q[act_q]) + Kd * (at(ref_v, time) - v[act_v])

    T = plan.cycle_time
    step = T / 2000.0 if dt is None else dt
    sim = simulate(mech, plan.coefficients.q[0], np.zeros(mech.na), duration=T, dt=step, controller=controller,
                   saturate=True, limits=False)
    ref = np.array([at(ref_q, time) for time in sim.time])
    track = np.max(np.abs(sim.actuated - ref), axis=0)
    task = TaskMap.of(mech)
    pos = [i for i, k in enumerate(task.value_names) if task.kinds.get(k) == "length"]
    yref = np.array([at(traj.task[order][:, pos], time) for time in sim.time])  # type: ignore[attr-defined]
    task_err = float(np.max(np.linalg.norm(sim.task[:, pos] - yref, axis=1))) if pos else None  # (no lengths)
    return track, task_err, float(sim.time[-1]), None if sim.event is None else str(sim.event)


__all__ = ["HOLD_RTOL", "Verification", "verify"]
