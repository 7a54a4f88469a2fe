"""Simulation of any closed-loop mechanism in its actuated (minimal) coordinates.

The state is the actuated coordinates and rates ``(q_a, qd)``; the equations are those of
:mod:`pkm.core.dynamics.model`, ``M_a qdd = sat(τ_a) + f_a - h_a``, with the actuators' torque saturation (each
effort clipped to its peak, else continuous, limit) and the joints' viscous and Coulomb friction. At every stage
of the integrator the passive joints are found by closing the loops from the previous configuration (a few Newton
iterations, to 1e-12 with lengths counted in the characteristic length: the same iterations for a copy scaled in
size): the loops are exact at every step, there is no drift to stabilise and no Baumgarte gain to
tune.

Integrators:

* ``"rk4"`` (default): classical Runge-Kutta of order 4 on the ``dt`` grid; energy drift ``O(dt^4)``. A step is
  halved (recursively, at most 8 times) where the closed configuration at its end lies more than ``step_tol`` from
  the stages' own prediction: near a singularity the passive joints outrun the actuated ones and a fixed step
  would lose accuracy first, then the assembly mode.
* ``"radau"``: SciPy's Radau IIA (implicit, order 5, L-stable, adaptive step, output on the ``dt`` grid), for stiff
  cases: heavy viscous friction, a Coulomb friction's steep smoothed sign, high controller gains, where an explicit
  step must be tiny to stay stable. Each of its steps solves the implicit stages by Newton with a finite-difference
  Jacobian of the closed-loop dynamics; each evaluation closes the loops from the last step's configuration moved
  by the joint rates, so that the right-hand side is a function of the state and an idle motion's coordinate, which
  the closure does not fix, follows its rate (:mod:`pkm.core.differential.idle`; the trapezoidal rule). Its work is
  bounded, as RK4's is: past :data:`RADAU_EVALUATIONS`
  evaluations a sample or :data:`RADAU_RATE` a simulated second (whichever allows more), the run stops (a
  ``"singularity"`` event: the motion is too fast to follow).

The run stops with an :class:`Event`, keeping the samples up to it, where the motion

* comes within ``singular_tol`` of a direct singularity (the passive joints' Jacobian's smallest singular value
  relative to its largest, the Jacobian homogenised by the mechanism's characteristic length as in
  :func:`pkm.diagnose`: the same for the mechanism scaled in size), where the actuators lose control and the model
  its meaning;
* leaves its assembly mode (the loops do not close from the previous configuration; where they fail within
  :data:`SINGULAR_CLOSURE` ``* singular_tol`` of a direct singularity, the event is that singularity);
* crosses a position limit stated by the model file, or exceeds an actuator's speed limit.

A floating base (``spec.floating_base``) is free by default (``base="free"``, :mod:`pkm.core.dynamics.model`): no
wrench acts on it, its acceleration comes from its own equations, and its pose (position and unit quaternion,
integrated from its twist: ``ṗ = R v``, ``q̇ = ½ q ⊗ ω``, the quaternion normalised where it is used) and twist join
the state; with no effort and no friction the energy is conserved (tests). The joint springs (``[springs]``,
:mod:`pkm.core.model.springs`) act in ``h_a`` and their energy is in the potential; their damping is friction. ``base="fixed"`` holds it where ``q0``
puts it. A free base runs in Python (the C route models a held base).

A controller is a callable ``(t, q, v) -> τ_a`` (``q`` the whole configuration, nq; ``v`` the joint rates, nv; the
actuated ones are ``q[mech.act_q]`` and ``v[mech.act_v]``), or a sampled table ``(times, efforts)`` interpolated
linearly (held outside its span).

Backends (``backend=``): ``"python"`` runs every stage in Python as above; ``"c"`` runs the same ``"rk4"`` in
generated C (:mod:`pkm.core.twin.simulation`: the closure's Newton, the actuator-space model, the efforts of a
torque table or of no effort, the events' checks; a Python controller is called back once per stage, the rest in
C). A step that the C route cannot settle as the Python route would (one to halve, one near an event, a fixed LU
pivot that fails, a closure that does not converge) is taken by Python, then the run goes back to C: the two
routes give the same samples (to about 1e-12) and the same events. ``"auto"`` (default) runs C where a C compiler
exists, the method is ``"rk4"``, the mechanism has no idle motions and either this mechanism's simulation is
already compiled or the run has at least :data:`AUTO_STEPS` steps (building costs about as much as that many
Python steps); else Python. The C route's samples are assembled by one compiled batch (accelerations, task
values, rates and accelerations, potential energy, residual).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.dynamics.model import (
    COULOMB_VELOCITY,
    RTOL,
    ActuatorSpaceModel,
    _check_state,
    _evaluate,
    _solve_inertia,
    base_choice,
)
from pkm.core.dynamics.projection import energy
from pkm.core.kinematics import constraints
from pkm.core.kinematics.newton import least_squares
from pkm.core.kinematics.solve import close_loops
from pkm.core.kinematics.task import TaskMap
from pkm.core.kinematics.trajectory import Trajectory, _units, interference_along
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.plausibility import require_physical
from pkm.core.model.scale import JacobianScales
from pkm.errors import CompilerError, ControllerError, InvalidInputError, PkmError, SingularityError, SpecError
from pkm.validation import as_array, as_choice, as_scalar

if TYPE_CHECKING:
    from pkm.core.twin.simulation import Simulator

METHODS = ("rk4", "radau")
BACKENDS = ("auto", "python", "c")
AUTO_STEPS = 2000  # "auto" builds a mechanism's compiled simulation for runs of at least this many steps
MAX_STEPS = 10_000_000  # a run of more steps than this is refused (its arrays alone would be gigabytes)
CLOSURE_TOL = 1e-12  #: the loop closure's largest residual, lengths in the characteristic length (angles in rad)
SINGULAR_CLOSURE = 10.0  # a closure that fails within this many singular_tol of a direct singularity: "singularity"
MAX_HALVINGS = 8  # an RK4 step is halved at most this many times (a 1-ms step down to 4 us)
RADAU_EVALUATIONS = 10 * 2 ** MAX_HALVINGS  # "radau" stops past this many evaluations a sample (RK4's worst case)
RADAU_RATE = 1e6  # ... or a simulated second, whichever allows more (a stiff run with Coulomb friction takes 2e5)
Controller = Callable[[float, np.ndarray, np.ndarray], ArrayLike]


@dataclass(frozen=True)
class Event:
    """Why a simulation stopped before its end.

    Attributes:
        kind: ``"singularity"``, ``"assembly_mode"``, ``"joint_limit"`` or ``"velocity_limit"``.
        time: The time of the last sample kept [s].
        detail: What was measured (the joint, the value, the limit).
    """

    kind: str
    time: float
    detail: str


@dataclass(frozen=True)
class Simulation(Trajectory):
    """A simulated motion: a :class:`~pkm.core.kinematics.trajectory.Trajectory` (``efforts`` are the efforts
    applied, after saturation) with its time and energies.

    Attributes:
        time: The sample times (N,) [s].
        kinetic: Kinetic energy (N,) [J] (reflected rotor inertias included).
        potential: Potential energy under gravity and in the joint springs (``[springs]``) (N,) [J].
        work: The actuators' work since the start (N,) [J] (trapezoidal rule on the samples).
        dissipated: The energy friction has taken since the start (N,) [J] (trapezoidal rule; >= 0; the springs'
            damping among it).
        event: Why the run stopped early, or None.
        method: The integrator.
        saturated: Per actuator, the samples whose effort is at or beyond its limit (peak, else continuous): clipped
            there when the run saturates (the default), exceeded when it does not.
        base: How a floating base moved: ``"free"`` (its own equations, no wrench on it) or ``"fixed"`` (held; every
            mechanism without a floating base) (:mod:`pkm.core.dynamics.model`).

    Examples:
        >>> import pkm
        >>> sim = pkm.simulate(pkm.load("delta"), duration=0.01, dt=0.005)
        >>> sim.units["task"]
        {'x': 'm', 'y': 'm', 'z': 'm'}
        >>> sim.actuated.shape, sim.efforts.shape
        ((3, 3), (3, 3))
    """

    time: np.ndarray = field(default_factory=lambda: np.zeros(0))
    kinetic: np.ndarray = field(default_factory=lambda: np.zeros(0))
    potential: np.ndarray = field(default_factory=lambda: np.zeros(0))
    work: np.ndarray = field(default_factory=lambda: np.zeros(0))
    dissipated: np.ndarray = field(default_factory=lambda: np.zeros(0))
    event: Event | None = None
    method: str = "rk4"
    saturated: dict[str, int] = field(default_factory=dict)
    base: str = "fixed"

    @property
    def energy(self) -> np.ndarray:
        """Total mechanical energy, kinetic plus potential (N,) [J]."""
        return self.kinetic + self.potential


class _Stop(Exception):
    """A run stops with ``event``; ``sigma`` and ``distance``: the singular value and its ratio to the largest that
    stopped it, where one did (a start there raises a SingularityError carrying them)."""

    def __init__(self, event: Event, sigma: float | None = None, distance: float | None = None):
        self.event, self.sigma, self.distance = event, sigma, distance


def _passive_distance(mech: Mechanism, q: np.ndarray) -> tuple[float, float, int]:
    """The smallest singular value of the passive columns of the homogenised constraint Jacobian at ``q``
    (:mod:`pkm.core.model.scale`) above ``RTOL`` times the largest, its ratio to the largest (the distance to a
    direct singularity that ``singular_tol`` is compared with: the same for the mechanism scaled in size), and how
    many there are: ``(sigma [m], distance, rank)``."""
    s = np.linalg.svd(JacobianScales.of(mech).constraint(constraints.jacobian(mech, q))[:, mech.passive_v],
                      compute_uv=False)
    nonzero = s[s > RTOL * s[0]] if s.size and s[0] > 0.0 else s[:0]
    if not nonzero.size:
        return 0.0, 0.0, 0
    return float(nonzero[-1]), float(nonzero[-1] / nonzero[0]), int(nonzero.size)


@dataclass
class _Dynamics:
    """The closed-loop right-hand side, warm-started from the last configuration it closed."""

    mech: Mechanism
    controller: Callable[[float, np.ndarray, np.ndarray], np.ndarray]
    friction: bool
    saturate: bool
    limits: bool
    singular_tol: float
    coulomb_velocity: float
    step_tol: float
    q: np.ndarray  # the last closed configuration (the next closure's seed)
    base: str = "fixed"  # a floating base "free": x = (qa, qd, base pose (7), base twist (6)); else x = (qa, qd)
    limit: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.limit = np.array([a.max_effort for a in self.mech.actuators])

    def close(self, qa: np.ndarray, seed: np.ndarray, t: float, pose: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
        """The loops closed from ``seed`` at ``qa``: the configuration and the constraint Jacobian there (the last
        Newton pass's, which the model takes instead of computing it again)."""
        mech = self.mech
        q = mech.with_actuated(seed, qa)
        if pose is not None and mech.base is not None:  # (a free base: its pose from the state, unit quaternion)
            at = mech.base.idx_q
            q[at:at + 3] = pose[:3]
            q[at + 3:at + 7] = pose[3:] / np.linalg.norm(pose[3:])
        pv, weights = mech.passive_v, JacobianScales.of(mech).closure_residual
        for _ in range(12):
            r, J = constraints.residual_and_jacobian(mech, q)
            if np.max(np.abs(r * weights), initial=0.0) <= CLOSURE_TOL:
                return q, J
            dv = np.zeros(mech.nv)
            dv[pv] = -least_squares(J[:, pv], r)
            q = pin.integrate(mech.model, q, dv)
        gap, _, closure = constraints.worst_closure(mech, constraints.residual(mech, q))
        sigma, near, _ = _passive_distance(mech, seed)
        if near < SINGULAR_CLOSURE * self.singular_tol:  # (the closure fails because a singularity is near)
            raise _Stop(Event("singularity", t, f"the loops do not close (closure {closure!r} open by {gap:.3g}) "
                                                f"within {near:.3g} (relative) of a direct singularity"), sigma, near)
        raise _Stop(Event("assembly_mode", t, f"the loops do not close from the previous configuration (closure "
                                              f"{closure!r} open by {gap:.3g}): the motion left its assembly mode"))

    def state(self, t: float, qa: np.ndarray, qd: np.ndarray, seed: np.ndarray, pose: np.ndarray | None = None,
              twist: np.ndarray | None = None) -> tuple[ActuatorSpaceModel, np.ndarray]:
        """The model at ``(qa, qd)`` (closed from ``seed``; a free base at ``pose``, ``twist``) and the efforts
        applied there."""
        if not (np.all(np.isfinite(qa)) and np.all(np.isfinite(qd))):
            raise _Stop(Event("singularity", t, "the state is no longer finite (a singularity crossed)"))
        q, Jc = self.close(qa, seed, t, pose)
        try:
            model = _evaluate(self.mech, q, qd, RTOL, self.coulomb_velocity, self.base, twist, Jc)
        except SingularityError as exc:
            raise _Stop(Event("singularity", t, str(exc)), exc.sigma_min, exc.distance) from None
        tau = self.efforts(t, q, model.v)
        return model, tau

    def efforts(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        try:
            tau = self.controller(t, q.copy(), v.copy())
        except PkmError:
            raise
        except Exception as exc:
            raise ControllerError(t, f"raised {type(exc).__name__}: {exc}") from exc
        try:
            tau = np.asarray(tau, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ControllerError(t, f"returned {type(tau).__name__}, not {self.mech.na} numbers") from exc
        if tau.shape != (self.mech.na,):
            raise ControllerError(t, f"returned shape {tau.shape}, expected ({self.mech.na},) efforts in "
                                     f"{list(self.mech.actuated_names)} order")
        if not np.all(np.isfinite(tau)):
            raise ControllerError(t, f"returned non-finite efforts {tau}")
        return np.clip(tau, -self.limit, self.limit) if self.saturate else tau

    def rates(self, t: float, x: np.ndarray, seed: np.ndarray) -> tuple[np.ndarray, np.ndarray, ActuatorSpaceModel,
                                                                          np.ndarray]:
        """``dx/dt`` for ``x = (qa, qd)`` (a free base: ``(qa, qd, pose, twist)``), with the closed configuration, the
        model and the efforts."""
        na = self.mech.na
        free = self.base == "free"
        pose, twist = (x[2 * na:2 * na + 7], x[2 * na + 7:]) if free else (None, None)
        model, tau = self.state(t, x[:na], x[na:2 * na], seed, pose, twist)
        rhs = tau + (model.friction if self.friction else 0.0) - model.h
        try:
            qdd = _solve_inertia(model.M, rhs, JacobianScales.of(self.mech).actuated)
        except SingularityError as exc:
            raise _Stop(Event("singularity", t, str(exc)), exc.sigma_min, exc.distance) from None
        if not free or pose is None or twist is None:
            return np.concatenate([x[na:2 * na], qdd]), model.q, model, tau
        base_a = model.joint_accelerations(qdd, friction=self.friction)[self.mech.base_v]
        return np.concatenate([x[na:2 * na], qdd, _pose_rate(pose, twist), base_a]), model.q, model, tau


def _pose_rate(pose: np.ndarray, twist: np.ndarray) -> np.ndarray:
    """The rate of a free-flyer's ``(p, quaternion x y z w)`` under its twist (linear, angular, in its own frame):
    ``ṗ = R v``, ``q̇ = ½ q ⊗ (ω, 0)``."""
    quat = pose[3:] / np.linalg.norm(pose[3:])
    R = pin.Quaternion(quat[3], quat[0], quat[1], quat[2]).matrix()
    xyz, w, omega = pose[3:6], pose[6], twist[3:]
    return np.concatenate([R @ twist[:3], 0.5 * (w * omega + np.cross(xyz, omega)), [-0.5 * float(xyz @ omega)]])


def _controller(mech: Mechanism, controller: object, torques: object) -> Callable[[float, np.ndarray, np.ndarray],
                                                                                   np.ndarray]:
    if controller is not None and torques is not None:
        raise InvalidInputError("torques", "give a controller or a torque table, not both", torques)
    if controller is not None:
        if not callable(controller):
            raise InvalidInputError("controller", "expected a callable (t, q, v) -> efforts", controller)
        return controller  # type: ignore[return-value]
    if torques is None:
        zero = np.zeros(mech.na)
        return lambda t, q, v: zero
    if not isinstance(torques, (tuple, list)) or len(torques) != 2:
        raise InvalidInputError("torques", "expected (times, efforts): N times [s] and N x na efforts", torques)
    times = as_array(torques[0], "torques times", "N times [s]")
    table = as_array(torques[1], "torques efforts", f"N x {mech.na} efforts")
    if table.ndim == 1 and mech.na == 1:
        table = table[:, None]
    if times.ndim != 1 or len(times) < 1 or table.shape != (len(times), mech.na):
        raise InvalidInputError("torques", f"expected N times and N x {mech.na} efforts, got shapes {times.shape} "
                                           f"and {table.shape}", torques)
    if not (np.all(np.isfinite(times)) and np.all(np.isfinite(table))):
        raise InvalidInputError("torques", "the table holds non-finite values", torques)
    if np.any(np.diff(times) <= 0.0):
        raise InvalidInputError("torques", "the times must increase strictly", times)
    return _Table(times, table)


class _Table:
    """A sampled torque table, interpolated linearly per actuator (held outside its span); the C route reads it."""

    def __init__(self, times: np.ndarray, values: np.ndarray):
        self.times, self.values = times, values

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.array([np.interp(t, self.times, self.values[:, j]) for j in range(self.values.shape[1])])


def simulate(mech: Mechanism, q0: ArrayLike | None = None, v0: ArrayLike | None = None, duration: float = 1.0,
             dt: float = 1e-3, controller: Controller | None = None, *,
             torques: tuple[ArrayLike, ArrayLike] | None = None, method: str = "rk4", friction: bool = True,
             saturate: bool = True, limits: bool = True, singular_tol: float = 1e-3, coulomb_velocity: float = COULOMB_VELOCITY,
             step_tol: float = 1e-9, max_steps: int = MAX_STEPS, backend: str = "auto",
             base: str | None = None) -> Simulation:
    """Simulate ``mech`` from ``(q0, v0)`` for ``duration`` seconds (module doc).

    Args:
        mech: The mechanism.
        q0: The initial configuration: assembled (nq,), or the actuated coordinates (na,) closed from the
            reference; default the reference.
        v0: The initial actuated rates (na,) or joint rates (nv,) read on their actuated entries (and a free base's
            twist on its free-flyer entries; with actuated rates alone the base starts at rest); default rest.
        duration: Simulated time [s] (> 0).
        dt: The sample period [s], the step of ``"rk4"`` (> 0).
        controller: ``(t, q, v) -> τ_a`` (module doc); default no effort.
        torques: A sampled table ``(times (N,) [s], efforts (N, na))`` instead of a controller.
        method: ``"rk4"`` or ``"radau"`` (module doc).
        friction: Apply the joints' viscous and Coulomb friction (:class:`~pkm.core.model.actuators.Actuator`,
            Pinocchio's ``damping`` and ``friction``).
        saturate: Clip each effort to its actuator's peak (else continuous) limit.
        limits: Stop where a joint leaves its position limits or an actuator exceeds its speed limit (else those
            limits are not watched: the model's free motion, as in an energy check).
        singular_tol: Stop this close to a direct singularity (relative singular value of the homogenised passive
            Jacobian, dimensionless: :attr:`pkm.Diagnostics.direct_distance` where there are no idle motions).
        coulomb_velocity: The speed over which the Coulomb friction's sign is smoothed [rad/s or m/s].
        step_tol: ``"rk4"``: a step is halved (up to 8 times) where the closed configuration at its end lies
            further than this from the stages' prediction [rad or m]: near a singularity the passive joints move
            fast and a fixed step would lose accuracy, or the assembly mode.
        max_steps: Refuse runs of more samples than this.
        backend: ``"auto"``, ``"python"`` or ``"c"`` (module doc): where the ``"rk4"`` steps run.
        base: A floating base ``"free"`` (default where there is one: no wrench on it) or ``"fixed"`` (held where
            ``q0`` puts it) (module doc).

    Returns:
        A :class:`Simulation` (with its :class:`Event` if it stopped early).

    Raises:
        InvalidInputError: a bad argument (``dt <= 0``, a run beyond ``max_steps``, a torque table of the wrong
            shape...).
        ControllerError: the controller raised or returned efforts of the wrong shape, or not finite.
        SingularityError: the initial state is singular (``kind="start"``; its ``sigma_min`` and ``distance`` are
            those the detail states, or measured at the initial configuration).
        CompilerError: ``backend="c"`` without a C compiler.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> sim = pkm.simulate(delta, duration=0.02, dt=0.005)  # no effort: the platform falls
        >>> sim.time
        array([0.   , 0.005, 0.01 , 0.015, 0.02 ])
        >>> np.round(sim.task[:, 2], 5)
        array([-0.25438, -0.25451, -0.25492, -0.2556 , -0.25656])
        >>> hold = pkm.gravity_efforts(delta, delta.q_reference)
        >>> still = pkm.simulate(delta, duration=0.02, dt=0.005, controller=lambda t, q, v: hold)  # held still
        >>> np.round(still.task[:, 2], 6)
        array([-0.254375, -0.254375, -0.254375, -0.254375, -0.254375])
    """
    mech = check_mechanism(mech)
    require_physical(mech, "the simulation")
    method = as_choice(method, METHODS, "method")
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise InvalidInputError("backend", f"use one of {list(BACKENDS)}, got {backend!r}", backend)
    base = base_choice(mech, base)
    if base == "free" and backend == "c":
        raise InvalidInputError("backend", "the C route models a held base: a free floating base runs in Python "
                                           "(backend='python' or 'auto'), or pass base='fixed'", backend)
    duration = as_scalar(duration, "duration", low=0.0, strict_low=True)
    dt = as_scalar(dt, "dt", low=0.0, strict_low=True)
    singular_tol = as_scalar(singular_tol, "singular_tol", low=0.0)
    coulomb_velocity = as_scalar(coulomb_velocity, "coulomb_velocity", low=0.0, strict_low=True)
    step_tol = as_scalar(step_tol, "step_tol", low=0.0, strict_low=True)
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise InvalidInputError("max_steps", "expected a positive integer", max_steps)
    if duration / dt - 1e-9 > max_steps:  # (duration / dt may overflow to inf)
        raise InvalidInputError("dt", f"{duration:g} s at dt = {dt:g} s is {duration / dt:.6g} steps, more than "
                                      f"max_steps = {max_steps}: raise dt or max_steps, or shorten the run", dt)
    n_steps = math.ceil(duration / dt - 1e-9)
    ctrl = _controller(mech, controller, torques)
    if q0 is None:
        q = mech.q_reference.copy()
    elif np.size(np.asarray(q0, dtype=object)) == mech.na and mech.na != mech.nq:  # (object: ragged input counts)
        q = close_loops(mech, mech.check_actuated(q0, "q0", positions=True)).q
    else:
        q = mech.check_q(q0, "q0")
        gap, _, closure = constraints.worst_closure(mech, constraints.residual(mech, q))
        if gap > 1e-9:
            raise InvalidInputError("q0", f"not assembled: closure {closure!r} open by {gap:.3g} (close it with "
                                          "pkm.close_loops)", gap)
    _, _, qd, _, twist = _check_state(mech, q, v0, base, "v0")  # (all joint rates give a free base its twist)
    dyn = _Dynamics(mech, ctrl, friction, saturate, bool(limits), singular_tol, coulomb_velocity, step_tol, q, base)
    x = np.concatenate([mech.actuated_q(q), qd])
    if base == "free" and mech.base is not None:
        x = np.concatenate([x, q[mech.base.idx_q:mech.base.idx_q + 7], twist])
    sim = _compiled(mech, method, "python" if base == "free" else backend, n_steps)
    if sim is not None:
        table = ctrl if isinstance(ctrl, _Table) else _Table(np.zeros(1), np.zeros((1, mech.na))) \
            if controller is None else None
        return _rk4_c(dyn, sim, x, q, dt, n_steps, table)
    run = _rk4 if method == "rk4" or n_steps == 0 else _radau  # (no step: the initial sample alone)
    return run(dyn, x, q, dt, n_steps, method)


class _Recorder:
    def __init__(self, dyn: _Dynamics):
        self.dyn = dyn
        self.t: list[float] = []
        self.q: list[np.ndarray] = []
        self.models: list[ActuatorSpaceModel] = []
        self.tau: list[np.ndarray] = []
        self.qdd: list[np.ndarray] = []

    def add(self, t: float, q: np.ndarray, model: ActuatorSpaceModel, tau: np.ndarray, qdd: np.ndarray) -> None:
        self.t.append(t)
        self.q.append(q)
        self.models.append(model)
        self.tau.append(tau)
        self.qdd.append(qdd)

    def check(self, t: float, model: ActuatorSpaceModel) -> None:
        """Raise :class:`_Stop` at a limit or near a singularity."""
        mech = self.dyn.mech
        outside = mech.outside_limits(model.q) if self.dyn.limits else ()
        if outside:
            j = mech.joints[outside[0]]
            lo, hi = mech.limits[outside[0]]
            raise _Stop(Event("joint_limit", t, f"joint {outside[0]!r} at {model.q[j.idx_q]:.6g} outside its limits "
                                                f"[{lo:.6g}, {hi:.6g}]"))
        for a, rate in zip(mech.actuators, model.qd):
            if self.dyn.limits and abs(rate) > a.velocity_limit:
                raise _Stop(Event("velocity_limit", t, f"actuator {a.joint!r} at {rate:.6g} beyond its speed limit "
                                                       f"{a.velocity_limit:.6g}"))
        if self.dyn.singular_tol > 0.0 and mech.n_constraints:
            sigma, distance, rank = _passive_distance(mech, model.q)
            if rank and distance < self.dyn.singular_tol and rank == len(mech.passive_v) - model.idle.shape[1]:
                raise _Stop(Event("singularity", t, f"within {distance:.3g} (relative) of a direct singularity "
                                                    f"(singular_tol = {self.dyn.singular_tol:g})"), sigma, distance)

    def result(self, event: Event | None, method: str) -> Simulation:
        mech = self.dyn.mech
        n = len(self.t)
        q = np.array(self.q)
        v = np.array([m.v for m in self.models])
        a = np.array([m.joint_accelerations(qdd, friction=self.dyn.friction) for m, qdd in zip(self.models, self.qdd)])
        qd = np.array([m.qd for m in self.models])
        tau = np.array(self.tau)
        tm = TaskMap.of(mech)
        task = np.array([tm.value(qq) for qq in q])
        task_v = np.array([tm.jacobian(qq) @ vv for qq, vv in zip(q, v)])
        task_a = np.array([tm.jacobian(qq) @ aa + tm.bias(qq, vv) for qq, vv, aa in zip(q, v, a)])
        kinetic = np.array([m.kinetic_energy for m in self.models])
        potential = np.array([energy(mech, qq, np.zeros(mech.nv))[1] for qq in q])
        loss = -np.array([m.friction_power for m in self.models]) if self.dyn.friction else np.zeros(n)
        residual = constraints.largest(mech, q)
        return _simulation(mech, np.array(self.t), q, v, a, qd, np.array(self.qdd), task, task_v, task_a, tau,
                           residual, kinetic, potential, loss, event, method, self.dyn.base)


def _simulation(mech: Mechanism, t: np.ndarray, q: np.ndarray, v: np.ndarray, a: np.ndarray, qd: np.ndarray,
                qdd: np.ndarray, task: np.ndarray, task_v: np.ndarray, task_a: np.ndarray, tau: np.ndarray,
                residual: np.ndarray, kinetic: np.ndarray, potential: np.ndarray, loss: np.ndarray, event: Event | None,
                method: str, base: str = "fixed") -> Simulation:
    """The :class:`Simulation` of the samples' arrays (the work and the dissipated energy by the trapezoidal rule)."""
    power = np.einsum("ij,ij->i", tau, qd)
    steps = np.diff(t)
    work = np.concatenate([[0.0], np.cumsum(0.5 * steps * (power[1:] + power[:-1]))])
    dissipated = np.concatenate([[0.0], np.cumsum(0.5 * steps * (loss[1:] + loss[:-1]))])
    units = _units(mech)
    units["efforts"] = {j.name: "N m" if j.revolute else "N" for j in mech.actuated}
    units["time"], units["energy"] = {"time": "s"}, {"energy": "J"}
    limit = np.array([a.max_effort for a in mech.actuators], dtype=float)
    at = np.abs(tau) >= limit * (1.0 - 1e-12) if len(tau) else np.zeros((0, mech.na), dtype=bool)
    saturated = {name: int(n) for name, n in zip(mech.actuated_names, at.sum(axis=0))}
    return Simulation(q, v, a, q[:, mech.act_q], qd, qdd, task, task_v, task_a, tau, residual,
                      (), units, mech.limits_along(q), *interference_along(mech, q), time=t, kinetic=kinetic,
                      potential=potential, work=work, dissipated=dissipated, event=event, method=method,
                      saturated=saturated, base=base)


def _start(dyn: _Dynamics, x: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, ActuatorSpaceModel,
                                                                      np.ndarray]:
    """The first sample, checked: a start beyond a limit is bad input, a singular one a SingularityError."""
    try:
        k, q1, model, tau = dyn.rates(0.0, x, q)
        _Recorder(dyn).check(0.0, model)
    except _Stop as stop:
        if stop.event.kind in ("joint_limit", "velocity_limit"):
            raise InvalidInputError("q0" if stop.event.kind == "joint_limit" else "v0",
                                    f"the initial state is beyond a limit: {stop.event.detail}") from None
        sigma, distance = (stop.sigma, stop.distance) if stop.sigma is not None else _passive_distance(dyn.mech, q)[:2]
        raise SingularityError("start", sigma, f"the simulation cannot start: {stop.event.detail}",
                               distance=distance) from None
    return k, q1, model, tau


def _rk4_step(dyn: _Dynamics, t: float, h: float, x: np.ndarray, k1: np.ndarray, q: np.ndarray, v1: np.ndarray,
              depth: int) -> tuple[np.ndarray, np.ndarray, ActuatorSpaceModel, np.ndarray, np.ndarray]:
    """One RK4 step of ``h`` from ``(x, q)`` (``k1``, ``v1`` its rates), split in halves while the closed end
    moves more than ``dyn.step_tol`` from the stages' joint-rate prediction (a fast passive motion near a
    singularity, where a step of ``h`` would lose accuracy or the assembly mode). Returns the end's ``x``, ``q``,
    model, efforts and rates."""
    mech = dyn.mech
    integrate = mech.model
    k2, _, m2, _ = dyn.rates(t + 0.5 * h, x + 0.5 * h * k1, pin.integrate(integrate, q, 0.5 * h * v1))
    k3, _, m3, _ = dyn.rates(t + 0.5 * h, x + 0.5 * h * k2, pin.integrate(integrate, q, 0.5 * h * m2.v))
    k4, _, m4, _ = dyn.rates(t + h, x + h * k3, pin.integrate(integrate, q, h * m3.v))
    x_new = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    predicted = pin.integrate(integrate, q, h / 6.0 * (v1 + 2.0 * m2.v + 2.0 * m3.v + m4.v))
    k, q_new, model, tau = dyn.rates(t + h, x_new, predicted)
    off = pin.difference(integrate, predicted, q_new)
    off[mech.base_v] = 0.0  # (a free base's pose is the state's, not a closure's: RK4's, not the one-step prediction's)
    moved = float(np.abs(off).max())
    if moved > dyn.step_tol and depth < MAX_HALVINGS:
        xm, qm, mm, _, km = _rk4_step(dyn, t, 0.5 * h, x, k1, q, v1, depth + 1)
        return _rk4_step(dyn, t + 0.5 * h, 0.5 * h, xm, km, qm, mm.v, depth + 1)
    if moved > dyn.step_tol:
        raise _Stop(Event("singularity", t, f"a step of {h:.3g} s moves the passive joints {moved:.3g} off their "
                                            f"predicted path: the motion is too fast here (near a singularity)"))
    return x_new, q_new, model, tau, k


def _rk4(dyn: _Dynamics, x: np.ndarray, q: np.ndarray, dt: float, n_steps: int, method: str) -> Simulation:
    na = dyn.mech.na
    rec = _Recorder(dyn)
    k1, q, model, tau = _start(dyn, x, q)
    rec.add(0.0, q, model, tau, k1[na:2 * na])
    event = None
    try:
        for step in range(1, n_steps + 1):
            x, q, model, tau, k1 = _rk4_step(dyn, (step - 1) * dt, dt, x, k1, q, model.v, 0)
            rec.check(step * dt, model)
            rec.add(step * dt, q, model, tau, k1[na:2 * na])
    except _Stop as stop:
        event = Event(stop.event.kind, rec.t[-1], stop.event.detail)
    return rec.result(event, method)


@dataclass(frozen=True)
class _Base:
    """A closed state ``x = (qa, qd)``, its configuration and its map ``Ĝ``: the seed of the loop closure at a nearby
    state is ``q`` moved by ``Ĝ`` times the change of ``qa``, so that an idle motion's coordinate (which the closure
    does not fix) follows its rate (:mod:`pkm.core.differential.idle`) instead of staying where the last closure
    left it."""

    x: np.ndarray
    q: np.ndarray
    G: np.ndarray

    def rates(self, dyn: _Dynamics, t: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, ActuatorSpaceModel,
                                                                        np.ndarray]:
        """:meth:`_Dynamics.rates` at ``x``, closed from here moved by ``Ĝ (qa - qa_here)``; with idle motions, again
        by the mean of both ends' ``Ĝ`` (the trapezoidal rule for the idle coordinates)."""
        mech = dyn.mech
        step = x[:mech.na] - self.x[:mech.na]
        out = dyn.rates(t, x, pin.integrate(mech.model, self.q, self.G @ step))
        if out[2].idle.shape[1]:
            out = dyn.rates(t, x, pin.integrate(mech.model, self.q, 0.5 * (self.G + out[2].G) @ step))
        return out

    def next(self, dyn: _Dynamics, t: float, x: np.ndarray,
             last: tuple[float, np.ndarray, ActuatorSpaceModel] | None = None) -> _Base:
        """The base at ``x``, closed from here (``last``: the evaluation at ``(t, x)`` from here, if it was made)."""
        if last is not None and last[0] == t and np.array_equal(last[1], x):
            return _Base(x.copy(), last[2].q, last[2].G)
        _, q, model, _ = self.rates(dyn, t, x)
        return _Base(x.copy(), q, model.G)


def _radau(dyn: _Dynamics, x0: np.ndarray, q: np.ndarray, dt: float, n_steps: int, method: str) -> Simulation:
    from scipy.integrate import Radau

    mech = dyn.mech
    na = mech.na
    # every evaluation closes the loops from the last accepted step's configuration moved by the rates (_Base), so
    # that the right-hand side is a function of the state and an idle motion's coordinate follows its rate
    _, q, model, _ = _start(dyn, x0, q)
    start = base = _Base(x0.copy(), q, model.G)
    last: list[tuple[float, np.ndarray, ActuatorSpaceModel]] = []  # (Radau evaluates the end of each step it takes)

    def f(t: float, x: np.ndarray) -> np.ndarray:
        dx, _, model, _ = base.rates(dyn, t, x)
        last[:] = [(t, x.copy(), model)]
        return dx

    grid = np.arange(n_steps + 1) * dt
    rec = _Recorder(dyn)
    event = None
    ts, xs = [0.0], [x0]  # (the samples reached, kept when the run stops)
    budget = max(RADAU_EVALUATIONS * (n_steps + 1), RADAU_RATE * float(grid[-1]))
    try:
        solver = Radau(f, 0.0, x0, grid[-1], rtol=1e-10, atol=1e-12, max_step=max(10.0 * dt, grid[-1] / 10.0))
        while len(ts) < len(grid):
            message = solver.step()
            if solver.status == "failed":
                raise _Stop(Event("singularity", solver.t, f"Radau failed: {message}"))
            base = base.next(dyn, solver.t, solver.y, last[0] if last else None)
            interp = solver.dense_output()
            while len(ts) < len(grid) and grid[len(ts)] <= solver.t:
                ts.append(float(grid[len(ts)]))
                xs.append(interp(ts[-1]))
            if len(ts) < len(grid) and solver.nfev > budget:
                raise _Stop(Event("singularity", solver.t, f"Radau's steps took more than {budget:.0f} evaluations "
                                                           f"({RADAU_EVALUATIONS} a sample or {RADAU_RATE:g} a "
                                                           "simulated second): the motion is too fast here (near a "
                                                           "singularity, or a state far too fast)"))
    except _Stop as stop:
        event = stop.event
    base = start
    for t, x in zip(ts, xs):
        try:
            dx, qq, model, tau = base.rates(dyn, float(t), x)
            base = _Base(x.copy(), qq, model.G)
            rec.check(float(t), model)
        except _Stop as stop:
            event = stop.event
            break
        rec.add(float(t), qq, model, tau, dx[na:2 * na])
    if event is not None:
        event = Event(event.kind, rec.t[-1], event.detail)
    return rec.result(event, method)


# ---------------------------------------------------------------------- the C route
def _compiled(mech: Mechanism, method: str, backend: str, n_steps: int) -> Simulator | None:
    """The compiled simulation where the backend and the run ask for it (module doc), else None."""
    from pkm.core.twin import simulation

    if backend == "python" or (backend == "auto" and n_steps < AUTO_STEPS and mech not in simulation._SIMULATORS):
        return None
    if method != "rk4":
        if backend == "c":
            raise InvalidInputError("backend", f"the C route runs method='rk4', not {method!r}", backend)
        return None
    try:
        sim = simulation.simulator(mech)
    except (SpecError, ValueError) as exc:  # (idle motions: the closure has no unique solution to step along)
        if backend == "c":
            raise InvalidInputError("backend", f"the C route does not run this mechanism: {exc}", backend) from None
        return None
    if sim.lib is None:
        if backend == "c":
            raise CompilerError("the compiled simulation (backend='c')", sim.how)
        return None
    return sim


def _rk4_c(dyn: _Dynamics, sim: Simulator, x: np.ndarray, q: np.ndarray, dt: float, n_steps: int,
           table: _Table | None) -> Simulation:
    """``"rk4"`` in C (:mod:`pkm.core.twin.simulation`), a step the C route hands back taken by :func:`_rk4_step`."""
    mech = dyn.mech
    na, nq, nv = mech.na, mech.model.nq, mech.nv
    n = n_steps + 1
    rows = {"X": np.empty((n, 2 * na)), "Q": np.empty((n, nq)), "QDD": np.empty((n, na)), "V": np.empty((n, nv)),
            "TAU": np.empty((n, na)), "KIN": np.empty(n), "FQD": np.empty(n)}

    def put(i: int, x: np.ndarray, q: np.ndarray, model: ActuatorSpaceModel, tau: np.ndarray, k: np.ndarray) -> None:
        rows["X"][i], rows["Q"][i], rows["QDD"][i], rows["V"][i], rows["TAU"][i] = x, q, k[na:], model.v, tau
        rows["KIN"][i], rows["FQD"][i] = model.kinetic_energy, model.friction @ model.qd

    k1, q, model, tau = _start(dyn, x, q)
    put(0, x, q, model, tau, k1)
    settings = np.array([1.0 if dyn.friction else 0.0, dyn.coulomb_velocity, 1.0 if dyn.saturate else 0.0,
                         1.0 if dyn.limits else 0.0, dyn.singular_tol, dyn.step_tol, dt])
    named = [(mech.joints[name].idx_q, lo, hi) for name, (lo, hi) in mech.limits.items() if name in mech.joints]
    limits = (np.array([i for i, _, _ in named], dtype=np.int64), np.array([lo for _, lo, _ in named], dtype=float),
              np.array([hi for _, _, hi in named], dtype=float))
    speed = np.array([a.velocity_limit for a in mech.actuators], dtype=float)
    effort = np.ascontiguousarray(dyn.limit, dtype=float)
    failure: list[BaseException] = []

    def call(t: float, qp: object, vp: object, taup: object) -> int:  # (the controller, called back from C)
        try:
            tau = dyn.efforts(t, np.ctypeslib.as_array(qp, (nq,)).copy(), np.ctypeslib.as_array(vp, (nv,)).copy())
            np.ctypeslib.as_array(taup, (na,))[:] = tau
        except BaseException as exc:  # (raised again below, out of C)
            failure.append(exc)
            return 1
        return 0

    tables = None if table is None else (np.ascontiguousarray(table.times, dtype=float),
                                         np.ascontiguousarray(table.values, dtype=float))
    done, event = 0, None
    while done < n_steps:
        done, code = sim.run(settings, effort, speed, limits, tables, call if table is None else None, done, n_steps,
                             rows)
        if code == 0:
            break
        if failure:
            raise failure[0]
        if code == 1:
            raise CompilerError("the compiled simulation", "a generated function failed")
        x, q, qdd = rows["X"][done].copy(), rows["Q"][done].copy(), rows["QDD"][done]
        try:  # (the step the C route handed back: Python halves it, or stops, as the Python route)
            x, q, model, tau, k = _rk4_step(dyn, done * dt, dt, x, np.concatenate([x[na:], qdd]), q,
                                            rows["V"][done].copy(), 0)
            _Recorder(dyn).check((done + 1) * dt, model)
        except _Stop as stop:
            event = Event(stop.event.kind, done * dt, stop.event.detail)
            break
        done += 1
        put(done, x, q, model, tau, k)
    return _c_result(dyn, sim, {key: value[:done + 1].copy() if done < n_steps else value
                                for key, value in rows.items()}, dt, event)


def _c_result(dyn: _Dynamics, sim: Simulator, rows: dict[str, np.ndarray], dt: float, event: Event | None) \
        -> Simulation:
    """The :class:`Simulation` of the C route's samples (one compiled batch; a sample whose LU pivot fails, by the
    core, as :meth:`_Recorder.result`)."""
    from pkm.core.twin.kernels import PIVOT_FLOOR

    mech = dyn.mech
    na = mech.na
    Q, V, QDD, X = rows["Q"], rows["V"], rows["QDD"], rows["X"]
    a, task, task_v, task_a, potential, residual, pivot = sim.samples(Q, V, QDD)
    tm = TaskMap.of(mech)
    for k in np.flatnonzero(~(pivot[:, 0] >= PIVOT_FLOOR)):
        model = _evaluate(mech, Q[k], X[k, na:], RTOL, dyn.coulomb_velocity)
        a[k] = model.joint_accelerations(QDD[k])
        task[k], task_v[k] = tm.value(Q[k]), tm.jacobian(Q[k]) @ V[k]
        task_a[k] = tm.jacobian(Q[k]) @ a[k] + tm.bias(Q[k], V[k])
        potential[k] = energy(mech, Q[k], np.zeros(mech.nv))[1]
        residual[k] = constraints.largest(mech, Q[k])[0]
    loss = -rows["FQD"] if dyn.friction else np.zeros(len(Q))
    return _simulation(mech, np.arange(len(Q)) * dt, Q, V, a, X[:, na:], QDD, task, task_v, task_a, rows["TAU"],
                       residual[:, 0], rows["KIN"], potential[:, 0], loss, event, "rk4")


__all__ = ["AUTO_STEPS", "BACKENDS", "MAX_STEPS", "METHODS", "Controller", "Event", "Simulation", "simulate"]
