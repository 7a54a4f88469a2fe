"""One mode followed along a path: the forward kinematics along actuator samples stays on the assembly mode the
user picked, the inverse along task samples on the working mode, and where two modes meet (a singularity between
two samples) the track stops there and says so, instead of carrying on in another mode.

The track starts from a :class:`~pkm.core.modes.assembly.Mode` (its configuration: the polynomial solution's label
picks it) and runs the core's continuation (:func:`pkm.core.follow_actuators`, :func:`pkm.core.follow_task`),
whose every step is checked against its first-order prediction: a step far beyond it, a map singular at a sample,
or (inverse kinematics) a working mode's joint signs changing mark a meeting. Samples from the meeting on are
not reached (NaN; the continuation stops at the meeting, the samples after it are not solved). The meeting is then
located by bisection between the last sample reached and the next (the mode followed in ever smaller steps, to 1e-9
of the interval): its fraction ``s`` of the interval, the configuration there, and the smallest singular value
(relative to the largest) of the map that loses rank where the modes meet: the closure Jacobian in the passive joints
(forward), closure and task in every joint (inverse).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.kinematics import constraints
from pkm.core.kinematics.configuration import Configuration
from pkm.core.kinematics.solve import SolveResult, close_loops, solve_ik
from pkm.core.kinematics.task import TaskMap
from pkm.core.kinematics.trajectory import FOLLOW_TOL, _actuator_steps, _follow, _Steps, _task_steps
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.modes.assembly import Mode
from pkm.validation import instance_of

#: Largest joint step [rad or m] accepted while bisecting towards a meeting (a larger one: another mode).
_STEP = 0.5
#: The core's jump reasons that are two modes meeting (forward: assembly modes; inverse: working modes too).
_FK_MEETING = {"fold", "singular", "did not converge", "corrected"}
_IK_MEETING = _FK_MEETING | {"branch"}


@dataclass(frozen=True)
class Meeting:
    """Where the followed mode meets another.

    Attributes:
        index: The first sample not reached on the mode (the meeting lies between it and the one before).
        reason: The core's verdict (``"fold"``, ``"singular"``, ``"branch"``, ...).
        detail: What was measured.
        s: Where between the two samples the mode was last reached (0 to 1).
        q: The configuration there.
        sigma_min: The distance to a singularity there: the smallest over the largest singular value of the
            passive Jacobian (actuated motion) or of ``[J_c; J_t]`` (task motion), homogenised by the characteristic
            length (:mod:`pkm.core.model.scale`: the same for the mechanism scaled in size).
    """

    index: int
    reason: str
    detail: str
    s: float
    q: np.ndarray
    sigma_min: float


@dataclass(frozen=True)
class ModeTrack:
    """A mode followed along N samples.

    Attributes:
        label: The mode's label in the set it came from.
        q: The configurations (N x nq); NaN from the meeting on.
        reached: Samples reached on the mode (N when no meeting).
        meeting: Where the mode meets another, or None.
    """

    label: int
    q: np.ndarray
    reached: int
    meeting: Meeting | None


def _check_mode(mode: object, kind: str) -> Mode:
    """``mode`` itself if it is a :class:`Mode`, else :class:`InvalidInputError` saying where one comes from (a
    configuration passed in its place: its seed is ``mode.q``)."""
    return instance_of(mode, Mode, "mode", f"a pkm {kind} mode (one of pkm.{kind}_modes(mech, ...).modes; a "
                                           "configuration is no mode)")


def _sigma(J: np.ndarray) -> float:
    sv = np.linalg.svd(J, compute_uv=False)
    return float(sv[-1] / sv[0]) if sv.size and sv[0] > 0 else 0.0


def _track(mech: Mechanism, mode: Mode, steps: _Steps, reasons: set[str],
           solve_between: Callable[[int, float, np.ndarray], SolveResult],
           jacobian: Callable[[np.ndarray], np.ndarray]) -> ModeTrack:
    # (the core's continuation from the mode, ended at the first meeting: the samples after it are not the mode's)
    n, solve, predict, rates = steps
    traj = _follow(mech, n, mode.q, solve, predict, rates, False, None, FOLLOW_TOL, until=reasons)
    q = np.full((n, mech.nq), np.nan)
    q[:len(traj.q)] = traj.q
    stop = next((j for j in traj.jumps if j.reason in reasons), None)
    if stop is None:
        return ModeTrack(mode.label, q, len(q), None)
    k = stop.index
    lo, hi, q_lo = 0.0, 1.0, q[k - 1].copy()
    while hi - lo > 1e-9:
        mid = 0.5 * (lo + hi)
        res = solve_between(k, mid, q_lo)
        if res.converged and np.abs(mech.difference(q_lo, res.q)).max() <= _STEP:
            lo, q_lo = mid, res.q
        else:
            hi = mid
    q[k:] = np.nan
    return ModeTrack(mode.label, q, k, Meeting(k, stop.reason, stop.detail, lo, q_lo, _sigma(jacobian(q_lo))))


def track_assembly_mode(mech: Mechanism, mode: Mode, q_actuated: ArrayLike) -> ModeTrack:
    """The assembly mode ``mode`` (of :func:`pkm.assembly_modes` at the first sample) along actuator samples
    ``q_actuated`` (N x na) [rad or m].

    Raises:
        InvalidInputError: ``mech`` no mechanism, ``mode`` no :class:`Mode` (a configuration in its place).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> rrr3 = pkm.load("rrr3")
        >>> qa0 = rrr3.actuated_q(rrr3.q_reference)
        >>> modes = pkm.assembly_modes(rrr3, qa0)
        >>> path = qa0 + np.linspace(0.0, 0.2, 5)[:, None] * [1.0, -1.0, 0.5]
        >>> track = pkm.track_assembly_mode(rrr3, modes.modes[0], path)
        >>> track.reached, track.q.shape, track.meeting
        (5, (5, 7), None)
    """
    mech, mode = check_mechanism(mech), _check_mode(mode, "assembly")
    steps = _actuator_steps(mech, q_actuated, None, None, FOLLOW_TOL)
    A = np.asarray(q_actuated, dtype=float).reshape(steps[0], -1)  # the samples asked for (checked by the core)

    def between(k: int, s: float, q_from: np.ndarray) -> SolveResult:
        return close_loops(mech, A[k - 1] + s * (A[k] - A[k - 1]), q_from, raise_on_failure=False)

    return _track(mech, mode, steps, _FK_MEETING, between,
                  lambda qq: JacobianScales.of(mech).constraint(constraints.jacobian(mech, qq))[:, mech.passive_v])


def track_working_mode(mech: Mechanism, mode: Mode, task: ArrayLike) -> ModeTrack:
    """The working mode ``mode`` (of :func:`pkm.working_modes` at the first sample) along task samples ``task``
    (N x the task's value size, as :meth:`pkm.core.TaskMap.value`).

    Raises:
        InvalidInputError: ``mech`` no mechanism, ``mode`` no :class:`Mode` (a configuration in its place).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> modes = pkm.working_modes(delta, [0.0, 0.0, -0.36])
        >>> ys = np.array([[x, 0.0, -0.36] for x in np.linspace(0.0, 0.05, 4)])
        >>> track = pkm.track_working_mode(delta, modes.modes[0], ys)
        >>> track.reached, track.q.shape, track.meeting
        (4, (4, 12), None)
    """
    mech, mode = check_mechanism(mech), _check_mode(mode, "working")
    steps = _task_steps(mech, task, None, None, FOLLOW_TOL)
    Y = np.asarray(task, dtype=float).reshape(steps[0], -1)
    tm = TaskMap.of(mech)

    def between(k: int, s: float, q_from: np.ndarray) -> SolveResult:
        return solve_ik(mech, tm.interpolate(Y[k - 1], Y[k], s), q_from, raise_on_failure=False)

    def jac(qq: np.ndarray) -> np.ndarray:
        c, sc = Configuration.compute(mech, qq), JacobianScales.of(mech)
        J = np.vstack([sc.constraint(c.constraint_jacobian), sc.task(c.task_jacobian)])
        return J if mech.free_v is None else J[:, mech.free_v]

    return _track(mech, mode, steps, _IK_MEETING, between, jac)
