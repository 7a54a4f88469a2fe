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

from pkm.core.mechanism import Mechanism, check_mechanism
from pkm.core.task import zyx_matrix
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms._common import check_params
from pkm.mechanisms.gough_stewart.params import GoughStewartParams
from pkm.validation import as_vector

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
    rho = np.linalg.norm(leg_vectors(params, *pose(y)), axis=1)
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
    """The reference task vector: ``params.reference``, or the level platform above the base centre with the mean
    leg mid-stroke (``InvalidParameterError`` when no such height exists or a leg leaves its stroke)."""
    from pkm.errors import InvalidParameterError

    params = check_params(params, GoughStewartParams)
    if params.reference is not None:
        x, y, z, roll, pitch, yaw = params.reference
        y_ref = task_vector(zyx_matrix(roll, pitch, yaw), np.array([x, y, z]))
    else:
        dz = params.platform_points[:, 2] - params.base_points[:, 2]
        horiz = params.platform_points[:, :2] - params.base_points[:, :2]
        mid = 0.5 * (params.leg_min + params.leg_max)
        h2 = mid ** 2 - float(np.mean(np.sum(horiz ** 2, axis=1)))
        if h2 <= 0.0:
            raise InvalidParameterError("leg_max", "the legs are too short to hold the platform level above the base "
                                                   "centre: give a longer stroke or a reference", params.leg_max)
        y_ref = task_vector(np.eye(3), np.array([0.0, 0.0, float(np.sqrt(h2) - np.mean(dz))]))
    try:
        inverse_kinematics(params, y_ref)
    except UnreachableError as exc:
        raise InvalidParameterError("reference", f"the reference pose is unreachable: {exc}", params.reference) \
            from None
    return y_ref
