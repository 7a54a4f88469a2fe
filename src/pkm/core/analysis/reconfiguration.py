"""Reconfiguration of any mechanism: its redundant parameters chosen pose by pose and along a path.

A mechanism whose task holds joint outputs beyond what the poses fix (the hexapod's ``beta_1``; any spec's
``[task] joints``) is reconfigurable: for a pose, those ``p`` joint values can be chosen within limits.
:func:`reconfigure` chooses them to maximise a performance index of the rest of the machine, through
:mod:`pkm.core.analysis.redundant_parameter` (trust-region SQP on proxsuite QPs, one or several parameters):

* the index at pose ``k`` and parameters ``x``: the inverse kinematics of the task value (pose ``k``, ``x``)
  by the twin's compiled Newton iteration, batched over every ``(k, x)`` the optimiser asks for and seeded with
  the pose's solution at the middle of its box; then the inverse Jacobian with the parameters held, ``K``
  (the other actuators' rates per pose rate, homogenised by ``length``), and ``1/kappa_2(K)`` (``"ci_2"``),
  ``n / (||K||_F ||K^-1||_F)`` (``"ci_fro"``) or Yoshikawa's manipulability of ``K^-1`` (``"manipulability"``);
* the boxes: the ``limits`` intersected, for one parameter, with the interval of the pose's reachable values
  that holds the best node of a scan (its ends found by bisection to :data:`EDGE` of the limits); with several parameters
  the box is the ``limits``, which must be reachable at every node of the scan (else
  :class:`~pkm.errors.UnreachableError` names the pose and the values).

A pose is solved in the default working mode (or ``branch``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.analysis import redundant_parameter
from pkm.core.differential import indices
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, UnreachableError
from pkm.validation import ABSURD, as_array, as_count, as_scalar, as_tolerance

if TYPE_CHECKING:
    from pkm.core.twin import Kernels

INDICES = ("ci_2", "ci_fro", "manipulability")
#: A scanned reachable interval's ends are located to this fraction of its limits' width.
EDGE = 1e-7
_NEWTON = 25  # batched Newton iterations per evaluation (a box's far corner from the seed: ~5-8 suffice)
_STEPS = 16  # steps of the continuation from the seed where Newton alone does not reach


@dataclass(frozen=True)
class Reconfiguration:
    """The parameters chosen for each pose.

    Attributes:
        parameters: Their names (task joints).
        x: The choice, (n,) for one parameter, (n, p) for several [m or rad].
        value: The index there.
        lower, upper: The boxes searched (shaped like ``x``).
        q: The configuration of every pose at its choice (n x nq).
        optimum: :class:`~pkm.core.analysis.redundant_parameter.PointOptimum` (pose by pose) or
            :class:`~pkm.core.analysis.redundant_parameter.ProfileOptimum` (along a path).
    """

    parameters: tuple[str, ...]
    x: np.ndarray
    value: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    q: np.ndarray
    optimum: object


class _Index:
    """``index(k, x)`` of a mechanism (see the module doc), vectorised over ``(k, x)`` pairs."""

    def __init__(self, mech: Mechanism, poses: np.ndarray, params: list[str], kind: str, length: float | None,
                 branch: str | None, kernels: Kernels):
        task = TaskMap(mech)
        self.mech, self.poses, self.kind, self.kernels, self.branch = mech, poses, kind, kernels, branch
        self.parameter_names = params
        self.cols = [task.value_names.index(n) for n in params]  # (task joints: the same place in value and tangent)
        self.keep_task = [i for i, key in enumerate(task.keys) if key not in params]
        self.scale = task.rate_scale(length, [task.keys[i] for i in self.keep_task])
        self.keep_act = [i for i, name in enumerate(mech.actuated_names) if name not in params]
        signs = {} if mech.spec.default_branch is None else mech.branch(branch).signs
        self._signs = [(mech.joints[j].idx_q, s, mech.joints[j].revolute) for j, s in signs.items()]
        self.seeds: dict[int, np.ndarray] = {}
        self.seed_x: dict[int, np.ndarray] = {}
        self.residual = np.zeros(0)

    def targets(self, k: np.ndarray, x: np.ndarray) -> np.ndarray:
        t = self.poses[k].copy()
        t[:, self.cols] = x
        return t

    def seed(self, k: int, x: np.ndarray) -> np.ndarray:
        """Pose ``k``'s configuration at parameters ``x`` by the generic IK (its error when it fails), kept as the
        start of every later Newton iteration of that pose."""
        if k not in self.seeds:
            from pkm.core.kinematics.solve import solve_ik

            self.seeds[k] = solve_ik(self.mech, self.targets(np.array([k]), x[None])[0], branch=self.branch).q
            self.seed_x[k] = np.array(x, dtype=float)
        return self.seeds[k]

    def _on_branch(self, Q: np.ndarray) -> np.ndarray:
        ok = np.ones(len(Q), dtype=bool)
        for idx, sign, revolute in self._signs:
            v = np.sin(Q[:, idx]) if revolute else Q[:, idx]
            ok &= sign * v >= 0
        return ok

    def configurations(self, k: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(q, solved)`` for the pairs: batched Newton from each pose's seed, in the working mode; a pair Newton
        does not reach from there is followed from the seed's parameters in :data:`_STEPS` steps (the last
        residual in :attr:`residual`)."""
        T = self.targets(k, x)
        Q = np.array([self.seeds[int(kk)] for kk in k])
        newton = self.kernels.kernel("ik_newton")
        residual = np.full(len(k), np.inf)
        for _ in range(_NEWTON):
            Q, residual, _pivot = newton(Q, T)
            residual = residual[:, 0]
            if np.all(residual <= 1e-11):
                break
        solved = (residual <= 1e-10) & self._on_branch(Q)
        for i in np.flatnonzero(~solved):  # continuation along the parameters, warm-started step by step
            kk = int(k[i])
            path = self.targets(np.full(_STEPS, kk), self.seed_x[kk] + np.linspace(1.0 / _STEPS, 1.0, _STEPS)[:, None]
                                * (x[i] - self.seed_x[kk]))
            q_path, r_path, _, _ = newton.follow(self.seeds[kk], path, _NEWTON, 1e-11)
            Q[i], residual[i] = q_path[-1], r_path.max()
            solved[i] = bool(np.all(r_path <= 1e-10)) and bool(self._on_branch(q_path).all())
        self.residual = residual
        return Q, solved

    def values(self, Q: np.ndarray) -> np.ndarray:
        K = self.kernels.inverse_jacobian(Q)[:, self.keep_act][:, :, self.keep_task] * self.scale
        if self.kind == "manipulability":  # of the forward map K^-1
            return 1.0 / np.asarray(indices.manipulability(K))
        return np.asarray(indices.inverse_condition(K, "2" if self.kind == "ci_2" else "fro_normalized"))

    def __call__(self, k: ArrayLike, x: ArrayLike) -> np.ndarray:
        k = np.asarray(k, dtype=int)
        x = np.asarray(x, dtype=float).reshape(len(k), -1)
        Q, solved = self.configurations(k, x)
        if not np.all(solved):
            i = int(np.flatnonzero(~solved)[0])
            raise _unreached(self, int(k[i]), x[i], i, "narrow the limits")
        return self.values(Q)


