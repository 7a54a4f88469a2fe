"""Closed-form kinematics of the Delta: inverse and forward position, velocities, the task vector."""

from __future__ import annotations

import functools
import math

import numpy as np

from pkm.core.differential.indices import inverse_condition
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import AssemblyError, InvalidInputError, InvalidParameterError, SingularityError, UnreachableError
from pkm.mechanisms._common import (
    best_reference,
    check_params,
    leg_arm_angles,
    leg_branches,
    rot_z,
)
from pkm.mechanisms.delta.params import BRANCHES, PHI, DeltaParams
from pkm.validation import as_vector, finite_result

# ---------------------------------------------------------------------- closed forms
_COS_PHI, _SIN_PHI = np.cos(PHI), np.sin(PHI)


def _arm_frame_points(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Rz(-phi_i) p`` for the three arms: coordinates ``x, y, z`` of shape (3,) [m]."""
    return _COS_PHI * p[0] + _SIN_PHI * p[1], -_SIN_PHI * p[0] + _COS_PHI * p[1], np.full(3, p[2])


def inverse_kinematics(params: DeltaParams, p, branch: str | tuple[str, str, str] = "knee_out") -> np.ndarray:
    """Motor angles ``(th_1, th_2, th_3)`` [rad] placing the platform centre at ``p`` [m].

    Per arm, ``B_i`` lies on a circle of radius ``La`` and at distance ``Lb`` from the
    shifted platform point (eqs. 2-3, 8): ``Y cos th + z sin th = K`` with
    ``Y = y_i - (R - r)``, ``K = (x_i^2 + Y^2 + z_i^2 + La^2 - Lb^2) / (2 La)``.

    Args:
        params: The design.
        p: Platform centre [m], shape (3,).
        branch: ``"knee_out"``/``"knee_in"`` for all arms, or one per arm.

    Raises:
        UnreachableError: with the first arm that cannot reach and by how much [m].
    """
    params = check_params(params, DeltaParams)
    p = as_vector(p, 3, "p")
    return arm_angles(params.La, params.Lb, params.R - params.r, p, branch_signs(branch))


def branch_signs(branch) -> tuple[int, int, int]:
    """The sign of each arm's root (``-BRANCHES[name]``) for one working-mode name or a tuple of three."""
    a, b, c = (-BRANCHES[name] for name in leg_branches(branch, BRANCHES, 3))
    return a, b, c


def arm_angles(La: float, Lb: float, offset: float, p: np.ndarray, signs: tuple[int, int, int],
               where: str = "") -> np.ndarray:
    """The motor angles [rad] of :func:`inverse_kinematics` from raw dimensions [m]:
    ``offset = R - r``, ``signs[i] = +1`` for knee out, ``-1`` for knee in; ``where`` ends
    the message of the :class:`UnreachableError` (for example the design studied)."""
    x, y, z = _arm_frame_points(p)
    return leg_arm_angles(y - offset, z, x, La, Lb, signs,
                      lambda leg: f"arm {leg}: the forearm cannot span the distance to the elbow circle{where}")


def sphere_centres(params: DeltaParams, theta) -> np.ndarray:
    """Centres ``B'_i`` of the three spheres of radius Lb (eqs. 3-7), rows i = 1..3 [m]."""
    params = check_params(params, DeltaParams)
    theta = as_vector(theta, 3, "theta")
    return np.array([rot_z(PHI[i]) @ np.array([0.0, params.R + params.La * math.cos(theta[i]) - params.r,
                                                params.La * math.sin(theta[i])]) for i in range(3)])


def forward_kinematics(params: DeltaParams, theta, *, both: bool = False) -> np.ndarray:
    """Platform centre [m] from motor angles [rad], by intersecting three spheres (eqs. 1-8).

    As in the paper, (8c)-(8a) and (8c)-(8b) give x and y as affine functions of z, and (8a)
    becomes a quadratic in z; the root with the lower z (the platform below the base) is
    returned, or both (lower first) with ``both=True``. The paper keeps "the negative root";
    with the arms raised both roots can be negative. The two roots are mirror images through the
    plane of the three sphere centres; the lower one is the platform below that plane.

    Raises:
        AssemblyError: when the spheres have no common point (by how much, in m^2 of the
            discriminant scaled back to metres).
    """
    c = sphere_centres(params, theta)
    # 2 (c_a - c_3) . p = |c_a|^2 - |c_3|^2 for a = 1, 2  ->  M [x, y] = b + n z
    M = 2.0 * np.array([c[0, :2] - c[2, :2], c[1, :2] - c[2, :2]])
    rhs = np.array([c[0] @ c[0] - c[2] @ c[2], c[1] @ c[1] - c[2] @ c[2]])
    nz = -2.0 * np.array([c[0, 2] - c[2, 2], c[1, 2] - c[2, 2]])
    det = np.linalg.det(M)
    if abs(det) < 1e-15:
        raise AssemblyError(0.0, "m", "sphere centres aligned in the base plane: x, y are not functions of z")
    Minv = np.linalg.inv(M)
    b0, b1 = Minv @ rhs, Minv @ nz  # [x, y] = b0 + b1 z
    d0 = b0 - c[0, :2]
    qa = b1 @ b1 + 1.0
    qb = 2.0 * (d0 @ b1 - c[0, 2])
    qc = d0 @ d0 + c[0, 2] ** 2 - params.Lb**2
    disc = qb * qb - 4.0 * qa * qc
    if disc < 0.0:
        raise AssemblyError(float(math.sqrt(-disc) / (2.0 * qa)), "m", "the three spheres do not intersect")
    roots = sorted([(-qb - math.sqrt(disc)) / (2.0 * qa), (-qb + math.sqrt(disc)) / (2.0 * qa)])
    sols = finite_result(np.array([np.concatenate([b0 + b1 * z, [z]]) for z in roots]), "platform position",
                         "the sphere centres are nearly aligned (x, y barely determined by z)")
    return sols if both else sols[0]


def jacobian_factors(params: DeltaParams, p, theta, R=None) -> tuple[np.ndarray, np.ndarray]:
    """The two factors of the velocity equations ``A Xd = diag(d) thd``, over stacks of poses.

    Differentiating the sphere equations (8), ``f_i = |E + Rz(phi_i)(0, r, 0) - B_i(th_i)|^2 - Lb^2 = 0``,
    gives ``u_i . Ed = (u_i . dB_i/dth_i) thd_i`` with ``u_i`` the forearm vector from ``B_i`` to the
    ball joint. So ``A`` has rows ``u_i`` [m] (it loses rank at direct singularities) and
    ``d_i = u_i . dB_i/dth_i`` [m^2/rad] (it vanishes at inverse singularities, arm and forearm aligned).

    Args:
        params: The design.
        p: Platform centres [m], shape (..., 3).
        theta: Motor angles [rad] assembled with ``p``, shape (..., 3).
        R: The base radius [m] in place of ``params.R``: a float, or an array of shape (...) (a family of
            designs, one pose each; as :func:`pkm.mechanisms.delta.design.condition_vs_radius` sweeps R).

    Returns:
        ``A`` of shape (..., 3, 3) and ``d`` of shape (..., 3).
    """
    params = check_params(params, DeltaParams)
    p, theta = np.asarray(p, dtype=float), np.asarray(theta, dtype=float)
    R = params.R if R is None else R
    c, s = np.cos(theta), np.sin(theta)
    A = np.empty(p.shape[:-1] + (3, 3))
    d = np.empty(p.shape[:-1] + (3,))
    for i in range(3):
        ci, si = math.cos(PHI[i]), math.sin(PHI[i])
        # arm frame: forearm vector (x, y, z) and dB/dth = (0, -La s, La c); back to the base by Rz(phi_i)
        x = ci * p[..., 0] + si * p[..., 1]
        y = -si * p[..., 0] + ci * p[..., 1] + params.r - R - params.La * c[..., i]
        z = p[..., 2] - params.La * s[..., i]
        A[..., i, 0], A[..., i, 1], A[..., i, 2] = ci * x - si * y, si * x + ci * y, z
        d[..., i] = params.La * (z * c[..., i] - y * s[..., i])
    return A, d


def jacobian(params: DeltaParams, theta, p=None) -> np.ndarray:
    """``J = dX/dth`` [m/rad] (eq. 12), in closed form from the sphere equations: ``J = A^-1 diag(d)``.

    See :func:`jacobian_factors`. The paper differentiates its explicit forward solution; the
    implicit route gives the same matrix without the long symbolic expressions.

    Args:
        params: The design.
        theta: Motor angles [rad], shape (3,).
        p: The platform centre assembled with ``theta`` [m]; default: :func:`forward_kinematics`
            (the lower root). Pass the other root for the other assembly.

    Raises:
        InvalidInputError: if ``p`` is not assembled with ``theta`` (a forearm off its length by > 1e-9 m).
        SingularityError: ``kind="direct"`` where the forearm vectors are linearly dependent.
    """
    params = check_params(params, DeltaParams)
    theta = as_vector(theta, 3, "theta")
    p = forward_kinematics(params, theta) if p is None else as_vector(p, 3, "p")
    A, d = jacobian_factors(params, p, theta)
    gap = np.abs(np.linalg.norm(A, axis=1) - params.Lb)
    if gap.max() > 1e-9:
        k = int(np.argmax(gap))
        raise InvalidInputError("p", f"not assembled with theta: forearm {k + 1} is off its length by {gap[k]:.3g} m", p)
    sv = np.linalg.svd(A, compute_uv=False)
    if sv[-1] <= 1e-12 * params.Lb:
        raise SingularityError("direct", sv[-1], "forearms linearly dependent: the platform moves with the motors locked")
    return np.linalg.solve(A, np.diag(d))


def joint_values(params: DeltaParams, p, branch: str | tuple[str, str, str] = "knee_out") -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form), for platform centre ``p``."""
    params = check_params(params, DeltaParams)
    p = as_vector(p, 3, "p")
    th = inverse_kinematics(params, p, branch)
    out: dict[str, list[float]] = {}
    for i in range(3):
        Rz = rot_z(PHI[i])
        c, s = math.cos(th[i]), math.sin(th[i])
        L = Rz @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])  # arm frame after the motor
        B = Rz @ np.array([0.0, params.R + params.La * c, params.La * s])
        P = p + Rz @ np.array([0.0, params.r, 0.0])
        f = L.T @ (P - B) / params.Lb  # forearm direction in the arm frame = Rx(k1) Rz(k2) e_y
        out[f"motor_{i + 1}"] = [float(th[i])]
        out[f"knee_{i + 1}"] = [math.atan2(f[2], f[1])]
        out[f"knee_{i + 1}_b"] = [math.asin(max(-1.0, min(1.0, -f[0])))]
    for k, axis in enumerate("xyz"):
        out[f"platform_{axis}"] = [float(p[k])]
    return out


def configuration(mech: Mechanism, p, branch: str | tuple[str, str, str] = "knee_out") -> np.ndarray:
    """Full configuration vector ``q`` of ``mech`` for platform centre ``p`` (closed form)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(mech.params, p, branch))


