"""Velocity and acceleration kinematics of closed-loop mechanisms; singularity diagnostics.

With ``J_c`` the constraint Jacobian (:mod:`pkm.core.kinematics.constraints`), split into
actuated columns ``J_a`` and passive columns ``J_p``, and ``J_t`` the task Jacobian
(:mod:`pkm.core.kinematics.task`):

* *idle motions*: passive motions that move neither the closures (``J_p x = 0``) nor the task
  (``J_t x = 0``): a rod spinning about its own axis between two ball joints, two coaxial
  revolutes. They are not singularities; :func:`diagnose` reports them, and every rate and acceleration below carries
  none of them in the mass metric (``Nᵀ M v = 0``, the rates of least kinetic energy: the convention of
  :mod:`pkm.core.differential.idle`, shared with the dynamic model);
* passive rates: ``v_p = -J_p^+ J_a qd_a`` (``G = dq/dq_a``, :func:`passive_map`); undefined when,
  off the idle motions, ``J_p`` loses column rank: a *direct* (type 2) singularity, the actuators
  locked yet the task movable;
* forward Jacobian ``J_fwd = J_t G`` (task rates from actuated rates);
* inverse Jacobian: ``[J_c; J_t] v = [0; yd]``, read on the actuated rows; undefined when, off the
  idle motions, ``[J_c; J_t]`` loses column rank: an *inverse* (type 1) singularity, the task
  frozen yet the actuators movable;
* accelerations: ``J_c a + gamma_c = 0`` with the drift ``gamma_c = dJ_c/dt v``, and
  task accelerations ``J_t a + gamma_t``.

Every function taking ``(mech, q)`` also takes a :class:`~pkm.core.kinematics.configuration.Configuration` of the
mechanism for ``q`` (``Configuration.at(mech, q)``): the kinematics is then computed once for all of them.

Rank decisions compare singular values with ``rtol`` times the largest one; idle motions are those that move the
task by at most ``rtol`` times the largest singular value of ``J_t``. Both are taken of the Jacobians made
homogeneous by the mechanism's characteristic length ``L``
(:attr:`~pkm.core.model.mechanism.Mechanism.characteristic_length`, :mod:`pkm.core.model.scale`: rotation rows of
6-D closures and angular task coordinates times ``L``, prismatic columns times ``L``; every entry a length): a ratio of their singular values does not change when the mechanism is
scaled in size, so that every threshold (``rtol``, ``near``) judges a robot of 5 cm as the same robot of 5 m. A
mechanism of revolute and ball joints closed by points, whose task is a position, is left as it is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm._derived import derived
from pkm.core.differential.idle import joint_inertia, without_idle
from pkm.core.differential.indices import singularity_class
from pkm.core.kinematics import constraints
from pkm.core.kinematics.configuration import Configuration
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, SingularityError
from pkm.validation import as_tolerance, as_vector, finite_result

RTOL = 1e-9


def _at(mech: Mechanism, q: ArrayLike | Configuration) -> tuple[Mechanism, Configuration]:
    """The mechanism and its kinematics at ``q``: a :class:`Configuration` of that mechanism is used as it is (the
    kinematics computed once for every analysis at one configuration), anything else is checked (type, shape,
    finiteness, unit quaternions) and computed."""
    mech = check_mechanism(mech)
    if isinstance(q, Configuration):
        if q.mech is not mech:
            raise InvalidInputError("q", f"a Configuration of {q.mech.name!r}, not of {mech.name!r}", q.mech.name)
        return mech, q
    return mech, Configuration.compute(mech, mech.check_q(q))


def _svd(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Full SVD of ``A`` (m x n): ``U, s, Vt`` with ``s`` padded with zeros to ``n`` values."""
    finite_result(A, "Jacobian")
    try:
        U, s, Vt = np.linalg.svd(A, full_matrices=True)
    except np.linalg.LinAlgError as exc:
        finite_result(np.nan, "singular values", f"numpy: {exc}")
        raise
    return U, np.concatenate([s, np.zeros(A.shape[1] - len(s))]), Vt


def _complement(B: np.ndarray, n: int) -> np.ndarray:
    """An orthonormal basis (n x (n - k)) of the orthogonal complement of the orthonormal columns of ``B`` (n x k)."""
    if B.shape[1] == 0:
        return np.eye(n)
    return np.linalg.svd(B.T, full_matrices=True)[2][B.shape[1]:].T