def _unreached(f: _Index, k: int, x: np.ndarray, i: int, advice: str) -> UnreachableError:
    """Pose ``k`` not reached (in the working mode) at parameters ``x``, the ``i``-th pair just solved."""
    miss = float(f.residual[i]) if np.isfinite(f.residual[i]) and f.residual[i] > 0 else 0.0
    where = dict(zip(f.parameter_names, map(float, np.atleast_1d(x))))
    mode = "" if miss > 1e-10 else " (solved, but in another working mode)"
    return UnreachableError(0, miss, "characteristic lengths or rad", f"pose {k} with {where}{mode}: {advice}")


def reconfigure(mech: Mechanism, poses: np.ndarray | Sequence[ArrayLike | Mapping[str, Any]],
                parameters: Sequence[str], limits: ArrayLike, *, index: str = "ci_2", length: float | None = None,
                rate_limit: ArrayLike | None = None, smoothness: float = 1.0, baseline: ArrayLike | None = None,
                branch: str | None = None, grid: int = 31, tol: float = 1e-9,
                kernels: Kernels | None = None) -> Reconfiguration:
    """The redundant ``parameters`` of ``mech`` chosen for each of ``poses`` (see the module doc).

    Args:
        mech: Any mechanism whose task holds the ``parameters`` as joint outputs.
        poses: Task targets (n, as :meth:`TaskMap.parse` reads them: vectors laid out as
            :meth:`TaskMap.value`, or mappings by name); the parameters' entries are ignored.
        parameters: Names of task joints to choose.
        limits: ``(low, high)`` per parameter [m or rad].
        index: One of :data:`INDICES`.
        length: Characteristic length dividing the angular pose rates [m]; needed when the pose mixes lengths and
            angles.
        rate_limit: None: pose by pose (:func:`~pkm.core.analysis.redundant_parameter.maximise`); else the largest change
            per pose of each parameter along the path (:func:`~pkm.core.analysis.redundant_parameter.optimise_profile`).
        smoothness: The path's smoothing weight ``mu`` [1/unit^2].
        baseline: The parameters of the machine without reconfiguration (for the path's gain), or None.
        branch: The working mode (default: the spec's).
        grid: Nodes of the scan per parameter (the optimiser's start and the reachability scan).
        tol: The optimiser's tolerance on the parameters.
        kernels: The :class:`pkm.Kernels` of ``mech`` to reuse (default: made here, their twin built each call).

    Raises:
        InvalidInputError: unknown parameters or index, bad limits, a missing ``length``.
        UnreachableError: a pose no parameter value within the limits reaches (one parameter), or a box not
            reached everywhere (several).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> hexapod = pkm.load("hexapod")
        >>> pose = pkm.task_values(hexapod, hexapod.q_reference)
        >>> r = pkm.reconfigure(hexapod, [pose], ["beta_1"], [(-1.5, 1.5)], length=0.1)
        >>> np.round(r.x, 4), np.round(r.value, 4)
        (array([-1.5]), array([0.1469]))
        >>> np.round(r.lower, 4), np.round(r.upper, 4)
        (array([-1.5]), array([0.7867]))
    """
    from pkm.core.twin import Kernels

    mech = check_mechanism(mech)
    if kernels is not None and (not isinstance(kernels, Kernels) or kernels.mech is not mech):
        raise InvalidInputError("kernels", "give the pkm.Kernels of this mechanism", kernels)
    task = TaskMap(mech)
    if not isinstance(index, str) or index not in INDICES:
        raise InvalidInputError("index", f"use one of {INDICES}", index)
    params = [parameters] if isinstance(parameters, str) else list(parameters) \
        if isinstance(parameters, (list, tuple)) else []
    if not params or len(set(map(str, params))) != len(params) or any(p not in task.spec.joints for p in params):
        raise InvalidInputError("parameters", f"name distinct task joints of {mech.name}: {list(task.spec.joints)}",
                                parameters)
    lim = as_array(limits, "limits", "(low, high) per parameter")
    if lim.shape != (len(params), 2) or not np.all(np.isfinite(lim)) or np.any(lim[:, 0] >= lim[:, 1]):
        raise InvalidInputError("limits", f"give (low, high) with low < high for each of {params}", limits)
    if np.abs(lim).max() > ABSURD:
        raise InvalidInputError("limits", f"beyond {ABSURD:g} (SI units: m, rad)", limits)
    if length is not None:
        length = as_scalar(length, "length", low=0.0, strict_low=True, unit="m")
    tol = as_tolerance(tol, "tol")
    task.rate_scale(length, [k for k in task.keys if k not in params])  # (mixed and no length: refused here)
    grid = as_count(grid, "grid", low=3, high=10_000)
    targets = poses if isinstance(poses, np.ndarray) and poses.ndim == 2 else list(poses)
    Y = np.array([task.parse(t) for t in targets]) if len(targets) else np.zeros((0, task.value_size))
    if len(Y) == 0:
        raise InvalidInputError("poses", "give at least one pose", poses)
    f = _Index(mech, Y, params, index, length, branch, Kernels(mech) if kernels is None else kernels)
    n, p = len(Y), len(params)
    mid = lim.mean(axis=1)
    for k in range(n):  # (the generic IK's own error, UnreachableError or ConvergenceError, when one fails)
        f.seed(k, mid)
    lo, hi = _boxes(f, lim, grid, n, p)
    shape = (n,) if p == 1 else (n, p)
    lower, upper = lo.reshape(shape), hi.reshape(shape)
    opt: redundant_parameter.PointOptimum | redundant_parameter.ProfileOptimum
    if rate_limit is None:
        opt = redundant_parameter.maximise(f, lower, upper, grid=grid, tol=tol)
    else:
        opt = redundant_parameter.optimise_profile(f, lower, upper, rate_limit=rate_limit, smoothness=smoothness,
                                                   baseline=baseline, tol=tol)
    x, value = opt.x, opt.value
    Q, _ = f.configurations(np.arange(n), np.asarray(x, dtype=float).reshape(n, p))
    return Reconfiguration(tuple(params), x, value, lower, upper, Q, opt)


