r"""Measurement models of a calibration: residuals and their Jacobians with respect to the parameters.

A **calibration model** (:class:`CalibrationModel`) is a mechanism, its calibration parameters ``x``
(:mod:`~pkm.core.calibration.parameters`) and what is measured at each pose, given the actuators' readings ``m``:

* ``pose``: the target's placement in the tracker's frame, ``T(x)^{-1} \, {}^0M_{ee}(q) \, E(x)``; residual
  ``[p - p_m; \tfrac12 \mathrm{vee}(R_m^T R - R^T R_m)]`` [m, rad] (the rotation residual is ``sin`` of the angle
  times the axis, in the measured frame: smooth through zero, the angle to third order);
* ``position``: that placement's translation [m];
* ``planar``: its ``x, y`` [m] and yaw [rad] (the angle's difference wrapped to ``(-pi, pi]``);
* ``passive``: the readings of encoders on passive joints, ``q_j + offset_j`` [rad or m] (self-calibration: the
  loops closed by the mechanism itself, no external instrument).

The configuration ``q(x, m)`` solves the loop closure ``c(q, x) = 0`` with the actuated coordinates
``q_a = gain * m + offset`` (Newton's method on the tangent space, from the nominal mechanism's closed
configuration, each step halved where it would raise the residual), the closure rows ``A.p - B.p`` for a point closure and, for a frame closure,
``[A.p - B.p; \tfrac12 \mathrm{vee}(A.R^T B.R - B.R^T A.R)]`` (the same zero set as the core's ``log6``, smooth
through it). **The Jacobian** ``dy/dx`` follows from the implicit function theorem through the closure: with
``g(q, x, m) = [c; q_a - gain\, m - offset] = 0``, ``dq/dx = -G_q^+ G_x`` and ``dy/dx = Y_x + Y_q \, dq/dx``,
where ``G_q, Y_q`` are the derivatives along the tangent space (``\partial/\partial q \cdot T(q)``, the twin's
:attr:`~pkm.core.twin.tree.Twin.tangent`) and ``G_x, Y_x`` the exact derivatives of the twin's expressions in the
joint origins (:mod:`pkm.core.twin.design`), all CasADi expressions differentiated symbolically. The test checks it
against finite differences of the residual, which closes the loops anew at each perturbed ``x``.

An origin component that would open an overconstrained loop (an out-of-plane error of a planar mechanism modelled
with 6-D closures) cannot be calibrated: :attr:`CalibrationModel.inadmissible` lists those dropped, and why.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as cs
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.calibration.parameters import CalibrationParameters, calibration_parameters, check_kind
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.origins import ORIGIN
from pkm.core.model.scale import JacobianScales
from pkm.errors import ConvergenceError, InvalidInputError, PkmError
from pkm.validation import instance_of, wrap_angle

#: The closure is solved to this infinity norm, a length relative to the mechanism's characteristic length (its
#: closure rows' and a prismatic actuator's row over ``L``), an angle in rad.
CLOSURE_TOL = 1e-13
#: Newton iterations at most per closure.
MAX_NEWTON = 30
#: An origin component is inadmissible where its closure derivative leaves the closure Jacobian's range by more
#: than this, relative to the derivative's norm.
ADMISSIBLE = 1e-8


def _rpy(r: Any, p: Any, y: Any) -> cs.SX:
    from pkm.core.twin.design import _rpy_matrix

    return _rpy_matrix(r, p, y)


def _vee_skew(A: cs.SX) -> cs.SX:
    """``vee((A - A^T) / 2)``."""
    return 0.5 * cs.vertcat(A[2, 1] - A[1, 2], A[0, 2] - A[2, 0], A[1, 0] - A[0, 1])


@dataclass(frozen=True)
class Rows:
    """What one pose contributes: ``labels`` of its residual rows and their ``units``."""

    labels: tuple[str, ...]
    units: tuple[str, ...]


class CalibrationModel:
    """A mechanism, its calibration parameters and a measurement model (module doc).

    Args:
        mech: The mechanism (built from URDF text: its origins become the twin's design inputs).
        kind: ``pose``, ``position``, ``planar`` or ``passive`` (:data:`~pkm.core.calibration.parameters.KINDS`).
        parameters: The parameters (default :func:`~pkm.core.calibration.parameters.calibration_parameters` of
            ``kind``, with ``sensors``).
        sensors: The passive joints read by encoders (``passive``; default every passive joint with one
            coordinate).

    Raises:
        UnknownNameError: an unknown ``kind`` or sensor.
        InvalidInputError: a ``passive`` model without sensors, or a mechanism without an end effector for the
            others.
    """

    def __init__(self, mech: Mechanism, kind: str = "pose", parameters: CalibrationParameters | None = None,
                 sensors: Sequence[str] | None = None):
        from pkm.core.twin.design import with_merged_bodies
        from pkm.core.twin.tree import Twin

        self.mech = mech = check_mechanism(mech)
        self.kind = kind = check_kind(kind)
        self.twin = tw = Twin(mech)  # (replaced below by the twin with design inputs)
        idle = self._idle_joints()
        if kind == "passive":
            one = [n for n, j in mech.joints.items() if j.nv == 1 and n not in mech.actuated_names and n not in idle]
            self.sensors = tuple(one if sensors is None else sensors)
            if not self.sensors:
                raise InvalidInputError("sensors", "self-calibration needs encoders on passive joints", sensors)
            moved = [s for s in self.sensors if s in idle]
            if moved:
                raise InvalidInputError("sensors", f"{moved[0]!r} moves in an idle motion (the actuators do not fix "
                                                   f"it): its reading cannot be predicted", moved[0])
        else:
            self.sensors = ()
            if not mech.ee_frame:
                raise InvalidInputError("kind", f"{mech.name} has no end effector: use kind='passive' with "
                                                f"encoders on passive joints", kind)
        P = parameters if parameters is not None else calibration_parameters(mech, kind, sensors=self.sensors)
        origin_names = [P.names[i] for i in P.origins]
        self.twin = tw = Twin(mech, with_merged_bodies(mech, origin_names))
        self._tw_index = {n: k for k, n in enumerate(tw.design.names)}
        P, self.inadmissible = self._admissible(P)
        self.parameters = P
        self._functions()

    # ------------------------------------------------------------------ symbols
    def _expressions(self, P: CalibrationParameters) -> tuple[cs.SX, cs.SX, cs.SX, cs.SX]:
        """``(x, m, g, y)``: the parameter and reading symbols, the closure with actuated rows, the measurement."""
        mech, tw = self.mech, self.twin
        x, m = cs.SX.sym("x", len(P)), cs.SX.sym("m", mech.na)
        pd = [cs.SX(float(v)) for v in tw.design.base]
        for i in P.origins:
            pd[self._tw_index[P.names[i]]] = x[i]
        value = dict(zip(P.names, [x[i] for i in range(len(P))]))
        rows = [_closure(tw)]
        for k, a in enumerate(mech.actuated_names):
            qa = tw.q[int(mech.act_q[k])]
            rows.append(qa - value.get(f"{a}.gain", 1.0) * m[k] - value.get(f"{a}.offset", 0.0))
        g = cs.vertcat(*rows)
        if self.kind == "passive":
            y = cs.vertcat(*[tw.q[mech.joints[s].idx_q] + value.get(f"{s}.offset", 0.0) for s in self.sensors])
        else:
            def frame(name: str) -> tuple[cs.SX, cs.SX]:
                comp = [value.get(f"{name}.{c}", 0.0) for c in ORIGIN]
                return _rpy(*comp[3:]), cs.vertcat(*comp[:3])

            (Rt, pt), (Re, pe) = frame("tracker"), frame("target")
            M = tw.frame_placement(mech.ee_frame)
            R = Rt.T @ M.R @ Re
            p = Rt.T @ (M.p + M.R @ pe - pt)
            if self.kind == "pose":
                y = cs.vertcat(p, cs.reshape(R, 9, 1))
            elif self.kind == "position":
                y = p
            else:
                y = cs.vertcat(p[0], p[1], cs.atan2(R[1, 0], R[0, 0]))
        g, y = cs.substitute([g, y], [tw.p], [cs.vertcat(*pd)])
        return x, m, g, y

    def _functions(self) -> None:
        tw = self.twin
        x, m, g, y = self._expressions(self.parameters)
        T = tw.tangent
        Gq, Yq = cs.jacobian(g, tw.q) @ T, cs.jacobian(y, tw.q) @ T
        d = cs.densify  # (dense outputs: the exact route reads them entry by entry)
        self._close = cs.Function("close", [tw.q, m, x], [d(g), d(Gq)])
        self._full = cs.Function("full", [tw.q, m, x], [d(g), d(Gq), d(cs.jacobian(g, x)), d(y), d(Yq),
                                                          d(cs.jacobian(y, x))])
        self._maps: dict[tuple[str, int], cs.Function] = {}

    def _idle_joints(self) -> tuple[str, ...]:
        """The joints that move in the idle motions at the reference (motions the actuators do not fix: the
        closure with actuated rows has a null space); :attr:`idle` counts those motions."""
        mech, tw = self.mech, self.twin
        rows = [_closure(tw), *(tw.q[int(i)] for i in mech.act_q)]
        G = np.array(cs.Function("g", [tw.q], [cs.jacobian(cs.vertcat(*rows), tw.q) @ tw.tangent])(mech.q_reference))
        _, s, Vt = np.linalg.svd(G)
        rank = int(np.sum(s > 1e-10 * s[0])) if s.size else 0
        null = Vt[rank:]
        #: The number of idle motions at the reference.
        self.idle = len(null)
        return tuple(n for n, j in mech.joints.items()
                     if len(null) and np.max(np.abs(null[:, j.idx_v:j.idx_v + j.nv])) > 1e-8)

    def _admissible(self, P: CalibrationParameters) -> tuple[CalibrationParameters, tuple[str, ...]]:
        """``P`` without the origin components that would open an overconstrained loop (module doc)."""
        mech, tw = self.mech, self.twin
        x, m, g, _ = self._expressions(P)
        T = tw.tangent
        f = cs.Function("adm", [tw.q, m, x], [cs.jacobian(g, tw.q) @ T, cs.jacobian(g, x)])
        Gq, Gx = (np.array(a) for a in f(mech.q_reference, mech.actuated_q(mech.q_reference), P.nominal))
        U, s, _ = np.linalg.svd(Gq)
        rank = int(np.sum(s > 1e-10 * s[0])) if s.size else 0
        N = U[:, rank:]
        if N.shape[1] == 0:
            return P, ()
        leak = np.linalg.norm(N.T @ Gx, axis=0) / np.maximum(np.linalg.norm(Gx, axis=0), 1e-300)
        bad = [k for k in P.origins if leak[k] > ADMISSIBLE and np.linalg.norm(Gx[:, k]) > 0.0]
        if not bad:
            return P, ()
        keep = [k for k in range(len(P)) if k not in bad]
        return P.subset(keep), tuple(P.names[k] for k in bad)

    def _map(self, which: str, n: int) -> cs.Function:
        key = (which, n)
        if key not in self._maps:
            if len(self._maps) > 8:
                self._maps.clear()
            self._maps[key] = (self._close if which == "close" else self._full).map(n)
        return self._maps[key]

    # ------------------------------------------------------------------ shapes
    @functools.cached_property
    def rows(self) -> Rows:
        """The residual rows of one pose: their labels and units."""
        if self.kind == "pose":
            return Rows(("x", "y", "z", "rx", "ry", "rz"), ("m",) * 3 + ("rad",) * 3)
        if self.kind == "position":
            return Rows(("x", "y", "z"), ("m",) * 3)
        if self.kind == "planar":
            return Rows(("x", "y", "yaw"), ("m", "m", "rad"))
        return Rows(tuple(f"q.{s}" for s in self.sensors),
                    tuple("rad" if self.mech.joints[s].revolute else "m" for s in self.sensors))

    @property
    def names(self) -> tuple[str, ...]:
        """The parameters' names."""
        return self.parameters.names

    def _readings(self, readings: ArrayLike) -> np.ndarray:
        from pkm.validation import as_array

        M = as_array(readings, "readings", "motor readings (n x na) [rad or m]")
        M = np.atleast_2d(M)
        if M.ndim != 2 or M.shape[1] != self.mech.na:
            raise InvalidInputError("readings", f"expected n x {self.mech.na} readings ({', '.join(self.mech.actuated_names)})",
                                    M.shape)
        bad = np.argwhere(~np.isfinite(M))
        if bad.size:
            r, c = bad[0]
            raise InvalidInputError(f"m.{self.mech.actuated_names[c]}", f"row {r + 1}: {M[r, c]} is not a finite "
                                                                         f"reading", M[r, c])
        return M

    def vector(self, x: ArrayLike | None) -> np.ndarray:
        """``x`` checked (default: the nominal parameters)."""
        if x is None:
            return self.parameters.nominal.copy()
        out = np.asarray(x, dtype=float)
        if out.shape != (len(self.parameters),) or not np.all(np.isfinite(out)):
            raise InvalidInputError("x", f"expected {len(self.parameters)} finite parameter values", x)
        return out

    # ------------------------------------------------------------------ closure
    def seeds(self, readings: ArrayLike) -> np.ndarray:
        """Closed configurations of the nominal mechanism at ``readings`` (the Newton iterations' seeds)."""
        from pkm.core.kinematics.solve import close_loops

        M = self._readings(readings)
        out = np.empty((len(M), self.mech.nq))
        q = self.mech.q_reference
        for k, qa in enumerate(M):
            try:
                q = close_loops(self.mech, qa, q).q
            except PkmError as exc:  # (any failure of the solver: said with the row)
                raise InvalidInputError("readings", f"row {k + 1}: the nominal mechanism does not close at "
                                                    f"{np.round(qa, 6).tolist()} ({exc})", qa) from None
            out[k] = q
        return out

    def close(self, x: ArrayLike | None, readings: ArrayLike, seeds: ArrayLike | None = None) -> np.ndarray:
        """The configurations (n x nq) closed at ``readings`` with parameters ``x``, Newton's method from
        ``seeds`` (default :meth:`seeds`).

        Raises:
            ConvergenceError: a pose does not close (its row named).
        """
        Q, worst = self._newton(x, readings, seeds)
        if np.all(worst < CLOSURE_TOL):
            return Q
        k = int(np.argmax(worst))
        raise ConvergenceError(f"loop closure of the calibration model at pose {k + 1}", float(worst[k]), MAX_NEWTON,
                               CLOSURE_TOL, detail=f"the residual counts lengths in the characteristic length L = "
                                                   f"{JacobianScales.of(self.mech).length:.4g} m, angles in rad")

    def reaches(self, x: ArrayLike | None, readings: ArrayLike) -> np.ndarray:
        """Whether the mechanism of parameters ``x`` reaches each pose of ``readings`` (n booleans): its loops close
        there by :meth:`close`'s Newton iterations from the nominal mechanism's closed configuration (the assembly
        the robot is in; a pose beyond the workspace of this robot, or across a singularity from that assembly,
        is not reached)."""
        return self._newton(x, readings, None)[1] < CLOSURE_TOL

    def _newton(self, x: ArrayLike | None, readings: ArrayLike,
                seeds: ArrayLike | None) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`close`'s iterations: the configurations and each pose's closure residual (infinity norm, lengths
        over the characteristic length), below :data:`CLOSURE_TOL` where the pose closed."""
        x, M = self.vector(x), self._readings(readings)
        Q = np.array(self.seeds(M) if seeds is None else seeds, dtype=float, copy=True)
        model = self.mech.model
        scales = JacobianScales.of(self.mech)  # (per row: a length over L, an angle in rad)
        w = np.concatenate([scales.closure_residual, 1.0 / scales.actuated])[:, None]
        f = self._map("close", len(M))
        g, Gq = f(Q.T, M.T, x)
        for _ in range(MAX_NEWTON):
            g = np.array(g).T  # (n, rows)
            worst = np.max(np.abs(g * w.T), axis=1)
            if np.all(worst < CLOSURE_TOL):
                return Q, worst
            G = np.array(Gq).reshape(g.shape[1], len(M), -1).transpose(1, 0, 2)
            dq = -np.einsum("kij,kj->ki", np.linalg.pinv(G), g)
            step = np.ones(len(M))
            for _ in range(8):  # (halved where the residual grows: a pose far from its seed)
                new = np.array([pin.integrate(model, q, t * d) for q, d, t in zip(Q, dq, step)])
                g_new, Gq_new = f(new.T, M.T, x)
                grew = np.max(np.abs(np.array(g_new) * w), axis=0) > np.maximum(worst, CLOSURE_TOL)
                if not grew.any():
                    break
                step[grew] *= 0.5
            Q, g, Gq = new, g_new, Gq_new
        return Q, worst

    # ------------------------------------------------------------------ measurements
    def evaluate(self, x: ArrayLike | None, readings: ArrayLike, Q: np.ndarray | None = None,
                 jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
        """``(y, dy/dx, Q)``: the measurement function's values (n x ny: pose ``p`` then ``R`` column-major,
        position ``p``, planar ``x, y, yaw``, passive the readings), its Jacobian (n x ny x len(x), the implicit
        function theorem: module doc) and the closed configurations."""
        x, M = self.vector(x), self._readings(readings)
        if Q is None:
            Q = self.close(x, M)
        n = len(M)
        _, Gq, Gx, y, Yq, Yx = (np.array(a) for a in self._map("full", n)(Q.T, M.T, x))
        y = y.T
        if not jacobian:
            return y, None, Q
        nv, p = self.mech.nv, len(x)

        def stack(A: np.ndarray, cols: int) -> np.ndarray:
            return A.reshape(A.shape[0], n, cols).transpose(1, 0, 2)

        Gq, Gx, Yq, Yx = stack(Gq, nv), stack(Gx, p), stack(Yq, nv), stack(Yx, p)
        dq = -np.linalg.pinv(Gq) @ Gx
        return y, Yx + Yq @ dq, Q

    def residual(self, y: np.ndarray, measured: ArrayLike, J: np.ndarray | None = None) \
            -> tuple[np.ndarray, np.ndarray | None]:
        """The residuals (n x rows, SI: :attr:`rows`) of predictions ``y`` (:meth:`evaluate`) against
        ``measured`` (n x ny in :meth:`evaluate`'s layout), and their Jacobian (n x rows x len(x)) from ``J``."""
        Ym = np.asarray(measured, dtype=float)
        if self.kind == "pose":
            R, Rm = y[:, 3:].reshape(-1, 3, 3).transpose(0, 2, 1), Ym[:, 3:].reshape(-1, 3, 3).transpose(0, 2, 1)
            A = np.einsum("kji,kjl->kil", Rm, R)  # Rm^T R
            r = np.hstack([y[:, :3] - Ym[:, :3], _vee(A)])
            if J is None:
                return r, None
            dR = J[:, 3:, :].reshape(len(y), 3, 3, -1).transpose(0, 2, 1, 3)  # (column-major entries)
            dA = np.einsum("kji,kjlp->kilp", Rm, dR)
            return r, np.concatenate([J[:, :3, :], _vee(dA)], axis=1)
        r = y - Ym
        if self.kind == "planar":
            r[:, 2] = wrap_angle(r[:, 2])
        return r, J

    def mechanism(self, x: ArrayLike | None = None) -> Mechanism:
        """The mechanism with the joint origins of ``x`` (its loops assembled again at the file's reference:
        :func:`~pkm.core.twin.design.design_mechanism`); the actuators' offsets and gains and the frames stay
        with the readings and the instrument."""
        from pkm.core.twin.design import design_mechanism

        x = self.vector(x)
        return design_mechanism(self.mech, {self.names[k]: float(x[k]) for k in self.parameters.origins})

    def measure(self, x: ArrayLike | None, readings: ArrayLike) -> np.ndarray:
        """What the model measures at ``readings`` with parameters ``x`` (n x ny, :meth:`evaluate`'s layout)."""
        return self.evaluate(x, readings, jacobian=False)[0]


def check_model(model: object, name: str = "model") -> CalibrationModel:
    """``model`` itself if it is a :class:`CalibrationModel`, else :class:`InvalidInputError` saying how to get one
    (a mechanism or a configuration passed in its place)."""
    return instance_of(model, CalibrationModel, name, "a pkm.CalibrationModel (pkm.CalibrationModel(mech, kind))")


def _closure(tw: Any) -> cs.SX:
    """The closure rows of twin ``tw`` (module doc: smooth through a closed frame closure)."""
    rows = []
    for c, (fa, fb) in zip(tw.mech.spec.closures, tw.mech.closure_frames):
        A, B = tw.frame_placement(fa), tw.frame_placement(fb)
        rows.append(A.p - B.p if c.type == "point" else cs.vertcat(A.p - B.p, _vee_skew(A.R.T @ B.R)))
    return cs.vertcat(*rows)


def _vee(A: np.ndarray) -> np.ndarray:
    """``vee((A - A^T) / 2)`` over the leading axis, with trailing axes kept."""
    return 0.5 * np.stack([A[:, 2, 1] - A[:, 1, 2], A[:, 0, 2] - A[:, 2, 0], A[:, 1, 0] - A[:, 0, 1]], axis=1)


__all__ = ["ADMISSIBLE", "CLOSURE_TOL", "MAX_NEWTON", "CalibrationModel", "Rows", "check_model"]
