"""The hexapod's geometry in closed form, below its kinematics and its screws (both import it): the base, elbow and
platform points, the paper's actuated angles, the inverse position kinematics of each leg (paper eqs. 1-7)."""

from __future__ import annotations

import math

import numpy as np

from pkm.core.kinematics.task import as_rotation
from pkm.mechanisms._common import check_params, leg_arm_angles, leg_branches
from pkm.mechanisms.hexapod.params import BRANCHES, DEFAULT_BRANCH, LAYOUTS, HexapodParams, leg_frame
from pkm.validation import as_vector, wrap_angle

_E_Y = np.array([0.0, 1.0, 0.0])


def base_points(params: HexapodParams, beta: float) -> np.ndarray:
    """Actuated joint centres ``A_1..A_6`` for reconfiguration angle ``beta`` [rad] (eqs. 1-2), rows [m]."""
    params = check_params(params, HexapodParams)
    out = np.empty((6, 3))
    for i, th in enumerate(params.theta):
        e_r = leg_frame(th)[:, 0]
        if i < 3:
            out[i] = params.Rf * e_r + params.Rr * (math.cos(beta) * e_r + math.sin(beta) * _E_Y)
        else:
            out[i] = params.R2 * e_r - params.H0 * _E_Y
    return out


def platform_local_points(params: HexapodParams) -> np.ndarray:
    """Spherical joint centres ``C*_1..C*_6`` in the platform frame, rows [m]."""
    params = check_params(params, HexapodParams)
    low = np.array([[params.r * math.cos(math.radians(p)), 0.0, params.r * math.sin(math.radians(p))]
                    for p in LAYOUTS[params.layout]])
    return np.vstack([low + params.h * _E_Y, low])


def platform_points(params: HexapodParams, R: np.ndarray, P) -> np.ndarray:
    """``C_1..C_6`` in the base frame for platform orientation ``R`` and position ``P`` (eq. 14), rows [m]."""
    params = check_params(params, HexapodParams)
    return np.asarray(P, dtype=float) + platform_local_points(params) @ np.asarray(R, dtype=float).T


def elbow_points(params: HexapodParams, alphas, beta: float) -> np.ndarray:
    """Universal-joint centres ``B_1..B_6`` from the paper's absolute ``alpha_i`` and ``beta`` [rad] (eq. 3), rows [m]."""
    params = check_params(params, HexapodParams)
    alphas = as_vector(alphas, 6, "alphas")
    A = base_points(params, beta)
    return np.array([A[i] + params.LA * (leg_frame(params.theta[i]) @ [math.cos(alphas[i]), math.sin(alphas[i]), 0.0])
                     for i in range(6)])


def paper_alphas(q_actuated) -> np.ndarray:
    """The paper's absolute ``alpha_1..alpha_6`` [rad] from the actuated vector (spec order).

    Legs 1-3: ``alpha(paper) = alpha(joint) + beta``; legs 4-6 unchanged.
    """
    qa = as_vector(q_actuated, 7, "q_actuated")
    return np.concatenate([qa[:3] + qa[6], qa[3:6]])


def actuated_from_paper(alphas, beta: float) -> np.ndarray:
    """The actuated vector (``alpha_1..alpha_6`` joint coordinates, ``beta_1``) from the paper's angles."""
    a = as_vector(alphas, 6, "alphas")
    b = _scalar(beta, "beta")
    return np.concatenate([wrap_angle(a[:3] - b), wrap_angle(a[3:]), [b]])


# ---------------------------------------------------------------------- closed forms
def inverse_kinematics(params: HexapodParams, R, P, beta: float,
                       branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> np.ndarray:
    """The paper's absolute ``alpha_1..alpha_6`` [rad] for a platform pose and ``beta`` [rad].

    Per leg, with ``d = C_i - A_i`` in the leg frame, ``|C_i - B_i| = LB`` reads
    ``cos(alpha) d_r + sin(alpha) d_y = K``, ``K = (d.d + LA^2 - LB^2) / (2 LA)``, so
    ``alpha = phi +- delta`` with ``phi = atan2(d_y, d_r)``, ``delta = acos(K / hypot(d_r, d_y))``
    (``+`` for ``elbow_out``, ``-`` for ``elbow_in``).

    Args:
        params: The design.
        R: Platform orientation (3x3 rotation).
        P: Platform position [m], shape (3,).
        beta: Reconfiguration angle [rad].
        branch: ``"elbow_out"``/``"elbow_in"`` for all legs, or one per leg.

    Raises:
        InvalidInputError: ``R`` is not a rotation (see :func:`as_rotation`).
        UnreachableError: with the first leg that cannot reach and by how much [m].
    """
    params = check_params(params, HexapodParams)
    branches = branch_names(branch)
    C = platform_points(params, as_rotation(R), as_vector(P, 3, "P"))
    A = base_points(params, _scalar(beta, "beta"))
    frames = np.stack([leg_frame(t) for t in params.theta])  # (6, 3, 3): columns e_r, e_y, u of each leg
    dr, dy, du = np.einsum("nij,ni->jn", frames, C - A)  # C_i - A_i in leg i's frame
    return leg_arm_angles(dr, dy, du, params.LA, params.LB, [-BRANCHES[b] for b in branches],
                      lambda leg: f"leg {leg}: the rod LB cannot span the distance from C_{leg} to the circle of B")


# ---------------------------------------------------------------------- helpers
def branch_names(branch: str | tuple[str, ...]) -> tuple[str, ...]:
    """The working mode of each of the six legs (one name for all, or six)."""
    return leg_branches(branch, BRANCHES, 6)


def _scalar(x, name: str) -> float:
    return float(as_vector([x], 1, name)[0])


