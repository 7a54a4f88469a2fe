r"""The fastest time law :math:`s(t)` along a path under the actuators' limits: time-optimal path parameterisation.

**Solver: TOPP-RA** (Pham & Pham, IEEE T-RO 2018; the ``toppra`` package, extra ``plan``). toppra was evaluated
before writing one: its reachability analysis (a backward pass of controllable sets, then a greedy forward pass, each
stage a two-variable LP solved by its Cython Seidel solver) is exact for constraints linear in
:math:`(u, x) = (\ddot s, \dot s^2)` on a grid, takes per-point coefficients (a ``LinearConstraint`` returning
arrays), and times a 1,000-point Delta path in about 25 ms; writing another would only duplicate it. toppra's own
``SecondOrderConstraint`` needs a serial robot's inverse dynamics on a joint path; here the coefficients
:math:`a, b, c, d` of a closed chain (:mod:`pkm.core.timing.coefficients`) are handed to it directly, in its
**interpolation** discretisation (the efforts at both ends of each segment held with the segment's
:math:`\ddot s`: the efforts just before a grid point are checked too, not only those at it).

**The torque-speed curve and viscous friction** depend on :math:`\dot s = \sqrt{x}`, which is not linear in
:math:`x`: each effort row :math:`\sigma (a u + b x + c) + e \sqrt{x} \le \alpha` (:math:`e = \sigma d + \beta
|q_a'|`) is linearised per grid point on the tangent of :math:`\sqrt{x}` at the previous solution's :math:`x_0`,
:math:`\sqrt{x} \le \sqrt{x_0}/2 + x / (2 \sqrt{x_0})` (an upper bound for every :math:`x`: each iterate is
feasible for the true curve when :math:`e \ge 0`; a row with :math:`e < 0` drops the term, conservatively; the
tangent's point no further than where :math:`e \sqrt{x_0} / 2` would take 3/4 of the row's slack at rest, so that
the linearised rows leave the path controllable), and
solved again until the cycle time changes by less than 1e-9 relative (at most 12 passes; the first from the
constant-peak solution). Where no limit depends on the speed, one pass: toppra's exact answer on these coefficients.

**Speed limits** bound :math:`x \le (V_i / |q_{a,i}'|)^2`; **acceleration limits** are rows
:math:`|q_a' u + q_a'' x| \le A`. **Jerk is not limited**: the law is bang-bang in :math:`\ddot s` (Pontryagin),
with unbounded jerk at its switches; a jerk-limited law needs a third-order method (not handled; stated by
:attr:`TimeOptimal.jerk_limited`).

**Position limits**: the path itself must keep every joint within the position limits the model states (actuated,
task and passive joints alike, at every grid point and segment midpoint): one that leaves them is refused before any
timing (:func:`check_positions`, :class:`~pkm.errors.PathError` naming the point, the joint, its value and its
limits), never timed and reported as a success.

The law between grid points: :math:`\ddot s = u_i` constant, :math:`\dot s^2` linear in :math:`s`, so that
:math:`\Delta t_i = 2 \Delta s_i / (\dot s_i + \dot s_{i+1})`. **Between the grid points** the coefficients
change and :math:`\dot s = \sqrt{x}` is concave (steepest just after a start from rest, where a torque-speed
line falls fastest): :func:`pkm.time_optimal` also computes the coefficients at each segment's midpoint, and
:func:`solve` checks the limits inside every segment (the coefficients' quadratic through its ends and midpoint, at
:data:`FRACTIONS` of it) and tightens them where the grid alone would let them be crossed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.model.mechanism import Mechanism
from pkm.core.timing.coefficients import PathCoefficients
from pkm.core.timing.limits import Limits
from pkm.core.timing.path import GeometricPath
from pkm.errors import InvalidInputError, PathError, PkmError

if TYPE_CHECKING:
    from pkm.core.twin.kernels import Kernels

MAX_PASSES = 12
#: Rounds of tightening where the limits are used beyond 1 between the grid points (:func:`solve`).
MAX_REFINE = 12
#: A limit counts as held inside a segment where used to 1 + this (rounding; the margin is far larger).
REFINE_HOLD = 1e-9
PASS_RTOL = 1e-9
#: A limit counts as active at a stage where used to within this fraction (:attr:`TimeOptimal.active`).
ACTIVE_RTOL = 1e-6


@dataclass(frozen=True)
class TimeOptimal:
    """A time-optimal law along a path, and the motors' motion under it (rows per grid point).

    Attributes:
        mech: The mechanism timed (with its payload).
        path: The geometric path.
        limits: The limits held.
        coefficients: The effort coefficients on the grid.
        payload: The payload [kg].
        s: The grid (n,).
        sd: :math:`\\dot s` at the grid points (n,) [1/s].
        sdd: :math:`\\ddot s` on each segment (n - 1,) [1/s^2].
        time: The time at each grid point (n,) [s].
        cycle_time: The duration [s].
        qa, qa_rate, qa_acceleration: The actuated coordinates and their rates (n x na); the acceleration at a grid
            point is the one of the segment it starts (the last point: the last segment's).
        efforts: The efforts at each grid point (n x na) [N m, N], with the same acceleration.
        active: At each segment, the limit whose row, as solved, is most used (``"effort motor_1"``, ``"speed
            motor_2"``, ``"acceleration motor_3"``; :attr:`planned_usage`).
        usage: At each segment, the largest use of any true limit at its ends (1: at the margin-reduced limit; the
            torque-speed curve and viscous friction exact), or inside it where a limit was held there.
        passes: toppra solves made (more than one where a limit depends on the speed, or where the limits were
            tightened between the grid points).
        tightened: The factors (>= 1, n x 3) the limits were tightened by so that they hold between the grid points
            too (:func:`solve`): per segment (row ``i``: segment ``i``) for the effort and acceleration columns 0
            and 2, per grid point for the speed column 1.
        jerk_limited: False: jerk is not limited (module doc).
        planned_usage: At each segment, the largest use of the rows the planner solved (:func:`planned_usage`: the
            speed-dependent terms linearised as solved, each row tightened as solved): 1 where a limit is
            **active**; :attr:`inactive` lists where none is. With viscous friction or a motor line the true use
            (:attr:`usage`) of an active row is at most this (the tangent is an upper bound, a term that helps is
            dropped): active segments whose true use is under 1.
        linearised_at: The :math:`\\dot s^2` the speed-dependent rows were linearised at (n,; None: none).
    """

    mech: Mechanism
    path: GeometricPath
    limits: Limits
    coefficients: PathCoefficients
    payload: float
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    time: np.ndarray
    cycle_time: float
    qa: np.ndarray
    qa_rate: np.ndarray
    qa_acceleration: np.ndarray
    efforts: np.ndarray
    active: tuple[str, ...]
    usage: np.ndarray
    passes: int
    tightened: np.ndarray | None = None
    jerk_limited: bool = False
    planned_usage: np.ndarray | None = None
    linearised_at: np.ndarray | None = None

    @property
    def inactive(self) -> tuple[int, ...]:
        """The segments where no row the planner solved is active (:attr:`planned_usage` under ``1 -
        ACTIVE_RTOL``): the switches of a bang-bang law."""
        use = self.usage if self.planned_usage is None else self.planned_usage
        return tuple(int(i) for i in np.flatnonzero(use < 1.0 - ACTIVE_RTOL))

    def state_at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""``(t, sd, sdd)`` of the law at path parameters ``s`` (m,) in [0, 1]: on segment ``i``,
        :math:`\dot s^2 = \dot s_i^2 + 2 u_i (s - s_i)`, :math:`\ddot s = u_i`."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        i = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.sdd) - 1)
        u = self.sdd[i]
        x = np.maximum(self.sd[i] ** 2 + 2.0 * u * (s - self.s[i]), 0.0)
        sd = np.sqrt(x)
        t = self.time[i] + 2.0 * (s - self.s[i]) / np.maximum(self.sd[i] + sd, 1e-300)
        return t, sd, u


def _rows(C: PathCoefficients, L: Limits, x0: np.ndarray | None) -> tuple[np.ndarray, ...]:
    """The stage constraints ``A_u u + A_x x + c <= g`` at every grid point (n x m each), the effort rows
    linearised at ``x0`` (None: where no term depends on the speed), and each row's kind (m,: 0 effort, 2
    acceleration)."""
    n, na = C.a.shape
    alpha = L.lines[..., 0]  # (na x k)
    scale = 1.0 - L.margin
    Au, Ax, c0, g = [], [], [], []
    for sigma in (1.0, -1.0):
        lin_x, lin_c = _tangent(C, L, x0, sigma)
        finite = np.isfinite(alpha)[None] & np.ones((n, 1, 1), dtype=bool)
        Au.append(np.where(finite, sigma * C.a[:, :, None], 0.0))
        Ax.append(np.where(finite, sigma * C.b[:, :, None] + lin_x, 0.0))
        c0.append(np.where(finite, sigma * C.c[:, :, None] + lin_c, 0.0))
        g.append(np.where(finite, scale * np.where(np.isfinite(alpha), alpha, 1.0)[None], 1.0))
    for sigma in (1.0, -1.0):
        finite = np.isfinite(L.acceleration)[None] & np.ones((n, 1), dtype=bool)
        Au.append(np.where(finite, sigma * C.dqa, 0.0)[..., None])
        Ax.append(np.where(finite, sigma * C.ddqa, 0.0)[..., None])
        c0.append(np.zeros((n, na, 1)))
        g.append(np.where(finite, scale * np.where(np.isfinite(L.acceleration), L.acceleration, 1.0)[None],
                          1.0)[..., None])
    flat = [np.concatenate([x.reshape(n, -1) for x in part], axis=1) for part in (Au, Ax, c0, g)]
    kinds = np.concatenate([np.zeros(Au[0].size // n + Au[1].size // n), np.full(2 * na, 2)]).astype(int)
    return (*flat, kinds)


def _tangent(C: PathCoefficients, L: Limits, x0: np.ndarray | None, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    r"""The effort rows' speed-dependent term :math:`e \sqrt{x}` (:math:`e = \sigma d + \beta |q_a'|`, sign
    ``sigma``) as the planner solves it, ``(lin_x, lin_c)`` (n x na x k): :math:`e \sqrt{x} \le` ``lin_x x +
    lin_c``, the tangent at ``x0`` where :math:`e > 0`, nothing where :math:`e \le 0` (module doc); zeros for
    ``x0`` None (no speed-dependent term)."""
    alpha, beta = L.lines[..., 0], L.lines[..., 1]  # (na x k)
    scale = 1.0 - L.margin
    e = sigma * C.d[:, :, None] + scale * beta[None] * np.abs(C.dqa)[:, :, None]  # (n x na x k)
    if x0 is None:  # (no speed-dependent term: e == 0)
        return np.zeros_like(e), np.zeros_like(e)
    # (the tangent's point: the last law's x, but no further than where the row's constant e sqrt(x0) / 2 would
    # take 3/4 of its slack at rest; any x0 > 0 gives an upper bound)
    ep = np.where(e > 0.0, e, 0.0)
    slack = np.maximum(scale * np.where(np.isfinite(alpha), alpha, 0.0)[None] - sigma * C.c[:, :, None], 1e-12)
    with np.errstate(divide="ignore"):
        cap = np.where(ep > 0.0, (1.5 * slack / ep) ** 2, np.inf)
    r0 = np.sqrt(np.maximum(np.minimum(x0[:, None, None], cap), 1e-9 * max(float(x0.max()), 1e-12)))
    return ep / (2.0 * r0), ep * r0 / 2.0


def planned_usage(C: PathCoefficients, L: Limits, sd: np.ndarray, sdd: np.ndarray, tight: np.ndarray | None,
                  x0: np.ndarray | None, static: np.ndarray | None = None, rate: np.ndarray | None = None,
                  acceleration: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Per segment, the largest use of the rows the planner solved (its definition of **active**), at the
    segment's two ends with its ``sdd``, and which (an index, as :func:`usage`): each effort row
    :math:`(\sigma (a u + b x + c) + \text{lin}_x x + \text{lin}_c) / ((1 - m) \alpha_k)` with the speed-dependent
    term as linearised at ``x0`` (:func:`_tangent`: a motor line's and the viscous friction's tangent, the term
    dropped where it helps), the speed and acceleration rows against ``(1 - m)`` of their limits, each times its
    tightening factor ``tight``. 1: the row is at its bound (active); a segment where every row is under
    ``1 - ACTIVE_RTOL`` is a switch.

    ``static``, ``rate``, ``acceleration`` (2 x n - 1 x na: at the segments' starts and ends) replace the
    efforts :math:`a u + b x + c` (without the viscous term :math:`d \dot s`), the joint rates and accelerations
    the coefficients give (:func:`pkm.verify_time_optimal` passes its own, recomputed)."""
    na = C.a.shape[1]
    scale = 1.0 - L.margin
    tight = np.ones((len(C.s), 3)) if tight is None else tight
    alpha = L.lines[..., 0]  # (na x k)
    finite = np.isfinite(alpha)
    lins = {sigma: _tangent(C, L, x0, sigma) for sigma in (1.0, -1.0)}
    out = []
    for j in (0, 1):
        idx = slice(0, -1) if j == 0 else slice(1, None)
        x = sd[idx] ** 2
        tau = C.a[idx] * sdd[:, None] + C.b[idx] * x[:, None] + C.c[idx] if static is None else static[j]
        omega = C.dqa[idx] * sd[idx, None] if rate is None else rate[j]
        acc = C.dqa[idx] * sdd[:, None] + C.ddqa[idx] * x[:, None] if acceleration is None else acceleration[j]
        eff = np.zeros_like(tau)
        for sigma, (lin_x, lin_c) in lins.items():
            row = sigma * tau[..., None] + lin_x[idx] * x[:, None, None] + lin_c[idx]  # (n - 1 x na x k)
            use = np.where(finite[None], row / (scale * np.where(finite, alpha, 1.0))[None], -np.inf)
            eff = np.maximum(eff, use.max(axis=-1))
        out.append(np.concatenate([eff * tight[:-1, 0, None], np.abs(omega) / (scale * L.speed[None]) *
                                   tight[idx, 1, None], np.abs(acc) / (scale * L.acceleration[None]) *
                                   tight[:-1, 2, None]], axis=1))
    both = np.maximum(out[0], out[1])
    k = np.argmax(both, axis=1)
    assert both.shape[1] == 3 * na
    return both[np.arange(len(k)), k], k


def _x_bound(C: PathCoefficients, L: Limits, tight: np.ndarray) -> np.ndarray:
    """The speed limits' bound on :math:`\\dot s^2` at every grid point (n,), tightened by ``tight[:, 1]``."""
    V = (1.0 - L.margin) * L.speed
    with np.errstate(divide="ignore"):
        bound = np.where(np.abs(C.dqa) > 0.0, (V[None] / np.abs(C.dqa)) ** 2, np.inf)
    return np.minimum(bound.min(axis=1) / tight[:, 1] ** 2, 1e12)


def _toppra(C: PathCoefficients, L: Limits, x0: np.ndarray | None,
            tight: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One toppra solve: ``(sd (n,), sdd (n - 1,))``."""
    from pkm._optional import module

    module("toppra", extra="plan", what="time-optimal motion (pkm.time_optimal)")
    from toppra.algorithm import TOPPRA
    from toppra.constraint import DiscretizationType
    from toppra.constraint.linear_constraint import LinearConstraint, canlinear_colloc_to_interpolate
    from toppra.interpolator import AbstractGeometricPath

    tight = np.ones((len(C.s), 3)) if tight is None else tight
    Au, Ax, c0, g, kinds = _rows(C, L, x0)
    keep = np.flatnonzero(np.any(Au != 0.0, axis=0) | np.any(Ax != 0.0, axis=0))  # (rows of no limit left out)
    Au, Ax, c0, g, kinds = Au[:, keep], Ax[:, keep], c0[:, keep], g[0, keep], kinds[keep]  # (g: the same everywhere)
    n, m = Au.shape
    xb = np.column_stack([np.zeros(n), _x_bound(C, L, tight)])
    params = list(canlinear_colloc_to_interpolate(Au, Ax, c0, np.eye(m), g, xb, None, C.s, identical=True))
    if np.any(tight[:, [0, 2]] != 1.0):  # (a stage's rows, at both its ends, tightened: the row times the factor)
        factor = np.tile(tight[:, kinds], 2)
        params[:3] = [x * factor for x in params[:3]]

    class _Rows(LinearConstraint):  # (the rows computed here, handed over as they are)
        def __init__(self) -> None:
            super().__init__()
            self.discretization_type = DiscretizationType.Interpolation
            self.identical = True

        def compute_constraint_params(self, path: object, gridpoints: np.ndarray, *args: object,
                                      **kwargs: object) -> tuple:
            a, b, c, FF, gg, xbound, ubound = params
            return a, b, c, FF, gg, ubound, xbound

    class _Path(AbstractGeometricPath):  # (toppra reads only the interval and the dof)
        @property
        def path_interval(self) -> np.ndarray:
            return np.array([0.0, 1.0])

        @property
        def dof(self) -> int:
            return C.a.shape[1]

        def __call__(self, s: np.ndarray, order: int = 0) -> np.ndarray:
            return np.zeros((int(np.size(s)), C.a.shape[1]))

    algo = TOPPRA([_Rows()], _Path(), gridpoints=C.s, solver_wrapper="seidel")
    sdd, sd, _, _ = algo.compute_parameterization(0.0, 0.0, return_data=True)
    if sd is None or sdd is None:
        raise PkmError("toppra found no time law: the path is not controllable under these limits (at rest at "
                       "both ends)")
    return np.maximum(np.asarray(sd, dtype=float), 0.0), np.asarray(sdd, dtype=float)


def _times(s: np.ndarray, sd: np.ndarray) -> np.ndarray:
    ds = np.diff(s)
    with np.errstate(divide="ignore"):
        dt = 2.0 * ds / (sd[1:] + sd[:-1])
    return np.concatenate([[0.0], np.cumsum(dt)])


def check_static(C: PathCoefficients, L: Limits) -> None:
    """Refuse a path where a limit cannot hold the mechanism still (:class:`~pkm.errors.PathError` naming the grid
    point and the actuator): the gravity (and payload) efforts beyond the margin-reduced peak."""
    peak = (1.0 - L.margin) * L.peak
    ratio = np.abs(C.gravity) / peak[None]
    if ratio.max() >= 1.0:
        k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        raise PathError(int(k), float(C.s[k]), f"peak effort of {L.names[i]}",
                        f"holding the mechanism still needs {C.gravity[k, i]:.6g} against a limit of "
                        f"{L.peak[i]:.6g} (planned at {peak[i]:.6g}): the limit cannot hold the payload")


def check_positions(mech: Mechanism, C: PathCoefficients, between: PathCoefficients | None = None) -> None:
    """Refuse a path that takes a joint outside the position limits the model states (every joint that has some:
    actuated, task, passive; :meth:`~pkm.core.Mechanism.limit_violations`): :class:`~pkm.errors.PathError` at the
    first grid point (or segment midpoint, ``between``) outside, naming the joint, its value and its limits."""
    s = C.s if between is None else np.concatenate([C.s, between.s])
    order = np.argsort(s, kind="stable")
    Q = (C.q if between is None else np.concatenate([C.q, between.q]))[order]
    along = mech.limits_along(Q)
    if along:
        i, (joint, value, (lo, hi)) = along[0]
        o = int(order[i])
        k, what = (o, "path point") if o < len(C.s) else (o - len(C.s), "segment")
        unit = "rad" if mech.joints[joint].revolute else "m"
        others = [v.joint for v in mech.limit_violations(Q[i]) if v.joint != joint]
        more = f" (also outside: {', '.join(others)})" if others else ""
        raise PathError(k, float(s[o]), f"position limit of {joint}",
                        f"{joint} = {value:.6g} {unit}, outside its limits [{lo:.6g}, {hi:.6g}] {unit} (the "
                        f"model's){more}: the path leaves the joints' range", what, joint=joint, value=value,
                        bound=(lo, hi))


def usage(C: PathCoefficients, L: Limits, sd: np.ndarray, sdd: np.ndarray,
          tight: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per segment, the largest use of any limit at its two ends with its ``sdd`` against the margin-reduced
    limits (the true torque-speed curve; each grid point's tightened by ``tight``, as planned), and which (an index:
    ``k < na`` effort of actuator k, ``na + k`` speed, ``2 na + k`` acceleration)."""
    na = C.a.shape[1]
    scale = 1.0 - L.margin
    out = []
    for j in (0, 1):
        idx = slice(0, -1) if j == 0 else slice(1, None)
        x = sd[idx] ** 2
        tau = C.a[idx] * sdd[:, None] + C.b[idx] * x[:, None] + C.c[idx] + C.d[idx] * sd[idx, None]
        omega = C.dqa[idx] * sd[idx, None]
        limit = L.effort_limit(omega) * scale
        eff = np.abs(tau) / limit
        speed = np.abs(omega) / (scale * L.speed[None])
        acc = np.abs(C.dqa[idx] * sdd[:, None] + C.ddqa[idx] * x[:, None]) / (scale * L.acceleration[None])
        if tight is not None:  # (effort and acceleration: the segment's factor; speed: the point's)
            eff, speed, acc = eff * tight[:-1, 0, None], speed * tight[idx, 1, None], acc * tight[:-1, 2, None]
        out.append(np.concatenate([eff, speed, acc], axis=1))
    both = np.maximum(out[0], out[1])
    k = np.argmax(both, axis=1)
    assert both.shape[1] == 3 * na
    return both[np.arange(len(k)), k], k


def _law(C: PathCoefficients, L: Limits, tight: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, np.ndarray | None]:
    """``(sd, sdd, toppra solves, x0)``: one solve, or the passes of the linearised speed-dependent limits (``x0``:
    where the law kept was linearised; None for one solve)."""
    if not (L.speed_dependent or bool(np.any(C.d != 0.0))):
        sd, sdd = _toppra(C, L, None, tight)
        return sd, sdd, 1, None
    const = Limits(np.stack([L.lines[..., 0], np.zeros_like(L.lines[..., 1])], -1), L.speed, L.acceleration,
                   L.margin, L.names)  # (the constant-peak law: the first linearisation point)
    sd, sdd = _toppra(dataclasses.replace(C, d=np.zeros_like(C.d)), const, None, tight)
    best: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    T, passes = math.inf, 1
    for _ in range(MAX_PASSES):
        x0 = sd ** 2
        try:
            sd, sdd = _toppra(C, L, x0, tight)
        except PkmError:
            if best is None:
                raise
            break  # (the last law found holds the limits: kept)
        passes += 1
        T_new = float(_times(C.s, sd)[-1])
        if best is not None and T_new >= T:
            break
        converged = abs(T - T_new) <= PASS_RTOL * T_new
        best, T = (sd, sdd, x0), T_new
        if converged:
            break
    assert best is not None
    return best[0], best[1], passes, best[2]


#: Where :func:`solve` checks the limits inside each segment (fractions of it): dense near the ends, where
#: :math:`\\dot s = \\sqrt{x}` grows fastest from rest and a speed-dependent limit falls fastest.
FRACTIONS = np.array([0.003, 0.01, 0.03, 0.1, 0.25, 0.5, 0.75, 0.9, 0.97, 0.99, 0.997])


def _between(M: PathCoefficients, C: PathCoefficients, L: Limits, sd: np.ndarray, sdd: np.ndarray) -> np.ndarray:
    """Per segment (n - 1 x 3), the largest use of the margin-reduced effort, speed and acceleration limits inside
    it under its law, at :data:`FRACTIONS` of it: the coefficients there the quadratic through the segment's ends
    (``C``) and its midpoint (``M``), :math:`\\dot s^2 = \\dot s_i^2 + 2 u_i (s - s_i)`."""
    f = FRACTIONS[:, None, None]
    w0, wm, w1 = 2.0 * (f - 0.5) * (f - 1.0), -4.0 * f * (f - 1.0), 2.0 * f * (f - 0.5)

    def at(name: str) -> np.ndarray:  # (fractions x segments x na)
        x = getattr(C, name)
        return w0 * x[None, :-1] + wm * getattr(M, name)[None] + w1 * x[None, 1:]

    a, b, c, d, dqa, ddqa = (at(k) for k in ("a", "b", "c", "d", "dqa", "ddqa"))
    u = sdd[None, :, None]
    x = np.maximum(sd[None, :-1, None] ** 2 + 2.0 * u * f * np.diff(C.s)[None, :, None], 0.0)
    rate = np.sqrt(x)
    scale = 1.0 - L.margin
    tau = a * u + b * x + c + d * rate
    omega = dqa * rate
    limit = L.effort_limit(omega.reshape(-1, omega.shape[-1])).reshape(omega.shape) if L.speed_dependent else \
        L.peak
    out = np.empty((len(sdd), 3))
    out[:, 0] = np.max(np.abs(tau) / (scale * limit), axis=(0, 2))
    out[:, 1] = np.max(np.abs(omega) / (scale * L.speed), axis=(0, 2))
    out[:, 2] = np.max(np.abs(dqa * u + ddqa * x) / (scale * L.acceleration), axis=(0, 2))
    return out


def solve(mech: Mechanism, path: GeometricPath, C: PathCoefficients, L: Limits, payload: float,
          between: PathCoefficients | None = None) -> TimeOptimal:
    """The time-optimal law on the coefficients ``C`` under ``L`` (module doc); with ``between`` (the coefficients
    at each segment's midpoint), the limits are also checked inside each segment under its law
    (:func:`_between`); where used beyond ``1 + margin / 2`` on the first pass (beyond 1 on later ones) the limits
    are tightened (the segment's effort and acceleration rows, the speed bound at its two grid points) by the
    square of that use and the law solved again (up to :data:`MAX_REFINE` rounds): what the grid does not see
    between its points is held too, at the price of a segment or two used slightly under 1 on a coarse grid."""
    check_positions(mech, C, between)
    check_static(C, L)
    tight = np.ones((len(C.s), 3))
    passes, over = 0, None
    for _ in range(MAX_REFINE + 1):
        sd, sdd, p, x0 = _law(C, L, tight)
        passes += p
        if between is None:
            break
        over = _between(between, C, L, sd, sdd)
        if over.max() <= 1.0 + (0.5 * L.margin if passes == p else REFINE_HOLD):
            break  # (first pass: inside the segments within half the margin, the true limits hold with the rest)
        # (tightened, never relaxed: effort and acceleration per segment, speed per grid point (what its two
        # segments need); squared: from rest the use inside falls slower than the factor rises)
        step = np.maximum(over, 1.0) ** 2
        tight[:-1, [0, 2]] *= step[:, [0, 2]]
        tight[:-1, 1] *= step[:, 1]
        tight[1:, 1] *= step[:, 1]
    else:
        raise PkmError(f"the limits do not hold between the grid points after {MAX_REFINE} rounds of tightening "
                       f"(used {over.max():.6g} inside a segment): give more points")  # type: ignore[union-attr]
    t = _times(C.s, sd)
    if not np.isfinite(t[-1]):
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise PathError(k, float(C.s[k]), "standstill", "the time law stops inside the path (a limit leaves no "
                                                        "speed here)")
    u_pt = np.append(sdd, sdd[-1])
    qa_rate = C.dqa * sd[:, None]
    qa_acc = C.dqa * u_pt[:, None] + C.ddqa * (sd ** 2)[:, None]
    efforts = C.efforts(u_pt, sd)
    use, _ = usage(C, L, sd, sdd, tight)
    if over is not None:  # (a limit held inside a segment is the one active there)
        use = np.maximum(use, np.max(over, axis=1))
    na = mech.na
    kinds = ("effort", "speed", "acceleration")
    planned, which = planned_usage(C, L, sd, sdd, tight, x0)
    active = tuple(f"{kinds[k // na]} {L.names[k % na]}" for k in which)
    return TimeOptimal(mech, path, L, C, payload, C.s, sd, sdd, t, float(t[-1]), C.qa, qa_rate, qa_acc, efforts,
                       active, use, passes, tight, planned_usage=planned, linearised_at=x0)


_KERNELS: dict[int, object] = {}


def kernels_of(mech: Mechanism, kernels: object) -> Kernels:
    """``kernels`` checked as :class:`pkm.Kernels` of ``mech``; for True, the kernels of ``mech`` built on the first
    call and kept (a few mechanisms at a time).

    Raises:
        InvalidInputError: ``kernels`` is neither True nor kernels of ``mech``.
    """
    from pkm.core.twin.kernels import Kernels

    if kernels is True:
        if id(mech) not in _KERNELS or _KERNELS[id(mech)].mech is not mech:  # type: ignore[attr-defined]
            if len(_KERNELS) > 8:
                _KERNELS.clear()
            _KERNELS[id(mech)] = Kernels(mech)
        kernels = _KERNELS[id(mech)]
    if not isinstance(kernels, Kernels) or kernels.mech is not mech:
        raise InvalidInputError("kernels", "expected True or pkm.Kernels of the plan's mechanism (with its payload: "
                                           "pkm.core.timing.with_payload)", kernels)
    return kernels


def time_optimal(mech: Mechanism, path: object, *, payload: float = 0.0, limits: Limits | Mapping[str, Any] | None = None,
                 points: int = 1000, space: str = "task", kernels: object = None,
                 q0: ArrayLike | None = None) -> TimeOptimal:
    r"""The fastest time law along ``path``, at rest at both ends, under the actuators' limits (module doc).

    Args:
        mech: The mechanism.
        path: A :class:`~pkm.core.timing.path.GeometricPath`, waypoints (n x value size in task space, or n x na
            with ``space="actuated"``: a C² cubic spline through them, :func:`~pkm.core.timing.path.waypoint_path`)
            or a ``pkm.motion`` case (:class:`pkm.motion.Motion`: its geometric path).
        payload: A point mass at the end effector [kg] (:func:`~pkm.core.timing.coefficients.with_payload`).
        limits: :class:`~pkm.core.timing.limits.Limits`, or the arguments of
            :func:`~pkm.core.timing.limits.actuator_limits` as a dict; default the drives' own peak efforts and
            speed limits.
        points: Grid points along the path (uniform in s), >= 3.
        space: The waypoints' space (``"task"`` or ``"actuated"``).
        kernels: The compiled route: True (kernels of the mechanism with its payload, built once and kept) or
            :class:`pkm.Kernels` of that mechanism; default the generic core.
        q0: The configuration the path's inverse kinematics starts from (default the reference): the working
            mode it keeps.

    Returns:
        A :class:`TimeOptimal`: the law, the motors' motion and efforts, the active limit per segment.

    Raises:
        PathError: the path leaves the workspace, crosses a singularity, is not smooth, takes a joint outside the
            position limits the model states, or a limit cannot hold the mechanism (and payload) still, at the point
            it names.
        InvalidInputError: bad limits, payload or grid.
        MissingDependencyError: toppra is not installed (``pip install "pkm-robotics[plan]"``).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> line = np.array([[-0.05, 0.0, -0.36], [0.05, 0.0, -0.36]])
        >>> plan = pkm.time_optimal(delta, line, points=50)
        >>> round(plan.cycle_time, 4)
        0.1729
    """
    from pkm.core.model.mechanism import check_mechanism
    from pkm.core.timing.coefficients import path_coefficients, with_payload
    from pkm.core.timing.limits import actuator_limits
    from pkm.core.timing.path import motion_path, waypoint_path
    from pkm.motion import Motion
    from pkm.validation import as_count

    mech = check_mechanism(mech)
    n = as_count(points, "points", low=3, high=1_000_000)
    timed = with_payload(mech, payload)
    if isinstance(path, GeometricPath):
        geo = path
    elif isinstance(path, Motion):
        geo = motion_path(mech, path)
    else:
        geo = waypoint_path(mech, path, space=space)  # type: ignore[arg-type]
    if isinstance(limits, Limits):
        lim = limits
    else:
        lim = actuator_limits(timed, **dict(limits or {}))
    if len(lim.names) != mech.na:
        raise InvalidInputError("limits", f"limits for {len(lim.names)} actuators, the mechanism has {mech.na}",
                                lim.names)
    if kernels is True:
        kernels = kernels_of(timed, True)
    s = np.linspace(0.0, 1.0, n)
    start = None if q0 is None else timed.check_q(q0, "q0")
    C = path_coefficients(timed, geo, s, q0=start, kernels=kernels or None)
    mid = path_coefficients(timed, geo, 0.5 * (s[1:] + s[:-1]), q0=C.q[0], kernels=kernels or None)
    return solve(timed, geo, C, lim, float(payload), mid)


__all__ = ["ACTIVE_RTOL", "TimeOptimal", "check_positions", "kernels_of", "planned_usage", "solve", "time_optimal", "usage"]
