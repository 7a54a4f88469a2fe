"""Closed-form kinematics of the 3-PRS: inverse and forward position, velocities, the task vector."""

from __future__ import annotations

import functools
import math

import numpy as np
import pinocchio as pin

from pkm.core.differential.indices import inverse_condition
from pkm.core.kinematics.task import zyx_matrix
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidParameterError, UnreachableError
from pkm.mechanisms._common import (
    best_reference,
    check_params,
    leg_branches,
)
from pkm.mechanisms.prs3.params import BRANCHES, DEFAULT_BRANCH, PHI, Prs3Params, as_task
from pkm.validation import finite_result

ROOT_TOL = 1e-12  # radicands of eq. (10) above -ROOT_TOL l^2 count as the double root


# ---------------------------------------------------------------------- closed forms
def leg_geometry(params: Prs3Params) -> tuple[np.ndarray, ...]:
    """Per-leg vectors (rows i = 1..3, world axes): a_i, u_1,i, w_i, e_t,i, and b_i (platform axes)."""
    try:
        return tuple(v.copy() for v in _leg_geometry(params))  # (a design's reference search: 400 IK calls)
    except TypeError:  # (unhashable parameters)
        return _leg_geometry.__wrapped__(params)


@functools.lru_cache(maxsize=256)
def _leg_geometry(params: Prs3Params) -> tuple[np.ndarray, ...]:
    cg, sg = math.cos(params.gamma), math.sin(params.gamma)
    er = np.array([[math.cos(f), math.sin(f), 0.0] for f in PHI])
    ez = np.array([0.0, 0.0, 1.0])
    et = np.cross(ez, er)
    return params.g * er, cg * er + sg * ez, -sg * er + cg * ez, et, params.h * er


def _yaw(pitch: float, roll: float) -> tuple[float, tuple[float, ...]]:
    """``alpha = atan2(s_b s_f, c_f + c_b)`` (eq. 15) and ``(s_a, c_a, s_b, c_b, s_f, c_f)``."""
    sb, cb, sf, cf = math.sin(pitch), math.cos(pitch), math.sin(roll), math.cos(roll)
    alpha = math.atan2(sb * sf, cf + cb)
    return alpha, (math.sin(alpha), math.cos(alpha), sb, cb, sf, cf)


def parasitic_motion(h: float, pitch: float, roll: float) -> tuple[float, float, float]:
    """Dependent coordinates ``(x_p [m], y_p [m], alpha [rad])`` from ``beta``, ``phi`` (derived, eqs. 12-14).

    For the layout of eqs. (6)-(7), ``e_t,i . B_i = 0`` for the three legs gives ``R_01 = R_10``,
    ``x_p = h (R_00 - R_11) / 2`` and ``y_p = -h R_10`` (see the module doc for eq. 15). ``alpha`` is the
    root of ``s_a (c_b + c_f) = c_a s_b s_f`` given by ``atan2`` (0 at ``beta = phi = 0``).

    Args:
        h: Platform radius [m].
        pitch: beta [rad].
        roll: phi [rad].
    """
    alpha, (sa, ca, sb, cb, sf, cf) = _yaw(pitch, roll)
    return 0.5 * h * (ca * cb - sa * sb * sf - ca * cf), -h * sa * cb, alpha


def paper_parasitic_motion(h: float, pitch: float, roll: float) -> tuple[float, float, float]:
    """Eq. (15) as printed: ``(x_p [m], y_p [m], alpha [rad])`` from ``beta``, ``phi``.

    ``x_p = -h s_a c_b``, ``y_p = -h/2 (c_a c_b - s_a s_b s_f - c_a c_f)``,
    ``alpha = atan2(s_b s_f, c_f + c_b)``. It keeps the spherical joints in their leg planes for the
    layout rotated by 90 deg about Z (``phi_i = 90, 210, 330 deg``), not for eqs. (6)-(7), where
    :func:`parasitic_motion` holds; ``alpha`` is right for both.
    """
    alpha, (sa, ca, sb, cb, sf, cf) = _yaw(pitch, roll)
    return -h * sa * cb, -0.5 * h * (ca * cb - sa * sb * sf - ca * cf), alpha


