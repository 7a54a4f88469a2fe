"""The physically consistent estimate: standard parameters every body of which can exist, fitted to the efforts.

Least squares (:func:`pkm.estimate`) gives base parameters that may belong to no real mechanism (a negative mass
behind a combination, an inertia that violates the triangle inequality). This estimate solves for every standard
parameter ``θ`` (ten per body, four per drive) a semidefinite program (Wensing, Kim and Slotine, IEEE RA-L 2018):

* minimise ``|w ⊙ (Y θ - τ)|² + ε |θ - θ_model|²``, the weights ``w`` Gautier's (each actuator's, from the least
  squares residual), ``ε`` = :data:`REGULARISATION` times the mean squared column norm of the weighted regressor:
  small enough to leave the fit of the base parameters alone (tested: they move by much less than their standard
  deviations), large enough to fix the directions the efforts cannot see at the model's own values;
* subject to every body's **pseudo-inertia** ``J = [[Σ, h], [hᵀ, m]] ⪰ 0`` (``Σ = ½ tr(Ī) 1 - Ī``, ``Ī`` the
  inertia about the body's frame origin, ``h = m c``: equivalent to a non-negative mass density, so mass ≥ 0, the
  inertia about the centre of mass positive semi-definite and its triangle inequalities), and each drive's reflected
  inertia, viscous and Coulomb friction ``≥ 0`` (the offset free).

Solver: ``cvxpy`` with **Clarabel** (an interior-point conic solver, maintained, in Rust; the ``identify`` extra):
chosen over SCS, a first-order method whose accuracy (about 1e-4 relative) would blur a fit whose residuals are at
the 1e-3 level; the problem is stated on the ``R`` factor of the weighted regressor's QR (p x p) instead of its
``(N na)`` rows, which gives the same minimiser.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike

from pkm._optional import module
from pkm.core.identification.base import BaseParameters, base_parameters
from pkm.core.identification.estimate import Estimate, _scale, estimate
from pkm.core.identification.regressor import known_efforts, parameters, regressor_batch
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.plausibility import require_physical
from pkm.errors import ConvergenceError, InvalidInputError

REGULARISATION = 1e-6  # ε, relative to the weighted regressor's mean squared column norm


def _cvxpy(what: str) -> ModuleType:
    """``cvxpy``, imported without JAX where the MPAX solver is absent: cvxpy's import asks every solver whether it is
    installed by importing it, and MPAX's check imports JAX (1.5 s of CPU) before it fails on ``mpax``; pkm solves
    with Clarabel. (JAX imports as usual afterwards.)"""
    import importlib.util
    import sys

    hide = "cvxpy" not in sys.modules and "jax" not in sys.modules and importlib.util.find_spec("mpax") is None
    if hide:
        sys.modules["jax"] = None  # type: ignore[assignment]  # (import jax: ModuleNotFoundError, as when absent)
    try:
        return module("cvxpy", extra="identify", what=what)
    finally:
        if hide and "jax" in sys.modules and sys.modules["jax"] is None:
            del sys.modules["jax"]


def pseudo_inertia(theta10: ArrayLike) -> np.ndarray:
    """A body's 4 x 4 pseudo-inertia from its ten standard parameters (Pinocchio's order: ``m, h, Ixx, Ixy, Iyy,
    Ixz, Iyz, Izz`` about the frame's origin): ``[[½ tr(Ī) 1 - Ī, h], [hᵀ, m]]``."""
    m, hx, hy, hz, xx, xy, yy, xz, yz, zz = np.asarray(theta10, dtype=float)
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    J = np.zeros((4, 4))
    J[:3, :3] = 0.5 * np.trace(inertia) * np.eye(3) - inertia
    J[:3, 3] = J[3, :3] = (hx, hy, hz)
    J[3, 3] = m
    return J


def _projected(theta: np.ndarray, n_bodies: int, n_body: int, na: int) -> np.ndarray:
    """``theta`` with every body's pseudo-inertia projected onto the positive semidefinite cone (its negative
    eigenvalues set to zero: the nearest consistent body in the Frobenius norm) and every drive's inertia and
    friction clipped at zero. Clarabel meets the constraints to its tolerance only: a massless body (the Delta's
    guides) came out at -3e-11 kg, a mass no file holds (the URDF reader refuses it); the projection moves the
    parameters by as little, and the mass it gives, a sum of non-negative terms, is never negative."""
    out = theta.copy()
    for b in range(n_bodies):
        lam, V = np.linalg.eigh(pseudo_inertia(theta[10 * b:10 * b + 10]))
        if lam.min() >= 0.0:
            continue
        J = (V * np.maximum(lam, 0.0)) @ V.T
        sigma = J[:3, :3]
        inertia = np.trace(sigma) * np.eye(3) - sigma  # (Σ = ½ tr(Ī) 1 - Ī, so tr Σ = ½ tr Ī)
        out[10 * b:10 * b + 10] = (J[3, 3], *J[:3, 3], inertia[0, 0], inertia[0, 1], inertia[1, 1], inertia[0, 2],
                                   inertia[1, 2], inertia[2, 2])
    for i in range(na):
        k = n_body + 4 * i
        out[k:k + 3] = np.maximum(out[k:k + 3], 0.0)
    return out