def homogenised_pinv(J: np.ndarray, rows: np.ndarray, columns: np.ndarray, rtol: float) \
        -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """The pseudo-inverse of a block ``J`` of a closure Jacobian (its rows and the columns of some joints), taken on
    the block homogenised by the mechanism's characteristic length (``Ĵ = rows J columns``,
    :class:`~pkm.core.model.scale.JacobianScales`): ``J⁺ = columns Ĵ⁺ rows``, the singular values of ``Ĵ`` under
    ``rtol`` times its largest dropped, so that the rank decision and the minimum norm are those of the mechanism
    scaled in size. Returns ``(J⁺, s, Vt, rank)``: ``Ĵ``'s singular values (padded with zeros to its columns) and right
    singular vectors (``Vt[rank:]`` spans its null space). The one pseudo-inverse of a closure block: the passive
    joints' (:func:`pkm.diagnose`'s split, the actuator-space dynamics) and a transmission's with its outputs held."""
    U, s, Vt = _svd(rows[:, None] * J * columns)
    smax = float(s[0]) if s.size else 0.0
    r = int(np.sum(s > rtol * smax)) if smax > 0.0 else 0
    return columns[:, None] * ((Vt[:r].T / s[:r]) @ U[:, :r].T) * rows, s, Vt, r


@dataclass(frozen=True)
class _Split:
    """The motions at one configuration, split: idle, closure-keeping, singular (see the module doc).

    Every decomposition is of the Jacobians homogenised by the mechanism's characteristic length
    (:class:`~pkm.core.model.scale.JacobianScales`: rows ``r``, columns ``c``, ``Ĵ = r J c``), so that every rank
    decision and distance is the same for the mechanism scaled in size; the solutions are given back in joint rates.
    ``Ĵp`` (passive columns of ``Ĵ_c``) is inverted by :func:`homogenised_pinv`; ``ÂC = Ua diag(sa) Vat`` with
    ``Â = [Ĵ_c; Ĵ_t]`` restricted to the complement ``C`` of the idle motions (in the homogenised rates).
    """

    mech: Mechanism
    idle: np.ndarray  # (nv, k) orthonormal, zero on the actuated rows (joint rates)
    Jp_pinv: np.ndarray  # (n_passive, n_constraints): J_p's pseudo-inverse (homogenised_pinv)
    sigma_direct: float  # smallest singular value of Ĵ_p off the idle motions [m]
    smax_direct: float
    direct_direction: np.ndarray  # the task motion of the weakest passive motion (unit), n_task
    C: np.ndarray
    Ua: np.ndarray
    sa: np.ndarray
    Vat: np.ndarray
    sigma_inverse: float
    smax_inverse: float
    inverse_direction: np.ndarray  # the actuated rates of the weakest frozen-task motion (unit), na
    rows: np.ndarray  # (n_constraints + n_task,) the row factors r of [J_c; J_t]
    columns: np.ndarray  # (nv,) the column factors c

    @classmethod
    def of(cls, mech: Mechanism, Jc: np.ndarray, Jt: np.ndarray, rtol: float) -> _Split:
        scales = JacobianScales.of(mech)
        pv, nv = mech.passive_v, mech.nv
        Jp_pinv, sp, Vpt, rp = homogenised_pinv(Jc[:, pv], scales.constraint_rows, scales.columns[pv], rtol)
        Jc, Jt, col = scales.constraint(Jc), scales.task(Jt), scales.columns
        Jp, Jtp = Jc[:, pv], Jt[:, pv]
        smax_d = float(sp[0]) if len(sp) else 0.0
        N = Vpt[rp:].T  # passive motions the closures allow with the actuators locked
        t_ref = float(np.linalg.norm(Jt, 2)) if Jt.size else 0.0
        if N.shape[1]:
            _, t, Wt = _svd(Jtp @ N)
            idle_p = N @ Wt[t <= rtol * t_ref].T  # ... of those, the ones the task does not see
        else:
            idle_p = np.zeros((len(pv), 0))
        Cp = _complement(idle_p, len(pv))
        if Cp.shape[1]:
            _, sc, Wct = _svd(Jp @ Cp)
            sigma_d, weakest = float(sc[-1]), Cp @ Wct[-1]
        else:
            sigma_d, weakest = np.inf, np.zeros(len(pv))
        move = (Jtp @ weakest) / scales.task_rows  # (in the task's own coordinates)
        idle = np.zeros((nv, idle_p.shape[1]))
        idle[pv] = idle_p
        base = np.zeros((nv, len(mech.base_v)))
        base[mech.base_v, np.arange(len(mech.base_v))] = 1.0  # a floating base is an input: it does not move here
        C = _complement(np.hstack([idle, base]), nv)
        A = np.vstack([Jc, Jt])
        Ua, sa, Vat = _svd(A @ C)
        w = col * (C @ Vat[-1]) if C.shape[1] else np.zeros(nv)
        act = w[mech.act_v]
        idle = scales.joint_motions(idle)  # (the idle motions in joint rates, orthonormal)
        return cls(mech, idle, Jp_pinv, sigma_d, smax_d,
                   move / max(float(np.linalg.norm(move)), 1e-300), C, Ua, sa, Vat,
                   float(sa[-1]) if len(sa) else np.inf, float(sa[0]) if len(sa) else 0.0,
                   act / max(float(np.linalg.norm(act)), 1e-300),
                   np.concatenate([scales.constraint_rows, scales.task_rows]), col)

    @property
    def direct_distance(self) -> float:
        """``sigma_direct`` over the largest singular value of ``Ĵ_p``, in [0, 1] (0 where ``Ĵ_p`` is zero; 1 where
        no passive motion is left to lock: every joint actuated, or every passive motion idle)."""
        if self.sigma_direct == np.inf:
            return 1.0
        return min(self.sigma_direct / self.smax_direct, 1.0) if self.smax_direct > 0.0 else 0.0

    @property
    def inverse_distance(self) -> float:
        """``sigma_inverse`` over the largest singular value of ``[Ĵ_c; Ĵ_t]``, in [0, 1]."""
        return min(self.sigma_inverse / self.smax_inverse, 1.0) if self.smax_inverse > 0.0 else 0.0

    def direct_singular(self, rtol: float) -> bool:
        return self.sigma_direct <= rtol * self.smax_direct

    def inverse_singular(self, rtol: float) -> bool:
        return self.sigma_inverse <= rtol * self.smax_inverse

    def passive_solve(self, rhs: np.ndarray) -> np.ndarray:
        """The minimum-norm passive rates ``x`` with ``J_p x = rhs`` (no idle motion in them; the norm of the
        homogenised rates: :func:`homogenised_pinv`)."""
        return np.tensordot(self.Jp_pinv, rhs, axes=1)

    def joint_solve(self, rhs: np.ndarray) -> np.ndarray:
        """The joint rates ``v`` off the idle motions with ``[J_c; J_t] v = rhs`` (least squares)."""
        n = self.C.shape[1]
        extra = (1,) * (rhs.ndim - 1)
        rhs = self.rows.reshape((len(self.rows),) + extra) * rhs
        keep = self.sa[:n] > np.finfo(float).eps * max(self.Ua.shape[0], n) * self.smax_inverse  # as lstsq's rcond
        y = (self.Ua[:, :n][:, keep].T @ rhs) / self.sa[:n][keep].reshape((-1,) + extra)
        return self.columns.reshape((len(self.columns),) + extra) * (self.C @ (self.Vat[:n][keep].T @ y))


