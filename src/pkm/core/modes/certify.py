"""Smale's alpha test on a polished solution of a square polynomial system of degree <= 2.

For ``F`` analytic with ``J = DF(x)`` invertible, let ``beta = |J^-1 F(x)|`` (the Newton step) and
``gamma = sup_k |J^-1 D^k F(x) / k!|^(1/(k-1))``. If ``alpha = beta gamma < (13 - 3 sqrt 17)/4 ~ 0.1577``, Newton's
method from ``x`` converges quadratically to a true zero ``x*`` with ``|x - x*| <= 2 beta`` (Blum, Cucker, Shub,
Smale, *Complexity and Real Computation*, 1998, ch. 8). For a system of degree <= 2 the only term is ``k = 2``
with the constant second derivative, so ``gamma = |J^-1 D^2F / 2|`` exactly; pkm bounds that bilinear map's norm
by its Frobenius norm (an upper bound: the certificate only gets more conservative).

What this is not: the quantities are evaluated in double precision, not interval arithmetic; the certificate is
a numerical one (rounding in ``beta`` is of order ``1e-16 |x|``, far inside the radius it certifies).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm.core.modes.polynomial import System

#: Smale's constant: alpha below it certifies a zero within ``2 beta``.
ALPHA0 = (13.0 - 3.0 * math.sqrt(17.0)) / 4.0


@dataclass(frozen=True)
class Certificate:
    """Smale's alpha test at one point (module doc).

    Attributes:
        alpha: ``beta * gamma`` (certified when < :data:`ALPHA0`).
        beta: The Newton step's length at the point (variables' units).
        gamma: The bound on ``|J^-1 D^2F / 2|``.
        radius: ``2 beta``: a true solution lies within it of the point (when certified).
        certified: ``alpha < ALPHA0``.
    """

    alpha: float
    beta: float
    gamma: float
    radius: float
    certified: bool


def polish(system: System, x: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Newton's method in complex double precision from ``x`` (square system); stops when the step stalls."""
    x = np.asarray(x, dtype=complex).copy()
    for _ in range(iterations):
        try:
            dx = np.linalg.solve(system.jacobian(x), system(x))
        except np.linalg.LinAlgError:
            break
        x = x - dx
        if np.linalg.norm(dx) <= 1e-15 * max(1.0, float(np.linalg.norm(x))):
            break
    return x


def alpha_test(system: System, x: np.ndarray) -> Certificate:
    """Smale's alpha test at ``x`` for a square ``system`` of degree <= 2."""
    x = np.asarray(x, dtype=complex)
    J = system.jacobian(x)
    if len(system) != system.n or not np.all(np.isfinite(J)):
        return Certificate(math.inf, math.inf, math.inf, math.inf, False)
    try:
        Jinv = np.linalg.inv(J)
    except np.linalg.LinAlgError:
        return Certificate(math.inf, math.inf, math.inf, math.inf, False)
    beta = float(np.linalg.norm(Jinv @ system(x)))
    M = np.einsum("ki,ijl->kjl", Jinv, system.hessians()) / 2.0
    gamma = float(np.sqrt(np.sum(np.abs(M) ** 2)))
    alpha = beta * gamma
    return Certificate(alpha, beta, gamma, 2.0 * beta, bool(alpha < ALPHA0))
