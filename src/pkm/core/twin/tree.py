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

from pkm.core.mechanism import Mechanism, check_mechanism
from pkm.core.twin.joint import Joint
from pkm.core.twin.spatial import SE3, cross, force_cross, log6, motion_cross
from pkm.errors import SpecError


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
        self.joints: list = [None] + [Joint(model, j, mech.source) for j in range(1, model.njoints)]
        self._inertia = [model.inertias[j] for j in range(model.njoints)]
        self._forward()

    def _forward(self) -> None:
        """Placements, velocities, accelerations (classical bias with ``a``) of every joint frame."""
        q, v, a = self.q, self.v, self.a
        n = len(self.joints)
        self.oMi: list[SE3] = [SE3(cs.DM(np.eye(3)), cs.DM.zeros(3))] + [None] * (n - 1)  # type: ignore[list-item]
        self.liMi: list[SE3] = [None] * n  # type: ignore[list-item]
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
            c = J.bias(q, v) + motion_cross(self.vel[j], vj)
            self.acc[j] = M.inv_act_motion(self.acc[J.parent]) + J.velocity(q, a) + c
            self.acc0[j] = M.inv_act_motion(self.acc0[J.parent]) + c

    # ---------------------------------------------------------------- kinematics
    def frame_placement(self, fid: int) -> SE3:
        f = self.mech.model.frames[fid]
        return self.oMi[f.parentJoint] * SE3.of(f.placement)

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
                J[:, col] = J[:, col] + cs.vertcat(S[:3, k] + cross(S[3:, k], p), S[3:, k])
            j = Jt.parent
        return J

    def frame_classical_acceleration(self, fid: int):
        """The frame origin's acceleration ``[a; alpha]`` in world axes with ``a = 0`` (classical: ``a + w x v``)."""
        f = self.mech.model.frames[fid]
        X = SE3.of(f.placement)
        vf = X.inv_act_motion(self.vel[f.parentJoint])
        af = X.inv_act_motion(self.acc0[f.parentJoint])
        R = self.frame_placement(fid).R
        return cs.vertcat(R @ (af[:3] + cross(vf[3:], vf[:3])), R @ af[3:])

    # ---------------------------------------------------------------- closures
    @functools.cached_property
    def closure_residual(self):
        """The closure residual (n_constraints) in :mod:`pkm.core.constraints`' conventions."""
        out = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            A, B = self.frame_placement(fa), self.frame_placement(fb)
            out.append(A.p - B.p if c.type == "point" else -log6(A.inverse() * B))
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
    def _local(M: SE3, J_lwa):
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
                Xa, Xb = (SE3.of(self.mech.model.frames[f].placement) for f in (fa, fb))
                ja, jb = (self.mech.model.frames[f].parentJoint for f in (fa, fb))
                aMb = self.frame_placement(fa).inverse() * self.frame_placement(fb)
                va, vb = Xa.inv_act_motion(self.vel[ja]), aMb.act_motion(Xb.inv_act_motion(self.vel[jb]))
                aa, ab = Xa.inv_act_motion(self.acc0[ja]), aMb.act_motion(Xb.inv_act_motion(self.acc0[jb]))
                out.append(aa - ab - motion_cross(va, vb))
        return cs.vertcat(*out)

    # ---------------------------------------------------------------- dynamics
    def _inertia_times(self, j: int, m):
        I = self._inertia[j]
        mass, c, Ic = I.mass, cs.DM(I.lever), cs.DM(I.inertia)
        lin = mass * (m[:3] - cross(c, m[3:]))
        return cs.vertcat(lin, Ic @ m[3:] + cross(c, lin))

    @functools.cached_property
    def rnea(self):
        """Joint torques (nv) for ``q, v, a`` under ``model.gravity`` (Pinocchio's ``rnea``)."""
        model = self.mech.model
        n = len(self.joints)
        g = cs.DM(model.gravity.vector)
        f = [cs.DM.zeros(6)] * n
        for j in range(1, n):  # gravity as the world's acceleration -g, seen in each frame (the recursion is linear)
            acc = self.acc[j] + self.oMi[j].inv_act_motion(-g)
            f[j] = self._inertia_times(j, acc) + force_cross(self.vel[j], self._inertia_times(j, self.vel[j]))
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



__all__ = ["Twin"]