def _last_splits(mech: Mechanism) -> dict[tuple[float, bytes, bytes], _Split]:
    return {}


def _split(mech: Mechanism, c: Configuration, rtol: float) -> _Split:
    """:meth:`_Split.of` at ``c``, the last one kept with the mechanism (:func:`pkm._derived.derived`: made again
    where the mechanism changes) and given again for the same Jacobians, bit for bit, and ``rtol``: a path step asks
    for it four times (its rates, accelerations and efforts, the next step's prediction)."""
    Jc, Jt = c.constraint_jacobian, c.task_jacobian
    key = (rtol, Jc.tobytes(), Jt.tobytes())
    last = derived(mech, _last_splits)
    found = last.get(key)
    if found is None:
        found = _Split.of(mech, Jc, Jt, rtol)
        last.clear()
        last[key] = found
    return found


def _direct_check(sp: _Split, rtol: float) -> None:
    if sp.direct_singular(rtol):
        raise SingularityError("direct", sp.sigma_direct, "actuators locked, the task can still move",
                               distance=sp.direct_distance)


def _inverse_check(sp: _Split, rtol: float) -> None:
    if sp.inverse_singular(rtol):
        raise SingularityError("inverse", sp.sigma_inverse, "the task frozen, the actuators can still move",
                               distance=sp.inverse_distance)


