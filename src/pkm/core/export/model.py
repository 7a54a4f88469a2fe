"""What an exported library computes, as CasADi functions of the twin (:class:`~pkm.core.twin.tree.Twin`).

Every function is built from the mechanism's own model, as the kernels are (:mod:`pkm.core.twin.kernels`), with two
differences that a library running alone on a controller needs:

* **Idle motions are held.** A rod between two balls spins about its own axis without moving anything else; the
  kernels hand such a mechanism's kinematics back to the core, which the C cannot do. Here one passive coordinate
  per idle motion (:func:`pkm.core.twin.dynamics.idle_columns`) keeps the value of the caller's previous solution;
  the closures fix every other coordinate. The dynamics treat them as the model does (mass-orthogonal,
  :class:`~pkm.core.twin.dynamics.ActuatorTwin`).
* **Each Newton step has a dense twin.** The step uses the sparse LU with pivots fixed at the reference
  (:class:`~pkm.core.twin.linear.PivotedLU`) and gives the determinants of the matrix's diagonal blocks (the
  assembly mode); where a pivot fails the C evaluates the same square system, solves it densely with partial
  pivoting and tells a singular matrix by its smallest singular value (:class:`Newton`).

The assembly mode: the Newton matrix (the closure Jacobian on the passive coordinates for the forward kinematics;
closure and task rows on every coordinate for the inverse) has a block triangular form (Dulmage-Mendelsohn, from its
sparsity): the inverse kinematics of a mechanism with independent legs has one block per leg. A block's determinant
changes sign only where the block is singular, so the signs of the blocks' determinants relative to the reference
configuration's label the mode: bit ``k`` of the mode id is set when block ``k``'s sign is the reference's opposite.
Mode 0 is the reference's. Blocks whose entries are constants (a joint output's unit row) cannot change sign and are
left out; the first :data:`MODE_BITS` blocks label the mode.
"""

from __future__ import annotations

import dataclasses
import functools
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as cs
import numpy as np
import pinocchio as pin

from pkm.core.kinematics.blocks import block_triangular
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.twin.dynamics import ActuatorTwin
from pkm.core.twin.linear import PivotedLU
from pkm.core.twin.spatial import Expr, zyx_angles
from pkm.core.twin.task import TaskTwin
from pkm.core.twin.tree import Twin
from pkm.errors import PkmError, SpecError

#: At most this many diagonal blocks label a mode (the bits of a C ``long``, 32 bits on some platforms).
MODE_BITS = 31


class ExportError(PkmError):
    """``mech`` cannot be exported to C: :attr:`reason` says why (a joint kind the twin does not write, a task that
    does not fix the joints, a Newton iteration that does not converge at the reference, ...)."""

    def __init__(self, mechanism: str, reason: str):
        self.mechanism, self.reason = mechanism, reason
        super().__init__(f"{mechanism}: cannot be exported to C: {reason}")


def c_name(name: str) -> str:
    """A C identifier from a mechanism's name: lower case, other characters as ``_``, never starting with a digit."""
    out = re.sub(r"[^0-9a-zA-Z_]", "_", name).lower().strip("_") or "mechanism"
    return out if not out[0].isdigit() else "m_" + out


@dataclass(frozen=True)
class Block:
    """A diagonal block of a Newton matrix: its rows and columns (indices into the square matrix) and the sign of its
    determinant at the reference configuration."""

    rows: tuple[int, ...]
    cols: tuple[int, ...]
    sign: int


def diagonal_blocks(A: Expr, A_ref: np.ndarray) -> list[Block]:
    """The irreducible diagonal blocks of the square ``A``'s block triangular form, from its sparsity (a maximum
    matching puts a nonzero on every diagonal entry; the strongly connected components of the rows' graph are the
    blocks), without the blocks whose entries are all constants."""
    n = A.shape[0]
    nz = np.array([[not A[i, j].is_zero() for j in range(n)] for i in range(n)])
    blocks = []
    for rows, cols in block_triangular(nz):
        if all(A[r, c].is_constant() for r in rows for c in cols):
            continue
        det = float(np.linalg.det(A_ref[np.ix_(rows, cols)]))
        blocks.append(Block(rows, cols, 1 if det > 0 else -1))
    return blocks


