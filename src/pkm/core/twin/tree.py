"""The symbolic twin of a mechanism: its Pinocchio tree as CasADi SX expressions, built from the model itself.

For any :class:`~pkm.core.Mechanism` (loaded from any file pkm reads), :class:`Twin` gives, as functions of
symbols ``q`` (nq), ``v`` (nv) and ``a`` (nv):

* joint and frame placements, world-aligned frame Jacobians (``LOCAL_WORLD_ALIGNED``, as Pinocchio's);
* the closure residual (the conventions of :mod:`pkm.core.kinematics.constraints`), its Jacobian and drift
  ``gamma = dJ/dt v``;
* RNEA (joint torques for ``q, v, a`` under ``model.gravity``, less the joint springs' efforts), kinetic and
  potential energy (gravity's and the springs');
* for mechanisms without idle motions: the passive map ``G``, the joint rates and accelerations from the
  actuated ones, the actuator efforts at a consistent state and from ``(q, qd, qdd)`` with their derivatives,
  every linear solve a sparse LU with pivots fixed at the reference (:mod:`~pkm.core.twin.linear`), the closure
  rows in the axes that make them cheapest;
* the loop closure's Newton iteration, with a retraction on the configuration space. The task's expressions and
  the Newton iterations of the inverse kinematics and the maps are built on the twin:
  :meth:`TaskTwin.of(twin) <pkm.core.twin.task.TaskTwin.of>` (this module does not import it).

:class:`~pkm.core.twin.kernels.Kernels` turns them into functions run on states, batches and paths, compiled to C.

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
from collections.abc import Sequence
from typing import Any

import casadi as cs
import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.twin.design import design_of
from pkm.core.twin.joint import Joint
from pkm.core.twin.linear import HomogenisedPinv, PivotedLU
from pkm.core.twin.spatial import (
    SE3,
    Expr,
    cross,
    force_cross,
    log6,
    motion_cross,
)
from pkm.errors import SpecError


def theta_times(th: Expr, m: Expr) -> Expr:
    """A body's spatial force for the spatial motion ``m = [v; w]`` from its ten standard parameters ``th``
    (Pinocchio's ``toDynamicParameters``: ``m``, ``h = m c``, the inertia about the frame's origin):
    ``f = m v - h x w``, ``n = I_o w + h x v`` (Featherstone's)."""
    mass, h = th[0], th[1:4]
    inertia = cs.vertcat(cs.horzcat(th[4], th[5], th[7]), cs.horzcat(th[5], th[6], th[8]),
                         cs.horzcat(th[7], th[8], th[9]))
    lin = mass * m[:3] - cross(h, m[3:])
    return cs.vertcat(lin, inertia @ m[3:] + cross(h, m[:3]))


# ---------------------------------------------------------------------- the twin
class Twin:
    """The symbolic twin of ``mech`` (see the module doc). Its expressions are built once, in terms of the
    symbols :attr:`q`, :attr:`v`, :attr:`a`, and :attr:`p` for the ``design`` parameters taken as symbols (URDF
    joint origins, bodies' inertial parameters: :mod:`~pkm.core.twin.design`; none by default); :meth:`function`
    wraps any of them as a ``casadi.Function``."""

    def __init__(self, mech: Mechanism, design: Sequence[str] | None = None):
        self.mech = mech = check_mechanism(mech)
        model = mech.model
        #: The design parameters taken as symbols (:mod:`~pkm.core.twin.design`; none by default) and the symbols.
        self.design = design_of(mech, design)
        self.p = cs.SX.sym("design", len(self.design))
        self.q, self.v, self.a = cs.SX.sym("q", model.nq), cs.SX.sym("v", model.nv), cs.SX.sym("a", model.nv)
        #: The actuated rates and accelerations (symbols, na), inputs of :attr:`velocities` and :attr:`accelerations`.
        self.qd, self.qdd = cs.SX.sym("qd", mech.na), cs.SX.sym("qdd", mech.na)
        self.joints: list = [None] + [Joint(model, j, mech.source) for j in range(1, model.njoints)]
        self._frames: dict[int, SE3] = {}
        self._moved = self._moved_frames()
        for j in range(1, model.njoints) if self.design.joints else ():
            self._design_placement(j)
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
            v_parent = M.inv_act_motion(self.vel[J.parent])
            self.vel[j] = v_parent + vj
            c = J.bias(q, v) + motion_cross(v_parent, vj)  # (v_parent + vj) x vj, without vj x vj = 0
            self.acc[j] = M.inv_act_motion(self.acc[J.parent]) + J.velocity(q, a) + c
            self.acc0[j] = M.inv_act_motion(self.acc0[J.parent]) + c

    # ---------------------------------------------------------------- the design's geometry
    def _moved_frames(self) -> set[int]:
        """The frames whose placement in their joint a varied fixed-joint origin moves (parents come first)."""
        model, moved = self.mech.model, set()
        for fid, f in enumerate(model.frames) if self.design.joints else ():
            parent = model.frames[f.parentFrame]
            if f.type == pin.FrameType.FIXED_JOINT and f.name in self.design.joints:
                moved.add(fid)
            elif fid and f.type != pin.FrameType.JOINT and parent.parentJoint == f.parentJoint and f.parentFrame in moved:
                moved.add(fid)
        return moved

    def frame_local(self, fid: int) -> SE3:
        """Frame ``fid``'s placement in its joint: the model's, or with the design's varied fixed-joint origins as
        symbols (:mod:`~pkm.core.twin.design`)."""
        f = self.mech.model.frames[fid]
        if fid not in self._moved:
            return SE3.of(f.placement)
        if fid not in self._frames:
            parent = self.mech.model.frames[f.parentFrame]
            own = (self.design.origin(f.name, self.p) if f.type == pin.FrameType.FIXED_JOINT
                   and f.name in self.design.joints else SE3.of(parent.placement.inverse() * f.placement))
            self._frames[fid] = self.frame_local(f.parentFrame) * own
        return self._frames[fid]

    def _design_placement(self, j: int) -> None:
        """Joint ``j``'s placement from the design: its parent link's frame, then its URDF origin (either varied)."""
        model = self.mech.model
        name = model.names[j]
        if name not in self.design.urdf:
            return
        link = self.design.urdf[name][2]
        parent = model.getFrameId(link, pin.FrameType.BODY) if model.existFrame(link, pin.FrameType.BODY) else None
        if name not in self.design.joints and parent not in self._moved:
            return
        if parent is None or model.frames[parent].parentJoint != model.parents[j]:
            raise SpecError(self.mech.source, f"joint {name!r}: its URDF parent link {link!r} is not a body of its "
                                              f"parent joint in the model: its origin cannot be a design input")
        xyz, rpy, _ = self.design.urdf[name]
        if not (model.frames[parent].placement * pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)).isApprox(
                model.jointPlacements[j], 1e-10):
            raise SpecError(self.mech.source, f"joint {name!r}: the model's placement is not its URDF origin in its "
                                              f"parent link: its origin cannot be a design input")
        self.joints[j].placement = self.frame_local(parent) * self.design.origin(name, self.p)

    # ---------------------------------------------------------------- kinematics
    def frame_placement(self, fid: int) -> SE3:
        f = self.mech.model.frames[fid]
        return self.oMi[f.parentJoint] * self.frame_local(fid)

    def frame_jacobian(self, fid: int) -> Expr:
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

    def frame_classical_acceleration(self, fid: int) -> Expr:
        """The frame origin's acceleration ``[a; alpha]`` in world axes with ``a = 0`` (classical: ``a + w x v``)."""
        f = self.mech.model.frames[fid]
        X = self.frame_local(fid)
        vf = X.inv_act_motion(self.vel[f.parentJoint])
        af = X.inv_act_motion(self.acc0[f.parentJoint])
        R = self.frame_placement(fid).R
        return cs.vertcat(R @ (af[:3] + cross(vf[3:], vf[:3])), R @ af[3:])

    # ---------------------------------------------------------------- closures
    @functools.cached_property
    def closure_residual(self) -> Expr:
        """The closure residual (n_constraints) in :mod:`pkm.core.kinematics.constraints`' conventions."""
        out = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            A, B = self.frame_placement(fa), self.frame_placement(fb)
            out.append(A.p - B.p if c.type == "point" else -log6(A.inverse() * B))
        return cs.vertcat(*out)

    @functools.cached_property
    def closure_jacobian(self) -> Expr:
        """``d(residual)/dq`` on the tangent space (n_constraints x nv), as :func:`pkm.core.kinematics.constraints.jacobian`."""
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
    def _local(M: SE3, J_lwa: Expr) -> Expr:
        """A ``LOCAL_WORLD_ALIGNED`` Jacobian in the frame's own axes (``LOCAL``)."""
        return cs.vertcat(M.R.T @ J_lwa[:3, :], M.R.T @ J_lwa[3:, :])

    @functools.cached_property
    def closure_drift(self) -> Expr:
        """``gamma = dJ/dt(q, v) v`` (n_constraints): the closure acceleration of ``v`` alone, as
        :func:`pkm.core.kinematics.constraints.drift`."""
        out = []
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            if c.type == "point":
                out.append(self.frame_classical_acceleration(fa)[:3] - self.frame_classical_acceleration(fb)[:3])
            else:  # relative acceleration of A w.r.t. B in A: a_A - X a_B - v_A x (X v_B), X = Ad(A^-1 B)
                Xa, Xb = (self.frame_local(f) for f in (fa, fb))
                ja, jb = (self.mech.model.frames[f].parentJoint for f in (fa, fb))
                aMb = self.frame_placement(fa).inverse() * self.frame_placement(fb)
                va, vb = Xa.inv_act_motion(self.vel[ja]), aMb.act_motion(Xb.inv_act_motion(self.vel[jb]))
                aa, ab = Xa.inv_act_motion(self.acc0[ja]), aMb.act_motion(Xb.inv_act_motion(self.acc0[jb]))
                out.append(aa - ab - motion_cross(va, vb))
        return cs.vertcat(*out)

    def frame_jacobian_local(self, fid: int) -> Expr:
        """The frame's Jacobian in ``LOCAL`` axes (6 x nv), by a backward pass from the frame: a joint right above
        it (a free-flyer platform's) costs nothing."""
        model = self.mech.model
        f = model.frames[fid]
        J = cs.SX.zeros(6, model.nv)
        M = self.frame_local(fid).inverse()  # the frame from joint j
        j = f.parentJoint
        while j > 0:
            Jt = self.joints[j]
            S = Jt.subspace(self.q)
            for k, col in enumerate(Jt.cols):
                J[:, col] = J[:, col] + M.act_motion(S[:, k])
            if Jt.parent > 0:
                M = M * self.liMi[j].inverse()
            j = Jt.parent
        return J

    @functools.cached_property
    def closure_rows(self) -> dict:
        """The closure's velocity-level rows in the axes that make them cheapest: a point closure's in the axes of
        whichever of its frames hangs from the joint with more velocity coordinates (a free-flyer platform's: its
        columns are then constants), a frame closure's in frame A's (as :attr:`closure_jacobian`). Returns
        ``jacobian`` (``W J``), ``drift`` (``W gamma``) and ``rotations`` (the blocks of ``W``, None for identity).
        Any invertible ``W`` gives the same rates, accelerations and efforts."""
        model = self.mech.model
        rows: list = []
        drift: list = []
        rotations: list = []
        J_all, g_all = self.closure_jacobian, self.closure_drift
        nv_of = lambda f: model.joints[model.frames[f].parentJoint].nv
        at = 0
        for c, (fa, fb) in zip(self.mech.spec.closures, self.mech.closure_frames):
            if c.type != "point":
                rows.append(J_all[at:at + 6, :])
                drift.append(g_all[at:at + 6])
                rotations.append(None)
                at += 6
                continue
            F, G, sign = (fa, fb, 1) if nv_of(fa) >= nv_of(fb) else (fb, fa, -1)
            R = self.frame_placement(F).R
            J = self.frame_jacobian_local(F)[:3, :] - R.T @ self.frame_jacobian(G)[:3, :]
            X = self.frame_local(F)
            vf = X.inv_act_motion(self.vel[model.frames[F].parentJoint])
            af = X.inv_act_motion(self.acc0[model.frames[F].parentJoint])
            gF = af[:3] + cross(vf[3:], vf[:3])
            gamma = gF - R.T @ self.frame_classical_acceleration(G)[:3]
            rows.append(sign * J)
            drift.append(sign * gamma)
            rotations.append(R)
            at += 3
        return {"jacobian": cs.vertcat(*rows), "drift": cs.vertcat(*drift), "rotations": rotations}

    def rotate_rows(self, residual: Expr) -> Expr:
        """``W residual`` for the rows of :attr:`closure_rows`."""
        out, at = [], 0
        for R in self.closure_rows["rotations"]:
            n = 6 if R is None else 3
            out.append(residual[at:at + n] if R is None else R.T @ residual[at:at + n])
            at += n
        return cs.vertcat(*out)

    # ---------------------------------------------------------------- dynamics
    def _inertia_times(self, j: int, m: Expr) -> Expr:
        if j in self.design.bodies:
            return theta_times(self._theta(j), m)
        I = self._inertia[j]
        mass, c, Ic = I.mass, cs.DM(I.lever), cs.DM(I.inertia)
        lin = mass * (m[:3] - cross(c, m[3:]))
        return cs.vertcat(lin, Ic @ m[3:] + cross(c, lin))

    @functools.cached_property
    def rnea(self) -> Expr:
        """Joint torques (nv) for ``q, v, a`` under ``model.gravity`` (Pinocchio's ``rnea``, the model's ``armature``,
        the actuators' reflected inertia, included: ``armature * a`` on each joint's diagonal), less the joint springs'
        efforts ``τ_s = -k (q - rest)`` (``[springs]``, :mod:`pkm.core.model.springs`), as pkm's inverse dynamics."""
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
        armature = np.asarray(model.armature, dtype=float)  # the actuators' reflected inertia, as Pinocchio's rnea
        for i in np.flatnonzero(armature):
            tau[int(i)] = tau[int(i)] + float(armature[i]) * self.a[int(i)]
        sp = self.mech.springs
        for iq, iv, k, rest in zip(sp.idx_q, sp.idx_v, sp.stiffness, sp.rest):
            tau[int(iv)] = tau[int(iv)] + float(k) * (self.q[int(iq)] - float(rest))
        return tau

    @functools.cached_property
    def kinetic_energy(self) -> Expr:
        return sum(0.5 * cs.dot(self.vel[j], self._inertia_times(j, self.vel[j])) for j in range(1, len(self.joints)))

    @functools.cached_property
    def potential_energy(self) -> Expr:
        g = cs.DM(self.mech.model.gravity.linear)
        out = 0
        for j in range(1, len(self.joints)):
            th = self._theta(j) if j in self.design.bodies else cs.DM(self._inertia[j].toDynamicParameters())
            out = out - cs.dot(g, th[0] * self.oMi[j].p + self.oMi[j].R @ th[1:4])  # (m times the centre of mass)
        sp = self.mech.springs  # (and the joint springs', as pkm.core.dynamics.projection.energy)
        return out + sum((0.5 * float(k) * (self.q[int(iq)] - float(r)) ** 2
                          for iq, k, r in zip(sp.idx_q, sp.stiffness, sp.rest)), cs.SX(0)) if sp else out

    def _theta(self, j: int) -> Expr:
        """Body ``j``'s ten inertial parameters, the design's as symbols."""
        return self.design.theta(j, np.asarray(self._inertia[j].toDynamicParameters()), self.p)

    def _no_idle(self) -> None:
        from pkm.core.differential.velocity import idle_motions

        if idle_motions(self.mech, self.mech.q_reference).shape[1]:
            raise SpecError(self.mech.source, "the twin's rate maps and efforts need a mechanism without idle motions; "
                                              "pkm.passive_map and pkm.inverse_dynamics handle them")

    def at_reference(self, expr: Expr) -> np.ndarray:
        """The value of an expression of ``q`` (and the design) at the mechanism's reference configuration (and
        its own design)."""
        return np.array(cs.Function("at_reference", [self.q, self.p], [expr])(self.mech.q_reference,
                                                                                 self.design.base))

    @functools.cached_property
    def passive_lu(self) -> PivotedLU:
        """The closure Jacobian's passive columns ``J_p``, factored (pivots fixed at the reference)."""
        self._no_idle()
        Jp = self.closure_rows["jacobian"][:, self.mech.passive_v.tolist()]
        return PivotedLU(Jp, self.at_reference(Jp))

    @functools.cached_property
    def passive_solve(self) -> PivotedLU | HomogenisedPinv:
        """The solves of ``J_p`` the rate maps and the efforts use: :attr:`passive_lu`'s, or, under redundant actuation
        (:attr:`~pkm.core.Mechanism.dependent_actuators`: more closure rows than the passive joints need, so that
        an actuated rate alone has no exact passive answer, and the efforts' closure multipliers are not unique),
        the generic core's homogenised pseudo-inverse (:func:`pkm.passive_map`'s ``G``, its ``G^T`` the efforts'),
        so that the kernels give the core's maps and efforts (:class:`~pkm.core.twin.linear.HomogenisedPinv`)."""
        lu = self.passive_lu  # (idle motions refused)
        if not self.mech.dependent_actuators:
            return lu
        sc, pv = JacobianScales.of(self.mech), self.mech.passive_v
        Jp = self.closure_rows["jacobian"][:, pv.tolist()]
        return HomogenisedPinv(Jp, self.at_reference(Jp), sc.constraint_rows, sc.columns[pv])

    def _passive(self, values: Expr) -> cs.SX:
        """An nv vector: ``values`` (passive) on the passive rows, zero elsewhere."""
        out = cs.SX.zeros(self.mech.nv)
        for r, row in enumerate(self.mech.passive_v):
            out[int(row)] = values[r]
        return out

    def _actuated(self, values: Expr) -> cs.SX:
        out = cs.SX.zeros(self.mech.nv)
        for k, col in enumerate(self.mech.act_v):
            out[int(col)] = values[k]
        return out

    @functools.cached_property
    def passive_map(self) -> Expr:
        """``G = dq/dq_a`` (nv x na), as :func:`pkm.passive_map` (mechanisms without idle motions)."""
        Ja = self.closure_rows["jacobian"][:, self.mech.act_v.tolist()]
        return cs.horzcat(*[self._actuated(np.eye(self.mech.na)[k]) - self._passive(self.passive_solve.solve(Ja[:, k]))
                            for k in range(self.mech.na)])

    @functools.cached_property
    def velocities(self) -> Expr:
        """All joint rates for the actuated rates :attr:`qd` (symbol, na), as :func:`pkm.velocities`."""
        Ja = self.closure_rows["jacobian"][:, self.mech.act_v.tolist()]
        return self._actuated(self.qd) - self._passive(self.passive_solve.solve(Ja @ self.qd))

    @functools.cached_property
    def accelerations(self) -> Expr:
        """All joint accelerations at ``(q, v)`` for the actuated accelerations :attr:`qdd` (symbol, na), as
        :func:`pkm.accelerations`: the passive ones close the loops at the acceleration level (drift included)."""
        Ja = self.closure_rows["jacobian"][:, self.mech.act_v.tolist()]
        return self._actuated(self.qdd) - self._passive(self.passive_solve.solve(Ja @ self.qdd + self.closure_rows["drift"]))

    @functools.cached_property
    def closure_step(self) -> Expr:
        """The Newton step of the loop closure at ``q`` (actuators held): the passive rates ``dq`` (nv, zero on the
        actuated and base rows) with ``J_p dq_p = -residual``; ``pin.integrate(q, dq)`` applies it."""
        return -self._passive(self.passive_lu.solve(self.rotate_rows(self.closure_residual)))

    @functools.cached_property
    def actuated_efforts(self) -> Expr:
        """Actuator efforts (na) at a consistent state ``(q, v, a)``: ``G^T rnea``
        (:func:`pkm.core.dynamics.projection.virtual_work_dynamics`), computed as ``tau_a - J_a^T lambda`` with
        ``J_p^T lambda = tau_p`` (one transposed solve instead of the matrix ``G``; under redundant actuation the
        least-norm ``lambda`` of :attr:`passive_solve`, the core's: the same efforts as :func:`pkm.inverse_dynamics`).

        Raises:
            SpecError: the mechanism has idle motions (their accelerations need the dynamics:
                :func:`pkm.inverse_dynamics` handles them).
        """
        mech, tau = self.mech, self.rnea
        lam = self.passive_solve.solve_transposed(cs.vertcat(*[tau[int(r)] for r in mech.passive_v]))
        Ja = self.closure_rows["jacobian"][:, mech.act_v.tolist()]
        return cs.vertcat(*[tau[int(c)] for c in mech.act_v]) - Ja.T @ lam

    @functools.cached_property
    def inverse_dynamics(self) -> Expr:
        """Actuator efforts (na) from the closed configuration :attr:`q` and the actuated rates and accelerations
        :attr:`qd`, :attr:`qdd`: joint rates, accelerations (drift included), RNEA under gravity, projection. A
        floating base is held still (its pose in ``q``)."""
        v = self.velocities
        a = cs.substitute(self.accelerations, self.v, v)
        return cs.substitute(self.actuated_efforts, cs.vertcat(self.v, self.a), cs.vertcat(v, a))

    @functools.cached_property
    def inverse_dynamics_derivatives(self) -> dict:
        """Derivatives of :attr:`inverse_dynamics` for trajectory optimisation (each na x na): ``dtau_dqa``, the total
        derivative along the closure (the configuration moved by the actuated coordinates, ``dq = G dq_a``, rates
        and accelerations held); ``dtau_dqd``, ``dtau_dqdd``."""
        tau = self.inverse_dynamics
        return {"dtau_dqa": cs.jtimes(tau, self.q, self.tangent @ self.passive_map),  # na forward sweeps, not nq
                "dtau_dqd": cs.jacobian(tau, self.qd), "dtau_dqdd": cs.jacobian(tau, self.qdd)}

    @property
    def task(self) -> Any:
        """Moved: :meth:`TaskTwin.of(twin) <pkm.core.twin.task.TaskTwin.of>` (built on the twin, above it)."""
        raise AttributeError("Twin.task moved to pkm.core.twin.task.TaskTwin.of(twin): the task's expressions are "
                             "built on the twin, above it")

    # ---------------------------------------------------------------- configuration space
    @functools.cached_property
    def tangent(self) -> Expr:
        """``T(q)`` (nq x nv), ``dq/d(dq)`` of Pinocchio's ``integrate(q, dq)`` at ``dq = 0``."""
        T = cs.SX.zeros(self.mech.model.nq, self.mech.nv)
        for J in self.joints[1:]:
            block = J.tangent(self.q)
            if block is not None:
                T[J.idx_q:J.idx_q + block.shape[0], J.cols[0]:J.cols[-1] + 1] = block
        return T

    def retract(self, dq: Expr) -> Expr:
        """:attr:`q` moved by the tangent vector ``dq`` (nv): ``q + T dq`` with unit blocks renormalised, which
        agrees with ``pin.integrate`` to first order (see :meth:`Joint.retract`)."""
        out = [self.q[i] for i in range(self.mech.model.nq)]
        for J in self.joints[1:]:
            for i, x in J.retract(self.q, dq):
                out[i] = x
        return cs.vertcat(*out)

    @functools.cached_property
    def target(self) -> Expr:
        """The symbol of a Newton iteration's target: the actuated coordinates (na) for :attr:`closure_newton`."""
        return cs.SX.sym("qa", self.mech.na)

    def with_actuated(self, expr: Expr) -> Expr:
        """``expr`` at :attr:`q` with its actuated coordinates replaced by :attr:`target`."""
        q = [self.q[i] for i in range(self.mech.model.nq)]
        for k, i in enumerate(self.mech.act_q):
            q[int(i)] = self.target[k]
        return cs.substitute(expr, self.q, cs.vertcat(*q))

    @functools.cached_property
    def closure_newton(self) -> dict:
        """One Newton iteration of the loop closure for the actuated coordinates :attr:`target`, from :attr:`q`:
        ``q_next`` (the next iterate, its actuated coordinates set), ``residual`` (the largest closure residual there,
        counted in the characteristic length: :attr:`relative_closure_residual`) and ``pivot``
        (:meth:`PivotedLU.smallest_relative_pivot` at the iterate it starts from)."""
        q_next = self.with_actuated(self.retract(self.closure_step))
        return {"q_next": q_next, "residual": self.largest_at(self.relative_closure_residual, q_next),
                "pivot": self.with_actuated(self.passive_lu.smallest_relative_pivot())}

    @functools.cached_property
    def relative_closure_residual(self) -> Expr:
        """:attr:`closure_residual` counted in the mechanism's characteristic length ``L`` (a translation row divided by
        ``L``, a rotation row in rad: :attr:`~pkm.core.model.scale.JacobianScales.closure_residual`), as
        :func:`pkm.close_loops`' tolerance counts it: the Newton kernels' residual, the same for a copy scaled in
        size."""
        return self.closure_residual * cs.DM(JacobianScales.of(self.mech).closure_residual)

    def largest_at(self, residual: Expr, q: Expr) -> Expr:
        """The largest entry of ``residual`` (an expression of :attr:`q`) at the configuration ``q``."""
        return cs.mmax(cs.fabs(cs.substitute(residual, self.q, q)))

    # ---------------------------------------------------------------- functions
    def function(self, name: str, outputs: dict, inputs: tuple[str, ...] = ("q", "v", "a")) -> cs.Function:
        """``casadi.Function(name, inputs, outputs)`` over the twin's symbols (the task's are
        :class:`~pkm.core.twin.task.TaskTwin`'s)."""
        sym = {"q": self.q, "v": self.v, "a": self.a, "qd": self.qd, "qdd": self.qdd, "target": self.target,
               "design": self.p}
        return cs.Function(name, [sym[i] for i in inputs], list(outputs.values()), list(inputs), list(outputs))



__all__ = ["Twin"]