def paper_constraint_jacobians(params: Prs3Params, y) -> tuple[np.ndarray, np.ndarray]:
    """``J_r1``, ``J_r2`` of eq. (25), ``J_r1 v_p = J_r2 omega_p`` (the leg-plane velocity conditions).

    Row ``i`` is eq. (24) for leg ``i``: ``e_t,i . v_p + (r_i x e_t,i) . omega_p = 0``, with ``e_t,i``
    the knee axis (third row of ``^{i,2}R_o``) and ``r_i = R b_i``. The paper solves it as
    ``omega_p = J_r2^-1 J_r1 v_p`` (eq. 26); at ``beta = phi = 0`` every ``r_i x e_t,i`` is ``h e_z``,
    so ``J_r2`` has rank 1 and eq. (26) cannot be evaluated where the sec. 5 trajectories start.
    :class:`pkm.mechanisms.prs3.dynamics.Prs3Dynamics` takes ``(z_p, beta, phi)`` as independent
    instead (its ``jacobian``).
    """
    params = check_params(params, Prs3Params)
    _p, R = platform_pose(params, y)
    _, _, _, et, b = leg_geometry(params)
    r = b @ R.T
    return et.copy(), -np.cross(r, et)


def platform_pose(params: Prs3Params, y) -> tuple[np.ndarray, np.ndarray]:
    """Platform position ``p`` [m] and rotation ``R`` for task vector ``y = (z_p, beta, phi)``."""
    params = check_params(params, Prs3Params)
    z, pitch, roll = as_task(y, "y")
    x, yp, alpha = parasitic_motion(params.h, pitch, roll)
    return np.array([x, yp, z]), zyx_matrix(roll, pitch, alpha)


def leg_vectors(params: Prs3Params, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``c_i = B_i - a_i`` (rows, m) and the radicands ``l^2 - dist(B_i, rail_i)^2`` of eq. (10) [m^2].

    Raises:
        UnreachableError: The first leg with a negative radicand, by ``dist - l`` [m].
    """
    p, R = platform_pose(params, y)
    a, u1, _, _, b = leg_geometry(params)
    c = p + b @ R.T - a
    cu = np.einsum("ij,ij->i", c, u1)
    with np.errstate(over="ignore", invalid="ignore"):  # a pose 1e155 m away: NaN, reported by inverse_kinematics
        rad = cu**2 - np.einsum("ij,ij->i", c, c) + params.l**2
    for i in range(3):
        if rad[i] < -ROOT_TOL * params.l**2:
            dist = math.sqrt(params.l**2 - rad[i])
            raise UnreachableError(i + 1, dist - params.l, "m",
                                   f"leg {i + 1}: the spherical joint is farther than l from the rail")
    return c, np.maximum(rad, 0.0)


def inverse_kinematics(params: Prs3Params, y, branch: str | tuple[str, ...] | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Slider positions ``d_i`` [m] and knee angles ``theta_i`` [rad] for ``y = (z_p, beta, phi)`` (eqs. 8-11).

    ``d_i = c_i.u_1,i -+ sqrt((c_i.u_1,i)^2 - c_i.c_i + l^2)`` (eq. 10 with its missing square), the minus
    sign for ``slider_below``; ``theta_i = atan2((c_i - d_i u_1,i).u_1,i, (c_i - d_i u_1,i).w_i)`` (eq. 8).

    Args:
        params: The design.
        y: ``(z_p [m], beta [rad], phi [rad])``, shape (3,), ``|beta| < pi/2``.
        branch: ``"slider_below"`` (default) / ``"slider_above"`` for all legs, or one per leg.

    Raises:
        UnreachableError: The first leg whose spherical joint is farther than ``l`` from its rail,
            with the excess distance [m].
        InvalidInputError: Bad ``y`` or branch.
    """
    params = check_params(params, Prs3Params)
    signs = np.array([BRANCHES[b] for b in branch_names(branch)], dtype=float)
    y = as_task(y, "y")
    c, rad = leg_vectors(params, y)
    _, u1, w, _, _ = leg_geometry(params)
    cu = np.einsum("ij,ij->i", c, u1)
    d = cu - signs * np.sqrt(rad)
    theta = np.arctan2(cu - d, np.einsum("ij,ij->i", c, w))
    finite_result((d, theta), "slider positions and knee angles", f"y = {y.tolist()} is too far out (overflow)")
    return d, theta


def joint_values(params: Prs3Params, y, branch: str | tuple[str, ...] | None = None) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for ``y = (z_p, beta, phi)``."""
    params = check_params(params, Prs3Params)
    d, theta = inverse_kinematics(params, y, branch)
    p, R = platform_pose(params, y)
    # "+ 0.0" turns the -0.0 of the closed forms into 0.0
    out: dict[str, list[float]] = {"platform": [float(v) + 0.0 for v in (*p, *pin.Quaternion(R).coeffs())]}
    for i in range(3):
        out[f"slider_{i + 1}"] = [float(d[i]) + 0.0]
        out[f"knee_{i + 1}"] = [float(theta[i]) + 0.0]
    return out


def configuration(mech: Mechanism, y, branch: str | tuple[str, ...] | None = None) -> np.ndarray:
    """Full configuration vector ``q`` of ``mech`` for ``y = (z_p, beta, phi)`` (closed form)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(mech.params, y, branch))