@dataclass(frozen=True)
class Newton:
    """One Newton iteration as the C runs it.

    Attributes:
        step: ``(q, target) -> (q_next, residual, pivot, mode)``: the next iterate by the fixed-pivot LU, the largest
            residual at ``q`` (lengths counted in the characteristic length, angles in rad: scale-free, as
            :func:`pkm.close_loops`' tolerance counts it), the smallest relative pivot (of the LU and of the blocks' own), and per diagonal block
            its determinant relative to the reference's (positive: the reference's sign; see the module doc).
        system: ``(q, target) -> (A, b)``: the square system ``A dx = b`` the step solves (``A`` column-major), for
            the dense fallback and the smallest singular value.
        retract: ``(q, dx, target) -> q_next``: a step ``dx`` solved elsewhere, applied.
        blocks: The blocks that label the mode.
        columns: The coordinates of ``dx`` (velocity indices).
        row_scale: Per row of ``A``, the factor that homogenises it (:class:`~pkm.core.model.scale.JacobianScales`:
            the characteristic length for a rotation row or an angular task row, else 1).
        column_scale: Per column of ``A``, the characteristic length for a length (prismatic, translation), else 1:
            ``row_scale[:, None] * A * column_scale``'s singular values are scale-free (the singularity test's).
    """

    step: cs.Function
    system: cs.Function
    retract: cs.Function
    blocks: tuple[Block, ...]
    columns: tuple[int, ...]
    row_scale: np.ndarray = dataclasses.field(default_factory=lambda: np.ones(0))
    column_scale: np.ndarray = dataclasses.field(default_factory=lambda: np.ones(0))

    def homogenised(self, A: np.ndarray) -> np.ndarray:
        """The square system matrix ``A`` (of :attr:`system`) homogenised by :attr:`row_scale` and
        :attr:`column_scale`."""
        return self.row_scale[:, None] * A * self.column_scale


