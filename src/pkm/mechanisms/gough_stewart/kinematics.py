"""Gough-Stewart kinematics: the inverse in closed form (leg lengths), the forward through every assembly mode.

Leg ``i`` joins the base point ``a_i`` (a universal joint) to the platform point ``p + R b_i`` (a spherical joint);
its actuated coordinate is its length ``rho_i = |p + R b_i - a_i|``. The forward kinematics has 40 complex
solutions for generic data (Raghavan 1993; Husty 1996), up to 40 real (Dietmaier 1998), and no closed form:
:func:`pkm.assembly_modes` computes them all (a parameter homotopy from the six-sphere family's 40 generic
solutions); the generic core's :func:`pkm.close_loops` follows one of them.

Task: the platform pose (``components = ["pose"]``): ``(x, y, z, qx, qy, qz, qw)``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pkm.core.kinematics.task import zyx_matrix
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms._common import check_params
from pkm.mechanisms.gough_stewart.params import GoughStewartParams
from pkm.validation import as_vector, finite_result

#: ``closed_form_fk``: none (the forward kinematics is :func:`pkm.assembly_modes`).
closed_form_fk = None


def pose(y) -> tuple[np.ndarray, np.ndarray]:
    """``(R, p)`` of a task vector ``(x, y, z, qx, qy, qz, qw)``."""
    y = as_vector(y, 7, "y")
    q = y[3:]
    n = float(np.linalg.norm(q))
    if not abs(n - 1.0) < 1e-6:
        raise InvalidInputError("y", f"the quaternion (qx, qy, qz, qw) must have norm 1, got {n:.9g}", y)
    return pin.Quaternion(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix(), y[:3].copy()


def task_vector(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    return np.concatenate([p, pin.Quaternion(np.asarray(R, dtype=float)).coeffs()])


def leg_vectors(params: GoughStewartParams, R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``p + R b_i - a_i`` (6 x 3) [m], base axes."""
    return p + params.platform_points @ np.asarray(R).T - params.base_points


def inverse_kinematics(params: GoughStewartParams, y, *, check_limits: bool = True) -> np.ndarray:
    """The six leg lengths [m] of a pose; :class:`UnreachableError` (the leg, by how much) when one is outside
    ``[leg_min, leg_max]`` and ``check_limits``."""
    params = check_params(params, GoughStewartParams)
    with np.errstate(over="ignore", invalid="ignore"):  # (a pose near 1e308 m: refused below, not warned about)
        rho = finite_result(np.linalg.norm(leg_vectors(params, *pose(y)), axis=1), "leg lengths")
    if check_limits:
        for i, r in enumerate(rho):
            excess = max(params.leg_min - r, r - params.leg_max)
            if excess > 0.0:
                raise UnreachableError(i + 1, excess, "m", f"leg length {r:.6g} m outside "
                                                                f"[{params.leg_min:g}, {params.leg_max:g}] m")
    return rho


def joint_values(params: GoughStewartParams, y) -> dict[str, list[float]]:
    """Every joint's coordinates for a pose: the free-flyer, the universal joints (about the base frame's x, then
    the turned y) and the leg lengths."""
    R, p = pose(y)
    d = leg_vectors(params, R, p)
    rho = np.linalg.norm(d, axis=1)
    u = d / rho[:, None]
    out: dict[str, list[float]] = {"platform": [*p, *pin.Quaternion(R).coeffs()]}
    for i in range(6):
        # Rx(t1) Ry(t2) e_z = (sin t2, -sin t1 cos t2, cos t1 cos t2)
        out[f"u{i + 1}"] = [float(np.arctan2(-u[i, 1], u[i, 2])), float(np.arcsin(np.clip(u[i, 0], -1.0, 1.0)))]
        out[f"leg{i + 1}"] = [float(rho[i])]
    return out


def closed_form_ik(params: GoughStewartParams, y, branch: str | None = None) -> np.ndarray:
    """The actuated coordinates (leg lengths, m) of task vector ``y`` (one working mode: ``branch`` is ignored)."""
    return inverse_kinematics(params, y, check_limits=False)


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form; the working mode ``extended``)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(check_params(mech.params, GoughStewartParams, "mech.params"), y))


