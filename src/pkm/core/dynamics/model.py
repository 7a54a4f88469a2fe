r"""The dynamic model of any closed-loop mechanism in its actuated coordinates.

The closures leave ``na`` degrees of freedom, driven by the actuated joints: the state is the configuration ``q``
(assembled) and the actuated rates ``qd`` (``q̇_a``). With ``J_c = [J_a J_p]`` the closure Jacobian split into
actuated and passive columns (:mod:`pkm.core.kinematics.constraints`), ``M`` Pinocchio's joint-space mass matrix
(``crba``, the actuators' reflected inertia on its diagonal, :mod:`pkm.core.model.actuators`) and ``b`` its
non-linear effects (``rnea``):

* ``Ĝ``: joint rates from actuated rates, ``v = Ĝ qd`` (:func:`~pkm.core.differential.velocity.passive_map`,
  :func:`pkm.velocities`);
* the **idle motions** ``N`` (a rod spinning between two balls: passive motions the closures and the task leave
  free with the actuators locked) are **kept out of the state** by pkm's one idle-motion convention
  (:mod:`pkm.core.differential.idle`): rates and accelerations carry none in the mass metric, ``Ĝ = G - N (Nᵀ M
  N)⁺ Nᵀ M G`` (``G`` the minimum-norm map), so that ``Nᵀ M Ĝ = 0`` and the spin carries no momentum of its own.
  For a rod whose inertia is symmetric about the line of its two balls (any cylinder, any point mass) ``Ĝ = G``: the
  spin decouples exactly and a spin started at zero stays zero; otherwise the spin is slaved to carry no momentum
  (exact for a spin-free start to first order). No idle acceleration changes an effort (``Ĝᵀ M N = 0``);
* ``a = Ĝ qdd + a_b`` (:func:`pkm.accelerations`), ``a_b`` the closure's drift compensation (``J_c a_b + gamma =
  0``, no actuated acceleration, no idle acceleration in the mass metric).

Then, with :math:`\tau_a` the actuator efforts,

$$
M_a(q)\,\ddot q_a + h_a(q, \dot q_a) = \tau_a + f_a(q, \dot q_a), \qquad
M_a = \hat G^\top M \hat G, \qquad h_a = \hat G^\top \mathrm{rnea}(q, \hat G \dot q_a, a_b)
$$

where :math:`h_a` holds the Coriolis, centrifugal and gravity terms and the drift of the closures,
:math:`g_a = \hat G^\top g(q)` is gravity alone, and :math:`f_a = \hat G^\top (-D v - F \operatorname{sgn}(v))` the joints' friction (Pinocchio's
``damping`` ``D`` and ``friction`` ``F``, the actuators' viscous and Coulomb friction among them; ``sgn`` a sign
smoothed over ``coulomb_velocity``). :math:`\tfrac{1}{2} \dot q_a^\top M_a \dot q_a` is the kinetic energy. The
Coriolis matrix :math:`C_a` is built from the Christoffel symbols of :math:`M_a` (:func:`coriolis_matrix`), so that
:math:`\dot M_a - 2 C_a` is skew-symmetric; the derivatives of ``M_a``
are Richardson-extrapolated central differences on the closed mechanism (steps of 2e-5 and 1e-5 in the actuated
coordinates).

In task coordinates (a task of ``na`` coordinates, :math:`\dot y = J \dot q_a`),
:math:`\Lambda = J^{-\top} M_a J^{-1}` (Khatib's operational-space inertia) and
:math:`\mu = J^{-\top} h_a - \Lambda \ddot y_b` (:math:`\ddot y_b` the task acceleration at :math:`\ddot q_a = 0`):
:math:`J^{-\top} \tau_a = \Lambda \ddot y + \mu`.

Redundant closures (a planar loop closed with a 6-D frame) are handled by rank: ``J_p``'s pseudo-inverse drops the
dependent rows; no regularisation is involved. A direct singularity (a passive motion the actuators do not hold)
and an actuated motion that moves no mass raise :class:`~pkm.errors.SingularityError`.

Checks (tests): ``M_a qdd + h_a`` equals :func:`pkm.inverse_dynamics` to 1e-10 relative; ``½ qdᵀ M_a qd`` equals
Pinocchio's kinetic energy; ``Ṁ_a - 2C_a`` is skew against finite differences of ``M_a``; the forward dynamics
equals Pinocchio's ``constraintDynamics`` (proximal where closures are redundant).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.differential.idle import joint_inertia, without_idle
from pkm.core.differential.velocity import RTOL, homogenised_pinv  # (one rank threshold with pkm.diagnose's)
from pkm.core.kinematics import constraints
from pkm.core.kinematics.solve import close_loops
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, SingularityError
from pkm.validation import as_scalar, as_tolerance, finite_result

COULOMB_VELOCITY = 1e-3  # [rad/s or m/s]: the Coulomb friction's sign is smoothed as tanh(v / this)
_FD_STEP = 2e-5


@dataclass(frozen=True)
class _Reduction:
    """What the model needs of the kinematics at ``q``: ``Ĝ``, the passive pseudo-inverse, the idle motions."""

    G: np.ndarray  # nv x na, Ĝ
    Jp_pinv: np.ndarray  # n_passive x n_constraints
    idle: np.ndarray  # nv x k
    M: np.ndarray  # nv x nv, crba with the reflected inertias


def _reduce(mech: Mechanism, q: np.ndarray, rtol: float) -> _Reduction:
    """The rank of ``J_p`` and the idle motions are judged on the Jacobians homogenised by the mechanism's
    characteristic length (:mod:`pkm.core.model.scale`), as :func:`pkm.diagnose` judges them: the same for the
    mechanism scaled in size."""
    scales = JacobianScales.of(mech)
    Jc = constraints.jacobian(mech, q)
    pv, av = mech.passive_v, mech.act_v
    Jp_pinv, s, Vt, r = homogenised_pinv(Jc[:, pv], scales.constraint_rows, scales.columns[pv], rtol)
    smax = float(s[0]) if s.size else 0.0
    G = np.zeros((mech.nv, mech.na))
    G[av, np.arange(mech.na)] = 1.0
    G[pv] = -Jp_pinv @ Jc[:, av]
    null = Vt[r:].T
    idle = np.zeros((mech.nv, null.shape[1]))
    if null.shape[1]:  # passive motions with the actuators locked: idle (the task does not see them) or singular
        idle[pv] = null
        Jt = scales.task(TaskMap.of(mech).jacobian(q))
        seen = np.linalg.svd(Jt @ idle, compute_uv=False)
        t_ref = max(float(np.linalg.norm(Jt, 2)), 1e-300)
        if seen.size and seen[0] > rtol * t_ref:
            sigma = float(s[r]) if r < s.size else 0.0
            raise SingularityError("direct", sigma,
                                   "with the actuators locked a passive motion moves the task: the actuators do "
                                   "not hold the mechanism here, its dynamics in actuated coordinates is undefined",
                                   distance=sigma / smax if smax > 0.0 else 0.0)
        idle = scales.joint_motions(idle)  # (in joint rates, orthonormal)
    M = joint_inertia(mech, q)
    return _Reduction(without_idle(M, idle, G), Jp_pinv, idle, M)


@dataclass(frozen=True)
class ActuatorSpaceModel:
    """The dynamic model at one state ``(q, qd)`` in the actuated coordinates (see the module doc).

    Attributes:
        mech: The mechanism.
        q: The configuration (nq,).
        qd: The actuated rates (na,) [rad/s or m/s].
        v: The joint rates ``Ĝ qd`` (nv,).
        G: ``Ĝ`` (nv x na): joint rates from actuated rates, mass-orthogonal to the idle motions.
        drift_acceleration: ``a_b`` (nv,): the joint accelerations at ``qdd = 0`` (closure drift compensated, no idle
            acceleration in the mass metric).
        M: ``M_a`` (na x na) [kg m^2, kg]: symmetric, positive definite away from singularities.
        h: ``h_a`` (na,) [N m, N]: Coriolis, centrifugal, gravity and closure-drift efforts.
        g: ``g_a`` (na,): the gravity part of ``h_a`` (the efforts that hold the mechanism still).
        friction: ``f_a`` (na,): the joints' viscous and Coulomb friction at ``v`` (opposes the motion).
        idle: The idle motions (nv x k, orthonormal), carried by no rate in the mass metric.
    """

    mech: Mechanism
    q: np.ndarray
    qd: np.ndarray
    v: np.ndarray
    G: np.ndarray
    drift_acceleration: np.ndarray
    M: np.ndarray
    h: np.ndarray
    g: np.ndarray
    friction: np.ndarray
    idle: np.ndarray
    _M_joint: np.ndarray

    def __post_init__(self) -> None:
        for value in vars(self).values():
            if isinstance(value, np.ndarray):
                value.setflags(write=False)

    @property
    def kinetic_energy(self) -> float:
        r"""The kinetic energy :math:`\tfrac{1}{2} \dot q_a^\top M_a \dot q_a` [J]."""
        return float(0.5 * self.qd @ self.M @ self.qd)

    def efforts(self, qdd: ArrayLike) -> np.ndarray:
        r""":math:`M_a \ddot q_a + h_a` (na,) [N m, N]: the efforts for actuated accelerations ``qdd`` (no friction)."""
        qdd = self.mech.check_actuated(qdd, "qdd")
        return finite_result(self.M @ qdd + self.h, "actuator efforts")

    def accelerations(self, tau: ArrayLike, *, friction: bool = True) -> np.ndarray:
        r""":math:`\ddot q_a = M_a^{-1} (\tau_a + f_a - h_a)` (na,) for actuator efforts ``tau`` (with the friction,
        by default).

        Raises:
            SingularityError: ``kind="inertia"``: an actuated motion moves no mass (``M_a`` singular).
        """
        tau = self.mech.check_actuated(tau, "tau")
        return finite_result(_solve_inertia(self.M, tau + (self.friction if friction else 0.0) - self.h,
                                            JacobianScales.of(self.mech).actuated),
                             "actuated accelerations")

    def joint_accelerations(self, qdd: ArrayLike) -> np.ndarray:
        """All joint accelerations (nv,) for actuated ones: ``Ĝ qdd + a_b``, as :func:`pkm.accelerations` gives them
        (no idle acceleration in the mass metric)."""
        qdd = self.mech.check_actuated(qdd, "qdd")
        return finite_result(self.G @ qdd + self.drift_acceleration, "joint accelerations")


def _solve_inertia(M: np.ndarray, rhs: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """``M^-1 rhs`` by Cholesky, refused where the factor's diagonal, homogenised by ``scale`` (the actuated columns'
    factors of :class:`~pkm.core.model.scale.JacobianScales`: ``L`` for a prismatic actuator, so that every entry of
    ``D M D`` is in kg m^2), spans more than ``1 / sqrt(RTOL)``: the same test for the mechanism scaled in size."""
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        L = None
    if L is not None:
        d = np.diag(L) * scale
        if d.min() > np.sqrt(RTOL) * d.max():
            return np.linalg.solve(L.T, np.linalg.solve(L, rhs))
    w = np.linalg.eigvalsh(M)
    raise SingularityError("inertia", float(max(w[0], 0.0)), "an actuated motion moves no mass (the actuator-space "
                                                             "mass matrix is singular): give the bodies or the "
                                                             "actuators (rotor_inertia) inertia")


def _check_state(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None) -> tuple[Mechanism, np.ndarray, np.ndarray]:
    mech = check_mechanism(mech)
    q = mech.check_q(q)
    if qd is None:
        return mech, q, np.zeros(mech.na)
    try:
        arr = np.asarray(qd, dtype=float) if not isinstance(qd, str) else None
    except (TypeError, ValueError, OverflowError):  # (check_actuated says what is wrong)
        arr = None
    if arr is not None and arr.shape == (mech.nv,) and mech.nv != mech.na:
        return mech, q, mech.check_actuated(mech.check_v(arr, "qd")[mech.act_v], "qd")
    return mech, q, mech.check_actuated(qd, "qd")


def _evaluate(mech: Mechanism, q: np.ndarray, qd: np.ndarray, rtol: float,
              coulomb_velocity: float = COULOMB_VELOCITY) -> ActuatorSpaceModel:
    red = _reduce(mech, q, rtol)
    m, d = mech.model, mech.data
    v = red.G @ qd
    a_b = np.zeros(mech.nv)
    if mech.n_constraints:
        a_b[mech.passive_v] = -red.Jp_pinv @ constraints.drift(mech, q, v)
        a_b = without_idle(red.M, red.idle, a_b)
    b = pin.rnea(m, d, q, v, a_b).copy()
    g = pin.computeGeneralizedGravity(m, d, q)
    f_joint = -np.asarray(m.damping) * v - np.asarray(m.friction) * np.tanh(v / coulomb_velocity)
    Gt = red.G.T
    M_a = Gt @ red.M @ red.G
    M_a = 0.5 * (M_a + M_a.T)
    return ActuatorSpaceModel(mech, q, qd.copy(), v, red.G, a_b, finite_result(M_a, "actuator-space mass matrix"),
                              finite_result(Gt @ b, "actuator-space bias"), Gt @ g, Gt @ f_joint, red.idle,
                              red.M)


def actuator_model(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None = None, *, rtol: float = RTOL,
                   coulomb_velocity: float = COULOMB_VELOCITY) -> ActuatorSpaceModel:
    r"""The dynamic model of ``mech`` in its actuated coordinates at the state ``(q, qd)``:
    :math:`M_a(q)\,\ddot q_a + h_a(q, \dot q_a) = \tau_a + f_a(q, \dot q_a)` (module doc).

    Args:
        mech: The mechanism.
        q: An assembled configuration (nq,) (:func:`pkm.close_loops`).
        qd: The actuated rates (na,) [rad/s or m/s], or all joint rates (nv,), read on their actuated entries;
            default zero.
        rtol: Relative rank threshold (redundant closures, idle motions, singularities).
        coulomb_velocity: The speed over which the Coulomb friction's sign is smoothed [rad/s or m/s].

    Raises:
        SingularityError: ``kind="direct"`` at a direct singularity.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> model = pkm.actuator_model(delta, delta.q_reference, [1.0, 0.0, 0.0])
        >>> np.round(model.M, 5)
        array([[ 0.00298, -0.00058, -0.00058],
               [-0.00058,  0.00298, -0.00058],
               [-0.00058, -0.00058,  0.00298]])
        >>> np.round(model.h, 4)
        array([0.1784, 0.1805, 0.1805])
        >>> np.round(model.efforts([10.0, 0.0, 0.0]), 4)
        array([0.2082, 0.1747, 0.1747])
        >>> np.allclose(model.efforts([10.0, 0.0, 0.0]), model.M @ [10.0, 0.0, 0.0] + model.h)
        True
        >>> round(model.kinetic_energy, 6)
        0.001489
    """
    mech, q, qd = _check_state(mech, q, qd)
    rtol = as_tolerance(rtol, "rtol")
    coulomb_velocity = as_scalar(coulomb_velocity, "coulomb_velocity", low=1e-12)
    return _evaluate(mech, q, qd, rtol, coulomb_velocity)


def mass_matrix(mech: Mechanism, q: ArrayLike) -> np.ndarray:
    r"""The mass matrix in the actuated coordinates :math:`M_a(q) = \hat G^\top M(q) \hat G` (na x na)
    [kg m^2, kg]: the reflected inertias in (module doc: :math:`\hat G` the passive map, :math:`M` Pinocchio's).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> M = pkm.mass_matrix(delta, delta.q_reference)
        >>> np.round(M, 5)
        array([[ 0.00298, -0.00058, -0.00058],
               [-0.00058,  0.00298, -0.00058],
               [-0.00058, -0.00058,  0.00298]])
        >>> bool(np.all(np.linalg.eigvalsh(M) > 0))
        True
    """
    return actuator_model(mech, q).M.copy()


def bias_efforts(mech: Mechanism, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
    r"""The bias efforts :math:`h_a(q, \dot q_a)` (na,) [N m, N]: Coriolis, centrifugal, gravity and closure-drift
    efforts, the efforts at :math:`\ddot q_a = 0` in :math:`M_a \ddot q_a + h_a = \tau_a + f_a` (module doc).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = delta.q_reference
        >>> np.round(pkm.bias_efforts(delta, q, [1.0, 0.0, 0.0]), 4)
        array([0.1784, 0.1805, 0.1805])
        >>> np.allclose(pkm.bias_efforts(delta, q, np.zeros(3)), pkm.gravity_efforts(delta, q))
        True
    """
    return actuator_model(mech, q, qd).h.copy()


def gravity_efforts(mech: Mechanism, q: ArrayLike) -> np.ndarray:
    r"""The gravity efforts :math:`g_a(q) = \hat G^\top g(q)` (na,) [N m, N]: the actuator efforts that hold the
    mechanism still against gravity.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> np.round(pkm.gravity_efforts(delta, delta.q_reference), 4)
        array([0.1797, 0.1797, 0.1797])
    """
    return actuator_model(mech, q).g.copy()


def mass_matrix_derivatives(mech: Mechanism, q: ArrayLike, *, rtol: float = RTOL) -> np.ndarray:
    """``∂M_a/∂q_a`` (na x na x na, ``[k]`` the derivative along actuated coordinate ``k``), by Richardson-extrapolated
    central differences on the closed mechanism (``(4 D(h/2) - D(h)) / 3``, ``h`` = 2e-5 rad or m, each point
    closed by :func:`pkm.close_loops`; truncation O(h^4): a plain central difference is 1e-5 off on the hexapod)."""
    mech = check_mechanism(mech)
    q = mech.check_q(q)
    rtol = as_tolerance(rtol, "rtol")
    G = _reduce(mech, q, rtol).G
    qa = mech.actuated_q(q)

    def at(k: int, step: float) -> np.ndarray:
        qs = close_loops(mech, qa + step * np.eye(mech.na)[k], pin.integrate(mech.model, q, step * G[:, k])).q
        return _evaluate(mech, qs, np.zeros(mech.na), rtol).M

    out = np.empty((mech.na, mech.na, mech.na))
    for k in range(mech.na):
        wide = (at(k, _FD_STEP) - at(k, -_FD_STEP)) / (2.0 * _FD_STEP)
        narrow = (at(k, 0.5 * _FD_STEP) - at(k, -0.5 * _FD_STEP)) / _FD_STEP
        out[k] = (4.0 * narrow - wide) / 3.0
    return out


def coriolis_matrix(mech: Mechanism, q: ArrayLike, qd: ArrayLike, *, rtol: float = RTOL) -> np.ndarray:
    r"""The Coriolis matrix :math:`C_a(q, \dot q_a)` (na x na) from the Christoffel symbols of :math:`M_a`:

    $$
    C_{ij} = \sum_k \tfrac{1}{2} \left( \partial_k M_{ij} + \partial_j M_{ik} - \partial_i M_{jk} \right) \dot q_k,
    $$

    so that :math:`\dot M_a - 2 C_a` is skew-symmetric and :math:`C_a \dot q_a = h_a - g_a` (the derivatives by
    :func:`mass_matrix_derivatives`).

    Pinocchio's own ``computeCoriolisMatrix`` is not used: on Pinocchio 4.1 it is wrong for universal joints (NaN)
    and mimic joints (tested).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q, qd = delta.q_reference, np.array([1.0, -0.5, 0.2])
        >>> C = pkm.coriolis_matrix(delta, q, qd)
        >>> np.round(C @ qd, 4)
        array([-0.0009,  0.001 ,  0.0008])
        >>> np.allclose(C @ qd, pkm.bias_efforts(delta, q, qd) - pkm.gravity_efforts(delta, q))
        True
    """
    mech, q, qd = _check_state(mech, q, qd)
    dM = mass_matrix_derivatives(mech, q, rtol=rtol)  # dM[k, i, j] = d M_ij / d q_k
    gamma = 0.5 * (dM + np.transpose(dM, (2, 1, 0)) - np.transpose(dM, (2, 0, 1)))  # gamma[k, i, j]
    return finite_result(np.einsum("kij,k->ij", gamma, qd), "Coriolis matrix")


@dataclass(frozen=True)
class OperationalSpace:
    """Khatib's operational-space model at one state: ``J⁻ᵀ τ_a = Λ ÿ + μ`` (task coordinates ``y``).

    Attributes:
        inertia: ``Λ = J⁻ᵀ M_a J⁻¹`` (n x n).
        bias: ``μ = J⁻ᵀ h_a - Λ ÿ_b`` (n,).
        jacobian: ``J``, task rates from actuated rates (n x na, square).
        drift: ``ÿ_b``, the task acceleration at zero actuated acceleration (n,).
    """

    inertia: np.ndarray
    bias: np.ndarray
    jacobian: np.ndarray
    drift: np.ndarray


def operational_space(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None = None, *,
                      rtol: float = RTOL) -> OperationalSpace:
    r"""The operational-space inertia :math:`\Lambda = J^{-\top} M_a J^{-1}` and bias :math:`\mu`, such that
    :math:`J^{-\top} \tau_a = \Lambda \ddot y + \mu`, in the task coordinates (needs as many as actuators).

    Raises:
        InvalidInputError: the task does not have ``na`` coordinates.
        SingularityError: ``kind="inverse"`` where ``J`` loses rank.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> osp = pkm.operational_space(delta, delta.q_reference)
        >>> np.round(np.diag(osp.inertia), 4)
        array([0.3011, 0.3011, 0.4505])
        >>> round(float(osp.bias[2]), 4)
        4.908
    """
    mech, q, qd = _check_state(mech, q, qd)
    if mech.n_task != mech.na:
        raise InvalidInputError("mech", f"the task has {mech.n_task} coordinates for {mech.na} actuators: the "
                                        "operational space needs as many", mech.n_task)
    model = _evaluate(mech, q, qd, as_tolerance(rtol, "rtol"))
    tm = TaskMap.of(mech)
    Jt = tm.jacobian(q)
    J = Jt @ model.G
    scales = JacobianScales.of(mech)  # (homogenised: judged as for the mechanism scaled in size)
    s = np.linalg.svd(scales.forward(J), compute_uv=False)
    if s[-1] <= rtol * max(float(s[0]), 1e-300):
        raise SingularityError("inverse", float(s[-1]), "the task Jacobian J = dy/dq_a loses rank",
                               distance=float(s[-1]) / max(float(s[0]), 1e-300))
    drift = Jt @ model.drift_acceleration + tm.bias(q, model.v)
    Jinv = np.linalg.inv(J)
    Lam = Jinv.T @ model.M @ Jinv
    Lam = 0.5 * (Lam + Lam.T)
    return OperationalSpace(finite_result(Lam, "operational-space inertia"),
                            finite_result(Jinv.T @ model.h - Lam @ drift, "operational-space bias"), J, drift)


def forward_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, tau_actuated: ArrayLike, *,
                     friction: bool = False, rtol: float = RTOL) -> np.ndarray:
    """All joint accelerations (nv,) under actuator efforts, from the actuated-coordinate model (exact by rank:
    redundant closures need no regularisation).

    Args:
        mech: The mechanism.
        q: An assembled configuration.
        v: The joint rates (nv,) or the actuated rates (na,); only the actuated rates are read (the state).
        tau_actuated: Efforts in ``mech.actuated`` order [N m, N].
        friction: Include the joints' friction (:class:`ActuatorSpaceModel`); off by default, as Pinocchio's
            ``constraintDynamics``.
        rtol: Relative rank threshold.

    Raises:
        SingularityError: at a direct singularity, or where an actuated motion moves no mass.
    """
    model = actuator_model(mech, q, v, rtol=rtol)
    return model.joint_accelerations(model.accelerations(tau_actuated, friction=friction))


__all__ = ["COULOMB_VELOCITY", "ActuatorSpaceModel", "OperationalSpace", "actuator_model", "bias_efforts",
           "coriolis_matrix", "forward_dynamics", "gravity_efforts", "mass_matrix", "mass_matrix_derivatives",
           "operational_space"]