class ExportModel:
    """The functions of ``mech``'s exported library (see the module doc).

    Raises:
        ExportError: the twin cannot be built (a joint kind it does not write), the closures or the task do not fix
            the joints at the reference.
    """

    def __init__(self, mech: Mechanism):
        self.mech = mech = check_mechanism(mech)
        try:
            self.twin = Twin(mech)
            self.dyn = ActuatorTwin(self.twin)
            self.rows = self.twin.closure_rows
        except SpecError as e:
            raise ExportError(mech.name, str(e)) from None
        tw = self.twin
        base = {int(c) for c in mech.base_v}
        idle = set(self.dyn.idle)
        self.idle = tuple(self.dyn.idle)
        #: The velocity coordinates the forward kinematics solves for (passive, not idle) and the inverse (all but
        #: a floating base's and the idle ones).
        self.fk_columns = tuple(self.dyn.passive)
        self.ik_columns = tuple(c for c in range(mech.nv) if c not in base and c not in idle)
        self.qa = tw.target
        self.y = TaskTwin.of(tw).task_target
        self.dx_fk = cs.SX.sym("dx", len(self.fk_columns))
        self.dx_ik = cs.SX.sym("dx", len(self.ik_columns))
        self.closure_rhs = -tw.rotate_rows(tw.closure_residual)

    # ---------------------------------------------------------------- helpers
    def _spread(self, values: Expr, columns: tuple[int, ...]) -> cs.SX:
        out = cs.SX.zeros(self.mech.nv)
        for k, c in enumerate(columns):
            out[c] = values[k]
        return out

    def _newton(self, name: str, A: Expr, rhs: Expr, residual: Expr, columns: tuple[int, ...], dx: Expr,
                target: Expr, at: Callable[[Expr], Expr], row_scale: np.ndarray) -> Newton:
        """The Newton functions of the system ``A dq[columns] = rhs`` (``at`` maps an expression of ``q`` to the
        point the step is taken from; ``row_scale``: the factors that homogenise ``A``'s rows)."""
        tw = self.twin
        A_ref = tw.at_reference(A)
        try:
            lu = PivotedLU(A, A_ref)
        except ValueError as e:
            what = "the closures do not fix the passive joints" if name == "fk" else \
                "the closures and the task do not fix every joint"
            raise ExportError(self.mech.name, f"{what} at the reference ({e})") from None
        rows = sorted(r for r, _ in lu.order)  # a tall matrix: the rows the LU pivots on
        A_sq, b_sq = A[rows, :], rhs[rows]
        try:
            blocks = diagonal_blocks(A_sq, A_ref[rows, :])
        except ValueError:
            raise ExportError(self.mech.name, f"the {name} matrix is structurally singular") from None
        q_next = tw.retract(self._spread(lu.solve(rhs), columns))
        pivots, modes = [lu.smallest_relative_pivot()], []
        for b in blocks[:MODE_BITS]:  # each block's determinant from its own LU (pivots fixed at the reference)
            block_lu = PivotedLU(A_sq[list(b.rows), list(b.cols)], A_ref[rows, :][np.ix_(b.rows, b.cols)])
            pivots.append(block_lu.smallest_relative_pivot())
            modes.append(cs.SX(1.0))
            for u, r in zip(block_lu.pivots, block_lu.reference_pivots):
                modes[-1] = modes[-1] * (u / r)
        outs = [q_next, cs.mmax(cs.fabs(residual)), cs.mmin(cs.vertcat(*pivots)),
                cs.vertcat(*modes) if modes else cs.SX(1.0)]
        step = cs.Function(f"{name}_step", [tw.q, target], cs.cse([cs.densify(cs.SX(at(o))) for o in outs]),
                           ["q", "target"], ["q_next", "residual", "pivot", "mode"])
        system = cs.Function(f"{name}_system", [tw.q, target], cs.cse([cs.densify(cs.SX(at(o))) for o in (A_sq, b_sq)]),
                             ["q", "target"], ["A", "b"])
        retract = cs.Function(f"{name}_retract", [tw.q, dx, target],
                              [cs.densify(at(tw.retract(self._spread(dx, columns))))], ["q", "dx", "target"],
                              ["q_next"])
        return Newton(step, system, retract, tuple(blocks[:MODE_BITS]), columns, np.asarray(row_scale, float)[rows],
                      JacobianScales.of(self.mech).columns[list(columns)])

    # ---------------------------------------------------------------- kinematics
    @functools.cached_property
    def fk(self) -> Newton:
        """The loop closure for actuated coordinates ``target`` (na): the closure rows on the passive, non-idle
        coordinates, taken at ``q`` with its actuated coordinates set to the target."""
        tw = self.twin
        if not self.fk_columns:
            raise ExportError(self.mech.name, "no passive coordinate for the forward kinematics to solve for (every "
                                              "joint actuated or idle): the actuators fix the whole configuration")
        A = self.rows["jacobian"][:, list(self.fk_columns)]
        return self._newton("fk", A, self.closure_rhs, tw.relative_closure_residual, self.fk_columns, self.dx_fk, self.qa,
                            tw.with_actuated, JacobianScales.of(self.mech).constraint_rows)

    @functools.cached_property
    def ik(self) -> Newton:
        """The inverse kinematics for a task value ``target`` (laid out as :meth:`pkm.core.kinematics.task.TaskMap.value`):
        closure and task rows on every coordinate but a floating base's and the idle ones."""
        tw, tk = self.twin, TaskTwin.of(self.twin)
        A = cs.vertcat(self.rows["jacobian"], tk.task_jacobian)[:, list(self.ik_columns)]
        rhs = cs.vertcat(self.closure_rhs, tk.task_error)
        residual = cs.vertcat(tw.relative_closure_residual, tk.relative_task_error)
        scales = JacobianScales.of(self.mech)
        return self._newton("ik", A, rhs, residual, self.ik_columns, self.dx_ik, self.y, lambda e: e,
                            np.concatenate([scales.constraint_rows, scales.task_rows]))

    @functools.cached_property
    def _rates(self) -> Expr:
        """Joint rates (nv) for the actuated rates ``qd``, idle motions held."""
        k = len(self.idle)
        return self.dyn._rates(cs.vertcat(self.twin.qd, cs.DM.zeros(k)))

    def task_value(self) -> cs.Function:
        """``q -> y``: the task value (as :meth:`pkm.core.kinematics.task.TaskMap.value`: positions, Z-Y-X angles,
        a pose's quaternion ``x y z w``, the joint outputs)."""
        tw, tk = self.twin, TaskTwin.of(self.twin)
        out: list = []
        for fid, comps in tk._task_groups():
            M = tw.frame_placement(fid)
            if comps == ("pose",):
                out += [M.p, quaternion(M.R)]
                continue
            rpy = zyx_angles(M.R)
            out += [M.p[{"x": 0, "y": 1, "z": 2}[c]] if c in "xyz" else rpy[("roll", "pitch", "yaw").index(c)]
                    for c in comps]
        out += [tw.q[j.idx_q] for j in self.mech.task_joints]
        return _function("task_value", [("q", tw.q)], [("y", cs.vertcat(*out))])

    def jacobians(self) -> cs.Function:
        """``q -> (J, K, pivot)``: the forward Jacobian ``J`` (task rates per actuated rate, task size x na), the
        inverse ``K`` (na x task size) and the smallest relative pivot of the two factorisations."""
        tw, tk = self.twin, TaskTwin.of(self.twin)
        J = cs.jacobian(tk.task_jacobian @ self._rates, tw.qd)
        A = cs.vertcat(self.rows["jacobian"], tk.task_jacobian)[:, list(self.ik_columns)]
        lu = PivotedLU(A, tw.at_reference(A))
        n_closure = self.rows["jacobian"].shape[0]
        at = {c: r for r, c in enumerate(self.ik_columns)}
        cols = []
        for k in range(tk.task_jacobian.shape[0]):
            e = cs.DM.zeros(A.shape[0])
            e[n_closure + k] = 1
            x = lu.solve(e)
            cols.append(cs.vertcat(*[x[at[int(c)]] for c in self.mech.act_v]))
        pivot = cs.fmin(self.fk_pivot, lu.smallest_relative_pivot())
        return _function("jacobians", [("q", tw.q)], [("J", J), ("K", cs.horzcat(*cols)), ("pivot", pivot)])

    @functools.cached_property
    def fk_pivot(self) -> Expr:
        return self.dyn.lu.smallest_relative_pivot() if self.dyn.lu is not None else cs.SX(1.0)

    def jdot_qdot(self) -> cs.Function:
        """``(q, qd) -> (c, pivot)``: the task acceleration at zero actuated acceleration, ``dJ/dt qd`` (task size),
        differentiated exactly along the closure's motion ``dq/dt = T(q) v``."""
        tw, tk = self.twin, TaskTwin.of(self.twin)
        xd = tk.task_jacobian @ self._rates
        J = cs.jacobian(xd, tw.qd)
        c = cs.jtimes(J @ tw.qd, tw.q, tw.tangent @ self._rates)
        return _function("jdot_qdot", [("q", tw.q), ("qd", tw.qd)], [("c", c), ("pivot", self.fk_pivot)])

    @functools.cached_property
    def closed_form(self) -> tuple[cs.Function | None, np.ndarray, str]:
        """The inverse kinematics of the actuated coordinates in closed form, where the mechanism is made of crank
        legs on a task-placed body: ``(function, signs, why)``, the function ``(y, signs) -> (qa, margin)`` and the
        reference's signs, or ``(None, [], why not)``.

        The pattern (a humanoid ankle's, a four-bar knee's, any RSS or RRR leg): every closure is a point closure
        between a frame on a body placed by the task alone (the task's joints, every joint on its way to the root
        a task joint) and the end of a two-joint leg: an actuated one-coordinate revolute on the fixed base, then
        any joint (a ball, a universal, a revolute), then the frame at a fixed distance ``L`` from that joint's
        centre. The centre runs on a circle as the crank turns, ``c(a) = m + cos(a) u + sin(a) v`` (read off the
        model at a = 0, pi/2, pi), so ``|c(a) - p| = L`` with ``p`` the body's point is ``A cos(a) + B sin(a) = C``:
        ``a = atan2(B, A) + s acos(C / rho)``, ``rho = sqrt(A^2 + B^2)``, ``s = ±1`` the leg's branch (``signs``; the
        reference's gives its own angle there), ``a`` then taken within pi of the reference's. ``margin`` per leg is
        ``1 - |C| / rho``: negative where the leg cannot reach, zero at its inverse singularity (the rod along the
        crank's tangent)."""
        mech, tw = self.mech, self.twin
        model = mech.model
        if mech.spec.task.components or mech.spec.task.frames:
            return None, np.zeros(0), "the task is not joint outputs alone"
        task_ids = {j.id for j in mech.task_joints}
        y_of = {j.idx_q: self.y[k] for k, j in enumerate(mech.task_joints)}
        q_task = cs.vertcat(*[y_of.get(i, tw.q[i]) for i in range(model.nq)])
        act = {int(j.id): k for k, j in enumerate(mech.actuated)}
        legs: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray, float, Expr]] = {}
        for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
            if c.type != "point":
                return None, np.zeros(0), f"closure {c.name!r} is not a point closure"
            leg = None
            for f_leg, f_body in ((fa, fb), (fb, fa)):
                j = model.frames[f_body].parentJoint
                while j > 0 and j in task_ids:
                    j = model.parents[j]
                j2 = model.frames[f_leg].parentJoint
                j1 = model.parents[j2] if j2 > 0 else 0
                if j == 0 and j1 in act and model.parents[j1] == 0 and model.joints[j1].nq == 1 \
                        and mech.joints[model.names[j1]].revolute and j1 not in legs:
                    leg = (j1, j2, f_leg, f_body)
                    break
            if leg is None:
                return None, np.zeros(0), f"closure {c.name!r} does not join a crank leg to a body the task places"
            j1, j2, f_leg, f_body = leg
            centres = [_centre(model, j1, j2, angle) for angle in (0.0, np.pi / 2, np.pi)]
            m = 0.5 * (centres[0] + centres[2])
            u, v = centres[0] - m, centres[1] - m
            if not (abs(u @ v) <= 1e-12 * (u @ u) and abs(u @ u - v @ v) <= 1e-12 * (u @ u) and u @ u > 0):
                return None, np.zeros(0), f"joint {model.names[j1]!r}: its leg's centre does not turn on a circle"
            L = float(np.linalg.norm(model.frames[f_leg].placement.translation))
            p = cs.substitute(tw.frame_placement(f_body).p, tw.q, q_task)
            legs[j1] = (m, u, v, L, p)
        if sorted(act[j] for j in legs) != list(range(mech.na)):
            return None, np.zeros(0), "not every actuator drives a crank leg"
        signs = cs.SX.sym("signs", mech.na)
        qa: list[Any] = [None] * mech.na
        margin: list[Any] = [None] * mech.na
        ref = mech.q_reference
        qa_ref = mech.actuated_q(ref)
        for j1, (m, u, v, L, p) in legs.items():
            k = act[j1]
            d = cs.DM(m) - p
            A, B = 2 * cs.dot(d, cs.DM(u)), 2 * cs.dot(d, cs.DM(v))
            C = L * L - cs.dot(d, d) - float(u @ u)
            rho = cs.sqrt(A * A + B * B)
            ratio = C / rho
            a = cs.atan2(B, A) + signs[k] * cs.acos(cs.fmin(cs.fmax(ratio, -1.0), 1.0))
            qa[k] = a - 2 * np.pi * cs.floor((a - float(qa_ref[k]) + np.pi) / (2 * np.pi))  # (near the reference's)
            margin[k] = 1 - cs.fabs(ratio)
        fun = _function("ik_closed", [("y", self.y), ("signs", signs)],
                        [("qa", cs.vertcat(*qa)), ("margin", cs.vertcat(*margin))])
        y_ref = TaskMap.of(mech).value(ref)
        chosen = []
        for k in range(mech.na):  # the reference's branch of each leg
            gaps = {}
            for s_k in (1.0, -1.0):
                trial = np.ones(mech.na)
                trial[k] = s_k
                gaps[s_k] = abs(float(np.array(fun(y_ref, trial)[0])[k, 0]) - qa_ref[k])
            best = min(gaps, key=lambda x: gaps[x])
            if gaps[best] > 1e-8:
                return None, np.zeros(0), (f"the closed form misses the reference of {mech.actuated_names[k]} by "
                                           f"{gaps[best]:.3g}")
            chosen.append(best)
        return fun, np.array(chosen), ""

    # ---------------------------------------------------------------- dynamics
    def inverse_dynamics(self) -> cs.Function:
        """``(q, qd, qdd) -> (tau, pivot)``: the actuator efforts (:func:`pkm.inverse_dynamics`'s, projected; with
        idle motions ``M_a qdd + h_a``, as :func:`pkm.actuator_model`)."""
        tw, d = self.twin, self.dyn
        if self.idle:
            tau, pivot = d.mass_matrix @ tw.qdd + d.bias, d.pivot
        else:
            tau, pivot = tw.inverse_dynamics, tw.passive_lu.smallest_relative_pivot()
        return _function("inverse_dynamics", [("q", tw.q), ("qd", tw.qd), ("qdd", tw.qdd)],
                         [("tau", tau), ("pivot", pivot)])

    def mass_matrix(self) -> cs.Function:
        """``q -> (M, pivot)``: ``M_a`` (na x na, column-major), as :func:`pkm.mass_matrix`."""
        return _function("mass_matrix", [("q", self.twin.q)], [("M", self.dyn.mass_matrix), ("pivot", self.dyn.pivot)])

    def gravity(self) -> cs.Function:
        """``q -> (g, pivot)``: the efforts that hold the mechanism still, as :func:`pkm.gravity_efforts`."""
        return _function("gravity", [("q", self.twin.q)], [("g", self.dyn.gravity), ("pivot", self.dyn.pivot)])


