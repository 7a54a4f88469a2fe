"""The symbolic twin of a mechanism: its Pinocchio tree as CasADi SX expressions, built from the model itself.

For any :class:`~pkm.core.Mechanism` (loaded from any file pkm reads), :class:`Twin` gives, as functions of
symbols ``q`` (nq), ``v`` (nv) and ``a`` (nv):

* joint and frame placements, world-aligned frame Jacobians (``LOCAL_WORLD_ALIGNED``, as Pinocchio's);
* the closure residual (the conventions of :mod:`pkm.core.constraints`), its Jacobian and drift
  ``gamma = dJ/dt v``;
* RNEA (joint torques for ``q, v, a`` under ``model.gravity``), kinetic and potential energy;
* for mechanisms without idle motions: the passive map ``G``, the joint rates and accelerations from the
  actuated ones, the loop closure's Gauss-Newton step, and the actuator efforts ``G^T rnea`` at a consistent
  state; their CasADi functions map over batches (``Function.map``), differentiate (``casadi.jacobian``) and
  compile to C (:func:`compile_function`).

Everything is derived from the model: each joint's placement, its motion subspace ``S`` (constant in
the joint's frame for every joint kind handled) and the exponential of ``S`` for one-coordinate joints,
the bodies' spatial inertias. Joint kinds: revolute and prismatic about any axis, unbounded revolute
(``cos, sin``), spherical (a unit quaternion), universal, planar, free-flyer, mimic. Not handled (a
:class:`~pkm.errors.SpecError` says so): helical, spherical ZYX, translation and composite joints
(pkm's loaders split composites).

Why not a library: ``adam-robotics`` (CasADi backend) builds from URDF text, with revolute, prismatic
and fixed joints below one floating base; it has no spherical, universal, planar or mimic joint, nor a
free-flyer inside the tree, which pkm's mechanisms need (the Gough-Stewart's platform, the RSSR's ball
joint, the hexapod's mimic joints). Pinocchio's own CasADi bindings are not in the PyPI wheel.

Conventions are Pinocchio's: spatial motions ``[v; w]`` and forces ``[f; n]`` in a body's frame, a
free-flyer's velocity is its body twist, a spherical joint's its body angular velocity.
"""

from __future__ import annotations

import functools

import casadi as cs
import numpy as np
import pinocchio as pin

from pkm.core.mechanism import Mechanism, check_mechanism
from pkm.errors import SpecError

_ONE_DOF = {"RX", "RY", "RZ", "RevoluteUnaligned", "PX", "PY", "PZ", "PrismaticUnaligned"}


