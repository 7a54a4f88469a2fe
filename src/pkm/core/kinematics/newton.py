"""One bounded Gauss-Newton for every square or over-determined system pkm solves (numpy only).

The generic loop closure and inverse kinematics (:mod:`pkm.core.kinematics.solve`), the hexapod's semi-closed
forward kinematics and the polishing of the 3-RRR's polynomial roots all call :func:`gauss_newton`
with their own residual, Jacobian and, on a manifold, their own retraction.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

Fun = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def least_squares(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Newton's step: the least-squares solution of ``A x = b``, by LU when ``A`` is square and regular, SVD
    (rank-revealing, minimum norm) otherwise; zeros (no step: Newton's method then backtracks or stops) where
    ``A`` or ``b`` is not finite or LAPACK fails (entries overflowing). The analyses solve by the SVD of
    :mod:`pkm.core.differential.velocity`, which separates idle motions and raises at singularities."""
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        return np.zeros(A.shape[1])
    if A.shape[0] == A.shape[1]:
        try:
            x = np.linalg.solve(A, b)
            if np.all(np.isfinite(x)):
                return x
        except np.linalg.LinAlgError:
            pass
    try:
        return np.linalg.lstsq(A, b, rcond=None)[0]
    except np.linalg.LinAlgError:  # SVD did not converge
        return np.zeros(A.shape[1])


def gauss_newton(fun: Fun | Callable[[np.ndarray], np.ndarray], x: np.ndarray, *, tol: float, max_iter: int,
                 max_step: float = math.inf, retract: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
                 halvings: int = 8, min_alpha: float = 0.02, stall: int = 3,
                 jacobian: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None) \
        -> tuple[np.ndarray, float, int]:
    """Gauss-Newton with a step cap and backtracking.

    Args:
        fun: ``x -> (residual, Jacobian)``; the Jacobian's columns are the tangent directions of ``x``.
        x: Start.
        tol: Stop when ``max|residual| <= tol``.
        max_iter: Iterations at most.
        max_step: Largest ``max|dx|`` of a step (a longer one is scaled down).
        retract: ``(x, dx) -> x'`` on a manifold (``pin.integrate``); default ``x + dx``.
        halvings: Backtracking halvings of a step that does not lower the residual; a step shortened below
            ``min_alpha`` of its length is taken as it is.
        stall: Stop after this many iterations in a row that lower the residual by less than 1 % (the
            least-squares point of a system with no solution).
        jacobian: ``(x, residual) -> Jacobian``, where it costs more than the residual (finite differences): then
            ``fun`` returns the residual alone, and the Jacobian is made at the iterates kept only, never at a
            backtracking trial.

    Returns:
        ``(x, residual, iterations)``: the last iterate, ``max|residual|`` there (``inf`` if not finite) and
        the iterations made. It stops before a step that would make the residual or ``x`` non-finite.
    """
    move = retract if retract is not None else (lambda x0, dx: x0 + dx)

    evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray | None]] = \
        fun if jacobian is None else (lambda x: (fun(x), None))  # type: ignore[assignment, return-value]
    r, J = evaluate(x)
    res = float(np.max(np.abs(r))) if r.size else 0.0
    it = stalled = 0
    while res > tol and it < max_iter and stalled < stall:
        it += 1
        if J is None:
            J = jacobian(x, r)  # type: ignore[misc]
        step = -least_squares(J, r)
        nrm = float(np.max(np.abs(step))) if step.size else 0.0
        if nrm > max_step:
            step *= max_step / nrm
        alpha = 1.0
        for _ in range(halvings):
            x_try = move(x, alpha * step)
            r_try, J_try = evaluate(x_try)
            res_try = float(np.max(np.abs(r_try)))
            if res_try < res or alpha < min_alpha:
                break
            alpha *= 0.5
        if not (math.isfinite(res_try) and np.all(np.isfinite(x_try))):  # overflow far from a solution: stop here
            break
        stalled = stalled + 1 if res_try >= 0.99 * res else 0
        x, r, J, res = x_try, r_try, J_try, res_try
    return x, (res if math.isfinite(res) else math.inf), it


__all__ = ["gauss_newton", "least_squares"]
