"""The five-bar's closed forms: each leg a circle intersection."""

from __future__ import annotations

import math

import numpy as np

from pkm.core.model.mechanism import check_mechanism
from pkm.errors import AssemblyError, InvalidInputError, UnreachableError
from pkm.mechanisms._common import best_reference, check_params
from pkm.validation import as_vector, wrap_angle
from tests.fivebar.params import BRANCHES, FiveBarParams


def _bases(p: FiveBarParams) -> np.ndarray:
    return np.array([[-p.d / 2.0, 0.0], [p.d / 2.0, 0.0]])


def reference_pose(p: FiveBarParams) -> np.ndarray:
    """``p.home``, or the tip on the axis ``x = 0`` whose elbows are farthest from folded or stretched."""
    p = check_params(p, FiveBarParams)
    if p.home is not None:
        inverse_kinematics(p, p.home)
        return np.array(p.home)

    def score(y) -> float:
        q = inverse_kinematics(p, y)
        return min(abs(math.sin(q[f"elbow_{n}"][0])) for n in (1, 2))

    return np.array(best_reference("home", ((0.0, (p.l1 + p.l2) * k / 32) for k in range(1, 33)), score,
                                   minimum=1e-3))


def inverse_kinematics(p: FiveBarParams, y, branch: str | None = None) -> dict[str, list[float]]:
    """Joint values for tip ``y = (x, y)`` in working mode ``branch``."""
    p = check_params(p, FiveBarParams)
    y = as_vector(y, 2, "y")
    if branch is not None and (not isinstance(branch, str) or branch not in BRANCHES):
        raise InvalidInputError("branch", f"use one of {list(BRANCHES)}, got {branch!r}", branch)
    signs = BRANCHES[branch or "elbows_out"]
    out: dict[str, list[float]] = {}
    for i, (a, s) in enumerate(zip(_bases(p), signs)):
        v = y - a
        rho = math.hypot(*v)
        c = (p.l1 * p.l1 + rho * rho - p.l2 * p.l2) / (2.0 * p.l1 * rho) if rho > 0 else math.inf
        if not abs(c) <= 1.0:  # out of reach (or beyond the float range: c is NaN)
            raise UnreachableError(i + 1, rho - (p.l1 + p.l2) if c < -1 or rho > p.l1 else abs(p.l1 - p.l2) - rho, "m",
                                   f"tip {tuple(y)} is out of reach of leg {i + 1}")
        theta = math.atan2(v[1], v[0]) + s * math.acos(c)
        b = a + p.l1 * np.array([math.cos(theta), math.sin(theta)])
        w = y - b
        out[f"motor_{i + 1}"] = [float(wrap_angle(theta))]
        out[f"elbow_{i + 1}"] = [float(wrap_angle(math.atan2(w[1], w[0]) - theta))]
    return out


def closed_form_ik(p: FiveBarParams, y, branch: str | None = None) -> np.ndarray:
    q = inverse_kinematics(p, y, branch)
    return np.array([q["motor_1"][0], q["motor_2"][0]])


def closed_form_configuration(mech, y, branch: str | None = None) -> np.ndarray:
    mech = check_mechanism(mech)
    return mech.q_from_dict(inverse_kinematics(mech.params, y, branch))


def closed_form_fk(p: FiveBarParams, q_actuated, seed=None) -> np.ndarray:
    """The tip for motor angles ``q_actuated``: the intersection of two circles of radius ``l2`` about the elbows;
    of the two, the one nearer ``seed`` (default: the upper one)."""
    p = check_params(p, FiveBarParams)
    th = as_vector(q_actuated, 2, "q_actuated")
    b = _bases(p) + p.l1 * np.column_stack([np.cos(th), np.sin(th)])
    m, e = (b[0] + b[1]) / 2.0, b[1] - b[0]
    half = np.linalg.norm(e) / 2.0
    if half > p.l2 or half == 0.0:
        raise AssemblyError(f"the elbows are {2 * half:.4g} m apart: the distal links (2 x {p.l2} m) cannot meet")
    n = np.array([-e[1], e[0]]) / (2.0 * half)
    h = math.sqrt(p.l2**2 - half**2)
    tips = [m + h * n, m - h * n]
    if seed is None:
        return max(tips, key=lambda t: t[1])
    seed = as_vector(seed, 2, "seed")
    return min(tips, key=lambda t: float(np.linalg.norm(t - seed)))
