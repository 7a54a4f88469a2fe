r"""The efforts along a path as a function of the path speed: :math:`\tau = a(s)\,\ddot s + b(s)\,\dot s^2 + c(s) +
d(s)\,\dot s` (for :math:`\dot s \ge 0`).

Along :math:`q_a(s)`, :math:`\dot q_a = q_a' \dot s` and :math:`\ddot q_a = q_a' \ddot s + q_a'' \dot s^2`; the
actuator-space model :math:`M_a \ddot q_a + h_a(q, \dot q_a) = \tau_a + f_a` (:mod:`pkm.core.dynamics.model`) with
:math:`h_a(q, \dot q_a) - g_a(q)` quadratic in :math:`\dot q_a` (Coriolis, centrifugal, closure drift) gives

$$
a = M_a q_a', \qquad b = M_a q_a'' + h_a(q, q_a') - g_a(q), \qquad
c = g_a(q) + \hat G^\top F \operatorname{sgn}(\hat G q_a'), \qquad d = \hat G^\top D \hat G q_a'
$$

(``F``, ``D`` the joints' Coulomb and viscous friction, :math:`\hat G` the passive map). :math:`q_a'` and
:math:`q_a''` come from the inverse kinematics along the path and the inverse Jacobian and its derivative
(:func:`pkm.follow_task`: :func:`pkm.inverse_velocities` and :func:`pkm.inverse_accelerations` at :math:`\dot y =
y'`, :math:`\ddot y = y''`); for an actuator-space path they are the path's own derivatives.

Departure from the model: Coulomb's sign is taken exact (:math:`\operatorname{sgn}`), where
:func:`pkm.actuator_model` smooths it as :math:`\tanh(v / 10^{-3})`; the two differ only below 1 mm/s or mrad/s.

**Payload**: a point mass at the end-effector frame's origin, added to the body that carries the frame
(:func:`with_payload`): every route (the model, the kernels, :func:`pkm.inverse_dynamics`) sees it.

**Two routes**: the generic core (per point, exact), or the compiled kernels (:class:`pkm.Kernels`:
``ik_path`` warm-started, ``inverse_jacobian``, ``mass_and_bias``, ``gravity``, ``velocities`` in batches), where
:math:`q_a''` is the derivative of :math:`q_a'(s) = J^{-1} y'(s)` along the path by Richardson-extrapolated central
differences (steps 1e-3 and 5e-4 in s: truncation O(h⁴)); tests hold both to 1e-9 relative of each other and of
:func:`pkm.inverse_dynamics`. Idle motions (the humanoid ankle's rods spinning between their balls) are held in the
kernels' inverse kinematics, one coordinate each, and mass-orthogonal in their model, as the core's; friction at
the actuated joints alone reads the passive map's identity rows (:func:`friction_map`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.timing.path import GeometricPath
from pkm.errors import ConvergenceError, InvalidInputError, PathError, SingularityError, UnreachableError
from pkm.validation import as_scalar

_FD = 1e-3  # the Richardson step in s of the compiled route's q_a''
_PAYLOADS: dict[tuple[int, float], Mechanism] = {}


@dataclass(frozen=True)
class PathCoefficients:
    r"""The coefficients along a path at grid points ``s`` (module doc); rows per point.

    Attributes:
        s: The grid (n,) in [0, 1].
        q: The configurations (n x nq).
        y: The path's values (n x value size).
        dy, ddy: The path's derivatives (n x rate size).
        qa, dqa, ddqa: :math:`q_a, q_a', q_a''` (n x na) [rad, m per unit s].
        a, b, c, d: The effort coefficients (n x na) [N m, N].
        gravity: :math:`g_a` (n x na), the part of ``c`` that holds the mechanism still.
        route: ``"core"`` or what ran the kernels.
    """

    s: np.ndarray
    q: np.ndarray
    y: np.ndarray
    dy: np.ndarray
    ddy: np.ndarray
    qa: np.ndarray
    dqa: np.ndarray
    ddqa: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    gravity: np.ndarray
    route: str

    def efforts(self, sdd: np.ndarray, sd: np.ndarray) -> np.ndarray:
        r""":math:`a \ddot s + b \dot s^2 + c + d \dot s` (n x na) for per-point ``sdd``, ``sd >= 0`` (n,)."""
        sdd, sd = np.asarray(sdd, dtype=float)[:, None], np.asarray(sd, dtype=float)[:, None]
        return self.a * sdd + self.b * sd * sd + self.c + self.d * sd


def with_payload(mech: Mechanism, payload: float) -> Mechanism:
    """``mech`` with a point mass ``payload`` [kg] at its end-effector frame's origin, added to the inertia of the
    body that carries the frame (:func:`pkm.core.twin.design.design_mechanism`); ``mech`` itself for 0. Cached per
    mechanism and mass.

    Raises:
        InvalidInputError: a negative or non-finite payload; a mechanism without an end effector.
    """
    mech = check_mechanism(mech)
    m = as_scalar(payload, "payload", low=0.0)
    if m == 0.0:
        return mech
    key = (id(mech), m)
    if key in _PAYLOADS and _PAYLOADS[key].name == mech.name:
        return _PAYLOADS[key]
    if not mech.ee_frame:
        raise InvalidInputError("payload", "the mechanism has no end-effector frame to carry a payload", payload)
    from pkm.core.model.bodies import BODY_FIELDS, body_names
    from pkm.core.twin.design import design_mechanism

    frame = mech.model.frames[mech.ee_frame]
    jid = frame.parentJoint
    body = body_names(mech.model)[jid - 1]
    point = pin.Inertia(m, frame.placement.translation, np.zeros((3, 3)))
    theta = (mech.model.inertias[jid] + point).toDynamicParameters()
    out = design_mechanism(mech, {f"{body}.{f}": float(v) for f, v in zip(BODY_FIELDS, theta)})
    if len(_PAYLOADS) > 16:
        _PAYLOADS.clear()
    _PAYLOADS[key] = out
    return out


def _friction(mech: Mechanism, G: np.ndarray, dqa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Ĝᵀ F sgn(Ĝ q_a'), Ĝᵀ D Ĝ q_a')`` for ``G`` (n x nv x na)."""
    D, F = np.asarray(mech.model.damping), np.asarray(mech.model.friction)
    v = np.einsum("kij,kj->ki", G, dqa)
    return np.einsum("kij,ki->kj", G, F * np.sign(v)), np.einsum("kij,ki->kj", G, D * v)