@dataclass(frozen=True)
class ConsistentEstimate:
    """A physically consistent estimate (module doc).

    Attributes:
        theta: Every standard parameter (:func:`pkm.parameters`' order).
        base_values: ``P θ``: the base parameters it implies (comparable with least squares').
        smallest_eigenvalue: The smallest eigenvalue of every body's pseudo-inertia [kg m^2 or kg]: ``≥ 0`` up to
            rounding (the solver's answer is projected onto the constraints: :func:`_projected`).
        residual_rms: Each actuator's residual RMS on the data [N m, N].
        least_squares: The least-squares estimate it started from (its weights used).
        status: The solver's status.
    """

    theta: np.ndarray
    base_values: np.ndarray
    smallest_eigenvalue: float
    residual_rms: np.ndarray
    least_squares: Estimate
    status: str

    def predict(self, Y: ArrayLike) -> np.ndarray:
        """The efforts ``Y θ`` of a standard regressor ``Y`` (rows as stacked by :func:`pkm.regressor`)."""
        return np.asarray(Y, dtype=float) @ self.theta


def consistent_estimate(mech: Mechanism, Q: ArrayLike, QD: ArrayLike, QDD: ArrayLike, TAU: ArrayLike, *,
                        base: BaseParameters | None = None, ls: Estimate | None = None,
                        regularisation: float = REGULARISATION) -> ConsistentEstimate:
    """The physically consistent estimate from N samples (as :func:`pkm.estimate` takes them; module doc).

    Raises:
        MissingDependencyError: cvxpy or Clarabel missing (``pip install "pkm-robotics[identify]"``).
        ConvergenceError: the solver did not reach an optimal solution (its status in the message).
        InvalidInputError, SingularityError: as :func:`pkm.estimate`.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> rng = np.random.default_rng(0)
        >>> Q = np.array([pkm.solve_ik(delta, [x, y, -0.36]).q for x, y in 0.05 * rng.standard_normal((50, 2))])
        >>> QD, QDD = rng.standard_normal((50, 3)), 10 * rng.standard_normal((50, 3))
        >>> TAU = np.array([pkm.actuator_model(delta, q, qd).efforts(qdd)
        ...                 for q, qd, qdd in zip(Q, QD, QDD)])
        >>> base = pkm.base_parameters(delta, 50, precise=False)
        >>> TAU += 1e-3 * rng.standard_normal(TAU.shape)  # measurement noise [N m]
        >>> sdp = pkm.consistent_estimate(delta, Q, QD, QDD, TAU, base=base)
        >>> sdp.status, bool(sdp.smallest_eigenvalue >= -1e-9)
        ('optimal', True)
        >>> sdp.theta.shape
        (132,)
    """
    what = "the physically consistent estimate"
    mech = check_mechanism(mech)
    require_physical(mech, what + " (its prior: the model's inertias)")
    cp = _cvxpy(what)
    module("clarabel", extra="identify", what=what)
    base = base if base is not None else base_parameters(mech, precise=False)
    ls = ls if ls is not None else estimate(mech, Q, QD, QDD, TAU, base=base)
    P = parameters(mech)
    Q_, QD_, QDD_, TAU_ = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (Q, QD, QDD, TAU))
    Y = regressor_batch(mech, Q_, QD_, QDD_)
    TAU_ = TAU_ - known_efforts(mech, Q_, QD_)  # (the springs' and the passive joints' friction: no parameter's)
    w = np.tile(ls.weights, len(Q_))
    Yw, yw = Y * w[:, None], TAU_.reshape(-1) * w
    Qf, R = np.linalg.qr(Yw)
    rhs = Qf.T @ yw
    eps = regularisation * float(np.mean(np.sum(Yw * Yw, axis=0)))
    theta = cp.Variable(len(P))
    cost = cp.sum_squares(R @ theta - rhs) + eps * cp.sum_squares(theta - P.values)
    cons = []
    for b in range(len(P.bodies)):
        t = theta[10 * b:10 * b + 10]
        m, hx, hy, hz, xx, xy, yy, xz, yz, zz = (t[i] for i in range(10))
        half = 0.5 * (xx + yy + zz)
        J = cp.bmat([[half - xx, -xy, -xz, hx], [-xy, half - yy, -yz, hy], [-xz, -yz, half - zz, hz],
                     [hx, hy, hz, m]])
        cons.append(0.5 * (J + J.T) >> 0)
    for i in range(mech.na):
        k = P.n_body + 4 * i
        cons.append(theta[k:k + 3] >= 0)
    problem = cp.Problem(cp.Minimize(cost), cons)
    try:
        problem.solve(solver="CLARABEL")
    except cp.error.SolverError as exc:
        raise ConvergenceError(f"{what} (Clarabel: {exc})", float("nan"), 0, 0.0) from None
    if problem.status not in ("optimal", "optimal_inaccurate") or theta.value is None:
        raise ConvergenceError(f"{what} (Clarabel's status: {problem.status})", float("nan"), 0, 0.0)
    th = _projected(np.asarray(theta.value, dtype=float), len(P.bodies), P.n_body, mech.na)
    smallest = min(float(np.linalg.eigvalsh(pseudo_inertia(th[10 * b:10 * b + 10])).min())
                   for b in range(len(P.bodies)))
    s = _scale(float(np.abs(TAU_).max()))  # (the residuals' squares overflow beyond 1e154: taken divided by s)
    with np.errstate(over="ignore"):
        rms = s * np.sqrt(np.mean(((TAU_ - (Y @ th).reshape(TAU_.shape)) / s) ** 2, axis=0))
    if not np.all(np.isfinite(rms)):
        raise InvalidInputError("TAU", f"efforts up to {np.abs(TAU_).max():.3g} [N m, N]: the residuals of "
                                       f"{what} overflow", float(np.abs(TAU_).max()))
    return ConsistentEstimate(th, base.map @ th, smallest, rms, ls, str(problem.status))


__all__ = ["REGULARISATION", "ConsistentEstimate", "consistent_estimate", "pseudo_inertia"]