# ---------------------------------------------------------------------- SE(3) and spatial algebra in SX
def _cross(a, b):
    return cs.vertcat(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _skew(a):
    return cs.vertcat(cs.horzcat(0, -a[2], a[1]), cs.horzcat(a[2], 0, -a[0]), cs.horzcat(-a[1], a[0], 0))


def _rodrigues(axis: np.ndarray, c, s):
    """The rotation about the unit ``axis`` by the angle whose cosine and sine are ``c, s``."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return cs.DM(np.eye(3)) + s * cs.DM(K) + (1 - c) * cs.DM(K @ K)


def _quat_matrix(x, y, z, w):
    """The rotation of the unit quaternion ``(x, y, z, w)`` (Pinocchio's order in ``q``)."""
    return cs.vertcat(
        cs.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        cs.horzcat(2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        cs.horzcat(2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


class _SE3:
    """A placement ``(R, p)`` of SX (or DM) entries."""

    def __init__(self, R, p):
        self.R, self.p = R, p

    @classmethod
    def of(cls, M: pin.SE3) -> _SE3:
        return cls(cs.DM(M.rotation), cs.DM(M.translation))

    def __mul__(self, other: _SE3) -> _SE3:
        return _SE3(self.R @ other.R, self.p + self.R @ other.p)

    def inverse(self) -> _SE3:
        return _SE3(self.R.T, -self.R.T @ self.p)

    def act_motion(self, m):
        """``Ad(M) m`` for a motion ``[v; w]`` (from the frame of M's child to its parent)."""
        w = self.R @ m[3:]
        return cs.vertcat(self.R @ m[:3] + _cross(self.p, w), w)

    def inv_act_motion(self, m):
        """``Ad(M^-1) m``."""
        v = m[:3] - _cross(self.p, m[3:])
        return cs.vertcat(self.R.T @ v, self.R.T @ m[3:])

    def act_force(self, f):
        """``Ad(M)^-T f`` for a force ``[f; n]`` (from the child's frame to the parent's)."""
        lin = self.R @ f[:3]
        return cs.vertcat(lin, self.R @ f[3:] + _cross(self.p, lin))

    def action(self):
        """The 6x6 action matrix of motions."""
        return cs.vertcat(cs.horzcat(self.R, _skew(self.p) @ self.R), cs.horzcat(cs.DM.zeros(3, 3), self.R))


def _motion_cross(m, n):
    """``m x n`` for two motions."""
    return cs.vertcat(_cross(m[3:], n[:3]) + _cross(m[:3], n[3:]), _cross(m[3:], n[3:]))


def _force_cross(m, f):
    """``m x* f``: a motion acting on a force."""
    return cs.vertcat(_cross(m[3:], f[:3]), _cross(m[3:], f[3:]) + _cross(m[:3], f[:3]))


def _log3(R):
    """The rotation vector of ``R`` (angle in [0, pi)); smooth through the identity (series)."""
    c = cs.fmin(cs.fmax((cs.trace(R) - 1) / 2, -1.0), 1.0)
    theta = cs.acos(c)
    w = cs.vertcat(R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1])
    s = cs.sin(theta)
    small = theta < 1e-4
    factor = cs.if_else(small, 0.5 + theta * theta / 12.0, theta / (2 * cs.if_else(small, 1.0, s)))
    return factor * w


def _log6(M: _SE3):
    """Pinocchio's ``log6``: the twist ``[v; w]`` whose exponential is ``M``."""
    w = _log3(M.R)
    theta2 = cs.dot(w, w)
    theta = cs.sqrt(theta2 + 1e-300)
    small = theta2 < 1e-8
    # V^-1 = I - W/2 + (1/theta^2)(1 - theta sin / (2 (1 - cos))) W^2
    coeff = cs.if_else(small, 1.0 / 12.0 + theta2 / 720.0,
                       (1 - theta * cs.sin(theta) / (2 * (1 - cs.cos(theta)) + cs.if_else(small, 1.0, 0.0)))
                       / cs.if_else(small, 1.0, theta2))
    W = _skew(w)
    Vinv = cs.DM(np.eye(3)) - 0.5 * W + coeff * (W @ W)
    return cs.vertcat(Vinv @ M.p, w)


# ---------------------------------------------------------------------- joints
class _Joint:
    """One joint of the tree: its placement in its parent, motion ``M(q)``, constant subspace ``S`` (6 x k) and the
    velocity coordinates it takes (``cols``, with their ``scale``: a mimic joint takes its leader's)."""

    def __init__(self, model: pin.Model, jid: int, source: str):
        jm = model.joints[jid]
        self.placement = _SE3.of(model.jointPlacements[jid])
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

    def motion(self, q) -> _SE3:
        """``M(q)``: the joint's transform (after its placement)."""
        k = self.kind
        if k in _ONE_DOF or k == "mimic":
            theta = q[self.idx_q] * self.scale + self.offset
            S = self.S[:, 0] / self.scale  # the joint's own subspace
            if np.abs(S[3:]).max() > 0:
                return _SE3(_rodrigues(S[3:] / np.linalg.norm(S[3:]), cs.cos(theta), cs.sin(theta)), cs.DM.zeros(3))
            return _SE3(cs.DM(np.eye(3)), cs.DM(S[:3]) * theta)
        if k in ("RUBX", "RUBY", "RUBZ"):
            axis = np.eye(3)["XYZ".index(k[-1])]
            return _SE3(_rodrigues(axis, q[self.idx_q], q[self.idx_q + 1]), cs.DM.zeros(3))
        if k == "Spherical":
            i = self.idx_q
            return _SE3(_quat_matrix(q[i], q[i + 1], q[i + 2], q[i + 3]), cs.DM.zeros(3))
        if k == "FreeFlyer":
            i = self.idx_q
            return _SE3(_quat_matrix(q[i + 3], q[i + 4], q[i + 5], q[i + 6]), cs.vertcat(q[i], q[i + 1], q[i + 2]))
        if k == "Planar":
            i = self.idx_q
            return _SE3(_rodrigues(np.array([0.0, 0.0, 1.0]), q[i + 2], q[i + 3]), cs.vertcat(q[i], q[i + 1], 0))
        # universal: about axis1, then about axis2 of the moved frame
        i = self.idx_q
        R1 = _rodrigues(self.axes[0], cs.cos(q[i]), cs.sin(q[i]))
        R2 = _rodrigues(self.axes[1], cs.cos(q[i + 1]), cs.sin(q[i + 1]))
        return _SE3(R1 @ R2, cs.DM.zeros(3))

    def subspace(self, q):
        """``S`` (6 x k) in the joint's frame; constant except a universal joint's first column."""
        if self.kind != "Universal":
            return cs.DM(self.S)
        i = self.idx_q
        R2 = _rodrigues(self.axes[1], cs.cos(q[i + 1]), cs.sin(q[i + 1]))
        return cs.horzcat(cs.vertcat(cs.DM.zeros(3), R2.T @ cs.DM(self.axes[0])),
                          cs.vertcat(cs.DM.zeros(3), cs.DM(self.axes[1])))

    def velocity(self, q, v):
        """The joint's twist in its frame, ``S v_j``."""
        return self.subspace(q) @ cs.vertcat(*[v[c] for c in self.cols])

    def bias(self, q, v):
        """``dS/dt v_j`` (only the universal joint's first axis turns with the second coordinate)."""
        if self.kind != "Universal":
            return cs.DM.zeros(6)
        i, iv = self.idx_q, self.idx_v
        q2, q1d, q2d = q[i + 1], v[iv], v[iv + 1]
        R2 = _rodrigues(self.axes[1], cs.cos(q2), cs.sin(q2))
        w1 = R2.T @ cs.DM(self.axes[0])
        return cs.vertcat(cs.DM.zeros(3), -_cross(cs.DM(self.axes[1]) * q2d, w1) * q1d)


# ---------------------------------------------------------------------- the twin
class Twin:
    """The symbolic twin of ``mech`` (see the module doc). Its expressions are built once, in terms of the
    symbols :attr:`q`, :attr:`v`, :attr:`a`; :meth:`function` wraps any of them as a ``casadi.Function``."""

    def __init__(self, mech: Mechanism):
        self.mech = mech = check_mechanism(mech)
        model = mech.model
        self.q, self.v, self.a = cs.SX.sym("q", model.nq), cs.SX.sym("v", model.nv), cs.SX.sym("a", model.nv)
        #: The actuated rates and accelerations (symbols, na), inputs of :attr:`velocities` and :attr:`accelerations`.
        self.qd, self.qdd = cs.SX.sym("qd", mech.na), cs.SX.sym("qdd", mech.na)
        self.joints: list = [None] + [_Joint(model, j, mech.source) for j in range(1, model.njoints)]
        self._inertia = [model.inertias[j] for j in range(model.njoints)]
        self._forward()

    def _forward(self) -> None:
        """Placements, velocities, accelerations (classical bias with ``a``) of every joint frame."""
        q, v, a = self.q, self.v, self.a
        n = len(self.joints)
        self.oMi: list[_SE3] = [_SE3(cs.DM(np.eye(3)), cs.DM.zeros(3))] + [None] * (n - 1)  # type: ignore[list-item]
        self.liMi: list[_SE3] = [None] * n  # type: ignore[list-item]
        self.vel = [cs.DM.zeros(6)] * n  # body twists, local frames
        self.acc = [cs.DM.zeros(6)] * n  # spatial accelerations with a
        self.acc0 = [cs.DM.zeros(6)] * n  # ... with a = 0 (for the drift)
        for j in range(1, n):
            J = self.joints[j]
            M = J.placement * J.motion(q)
            self.liMi[j] = M
            self.oMi[j] = self.oMi[J.parent] * M
            vj = J.velocity(q, v)
            self.vel[j] = M.inv_act_motion(self.vel[J.parent]) + vj
            c = J.bias(q, v) + _motion_cross(self.vel[j], vj)
            self.acc[j] = M.inv_act_motion(self.acc[J.parent]) + J.velocity(q, a) + c
            self.acc0[j] = M.inv_act_motion(self.acc0[J.parent]) + c

    # ---------------------------------------------------------------- kinematics
    def frame_placement(self, fid: int) -> _SE3:
        f = self.mech.model.frames[fid]
        return self.oMi[f.parentJoint] * _SE3.of(f.placement)

    def frame_jacobian(self, fid: int):
        """The frame's Jacobian in ``LOCAL_WORLD_ALIGNED`` (6 x nv): ``[v of its origin; w]`` in world axes."""
        model = self.mech.model
        f = model.frames[fid]
        p = self.frame_placement(fid).p
        J = cs.SX.zeros(6, model.nv)
        j = f.parentJoint
        while j > 0:
            Jt = self.joints[j]
            S = self.oMi[j].action() @ Jt.subspace(self.q)  # world twists at the world origin
            for k, col in enumerate(Jt.cols):  # the velocity of the point p: v0 + w x p
                J[:, col] = J[:, col] + cs.vertcat(S[:3, k] + _cross(S[3:, k], p), S[3:, k])
            j = Jt.parent
        return J

    def frame_classical_acceleration(self, fid: int):
        """The frame origin's acceleration ``[a; alpha]`` in world axes with ``a = 0`` (classical: ``a + w x v``)."""
        f = self.mech.model.frames[fid]
        X = _SE3.of(f.placement)
        vf = X.inv_act_motion(self.vel[f.parentJoint])
        af = X.inv_act_motion(self.acc0[f.parentJoint])
        R = self.frame_placement(fid).R
        return cs.vertcat(R @ (af[:3] + _cross(vf[3:], vf[:3])), R @ af[3:])

    # ---------------------------------------------------------------- closures
    @functools.cached_property
    def closure_residual(self):
        """The closure residual (n_constraints) in :mod:`pkm.core.constraints`' conventions."""
        out = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            A, B = self.frame_placement(fa), self.frame_placement(fb)
            out.append(A.p - B.p if c.type == "point" else -_log6(A.inverse() * B))
        return cs.vertcat(*out)

    @functools.cached_property
    def closure_jacobian(self):
        """``d(residual)/dq`` on the tangent space (n_constraints x nv), as :func:`pkm.core.constraints.jacobian`."""
        rows = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            Ja, Jb = self.frame_jacobian(fa), self.frame_jacobian(fb)
            if c.type == "point":
                rows.append(Ja[:3, :] - Jb[:3, :])
            else:
                A, B = self.frame_placement(fa), self.frame_placement(fb)
                rows.append(self._local(A, Ja) - (A.inverse() * B).action() @ self._local(B, Jb))
        return cs.vertcat(*rows)

    @staticmethod
    def _local(M: _SE3, J_lwa):
        """A ``LOCAL_WORLD_ALIGNED`` Jacobian in the frame's own axes (``LOCAL``)."""
        return cs.vertcat(M.R.T @ J_lwa[:3, :], M.R.T @ J_lwa[3:, :])

    @functools.cached_property
    def closure_drift(self):
        """``gamma = dJ/dt(q, v) v`` (n_constraints): the closure acceleration of ``v`` alone, as
        :func:`pkm.core.constraints.drift`."""
        out = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            if c.type == "point":
                out.append(self.frame_classical_acceleration(fa)[:3] - self.frame_classical_acceleration(fb)[:3])
            else:  # relative acceleration of A w.r.t. B in A: a_A - X a_B - v_A x (X v_B), X = Ad(A^-1 B)
                Xa, Xb = (_SE3.of(self.mech.model.frames[f].placement) for f in (fa, fb))
                ja, jb = (self.mech.model.frames[f].parentJoint for f in (fa, fb))
                aMb = self.frame_placement(fa).inverse() * self.frame_placement(fb)
                va, vb = Xa.inv_act_motion(self.vel[ja]), aMb.act_motion(Xb.inv_act_motion(self.vel[jb]))
                aa, ab = Xa.inv_act_motion(self.acc0[ja]), aMb.act_motion(Xb.inv_act_motion(self.acc0[jb]))
                out.append(aa - ab - _motion_cross(va, vb))
        return cs.vertcat(*out)

    # ---------------------------------------------------------------- dynamics
    def _inertia_times(self, j: int, m):
        I = self._inertia[j]
        mass, c, Ic = I.mass, cs.DM(I.lever), cs.DM(I.inertia)
        lin = mass * (m[:3] - _cross(c, m[3:]))
        return cs.vertcat(lin, Ic @ m[3:] + _cross(c, lin))

    @functools.cached_property
    def rnea(self):
        """Joint torques (nv) for ``q, v, a`` under ``model.gravity`` (Pinocchio's ``rnea``)."""
        model = self.mech.model
        n = len(self.joints)
        g = cs.DM(model.gravity.vector)
        f = [cs.DM.zeros(6)] * n
        for j in range(1, n):  # gravity as the world's acceleration -g, seen in each frame (the recursion is linear)
            acc = self.acc[j] + self.oMi[j].inv_act_motion(-g)
            f[j] = self._inertia_times(j, acc) + _force_cross(self.vel[j], self._inertia_times(j, self.vel[j]))
        tau = cs.SX.zeros(model.nv)
        for j in range(n - 1, 0, -1):
            J = self.joints[j]
            t = J.subspace(self.q).T @ f[j]
            for k, col in enumerate(J.cols):
                tau[col] = tau[col] + t[k]
            f[J.parent] = f[J.parent] + self.liMi[j].act_force(f[j])
        return tau

    @functools.cached_property
    def kinetic_energy(self):
        return sum(0.5 * cs.dot(self.vel[j], self._inertia_times(j, self.vel[j])) for j in range(1, len(self.joints)))

    @functools.cached_property
    def potential_energy(self):
        g = cs.DM(self.mech.model.gravity.linear)
        out = 0
        for j in range(1, len(self.joints)):
            I = self._inertia[j]
            com = self.oMi[j].p + self.oMi[j].R @ cs.DM(I.lever)
            out = out - I.mass * cs.dot(g, com)
        return out

    def _no_idle(self) -> None:
        from pkm.core.differential import idle_motions

        if idle_motions(self.mech, self.mech.q_reference).shape[1]:
            raise SpecError(self.mech.source, "the twin's rate maps and efforts need a mechanism without idle motions; "
                                              "pkm.passive_map and pkm.inverse_dynamics handle them")

    def _passive_solve(self, rhs):
        """``x`` with ``J_p x = rhs`` in least squares (redundant planar rows allowed), ``J_p`` the passive columns."""
        Jp = self.closure_jacobian[:, self.mech.passive_v.tolist()]
        return cs.solve(Jp.T @ Jp, Jp.T @ rhs)

    @functools.cached_property
    def passive_map(self):
        """``G = dq/dq_a`` (nv x na), as :func:`pkm.passive_map` (mechanisms without idle motions)."""
        self._no_idle()
        mech = self.mech
        G = cs.SX.zeros(mech.nv, mech.na)
        for k, col in enumerate(mech.act_v):
            G[int(col), k] = 1
        X = -self._passive_solve(self.closure_jacobian[:, mech.act_v.tolist()])
        for r, row in enumerate(mech.passive_v):
            G[int(row), :] = X[r, :]
        return G

    @functools.cached_property
    def velocities(self):
        """All joint rates for the actuated rates :attr:`qd` (symbol, na), as :func:`pkm.velocities`."""
        return self.passive_map @ self.qd

    @functools.cached_property
    def accelerations(self):
        """All joint accelerations at ``(q, v)`` for the actuated accelerations :attr:`qdd` (symbol, na), as
        :func:`pkm.accelerations`: the passive ones close the loops at the acceleration level (drift included)."""
        mech = self.mech
        self._no_idle()
        a = cs.SX.zeros(mech.nv)
        for k, col in enumerate(mech.act_v):
            a[int(col)] = self.qdd[k]
        ap = -self._passive_solve(self.closure_jacobian[:, mech.act_v.tolist()] @ self.qdd + self.closure_drift)
        for r, row in enumerate(mech.passive_v):
            a[int(row)] = ap[r]
        return a

    @functools.cached_property
    def closure_step(self):
        """The Gauss-Newton step of the loop closure at ``q`` (actuators held): the passive rates ``dq`` (nv, zero on
        the actuated and base rows) with ``J_p dq_p = -residual`` in least squares; ``pin.integrate(q, dq)`` applies it."""
        self._no_idle()
        mech = self.mech
        dq = cs.SX.zeros(mech.nv)
        step = -self._passive_solve(self.closure_residual)
        for r, row in enumerate(mech.passive_v):
            dq[int(row)] = step[r]
        return dq

    @functools.cached_property
    def actuated_efforts(self):
        """Actuator efforts (na) at a consistent state, ``G^T rnea(q, v, a)`` (:func:`pkm.core.dynamics.virtual_work_dynamics`).

        Raises:
            SpecError: the mechanism has idle motions (their accelerations need the dynamics:
                :func:`pkm.inverse_dynamics` handles them).
        """
        return self.passive_map.T @ self.rnea

    # ---------------------------------------------------------------- functions
    def function(self, name: str, outputs: dict, inputs: tuple[str, ...] = ("q", "v", "a")) -> cs.Function:
        """``casadi.Function(name, inputs, outputs)`` over the twin's symbols."""
        sym = {"q": self.q, "v": self.v, "a": self.a, "qd": self.qd, "qdd": self.qdd}
        return cs.Function(name, [sym[i] for i in inputs], list(outputs.values()), list(inputs), list(outputs))


def compile_function(fun: cs.Function, directory=None) -> tuple[cs.Function, str]:
    """``fun`` as generated C, compiled (``cc -O2 -shared``) and loaded, when a C compiler is present; else ``fun``
    itself, run by CasADi's virtual machine. Returns ``(function, how)``, ``how`` saying which (and why).

    Args:
        fun: A CasADi function (from :meth:`Twin.function`).
        directory: Where the C source and the shared library go (default: a new temporary folder, kept for the
            life of the process: the library stays loaded).
    """
    import shutil
    import subprocess
    import tempfile
    from pathlib import Path

    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return fun, "CasADi's virtual machine (no C compiler on the PATH: cc, gcc or clang)"
    folder = Path(directory) if directory is not None else Path(tempfile.mkdtemp(prefix="pkm-twin-"))
    folder.mkdir(parents=True, exist_ok=True)
    name = fun.name()
    source = folder / f"{name}.c"
    gen = cs.CodeGenerator(source.name)
    gen.add(fun)
    gen.generate(str(folder) + "/")
    library = folder / f"{name}.so"
    run = subprocess.run([cc, "-O2", "-shared", "-fPIC", "-o", str(library), str(source)], capture_output=True,
                         text=True, check=False, timeout=600)
    if run.returncode != 0:
        return fun, f"CasADi's virtual machine (the C compiler failed: {run.stderr.strip()[-300:]})"
    return cs.external(name, str(library)), f"C ({Path(cc).name} -O2, {library})"


__all__ = ["Twin", "compile_function"]