# ---------------------------------------------------------------------- uniform interface
def closed_form_ik(params: Prs3Params, y, branch: str | None = None) -> np.ndarray:
    """Actuated coordinates for ``y = (z, pitch, roll)``: ``d_i`` [m] (actuation P) or ``theta_i`` [rad] (R)."""
    params = check_params(params, Prs3Params)
    d, theta = inverse_kinematics(params, y, branch)
    return d if params.actuation == "P" else theta


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form)."""
    return configuration(mech, y, branch)


# ---------------------------------------------------------------------- reference pose
REFERENCE_HEIGHTS = 64  # candidate reference heights z_p of the level platform


def reference_pose(params: Prs3Params) -> np.ndarray:
    """The design's reference independent coordinates ``(z_p, beta, phi)`` [m, rad, rad].

    ``params.reference`` when given; otherwise the level platform at the height of largest inverse
    condition number of ``d q_a / d(z_p, h beta, h phi)`` (the actuated coordinates, knee angles times
    ``l``; central differences) among ``z_p = 2 l k / 64``, ``k = 1..64`` (of equal ones, the nearest
    ``l``).

    Raises:
        InvalidParameterError: (``reference``) the given pose is unreachable (which leg, by how much)
            or puts a coupler perpendicular to its rail, or no candidate scores at least 1e-3.
    """
    params = check_params(params, Prs3Params)
    return np.array(_reference(params))


@functools.lru_cache(maxsize=256)
def _reference(params: Prs3Params) -> tuple[float, float, float]:
    if params.reference is None:
        step = 1e-6 * params.l
        scale = np.array([1.0, params.h, params.h])

        def actuated(y: np.ndarray) -> np.ndarray:
            d, theta = inverse_kinematics(params, y)
            return d if params.actuation == "P" else params.l * theta

        def score(y: tuple[float, float, float]) -> float:
            cols = [(actuated(y + e) - actuated(y - e)) / (2.0 * step) for e in np.diag(step / scale)]
            return float(inverse_condition(np.column_stack(cols)))

        heights = sorted((2.0 * params.l * k / REFERENCE_HEIGHTS for k in range(1, REFERENCE_HEIGHTS + 1)),
                         key=lambda z: abs(z - params.l))
        return best_reference("reference", ((z, 0.0, 0.0) for z in heights), score, minimum=1e-3)
    y = params.reference
    try:
        rad = leg_vectors(params, np.array(y))[1]
    except UnreachableError as exc:
        raise InvalidParameterError(
            "reference", f"reference pose {y} is unreachable with this design (leg {exc.leg} misses by "
                         f"{exc.excess:.4g} m); lengthen l, bring g and h closer, or choose another reference",
            y) from None
    if np.min(rad) <= ROOT_TOL * params.l**2:
        leg = int(np.argmin(rad)) + 1
        raise InvalidParameterError(
            "reference", f"at the reference pose {y} the coupler of leg {leg} is perpendicular to its rail "
                         f"(double root of eq. 10, branches undefined); change l, g, h or the reference", y)
    return y


# ---------------------------------------------------------------------- input checks
def branch_names(branch: str | tuple[str, ...] | None) -> tuple[str, ...]:
    """The working mode of each of the three legs (one name for all, or three; None: the default)."""
    return leg_branches(branch, BRANCHES, 3, DEFAULT_BRANCH)
