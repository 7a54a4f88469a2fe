"""SE(3) and spatial algebra on CasADi SX: placements, motions and forces in Pinocchio's conventions
(``[v; w]``, ``[f; n]``), the logarithms of SO(3) and SE(3).

Arguments and results are :data:`Expr`: a CasADi ``SX`` expression or a ``DM`` constant, which every formula here
takes alike."""

from __future__ import annotations

from typing import Any, TypeAlias

import casadi as cs
import numpy as np
import pinocchio as pin

#: A CasADi ``SX`` expression or ``DM`` constant (CasADi's stubs type the two apart, and their overloads give a
#: ``DM`` from ``DM`` inputs; the formulas here take either, so the alias is ``Any``).
Expr: TypeAlias = Any


def cross(a: Expr, b: Expr) -> Expr:
    return cs.vertcat(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def skew(a: Expr) -> Expr:
    return cs.vertcat(cs.horzcat(0, -a[2], a[1]), cs.horzcat(a[2], 0, -a[0]), cs.horzcat(-a[1], a[0], 0))


def rodrigues(axis: np.ndarray, c: Expr, s: Expr) -> Expr:
    """The rotation about the unit ``axis`` by the angle whose cosine and sine are ``c, s``."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return cs.DM(np.eye(3)) + s * cs.DM(K) + (1 - c) * cs.DM(K @ K)


def quat_matrix(x: Expr, y: Expr, z: Expr, w: Expr) -> Expr:
    """The rotation of the unit quaternion ``(x, y, z, w)`` (Pinocchio's order in ``q``)."""
    return cs.vertcat(
        cs.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        cs.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        cs.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


class SE3:
    """A placement ``(R, p)`` of SX (or DM) entries."""

    def __init__(self, R: Expr, p: Expr) -> None:
        self.R, self.p = R, p

    @classmethod
    def of(cls, M: pin.SE3) -> SE3:
        return cls(cs.DM(M.rotation), cs.DM(M.translation))

    def __mul__(self, other: SE3) -> SE3:
        return SE3(self.R @ other.R, self.p + self.R @ other.p)

    def inverse(self) -> SE3:
        return SE3(self.R.T, -self.R.T @ self.p)

    def act_motion(self, m: Expr) -> Expr:
        """``Ad(M) m`` for a motion ``[v; w]`` (from the frame of M's child to its parent)."""
        w = self.R @ m[3:]
        return cs.vertcat(self.R @ m[:3] + cross(self.p, w), w)

    def inv_act_motion(self, m: Expr) -> Expr:
        """``Ad(M^-1) m``."""
        v = m[:3] - cross(self.p, m[3:])
        return cs.vertcat(self.R.T @ v, self.R.T @ m[3:])

    def act_force(self, f: Expr) -> Expr:
        """``Ad(M)^-T f`` for a force ``[f; n]`` (from the child's frame to the parent's)."""
        lin = self.R @ f[:3]
        return cs.vertcat(lin, self.R @ f[3:] + cross(self.p, lin))

    def action(self) -> Expr:
        """The 6x6 action matrix of motions."""
        return cs.vertcat(cs.horzcat(self.R, skew(self.p) @ self.R), cs.horzcat(cs.DM.zeros(3, 3), self.R))


def motion_cross(m: Expr, n: Expr) -> Expr:
    """``m x n`` for two motions."""
    return cs.vertcat(cross(m[3:], n[:3]) + cross(m[:3], n[3:]), cross(m[3:], n[3:]))


def force_cross(m: Expr, f: Expr) -> Expr:
    """``m x* f``: a motion acting on a force."""
    return cs.vertcat(cross(m[3:], f[:3]), cross(m[3:], f[3:]) + cross(m[:3], f[:3]))


def log3(R: Expr) -> Expr:
    """The rotation vector of ``R`` (angle in [0, pi)); smooth through the identity (series)."""
    c = cs.fmin(cs.fmax((cs.trace(R) - 1) / 2, -1.0), 1.0)
    theta = cs.acos(c)
    w = cs.vertcat(R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1])
    s = cs.sin(theta)
    small = theta < 1e-4
    factor = cs.if_else(small, 0.5 + theta * theta / 12.0, theta / (2 * cs.if_else(small, 1.0, s)))
    return factor * w


def log6(M: SE3) -> Expr:
    """Pinocchio's ``log6``: the twist ``[v; w]`` whose exponential is ``M``."""
    w = log3(M.R)
    theta2 = cs.dot(w, w)
    theta = cs.sqrt(theta2 + 1e-300)
    small = theta2 < 1e-8
    # V^-1 = I - W/2 + (1/theta^2)(1 - theta sin / (2 (1 - cos))) W^2
    coeff = cs.if_else(small, 1.0 / 12.0 + theta2 / 720.0,
                       (1 - theta * cs.sin(theta) / (2 * (1 - cs.cos(theta)) + cs.if_else(small, 1.0, 0.0)))
                       / cs.if_else(small, 1.0, theta2))
    W = skew(w)
    Vinv = cs.DM(np.eye(3)) - 0.5 * W + coeff * (W @ W)
    return cs.vertcat(Vinv @ M.p, w)


def zyx_angles(R: Expr) -> Expr:
    """``(roll, pitch, yaw)`` with ``R = Rz(yaw) Ry(pitch) Rx(roll)`` (as :func:`pkm.core.kinematics.task.zyx_angles`)."""
    return cs.vertcat(cs.atan2(R[2, 1], R[2, 2]), cs.atan2(-R[2, 0], cs.sqrt(R[0, 0] ** 2 + R[1, 0] ** 2)),
                      cs.atan2(R[1, 0], R[0, 0]))


def euler_rates(R: Expr) -> Expr:
    """``B^-1`` (3 x 3): world angular velocity to Z-Y-X Euler-angle rates (singular at pitch = +-90 deg)."""
    _, pitch, yaw = (zyx_angles(R)[i] for i in range(3))
    cp, sp, cy, sy = cs.cos(pitch), cs.sin(pitch), cs.cos(yaw), cs.sin(yaw)
    return cs.vertcat(cs.horzcat(cy / cp, sy / cp, 0), cs.horzcat(-sy, cy, 0), cs.horzcat(sp * cy / cp, sp * sy / cp, 1))
