r"""A time law checked, not just planned (:func:`verify`).

1. **The efforts again, by another route, finer**: on every segment of the planning grid, ``factor + 1`` points
   (both ends and ``factor - 1`` between: 10x the planning resolution by default) with the segment's
   :math:`\ddot s` and :math:`\dot s^2 = \dot s_i^2 + 2 u_i (s - s_i)`; at each, the inverse kinematics of the path
   point, the joint rates and accelerations (:func:`pkm.follow_task` or :func:`pkm.follow_actuators`) and the
   efforts by :func:`pkm.inverse_dynamics` (Khalil's projection or virtual work: not the actuator-space model the
   plan was built on) on the mechanism with its payload, plus the joints' friction (Coulomb's sign exact, as
   planned). Each effort is compared with its actuator's curve at that speed, each speed and acceleration with
   its limit: :attr:`Verification.effort_usage` etc., 1 at the true limit. The plan holds the limits where these
   are at most ``1 + 1e-6`` (:attr:`Verification.holds`); planned at ``1 - margin`` (:data:`~pkm.core.timing.limits.
   MARGIN`), they stay under 1 by the margin less what the grid misses between its points.
2. **Pontryagin's structure**: on a time-optimal law some limit is active at every instant but the switching
   points. :attr:`Verification.inactive` lists the planning segments where no limit is used to within
   :data:`~pkm.core.timing.solve.ACTIVE_RTOL` (against the margin-reduced limits).
3. **Position limits**: every joint the model states position limits for (actuated, task, passive) stays within
   them at every check point (:meth:`pkm.core.Mechanism.limit_violations`); the first one outside is named in
   :attr:`Verification.reason` and the plan does not hold.
4. **Tracking**: :func:`pkm.simulate` (the model's friction, Coulomb smoothed) under the planned efforts plus a
   PD on the actuated coordinates, :math:`\tau = \tau_{plan}(t) + K_p (q_{a,ref} - q_a) + K_d (\dot q_{a,ref} -
   \dot q_a)`, gains from the mass matrix at the start, :math:`K_p = \omega_n^2 \operatorname{diag} M_a`,
   :math:`K_d = 2 \zeta \omega_n \operatorname{diag} M_a` (:math:`\omega_n = 2\pi \cdot 20` rad/s,
   :math:`\zeta = 1`); the largest actuated and task-space tracking errors are reported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pkm.core.kinematics.task import TaskMap
from pkm.core.timing.solve import ACTIVE_RTOL, TimeOptimal
from pkm.errors import InvalidInputError
from pkm.validation import as_count

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
        holds: Every usage is at most ``1 + HOLD_RTOL``, every joint within its position limits, and the motors'
            motion continuous.
        inactive: Planning segments where no limit is active (switching points of the law).
        tracking_error: The largest actuated error of the simulated tracking (na,) [rad, m]; None if not run.
        task_error: The largest task-space distance of the simulated end effector from the plan's [m] (position
            coordinates); None if not run.
        simulated_duration: How long the simulation ran [s] (the cycle time, or less where it stopped: see
            ``event``).
        event: Why the simulation stopped early, or None.
        outside_limits: The joints that leave their stated position limits at some check point (in the order they
            do).
        reason: Why the plan does not hold, in words (None where it holds).
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


def verify(plan: TimeOptimal, *, factor: int = 10, simulate: bool = True, dt: float | None = None) -> Verification:
    """Check ``plan`` (module doc): the efforts by :func:`pkm.inverse_dynamics` at ``factor`` times the planning
    resolution against the limits, Pontryagin's structure, and a tracking simulation (``simulate``; step ``dt``,
    default the cycle time / 2000).

    Raises:
        InvalidInputError: ``plan`` is not a :class:`~pkm.core.timing.solve.TimeOptimal`.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> plan = pkm.time_optimal(delta, [[-0.05, 0.0, -0.36], [0.05, 0.0, -0.36]], points=20)
        >>> check = pkm.verify_time_optimal(plan, simulate=False)
        >>> check.holds, round(check.speed_usage, 3), check.inactive
        (True, 0.999, ())
    """
    from pkm.core.dynamics.model import actuator_model
    from pkm.core.kinematics.trajectory import follow_actuators, follow_task

    if not isinstance(plan, TimeOptimal):
        raise InvalidInputError("plan", "expected a TimeOptimal (pkm.time_optimal)", plan)
    factor = as_count(factor, "factor", low=1, high=1000)
    mech, L = plan.mech, plan.limits
    s, t, sd, u = _points(plan, factor)
    y, dy, ddy = plan.path.evaluate(s)
    follow = follow_task if plan.path.space == "task" else follow_actuators
    traj = follow(mech, y, dy * sd[:, None], ddy * (sd * sd)[:, None] + dy * u[:, None], q0=plan.coefficients.q[0],
                  efforts=True, tol=1e-12)
    assert traj.efforts is not None
    tau = traj.efforts.copy()
    if np.any(np.asarray(mech.model.damping) != 0.0) or np.any(np.asarray(mech.model.friction) != 0.0):
        for k in range(len(s)):  # (the model's friction, Coulomb's sign exact as planned)
            model = actuator_model(mech, traj.q[k], traj.actuated_velocity[k], coulomb_velocity=1e-12)
            tau[k] -= model.friction
    omega = traj.actuated_velocity
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
    holds = not reasons
    inactive = tuple(int(i) for i in np.flatnonzero(plan.usage < 1.0 - ACTIVE_RTOL))
    track, task_err, dur, event = None, None, 0.0, None
    if simulate:
        track, task_err, dur, event = _track(plan, t, traj, tau, dt)
    return Verification(s, t, tau, effort, speed, acc, holds, inactive, track, task_err, dur, event,
                        tuple(v.joint for _, v in traj.outside_limits), "; ".join(reasons) or None)


def _track(plan: TimeOptimal, t: np.ndarray, traj: object, tau: np.ndarray,
           dt: float | None) -> tuple[np.ndarray, float, float, str | None]:
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
    task_err = float(np.max(np.linalg.norm(sim.task[:, pos] - yref, axis=1))) if pos else 0.0
    return track, task_err, float(sim.time[-1]), None if sim.event is None else str(sim.event)


__all__ = ["HOLD_RTOL", "Verification", "verify"]