def _convention(sp: _Split, c: Configuration, X: np.ndarray) -> np.ndarray:
    """Joint rates or accelerations ``X`` (no idle part in the Euclidean metric) with none in the mass metric
    (:func:`pkm.core.differential.idle.without_idle`); unchanged without idle motions."""
    if not sp.idle.shape[1]:
        return X
    return without_idle(joint_inertia(sp.mech, c.q), sp.idle, X)


def _passive_map(mech: Mechanism, sp: _Split, c: Configuration) -> np.ndarray:
    G = np.zeros((mech.nv, mech.na))
    G[mech.act_v, np.arange(mech.na)] = 1.0
    G[mech.passive_v] = -sp.passive_solve(c.constraint_jacobian[:, mech.act_v])
    return _convention(sp, c, G)


def idle_motions(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = RTOL) -> np.ndarray:
    """An orthonormal basis (nv x k) of the idle motions at ``q``: joint rates that the closures allow with the
    actuators locked and that the task does not see (a rod spinning about its axis between two ball joints);
    k = 0 for most mechanisms. The kinematics does not fix their rates and accelerations; pkm's rates and
    accelerations carry none of them in the mass metric (:mod:`pkm.core.differential.idle`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> pkm.idle_motions(delta, delta.q_reference).shape
        (12, 0)
        >>> robot = pkm.load("gepetto:robot_delta")
        >>> N = pkm.idle_motions(robot, robot.q_reference)
        >>> N.shape
        (14, 3)
        >>> np.allclose(N.T @ N, np.eye(3))
        True
    """
    mech, c = _at(mech, q)
    return _split(mech, c, as_tolerance(rtol, "rtol")).idle.copy()  # (the split is kept: its arrays are not given)


