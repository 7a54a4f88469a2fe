"""Position problems of closed-loop mechanisms, solved on the Pinocchio tree.

* :func:`close_loops` (forward kinematics): given the actuated coordinates, find
  the passive ones so that every loop closes.
* :func:`solve_ik` (inverse kinematics): given the task coordinates (end-effector
  pose or components, plus any joint outputs), find every joint coordinate.

Both are Gauss-Newton iterations on the tangent space (``pin.integrate``) with
rank-revealing least-squares steps (a planar mechanism closed with 3-D point
constraints has zero rows), a step-length cap and a backtracking line search.
Far from the seed they follow a continuation path (actuated coordinates or task
coordinates moved in steps of at most ``max_step``), each step corrected by
Newton, so that the solution stays on the seed's assembly mode and working mode
unless the path crosses a singularity. A straight path in actuated coordinates can
leave the workspace through a fold near a direct singularity: loop closure then
raises :class:`~pkm.errors.ConvergenceError` rather than jump to another assembly
mode; follow a path inside the workspace instead (seed each solve with the last).
Every solver stops after a bounded number of iterations and raises
:class:`~pkm.errors.ConvergenceError` with its residual: at most ``max_iter`` Newton iterations
per continuation step, at most :data:`MAX_STEPS` steps planned (a farther target takes longer
steps, which fail early when it is out of reach), and at most :data:`MAX_TOTAL_ITER` Newton
iterations for a whole solve. No solver returns a non-finite configuration.

Scale-free: :func:`close_loops` and :func:`solve_ik` iterate in the metric of :mod:`pkm.core.model.scale`, every
length counted in the mechanism's characteristic length ``L`` (:attr:`~pkm.core.Mechanism.characteristic_length`):
their tolerance bounds the residual with a closure's translation rows and the task's lengths divided by ``L``
(angles in rad), a Newton step is capped and a continuation step planned with prismatic coordinates and task lengths
in ``L`` (angles in rad), and the least-squares steps are taken in that metric. A copy of a mechanism scaled in size
(:func:`~pkm.core.model.builder.scaled_mechanism`) then takes the same steps, the same iterations and the same
verdicts, its lengths scaled (to round-off). :attr:`SolveResult.relative_residual` is the residual so counted,
:attr:`SolveResult.residual` the same equations' in m and rad.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.kinematics import constraints
from pkm.core.kinematics.configuration import Configuration
from pkm.core.kinematics.labels import ModeLabel, mode_label, mode_label_at
from pkm.core.kinematics.newton import gauss_newton
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism, spread
from pkm.core.model.scale import JacobianScales
from pkm.errors import (
    AssemblyError,
    BranchError,
    ConvergenceError,
    InvalidInputError,
    ModeChangeWarning,
    UnreachableError,
)
from pkm.validation import as_count, as_scalar, as_tolerance, wrap_angle

DEFAULT_TOL = 1e-12
MAX_STEPS = 1000  #: continuation steps planned at most (a farther target gets longer steps)
MAX_TOTAL_ITER = 5_000  #: Newton iterations at most for one solve, every continuation step included


#: ``solve_at(q, s, tol) -> (q, residual, iterations, residual in m and rad)``: a continuation step's correction
#: (:func:`_follow`; the first residual the one ``tol`` bounds).
_StepSolver = Callable[[np.ndarray, float, float], tuple[np.ndarray, float, int, float]]


@dataclass(frozen=True)
class SolveResult:
    """Outcome of a position solver.

    Attributes:
        q: The configuration found (nq,).
        converged: Whether the residual reached the tolerance.
        residual: Infinity norm of the equations at ``q`` (m for points, rad for angles).
        iterations: Newton iterations, all continuation steps included.
        steps: Continuation steps taken (1 when solved directly).
        branch_signs: Signs of the default-branch joints at ``q`` (empty without branches).
        mode: The assembly and working mode labels at ``q`` (:class:`~pkm.core.kinematics.labels.ModeLabel`: the
            signs of the solvers' Newton blocks relative to the reference's; a solve that ends in another mode than
            its seed's warns, :class:`~pkm.errors.ModeChangeWarning`).
        outside_limits: The joints whose coordinate at ``q`` lies outside the position limits their URDF
            states (:meth:`pkm.core.Mechanism.outside_limits`); pkm's solvers do not enforce limits.
        relative_residual: The residual the solver's tolerance bounds (dimensionless): the infinity norm of the same
            equations with lengths (a closure's translation rows, the task's lengths) divided by the characteristic
            length ``L`` and angles in rad (:func:`close_loops`, :func:`solve_ik`; :func:`assemble`'s by its own
            ``L``); NaN where a solver states none. ``converged`` is ``relative_residual <= tol``.
        clearance: The smallest signed distance between the bodies checked for collision at ``q`` [m] (negative:
            two interpenetrate; :func:`pkm.clearance` has every pair), where the solve was asked for it
            (``collisions=True``), else None; pkm's solvers do not avoid collisions.
    """

    q: np.ndarray
    converged: bool
    residual: float
    iterations: int
    steps: int = 1
    branch_signs: dict[str, int] = field(default_factory=dict)
    outside_limits: tuple[str, ...] = ()
    mode: ModeLabel = field(default_factory=ModeLabel)
    relative_residual: float = math.nan
    clearance: float | None = None

    @property
    def interferes(self) -> bool:
        """Whether two checked bodies interpenetrate at ``q`` (False where the clearance was not asked for)."""
        return self.clearance is not None and self.clearance < 0.0

    def check(self, mech: Mechanism, *, tol: float = 1e-9) -> bool:
        """Whether this result still holds on ``mech``, checked again from ``q`` alone (as qpsolvers'
        ``Solution.is_optimal``): ``q`` a valid configuration of ``mech``; when converged, its loops closed to
        ``max(tol, relative_residual)``, each closure's gap counted as the solvers' tolerance counts it (lengths in the
        characteristic length ``L``, angles in rad: the same verdict for a copy scaled in size); the branch signs and
        the joints outside their limits as recorded. A result of another mechanism, or one edited since, does not
        hold."""
        mech = check_mechanism(mech)
        tol = as_tolerance(tol, "tol")
        try:
            q = mech.check_q(self.q)
        except InvalidInputError:
            return False
        gap = constraints.worst_closure(mech, constraints.residual(mech, q) * JacobianScales.of(mech).closure_residual)[0]
        bound = max(tol, self.relative_residual) if math.isfinite(self.relative_residual) else tol
        return bool((not self.converged or gap <= bound)
                    and self.branch_signs == _signs(mech, q) and self.outside_limits == mech.outside_limits(q))


@dataclass(frozen=True)
class ClosureProblem:
    """The loop-closure problem of :func:`close_loops` as equations ``F(q) = 0``.

    On the whole configuration: every closure residual, then the actuated coordinates less their targets
    (qpsolvers' ``Problem``, pink's ``build_ik``: inspect it, evaluate it, check a solution). A :class:`~pkm.errors.ConvergenceError` of
    :func:`close_loops` carries it (``problem``).

    Attributes:
        mech: The mechanism.
        q_actuated: The actuated coordinates asked for (spec order) [rad or m].
    """

    mech: Mechanism
    q_actuated: np.ndarray

    def residual(self, q: ArrayLike) -> np.ndarray:
        """``F(q)``: closure residuals [m, rad], then ``q_a - q_actuated`` [rad or m]."""
        q = self.mech.check_q(q)
        return np.concatenate([constraints.residual(self.mech, q), self.mech.actuated_q(q) - self.q_actuated])

    def jacobian(self, q: ArrayLike) -> np.ndarray:
        """``dF/dq`` on the tangent space (rows of :meth:`residual`, ``nv`` columns)."""
        q = self.mech.check_q(q)
        select = np.zeros((self.mech.na, self.mech.nv))
        select[np.arange(self.mech.na), self.mech.act_v] = 1.0
        return np.vstack([constraints.jacobian(self.mech, q), select])


@dataclass(frozen=True)
class IKProblem:
    """The inverse-kinematics problem of :func:`solve_ik` as equations ``F(q) = 0``.

    Every closure residual, then the task error ``-(target - task(q))`` (as :class:`ClosureProblem`; a
    :class:`~pkm.errors.ConvergenceError` of :func:`solve_ik` carries it).

    Attributes:
        mech: The mechanism.
        target: The task coordinates asked for (:meth:`~pkm.core.kinematics.task.TaskMap.parse`'s vector).
    """

    mech: Mechanism
    target: np.ndarray

    def evaluate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(F(q), dF/dq)`` from one kinematics pass (``q`` unchecked: the solvers' iterations)."""
        c = Configuration.compute(self.mech, q)
        return (np.concatenate([c.residual, -TaskMap.of(self.mech).error(self.target, c.task_value)]),
                np.array(c.closure_and_task_jacobian))

    def residual(self, q: ArrayLike) -> np.ndarray:
        """``F(q)``: closure residuals [m, rad], then the task error [m, rad]."""
        return self.evaluate(self.mech.check_q(q))[0]

    def jacobian(self, q: ArrayLike) -> np.ndarray:
        """``dF/dq`` on the tangent space."""
        return self.evaluate(self.mech.check_q(q))[1]


def _newton(mech: Mechanism, fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], q: np.ndarray,
            cols: np.ndarray | None, tol: float, max_iter: int, max_dq: float) -> tuple[np.ndarray, float, int]:
    """:func:`pkm.core.kinematics.newton.gauss_newton` on the configuration manifold (``pin.integrate``), moving only the
    velocity columns ``cols`` (all when None); returns (q, residual inf-norm, iterations)."""
    m = mech.model
    if cols is None:
        return gauss_newton(fun, q, tol=tol, max_iter=max_iter, max_step=max_dq,
                            retract=lambda x, dx: pin.integrate(m, x, dx))

    def restricted(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r, J = fun(x)
        return r, J[:, cols]

    def retract(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        full = np.zeros(m.nv)
        full[cols] = dx
        return pin.integrate(m, x, full)

    return gauss_newton(restricted, q, tol=tol, max_iter=max_iter, max_step=max_dq, retract=retract)


@dataclass(frozen=True)
class _Metric:
    """The scale-free metric of :func:`close_loops` and :func:`solve_ik` (module doc): ``rows`` multiply the
    residual (a translation or task length by ``1 / L``, an angle by 1), ``cols`` the Newton step in the joints
    (a length by ``L``, an angle by 1: the step taken in ``L`` and rad)."""

    rows: np.ndarray
    cols: np.ndarray
    length: float

    @staticmethod
    def of(mech: Mechanism, task: bool) -> _Metric:
        """The closure rows' metric, and the task rows' after them with ``task``."""
        s = JacobianScales.of(mech)
        rows = s.closure_residual
        return _Metric(np.concatenate([rows, s.task_residual]) if task else rows, s.columns, s.length)


def _scaled_newton(mech: Mechanism, fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], q: np.ndarray,
                   cols: np.ndarray | None, tol: float, max_iter: int, max_dq: float, metric: _Metric
                   ) -> tuple[np.ndarray, float, int, float]:
    """:func:`_newton` in ``metric`` (the residual's rows and the step's columns homogenised: ``tol`` and ``max_dq``
    in ``L`` and rad); returns (q, homogenised residual inf-norm, iterations, residual inf-norm in m and rad)."""
    m = mech.model
    cols = np.arange(m.nv) if cols is None else cols
    units = metric.cols[cols]
    seen: list[tuple[np.ndarray, float]] = []  # (the latest evaluations' points and raw residuals)

    def scaled(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r, J = fun(x)
        seen.append((x, float(np.max(np.abs(r), initial=0.0))))
        del seen[:-12]
        return metric.rows * r, metric.rows[:, None] * J[:, cols] * units

    def retract(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
        full = np.zeros(m.nv)
        full[cols] = units * dx
        return pin.integrate(m, x, full)

    x, res, it = gauss_newton(scaled, q, tol=tol, max_iter=max_iter, max_step=max_dq, retract=retract)
    raw = next((r for xx, r in reversed(seen) if xx is x), None)
    if raw is None:  # (not among the latest evaluations: evaluated again)
        raw = float(np.max(np.abs(fun(x)[0]), initial=0.0))
    return x, res, it, (raw if math.isfinite(raw) else math.inf)


def _result(mech: Mechanism, q: np.ndarray, converged: bool, residual: float, iterations: int,
            steps: int, mode: ModeLabel | None = None, relative: float = math.nan) -> SolveResult:
    return SolveResult(q, converged, residual, iterations, steps, _signs(mech, q), mech.outside_limits(q),
                       mode_label_at(mech, q, result=True) if mode is None else mode, relative)


class _Matrices:
    """The Newton matrices a solve's mode labels need, kept as the solver makes them (no kinematics pass of their
    own): the closure-and-task Jacobian at the last evaluation that met the final step's tolerance (the solution,
    where the solver stops) and, with ``at_seed`` (the inverse kinematics, whose first Newton iterate is its seed),
    at the first evaluation.

    The kept function's Jacobian is the closure-and-task Jacobian, or, with ``task`` (the loop closure's, with the
    closure rows only), the closure Jacobian: the task rows are then added at the solution only, from the kinematics
    pass just made in ``mech.data``."""

    def __init__(self, mech: Mechanism, *, at_seed: bool = False, task: TaskMap | None = None) -> None:
        self.mech, self.task, self.at_seed = mech, task, at_seed
        self.first: tuple[np.ndarray, np.ndarray] | None = None
        self.last: tuple[np.ndarray, np.ndarray] | None = None

    def keep(self, fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], final: bool, tol: float,
             rows: np.ndarray) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """``fun`` keeping its matrices; ``final``: the final step's, solved to ``tol`` (on the residual times
        ``rows``: :class:`_Metric`)."""
        def kept(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            r, J = fun(x)
            if self.at_seed and self.first is None:
                self.first = (x.copy(), J)
            if final and float(np.max(np.abs(rows * r), initial=0.0)) <= tol:
                full = J if self.task is None else np.vstack([J, self.task.jacobian_from(self.mech.data)])
                self.last = (x.copy(), full)
            return r, J
        return kept

    def label(self, q: np.ndarray, at: np.ndarray | None = None) -> ModeLabel:
        """The label of ``q``, from the matrices kept at ``at`` (``q``'s unwrapped copy: the same configuration;
        given for the solve's result, default ``q``, the seed), or from scratch where none were kept there."""
        kept = next((k for k in (self.last, self.first) if k is not None
                     and np.array_equal(k[0], q if at is None else at)), None)
        return mode_label_at(self.mech, q, None if kept is None else kept[1], result=at is not None)


def _warn_mode_change(what: str, seed: ModeLabel, result: SolveResult) -> None:
    """A :class:`~pkm.errors.ModeChangeWarning` when a converged ``result`` lies in another assembly or working
    mode than its seed (a block's determinant changed sign on the way: the path crossed a singularity)."""
    changed = seed.differs(result.mode) if result.converged else ()
    if changed:
        warnings.warn(ModeChangeWarning(what, changed, seed, result.mode), stacklevel=3)


#: The smallest continuation step, relative to the first, before a path is judged to leave the workspace.
MIN_STEP = 1e-3


def _follow(mech: Mechanism, what: str, solve_at: _StepSolver, q: np.ndarray, n_steps: int, tol: float,
            raise_on_failure: bool, matrices: _Matrices, min_step: float = MIN_STEP) -> SolveResult:
    """Continuation from ``s = 0`` (the seed ``q``) to ``s = 1`` (the target).

    ``solve_at(q, s, tol) -> (q, residual, iterations, raw residual)`` corrects at path parameter ``s`` from
    ``q``.
    Steps start at ``1 / n_steps``, halve on failure, grow again on success; intermediate points
    are solved to 1e-9, the target to ``tol``. When the step falls below ``min_step`` of its initial length
    the path has left the workspace: a last correction at the target gives the residual reported.
    """
    total, steps = 0, 0
    s, ds = 0.0, 1.0 / n_steps
    while True:
        if total >= MAX_TOTAL_ITER:
            q_new, res, it, raw = solve_at(q, 1.0, tol)
            result = _result(mech, q_new, False, raw, total + it, steps, relative=res)
            if raise_on_failure:
                err = _failure(mech, what, result, tol)
                raise ConvergenceError(what, err.residual, err.iterations, tol, result,
                                       f"gave up after {MAX_TOTAL_ITER} Newton iterations at {s:.0%} of the path; "
                                       "seed nearer the target (q0) or split the path")
            return result
        s_next = min(1.0, s + ds)
        t = tol if s_next >= 1.0 else max(tol, 1e-9)
        q_new, res, it, raw = solve_at(q, s_next, t)
        total += it
        if res <= t:
            q, s, steps = q_new, s_next, steps + 1
            if s >= 1.0:
                q_wrapped = mech.wrap(q)
                return _result(mech, q_wrapped, True, raw, total, steps, matrices.label(q_wrapped, q), res)
            ds = min(ds * 1.5, 1.0 / n_steps)
        else:
            ds *= 0.5
            if ds < min_step / n_steps:
                res_path = res
                q_new, res, it, raw = solve_at(q, 1.0, tol)
                result = _result(mech, q_new, False, raw, total + it, steps, relative=res)
                if raise_on_failure and res <= tol:  # the target closes, but not by following the seed's branch
                    raise ConvergenceError(f"{what} along the path from the seed", res_path, result.iterations,
                                           tol, result,
                                           f"the path left the workspace at {s:.0%} of the way; "
                                           "a direct correction at the target closes, possibly in "
                                           "another assembly mode: seed nearer the target (q0)")
                if raise_on_failure:
                    raise _failure(mech, what, result, tol)
                return result


def close_loops(mech: Mechanism, q_actuated: ArrayLike, q0: ArrayLike | None = None, *, tol: float = DEFAULT_TOL,
                max_iter: int = 30, max_step: float = 0.1, raise_on_failure: bool = True,
                min_step: float = MIN_STEP, collisions: bool = False) -> SolveResult:
    """Forward position problem: passive coordinates for given actuated ones.

    Args:
        mech: The mechanism.
        q_actuated: Actuated coordinates in spec order (rad or m), shape (na,).
        q0: Seed configuration (nq,); its assembly mode is kept (a result in another assembly or working mode, the
            path having crossed a singularity, warns: :class:`~pkm.errors.ModeChangeWarning`). Default: the
            reference configuration.
        tol: Tolerance on the infinity norm of the closure residual, its translations in units of the characteristic
            length ``L`` (a gap of ``tol * L`` m) and its rotations in rad (module doc: scale-free).
        max_iter: Newton iterations allowed per continuation step.
        max_step: Largest change of an actuated coordinate per continuation step [rad, or ``L`` for a prismatic
            one].
        raise_on_failure: Raise :class:`ConvergenceError` (default) instead of returning ``converged=False``.
        min_step: The smallest continuation step, relative to the first, before the path is judged to leave the
            workspace (in (0, 1]): a search that only keeps the targets that close (random states) gives up sooner
            with a coarser one.
        collisions: Report the smallest distance between the bodies checked for collision at the result
            (:attr:`SolveResult.clearance`; about 25 us a solve on the Gough-Stewart's 66 pairs, 5 % of a close
            solve); :class:`~pkm.errors.NoCollisionGeometryError` where ``mech`` has no collision geometry.

    Returns:
        A :class:`SolveResult` whose ``q`` has the requested actuated coordinates. Where every joint is actuated
        (no passive coordinate), ``q`` is the actuated values themselves, only checked: converged where they close
        the loops, else the :class:`ConvergenceError` naming the open closure (no path followed, no mode change
        told: the seed plays no part). Under redundant actuation (:attr:`~pkm.core.Mechanism.dependent_actuators`:
        actuators whose values the others fix), the path moves the independent actuators with the dependent ones
        released (solved for with the passive joints: the straight path between two consistent targets crosses
        inconsistent values), every actuator held at the target only; values that disagree with the others' end in
        the :class:`ConvergenceError` naming the open closure and the dependent actuators.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> res = pkm.close_loops(delta, [-0.9, -0.8, -1.0])
        >>> res.converged, bool(res.residual < 1e-12)
        (True, True)
        >>> np.round(delta.actuated_q(res.q), 3)
        array([-0.9, -0.8, -1. ])
        >>> {k: round(v, 4) for k, v in pkm.task_values(delta, res.q).items()}
        {'x': -0.0232, 'y': 0.0002, 'z': -0.3691}
    """
    mech = check_mechanism(mech)
    qa1 = mech.check_actuated(q_actuated, positions=True)
    q = mech.q_reference.copy() if q0 is None else mech.check_q(q0, "q0")
    tol, max_iter, max_step = _settings(tol, max_iter, max_step)
    qa0 = mech.actuated_q(q)
    rev = np.array([j.revolute for j in mech.actuated], dtype=bool)  # angles go the short way round (+-pi)
    qa1 = np.where(rev, qa0 + wrap_angle(qa1 - qa0), qa1)
    metric = _Metric.of(mech, task=False)
    n_steps = _n_steps(np.max(np.abs(qa1 - qa0) / metric.cols[mech.act_v], initial=0.0), max_step)
    min_step = as_scalar(min_step, "min_step", low=0.0, high=1.0, strict_low=True)
    if not len(mech.passive_v):  # (every joint actuated: no path to follow, the target only checked: one step)
        n_steps, min_step = 1, 1.0

    def fun(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return constraints.residual_and_jacobian(mech, qq)

    matrices = _Matrices(mech, task=TaskMap.of(mech))

    # (redundant actuation, joints left to solve for: the dependent actuators released along the way, solved for
    # with the passive joints while the others move; every actuator held at its value at the target only)
    held = np.array([n not in mech.dependent_actuators for n in mech.actuated_names], dtype=bool)
    released = np.sort(np.concatenate([mech.passive_v, mech.act_v[~held]]))

    def solve_at(q: np.ndarray, s: float, t: float) -> tuple[np.ndarray, float, int, float]:
        qa = qa0 + s * (qa1 - qa0)
        if s < 1.0 and not held.all() and len(mech.passive_v):
            return _scaled_newton(mech, matrices.keep(fun, False, t, metric.rows),
                                  mech.with_actuated(q, np.where(held, qa, mech.actuated_q(q))), released, t,
                                  max_iter, 0.5, metric)
        return _scaled_newton(mech, matrices.keep(fun, s >= 1.0, t, metric.rows), mech.with_actuated(q, qa),
                              mech.passive_v, t, max_iter, 0.5, metric)

    seed = mode_label(mech, q)  # (found kept where the seed is the last solve's result: a path followed)
    try:
        result = _follow(mech, "loop closure", solve_at, q, n_steps, tol, raise_on_failure, matrices, min_step)
    except ConvergenceError as exc:
        exc.problem = ClosureProblem(mech, qa1)
        raise
    if len(mech.passive_v):
        _warn_mode_change("loop closure", seed, result)
    return _with_clearance(mech, result) if collisions else result


def _with_clearance(mech: Mechanism, result: SolveResult) -> SolveResult:
    """``result`` with its :attr:`SolveResult.clearance`."""
    import dataclasses

    from pkm.core.collision import CollisionModel
    from pkm.core.collision.interference import minimum_distances

    CollisionModel.of(mech).require()
    return dataclasses.replace(result, clearance=float(minimum_distances(mech, result.q[None])[0]))


def solve_ik(mech: Mechanism, target: ArrayLike | Mapping[str, object], q0: ArrayLike | None = None, *,
             branch: str | None = None, tol: float = DEFAULT_TOL, max_iter: int = 30, max_step: float = 0.25,
             raise_on_failure: bool = True, collisions: bool = False) -> SolveResult:
    """Inverse position problem: every joint coordinate for given task coordinates.

    Args:
        mech: The mechanism.
        target: Task coordinates (see :meth:`pkm.core.kinematics.task.TaskMap.parse`): a vector, or a mapping by name of
            some of them (``{"z": "-36cm"}``), the others those of the reference; values may carry units.
        q0: Seed configuration; default: the reference configuration (or, with ``branch``,
            the reference with that branch's joint signs imposed and the loops re-closed). A result in another
            working or assembly mode than the seed's warns (:class:`~pkm.errors.ModeChangeWarning`).
        branch: Working mode the solution must lie on; checked at the end (:class:`BranchError`).
        tol: Tolerance on the infinity norm of closure residual and task error, their lengths in units of the
            characteristic length ``L`` and their angles in rad (module doc: scale-free).
        max_iter: Newton iterations allowed per continuation step.
        max_step: Largest task change per continuation step [``L`` or rad] (0.25: 5 cm on the Delta, whose
            ``L`` is 0.21 m, as the 0.05 m of the former default in m; 0.25 rad).
        raise_on_failure: Raise :class:`ConvergenceError` instead of returning ``converged=False``.
        collisions: Report the smallest distance between the bodies checked for collision at the result
            (:attr:`SolveResult.clearance`; about 25 us, under 1 % of a solve on the Gough-Stewart);
            :class:`~pkm.errors.NoCollisionGeometryError` where ``mech`` has no collision geometry.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> ik = pkm.solve_ik(delta, [0.02, 0.0, -0.36])
        >>> ik.converged
        True
        >>> np.round(delta.actuated_q(ik.q), 4)
        array([-0.8243, -0.9097, -0.7367])
        >>> ik = pkm.solve_ik(delta, {"z": "-34cm"})
        >>> {k: round(v, 6) for k, v in pkm.task_values(delta, ik.q).items()}
        {'x': 0.0, 'y': 0.0, 'z': -0.34}
    """
    mech = check_mechanism(mech)
    task = TaskMap.of(mech)
    y1 = task.parse(target)
    tol, max_iter, max_step = _settings(tol, max_iter, max_step)
    if branch is not None:
        mech.branch(branch)  # an unknown branch is refused before any work
    if q0 is None:
        q = branch_seed(mech, branch) if branch is not None else mech.q_reference.copy()
    else:
        q = mech.check_q(q0, "q0")
    y0 = task.value(q)
    metric = _Metric.of(mech, task=True)
    dist = np.max(np.abs(task.error(y1, y0) * metric.rows[mech.n_constraints:]), initial=0.0)
    n_steps = _n_steps(dist, max_step)

    matrices = _Matrices(mech, at_seed=True)

    def solve_at(q: np.ndarray, s: float, t: float) -> tuple[np.ndarray, float, int, float]:
        goal = IKProblem(mech, y1 if s >= 1.0 else task.interpolate(y0, y1, s))
        return _scaled_newton(mech, matrices.keep(goal.evaluate, s >= 1.0, t, metric.rows), q, mech.free_v, t,
                              max_iter, 0.5, metric)

    problem = IKProblem(mech, y1)
    seed_q = q
    try:
        result = _follow(mech, "inverse kinematics", solve_at, q, n_steps, tol, raise_on_failure, matrices)
    except ConvergenceError as exc:
        if isinstance(exc.result, SolveResult):
            _raise_if_out_of_reach(mech, problem.evaluate, exc.result.q, tol, metric)
        exc.problem = problem
        raise
    q = result.q
    if result.converged and branch is not None and not mech.on_branch(q, branch):
        raise BranchError(branch, dict(mech.branch(branch).signs), mech.branch_signs(q, branch))
    _warn_mode_change("inverse kinematics", matrices.label(seed_q), result)
    return _with_clearance(mech, result) if collisions else result


def branch_seed(mech: Mechanism, branch: str, *, tol: float = DEFAULT_TOL, max_iter: int = 50) -> np.ndarray:
    """An assembled configuration on ``branch`` at the reference task coordinates.

    Two phases: Gauss-Newton on the closures, the reference task and the branch joints pinned
    to their mirrored values (sign imposed, magnitude kept), which moves every leg to the
    requested side with the platform held; then the generic inverse kinematics removes what
    the least-squares compromise left. Raises :class:`BranchError` if the result is on
    another branch.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> list(delta.spec.branches)
        ['knee_out', 'knee_in']
        >>> q = pkm.branch_seed(delta, "knee_in")
        >>> delta.on_branch(q, "knee_in"), round(pkm.task_values(delta, q)["z"], 6)
        (True, -0.254375)
    """
    mech = check_mechanism(mech)
    b = mech.branch(branch)
    tol, max_iter, _ = _settings(tol, max_iter, 1.0)
    q = mech.q_reference.copy()
    if mech.on_branch(q, branch):
        return q
    task = TaskMap.of(mech)
    y_ref = task.value(q)
    wrapped = mech.wrap(q)
    pins = np.array([mech.joints[n].idx_v for n in b.signs])
    values = np.array([sign * max(abs(wrapped[mech.joints[n].idx_q]), 0.3) for n, sign in b.signs.items()])
    pin_q = np.array([mech.joints[n].idx_q for n in b.signs])
    q[pin_q] = values
    S = np.zeros((len(pins), mech.nv))
    S[np.arange(len(pins)), pins] = 1.0

    def fun(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = Configuration.compute(mech, qq)
        return (np.concatenate([c.residual, -task.error(y_ref, c.task_value), qq[pin_q] - values]),
                np.vstack([c.closure_and_task_jacobian, S]))

    # over-determined when a pinned magnitude is not the mirrored leg's: Gauss-Newton lands close
    q, _, _ = _newton(mech, fun, q, mech.free_v, tol, max_iter, 0.5)
    out = solve_ik(mech, y_ref, q, tol=tol).q
    if not mech.on_branch(out, branch):
        raise BranchError(branch, dict(b.signs), mech.branch_signs(out, branch))
    return out


def assemble(mech: Mechanism, q0: ArrayLike | None = None, *, hold: Sequence[str] = (), tol: float = DEFAULT_TOL,
             restarts: int = 16, seed: int = 0, max_iter: int = 200, raise_on_failure: bool = True) -> SolveResult:
    """A configuration that closes every loop, from any seed (the mechanism's own files need not be closed).

    Levenberg-Marquardt on the closure residual over every joint, on the configuration manifold, from
    ``q0`` (default: the reference); when it stalls above ``tol``, restarts from ``q0`` perturbed by
    normal draws of growing size (0.1, 0.3, 1 rad or ``L``), ``restarts`` times at most (seeded: the same
    answer every run). Scale-free: the residual's translation rows and the prismatic (and translation) coordinates
    are counted in ``L``, the :func:`~pkm.core.model.mechanism.spread` of the joints at ``q0`` (the configuration the
    assembly starts from, known before any assembly: the characteristic length is measured at the reference, which
    this finds), rotations and angles in rad; ``tol`` bounds that residual (a translation gap of ``tol * L`` m).
    A copy of the mechanism with every length scaled (:func:`~pkm.core.model.builder.scaled_mechanism`), started
    from ``q0`` scaled alike, assembles to the same angles and to lengths scaled alike (to round-off). Every joint moves but those named in ``hold``, which keep their values in ``q0``
    (a spec's partial ``[reference]`` holds the joints it states): with no ``hold`` this finds *an*
    assembly, not the one for given actuators (that is :func:`close_loops`).

    With ``raise_on_failure=False`` the best start's result is returned (``converged`` False) instead of raising,
    as :func:`close_loops` and :func:`solve_ik` do.

    Raises:
        AssemblyError: no start closes: the best residual, and the closure that stays most open and by how much.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> rrr3 = pkm.load("rrr3")
        >>> res = pkm.assemble(rrr3, np.zeros(rrr3.nq))
        >>> res.converged, bool(res.residual < 1e-12)
        (True, True)
    """
    mech = check_mechanism(mech)
    q_seed = mech.q_reference.copy() if q0 is None else mech.check_q(q0, "q0")
    tol = as_tolerance(tol, "tol")
    restarts = as_count(restarts, "restarts", low=0, high=10_000)
    max_iter = as_count(max_iter, "max_iter", low=1, high=100_000)
    rng = np.random.default_rng(as_count(seed, "seed", low=0, high=2**63 - 1))
    if isinstance(hold, str) or not all(isinstance(n, str) for n in hold):
        raise InvalidInputError("hold", "expected a sequence of joint names", hold)
    held = np.zeros(mech.nv, dtype=bool)
    held[mech.base_v] = True  # (a floating base is an input)
    for name in hold:
        j = mech.joint(name)
        held[j.idx_v:j.idx_v + j.nv] = True

    rows, cols = _assembly_metric(mech, q_seed)

    def closure(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        F, J = constraints.residual_and_jacobian(mech, qq)
        J[:, held] = 0.0  # (Levenberg-Marquardt's damping then leaves the held coordinates where they are)
        return rows * F, rows[:, None] * J * cols

    m = mech.model
    best: tuple[float, np.ndarray, float] = (np.inf, q_seed, np.inf)
    total = 0
    for k in range(restarts + 1):
        scale = (0.0, 0.1, 0.3, 1.0)[min(k, 3)]
        q = (pin.integrate(m, q_seed, np.where(held, 0.0, scale * cols * rng.standard_normal(m.nv))) if k
             else q_seed.copy())
        q, r, it = _levenberg_marquardt(mech, closure, q, tol, max_iter, cols)
        total += it
        res, raw = float(np.abs(r).max()), float(np.abs(r / rows).max())  # (scale-free; in m or rad)
        if res < best[0]:
            best = (res, q, raw)
        if res <= tol:
            q = mech.wrap(q)
            return _result(mech, q, True, raw, total, k + 1, relative=res)
    result = _result(mech, best[1], False, best[2], total, restarts + 1, relative=best[0])
    if not raise_on_failure:
        return result
    err = _failure(mech, "assembly", result, tol)
    alone, detail = _open_alone(mech, q_seed, held, tol * (1.0 / rows).max(), max_iter, rng)
    detail = detail or (f"{restarts + 1} starts of Levenberg-Marquardt: each closure closes alone, not all of them "
                        f"together; at the best start closure {err.worst_closure!r} "
                        f"({_frames(mech, err.worst_closure)}) stays open by {err.worst_gap:.3g}")
    raise AssemblyError(best[2], "m or rad", detail, subject="this mechanism",
                        closures=alone or ((str(err.worst_closure), err.worst_gap),))


#: Seeded starts of :func:`nearest_assembly` besides ``q0`` itself (normal draws of 0.3, 1 and 2 rad or m).
NEAREST_STARTS = 12


def nearest_assembly(mech: Mechanism, q0: ArrayLike | None = None, *, tol: float = DEFAULT_TOL,
                     seed: int = 0) -> SolveResult:
    """The closed configuration nearest ``q0`` (default: the zero pose, Pinocchio's neutral configuration): a
    reference chosen by a rule, for a mechanism whose files state none (not the builder's default, which is the
    first assembly :func:`assemble` reaches: see :mod:`pkm.core.model.builder` for why).

    Distance: the norm of :meth:`~pkm.core.Mechanism.difference` (every joint coordinate alike, rad and m). Each of
    ``q0`` and :data:`NEAREST_STARTS` seeded perturbations of it is closed by Levenberg-Marquardt, then slid along
    the closed configurations to a local minimum of the distance (the distance's gradient projected on the closures'
    null space, the loops closed again by minimum-norm Newton steps). The nearest wins; among those as near to
    ``1e-9`` (a mechanism symmetric about ``q0``, such as a five-bar mirrored by ``q -> -q``, has its nearest
    configurations in mirrored pairs) the first in the lexicographic order of ``q`` from the largest. A symmetry
    of the mechanism that fixes ``q0`` and the distance (legs alike, permuted) maps the nearest configuration to one
    as near: where the nearest is unique, it is symmetric. A local minimum from a finite set of starts, not a
    certified global one; the same every run.

    Raises:
        AssemblyError: no start closes the loops (as :func:`assemble`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> rrr3 = pkm.load("rrr3")
        >>> res = pkm.nearest_assembly(rrr3)
        >>> res.converged
        True
        >>> round(float(np.linalg.norm(rrr3.difference(np.zeros(rrr3.nq), res.q))), 4)
        2.9202
    """
    mech = check_mechanism(mech)
    q_zero = pin.neutral(mech.model) if q0 is None else mech.check_q(q0, "q0")
    tol = as_tolerance(tol, "tol")
    rng = np.random.default_rng(as_count(seed, "seed", low=0, high=2**63 - 1))
    held = np.zeros(mech.nv, dtype=bool)
    held[mech.base_v] = True
    cols = ~held

    def closure(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        F, J = constraints.residual_and_jacobian(mech, qq)
        J[:, held] = 0.0
        return F, J

    found: list[tuple[float, np.ndarray]] = []
    for k in range(NEAREST_STARTS + 1):
        scale = (0.0, 0.3, 1.0, 2.0)[min(k, 3) if k < 4 else 1 + k % 3]
        q = pin.integrate(mech.model, q_zero, np.where(held, 0.0, scale * rng.standard_normal(mech.nv)))
        q, F, _ = _levenberg_marquardt(mech, closure, q, tol, 200)
        if np.abs(F).max() > tol:
            continue
        q = _slide_nearest(mech, q, q_zero, cols, tol)
        if q is not None:
            found.append((float(np.linalg.norm(mech.difference(q_zero, q))), mech.wrap(q)))
    if not found:
        return assemble(mech, q_zero, tol=tol, seed=seed)  # (its AssemblyError says which closure stays open)
    best = min(d for d, _ in found)
    near = [q for d, q in found if d <= best + 1e-9 * max(1.0, best)]
    q = max(near, key=lambda x: tuple(np.round(np.asarray(x, dtype=float), 9).tolist()))
    res = float(np.abs(constraints.residual(mech, q)).max())
    return _result(mech, q, True, res, 0, len(found))


def _slide_nearest(mech: Mechanism, q: np.ndarray, q_zero: np.ndarray, cols: np.ndarray, tol: float) \
        -> np.ndarray | None:
    """From the closed ``q``, a closed configuration where the distance to ``q_zero`` is locally least (its gradient
    normal to the closures' tangent space to 1e-10), or None when the loops do not close again."""
    m = mech.model

    def fun(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return constraints.residual_and_jacobian(mech, qq)

    for _ in range(200):
        g = np.where(cols, mech.difference(q_zero, q), 0.0)
        J = constraints.jacobian(mech, q)[:, cols]
        step = np.zeros(mech.nv)
        step[cols] = -(g[cols] - np.linalg.pinv(J, rcond=1e-10) @ (J @ g[cols]))
        if np.abs(step).max() <= 1e-10:
            return q
        d0 = float(np.linalg.norm(mech.difference(q_zero, q)))
        for alpha in (1.0, 0.5, 0.25, 0.125, 0.0625):
            q_try, res, _ = _newton(mech, fun, pin.integrate(m, q, alpha * step), np.flatnonzero(cols), tol, 30, 0.5)
            if res <= tol and float(np.linalg.norm(mech.difference(q_zero, q_try))) < d0:
                q = q_try
                break
        else:
            return q  # no shorter closed configuration along the projected gradient: a minimum to the step size
    return q


def _frames(mech: Mechanism, closure: str | None) -> str:
    """``"frames 'A' and 'B'"`` of the named closure, as its file names them."""
    c = next((c for c in mech.spec.closures if c.name == closure), None)
    return f"frames {c.frame_a!r} and {c.frame_b!r}" if c is not None else "no closure"


def _open_alone(mech: Mechanism, q_seed: np.ndarray, held: np.ndarray, tol: float, max_iter: int,
                rng: np.random.Generator                ) -> tuple[list[tuple[str, float]], str]:
    """Why no assembly was found: the closures that do not close even alone (each tried with the others cut, from
    the seed and three perturbed starts) with their gaps, worst first, and a sentence saying so and what would close
    them: a frame closure whose origins can meet but whose frames stay turned apart closes as a point closure.
    ``([], "")`` when every closure closes alone (then they fail only together)."""
    sizes = [cm.residualSize() for cm in mech.constraint_models]
    starts = np.cumsum([0, *sizes])

    def gap(rows: np.ndarray) -> tuple[float, np.ndarray]:
        def fun(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            F, J = constraints.residual_and_jacobian(mech, qq)
            J[:, held] = 0.0
            return F[rows], J[rows]

        best = (np.inf, q_seed)
        for k in range(4):
            q = pin.integrate(mech.model, q_seed, np.where(held, 0.0, 0.3 * k * rng.standard_normal(mech.nv)))
            q, r, _ = _levenberg_marquardt(mech, fun, q, tol, max_iter)
            if np.abs(r).max() < best[0]:
                best = (float(np.abs(r).max()), q)
            if best[0] <= tol:
                break
        return best

    open_: list[tuple[str, float, str]] = []
    as_points = 0
    for c, a, n in zip(mech.spec.closures, starts, sizes):
        g, q = gap(np.arange(a, a + n))
        if g <= tol:
            continue
        r = constraints.residual(mech, q)[a:a + n]
        apart, turned = (float(np.linalg.norm(part)) if part.size and np.abs(part).max() > tol else 0.0
                         for part in (r[:3], r[3:]))
        what = f"{c.name!r} ({c.frame_a!r}/{c.frame_b!r}) open by {apart:.3g} m"
        if c.type == "frame":
            what += f" and {turned:.3g} rad at best"
            if gap(np.arange(a, a + 3))[0] <= tol:
                as_points += 1
                what += " (its origins can meet)"
        open_.append((c.name, g, what))
    if not open_:
        return [], ""
    open_.sort(key=lambda t: -t[1])
    fix = (f"; {'each' if as_points == len(open_) else f'{as_points} of them'} closes alone as a point closure (the "
           "frames' origins meet: type 'point' in a closure spec, '3d' in a robot.yaml)" if as_points else "")
    return ([(name, g) for name, g, _ in open_],
            f"{len(open_)} closure(s) cannot close even alone: " + "; ".join(w for _, _, w in open_) + fix)


def _assembly_metric(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`assemble`'s scale-free metric from its start ``q``: per closure row, ``1 / L`` for a translation and 1 for
    a rotation (the residual in ``L`` and rad), and per velocity ``L`` for a length and 1 for an angle (a step in
    ``L`` and rad), ``L`` the :func:`~pkm.core.model.mechanism.spread` of the joints at ``q``."""
    scales = JacobianScales.at(mech, spread(mech.model, q))
    return scales.closure_residual, scales.columns


def _levenberg_marquardt(mech: Mechanism, fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], q: np.ndarray, tol: float, max_iter: int,
                         columns: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Levenberg-Marquardt on ``|F(q)|^2`` over every joint (``fun(q) -> (F, J)``, J on the tangent space), on the
    configuration manifold; stops at ``|F|_inf <= tol``, at a stationary point (no decrease for any damping) or
    after ``max_iter`` iterations. ``columns``: the units of J's columns (nv,), a step ``dq`` of the iteration moving
    the joints by ``columns * dq`` (``fun``'s Jacobian homogenised by them: :func:`_assembly_metric`); default 1.
    Returns ``(q, F, iterations)``."""
    m = mech.model
    unit = np.ones(m.nv) if columns is None else columns
    F, J = fun(q)
    cost, lam, it = float(F @ F), 1e-3, 0
    while it < max_iter and np.abs(F).max() > tol:
        it += 1
        JtJ, g = J.T @ J, J.T @ F
        dq = -np.linalg.solve(JtJ + lam * (np.diag(np.diag(JtJ)) + 1e-12 * np.eye(m.nv)), g)
        q_try = pin.integrate(m, q, unit * dq)
        F_try, J_try = fun(q_try)
        cost_try = float(F_try @ F_try)
        if np.isfinite(cost_try) and cost_try < cost:
            q, F, J, cost, lam = q_try, F_try, J_try, cost_try, max(lam / 3.0, 1e-12)
        else:
            lam *= 5.0
            if lam > 1e12:
                break
    return q, F, it


def _raise_if_out_of_reach(mech: Mechanism, fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], q: np.ndarray,
                           tol: float, metric: _Metric) -> None:
    """:class:`UnreachableError` when the IK equations ``fun`` have a least-squares minimum that is not a solution
    near ``q`` (Levenberg-Marquardt from ``q``, in ``metric``, stalls with ``|F|_inf > max(tol, 1e-9)``, lengths in
    ``L``): the target lies outside the workspace. It names the closure left most open there, or the task when the
    loops close there (to a thousandth of the task's miss: the least-squares minimum trades a little closure for a
    far target); the gaps it prints are in m or rad."""
    def held(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # (a floating base stays where it is)
        F, J = fun(qq)
        J[:, mech.base_v] = 0.0
        return metric.rows * F, metric.rows[:, None] * J

    with np.errstate(over="ignore", invalid="ignore"):
        q, Fs, _ = _levenberg_marquardt(mech, held, q, tol, 500, metric.cols)
        F = Fs / metric.rows
        gap, index, name = constraints.worst_closure(mech, F)
        gap_s = constraints.worst_closure(mech, Fs)[0]
        task_gap = float(np.linalg.norm(F[mech.n_constraints:]))
        task_gap_s = float(np.linalg.norm(Fs[mech.n_constraints:]))
    if not (np.isfinite(gap) and np.isfinite(task_gap) and np.abs(Fs).max() > max(tol, 1e-9)):
        return  # solved after all, or beyond the float range: the ConvergenceError stands
    if gap_s > tol and gap_s > 1e-3 * task_gap_s:  # a loop that cannot close, not a trade-off with a task far away
        raise UnreachableError(index, gap, "m or rad",
                               f"the target is out of the workspace: at the nearest configuration (a least-squares "
                               f"minimum) closure {name!r} stays open by {gap:.3g} and the task misses by "
                               f"{task_gap:.3g}")
    raise UnreachableError(0, task_gap, "m or rad", "the target is out of the workspace: the loops close (to "
                                                    f"{gap:.1e}) at the nearest configuration, where the task misses "
                                                    f"by {task_gap:.3g}")


def _failure(mech: Mechanism, what: str, result: SolveResult, tol: float) -> ConvergenceError:
    """A ConvergenceError naming the loop that stays most open and by how much."""
    F = constraints.residual(mech, result.q)
    gap, _, name = constraints.worst_closure(mech, F)
    scaled = math.isfinite(result.relative_residual)
    open_ = (constraints.worst_closure(mech, _Metric.of(mech, task=False).rows * F)[0] if scaled else gap) > tol
    detail = (f"closure {name!r} stays open by {gap:.3g} (m or rad) at the last iterate"
              if name is not None and open_ else "the task target is not met")
    if what == "loop closure" and mech.dependent_actuators:
        detail += (f"; actuators {list(mech.dependent_actuators)} depend on the others (see mech.notes): values "
                   "that do not agree with the others' admit no assembly")
    if scaled and what != "assembly":
        detail += (f" (the residual counts lengths in the characteristic length L = {mech.characteristic_length:.4g} m, "
                   f"angles in rad; in m and rad {result.residual:.3e})")
    err = ConvergenceError(what, result.relative_residual if scaled else result.residual, result.iterations, tol,
                           result, detail)
    err.worst_closure, err.worst_gap = name, gap
    return err


def _settings(tol: object, max_iter: object, max_step: object) -> tuple[float, int, float]:
    """The solver settings checked: ``tol`` in (0, 1], ``max_iter`` in [1, 10^4], ``max_step`` > 0."""
    return (as_tolerance(tol, "tol"), as_count(max_iter, "max_iter", low=1, high=10_000),
            as_scalar(max_step, "max_step", low=0.0, strict_low=True))


def _n_steps(dist: float, max_step: float) -> int:
    """Continuation steps for a path of length ``dist`` in steps of at most ``max_step``, capped at MAX_STEPS."""
    if not np.isfinite(dist):
        raise InvalidInputError("target", f"the distance to the target is not finite ({dist!r})", dist)
    return int(min(MAX_STEPS, max(1, np.ceil(dist / max_step))))


def _signs(mech: Mechanism, q: np.ndarray) -> dict[str, int]:
    return mech.branch_signs(q) if mech.spec.default_branch is not None else {}