def friction_map(mech: Mechanism, n: int, passive: Callable[[], np.ndarray]) -> np.ndarray | None:
    """The passive map ``Ĝ`` (n x nv x na) as the friction reads it: None where no joint rubs (no damping nor
    Coulomb friction in the model); where only actuated joints rub, the identity on their rows (``Ĝ``'s rows there;
    the others, which the friction does not read, zero); else ``passive()``, the map itself at the n points."""
    rubbing = np.flatnonzero((np.asarray(mech.model.damping) != 0.0) | (np.asarray(mech.model.friction) != 0.0))
    if not rubbing.size:
        return None
    act = np.asarray(mech.act_v)
    if not np.isin(rubbing, act).all():
        return passive()
    G = np.zeros((n, mech.nv, mech.na))
    G[:, act, np.arange(mech.na)] = 1.0
    return G


def _core(mech: Mechanism, path: GeometricPath, s: np.ndarray, q0: np.ndarray | None) -> PathCoefficients:
    from pkm.core.dynamics.model import actuator_model
    from pkm.core.kinematics.trajectory import follow_actuators, follow_task

    y, dy, ddy = path.evaluate(s)
    follow = follow_task if path.space == "task" else follow_actuators
    traj = follow(mech, y, dy, ddy, q0=q0, efforts=False, tol=1e-12)
    for jump in traj.jumps:
        k = jump.index
        if jump.reason == "did not converge":
            raise PathError(k, s[k], "workspace", f"the inverse kinematics does not reach the path here "
                                                  f"({jump.detail}): outside the workspace")
        if jump.reason in ("fold", "singular", "corrected", "branch"):
            raise PathError(k, s[k], "singularity", f"the path crosses a singularity or changes branch here "
                                                    f"({jump.reason}: {jump.detail})")
    n, na = len(s), mech.na
    M, h, g = np.empty((n, na, na)), np.empty((n, na)), np.empty((n, na))
    G = np.empty((n, mech.nv, na))
    for k in range(n):
        try:
            model = actuator_model(mech, traj.q[k], traj.actuated_velocity[k])
        except SingularityError as exc:
            raise PathError(k, s[k], "singularity", str(exc)) from None
        M[k], h[k], g[k], G[k] = model.M, model.h, model.g, model.G
    return _assemble(mech, s, traj.q, y, dy, ddy, traj.actuated, traj.actuated_velocity,
                     traj.actuated_acceleration, M, h, g, G, "core")