def passive_map(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = RTOL) -> np.ndarray:
    r"""The passive map :math:`G = \partial q / \partial q_a` (nv x na): all joint rates from the actuated rates, the
    idle motions' rates those of least kinetic energy (:math:`N^\top M G = 0`, :mod:`pkm.core.differential.idle`;
    the mass matrix is computed only where there are idle motions).

    Raises:
        SingularityError: ``kind="direct"``: with the actuators locked, a passive motion that moves
            the task is allowed to first order (the smallest singular value of ``J_p`` off the idle
            motions is at most ``rtol`` times the largest).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> G = pkm.passive_map(delta, q)
        >>> G.shape
        (12, 3)
        >>> np.allclose(G @ [0.1, 0.2, 0.3], pkm.velocities(delta, q, [0.1, 0.2, 0.3]))
        True
    """
    mech, c = _at(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    sp = _split(mech, c, rtol)
    _direct_check(sp, rtol)
    return finite_result(_passive_map(mech, sp, c), "passive map G")


def forward_jacobian(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = RTOL) -> np.ndarray:
    r"""The forward Jacobian :math:`J = J_t G`: task rates from actuated rates, :math:`\dot y = J \dot q_a`
    (n_task x na); raises as :func:`passive_map`.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> J = pkm.forward_jacobian(delta, q)
        >>> J.shape
        (3, 3)
        >>> np.round(J @ [0.1, 0.2, 0.3], 4)
        array([ 0.0108, -0.0198,  0.0257])
    """
    return _forward(mech, q, rtol, "forward")


def twist_jacobian(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = RTOL) -> np.ndarray:
    r"""The twist Jacobian: the end-effector twist :math:`[v; \omega]` (origin velocity, world axes) from actuated
    rates (6 x na).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> gs = pkm.load("gough_stewart")
        >>> Jt = pkm.twist_jacobian(gs, gs.q_reference)
        >>> Jt.shape
        (6, 6)
        >>> twist = Jt @ np.full(6, 0.01)  # every leg extending at 1 cm/s: the platform rises
        >>> round(float(twist[2]), 4), np.allclose(np.delete(twist, 2), 0.0)
        (0.0107, True)
    """
    return _forward(mech, q, rtol, "twist")


def _forward(mech: Mechanism, q: ArrayLike | Configuration, rtol: float, which: str) -> np.ndarray:
    mech, c = _at(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    sp = _split(mech, c, rtol)
    _direct_check(sp, rtol)
    J = c.task_jacobian if which == "forward" else c.ee_jacobian
    return finite_result(J @ _passive_map(mech, sp, c), f"{which} Jacobian")


def inverse_jacobian(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = RTOL) -> np.ndarray:
    r"""The inverse Jacobian :math:`J_{\mathrm{inv}}`: actuated rates from task rates,
    :math:`\dot q_a = J_{\mathrm{inv}} \dot y` (na x n_task), from :math:`[J_c; J_t]\, v = [0; \dot y]` read on the actuated rows.

    Raises:
        SingularityError: ``kind="inverse"``: with the task frozen, a motion of the actuators is
            allowed to first order (``[J_c; J_t]`` off the idle motions loses column rank, relative
            to ``rtol``).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> K = pkm.inverse_jacobian(delta, q)
        >>> np.round(K @ [0.0, 0.0, 0.1], 4)
        array([0.7986, 0.7918, 0.8072])
        >>> np.allclose(K @ pkm.forward_jacobian(delta, q), np.eye(3))
        True
    """
    mech, c = _at(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    sp = _split(mech, c, rtol)
    _inverse_check(sp, rtol)
    rhs = np.zeros((mech.n_constraints + mech.n_task, mech.n_task))
    rhs[mech.n_constraints:] = np.eye(mech.n_task)
    return finite_result(sp.joint_solve(rhs)[mech.act_v], "inverse Jacobian")


def velocities(mech: Mechanism, q: ArrayLike | Configuration, qd_actuated: ArrayLike) -> np.ndarray:
    r"""All joint rates :math:`v = G \dot q_a` (nv,) from the actuated rates (:func:`passive_map`: no idle motion in
    the mass metric).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.velocities(delta, q, [0.1, 0.2, 0.3])
        >>> v.shape
        (12,)
        >>> np.round(delta.actuated_q(v), 3)
        array([0.1, 0.2, 0.3])
        >>> np.round(pkm.task_velocity(delta, q, v), 4)
        array([ 0.0108, -0.0198,  0.0257])
    """
    G = passive_map(mech, q)
    return finite_result(G @ mech.check_actuated(qd_actuated, "qd_actuated", order="rate"), "joint velocities")


def accelerations(mech: Mechanism, q: ArrayLike | Configuration, v: ArrayLike, qdd_actuated: ArrayLike) -> np.ndarray:
    r"""All joint accelerations ``a`` (nv,) from the actuated ones, the drift included (:math:`J_c a + \dot J_c v = 0`),
    with no idle acceleration in the mass metric (:math:`N^\top M a = 0`, :mod:`pkm.core.differential.idle`).

    Raises:
        SingularityError: as :func:`passive_map`.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.velocities(delta, q, [0.1, 0.2, 0.3])
        >>> a = pkm.accelerations(delta, q, v, [1.0, 0.0, -1.0])
        >>> np.round(delta.actuated_q(a), 3)
        array([ 1.,  0., -1.])
        >>> np.round(pkm.task_acceleration(delta, q, v, a), 4)
        array([-0.1143,  0.1993, -0.0029])
    """
    mech, c = _at(mech, q)
    v = mech.check_v(v)
    qdd = mech.check_actuated(qdd_actuated, "qdd_actuated")
    gamma = constraints.drift(mech, c.q, v)
    sp = _split(mech, c, RTOL)
    _direct_check(sp, RTOL)
    a = np.zeros(mech.nv)
    a[mech.act_v] = qdd
    a[mech.passive_v] = -sp.passive_solve(c.constraint_jacobian[:, mech.act_v] @ qdd + gamma)
    return finite_result(_convention(sp, c, a), "joint accelerations")


def task_velocity(mech: Mechanism, q: ArrayLike | Configuration, v: ArrayLike) -> np.ndarray:
    """Task rates for joint rates ``v``.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.velocities(delta, q, [0.1, 0.2, 0.3])
        >>> np.round(pkm.task_velocity(delta, q, v), 4)
        array([ 0.0108, -0.0198,  0.0257])
        >>> np.allclose(pkm.task_velocity(delta, q, v), pkm.forward_jacobian(delta, q) @ [0.1, 0.2, 0.3])
        True
    """
    mech, c = _at(mech, q)
    v = mech.check_v(v)
    return finite_result(c.task_jacobian @ v, "task velocity")


def task_acceleration(mech: Mechanism, q: ArrayLike | Configuration, v: ArrayLike, a: ArrayLike) -> np.ndarray:
    r"""Task accelerations :math:`\ddot y = J_t a + \dot J_t v`.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.velocities(delta, q, [0.1, 0.2, 0.3])
        >>> a = pkm.accelerations(delta, q, v, [0.0, 0.0, 0.0])
        >>> np.round(pkm.task_acceleration(delta, q, v, a), 4)
        array([-0.002 ,  0.0007,  0.0041])
    """
    mech, c = _at(mech, q)
    v, a = mech.check_v(v), mech.check_v(a, "a")
    return finite_result(c.task_jacobian @ a + TaskMap.of(mech).bias(c.q, v), "task acceleration")


def inverse_velocities(mech: Mechanism, q: ArrayLike | Configuration, yd: ArrayLike) -> np.ndarray:
    """All joint rates ``v`` for task rates ``yd`` (nv,), no idle motion in the mass metric (as :func:`velocities`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.inverse_velocities(delta, q, [0.1, 0.0, 0.1])
        >>> np.allclose(pkm.task_velocity(delta, q, v), [0.1, 0.0, 0.1])
        True
        >>> np.round(delta.actuated_q(v), 4)
        array([0.7414, 0.3133, 1.1942])
    """
    mech, c = _at(mech, q)
    yd = as_vector(yd, mech.n_task, "yd")
    sp = _split(mech, c, RTOL)
    v = sp.joint_solve(np.concatenate([np.zeros(mech.n_constraints), yd]))
    return finite_result(_convention(sp, c, v), "joint velocities")


def inverse_accelerations(mech: Mechanism, q: ArrayLike | Configuration, v: ArrayLike, ydd: ArrayLike) -> np.ndarray:
    """All joint accelerations ``a`` for task accelerations ``ydd`` at state ``(q, v)``, no idle acceleration in the
    mass metric (as :func:`accelerations`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.inverse_velocities(delta, q, [0.1, 0.1, 0.0])
        >>> a = pkm.inverse_accelerations(delta, q, v, [1.0, 1.0, 2.0])
        >>> np.round(pkm.task_acceleration(delta, q, v, a), 6)
        array([1., 1., 2.])
    """
    mech, c = _at(mech, q)
    v = mech.check_v(v)
    ydd = as_vector(ydd, mech.n_task, "ydd")
    gamma_c = constraints.drift(mech, c.q, v)
    gamma_t = TaskMap.of(mech).bias(c.q, v)
    sp = _split(mech, c, RTOL)
    a = sp.joint_solve(np.concatenate([-gamma_c, ydd - gamma_t]))
    return finite_result(_convention(sp, c, a), "joint accelerations")


@dataclass(frozen=True)
class Diagnostics:
    """Rank and singularity measures at a configuration.

    Attributes:
        constraint_rank: Rank of the homogenised constraint Jacobian (relative to its largest singular value).
        redundant_constraints: Equations that are linearly dependent on others (planar loops
            closed with 3-D points have some).
        mobility: Instantaneous degrees of freedom, ``nv - constraint_rank`` (idle motions included).
        sigma_direct: Smallest singular value of the passive columns ``J_p`` off the idle motions, the Jacobian
            homogenised by the characteristic length (module doc; type 2 measure) [m]: it scales with the mechanism;
            inf where no passive motion is left (every joint actuated).
        sigma_inverse: Smallest singular value of ``[J_c; J_t]`` off the idle motions, homogenised (type 1
            measure) [m].
        classification: ``"regular"``, ``"inverse"``, ``"direct"`` or ``"combined"``.
        idle_motions: Passive motions that move neither the closures, nor the task, nor the actuators
            (a rod spinning about its axis between two ball joints; coaxial revolutes): not singularities.
        idle_joints: The joints those motions turn.
        direct_distance: ``sigma_direct`` over the largest singular value of the homogenised ``J_p``, in [0, 1]:
            dimensionless, the same for the mechanism scaled in size; 1 where no passive motion is left.
        inverse_distance: ``sigma_inverse`` over the largest singular value of the homogenised ``[J_c; J_t]``.
        near: The kinds (``"direct"``, ``"inverse"``) whose distance is below ``near`` but above
            ``rtol``: regular, but the Jacobians are large there.
        direct_direction: The task motion (unit, task tangent coordinates) of the weakest passive
            motion with the actuators locked: where the platform gives way near a direct singularity.
        inverse_direction: The actuated rates (unit) of the weakest motion with the task frozen.
        dependent_actuators: Actuators whose rates the others fix here (:class:`Actuation`).
        unactuated: Degrees of freedom that move the task with every actuator locked (:class:`Actuation`).
        near_threshold: The ``near`` argument: the distance below which :attr:`near` lists a kind.
    """

    constraint_rank: int
    redundant_constraints: int
    mobility: int
    sigma_direct: float
    sigma_inverse: float
    classification: str
    idle_motions: int = 0
    idle_joints: tuple[str, ...] = ()
    direct_distance: float = 1.0
    inverse_distance: float = 1.0
    near: tuple[str, ...] = ()
    direct_direction: np.ndarray | None = None
    inverse_direction: np.ndarray | None = None
    dependent_actuators: tuple[str, ...] = ()
    unactuated: int = 0
    near_threshold: float = 1e-3

    @property
    def summary(self) -> str:
        """One sentence (``str(diagnostics)``): the class, and how near a singularity a regular configuration is;
        the rank and the mobility (idle motions, redundant equations); the distances to each kind of singularity;
        the actuators that do not fit the mobility. The Delta at its reference: ``regular: mobility 3 (constraint
        rank 9 of 9 equations); distance to a direct singularity 0.236, to an inverse one 0.068 (0: singular,
        1: far)``."""
        out = self.classification
        dist = {"direct": self.direct_distance, "inverse": self.inverse_distance}
        if self.near:
            out += ", but near " + " and ".join(f"{'an' if k == 'inverse' else 'a'} {k} singularity (distance "
                                                 f"{dist[k]:.2g} < {self.near_threshold:g})" for k in self.near)
        equations = self.constraint_rank + self.redundant_constraints
        out += f": mobility {self.mobility} (constraint rank {self.constraint_rank} of {equations} equations"
        if self.redundant_constraints:
            out += f", {self.redundant_constraints} redundant"
        if self.idle_motions:
            out += f"; {self.idle_motions} idle motion(s), of {', '.join(self.idle_joints)}"
        out += (f"); distance to a direct singularity {dist['direct']:.3g}, to an inverse one {dist['inverse']:.3g} "
                "(0: singular, 1: far)")
        if self.dependent_actuators:
            out += f"; actuators {list(self.dependent_actuators)} depend on the others"
        if self.unactuated:
            out += f"; {self.unactuated} degree(s) of freedom move the task with every actuator locked"
        return out

    def __str__(self) -> str:
        return self.summary


@dataclass(frozen=True)
class Actuation:
    """How the actuators match the mechanism's mobility at a configuration (:func:`actuation`).

    Attributes:
        mobility: Degrees of freedom the closures leave (idle motions included, a floating base's six not).
        independent: How many actuators move independently: the rank of the actuated rates over the motions the
            closures allow.
        dependent: Actuators whose rates the others' fix (redundant actuation, or a joint held that leaves an
            actuator no freedom), in spec order: each one's value must agree with the others'.
        unactuated: Degrees of freedom left with every actuator locked that are not idle motions (they move the
            task): the actuators fall short of the mobility by this.
        idle_motions: Motions left with every actuator locked that the task does not see.
    """

    mobility: int
    independent: int
    dependent: tuple[str, ...]
    unactuated: int
    idle_motions: int

    @property
    def problem(self) -> str:
        """A sentence naming the dependent or missing actuators, or ``""`` when the actuators fit the mobility."""
        out = []
        if self.dependent:
            out.append(f"actuator(s) {list(self.dependent)} depend on the others (mobility {self.mobility}, "
                       f"{self.independent} independent actuators): their values must agree with the others'")
        if self.unactuated:
            out.append(f"{self.unactuated} degree(s) of freedom move the task with every actuator locked: the "
                       f"actuators fall short of the mobility ({self.mobility}, of which {self.idle_motions} idle)")
        return "; ".join(out)


def actuation(mech: Mechanism, q: ArrayLike | Configuration | None = None, *, rtol: float = 1e-7) -> Actuation:
    """The actuators against the mobility at ``q`` (default: the reference configuration): which actuators depend
    on the others, and how many degrees of freedom no actuator drives (:class:`Actuation`).

    With ``N`` a basis of the motions the closures allow (the null space of ``J_c``, the floating base held), the
    actuators are independent as far as the rows ``N[act]`` are (their rank, judged against ``rtol`` times the
    largest singular value of the homogenised ``J_c`` and 1e-6 for the unit-free rows), taken greedily in spec
    order: an actuator whose row adds no rank depends on those before it. Judged at one configuration: at a singular one more
    actuators look dependent than elsewhere.
    """
    mech = check_mechanism(mech)
    mech, c = _at(mech, mech.q_reference if q is None else q)
    rtol = as_tolerance(rtol, "rtol")
    return _actuation(mech, c, _split(mech, c, rtol), rtol)


def _actuation(mech: Mechanism, c: Configuration, sp: _Split, rtol: float) -> Actuation:
    Jc = JacobianScales.of(mech).constraint(finite_result(c.constraint_jacobian, "constraint Jacobian"))
    keep = np.setdiff1d(np.arange(mech.nv), mech.base_v)
    _, s, Vt = _svd(Jc[:, keep])
    rank = int(np.sum(s > rtol * s[0])) if len(s) and s[0] > 0.0 else 0
    N = Vt[rank:].T
    rows = N[np.searchsorted(keep, mech.act_v)]
    dependent, basis = [], np.zeros((0, N.shape[1]))
    for name, row in zip(mech.actuated_names, rows):
        trial = np.vstack([basis, row])
        if len(trial) <= N.shape[1] and np.linalg.svd(trial, compute_uv=False)[-1] > 1e-6:
            basis = trial
        else:
            dependent.append(name)
    idle = sp.idle.shape[1]
    mobility = N.shape[1]
    return Actuation(mobility, len(basis), tuple(dependent), max(mobility - len(basis) - idle, 0), idle)


def diagnose(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = 1e-7, near: float = 1e-3) -> Diagnostics:
    """Rank, mobility, idle motions, graded singularity measures and the actuators against the mobility at ``q``
    (which should be assembled). ``str()`` of the result is one sentence (:attr:`Diagnostics.summary`): the class
    (a regular configuration inside the ``near`` band says how near it is), the mobility and the constraint rank, the
    distances to a direct and an inverse singularity.

    Args:
        rtol: Relative rank tolerance: a kind is singular where its distance is at most ``rtol``.
        near: Distances below this (and above ``rtol``) are reported in :attr:`Diagnostics.near`.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> d = pkm.diagnose(delta, delta.q_reference)
        >>> print(d)  # doctest: +NORMALIZE_WHITESPACE
        regular: mobility 3 (constraint rank 9 of 9 equations); distance to a direct singularity 0.236,
        to an inverse one 0.068 (0: singular, 1: far)
        >>> d.mobility, round(d.direct_distance, 3), round(d.inverse_distance, 3)
        (3, 0.236, 0.068)
    """
    mech, c = _at(mech, q)
    rtol = as_tolerance(rtol, "rtol")
    near = max(as_tolerance(near, "near"), rtol)
    Jc = JacobianScales.of(mech).constraint(finite_result(c.constraint_jacobian, "constraint Jacobian"))
    s = np.linalg.svd(Jc, compute_uv=False)
    rank = int(np.sum(s > rtol * s[0])) if len(s) and s[0] > 0.0 else 0
    sp = _split(mech, c, rtol)
    dd, di = sp.direct_distance, sp.inverse_distance
    direct, inverse = dd <= rtol, di <= rtol
    moved = np.abs(sp.idle).max(axis=1) > 1e-6 if sp.idle.shape[1] else np.zeros(mech.nv, dtype=bool)
    idle_joints = tuple(j.name for j in mech.joints.values() if moved[j.idx_v:j.idx_v + j.nv].any())
    fit = _actuation(mech, c, sp, rtol)
    return Diagnostics(rank, mech.n_constraints - rank, mech.nv - rank, sp.sigma_direct, sp.sigma_inverse,
                       singularity_class(inverse, direct), sp.idle.shape[1], idle_joints, dd, di,
                       tuple(k for k, d in (("direct", dd), ("inverse", di)) if rtol < d < near),
                       sp.direct_direction.copy(), sp.inverse_direction.copy(), fit.dependent, fit.unactuated, near)


def singularity_distances(mech: Mechanism, q: ArrayLike | Configuration, *, rtol: float = 1e-7) -> tuple[float, float]:
    """:func:`diagnose`'s ``(direct_distance, inverse_distance)`` at ``q``, the same numbers, without the rest of the
    diagnosis (the constraint rank's SVD and the actuators against the mobility: over half its cost): what a search
    that asks at each of its points how far the singularities are needs (:func:`pkm.feasible_region`, an
    excitation's check).

    Examples:
        >>> import pkm
        >>> from pkm.core.differential.velocity import singularity_distances
        >>> delta = pkm.load("delta")
        >>> direct, inverse = singularity_distances(delta, delta.q_reference)
        >>> d = pkm.diagnose(delta, delta.q_reference)
        >>> (direct, inverse) == (d.direct_distance, d.inverse_distance), round(direct, 4), round(inverse, 4)
        (True, 0.2364, 0.068)
    """
    mech, c = _at(mech, q)
    sp = _split(mech, c, as_tolerance(rtol, "rtol"))
    return sp.direct_distance, sp.inverse_distance