def reference_pose(params: GoughStewartParams) -> np.ndarray:
    """The reference task vector: ``params.reference``, or else a pose that puts every leg inside its stroke.

    Without a stated reference the level platform above the base centre with the mean leg mid-stroke is taken
    when every leg is inside ``[leg_min, leg_max]`` there (the textbook designs, the default one among them);
    otherwise (a geometry of general shape: points off the base and platform planes, legs leaning far) one of
    twelve orientations (the level platform turned in yaw by multiples of 60 degrees, upright and turned over),
    each at the position that brings the legs nearest mid-stroke in the least-squares sense: the one with the
    smallest excess of the legs over the stroke, then the farthest from a singularity (the largest smallest
    singular value of the legs' Plücker lines). The orientation is held while the position is fitted because a
    least-squares fit over the whole pose whose residual stays nonzero ends where the six legs' Jacobian is
    singular (its gradient ``J^T r`` vanishes): a direct singularity, a double assembly mode. When the excess is
    not zero, the whole pose is moved from the best candidate until it is (a least-squares fit of the excess, which
    ends where it reaches zero, generically away from singularities), and when that fails too, the best candidate is the reference all the same and
    ``mech.outside_limits(mech.q_reference)`` names the legs outside (pkm's solvers report limits, they do not
    enforce them); reachability is the solvers' business (:func:`pkm.assembly_modes` finds every assembly mode).

    Raises:
        InvalidParameterError: a stated reference puts a leg outside the stroke.
    """
    from scipy.optimize import least_squares

    from pkm.errors import InvalidParameterError

    params = check_params(params, GoughStewartParams)
    if params.reference is not None:
        x, y, z, roll, pitch, yaw = params.reference
        y_ref = task_vector(zyx_matrix(roll, pitch, yaw), np.array([x, y, z]))
        try:
            inverse_kinematics(params, y_ref)
        except UnreachableError as exc:
            raise InvalidParameterError("reference", f"the reference pose is unreachable: {exc}", params.reference) \
                from None
        return y_ref
    mid = 0.5 * (params.leg_min + params.leg_max)
    dz = params.platform_points[:, 2] - params.base_points[:, 2]
    horiz = params.platform_points[:, :2] - params.base_points[:, :2]
    h2 = mid ** 2 - float(np.mean(np.sum(horiz ** 2, axis=1)))
    z0 = float(np.sqrt(max(h2, 0.0)) - np.mean(dz))
    level = task_vector(np.eye(3), np.array([0.0, 0.0, z0]))
    if h2 > 0.0 and _inside_stroke(params, level):
        return level

    best: tuple[float, float, np.ndarray] | None = None  # (stroke violation, -smallest singular value, y)
    for flip in (0.0, np.pi):
        for yaw in np.linspace(0.0, 2.0 * np.pi, 6, endpoint=False):
            R = pin.rpy.rpyToMatrix(flip, 0.0, yaw)
            b = params.platform_points @ R.T - params.base_points

            def legs(p: np.ndarray, b: np.ndarray = b) -> np.ndarray:
                return np.linalg.norm(b + p, axis=1) - mid

            p = least_squares(legs, [0.0, 0.0, -z0 if flip else z0], method="lm", xtol=1e-12, ftol=1e-12).x
            y_try = task_vector(R, p)
            rho = inverse_kinematics(params, y_try, check_limits=False)
            violation = float(np.sum(np.maximum(rho - params.leg_max, 0.0) + np.maximum(params.leg_min - rho, 0.0)))
            u = (b + p) / rho[:, None]
            sigma = float(np.linalg.svd(np.hstack([u, np.cross(params.platform_points @ R.T, u)]),
                                        compute_uv=False)[-1])
            if best is None or (violation, -sigma) < best[:2]:
                best = (violation, -sigma, y_try)
    assert best is not None
    if best[0] == 0.0:
        return best[2]
    R0, p0 = pose(best[2])

    def excess(x: np.ndarray) -> np.ndarray:  # each leg's length outside the stroke [m]; x = (p, rotation vector)
        rho = np.linalg.norm(leg_vectors(params, R0 @ pin.exp3(x[3:]), x[:3]), axis=1)
        return np.maximum(rho - params.leg_max, 0.0) + np.minimum(rho - params.leg_min, 0.0)

    x = least_squares(excess, np.r_[p0, 0.0, 0.0, 0.0], method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
                      max_nfev=200).x
    y_fit = task_vector(R0 @ pin.exp3(x[3:]), x[:3])
    return y_fit if _inside_stroke(params, y_fit) else best[2]


def _inside_stroke(params: GoughStewartParams, y: np.ndarray) -> bool:
    rho = inverse_kinematics(params, y, check_limits=False)
    return bool(np.all((rho >= params.leg_min) & (rho <= params.leg_max)))