# ---------------------------------------------------------------------- reference pose
REFERENCE_DEPTHS = 64  # candidate reference positions on the axis below the base


def reference_pose(params: DeltaParams) -> np.ndarray:
    """The design's reference platform position [m], where its reference configuration is assembled.

    ``params.home`` when given; otherwise the position ``(0, 0, z)`` of largest inverse condition
    number of ``J`` (eq. 12, knee out) among ``z = -(La + Lb) k / 64``, ``k = 1..64``.

    Raises:
        InvalidParameterError: (``home``) the given pose is unreachable (which leg, by how much), or no
            candidate assembles away from singularity (inverse condition number >= 1e-3).
    """
    params = check_params(params, DeltaParams)
    return np.array(_reference(params))


@functools.lru_cache(maxsize=256)
def _reference(params: DeltaParams) -> tuple[float, float, float]:
    if params.home is not None:
        try:
            inverse_kinematics(params, params.home)
        except UnreachableError as exc:
            raise InvalidParameterError(
                "home", f"reference pose {params.home} is unreachable with this design (leg {exc.leg} misses by "
                        f"{exc.excess:.4g} m); choose another home or other lengths", params.home) from None
        return params.home

    def score(p: tuple[float, float, float]) -> float:
        return float(inverse_condition(jacobian(params, inverse_kinematics(params, p), p)))

    reach = params.La + params.Lb
    depths = (-reach * k / REFERENCE_DEPTHS for k in range(1, REFERENCE_DEPTHS + 1))
    return best_reference("home", ((0.0, 0.0, z) for z in depths), score, minimum=1e-3)


# ---------------------------------------------------------------------- uniform interface
# Every mechanism module offers these three, over the task vector ``y`` laid out as
# :class:`pkm.core.TaskMap` does (here: platform centre x, y, z).
def closed_form_ik(params: DeltaParams, y, branch: str | None = None) -> np.ndarray:
    """Actuated coordinates for task vector ``y`` (closed form)."""
    return inverse_kinematics(params, y, branch or "knee_out")


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form)."""
    return configuration(mech, y, branch or "knee_out")


def closed_form_fk(params: DeltaParams, q_actuated, seed=None) -> np.ndarray:
    """Task vector from actuated coordinates (sphere intersection; ``seed`` unused)."""
    return forward_kinematics(params, q_actuated)