def _centre(model: pin.Model, j1: int, j2: int, angle: float) -> np.ndarray:
    """The origin of joint ``j2`` (child of ``j1``, whose parent is the base) with ``j1`` at ``angle``, the others at 0."""
    q = pin.neutral(model)
    q[model.joints[j1].idx_q] = angle
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    return np.array(data.oMi[j2].translation)


def _function(name: str, inputs: list[tuple[str, Expr]], outputs: list[tuple[str, Expr]]) -> cs.Function:
    values = cs.cse([cs.densify(cs.SX(e)) for _, e in outputs])
    return cs.Function(name, [s for _, s in inputs], values, [n for n, _ in inputs], [n for n, _ in outputs])


def quaternion(R: Expr) -> Expr:
    """The unit quaternion ``(x, y, z, w)`` of the rotation matrix ``R`` with ``w >= 0`` (Shepperd's method: the
    largest of ``w, x, y, z`` from the diagonal, the others from the off-diagonal sums, so that no component comes
    from a small square root), as :class:`pinocchio.Quaternion` gives it up to sign."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    cands = [
        (t, lambda: _q_w(R, t)),
        (R[0, 0], lambda: _q_x(R)),
        (R[1, 1], lambda: _q_y(R)),
        (R[2, 2], lambda: _q_z(R)),
    ]
    best_w = cs.logic_and(cs.logic_and(t >= R[0, 0], t >= R[1, 1]), t >= R[2, 2])
    best_x = cs.logic_and(R[0, 0] >= R[1, 1], R[0, 0] >= R[2, 2])
    best_y = R[1, 1] >= R[2, 2]
    qw, qx, qy, qz = (f() for _, f in cands)
    q = cs.if_else(best_w, qw, cs.if_else(best_x, qx, cs.if_else(best_y, qy, qz)))
    return q * cs.sign(q[3] + (q[3] == 0))  # w >= 0


def _q_w(R: Expr, t: Expr) -> Expr:
    s = 2 * cs.sqrt(cs.fmax(1 + t, 1e-300))
    return cs.vertcat((R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, s / 4)


def _q_x(R: Expr) -> Expr:
    s = 2 * cs.sqrt(cs.fmax(1 + R[0, 0] - R[1, 1] - R[2, 2], 1e-300))
    return cs.vertcat(s / 4, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s, (R[2, 1] - R[1, 2]) / s)


def _q_y(R: Expr) -> Expr:
    s = 2 * cs.sqrt(cs.fmax(1 + R[1, 1] - R[0, 0] - R[2, 2], 1e-300))
    return cs.vertcat((R[0, 1] + R[1, 0]) / s, s / 4, (R[1, 2] + R[2, 1]) / s, (R[0, 2] - R[2, 0]) / s)


def _q_z(R: Expr) -> Expr:
    s = 2 * cs.sqrt(cs.fmax(1 + R[2, 2] - R[0, 0] - R[1, 1], 1e-300))
    return cs.vertcat((R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, s / 4, (R[1, 0] - R[0, 1]) / s)


__all__ = ["MODE_BITS", "Block", "ExportError", "ExportModel", "Newton", "c_name", "diagonal_blocks", "quaternion"]