def _assemble(mech: Mechanism, s: np.ndarray, q: np.ndarray, y: np.ndarray, dy: np.ndarray, ddy: np.ndarray,
              qa: np.ndarray, dqa: np.ndarray, ddqa: np.ndarray, M: np.ndarray, h: np.ndarray, g: np.ndarray,
              G: np.ndarray | None, route: str) -> PathCoefficients:
    a = np.einsum("kij,kj->ki", M, dqa)
    b = np.einsum("kij,kj->ki", M, ddqa) + h - g
    coulomb, viscous = (np.zeros_like(a), np.zeros_like(a)) if G is None else _friction(mech, G, dqa)
    out = PathCoefficients(s, q, y, dy, ddy, qa, dqa, ddqa, a, b, g + coulomb, viscous, g, route)
    bad = np.flatnonzero(~(np.isfinite(a).all(axis=1) & np.isfinite(b).all(axis=1)))
    if bad.size:
        k = int(bad[0])
        raise PathError(k, s[k], "singularity", "non-finite effort coefficients (a singular state)")
    return out


def _kernels(mech: Mechanism, kernels: object, path: GeometricPath, s: np.ndarray,
             q0: np.ndarray | None) -> PathCoefficients:
    from pkm.core.twin.kernels import Kernels

    if not isinstance(kernels, Kernels) or kernels.mech is not mech:
        raise InvalidInputError("kernels", "expected pkm.Kernels of the mechanism timed (with its payload: "
                                           "pkm.core.timing.with_payload)", kernels)
    n, h = len(s), _FD
    offsets = np.array([-h, -h / 2, 0.0, h / 2, h])
    ss = (s[:, None] + offsets[None]).ravel()  # (interleaved: the warm start follows the path)
    ya, d1a, _ = path._raw(ss)  # (continued past the ends: the differences stay central)
    if path.space == "task":
        try:
            res = kernels.ik_path(ya, q0, tol=1e-14)
        except (UnreachableError, ConvergenceError):  # (a point the kernels' core fallback cannot reach either:
            return _core(mech, path, s, q0)  # the core names it)
        bad = np.flatnonzero(res.residual > 1e-9)
        if bad.size:
            k = int(bad[0]) // 5
            raise PathError(k, s[k], "workspace", f"the inverse kinematics does not reach the path here (residual "
                                                  f"{res.residual[bad[0]]:.3g}): outside the workspace")
        Q = res.q
        Ji = kernels.inverse_jacobian(Q).reshape(len(Q), mech.na, d1a.shape[1])  # (a 1 x 1 comes back as a column)
        dqa_all = np.einsum("kij,kj->ki", Ji, d1a)
        qa_all = Q[:, mech.act_q]
    else:
        Q, qa_all, dqa_all = kernels.close_loops_path(ya, q0).q, ya, d1a
    D = dqa_all.reshape(n, 5, -1)
    ddqa = (4.0 * (D[:, 3] - D[:, 1]) / h - (D[:, 4] - D[:, 0]) / (2.0 * h)) / 3.0
    if path.space == "actuated":
        ddqa = path.evaluate(s)[2]
    q, dqa, qa = Q[2::5], D[:, 2], qa_all[2::5]
    M, hq = kernels.mass_and_bias(q, dqa)
    M = M.reshape(n, mech.na, mech.na)
    g = kernels.gravity(q)
    G = friction_map(mech, n, lambda: np.stack([kernels.velocities(q, np.tile(e, (n, 1))) for e in np.eye(mech.na)],
                                               axis=2))
    y0, dy0, ddy0 = path.evaluate(s)
    return _assemble(mech, s, q, y0, dy0, ddy0, qa, dqa, ddqa, M, hq, g, G, f"kernels ({kernels.how.get('mass_and_bias', '')})")


def path_coefficients(mech: Mechanism, path: GeometricPath, s: np.ndarray, *, q0: np.ndarray | None = None,
                      kernels: object = None) -> PathCoefficients:
    """The coefficients :math:`a, b, c, d` at grid points ``s`` (module doc), by the generic core or by compiled
    ``kernels`` (:class:`pkm.Kernels` of ``mech``).

    Raises:
        PathError: the path leaves the workspace (``limit="workspace"``) or crosses a singularity
            (``"singularity"``) at a grid point.
    """
    mech = check_mechanism(mech)
    s = np.asarray(s, dtype=float)
    if kernels is None:
        return _core(mech, path, s, q0)
    return _kernels(mech, kernels, path, s, q0)


__all__ = ["PathCoefficients", "friction_map", "path_coefficients", "with_payload"]
