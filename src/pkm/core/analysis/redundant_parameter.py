"""Choosing redundant reconfiguration parameters by sequential QPs (proxsuite.proxqp).

A reconfigurable mechanism has more actuators than its task needs: parameters ``x`` (angles, lengths; one, as the
hexapod's ``beta``, or ``p`` of them) that can be chosen freely within a box. Given a performance index
``f_k(x)`` for each pose ``k`` of a task (a manipulability, an inverse condition number...) this
module finds

* per pose, ``x*_k`` maximising ``f_k`` on ``[lower_k, upper_k]`` (:func:`maximise`);
* along a path of poses, the whole profile ``x_0..x_{n-1}`` (:func:`optimise_profile`) that
  maximises ``sum_k f_k(x_k) / s - (mu / 2) sum_k ||x_{k+1} - x_k||^2`` subject to the box of
  every pose and the rate limit ``|x_{k+1} - x_k| <= delta`` (per parameter); ``s`` is the largest pointwise
  optimum ``max_k f_k(x*_k)``, so that ``mu`` is in 1/unit(x)^2 whatever the index.

One parameter is given as intervals of shape (n,) and ``x`` as (n,) arrays; ``p`` parameters as boxes (n, p),
``x`` with one row per pose. With several parameters the finite differences add 4 points per pair of parameters
(the Hessian's coupling) and the model's curvature is ``-H`` with its eigenvalues floored; with one, the
algorithm is the scalar one it always was.

The index is a callback ``index(k, x) -> f`` vectorised over arrays of pose indices and values
(same shape). It must be finite on ``[lower_k, upper_k]``; the caller supplies those intervals
(for a mechanism: the parameter's limits intersected with the interval where the pose is
reachable). Derivatives are central differences (step ``fd_step``, the stencil kept inside the
interval), so the index only needs to be twice differentiable.

Method: a trust-region SQP. Each iteration builds the concave quadratic model of the objective
(curvature ``min(f'', -eta)``: a convex QP even where ``f`` is locally convex) and solves it with
``proxsuite.proxqp.dense`` (box constraints for the intervals and the trust region, one inequality
row per rate limit); a step is accepted when the objective increases, and the trust radius grows
or shrinks with the ratio of actual to predicted gain. :func:`maximise` starts from the best node
of a grid (the index may have several local maxima); :func:`optimise_profile` starts from the
pointwise optima clipped to the rate limit (:func:`clip_to_rate`), so its objective is never worse.

The profile's QPs are written in the new values ``y = x + d`` (not in the steps ``d``), so that the
previous solution is a good warm start: proxqp then needs 1-5 iterations instead of about 25 cold.
The pointwise QPs are written in the steps divided by the trust radius, each pose's model scaled to
O(1), since an index can be tiny near the edge of its interval. Known
traps of proxqp are guarded (:class:`WarmQP`): ``update()`` is never called before the first
``solve()`` (reported to leave the workspace half set up; not reproduced with proxsuite 0.8.0 on
a small box QP, guarded anyway); the duality-gap check (``settings.check_duality_gap``) is on, as
a warm start near an active bound can otherwise stop on small primal and dual residuals with a
wrong "solved" answer; and a warm solve that does not end ``PROXQP_SOLVED`` is redone cold (with
step variables, proxsuite 0.8.0 warm-started from the previous step reported a feasible QP
``PROXQP_PRIMAL_INFEASIBLE``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import proxsuite
from numpy.typing import ArrayLike

from pkm.errors import ConvergenceError, InvalidInputError, PkmError
from pkm.validation import as_array, as_count, as_scalar, as_tolerance, finite_result

IndexFn = Callable[[np.ndarray, np.ndarray], np.ndarray]

#: proxqp accuracy (absolute primal/dual residuals and duality gap).
QP_EPS = 1e-10


class WarmQP:
    """A dense proxqp problem with fixed inequality rows, solved repeatedly and warm-started.

    Minimise ``1/2 y^T H y + g^T y`` s.t. ``l <= C y <= u`` (fixed at construction) and
    ``l_box <= y <= u_box``. The first :meth:`solve` calls ``init`` then ``solve``; later ones
    ``update`` then ``solve`` with ``WARM_START_WITH_PREVIOUS_RESULT``, so ``update`` never precedes
    the first ``solve``. The duality-gap check is on. A warm solve that does not report
    ``PROXQP_SOLVED`` is redone cold; if that fails too, :class:`ConvergenceError`.

    Attributes:
        solves: QPs solved so far; iterations: proxqp iterations, all solves included;
        cold_restarts: warm solves that had to be redone cold; statuses: status of every solve.
    """

    def __init__(self, n: int, C: np.ndarray | None = None, l: ArrayLike | None = None,
                 u: ArrayLike | None = None, *, eps: float = QP_EPS,
                 max_iter: int = 1000):
        self.n = n
        self._C = np.zeros((0, n)) if C is None else np.asarray(C, dtype=float)
        self._l = np.zeros(0) if l is None else np.asarray(l, dtype=float)
        self._u = np.zeros(0) if u is None else np.asarray(u, dtype=float)
        self._qp: Any = None  # a proxsuite.proxqp.dense.QP once set up
        self._eps, self._max_iter = eps, max_iter
        self.solves = self.iterations = self.cold_restarts = 0
        self.statuses: list[str] = []

    def _cold(self, H: np.ndarray, g: np.ndarray, l_box: np.ndarray, u_box: np.ndarray, *, careful: bool = False) -> None:
        qp = proxsuite.proxqp.dense.QP(self.n, 0, self._C.shape[0], True)
        s = qp.settings
        # the QPs here are feasible and bounded by construction (feasible_bounds, boxes): with proxqp's default
        # thresholds (1e-4) a well-posed 3-pose QP was reported PRIMAL_INFEASIBLE; detect infeasibility strictly
        s.eps_primal_inf = s.eps_dual_inf = 1e-12
        if careful:
            s.primal_infeasibility_solving = True
        s.eps_abs, s.eps_rel = self._eps, 1e-14  # relative part: see the duality gap below
        s.max_iter_in = 200  # inner iterations per outer one (proxqp's default 1500 lets a bad QP run 1.5e6)
        s.check_duality_gap = True
        # the gap also relative (1e-14) to the objective's terms: a pose near the edge of its interval can carry a
        # curvature of 1e10, where an absolute 1e-10 gap is out of reach in floating point (MAX_ITER_REACHED)
        s.eps_duality_gap_abs, s.eps_duality_gap_rel = self._eps, 1e-14
        s.max_iter = self._max_iter
        s.verbose = False
        qp.init(H, g, None, None, self._C, self._l, self._u, l_box, u_box)
        qp.solve()  # before any update(): proxqp's workspace is only set up by the first solve
        s.initial_guess = proxsuite.proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
        self._qp = qp

    def solve(self, H: np.ndarray, g: np.ndarray, l_box: np.ndarray, u_box: np.ndarray) -> np.ndarray:
        """The minimiser ``y`` (see the class doc).

        Raises:
            NonFiniteError: the QP data hold a NaN or an infinity (proxqp would spin to its iteration limit).
        """
        for name, v in (("H", H), ("g", g), ("l_box", l_box), ("u_box", u_box)):
            finite_result(v, f"QP data {name}", "the index or its finite-difference derivatives overflow; "
                                                "rescale the index")
        if self._qp is None:
            self._cold(H, g, l_box, u_box)
        else:
            self._qp.update(H, g, None, None, None, None, None, l_box, u_box)
            self._qp.solve()
            if self._qp.results.info.status != proxsuite.proxqp.PROXQP_SOLVED:
                self.cold_restarts += 1
                self.iterations += self._qp.results.info.iter
                self._cold(H, g, l_box, u_box)
        if self._qp.results.info.status != proxsuite.proxqp.PROXQP_SOLVED:  # one careful cold try more
            self.cold_restarts += 1
            self.iterations += self._qp.results.info.iter
            self._cold(H, g, l_box, u_box, careful=True)
        info = self._qp.results.info
        self.solves += 1
        self.iterations += info.iter
        self.statuses.append(str(info.status).rsplit(".", 1)[-1])
        if info.status != proxsuite.proxqp.PROXQP_SOLVED:
            raise ConvergenceError("proxqp", max(info.pri_res, info.dua_res, abs(info.duality_gap)), info.iter,
                                   self._eps, detail=f"status {info.status} (primal {info.pri_res:.2e}, dual "
                                                     f"{info.dua_res:.2e}, duality gap {info.duality_gap:.2e})")
        return np.array(self._qp.results.x)


@dataclass(frozen=True)
class PointOptimum:
    """Pointwise maxima of an index (one entry per pose).

    Attributes:
        x: The maximisers, shape (n,).
        value: The index there.
        lower, upper: The intervals searched.
        iterations: SQP iterations.
        qp_solves, qp_iterations: proxqp solves and iterations.
        converged: Whether every step fell below ``tol`` within ``max_iter``.
    """

    x: np.ndarray
    value: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    iterations: int
    qp_solves: int
    qp_iterations: int
    converged: bool


@dataclass(frozen=True)
class ProfileOptimum:
    """A profile along a path of poses and how it was found.

    Attributes:
        x: The profile, shape (n,).
        value: The index along it, shape (n,).
        objective: ``sum f_k(x_k) / scale - (mu / 2) sum (x_{k+1} - x_k)^2``.
        scale: ``s``, the largest pointwise optimum of the index.
        pointwise: The pointwise optima (:class:`PointOptimum`).
        start: The pointwise optima clipped to the rate limit (:func:`clip_to_rate`), where the SQP starts.
        start_objective: The objective there (the result is never worse).
        baseline_value: The index at the baseline parameter (the model without reconfiguration),
            ``nan`` where the baseline lies outside ``[lower_k, upper_k]`` (see ``baseline_ok``).
        baseline_ok: Where the baseline is admissible.
        relative_gain: ``value / baseline_value - 1`` where ``baseline_ok``, else ``nan`` (``nan`` too
            where the baseline's index is 0: no relative gain exists there).
        max_rate: ``max |x_{k+1} - x_k|``.
        iterations: SQP iterations; qp_solves, qp_iterations, cold_restarts: proxqp counters.
        converged: Whether the SQP converged within its iteration budget.
        qp_status: Status of every QP solve.
    """

    x: np.ndarray
    value: np.ndarray
    objective: float
    scale: float
    pointwise: PointOptimum
    start: np.ndarray
    start_objective: float
    baseline_value: np.ndarray
    baseline_ok: np.ndarray
    relative_gain: np.ndarray
    max_rate: float
    iterations: int
    qp_solves: int
    qp_iterations: int
    cold_restarts: int
    converged: bool
    qp_status: tuple[str, ...] = field(default=())

    def mean_gain(self, start: int = 0) -> float:
        """Mean relative gain over the poses ``k >= start`` where the baseline is admissible (and its index > 0)."""
        start = as_count(start, "start", low=0, high=max(len(self.x) - 1, 0))
        g = self.relative_gain[start:][self.baseline_ok[start:]]
        g = g[np.isfinite(g)]
        if g.size == 0:
            raise InvalidInputError("start", f"no pose from {start} on admits the baseline", start)
        return float(np.mean(g))


# ---------------------------------------------------------------------- derivatives
def _derivatives(index: IndexFn, k: np.ndarray, x: np.ndarray, lo: np.ndarray, hi: np.ndarray, h: float,
                 vector: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``f`` (n), gradient (n x p) and Hessian (n x p x p) at ``x`` (n x p); the stencils (3 points per coordinate,
    4 per pair) are centred at ``c`` inside ``[lo + h, hi - h]``, then carried back to ``x`` by Taylor."""
    n, p = x.shape
    c = np.clip(x, lo + h, hi - h)
    c = np.where(hi - lo < 2 * h, 0.5 * (lo + hi), c)
    hh = np.minimum(h, 0.5 * (hi - lo))
    pairs = [(i, j) for i in range(p) for j in range(i + 1, p)]
    points: list[np.ndarray] = []
    for i, e in enumerate(np.eye(p)):
        points += [c - hh * e, c, c + hh * e] if i == 0 else [c - hh * e, c + hh * e]
    for i, j in pairs:
        for si, sj in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            e = np.zeros(p)
            e[i], e[j] = si, sj
            points.append(c + hh * e)
    f_all = _call(index, np.tile(k, len(points)), np.concatenate(points), vector).reshape(len(points), n)
    # rows of f_all: c - h e_0, c, c + h e_0, then (c - h e_i, c + h e_i) for i >= 1, then the pairs' four corners
    f0 = f_all[1]
    fm = np.stack([f_all[0]] + [f_all[1 + 2 * i] for i in range(1, p)], axis=1)
    fp = np.stack([f_all[2]] + [f_all[2 + 2 * i] for i in range(1, p)], axis=1)
    safe = np.where(hh > 0, hh, 1.0)
    d1 = np.empty((n, p))
    d2 = np.zeros((n, p, p))
    with np.errstate(over="ignore", invalid="ignore"):
        d1[:] = np.where(hh > 0, (fp - fm) / (2 * safe), 0.0)
        for i in range(p):
            d2[:, i, i] = np.where(hh[:, i] > 0, (fp[:, i] - 2 * f0 + fm[:, i]) / safe[:, i] ** 2, 0.0)
        at = 1 + 2 * p
        for i, j in pairs:
            pp_, pm, mp, mm = f_all[at:at + 4]
            at += 4
            both = (hh[:, i] > 0) & (hh[:, j] > 0)
            d2[:, i, j] = d2[:, j, i] = np.where(both, (pp_ - pm - mp + mm) / (4 * safe[:, i] * safe[:, j]), 0.0)
    if not (np.all(np.isfinite(d1)) and np.all(np.isfinite(d2))):
        i = int(np.flatnonzero(~(np.all(np.isfinite(d1), axis=1) & np.all(np.isfinite(d2), axis=(1, 2))))[0])
        raise InvalidInputError("index", f"the finite-difference derivatives of the index overflow at pose "
                                         f"{int(k[i])}, x = {_show(x[i])} (index values up to "
                                         f"{np.max(np.abs(f_all)):.3g}); rescale the index", index)
    moved = np.any(c != x, axis=1)
    if np.any(moved):  # Taylor back to x (x near an end of its interval)
        f0 = np.where(moved, _call(index, k, x, vector), f0)
        d1 = d1 + np.einsum("nij,nj->ni", d2, x - c) if p > 1 else d1 + d2[:, :, 0] * (x - c)
    return f0, d1, d2


def _show(x: np.ndarray) -> str:
    return f"{x[0]:.6g}" if x.size == 1 else "(" + ", ".join(f"{v:.6g}" for v in x) + ")"


def _call(index: IndexFn, k: np.ndarray, x: np.ndarray, vector: bool) -> np.ndarray:
    """``index(k, x)`` checked: one finite number per row of ``x`` (m x p; a scalar parameter's index gets the
    column ``x[:, 0]``)."""
    arg = x if vector else x[:, 0]
    try:
        f = index(k, arg)
    except PkmError:
        raise
    except Exception as exc:  # the caller's callback: its failure is reported, not leaked
        raise InvalidInputError("index", f"index(k, x) raised {type(exc).__name__}: {exc}; it must accept arrays "
                                         "k (pose indices) and x (values: one row per pose index) of one length",
                                index) from None
    f = as_array(f, "index", "an array of index values, one per pose index")
    if f.shape != (len(x),):
        if f.size == 1 or f.shape == ():
            f = np.full(len(x), float(f.reshape(())) if f.size == 1 else np.nan)
        else:
            raise InvalidInputError("index", f"index(k, x) returned shape {f.shape} for {len(x)} (k, x) pairs; it "
                                             "must be vectorised (one value per pair)", index)
    _check_finite(f, k, x)
    return f


def _check_index(index: object) -> None:
    if not callable(index):
        raise InvalidInputError("index", f"expected a callable index(k, x) -> values, got {type(index).__name__}",
                                index)


def _check_finite(f: np.ndarray, k: np.ndarray, x: np.ndarray) -> None:
    bad = ~np.isfinite(f)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InvalidInputError("index", f"the index is not finite at pose {int(k[i])}, x = {_show(x[i])}; "
                                         "it must be finite on the whole interval given", f[i])


def _intervals(lower: ArrayLike, upper: ArrayLike) -> tuple[np.ndarray, np.ndarray, bool]:
    """``(lo, hi, vector)``: the boxes as (n x p) arrays; ``vector`` when given as (n, p) (several parameters),
    not as (n,) or a scalar (one parameter)."""
    lo, hi = as_array(lower, "lower", "interval ends (n,) or (n, p)"), as_array(upper, "upper", "interval ends")
    if lo.shape != hi.shape or lo.ndim > 2:
        raise InvalidInputError("lower", f"lower and upper must be arrays of one shape (n,) or (n, p), got "
                                         f"{lo.shape}, {hi.shape}")
    vector = lo.ndim == 2
    lo, hi = (np.atleast_1d(a)[:, None] if not vector else a for a in (lo, hi))
    if lo.size == 0:
        raise InvalidInputError("lower", "needs at least one interval")
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise InvalidInputError("lower", "the intervals must be finite")
    if max(np.max(np.abs(lo)), np.max(np.abs(hi))) > 1e150:
        raise InvalidInputError("lower", "interval ends beyond 1e150 are refused (rescale the parameter)")
    if np.any(lo > hi):
        k = int(np.flatnonzero(np.any(lo > hi, axis=1))[0])
        raise InvalidInputError("lower", f"empty interval at pose {k}: [{_show(lo[k])}, {_show(hi[k])}]")
    return lo, hi, vector


def _concave(H: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """The curvature of the concave model: ``-H`` (n x p x p) with its eigenvalues raised to ``floor`` (n)."""
    if H.shape[1] == 1:
        return np.maximum(-H, floor[:, None, None])
    w, V = np.linalg.eigh(-0.5 * (H + np.swapaxes(H, 1, 2)))
    return np.einsum("nij,nj,nkj->nik", V, np.maximum(w, floor[:, None]), V)


def _block_diagonal(C: np.ndarray) -> np.ndarray:
    n, p, _ = C.shape
    out = np.zeros((n, p, n, p))
    out[np.arange(n), :, np.arange(n), :] = C
    return out.reshape(n * p, n * p)


def _quadratic(d: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``d_k^T C_k d_k`` per pose."""
    return C[:, 0, 0] * d[:, 0] * d[:, 0] if d.shape[1] == 1 else np.einsum("ni,nij,nj->n", d, C, d)


def _out(x: np.ndarray, vector: bool) -> np.ndarray:
    return x if vector else x[:, 0]


# ---------------------------------------------------------------------- pointwise
def maximise(index: IndexFn, lower: ArrayLike, upper: ArrayLike, *, grid: int = 31, tol: float = 1e-9, fd_step: float = 1e-5,
             max_iter: int = 50, eta: float = 1e-6) -> PointOptimum:
    """Maximise ``f_k`` on the box ``[lower_k, upper_k]`` for every pose ``k`` at once.

    The start of pose ``k`` is the best node of a grid of its box (``grid`` nodes for one parameter, about
    ``grid^(1/p)`` per coordinate for ``p``); then a trust-region SQP, the ``n`` separable QPs solved as one proxqp
    problem per iteration (in the steps scaled by the trust radius, each pose's model scaled to O(1)). With
    several parameters the model's curvature is ``-H`` with its eigenvalues raised to ``eta |f|``.

    Args:
        index: ``index(k, x)``, vectorised (see the module doc); for several parameters ``x`` has one row per
            pose index.
        lower, upper: The intervals, shape (n,) or scalars for one pose; (n, p) for ``p`` parameters.
        grid: Nodes of the starting grid per pose (>= 2).
        tol: Stop when every accepted step is below ``tol`` (unit of x).
        fd_step: Finite-difference step (unit of x).
        max_iter: SQP iterations allowed.
        eta: Least curvature of the model, relative to ``|f|`` per unit(x)^2.

    Returns:
        The maximisers and diagnostics (``x`` shaped like ``lower``).
    """
    _check_index(index)
    lo, hi, vector = _intervals(lower, upper)
    grid = as_count(grid, "grid", low=2, high=100_000)
    tol, fd_step, eta = as_tolerance(tol, "tol", high=np.inf), as_tolerance(fd_step, "fd_step", high=np.inf), \
        as_tolerance(eta, "eta", high=np.inf)
    max_iter = as_count(max_iter, "max_iter", low=1, high=100_000)
    n, p = lo.shape
    k = np.arange(n)
    per_axis = grid if p == 1 else max(2, round(grid ** (1.0 / p)))
    t = np.stack(np.meshgrid(*[np.linspace(0.0, 1.0, per_axis)] * p, indexing="ij"), axis=-1).reshape(-1, p)
    nodes = lo[:, None, :] + (hi - lo)[:, None, :] * t[None]  # (n, G, p)
    fg = _call(index, np.repeat(k, len(t)), nodes.reshape(-1, p), vector).reshape(n, len(t))
    x = nodes[k, np.argmax(fg, axis=1)]
    radius = np.maximum((hi - lo) / (per_axis - 1), tol)
    qp = WarmQP(n * p)
    f, g, H = _derivatives(index, k, x, lo, hi, fd_step, vector)
    it, converged = 0, False
    while it < max_iter:
        it += 1
        # model f + g d - d^T C d / 2 in the scaled step z = d / radius (|z| <= 1), each pose divided by the size s
        # of its model over the trust region, so that every QP entry is O(1) whatever the index
        C = _concave(H, eta * np.maximum(np.abs(f), 1e-300))
        RCR = C * (radius[:, :, None] * radius[:, None, :])
        gr = g * radius
        s = np.maximum(np.maximum(np.max(np.abs(gr), axis=1), np.max(np.abs(RCR), axis=(1, 2))), 1e-300)
        z = qp.solve(_block_diagonal(RCR / s[:, None, None]), (-gr / s[:, None]).ravel(),
                     (np.maximum(lo - x, -radius) / radius).ravel(), (np.minimum(hi - x, radius) / radius).ravel())
        x_new = np.clip(x + z.reshape(n, p) * radius, lo, hi)
        d = x_new - x
        if np.all((np.abs(d) <= tol) | (radius <= tol)):  # no step left above tol
            converged = True
            break
        predicted = np.sum(g * d, axis=1) - 0.5 * _quadratic(d, C)
        f_new, g_new, H_new = _derivatives(index, k, x_new, lo, hi, fd_step, vector)
        ok = (f_new >= f) & np.any(np.abs(d) > 0, axis=1)
        ratio = np.where(predicted > 0, (f_new - f) / np.where(predicted > 0, predicted, 1.0), 0.0)[:, None]
        radius = np.where(ratio > 0.75, np.minimum(2 * radius, hi - lo + tol),
                          np.where(ratio < 0.25, np.maximum(0.25 * np.minimum(radius, np.abs(d)), tol), radius))
        x, g = np.where(ok[:, None], x_new, x), np.where(ok[:, None], g_new, g)
        f, H = np.where(ok, f_new, f), np.where(ok[:, None, None], H_new, H)
    return PointOptimum(_out(x, vector), f, _out(lo, vector), _out(hi, vector), it, qp.solves, qp.iterations,
                        converged)


# ---------------------------------------------------------------------- path
def _rates(rate_limit: ArrayLike, p: int) -> np.ndarray:
    r = as_array(rate_limit, "rate_limit", "a rate limit (one, or one per parameter)")
    r = np.full(p, float(r)) if r.ndim == 0 else r.ravel()
    if r.shape != (p,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
        raise InvalidInputError("rate_limit", f"expected one finite rate limit > 0, or {p} of them", rate_limit)
    return r


def _feasible(lo: np.ndarray, hi: np.ndarray, rate: np.ndarray, vector: bool) -> tuple[np.ndarray, np.ndarray]:
    L, U = lo.copy(), hi.copy()
    for k in range(1, len(L)):
        L[k], U[k] = np.maximum(L[k], L[k - 1] - rate), np.minimum(U[k], U[k - 1] + rate)
        if np.any(L[k] > U[k]):
            i = int(np.flatnonzero(L[k] > U[k])[0])
            which = f" (parameter {i})" if vector else ""
            raise InvalidInputError("rate_limit", f"no profile within the rate limit {rate[i]:.6g} reaches pose "
                                                  f"{k}{which}: its interval [{lo[k, i]:.6g}, {hi[k, i]:.6g}] is "
                                                  "too far from the previous ones", float(rate[i]))
    for k in range(len(L) - 2, -1, -1):
        L[k], U[k] = np.maximum(L[k], L[k + 1] - rate), np.minimum(U[k], U[k + 1] + rate)
    return L, U


def feasible_bounds(lower: ArrayLike, upper: ArrayLike, rate_limit: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The tightest intervals that admit a profile within ``[lower_k, upper_k]`` and the rate limit.

    Forward then backward propagation of the intervals by ``+- rate_limit``, per parameter (``rate_limit`` one
    number, or one per parameter for (n, p) intervals).

    Raises:
        InvalidInputError: when no profile satisfies both (with the first pose that cannot be met).
    """
    lo, hi, vector = _intervals(lower, upper)
    L, U = _feasible(lo, hi, _rates(rate_limit, lo.shape[1]), vector)
    return _out(L, vector), _out(U, vector)


def _clip(x: np.ndarray, L: np.ndarray, U: np.ndarray, rate: np.ndarray) -> np.ndarray:
    y = np.empty_like(L)
    y[0] = np.minimum(np.maximum(x[0], L[0]), U[0])
    for k in range(1, len(y)):
        y[k] = np.minimum(np.minimum(np.maximum(np.maximum(x[k], L[k]), y[k - 1] - rate), U[k]), y[k - 1] + rate)
    return y


def clip_to_rate(x: ArrayLike, lower: ArrayLike, upper: ArrayLike, rate_limit: ArrayLike) -> np.ndarray:
    """``x`` clipped pose by pose, from the first, into the feasible bounds and the rate limit.

    ``y_0 = clip(x_0, L_0, U_0)``, ``y_k = clip(x_k, max(L_k, y_{k-1} - delta), min(U_k, y_{k-1} + delta))``
    with ``L, U`` from :func:`feasible_bounds` (which keeps every interval non-empty), per parameter.
    """
    lo, hi, vector = _intervals(lower, upper)
    rate = _rates(rate_limit, lo.shape[1])
    L, U = _feasible(lo, hi, rate, vector)
    x = as_array(x, "x", "a profile shaped like the intervals")
    x = x if vector else x.reshape(-1, 1) if x.ndim == 1 else x
    if x.shape != L.shape or not np.all(np.isfinite(x)):
        raise InvalidInputError("x", f"expected a finite profile of shape {_out(L, vector).shape}, got shape "
                                     f"{x.shape}", x)
    return _out(_clip(x, L, U, rate), vector)


def optimise_profile(index: IndexFn, lower: ArrayLike, upper: ArrayLike, *, rate_limit: ArrayLike,
                     smoothness: float = 1.0, baseline: ArrayLike | None = 0.0, tol: float = 1e-9,
                     fd_step: float = 1e-5, max_iter: int = 100,
                     eta: float = 1e-6, pointwise: PointOptimum | None = None) -> ProfileOptimum:
    """The profile maximising the summed index minus a smoothness penalty (see the module doc).

    Args:
        index: ``index(k, x)``, vectorised, for the poses ``k = 0..n-1`` of the path (several parameters: ``x`` has
            one row per pose index).
        lower, upper: Admissible interval of each pose, shape (n,); (n, p) for ``p`` parameters.
        rate_limit: ``delta`` >= ``|x_{k+1} - x_k|`` (unit of x per pose; one per parameter, or one for all).
        smoothness: ``mu`` >= 0 [1/unit(x)^2]: the penalty is ``(mu / 2) sum_k ||x_{k+1} - x_k||^2``.
        baseline: The parameter(s) of the model without reconfiguration (``None``: no comparison).
        tol: Stop when the step is below ``tol`` (unit of x).
        fd_step: Finite-difference step.
        max_iter: SQP iterations allowed.
        eta: Least curvature of the model per pose, in units of the scaled objective per unit(x)^2.
        pointwise: The pointwise optima if already computed (else :func:`maximise`).

    Raises:
        InvalidInputError: bad arguments, or no profile fits the intervals and the rate limit.
        ConvergenceError: a QP could not be solved.
    """
    _check_index(index)
    lo, hi, vector = _intervals(lower, upper)
    n, p = lo.shape
    smoothness = as_scalar(smoothness, "smoothness", low=0.0, high=1e12)
    rate = _rates(rate_limit, p)
    base_x = None if baseline is None else np.broadcast_to(as_array(baseline, "baseline", "the baseline parameter(s)"),
                                                           (p,)).astype(float)
    if base_x is not None and not np.all(np.isfinite(base_x)):
        raise InvalidInputError("baseline", "must be finite", baseline)
    tol, fd_step, eta = as_tolerance(tol, "tol", high=np.inf), as_tolerance(fd_step, "fd_step", high=np.inf), \
        as_tolerance(eta, "eta", high=np.inf)
    max_iter = as_count(max_iter, "max_iter", low=1, high=100_000)
    if pointwise is not None and (not isinstance(pointwise, PointOptimum)
                                  or np.shape(pointwise.x) != _out(lo, vector).shape):
        raise InvalidInputError("pointwise", f"expected the PointOptimum of these {n} poses (from maximise)",
                                pointwise)
    Lb, Ub = _feasible(lo, hi, rate, vector)
    pw = maximise(index, _out(lo, vector), _out(hi, vector), tol=tol, fd_step=fd_step, eta=eta) \
        if pointwise is None else pointwise
    scale = float(np.max(np.abs(pw.value)))
    if not scale > 0:
        raise InvalidInputError("index", "the index is zero at every pointwise optimum: nothing to maximise")
    k = np.arange(n)
    D = np.kron(np.diff(np.eye(n), axis=0), np.eye(p))  # ((n-1) p, n p): x_{k+1} - x_k, per parameter
    DtD = D.T @ D

    def objective(x: np.ndarray, f: np.ndarray) -> float:
        return float(np.sum(f) / scale - 0.5 * smoothness * np.sum(np.diff(x, axis=0) ** 2))

    x = _clip(np.asarray(pw.x, dtype=float).reshape(n, p), Lb, Ub, rate)
    f, g, H = _derivatives(index, k, x, Lb, Ub, fd_step, vector)
    start, start_obj = x.copy(), objective(x, f)
    obj = start_obj
    radius = max(float(np.max(Ub - Lb)) / 4, tol)
    qp = WarmQP(n * p, D, -np.tile(rate, n - 1), np.tile(rate, n - 1))
    it, converged = 0, False
    while it < max_iter:
        it += 1
        # the model in the new profile y = x + d: 1/2 y^T (blockdiag(C) + mu D^T D) y - (g + C x)^T y
        C = _concave(H / scale, np.full(n, eta))
        Hq = _block_diagonal(C) + smoothness * DtD
        gq = (-g / scale - np.einsum("nij,nj->ni", C, x)).ravel() if p > 1 else -g[:, 0] / scale - C[:, 0, 0] * x[:, 0]
        y = qp.solve(Hq, gq, np.maximum(Lb, x - radius).ravel(), np.minimum(Ub, x + radius).ravel())
        x_new = np.clip(y.reshape(n, p), Lb, Ub)
        d = x_new - x
        step = float(np.max(np.abs(d)))
        if step <= tol or radius <= tol:
            converged = True
            break
        predicted = float(np.sum(g * d) / scale - 0.5 * np.sum(_quadratic(d, C))
                          - 0.5 * smoothness * (np.sum(np.diff(x_new, axis=0) ** 2) - np.sum(np.diff(x, axis=0) ** 2)))
        f_new, g_new, H_new = _derivatives(index, k, x_new, Lb, Ub, fd_step, vector)
        obj_new = objective(x_new, f_new)
        ratio = (obj_new - obj) / predicted if predicted > 0 else 0.0
        if obj_new >= obj and step > 0:
            x, f, g, H, obj = x_new, f_new, g_new, H_new, obj_new
        if ratio > 0.75 and step >= 0.5 * radius:
            radius = 2 * radius
        elif ratio < 0.25:
            radius = max(0.25 * min(radius, step), tol)
        if 0 <= predicted <= 1e-14 * max(abs(obj), 1.0):
            converged = True
            break
    base = np.full(n, np.nan)
    if base_x is None:
        base_ok = np.zeros(n, dtype=bool)
    else:
        base_ok = np.all((lo <= base_x) & (base_x <= hi), axis=1)
        if np.any(base_ok):
            base[base_ok] = _call(index, k[base_ok], np.tile(base_x, (int(base_ok.sum()), 1)), vector)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        gain = np.where(base_ok & (base != 0.0), f / np.where(base != 0.0, base, 1.0) - 1.0, np.nan)
    gain = np.where(np.isfinite(gain), gain, np.nan)
    return ProfileOptimum(_out(x, vector), f, obj, scale, pw, _out(start, vector), start_obj, base, base_ok, gain,
                          float(np.max(np.abs(np.diff(x, axis=0)))) if n > 1 else 0.0, it, qp.solves, qp.iterations,
                          qp.cold_restarts, converged, tuple(qp.statuses))


__all__ = ["PointOptimum", "ProfileOptimum", "WarmQP", "clip_to_rate", "feasible_bounds", "maximise",
           "optimise_profile"]