def _boxes(f: _Index, lim: np.ndarray, grid: int, n: int, p: int) -> tuple[np.ndarray, np.ndarray]:
    """The boxes per pose (n x p): see the module doc."""
    t = np.linspace(0.0, 1.0, grid)
    if p > 1:
        axes = np.stack(np.meshgrid(*[lim[i, 0] + (lim[i, 1] - lim[i, 0]) * t for i in range(p)],
                                    indexing="ij"), axis=-1).reshape(-1, p)
        for k in range(n):
            _, ok = f.configurations(np.full(len(axes), k), axes)
            if not np.all(ok):
                i = int(np.flatnonzero(~ok)[0])
                raise _unreached(f, k, axes[i], i, "with several parameters the limits must be reachable everywhere")
        return np.tile(lim[:, 0], (n, 1)), np.tile(lim[:, 1], (n, 1))
    lo, hi = np.empty((n, 1)), np.empty((n, 1))
    nodes = lim[0, 0] + (lim[0, 1] - lim[0, 0]) * t
    for k in range(n):
        kk = np.full(grid, k)
        Q, ok = f.configurations(kk, nodes[:, None])
        if not ok.any():
            raise _unreached(f, k, nodes[int(np.argmin(f.residual))], int(np.argmin(f.residual)),
                             f"no {f.parameter_names[0]} in [{lim[0, 0]:.6g}, {lim[0, 1]:.6g}] reaches it")
        vals = np.full(grid, -np.inf)
        vals[ok] = f.values(Q[ok])
        best = int(np.argmax(vals))
        a, b = best, best
        while a > 0 and ok[a - 1]:
            a -= 1
        while b < grid - 1 and ok[b + 1]:
            b += 1
        lo[k, 0] = nodes[a] if a == 0 else _edge(f, k, nodes[a - 1], nodes[a], lim)
        hi[k, 0] = nodes[b] if b == grid - 1 else _edge(f, k, nodes[b + 1], nodes[b], lim)
    return lo, hi


def _edge(f: _Index, k: int, out: float, inside: float, lim: np.ndarray) -> float:
    """The reachable end between an unreached ``out`` and a reached ``inside`` value, by bisection."""
    while abs(out - inside) > EDGE * (lim[0, 1] - lim[0, 0]):
        mid = 0.5 * (out + inside)
        _, ok = f.configurations(np.array([k]), np.array([[mid]]))
        out, inside = (out, mid) if ok[0] else (mid, inside)
    return inside


__all__ = ["EDGE", "INDICES", "Reconfiguration", "reconfigure"]
