"""One joint of a Pinocchio tree as SX: its placement, motion ``M(q)``, subspace ``S`` and bias."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pinocchio as pin

from pkm.core.twin.spatial import SE3, Expr, cross, quat_matrix, rodrigues
from pkm.errors import SpecError

_ONE_DOF = {"RX", "RY", "RZ", "RevoluteUnaligned", "PX", "PY", "PZ", "PrismaticUnaligned"}


class Joint:
    """One joint of the tree: its placement in its parent, motion ``M(q)``, constant subspace ``S`` (6 x k) and the
    velocity coordinates it takes (``cols``, with their ``scale``: a mimic joint takes its leader's)."""

    def __init__(self, model: pin.Model, jid: int, source: str):
        jm = model.joints[jid]
        self.placement = SE3.of(model.jointPlacements[jid])
        self.parent = int(model.parents[jid])
        self.kind = jm.shortname().removeprefix("JointModel")
        self.idx_q, self.idx_v = jm.idx_q, jm.idx_v
        self.scale, self.offset = 1.0, 0.0
        if self.kind == "Mimic":
            mimic = jm.extract()
            self.scale, self.offset = float(mimic.scaling), float(mimic.offset)
            if self.scale == 0.0:
                raise SpecError(source, f"joint {model.names[jid]!r}: a mimic joint with multiplier 0 is a fixed joint")
            jd = jm.createData()
            jm.calc(jd, pin.neutral(model))
            self.S = np.asarray(jd.S, dtype=float).reshape(6, -1)  # (Pinocchio's: the multiplier included)
            self.cols = [jm.idx_v]
            self.kind = "mimic"
        elif self.kind in _ONE_DOF or self.kind in ("RUBX", "RUBY", "RUBZ", "Spherical", "FreeFlyer", "Planar",
                                                    "Universal"):
            jd = jm.createData()
            jm.calc(jd, pin.neutral(model))
            self.S = np.asarray(jd.S, dtype=float).reshape(6, -1)
            self.cols = list(range(jm.idx_v, jm.idx_v + jm.nv))
            if self.kind == "Universal":
                u = jm.extract()
                self.axes = (np.asarray(u.axis1, dtype=float), np.asarray(u.axis2, dtype=float))
        else:
            raise SpecError(source, f"joint {model.names[jid]!r}: the symbolic twin does not handle a Pinocchio "
                                    f"{jm.shortname()}")

    def motion(self, q: Expr) -> SE3:
        """``M(q)``: the joint's transform (after its placement)."""
        k = self.kind
        if k in _ONE_DOF or k == "mimic":
            theta = q[self.idx_q] * self.scale + self.offset
            S = self.S[:, 0] / self.scale  # the joint's own subspace
            if np.abs(S[3:]).max() > 0:
                return SE3(rodrigues(S[3:] / np.linalg.norm(S[3:]), cs.cos(theta), cs.sin(theta)), cs.DM.zeros(3))
            return SE3(cs.DM(np.eye(3)), cs.DM(S[:3]) * theta)
        if k in ("RUBX", "RUBY", "RUBZ"):
            axis = np.eye(3)["XYZ".index(k[-1])]
            return SE3(rodrigues(axis, q[self.idx_q], q[self.idx_q + 1]), cs.DM.zeros(3))
        if k == "Spherical":
            i = self.idx_q
            return SE3(quat_matrix(q[i], q[i + 1], q[i + 2], q[i + 3]), cs.DM.zeros(3))
        if k == "FreeFlyer":
            i = self.idx_q
            return SE3(quat_matrix(q[i + 3], q[i + 4], q[i + 5], q[i + 6]), cs.vertcat(q[i], q[i + 1], q[i + 2]))
        if k == "Planar":
            i = self.idx_q
            return SE3(rodrigues(np.array([0.0, 0.0, 1.0]), q[i + 2], q[i + 3]), cs.vertcat(q[i], q[i + 1], 0))
        # universal: about axis1, then about axis2 of the moved frame
        i = self.idx_q
        R1 = rodrigues(self.axes[0], cs.cos(q[i]), cs.sin(q[i]))
        R2 = rodrigues(self.axes[1], cs.cos(q[i + 1]), cs.sin(q[i + 1]))
        return SE3(R1 @ R2, cs.DM.zeros(3))

    def subspace(self, q: Expr) -> Expr:
        """``S`` (6 x k) in the joint's frame; constant except a universal joint's first column."""
        if self.kind != "Universal":
            return cs.DM(self.S)
        i = self.idx_q
        R2 = rodrigues(self.axes[1], cs.cos(q[i + 1]), cs.sin(q[i + 1]))
        return cs.horzcat(cs.vertcat(cs.DM.zeros(3), R2.T @ cs.DM(self.axes[0])),
                          cs.vertcat(cs.DM.zeros(3), cs.DM(self.axes[1])))

    def velocity(self, q: Expr, v: Expr) -> Expr:
        """The joint's twist in its frame, ``S v_j``."""
        return self.subspace(q) @ cs.vertcat(*[v[c] for c in self.cols])

    def bias(self, q: Expr, v: Expr) -> Expr:
        """``dS/dt v_j`` (only the universal joint's first axis turns with the second coordinate)."""
        if self.kind != "Universal":
            return cs.DM.zeros(6)
        i, iv = self.idx_q, self.idx_v
        q2, q1d, q2d = q[i + 1], v[iv], v[iv + 1]
        R2 = rodrigues(self.axes[1], cs.cos(q2), cs.sin(q2))
        w1 = R2.T @ cs.DM(self.axes[0])
        return cs.vertcat(cs.DM.zeros(3), -cross(cs.DM(self.axes[1]) * q2d, w1) * q1d)

    def tangent(self, q: Expr) -> Expr | None:
        """``d(q + T dq)/d(dq)``: the joint's own coordinates' derivative along its velocity coordinates, the block
        ``(nq_j x nv_j)`` of Pinocchio's ``integrate(q, dq)`` at ``dq = 0`` (None for a mimic joint: no coordinates
        of its own)."""
        k, i = self.kind, self.idx_q
        if k == "mimic":
            return None
        if k in ("RUBX", "RUBY", "RUBZ"):
            return cs.vertcat(-q[i + 1], q[i])
        if k == "Spherical":
            return _quat_tangent(q[i:i + 4])
        if k == "FreeFlyer":
            R = quat_matrix(q[i + 3], q[i + 4], q[i + 5], q[i + 6])
            return cs.vertcat(cs.horzcat(R, cs.DM.zeros(3, 3)), cs.horzcat(cs.DM.zeros(4, 3), _quat_tangent(q[i + 3:i + 7])))
        if k == "Planar":
            c, s = q[i + 2], q[i + 3]
            return cs.vertcat(cs.horzcat(c, -s, 0), cs.horzcat(s, c, 0), cs.horzcat(0, 0, -s), cs.horzcat(0, 0, c))
        return cs.DM.eye(len(self.cols))  # one-coordinate joints, universal

    def retract(self, q: Expr, dq: Expr) -> list[tuple[int, Expr]]:
        """The joint's coordinates moved by its velocity coordinates ``dq`` (``(index, value)`` pairs): ``q + T dq``,
        unit blocks (quaternions, ``cos, sin`` pairs) renormalised. A retraction: it agrees with Pinocchio's
        ``integrate`` to first order, which keeps Newton's quadratic convergence."""
        T = self.tangent(q)
        if T is None:
            return []
        nq = T.shape[0]
        new = q[self.idx_q:self.idx_q + nq] + T @ cs.vertcat(*[dq[c] for c in self.cols])
        unit = {"RUBX": (0, 2), "RUBY": (0, 2), "RUBZ": (0, 2), "Spherical": (0, 4), "FreeFlyer": (3, 7),
                "Planar": (2, 4)}.get(self.kind)
        if unit is not None:
            a, b = unit
            block = new[a:b] / cs.norm_2(new[a:b])
            new = cs.vertcat(new[:a], block, new[b:])
        return [(self.idx_q + r, new[r]) for r in range(nq)]


def _quat_tangent(quat: Expr) -> Expr:
    """``d(quat * (dw/2, 1))/d(dw)`` for a unit quaternion ``(x, y, z, w)``: right multiplication by the rotation
    ``exp(dw)`` to first order (4 x 3)."""
    x, y, z, w = quat[0], quat[1], quat[2], quat[3]
    return 0.5 * cs.vertcat(cs.horzcat(w, -z, y), cs.horzcat(z, w, -x), cs.horzcat(-y, x, w), cs.horzcat(-x, -y, -z))
