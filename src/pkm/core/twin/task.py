"""The task of a mechanism's twin: its error and Jacobian, the forward and inverse Jacobians, and the Newton
iterations of the inverse kinematics and of the maps (:mod:`pkm.core.analysis.maps`), as SX expressions of the twin's
symbols (:class:`~pkm.core.twin.tree.Twin`: :meth:`TaskTwin.of(twin) <TaskTwin.of>`, built on the twin, which does
not import this module)."""

from __future__ import annotations

import functools

import casadi as cs
import numpy as np

from pkm._derived import derived
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.scale import JacobianScales
from pkm.core.twin.linear import PivotedLU
from pkm.core.twin.spatial import Expr, euler_rates, log3, quat_matrix, zyx_angles
from pkm.core.twin.tree import Twin
from pkm.errors import SpecError

_POS = {"x": 0, "y": 1, "z": 2}
_ANGLES = ("roll", "pitch", "yaw")


class TaskTwin:
    """The task expressions of ``twin`` (see the module doc)."""

    @classmethod
    def of(cls, twin: Twin) -> TaskTwin:
        """``twin``'s task expressions, made on the first call and kept with the twin."""
        return derived(twin, cls)

    def __init__(self, twin: Twin):
        self.tw = twin

    def _task_groups(self) -> list[tuple[int, tuple[str, ...]]]:
        spec = self.tw.mech.spec.task
        groups = [(self.tw.mech.ee_frame, spec.components)] if spec.components else []
        return groups + list(zip(self.tw.mech.task_frames, spec.frames.values()))

    @functools.cached_property
    def task_target(self) -> Expr:
        """The symbol of a task target, laid out as :meth:`pkm.core.kinematics.task.TaskMap.value` gives values."""
        return cs.SX.sym("y", TaskMap.of(self.tw.mech).value_size)

    @functools.cached_property
    def task_error(self) -> Expr:
        """``target - task(q)`` on the task's tangent space, as :meth:`pkm.core.kinematics.task.TaskMap.error` (angles wrapped to
        ``(-pi, pi]``, a pose's orientation as ``log3(R_target R^T)``)."""
        y, out, at = self.task_target, [], 0
        for fid, comps in self._task_groups():
            M = self.tw.frame_placement(fid)
            if comps == ("pose",):
                R_t = quat_matrix(y[at + 3], y[at + 4], y[at + 5], y[at + 6])
                out += [y[at:at + 3] - M.p, log3(R_t @ M.R.T)]
                at += 7
                continue
            rpy = zyx_angles(M.R)
            for c in comps:
                if c in _POS:
                    out.append(y[at] - M.p[_POS[c]])
                else:
                    d = y[at] - rpy[_ANGLES.index(c)]
                    out.append(d - 2 * np.pi * cs.floor((d + np.pi) / (2 * np.pi)))
                at += 1
        for k, j in enumerate(self.tw.mech.task_joints):
            out.append(y[at + k] - self.tw.q[j.idx_q])
        return cs.vertcat(*out)

    @functools.cached_property
    def relative_task_error(self) -> Expr:
        """:attr:`task_error` counted in the characteristic length ``L`` (a length divided by ``L``, an angle in rad:
        :attr:`~pkm.core.model.scale.JacobianScales.task_residual`), as :func:`pkm.solve_ik`'s tolerance counts it."""
        return self.task_error * cs.DM(JacobianScales.of(self.tw.mech).task_residual)

    @functools.cached_property
    def task_jacobian(self) -> Expr:
        """``d(task)/dq`` on the tangent space (task size x nv), as :meth:`pkm.core.kinematics.task.TaskMap.jacobian`."""
        rows = []
        for fid, comps in self._task_groups():
            J6 = self.tw.frame_jacobian(fid)
            if comps == ("pose",):
                rows.append(J6)
                continue
            Jw = euler_rates(self.tw.frame_placement(fid).R) @ J6[3:, :]
            rows += [J6[_POS[c], :] if c in _POS else Jw[_ANGLES.index(c), :] for c in comps]
        for j in self.tw.mech.task_joints:
            e = cs.SX.zeros(1, self.tw.mech.nv)
            e[0, j.idx_v] = 1
            rows.append(e)
        return cs.vertcat(*rows)

    @functools.cached_property
    def ik_lu(self) -> PivotedLU:
        """``[closure rows; task Jacobian]`` over every velocity coordinate but a floating base's and the idle motions'
        own (:attr:`_free_cols`), factored (pivots fixed at the reference)."""
        A = cs.vertcat(self.tw.closure_rows["jacobian"], self.task_jacobian)[:, self._free_cols]
        try:
            return PivotedLU(A, self.tw.at_reference(A))
        except ValueError as e:
            raise SpecError(self.tw.mech.source, f"the closure and the task do not fix every joint at the reference ({e}): "
                                              "the task has fewer coordinates than the mechanism has degrees of "
                                              "freedom, or the reference is singular") from None

    @functools.cached_property
    def _free_cols(self) -> list[int]:
        """The velocity coordinates the inverse kinematics solves for: all but a floating base's and the idle
        motions' own (:func:`~pkm.core.twin.dynamics.idle_columns`: held, as the exported C holds them)."""
        from pkm.core.twin.dynamics import idle_columns

        held = set(self.tw.mech.base_v.tolist()) | set(idle_columns(self.tw.mech))
        return [i for i in range(self.tw.mech.nv) if i not in held]

    def _on_free(self, values: Expr) -> cs.SX:
        out = cs.SX.zeros(self.tw.mech.nv)
        for r, col in enumerate(self._free_cols):
            out[col] = values[r]
        return out

    @functools.cached_property
    def ik_newton(self) -> dict:
        """One Newton iteration of the inverse kinematics toward :attr:`task_target` from :attr:`q` (closure and task
        together, a floating base held): ``q_next`` (the next iterate), ``residual`` (the largest closure residual or task
        error there, lengths counted in the characteristic length as :attr:`relative_task_error`), ``pivot`` (as in
        :attr:`closure_newton`)."""
        rhs = cs.vertcat(-self.tw.rotate_rows(self.tw.closure_residual), self.task_error)
        q_next = self.tw.retract(self._on_free(self.ik_lu.solve(rhs)))
        return {"q_next": q_next,
                "residual": self.tw.largest_at(cs.vertcat(self.tw.relative_closure_residual, self.relative_task_error),
                                               q_next),
                "pivot": self.ik_lu.smallest_relative_pivot()}

    @functools.cached_property
    def map_newton(self) -> dict:
        """The Newton iteration of the maps (:mod:`pkm.core.analysis.maps`): ``q_next`` as :attr:`ik_newton`, ``step`` the
        largest entry of the step (no residual at the new iterate: convergence is tested on the step, then on
        :attr:`map_indices`' residual), ``pivot`` as in :attr:`ik_newton` (at ``q``)."""
        rhs = cs.vertcat(-self.tw.rotate_rows(self.tw.closure_residual), self.task_error)
        step = self._on_free(self.ik_lu.solve(rhs))
        return {"q_next": self.tw.retract(step), "step": cs.mmax(cs.fabs(step)),
                "pivot": self.ik_lu.smallest_relative_pivot()}

    @functools.cached_property
    def map_newton_qr(self) -> dict:
        """:attr:`map_newton` with the step from CasADi's QR factorisation of the rows the LU pivots on (no
        pivoting needed: the maps' fallback where the LU's fixed pivots fail although the matrix is regular)."""
        rows = sorted(r for r, _ in self.ik_lu.order)
        A = cs.vertcat(self.tw.closure_rows["jacobian"], self.task_jacobian)[rows, self._free_cols]
        rhs = cs.vertcat(-self.tw.rotate_rows(self.tw.closure_residual), self.task_error)[rows]
        step = self._on_free(cs.solve(A, rhs))
        return {"q_next": self.tw.retract(step), "step": cs.mmax(cs.fabs(step))}

    @functools.cached_property
    def scale(self) -> Expr:
        """The symbol of the task rates' scales (task size): :attr:`map_indices` homogenises with ``K diag(scale)``."""
        return cs.SX.sym("scale", self.task_jacobian.shape[0])

    @functools.cached_property
    def map_indices(self) -> dict:
        """What a map needs at a solved node: ``K`` (na x task size), :attr:`inverse_jacobian` times
        ``diag(scale)``; ``residual`` (the largest closure residual or task error at ``q``); ``branch``, the quantities
        whose signs define the default branch (the sine of a revolute coordinate, a prismatic coordinate)."""
        mech = self.tw.mech
        branch = []
        if mech.spec.default_branch is not None:
            for name in mech.branch().signs:
                j = mech.joints[name]
                x = self.tw.q[j.idx_q]
                branch.append(cs.sin(x) if j.revolute else x)
        return {"K": self.inverse_jacobian @ cs.diag(self.scale),
                "residual": cs.mmax(cs.fabs(cs.vertcat(self.tw.closure_residual, self.task_error))),
                "branch": cs.vertcat(*branch) if branch else cs.SX(0, 1)}

    @functools.cached_property
    def forward_jacobian(self) -> Expr:
        """Task rates per actuated rate (task size x na): ``J_task G``."""
        return self.task_jacobian @ self.tw.passive_map

    @functools.cached_property
    def inverse_jacobian(self) -> Expr:
        """Actuated rates per task rate (na x task size): the actuated rows of ``[W J; J_task]^-1 [0; I]``."""
        n_closure = self.tw.closure_rows["jacobian"].shape[0]
        at = {c: r for r, c in enumerate(self._free_cols)}
        cols = []
        for k in range(self.task_jacobian.shape[0]):
            e = cs.DM.zeros(n_closure + self.task_jacobian.shape[0])
            e[n_closure + k] = 1
            x = self.ik_lu.solve(e)
            cols.append(cs.vertcat(*[x[at[int(c)]] for c in self.tw.mech.act_v]))
        return cs.horzcat(*cols)

    @functools.cached_property
    def task_rates(self) -> tuple[cs.SX, cs.SX]:
        """The symbols of task rates and accelerations (task size each), in :attr:`task_jacobian`'s coordinates."""
        n = self.task_jacobian.shape[0]
        return cs.SX.sym("yd", n), cs.SX.sym("ydd", n)

    @functools.cached_property
    def inverse_rates(self) -> dict:
        """The joint rates and the actuated accelerations for task rates and accelerations :attr:`task_rates` at a
        closed configuration :attr:`q`: ``v`` (nv), ``[W J; J_task] v = [0; yd]`` on :attr:`_free_cols` (the idle
        coordinates held at zero rate; the actuated entries, which the idle motions do not move, are
        :func:`pkm.inverse_velocities`'); ``qdd`` (na), the time derivative of ``qd = K(q) yd`` (``K`` the
        :attr:`inverse_jacobian`): ``K ydd + (dK/dq T v) yd``, exact (``T`` the :attr:`Twin.tangent`; ``K``
        does not change along an idle motion, so the rate held there changes nothing); ``pivot`` as in
        :attr:`ik_newton`."""
        yd, ydd = self.task_rates
        n_closure = self.tw.closure_rows["jacobian"].shape[0]
        v = self._on_free(self.ik_lu.solve(cs.vertcat(cs.DM.zeros(n_closure), yd)))
        qd = self.inverse_jacobian @ yd
        qdd = self.inverse_jacobian @ ydd + cs.jtimes(qd, self.tw.q, self.tw.tangent @ v)
        return {"v": v, "qdd": qdd, "pivot": self.ik_lu.smallest_relative_pivot()}


__all__ = ["TaskTwin"]
