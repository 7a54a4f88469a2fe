"""Closed-form kinematics of the reconfigurable hexapod: inverse and forward position, velocities, the task vector."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.core.differential.indices import inverse_condition
from pkm.core.kinematics import constraints
from pkm.core.kinematics.newton import gauss_newton
from pkm.core.kinematics.task import as_rotation
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import AssemblyError, ConvergenceError, InvalidInputError, InvalidParameterError, UnreachableError
from pkm.mechanisms._common import (
    best_reference,
    check_params,
    rot_z,
)
from pkm.mechanisms.hexapod.geometry import (
    _scalar,
    actuated_from_paper,
    elbow_points,
    inverse_kinematics,
    paper_alphas,
    platform_points,
)
from pkm.mechanisms.hexapod.params import (
    DEFAULT_BRANCH,
    HOME_ROTATION_TOL,
    HexapodParams,
    leg_frame,
)
from pkm.validation import as_array, as_count, as_scalar, as_tolerance, as_vector


def joint_values(params: HexapodParams, R, P, beta: float,
                 branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for a platform pose and ``beta``.

    Args:
        params: The design.
        R: Platform orientation (3x3 rotation).
        P: Platform position [m].
        beta: Reconfiguration angle [rad].
        branch: As for :func:`inverse_kinematics`.

    Returns:
        ``{joint name: coordinates}``; the platform's quaternion is that of ``R``.
    """
    params = check_params(params, HexapodParams)
    R = as_rotation(R)
    alphas = inverse_kinematics(params, R, P, beta, branch)
    return _joint_values(params, R, P, pin.Quaternion(R).coeffs(), beta, alphas)


def _joint_values(params: HexapodParams, R: np.ndarray, P, quat: np.ndarray, beta: float,
                  alphas: np.ndarray) -> dict[str, list[float]]:
    C = platform_points(params, R, P)
    B = elbow_points(params, alphas, beta)
    qa = actuated_from_paper(alphas, beta)
    out: dict[str, list[float]] = {"beta_1": [float(beta)]}
    for i in range(6):
        n = i + 1
        # rod direction in the arm frame = Rz(knee) Ry(knee_b) x
        w = rot_z(-alphas[i]) @ (leg_frame(params.theta[i]).T @ (C[i] - B[i])) / params.LB
        out[f"alpha_{n}"] = [float(qa[i])]
        out[f"knee_{n}"] = [math.atan2(w[1], w[0])]
        out[f"knee_{n}_b"] = [math.asin(max(-1.0, min(1.0, -w[2])))]
    out["platform"] = [float(x) for x in np.concatenate([np.asarray(P, dtype=float), quat])]
    return out


def configuration(mech: Mechanism, y, branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> np.ndarray:
    """Full configuration ``q`` of ``mech`` for task vector ``y = (x, y, z, qx, qy, qz, qw, beta)`` (closed form)."""
    mech = check_mechanism(mech)
    R, P, quat, beta = _task(y)
    alphas = inverse_kinematics(mech.params, R, P, beta, branch)
    return mech.q_from_dict(_joint_values(mech.params, R, P, quat, beta, alphas))


def forward_kinematics(params: HexapodParams, alphas, beta: float, seed=None, *, tol: float = 1e-12,
                       max_iter: int = 50) -> np.ndarray:
    """``C_1..C_6`` [m] from the paper's absolute ``alpha_1..alpha_6`` and ``beta`` (eqs. 4-7).

    Unknowns ``C1, C2, C3`` (9); equations (6) for the six legs, with ``C_{i+3} = C_i + h g``
    (eq. 4, ``g`` from eq. 5 with the layout's sign, see the module doc), and (7) for the three
    sides of ``C1C2C3``. Each equation is divided by twice its length (LB or e) so that the
    residual is in metres. Newton's method with the exact Jacobian and a backtracking line search.

    Args:
        params: The design.
        alphas: The paper's absolute arm angles [rad], shape (6,).
        beta: Reconfiguration angle [rad].
        seed: ``C1, C2, C3`` to start from [m], shape (3, 3); default: those of the reference pose.
        tol: Tolerance on the infinity norm of the residual [m].
        max_iter: Newton iterations allowed.

    Returns:
        ``C_1..C_6`` as rows [m].

    Raises:
        ConvergenceError: with the residual, when Newton's method does not reach ``tol``.
    """
    params = check_params(params, HexapodParams)
    B = elbow_points(params, alphas, _scalar(beta, "beta"))
    if seed is None:
        seed = platform_points(params, *reference_pose(params)[:2])[:3]
    X = as_vector(np.ravel(as_array(seed, "seed", "C1, C2, C3 (3, 3) [m]")), 9, "seed").copy()
    tol = as_tolerance(tol, "tol")
    max_iter = as_count(max_iter, "max_iter", low=1, high=10_000)
    e = params.r * math.sqrt(3.0)
    k = (-1.0 if params.layout == "sector" else 1.0) * 2.0 / (math.sqrt(3.0) * e * e)
    LB, h = params.LB, params.h
    pa, pb = np.array([0, 1, 0]), np.array([1, 2, 2])  # the sides C1C2, C2C3, C1C3
    legs, cols = np.arange(6), np.array([0, 1, 2, 0, 1, 2])

    def normal(C: np.ndarray) -> np.ndarray:  # eq. (5), unit when C1C2C3 is the platform's triangle
        a, b = C[1] - C[2], C[0] - C[2]
        return k * np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])

    def fun(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        C = x.reshape(3, 3)  # vectorised over the legs and the sides
        dv = np.vstack([C, C + h * normal(C)]) - B  # legs 1-3 at C_i, legs 4-6 at C_i + h g
        D = C[pa] - C[pb]
        f = np.empty(9)
        f[:6] = (np.einsum("ij,ij->i", dv, dv) - LB**2) / (2.0 * LB)
        f[6:] = (np.einsum("ij,ij->i", D, D) - e * e) / (2.0 * e)
        dg = k * np.hstack([pin.skew(C[1] - C[2]), -pin.skew(C[0] - C[2]), pin.skew(C[0] - C[1])])  # dg/dX
        J = np.zeros((9, 9))
        J6 = np.zeros((6, 3, 3))
        J6[legs, cols] = dv / LB
        J[:6] = J6.reshape(6, 9)
        J[3:6] += h * (dv[3:] @ dg) / LB
        J3 = np.zeros((3, 3, 3))
        J3[np.arange(3), pa] = D / e
        J3[np.arange(3), pb] = -D / e
        J[6:] = J3.reshape(3, 9)
        return f, J

    X, res, it = gauss_newton(fun, X, tol=tol, max_iter=max_iter, halvings=20, min_alpha=0.0)
    if not res <= tol:
        raise ConvergenceError("semi-closed forward kinematics (eqs. 4-7)", res if np.isfinite(res) else np.inf, it,
                               tol, detail="the actuated angles may admit no assembly near the seed; try another "
                                           "seed or assembly_modes()")
    C = X.reshape(3, 3)
    return np.vstack([C, C + params.h * normal(C)])


@dataclass(frozen=True)
class AssemblyMode:
    """One solution of the forward kinematics.

    Attributes:
        C: ``C_1..C_6`` as rows [m].
        R: Platform orientation (eqs. 9-12).
        P: Platform position [m] (eq. 8).
        q: The full configuration of the tree (closed-form joint values of this assembly).
        core_residual: Largest closure residual of the generic core at ``q`` [m]
            (:func:`pkm.core.kinematics.constraints.residual`): the independent check of the solution.
    """

    C: np.ndarray
    R: np.ndarray
    P: np.ndarray
    q: np.ndarray
    core_residual: float


def assembly_modes(mech: Mechanism, q_actuated, *, n_starts: int = 32, seed: int = 0, tol: float = 1e-12,
                   max_iter: int = 25, distinct: float = 1e-6, verify_tol: float = 1e-9) -> list[AssemblyMode]:
    """Assembly modes for given actuated coordinates: the semi-closed FK (eqs. 4-13) from many seeds.

    Multistart: Newton's method (:func:`forward_kinematics`) from the reference pose and from
    ``n_starts - 1`` random platform poses (uniform rotations, positions in a box below the base
    spanning the legs' reach); solutions closer than ``distinct`` (max over ``C_i`` [m]) are merged.
    Each solution is then checked by the generic core: the full configuration built from it must
    close every loop to ``verify_tol`` (it always does when Newton converged; a failure would mean
    eqs. 4-13 and the tree disagree). There is no guarantee that every mode is found.

    Args:
        mech: The hexapod (:func:`build`).
        q_actuated: ``alpha_1..alpha_6`` (joint coordinates, relative for legs 1-3), ``beta_1`` [rad].
        n_starts: Seeds tried (>= 1).
        seed: Seed of the random generator (reproducible results).
        tol: Newton tolerance [m].
        max_iter: Newton iterations per seed.
        distinct: Distance under which two solutions are the same [m].
        verify_tol: Largest closure residual of the generic core accepted [m].

    Returns:
        The modes found, sorted by distance of ``P`` from the reference pose.

    Raises:
        AssemblyError: no seed converged (the actuated coordinates probably admit no assembly).
    """
    mech = check_mechanism(mech)
    params = check_params(mech.params, HexapodParams, "mech.params")
    qa = as_vector(q_actuated, 7, "q_actuated")
    n_starts = as_count(n_starts, "n_starts", low=1, high=100_000)
    seed = as_count(seed, "seed", low=0, high=2**63 - 1)
    tol, verify_tol = as_tolerance(tol, "tol"), as_tolerance(verify_tol, "verify_tol")
    max_iter = as_count(max_iter, "max_iter", low=1, high=10_000)
    distinct = as_scalar(distinct, "distinct", low=0.0, strict_low=True, unit="m")
    alphas, beta = paper_alphas(qa), float(qa[6])
    rng = np.random.default_rng(seed)
    reach = params.LA + params.LB
    seeds: list[np.ndarray | None] = [None]
    for _ in range(n_starts - 1):
        Rs = pin.Quaternion(*rng.normal(size=4)).normalized().toRotationMatrix()
        Ps = rng.uniform([-reach / 2, -reach - params.H0, -reach / 2], [reach / 2, params.Rr, reach / 2])
        seeds.append(platform_points(params, Rs, Ps)[:3])
    found: list[AssemblyMode] = []
    best_res = math.inf
    for s0 in seeds:
        try:
            C = forward_kinematics(params, alphas, beta, s0, tol=tol, max_iter=max_iter)
        except ConvergenceError as exc:
            best_res = min(best_res, exc.residual)
            continue
        if any(np.abs(C - m.C).max() < distinct for m in found):
            continue
        R, P = pose_from_points(params, C)
        q = mech.q_from_dict(_joint_values(params, R, P, pin.Quaternion(R).coeffs(), beta, alphas))
        res = float(np.abs(constraints.residual(mech, q)).max())
        if res > verify_tol or np.abs(mech.actuated_q(q) - actuated_from_paper(alphas, beta)).max() > 1e-12:
            raise ConvergenceError("assembly-mode check by the generic core", res, 0, verify_tol,
                                   detail="the semi-closed FK and the tree disagree")
        found.append(AssemblyMode(C, R, P, q, res))
    if not found:
        raise AssemblyError(best_res, "m", f"Newton's method failed from all {n_starts} seeds")
    P0 = reference_pose(params)[1]
    return sorted(found, key=lambda m: float(np.linalg.norm(m.P - P0)))


def pose_from_points(params: HexapodParams, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Platform orientation and position ``(R, P)`` from ``C_1..C_6`` (eqs. 8-13, layout's sign of eq. 11)."""
    params = check_params(params, HexapodParams)
    C = np.asarray(C, dtype=float)
    P = C[3:].mean(axis=0)
    x = (C[3] - P) / np.linalg.norm(C[3] - P)
    z = C[4] - C[5] if params.layout == "sector" else C[5] - C[4]
    z = z / np.linalg.norm(z)
    return np.column_stack([x, np.cross(z, x), z]), P


def task_vector(R, P, beta: float) -> np.ndarray:
    """The task vector ``(x, y, z, qx, qy, qz, qw, beta)`` of a pose and ``beta``."""
    return np.concatenate([np.asarray(P, dtype=float), pin.Quaternion(np.asarray(R, dtype=float)).coeffs(),
                           [float(beta)]])


# ---------------------------------------------------------------------- reference pose
REFERENCE_DEPTHS = 64  # candidate reference depths of P below the base


def reference_pose(params: HexapodParams) -> tuple[np.ndarray, np.ndarray, float]:
    """The design's reference pose ``(R, P, beta)`` [-, m, rad], where its reference configuration is
    assembled (elbows out).

    ``R``: ``params.home_rotation`` projected on SO(3), or the identity (level platform); ``beta``:
    ``params.home_beta``; ``P``: ``params.home_position`` when given, otherwise the point
    ``(0, -(LA + LB) k / 64, 0)``, ``k = 1..64``, of largest inverse condition number of the twist
    Jacobian (velocities of P divided by ``LA``, per ``alpha_1..alpha_6``).

    Raises:
        InvalidParameterError: (``home_position``) the given pose is unreachable (which leg, by how
            much), or no candidate assembles at an inverse condition number >= 1e-3.
    """
    params = check_params(params, HexapodParams)
    R, P, beta = _reference(params)
    return R.copy(), P.copy(), beta


@functools.lru_cache(maxsize=256)
def _reference(params: HexapodParams) -> tuple[np.ndarray, np.ndarray, float]:
    from pkm.mechanisms.hexapod import screws  # (screws imports the geometry, not this module)

    R = np.eye(3) if params.home_rotation is None else as_rotation(params.home_rotation, "home_rotation",
                                                                   HOME_ROTATION_TOL)
    beta = params.home_beta
    if params.home_position is not None:
        try:
            inverse_kinematics(params, R, params.home_position, beta)
        except UnreachableError as exc:
            raise InvalidParameterError(
                "home_position", f"the reference pose is unreachable with this design (leg {exc.leg} misses by "
                                 f"{exc.excess:.4g} m); choose another home pose, home_beta or other lengths",
                params.home_position) from None
        return R, np.array(params.home_position), beta
    scale = np.r_[np.ones(3), np.full(3, 1.0 / params.LA)]

    def score(P: np.ndarray) -> float:
        J = screws.jacobians(params, R, P, beta).twist_jacobian("P")[:, :6]
        return float(inverse_condition(scale[:, None] * J))

    reach = params.LA + params.LB
    depths = (np.array([0.0, -reach * k / REFERENCE_DEPTHS, 0.0]) for k in range(1, REFERENCE_DEPTHS + 1))
    return R, best_reference("home_position", depths, score, minimum=1e-3), beta


# ---------------------------------------------------------------------- uniform interface
# Task vector y (as pkm.core.TaskMap lays it out): x y z qx qy qz qw of the frame ``platform``, then beta_1.
def closed_form_ik(params: HexapodParams, y, branch: str | tuple[str, ...] | None = None) -> np.ndarray:
    """Actuated coordinates (``alpha_1..alpha_6`` joint coordinates, ``beta_1``) for task vector ``y``."""
    params = check_params(params, HexapodParams)
    R, P, _, beta = _task(y)
    return actuated_from_paper(inverse_kinematics(params, R, P, beta, branch or DEFAULT_BRANCH), beta)


def closed_form_configuration(mech: Mechanism, y, branch: str | tuple[str, ...] | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form)."""
    return configuration(mech, y, branch or DEFAULT_BRANCH)


def closed_form_fk(params: HexapodParams, q_actuated, seed=None) -> np.ndarray:
    """Task vector from the actuated coordinates by the paper's semi-closed method (eqs. 4-13).

    Args:
        params: The design.
        q_actuated: ``alpha_1..alpha_6`` (joint coordinates: relative for legs 1-3), ``beta_1`` [rad].
        seed: A task vector whose pose seeds Newton's method (its ``beta`` is ignored); default:
            the reference pose.

    Raises:
        ConvergenceError: when Newton's method fails (residual attached).
    """
    params = check_params(params, HexapodParams)
    qa = as_vector(q_actuated, 7, "q_actuated")
    C0 = None
    if seed is not None:
        R0, P0, _, _ = _task(seed, "seed")
        C0 = platform_points(params, R0, P0)[:3]
    C = forward_kinematics(params, paper_alphas(qa), qa[6], C0)
    R, P = pose_from_points(params, C)
    return task_vector(R, P, qa[6])


def _task(y, name: str = "y") -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """``(R, P, quaternion xyzw, beta)`` from a task vector; the quaternion must have norm 1 (to 1e-6)."""
    y = as_vector(y, 8, name)
    quat = y[3:7]
    nrm = np.linalg.norm(quat)
    if abs(nrm - 1.0) > 1e-6:
        raise InvalidInputError(name, f"quaternion (qx, qy, qz, qw) has norm {nrm:.6g}, expected 1", y)
    quat = quat / nrm
    R = pin.Quaternion(quat[3], quat[0], quat[1], quat[2]).toRotationMatrix()
    return R, y[:3].copy(), quat, float(y[7])
